//! Every reject reason of ICD §6, provoked through mission data handling: the FCC answers with
//! #17000 type 3 (or #3012 status 0) and the reason, and its active lists stay as they were.

use std::time::Duration;

use crate::support::*;
use missionlink_flight::mission_data_handling::{DataKind, FccEvent};
use missionlink_interfaces::wire::{
    self, AreaTransferMode, ExecuteCommand, LegType, Message, MissionExecuteCommand,
    MissionPlanMode, Reason, Text, Timestamp,
};
use missionlink_protocol::testkit::{self, RawFrame};
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::sender::mission_command;

#[test]
fn malformed() {
    let mut rig = FccRig::new();
    let mut w = waypoint(1, 0, (48.275, 11.645), LegType::TrackToFix);
    w.waypoint_number = 0;
    assert_eq!(rig.reason(w), Some(Reason::Malformed));
}

#[test]
fn missing_field() {
    let mut rig = FccRig::new();
    assert_eq!(
        rig.reason(mission_command(
            MissionPlanMode::TransmitMission,
            None,
            None
        )),
        Some(Reason::MissingField)
    );
}

#[test]
fn unknown_field() {
    let mut rig = FccRig::new();
    // #50000 with PV bit 3 set: only bits 0 to 2 are defined.
    let mut data = vec![0b1011];
    data.extend_from_slice(&TS);
    data.extend_from_slice(&[1, 0]);
    assert_eq!(
        reason_of(&rig.send_raw(&RawFrame::uplink(50000).with_ack().build(&data))),
        Some(Reason::UnknownField)
    );
}

#[test]
fn unsupported() {
    let mut rig = FccRig::new();
    // #13000 mode 4 is not implemented.
    let mut data = vec![0b101];
    data.extend_from_slice(&TS);
    data.push(4);
    assert_eq!(
        reason_of(&rig.send_raw(&RawFrame::uplink(13000).with_ack().build(&data))),
        Some(Reason::Unsupported)
    );
    // Return to home on a route that is not bidirectional.
    let mut rig = FccRig::new().with_mission_2();
    let mut route = route(1, false);
    route.time_stamp = Timestamp::default();
    rig.accepted(route);
    rig.accepted(mission_command(
        MissionPlanMode::TransmitMission,
        Some(3),
        None,
    ));
    assert_eq!(
        rig.reason(MissionExecuteCommand {
            time_stamp: Timestamp::default(),
            command: ExecuteCommand::ReturnToHome,
            mission_id: None,
        }),
        Some(Reason::Unsupported)
    );
}

#[test]
fn capacity() {
    let mut rig = FccRig::new();
    assert_eq!(
        rig.reason(area_command(AreaTransferMode::InitiateUpload, Some(12))),
        Some(Reason::Capacity)
    );
    // A 257th waypoint in the buffer.
    for n in 1..=256u16 {
        rig.accepted(waypoint(n, n + 1, (48.27, 11.66), LegType::TrackToFix));
    }
    assert_eq!(
        rig.reason(waypoint(999, 0, (48.27, 11.66), LegType::TrackToFix)),
        Some(Reason::Capacity)
    );
}

#[test]
fn wrong_state() {
    let mut rig = FccRig::new().with_mission_2();
    // #13002 during a download (the ICD's example).
    let answers = rig.send(mission_command(MissionPlanMode::ReceiveMission, None, None));
    assert_eq!(reason_of(&answers), None);
    assert!(answers.len() >= 2, "the download starts: {answers:?}");
    assert_eq!(
        rig.reason(waypoint(1, 0, (48.275, 11.645), LegType::TrackToFix)),
        Some(Reason::WrongState)
    );
    // Execute without an active area list.
    let mut rig = FccRig::new();
    assert_eq!(
        rig.reason(MissionExecuteCommand {
            time_stamp: Timestamp::default(),
            command: ExecuteCommand::Execute,
            mission_id: None,
        }),
        Some(Reason::WrongState)
    );
}

