//! The FCC side of staged missions and atomic activation (ICD §8), through mission data handling
//! driven by hand ([`FccRig`]): every test reads the FCC's answers off the wire (#17000 type and
//! reason, #3012, #3013, #14000, #2011 mode 4, #50001) and checks the active lists, their
//! generations, the staged store and the events the driver gets.
//!
//! | rule (ICD §8 unless noted) | tests |
//! |---|---|
//! | the waypoint buffer: #13000 mode 10 | `mode_10_with_a_staged_id_loads_its_waypoints`, `mode_10_with_an_empty_id_loads_the_active_waypoints`, `mode_10_with_an_unknown_id_empties_the_buffer`, `mode_10_is_allowed_while_trajectory_generation_is_active` |
//! | upload: #13000 mode 8, #2011 mode 7 | `mode_8_stages_without_touching_the_active_lists`, `area_mode_7_stages_without_touching_the_active_lists` |
//! | at most 8 IDs | `a_ninth_id_is_refused_and_a_staged_id_is_replaced` |
//! | delete: #13000 mode 6 | `mode_6_deletes_a_staged_mission`, `mode_6_of_an_unknown_id_is_wrong_state` |
//! | download: #13000 mode 9, #2011 mode 8 | `mode_9_downloads_the_staged_waypoints`, `area_mode_8_downloads_the_staged_areas`, `downloads_of_a_missing_list_are_refused_and_nothing_follows` |
//! | the Mission ID | `a_missing_mission_id_is_missing_field`, `an_empty_or_unprintable_mission_id_is_malformed` |
//! | activate: #50000 command 4 | `activation_replaces_both_lists_in_one_step`, `activation_of_an_unknown_or_incomplete_mission_is_wrong_state`, `activation_is_refused_while_trajectory_generation_is_active`, `activation_of_a_mission_that_leaves_its_fly_zone_is_refused`, `activation_without_navigation_checks_from_the_initial_waypoint` |
//! | report: #13000 mode 7, #50001 | `the_report_lists_the_active_lists_then_the_staged_missions_in_byte_order` |
//! | ICD §11 with staging | `a_staging_closer_with_a_wrong_checksum_stages_nothing`, `a_retried_staging_closer_gets_the_same_answer_once_stored` |
//! | restart | `staged_missions_survive_a_resume` |
//! | edition 1 unchanged | `an_edition_1_upload_naming_its_mission_activates_and_stages_nothing` |

use crate::support::*;
use missionlink_flight::mission_data_handling::{DataKind, FccEvent, Resumed};
use missionlink_ground::ground_station::ValidatedPlan;
use missionlink_interfaces::wire::{
    Altitude, AreaTransferMode, AreaTransmissionCommand, Checksum, ExecuteCommand, GeofenceCheck,
    LegType, Message, MissionExecuteCommand, MissionPlanMode, MissionReport,
    MissionTransferCommand, Reason, Text, Timestamp, TransferStatus, WindowOrChecksum,
};
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::sender::{
    Target, activate_staged, area_download_request, delete_staged, load_buffer, mission_command,
    mission_download_request, transfer_command,
};
use missionlink_protocol::transfer::staged::MissionId;

// ---- Names and messages ----

fn id(s: &str) -> MissionId {
    MissionId::new(s).unwrap()
}

fn text(s: &str) -> Text<20> {
    Text::new(s).unwrap()
}

/// #13000 mode 8 that closes the upload of `mission` into the staged mission `id`.
fn stage_closer(mission: &Mission, id: MissionId, checksum: Option<Checksum>) -> Message {
    MissionTransferCommand {
        mode: MissionPlanMode::StageMission,
        mission_id: Some(id.text()),
        ..transmit(mission, checksum)
    }
    .into()
}

/// #2011 mode 7 that closes the upload of `list` into the staged mission `id`.
fn stage_area_closer(list: &AreaList, id: MissionId, checksum: Option<Checksum>) -> Message {
    AreaTransmissionCommand {
        mode: AreaTransferMode::UploadCompleteStaged,
        mission_id: Some(id.text()),
        ..area_closer(list, checksum)
    }
    .into()
}

/// #50000 command 4 with the Mission ID field as given.
fn activate(mission_id: Option<Text<20>>) -> Message {
    MissionExecuteCommand {
        time_stamp: Timestamp::default(),
        command: ExecuteCommand::ActivateStaged,
        mission_id,
    }
    .into()
}

// ---- Reading the answers ----

/// Whether `e` changes an active list (what guidance would be given).
fn changes_active(e: &FccEvent) -> bool {
    matches!(
        e,
        FccEvent::MissionActivated { .. }
            | FccEvent::MissionCleared
            | FccEvent::AreasActivated { .. }
            | FccEvent::AreasCleared
            | FccEvent::StagedActivated { .. }
    )
}

