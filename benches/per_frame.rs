//! The per-frame work of mission data handling, step by step, and the assembly of full lists.
//!
//! - `13002/decode`: `wire::decode` of one #13002 frame (wrapper, presence vector, fields,
//!   checksum);
//! - `13002/sampling`: `MessageSampler::sample` of a fresh (source, type, time stamp);
//! - `13002/handle`: `MissionDataHandling::handle_frame` of a #13002 during an upload (after a
//!   clear): preprocessing, sampling, moding, storing in the buffer, #17000 queued;
//! - `13002/ack_encode`: `poll_transmit` of that queued #17000 into a buffer;
//! - `13002/frame_total`: `handle_frame` and `poll_transmit` together, what the per-frame budget
//!   of 2 µs covers;
//! - `assembly/...`: `MissionBuffer::assemble` of 256 waypoints stored in shuffled order and
//!   `AreaBuffer::assemble` of 1 fly-zone and 10 no-fly-zones of 60 vertices, each also with
//!   `to_payload` (the lists as published to guidance).
//!
//! The #13002 frames of an upload carry waypoint numbers rotating through 1..=256 (the buffer
//! never overflows: a number sent again overwrites) and rising time stamps (sampling never drops
//! them). Run with `cargo bench --bench per_frame`.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::hint::black_box;
use std::time::{Duration, Instant as WallClock};

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use missionlink_flight::mission_data_handling::MissionDataHandling;
use missionlink_flight::testkit::{self, Transmit, UTC_AT_ZERO_MS, ts, uplink};
use missionlink_interfaces::capacity::MAX_WAYPOINTS;
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{
    self, AckType, LegType, MAX_FRAME_LEN, Message, MissionPlanMode, SafetyOffset,
    UaPositionWaypoint,
};
use missionlink_protocol::link::endpoint::OUTBOX_CAPACITY;
use missionlink_protocol::link::sampling::{MessageSampler, Sample};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::areas::AreaBuffer;
use missionlink_protocol::transfer::mission::MissionBuffer;
use missionlink_protocol::transfer::sender::mission_command;

const WAYPOINTS: u16 = MAX_WAYPOINTS as u16;

/// Waypoint `n` of a 256-waypoint ring: all 18 fields (as the wire bench), track-to-fix.
fn waypoint(n: u16, stamp_ms: u64) -> Message {
    let full = testkit::full_waypoint();
    let latitude = wire::Angle::from_degrees(48.26 + f64::from(n) * 1e-4).expect("latitude");
    UaPositionWaypoint {
        time_stamp: ts(stamp_ms),
        waypoint_number: n,
        next_waypoint: n % WAYPOINTS + 1,
        leg_type: LegType::TrackToFix,
        latitude,
        ..full
    }
    .into()
}

/// The #13002 frames of an upload, one per call: numbers 1..=256 round and round, time stamps
/// rising by 1 ms, the receive instant with them.
struct Upload {
    count: u64,
}

impl Upload {
    /// Starts after the clear, which had stamp and instant 0.
    fn new() -> Self {
        Self { count: 0 }
    }

    fn next_frame(&mut self) -> (Instant, Vec<u8>) {
        self.count += 1;
        let n = (self.count % u64::from(WAYPOINTS)) as u16 + 1;
        let frame = uplink(&waypoint(n, UTC_AT_ZERO_MS + self.count));
        (Instant::from_millis(self.count), frame)
    }
}

/// Mission data handling with an upload in progress: it has received (and answered) a clear.
fn fcc_uploading() -> MissionDataHandling {
    let mut fcc = MissionDataHandling::new(testkit::fcc_config());
    let mut clear = mission_command(MissionPlanMode::ClearMission, None, None);
    clear.set_time_stamp(ts(UTC_AT_ZERO_MS));
    fcc.handle_frame(Instant::ZERO, &uplink(&clear))
        .expect("clear accepted");
    expect_completed(&mut fcc, 13000);
    fcc
}

/// Mission data handling uploading, the frames to give it and a buffer for its answers.
fn uploading() -> (MissionDataHandling, Upload, [u8; MAX_FRAME_LEN]) {
    (fcc_uploading(), Upload::new(), [0u8; MAX_FRAME_LEN])
}

/// Takes the one queued answer and checks it accepts a message of `original_type`.
fn expect_completed(fcc: &mut MissionDataHandling, original_type: u16) {
    match fcc.messages().as_slice() {
        [Message::MessageAcknowledgement(a)] => {
            assert_eq!(a.ack_type, AckType::Completed, "{a:?}");
            assert_eq!(a.original_message_type, original_type);
        }
        other => panic!("expected one #17000, got {other:?}"),
    }
}