#[test]
fn guidance_active() {
    let mut rig = FccRig::new().with_mission_2();
    rig.fcc.set_automation_state(&flying());
    let before = rig.fcc.active_mission().cloned();
    assert_eq!(
        rig.reason(mission_command(MissionPlanMode::ClearMission, None, None)),
        Some(Reason::GuidanceActive)
    );
    assert_eq!(
        rig.reason(area_command(AreaTransferMode::ClearAreas, None)),
        Some(Reason::GuidanceActive)
    );
    assert_eq!(rig.fcc.active_mission().cloned(), before);
    assert!(rig.fcc.active_areas().is_some());
}

#[test]
fn count_mismatch() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_mission().cloned();
    assert_eq!(
        rig.reason(mission_command(
            MissionPlanMode::TransmitMission,
            Some(4),
            None
        )),
        Some(Reason::CountMismatch)
    );
    assert_eq!(rig.fcc.active_mission().cloned(), before);
}

#[test]
fn broken_chain() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_mission().cloned();
    // An edit: waypoint 2 now points at 9, which does not exist.
    rig.accepted(waypoint(2, 9, (48.278, 11.658), LegType::TrackToFix));
    assert_eq!(
        rig.reason(mission_command(
            MissionPlanMode::TransmitMission,
            Some(3),
            None
        )),
        Some(Reason::BrokenChain)
    );
    assert_eq!(rig.fcc.active_mission().cloned(), before);
}

#[test]
fn missing_initial() {
    let mut rig = FccRig::new();
    rig.accepted(mission_command(MissionPlanMode::ClearMission, None, None));
    rig.accepted(take_off(30.0));
    rig.accepted(waypoint(1, 0, (48.275, 11.645), LegType::TrackToFix));
    rig.accepted(route(5, false));
    assert_eq!(
        rig.reason(mission_command(
            MissionPlanMode::TransmitMission,
            Some(1),
            None
        )),
        Some(Reason::MissingInitial)
    );
    assert!(rig.fcc.active_mission().is_none());
}

#[test]
fn missing_rf_centre() {
    let mut rig = FccRig::new();
    rig.accepted(mission_command(MissionPlanMode::ClearMission, None, None));
    rig.accepted(take_off(30.0));
    rig.accepted(waypoint(1, 0, (48.275, 11.645), LegType::RadiusToFix));
    rig.accepted(route(1, false));
    assert_eq!(
        rig.reason(mission_command(
            MissionPlanMode::TransmitMission,
            Some(1),
            None
        )),
        Some(Reason::MissingRfCentre)
    );
}

#[test]
fn bad_geometry() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_areas().cloned();
    // No fly-zone: one no-fly-zone alone.
    rig.accepted(area_command(AreaTransferMode::InitiateUpload, Some(1)));
    rig.accepted(circle(2, (48.268, 11.675), (48.268, 11.679)));
    assert_eq!(
        reason_of(&rig.send(area_command(AreaTransferMode::UploadComplete, Some(1)))),
        Some(Reason::BadGeometry)
    );
    assert_eq!(rig.fcc.active_areas().cloned(), before);
    // A polygon of two vertices is refused at decode. PV 0x018F: time stamp, area ID, area
    // type, shape, vertex count, vertices.
    let mut data = vec![0x01, 0x8f];
    data.extend_from_slice(&TS);
    data.extend_from_slice(&[0, 7, 1, 0, 0, 0, 2]);
    data.extend_from_slice(&[0u8; 16]);
    assert_eq!(
        reason_of(&rig.send_raw(&RawFrame::uplink(2012).with_ack().build(&data))),
        Some(Reason::BadGeometry)
    );
}

