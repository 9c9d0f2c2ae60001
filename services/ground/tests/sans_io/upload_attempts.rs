//! Attempts of a whole upload (`GcsConfig::upload_attempts`): an upload whose attempt failed
//! with the lists as they were, for a cause that may pass (no answer, `Busy`, `WrongState`), is
//! begun again, report first, and its outcome is that of the attempt that ended it. A failure
//! that changed a list, that the FCC refused for the content, or whose result the GCS could not
//! learn, is never attempted again.

use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::outcome::{Held, UploadOutcome, UploadReport};
use missionlink_ground::ground_station::{
    GcsConfig, GcsError, GcsEvent, GroundStation, Phase, Sequence, WithoutGateway,
};
use missionlink_interfaces::wire::{Message, MissionPlanMode, Reason};
use missionlink_protocol::link::retry::AttemptFailure;

/// A pair whose GCS attempts an upload up to `attempts` times, mission 1 active.
fn pair(attempts: u8) -> Pair {
    let mut pair = Pair::new(7);
    let config = GcsConfig {
        upload_attempts: attempts,
        ..gcs_config()
    };
    pair.gcs = GroundStation::new(config, WithoutGateway);
    let now = pair.now;
    pair.gcs.upload(now, &mission_1(), true).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    assert!(matches!(
        pair.take_gcs_events().last(),
        Some(GcsEvent::Uploaded(_))
    ));
    pair
}

/// Report requests (#13000 mode 7) the GCS sent: one per attempt, and the ones after a failure.
fn report_requests(pair: &Pair) -> usize {
    pair.sent
        .iter()
        .filter(|s| {
            matches!(&s.message, Message::MissionTransferCommand(c)
                if c.mode == MissionPlanMode::ReportMissions)
        })
        .count()
}

/// Waypoints (#13002) the GCS sent.
fn waypoints_sent(pair: &Pair) -> usize {
    pair.sent
        .iter()
        .filter(|s| matches!(s.message, Message::UaPositionWaypoint(_)))
        .count()
}

/// The upload's one outcome: its report, or the error it failed with.
fn outcome(pair: &mut Pair) -> Result<UploadReport, GcsError<core::convert::Infallible>> {
    let mut ends: Vec<_> = pair
        .take_gcs_events()
        .into_iter()
        .filter_map(|e| match e {
            GcsEvent::Uploaded(r) => Some(Ok(*r)),
            GcsEvent::Failed(e) => Some(Err(e)),
            _ => None,
        })
        .collect();
    assert_eq!(ends.len(), 1, "one outcome per upload: {ends:?}");
    ends.pop().unwrap()
}

/// Starts the atomic upload of mission 2, lets it send `waypoints` waypoints, then cuts the
/// uplink (both links) for `cut`.
fn upload_with_a_cut(pair: &mut Pair, waypoints: usize, cut: Duration) {
    upload_by_with_a_cut(pair, Sequence::Atomic, waypoints, cut);
}

/// As [`upload_with_a_cut`], the upload by `sequence`.
fn upload_by_with_a_cut(pair: &mut Pair, sequence: Sequence, waypoints: usize, cut: Duration) {
    let before = waypoints_sent(pair);
    let now = pair.now;
    pair.gcs.upload_with(now, &mission_2(), sequence).unwrap();
    while waypoints_sent(pair) < before + waypoints {
        assert!(pair.step(), "the upload stopped");
    }
    pair.uplink = [DOWN; 2];
    let until = pair.now + cut;
    pair.run_until(until);
    pair.uplink = [CLEAN; 2];
    pair.run_until_standby(Duration::from_secs(30));
}

#[test]
fn an_attempt_that_left_the_lists_as_they_were_is_begun_again_and_completes() {
    let mut pair = pair(2);
    let reports_before = report_requests(&pair);
    // A cut long enough that a waypoint and its one resend go unanswered (2 x the ack timeout),
    // short enough that the GCS's question after it is answered.
    upload_with_a_cut(&mut pair, 1, 2 * ACK_TIMEOUT + Duration::from_millis(10));

    let report = outcome(&mut pair).expect("the second attempt completes");
    assert_eq!(report.outcome(), UploadOutcome::Complete, "{report}");
    assert_eq!(report.attempts, 2, "{report}");
    assert!(report.to_string().ends_with("; attempt 2"), "{report}");
    // The first attempt's report, its question after the failure (asked again while the cut
    // lasts), the second attempt's report.
    assert!(report_requests(&pair) - reports_before >= 3);
    let new = pair.gcs.validate(&mission_2()).unwrap();
    assert_eq!(
        pair.fcc.active_mission().map(|m| &m.waypoints),
        Some(&new.mission.waypoints)
    );
    assert_eq!(pair.fcc.active_areas(), Some(&new.areas));
}

