//! The MAVLink vehicle in scripted time.

use mavlink::dialects::common::{
    COMMAND_LONG_DATA, MISSION_REQUEST_LIST_DATA, MavMissionType as T,
};

use super::*;
use crate::qgc::ImportOptions;
use mavlink::Message as _;

fn at(ms: u64) -> Instant {
    Instant::from_millis(ms)
}

fn config() -> VehicleConfig {
    VehicleConfig {
        system_id: SYSTEM_ID,
        heartbeat: Duration::from_secs(1),
        item_timeout: Duration::from_millis(1500),
        item_retries: 3,
        fence_wait: Duration::from_secs(2),
        plan: PlanContext {
            cruise_speed_mps: 25.0,
            home: None,
            import: ImportOptions::default(),
        },
    }
}

/// What the vehicle sent since the last call, decoded.
fn sent(b: &mut Vehicle) -> Vec<MavMessage> {
    let mut out = Vec::new();
    let mut buf = [0u8; 300];
    while let Some(len) = b.poll_transmit(&mut buf) {
        out.extend(decode(&buf[..len]));
    }
    out
}

/// The client's message, through the bytes of a datagram.
fn from_client(b: &mut Vehicle, now: Instant, m: MavMessage) {
    let mut buf = [0u8; 300];
    let mut out: &mut [u8] = &mut buf;
    let header = MavHeader {
        system_id: 255,
        component_id: 190,
        sequence: 0,
    };
    let len = mavlink::write_v2_msg(&mut out, header, &m).unwrap();
    b.handle_datagram(now, &buf[..len]);
}

#[allow(
    clippy::too_many_arguments,
    reason = "a MISSION_ITEM_INT in one line: its fields"
)]
fn item(
    seq: u16,
    kind: T,
    command: MavCmd,
    frame: MavFrame,
    p1: f32,
    lat: f64,
    lon: f64,
    z: f32,
) -> MavMessage {
    MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
        param1: p1,
        param2: 0.0,
        param3: 0.0,
        param4: 0.0,
        x: (lat * 1e7).round() as i32,
        y: (lon * 1e7).round() as i32,
        z,
        seq,
        command,
        target_system: SYSTEM_ID,
        target_component: COMPONENT_ID,
        frame,
        current: 0,
        autocontinue: 1,
        mission_type: kind,
    })
}

fn mission() -> Vec<MavMessage> {
    let rel = MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT;
    let m = T::MAV_MISSION_TYPE_MISSION;
    vec![
        item(
            0,
            m,
            MavCmd::MAV_CMD_NAV_TAKEOFF,
            rel,
            0.0,
            48.26,
            11.66,
            30.0,
        ),
        item(
            1,
            m,
            MavCmd::MAV_CMD_NAV_WAYPOINT,
            rel,
            0.0,
            48.265,
            11.655,
            120.0,
        ),
        item(
            2,
            m,
            MavCmd::MAV_CMD_NAV_WAYPOINT,
            rel,
            0.0,
            48.275,
            11.645,
            120.0,
        ),
    ]
}

fn fence() -> Vec<MavMessage> {
    let f = T::MAV_MISSION_TYPE_FENCE;
    let g = MavFrame::MAV_FRAME_GLOBAL;
    let corners = [
        (48.255, 11.635),
        (48.255, 11.69),
        (48.285, 11.69),
        (48.285, 11.635),
    ];
    let mut items: Vec<MavMessage> = corners
        .iter()
        .enumerate()
        .map(|(i, &(lat, lon))| {
            item(
                i as u16,
                f,
                MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION,
                g,
                4.0,
                lat,
                lon,
                0.0,
            )
        })
        .collect();
    items.push(item(
        4,
        f,
        MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION,
        g,
        200.0,
        48.268,
        11.675,
        0.0,
    ));
    items
}

/// Uploads `items` of `kind` as a client does: count, then each item the vehicle requests.
fn upload(b: &mut Vehicle, now: Instant, kind: T, items: &[MavMessage]) -> Vec<MavMessage> {
    from_client(
        b,
        now,
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: items.len() as u16,
            target_system: SYSTEM_ID,
            target_component: COMPONENT_ID,
            mission_type: kind,
            opaque_id: 0,
        }),
    );
    let mut out = Vec::new();
    loop {
        let got = sent(b);
        let request = got.iter().find_map(|m| match m {
            MavMessage::MISSION_REQUEST_INT(r) => Some(r.seq),
            _ => None,
        });
        out.extend(got);
        match request {
            Some(seq) => from_client(b, now, items[usize::from(seq)].clone()),
            None => return out,
        }
    }
}