/// A download request the GCS stamped before the newest message of its mission upload, delayed
/// on the link, finds the upload open: `Busy`. One stamped after it ends the upload (the GCS has
/// given it up; the active list stays) and the download begins.
#[test]
fn busy() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_mission().cloned();
    rig.now = rig.now + Duration::from_millis(1);
    let request = mission_command(MissionPlanMode::ReceiveMission, None, None);
    rig.gcs.send(rig.now, request.clone(), true);
    let mut buf = [0u8; wire::MAX_FRAME_LEN];
    let len = rig.gcs.poll_transmit(&mut buf).unwrap().unwrap();
    let delayed = buf[..len].to_vec();

    rig.accepted(waypoint(2, 3, (48.278, 11.658), LegType::TrackToFix));
    rig.events();
    assert_eq!(reason_of(&rig.send_raw(&delayed)), Some(Reason::Busy));
    assert!(rig.events().is_empty());

    assert_eq!(rig.reason(request), None);
    assert!(rig.events().contains(&FccEvent::UploadAbandoned {
        kind: DataKind::Mission,
        reason: None
    }));
    assert_eq!(rig.fcc.active_mission().cloned(), before);
}

/// An area upload opener the GCS stamped before its area download request, delayed on the
/// link, finds the download in progress: `Busy`. One stamped after it ends the download (the
/// GCS has moved on) and opens the upload.
#[test]
fn a_newer_opener_ends_the_download_an_older_one_is_busy() {
    let mut rig = FccRig::new().with_mission_2();
    rig.now = rig.now + Duration::from_millis(1);
    let opener = area_command(AreaTransferMode::InitiateUpload, Some(1));
    rig.gcs.send(rig.now, opener.into(), true);
    let mut buf = [0u8; wire::MAX_FRAME_LEN];
    let len = rig.gcs.poll_transmit(&mut buf).unwrap().unwrap();
    let delayed = buf[..len].to_vec();

    let answers = rig.send(area_command(AreaTransferMode::InitiateDownload, None));
    assert!(matches!(
        answers.first(),
        Some(Message::AreaTransmissionStatus(_))
    ));
    assert_eq!(reason_of(&rig.send_raw(&delayed)), Some(Reason::Busy));
    let ended = |events: Vec<FccEvent>| {
        events.contains(&FccEvent::DownloadEnded {
            kind: DataKind::Areas,
        })
    };
    assert!(!ended(rig.events()));

    assert_eq!(rig.reason(opener), None);
    assert!(ended(rig.events()));
    // Nothing more of the download: no resend of its areas at their ack timeouts.
    let later = rig.now + Duration::from_secs(5);
    let sent = rig.advance_to(later);
    assert!(
        sent.iter()
            .all(|(_, m)| !matches!(m, Message::AreaPolygonLoopSegment(_))),
        "{sent:?}"
    );
}

