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

use std::hint::black_box;
use std::time::{Duration, Instant as WallClock};

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use missionlink_interfaces::capacity::{MAX_POLYGON_VERTICES, MAX_WAYPOINTS};
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{
    self, AckType, Altitude, AreaPolygonLoopSegment, AreaShape, AreaType, Envelope, GeoPoint,
    LegType, MAX_FRAME_LEN, Message, MissionPlanMode, SafetyOffset, SpecificData, Timestamp,
    UaRoute, VehicleSpecificWaypoint,
};
use missionlink_services::link::endpoint::{EndpointConfig, OUTBOX_CAPACITY};
use missionlink_services::link::sampling::{MessageSampler, Sample};
use missionlink_services::link::time::Instant;
use missionlink_services::mission_data_handling::{FccConfig, MissionDataHandling};
use missionlink_services::transfer::areas::AreaBuffer;
use missionlink_services::transfer::mission::MissionBuffer;
use missionlink_services::transfer::sender::mission_command;

mod common;

/// 2026-11-21T12:00:00Z, the UTC time of instant zero.
const UTC_AT_ZERO_MS: u64 = 848_577_600_000;
const TRANSFER_TIMEOUT: Duration = Duration::from_secs(3);
const WAYPOINTS: u16 = MAX_WAYPOINTS as u16;

fn ts(ms: u64) -> Timestamp {
    Timestamp::from_millis(ms).expect("fits a U5")
}

/// Waypoint `n` of a 256-waypoint ring: all 18 fields (as the wire bench), track-to-fix.
fn waypoint(n: u16, stamp_ms: u64) -> Message {
    let mut m = common::waypoint();
    if let Message::UaPositionWaypoint(w) = &mut m {
        w.waypoint_number = n;
        w.next_waypoint = n % WAYPOINTS + 1;
        w.leg_type = LegType::TrackToFix;
        w.latitude = wire::Angle::from_degrees(48.26 + f64::from(n) * 1e-4).expect("latitude");
    }
    m.set_time_stamp(ts(stamp_ms));
    m
}

/// `message` as the GCS sends it to the FCC, acknowledgement requested.
fn uplink_frame(message: &Message) -> ([u8; MAX_FRAME_LEN], usize) {
    let envelope = Envelope::new(defaults::GCS_ID, defaults::FCC_ID).with_ack(true);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(&envelope, message, &mut buf).expect("encodes");
    (buf, len)
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

    fn next_frame(&mut self) -> (Instant, [u8; MAX_FRAME_LEN], usize) {
        self.count += 1;
        let n = (self.count % u64::from(WAYPOINTS)) as u16 + 1;
        let (buf, len) = uplink_frame(&waypoint(n, UTC_AT_ZERO_MS + self.count));
        (Instant::from_millis(self.count), buf, len)
    }
}

/// Mission data handling with an upload in progress: it has received (and answered) a clear.
fn fcc_uploading() -> MissionDataHandling {
    let mut fcc = MissionDataHandling::new(FccConfig {
        endpoint: EndpointConfig {
            local_id: defaults::FCC_ID,
            peer_id: defaults::GCS_ID,
            utc_at_zero: ts(UTC_AT_ZERO_MS),
            sampling_window: TRANSFER_TIMEOUT,
        },
        ack_timeout: Duration::from_millis(500),
        transfer_timeout: TRANSFER_TIMEOUT,
    });
    let mut clear = mission_command(MissionPlanMode::ClearMission, None, None);
    clear.set_time_stamp(ts(UTC_AT_ZERO_MS));
    let (buf, len) = uplink_frame(&clear);
    fcc.handle_frame(Instant::ZERO, &buf[..len])
        .expect("clear accepted");
    expect_completed(&mut fcc, 13000);
    fcc
}

/// Takes the one queued answer and checks it accepts a message of `original_type`.
fn expect_completed(fcc: &mut MissionDataHandling, original_type: u16) {
    match fcc.poll_outgoing() {
        Some((_, Message::MessageAcknowledgement(a))) => {
            assert_eq!(a.ack_type, AckType::Completed, "{a:?}");
            assert_eq!(a.original_message_type, original_type);
        }
        other => panic!("expected a #17000, got {other:?}"),
    }
    assert!(fcc.poll_outgoing().is_none());
}

