//! The GCS side of staged missions (ICD §8) against the real FCC ([`StationRig`]: the GCS logic
//! and the FCC of an [`FccRig`], every message moved at once, losses injected by hand): the
//! atomic upload, stage / activate / delete / download of a staged mission, the truth after a
//! failure, edits that send only what changed, and the edition-1 FCC that gets the paper's
//! sequence as before.
//!
//! | rule | tests |
//! |---|---|
//! | atomic upload | `the_atomic_upload_stages_activates_and_deletes_its_copy`, `a_failure_in_the_area_phase_leaves_the_active_lists_as_they_were`, `a_lost_answer_to_the_activation_is_resolved_by_the_report`, `the_paper_sequence_can_be_forced_toward_edition_2` |
//! | staged requests | `stage_download_activate_delete`, `requests_about_unknown_staged_missions_name_the_reason`, `a_ninth_staged_mission_is_refused_before_anything_is_staged` |
//! | edits | `one_changed_waypoint_of_256_is_four_messages`, `an_edit_without_the_cache_downloads_the_mission_first`, `an_edit_of_a_staged_mission_sends_only_the_difference`, `an_edit_that_changes_the_areas_stays_atomic`, `an_edit_that_removes_a_waypoint_is_a_full_upload` |
//! | edition 1 | `toward_edition_1_the_upload_is_the_papers_sequence`, `an_edit_toward_edition_1_downloads_then_sends_the_difference`, `an_edition_1_fcc_stages_nothing` |

use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::outcome::{
    UploadKind, UploadOutcome, UploadReport, Warning,
};
use missionlink_ground::ground_station::{
    GcsError, GcsEvent, MissionPlan, Sequence, StagedRequest, ValidatedPlan,
};
use missionlink_interfaces::wire::{
    Altitude, Message, MessageType, MissionPlanMode, MissionReport, Reason,
};
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::sender::Target;
use missionlink_protocol::transfer::staged::MissionId;

type Event = GcsEvent<core::convert::Infallible>;

/// The requests of mission 1's upload in the paper's sequence (edition 1, or a GCS that asks
/// for it), as [`StationRig::requests`] names them.
const MISSION_1_PAPER: [&str; 9] = [
    "13000 mode 7",
    "13000 mode 1",
    "13006 take-off",
    "13002 wp 1",
    "13001",
    "13000 mode 2",
    "2011 mode 1",
    "2012 area 1",
    "2011 mode 2",
];

/// The requests of mission 1's upload as a staged mission (ICD §8).
const MISSION_1_STAGED: [&str; 9] = [
    "13000 mode 7",
    "13000 mode 10",
    "13006 take-off",
    "13002 wp 1",
    "13001",
    "13000 mode 8",
    "2011 mode 1",
    "2012 area 1",
    "2011 mode 7",
];

/// What an atomic upload sends after the staged mission: the activation, the delete.
const ACTIVATE_STAGED: [&str; 2] = ["50000", "13000 mode 6"];

/// Long enough for any request of these tests in simulated time.
const LIMIT: Duration = Duration::from_secs(120);

fn id(s: &str) -> MissionId {
    MissionId::new(s).unwrap()
}