/// The events of `events` that concern staged missions.
fn staged_events(events: &[FccEvent]) -> Vec<FccEvent> {
    events
        .iter()
        .filter(|e| {
            matches!(
                e,
                FccEvent::StagedStored { .. }
                    | FccEvent::StagedDeleted { .. }
                    | FccEvent::StagedActivated { .. }
            )
        })
        .cloned()
        .collect()
}

/// `m` without its time stamp.
fn unstamped(m: &Message) -> Message {
    let mut m = m.clone();
    m.set_time_stamp(Timestamp::default());
    m
}

// ---- Driving the FCC ----

/// Uploads `mission` into the staged mission `id` (#13000 mode 10 with the ID, every message,
/// mode 8); returns the answers to the closer.
fn stage_mission(
    rig: &mut FccRig,
    mission: &Mission,
    id: MissionId,
    checksum: Option<Checksum>,
) -> Vec<Message> {
    assert_eq!(one_ack(&rig.send(load_buffer(Target::Staged(id)))), Ok(()));
    for m in mission.messages() {
        rig.accepted(m);
    }
    rig.send(stage_closer(mission, id, checksum))
}

/// Uploads `list` into the staged mission `id` (#2011 mode 1, every #2012, mode 7); returns the
/// answers to the closer.
fn stage_areas(
    rig: &mut FccRig,
    list: &AreaList,
    id: MissionId,
    checksum: Option<Checksum>,
) -> Vec<Message> {
    let count = list.areas.len() as u8;
    rig.accepted(area_command(AreaTransferMode::InitiateUpload, Some(count)));
    for a in &list.areas {
        rig.accepted(a.clone());
    }
    rig.send(stage_area_closer(list, id, checksum))
}

/// Stages both lists of `plan` under `id` with their checksums, each accepted; the events are
/// drained.
fn stage_plan(rig: &mut FccRig, plan: &ValidatedPlan, id: MissionId) {
    let answers = stage_mission(
        rig,
        &plan.mission,
        id,
        Some(mission_checksum(&plan.mission)),
    );
    assert_eq!(one_ack(&answers), Ok(()));
    let answers = stage_areas(rig, &plan.areas, id, Some(areas_checksum(&plan.areas)));
    assert_eq!(
        area_status(&answers),
        (plan.areas.areas.len() as u8, Ok(()))
    );
    assert!(rig.fcc.staged().get(&id).is_some_and(|e| e.is_complete()));
    rig.events();
}

/// Asks for the report (#13000 mode 7, Mission ID empty), checks its acknowledgement,
/// acknowledges each #50001 and returns them.
fn report(rig: &mut FccRig) -> Vec<MissionReport> {
    let request = transfer_command(MissionPlanMode::ReportMissions, None, Some(Text::default()));
    let mut answers = rig.send_enveloped(request);
    assert!(!answers.is_empty(), "the report request is answered");
    let (_, ack) = answers.remove(0);
    assert_eq!(one_ack(&[ack]), Ok(()));
    let sent = follow(rig, answers);
    rig.assert_download_complete(DataKind::Report);
    sent.iter()
        .map(|m| match m {
            Message::MissionReport(r) => *r,
            other => panic!("#50001 expected: {other:?}"),
        })
        .collect()
}

/// Navigation reports the aircraft on the ground at TROL (where the activation's check starts).
fn at_trol(rig: &mut FccRig) {
    rig.fcc.handle_progress(rig.now, &on_ground_at(TROL));
    rig.out(); // #4001 of the first progress
}

/// An FCC with demo mission 2 active (generations 1, 1) and navigation at TROL, events drained.
fn active_mission_2() -> FccRig {
    let mut rig = FccRig::new().with_mission_2();
    at_trol(&mut rig);
    rig.events();
    rig
}

/// A mission whose second leg leaves the demo fly-zone (to 48.29 N; the fly-zone ends at
/// 48.285 N): valid by the assembly rules of ICD §7, refused by the onboard geofence check.
fn leaving_the_fly_zone() -> ValidatedPlan {
    let mission = mission_buffer(&[
        take_off(30.0).into(),
        waypoint(1, 2, CCP, LegType::TrackToFix).into(),
        waypoint(2, 0, (48.29, 11.66), LegType::TrackToFix).into(),
        route(1, false).into(),
    ])
    .assemble(Some(2), None)
    .unwrap();
    ValidatedPlan {
        mission,
        ..validated(&mission_1())
    }
}

/// `mission` as stored under the staged ID `id` (the closer's Mission ID names it).
fn named(mission: &Mission, id: MissionId) -> Mission {
    Mission {
        mission_id: Some(id.text()),
        ..mission.clone()
    }
}

// ---- The waypoint buffer (#13000 mode 10) ----

