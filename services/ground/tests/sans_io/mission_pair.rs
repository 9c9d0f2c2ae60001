//! The GCS and the FCC stepped through simulated time (ICD §5): uploads, downloads and the
//! message sequence, without faults.

use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::{GcsError, GcsEvent, ValidatedPlan};
use missionlink_interfaces::wire::{GeoPoint, Message, MissionPlanMode, Reason};
use missionlink_protocol::link::retry::AttemptFailure;

fn upload(pair: &mut Pair, plan: &missionlink_ground::ground_station::MissionPlan, clear: bool) {
    let now = pair.now;
    pair.gcs.upload(now, plan, clear).unwrap();
    pair.run_until_standby(Duration::from_secs(60));
}

/// Downloads the FCC's lists; what arrived, once the download completed.
fn download(pair: &mut Pair) -> ValidatedPlan {
    let now = pair.now;
    pair.gcs.download(now).unwrap();
    pair.run_until_standby(Duration::from_secs(60));
    let events = pair.take_gcs_events();
    let Some(GcsEvent::DownloadComplete(downloaded)) = events.last() else {
        panic!("download did not complete: {events:?}");
    };
    (**downloaded).clone()
}

fn sequence(pair: &Pair, from: usize) -> Vec<String> {
    pair.sent[from..]
        .iter()
        .map(|s| {
            let dir = match s.direction {
                Direction::Up => "up",
                Direction::Down => "down",
            };
            format!("{dir} {}", describe(&s.message))
        })
        .collect()
}

/// Whether `events` hold an upload that ended complete.
fn uploaded_complete(events: &[GcsEvent<core::convert::Infallible>]) -> bool {
    events
        .iter()
        .any(|e| matches!(e, GcsEvent::Uploaded(r) if r.is_complete()))
}

#[test]
fn demo_mission_1_upload_and_download_follow_icd_5_message_by_message() {
    let mut pair = Pair::new(1);
    let plan = mission_1();
    let expected = pair.gcs.validate(&plan).unwrap();
    upload(&mut pair, &plan, true);
    assert!(
        uploaded_complete(&pair.take_gcs_events()),
        "upload did not complete"
    );
    assert_eq!(pair.fcc.active_mission(), Some(&expected.mission));
    assert_eq!(pair.fcc.active_areas(), Some(&expected.areas));
    // The report first (ICD §8, §10.1: the edition, and what is active before), then ICD §5.1
    // and §5.3, each message answered before the next.
    assert_eq!(
        sequence(&pair, 0),
        [
            "up 13000 mode 7",
            "down 17000 completed 13000",
            "down 50001",
            "up 17000 completed 50001",
            "up 13000 mode 1",
            "down 17000 completed 13000",
            "up 13006 take-off",
            "down 17000 completed 13006",
            "up 13002 wp 1",
            "down 17000 completed 13002",
            "up 13001",
            "down 17000 completed 13001",
            "up 13000 mode 2",
            "down 17000 completed 13000",
            "up 2011 mode 1",
            "down 17000 completed 2011",
            "up 2012 area 1",
            "down 17000 completed 2012",
            "up 2011 mode 2",
            "down 3012 Valid",
        ]
    );
    // Every GCS message asks for an answer; answers do not.
    for s in &pair.sent {
        let answer = matches!(
            s.message,
            Message::MessageAcknowledgement(_) | Message::AreaStatusAlert(_)
        );
        assert_eq!(s.ack_requested, !answer, "{}", describe(&s.message));
    }
    // The whole upload took the report's round trip (the entry follows its acceptance at once,
    // and is answered: 18 hops in all) and 8 + 3 round trips, 2 ms latency each way.
    assert_eq!(pair.now.micros(), 18 * 2_000);

    let before = pair.sent.len();
    // ICD §5.2: every field equal.
    assert_eq!(download(&mut pair), expected);
    assert_eq!(
        sequence(&pair, before),
        [
            "up 13000 mode 3",
            "down 17000 completed 13000",
            "down 13006 take-off",
            "up 17000 completed 13006",
            "down 13002 wp 1",
            "up 17000 completed 13002",
            "down 13001",
            "up 17000 completed 13001",
            "down 14000 Complete",
            "up 17000 completed 14000",
            "up 2011 mode 3",
            "down 3013 Ready",
            "up 17000 completed 3013",
            "down 2012 area 1",
            "up 17000 completed 2012",
            "down 2011 mode 4",
            "up 17000 completed 2011",
        ]
    );
}

