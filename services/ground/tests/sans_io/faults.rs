//! Loss, duplication and reordering on one or both links, drawn from a seeded RNG over many
//! seeds: every run ends either with the exact new mission and areas active, or with a clean
//! abort; never a partial list. And the GCS says which (ICD §11, "The truth after a failure"):
//! after a failed transfer it asks the FCC what is active, so it reports success exactly when
//! both new lists are active, names each list new or previous, and says "unknown" only when the
//! FCC did not answer that question either.

use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::outcome::{Held, UploadOutcome, UploadReport};
use missionlink_ground::ground_station::{GcsError, GcsEvent};

fn random_faults(rng: &mut Rng, max_loss: f64) -> Impairments {
    let lo = rng.range(1, 30);
    faulty(
        rng.unit() * max_loss,
        rng.unit() * 0.2,
        (lo, lo + rng.range(0, 60)),
    )
}

#[derive(Default, Debug)]
struct Tally {
    completed: usize,
    /// Complete although an answer was lost: the GCS found out.
    confirmed_after_lost_answer: usize,
    /// Failed with the previous lists active.
    previous: usize,
    /// Failed in the area phase: the new mission is active, the previous areas.
    mixed: usize,
    /// Failed, and the FCC did not answer the question either.
    unknown: usize,
    /// Failed after the paper's sequence's clear deleted the mission (ICD §5.1).
    cleared: usize,
    /// The report before the upload failed: nothing that changes a list was sent.
    not_started: usize,
}

