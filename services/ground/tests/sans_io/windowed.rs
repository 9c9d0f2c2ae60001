//! Windowed transfer (ICD §10.2) between the GCS and the FCC stepped through simulated time:
//! windows 1, 2, 16 and 32, without faults and under loss, duplication and reordering on both
//! links.
//!
//! | rule (ICD §10.2) | tests |
//! |---|---|
//! | at most W data messages unanswered; W reached | `the_window_bounds_what_is_in_flight_and_is_used` |
//! | the closer after every data message was accepted (the opener, ICD §10.3, with the data behind it) | `the_window_bounds_what_is_in_flight_and_is_used` |
//! | W = 1 is edition 1 | `window_1_sends_what_stop_and_wait_sends` |
//! | uploads and downloads under loss, duplication, reordering: each list the exact one or the previous one, whole (the mission none after the paper's clear), as the GCS says | `windows_under_faults_end_with_the_exact_lists_or_the_previous_ones` |
//! | fewer round trips | `a_window_takes_fewer_round_trips` |

use std::collections::HashMap;
use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::{
    GcsError, GcsEvent, GroundStation, MissionPlan, WithoutGateway,
};
use missionlink_interfaces::wire::Message;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};

const WINDOWS: [u8; 4] = [1, 2, 16, 32];

/// A pair whose GCS keeps `window` data messages in flight toward the (edition-2) FCC.
fn pair(seed: u64, window: u8) -> Pair {
    let mut pair = Pair::new(seed);
    let config = missionlink_ground::ground_station::GcsConfig {
        transfer_window: window,
        ..gcs_config()
    };
    pair.gcs = GroundStation::new(config, WithoutGateway);
    pair
}

fn upload(pair: &mut Pair, plan: &MissionPlan) -> bool {
    let now = pair.now;
    pair.gcs.upload(now, plan, true).unwrap();
    pair.run_until_standby(Duration::from_secs(120));
    matches!(pair.take_gcs_events().last(), Some(GcsEvent::Uploaded(r)) if r.is_complete())
}

fn download(pair: &mut Pair) -> Option<missionlink_ground::ground_station::ValidatedPlan> {
    let now = pair.now;
    pair.gcs.download(now).unwrap();
    pair.run_until_standby(Duration::from_secs(120));
    match pair.take_gcs_events().last() {
        Some(GcsEvent::DownloadComplete(plan)) => Some((**plan).clone()),
        _ => None,
    }
}

fn is_data(m: &Message) -> bool {
    matches!(
        m,
        Message::UaPositionWaypoint(_)
            | Message::VehicleSpecificWaypoint(_)
            | Message::UaRoute(_)
            | Message::AreaPolygonLoopSegment(_)
    )
}

/// Which list a message of a transfer carries: 0 missions, 1 areas.
fn kind(m: &Message) -> u8 {
    match m {
        Message::AreaTransmissionCommand(_) | Message::AreaPolygonLoopSegment(_) => 1,
        _ => 0,
    }
}

/// Whether `m` closes a transfer (ICD §10.2).
fn is_closer(m: &Message) -> bool {
    use missionlink_interfaces::wire::{AreaTransferMode, MissionPlanMode};
    match m {
        Message::MissionTransferCommand(c) => matches!(
            c.mode,
            MissionPlanMode::TransmitMission | MissionPlanMode::StageMission
        ),
        Message::AreaTransmissionCommand(c) => matches!(
            c.mode,
            AreaTransferMode::UploadComplete
                | AreaTransferMode::UploadCompleteStaged
                | AreaTransferMode::DownloadComplete
        ),
        Message::MissionUploadDownloadStatus(_) => true,
        _ => false,
    }
}

/// The most data messages of one direction that were sent and not yet answered at once, and
/// whether every closer went out with no message of its transfer unanswered (ICD §10.2: the
/// receiver assembles what a stop-and-wait transfer would have given it). Before ICD §10.3 the
/// openers went alone too; now the data go right behind the opener, and the next transfer's
/// opener behind a closer, so only the closers are checked.
fn in_flight(sent: &[Sent], direction: Direction) -> (usize, bool) {
    let mut open: HashMap<(u16, u64), (bool, u8)> = HashMap::new();
    let (mut most, mut alone) = (0, true);
    for s in sent {
        let key = |m: &Message| (m.message_type() as u16, m.time_stamp().millis());
        if s.direction == direction && s.ack_requested {
            let data = is_data(&s.message);
            if is_closer(&s.message) && open.values().any(|(_, k)| *k == kind(&s.message)) {
                alone = false;
            }
            open.insert(key(&s.message), (data, kind(&s.message)));
        } else if s.direction != direction {
            match &s.message {
                Message::MessageAcknowledgement(a) => {
                    open.remove(&(a.original_message_type, a.original_time_stamp.millis()));
                }
                // The answers of the area closer and the area download request (ICD §5.3,
                // §5.4) close what is in flight of their kind.
                Message::AreaStatusAlert(_) | Message::AreaTransmissionStatus(_) => {
                    open.retain(|(t, _), _| *t != 2011);
                }
                _ => {}
            }
        }
        most = most.max(open.values().filter(|(d, _)| *d).count());
    }
    (most, alone)
}

