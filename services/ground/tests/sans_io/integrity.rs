//! The FCC side of ICD §11 (end-to-end mission integrity) and of restart safety (a restart
//! never assembles a transfer it did not see from the start,
//! `services/flight/src/mission_data_handling/`), through mission data handling driven by hand
//! ([`FccRig`]): every test reads the FCC's answers off the wire (#17000 type and reason, #3012
//! status, #14000, #2011 mode 4, #50001) and checks the active lists, their generations and the
//! events the driver gets.
//!
//! | rule | tests |
//! |---|---|
//! | closers' checksums | `a_closer_with_the_checksum_of_the_list_assembled_activates_it`, `a_mission_closer_whose_checksum_differs_is_refused`, `an_area_closer_whose_checksum_differs_is_refused`, `the_clear_of_the_active_mission_carries_no_checksum` |
//! | idempotent closers | `a_retried_closer_gets_the_same_success_and_changes_nothing`, `edition_1_closers_are_idempotent_too`, `a_retried_closer_gets_the_same_refusal`, `only_the_last_closer_is_remembered`, `an_accepted_data_message_or_opener_ends_the_memory`, `a_clear_of_the_areas_ends_the_memory` |
//! | restart safety | `a_restart_holds_the_cut_upload_until_a_clear`, `a_cancel_ends_the_interruption`, `silence_for_the_transfer_timeout_ends_the_interruption`, `a_restart_without_an_open_upload_holds_nothing`, `upload_events_come_exactly_when_an_upload_opens_or_closes` |
//! | downloads | `an_edition_2_mission_download_carries_the_checksum`, `an_edition_2_area_download_carries_the_checksum` |
//! | report | `the_report_without_lists`, `the_report_of_the_active_lists`, `the_report_runs_no_check_without_both_lists`, `the_report_is_retried_as_downloads_are` |
//! | golden | `the_fcc_reports_the_checksum_the_gcs_computed_for_mission_2` |

use crate::support::*;
use missionlink_flight::mission_data_handling::{DataKind, FccEvent, Resumed};
use missionlink_interfaces::wire::{
    AckType, AreaDownloadStatus, AreaTransferMode, AreaTransmissionCommand, Checksum,
    ExecuteCommand, GeofenceCheck, LegType, Message, MessageType, MissionExecuteCommand,
    MissionPlanMode, MissionReport, MissionTransferCommand, Reason, Text, Timestamp,
    TransferStatus, TransferWindow, WindowOrChecksum,
};
use missionlink_protocol::link::retry::AttemptFailure;
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::receiver::{AreaReceiver, MissionReceiver, Received};
use missionlink_protocol::transfer::sender::{mission_command, transfer_command};

// ---- Reading the answers ----

/// The FCC's one answer by #17000 to a message of `original`: accepted, or the reason.
fn ack_of(answers: &[Message], original: MessageType) -> Result<(), Reason> {
    let [Message::MessageAcknowledgement(a)] = answers else {
        panic!("one #17000 expected: {answers:?}");
    };
    assert_eq!(a.original_message_type, original as u16, "{a:?}");
    match a.ack_type {
        AckType::Completed => {
            assert_eq!(a.reject_reason, Some(Reason::None));
            Ok(())
        }
        AckType::Rejected => Err(a.reject_reason.expect("a rejection names its reason")),
        other => panic!("ack type {other:?}"),
    }
}

/// The FCC's one answer by #17000 to a #13000.
fn transfer_ack(answers: &[Message]) -> Result<(), Reason> {
    ack_of(answers, MessageType::MissionTransferCommand)
}

/// The original time stamp of the one #17000 in `answers`.
fn acknowledged_stamp(answers: &[Message]) -> Timestamp {
    match answers {
        [Message::MessageAcknowledgement(a)] => a.original_time_stamp,
        other => panic!("one #17000 expected: {other:?}"),
    }
}

/// A checksum that is not `c`.
fn other_than(c: Checksum) -> Checksum {
    Checksum::new(c.value() ^ 0x0000_0001)
}

// ---- Messages ----

/// #13000 mode 3 (download), edition 2 (with a Transfer Window) or edition 1 (without).
fn mission_download_request(window: Option<TransferWindow>) -> MissionTransferCommand {
    MissionTransferCommand {
        transfer_window: window,
        ..transfer_command(MissionPlanMode::ReceiveMission, None, None)
    }
}

/// #2011 mode 3 (download of all areas), edition 2 (with a Transfer Window) or edition 1.
fn area_download_request(window: Option<TransferWindow>) -> AreaTransmissionCommand {
    AreaTransmissionCommand {
        area_id: Some(0),
        safety_offset: None,
        window_or_checksum: window.map(WindowOrChecksum::TransferWindow),
        ..area_command(AreaTransferMode::InitiateDownload, None)
    }
}

/// #13000 mode 7 (report missions), Mission ID empty (ICD §8).
fn report_request() -> MissionTransferCommand {
    transfer_command(MissionPlanMode::ReportMissions, None, Some(Text::default()))
}

/// #13000 mode 1.
fn clear() -> Message {
    mission_command(MissionPlanMode::ClearMission, None, None)
}

/// #13000 mode 5.
fn cancel() -> Message {
    mission_command(MissionPlanMode::CancelTransfer, None, None)
}

/// An edit of demo mission 2: waypoint 2 at 150 m.
fn edited_waypoint_2() -> Message {
    let mut w = waypoint(2, 3, (48.278, 11.658), LegType::TrackToFix);
    w.altitude = missionlink_interfaces::wire::Altitude::from_metres(150.0).unwrap();
    w.into()
}

// ---- Driving transfers the FCC sends ----

/// Asks for the report (ICD §8), checks its acknowledgement, acknowledges the #50001 and
/// returns it: the report of the active lists, the only entry while staging is not there.
fn report(rig: &mut FccRig) -> MissionReport {
    let mut answers = rig.send_enveloped(report_request());
    assert!(!answers.is_empty(), "the report request is answered");
    let (_, ack) = answers.remove(0);
    assert_eq!(transfer_ack(&[ack]), Ok(()));
    let sent = follow(rig, answers);
    let [Message::MissionReport(r)] = sent.as_slice() else {
        panic!("one #50001 expected: {sent:?}");
    };
    assert_eq!((r.report_index, r.report_count), (1, 1));
    assert_eq!(
        r.mission_id,
        Some(Text::default()),
        "present and empty: the active lists"
    );
    rig.assert_download_complete(DataKind::Report);
    *r
}