fn frame_benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("13002");
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));

    let (frame, len) = uplink_frame(&waypoint(1, UTC_AT_ZERO_MS + 1));
    group.bench_function("decode", |b| {
        b.iter(|| wire::decode(black_box(&frame[..len])))
    });

    group.bench_function("sampling", |b| {
        let mut sampler = MessageSampler::new(TRANSFER_TIMEOUT);
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

    // The outgoing queue holds OUTBOX_CAPACITY messages: handle that many frames, timed, then
    // drain their acknowledgements, untimed (and the other way round for the encode).
    group.bench_function("handle", |b| {
        let mut fcc = fcc_uploading();
        let mut upload = Upload::new();
        let mut out = [0u8; MAX_FRAME_LEN];
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let chunk = left.min(OUTBOX_CAPACITY as u64) as usize;
                let frames: Vec<_> = (0..chunk).map(|_| upload.next_frame()).collect();
                let start = WallClock::now();
                for (now, buf, len) in &frames {
                    let _ = black_box(fcc.handle_frame(*now, black_box(&buf[..*len])));
                }
                total += start.elapsed();
                while fcc.poll_transmit(&mut out).is_some() {}
                left -= chunk as u64;
            }
            total
        })
    });

    group.bench_function("ack_encode", |b| {
        let mut fcc = fcc_uploading();
        let mut upload = Upload::new();
        let mut out = [0u8; MAX_FRAME_LEN];
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let chunk = left.min(OUTBOX_CAPACITY as u64) as usize;
                for _ in 0..chunk {
                    let (now, buf, len) = upload.next_frame();
                    fcc.handle_frame(now, &buf[..len]).expect("frame accepted");
                }
                let start = WallClock::now();
                for _ in 0..chunk {
                    let _ = black_box(fcc.poll_transmit(black_box(&mut out)));
                }
                total += start.elapsed();
                left -= chunk as u64;
            }
            total
        })
    });

    group.bench_function("frame_total", |b| {
        let mut fcc = fcc_uploading();
        let mut upload = Upload::new();
        let mut out = [0u8; MAX_FRAME_LEN];
        b.iter_batched(
            || upload.next_frame(),
            |(now, buf, len)| {
                let _ = fcc.handle_frame(now, black_box(&buf[..len]));
                black_box(fcc.poll_transmit(&mut out))
            },
            BatchSize::SmallInput,
        )
    });
    group.finish();

    // Every frame above was accepted: the same path, checked once outside the measurement.
    let mut fcc = fcc_uploading();
    let mut upload = Upload::new();
    for _ in 0..3 * WAYPOINTS {
        let (now, buf, len) = upload.next_frame();
        fcc.handle_frame(now, &buf[..len]).expect("frame accepted");
        expect_completed(&mut fcc, 13002);
    }
}

/// A small deterministic RNG (xorshift64*) for the shuffle.
fn shuffle<T>(items: &mut [T], mut seed: u64) {
    for i in (1..items.len()).rev() {
        seed ^= seed >> 12;
        seed ^= seed << 25;
        seed ^= seed >> 27;
        let j = (seed.wrapping_mul(0x2545_F491_4F6C_DD1D) % (i as u64 + 1)) as usize;
        items.swap(i, j);
    }
}

/// 256 waypoints chained 1 -> 2 -> ... -> 256, stored in shuffled order, with take-off height
/// and route.
fn mission_buffer() -> MissionBuffer {
    let mut messages: Vec<Message> = (1..=WAYPOINTS)
        .map(|n| {
            let mut m = waypoint(n, UTC_AT_ZERO_MS + u64::from(n));
            if let Message::UaPositionWaypoint(w) = &mut m {
                w.next_waypoint = if n == WAYPOINTS { 0 } else { n + 1 };
            }
            m
        })
        .collect();
    messages.push(
        VehicleSpecificWaypoint {
            time_stamp: Timestamp::default(),
            data: SpecificData::TakeOffHeight {
                height: Altitude::from_metres(30.0).expect("height"),
            },
            activity_id: None,
        }
        .into(),
    );
    messages.push(
        UaRoute {
            time_stamp: Timestamp::default(),
            initial_waypoint: 1,
            route_id: None,
            route_type: Some(wire::RouteType::Flight),
            bidirectional: false,
        }
        .into(),
    );
    shuffle(&mut messages, 0x9E37_79B9_7F4A_7C15);
    let mut buffer = MissionBuffer::new();
    for m in &messages {
        buffer.store(m).expect("stored");
    }
    buffer
}

/// A no-fly-zone: a circle of `radius_deg` (latitude degrees) around `centre` as a 60-vertex
/// polygon.
fn no_fly_zone(id: u16, centre: (f64, f64), radius_deg: f64) -> AreaPolygonLoopSegment {
    let mut vertices = wire::PolygonVertices::new();
    let lon_scale = 1.0 / centre.0.to_radians().cos();
    for i in 0..MAX_POLYGON_VERTICES {
        let a = i as f64 / MAX_POLYGON_VERTICES as f64 * std::f64::consts::TAU;
        let p = GeoPoint::from_degrees(
            centre.0 + radius_deg * a.sin(),
            centre.1 + radius_deg * lon_scale * a.cos(),
        )
        .expect("vertex");
        vertices.push(p).expect("capacity");
    }
    AreaPolygonLoopSegment {
        time_stamp: Timestamp::default(),
        area_id: id,
        area_type: AreaType::NoFlyZone,
        lower_altitude: None,
        upper_altitude: None,
        altitude_type: None,
        shape: AreaShape::Polygon(vertices),
    }
}

/// The fly-zone (60 vertices) and 10 no-fly-zones of 60 vertices inside it.
fn area_buffer() -> AreaBuffer {
    let Message::AreaPolygonLoopSegment(fly_zone) = common::polygon() else {
        unreachable!("common::polygon is a #2012")
    };
    let mut buffer = AreaBuffer::new();
    buffer.store(&fly_zone).expect("stored");
    for k in 0..10u16 {
        let lat = 48.266 + 0.008 * f64::from(k / 5);
        let lon = 11.648 + 0.0075 * f64::from(k % 5);
        buffer
            .store(&no_fly_zone(k + 2, (lat, lon), 0.0012))
            .expect("stored");
    }
    buffer
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