fn acks(messages: &[MavMessage]) -> Vec<(T, MavMissionResult)> {
    messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::MISSION_ACK(a) => Some((a.mission_type, a.mavtype)),
            _ => None,
        })
        .collect()
}

/// COMMAND_LONG of `command` with `param1`, the other params 0.
fn command_long(command: MavCmd, param1: f32) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1,
        param2: 0.0,
        param3: 0.0,
        param4: 0.0,
        param5: 0.0,
        param6: 0.0,
        param7: 0.0,
        command,
        target_system: SYSTEM_ID,
        target_component: COMPONENT_ID,
        confirmation: 0,
    })
}

/// The one MISSION_ACK of an accepted upload of `kind`.
fn accepted(kind: T) -> Vec<(T, MavMissionResult)> {
    vec![(kind, MavMissionResult::MAV_MISSION_ACCEPTED)]
}

fn texts(messages: &[MavMessage]) -> Vec<String> {
    messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::STATUSTEXT(t) => Some(
                String::from_utf8_lossy(&<[u8; 50]>::from(t.text))
                    .trim_end_matches('\0')
                    .to_owned(),
            ),
            _ => None,
        })
        .collect()
}

/// Scripted time: a HEARTBEAT at start and every second, nothing at t - 1 ms.
#[test]
fn heartbeat_once_a_second() {
    let mut b = Vehicle::new(config());
    b.start(at(0));
    b.handle_timeout(at(0));
    let first = sent(&mut b);
    // PX4's encoding: AUTO (4) in bits 16..24, LOITER (3) in bits 24..32, standing by.
    assert!(matches!(first.first(), Some(MavMessage::HEARTBEAT(h))
        if h.autopilot == MavAutopilot::MAV_AUTOPILOT_PX4
            && h.custom_mode == 0x0304_0000
            && h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED)));
    assert!(
        first
            .iter()
            .any(|m| matches!(m, MavMessage::EXTENDED_SYS_STATE(e)
        if e.landed_state == MavLandedState::MAV_LANDED_STATE_UNDEFINED))
    );
    assert_eq!(b.poll_timeout(), Some(at(1000)));
    b.handle_timeout(at(999));
    assert!(sent(&mut b).is_empty());
    b.handle_timeout(at(1000));
    assert!(matches!(
        sent(&mut b).first(),
        Some(MavMessage::HEARTBEAT(_))
    ));
}

/// QGroundControl's order: the mission is acknowledged as the pending half, the fence
/// commits the pair and is acknowledged when the FCC confirmed both; a download gives the
/// items back.
#[test]
fn mission_then_fence_commit_as_one() {
    let mut b = Vehicle::new(config());
    let out = upload(&mut b, at(0), T::MAV_MISSION_TYPE_MISSION, &mission());
    assert_eq!(acks(&out), accepted(T::MAV_MISSION_TYPE_MISSION));
    assert!(
        b.poll_event().is_none(),
        "nothing committed before the fence"
    );
    assert_eq!(b.poll_timeout(), Some(at(2000)));
    let out = upload(&mut b, at(100), T::MAV_MISSION_TYPE_FENCE, &fence());
    assert!(acks(&out).is_empty(), "the fence's ACK waits for the FCC");
    let Some(VehicleEvent::Commit { plan }) = b.poll_event() else {
        panic!("no commit");
    };
    assert_eq!(plan.plan.areas.len(), 2);
    assert_eq!(b.poll_timeout(), None, "the fence ended the wait");
    b.committed(Ok(()));
    let out = sent(&mut b);
    assert_eq!(acks(&out), accepted(T::MAV_MISSION_TYPE_FENCE));
    // Rally: none is accepted.
    let out = upload(&mut b, at(200), T::MAV_MISSION_TYPE_RALLY, &[]);
    assert_eq!(acks(&out), accepted(T::MAV_MISSION_TYPE_RALLY));
    // Download: the same items.
    for (kind, items) in [
        (T::MAV_MISSION_TYPE_MISSION, mission()),
        (T::MAV_MISSION_TYPE_FENCE, fence()),
    ] {
        from_client(
            &mut b,
            at(300),
            MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
                target_system: SYSTEM_ID,
                target_component: COMPONENT_ID,
                mission_type: kind,
            }),
        );
        let count = sent(&mut b);
        assert!(
            matches!(count.first(), Some(MavMessage::MISSION_COUNT(c)) if usize::from(c.count) == items.len())
        );
        for (seq, want) in items.iter().enumerate() {
            from_client(
                &mut b,
                at(300),
                MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                    seq: seq as u16,
                    target_system: SYSTEM_ID,
                    target_component: COMPONENT_ID,
                    mission_type: kind,
                }),
            );
            let (Some(MavMessage::MISSION_ITEM_INT(got)), MavMessage::MISSION_ITEM_INT(want)) =
                (sent(&mut b).first().cloned(), want)
            else {
                panic!("no item {seq}");
            };
            assert_eq!(
                (got.command, got.x, got.y, got.z, got.param1),
                (want.command, want.x, want.y, want.z, want.param1)
            );
        }
    }
}