/// `r` without its time stamp, to compare a retry with its first attempt.
fn content(r: &MissionReport) -> MissionReport {
    MissionReport {
        time_stamp: Timestamp::default(),
        ..*r
    }
}

/// An FCC with demo mission 1 and its areas active (generations 1, 1), uploaded by edition 1,
/// events drained.
fn with_mission_1() -> FccRig {
    let mut rig = FccRig::new();
    let valid = validated(&mission_1());
    assert_eq!(
        transfer_ack(&rig.upload_mission(&valid.mission, None)),
        Ok(())
    );
    assert_eq!(
        area_status(&rig.upload_areas(&valid.areas, None)),
        (1, Ok(()))
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    rig.events();
    rig
}

/// An FCC restarted at `rig.now` with demo mission 1 and its areas active, and the record that
/// a mission upload was open (`upload_open`).
fn restarted(upload_open: bool) -> FccRig {
    let mut rig = FccRig::new();
    let valid = validated(&mission_1());
    rig.fcc.resume(
        rig.now,
        Resumed {
            mission: Some(valid.mission),
            mission_generation: 1,
            areas: Some(valid.areas),
            area_generation: 1,
            mission_upload_open: upload_open,
            ..Resumed::default()
        },
    );
    rig
}

/// 1 ms before `at`.
fn just_before(at: Instant) -> Instant {
    Instant::from_micros(at.micros() - 1_000)
}

// ---- Closers' checksums ----

/// ICD §11 upload: a closer whose checksum is that of the list the FCC assembled is handled as
/// in edition 1: accepted, the list activated.
#[test]
fn a_closer_with_the_checksum_of_the_list_assembled_activates_it() {
    let mut rig = FccRig::new();
    let valid = validated(&mission_2());
    let answers = rig.upload_mission(&valid.mission, Some(mission_checksum(&valid.mission)));
    assert_eq!(transfer_ack(&answers), Ok(()));
    assert_eq!(rig.fcc.active_mission(), Some(&valid.mission));
    assert_eq!(
        rig.events(),
        [
            FccEvent::MissionUploadOpened,
            FccEvent::MissionActivated { generation: 1 },
            FccEvent::MissionUploadClosed,
        ]
    );
    let answers = rig.upload_areas(&valid.areas, Some(areas_checksum(&valid.areas)));
    assert_eq!(area_status(&answers), (3, Ok(())));
    assert_eq!(rig.fcc.active_areas(), Some(&valid.areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), [FccEvent::AreasActivated { generation: 1 }]);
}

/// ICD §11 upload: the GCS means mission 2 but its checksum is not that of the list assembled:
/// refused with `IntegrityMismatch` (#17000 type 3 reason 15), the active mission as it was, the
/// buffer as it was and the upload open (ICD §10.3: a closer sent right behind its data may
/// have overtaken one of them). Only a closer whose checksum names the list assembled closes
/// it; the GCS's cancel empties it.
#[test]
fn a_mission_closer_whose_checksum_differs_is_refused_and_the_buffer_stays() {
    let mut rig = with_mission_1();
    let before = rig.fcc.active_mission().cloned().unwrap();
    let new = validated(&mission_2()).mission;
    let answers =
        rig.upload_mission_into_empty_buffer(&new, Some(other_than(mission_checksum(&new))));
    assert_eq!(transfer_ack(&answers), Err(Reason::IntegrityMismatch));
    assert_eq!(rig.fcc.active_mission(), Some(&before));
    assert_eq!(rig.fcc.generations(), (1, 1));
    // Opened by mode 10 and still open: nothing activated.
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    // The same closer again: the same answer from the memory (ICD §11), nothing changes.
    assert_eq!(
        transfer_ack(&rig.send(transmit(&new, Some(other_than(mission_checksum(&new)))))),
        Err(Reason::IntegrityMismatch)
    );
    assert_eq!(rig.fcc.active_mission(), Some(&before));
    assert_eq!(rig.events(), []);
    // The GCS cancels (ICD §5): the buffer is emptied and the upload closed; the closer with
    // the right checksum, without the messages, finds nothing of mission 2 to assemble.
    assert_eq!(transfer_ack(&rig.send(cancel())), Ok(()));
    assert_eq!(
        rig.events(),
        [
            FccEvent::UploadAbandoned {
                kind: DataKind::Mission,
                reason: None
            },
            FccEvent::MissionUploadClosed
        ]
    );
    assert_ne!(
        transfer_ack(&rig.send(transmit(&new, Some(mission_checksum(&new))))),
        Ok(())
    );
    assert_eq!(rig.fcc.active_mission(), Some(&before));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert!(
        !rig.events().iter().any(|e| matches!(
            e,
            FccEvent::MissionActivated { .. } | FccEvent::MissionCleared
        )),
        "no list changes"
    );
}

/// ICD §10.3, §11: a closer that overtook a data message of its upload (here the route, the
/// last) finds an incomplete list and is refused, changing nothing; the data message stored,
/// the same closer (a new time stamp) closes the upload with exactly the list it names.
#[test]
fn a_closer_that_overtook_its_data_is_refused_and_closes_after_them() {
    let mut rig = with_mission_1();
    let new = validated(&mission_2()).mission;
    let sum = Some(mission_checksum(&new));
    let mut messages: Vec<Message> = new.messages().collect();
    let last = messages.pop().unwrap();
    assert_eq!(transfer_ack(&rig.send(clear())), Ok(()));
    for m in messages {
        assert_eq!(ack_of(&rig.send(m.clone()), m.message_type()), Ok(()));
    }
    assert_eq!(
        transfer_ack(&rig.send(transmit(&new, sum))),
        Err(Reason::MissingInitial)
    );
    assert_ne!(rig.fcc.active_mission(), Some(&new));
    assert_eq!(ack_of(&rig.send(last.clone()), last.message_type()), Ok(()));
    assert_eq!(transfer_ack(&rig.send(transmit(&new, sum))), Ok(()));
    assert_eq!(rig.fcc.active_mission(), Some(&new));
}

/// ICD §11 upload, areas: refused with #3012 status 0 reason 15 (loop count 0), the active areas
/// as they were, the transfer open with its buffer (ICD §10.3), until the GCS cancels it.
#[test]
fn an_area_closer_whose_checksum_differs_is_refused() {
    let mut rig = with_mission_1();
    let before = rig.fcc.active_areas().cloned().unwrap();
    let new = validated(&mission_2()).areas;
    let answers = rig.upload_areas(&new, Some(other_than(areas_checksum(&new))));
    assert_eq!(area_status(&answers), (0, Err(Reason::IntegrityMismatch)));
    assert_eq!(rig.fcc.active_areas(), Some(&before));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
    assert_eq!(
        ack_of(
            &rig.send(new.areas[0].clone()),
            MessageType::AreaPolygonLoopSegment
        ),
        Ok(()),
        "still open"
    );
    assert_eq!(
        ack_of(
            &rig.send(area_command(AreaTransferMode::Cancel, None)),
            MessageType::AreaTransmissionCommand
        ),
        Ok(())
    );
    assert_eq!(
        ack_of(
            &rig.send(new.areas[0].clone()),
            MessageType::AreaPolygonLoopSegment
        ),
        Err(Reason::WrongState),
        "cancelled: no transfer to go to"
    );
    assert_eq!(
        rig.events(),
        [FccEvent::UploadAbandoned {
            kind: DataKind::Areas,
            reason: None
        }]
    );
    // The areas of mission 1 again, with the right checksum: accepted, nothing changes.
    let answers = rig.upload_areas(&before, Some(areas_checksum(&before)));
    assert_eq!(area_status(&answers), (1, Ok(())));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// The clear (#13000 mode 1) deletes the waypoint buffer and the active waypoint list at once
/// (paper §3.1, ICD §5.1 step 1): one activation of the empty list. The empty list has no
/// canonical form, so mode 2 with Waypoint Number 0 and a checksum is `Malformed` and changes
/// nothing; without the checksum it closes the upload the clear opened, the list empty as it is.
#[test]
fn the_clear_deletes_the_active_mission_and_its_closer_carries_no_checksum() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_mission().cloned().unwrap();
    rig.events();
    assert_eq!(transfer_ack(&rig.send(clear())), Ok(()));
    assert_eq!(rig.fcc.active_mission(), None);
    assert_eq!(rig.fcc.waypoint_list().waypoints(), []);
    assert_eq!(rig.fcc.generations(), (2, 1));
    assert_eq!(
        rig.events(),
        [FccEvent::MissionCleared, FccEvent::MissionUploadOpened]
    );
    let with_checksum = MissionTransferCommand {
        mission_checksum: Some(mission_checksum(&before)),
        ..transfer_command(MissionPlanMode::TransmitMission, Some(0), None)
    };
    assert_eq!(
        transfer_ack(&rig.send(with_checksum)),
        Err(Reason::Malformed)
    );
    assert_eq!(rig.fcc.generations(), (2, 1));
    assert_eq!(rig.events(), []);
    let without = transfer_command(MissionPlanMode::TransmitMission, Some(0), None);
    assert_eq!(transfer_ack(&rig.send(without)), Ok(()));
    assert_eq!(rig.fcc.active_mission(), None);
    assert_eq!(rig.fcc.generations(), (2, 1));
    assert_eq!(rig.events(), [FccEvent::MissionUploadClosed]);
}

// ---- Idempotent closers ----

/// ICD §11: the retry of a closer (same content, new time stamp) whose answer was lost gets the
/// same success and changes nothing. Acknowledgements, reports and #50000 in between do not end
/// the memory. For the areas the memory is what makes the retry succeed: without it there is no
/// transfer open and the retry is refused (`WrongState`).
#[test]
fn a_retried_closer_gets_the_same_success_and_changes_nothing() {
    let mut rig = FccRig::new();
    let valid = validated(&mission_2());
    let (m, a) = (
        mission_checksum(&valid.mission),
        areas_checksum(&valid.areas),
    );
    let first = rig.upload_mission(&valid.mission, Some(m));
    assert_eq!(transfer_ack(&first), Ok(()));
    rig.events();
    let retry = rig.send(transmit(&valid.mission, Some(m)));
    assert_eq!(transfer_ack(&retry), Ok(()));
    assert_ne!(
        acknowledged_stamp(&retry),
        acknowledged_stamp(&first),
        "the answer matches the retry's own time stamp"
    );
    assert_eq!(rig.fcc.active_mission(), Some(&valid.mission));
    assert_eq!(rig.fcc.generations(), (1, 0));
    assert_eq!(rig.events(), []);

    assert_eq!(
        area_status(&rig.upload_areas(&valid.areas, Some(a))),
        (3, Ok(()))
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    rig.events();
    // In between: a report (its #50001 acknowledged) and an accepted #50000.
    report(&mut rig);
    rig.fcc.handle_progress(rig.now, &on_ground_at(TROL));
    rig.out(); // #4001 of the first progress
    let execute = MissionExecuteCommand {
        time_stamp: Timestamp::default(),
        command: ExecuteCommand::Execute,
        mission_id: None,
    };
    assert_eq!(
        ack_of(&rig.send(execute), MessageType::MissionExecuteCommand),
        Ok(())
    );
    assert_eq!(rig.events(), [FccEvent::Execute(ExecuteCommand::Execute)]);
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, Some(a)))),
        (3, Ok(()))
    );
    assert_eq!(rig.fcc.active_mission(), Some(&valid.mission));
    assert_eq!(rig.fcc.active_areas(), Some(&valid.areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// ICD §11: "This holds for edition-1 closers too" (no checksum).
#[test]
fn edition_1_closers_are_idempotent_too() {
    let mut rig = FccRig::new().with_mission_2();
    let valid = validated(&mission_2());
    rig.events();
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, None))),
        (3, Ok(()))
    );
    assert_eq!(rig.fcc.active_areas(), Some(&valid.areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// ICD §11: a refusal is repeated too. Without the memory the mission closer's retry would be
/// an edit of the active mission 1 (one waypoint, `CountMismatch`) and the area closer's would
/// find no transfer open (`WrongState`): the GCS would report another cause than the real one.
#[test]
fn a_retried_closer_gets_the_same_refusal() {
    let mut rig = with_mission_1();
    let before = (
        rig.fcc.active_mission().cloned(),
        rig.fcc.active_areas().cloned(),
    );
    let new = validated(&mission_2());
    let (m, a) = (
        other_than(mission_checksum(&new.mission)),
        other_than(areas_checksum(&new.areas)),
    );
    assert_eq!(
        transfer_ack(&rig.upload_mission_into_empty_buffer(&new.mission, Some(m))),
        Err(Reason::IntegrityMismatch)
    );
    rig.events();
    assert_eq!(
        transfer_ack(&rig.send(transmit(&new.mission, Some(m)))),
        Err(Reason::IntegrityMismatch)
    );
    assert_eq!(rig.events(), []);
    assert_eq!(
        area_status(&rig.upload_areas(&new.areas, Some(a))),
        (0, Err(Reason::IntegrityMismatch))
    );
    assert_eq!(
        area_status(&rig.send(area_closer(&new.areas, Some(a)))),
        (0, Err(Reason::IntegrityMismatch))
    );
    assert_eq!(
        (
            rig.fcc.active_mission().cloned(),
            rig.fcc.active_areas().cloned()
        ),
        before
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// ICD §11: the FCC remembers the last closer of each kind of list. The area upload after the
/// mission's (its opener and data) leaves the mission closer's memory, so that the GCS may send
/// the area opener beside the mission upload (ICD §10.3): both retries get their answers again
/// and nothing changes. (Before the memory was kept per kind, the mission closer's retry was
/// judged afresh here and the area closer's refused `WrongState`.)
#[test]
fn the_last_closer_of_each_kind_is_remembered() {
    let mut rig = FccRig::new().with_mission_2();
    let valid = validated(&mission_2());
    rig.events();
    assert_eq!(
        transfer_ack(&rig.send(transmit(&valid.mission, None))),
        Ok(())
    );
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, None))),
        (valid.areas.areas.len() as u8, Ok(()))
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
    // A mission opener ends the mission closer's memory only (mode 10 with an ID that holds
    // nothing: it empties the buffer and changes no list, which would end both).
    rig.accepted(mission_command(
        MissionPlanMode::LoadWaypointBuffer,
        None,
        Text::new("no-such-mission").ok(),
    ));
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, None))),
        (valid.areas.areas.len() as u8, Ok(()))
    );
    assert_eq!(
        transfer_ack(&rig.send(transmit(&valid.mission, None))),
        Err(Reason::CountMismatch),
        "judged afresh: the buffer is empty"
    );
}

