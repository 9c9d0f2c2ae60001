//! Property tests of the wire layer (ICD §2 to §4):
//!
//! - every valid value of each of the thirteen messages (edition 2, ICD rev. 2), in any envelope, survives `wire::encode`
//!   then `wire::decode` unchanged (the types store exact wire values);
//! - the physical-unit constructors round-trip within half an LSB;
//! - `wire::decode`, `wire::frames` and `Message::decode` never panic, whatever the bytes;
//! - a datagram of several frames back to back is walked into exactly those frames.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::fmt::Debug;

use missionlink_interfaces::capacity::{MAX_POLYGON_VERTICES, MIN_POLYGON_VERTICES};
use missionlink_interfaces::wire::{
    self, AckType, Altitude, AltitudeType, Angle, AreaDownloadStatus, AreaListStatus,
    AreaPolygonLoopSegment, AreaShape, AreaStatusAlert, AreaTransferMode, AreaTransmissionCommand,
    AreaTransmissionStatus, AreaType, Checksum, ChecksumWidth, DecodeError, EncodeError, Envelope,
    ExecuteCommand, FrameError, FromToNext, FromWaypointState, GeoPoint, GeofenceCheck, HEADER_LEN,
    InertialStates, LegType, LocationType, MAX_DATA_LEN, MAX_FRAME_LEN, Message,
    MessageAcknowledgement, MessageType, MissionExecuteCommand, MissionPlanMode, MissionReport,
    MissionTransferCommand, MissionUploadDownloadStatus, PolygonVertices, Reason, RouteType,
    SafetyOffset, SpecificData, Speed, SpeedType, Text, Timestamp, TransferStatus, TransferWindow,
    TurnDirection, TurnType, U3, UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint, Velocity,
    WaypointState, WindowOrChecksum,
};
use proptest::collection::vec;
use proptest::option;
use proptest::prelude::*;
use proptest::sample::{Index, select};

// ---------------------------------------------------------------------------------------------
// Field strategies
// ---------------------------------------------------------------------------------------------

/// One of the values of an enumeration (each has `ALL`).
fn pick<T: Clone + Debug + 'static>(all: &'static [T]) -> impl Strategy<Value = T> {
    select(all)
}

/// Any U5 time stamp, with its bounds more likely than chance.
fn time_stamp() -> impl Strategy<Value = Timestamp> {
    prop_oneof![
        1 => Just(0),
        1 => Just(Timestamp::MAX_MILLIS),
        8 => 0..=Timestamp::MAX_MILLIS,
    ]
    .prop_map(|ms| Timestamp::from_millis(ms).unwrap())
}

/// Any U3 (24 bits).
fn u3() -> impl Strategy<Value = U3> {
    prop_oneof![1 => Just(U3::MAX), 8 => 0..=U3::MAX].prop_map(|v| U3::new(v).unwrap())
}

/// A latitude: raw BAM4 within +-2^30 (+-90 deg).
fn latitude() -> impl Strategy<Value = Angle> {
    prop_oneof![
        1 => Just(1i32 << 30),
        1 => Just(-(1i32 << 30)),
        8 => -(1i32 << 30)..=(1 << 30),
    ]
    .prop_map(Angle::from_raw)
}

/// A longitude: any raw BAM4.
fn longitude() -> impl Strategy<Value = Angle> {
    prop_oneof![
        1 => Just(i32::MIN),
        1 => Just(i32::MAX),
        8 => any::<i32>(),
    ]
    .prop_map(Angle::from_raw)
}

fn geo_point() -> impl Strategy<Value = GeoPoint> {
    (latitude(), longitude()).prop_map(|(latitude, longitude)| GeoPoint {
        latitude,
        longitude,
    })
}

/// Any ALT3: raw within -2^23..2^23.
fn altitude() -> impl Strategy<Value = Altitude> {
    prop_oneof![
        1 => Just(-(1i32 << 23)),
        1 => Just((1i32 << 23) - 1),
        8 => -(1i32 << 23)..(1 << 23),
    ]
    .prop_map(|raw| Altitude::from_raw(raw).unwrap())
}

/// A height above ground: ALT3 not below 0.
fn height() -> impl Strategy<Value = Altitude> {
    (0..(1i32 << 23)).prop_map(|raw| Altitude::from_raw(raw).unwrap())
}

/// Any SPD2.
fn speed() -> impl Strategy<Value = Speed> {
    any::<u16>().prop_map(Speed::from_raw)
}

/// A waypoint speed of #13002: above 0.
fn flying_speed() -> impl Strategy<Value = Speed> {
    (1..=u16::MAX).prop_map(Speed::from_raw)
}

fn safety_offset() -> impl Strategy<Value = SafetyOffset> {
    any::<u16>().prop_map(SafetyOffset::from_raw)
}

/// A CharN: 0 to N-1 printable ASCII characters.
fn text<const N: usize>() -> impl Strategy<Value = Text<N>> {
    proptest::string::string_regex(&format!("[ -~]{{0,{}}}", N - 1))
        .unwrap()
        .prop_map(|s| Text::new(&s).unwrap())
}