/// A mission with no fence after it is committed with the fence held once the wait is
/// over: nothing at t - 1 ms, the commit at t.
#[test]
fn a_mission_alone_is_committed_after_the_wait() {
    let mut b = Vehicle::new(config());
    // Without a mission, a fence is held for the next one.
    let out = upload(&mut b, at(0), T::MAV_MISSION_TYPE_FENCE, &fence());
    assert_eq!(acks(&out), accepted(T::MAV_MISSION_TYPE_FENCE));
    assert!(b.poll_event().is_none());
    upload(&mut b, at(1000), T::MAV_MISSION_TYPE_MISSION, &mission());
    b.handle_timeout(at(2999));
    assert!(b.poll_event().is_none());
    b.handle_timeout(at(3000));
    let Some(VehicleEvent::Commit { plan }) = b.poll_event() else {
        panic!("no commit at the end of the wait")
    };
    assert_eq!(plan.plan.areas.len(), 2, "with the fence held");
    b.committed(Err("the safety gateway refused: energy".to_owned()));
    let t = texts(&sent(&mut b));
    assert!(t.iter().any(|t| t.contains("unchanged")), "{t:?}");
    assert_eq!(b.lists().0.len(), 0, "the FCC's lists stay as they were");
}

/// An item the ICD cannot carry: MISSION_ACK with an error and a STATUSTEXT naming it.
#[test]
fn a_refusal_names_the_item() {
    let mut b = Vehicle::new(config());
    let mut m = mission();
    m.insert(
        2,
        item(
            2,
            T::MAV_MISSION_TYPE_MISSION,
            MavCmd::MAV_CMD_NAV_LOITER_UNLIM,
            MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
            0.0,
            48.27,
            11.65,
            120.0,
        ),
    );
    let m: Vec<MavMessage> = m
        .into_iter()
        .enumerate()
        .map(|(i, mut msg)| {
            if let MavMessage::MISSION_ITEM_INT(d) = &mut msg {
                d.seq = i as u16;
            }
            msg
        })
        .collect();
    let out = upload(&mut b, at(0), T::MAV_MISSION_TYPE_MISSION, &m);
    assert_eq!(
        acks(&out),
        [(
            T::MAV_MISSION_TYPE_MISSION,
            MavMissionResult::MAV_MISSION_DENIED
        )]
    );
    let t = texts(&out).join("");
    assert!(t.contains("mission item 2"), "{t}");
    assert!(b.poll_event().is_none());
}

/// An item not sent is asked for again after the timeout, then the upload is abandoned.
#[test]
fn a_missing_item_is_asked_again_then_abandoned() {
    let mut b = Vehicle::new(config());
    from_client(
        &mut b,
        at(0),
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: 3,
            target_system: SYSTEM_ID,
            target_component: COMPONENT_ID,
            mission_type: T::MAV_MISSION_TYPE_MISSION,
            opaque_id: 0,
        }),
    );
    assert_eq!(sent(&mut b).len(), 1);
    b.handle_timeout(at(1499));
    assert!(sent(&mut b).is_empty());
    for k in 1..=3u64 {
        b.handle_timeout(at(1500 * k));
        assert!(
            matches!(sent(&mut b).first(), Some(MavMessage::MISSION_REQUEST_INT(r)) if r.seq == 0)
        );
    }
    b.handle_timeout(at(6000));
    assert_eq!(
        acks(&sent(&mut b)),
        [(
            T::MAV_MISSION_TYPE_MISSION,
            MavMissionResult::MAV_MISSION_OPERATION_CANCELLED
        )]
    );
}