/// ICD §11: accepting a data message or an opener ends the memory; the same closer is then
/// judged afresh. A refused opener does not end it.
#[test]
fn an_accepted_data_message_or_opener_ends_the_memory() {
    let mut rig = FccRig::new();
    let valid = validated(&mission_2());
    let (m, a) = (
        mission_checksum(&valid.mission),
        areas_checksum(&valid.areas),
    );
    assert_eq!(
        transfer_ack(&rig.upload_mission(&valid.mission, Some(m))),
        Ok(())
    );
    rig.events();
    // A data message (an edit of waypoint 2): the closer's checksum no longer describes the
    // buffer, and the closer, judged afresh, is refused instead of repeated.
    assert_eq!(
        ack_of(
            &rig.send(edited_waypoint_2()),
            MessageType::UaPositionWaypoint
        ),
        Ok(())
    );
    assert_eq!(
        transfer_ack(&rig.send(transmit(&valid.mission, Some(m)))),
        Err(Reason::IntegrityMismatch)
    );
    assert_eq!(rig.fcc.active_mission(), Some(&valid.mission));
    assert_eq!(rig.fcc.generations(), (1, 0));
    // The edit stays open (ICD §10.3) until cancelled.
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    assert_eq!(transfer_ack(&rig.send(cancel())), Ok(()));
    assert_eq!(
        rig.events(),
        [
            FccEvent::UploadAbandoned {
                kind: DataKind::Mission,
                reason: None
            },
            FccEvent::MissionUploadClosed
        ]
    );

    assert_eq!(
        area_status(&rig.upload_areas(&valid.areas, Some(a))),
        (3, Ok(()))
    );
    rig.events();
    // A refused opener (12 areas: `Capacity`) leaves the memory as it was.
    assert_eq!(
        ack_of(
            &rig.send(area_command(AreaTransferMode::InitiateUpload, Some(12))),
            MessageType::AreaTransmissionCommand
        ),
        Err(Reason::Capacity)
    );
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, Some(a)))),
        (3, Ok(()))
    );
    // An accepted opener ends it: the closer now closes the new, empty transfer.
    assert_eq!(
        ack_of(
            &rig.send(area_command(AreaTransferMode::InitiateUpload, Some(3))),
            MessageType::AreaTransmissionCommand
        ),
        Ok(())
    );
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, Some(a)))),
        (0, Err(Reason::CountMismatch))
    );
    assert_eq!(rig.fcc.active_areas(), Some(&valid.areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// This project's choice (transfer::closer): a clear of the areas ends the memory, since "valid
/// and active" of the last area closer is no longer true. The retry is judged afresh: no
/// transfer open.
#[test]
fn a_clear_of_the_areas_ends_the_memory() {
    let mut rig = FccRig::new().with_mission_2();
    let valid = validated(&mission_2());
    rig.events();
    assert_eq!(
        ack_of(
            &rig.send(area_command(AreaTransferMode::ClearAreas, None)),
            MessageType::AreaTransmissionCommand
        ),
        Ok(())
    );
    assert_eq!(rig.fcc.active_areas(), None);
    assert_eq!(rig.fcc.generations(), (1, 2));
    assert_eq!(rig.events(), [FccEvent::AreasCleared]);
    assert_eq!(
        area_status(&rig.send(area_closer(&valid.areas, None))),
        (0, Err(Reason::WrongState))
    );
    assert_eq!(rig.fcc.active_areas(), None);
    assert_eq!(rig.fcc.generations(), (1, 2));
    assert_eq!(rig.events(), []);
}

// ---- Restart safety without checksum ----

/// Restart safety: a partition restarted with the record of an open mission upload refuses the rest
/// of that upload (every data message and the transmit, `WrongState`), each refusal holding it
/// for another transfer timeout, until the GCS opens a new upload with a clear. The record
/// stays: a clear opens an upload, so nothing is told to the driver until it closes.
#[test]
fn a_restart_holds_the_cut_upload_until_a_clear() {
    let mut rig = restarted(true);
    let before = (
        rig.fcc.active_mission().cloned(),
        rig.fcc.active_areas().cloned(),
    );
    assert_eq!(rig.events(), [], "the driver holds the record already");
    assert_eq!(rig.fcc.poll_timeout(), Some(rig.now + TRANSFER_TIMEOUT));
    let new = validated(&mission_2()).mission;
    // The rest of the cut upload, as the GCS goes on sending it.
    for message in new.messages() {
        let kind = message.message_type();
        assert_eq!(
            ack_of(&rig.send(message), kind),
            Err(Reason::WrongState),
            "{kind:?}"
        );
        assert_eq!(rig.fcc.poll_timeout(), Some(rig.now + TRANSFER_TIMEOUT));
    }
    assert_eq!(
        transfer_ack(&rig.send(transmit(&new, None))),
        Err(Reason::WrongState)
    );
    assert_eq!(
        (
            rig.fcc.active_mission().cloned(),
            rig.fcc.active_areas().cloned()
        ),
        before
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
    // The GCS starts over: the clear deletes mission 1 and opens a new upload, which
    // activates mission 2.
    assert_eq!(transfer_ack(&rig.upload_mission(&new, None)), Ok(()));
    assert_eq!(rig.fcc.active_mission(), Some(&new));
    assert_eq!(rig.fcc.generations(), (3, 1));
    assert_eq!(
        rig.events(),
        [
            FccEvent::MissionCleared,
            FccEvent::MissionActivated { generation: 3 },
            FccEvent::MissionUploadClosed
        ]
    );
}

/// Restart safety: #13000 mode 5 ends the interruption (an area cancel does not); then an upload
/// without clear is an edit of the active mission again.
#[test]
fn a_cancel_ends_the_interruption() {
    let mut rig = restarted(true);
    let before = rig.fcc.active_mission().cloned().unwrap();
    assert_eq!(
        ack_of(
            &rig.send(edited_waypoint_2()),
            MessageType::UaPositionWaypoint
        ),
        Err(Reason::WrongState)
    );
    assert_eq!(
        ack_of(
            &rig.send(area_command(AreaTransferMode::Cancel, None)),
            MessageType::AreaTransmissionCommand
        ),
        Ok(())
    );
    assert_eq!(rig.events(), []);
    assert_eq!(
        ack_of(
            &rig.send(edited_waypoint_2()),
            MessageType::UaPositionWaypoint
        ),
        Err(Reason::WrongState),
        "an area cancel ends no mission upload"
    );
    assert_eq!(transfer_ack(&rig.send(cancel())), Ok(()));
    assert_eq!(rig.events(), [FccEvent::MissionUploadClosed]);
    assert_eq!(rig.fcc.active_mission(), Some(&before));
    assert_eq!(rig.fcc.generations(), (1, 1));
    // An edit of mission 1's only waypoint is accepted now.
    let mut w1 = waypoint(1, 0, CCP, LegType::TrackToFix);
    w1.altitude = missionlink_interfaces::wire::Altitude::from_metres(150.0).unwrap();
    assert_eq!(
        ack_of(&rig.send(w1), MessageType::UaPositionWaypoint),
        Ok(())
    );
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    assert_eq!(transfer_ack(&rig.send(transmit(&before, None))), Ok(()));
    let after = rig.fcc.active_mission().unwrap();
    assert_eq!(after.waypoints[0].waypoint.altitude.metres(), 150.0);
    assert_eq!(after.take_off, before.take_off);
    assert_eq!(
        rig.events(),
        [
            FccEvent::MissionActivated { generation: 2 },
            FccEvent::MissionUploadClosed
        ]
    );
}

/// Restart safety: the interruption ends after the transfer timeout of silence from the cut upload
/// (counted from its last refused message), as the upload itself would have been abandoned.
#[test]
fn silence_for_the_transfer_timeout_ends_the_interruption() {
    let mut rig = restarted(true);
    assert_eq!(
        ack_of(
            &rig.send(edited_waypoint_2()),
            MessageType::UaPositionWaypoint
        ),
        Err(Reason::WrongState)
    );
    let end = rig.now + TRANSFER_TIMEOUT;
    assert_eq!(rig.fcc.poll_timeout(), Some(end));
    assert!(rig.advance_to(just_before(end)).is_empty());
    assert_eq!(rig.events(), [], "still held");
    assert!(rig.advance_to(end).is_empty());
    assert_eq!(rig.events(), [FccEvent::MissionUploadClosed]);
    assert_eq!(rig.fcc.poll_timeout(), None);
    // An edit now opens an ordinary upload, itself abandoned after the transfer timeout.
    let mut w1 = waypoint(1, 0, CCP, LegType::TrackToFix);
    w1.altitude = missionlink_interfaces::wire::Altitude::from_metres(150.0).unwrap();
    assert_eq!(
        ack_of(&rig.send(w1), MessageType::UaPositionWaypoint),
        Ok(())
    );
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    let end = rig.now + TRANSFER_TIMEOUT;
    assert_eq!(rig.fcc.poll_timeout(), Some(end));
    assert!(rig.advance_to(end).is_empty());
    assert_eq!(
        rig.events(),
        [
            FccEvent::UploadAbandoned {
                kind: DataKind::Mission,
                reason: None
            },
            FccEvent::MissionUploadClosed
        ]
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// A restart without the record holds nothing: an upload without clear is an edit.
#[test]
fn a_restart_without_an_open_upload_holds_nothing() {
    let mut rig = restarted(false);
    assert_eq!(rig.fcc.poll_timeout(), None);
    assert_eq!(
        ack_of(
            &rig.send(waypoint(1, 0, CCP, LegType::TrackToFix)),
            MessageType::UaPositionWaypoint
        ),
        Ok(())
    );
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
}

/// `MissionUploadOpened` and `MissionUploadClosed` come exactly when a mission upload opens or
/// closes: a clear (which also deletes the active list) or an edit opens it; a closer (accepted or refused for its checksum), a
/// cancel or the transfer timeout closes it; a refused clear, the messages inside an upload,
/// area uploads and downloads say nothing.
#[test]
fn upload_events_come_exactly_when_an_upload_opens_or_closes() {
    let mut rig = FccRig::new();
    let valid = validated(&mission_2());
    rig.fcc.set_automation_state(&flying());
    assert_eq!(
        transfer_ack(&rig.send(clear())),
        Err(Reason::GuidanceActive)
    );
    assert_eq!(rig.events(), []);
    rig.fcc.set_automation_state(&on_ground());

    // Clear, data messages, closer.
    assert_eq!(transfer_ack(&rig.send(clear())), Ok(()));
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    for m in valid.mission.messages() {
        rig.accepted(m);
        assert_eq!(rig.events(), []);
    }
    assert_eq!(
        transfer_ack(&rig.send(transmit(&valid.mission, None))),
        Ok(())
    );
    assert_eq!(
        rig.events(),
        [
            FccEvent::MissionActivated { generation: 1 },
            FccEvent::MissionUploadClosed
        ]
    );

    // An edit, cancelled.
    rig.accepted(edited_waypoint_2());
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    assert_eq!(transfer_ack(&rig.send(cancel())), Ok(()));
    assert_eq!(
        rig.events(),
        [
            FccEvent::UploadAbandoned {
                kind: DataKind::Mission,
                reason: None
            },
            FccEvent::MissionUploadClosed
        ]
    );

    // An edit, timed out.
    rig.accepted(edited_waypoint_2());
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    let end = rig.now + TRANSFER_TIMEOUT;
    rig.advance_to(just_before(end));
    assert_eq!(rig.events(), []);
    rig.advance_to(end);
    assert_eq!(
        rig.events(),
        [
            FccEvent::UploadAbandoned {
                kind: DataKind::Mission,
                reason: None
            },
            FccEvent::MissionUploadClosed
        ]
    );

    // A closer refused for its checksum leaves the upload (opened by mode 10) open, for data
    // still on their way (ICD §10.3); the cancel closes it.
    let answers = rig.upload_mission_into_empty_buffer(
        &valid.mission,
        Some(other_than(mission_checksum(&valid.mission))),
    );
    assert_eq!(transfer_ack(&answers), Err(Reason::IntegrityMismatch));
    assert_eq!(rig.events(), [FccEvent::MissionUploadOpened]);
    assert_eq!(transfer_ack(&rig.send(cancel())), Ok(()));
    assert_eq!(
        rig.events(),
        [
            FccEvent::UploadAbandoned {
                kind: DataKind::Mission,
                reason: None
            },
            FccEvent::MissionUploadClosed
        ]
    );

    // Areas up and down, and a mission download: no mission upload.
    assert_eq!(
        area_status(&rig.upload_areas(&valid.areas, None)),
        (3, Ok(()))
    );
    assert_eq!(rig.events(), [FccEvent::AreasActivated { generation: 1 }]);
    let mut answers = rig.send_enveloped(mission_download_request(None));
    let (_, ack) = answers.remove(0);
    assert_eq!(transfer_ack(&[ack]), Ok(()));
    follow(&mut rig, answers);
    rig.assert_download_complete(DataKind::Mission);

    // The clear deletes the active mission and opens an upload; transmit with Waypoint Number
    // 0 closes it.
    assert_eq!(transfer_ack(&rig.send(clear())), Ok(()));
    assert_eq!(
        rig.events(),
        [FccEvent::MissionCleared, FccEvent::MissionUploadOpened]
    );
    assert_eq!(
        transfer_ack(&rig.send(transfer_command(
            MissionPlanMode::TransmitMission,
            Some(0),
            None
        ))),
        Ok(())
    );
    assert_eq!(rig.events(), [FccEvent::MissionUploadClosed]);
    assert_eq!(rig.fcc.generations(), (2, 1));
}

// ---- Downloads ----

/// ICD §11 download, §10.2: to an edition-2 request (with a Transfer Window) the #14000 status 1
/// carries the checksum of the mission sent, and the GCS's receiver, comparing it with what it
/// received, completes; to an edition-1 request the #14000 carries none ("edition-1 sequences
/// unchanged"), the rest of the download the same.
#[test]
fn an_edition_2_mission_download_carries_the_checksum() {
    let mut rig = FccRig::new().with_mission_2();
    let active = rig.fcc.active_mission().cloned().unwrap();
    rig.events();
    let mut downloads = Vec::new();
    for window in [window(), None] {
        let mut answers = rig.send_enveloped(mission_download_request(window));
        let (_, ack) = answers.remove(0);
        assert_eq!(transfer_ack(&[ack]), Ok(()));
        let sent = follow(&mut rig, answers);
        rig.assert_download_complete(DataKind::Mission);
        let Some(Message::MissionUploadDownloadStatus(status)) = sent.last() else {
            panic!("the download ends with #14000: {sent:?}");
        };
        assert_eq!(status.status, TransferStatus::Complete);
        let expected = window.map(|_| mission_checksum(&active));
        assert_eq!(status.mission_checksum, expected, "window {window:?}");
        // What the GCS does with it: the same receiver, the same comparison.
        let mut gcs = MissionReceiver::new(TRANSFER_TIMEOUT);
        gcs.begin(rig.now);
        let (data, closer) = sent.split_at(sent.len() - 1);
        for m in data {
            assert_eq!(gcs.handle(rig.now, m), Ok(Received::Stored), "{m:?}");
        }
        assert_eq!(gcs.handle(rig.now, &closer[0]), Ok(Received::Complete));
        assert_eq!(gcs.take().as_ref(), Some(&active));
        downloads.push(
            sent.iter()
                .map(|m| {
                    let mut m = m.clone();
                    m.set_time_stamp(Timestamp::default());
                    m
                })
                .collect::<Vec<_>>(),
        );
    }
    // Edition 1: the same messages, only the checksum absent.
    if let Some(Message::MissionUploadDownloadStatus(s)) = downloads[0].last_mut() {
        s.mission_checksum = None;
    }
    assert_eq!(downloads[0], downloads[1]);
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// ICD §11 download, areas: to an edition-2 #2011 mode 3 (field 7 a Transfer Window) the #2011
/// mode 4 carries the checksum of the list sent; to an edition-1 request none.
#[test]
fn an_edition_2_area_download_carries_the_checksum() {
    let mut rig = FccRig::new().with_mission_2();
    let active = rig.fcc.active_areas().cloned().unwrap();
    rig.events();
    for window in [window(), None] {
        let answers = rig.send_enveloped(area_download_request(window));
        let sent = follow_area_download(&mut rig, answers, 3);
        let Some(Message::AreaTransmissionCommand(done)) = sent.last() else {
            panic!("the download ends with #2011 mode 4: {sent:?}");
        };
        assert_eq!(done.mode, AreaTransferMode::DownloadComplete);
        assert_eq!(done.loop_count, Some(3));
        let expected = window.map(|_| WindowOrChecksum::AreaChecksum(areas_checksum(&active)));
        assert_eq!(done.window_or_checksum, expected, "window {window:?}");
        let mut gcs = AreaReceiver::new(TRANSFER_TIMEOUT);
        for m in &sent[..sent.len() - 1] {
            assert_eq!(gcs.handle(rig.now, m), Ok(Received::Stored), "{m:?}");
        }
        assert_eq!(
            gcs.handle(rig.now, &sent[sent.len() - 1]),
            Ok(Received::Complete)
        );
        assert_eq!(gcs.take().as_ref(), Some(&active));
    }
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// ICD §4 #2011 field 3, "mode 3: 0 = all areas, else that one": a download of one Area ID
/// sends that area alone, its #3013 names it, and the checksum is of what was sent; an Area ID
/// the list does not hold is answered by #3013 aborted.
#[test]
fn an_area_download_of_one_area_id_sends_that_area() {
    let mut rig = FccRig::new().with_mission_2();
    let active = rig.fcc.active_areas().cloned().unwrap();
    let wanted = active.areas[1].area_id;
    rig.events();
    let request = AreaTransmissionCommand {
        area_id: Some(wanted),
        ..area_download_request(window())
    };
    let answers = rig.send_enveloped(request);
    let sent = follow(&mut rig, answers);
    let Some(Message::AreaTransmissionStatus(ready)) = sent.first() else {
        panic!("the download starts with #3013: {sent:?}");
    };
    assert_eq!(
        (ready.status, ready.area_id, ready.loop_count),
        (AreaDownloadStatus::Ready, wanted, 1)
    );
    let areas: Vec<_> = sent
        .iter()
        .filter_map(|m| match m {
            Message::AreaPolygonLoopSegment(a) => Some(a.area_id),
            _ => None,
        })
        .collect();
    assert_eq!(areas, [wanted]);
    let one = active.only(wanted).unwrap();
    let Some(Message::AreaTransmissionCommand(done)) = sent.last() else {
        panic!("the download ends with #2011 mode 4: {sent:?}");
    };
    assert_eq!(done.loop_count, Some(1));
    assert_eq!(
        done.window_or_checksum,
        Some(WindowOrChecksum::AreaChecksum(areas_checksum(&one)))
    );

    let missing = AreaTransmissionCommand {
        area_id: Some(999),
        ..request
    };
    let sent = rig.send(missing);
    let [Message::AreaTransmissionStatus(aborted)] = sent.as_slice() else {
        panic!("only #3013 aborted: {sent:?}");
    };
    assert_eq!(
        (aborted.status, aborted.area_id, aborted.loop_count),
        (AreaDownloadStatus::Aborted, 999, 0)
    );
    assert_eq!(rig.fcc.active_areas(), Some(&active), "nothing changed");
}

// ---- The report (#13000 mode 7, #50001) ----

/// ICD §8: with no lists the report says so: counts 0, check not run, no checksums.
#[test]
fn the_report_without_lists() {
    let mut rig = FccRig::new();
    let r = report(&mut rig);
    assert_eq!((r.waypoint_count, r.area_count), (0, 0));
    assert_eq!((r.geofence_check, r.reason), (GeofenceCheck::NotRun, None));
    assert_eq!((r.mission_checksum, r.area_checksum), (None, None));
    assert_eq!(rig.fcc.generations(), (0, 0));
}

/// ICD §8: the report of the active lists: their counts and checksums, and the onboard
/// geofence check (ICD §7) from where navigation says the aircraft is: not run without a
/// position, passed from TROL, failed with `GeofenceViolation` from south of the polygonal
/// no-fly-zone. Asking changes nothing.
#[test]
fn the_report_of_the_active_lists() {
    let mut rig = FccRig::new().with_mission_2();
    let (mission, areas) = (
        rig.fcc.active_mission().cloned().unwrap(),
        rig.fcc.active_areas().cloned().unwrap(),
    );
    rig.events();
    let checksums = (
        Some(mission_checksum(&mission)),
        Some(areas_checksum(&areas)),
    );
    let r = report(&mut rig);
    assert_eq!((r.waypoint_count, r.area_count), (3, 3));
    assert_eq!((r.geofence_check, r.reason), (GeofenceCheck::NotRun, None));
    assert_eq!((r.mission_checksum, r.area_checksum), checksums);

    rig.fcc.handle_progress(rig.now, &on_ground_at(TROL));
    rig.out(); // #4001 of the first progress
    let r = report(&mut rig);
    assert_eq!((r.geofence_check, r.reason), (GeofenceCheck::Passed, None));
    assert_eq!((r.mission_checksum, r.area_checksum), checksums);

    // The direct way to CCP runs through the polygonal no-fly-zone.
    rig.fcc
        .handle_progress(rig.now, &on_ground_at((48.258, 11.643)));
    rig.out();
    let r = report(&mut rig);
    assert_eq!(
        (r.geofence_check, r.reason),
        (GeofenceCheck::Failed, Some(Reason::GeofenceViolation))
    );
    assert_eq!((r.waypoint_count, r.area_count), (3, 3));
    assert_eq!((r.mission_checksum, r.area_checksum), checksums);
    assert_eq!(rig.fcc.active_mission(), Some(&mission));
    assert_eq!(rig.fcc.active_areas(), Some(&areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// ICD §8: the check is not run while a list is missing, even with a position; the checksum of
/// the missing list is absent.
#[test]
fn the_report_runs_no_check_without_both_lists() {
    let valid = validated(&mission_2());
    let mut only_mission = FccRig::new();
    assert_eq!(
        transfer_ack(&only_mission.upload_mission(&valid.mission, None)),
        Ok(())
    );
    let mut only_areas = FccRig::new();
    assert_eq!(
        area_status(&only_areas.upload_areas(&valid.areas, None)),
        (3, Ok(()))
    );
    for rig in [&mut only_mission, &mut only_areas] {
        rig.events();
        rig.fcc.handle_progress(rig.now, &on_ground_at(TROL));
        rig.out();
    }
    let r = report(&mut only_mission);
    assert_eq!((r.waypoint_count, r.area_count), (3, 0));
    assert_eq!((r.geofence_check, r.reason), (GeofenceCheck::NotRun, None));
    assert_eq!(
        (r.mission_checksum, r.area_checksum),
        (Some(mission_checksum(&valid.mission)), None)
    );
    let r = report(&mut only_areas);
    assert_eq!((r.waypoint_count, r.area_count), (0, 3));
    assert_eq!((r.geofence_check, r.reason), (GeofenceCheck::NotRun, None));
    assert_eq!(
        (r.mission_checksum, r.area_checksum),
        (None, Some(areas_checksum(&valid.areas)))
    );
}

/// ICD §8: each #50001 is acknowledged by the GCS as a download message is, with the timeout and
/// retry of §5: no answer within the ack timeout, or a rejection, sends it once more with a new
/// time stamp; a second failure fails the report (`DownloadFailed`), an answer completes it.
#[test]
fn the_report_is_retried_as_downloads_are() {
    let mut rig = FccRig::new().with_mission_2();
    rig.events();

    // Twice no answer: failed.
    let answers = rig.send_enveloped(report_request());
    let [(_, ack), (envelope, Message::MissionReport(first))] = answers.as_slice() else {
        panic!("#17000 and #50001 expected: {answers:?}");
    };
    assert_eq!(transfer_ack(std::slice::from_ref(ack)), Ok(()));
    assert!(envelope.ack_requested);
    let deadline = rig.now + ACK_TIMEOUT;
    assert_eq!(rig.fcc.poll_timeout(), Some(deadline));
    assert!(rig.advance_to(just_before(deadline)).is_empty());
    let retried = rig.advance_to(deadline);
    let [(envelope, Message::MissionReport(retry))] = retried.as_slice() else {
        panic!("the #50001 again expected: {retried:?}");
    };
    assert!(envelope.ack_requested);
    assert_ne!(
        retry.time_stamp, first.time_stamp,
        "a retry has a new stamp"
    );
    assert_eq!(content(retry), content(first));
    assert_eq!(rig.events(), []);
    let deadline = deadline + ACK_TIMEOUT;
    assert_eq!(rig.fcc.poll_timeout(), Some(deadline));
    assert!(
        rig.advance_to(deadline).is_empty(),
        "the report has no abandon message"
    );
    let events = rig.events();
    let [
        FccEvent::DownloadFailed {
            kind: DataKind::Report,
            error,
        },
    ] = events.as_slice()
    else {
        panic!("the report fails: {events:?}");
    };
    assert_eq!(error.message_type, MessageType::MissionReport);
    assert_eq!(
        (error.first, error.second),
        (AttemptFailure::Timeout, Some(AttemptFailure::Timeout))
    );
    assert_eq!(rig.fcc.poll_timeout(), None);

    // Rejected once, then acknowledged: complete.
    let mut answers = rig.send_enveloped(report_request());
    let (_, ack) = answers.remove(0);
    assert_eq!(transfer_ack(&[ack]), Ok(()));
    let [(_, first)] = answers.as_slice() else {
        panic!("one #50001 expected: {answers:?}");
    };
    let retried = rig.acknowledge(first, Err(Reason::WrongState));
    let [(envelope, retry @ Message::MissionReport(_))] = retried.as_slice() else {
        panic!("the #50001 again expected: {retried:?}");
    };
    assert!(envelope.ack_requested);
    assert_ne!(retry.time_stamp(), first.time_stamp());
    assert!(rig.acknowledge(retry, Ok(())).is_empty());
    rig.assert_download_complete(DataKind::Report);
    assert_eq!(rig.fcc.poll_timeout(), None);
    assert_eq!(rig.fcc.generations(), (1, 1));
}

// ---- Golden ----

/// The ICD §11 golden idea: the checksum is of the list, not of its transfer. The FCC, which
/// assembled demo mission 2 from an edition-1 upload (no checksum to compare with), reports and
/// downloads exactly the checksums the GCS computes on its own assembly of `mission_2()`.
#[test]
fn the_fcc_reports_the_checksum_the_gcs_computed_for_mission_2() {
    let valid = validated(&mission_2());
    let (gcs_mission, gcs_areas) = (
        mission_checksum(&valid.mission),
        areas_checksum(&valid.areas),
    );
    let mut rig = FccRig::new().with_mission_2();
    rig.events();
    let r = report(&mut rig);
    assert_eq!(r.mission_checksum, Some(gcs_mission));
    assert_eq!(r.area_checksum, Some(gcs_areas));
    let mut answers = rig.send_enveloped(mission_download_request(window()));
    let (_, ack) = answers.remove(0);
    assert_eq!(transfer_ack(&[ack]), Ok(()));
    let sent = follow(&mut rig, answers);
    let Some(Message::MissionUploadDownloadStatus(status)) = sent.last() else {
        panic!("the download ends with #14000: {sent:?}");
    };
    assert_eq!(status.mission_checksum, Some(gcs_mission));
    // And an edition-2 upload of the same plan is accepted with the GCS's checksums.
    let mut rig = FccRig::new();
    assert_eq!(
        transfer_ack(&rig.upload_mission(&valid.mission, Some(gcs_mission))),
        Ok(())
    );
    assert_eq!(
        area_status(&rig.upload_areas(&valid.areas, Some(gcs_areas))),
        (3, Ok(()))
    );
}