#[test]
fn with_one_attempt_the_same_cut_fails_with_the_previous_lists() {
    let mut pair = pair(1);
    upload_with_a_cut(&mut pair, 1, 2 * ACK_TIMEOUT + Duration::from_millis(10));
    let Err(GcsError::Upload(report)) = outcome(&mut pair) else {
        panic!("the upload did not fail");
    };
    assert_eq!(report.outcome(), UploadOutcome::PreviousActive, "{report}");
    assert_eq!(report.attempts, 1);
    assert!(!report.to_string().contains("attempt"), "{report}");
}

#[test]
fn an_upload_whose_result_the_gcs_could_not_learn_is_not_attempted_again() {
    let mut pair = pair(3);
    let reports_before = report_requests(&pair);
    // Cut for good: the question after the failure goes unanswered too.
    upload_with_a_cut(&mut pair, 1, Duration::from_secs(60));
    let Err(GcsError::Upload(report)) = outcome(&mut pair) else {
        panic!("the upload did not fail");
    };
    // Before the activation an atomic upload knows the previous lists are active; the staged
    // copy may be left on the FCC, so the upload is not clean.
    assert_eq!(report.attempts, 1, "{report}");
    assert!(report.warning.is_some(), "{report}");
    let first_attempt_reports = report_requests(&pair) - reports_before;
    assert!(first_attempt_reports >= 2, "{first_attempt_reports}");
}

#[test]
fn a_refusal_of_the_content_is_not_attempted_again() {
    let mut pair = pair(3);
    // Trajectory generation active: the clear of the paper's sequence is refused
    // (`GuidanceActive`, ICD §5.1), which no second attempt changes.
    pair.fcc.set_automation_state(&flying());
    let reports_before = report_requests(&pair);
    let now = pair.now;
    pair.gcs
        .upload_with(now, &mission_2(), Sequence::Paper { clear: true })
        .unwrap();
    pair.run_until_standby(Duration::from_secs(30));
    let Err(GcsError::Upload(report)) = outcome(&mut pair) else {
        panic!("the upload did not fail");
    };
    let Some((Phase::MissionUpload, error)) = report.failure else {
        panic!("{report}");
    };
    assert_eq!(
        error.second,
        Some(AttemptFailure::Rejected(Reason::GuidanceActive))
    );
    assert_eq!(report.attempts, 1, "{report}");
    // The report before the upload and the question after its failure: one attempt.
    assert_eq!(report_requests(&pair) - reports_before, 2);
}

/// The paper's sequence clears first, and the clear deletes the active mission (paper §3.1, ICD
/// §5.1 step 1): cut after its clear, the upload fails with no mission on the FCC, and says so
/// (exit status 7 of `gcs upload`), the areas the previous ones.
#[test]
fn the_papers_sequence_cut_after_its_clear_says_the_fcc_holds_no_mission() {
    let mut pair = pair(1);
    let old_areas = pair.fcc.active_areas().cloned();
    upload_by_with_a_cut(
        &mut pair,
        Sequence::Paper { clear: true },
        1,
        2 * ACK_TIMEOUT + Duration::from_millis(10),
    );
    let Err(GcsError::Upload(report)) = outcome(&mut pair) else {
        panic!("the upload did not fail");
    };
    assert_eq!(pair.fcc.active_mission(), None);
    assert_eq!(pair.fcc.active_areas(), old_areas.as_ref());
    assert_eq!(report.outcome(), UploadOutcome::NoMission, "{report}");
    assert_eq!(report.mission.held, Held::Cleared, "{report}");
    assert_eq!(report.mission.checksum, None, "{report}");
    assert_eq!(report.areas.held, Held::Previous, "{report}");
    assert!(!report.is_complete());
    let line = report.to_string();
    assert!(
        line.contains("the FCC holds no mission (the paper's sequence cleared it"),
        "{line}"
    );
    assert!(line.contains("areas previous"), "{line}");
}

/// The same cut with a second attempt: the FCC held no mission only because the first
/// attempt's own clear deleted it, so the upload is begun again and completes.
#[test]
fn the_papers_sequence_cut_after_its_clear_is_begun_again_and_completes() {
    let mut pair = pair(2);
    upload_by_with_a_cut(
        &mut pair,
        Sequence::Paper { clear: true },
        1,
        2 * ACK_TIMEOUT + Duration::from_millis(10),
    );
    let report = outcome(&mut pair).expect("the second attempt completes");
    assert_eq!(report.outcome(), UploadOutcome::Complete, "{report}");
    assert_eq!(report.attempts, 2, "{report}");
    let new = pair.gcs.validate(&mission_2()).unwrap();
    assert_eq!(
        pair.fcc.active_mission().map(|m| &m.waypoints),
        Some(&new.mission.waypoints)
    );
    assert_eq!(pair.fcc.active_areas(), Some(&new.areas));
}
