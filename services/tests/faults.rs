//! Loss, duplication and reordering on one or both links, drawn from a seeded RNG over many
//! seeds: every run ends either with the exact new mission and areas active, or with a clean
//! abort; never a partial list.
//!
//! One ambiguity no protocol of acknowledgements removes: when the FCC activates a list and
//! both copies of its acceptance are lost twice, the FCC holds the new list while the GCS
//! reports the failure (the GCS can download to see which). So after an abort each list is
//! whole, the old one or the new one, and the GCS reports success only when the FCC holds the
//! new lists.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

mod support;

use std::time::Duration;

use missionlink_services::ground_station::GcsEvent;
use support::*;

fn random_faults(rng: &mut Rng, max_loss: f64) -> Faults {
    let lo = rng.range(1, 30);
    Faults {
        loss: rng.unit() * max_loss,
        duplicate: rng.unit() * 0.2,
        latency_ms: (lo, lo + rng.range(0, 60)),
    }
}

#[derive(Default)]
struct Tally {
    completed: usize,
    failed: usize,
    /// Aborted with the old mission and the old areas active.
    failed_old_old: usize,
    /// Aborted in the area phase: the new mission is active, the old areas.
    failed_new_old: usize,
    /// Aborted although the FCC activated both (the last answers were lost).
    failed_new_new: usize,
}

fn run(seed: u64, both_links: bool, max_loss: f64, tally: &mut Tally) {
    let mut pair = Pair::new(seed);
    // The old lists: demo mission 1, uploaded over clean links.
    let now = pair.now;
    pair.gcs.upload(now, &mission_1(), true).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    assert_eq!(
        pair.take_gcs_events().last(),
        Some(&GcsEvent::UploadComplete)
    );
    let old = pair.gcs.validate(&mission_1()).unwrap();
    let new = pair.gcs.validate(&mission_2()).unwrap();

    let mut rng = Rng::new(seed ^ 0xfa17);
    for i in 0..2 {
        if both_links || i == 0 {
            pair.uplink[i] = random_faults(&mut rng, max_loss);
            pair.downlink[i] = random_faults(&mut rng, max_loss);
        }
    }
    let now = pair.now;
    pair.gcs.upload(now, &mission_2(), true).unwrap();
    pair.run_until_standby(Duration::from_secs(300));
    assert!(pair.gcs.is_standby(), "seed {seed}: GCS never finished");
    // Give the FCC its transfer timeout to abandon whatever is half done.
    let settle = pair.now + TRANSFER_TIMEOUT + Duration::from_millis(100);
    pair.run_until(settle);

    let events = pair.take_gcs_events();
    let outcome = events
        .iter()
        .filter(|e| matches!(e, GcsEvent::UploadComplete | GcsEvent::Failed(_)))
        .collect::<Vec<_>>();
    assert_eq!(outcome.len(), 1, "seed {seed}: one outcome, got {events:?}");

    let mission = pair.fcc.active_mission().cloned();
    let areas = pair.fcc.active_areas().cloned();
    assert!(
        mission == Some(old.mission.clone()) || mission == Some(new.mission.clone()),
        "seed {seed}: partial or foreign mission {mission:?}"
    );
    assert!(
        areas == Some(old.areas.clone()) || areas == Some(new.areas.clone()),
        "seed {seed}: partial or foreign areas {areas:?}"
    );
    // What guidance receives is what is active.
    let published = pair.fcc.waypoint_list();
    let expected = mission.as_ref().unwrap().to_payload(published.generation);
    assert_eq!(published.waypoints(), expected.waypoints(), "seed {seed}");
    // Nothing is left half done on the FCC.
    assert_eq!(
        pair.fcc.poll_timeout(),
        None,
        "seed {seed}: FCC still in a transfer"
    );

    match outcome[0] {
        GcsEvent::UploadComplete => {
            assert_eq!(mission, Some(new.mission), "seed {seed}");
            assert_eq!(areas, Some(new.areas), "seed {seed}");
            tally.completed += 1;
        }
        _ => {
            tally.failed += 1;
            match (mission == Some(new.mission), areas == Some(new.areas)) {
                (false, false) => tally.failed_old_old += 1,
                (true, false) => tally.failed_new_old += 1,
                (true, true) => tally.failed_new_new += 1,
                // Areas go up only after the mission was accepted.
                (false, true) => panic!("seed {seed}: new areas with the old mission"),
            }
        }
    }
}

#[test]
fn faults_on_one_link_never_leave_a_partial_list() {
    let mut tally = Tally::default();
    for seed in 0..150 {
        run(seed, false, 0.9, &mut tally);
    }
    // One clean link is enough to complete every upload.
    assert_eq!(tally.failed, 0, "{} failed", tally.failed);
}

#[test]
fn faults_on_both_links_never_leave_a_partial_list() {
    let mut tally = Tally::default();
    for seed in 1000..1400 {
        run(seed, true, 0.7, &mut tally);
    }
    // Both outcomes occur, so both are checked.
    assert!(tally.completed > 50, "completed {}", tally.completed);
    assert!(tally.failed > 10, "failed {}", tally.failed);
    eprintln!(
        "400 runs: {} completed; {} aborted: {} with the old lists, {} in the area phase (new \
         mission, old areas), {} with both new lists active (last answers lost)",
        tally.completed,
        tally.failed,
        tally.failed_old_old,
        tally.failed_new_old,
        tally.failed_new_new
    );
}

#[test]
fn a_flood_of_bad_frames_on_both_links_is_counted_in_full_and_logged_once_a_second_per_cause() {
    use missionlink_interfaces::contracts::Link;
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_services::link::rejects::FrameCause;
    use missionlink_services::link::time::Instant;
    use missionlink_services::voting::Voter;

    const N: u64 = 10_000;
    let mut voter = Voter::new(FCC_ID, GCS_ID, TRANSFER_TIMEOUT);
    let mut forwarded = 0;
    // 10,000 steps 100 us apart, one simulated second: a short and an all-zero datagram each.
    for i in 0..N {
        let now = Instant::from_micros(100 * i);
        voter.vote_step(
            now,
            &[(Link::Direct, &[0xff; 7]), (Link::Lte, &[0x00; 40])],
            |_, _| forwarded += 1,
        );
    }
    assert_eq!(forwarded, 0);
    let stats = voter.stats();
    assert_eq!(stats.rejected_frames.total(), 2 * N);
    assert_eq!(stats.rejected_frames.get(FrameCause::TooShort), N);
    let counters: std::collections::HashMap<_, _> = stats.counters().collect();
    assert_eq!(counters["rejected_frames"], 2 * N);
    assert_eq!(counters["too_short"], N);
    // Zeros: Message Length 0.
    assert_eq!(counters["length_out_of_range"], N);
    // Two causes in one simulated second: two lines.
    assert_eq!(voter.reject_log_lines(), 2);
    // One more second later, one more line per cause.
    voter.vote_step(
        Instant::from_millis(2000),
        &[(Link::Direct, &[0xff; 7]), (Link::Lte, &[0x00; 40])],
        |_, _| forwarded += 1,
    );
    assert_eq!(voter.reject_log_lines(), 4);
}