/// Standing at `lat`, `lon`, `alt` m WGS-84 (the aircraft before take-off).
fn standing(lat: f64, lon: f64, alt: f64) -> InertialStates {
    let p = missionlink_interfaces::wire::GeoPoint::from_degrees(lat, lon).unwrap();
    InertialStates {
        latitude: Some(p.latitude),
        longitude: Some(p.longitude),
        altitude: Some(missionlink_interfaces::wire::Altitude::from_metres(alt).unwrap()),
        altitude_type: Some(AltitudeType::Wgs84),
        u_speed: Some(missionlink_interfaces::wire::Velocity::from_raw(0)),
        v_speed: Some(missionlink_interfaces::wire::Velocity::from_raw(0)),
        ..InertialStates::default()
    }
}

/// Flying: the monitor's example (120 m WGS-84, 25 m/s towards north-east), banked 20 deg
/// right, pitched 2 deg up, heading 40 deg, climbing 1.5 m/s.
fn flying() -> InertialStates {
    InertialStates {
        w_speed: Some(missionlink_interfaces::wire::Velocity::from_mps(-1.5).unwrap()),
        phi: InertialStates::roll_from_rad(20f64.to_radians()),
        theta: InertialStates::pitch_from_rad(2f64.to_radians()),
        psi: InertialStates::heading_from_rad(40f64.to_radians()),
        ..crate::monitor::tests::states()
    }
}

#[test]
#[allow(
    deprecated,
    reason = "GET_HOME_POSITION is superseded by REQUEST_MESSAGE, and MAVProxy still sends it"
)]
fn mission_start_executes_and_positions_become_global_position_int() {
    let mut b = Vehicle::new(config());
    b.start(at(0));
    // Standing before the mission: the home, sent once, above mean sea level by the geoid.
    b.handle_position(at(100), &standing(48.26, 11.66, 500.0));
    let n = crate::geoid::undulation_m(48.26, 11.66);
    let out = sent(&mut b);
    let Some(MavMessage::HOME_POSITION(h)) = out
        .iter()
        .find(|m| matches!(m, MavMessage::HOME_POSITION(_)))
    else {
        panic!("no HOME_POSITION: {out:?}")
    };
    assert_eq!((h.latitude, h.longitude), (482_600_000, 116_600_000));
    assert_eq!(h.altitude, ((500.0 - n) * 1000.0).round() as i32);
    b.handle_position(at(600), &standing(48.26, 11.66, 500.0));
    assert!(
        !sent(&mut b)
            .iter()
            .any(|m| matches!(m, MavMessage::HOME_POSITION(_))),
        "the home did not move: not sent again"
    );

    from_client(
        &mut b,
        at(700),
        command_long(MavCmd::MAV_CMD_MISSION_START, 0.0),
    );
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Execute)));
    b.executed(Ok(()));
    assert!(sent(&mut b).iter().any(
        |m| matches!(m, MavMessage::COMMAND_ACK(a) if a.result == MavResult::MAV_RESULT_ACCEPTED)
    ));
    // Flying: the home stays where the mission started.
    b.handle_position(at(1_000), &flying());
    let out = sent(&mut b);
    let [
        MavMessage::GLOBAL_POSITION_INT(g),
        MavMessage::ATTITUDE(a),
        MavMessage::VFR_HUD(v),
    ] = &out[..]
    else {
        panic!("GLOBAL_POSITION_INT, ATTITUDE and VFR_HUD: {out:?}")
    };
    let n_here = crate::geoid::undulation_m(48.2725, 11.6425);
    assert_eq!(
        (g.lat, g.lon, g.vx, g.vy, g.vz, g.hdg),
        (482_725_000, 116_425_000, 1770, 1770, -150, 4000)
    );
    assert_eq!(
        g.alt,
        ((120.0 - n_here) * 1000.0).round() as i32,
        "above mean sea level"
    );
    assert_eq!(g.relative_alt, -380_000, "above the home, 500 m");
    assert_eq!(g.time_boot_ms, 1_000);
    assert!((a.roll.to_degrees() - 20.0).abs() < 0.01, "{a:?}");
    assert!((a.pitch.to_degrees() - 2.0).abs() < 0.01, "{a:?}");
    assert!((a.yaw.to_degrees() - 40.0).abs() < 0.01, "{a:?}");
    assert!(a.rollspeed.is_nan(), "#101 carries no rates: unknown");
    assert!(v.airspeed.is_nan(), "#101 carries no airspeed: unknown");
    assert_eq!((v.heading, v.throttle), (40, u16::MAX));
    assert!(
        (v.groundspeed - 25.03).abs() < 0.01 && (v.climb - 1.5).abs() < 0.01,
        "{v:?}"
    );
    assert!((f64::from(v.alt) - (120.0 - n_here)).abs() < 0.01);
    // The home is the one the mission started from, asked for in both ways.
    for (command, id) in [
        (MavCmd::MAV_CMD_REQUEST_MESSAGE, 242.0),
        (MavCmd::MAV_CMD_GET_HOME_POSITION, 0.0),
    ] {
        from_client(&mut b, at(1_100), command_long(command, id));
        let out = sent(&mut b);
        assert!(
            matches!(&out[..], [MavMessage::COMMAND_ACK(a), MavMessage::HOME_POSITION(h)]
                if a.result == MavResult::MAV_RESULT_ACCEPTED && h.latitude == 482_600_000),
            "{out:?}"
        );
    }
}