fn run(seed: u64, both_links: bool, max_loss: f64, tally: &mut Tally) {
    let mut pair = Pair::new(seed);
    // The old lists: demo mission 1, uploaded over clean links.
    let now = pair.now;
    pair.gcs.upload(now, &mission_1(), true).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    assert!(
        matches!(pair.take_gcs_events().last(), Some(GcsEvent::Uploaded(r)) if r.is_complete())
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
    let outcomes: Vec<Option<&UploadReport>> = events
        .iter()
        .filter_map(|e| match e {
            GcsEvent::Uploaded(r) => Some(Some(&**r)),
            GcsEvent::Failed(GcsError::Upload(r)) => Some(Some(&**r)),
            // The report before the upload (ICD §8, §10.1) failed or broke off: the upload
            // never began.
            GcsEvent::Failed(e) if e.in_report() => Some(None),
            GcsEvent::Failed(other) => panic!("seed {seed}: not an upload outcome: {other}"),
            _ => None,
        })
        .collect();
    assert_eq!(
        outcomes.len(),
        1,
        "seed {seed}: one outcome, got {events:?}"
    );
    let report = outcomes[0];

    let mission = pair.fcc.active_mission().cloned();
    let areas = pair.fcc.active_areas().cloned();
    // The clear of the paper's sequence deletes the active mission (ICD §5.1 step 1): none is
    // the third whole state a failure may leave.
    assert!(
        mission.is_none()
            || mission == Some(old.mission.clone())
            || mission == Some(new.mission.clone()),
        "seed {seed}: partial or foreign mission {mission:?}"
    );
    assert!(
        areas == Some(old.areas.clone()) || areas == Some(new.areas.clone()),
        "seed {seed}: partial or foreign areas {areas:?}"
    );
    // What guidance receives is what is active.
    let published = pair.fcc.waypoint_list();
    let expected: Vec<_> = mission
        .as_ref()
        .map(|m| m.to_payload(published.generation).waypoints().to_vec())
        .unwrap_or_default();
    assert_eq!(published.waypoints(), expected, "seed {seed}");
    // Nothing is left half done on the FCC.
    assert_eq!(
        pair.fcc.poll_timeout(),
        None,
        "seed {seed}: FCC still in a transfer"
    );

    let Some(report) = report else {
        assert_eq!(mission, Some(old.mission), "seed {seed}: nothing was sent");
        assert_eq!(areas, Some(old.areas), "seed {seed}: nothing was sent");
        tally.not_started += 1;
        return;
    };
    // The GCS's report is the truth, list by list.
    let new_mission = mission == Some(new.mission.clone());
    let new_areas = areas == Some(new.areas.clone());
    for (name, held, is_new) in [
        ("mission", report.mission.held, new_mission),
        ("areas", report.areas.held, new_areas),
    ] {
        match held {
            Held::New => assert!(is_new, "seed {seed}: {name} reported new: {report}"),
            Held::Previous => assert!(!is_new, "seed {seed}: {name} reported previous: {report}"),
            Held::Cleared => assert!(
                name == "mission" && mission.is_none(),
                "seed {seed}: {name} reported cleared: {report}"
            ),
            Held::Unknown => {}
            Held::NotNew | Held::Foreign => panic!("seed {seed}: {name}: {report}"),
        }
    }
    match report.outcome() {
        UploadOutcome::Complete => tally.completed += 1,
        // A refused step with the new lists active before it: only where an earlier attempt
        // made them so.
        UploadOutcome::AlreadyActive => tally.completed += 1,
        UploadOutcome::CompleteAfterLostAnswer => tally.confirmed_after_lost_answer += 1,
        UploadOutcome::PreviousActive => tally.previous += 1,
        UploadOutcome::Mixed => {
            // Areas go up only after the mission was accepted.
            assert!(new_mission && !new_areas, "seed {seed}: {report}");
            tally.mixed += 1;
        }
        UploadOutcome::Unknown => tally.unknown += 1,
        UploadOutcome::NoMission => {
            assert!(mission.is_none() && !new_areas, "seed {seed}: {report}");
            tally.cleared += 1;
        }
        UploadOutcome::Foreign => panic!("seed {seed}: {report}"),
    }
    // Success is reported exactly when both new lists are active, unless the FCC could not be
    // asked.
    if report.outcome() != UploadOutcome::Unknown {
        assert_eq!(
            report.is_complete(),
            new_mission && new_areas,
            "seed {seed}: {report}"
        );
    }
}

#[test]
fn faults_on_one_link_never_leave_a_partial_list() {
    let mut tally = Tally::default();
    for seed in 0..150 {
        run(seed, false, 0.9, &mut tally);
    }
    // One clean link is enough to complete every upload.
    assert_eq!(
        tally.completed + tally.confirmed_after_lost_answer,
        150,
        "{tally:?}"
    );
}

#[test]
fn faults_on_both_links_never_leave_a_partial_list() {
    let mut tally = Tally::default();
    for seed in 1000..1400 {
        run(seed, true, 0.7, &mut tally);
    }
    // The outcomes occur, so each is checked.
    assert!(tally.completed > 50, "{tally:?}");
    assert!(
        tally.previous + tally.mixed + tally.cleared > 10,
        "{tally:?}"
    );
    eprintln!("400 runs: {tally:?}");
}

#[test]
fn a_flood_of_bad_frames_on_both_links_is_counted_in_full_and_logged_once_a_second_per_cause() {
    use missionlink_interfaces::contracts::Link;
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_protocol::link::rejects::FrameCause;
    use missionlink_protocol::link::time::Instant;
    use missionlink_protocol::voting::Voter;

    const N: u64 = 10_000;
    let mut voter = Voter::new(FCC_ID, GCS_ID, TRANSFER_TIMEOUT);
    let mut forwarded = 0;
    // 10,000 steps 100 us apart, one simulated second: a short and an all-zero datagram each.
    for i in 0..N {
        let now = Instant::from_micros(100 * i);
        voter.vote_step(
            now,
            &[(Link::Direct, &[0xff; 7]), (Link::Lte, &[0x00; 40])],
            |_, _, _| forwarded += 1,
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
        |_, _, _| forwarded += 1,
    );
    assert_eq!(voter.reject_log_lines(), 4);
}

/// Uploads mission 2 over mission 1 and loses the FCC's answers to the closer `closer` (as
/// `describe` names it) `times` times; the GCS's outcome.
fn lose_closer_answers(closer: &str, times: usize) -> (Pair, UploadReport) {
    let mut pair = Pair::new(7);
    let now = pair.now;
    pair.gcs.upload(now, &mission_1(), true).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    pair.take_gcs_events();
    let now = pair.now;
    pair.gcs.upload(now, &mission_2(), true).unwrap();
    let mut lost = 0;
    let mut checked = pair.sent.len();
    while lost < times {
        assert!(pair.step(), "{closer} never sent");
        for s in &pair.sent[checked..] {
            match s.direction {
                Direction::Up if describe(&s.message) == closer => {
                    pair.downlink = [DOWN; 2];
                }
                Direction::Down if pair.downlink == [DOWN; 2] => {
                    lost += 1;
                    pair.downlink = [CLEAN; 2];
                }
                _ => {}
            }
        }
        checked = pair.sent.len();
    }
    pair.run_until_standby(Duration::from_secs(30));
    let report = match pair.take_gcs_events().pop() {
        Some(GcsEvent::Uploaded(r)) => *r,
        Some(GcsEvent::Failed(GcsError::Upload(r))) => *r,
        other => panic!("{closer}: {other:?}"),
    };
    (pair, report)
}

/// ICD §11: a closer whose answer is lost is retried and answered as the first was; when both
/// answers are lost, the GCS asks and finds the new lists active. Either way it reports
/// success, and the FCC holds the new lists.
#[test]
fn a_lost_closer_answer_still_ends_in_success() {
    let new = mission_2().assemble().unwrap();
    for closer in ["13000 mode 2", "2011 mode 2"] {
        for (times, expected) in [
            (1, UploadOutcome::Complete),
            (2, UploadOutcome::CompleteAfterLostAnswer),
        ] {
            let (pair, report) = lose_closer_answers(closer, times);
            assert_eq!(report.outcome(), expected, "{closer} x{times}: {report}");
            assert_eq!(pair.fcc.active_mission(), Some(&new.mission));
            assert_eq!(pair.fcc.active_areas(), Some(&new.areas));
        }
    }
}
