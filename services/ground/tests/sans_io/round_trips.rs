//! What a whole upload costs in round trips, counted over the simulated links with a fixed delay
//! by the link emulator's own rule (`linksim/src/round_trips.rs`): the figures ICD §10 is about.
//! Each upload is measured after another one, as the links bench measures it (the FCC's lists
//! both change), toward an edition-2 FCC with the default window of 128 and the shared
//! contract's 32 (ICD §10.2; ICD §10.3 applies to both) and with a window of 1 (stop-and-wait,
//! as before it).

use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::{
    GcsConfig, GcsEvent, GroundStation, MissionPlan, Sequence, WithoutGateway,
};

/// One way on each link: a round trip is 200 ms of simulated time.
const ONE_WAY: u64 = 100;

/// A pair 100 ms apart on both links, nothing lost, its GCS with a window of `window`.
fn pair(window: u8) -> Pair {
    let mut pair = Pair::new(7);
    let config = GcsConfig {
        transfer_window: window,
        ..gcs_config()
    };
    pair.gcs = GroundStation::new(config, WithoutGateway);
    // Navigation reports the aircraft on the ground at TROL: the onboard geofence check of an
    // activation (ICD §8) starts from there.
    pair.fcc.set_automation_state(&on_ground());
    pair.fcc.handle_progress(pair.now, &on_ground_at(TROL));
    for f in pair.uplink.iter_mut().chain(pair.downlink.iter_mut()) {
        *f = faulty(0.0, 0.0, (ONE_WAY, ONE_WAY));
    }
    pair
}

/// Uploads `plan` by `sequence`; the round trips it took and whether it completed.
fn upload(pair: &mut Pair, plan: &MissionPlan, sequence: Sequence) -> (u64, bool) {
    let before = pair.round_trips.completed();
    let now = pair.now;
    pair.gcs.upload_with(now, plan, sequence).unwrap();
    pair.run_until_standby(Duration::from_secs(600));
    let events = pair.take_gcs_events();
    let done = matches!(events.last(), Some(GcsEvent::Uploaded(r)) if r.is_complete());
    if !done {
        println!("{:?}", events.last());
    }
    (pair.round_trips.completed() - before, done)
}

/// The round trips of uploading `plan` after another mission, by `sequence`.
fn measured(plan: &MissionPlan, sequence: Sequence, window: u8) -> u64 {
    let mut p = pair(window);
    let (_, done) = upload(&mut p, &mission_2(), sequence);
    assert!(done, "the upload before");
    // The aircraft stands where the plan takes off: the onboard check of the activation.
    let at = plan.take_off_position.unwrap();
    p.fcc.handle_progress(
        p.now,
        &on_ground_at((at.latitude.degrees(), at.longitude.degrees())),
    );
    let (rounds, done) = upload(&mut p, plan, sequence);
    assert!(done, "the upload measured");
    let valid = p.gcs.validate(plan).unwrap();
    assert_eq!(p.fcc.active_mission(), Some(&valid.mission));
    assert_eq!(p.fcc.active_areas(), Some(&valid.areas));
    rounds
}

/// The round trips of each upload, counted: (case, sequence, window, round trips).
///
/// - Window 1 is stop-and-wait, as before ICD §10.3: one round trip per message, the report's
///   included (mission 1: 9 by the paper's sequence, 11 atomic).
/// - Window 32 before ICD §10.3 took the report, each opener and closer one round trip each,
///   and the data messages a round trip per window of 32: mission 1 7 by the paper's sequence
///   (report, clear, data, transmit, area opener, area, area closer) and 9 atomic (report,
///   mode 10, data, mode 8, area opener, area, area closer, activation, delete); 256 waypoints
///   with 11 areas 15 and 17 (the 258 mission data messages in 9 windows).
/// - With ICD §10.3 (windows of 32 and 128): the report held from the upload before is fresh,
///   so none is asked; the opener goes with the first window, the area upload beside the
///   mission data once all of them were sent, each closer right behind its data once its
///   opener was accepted, the area closer once the mission closer was accepted, the activation
///   behind the area closer. Mission 1 by the paper's sequence: the clear, the data and the
///   areas; the transmit; the area closer: 3. Atomic: mode 10, the data and the areas; mode 8;
///   mode 7 with the activation; the delete: 4. 256 waypoints: the windows of data (9 of 32,
///   3 of 128; the transmit behind the last, the areas beside it), then the area closer: 10
///   and 4 by the paper's sequence, one more (the delete) atomically.
const EXPECTED: [(&str, &str, u8, u64); 12] = [
    ("mission 1", "paper", 1, 9),
    ("mission 1", "paper", 32, 3),
    ("mission 1", "paper", 128, 3),
    ("mission 1", "atomic", 1, 11),
    ("mission 1", "atomic", 32, 4),
    ("mission 1", "atomic", 128, 4),
    ("256 waypoints, 11 areas", "paper", 1, 274),
    ("256 waypoints, 11 areas", "paper", 32, 10),
    ("256 waypoints, 11 areas", "paper", 128, 4),
    ("256 waypoints, 11 areas", "atomic", 1, 276),
    ("256 waypoints, 11 areas", "atomic", 32, 11),
    ("256 waypoints, 11 areas", "atomic", 128, 5),
];

#[test]
fn round_trips_of_a_whole_upload() {
    let mut counted = Vec::new();
    for (name, how, window, _) in EXPECTED {
        let plan = match name {
            "mission 1" => mission_1(),
            // 256 waypoints and 11 areas that pass the onboard check of the activation.
            _ => geofence_worst_case_plan(),
        };
        let sequence = match how {
            "paper" => Sequence::Paper { clear: true },
            _ => Sequence::Atomic,
        };
        let rounds = measured(&plan, sequence, window);
        println!("{name}, {how}, window {window}: {rounds} round trips");
        counted.push((name, how, window, rounds));
    }
    assert_eq!(counted, EXPECTED);
}