#[test]
fn home_position_is_asked_again_until_a_position_tells_it() {
    let mut b = Vehicle::new(config());
    from_client(
        &mut b,
        at(0),
        command_long(MavCmd::MAV_CMD_REQUEST_MESSAGE, 242.0),
    );
    let out = sent(&mut b);
    assert!(
        matches!(&out[..], [MavMessage::COMMAND_ACK(a)]
            if a.result == MavResult::MAV_RESULT_TEMPORARILY_REJECTED),
        "{out:?}"
    );
    // A message the vehicle does not send is unsupported; the ones it sends are sent.
    from_client(
        &mut b,
        at(0),
        command_long(MavCmd::MAV_CMD_REQUEST_MESSAGE, 33.0),
    );
    assert!(matches!(&sent(&mut b)[..], [MavMessage::COMMAND_ACK(a)]
        if a.result == MavResult::MAV_RESULT_UNSUPPORTED));
    from_client(
        &mut b,
        at(0),
        command_long(MavCmd::MAV_CMD_REQUEST_MESSAGE, 1.0),
    );
    assert!(
        matches!(&sent(&mut b)[..], [MavMessage::COMMAND_ACK(_), MavMessage::SYS_STATUS(s)]
        if s.voltage_battery == u16::MAX && s.battery_remaining == -1)
    );
}

#[test]
fn the_second_heartbeat_has_sys_status_with_the_links_counts() {
    let mut b = Vehicle::new(config());
    b.start(at(0));
    b.set_link_counts(1000, 25);
    b.handle_timeout(at(0));
    let out = sent(&mut b);
    let kinds: Vec<&str> = out.iter().map(|m| m.message_name()).collect();
    assert_eq!(
        kinds,
        [
            "HEARTBEAT",
            "EXTENDED_SYS_STATE",
            "SYS_STATUS",
            "MISSION_CURRENT"
        ]
    );
    let Some(MavMessage::SYS_STATUS(s)) = out.get(2) else {
        panic!("{out:?}")
    };
    assert_eq!(
        (s.errors_comm, s.drop_rate_comm),
        (25, 250),
        "2.5 % in 0.01 %"
    );
}

/// The lists as the client uploaded them and the home, remembered across a restart; items of
/// lists the FCC no longer holds are not taken.
#[test]
fn a_restarted_vehicle_downloads_what_was_uploaded() {
    let mut b = Vehicle::new(config());
    b.start(at(0));
    b.handle_position(at(0), &standing(48.26, 11.66, 0.0));
    upload(&mut b, at(0), T::MAV_MISSION_TYPE_MISSION, &mission());
    upload(&mut b, at(10), T::MAV_MISSION_TYPE_FENCE, &fence());
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Commit { .. })));
    b.set_ids(0x1234, 0x5678);
    b.committed(Ok(()));
    let memory = b.memory().expect("the commit is remembered");
    assert!(b.memory().is_none(), "once");
    let memory = super::super::memory::Memory::from_text(&memory.to_text()).unwrap();

    // The FCC's lists read back (a take-off becomes a waypoint, a land is added): not what
    // the client sent, until the memory is recalled under the same checksums.
    let exported = vec![
        Item {
            command: 16,
            frame: 3,
            params: [0.0; 4],
            x: 482_600_000,
            y: 116_600_000,
            z: 30.0
        };
        4
    ];
    let mut restarted = Vehicle::new(config());
    restarted.set_lists(exported.clone(), Vec::new());
    restarted.set_ids(0x1234, 0x5678);
    restarted.recall(memory.clone());
    assert_eq!(restarted.lists().0.len(), 3);
    assert_eq!(
        restarted.lists().0[0].command,
        22,
        "the take-off as uploaded"
    );
    assert_eq!(restarted.lists().1.len(), fence().len());
    assert_eq!(restarted.home(), b.home());

    // Another ground station uploaded since: the FCC's lists stand.
    let mut other = Vehicle::new(config());
    other.set_lists(exported.clone(), Vec::new());
    other.set_ids(0x9999, 0x5678);
    other.recall(memory);
    assert_eq!(other.lists().0, &exported[..]);
}