/// Mode 10 with a staged ID fills the buffer with that staged waypoint list: an edit sends only
/// the changed waypoint, and the closer's checksum (the edited staged mission, not the active
/// one) matches.
#[test]
fn mode_10_with_a_staged_id_loads_its_waypoints() {
    let mut rig = active_mission_2();
    let base = validated(&generated_plan(4));
    stage_plan(&mut rig, &base, id("A"));
    let mut edited = base.mission.clone();
    edited.waypoints[1].waypoint.altitude = Altitude::from_metres(150.0).unwrap();

    assert_eq!(
        one_ack(&rig.send(load_buffer(Target::Staged(id("A"))))),
        Ok(())
    );
    rig.accepted(edited.waypoints[1].waypoint);
    let answers = rig.send(stage_closer(
        &edited,
        id("A2"),
        Some(mission_checksum(&edited)),
    ));
    assert_eq!(one_ack(&answers), Ok(()));
    assert_eq!(
        rig.fcc.staged().get(&id("A2")).unwrap().mission,
        Some(named(&edited, id("A2")))
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// Mode 10 with an empty Mission ID fills the buffer with the active waypoint list.
#[test]
fn mode_10_with_an_empty_id_loads_the_active_waypoints() {
    let mut rig = active_mission_2();
    let active = rig.fcc.active_mission().cloned().unwrap();
    let mut edited = active.clone();
    edited.waypoints[1].waypoint.altitude = Altitude::from_metres(150.0).unwrap();

    assert_eq!(one_ack(&rig.send(load_buffer(Target::Active))), Ok(()));
    rig.accepted(edited.waypoints[1].waypoint);
    let answers = rig.send(stage_closer(
        &edited,
        id("E"),
        Some(mission_checksum(&edited)),
    ));
    assert_eq!(one_ack(&answers), Ok(()));
    assert_eq!(
        rig.fcc.staged().get(&id("E")).unwrap().mission,
        Some(named(&edited, id("E")))
    );
    assert_eq!(
        rig.fcc.active_mission(),
        Some(&active),
        "the active list as it was"
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// Mode 10 with an ID that is not staged empties the buffer (a new mission): a one-waypoint
/// mission sent after it assembles alone, although the active mission has three waypoints.
#[test]
fn mode_10_with_an_unknown_id_empties_the_buffer() {
    let mut rig = active_mission_2();
    let new = validated(&mission_1()).mission;
    let answers = stage_mission(&mut rig, &new, id("NEW"), Some(mission_checksum(&new)));
    assert_eq!(one_ack(&answers), Ok(()));
    assert_eq!(
        rig.fcc.staged().get(&id("NEW")).unwrap().mission,
        Some(named(&new, id("NEW")))
    );
    // Without the data, the closer finds the emptied buffer: no waypoint of the active list.
    assert_eq!(
        one_ack(&rig.send(load_buffer(Target::Staged(id("NEW2"))))),
        Ok(())
    );
    assert_eq!(
        one_ack(&rig.send(stage_closer(&new, id("NEW2"), None))),
        Err(Reason::CountMismatch)
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// Mode 10 is acknowledged (type 2) while trajectory generation is active, and changes no
/// list: nothing active changes.
#[test]
fn mode_10_is_allowed_while_trajectory_generation_is_active() {
    let mut rig = active_mission_2();
    rig.fcc.set_automation_state(&flying());
    for target in [Target::Active, Target::Staged(id("X"))] {
        assert_eq!(one_ack(&rig.send(load_buffer(target))), Ok(()), "{target}");
    }
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert!(!rig.events().iter().any(changes_active));
    assert!(
        rig.fcc.staged().is_empty(),
        "loading the buffer stages nothing"
    );
}

// ---- Upload (#13000 mode 8, #2011 mode 7) ----

/// Mode 8 assembles, validates and stores the waypoints under the ID, acknowledged like mode 2;
/// the active lists, their generations and what guidance is given do not change.
#[test]
fn mode_8_stages_without_touching_the_active_lists() {
    let mut rig = active_mission_2();
    let (mission, areas) = (
        rig.fcc.active_mission().cloned().unwrap(),
        rig.fcc.active_areas().cloned().unwrap(),
    );
    let new = validated(&mission_1()).mission;
    let answers = stage_mission(&mut rig, &new, id("M1"), Some(mission_checksum(&new)));
    assert_eq!(one_ack(&answers), Ok(()));
    let events = rig.events();
    assert!(!events.iter().any(changes_active), "{events:?}");
    assert_eq!(
        staged_events(&events),
        [FccEvent::StagedStored {
            id: id("M1"),
            kind: DataKind::Mission
        }]
    );
    let entry = rig.fcc.staged().get(&id("M1")).unwrap();
    assert_eq!(entry.mission, Some(named(&new, id("M1"))));
    assert_eq!(entry.areas, None);
    assert_eq!(rig.fcc.active_mission(), Some(&mission));
    assert_eq!(rig.fcc.active_areas(), Some(&areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// #2011 mode 7 assembles, validates and stores the areas under the ID, answered by #3012
/// valid with the loop count; the active lists do not change.
#[test]
fn area_mode_7_stages_without_touching_the_active_lists() {
    let mut rig = active_mission_2();
    let areas = rig.fcc.active_areas().cloned().unwrap();
    let new = validated(&generated_plan(3)).areas;
    let answers = stage_areas(&mut rig, &new, id("G"), Some(areas_checksum(&new)));
    assert_eq!(area_status(&answers), (11, Ok(())));
    let events = rig.events();
    assert!(!events.iter().any(changes_active), "{events:?}");
    assert_eq!(
        staged_events(&events),
        [FccEvent::StagedStored {
            id: id("G"),
            kind: DataKind::Areas
        }]
    );
    let entry = rig.fcc.staged().get(&id("G")).unwrap();
    assert_eq!(entry.areas.as_ref(), Some(&new));
    assert_eq!(entry.mission, None);
    assert_eq!(rig.fcc.active_areas(), Some(&areas));
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// An ID counts as staged once either list is stored; a closer that would add a ninth ID is
/// refused with `Capacity` (mode 8: #17000 type 3; #2011 mode 7: #3012 status 0 reason 5),
/// while one for an ID already staged replaces that list.
#[test]
fn a_ninth_id_is_refused_and_a_staged_id_is_replaced() {
    let mut rig = FccRig::new();
    let one = validated(&mission_1());
    let two = validated(&mission_2());
    let ids: Vec<MissionId> = (0..8).map(|i| id(&format!("S{i}"))).collect();
    for &i in &ids {
        assert_eq!(
            area_status(&stage_areas(&mut rig, &one.areas, i, None)),
            (1, Ok(()))
        );
    }
    assert_eq!(rig.fcc.staged().len(), 8);
    rig.events();
    let before = rig.fcc.staged().clone();

    let answers = stage_mission(&mut rig, &one.mission, id("S8"), None);
    assert_eq!(one_ack(&answers), Err(Reason::Capacity));
    let answers = stage_areas(&mut rig, &one.areas, id("S8"), None);
    assert_eq!(area_status(&answers), (0, Err(Reason::Capacity)));
    assert_eq!(rig.fcc.staged(), &before, "nothing staged");
    assert_eq!(staged_events(&rig.events()), []);

    // An ID already staged: its missing waypoint list is stored, its area list replaced.
    let answers = stage_mission(&mut rig, &two.mission, ids[3], None);
    assert_eq!(one_ack(&answers), Ok(()));
    let answers = stage_areas(
        &mut rig,
        &two.areas,
        ids[3],
        Some(areas_checksum(&two.areas)),
    );
    assert_eq!(area_status(&answers), (3, Ok(())));
    let entry = rig.fcc.staged().get(&ids[3]).unwrap();
    assert_eq!(entry.mission, Some(named(&two.mission, ids[3])));
    assert_eq!(entry.areas.as_ref(), Some(&two.areas));
    // And its waypoint list replaced too (mode 10 loads it: the edit sends one waypoint).
    let mut edited = two.mission.clone();
    edited.waypoints[1].waypoint.altitude = Altitude::from_metres(150.0).unwrap();
    assert_eq!(
        one_ack(&rig.send(load_buffer(Target::Staged(ids[3])))),
        Ok(())
    );
    rig.accepted(edited.waypoints[1].waypoint);
    let answers = rig.send(stage_closer(
        &edited,
        ids[3],
        Some(mission_checksum(&edited)),
    ));
    assert_eq!(one_ack(&answers), Ok(()));
    assert_eq!(
        rig.fcc.staged().get(&ids[3]).unwrap().mission,
        Some(named(&edited, ids[3]))
    );
    assert_eq!(rig.fcc.staged().len(), 8);
    assert_eq!(
        staged_events(&rig.events()),
        [
            FccEvent::StagedStored {
                id: ids[3],
                kind: DataKind::Mission
            },
            FccEvent::StagedStored {
                id: ids[3],
                kind: DataKind::Areas
            },
            FccEvent::StagedStored {
                id: ids[3],
                kind: DataKind::Mission
            },
        ]
    );
    assert_eq!(rig.fcc.generations(), (0, 0), "no list activated");
}

// ---- Delete (#13000 mode 6) ----

/// Mode 6 removes the staged mission, both lists; the active lists stay.
#[test]
fn mode_6_deletes_a_staged_mission() {
    let mut rig = active_mission_2();
    stage_plan(&mut rig, &validated(&mission_1()), id("D"));
    assert_eq!(one_ack(&rig.send(delete_staged(id("D")))), Ok(()));
    assert_eq!(rig.events(), [FccEvent::StagedDeleted { id: id("D") }]);
    assert!(rig.fcc.staged().is_empty());
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// Mode 6 of an ID that is not staged: `WrongState`, nothing changes.
#[test]
fn mode_6_of_an_unknown_id_is_wrong_state() {
    let mut rig = active_mission_2();
    stage_plan(&mut rig, &validated(&mission_1()), id("D"));
    let before = rig.fcc.staged().clone();
    assert_eq!(
        one_ack(&rig.send(delete_staged(id("OTHER")))),
        Err(Reason::WrongState)
    );
    assert_eq!(rig.fcc.staged(), &before);
    assert_eq!(rig.events(), []);
    // Deleted once, the second delete finds nothing.
    assert_eq!(one_ack(&rig.send(delete_staged(id("D")))), Ok(()));
    assert_eq!(
        one_ack(&rig.send(delete_staged(id("D")))),
        Err(Reason::WrongState)
    );
}

// ---- Download (#13000 mode 9, #2011 mode 8) ----

/// Mode 9 downloads the staged waypoints by the sequence of §5.2: the messages are the staged
/// list's; to an edition-2 request (Transfer Window) the #14000 carries its checksum (§11), to
/// an edition-1 one none.
#[test]
fn mode_9_downloads_the_staged_waypoints() {
    let mut rig = active_mission_2();
    stage_plan(&mut rig, &validated(&generated_plan(5)), id("DL"));
    let staged = rig
        .fcc
        .staged()
        .get(&id("DL"))
        .unwrap()
        .mission
        .clone()
        .unwrap();
    let expected: Vec<Message> = staged.messages().collect();
    for window in [window(), None] {
        let mut answers =
            rig.send_enveloped(mission_download_request(Target::Staged(id("DL")), window));
        let (_, ack) = answers.remove(0);
        assert_eq!(one_ack(&[ack]), Ok(()));
        let sent = follow(&mut rig, answers);
        rig.assert_download_complete(DataKind::Mission);
        let (data, closer) = sent.split_at(sent.len() - 1);
        assert_eq!(data.iter().map(unstamped).collect::<Vec<_>>(), expected);
        let [Message::MissionUploadDownloadStatus(status)] = closer else {
            panic!("the download ends with #14000: {sent:?}");
        };
        assert_eq!(status.status, TransferStatus::Complete);
        assert_eq!(
            status.mission_checksum,
            window.map(|_| mission_checksum(&staged)),
            "window {window:?}"
        );
    }
    assert_ne!(
        rig.fcc.active_mission(),
        Some(&staged),
        "the active mission was not downloaded"
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// #2011 mode 8 downloads the staged areas by the sequence of §5.4 (opened by #3013, closed by
/// #2011 mode 4 with the checksum to an edition-2 request).
#[test]
fn area_mode_8_downloads_the_staged_areas() {
    let mut rig = active_mission_2();
    let plan = validated(&generated_plan(3));
    stage_plan(&mut rig, &plan, id("DL"));
    for window in [window(), None] {
        let answers = rig.send_enveloped(area_download_request(Target::Staged(id("DL")), window));
        let sent = follow_area_download(&mut rig, answers, 11);
        let areas: Vec<Message> = sent[1..sent.len() - 1].iter().map(unstamped).collect();
        let expected: Vec<Message> = plan
            .areas
            .areas
            .iter()
            .cloned()
            .map(Message::from)
            .collect();
        assert_eq!(areas, expected);
        let Some(Message::AreaTransmissionCommand(done)) = sent.last() else {
            panic!("the download ends with #2011 mode 4: {sent:?}");
        };
        assert_eq!(
            (done.mode, done.loop_count),
            (AreaTransferMode::DownloadComplete, Some(11))
        );
        assert_eq!(
            done.window_or_checksum,
            window.map(|_| WindowOrChecksum::AreaChecksum(areas_checksum(&plan.areas))),
            "window {window:?}"
        );
    }
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// A download of a staged list that is not there (the ID unknown, or only the other list
/// staged) is answered by #17000 type 3 `WrongState` (not by #3013) and nothing follows, not
/// even after the ack timeout.
#[test]
fn downloads_of_a_missing_list_are_refused_and_nothing_follows() {
    let mut rig = active_mission_2();
    let one = validated(&mission_1());
    assert_eq!(
        one_ack(&stage_mission(&mut rig, &one.mission, id("WP"), None)),
        Ok(())
    );
    assert_eq!(
        area_status(&stage_areas(&mut rig, &one.areas, id("AR"), None)),
        (1, Ok(()))
    );
    rig.events();
    let requests = [
        mission_download_request(Target::Staged(id("NONE")), window()),
        mission_download_request(Target::Staged(id("AR")), window()),
        mission_download_request(Target::Staged(id("AR")), None),
        area_download_request(Target::Staged(id("NONE")), window()),
        area_download_request(Target::Staged(id("WP")), window()),
        area_download_request(Target::Staged(id("WP")), None),
    ];
    for request in requests {
        let what = describe(&request);
        assert_eq!(
            one_ack(&rig.send(request)),
            Err(Reason::WrongState),
            "{what}"
        );
        let later = rig.now + ACK_TIMEOUT * 3;
        assert_eq!(rig.advance_to(later), [], "{what}: nothing follows");
        assert_eq!(rig.events(), [], "{what}");
    }
}

// ---- The Mission ID ----

/// Every request that names a staged mission, with the Mission ID field `field`: #13000 modes
/// 6, 8, 9, #2011 modes 7, 8, #50000 command 4.
fn naming_requests(field: Option<Text<20>>) -> Vec<Message> {
    let areas = validated(&mission_1()).areas;
    vec![
        mission_command(MissionPlanMode::DeleteStagedMission, None, field),
        mission_command(MissionPlanMode::StageMission, Some(1), field),
        mission_command(MissionPlanMode::ReceiveStagedMission, None, field),
        AreaTransmissionCommand {
            mode: AreaTransferMode::UploadCompleteStaged,
            mission_id: field,
            ..area_closer(&areas, None)
        }
        .into(),
        AreaTransmissionCommand {
            area_id: Some(0),
            mission_id: field,
            ..area_command(AreaTransferMode::InitiateStagedDownload, None)
        }
        .into(),
        activate(field),
    ]
}

/// Sends each request naming a staged mission by `field` to an FCC with a staged mission and
/// checks that each is refused with `reason` and changes nothing.
fn refused_by_its_id(field: Option<Text<20>>, reason: Reason) {
    let mut rig = active_mission_2();
    stage_plan(&mut rig, &validated(&mission_1()), id("OK"));
    let before = rig.fcc.staged().clone();
    for request in naming_requests(field) {
        let what = describe(&request);
        let answers = rig.send(request);
        assert_eq!(answers.len(), 1, "{what}: {answers:?}");
        assert_eq!(reason_of(&answers), Some(reason), "{what} with {field:?}");
    }
    assert_eq!(rig.fcc.staged(), &before);
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// A request that names a staged mission without the Mission ID: `MissingField`.
#[test]
fn a_missing_mission_id_is_missing_field() {
    refused_by_its_id(None, Reason::MissingField);
}

/// A Mission ID that is empty (it names the active lists only with mode 10) or holds a byte
/// that is not printable ASCII: `Malformed` (this project's choice of reason).
#[test]
fn an_empty_or_unprintable_mission_id_is_malformed() {
    for field in [Text::default(), text("a\tb"), text("ok\u{7f}")] {
        refused_by_its_id(Some(field), Reason::Malformed);
    }
}

// ---- Activate (#50000 command 4) ----

/// The staged mission replaces both active lists in one step: both generations + 1, one
/// activation on both published lists, one `StagedActivated` (no `MissionActivated` or
/// `AreasActivated`), and the staged copy stays staged.
#[test]
fn activation_replaces_both_lists_in_one_step() {
    let mut rig = active_mission_2();
    let plan = validated(&mission_1());
    stage_plan(&mut rig, &plan, id("M1"));
    let before = rig.fcc.waypoint_list().activation;
    assert_eq!(one_ack(&rig.send(activate_staged(id("M1")))), Ok(()));
    assert_eq!(
        rig.fcc.active_mission(),
        Some(&named(&plan.mission, id("M1")))
    );
    assert_eq!(rig.fcc.active_areas(), Some(&plan.areas));
    assert_eq!(rig.fcc.generations(), (2, 2));
    assert_eq!(
        rig.fcc.waypoint_list().activation,
        rig.fcc.area_list().activation
    );
    assert_ne!(rig.fcc.waypoint_list().activation, before);
    assert_eq!(rig.fcc.waypoint_list().generation, 2);
    assert_eq!(rig.fcc.area_list().generation, 2);
    assert_eq!(
        rig.events(),
        [FccEvent::StagedActivated {
            id: id("M1"),
            mission_generation: 2,
            area_generation: 2,
        }]
    );
    assert!(
        rig.fcc
            .staged()
            .get(&id("M1"))
            .is_some_and(|e| e.is_complete())
    );
}

/// An unknown staged mission, or one with only one of its lists: `WrongState`, nothing changes.
#[test]
fn activation_of_an_unknown_or_incomplete_mission_is_wrong_state() {
    let mut rig = active_mission_2();
    let plan = validated(&mission_1());
    assert_eq!(
        one_ack(&stage_mission(&mut rig, &plan.mission, id("WP"), None)),
        Ok(())
    );
    assert_eq!(
        area_status(&stage_areas(&mut rig, &plan.areas, id("AR"), None)),
        (1, Ok(()))
    );
    rig.events();
    let active = rig.fcc.active_mission().cloned();
    for name in ["NONE", "WP", "AR"] {
        assert_eq!(
            one_ack(&rig.send(activate_staged(id(name)))),
            Err(Reason::WrongState),
            "{name}"
        );
    }
    assert_eq!(rig.fcc.active_mission().cloned(), active);
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// While trajectory generation is active (airborne), `WrongState`, nothing changes.
#[test]
fn activation_is_refused_while_trajectory_generation_is_active() {
    let mut rig = active_mission_2();
    stage_plan(&mut rig, &validated(&mission_1()), id("M1"));
    rig.fcc.set_automation_state(&flying());
    assert_eq!(
        one_ack(&rig.send(activate_staged(id("M1")))),
        Err(Reason::WrongState)
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
    rig.fcc.set_automation_state(&on_ground());
    assert_eq!(one_ack(&rig.send(activate_staged(id("M1")))), Ok(()));
    assert_eq!(rig.fcc.generations(), (2, 2));
}

/// A staged mission whose route leaves its own fly-zone fails the onboard geofence check (§7):
/// `GeofenceViolation`, nothing changes.
#[test]
fn activation_of_a_mission_that_leaves_its_fly_zone_is_refused() {
    let mut rig = active_mission_2();
    let (mission, areas) = (
        rig.fcc.active_mission().cloned(),
        rig.fcc.active_areas().cloned(),
    );
    stage_plan(&mut rig, &leaving_the_fly_zone(), id("OUT"));
    assert_eq!(
        one_ack(&rig.send(activate_staged(id("OUT")))),
        Err(Reason::GeofenceViolation)
    );
    assert_eq!(rig.fcc.active_mission().cloned(), mission);
    assert_eq!(rig.fcc.active_areas().cloned(), areas);
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(rig.events(), []);
}

/// Without a position from navigation the check starts at the mission's initial waypoint (this
/// project's choice, `automation::check_activation`): a valid mission is activated, one whose
/// legs leave the fly-zone is refused with `GeofenceViolation`.
#[test]
fn activation_without_navigation_checks_from_the_initial_waypoint() {
    let mut rig = FccRig::new();
    stage_plan(&mut rig, &validated(&mission_2()), id("IN"));
    stage_plan(&mut rig, &leaving_the_fly_zone(), id("OUT"));
    assert_eq!(
        one_ack(&rig.send(activate_staged(id("OUT")))),
        Err(Reason::GeofenceViolation)
    );
    assert_eq!(rig.fcc.generations(), (0, 0));
    assert_eq!(one_ack(&rig.send(activate_staged(id("IN")))), Ok(()));
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert!(rig.fcc.active_mission().is_some());
}

// ---- Report (#13000 mode 7, #50001) ----

/// The report lists the active lists first (Mission ID present and empty), then each staged
/// mission in ascending byte order of ID, Report Index 1..=n and Report Count n on each, with
/// its counts and checksums; the check is not run for a staged mission that misses a list.
#[test]
fn the_report_lists_the_active_lists_then_the_staged_missions_in_byte_order() {
    let mut rig = active_mission_2();
    let (one, two) = (validated(&mission_1()), validated(&mission_2()));
    stage_plan(&mut rig, &two, id("b"));
    assert_eq!(
        one_ack(&stage_mission(&mut rig, &one.mission, id("B"), None)),
        Ok(())
    );
    assert_eq!(
        area_status(&stage_areas(&mut rig, &one.areas, id("a"), None)),
        (1, Ok(()))
    );
    rig.events();

    let entries = report(&mut rig);
    let ids: Vec<Option<Text<20>>> = entries.iter().map(|r| r.mission_id).collect();
    assert_eq!(
        ids,
        [
            Some(Text::default()),
            Some(text("B")),
            Some(text("a")),
            Some(text("b"))
        ]
    );
    for (i, r) in entries.iter().enumerate() {
        assert_eq!((r.report_index, r.report_count), (i as u8 + 1, 4), "{r:?}");
    }
    let summary = |r: &MissionReport| {
        (
            r.waypoint_count,
            r.area_count,
            r.geofence_check,
            r.mission_checksum,
            r.area_checksum,
        )
    };
    let (m1, a1) = (
        Some(mission_checksum(&one.mission)),
        Some(areas_checksum(&one.areas)),
    );
    let (m2, a2) = (
        Some(mission_checksum(&two.mission)),
        Some(areas_checksum(&two.areas)),
    );
    assert_eq!(summary(&entries[0]), (3, 3, GeofenceCheck::Passed, m2, a2));
    assert_eq!(
        summary(&entries[1]),
        (1, 0, GeofenceCheck::NotRun, m1, None)
    );
    assert_eq!(
        summary(&entries[2]),
        (0, 1, GeofenceCheck::NotRun, None, a1)
    );
    assert_eq!(summary(&entries[3]), (3, 3, GeofenceCheck::Passed, m2, a2));
    assert_eq!(rig.fcc.generations(), (1, 1));
}

// ---- ICD §11 with staging ----

/// Mode 8 whose checksum is not that of the list assembled: `IntegrityMismatch`, nothing
/// staged, no `StagedStored`.
#[test]
fn a_staging_closer_with_a_wrong_checksum_stages_nothing() {
    let mut rig = active_mission_2();
    let new = validated(&mission_1()).mission;
    let wrong = Checksum::new(mission_checksum(&new).value() ^ 1);
    let answers = stage_mission(&mut rig, &new, id("M1"), Some(wrong));
    assert_eq!(one_ack(&answers), Err(Reason::IntegrityMismatch));
    assert!(rig.fcc.staged().is_empty());
    let events = rig.events();
    assert_eq!(staged_events(&events), []);
    assert!(!events.iter().any(changes_active));
    assert_eq!(rig.fcc.generations(), (1, 1));
}

/// The retry of mode 8 (same content, new time stamp) gets the same answer and changes nothing:
/// no second `StagedStored`.
#[test]
fn a_retried_staging_closer_gets_the_same_answer_once_stored() {
    let mut rig = active_mission_2();
    let new = validated(&mission_1()).mission;
    let checksum = Some(mission_checksum(&new));
    assert_eq!(
        one_ack(&stage_mission(&mut rig, &new, id("M1"), checksum)),
        Ok(())
    );
    assert_eq!(staged_events(&rig.events()).len(), 1);
    let before = rig.fcc.staged().clone();
    assert_eq!(
        one_ack(&rig.send(stage_closer(&new, id("M1"), checksum))),
        Ok(())
    );
    assert_eq!(rig.events(), []);
    assert_eq!(rig.fcc.staged(), &before);
    assert_eq!(rig.fcc.generations(), (1, 1));
}

// ---- Restart ----

/// A partition resumed with the staged missions it recorded keeps them: the report lists them
/// and the activation works.
#[test]
fn staged_missions_survive_a_resume() {
    let mut before = active_mission_2();
    let plan = validated(&mission_1());
    stage_plan(&mut before, &plan, id("R"));

    let mut rig = FccRig::new();
    rig.fcc.resume(
        rig.now,
        Resumed {
            mission: before.fcc.active_mission().cloned(),
            mission_generation: 1,
            areas: before.fcc.active_areas().cloned(),
            area_generation: 1,
            mission_upload_open: false,
            staged: before.fcc.staged().clone(),
        },
    );
    at_trol(&mut rig);
    rig.events();
    let entries = report(&mut rig);
    assert_eq!(entries.len(), 2);
    assert_eq!(entries[1].mission_id, Some(text("R")));
    assert_eq!(
        (entries[1].mission_checksum, entries[1].area_checksum),
        (
            Some(mission_checksum(&plan.mission)),
            Some(areas_checksum(&plan.areas))
        )
    );
    assert_eq!(one_ack(&rig.send(activate_staged(id("R")))), Ok(()));
    assert_eq!(rig.fcc.active_areas(), Some(&plan.areas));
    assert_eq!(rig.fcc.generations(), (2, 2));
}

// ---- Edition 1 ----

/// An edition-1 GCS that names its mission in #13000 field 1 (mode 1 clear, data, mode 2) gets
/// exactly §5: the mission is activated, nothing is staged.
#[test]
fn an_edition_1_upload_naming_its_mission_activates_and_stages_nothing() {
    let mut rig = FccRig::new();
    let plan = validated(&mission_1());
    rig.accepted(mission_command(
        MissionPlanMode::ClearMission,
        None,
        Some(text("ED1")),
    ));
    for m in plan.mission.messages() {
        rig.accepted(m);
    }
    let closer = MissionTransferCommand {
        mission_id: Some(text("ED1")),
        ..transmit(&plan.mission, None)
    };
    assert_eq!(one_ack(&rig.send(closer)), Ok(()));
    assert_eq!(
        area_status(&rig.upload_areas(&plan.areas, None)),
        (1, Ok(()))
    );
    assert_eq!(rig.fcc.generations(), (1, 1));
    assert_eq!(
        rig.fcc.active_mission().and_then(|m| m.mission_id),
        Some(text("ED1"))
    );
    let events = rig.events();
    assert!(events.contains(&FccEvent::MissionActivated { generation: 1 }));
    assert!(events.contains(&FccEvent::AreasActivated { generation: 1 }));
    assert_eq!(staged_events(&events), []);
    assert!(rig.fcc.staged().is_empty());
    assert_eq!(report(&mut rig).len(), 1);
}
