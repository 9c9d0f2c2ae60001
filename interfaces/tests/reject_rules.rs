//! Negative tests of the wire layer: one test per reject rule of ICD §2 (wrapper, `FrameError`)
//! and §3/§4 (message data, `MessageError` and its §6 `Reason`), each asserting the exact error.
//!
//! Every frame is built by hand from the ICD tables (16-byte header of §2, message data of §3
//! and §4, 4-byte byte-sum checksum), never by the library's encoder, so these tests also pin
//! the wire layout.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink_interfaces::wire::{
    self, AckType, Altitude, AltitudeType, Angle, AreaDownloadStatus, AreaListStatus,
    AreaPolygonLoopSegment, AreaShape, AreaStatusAlert, AreaTransferMode, AreaTransmissionCommand,
    AreaTransmissionStatus, AreaType, BROADCAST_ID, Cause, Checksum, ChecksumWidth, DecodeError,
    Envelope, ExecuteCommand, FieldRef, Frame, FrameError, FromToNext, FromWaypointState, GeoPoint,
    GeofenceCheck, LegType, LocationType, MAX_DATA_LEN, Message, MessageAcknowledgement,
    MessageError, MessageType, MissionExecuteCommand, MissionPlanMode, MissionReport,
    MissionTransferCommand, MissionUploadDownloadStatus, PolygonVertices, Reason, RouteType,
    SafetyOffset, SpecificData, Speed, SpeedType, Text, Timestamp, TransferStatus, TransferWindow,
    TurnDirection, TurnType, U3, UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
    WaypointState, WindowOrChecksum,
};

use missionlink_protocol::testkit::{self, RawFrame};

// ---------------------------------------------------------------------------------------------
// Frames by hand (ICD §2)
// ---------------------------------------------------------------------------------------------

/// GCS (CUCS) ID, the peer of the FCC (ICD §1 defaults).
const GCS: u32 = 0x0A00_0001;
/// FCC (vehicle) ID, the local node in these tests.
const FCC: u32 = 0x0B00_0001;

// Message Properties: bit 15 ack requested, bits 14..8 IDD version, bits 7..6 checksum code.
use testkit::properties;

/// Properties as this project sends: IDD 40, 4-byte checksum (code 10), no ack request.
const PROPERTIES: u16 = properties(false, 40, 0b10);

/// The wrapper fields of a frame from `source` to `destination`, the testkit's one hand-made
/// frame ([`RawFrame`]).
fn raw(source: u32, destination: u32, message_type: u16, props: u16) -> RawFrame {
    RawFrame {
        source,
        destination,
        properties: props,
        ..RawFrame::uplink(message_type)
    }
}

/// The 16-byte wrapper header of ICD §2.
fn header(length: u16, source: u32, destination: u32, message_type: u16, props: u16) -> Vec<u8> {
    RawFrame {
        length: Some(length),
        ..raw(source, destination, message_type, props)
    }
    .header(0)
}

/// Byte-wise unsigned addition of every byte (ICD §2), not truncated: what a checksum test expects.
fn byte_sum(bytes: &[u8]) -> u32 {
    bytes.iter().map(|b| u32::from(*b)).sum()
}

/// Appends the byte-sum checksum of everything so far, `width` bytes (0, 2 or 4).
fn with_checksum(mut frame: Vec<u8>, width: usize) -> Vec<u8> {
    testkit::append_checksum(&mut frame, width);
    frame
}

/// A frame with these wrapper fields around `data`, Message Length = data length.
fn frame(
    source: u32,
    destination: u32,
    message_type: u16,
    props: u16,
    checksum_width: usize,
    data: &[u8],
) -> Vec<u8> {
    RawFrame {
        checksum_len: checksum_width,
        ..raw(source, destination, message_type, props)
    }
    .build(data)
}

/// Wraps message data as the GCS sends it to the FCC: IDD 40, 4-byte checksum.
fn wrap(message_type: u16, data: &[u8]) -> Vec<u8> {
    RawFrame::uplink(message_type).build(data)
}

/// A valid #50000 execute: PV 0b11, time stamp, command 1.
fn execute_data() -> Vec<u8> {
    data(1, &[(0, ts(TS)), (1, u1(1))])
}

/// The frames of a datagram as the walker yields them, each as its bytes.
fn walk(datagram: &[u8]) -> Vec<Result<&[u8], FrameError>> {
    wire::frames(datagram)
        .map(|r| r.map(|f| f.as_bytes()))
        .collect()
}