/// Reason 15 (ICD §11 ext): the closer's checksum describes another list than the one
/// assembled. Here the GCS means mission 2, but the FCC assembled mission 1.
#[test]
fn integrity_mismatch() {
    let mut rig = FccRig::new().with_mission_2();
    let (mission, areas) = (
        rig.fcc.active_mission().cloned().unwrap(),
        rig.fcc.active_areas().cloned().unwrap(),
    );
    let other = validated(&mission_1());
    assert_eq!(
        reason_of(
            &rig.upload_mission_into_empty_buffer(&other.mission, Some(mission_checksum(&mission)))
        ),
        Some(Reason::IntegrityMismatch)
    );
    assert_eq!(
        reason_of(&rig.upload_areas(&other.areas, Some(areas_checksum(&areas)))),
        Some(Reason::IntegrityMismatch)
    );
    assert_eq!(rig.fcc.active_mission(), Some(&mission));
    assert_eq!(rig.fcc.active_areas(), Some(&areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
}

#[test]
fn an_edit_changes_only_the_waypoints_sent() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_mission().cloned().unwrap();
    let mut w2 = waypoint(2, 3, (48.278, 11.658), LegType::TrackToFix);
    w2.altitude = wire::Altitude::from_metres(150.0).unwrap();
    rig.accepted(w2);
    // Not active before the transmit.
    assert_eq!(rig.fcc.active_mission(), Some(&before));
    rig.accepted(mission_command(
        MissionPlanMode::TransmitMission,
        Some(3),
        Some(Text::new("EDIT").unwrap()),
    ));
    let after = rig.fcc.active_mission().unwrap();
    assert_eq!(after.waypoints[0], before.waypoints[0]);
    assert_eq!(after.waypoints[2], before.waypoints[2]);
    assert_eq!(after.waypoints[1].waypoint.altitude.metres(), 150.0);
    assert_eq!(after.take_off, before.take_off);
    assert_eq!(after.route, before.route);
    assert_eq!(rig.fcc.waypoint_list().generation, 2);
}

#[test]
fn an_abandoned_edit_leaves_nothing_behind() {
    let mut rig = FccRig::new().with_mission_2();
    let before = rig.fcc.active_mission().cloned().unwrap();
    rig.accepted(waypoint(2, 9, (48.278, 11.658), LegType::TrackToFix));
    // The GCS falls silent: after the transfer timeout the edit is dropped.
    rig.now = rig.now + TRANSFER_TIMEOUT;
    rig.fcc.handle_timeout(rig.now);
    // A later edit of waypoint 3 alone is assembled on the active mission, not on the
    // abandoned edit of waypoint 2.
    rig.accepted(waypoint(3, 0, (48.280, 11.680), LegType::RadiusToFix));
    rig.accepted(transmit(&before, None));
    assert_eq!(rig.fcc.active_mission(), Some(&before));
}

/// Reason 14 (ICD §7 ext): execute from where the way to the initial waypoint crosses a
/// no-fly-zone is refused and changes nothing; from TROL the same mission is accepted.
#[test]
fn geofence_violation() {
    let execute = MissionExecuteCommand {
        time_stamp: Timestamp::default(),
        command: ExecuteCommand::Execute,
        mission_id: None,
    };
    let mut rig = FccRig::new().with_mission_2();
    // Without a position from navigation there is nothing to check from.
    assert_eq!(rig.reason(execute), Some(Reason::WrongState));
    let (mission, areas) = (
        rig.fcc.active_mission().cloned(),
        rig.fcc.active_areas().cloned(),
    );
    while rig.fcc.poll_event().is_some() {}
    // South of the polygonal no-fly-zone (48.262..48.266 N, 11.640..11.646 E): the direct way
    // to CCP (48.275 N, 11.645 E) runs through it.
    rig.fcc
        .handle_progress(rig.now, &on_ground_at((48.258, 11.643)));
    rig.fcc.messages(); // FROM-TO-NEXT (#4001) of the first progress
    assert_eq!(rig.reason(execute), Some(Reason::GeofenceViolation));
    assert_eq!(rig.fcc.active_mission().cloned(), mission);
    assert_eq!(rig.fcc.active_areas().cloned(), areas);
    assert!(
        std::iter::from_fn(|| rig.fcc.poll_event()).all(|e| !matches!(e, FccEvent::Execute(_))),
        "nothing goes to system automation"
    );
    // From TROL the way is clear.
    rig.fcc
        .handle_progress(rig.now, &on_ground_at(testkit::TROL));
    rig.fcc.messages();
    assert_eq!(rig.reason(execute), None);
}

/// docs/design.md "Health": while system automation says guidance is not alive, execute is refused
/// with `WrongState` (the ICD's "not now") and nothing goes to system automation; alive again,
/// the same execute is accepted.
#[test]
fn execute_while_guidance_is_not_alive() {
    let execute = MissionExecuteCommand {
        time_stamp: Timestamp::default(),
        command: ExecuteCommand::Execute,
        mission_id: None,
    };
    let mut rig = FccRig::new().with_mission_2();
    rig.fcc
        .handle_progress(rig.now, &on_ground_at(testkit::TROL));
    rig.fcc.messages();
    while rig.fcc.poll_event().is_some() {}
    rig.fcc
        .set_automation_state(&missionlink_interfaces::contracts::AutomationStatePayload {
            guidance_alive: false,
            ..on_ground()
        });
    assert_eq!(rig.reason(execute), Some(Reason::WrongState));
    assert!(
        std::iter::from_fn(|| rig.fcc.poll_event()).all(|e| !matches!(e, FccEvent::Execute(_))),
        "nothing goes to system automation"
    );
    rig.fcc.set_automation_state(&on_ground());
    assert_eq!(rig.reason(execute), None);
}