/// A CharN that is not empty: 1 to N-1 printable ASCII characters (a staged Mission ID, ICD §8).
fn named<const N: usize>() -> impl Strategy<Value = Text<N>> {
    proptest::string::string_regex(&format!("[ -~]{{1,{}}}", N - 1))
        .unwrap()
        .prop_map(|s| Text::new(&s).unwrap())
}

/// Any U4 checksum (ICD §11).
fn checksum() -> impl Strategy<Value = Checksum> {
    any::<u32>().prop_map(Checksum::new)
}

/// A Transfer Window, 1..=32 (ICD §10.2).
fn transfer_window() -> impl Strategy<Value = TransferWindow> {
    (TransferWindow::MIN..=TransferWindow::MAX).prop_map(|w| TransferWindow::new(w).unwrap())
}

/// A waypoint number (and area ID): 1..=65534.
fn waypoint_number() -> impl Strategy<Value = u16> {
    prop_oneof![1 => Just(1u16), 1 => Just(65534u16), 8 => 1..=65534u16]
}

// ---------------------------------------------------------------------------------------------
// Message strategies: every valid value of each message of ICD §4
// ---------------------------------------------------------------------------------------------

fn message_acknowledgement() -> impl Strategy<Value = MessageAcknowledgement> {
    (
        time_stamp(),
        time_stamp(),
        any::<u16>(),
        pick(AckType::ALL),
        option::of(pick(Reason::ALL)),
    )
        .prop_map(
            |(time_stamp, original_time_stamp, original_message_type, ack_type, reject_reason)| {
                MessageAcknowledgement {
                    time_stamp,
                    original_time_stamp,
                    original_message_type,
                    ack_type,
                    reject_reason,
                }
            },
        )
}

fn mission_transfer_command() -> impl Strategy<Value = MissionTransferCommand> {
    (
        time_stamp(),
        option::of(text::<20>()),
        named::<20>(),
        pick(MissionPlanMode::ALL),
        option::of(any::<u16>()),
        any::<u16>(),
        option::of(text::<33>()),
        option::of(u3()),
        option::of(transfer_window()),
        option::of(checksum()),
    )
        .prop_map(
            |(
                time_stamp,
                mission_id,
                staged,
                mode,
                waypoint_number,
                fallback,
                route_id,
                activity_id,
                transfer_window,
                mission_checksum,
            )| {
                use MissionPlanMode as Mode;
                // Mission ID is M and not empty for modes 6, 8, 9, M for mode 10, absent or
                // empty for mode 7 (ICD §8).
                let mission_id = match mode {
                    Mode::DeleteStagedMission | Mode::StageMission | Mode::ReceiveStagedMission => {
                        Some(staged)
                    }
                    Mode::LoadWaypointBuffer => Some(mission_id.unwrap_or(staged)),
                    Mode::ReportMissions => mission_id.map(|_| Text::default()),
                    _ => mission_id,
                };
                // Waypoint Number is M for modes 2 (transmit mission) and 8 (stage mission).
                let transmits = matches!(mode, Mode::TransmitMission | Mode::StageMission);
                let waypoint_number = if transmits {
                    Some(waypoint_number.unwrap_or(fallback))
                } else {
                    waypoint_number
                };
                // The extension fields only with the modes their table names (ICD §3).
                let receives = matches!(mode, Mode::ReceiveMission | Mode::ReceiveStagedMission);
                MissionTransferCommand {
                    time_stamp,
                    mission_id,
                    mode,
                    waypoint_number,
                    route_id,
                    activity_id,
                    transfer_window: transfer_window.filter(|_| receives),
                    mission_checksum: mission_checksum.filter(|_| transmits),
                }
            },
        )
}

fn ua_route() -> impl Strategy<Value = UaRoute> {
    (
        time_stamp(),
        waypoint_number(),
        option::of(text::<33>()),
        option::of(pick(RouteType::ALL)),
        any::<bool>(),
        option::of(speed()),
    )
        .prop_map(
            |(time_stamp, initial_waypoint, route_id, route_type, bidirectional, planning_wind)| {
                UaRoute {
                    time_stamp,
                    initial_waypoint,
                    route_id,
                    route_type,
                    bidirectional,
                    planning_wind,
                }
            },
        )
}