fn frame_error(bytes: &[u8]) -> FrameError {
    match wire::decode(bytes) {
        Err(DecodeError::Frame(e)) => {
            assert_eq!(Frame::new_checked(bytes).unwrap_err(), e);
            e
        }
        other => panic!("expected a frame error, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Message data by hand (ICD §3, §4)
// ---------------------------------------------------------------------------------------------

/// The time stamp of every test message: 2026-12-10 or so, in ms since 2000.
const TS: u64 = 850_000_000_000;
/// 40 deg and 10 deg in BAM4.
const LAT: i32 = 477_218_588;
const LON: i32 = 119_304_647;
/// Just beyond +90 deg.
const BEYOND_90: i32 = (1 << 30) + 1;

fn ts(ms: u64) -> Vec<u8> {
    ms.to_be_bytes()[3..].to_vec()
}
fn u1(v: u8) -> Vec<u8> {
    vec![v]
}
fn u2(v: u16) -> Vec<u8> {
    v.to_be_bytes().to_vec()
}
fn u3(v: u32) -> Vec<u8> {
    v.to_be_bytes()[1..].to_vec()
}
fn u4(v: u32) -> Vec<u8> {
    v.to_be_bytes().to_vec()
}
fn i3(v: i32) -> Vec<u8> {
    v.to_be_bytes()[1..].to_vec()
}
fn i4(v: i32) -> Vec<u8> {
    v.to_be_bytes().to_vec()
}
/// CharN: the text, then NUL up to `n` bytes.
fn text(s: &str, n: usize) -> Vec<u8> {
    let mut t = s.as_bytes().to_vec();
    t.resize(n, 0);
    t
}
/// #2012 vertices: latitude, longitude (BAM4 each) per vertex.
fn vertices(points: &[(i32, i32)]) -> Vec<u8> {
    points
        .iter()
        .flat_map(|(lat, lon)| [lat.to_be_bytes(), lon.to_be_bytes()].concat())
        .collect()
}
/// `n` distinct valid vertices.
fn n_vertices(n: usize) -> Vec<(i32, i32)> {
    (0..n as i32)
        .map(|i| (LAT + i * 1000, LON - i * 7000))
        .collect()
}

/// Message data: the presence vector (`pv_bytes` wide) with the bit of every field given, then
/// the fields' bytes in the order given.
fn data(pv_bytes: usize, fields: &[(u8, Vec<u8>)]) -> Vec<u8> {
    let pv = fields.iter().fold(0u32, |pv, (bit, _)| pv | (1 << bit));
    let mut d = pv.to_be_bytes()[4 - pv_bytes..].to_vec();
    for (_, bytes) in fields {
        d.extend_from_slice(bytes);
    }
    d
}

/// One message by hand: its type, PV width and fields (bit, bytes), in bit order.
#[derive(Clone, Debug)]
struct Msg {
    ty: u16,
    pv_bytes: usize,
    extra_pv: u32,
    fields: Vec<(u8, Vec<u8>)>,
}

impl Msg {
    fn new(ty: u16, pv_bytes: usize, fields: Vec<(u8, Vec<u8>)>) -> Self {
        Self {
            ty,
            pv_bytes,
            extra_pv: 0,
            fields,
        }
    }

    /// The same message without the field of `bit` (PV bit cleared, bytes gone).
    fn without(mut self, bit: u8) -> Self {
        self.fields.retain(|(b, _)| *b != bit);
        self
    }

    /// The same message with the field of `bit` set to `bytes`.
    fn with(mut self, bit: u8, bytes: Vec<u8>) -> Self {
        self.fields.retain(|(b, _)| *b != bit);
        self.fields.push((bit, bytes));
        self.fields.sort_by_key(|(b, _)| *b);
        self
    }

    /// The same message with PV bit `bit` set and no bytes for it.
    fn pv_bit(mut self, bit: u8) -> Self {
        self.extra_pv |= 1 << bit;
        self
    }

    fn data(&self) -> Vec<u8> {
        let mut d = data(self.pv_bytes, &self.fields);
        let pv = d
            .iter()
            .take(self.pv_bytes)
            .fold(0u32, |a, b| (a << 8) | u32::from(*b));
        let pv = (pv | self.extra_pv).to_be_bytes();
        d[..self.pv_bytes].copy_from_slice(&pv[4 - self.pv_bytes..]);
        d
    }

    fn decode(&self) -> Result<Message, DecodeError> {
        wire::decode(&wrap(self.ty, &self.data())).map(|(_, m)| m)
    }

    /// The rejection of this message, the same through `wire::decode` and `Message::decode`.
    fn reject(&self) -> MessageError {
        reject(self.ty, &self.data())
    }
}

/// The `MessageError` of message data `d` of type `ty`, the same through both entry points.
fn reject(ty: u16, d: &[u8]) -> MessageError {
    let direct = Message::decode(ty, d).unwrap_err();
    match wire::decode(&wrap(ty, d)) {
        Err(DecodeError::Message(e)) => {
            assert_eq!(e, direct);
            assert_eq!(DecodeError::Message(e).reason(), Some(e.reason()));
            e
        }
        other => panic!("expected a message error, got {other:?}"),
    }
}

/// The error expected: message type, field (bit, ICD name), cause, time stamp (ms).
fn rejected(
    ty: u16,
    field: Option<(u8, &'static str)>,
    cause: Cause,
    time_stamp: Option<u64>,
) -> MessageError {
    MessageError {
        message_type: ty,
        field: field.map(|(bit, name)| FieldRef { bit, name }),
        cause,
        time_stamp: time_stamp.map(stamp),
    }
}

fn stamp(ms: u64) -> Timestamp {
    Timestamp::from_millis(ms).unwrap()
}

// The messages of ICD §4 with every field present, by hand.

fn ack() -> Msg {
    Msg::new(
        17000,
        1,
        vec![
            (0, ts(TS)),
            (1, ts(TS - 10)),
            (2, u2(13002)),
            (3, u1(3)),
            (4, u1(2)),
        ],
    )
}

fn transfer_command(mode: u8) -> Msg {
    Msg::new(
        13000,
        1,
        vec![
            (0, ts(TS)),
            (1, text("M-1", 20)),
            (2, u1(mode)),
            (3, u2(12)),
            (4, text("R-7", 33)),
            (5, u3(0x12_3456)),
        ],
    )
}

fn route() -> Msg {
    Msg::new(
        13001,
        1,
        vec![
            (0, ts(TS)),
            (1, u2(1)),
            (2, text("R-7", 33)),
            (3, u1(2)),
            (4, u3(1)),
        ],
    )
}

fn waypoint() -> Msg {
    Msg::new(
        13002,
        3,
        vec![
            (0, ts(TS)),
            (1, u2(7)),
            (2, i4(LAT)),
            (3, i4(LON)),
            (4, u1(0)),
            (5, i3(25_000)),
            (6, u1(3)),
            (7, u1(1)),
            (8, u2(60)),
            (9, u1(2)),
            (10, u2(8)),
            (11, u1(1)),
            (12, u1(1)),
            (13, u1(1)),
            (14, u1(0)),
            (15, u2(3)),
            (16, ts(TS + 60_000)),
            (17, u3(42)),
        ],
    )
}

fn take_off_height() -> Msg {
    Msg::new(
        13006,
        1,
        vec![
            (0, ts(TS)),
            (1, u2(0)),
            (2, u1(1)),
            (3, i3(2_500)),
            (7, u3(5)),
        ],
    )
}

fn rf_centre() -> Msg {
    Msg::new(
        13006,
        1,
        vec![
            (0, ts(TS)),
            (1, u2(7)),
            (2, u1(2)),
            (4, i4(LAT)),
            (5, i4(LON)),
            (6, u1(1)),
            (7, u3(5)),
        ],
    )
}

fn transfer_status() -> Msg {
    Msg::new(
        14000,
        1,
        vec![
            (0, ts(TS)),
            (1, text("M-1", 20)),
            (2, u1(2)),
            (3, u1(40)),
            (4, u2(3)),
            (5, u1(3)),
            (6, u1(9)),
        ],
    )
}

fn from_to_next() -> Msg {
    Msg::new(
        4001,
        3,
        vec![
            (0, ts(TS)),
            (1, u1(3)),
            (2, u1(2)),
            (3, i4(LAT)),
            (4, i4(LON)),
            (5, i3(100)),
            (6, ts(TS - 1_000)),
            (7, u2(0)),
            (8, i4(LAT + 1)),
            (9, i4(LON + 1)),
            (10, i3(200)),
            (11, u2(60)),
            (12, ts(TS + 1_000)),
            (13, u2(1)),
            (14, i4(LAT + 2)),
            (15, i4(LON + 2)),
            (16, i3(300)),
            (17, u2(61)),
            (18, ts(TS + 2_000)),
            (19, u2(2)),
            (20, u1(1)),
        ],
    )
}

/// #101 with every field: position, altitude, the three velocities, and the raw I2 fields.
fn inertial_states() -> Msg {
    let mut fields = vec![
        (0, ts(TS)),
        (1, i4(LAT)),
        (2, i4(LON)),
        (3, i3(100)),
        (4, u1(3)),
        (5, (-20i16).to_be_bytes().to_vec()),
        (6, 340i16.to_be_bytes().to_vec()),
        (7, 2i16.to_be_bytes().to_vec()),
    ];
    for bit in 8..18u8 {
        fields.push((bit, (i16::from(bit) - 12).to_be_bytes().to_vec()));
    }
    Msg::new(101, 3, fields)
}

fn area_command(mode: u8) -> Msg {
    Msg::new(
        2011,
        1,
        vec![
            (0, ts(TS)),
            (1, u1(mode)),
            (2, u1(3)),
            (3, u2(0)),
            (4, u2(150)),
            (5, u3(9)),
        ],
    )
}

/// #2012 with `shape` (0 polygon, 1 circle) and these vertices.
fn area(shape: u32, points: &[(i32, i32)]) -> Msg {
    Msg::new(
        2012,
        2,
        vec![
            (0, ts(TS)),
            (1, u2(1)),
            (2, u1(0)),
            (3, u3(shape)),
            (4, i3(0)),
            (5, i3(6_000)),
            (6, u1(2)),
            (7, u1(points.len() as u8)),
            (8, vertices(points)),
        ],
    )
}

fn polygon() -> Msg {
    area(0, &n_vertices(4))
}

fn circle() -> Msg {
    area(1, &n_vertices(2))
}

fn area_alert() -> Msg {
    Msg::new(
        3012,
        1,
        vec![(0, ts(TS)), (1, u1(3)), (2, u1(0)), (3, u1(12))],
    )
}

fn area_transmission_status() -> Msg {
    Msg::new(
        3013,
        1,
        vec![
            (0, ts(TS)),
            (1, u2(0)),
            (2, u1(3)),
            (3, u2(150)),
            (4, u1(0)),
        ],
    )
}

fn execute() -> Msg {
    Msg::new(50000, 1, vec![(0, ts(TS)), (1, u1(2))])
}

/// #50000 command 4 (ext): activate the staged mission M-1.
fn activate() -> Msg {
    execute().with(1, u1(4)).with(2, text("M-1", 20))
}

/// #13000 with `mode` as edition 2 sends it: a Mission ID that suits the mode (empty for mode
/// 7, ICD §8) and the extension field its table names for it, if any (ICD §3).
fn transfer_command_ed2(mode: u8) -> Msg {
    let m = transfer_command(mode);
    match mode {
        2 | 8 => m.with(7, u4(0x1A2B_3C4D)),
        3 | 9 => m.with(6, u1(32)),
        7 => m.with(1, text("", 20)),
        _ => m,
    }
}

/// #2011 with `mode` as edition 2 sends it: the Mission ID of a staged mission with modes 7 and
/// 8, and field 7 where its table names it (a window with modes 3 and 8, else a checksum).
fn area_command_ed2(mode: u8) -> Msg {
    let m = area_command(mode);
    let m = if matches!(mode, 7 | 8) {
        m.with(6, text("M-1", 20))
    } else {
        m
    };
    match mode {
        3 | 8 => m.with(7, u4(32)),
        2 | 4 | 7 => m.with(7, u4(0xCBF4_3926)),
        _ => m,
    }
}

/// #50001 entry 2 of 3, the staged mission M-1, every field present.
fn mission_report() -> Msg {
    Msg::new(
        50001,
        2,
        vec![
            (0, ts(TS)),
            (1, u1(2)),
            (2, u1(3)),
            (3, text("M-1", 20)),
            (4, u2(12)),
            (5, u1(3)),
            (6, u1(2)),
            (7, u1(14)),
            (8, u4(0x1A2B_3C4D)),
            (9, u4(0xCBF4_3926)),
        ],
    )
}

/// Every message by hand with the bits ICD §4 marks M for it (in this mode or type).
fn all_messages() -> Vec<(Msg, &'static [u8])> {
    vec![
        (ack(), &[0, 1, 2, 3]),
        (transfer_command(2), &[0, 2, 3]),
        (transfer_command(1), &[0, 2]),
        (transfer_command_ed2(2), &[0, 2, 3]),
        (transfer_command_ed2(3), &[0, 2]),
        (transfer_command(6), &[0, 1, 2]),
        (transfer_command_ed2(7), &[0, 2]),
        (transfer_command_ed2(8), &[0, 1, 2, 3]),
        (transfer_command_ed2(9), &[0, 1, 2]),
        (transfer_command(10), &[0, 1, 2]),
        (route(), &[0, 1, 4]),
        (waypoint(), &[0, 1, 2, 3, 5, 8, 10, 11, 13]),
        (take_off_height(), &[0, 1, 2, 3]),
        (rf_centre(), &[0, 1, 2, 4, 5, 6]),
        (transfer_status(), &[0, 2]),
        (from_to_next(), &[0]),
        (inertial_states(), &[0]),
        (area_command(1), &[0, 1, 2]),
        (area_command(2), &[0, 1, 2]),
        (area_command(3), &[0, 1]),
        (area_command(4), &[0, 1, 2]),
        (area_command(5), &[0, 1]),
        (area_command(6), &[0, 1]),
        (area_command_ed2(2), &[0, 1, 2]),
        (area_command_ed2(3), &[0, 1]),
        (area_command_ed2(4), &[0, 1, 2]),
        (area_command_ed2(7), &[0, 1, 2, 6]),
        (area_command_ed2(8), &[0, 1, 6]),
        (polygon(), &[0, 1, 2, 3, 7, 8]),
        (circle(), &[0, 1, 2, 3, 7, 8]),
        (area_alert(), &[0, 1, 2]),
        (area_transmission_status(), &[0, 1, 2, 3, 4]),
        (execute(), &[0, 1]),
        (activate(), &[0, 1, 2]),
        (mission_report(), &[0, 1, 2, 4, 5, 6]),
    ]
}

fn name(ty: u16, bit: u8) -> &'static str {
    MessageType::try_from(ty).unwrap().fields()[usize::from(bit)]
}

// ---------------------------------------------------------------------------------------------
// The hand-built messages are valid: the baselines the reject tests break one rule of
// ---------------------------------------------------------------------------------------------

fn geo(lat: i32, lon: i32) -> GeoPoint {
    GeoPoint {
        latitude: Angle::from_raw(lat),
        longitude: Angle::from_raw(lon),
    }
}

fn alt(raw: i32) -> Altitude {
    Altitude::from_raw(raw).unwrap()
}

/// Each message of ICD §4 built by hand decodes to the value the ICD tables give, and that
/// value encodes to the same bytes.
#[test]
fn hand_built_messages_decode_and_encode_byte_for_byte() {
    let mut square = PolygonVertices::new();
    for (lat, lon) in n_vertices(4) {
        square.push(geo(lat, lon)).unwrap();
    }
    let circle_points = n_vertices(2);
    let cases: Vec<(Msg, Message)> = vec![
        (
            ack(),
            MessageAcknowledgement {
                time_stamp: stamp(TS),
                original_time_stamp: stamp(TS - 10),
                original_message_type: 13002,
                ack_type: AckType::Rejected,
                reject_reason: Some(Reason::MissingField),
            }
            .into(),
        ),
        (
            transfer_command(2),
            MissionTransferCommand {
                time_stamp: stamp(TS),
                mission_id: Some(Text::new("M-1").unwrap()),
                mode: MissionPlanMode::TransmitMission,
                waypoint_number: Some(12),
                route_id: Some(Text::new("R-7").unwrap()),
                activity_id: U3::new(0x12_3456),
                transfer_window: None,
                mission_checksum: None,
            }
            .into(),
        ),
        (
            transfer_command_ed2(8),
            MissionTransferCommand {
                time_stamp: stamp(TS),
                mission_id: Some(Text::new("M-1").unwrap()),
                mode: MissionPlanMode::StageMission,
                waypoint_number: Some(12),
                route_id: Some(Text::new("R-7").unwrap()),
                activity_id: U3::new(0x12_3456),
                transfer_window: None,
                mission_checksum: Some(Checksum::new(0x1A2B_3C4D)),
            }
            .into(),
        ),
        (
            transfer_command_ed2(9),
            MissionTransferCommand {
                time_stamp: stamp(TS),
                mission_id: Some(Text::new("M-1").unwrap()),
                mode: MissionPlanMode::ReceiveStagedMission,
                waypoint_number: Some(12),
                route_id: Some(Text::new("R-7").unwrap()),
                activity_id: U3::new(0x12_3456),
                transfer_window: TransferWindow::new(32),
                mission_checksum: None,
            }
            .into(),
        ),
        (
            route(),
            UaRoute {
                time_stamp: stamp(TS),
                initial_waypoint: 1,
                route_id: Some(Text::new("R-7").unwrap()),
                route_type: Some(RouteType::Flight),
                bidirectional: true,
                planning_wind: None,
            }
            .into(),
        ),
        (
            waypoint(),
            UaPositionWaypoint {
                time_stamp: stamp(TS),
                waypoint_number: 7,
                latitude: Angle::from_raw(LAT),
                longitude: Angle::from_raw(LON),
                location_type: Some(LocationType::Absolute),
                altitude: alt(25_000),
                altitude_type: Some(AltitudeType::Wgs84),
                altitude_change_behaviour: Some(1),
                speed: Speed::from_raw(60),
                speed_type: Some(SpeedType::GroundSpeed),
                next_waypoint: 8,
                turn_type: TurnType::FlyOver,
                optional_messages: Some(1),
                leg_type: LegType::RadiusToFix,
                limit_type: Some(0),
                loop_limit: Some(3),
                arrival_time: Some(stamp(TS + 60_000)),
                activity_id: U3::new(42),
            }
            .into(),
        ),
        (
            take_off_height(),
            VehicleSpecificWaypoint {
                time_stamp: stamp(TS),
                data: SpecificData::TakeOffHeight { height: alt(2_500) },
                activity_id: U3::new(5),
            }
            .into(),
        ),
        (
            rf_centre(),
            VehicleSpecificWaypoint {
                time_stamp: stamp(TS),
                data: SpecificData::RfCentre {
                    waypoint_number: 7,
                    latitude: Angle::from_raw(LAT),
                    longitude: Angle::from_raw(LON),
                    turn_direction: TurnDirection::CounterClockwise,
                },
                activity_id: U3::new(5),
            }
            .into(),
        ),
        (
            transfer_status(),
            MissionUploadDownloadStatus {
                time_stamp: stamp(TS),
                mission_id: Some(Text::new("M-1").unwrap()),
                status: TransferStatus::Aborted,
                percent_complete: Some(40),
                waypoint_request: Some(3),
                mode: Some(MissionPlanMode::ReceiveMission),
                reason: Some(Reason::BrokenChain),
                mission_checksum: None,
            }
            .into(),
        ),
        (
            transfer_status().with(7, u4(0x1A2B_3C4D)),
            MissionUploadDownloadStatus {
                time_stamp: stamp(TS),
                mission_id: Some(Text::new("M-1").unwrap()),
                status: TransferStatus::Aborted,
                percent_complete: Some(40),
                waypoint_request: Some(3),
                mode: Some(MissionPlanMode::ReceiveMission),
                reason: Some(Reason::BrokenChain),
                mission_checksum: Some(Checksum::new(0x1A2B_3C4D)),
            }
            .into(),
        ),
        (
            from_to_next(),
            FromToNext {
                time_stamp: stamp(TS),
                altitude_type: Some(AltitudeType::Wgs84),
                speed_type: Some(SpeedType::GroundSpeed),
                from: FromWaypointState {
                    latitude: Some(Angle::from_raw(LAT)),
                    longitude: Some(Angle::from_raw(LON)),
                    altitude: Some(alt(100)),
                    time: Some(stamp(TS - 1_000)),
                    waypoint_number: Some(0),
                },
                to: WaypointState {
                    latitude: Some(Angle::from_raw(LAT + 1)),
                    longitude: Some(Angle::from_raw(LON + 1)),
                    altitude: Some(alt(200)),
                    speed: Some(Speed::from_raw(60)),
                    time: Some(stamp(TS + 1_000)),
                    waypoint_number: Some(1),
                },
                next: WaypointState {
                    latitude: Some(Angle::from_raw(LAT + 2)),
                    longitude: Some(Angle::from_raw(LON + 2)),
                    altitude: Some(alt(300)),
                    speed: Some(Speed::from_raw(61)),
                    time: Some(stamp(TS + 2_000)),
                    waypoint_number: Some(2),
                },
                loiter_configuration_report_validity: Some(1),
            }
            .into(),
        ),
        (
            area_command(1),
            AreaTransmissionCommand {
                time_stamp: stamp(TS),
                mode: AreaTransferMode::InitiateUpload,
                loop_count: Some(3),
                area_id: Some(0),
                safety_offset: Some(SafetyOffset::from_raw(150)),
                activity_id: U3::new(9),
                mission_id: None,
                window_or_checksum: None,
            }
            .into(),
        ),
        (
            area_command_ed2(7),
            AreaTransmissionCommand {
                time_stamp: stamp(TS),
                mode: AreaTransferMode::UploadCompleteStaged,
                loop_count: Some(3),
                area_id: Some(0),
                safety_offset: Some(SafetyOffset::from_raw(150)),
                activity_id: U3::new(9),
                mission_id: Some(Text::new("M-1").unwrap()),
                window_or_checksum: Some(WindowOrChecksum::AreaChecksum(Checksum::new(
                    0xCBF4_3926,
                ))),
            }
            .into(),
        ),
        (
            area_command_ed2(8),
            AreaTransmissionCommand {
                time_stamp: stamp(TS),
                mode: AreaTransferMode::InitiateStagedDownload,
                loop_count: Some(3),
                area_id: Some(0),
                safety_offset: Some(SafetyOffset::from_raw(150)),
                activity_id: U3::new(9),
                mission_id: Some(Text::new("M-1").unwrap()),
                window_or_checksum: TransferWindow::new(32).map(WindowOrChecksum::TransferWindow),
            }
            .into(),
        ),
        (
            polygon(),
            AreaPolygonLoopSegment {
                time_stamp: stamp(TS),
                area_id: 1,
                area_type: AreaType::FlyZone,
                lower_altitude: Some(alt(0)),
                upper_altitude: Some(alt(6_000)),
                altitude_type: Some(AltitudeType::Agl),
                shape: AreaShape::Polygon(square),
            }
            .into(),
        ),
        (
            circle(),
            AreaPolygonLoopSegment {
                time_stamp: stamp(TS),
                area_id: 1,
                area_type: AreaType::FlyZone,
                lower_altitude: Some(alt(0)),
                upper_altitude: Some(alt(6_000)),
                altitude_type: Some(AltitudeType::Agl),
                shape: AreaShape::Circle {
                    centre: geo(circle_points[0].0, circle_points[0].1),
                    border: geo(circle_points[1].0, circle_points[1].1),
                },
            }
            .into(),
        ),
        (
            area_alert(),
            AreaStatusAlert {
                time_stamp: stamp(TS),
                loop_count: 3,
                status: AreaListStatus::Invalid,
                reason: Some(Reason::BadGeometry),
            }
            .into(),
        ),
        (
            area_transmission_status(),
            AreaTransmissionStatus {
                time_stamp: stamp(TS),
                area_id: 0,
                loop_count: 3,
                safety_offset: SafetyOffset::from_raw(150),
                status: AreaDownloadStatus::Ready,
            }
            .into(),
        ),
        (
            execute(),
            MissionExecuteCommand {
                time_stamp: stamp(TS),
                command: ExecuteCommand::ReturnToHome,
                mission_id: None,
            }
            .into(),
        ),
        (
            activate(),
            MissionExecuteCommand {
                time_stamp: stamp(TS),
                command: ExecuteCommand::ActivateStaged,
                mission_id: Some(Text::new("M-1").unwrap()),
            }
            .into(),
        ),
        (
            mission_report(),
            MissionReport {
                time_stamp: stamp(TS),
                report_index: 2,
                report_count: 3,
                mission_id: Some(Text::new("M-1").unwrap()),
                waypoint_count: 12,
                area_count: 3,
                geofence_check: GeofenceCheck::Failed,
                reason: Some(Reason::GeofenceViolation),
                mission_checksum: Some(Checksum::new(0x1A2B_3C4D)),
                area_checksum: Some(Checksum::new(0xCBF4_3926)),
            }
            .into(),
        ),
    ];
    for (msg, expected) in cases {
        assert_eq!(msg.decode(), Ok(expected.clone()), "#{}", msg.ty);
        let mut out = [0u8; MAX_DATA_LEN];
        let n = expected.encode(&mut out).unwrap();
        assert_eq!(
            &out[..n],
            &msg.data()[..],
            "#{} encodes differently",
            msg.ty
        );
    }
}

/// Each message with only its mandatory fields is valid (optional fields take no bytes).
#[test]
fn messages_with_only_their_mandatory_fields_decode() {
    for (msg, mandatory) in all_messages() {
        let mut m = msg.clone();
        m.fields.retain(|(bit, _)| mandatory.contains(bit));
        let decoded = m.decode();
        assert!(decoded.is_ok(), "#{} {:?}: {decoded:?}", m.ty, m.data());
    }
}

// The field names the errors carry are those of the ICD tables (§4): one owner,
// `every_message_type_has_its_field_table` in tests/icd_document.rs, which reads them (names,
// PV bits and how many, #4001's 21 too) from docs/icd.md itself rather than from a copy here.

// ---------------------------------------------------------------------------------------------
// ICD §2: the wrapper
// ---------------------------------------------------------------------------------------------

#[test]
fn frame_shorter_than_the_header_is_too_short() {
    let valid = wrap(50000, &execute_data());
    assert_eq!(frame_error(&[]), FrameError::TooShort { len: 0 });
    assert_eq!(frame_error(&valid[..15]), FrameError::TooShort { len: 15 });
    assert_eq!(
        walk(&valid[..15]).first().copied(),
        Some(Err(FrameError::TooShort { len: 15 }))
    );
    // A header alone (Message Length 7, no data) is long enough for the header rule.
    assert_eq!(
        frame_error(&valid[..16]),
        FrameError::LengthMismatch {
            expected: valid.len(),
            actual: 16
        }
    );
}

#[test]
fn message_length_0_is_out_of_range() {
    let f = with_checksum(header(0, GCS, FCC, 50000, PROPERTIES), 4);
    assert_eq!(frame_error(&f), FrameError::LengthOutOfRange { length: 0 });
    assert_eq!(
        walk(&f).first().copied(),
        Some(Err(FrameError::LengthOutOfRange { length: 0 }))
    );
}

#[test]
fn message_length_529_is_out_of_range() {
    let mut f = header(529, GCS, FCC, 50000, PROPERTIES);
    f.extend_from_slice(&[0u8; 529]);
    let f = with_checksum(f, 4);
    assert_eq!(
        frame_error(&f),
        FrameError::LengthOutOfRange { length: 529 }
    );
    let f = with_checksum(header(u16::MAX, GCS, FCC, 50000, PROPERTIES), 4);
    assert_eq!(
        frame_error(&f),
        FrameError::LengthOutOfRange { length: u16::MAX }
    );
}

#[test]
fn message_length_528_passes_the_wrapper() {
    // 528 bytes of message data: the wrapper is sound; the message has 521 trailing bytes.
    let mut d = execute_data();
    d.resize(528, 0xAA);
    let f = wrap(50000, &d);
    assert_eq!(f.len(), 548);
    let frame = Frame::new_checked(&f).unwrap();
    assert_eq!(frame.data().len(), 528);
    assert_eq!(
        wire::decode(&f),
        Err(DecodeError::Message(rejected(
            50000,
            None,
            Cause::TrailingBytes { count: 521 },
            Some(TS)
        )))
    );
}

#[test]
fn message_length_longer_than_the_datagram_is_length_mismatch() {
    let valid = wrap(50000, &execute_data());
    let n = valid.len();
    assert_eq!(
        frame_error(&valid[..n - 1]),
        FrameError::LengthMismatch {
            expected: n,
            actual: n - 1
        }
    );
    // Message Length one more than the data carried (checksum recomputed).
    let d = execute_data();
    let mut f = header(d.len() as u16 + 1, GCS, FCC, 50000, PROPERTIES);
    f.extend_from_slice(&d);
    let f = with_checksum(f, 4);
    assert_eq!(
        frame_error(&f),
        FrameError::LengthMismatch {
            expected: f.len() + 1,
            actual: f.len()
        }
    );
    assert_eq!(
        walk(&f).first().copied(),
        Some(Err(FrameError::LengthMismatch {
            expected: f.len() + 1,
            actual: f.len()
        }))
    );
}

#[test]
fn message_length_shorter_than_the_datagram_is_length_mismatch() {
    let valid = wrap(50000, &execute_data());
    let n = valid.len();
    let mut long = valid.clone();
    long.push(0);
    assert_eq!(
        frame_error(&long),
        FrameError::LengthMismatch {
            expected: n,
            actual: n + 1
        }
    );
    // Message Length one less than the data carried (checksum recomputed over what it covers).
    let d = execute_data();
    let mut f = header(d.len() as u16 - 1, GCS, FCC, 50000, PROPERTIES);
    f.extend_from_slice(&d[..d.len() - 1]);
    let mut f = with_checksum(f, 4);
    f.push(0x01);
    assert_eq!(
        frame_error(&f),
        FrameError::LengthMismatch {
            expected: f.len() - 1,
            actual: f.len()
        }
    );
}

#[test]
fn checksum_length_code_11_is_invalid() {
    let f = frame(
        GCS,
        FCC,
        50000,
        properties(false, 40, 0b11),
        4,
        &execute_data(),
    );
    assert_eq!(frame_error(&f), FrameError::InvalidChecksumLength);
    assert_eq!(
        walk(&f).first().copied(),
        Some(Err(FrameError::InvalidChecksumLength))
    );
}

#[test]
fn wrong_4_byte_checksum_is_checksum_mismatch() {
    let mut f = wrap(50000, &execute_data());
    let n = f.len();
    let computed = byte_sum(&f[..n - 4]);
    let received = computed.wrapping_add(1);
    f[n - 4..].copy_from_slice(&received.to_be_bytes());
    assert_eq!(
        frame_error(&f),
        FrameError::ChecksumMismatch { computed, received }
    );
}

#[test]
fn wrong_2_byte_checksum_is_checksum_mismatch() {
    let props = properties(false, 40, 0b01);
    let mut f = frame(GCS, FCC, 50000, props, 2, &execute_data());
    let n = f.len();
    let computed = byte_sum(&f[..n - 2]) & 0xFFFF;
    let received = computed ^ 0x0001;
    f[n - 2..].copy_from_slice(&(received as u16).to_be_bytes());
    assert_eq!(
        frame_error(&f),
        FrameError::ChecksumMismatch { computed, received }
    );
}

#[test]
fn frame_with_a_2_byte_checksum_decodes() {
    let f = frame(
        GCS,
        FCC,
        50000,
        properties(true, 40, 0b01),
        2,
        &execute_data(),
    );
    assert_eq!(f.len(), 16 + 7 + 2);
    let (envelope, message) = wire::decode(&f).unwrap();
    assert_eq!(
        envelope,
        Envelope {
            source_id: GCS,
            destination_id: FCC,
            ack_requested: true,
            idd_version: 40,
            checksum: ChecksumWidth::Two,
        }
    );
    assert_eq!(message.time_stamp(), stamp(TS));
}

#[test]
fn two_byte_checksum_is_the_byte_sum_truncated_to_16_bits() {
    // 60 vertices at (-1, -1) LSB: 480 bytes of 0xFF, a byte sum far above 0xFFFF.
    let d = area(0, &[(-1, -1); 60]).data();
    let props = properties(false, 40, 0b01);
    let mut f = header(d.len() as u16, GCS, FCC, 2012, props);
    f.extend_from_slice(&d);
    let sum = byte_sum(&f);
    assert!(sum > 0xFFFF);
    f.extend_from_slice(&(sum as u16).to_be_bytes());
    assert!(wire::decode(&f).is_ok());
    // The 4-byte checksum keeps every bit of the sum.
    let f4 = frame(GCS, FCC, 2012, PROPERTIES, 4, &d);
    let sum4 = byte_sum(&f4[..f4.len() - 4]);
    assert!(sum4 > 0xFFFF);
    assert_eq!(&f4[f4.len() - 4..], &sum4.to_be_bytes());
    assert!(wire::decode(&f4).is_ok());
}

#[test]
fn frame_without_checksum_decodes() {
    let f = frame(
        GCS,
        FCC,
        50000,
        properties(false, 40, 0b00),
        0,
        &execute_data(),
    );
    assert_eq!(f.len(), 16 + 7);
    let (envelope, message) = wire::decode(&f).unwrap();
    assert_eq!(envelope.checksum, ChecksumWidth::None);
    assert!(!envelope.ack_requested);
    assert_eq!(message.time_stamp(), stamp(TS));
}

#[test]
fn idd_version_29_and_41_are_unsupported() {
    for version in [29u8, 41, 0, 127] {
        let f = frame(
            GCS,
            FCC,
            50000,
            properties(false, u16::from(version), 0b10),
            4,
            &execute_data(),
        );
        assert_eq!(frame_error(&f), FrameError::UnsupportedVersion { version });
    }
}

#[test]
fn idd_version_30_and_40_are_accepted() {
    for version in [30u8, 35, 40] {
        let f = frame(
            GCS,
            FCC,
            50000,
            properties(false, u16::from(version), 0b10),
            4,
            &execute_data(),
        );
        let (envelope, _) = wire::decode(&f).unwrap();
        assert_eq!(envelope.idd_version, version);
    }
}

#[test]
fn reserved_field_and_property_bits_5_to_0_are_ignored_on_receive() {
    // Reserved (sequence) 0x1234 instead of 0xFFFF, properties bits 5..0 = 0b10_1010.
    let d = execute_data();
    let mut f = header(d.len() as u16, GCS, FCC, 50000, PROPERTIES | 0b10_1010);
    f[0..2].copy_from_slice(&0x1234u16.to_be_bytes());
    f.extend_from_slice(&d);
    let f = with_checksum(f, 4);
    let (envelope, _) = wire::decode(&f).unwrap();
    assert_eq!(envelope, Envelope::new(GCS, FCC));
}

#[test]
fn destination_neither_local_nor_broadcast_is_wrong_destination() {
    let f = frame(GCS, 0x0B00_0002, 50000, PROPERTIES, 4, &execute_data());
    let frame = Frame::new_checked(&f).unwrap();
    assert_eq!(
        frame.check_addressing(FCC, GCS),
        Err(FrameError::WrongDestination {
            destination: 0x0B00_0002
        })
    );
    // The destination is checked first: a foreign frame from a stranger is WrongDestination.
    let f = frame_bytes_from(0x0C00_0001, GCS);
    assert_eq!(
        Frame::new_checked(&f).unwrap().check_addressing(FCC, GCS),
        Err(FrameError::WrongDestination { destination: GCS })
    );
}

fn frame_bytes_from(source: u32, destination: u32) -> Vec<u8> {
    frame(source, destination, 50000, PROPERTIES, 4, &execute_data())
}

#[test]
fn local_and_broadcast_destinations_are_accepted() {
    for destination in [FCC, BROADCAST_ID] {
        let f = frame_bytes_from(GCS, destination);
        assert_eq!(
            Frame::new_checked(&f).unwrap().check_addressing(FCC, GCS),
            Ok(())
        );
    }
}

#[test]
fn source_not_the_peer_is_unknown_source() {
    for destination in [FCC, BROADCAST_ID] {
        let f = frame_bytes_from(0x0A00_0002, destination);
        assert_eq!(
            Frame::new_checked(&f).unwrap().check_addressing(FCC, GCS),
            Err(FrameError::UnknownSource {
                source: 0x0A00_0002
            })
        );
    }
}

#[test]
fn datagram_walker_stops_after_a_broken_frame() {
    let first = wrap(50000, &execute_data());
    let mut broken = wrap(3012, &area_alert().data());
    let last = broken.len() - 1;
    broken[last] ^= 0x01;
    let computed = byte_sum(&broken[..last - 3]);
    let third = wrap(13002, &waypoint().data());
    let datagram = [first.clone(), broken, third.clone()].concat();

    assert_eq!(
        walk(&datagram),
        vec![
            Ok(&first[..]),
            Err(FrameError::ChecksumMismatch {
                computed,
                received: computed ^ 0x01
            })
        ]
    );
    let mut walker = wire::frames(&datagram);
    assert!(walker.next().unwrap().is_ok());
    assert!(walker.next().unwrap().is_err());
    assert!(walker.next().is_none());
    assert!(walker.next().is_none());

    // Without the broken frame both are walked.
    let datagram = [first.clone(), third.clone()].concat();
    let walked: Vec<_> = wire::frames(&datagram).map(Result::unwrap).collect();
    assert_eq!(walked.len(), 2);
    assert_eq!(walked[0].as_bytes(), &first[..]);
    assert_eq!(walked[1].as_bytes(), &third[..]);
    // Trailing bytes too few for a header are a broken last frame.
    let datagram = [first.clone(), vec![0xFF; 3]].concat();
    assert_eq!(
        walk(&datagram),
        vec![Ok(&first[..]), Err(FrameError::TooShort { len: 3 })]
    );
}

#[test]
fn datagram_walker_follows_each_frames_checksum_width() {
    let d = execute_data();
    let a = frame(GCS, FCC, 50000, properties(false, 40, 0b00), 0, &d);
    let b = frame(GCS, FCC, 50000, properties(false, 40, 0b01), 2, &d);
    let c = frame(GCS, FCC, 50000, properties(false, 40, 0b10), 4, &d);
    let datagram = [a.clone(), b.clone(), c.clone()].concat();
    let walked: Vec<_> = wire::frames(&datagram).map(Result::unwrap).collect();
    let bytes: Vec<&[u8]> = walked.iter().map(Frame::as_bytes).collect();
    assert_eq!(bytes, vec![&a[..], &b[..], &c[..]]);
}

#[test]
fn frame_errors_are_never_acknowledged() {
    let e = DecodeError::Frame(FrameError::InvalidChecksumLength);
    assert_eq!(e.reason(), None);
    assert_eq!(
        e.to_string(),
        "frame rejected: checksum length code 11 is invalid"
    );
}

// ---------------------------------------------------------------------------------------------
// ICD §3: presence vector, field encodings
// ---------------------------------------------------------------------------------------------

#[test]
fn every_mandatory_field_absent_is_missing_field() {
    for (msg, mandatory) in all_messages() {
        for bit in mandatory {
            let e = msg.clone().without(*bit).reject();
            let time_stamp = (*bit != 0).then_some(TS);
            assert_eq!(
                e,
                rejected(
                    msg.ty,
                    Some((*bit, name(msg.ty, *bit))),
                    Cause::MissingField,
                    time_stamp
                ),
                "#{} without bit {bit}",
                msg.ty
            );
            assert_eq!(e.reason(), Reason::MissingField);
        }
    }
}

/// #101 carries a position as a pair and an altitude with its reference (ICD §4): one half
/// without the other is `MissingField` on the absent one.
#[test]
fn inertial_states_halves_are_missing_field() {
    for absent in [1, 2, 4] {
        assert_eq!(
            inertial_states().without(absent).reject(),
            rejected(
                101,
                Some((absent, name(101, absent))),
                Cause::MissingField,
                Some(TS)
            ),
            "#101 without bit {absent}"
        );
    }
    // Without the altitude, its type alone is no contradiction.
    assert!(inertial_states().without(3).decode().is_ok());
}

/// Named cases of the rule above, with the field named explicitly, and the fields mandatory
/// only in some modes (ICD §4): absent where the mode needs them, they are missing; the other
/// modes do without them.
#[test]
fn fields_mandatory_in_a_mode_absent_are_missing_field() {
    // The message without the field, the field (PV bit, ICD name), the time stamp it carries.
    let mut missing: Vec<(Msg, u8, &str, Option<u64>)> = vec![
        (waypoint().without(2), 2, "Waypoint to Latitude", Some(TS)),
        (rf_centre().without(6), 6, "Turn Direction", Some(TS)),
        (rf_centre().without(4), 4, "RF Centre Latitude", Some(TS)),
        (take_off_height().without(3), 3, "Take-off Height", Some(TS)),
        (execute().without(0), 0, "Time Stamp", None),
    ];
    // Transmit and stage mission need the Waypoint Number.
    for mode in [2, 8] {
        missing.push((
            transfer_command(mode).without(3),
            3,
            "Waypoint Number",
            Some(TS),
        ));
    }
    // Area command modes 1, 2, 4 and 7 need the loop count.
    for mode in [1, 2, 4, 7] {
        missing.push((
            area_command_ed2(mode).without(2),
            2,
            "Area Loop Count",
            Some(TS),
        ));
    }
    for (msg, bit, name, time_stamp) in missing {
        let e = msg.reject();
        assert_eq!(
            e,
            rejected(msg.ty, Some((bit, name)), Cause::MissingField, time_stamp),
            "#{} without {name}: {:?}",
            msg.ty,
            msg.fields
        );
        assert_eq!(e.reason(), Reason::MissingField);
    }
    // The other modes do without them.
    for mode in [1, 3, 5, 6, 9, 10] {
        assert!(
            transfer_command(mode).without(3).decode().is_ok(),
            "mode {mode}"
        );
    }
    for mode in [3, 5, 6, 8] {
        assert!(
            area_command_ed2(mode).without(2).decode().is_ok(),
            "mode {mode}"
        );
    }
}

#[test]
fn pv_bit_beyond_the_defined_fields_is_unknown_field() {
    let cases = [
        (ack().pv_bit(5), 17000, 5),
        (waypoint().pv_bit(18), 13002, 18),
        (polygon().pv_bit(9), 2012, 9),
        (from_to_next().pv_bit(21), 4001, 21),
        (inertial_states().pv_bit(18), 101, 18),
        (execute().pv_bit(7), 50000, 7),
    ];
    for (msg, ty, bit) in cases {
        let e = msg.reject();
        assert_eq!(
            e,
            rejected(ty, None, Cause::UnknownField { bit }, Some(TS)),
            "#{ty}"
        );
        assert_eq!(e.reason(), Reason::UnknownField);
    }
}

#[test]
fn every_pv_bit_beyond_the_defined_fields_is_unknown_field() {
    for (msg, _) in all_messages() {
        let defined = name_count(msg.ty);
        for bit in defined..(msg.pv_bytes * 8) as u8 {
            assert_eq!(
                msg.clone().pv_bit(bit).reject(),
                rejected(msg.ty, None, Cause::UnknownField { bit }, Some(TS)),
                "#{} bit {bit}",
                msg.ty
            );
        }
    }
}

fn name_count(ty: u16) -> u8 {
    MessageType::try_from(ty).unwrap().fields().len() as u8
}

#[test]
fn data_ending_inside_a_field_is_truncated() {
    // #13002 cut inside the latitude: PV (3) + time stamp (5) + waypoint number (2) + 2 bytes.
    let d = waypoint().data();
    let e = reject(13002, &d[..12]);
    assert_eq!(
        e,
        rejected(
            13002,
            Some((2, "Waypoint to Latitude")),
            Cause::Truncated,
            Some(TS)
        )
    );
    assert_eq!(e.reason(), Reason::Malformed);
    // #50000 without the command byte.
    let d = execute().data();
    assert_eq!(
        reject(50000, &d[..6]),
        rejected(50000, Some((1, "Command")), Cause::Truncated, Some(TS))
    );
    // Inside the time stamp: no time stamp to acknowledge with.
    assert_eq!(
        reject(50000, &d[..3]),
        rejected(50000, Some((0, "Time Stamp")), Cause::Truncated, None)
    );
    // #2012 with a vertex short.
    let d = polygon().data();
    assert_eq!(
        reject(2012, &d[..d.len() - 1]),
        rejected(2012, Some((8, "Vertices")), Cause::Truncated, Some(TS))
    );
}

#[test]
fn bytes_after_the_last_field_are_trailing_bytes() {
    let mut d = execute().data();
    d.extend_from_slice(&[0, 0]);
    let e = reject(50000, &d);
    assert_eq!(
        e,
        rejected(50000, None, Cause::TrailingBytes { count: 2 }, Some(TS))
    );
    assert_eq!(e.reason(), Reason::Malformed);
    let mut d = polygon().data();
    d.push(0);
    assert_eq!(
        reject(2012, &d),
        rejected(2012, None, Cause::TrailingBytes { count: 1 }, Some(TS))
    );
}

#[test]
fn message_data_shorter_than_the_presence_vector_is_short_presence_vector() {
    let e = reject(13002, &[0x00, 0x00]);
    assert_eq!(e, rejected(13002, None, Cause::ShortPresenceVector, None));
    assert_eq!(e.reason(), Reason::Malformed);
    assert_eq!(
        reject(2012, &[0x01]),
        rejected(2012, None, Cause::ShortPresenceVector, None)
    );
    assert_eq!(
        Message::decode(50000, &[]),
        Err(rejected(50000, None, Cause::ShortPresenceVector, None))
    );
}

/// A value outside its field's range (ICD §3, §4) is rejected as out of range, naming the
/// field (PV bit and ICD name) and the value, with the reason Malformed; the values at the
/// edges of each range decode.
#[test]
fn values_outside_a_fields_range_are_out_of_range() {
    let b90 = i64::from(BEYOND_90);
    let mut vertex_beyond_90 = n_vertices(5);
    vertex_beyond_90[3].0 = BEYOND_90;
    // The message with one field out of range, that field (PV bit, ICD name), the value.
    let out_of_range: Vec<(Msg, u8, &str, i64)> = vec![
        (waypoint().with(1, u2(0)), 1, "Waypoint Number", 0),
        (waypoint().with(1, u2(65535)), 1, "Waypoint Number", 65535),
        (waypoint().with(10, u2(65535)), 10, "Next Waypoint", 65535),
        (route().with(1, u2(0)), 1, "Initial Waypoint Number", 0),
        (rf_centre().with(1, u2(0)), 1, "Waypoint Number", 0),
        (
            waypoint().with(2, i4(BEYOND_90)),
            2,
            "Waypoint to Latitude",
            b90,
        ),
        (
            waypoint().with(2, i4(-BEYOND_90)),
            2,
            "Waypoint to Latitude",
            -b90,
        ),
        (
            waypoint().with(2, i4(i32::MIN)),
            2,
            "Waypoint to Latitude",
            i32::MIN.into(),
        ),
        (
            waypoint().with(2, i4(i32::MAX)),
            2,
            "Waypoint to Latitude",
            i32::MAX.into(),
        ),
        // The same rule on every latitude field.
        (
            rf_centre().with(4, i4(BEYOND_90)),
            4,
            "RF Centre Latitude",
            b90,
        ),
        (
            from_to_next().with(14, i4(-BEYOND_90)),
            14,
            "Next Latitude",
            -b90,
        ),
        (inertial_states().with(1, i4(BEYOND_90)), 1, "Latitude", b90),
        (area(0, &vertex_beyond_90), 8, "Vertices", b90),
        (waypoint().with(8, u2(0)), 8, "Waypoint to Speed", 0),
        (
            transfer_status().with(3, u1(101)),
            3,
            "Percent Complete",
            101,
        ),
        (polygon().with(1, u2(0)), 1, "Area ID", 0),
        (polygon().with(1, u2(65535)), 1, "Area ID", 65535),
        (take_off_height().with(3, i3(-1)), 3, "Take-off Height", -1),
    ];
    for (msg, bit, name, value) in out_of_range {
        let e = msg.reject();
        assert_eq!(
            e,
            rejected(
                msg.ty,
                Some((bit, name)),
                Cause::OutOfRange { value },
                Some(TS)
            ),
            "#{} {name} = {value}",
            msg.ty
        );
        assert_eq!(
            e.reason(),
            Reason::Malformed,
            "#{} {name} = {value}",
            msg.ty
        );
    }
    let edges = [
        waypoint().with(1, u2(1)),
        waypoint().with(1, u2(65534)),
        // Next Waypoint 0 = the last waypoint.
        waypoint().with(10, u2(0)),
        // Exactly +-90 deg is a latitude.
        waypoint().with(2, i4(1 << 30)),
        waypoint().with(2, i4(-(1 << 30))),
        waypoint().with(8, u2(1)),
        transfer_status().with(3, u1(100)),
        transfer_status().with(3, u1(0)),
        take_off_height().with(3, i3(0)),
    ];
    for msg in edges {
        assert!(msg.decode().is_ok(), "#{} {:?}", msg.ty, msg.fields);
    }
}

#[test]
fn lower_altitude_above_upper_is_inconsistent() {
    let e = polygon().with(4, i3(6_001)).reject();
    assert_eq!(
        e,
        rejected(
            2012,
            Some((5, "Upper Altitude")),
            Cause::Inconsistent,
            Some(TS)
        )
    );
    assert_eq!(e.reason(), Reason::Malformed);
    // Equal is fine, and so is a negative lower altitude (ALT3 is signed).
    assert!(polygon().with(4, i3(6_000)).decode().is_ok());
    assert!(polygon().with(4, i3(-100)).decode().is_ok());
    assert_eq!(
        polygon().with(4, i3(0)).with(5, i3(-1)).reject(),
        rejected(
            2012,
            Some((5, "Upper Altitude")),
            Cause::Inconsistent,
            Some(TS)
        )
    );
}

/// A text field (ICD §3) without its NUL terminator, padded with anything but NUL, or not
/// UTF-8 is rejected as bad text, naming the field, with the reason Malformed; a text of the
/// longest length with its terminator, and an empty text, decode.
#[test]
fn text_fields_that_break_the_text_rules_are_bad_text() {
    let unterminated = vec![b'A'; 20];
    let mut padded_with_x = text("M-1", 20);
    padded_with_x[10] = b'x';
    let mut padded_with_ff = text("M-1", 20);
    padded_with_ff[19] = 0xFF;
    let mut lone_lead_byte = text("", 33);
    lone_lead_byte[0] = 0xC3; // a lone UTF-8 lead byte
    // The message with one bad text, that field (PV bit, ICD name).
    let bad: Vec<(Msg, u8, &str)> = vec![
        (transfer_command(2).with(1, unterminated), 1, "Mission ID"),
        (route().with(2, vec![b'R'; 33]), 2, "Route ID"),
        (transfer_command(2).with(1, padded_with_x), 1, "Mission ID"),
        (transfer_status().with(1, padded_with_ff), 1, "Mission ID"),
        (route().with(2, lone_lead_byte), 2, "Route ID"),
    ];
    for (msg, bit, name) in bad {
        let e = msg.reject();
        assert_eq!(
            e,
            rejected(msg.ty, Some((bit, name)), Cause::BadText, Some(TS)),
            "#{} {name}",
            msg.ty
        );
        assert_eq!(e.reason(), Reason::Malformed, "#{} {name}", msg.ty);
    }
    // 19 characters and the terminator fit.
    let mut longest = vec![b'A'; 19];
    longest.push(0);
    assert!(transfer_command(2).with(1, longest).decode().is_ok());
    assert!(
        route().with(2, text("", 33)).decode().is_ok(),
        "empty text is fine"
    );
}

/// An enumeration value the ICD does not define, or a mode or type the project does not
/// support (relative locations, area shape 2), is rejected as unsupported, naming the field
/// (PV bit and ICD name) and the value, with the reason Unsupported.
#[test]
fn undefined_enumeration_values_are_unsupported() {
    // The message with one such value, the field (PV bit, ICD name), the value.
    let cases: Vec<(Msg, u8, &str, u32)> = vec![
        (waypoint().with(4, u1(1)), 4, "Location Type", 1), // relative
        (transfer_command(0), 2, "Mission Plan Mode", 0),
        (transfer_command(4), 2, "Mission Plan Mode", 4),
        (transfer_command(11), 2, "Mission Plan Mode", 11),
        (transfer_command(255), 2, "Mission Plan Mode", 255),
        (take_off_height().with(2, u1(0)), 2, "Specific Data Type", 0),
        (take_off_height().with(2, u1(3)), 2, "Specific Data Type", 3),
        // #2012 carries the area shape in its Activity ID field (ICD §4).
        (area(2, &n_vertices(3)), 3, "Activity ID", 2),
        (ack().with(3, u1(5)), 3, "Acknowledgement Type", 5),
        (ack().with(4, u1(16)), 4, "Reject Reason", 16),
        (route().with(3, u1(5)), 3, "Route Type", 5),
        (waypoint().with(6, u1(4)), 6, "Waypoint Altitude Type", 4),
        (waypoint().with(9, u1(3)), 9, "Waypoint Speed Type", 3),
        (waypoint().with(11, u1(2)), 11, "Turn Type", 2),
        (waypoint().with(13, u1(2)), 13, "Waypoint Type", 2),
        (rf_centre().with(6, u1(2)), 6, "Turn Direction", 2),
        (transfer_status().with(2, u1(3)), 2, "Status", 3),
        (transfer_status().with(6, u1(16)), 6, "Reason", 16),
        (from_to_next().with(1, u1(4)), 1, "Altitude Type", 4),
        (from_to_next().with(2, u1(3)), 2, "Speed Type", 3),
        (area_command(0), 1, "Area Transfer Mode", 0),
        (area_command(9), 1, "Area Transfer Mode", 9),
        (polygon().with(2, u1(2)), 2, "Area Type", 2),
        (polygon().with(6, u1(4)), 6, "Altitude Type", 4),
        (area_alert().with(2, u1(2)), 2, "Status", 2),
        (area_alert().with(3, u1(16)), 3, "Reason", 16),
        (area_transmission_status().with(4, u1(1)), 4, "Status", 1),
        (execute().with(1, u1(0)), 1, "Command", 0),
        (execute().with(1, u1(5)), 1, "Command", 5),
        (mission_report().with(6, u1(3)), 6, "Geofence Check", 3),
    ];
    for (msg, bit, name, value) in cases {
        let e = msg.reject();
        assert_eq!(
            e,
            rejected(
                msg.ty,
                Some((bit, name)),
                Cause::Unsupported { value },
                Some(TS)
            ),
            "#{} {name} = {value}",
            msg.ty
        );
        assert_eq!(e.reason(), Reason::Unsupported, "#{} {name}", msg.ty);
    }
}

#[test]
fn unknown_message_type_is_unsupported() {
    for ty in [0u16, 13003, 17001, 65535] {
        let e = reject(ty, &execute().data());
        assert_eq!(e, rejected(ty, None, Cause::UnknownMessageType, None));
        assert_eq!(e.reason(), Reason::Unsupported);
        assert_eq!(
            e.to_string(),
            format!("#{ty}: message type is not in the ICD [reason Unsupported (4)]")
        );
    }
}

/// A vertex count that does not make the shape (a polygon of fewer than 3 vertices, a circle
/// of other than 2: centre and border point) is bad geometry (ICD §4, #2012).
#[test]
fn vertex_counts_that_do_not_make_the_shape_are_bad_geometry() {
    // Shape (0 polygon, 1 circle) and vertex count.
    for (shape, n) in [(0, 0usize), (0, 1), (0, 2), (1, 1), (1, 3)] {
        let e = area(shape, &n_vertices(n)).reject();
        assert_eq!(
            e,
            rejected(
                2012,
                Some((7, "Vertex Count")),
                Cause::BadGeometry { count: n },
                Some(TS)
            ),
            "shape {shape}, {n} vertices"
        );
        assert_eq!(e.reason(), Reason::BadGeometry);
    }
    assert!(area(0, &n_vertices(3)).decode().is_ok());
}

#[test]
fn polygon_with_61_vertices_is_capacity() {
    let e = area(0, &n_vertices(61)).reject();
    assert_eq!(
        e,
        rejected(
            2012,
            Some((7, "Vertex Count")),
            Cause::Capacity { count: 61, max: 60 },
            Some(TS)
        )
    );
    assert_eq!(e.reason(), Reason::Capacity);
    assert!(area(0, &n_vertices(60)).decode().is_ok());
}

#[test]
fn take_off_height_with_a_waypoint_number_is_inconsistent() {
    let e = take_off_height().with(1, u2(5)).reject();
    assert_eq!(
        e,
        rejected(
            13006,
            Some((1, "Waypoint Number")),
            Cause::Inconsistent,
            Some(TS)
        )
    );
    assert_eq!(e.reason(), Reason::Malformed);
}

// ---------------------------------------------------------------------------------------------
// ICD §4 edition 2: the extension fields, modes and command (§8, §10, §11)
// ---------------------------------------------------------------------------------------------

/// `msg` is rejected as `Inconsistent` (reason `Malformed`) on the field of `bit`.
fn assert_inconsistent(msg: &Msg, bit: u8, what: &str) {
    let e = msg.reject();
    assert_eq!(
        e,
        rejected(
            msg.ty,
            Some((bit, name(msg.ty, bit))),
            Cause::Inconsistent,
            Some(TS)
        ),
        "{what}"
    );
    assert_eq!(e.reason(), Reason::Malformed, "{what}");
}

/// The edition-2 fields absent where their mode or command needs them are missing (ICD §4,
/// §8); the modes that do without them decode.
#[test]
fn edition_2_fields_their_mode_needs_absent_are_missing_field() {
    let mut missing: Vec<(Msg, u8, &str, String)> = Vec::new();
    for mode in [6, 8, 9, 10] {
        let msg = transfer_command_ed2(mode).without(1);
        missing.push((msg, 1, "Mission ID", format!("#13000 mode {mode}")));
    }
    for mode in [7, 8] {
        let msg = area_command_ed2(mode).without(6);
        missing.push((msg, 6, "Mission ID", format!("#2011 mode {mode}")));
    }
    missing.push((
        activate().without(2),
        2,
        "Mission ID",
        "activate".to_owned(),
    ));
    for (msg, bit, name, what) in missing {
        let e = msg.reject();
        assert_eq!(
            e,
            rejected(msg.ty, Some((bit, name)), Cause::MissingField, Some(TS)),
            "{what}"
        );
        assert_eq!(e.reason(), Reason::MissingField, "{what}");
    }
    // Edition 1 and mode 7 do without it.
    for mode in [1, 2, 3, 5, 7] {
        assert!(
            transfer_command_ed2(mode).without(1).decode().is_ok(),
            "mode {mode}"
        );
    }
}

/// An edition-2 field present with a mode or command it does not go with, or an empty Mission
/// ID where one is named, is inconsistent (ICD §4, §8, §10, §11); where it goes, it decodes.
#[test]
fn edition_2_fields_with_the_wrong_mode_are_inconsistent() {
    // The message, the field (PV bit) that does not fit, what the case is.
    let mut cases: Vec<(Msg, u8, String)> = Vec::new();
    for mode in [6, 8, 9] {
        let msg = transfer_command_ed2(mode).with(1, text("", 20));
        cases.push((msg, 1, format!("#13000 mode {mode}, empty Mission ID")));
    }
    let msg = transfer_command(7).with(1, text("M-1", 20));
    cases.push((msg, 1, "mode 7 with Mission ID M-1".to_owned()));
    for mode in [1, 2, 5, 6, 7, 8, 10] {
        let msg = transfer_command_ed2(mode).with(6, u1(4));
        cases.push((msg, 6, format!("#13000 mode {mode}, Transfer Window")));
    }
    for mode in [1, 3, 5, 6, 7, 9, 10] {
        let msg = transfer_command_ed2(mode).with(7, u4(0x1A2B_3C4D));
        cases.push((msg, 7, format!("#13000 mode {mode}, Mission Checksum")));
    }
    for mode in [7, 8] {
        let msg = area_command_ed2(mode).with(6, text("", 20));
        cases.push((msg, 6, format!("#2011 mode {mode}, empty Mission ID")));
    }
    for mode in 1..=6 {
        let msg = area_command_ed2(mode).with(6, text("M-1", 20));
        cases.push((msg, 6, format!("#2011 mode {mode}, Mission ID")));
    }
    for mode in [1, 5, 6] {
        let msg = area_command_ed2(mode).with(7, u4(4));
        cases.push((msg, 7, format!("#2011 mode {mode}, field 7")));
    }
    let msg = activate().with(2, text("", 20));
    cases.push((msg, 2, "empty Mission ID".to_owned()));
    for command in [1, 2, 3] {
        let msg = activate().with(1, u1(command));
        cases.push((msg, 2, format!("command {command}")));
    }
    for (msg, bit, what) in &cases {
        assert_inconsistent(msg, *bit, what);
    }
    // Mode 10 with an empty Mission ID loads the active list into the buffer (ICD §8).
    assert!(transfer_command(10).with(1, text("", 20)).decode().is_ok());
    assert!(transfer_command(7).with(1, text("", 20)).decode().is_ok());
    assert!(transfer_command(7).without(1).decode().is_ok());
    for mode in [3, 9] {
        assert!(
            transfer_command(mode).with(6, u1(4)).decode().is_ok(),
            "mode {mode}"
        );
    }
}

#[test]
fn transfer_window_0_and_33_are_out_of_range() {
    for mode in [3, 9] {
        for window in [0u8, 33, 255] {
            let e = transfer_command(mode).with(6, u1(window)).reject();
            assert_eq!(
                e,
                rejected(
                    13000,
                    Some((6, "Transfer Window")),
                    Cause::OutOfRange {
                        value: i64::from(window)
                    },
                    Some(TS)
                ),
                "mode {mode} window {window}"
            );
            assert_eq!(e.reason(), Reason::Malformed);
        }
        for window in [1u8, 32] {
            assert!(transfer_command(mode).with(6, u1(window)).decode().is_ok());
        }
    }
}

#[test]
fn area_command_field_7_is_read_by_the_mode() {
    let decoded = |msg: Msg| match msg.decode() {
        Ok(Message::AreaTransmissionCommand(c)) => c.window_or_checksum,
        other => panic!("#2011 mode {:?}: {other:?}", msg.fields),
    };
    // Modes 3 and 8: a Transfer Window.
    for mode in [3, 8] {
        for window in [1u32, 32] {
            assert_eq!(
                decoded(area_command_ed2(mode).with(7, u4(window))),
                Some(WindowOrChecksum::TransferWindow(
                    TransferWindow::try_from(window).unwrap()
                )),
                "mode {mode}"
            );
        }
    }
    // Modes 2, 4 and 7: an Area Checksum, any U4.
    for mode in [2, 4, 7] {
        for value in [0u32, 32, u32::MAX] {
            assert_eq!(
                decoded(area_command_ed2(mode).with(7, u4(value))),
                Some(WindowOrChecksum::AreaChecksum(Checksum::new(value))),
                "mode {mode}"
            );
        }
    }
}

#[test]
fn area_command_transfer_window_0_and_33_are_out_of_range() {
    for mode in [3, 8] {
        // 0x104 would be 4 if the U4 were cut to a U1.
        for window in [0u32, 33, 0x104, u32::MAX] {
            let e = area_command_ed2(mode).with(7, u4(window)).reject();
            assert_eq!(
                e,
                rejected(
                    2011,
                    Some((7, "Transfer Window or Area Checksum")),
                    Cause::OutOfRange {
                        value: i64::from(window)
                    },
                    Some(TS)
                ),
                "mode {mode} window {window}"
            );
            assert_eq!(e.reason(), Reason::Malformed);
        }
    }
}

#[test]
fn report_index_outside_1_to_report_count_is_out_of_range() {
    for (index, count) in [(0u8, 3u8), (4, 3), (1, 0), (255, 254)] {
        let e = mission_report()
            .with(1, u1(index))
            .with(2, u1(count))
            .reject();
        assert_eq!(
            e,
            rejected(
                50001,
                Some((1, "Report Index")),
                Cause::OutOfRange {
                    value: i64::from(index)
                },
                Some(TS)
            ),
            "{index} of {count}"
        );
        assert_eq!(e.reason(), Reason::Malformed);
    }
    for (index, count) in [(1u8, 1u8), (1, 3), (3, 3), (255, 255)] {
        assert!(
            mission_report()
                .with(1, u1(index))
                .with(2, u1(count))
                .decode()
                .is_ok(),
            "{index} of {count}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// What a rejection carries
// ---------------------------------------------------------------------------------------------

#[test]
fn rejection_carries_the_time_stamp_when_readable() {
    // Readable: rules broken after the time stamp, and even an unknown PV bit (checked first).
    assert_eq!(
        waypoint().with(1, u2(0)).reject().time_stamp,
        Some(stamp(TS))
    );
    assert_eq!(ack().pv_bit(7).reject().time_stamp, Some(stamp(TS)));
    assert_eq!(
        area(0, &n_vertices(61)).reject().time_stamp,
        Some(stamp(TS))
    );
    let mut d = execute().data();
    d.push(0);
    assert_eq!(reject(50000, &d).time_stamp, Some(stamp(TS)));
    // Unreadable: absent, cut short, before the PV, or a message type that is not ours.
    assert_eq!(execute().without(0).reject().time_stamp, None);
    assert_eq!(reject(50000, &execute().data()[..4]).time_stamp, None);
    assert_eq!(reject(13002, &[0]).time_stamp, None);
    assert_eq!(reject(13003, &execute().data()).time_stamp, None);
    // The acknowledgement of a rejection takes its time stamp and reason.
    let e = waypoint().without(8).reject();
    let answer = MessageAcknowledgement {
        time_stamp: stamp(TS + 5),
        original_time_stamp: e.time_stamp.unwrap(),
        original_message_type: e.message_type,
        ack_type: AckType::Rejected,
        reject_reason: Some(e.reason()),
    };
    assert_eq!(answer.original_message_type, 13002);
    assert_eq!(answer.reject_reason, Some(Reason::MissingField));
}

#[test]
fn rejection_display_names_message_field_and_reason() {
    let e = waypoint().with(1, u2(0)).reject();
    let s = e.to_string();
    assert_eq!(
        s,
        "#13002 UA Position Waypoint, Waypoint Number (PV bit 1): value 0 is out of range \
         [reason Malformed (1)]"
    );
    let e = polygon().without(8).reject();
    let s = e.to_string();
    for part in [
        "#2012",
        "Area Polygon Loop Segment",
        "Vertices",
        "8",
        "MissingField",
    ] {
        assert!(s.contains(part), "{s:?} lacks {part:?}");
    }
    let e = ack().pv_bit(5).reject();
    assert_eq!(
        e.to_string(),
        "#17000 Message Acknowledgement: presence vector bit 5 is beyond the defined fields \
         [reason UnknownField (3)]"
    );
    let d = DecodeError::Message(e);
    assert!(d.to_string().starts_with("message rejected: #17000"));
    assert_eq!(d.reason(), Some(Reason::UnknownField));
}