/// The upload's report, whether it completed or failed.
fn upload_report(events: &[Event]) -> UploadReport {
    events
        .iter()
        .find_map(|e| match e {
            GcsEvent::Uploaded(r) => Some((**r).clone()),
            GcsEvent::Failed(GcsError::Upload(r)) => Some((**r).clone()),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no upload report: {events:?}"))
}

fn failure(events: &[Event]) -> GcsError<core::convert::Infallible> {
    events
        .iter()
        .find_map(|e| match e {
            GcsEvent::Failed(f) => Some(f.clone()),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no failure: {events:?}"))
}

/// The FCC's report, asked by the GCS.
fn report(s: &mut StationRig) -> Vec<MissionReport> {
    let now = s.rig.now;
    s.gcs.report(now).unwrap();
    s.run(LIMIT)
        .into_iter()
        .find_map(|e| match e {
            GcsEvent::Reported(entries) => Some(entries.into_iter().collect()),
            _ => None,
        })
        .expect("a report")
}

/// The Mission IDs the report lists as staged.
fn staged_ids(entries: &[MissionReport]) -> Vec<String> {
    entries
        .iter()
        .filter_map(|e| e.mission_id.map(|t| t.as_str().to_owned()))
        .filter(|s| !s.is_empty())
        .collect()
}

/// What the GCS downloads from `target`.
fn download(s: &mut StationRig, target: Option<MissionId>) -> ValidatedPlan {
    let now = s.rig.now;
    s.gcs.download_of(now, target).unwrap();
    s.run(LIMIT)
        .into_iter()
        .find_map(|e| match e {
            GcsEvent::DownloadComplete(plan) => Some(*plan),
            _ => None,
        })
        .expect("a download")
}

/// The mission as flown: the Mission ID (which only the closer carries, informational) aside.
fn flown(m: &Mission) -> Mission {
    Mission {
        mission_id: None,
        ..m.clone()
    }
}

/// An FCC with `plan` active, uploaded by the rig's hand (edition 2, with checksums).
fn fcc_with(plan: &MissionPlan) -> FccRig {
    let mut rig = FccRig::new();
    let valid = validated(plan);
    let m = mission_checksum(&valid.mission);
    let a = areas_checksum(&valid.areas);
    assert_eq!(
        reason_of(&rig.upload_mission(&valid.mission, Some(m))),
        None
    );
    assert_eq!(reason_of(&rig.upload_areas(&valid.areas, Some(a))), None);
    rig
}

/// `plan` with the waypoint `index` (in flight-plan order) raised to `metres`.
fn with_altitude(plan: &MissionPlan, index: usize, metres: f64) -> MissionPlan {
    let mut edited = plan.clone();
    let mut w = validated(plan).mission.waypoints[index].waypoint;
    w.altitude = Altitude::from_metres(metres).unwrap();
    edited.mission.store(&Message::from(w)).unwrap();
    edited
}

// ---- The atomic upload ----

#[test]
fn the_atomic_upload_stages_activates_and_deletes_its_copy() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let expected = validated(&mission_1());
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.kind, UploadKind::Atomic);
    assert!(r.warning.is_none(), "{r}");
    assert_eq!(
        s.requests(0),
        [MISSION_1_STAGED.as_slice(), &ACTIVATE_STAGED].concat()
    );
    assert_eq!(r.messages.sent, 11);
    assert_eq!(r.messages.full, 11);
    // The opener and the closers name the operator's Mission ID: the activation makes it the
    // active lists' ID.
    let fresh = "MEDEVAC-1";
    for sent in s.sent.iter().filter(|x| x.direction == Direction::Up) {
        if let Message::MissionTransferCommand(c) = &sent.message
            && matches!(
                c.mode,
                MissionPlanMode::LoadWaypointBuffer
                    | MissionPlanMode::StageMission
                    | MissionPlanMode::DeleteStagedMission
            )
        {
            assert_eq!(c.mission_id.unwrap().as_str(), fresh);
        }
    }
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&expected.mission))
    );
    assert_eq!(s.rig.fcc.active_areas(), Some(&expected.areas));
    assert!(
        staged_ids(&report(&mut s)).is_empty(),
        "the copy is deleted"
    );
    // The FCC holds and hands back the operator's Mission ID.
    let down = download(&mut s, None);
    assert_eq!(down.mission.mission_id.unwrap().as_str(), "MEDEVAC-1");
    assert_eq!(down.mission, expected.mission);
}

#[test]
fn an_operators_staged_mission_of_the_same_name_is_neither_replaced_nor_deleted() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    // The operator staged another mission under the name the upload carries.
    let other = with_altitude(&mission_1(), 0, 150.0);
    let now = s.rig.now;
    s.gcs.stage(now, id("MEDEVAC-1"), &other).unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    let expected = validated(&mission_1());
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    // Staged and activated under a fresh ID, which the active lists now carry.
    let fresh = format!("gcs-{:08X}", mission_checksum(&expected.mission).value());
    let down = download(&mut s, None);
    assert_eq!(down.mission.mission_id.unwrap().as_str(), fresh);
    assert_eq!(flown(&down.mission), flown(&expected.mission));
    // The operator's staged mission is still there, unchanged.
    assert_eq!(staged_ids(&report(&mut s)), ["MEDEVAC-1"]);
    let staged = download(&mut s, Some(id("MEDEVAC-1")));
    assert_eq!(flown(&staged.mission), flown(&validated(&other).mission));
}