fn ua_position_waypoint() -> impl Strategy<Value = UaPositionWaypoint> {
    (
        (
            time_stamp(),
            waypoint_number(),
            latitude(),
            longitude(),
            option::of(pick(LocationType::ALL)),
            altitude(),
            option::of(pick(AltitudeType::ALL)),
            option::of(any::<u8>()),
        ),
        (
            flying_speed(),
            option::of(pick(SpeedType::ALL)),
            prop_oneof![Just(0u16), 0..=65534u16],
            pick(TurnType::ALL),
            option::of(any::<u8>()),
            pick(LegType::ALL),
            option::of(any::<u8>()),
            option::of(any::<u16>()),
            option::of(time_stamp()),
            option::of(u3()),
        ),
    )
        .prop_map(
            |(
                (
                    time_stamp,
                    waypoint_number,
                    latitude,
                    longitude,
                    location_type,
                    altitude,
                    altitude_type,
                    altitude_change_behaviour,
                ),
                (
                    speed,
                    speed_type,
                    next_waypoint,
                    turn_type,
                    optional_messages,
                    leg_type,
                    limit_type,
                    loop_limit,
                    arrival_time,
                    activity_id,
                ),
            )| UaPositionWaypoint {
                time_stamp,
                waypoint_number,
                latitude,
                longitude,
                location_type,
                altitude,
                altitude_type,
                altitude_change_behaviour,
                speed,
                speed_type,
                next_waypoint,
                turn_type,
                optional_messages,
                leg_type,
                limit_type,
                loop_limit,
                arrival_time,
                activity_id,
            },
        )
}

fn vehicle_specific_waypoint() -> impl Strategy<Value = VehicleSpecificWaypoint> {
    let data = prop_oneof![
        height().prop_map(|height| SpecificData::TakeOffHeight { height }),
        (
            waypoint_number(),
            latitude(),
            longitude(),
            pick(TurnDirection::ALL)
        )
            .prop_map(|(waypoint_number, latitude, longitude, turn_direction)| {
                SpecificData::RfCentre {
                    waypoint_number,
                    latitude,
                    longitude,
                    turn_direction,
                }
            }),
    ];
    (time_stamp(), data, option::of(u3())).prop_map(|(time_stamp, data, activity_id)| {
        VehicleSpecificWaypoint {
            time_stamp,
            data,
            activity_id,
        }
    })
}

fn mission_upload_download_status() -> impl Strategy<Value = MissionUploadDownloadStatus> {
    (
        time_stamp(),
        option::of(text::<20>()),
        pick(TransferStatus::ALL),
        option::of(0..=100u8),
        option::of(any::<u16>()),
        option::of(pick(MissionPlanMode::ALL)),
        option::of(pick(Reason::ALL)),
        option::of(checksum()),
    )
        .prop_map(
            |(
                time_stamp,
                mission_id,
                status,
                percent_complete,
                waypoint_request,
                mode,
                reason,
                mission_checksum,
            )| {
                MissionUploadDownloadStatus {
                    time_stamp,
                    mission_id,
                    status,
                    percent_complete,
                    waypoint_request,
                    mode,
                    reason,
                    mission_checksum,
                }
            },
        )
}

fn from_waypoint_state() -> impl Strategy<Value = FromWaypointState> {
    (
        option::of(latitude()),
        option::of(longitude()),
        option::of(altitude()),
        option::of(time_stamp()),
        option::of(any::<u16>()),
    )
        .prop_map(
            |(latitude, longitude, altitude, time, waypoint_number)| FromWaypointState {
                latitude,
                longitude,
                altitude,
                time,
                waypoint_number,
            },
        )
}

fn waypoint_state() -> impl Strategy<Value = WaypointState> {
    (
        option::of(latitude()),
        option::of(longitude()),
        option::of(altitude()),
        option::of(speed()),
        option::of(time_stamp()),
        option::of(any::<u16>()),
    )
        .prop_map(
            |(latitude, longitude, altitude, speed, time, waypoint_number)| WaypointState {
                latitude,
                longitude,
                altitude,
                speed,
                time,
                waypoint_number,
            },
        )
}

fn from_to_next() -> impl Strategy<Value = FromToNext> {
    (
        time_stamp(),
        option::of(pick(AltitudeType::ALL)),
        option::of(pick(SpeedType::ALL)),
        from_waypoint_state(),
        waypoint_state(),
        waypoint_state(),
        option::of(any::<u8>()),
    )
        .prop_map(
            |(
                time_stamp,
                altitude_type,
                speed_type,
                from,
                to,
                next,
                loiter_configuration_report_validity,
            )| FromToNext {
                time_stamp,
                altitude_type,
                speed_type,
                from,
                to,
                next,
                loiter_configuration_report_validity,
            },
        )
}

/// #101: a position is a pair, an altitude comes with its type (ICD §4).
fn inertial_states() -> impl Strategy<Value = InertialStates> {
    let velocity = || option::of(any::<i16>().prop_map(Velocity::from_raw));
    (
        time_stamp(),
        option::of(geo_point()),
        option::of((altitude(), pick(AltitudeType::ALL))),
        option::of(pick(AltitudeType::ALL)),
        (velocity(), velocity(), velocity()),
        proptest::array::uniform10(option::of(any::<i16>())),
    )
        .prop_map(
            |(time_stamp, position, altitude, lone_type, (u, v, w), other)| InertialStates {
                time_stamp,
                latitude: position.map(|p| p.latitude),
                longitude: position.map(|p| p.longitude),
                altitude: altitude.map(|(a, _)| a),
                altitude_type: altitude.map(|(_, t)| t).or(lone_type),
                u_speed: u,
                v_speed: v,
                w_speed: w,
                u_accel: other[0],
                v_accel: other[1],
                w_accel: other[2],
                phi: other[3],
                theta: other[4],
                psi: other[5],
                phi_dot: other[6],
                theta_dot: other[7],
                psi_dot: other[8],
                magnetic_variation: other[9],
            },
        )
}