#[test]
fn autopilot_version_names_mission_int_and_fence() {
    let mut b = Vehicle::new(config());
    from_client(
        &mut b,
        at(0),
        command_long(MavCmd::MAV_CMD_REQUEST_MESSAGE, 148.0),
    );
    let out = sent(&mut b);
    let [MavMessage::COMMAND_ACK(_), MavMessage::AUTOPILOT_VERSION(v)] = &out[..] else {
        panic!("the acknowledgement, then the message: {out:?}")
    };
    assert!(v.capabilities.contains(
        MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_MISSION_INT
            | MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_MISSION_FENCE
    ));
}

/// Datagrams from anyone: every prefix of a valid one, and bytes from a fixed-seed
/// generator, never panic; what does not parse is counted.
#[test]
fn any_bytes_are_counted_never_a_panic() {
    let mut b = Vehicle::new(config());
    let mut buf = [0u8; 300];
    let mut out: &mut [u8] = &mut buf;
    let len = mavlink::write_v2_msg(&mut out, MavHeader::default(), &mission()[1]).unwrap();
    for cut in 0..len {
        b.handle_datagram(at(0), &buf[..cut]);
    }
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut bytes = [0u8; 300];
    for round in 0..2000 {
        for byte in bytes.iter_mut() {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            *byte = seed as u8;
        }
        // Every fourth datagram starts as a MAVLink 2 frame does.
        if round % 4 == 0 {
            bytes[0] = 0xfd;
        }
        b.handle_datagram(at(0), &bytes[..(round % 300)]);
    }
    assert!(b.unreadable >= 1000, "{}", b.unreadable);
}

/// The target of a reply, for those messages that have one.
fn target(m: &MavMessage) -> Option<(u8, u8)> {
    match m {
        MavMessage::MISSION_REQUEST_INT(r) => Some((r.target_system, r.target_component)),
        MavMessage::MISSION_ACK(a) => Some((a.target_system, a.target_component)),
        MavMessage::MISSION_COUNT(c) => Some((c.target_system, c.target_component)),
        MavMessage::MISSION_ITEM_INT(i) => Some((i.target_system, i.target_component)),
        MavMessage::COMMAND_ACK(a) => Some((a.target_system, a.target_component)),
        _ => None,
    }
}

/// Every reply goes to the client that asked (255, 190): the upload's requests and acks, the
/// fence's ack held until the commit, a download, a COMMAND_ACK.
#[test]
fn replies_go_to_the_client_that_asked() {
    let mut b = Vehicle::new(config());
    let mut out = upload(&mut b, at(0), T::MAV_MISSION_TYPE_MISSION, &mission());
    out.extend(upload(&mut b, at(10), T::MAV_MISSION_TYPE_FENCE, &fence()));
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Commit { .. })));
    b.committed(Ok(()));
    out.extend(sent(&mut b));
    from_client(
        &mut b,
        at(20),
        MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
            target_system: SYSTEM_ID,
            target_component: COMPONENT_ID,
            mission_type: T::MAV_MISSION_TYPE_MISSION,
        }),
    );
    from_client(
        &mut b,
        at(20),
        MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
            seq: 0,
            target_system: SYSTEM_ID,
            target_component: COMPONENT_ID,
            mission_type: T::MAV_MISSION_TYPE_MISSION,
        }),
    );
    from_client(
        &mut b,
        at(30),
        command_long(MavCmd::MAV_CMD_DO_SET_MODE, 1.0),
    );
    out.extend(sent(&mut b));
    let targets: Vec<(u8, u8)> = out.iter().filter_map(target).collect();
    assert!(targets.len() >= 12, "{out:?}");
    assert!(targets.iter().all(|t| *t == (255, 190)), "{targets:?}");
    for kind in [
        "MISSION_REQUEST_INT",
        "MISSION_ACK",
        "MISSION_COUNT",
        "MISSION_ITEM_INT",
    ] {
        assert!(
            out.iter().any(|m| format!("{m:?}").starts_with(kind)),
            "no {kind}"
        );
    }
    assert!(out.iter().any(|m| matches!(m, MavMessage::COMMAND_ACK(_))));
}