#[test]
fn the_window_bounds_what_is_in_flight_and_is_used() {
    let plan = generated_plan(100);
    for window in WINDOWS {
        let mut p = pair(1, window);
        assert!(upload(&mut p, &plan), "window {window}");
        let valid = p.gcs.validate(&plan).unwrap();
        assert_eq!(p.fcc.active_mission(), Some(&valid.mission));
        assert_eq!(p.fcc.active_areas(), Some(&valid.areas));
        let (most, alone) = in_flight(&p.sent, Direction::Up);
        assert_eq!(
            most,
            usize::from(window),
            "window {window}: data messages in flight"
        );
        // ICD §10.2: with a window of 1 each closer waits for its data; above 1 this GCS sends
        // it right behind them (ICD §10.3).
        assert_eq!(
            alone,
            window == 1,
            "window {window}: whether each closer waited for every message of its transfer"
        );
        // The download the GCS asks for goes out with its window too (ICD §10.2).
        let from = p.sent.len();
        assert_eq!(download(&mut p), Some(valid), "window {window}");
        let (most, alone) = in_flight(&p.sent[from..], Direction::Down);
        assert_eq!(
            most,
            usize::from(window),
            "window {window}: the FCC's download"
        );
        assert!(
            alone,
            "window {window}: the FCC's closer before every message was answered"
        );
    }
}

#[test]
fn window_1_sends_what_stop_and_wait_sends() {
    let plan = mission_2();
    let mut stop_and_wait = Pair::new(3);
    assert!(upload(&mut stop_and_wait, &plan));
    let mut one = pair(3, 1);
    assert!(upload(&mut one, &plan));
    let describe_all = |p: &Pair| {
        p.sent
            .iter()
            .map(|s| (s.at, s.direction, describe(&s.message)))
            .collect::<Vec<_>>()
    };
    assert_eq!(describe_all(&one), describe_all(&stop_and_wait));
}

#[test]
fn a_window_takes_fewer_round_trips() {
    // Each link 20 ms one way: a round trip is 40 ms of simulated time.
    let plan = generated_plan(100);
    let mut took = Vec::new();
    for window in WINDOWS {
        let mut p = pair(4, window);
        for f in p.uplink.iter_mut().chain(p.downlink.iter_mut()) {
            *f = faulty(0.0, 0.0, (20, 20));
        }
        let start = p.now;
        assert!(upload(&mut p, &plan), "window {window}");
        took.push((window, p.now - start));
    }
    for pair in took.windows(2) {
        assert!(pair[1].1 < pair[0].1, "{took:?}");
    }
    // 100 waypoints, take-off, route and 11 areas are 113 data messages: at window 32 four
    // round trips carry them instead of 113.
    let (_, one) = took[0];
    let (_, thirty_two) = took[3];
    assert!(thirty_two * 5 < one, "{took:?}");
}

#[test]
fn windows_under_faults_end_with_the_exact_lists_or_the_previous_ones() {
    let old_plan = mission_1();
    let new_plan = generated_plan(40);
    let mut completed = HashMap::new();
    let mut runs = 0;
    for window in WINDOWS {
        for seed in 0..25u64 {
            runs += 1;
            let mut p = pair(seed, window);
            assert!(
                upload(&mut p, &old_plan),
                "window {window} seed {seed}: the old lists"
            );
            let old = p.gcs.validate(&old_plan).unwrap();
            let new = p.gcs.validate(&new_plan).unwrap();
            let mut rng = Rng::new(seed ^ 0x3a11);
            for f in p.uplink.iter_mut().chain(p.downlink.iter_mut()) {
                let lo = rng.range(1, 20);
                *f = faulty(0.1, 0.1, (lo, lo + rng.range(10, 60)));
            }
            let now = p.now;
            p.gcs.upload(now, &new_plan, true).unwrap();
            p.run_until_standby(Duration::from_secs(120));
            let report = match p.take_gcs_events().pop() {
                Some(GcsEvent::Uploaded(r)) => *r,
                Some(GcsEvent::Failed(GcsError::Upload(r))) => *r,
                other => panic!("window {window} seed {seed}: {other:?}"),
            };
            let ok = report.is_complete();
            // Let every late copy arrive and every receiver time out.
            p.run_until(p.now + Duration::from_secs(10));
            let lists = (
                p.fcc.active_mission().cloned(),
                p.fcc.active_areas().cloned(),
            );
            let exact = (Some(new.mission.clone()), Some(new.areas.clone()));
            if ok {
                assert_eq!(
                    lists, exact,
                    "window {window} seed {seed}: reported complete"
                );
                *completed.entry(window).or_insert(0) += 1;
            } else {
                // The paper's sequence: each list the new one or the previous one, whole, the
                // mission none after the clear (ICD §5.1); and the GCS says which.
                assert!(
                    [Some(&new.mission), Some(&old.mission), None].contains(&lists.0.as_ref()),
                    "window {window} seed {seed}: a partial mission"
                );
                assert!(
                    [Some(&new.areas), Some(&old.areas)].contains(&lists.1.as_ref()),
                    "window {window} seed {seed}: a partial area list"
                );
                assert_eq!(
                    (report.mission.checksum, report.areas.checksum),
                    (
                        lists.0.as_ref().map(mission_checksum),
                        lists.1.as_ref().map(areas_checksum)
                    ),
                    "window {window} seed {seed}: what the GCS says is active"
                );
            }
            // The download over the same faults gives what is active, or fails; never a
            // list that is not.
            if let Some(down) = download(&mut p) {
                let active = (Some(down.mission.clone()), Some(down.areas.clone()));
                assert_eq!(active, lists, "window {window} seed {seed}: the download");
            }
        }
    }
    let total: usize = completed.values().sum();
    println!(
        "windowed uploads under 10 % loss and 10 % duplication per link, reordering: {total} of {runs} completed: {completed:?}"
    );
    // Both links lose a message 1 % of the time, and each message has one retry: most uploads
    // complete whatever the window.
    for window in WINDOWS {
        assert!(
            completed.get(&window).copied().unwrap_or(0) >= 20,
            "{completed:?}"
        );
    }
}