fn area_transmission_command() -> impl Strategy<Value = AreaTransmissionCommand> {
    (
        time_stamp(),
        pick(AreaTransferMode::ALL),
        option::of(any::<u8>()),
        any::<u8>(),
        option::of(any::<u16>()),
        option::of(safety_offset()),
        option::of(u3()),
        named::<20>(),
        any::<bool>(),
        transfer_window(),
        checksum(),
    )
        .prop_map(
            |(
                time_stamp,
                mode,
                loop_count,
                fallback,
                area_id,
                safety_offset,
                activity_id,
                staged,
                field_7,
                window,
                checksum,
            )| {
                use AreaTransferMode as Mode;
                // Area Loop Count is M for modes 1, 2, 4 and 7.
                let loop_count = match mode {
                    Mode::InitiateUpload
                    | Mode::UploadComplete
                    | Mode::DownloadComplete
                    | Mode::UploadCompleteStaged => Some(loop_count.unwrap_or(fallback)),
                    _ => loop_count,
                };
                // Mission ID: M and not empty for modes 7 and 8, with no other mode (ICD §8).
                let mission_id = matches!(
                    mode,
                    Mode::UploadCompleteStaged | Mode::InitiateStagedDownload
                )
                .then_some(staged);
                // Field 7 by the mode: a window with 3 and 8, a checksum with 2, 4 and 7.
                let window_or_checksum = match mode {
                    Mode::InitiateDownload | Mode::InitiateStagedDownload => {
                        Some(WindowOrChecksum::TransferWindow(window))
                    }
                    Mode::UploadComplete | Mode::DownloadComplete | Mode::UploadCompleteStaged => {
                        Some(WindowOrChecksum::AreaChecksum(checksum))
                    }
                    Mode::InitiateUpload | Mode::Cancel | Mode::ClearAreas => None,
                }
                .filter(|_| field_7);
                AreaTransmissionCommand {
                    time_stamp,
                    mode,
                    loop_count,
                    area_id,
                    safety_offset,
                    activity_id,
                    mission_id,
                    window_or_checksum,
                }
            },
        )
}

fn area_shape() -> impl Strategy<Value = AreaShape> {
    prop_oneof![
        vec(geo_point(), MIN_POLYGON_VERTICES..=MAX_POLYGON_VERTICES).prop_map(|points| {
            let mut vertices = PolygonVertices::new();
            for p in points {
                vertices.push(p).unwrap();
            }
            AreaShape::Polygon(vertices)
        }),
        (geo_point(), geo_point())
            .prop_map(|(centre, border)| AreaShape::Circle { centre, border }),
    ]
}

fn area_polygon_loop_segment() -> impl Strategy<Value = AreaPolygonLoopSegment> {
    (
        time_stamp(),
        waypoint_number(),
        pick(AreaType::ALL),
        option::of(altitude()),
        option::of(altitude()),
        option::of(pick(AltitudeType::ALL)),
        area_shape(),
    )
        .prop_map(
            |(time_stamp, area_id, area_type, lower, upper, altitude_type, shape)| {
                // The lower altitude is not above the upper one.
                let (lower_altitude, upper_altitude) = match (lower, upper) {
                    (Some(a), Some(b)) => (Some(a.min(b)), Some(a.max(b))),
                    other => other,
                };
                AreaPolygonLoopSegment {
                    time_stamp,
                    area_id,
                    area_type,
                    lower_altitude,
                    upper_altitude,
                    altitude_type,
                    shape,
                }
            },
        )
}

fn area_status_alert() -> impl Strategy<Value = AreaStatusAlert> {
    (
        time_stamp(),
        any::<u8>(),
        pick(AreaListStatus::ALL),
        option::of(pick(Reason::ALL)),
    )
        .prop_map(|(time_stamp, loop_count, status, reason)| AreaStatusAlert {
            time_stamp,
            loop_count,
            status,
            reason,
        })
}

fn area_transmission_status() -> impl Strategy<Value = AreaTransmissionStatus> {
    (
        time_stamp(),
        any::<u16>(),
        any::<u8>(),
        safety_offset(),
        pick(AreaDownloadStatus::ALL),
    )
        .prop_map(|(time_stamp, area_id, loop_count, safety_offset, status)| {
            AreaTransmissionStatus {
                time_stamp,
                area_id,
                loop_count,
                safety_offset,
                status,
            }
        })
}

fn mission_execute_command() -> impl Strategy<Value = MissionExecuteCommand> {
    (time_stamp(), pick(ExecuteCommand::ALL), named::<20>()).prop_map(
        |(time_stamp, command, staged)| MissionExecuteCommand {
            time_stamp,
            command,
            // Mission ID: M and not empty for command 4, with no other command (ICD §8).
            mission_id: (command == ExecuteCommand::ActivateStaged).then_some(staged),
        },
    )
}