#[test]
fn mission_2_with_rf_leg_circle_and_polygon_round_trips() {
    let mut pair = Pair::new(2);
    let plan = mission_2();
    let expected = pair.gcs.validate(&plan).unwrap();
    // Flight-plan order, whatever the order of the plan.
    let order: Vec<u16> = expected
        .mission
        .waypoints
        .iter()
        .map(|r| r.waypoint.waypoint_number)
        .collect();
    assert_eq!(order, [1, 2, 3]);
    upload(&mut pair, &plan, true);
    assert!(uploaded_complete(&pair.take_gcs_events()));
    assert_eq!(pair.fcc.active_mission(), Some(&expected.mission));
    let list = pair.fcc.waypoint_list();
    assert!(list.bidirectional);
    assert!(list.waypoints()[2].rf_centre().is_some());
    let areas = pair.fcc.area_list();
    assert_eq!(areas.no_fly_circles().len(), 1);
    assert_eq!(areas.no_fly_polygons().len(), 1);
    assert_eq!(areas.safety_offset.metres(), 25.0);
    // The RF centre follows its waypoint (ICD §5.1 step 3).
    let up: Vec<String> = sequence(&pair, 0)
        .into_iter()
        .filter(|s| s.starts_with("up 1300"))
        .collect();
    assert_eq!(
        up,
        [
            "up 13000 mode 7",
            "up 13000 mode 1",
            "up 13006 take-off",
            "up 13002 wp 1",
            "up 13002 wp 2",
            "up 13002 wp 3",
            "up 13006 rf 3",
            "up 13001",
            "up 13000 mode 2",
        ]
    );

    assert_eq!(download(&mut pair), expected);
}

#[test]
fn upload_over_one_dead_link_completes_on_the_other() {
    for dead in 0..2 {
        let mut pair = Pair::new(3);
        pair.uplink[dead] = DOWN;
        pair.downlink[dead] = DOWN;
        let plan = mission_2();
        upload(&mut pair, &plan, true);
        assert!(uploaded_complete(&pair.take_gcs_events()));
        assert_eq!(
            pair.fcc.active_mission(),
            Some(&pair.gcs.validate(&plan).unwrap().mission)
        );
    }
}

#[test]
fn invalid_plan_is_refused_before_anything_is_sent() {
    let mut pair = Pair::new(4);
    let mut plan = mission_1();
    plan.mission
        .store(
            &waypoint(
                1,
                7,
                (48.275, 11.645),
                missionlink_interfaces::wire::LegType::TrackToFix,
            )
            .into(),
        )
        .unwrap();
    let now = pair.now;
    assert_eq!(
        pair.gcs.upload(now, &plan, true),
        Err(GcsError::InvalidMission(Reason::BrokenChain))
    );
    pair.run_until_standby(Duration::from_secs(10));
    assert!(pair.sent.is_empty());
}

#[test]
fn clear_is_refused_while_guidance_is_active_and_then_deletes_the_mission() {
    let mut pair = Pair::new(5);
    let plan = mission_2();
    upload(&mut pair, &plan, true);
    pair.take_gcs_events();
    let active = pair.fcc.active_mission().cloned();
    pair.fcc.set_automation_state(&flying());
    let now = pair.now;
    pair.gcs.clear_mission(now).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    let events = pair.take_gcs_events();
    let Some(GcsEvent::Failed(GcsError::Transfer { error, .. })) = events.last() else {
        panic!("clear was not refused: {events:?}");
    };
    assert_eq!(
        error.first,
        AttemptFailure::Rejected(Reason::GuidanceActive)
    );
    assert_eq!(
        error.second,
        Some(AttemptFailure::Rejected(Reason::GuidanceActive))
    );
    assert_eq!(pair.fcc.active_mission().cloned(), active);
    // Once guidance is inactive, the clear goes through.
    pair.fcc.set_automation_state(&on_ground());
    let from = pair.sent.len();
    let now = pair.now;
    pair.gcs.clear_mission(now).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    assert!(matches!(
        pair.take_gcs_events().last(),
        Some(GcsEvent::CommandAccepted(_))
    ));
    assert_eq!(pair.fcc.active_mission(), None);
    assert!(!pair.fcc.waypoint_list().is_active());
    // One message: the clear deletes the active list itself (ICD §5.1 step 1).
    let sent: Vec<&Message> = pair.sent[from..]
        .iter()
        .filter(|s| s.direction == Direction::Up)
        .map(|s| &s.message)
        .collect();
    assert!(
        matches!(sent[..], [Message::MissionTransferCommand(c)] if c.mode == MissionPlanMode::ClearMission),
        "{sent:?}"
    );
    // A download then says the FCC holds no mission, in those words.
    let now = pair.now;
    pair.gcs.download(now).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    let events = pair.take_gcs_events();
    let Some(GcsEvent::Failed(error @ GcsError::NoMission)) = events.last() else {
        panic!("the download did not find no mission: {events:?}");
    };
    assert!(
        error.to_string().starts_with("the FCC holds no mission"),
        "{error}"
    );
}