/// Commands and mission traffic addressed to another system or component are not answered and
/// change nothing; they are counted.
#[test]
fn traffic_for_another_vehicle_is_ignored() {
    let mut b = Vehicle::new(config());
    for (system, component) in [(7, 1), (1, 154)] {
        from_client(
            &mut b,
            at(0),
            MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
                count: 3,
                target_system: system,
                target_component: component,
                mission_type: T::MAV_MISSION_TYPE_MISSION,
                opaque_id: 0,
            }),
        );
        let mut start = command_long(MavCmd::MAV_CMD_MISSION_START, 0.0);
        if let MavMessage::COMMAND_LONG(c) = &mut start {
            c.target_system = system;
            c.target_component = component;
        }
        from_client(&mut b, at(0), start);
    }
    assert!(sent(&mut b).is_empty());
    assert!(b.poll_event().is_none());
    assert_eq!(b.elsewhere, 4);
    // Broadcast (0, 0) is for everyone.
    let mut start = command_long(MavCmd::MAV_CMD_MISSION_START, 0.0);
    if let MavMessage::COMMAND_LONG(c) = &mut start {
        c.target_system = 0;
        c.target_component = 0;
    }
    from_client(&mut b, at(0), start);
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Execute)));
}

/// The STATUSTEXT messages of one text: (id, chunk_seq, bytes without the padding).
fn chunks(messages: &[MavMessage]) -> Vec<(u16, u8, Vec<u8>)> {
    messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::STATUSTEXT(t) => {
                let bytes = <[u8; 50]>::from(t.text);
                let len = bytes.iter().position(|b| *b == 0).unwrap_or(50);
                Some((t.id, t.chunk_seq, bytes[..len].to_vec()))
            }
            _ => None,
        })
        .collect()
}

/// Short texts are one message of id 0; long ones are chunks under one id that end with a
/// chunk shorter than 50 bytes (empty when the length is a multiple of 50), none lost past 8.
#[test]
fn statustext_in_chunks_with_an_end_marker() {
    let mut b = Vehicle::new(config());
    b.statustext(MavSeverity::MAV_SEVERITY_INFO, "short");
    assert_eq!(chunks(&sent(&mut b)), [(0, 0, b"short".to_vec())]);

    let long: String = (0..523)
        .map(|i| char::from(b'a' + (i % 26) as u8))
        .collect();
    b.statustext(MavSeverity::MAV_SEVERITY_ERROR, &long);
    let c = chunks(&sent(&mut b));
    assert_eq!(c.len(), 11);
    assert!(c.iter().all(|(id, _, _)| *id == c[0].0 && *id != 0));
    assert!(
        c.iter()
            .enumerate()
            .all(|(n, (_, seq, _))| usize::from(*seq) == n)
    );
    assert_eq!(c[10].2.len(), 23);
    let joined: Vec<u8> = c.iter().flat_map(|(_, _, t)| t.clone()).collect();
    assert_eq!(joined, long.as_bytes());

    let hundred = "x".repeat(100);
    b.statustext(MavSeverity::MAV_SEVERITY_ERROR, &hundred);
    let c = chunks(&sent(&mut b));
    assert_eq!(c.len(), 3);
    assert!(c[2].2.is_empty(), "the end marker of a multiple of 50");
    assert_ne!(c[0].0, 0);

    let huge = "y".repeat(5000);
    b.statustext(MavSeverity::MAV_SEVERITY_ERROR, &huge);
    let c = chunks(&sent(&mut b));
    let joined: Vec<u8> = c.iter().flat_map(|(_, _, t)| t.clone()).collect();
    assert_eq!(joined.len(), STATUSTEXT_MAX);
    assert!(joined.ends_with(b"..."));
    assert!(c.last().is_some_and(|(_, _, t)| t.len() < 50));
}

fn clear_all(kind: T) -> MavMessage {
    MavMessage::MISSION_CLEAR_ALL(mavlink::dialects::common::MISSION_CLEAR_ALL_DATA {
        target_system: SYSTEM_ID,
        target_component: COMPONENT_ID,
        mission_type: kind,
    })
}