fn mission_report() -> impl Strategy<Value = MissionReport> {
    (
        time_stamp(),
        (1..=u8::MAX).prop_flat_map(|count| (1..=count, Just(count))),
        option::of(text::<20>()),
        any::<u16>(),
        any::<u8>(),
        pick(GeofenceCheck::ALL),
        option::of(pick(Reason::ALL)),
        option::of(checksum()),
        option::of(checksum()),
    )
        .prop_map(
            |(
                time_stamp,
                (report_index, report_count),
                mission_id,
                waypoint_count,
                area_count,
                geofence_check,
                reason,
                mission_checksum,
                area_checksum,
            )| MissionReport {
                time_stamp,
                report_index,
                report_count,
                mission_id,
                waypoint_count,
                area_count,
                geofence_check,
                reason,
                mission_checksum,
                area_checksum,
            },
        )
}

/// Any valid message of ICD §4.
fn message() -> impl Strategy<Value = Message> {
    prop_oneof![
        message_acknowledgement().prop_map(Message::from).boxed(),
        mission_transfer_command().prop_map(Message::from).boxed(),
        ua_route().prop_map(Message::from).boxed(),
        ua_position_waypoint().prop_map(Message::from).boxed(),
        vehicle_specific_waypoint().prop_map(Message::from).boxed(),
        mission_upload_download_status()
            .prop_map(Message::from)
            .boxed(),
        from_to_next().prop_map(Message::from).boxed(),
        inertial_states().prop_map(Message::from).boxed(),
        area_transmission_command().prop_map(Message::from).boxed(),
        area_polygon_loop_segment().prop_map(Message::from).boxed(),
        area_status_alert().prop_map(Message::from).boxed(),
        area_transmission_status().prop_map(Message::from).boxed(),
        mission_execute_command().prop_map(Message::from).boxed(),
        mission_report().prop_map(Message::from).boxed(),
    ]
}

const CHECKSUM_WIDTHS: &[ChecksumWidth] =
    &[ChecksumWidth::None, ChecksumWidth::Two, ChecksumWidth::Four];

/// Any envelope a receiver accepts: any IDs, IDD version 30..=40, any checksum width.
fn envelope() -> impl Strategy<Value = Envelope> {
    (
        any::<u32>(),
        any::<u32>(),
        any::<bool>(),
        30..=40u8,
        pick(CHECKSUM_WIDTHS),
    )
        .prop_map(
            |(source_id, destination_id, ack_requested, idd_version, checksum)| Envelope {
                source_id,
                destination_id,
                ack_requested,
                idd_version,
                checksum,
            },
        )
}

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/// Encodes into a buffer of the largest datagram; returns the frame.
fn encode(envelope: &Envelope, message: &Message) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = wire::encode(envelope, message, &mut buf).unwrap();
    buf[..n].to_vec()
}

/// Width of the presence vector of a message type (ICD §4).
fn pv_bytes(t: MessageType) -> usize {
    match t {
        MessageType::UaPositionWaypoint | MessageType::FromToNext | MessageType::InertialStates => {
            3
        }
        MessageType::AreaPolygonLoopSegment | MessageType::MissionReport => 2,
        _ => 1,
    }
}

/// Wraps message data in a sound wrapper (ICD §2, 4-byte byte-sum checksum), built by hand.
fn wrap(message_type: u16, data: &[u8]) -> Vec<u8> {
    missionlink_protocol::testkit::RawFrame::uplink(message_type).build(data)
}

/// Runs every decoding entry point over `bytes`; only a panic fails.
fn exercise(bytes: &[u8]) {
    let _ = wire::decode(bytes);
    let _ = wire::Frame::new_checked(bytes);
    let mut walked = 0;
    for item in wire::frames(bytes) {
        walked += 1;
        assert!(walked <= bytes.len(), "the walker does not terminate");
        if let Ok(frame) = item {
            let _ = frame.envelope();
            let _ = frame.check_addressing(0x0B00_0001, 0x0A00_0001);
            if let Err(e) = frame.message() {
                let _ = e.to_string();
            }
        }
    }
    for t in MessageType::ALL {
        if let Err(e) = Message::decode(*t as u16, bytes) {
            let _ = e.to_string();
            let _ = e.reason();
        }
    }
}

