//! Runs one of the measured paths of `benches/per_frame.rs` N times, for counting its
//! instructions under callgrind: on this guest a timing of the same binary varies by a third
//! from one run to the next, an instruction count does not.
//!
//! - `areas N`: the assembly and validation of the fly-zone and ten no-fly-zones of 60 vertices
//!   (`testkit::eleven_areas`, the bench's "assembly/11_areas_60_vertices"), N times.
//! - `frames N`: N #13002 frames of a 256-waypoint upload handed to mission data handling, each
//!   answer taken (`handle_frame` and `poll_transmit`, the bench's "13002/frame_total"); the
//!   frames are encoded before, outside the functions to read in the profile.
//! - `geofence N` / `geofence-wind N`: the onboard geofence check of the worst case
//!   (`testkit::geofence_worst_case`, the fence built once), N times; `geofence-wind` with the
//!   list planned in a wind of 2 m/s (the geofence bench's `track_to_fix_in_wind`: ICD §7 "Turns
//!   in wind").
//!
//! ```sh
//! cargo build --release --example count_instructions
//! valgrind --tool=callgrind target/release/examples/count_instructions areas 50
//! valgrind --tool=callgrind target/release/examples/count_instructions frames 10000
//! valgrind --tool=callgrind target/release/examples/count_instructions geofence 20
//! callgrind_annotate --inclusive=yes callgrind.out.<pid> | grep -E "handle_frame|poll_transmit"
//! ```
//!
//! Not a product binary: a measuring aid.
// An aid stops at its first failure.
#![allow(clippy::expect_used, clippy::panic)]

use std::hint::black_box;

use missionlink_flight::automation::fcc_turns;
use missionlink_flight::mission_data_handling::MissionDataHandling;
use missionlink_flight::onboard;
use missionlink_flight::testkit::{self, UTC_AT_ZERO_MS, ts, uplink};
use missionlink_interfaces::capacity::MAX_WAYPOINTS;
use missionlink_interfaces::wire::{
    self, LegType, MAX_FRAME_LEN, Message, MissionPlanMode, SafetyOffset, Speed, UaPositionWaypoint,
};
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::flown_route;
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::sender::mission_command;

fn main() {
    let mut args = std::env::args().skip(1);
    let what = args.next().unwrap_or_default();
    let times: u64 = args.next().and_then(|n| n.parse().ok()).unwrap_or(200);
    match what.as_str() {
        "areas" => areas(times),
        "frames" => frames(times),
        "geofence" => geofence(times, 0.0),
        "geofence-wind" => geofence(times, 2.0),
        other => panic!("{other:?}: areas N, frames N, geofence N or geofence-wind N"),
    }
}

fn geofence(times: u64, wind_mps: f64) {
    let (mut waypoints, areas, take_off) = testkit::geofence_worst_case();
    waypoints.planning_wind = Speed::from_mps(wind_mps).expect("a wind speed");
    let fence = Fence::of_payload(&areas);
    let site = Site::of(take_off);
    for _ in 0..times {
        let route = flown_route::execute_route(
            flown_route::RouteView::from(black_box(&waypoints)),
            site,
            Some(fcc_turns()),
        );
        assert!(onboard::check(black_box(&fence), route).is_ok());
    }
}

fn areas(times: u64) {
    let areas = testkit::area_buffer(&testkit::eleven_areas());
    let offset = SafetyOffset::from_metres(25.0).expect("25 m is a safety offset");
    for _ in 0..times {
        let _ = black_box(black_box(&areas).assemble(11, offset));
    }
}

fn frames(times: u64) {
    let waypoints = MAX_WAYPOINTS as u16;
    let frames: Vec<(Instant, Vec<u8>)> = (1..=times)
        .map(|count| {
            let n = (count % u64::from(waypoints)) as u16 + 1;
            let latitude =
                wire::Angle::from_degrees(48.26 + f64::from(n) * 1e-4).expect("latitude");
            let message: Message = UaPositionWaypoint {
                time_stamp: ts(UTC_AT_ZERO_MS + count),
                waypoint_number: n,
                next_waypoint: n % waypoints + 1,
                leg_type: LegType::TrackToFix,
                latitude,
                ..testkit::full_waypoint()
            }
            .into();
            (Instant::from_millis(count), uplink(&message))
        })
        .collect();
    let mut fcc = MissionDataHandling::new(testkit::fcc_config());
    let mut clear = mission_command(MissionPlanMode::ClearMission, None, None);
    clear.set_time_stamp(ts(UTC_AT_ZERO_MS));
    fcc.handle_frame(Instant::ZERO, &uplink(&clear))
        .expect("clear accepted");
    let mut out = [0u8; MAX_FRAME_LEN];
    while fcc.poll_transmit(&mut out).is_some() {}
    for (now, frame) in &frames {
        fcc.handle_frame(*now, black_box(frame))
            .expect("frame accepted");
        while black_box(fcc.poll_transmit(&mut out)).is_some() {}
    }
}