/// MISSION_CLEAR_ALL is the FCC's clear: the mission's (#13000 mode 1) or the areas' (#2011
/// mode 6); accepted, the list is empty; refused, MISSION_ACK DENIED with the FCC's reason in a
/// STATUSTEXT and the lists unchanged.
#[test]
fn clear_all_is_the_fccs_clear_and_its_refusal_says_why() {
    let mut b = Vehicle::new(config());
    upload(&mut b, at(0), T::MAV_MISSION_TYPE_MISSION, &mission());
    upload(&mut b, at(10), T::MAV_MISSION_TYPE_FENCE, &fence());
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Commit { .. })));
    b.committed(Ok(()));
    sent(&mut b);

    from_client(&mut b, at(20), clear_all(T::MAV_MISSION_TYPE_MISSION));
    assert!(matches!(
        b.poll_event(),
        Some(VehicleEvent::Clear {
            list: List::Mission
        })
    ));
    b.cleared(List::Mission, Err("refused GuidanceActive".to_owned()));
    let out = sent(&mut b);
    assert_eq!(
        acks(&out),
        [(
            T::MAV_MISSION_TYPE_MISSION,
            MavMissionResult::MAV_MISSION_DENIED
        )]
    );
    assert!(texts(&out).join("").contains("GuidanceActive"), "{out:?}");
    assert_eq!(b.lists().0.len(), mission().len());

    from_client(&mut b, at(30), clear_all(T::MAV_MISSION_TYPE_ALL));
    assert!(matches!(
        b.poll_event(),
        Some(VehicleEvent::Clear {
            list: List::Mission
        })
    ));
    assert!(matches!(
        b.poll_event(),
        Some(VehicleEvent::Clear { list: List::Fence })
    ));
    b.cleared(List::Mission, Ok(()));
    assert!(
        acks(&sent(&mut b)).is_empty(),
        "the ack waits for both clears"
    );
    b.cleared(List::Fence, Ok(()));
    let out = sent(&mut b);
    assert_eq!(
        acks(&out),
        [(
            T::MAV_MISSION_TYPE_ALL,
            MavMissionResult::MAV_MISSION_ACCEPTED
        )]
    );
    assert!(out.iter().filter_map(target).all(|t| t == (255, 190)));
    assert_eq!(b.lists(), (&[][..], &[][..]));
}

fn from_to_next(to: u16) -> FromToNext {
    FromToNext {
        time_stamp: missionlink_interfaces::wire::Timestamp::from_millis(1).unwrap(),
        altitude_type: None,
        speed_type: None,
        from: Default::default(),
        to: missionlink_interfaces::wire::WaypointState {
            waypoint_number: Some(to),
            ..Default::default()
        },
        next: Default::default(),
        loiter_configuration_report_validity: None,
    }
}

/// #4001 after start: MISSION_ITEM_REACHED for every item once, in order, MISSION_CURRENT on
/// the TO waypoint's item, and at the end (TO 0) MISSION_STATE_COMPLETE on the last item with
/// the plan's checksums; the heartbeat says AUTO.MISSION and in the air meanwhile.
#[test]
fn progress_reaches_every_item_and_completes_on_the_last() {
    let mut b = Vehicle::new(config());
    upload(&mut b, at(0), T::MAV_MISSION_TYPE_MISSION, &mission());
    upload(&mut b, at(10), T::MAV_MISSION_TYPE_FENCE, &fence());
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Commit { .. })));
    b.set_ids(0x1234_5678, 0x9abc_def0);
    b.committed(Ok(()));
    b.start(at(20));
    from_client(
        &mut b,
        at(20),
        command_long(MavCmd::MAV_CMD_MISSION_START, 0.0),
    );
    assert!(matches!(b.poll_event(), Some(VehicleEvent::Execute)));
    b.executed(Ok(()));
    sent(&mut b);
    let total = b.lists().0.len() as u16;
    let mut reached = Vec::new();
    let mut last = None;
    for to in [1, 1, 2, 0] {
        b.handle_from_to_next(&from_to_next(to));
        for m in sent(&mut b) {
            match m {
                MavMessage::MISSION_ITEM_REACHED(r) => reached.push(r.seq),
                MavMessage::MISSION_CURRENT(c) => last = Some(c),
                _ => {}
            }
        }
        if to == 2 {
            b.handle_timeout(at(1020));
            let beat = sent(&mut b);
            assert!(beat.iter().any(|m| matches!(m, MavMessage::HEARTBEAT(h)
                if h.custom_mode == 0x0404_0000)));
            assert!(
                beat.iter()
                    .any(|m| matches!(m, MavMessage::EXTENDED_SYS_STATE(e)
                if e.landed_state == MavLandedState::MAV_LANDED_STATE_IN_AIR))
            );
        }
    }
    assert_eq!(reached, (0..total).collect::<Vec<_>>());
    let c = last.unwrap();
    assert_eq!(c.mission_state, MissionState::MISSION_STATE_COMPLETE);
    assert_eq!((c.seq, c.total), (total - 1, total));
    assert_eq!((c.mission_id, c.fence_id), (0x1234_5678, 0x9abc_def0));
}