/// A staged copy whose delete went unanswered (the FCC keeps it: ICD §8, the copy stays staged
/// after the activation) is the operator's warning, and the next upload toward the same FCC
/// deletes it after its own: copies left on a bad link do not pile up to the FCC's capacity.
#[test]
fn a_staged_copy_left_by_a_lost_delete_is_deleted_by_the_next_upload() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    // Every delete (#13000 mode 6) is lost on the way up: the copy stays.
    s.lose = Box::new(|d, m| {
        d == Direction::Up
            && matches!(m, Message::MissionTransferCommand(c)
                if c.mode == MissionPlanMode::DeleteStagedMission)
    });
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(
        matches!(r.warning, Some(Warning::StagedCopyLeft { id, .. }) if id.as_str() == "MEDEVAC-1"),
        "{r}"
    );
    s.lose = Box::new(|_, _| false);
    assert_eq!(staged_ids(&report(&mut s)), ["MEDEVAC-1"]);

    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_2(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.warning, None, "{r}");
    assert!(
        staged_ids(&report(&mut s)).is_empty(),
        "the upload's own copy and the one left before are deleted"
    );
    // A copy the FCC no longer lists is forgotten: the next upload deletes nothing more.
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    let deletes = s
        .sent
        .iter()
        .rev()
        .take_while(|x| {
            !matches!(&x.message, Message::MissionTransferCommand(c)
                if x.direction == Direction::Up && c.mode == MissionPlanMode::ReportMissions)
        })
        .filter(|x| {
            x.direction == Direction::Up
                && matches!(&x.message, Message::MissionTransferCommand(c)
                    if c.mode == MissionPlanMode::DeleteStagedMission)
        })
        .count();
    assert_eq!(deletes, 1, "only the upload's own copy is deleted");
}

#[test]
fn a_failure_in_the_area_phase_leaves_the_active_lists_as_they_were() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let before = (
        s.rig.fcc.active_mission().cloned(),
        s.rig.fcc.active_areas().cloned(),
    );
    // Every #2012 is lost: the area phase fails after its retry.
    s.lose = Box::new(|d, m| d == Direction::Up && matches!(m, Message::AreaPolygonLoopSegment(_)));
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::PreviousActive, "{r}");
    assert!(r.to_string().contains("unchanged"), "{r}");
    assert_eq!(
        (
            s.rig.fcc.active_mission().cloned(),
            s.rig.fcc.active_areas().cloned()
        ),
        before,
        "the active lists are exactly as they were"
    );
    assert!(
        !s.requests(0).contains(&"50000".to_owned()),
        "no activation sent"
    );
    s.lose = Box::new(|_, _| false);
    assert!(
        staged_ids(&report(&mut s)).is_empty(),
        "the half-staged copy is deleted: {r}"
    );
}

#[test]
fn a_lost_answer_to_the_activation_is_resolved_by_the_report() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    // Both answers to #50000 (the first attempt's and the retry's) are lost.
    s.lose = Box::new(|d, m| {
        d == Direction::Down
            && matches!(m, Message::MessageAcknowledgement(a)
                if a.original_message_type == MessageType::MissionExecuteCommand as u16)
    });
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::CompleteAfterLostAnswer, "{r}");
    let expected = validated(&mission_1());
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&expected.mission))
    );
    let requests = s.requests(0);
    let after_activation: Vec<&String> = requests
        .iter()
        .skip_while(|r| r.as_str() != "50000")
        .collect();
    assert_eq!(
        after_activation,
        ["50000", "50000", "13000 mode 7", "13000 mode 6"],
        "the retry, the report, then the copy's delete"
    );
}

#[test]
fn the_paper_sequence_can_be_forced_toward_edition_2() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Paper { clear: true })
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete);
    assert_eq!(r.kind, UploadKind::Paper { edition_1: false });
    assert!(r.to_string().contains("one after the other"), "{r}");
    assert_eq!(s.requests(0), MISSION_1_PAPER);
}

// ---- Staged missions ----