#[test]
fn from_to_next_reaches_the_gcs_on_every_change_only() {
    use missionlink_interfaces::contracts::GuidanceProgressPayload;
    let mut pair = Pair::new(9);
    upload(&mut pair, &mission_2(), true);
    pair.take_gcs_events();
    let before = pair.sent.len();
    for (from, to, next) in [(0, 1, 2), (0, 1, 2), (1, 2, 3), (1, 2, 3), (2, 3, 0)] {
        let progress = GuidanceProgressPayload {
            from,
            to,
            next,
            ..GuidanceProgressPayload::IDLE
        };
        let now = pair.now;
        pair.fcc.handle_progress(now, &progress);
        pair.run_until(now + Duration::from_millis(50));
    }
    let triples: Vec<(u16, u16, u16)> = pair
        .take_gcs_events()
        .into_iter()
        .filter_map(|e| match e {
            GcsEvent::FromToNext(f) => Some((
                f.from.waypoint_number.unwrap(),
                f.to.waypoint_number.unwrap(),
                f.next.waypoint_number.unwrap(),
            )),
            _ => None,
        })
        .collect();
    assert_eq!(triples, [(0, 1, 2), (1, 2, 3), (2, 3, 0)]);
    // Not acknowledged (ICD §5.5): nothing goes up.
    assert!(
        pair.sent[before..]
            .iter()
            .all(|s| s.direction == Direction::Down && !s.ack_requested)
    );
}

#[test]
fn the_safety_gateway_can_refuse_and_then_nothing_is_sent() {
    use missionlink_ground::ground_station::{GroundStation, SafetyGateway};
    use missionlink_protocol::transfer::areas::AreaList;
    use missionlink_protocol::transfer::mission::Mission;

    /// Refuses missions with more than `max` waypoints.
    struct MaxWaypoints(usize);
    impl SafetyGateway for MaxWaypoints {
        type Report = String;
        fn check(
            &self,
            mission: &Mission,
            _: &AreaList,
            _: Option<GeoPoint>,
        ) -> Result<(), String> {
            match mission.waypoints.len() {
                n if n > self.0 => Err(format!("{n} waypoints, at most {}", self.0)),
                _ => Ok(()),
            }
        }
    }
    let mut gcs = GroundStation::new(gcs_config(), MaxWaypoints(2));
    assert!(gcs.validate(&mission_1()).is_ok());
    let now = missionlink_protocol::link::time::Instant::ZERO;
    assert_eq!(
        gcs.upload(now, &mission_2(), true),
        Err(GcsError::Gateway("3 waypoints, at most 2".to_owned()))
    );
    assert!(gcs.frames().is_empty());
    assert!(gcs.is_standby());
}

#[test]
fn plans_describe_themselves_in_one_line() {
    let plan = mission_2();
    assert_eq!(
        plan.to_string(),
        r#"plan "MEDEVAC-2": 3 waypoints, 3 areas, safety offset 25.0 m"#
    );
    let valid = Pair::new(1).gcs.validate(&plan).unwrap();
    // The wording of `gcs validate` (docs/gcs.md).
    assert_eq!(
        valid.to_string(),
        r#"mission "MEDEVAC-2": take-off 30.0 m, 3 waypoints (1 -> 2 -> 3), route bidirectional; 3 areas, safety offset 25.0 m"#
    );
    let one = Pair::new(1).gcs.validate(&mission_1()).unwrap();
    assert_eq!(
        one.to_string(),
        r#"mission "MEDEVAC-1": take-off 30.0 m, 1 waypoints (1), route one-way; 1 areas, safety offset 25.0 m"#
    );
}