/// Distance between two angles in degrees, on the circle.
fn angular_distance(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

const EPSILON: f64 = 1e-9;

// ---------------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------------

proptest! {
    /// encode then decode gives back exactly the envelope and message (ICD §2 to §4).
    #[test]
    fn encode_then_decode_is_identity(envelope in envelope(), message in message()) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let n = wire::encode(&envelope, &message, &mut buf).unwrap();
        let frame = &buf[..n];

        // The wrapper as ICD §2 lays it out.
        let data_len = usize::from(u16::from_be_bytes([frame[2], frame[3]]));
        prop_assert!((1..=MAX_DATA_LEN).contains(&data_len));
        prop_assert_eq!(n, HEADER_LEN + data_len + envelope.checksum.len());
        prop_assert_eq!(&frame[0..2], &[0xFF, 0xFF]);
        prop_assert_eq!(&frame[4..8], &envelope.source_id.to_be_bytes());
        prop_assert_eq!(&frame[8..12], &envelope.destination_id.to_be_bytes());
        prop_assert_eq!(
            u16::from_be_bytes([frame[12], frame[13]]),
            message.message_type() as u16
        );
        // Message Properties: bit 15 ack, bits 14..8 IDD version, bits 7..6 checksum code
        // (00 none, 01 two, 10 four), bits 5..0 zero.
        let code = match envelope.checksum {
            ChecksumWidth::None => 0b00u16,
            ChecksumWidth::Two => 0b01,
            ChecksumWidth::Four => 0b10,
        };
        prop_assert_eq!(
            u16::from_be_bytes([frame[14], frame[15]]),
            (u16::from(envelope.ack_requested) << 15)
                | (u16::from(envelope.idd_version) << 8)
                | (code << 6)
        );
        // The checksum: the byte sum of header and data, truncated to its width, big-endian.
        let sum: u32 = frame[..HEADER_LEN + data_len].iter().map(|b| u32::from(*b)).sum();
        let checksum = &frame[HEADER_LEN + data_len..];
        match envelope.checksum {
            ChecksumWidth::None => prop_assert!(checksum.is_empty()),
            ChecksumWidth::Two => prop_assert_eq!(checksum, &(sum as u16).to_be_bytes()[..]),
            ChecksumWidth::Four => prop_assert_eq!(checksum, &sum.to_be_bytes()[..]),
        }

        let (e, m) = wire::decode(frame).unwrap();
        prop_assert_eq!(e, envelope);
        prop_assert_eq!(&m, &message);

        // The message data alone decodes the same, and encoding again gives the same bytes.
        let data = &frame[HEADER_LEN..HEADER_LEN + data_len];
        prop_assert_eq!(&Message::decode(message.message_type() as u16, data).unwrap(), &message);
        prop_assert_eq!(m.time_stamp(), message.time_stamp());
        prop_assert_eq!(encode(&e, &m), frame.to_vec());
    }

    /// Every message describes itself on one line that starts with its type and ICD name.
    #[test]
    fn display_is_one_line_naming_the_message(message in message()) {
        let line = message.to_string();
        let t = message.message_type();
        prop_assert!(line.starts_with(&format!("#{} {}: ", t as u16, t.name())), "{}", line);
        prop_assert!(!line.contains('\n'), "{}", line);
    }

    /// A buffer too small for the frame is refused, never overrun.
    #[test]
    fn encode_into_a_short_buffer_is_refused(
        envelope in envelope(),
        message in message(),
        cut in any::<Index>(),
    ) {
        let n = encode(&envelope, &message).len();
        let mut buf = vec![0u8; cut.index(n)];
        let r = wire::encode(&envelope, &message, &mut buf);
        prop_assert!(matches!(r, Err(EncodeError::BufferTooSmall { .. })), "{:?}", r);
    }

    /// Angles: from_degrees then degrees is within half an LSB (on the circle: +180 is -180).
    #[test]
    fn angle_degrees_round_trip(d in -180.0f64..180.0) {
        let a = Angle::from_degrees(d).unwrap();
        prop_assert!(
            angular_distance(a.degrees(), d) <= Angle::LSB_DEGREES / 2.0 + EPSILON,
            "{} -> {:?}", d, a
        );
        prop_assert_eq!(Angle::from_degrees(a.degrees()).unwrap(), a);
    }

    /// Every raw BAM4 value survives degrees and back exactly.
    #[test]
    fn angle_raw_round_trip(raw in any::<i32>()) {
        let a = Angle::from_raw(raw);
        prop_assert_eq!(Angle::from_degrees(a.degrees()).unwrap(), a);
    }

    /// ALT3: within 0.01 m; every raw value survives metres and back exactly.
    #[test]
    fn altitude_metres_round_trip(
        m in -167_772.16f64..=167_772.14,
        raw in -(1i32 << 23)..(1 << 23),
    ) {
        let a = Altitude::from_metres(m).unwrap();
        prop_assert!((a.metres() - m).abs() <= Altitude::LSB_METRES / 2.0 + EPSILON, "{} -> {:?}", m, a);
        let a = Altitude::from_raw(raw).unwrap();
        prop_assert_eq!(Altitude::from_metres(a.metres()).unwrap(), a);
    }

    /// SPD2: within 0.25 m/s; every raw value survives m/s and back exactly.
    #[test]
    fn speed_mps_round_trip(v in 0.0f64..=32_767.5, raw in any::<u16>()) {
        let s = Speed::from_mps(v).unwrap();
        prop_assert!((s.mps() - v).abs() <= Speed::LSB_MPS / 2.0 + EPSILON, "{} -> {:?}", v, s);
        let s = Speed::from_raw(raw);
        prop_assert_eq!(Speed::from_mps(s.mps()).unwrap(), s);
    }

    /// Safety offset: within 0.05 m; every raw value survives metres and back exactly.
    #[test]
    fn safety_offset_metres_round_trip(m in 0.0f64..=6_553.5, raw in any::<u16>()) {
        let o = SafetyOffset::from_metres(m).unwrap();
        prop_assert!(
            (o.metres() - m).abs() <= SafetyOffset::LSB_METRES / 2.0 + EPSILON,
            "{} -> {:?}", m, o
        );
        let o = SafetyOffset::from_raw(raw);
        prop_assert_eq!(SafetyOffset::from_metres(o.metres()).unwrap(), o);
    }

    /// GeoPoint: both angles within half an LSB, the latitude a valid latitude.
    #[test]
    fn geo_point_degrees_round_trip(lat in -90.0f64..=90.0, lon in -180.0f64..180.0) {
        let p = GeoPoint::from_degrees(lat, lon).unwrap();
        prop_assert!(p.latitude.is_latitude());
        prop_assert!((p.latitude.degrees() - lat).abs() <= Angle::LSB_DEGREES / 2.0 + EPSILON);
        prop_assert!(
            angular_distance(p.longitude.degrees(), lon) <= Angle::LSB_DEGREES / 2.0 + EPSILON
        );
    }

    /// Values the encodings cannot carry are refused, not wrapped or clamped.
    #[test]
    fn physical_values_out_of_range_are_refused(excess in 1e-6f64..1e6) {
        prop_assert!(Angle::from_degrees(180.0 + excess).is_err());
        prop_assert!(Angle::from_degrees(-180.0 - excess).is_err());
        prop_assert!(GeoPoint::from_degrees(90.0 + excess.max(1e-4), 0.0).is_err());
        prop_assert!(GeoPoint::from_degrees(-90.0 - excess.max(1e-4), 0.0).is_err());
        prop_assert!(Altitude::from_metres(167_772.14 + excess.max(0.02)).is_err());
        prop_assert!(Altitude::from_metres(-167_772.16 - excess).is_err());
        prop_assert!(Speed::from_mps(-excess).is_err());
        prop_assert!(Speed::from_mps(32_767.5 + excess).is_err());
        prop_assert!(SafetyOffset::from_metres(-excess).is_err());
        prop_assert!(SafetyOffset::from_metres(6_553.5 + excess).is_err());
    }

    /// Several valid frames back to back are walked into exactly those frames (ICD §1).
    #[test]
    fn datagram_of_frames_is_walked_frame_by_frame(
        items in vec((envelope(), message()), 1..=6),
    ) {
        let frames: Vec<Vec<u8>> = items.iter().map(|(e, m)| encode(e, m)).collect();
        let datagram = frames.concat();
        let walked: Vec<_> = wire::frames(&datagram).collect();
        prop_assert_eq!(walked.len(), items.len());
        for ((walked, bytes), (envelope, message)) in walked.iter().zip(&frames).zip(&items) {
            let frame = walked.as_ref().unwrap();
            prop_assert_eq!(frame.as_bytes(), &bytes[..]);
            prop_assert_eq!(frame.data(), &bytes[HEADER_LEN..bytes.len() - envelope.checksum.len()]);
            prop_assert_eq!(frame.envelope(), *envelope);
            prop_assert_eq!(&frame.message().unwrap(), message);
        }
        // One datagram, one message: `decode` refuses a datagram of several.
        if items.len() > 1 {
            prop_assert_eq!(
                wire::decode(&datagram),
                Err(DecodeError::Frame(FrameError::LengthMismatch {
                    expected: frames[0].len(),
                    actual: datagram.len(),
                }))
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    /// No decoding entry point panics on arbitrary bytes.
    #[test]
    fn decoding_arbitrary_bytes_never_panics(bytes in vec(any::<u8>(), 0..600), t in any::<u16>()) {
        exercise(&bytes);
        let _ = Message::decode(t, &bytes);
    }

    /// Arbitrary message data in a sound wrapper, with a presence vector of defined bits (so
    /// that the fields are reached), never panics.
    #[test]
    fn decoding_arbitrary_message_data_never_panics(
        t in pick(MessageType::ALL),
        pv in any::<u32>(),
        unknown_bits in prop::bool::weighted(0.05),
        fields in vec(any::<u8>(), 0..=528),
    ) {
        let defined = (1u32 << t.fields().len()) - 1;
        let pv = if unknown_bits { pv } else { pv & defined };
        let width = pv_bytes(t);
        let mut data = pv.to_be_bytes()[4 - width..].to_vec();
        data.extend_from_slice(&fields);
        data.truncate(MAX_DATA_LEN);
        exercise(&data);
        exercise(&wrap(t as u16, &data));
        let r = wire::decode(&wrap(t as u16, &data));
        prop_assert!(!matches!(r, Err(DecodeError::Frame(_))), "{:?}", r);
    }

    /// A valid frame with one byte changed never panics; with the 4-byte checksum the change
    /// is always detected.
    #[test]
    fn frame_with_a_flipped_byte_never_panics(
        envelope in envelope(),
        message in message(),
        at in any::<Index>(),
        mask in 1..=255u8,
    ) {
        let mut frame = encode(&envelope, &message);
        let i = at.index(frame.len());
        frame[i] ^= mask;
        exercise(&frame);
        if envelope.checksum == ChecksumWidth::Four {
            let r = wire::decode(&frame);
            prop_assert!(matches!(r, Err(DecodeError::Frame(_))), "byte {} ^ {:#x}: {:?}", i, mask, r);
        }
    }

    /// Valid message data with one byte changed, in a sound wrapper, never panics.
    #[test]
    fn message_data_with_a_flipped_byte_never_panics(
        message in message(),
        at in any::<Index>(),
        mask in 1..=255u8,
    ) {
        let frame = encode(&Envelope::new(1, 2), &message);
        let mut data = frame[HEADER_LEN..frame.len() - 4].to_vec();
        let i = at.index(data.len());
        data[i] ^= mask;
        exercise(&data);
        exercise(&wrap(message.message_type() as u16, &data));
    }

    /// The time stamp the voter samples by is the one decoding finds: of a valid message its
    /// own, and of data with a byte changed the decoded message's or the one its rejection
    /// carries (`None` exactly where no acknowledgement could name the message).
    #[test]
    fn the_peeked_time_stamp_is_the_decoded_one(
        message in message(),
        at in any::<Index>(),
        mask in 0..=255u8,
    ) {
        let frame = encode(&Envelope::new(1, 2), &message);
        let mut data = frame[HEADER_LEN..frame.len() - 4].to_vec();
        let message_type = message.message_type() as u16;
        prop_assert_eq!(Message::peek_time_stamp(message_type, &data), Some(message.time_stamp()));
        let i = at.index(data.len());
        data[i] ^= mask;
        let decoded = match Message::decode(message_type, &data) {
            Ok(m) => Some(m.time_stamp()),
            Err(e) => e.time_stamp,
        };
        prop_assert_eq!(Message::peek_time_stamp(message_type, &data), decoded);
        let wrapped = wrap(message_type, &data);
        prop_assert_eq!(wire::Frame::new_checked(&wrapped).unwrap().time_stamp(), decoded);
    }

    /// A valid frame cut short is rejected (never panics).
    #[test]
    fn truncated_frame_is_rejected(
        envelope in envelope(),
        message in message(),
        cut in any::<Index>(),
    ) {
        let frame = encode(&envelope, &message);
        let short = &frame[..cut.index(frame.len())];
        exercise(short);
        prop_assert!(matches!(wire::decode(short), Err(DecodeError::Frame(_))));
        let first = wire::frames(short).next();
        prop_assert!(matches!(first, None | Some(Err(_))), "{:?}", first);
    }

    /// Valid message data cut short is rejected by the message rules (never panics), also in a
    /// sound wrapper: the presence vector promises fields that are not there.
    #[test]
    fn truncated_message_data_is_rejected(message in message(), cut in any::<Index>()) {
        let frame = encode(&Envelope::new(1, 2), &message);
        let data = &frame[HEADER_LEN..frame.len() - 4];
        let short = &data[..cut.index(data.len())];
        let t = message.message_type() as u16;
        exercise(short);
        prop_assert!(Message::decode(t, short).is_err());
        if !short.is_empty() {
            let r = wire::decode(&wrap(t, short));
            prop_assert!(matches!(r, Err(DecodeError::Message(_))), "{:?}", r);
        }
    }
}

/// `EncodeError::BufferTooSmall` documents `needed` as the bytes the frame needs at least and
/// `available` as the bytes available. When the buffer holds the header but not the message
/// data, the message-data writer reports both counted from the end of the header instead.
#[test]
fn buffer_too_small_reports_frame_sizes() {
    let message: Message = MissionExecuteCommand {
        time_stamp: Timestamp::from_millis(5).unwrap(),
        command: ExecuteCommand::Execute,
        mission_id: None,
    }
    .into();
    let envelope = Envelope::new(1, 2);
    // Header does not fit: frame sizes.
    let mut buf = [0u8; 10];
    assert!(matches!(
        wire::encode(&envelope, &message, &mut buf),
        Err(EncodeError::BufferTooSmall { needed, available: 10 }) if needed > 10
    ));
    // Checksum does not fit: frame sizes.
    let mut buf = [0u8; 23];
    assert_eq!(
        wire::encode(&envelope, &message, &mut buf),
        Err(EncodeError::BufferTooSmall {
            needed: 27,
            available: 23
        })
    );
    // Message data does not fit.
    let mut buf = [0u8; 20];
    let r = wire::encode(&envelope, &message, &mut buf);
    assert!(
        matches!(r, Err(EncodeError::BufferTooSmall { needed, available: 20 }) if needed > 20),
        "{r:?}"
    );
}
