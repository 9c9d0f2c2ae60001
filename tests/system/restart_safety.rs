//! Restart safety (`services/flight/src/mission_data_handling/mod.rs`): an upload of demo mission 2 over
//! mission 1, with mission data handling killed (`kill -9`) right after the FCC's k-th message of
//! the upload, for every k of the sequence (the report before the upload, the clear, every
//! waypoint, the transmit, the area upload, the last answer). Afterwards the active lists are the
//! old ones or the new ones, whole, and the GCS's report says which, every time.
//!
//! The launcher restarts the partition; it resumes with the lists it recorded before answering
//! and refuses the rest of an upload it did not see from the start (the restart record of
//! `missionlink_flight::mission_data_handling`).

use std::time::Duration;

use missionlink::harness::*;
use missionlink_gcs::gcs_link::{Direction, Finished};
use missionlink_ground::ground_station::GcsError;
use missionlink_ground::ground_station::outcome::{Held, UploadReport};
use missionlink_protocol::transfer::integrity;
use missionlink_protocol::transfer::staged::MissionId;

#[test]
fn killing_mission_data_handling_after_any_message_leaves_old_or_new_lists_and_the_gcs_says_which()
{
    let mut rig = Rig::new("restart-every-k");
    // The subject is which lists survive a kill, not the link's timing nor the watchdog's: on a
    // machine loaded enough to starve the FCC (the whole suite on two cores), a GCS that gives
    // up after 500 ms and one retry failed the upload that sets each round up, and a partition
    // silent for 250 ms (2.5 heartbeats of 100 ms) was killed as hung by the launcher, a second
    // restart in the middle of that upload. 2 s per answer and a 1 s watchdog leave the kills
    // of this test the only ones.
    rig.config.timing.ack_timeout_ms = 2_000;
    rig.config.health.period_ms = 400;
    let mut fcc = rig.start_fcc();
    let mut link = rig.gcs(&mut fcc);
    link.enable_log();
    let (mission_1, mission_2) = (plan("mission-1.toml"), plan("mission-2.toml"));
    let old = link.station().validate(&mission_1).unwrap();
    let new = link.station().validate(&mission_2).unwrap();

    // How many messages the FCC sends in an undisturbed upload of mission 2 over mission 1.
    upload(&mut link, &mission_1).unwrap();
    let from = link.log.len();
    upload(&mut link, &mission_2).unwrap();
    let total = logged_since(&link, from, Direction::Down);
    assert!(total >= 12, "{total} FCC messages");

    let mut restarts = 0;
    let mut seen = Vec::new();
    for k in 1..=total {
        upload(&mut link, &mission_1).unwrap();
        let from = link.log.len();
        let now = link.now();
        link.station().upload(now, &mission_2, true).unwrap();
        while logged_since(&link, from, Direction::Down) < k && !link.station().is_standby() {
            link.pump(Duration::from_millis(1));
        }
        signal_partition(&fcc, "mission-data-handling", rustix::process::Signal::KILL);
        let outcome = finish(&mut link);
        restarts += 1;
        wait_for_logs(
            &fcc,
            "resumed with the lists active before the restart",
            restarts,
            Duration::from_secs(20),
        );

        // What is active, asked of the restarted partition.
        let active = download(&mut link).unwrap_or_else(|e| panic!("k {k}: download: {e}"));
        let new_mission = active.mission == new.mission;
        let new_areas = active.areas == new.areas;
        assert!(
            new_mission || active.mission == old.mission,
            "k {k}: a mission neither old nor new: {active:?}"
        );
        assert!(
            new_areas || active.areas == old.areas,
            "k {k}: areas neither old nor new: {active:?}"
        );

        // What the GCS said.
        let report: Option<UploadReport> = match outcome {
            Ok(Finished::Uploaded(report)) => Some(*report),
            Err(GcsError::Upload(report)) => Some(*report),
            // The report before the upload failed: nothing that changes a list was sent.
            Err(e) if e.in_report() => None,
            other => panic!("k {k}: {other:?}"),
        };
        match &report {
            None => assert!(
                !new_mission && !new_areas,
                "k {k}: nothing was sent, yet {active:?}"
            ),
            Some(report) => {
                for (name, held, is_new) in [
                    ("mission", report.mission.held, new_mission),
                    ("areas", report.areas.held, new_areas),
                ] {
                    let said_new = match held {
                        Held::New => true,
                        Held::Previous => false,
                        other => {
                            panic!("k {k}: the GCS does not say which {name}: {other:?}: {report}")
                        }
                    };
                    assert_eq!(said_new, is_new, "k {k}: {name}: {report}");
                }
            }
        }
        seen.push((
            k,
            report.map_or_else(
                || "nothing sent".to_owned(),
                |r| format!("{:?}", r.outcome()),
            ),
        ));
    }
    eprintln!("kill after FCC message k of {total}: {seen:?}");
}

/// Staged missions are kept across a restart of mission data handling like the active
/// lists (ICD §8). Mission 2 is staged, the partition is killed (`kill -9`); the restarted one
/// reports the same staged mission (its checksums) and activates it.
#[test]
fn staged_missions_survive_a_restart_of_mission_data_handling() {
    let (_rig, fcc, mut link) = Rig::with_gcs("restart-staged");
    let (mission_1, mission_2) = (plan("mission-1.toml"), plan("mission-2.toml"));
    upload(&mut link, &mission_1).unwrap();
    let id = MissionId::new("MEDEVAC-2").unwrap();
    let now = link.now();
    link.station().stage(now, id, &mission_2).unwrap();
    finish(&mut link).unwrap();
    let before = report(&mut link);
    assert_eq!(before.len(), 2, "{before:?}");

    signal_partition(&fcc, "mission-data-handling", rustix::process::Signal::KILL);
    wait_for_logs(
        &fcc,
        "resumed with the lists active before the restart",
        1,
        Duration::from_secs(20),
    );
    let after = report(&mut link);
    assert_eq!(after.len(), 2, "{after:?}");
    for (b, a) in before.iter().zip(&after) {
        assert_eq!(
            (b.mission_id, b.mission_checksum, b.area_checksum),
            (a.mission_id, a.mission_checksum, a.area_checksum)
        );
    }

    let now = link.now();
    link.station().activate(now, id).unwrap();
    finish(&mut link).unwrap();
    let new = link.station().validate(&mission_2).unwrap();
    let active = download(&mut link).unwrap();
    assert_eq!(active.areas, new.areas);
    assert_eq!(
        integrity::mission_checksum(&active.mission),
        integrity::mission_checksum(&new.mission)
    );
}