#[test]
fn stage_download_activate_delete() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let active_before = s.rig.fcc.active_mission().cloned();
    let plan = mission_1();
    let expected = validated(&plan);
    let now = s.rig.now;
    s.gcs.stage(now, id("next"), &plan).unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.kind, UploadKind::Staged(id("next")));
    assert_eq!(s.requests(0), MISSION_1_STAGED);
    assert_eq!(
        s.rig.fcc.active_mission().cloned(),
        active_before,
        "staging leaves the active lists"
    );
    assert_eq!(staged_ids(&report(&mut s)), ["next"]);

    let staged = download(&mut s, Some(id("next")));
    assert_eq!(flown(&staged.mission), flown(&expected.mission));
    assert_eq!(staged.areas, expected.areas);

    let from = s.sent.len();
    let now = s.rig.now;
    s.gcs.activate(now, id("next")).unwrap();
    let events = s.run(LIMIT);
    assert!(
        matches!(
            events.last(),
            Some(GcsEvent::CommandAccepted(
                MessageType::MissionExecuteCommand
            ))
        ),
        "{events:?}"
    );
    assert_eq!(s.requests(from), ["50000"]);
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&expected.mission))
    );
    assert_eq!(s.rig.fcc.active_areas(), Some(&expected.areas));

    let now = s.rig.now;
    s.gcs.delete(now, id("next")).unwrap();
    let events = s.run(LIMIT);
    assert!(
        matches!(events.last(), Some(GcsEvent::CommandAccepted(_))),
        "{events:?}"
    );
    assert!(staged_ids(&report(&mut s)).is_empty());
}

#[test]
fn requests_about_unknown_staged_missions_name_the_reason() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let now = s.rig.now;
    s.gcs.delete(now, id("nowhere")).unwrap();
    let f = failure(&s.run(LIMIT));
    let GcsError::Staged {
        request: StagedRequest::Delete,
        error,
        ..
    } = &f
    else {
        panic!("{f:?}");
    };
    assert_eq!(error.reason(), Some(Reason::WrongState));
    let text = f.to_string();
    assert!(
        text.contains("\"nowhere\"") && text.contains("#13000") && text.contains("no such"),
        "{text}"
    );

    let now = s.rig.now;
    s.gcs.activate(now, id("nowhere")).unwrap();
    let f = failure(&s.run(LIMIT));
    assert!(
        matches!(&f, GcsError::Staged { request: StagedRequest::Activate, error, .. }
            if error.reason() == Some(Reason::WrongState)),
        "{f:?}"
    );
    assert!(f.to_string().contains("#50000"), "{f}");

    let now = s.rig.now;
    s.gcs.download_of(now, Some(id("nowhere"))).unwrap();
    let f = failure(&s.run(LIMIT));
    assert!(
        matches!(&f, GcsError::Staged { request: StagedRequest::Download, error, .. }
            if error.reason() == Some(Reason::WrongState)),
        "{f:?}"
    );
}

#[test]
fn a_ninth_staged_mission_is_refused_before_anything_is_staged() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    for n in 0..8 {
        let now = s.rig.now;
        s.gcs
            .stage(now, id(&format!("m{n}")), &mission_1())
            .unwrap();
        assert!(upload_report(&s.run(LIMIT)).is_complete());
    }
    let from = s.sent.len();
    let now = s.rig.now;
    s.gcs.stage(now, id("ninth"), &mission_1()).unwrap();
    let f = failure(&s.run(LIMIT));
    assert_eq!(f, GcsError::Capacity { staged: 8 });
    assert!(f.to_string().contains("delete one"), "{f}");
    assert_eq!(
        s.requests(from),
        ["13000 mode 7"],
        "only the report was sent"
    );
    // The atomic upload needs a slot too; the active lists stay.
    let before = s.rig.fcc.active_mission().cloned();
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    assert_eq!(failure(&s.run(LIMIT)), GcsError::Capacity { staged: 8 });
    assert_eq!(s.rig.fcc.active_mission().cloned(), before);
    // Replacing a staged ID needs no slot.
    let now = s.rig.now;
    s.gcs.stage(now, id("m3"), &mission_2()).unwrap();
    assert!(upload_report(&s.run(LIMIT)).is_complete());
}

// ---- Edits ----