/// The time `chunk` gives for `iters` frames, in chunks of at most OUTBOX_CAPACITY: the outgoing
/// queue holds that many answers, so each chunk handles its frames and drains their answers,
/// one of the two timed (`chunk` returns the time of that part).
fn in_chunks(iters: u64, mut chunk: impl FnMut(usize) -> Duration) -> Duration {
    let mut total = Duration::ZERO;
    let mut left = iters;
    while left > 0 {
        let n = left.min(OUTBOX_CAPACITY as u64);
        total += chunk(n as usize);
        left -= n;
    }
    total
}

fn frame_benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("13002");
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));

    let frame = uplink(&waypoint(1, UTC_AT_ZERO_MS + 1));
    group.bench_function("decode", |b| b.iter(|| wire::decode(black_box(&frame))));

    group.bench_function("sampling", |b| {
        let mut sampler = MessageSampler::new(defaults::TRANSFER_TIMEOUT);
        let mut count = 0u64;
        b.iter_batched(
            || {
                count += 1;
                (Instant::from_millis(count), ts(UTC_AT_ZERO_MS + count))
            },
            |(now, stamp)| {
                let s = sampler.sample(now, defaults::GCS_ID, 13002, black_box(stamp));
                debug_assert_eq!(s, Sample::Fresh);
                s
            },
            BatchSize::SmallInput,
        )
    });

    // Handle a chunk of frames, timed, then drain their acknowledgements, untimed (and the other
    // way round for the encode).
    group.bench_function("handle", |b| {
        let (mut fcc, mut upload, mut out) = uploading();
        b.iter_custom(|iters| {
            in_chunks(iters, |chunk| {
                let frames: Vec<_> = (0..chunk).map(|_| upload.next_frame()).collect();
                let start = WallClock::now();
                for (now, frame) in &frames {
                    let _ = black_box(fcc.handle_frame(*now, black_box(frame)));
                }
                let elapsed = start.elapsed();
                while fcc.poll_transmit(&mut out).is_some() {}
                elapsed
            })
        })
    });

    group.bench_function("ack_encode", |b| {
        let (mut fcc, mut upload, mut out) = uploading();
        b.iter_custom(|iters| {
            in_chunks(iters, |chunk| {
                for _ in 0..chunk {
                    let (now, frame) = upload.next_frame();
                    fcc.handle_frame(now, &frame).expect("frame accepted");
                }
                let start = WallClock::now();
                for _ in 0..chunk {
                    let _ = black_box(fcc.poll_transmit(black_box(&mut out)));
                }
                start.elapsed()
            })
        })
    });

    group.bench_function("frame_total", |b| {
        let (mut fcc, mut upload, mut out) = uploading();
        b.iter_batched(
            || upload.next_frame(),
            // The frame is handed back so that criterion frees it outside the measurement.
            |(now, frame)| {
                let _ = fcc.handle_frame(now, black_box(&frame));
                (frame, black_box(fcc.poll_transmit(&mut out)))
            },
            BatchSize::SmallInput,
        )
    });
    group.finish();

    // Every frame above was accepted: the same path, checked once outside the measurement.
    let (mut fcc, mut upload, _) = uploading();
    for _ in 0..3 * WAYPOINTS {
        let (now, frame) = upload.next_frame();
        fcc.handle_frame(now, &frame).expect("frame accepted");
        expect_completed(&mut fcc, 13002);
    }
}

/// 256 waypoints chained 1 -> 2 -> ... -> 256 with take-off height and route, stored in
/// shuffled order.
fn mission_buffer() -> MissionBuffer {
    let mut messages = testkit::zigzag(WAYPOINTS);
    missionlink_linksim::Rng::new(0x9E37_79B9_7F4A_7C15).shuffle(&mut messages);
    testkit::mission_buffer(&messages)
}

/// The fly-zone and 10 no-fly-zones of 60 vertices inside it.
fn area_buffer() -> AreaBuffer {
    testkit::area_buffer(&testkit::eleven_areas())
}

fn assembly_benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("assembly");
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));

    let missions = mission_buffer();
    let mission = missions.assemble(Some(WAYPOINTS), None).expect("assembles");
    assert_eq!(mission.waypoints.len(), MAX_WAYPOINTS);
    group.bench_function("256_waypoints", |b| {
        b.iter(|| black_box(&missions).assemble(Some(WAYPOINTS), None))
    });
    group.bench_function("256_waypoints_payload", |b| {
        b.iter(|| black_box(&mission).to_payload(black_box(2)))
    });

    let areas = area_buffer();
    let offset = SafetyOffset::from_metres(25.0).expect("offset");
    let list = areas.assemble(11, offset).expect("assembles");
    assert_eq!(list.to_payload(1).no_fly_polygon_count, 10);
    group.bench_function("11_areas_60_vertices", |b| {
        b.iter(|| black_box(&areas).assemble(11, offset))
    });
    group.bench_function("11_areas_60_vertices_payload", |b| {
        b.iter(|| black_box(&list).to_payload(black_box(2)))
    });
    group.finish();
}

criterion_group!(benches, frame_benches, assembly_benches);
criterion_main!(benches);