/// The position downlink (ICD §5.8) through signed links: with its default rate the FCC sends
/// #101 every 500 ms of simulated time from guidance's first progress, never acknowledged; the
/// GCS receives each with the latest position, the course of the last movement and the ground
/// speed.
#[test]
fn positions_reach_the_gcs_at_2_hz_signed_and_unacknowledged() {
    use missionlink_flight::mission_data_handling::{FccConfig, MissionDataHandling};
    use missionlink_flight::position::DEFAULT_PERIOD;
    use missionlink_interfaces::contracts::GuidanceProgressPayload;
    use missionlink_interfaces::wire::MessageType;
    use missionlink_protocol::link::signing::Policy;

    let mut pair = Pair::signed(23, Policy::Require, Policy::Require);
    pair.fcc = MissionDataHandling::new(FccConfig {
        position_period: Some(DEFAULT_PERIOD),
        ..fcc_config()
    });
    upload(&mut pair, &mission_2(), true);
    pair.take_gcs_events();
    let before = pair.sent.len();
    let wire_before = pair.wire.len();
    let start = pair.now;
    // Guidance reports every 100 ms for 5 s, flying due east.
    for step in 0..50u32 {
        let progress = GuidanceProgressPayload {
            sequence: u64::from(step) + 1,
            latitude_deg: 48.27,
            longitude_deg: 11.64 + f64::from(step) * 1e-4,
            altitude_m: 120.0,
            ground_speed_mps: 25.0,
            on_ground: false,
            ..GuidanceProgressPayload::IDLE
        };
        let now = start + Duration::from_millis(u64::from(step) * 100);
        pair.run_until(now);
        pair.fcc.handle_progress(now, &progress);
    }
    pair.run_until(start + Duration::from_millis(4_950));
    let positions: Vec<_> = pair
        .take_gcs_events()
        .into_iter()
        .filter_map(|e| match e {
            GcsEvent::Position(p) => Some(p),
            _ => None,
        })
        .collect();
    // At 0, 500, ..., 4500 ms.
    assert_eq!(positions.len(), 10, "{positions:?}");
    let sent: Vec<_> = pair.sent[before..]
        .iter()
        .filter(|s| s.message.message_type() == MessageType::InertialStates)
        .collect();
    assert_eq!(sent.len(), 10);
    for (i, s) in sent.iter().enumerate() {
        assert_eq!(s.direction, Direction::Down);
        assert!(!s.ack_requested, "#101 is never acknowledged");
        assert_eq!(s.at, start + Duration::from_millis(500 * i as u64));
    }
    // Nothing answers it.
    assert!(
        pair.sent[before..]
            .iter()
            .all(|s| s.direction == Direction::Down)
    );
    // Every #101 on the wire is signed (ICD §9: Message Properties bit 5).
    let on_wire: Vec<_> = pair.wire[wire_before..]
        .iter()
        .filter(|(_, _, bytes)| bytes[12..14] == [0x00, 0x65])
        .collect();
    assert_eq!(on_wire.len(), 20, "both links");
    assert!(on_wire.iter().all(|(_, _, b)| b[15] & 0x20 != 0));
    // The last, at 4500 ms, went before that instant's progress: it tells the one of 4400 ms.
    let last = positions.last().unwrap();
    let p = last.position().unwrap();
    assert!((p.latitude.degrees() - 48.27).abs() < 1e-6);
    assert!((p.longitude.degrees() - (11.64 + 44.0 * 1e-4)).abs() < 1e-6);
    assert!((last.course_deg().unwrap() - 90.0).abs() < 0.5, "{last}");
    assert!(
        (last.ground_speed_mps().unwrap() - 25.0).abs() < 0.05,
        "{last}"
    );
    assert_eq!(last.altitude.unwrap().metres(), 120.0);
}