/// The measure of an edit (docs/gcs.md, "Staged missions and edits"): one waypoint of a
/// 256-waypoint mission changed, the mission known from this GCS's last upload and confirmed by the
/// report: the report request, mode 10, the waypoint and the transmit; the download then equals the
/// edited file.
#[test]
fn one_changed_waypoint_of_256_is_four_messages() {
    let plan = generated_plan(256);
    let mut s = StationRig::new(fcc_with(&plan));
    let known = vec![validated(&plan).mission];
    let edited = with_altitude(&plan, 100, 321.0);
    let from = s.sent.len();
    let now = s.rig.now;
    s.gcs
        .edit(now, &edited, Target::Active, Sequence::Atomic, known)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.edit, Some(None), "only the difference was sent");
    assert_eq!(
        s.requests(from),
        [
            "13000 mode 7",
            "13000 mode 10",
            "13002 wp 101",
            "13000 mode 2"
        ]
    );
    assert_eq!(r.messages.sent, 4);
    assert!(r.messages.sent <= 4);
    println!(
        "edit of one waypoint of 256: sent {} messages (a full upload: {})",
        r.messages.sent, r.messages.full
    );
    assert_eq!(r.messages.full, 1 + 1 + 258 + 1 + 13 + 2);
    let down = download(&mut s, None);
    let expected = validated(&edited);
    assert_eq!(flown(&down.mission), flown(&expected.mission));
    assert_eq!(down.areas, expected.areas);
}

#[test]
fn an_edit_without_the_cache_downloads_the_mission_first() {
    let plan = generated_plan(256);
    let mut s = StationRig::new(fcc_with(&plan));
    let edited = with_altitude(&plan, 7, 222.0);
    let from = s.sent.len();
    let now = s.rig.now;
    s.gcs
        .edit(now, &edited, Target::Active, Sequence::Atomic, Vec::new())
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(
        s.requests(from),
        [
            "13000 mode 7",
            "13000 mode 3",
            "13000 mode 10",
            "13002 wp 8",
            "13000 mode 2"
        ]
    );
    println!(
        "edit of one waypoint of 256 without the cache: sent {} messages (a full upload: {})",
        r.messages.sent, r.messages.full
    );
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&validated(&edited).mission))
    );
}

#[test]
fn an_edit_of_a_staged_mission_sends_only_the_difference() {
    let plan = generated_plan(256);
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let now = s.rig.now;
    s.gcs.stage(now, id("long"), &plan).unwrap();
    assert!(upload_report(&s.run(LIMIT)).is_complete());
    let edited = with_altitude(&plan, 200, 333.0);
    let from = s.sent.len();
    let now = s.rig.now;
    s.gcs
        .edit(
            now,
            &edited,
            Target::Staged(id("long")),
            Sequence::Atomic,
            vec![validated(&plan).mission],
        )
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(
        s.requests(from),
        [
            "13000 mode 7",
            "13000 mode 10",
            "13002 wp 201",
            "13000 mode 8"
        ]
    );
    let down = download(&mut s, Some(id("long")));
    assert_eq!(flown(&down.mission), flown(&validated(&edited).mission));
}

#[test]
fn an_edit_that_changes_the_areas_stays_atomic() {
    let plan = mission_2();
    let mut s = StationRig::new(fcc_with(&plan));
    let mut edited = with_altitude(&plan, 1, 250.0);
    edited.safety_offset = missionlink_interfaces::wire::SafetyOffset::from_metres(30.0).unwrap();
    let from = s.sent.len();
    let now = s.rig.now;
    s.gcs
        .edit(
            now,
            &edited,
            Target::Active,
            Sequence::Atomic,
            vec![validated(&plan).mission],
        )
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    let requests = s.requests(from);
    assert_eq!(
        requests[..4],
        [
            "13000 mode 7",
            "13000 mode 10",
            "13002 wp 2",
            "13000 mode 8"
        ]
    );
    assert_eq!(
        requests[requests.len() - 3..],
        ["2011 mode 7", "50000", "13000 mode 6"]
    );
    let expected = validated(&edited);
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&expected.mission))
    );
    assert_eq!(s.rig.fcc.active_areas(), Some(&expected.areas));
}

#[test]
fn an_edit_that_removes_a_waypoint_is_a_full_upload() {
    let mut s = StationRig::new(fcc_with(&generated_plan(5)));
    let shorter = generated_plan(4);
    let now = s.rig.now;
    s.gcs
        .edit(
            now,
            &shorter,
            Target::Active,
            // The paper's sequence: the shorter zig-zag fails the onboard geofence check from
            // TROL, which an activation runs (the fallback to a full upload is the same).
            Sequence::Paper { clear: true },
            vec![validated(&generated_plan(5)).mission],
        )
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(matches!(r.edit, Some(Some(_))), "{r}");
    assert!(r.to_string().contains("full upload"), "{r}");
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&validated(&shorter).mission))
    );
}

// ---- Edition 1 ----

#[test]
fn toward_edition_1_the_upload_is_the_papers_sequence() {
    let mut s = StationRig::edition_1(FccRig::new().with_mission_2());
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.kind, UploadKind::Paper { edition_1: true });
    assert!(r.to_string().contains("one after the other"), "{r}");
    assert_eq!(s.requests(0), MISSION_1_PAPER);
    // No edition-2 field reached the FCC: no checksum in the closers.
    for sent in s.sent.iter().filter(|x| x.direction == Direction::Up) {
        if let Message::MissionTransferCommand(c) = &sent.message {
            assert_eq!(c.mission_checksum, None);
        }
    }
    let expected = validated(&mission_1());
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&expected.mission))
    );
}

#[test]
fn an_edit_toward_edition_1_downloads_then_sends_the_difference() {
    let plan = mission_2();
    let mut s = StationRig::edition_1(FccRig::new().with_mission_2());
    let edited = with_altitude(&plan, 2, 260.0);
    let now = s.rig.now;
    s.gcs
        .edit(
            now,
            &edited,
            Target::Active,
            Sequence::Atomic,
            vec![validated(&plan).mission],
        )
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.edit, Some(None), "{r}");
    let last = validated(&plan).mission.waypoints[2]
        .waypoint
        .waypoint_number;
    assert_eq!(
        s.requests(0),
        [
            "13000 mode 7".to_owned(),
            "13000 mode 3".to_owned(),
            "2011 mode 3".to_owned(),
            format!("13002 wp {last}"),
            "13000 mode 2".to_owned(),
        ],
        "no mode 10 toward edition 1; the areas are unchanged"
    );
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&validated(&edited).mission))
    );
}

#[test]
fn an_edition_1_fcc_stages_nothing() {
    let mut s = StationRig::edition_1(FccRig::new().with_mission_2());
    let now = s.rig.now;
    s.gcs.stage(now, id("next"), &mission_1()).unwrap();
    let f = failure(&s.run(LIMIT));
    assert!(matches!(f, GcsError::Edition1 { .. }), "{f:?}");
    assert_eq!(s.requests(0), ["13000 mode 7"]);
}

/// Found by fuzz_gcs: `execute` with command 4 put a #50000 without its Mission ID on the wire,
/// a message the FCC can only refuse (`MissingField`). Command 4 goes through `activate`;
/// `execute` refuses it and sends nothing.
#[test]
fn execute_refuses_command_4_and_sends_nothing() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    let now = s.rig.now;
    assert_eq!(
        s.gcs.execute(
            now,
            missionlink_interfaces::wire::ExecuteCommand::ActivateStaged
        ),
        Err(GcsError::ActivateWithoutId)
    );
    assert!(s.gcs.is_standby());
    assert!(s.gcs.frames().is_empty(), "a message went out");
    assert!(s.run(LIMIT).is_empty());
}

/// The upload in flight of the mission and areas already active: the FCC refuses the activation
/// (`WrongState`: trajectory generation is active) and holds the lists active already. The GCS
/// says so, nothing to do, not that an answer was lost; the outcome is a success.
#[test]
fn the_upload_of_the_lists_already_active_in_flight_is_nothing_to_do() {
    let mut s = StationRig::new(FccRig::new().with_mission_2());
    s.rig.fcc.set_automation_state(&flying());
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_2(), Sequence::Atomic)
        .unwrap();
    let r = upload_report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::AlreadyActive, "{r}");
    assert!(r.is_complete(), "{r}");
    let (_, e) = r.failure.as_ref().unwrap();
    assert_eq!(e.reason(), Some(Reason::WrongState), "{r}");
    let text = r.to_string();
    assert!(
        text.starts_with("nothing to do: the uploaded lists were active already"),
        "{text}"
    );
    assert!(!text.contains("lost"), "{text}");
    println!("{text}");
    let expected = validated(&mission_2());
    assert_eq!(
        s.rig.fcc.active_mission().map(flown),
        Some(flown(&expected.mission))
    );
}
