//! Fixtures shared by every test and benchmark of the workspace (after rust-mavlink's
//! `mavlink/tests/test_shared/mod.rs`; docs/design.md, "Examples followed"), so that no waypoint
//! literal, area helper, demo mission or endpoint configuration is written twice.
//!
//! Compiled in this crate's own tests and, for other crates' tests and benches, behind the cargo
//! feature `testkit` (`missionlink-protocol = { workspace = true, features = ["testkit"] }` in
//! `[dev-dependencies]`). No flight or ground binary enables it.
//!
//! What it holds:
//! - time and configuration: [`UTC_AT_ZERO_MS`], [`ts`], [`endpoint`] (the defaults of ICD
//!   §1, instant zero at 2026-11-21T12:00:00Z);
//! - messages: [`waypoint`] (the 18-field #13002 with the values every test uses),
//!   [`full_waypoint`] (every optional field present, as the wire benches encode it),
//!   [`take_off`], [`rf_centre`], [`route`];
//! - areas: [`polygon`], [`circle`], [`ellipse`] (a 60-vertex polygon), [`full_polygon`],
//!   [`FLY_ZONE`], [`NFZ_POLYGON`], [`eleven_areas`];
//! - missions and plans: [`mission_buffer`], [`area_buffer`], [`plan`], [`mission_1`] and
//!   [`mission_2`] (the demo missions of `missions/`), [`zigzag`] and [`generated_plan`] (N
//!   waypoints with 11 areas);
//! - the onboard geofence check's worst case: [`geofence_worst_case`] and
//!   [`geofence_worst_case_rf`] (256 waypoints against 11 areas of 60 vertices, every zone
//!   close to the route, the check passing), built from [`worst_case_messages`] and
//!   [`worst_case_areas`];
//! - frames: [`frame`], [`uplink`], [`RawFrame`] (a frame by hand, any rule broken),
//!   [`Transmit`] (what a machine sends, taken through its `poll_transmit`), [`decoded`];
//! - allocations: [`CountingAllocator`] and [`counted`], for the tests that prove a path
//!   allocates nothing.
//!
//! The FCC's and the GCS's configurations are in `missionlink-flight`'s and
//! `missionlink-ground`'s testkits, which re-export this one; the links' fault model and the
//! seeded RNG are `missionlink-linksim`'s.
//!
//! Every constructor takes values the tests choose and builds them with `expect`: a fixture that
//! does not build is a broken test, not outside input, so this module (test-only code) allows
//! what the crate denies elsewhere.
#![allow(
    clippy::expect_used,
    reason = "test-only fixtures: the values are literals the tests choose, a failure is a broken test"
)]

mod counting_alloc;
pub use counting_alloc::{CountingAllocator, counted};

use missionlink_interfaces::capacity::MAX_POLYGON_VERTICES;
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{
    self, Altitude, AltitudeType, Angle, AreaPolygonLoopSegment, AreaShape, AreaType, EncodeError,
    Envelope, GeoPoint, LegType, LocationType, MAX_FRAME_LEN, Message, PolygonVertices, RouteType,
    SafetyOffset, SpecificData, Speed, SpeedType, Text, Timestamp, TurnDirection, TurnType, U3,
    UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};

use crate::link::endpoint::{Endpoint, EndpointConfig};
use crate::transfer::areas::AreaBuffer;
use crate::transfer::mission::MissionBuffer;
use crate::transfer::plan::MissionPlan;

// ---- Time and configuration ----

/// 2026-11-21T12:00:00Z in milliseconds since 2000-01-01: the UTC time of instant zero in every
/// test and bench.
pub const UTC_AT_ZERO_MS: u64 = 848_577_600_000;

/// The time stamp `ms` milliseconds after 2000-01-01 (ICD §3, U5).
pub fn ts(ms: u64) -> Timestamp {
    Timestamp::from_millis(ms).expect("a time stamp fits a U5")
}

/// The UTC time of instant zero, [`UTC_AT_ZERO_MS`].
pub fn utc_at_zero() -> Timestamp {
    ts(UTC_AT_ZERO_MS)
}

/// An endpoint from `local_id` to `peer_id`: instant zero at [`UTC_AT_ZERO_MS`], sampling over
/// the transfer timeout of ICD §1.
pub fn endpoint(local_id: u32, peer_id: u32) -> EndpointConfig {
    EndpointConfig {
        local_id,
        peer_id,
        utc_at_zero: utc_at_zero(),
    }
}

/// Checks that `T::ALL` lists every timer at its own index, so that no two timers share a slot
/// of a [`crate::link::timer::TimerTable`]; each crate's tests run it on its timer enums.
pub fn check_timer_slots<T: crate::link::timer::Timer<N>, const N: usize>() {
    for (i, timer) in T::ALL.into_iter().enumerate() {
        assert_eq!(timer.index(), i, "{timer:?}");
    }
}

// ---- Messages ----

fn angle(degrees: f64) -> Angle {
    Angle::from_degrees(degrees).expect("an angle in range")
}

fn point(at: (f64, f64)) -> GeoPoint {
    GeoPoint::from_degrees(at.0, at.1).expect("a position in range")
}

fn altitude(metres: f64) -> Altitude {
    Altitude::from_metres(metres).expect("an altitude in range")
}

/// #13002 waypoint `number` at `at` (latitude, longitude in degrees), followed by `next` (0 =
/// last), ending a leg of type `leg`: 120 m WGS-84, 25 m/s indicated airspeed, fly-by, time
/// stamp 0; a radius-to-fix waypoint announces its #13006 centre (Optional Messages bit 0).
/// Change any other field with struct update syntax: `UaPositionWaypoint { time_stamp: ..,
/// ..waypoint(..) }`.
pub fn waypoint(number: u16, next: u16, at: (f64, f64), leg: LegType) -> UaPositionWaypoint {
    UaPositionWaypoint {
        time_stamp: Timestamp::default(),
        waypoint_number: number,
        latitude: angle(at.0),
        longitude: angle(at.1),
        location_type: None,
        altitude: altitude(120.0),
        altitude_type: Some(AltitudeType::Wgs84),
        altitude_change_behaviour: None,
        speed: Speed::from_mps(25.0).expect("a speed in range"),
        speed_type: Some(SpeedType::IndicatedAirspeed),
        next_waypoint: next,
        turn_type: TurnType::FlyBy,
        optional_messages: (leg == LegType::RadiusToFix).then_some(1),
        leg_type: leg,
        limit_type: None,
        loop_limit: None,
        arrival_time: None,
        activity_id: None,
    }
}

/// #13002 with all 18 fields present (waypoint 2 at CCP, radius-to-fix, next 3), stamped at
/// instant zero: what the wire benches encode and decode.
pub fn full_waypoint() -> UaPositionWaypoint {
    UaPositionWaypoint {
        time_stamp: utc_at_zero(),
        location_type: Some(LocationType::Absolute),
        altitude_change_behaviour: Some(0),
        limit_type: Some(0),
        loop_limit: Some(0),
        arrival_time: Some(ts(UTC_AT_ZERO_MS + 100_000)),
        activity_id: U3::new(7),
        ..waypoint(2, 3, CCP, LegType::RadiusToFix)
    }
}

/// #13006 type 1: the take-off height in metres.
pub fn take_off(height_m: f64) -> VehicleSpecificWaypoint {
    VehicleSpecificWaypoint {
        time_stamp: Timestamp::default(),
        data: SpecificData::TakeOffHeight {
            height: altitude(height_m),
        },
        activity_id: None,
    }
}

/// #13006 type 2: the centre `at` of the radius-to-fix leg ending at waypoint `number`.
pub fn rf_centre(number: u16, at: (f64, f64), direction: TurnDirection) -> VehicleSpecificWaypoint {
    VehicleSpecificWaypoint {
        time_stamp: Timestamp::default(),
        data: SpecificData::RfCentre {
            waypoint_number: number,
            latitude: angle(at.0),
            longitude: angle(at.1),
            turn_direction: direction,
        },
        activity_id: None,
    }
}

/// #13001: a flight route starting at `initial`.
pub fn route(initial: u16, bidirectional: bool) -> UaRoute {
    UaRoute {
        time_stamp: Timestamp::default(),
        initial_waypoint: initial,
        route_id: None,
        route_type: Some(RouteType::Flight),
        bidirectional,
        planning_wind: None,
    }
}

// ---- Areas ----

/// CCP, the casualty collection point: waypoint 1 of the demo missions, and where mission 2
/// takes off.
pub const CCP: (f64, f64) = (48.275, 11.645);

/// TROL, the trailer where mission 1 takes off (the guidance stub's start position).
pub const TROL: (f64, f64) = (48.26, 11.66);

/// The demo fly-zone rectangle: 48.255..48.285 N, 11.635..11.690 E.
pub const FLY_ZONE: [(f64, f64); 4] = [
    (48.255, 11.635),
    (48.255, 11.690),
    (48.285, 11.690),
    (48.285, 11.635),
];

/// The polygonal no-fly-zone of demo mission 2, inside [`FLY_ZONE`].
pub const NFZ_POLYGON: [(f64, f64); 4] = [
    (48.262, 11.640),
    (48.262, 11.646),
    (48.266, 11.646),
    (48.266, 11.640),
];

/// #2012: a polygon of `corners` (latitude, longitude in degrees), no altitudes.
pub fn polygon(id: u16, area_type: AreaType, corners: &[(f64, f64)]) -> AreaPolygonLoopSegment {
    let mut vertices = PolygonVertices::new();
    for &corner in corners {
        vertices
            .push(point(corner))
            .expect("at most MAX_POLYGON_VERTICES corners");
    }
    AreaPolygonLoopSegment {
        time_stamp: Timestamp::default(),
        area_id: id,
        area_type,
        lower_altitude: None,
        upper_altitude: None,
        altitude_type: None,
        shape: AreaShape::Polygon(vertices),
    }
}

/// #2012: a circular no-fly-zone around `centre` through `border`.
pub fn circle(id: u16, centre: (f64, f64), border: (f64, f64)) -> AreaPolygonLoopSegment {
    AreaPolygonLoopSegment {
        time_stamp: Timestamp::default(),
        area_id: id,
        area_type: AreaType::NoFlyZone,
        lower_altitude: None,
        upper_altitude: None,
        altitude_type: None,
        shape: AreaShape::Circle {
            centre: point(centre),
            border: point(border),
        },
    }
}

/// #2012: a closed curve of [`MAX_POLYGON_VERTICES`] vertices around `centre`, semi-axes
/// `axes` in degrees of latitude and longitude (the largest #2012 of an upload).
pub fn ellipse(
    id: u16,
    area_type: AreaType,
    centre: (f64, f64),
    axes: (f64, f64),
) -> AreaPolygonLoopSegment {
    let corners: Vec<(f64, f64)> = (0..MAX_POLYGON_VERTICES)
        .map(|i| {
            let a = i as f64 / MAX_POLYGON_VERTICES as f64 * core::f64::consts::TAU;
            (centre.0 + axes.0 * a.sin(), centre.1 + axes.1 * a.cos())
        })
        .collect();
    polygon(id, area_type, &corners)
}

/// A fly-zone #2012 of 60 vertices with every optional field present (0 to 300 m WGS-84),
/// stamped at instant zero: what the wire benches encode and decode.
pub fn full_polygon() -> AreaPolygonLoopSegment {
    AreaPolygonLoopSegment {
        time_stamp: utc_at_zero(),
        lower_altitude: Some(altitude(0.0)),
        upper_altitude: Some(altitude(300.0)),
        altitude_type: Some(AltitudeType::Wgs84),
        ..ellipse(1, AreaType::FlyZone, (48.27, 11.66), (0.01, 0.015))
    }
}

/// The largest area list: a 60-vertex elliptic fly-zone inside the demo rectangle (area 1) and
/// ten 60-vertex no-fly-zone circles of about 130 m radius inside it (areas 2 to 11).
pub fn eleven_areas() -> Vec<AreaPolygonLoopSegment> {
    const CENTRE: (f64, f64) = (48.270, 11.6625);
    let lon_scale = 1.0 / CENTRE.0.to_radians().cos();
    let mut areas = vec![ellipse(1, AreaType::FlyZone, CENTRE, (0.0145, 0.027))];
    areas.extend((0..10u16).map(|k| {
        let centre = (
            48.266 + 0.008 * f64::from(k / 5),
            11.648 + 0.0075 * f64::from(k % 5),
        );
        ellipse(
            k + 2,
            AreaType::NoFlyZone,
            centre,
            (0.0012, 0.0012 * lon_scale),
        )
    }));
    areas
}

// ---- Missions and plans ----

/// A waypoint buffer holding `messages`, stored in the order given.
pub fn mission_buffer(messages: &[Message]) -> MissionBuffer {
    let mut buffer = MissionBuffer::new();
    for m in messages {
        buffer.store(m).expect("a mission message the buffer holds");
    }
    buffer
}

/// An area buffer holding `areas`, stored in the order given.
pub fn area_buffer(areas: &[AreaPolygonLoopSegment]) -> AreaBuffer {
    let mut buffer = AreaBuffer::new();
    for a in areas {
        buffer.store(a).expect("an area the buffer holds");
    }
    buffer
}

/// A plan of `messages` and `areas`, safety offset 25 m, named `mission_id`.
pub fn plan(
    messages: &[Message],
    areas: &[AreaPolygonLoopSegment],
    mission_id: &str,
) -> MissionPlan {
    MissionPlan {
        mission: mission_buffer(messages),
        areas: area_buffer(areas),
        safety_offset: SafetyOffset::from_metres(25.0).expect("an offset in range"),
        mission_id: Some(Text::new(mission_id).expect("a mission ID of at most 20 bytes")),
        take_off_position: None,
    }
}

/// Demo mission 1 (`missions/mission-1.toml`): TROL to CCP, one waypoint (CCP), take-off 30 m,
/// its fly-zone.
pub fn mission_1() -> MissionPlan {
    let plan = plan(
        &[
            take_off(30.0).into(),
            waypoint(1, 0, CCP, LegType::TrackToFix).into(),
            route(1, false).into(),
        ],
        &[polygon(1, AreaType::FlyZone, &FLY_ZONE)],
        "MEDEVAC-1",
    );
    MissionPlan {
        take_off_position: Some(point(TROL)),
        ..plan
    }
}

/// Demo mission 2 (`missions/mission-2.toml`), the richer variant: CCP -> W1 (track-to-fix) ->
/// ROLE2 (radius-to-fix, clockwise), bidirectional, the fly-zone, a circular and a polygonal
/// no-fly-zone.
pub fn mission_2() -> MissionPlan {
    let plan = plan(
        &[
            take_off(30.0).into(),
            waypoint(3, 0, (48.280, 11.680), LegType::RadiusToFix).into(),
            rf_centre(3, (48.27455, 11.66991), TurnDirection::Clockwise).into(),
            waypoint(1, 2, CCP, LegType::TrackToFix).into(),
            waypoint(2, 3, (48.278, 11.658), LegType::TrackToFix).into(),
            route(1, true).into(),
        ],
        &[
            polygon(1, AreaType::FlyZone, &FLY_ZONE),
            circle(2, (48.268, 11.675), (48.268, 11.679)),
            polygon(3, AreaType::NoFlyZone, &NFZ_POLYGON),
        ],
        "MEDEVAC-2",
    );
    MissionPlan {
        take_off_position: Some(point(CCP)),
        ..plan
    }
}

/// The messages of an `n`-waypoint mission (1 <= n <= 65534): take-off 30 m, waypoints 1 -> 2
/// -> ... -> n zig-zagging west to east inside the demo fly-zone (track-to-fix), a one-way
/// route from 1.
pub fn zigzag(n: u16) -> Vec<Message> {
    let mut messages = vec![take_off(30.0).into()];
    messages.extend((0..n).map(|i| {
        let lat = if i % 2 == 0 { 48.262 } else { 48.278 };
        let lon = 11.645 + 0.035 * f64::from(i) / f64::from(n.saturating_sub(1).max(1));
        let next = if i + 1 == n { 0 } else { i + 2 };
        Message::from(waypoint(i + 1, next, (lat, lon), LegType::TrackToFix))
    }));
    messages.push(route(1, false).into());
    messages
}

/// [`zigzag`] with [`eleven_areas`], named `GENERATED-<n>`.
pub fn generated_plan(n: u16) -> MissionPlan {
    let plan = plan(&zigzag(n), &eleven_areas(), &format!("GENERATED-{n}"));
    MissionPlan {
        take_off_position: Some(point(TROL)),
        ..plan
    }
}

// ---- Frames and randomness ----

/// `message` encoded in a frame of `envelope`.
pub fn frame(envelope: &Envelope, message: &Message) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(envelope, message, &mut buf).expect("a message that encodes");
    buf.get(..len)
        .expect("encode returns a length within the buffer")
        .to_vec()
}

/// Message Properties (ICD §2): bit 15 acknowledgement requested, bits 14..8 the IDD version,
/// bits 7..6 the checksum code (00 none, 01 two bytes, 10 four bytes).
pub const fn properties(ack: bool, idd_version: u16, checksum_code: u16) -> u16 {
    ((ack as u16) << 15) | (idd_version << 8) | (checksum_code << 6)
}

/// A frame built byte by byte from the tables of ICD §2, never by the encoder: every wrapper
/// field is what the test sets, so a test can break any rule, and the bytes pin the layout. The
/// one hand-made frame of the tests, the benches and the fuzz inputs ([`frame`] is the
/// encoder's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RawFrame {
    /// The Reserved field (ICD §2: 0xFFFF).
    pub reserved: u16,
    /// Message Length; `None`: the length of the data.
    pub length: Option<u16>,
    /// Source ID.
    pub source: u32,
    /// Destination ID.
    pub destination: u32,
    /// Message Type.
    pub message_type: u16,
    /// Message Properties ([`properties`]).
    pub properties: u16,
    /// Checksum bytes appended (0, 2 or 4), whatever the properties say: the byte sum of
    /// everything before, cut to its low bytes.
    pub checksum_len: usize,
}

impl RawFrame {
    /// A frame from the GCS to the FCC (ICD §1 defaults) as this project sends it: IDD 40, a
    /// 4-byte checksum, no acknowledgement requested.
    pub const fn uplink(message_type: u16) -> Self {
        Self {
            reserved: 0xFFFF,
            length: None,
            source: defaults::GCS_ID,
            destination: defaults::FCC_ID,
            message_type,
            properties: properties(false, 40, 0b10),
            checksum_len: 4,
        }
    }

    /// The same with the acknowledgement requested (bit 15).
    pub const fn with_ack(self) -> Self {
        Self {
            properties: self.properties | 0x8000,
            ..self
        }
    }

    /// The 16-byte header for `data_len` bytes of data.
    pub fn header(&self, data_len: usize) -> Vec<u8> {
        let length = self
            .length
            .unwrap_or_else(|| u16::try_from(data_len).expect("data of a frame's length"));
        let mut h = Vec::with_capacity(16);
        h.extend_from_slice(&self.reserved.to_be_bytes());
        h.extend_from_slice(&length.to_be_bytes());
        h.extend_from_slice(&self.source.to_be_bytes());
        h.extend_from_slice(&self.destination.to_be_bytes());
        h.extend_from_slice(&self.message_type.to_be_bytes());
        h.extend_from_slice(&self.properties.to_be_bytes());
        h
    }

    /// Header, `data` and checksum.
    pub fn build(&self, data: &[u8]) -> Vec<u8> {
        let mut f = self.header(data.len());
        f.extend_from_slice(data);
        append_checksum(&mut f, self.checksum_len);
        f
    }
}

/// Appends the byte-sum checksum of ICD §2 (every byte added, unsigned, not truncated) of
/// everything in `frame`, its low `len` bytes big-endian (0, 2 or 4).
pub fn append_checksum(frame: &mut Vec<u8>, len: usize) {
    let sum: u32 = frame.iter().map(|b| u32::from(*b)).sum();
    let bytes = sum.to_be_bytes();
    frame.extend_from_slice(bytes.get(4 - len.min(4)..).unwrap_or_default());
}

/// `message` as the GCS sends it to the FCC, acknowledgement requested.
pub fn uplink(message: &Message) -> Vec<u8> {
    frame(
        &Envelope::new(defaults::GCS_ID, defaults::FCC_ID).with_ack(true),
        message,
    )
}

/// Whatever has frames to send through `poll_transmit`: the two machines and a bare endpoint.
/// Tests and benches take frames as a driver does (docs/design.md "Examples followed", after quinn-proto's
/// `tests/util.rs`): encoded by the machine into a buffer, the bytes moved, never re-encoded.
pub trait Transmit {
    /// The machine's own `poll_transmit`: the next frame into `buf`, its length.
    fn transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>>;

    /// Every frame ready to send, in order.
    fn frames(&mut self) -> Vec<Vec<u8>> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        std::iter::from_fn(|| {
            let len = self
                .transmit(&mut buf)?
                .expect("an outgoing message that encodes");
            Some(
                buf.get(..len)
                    .expect("poll_transmit returns a length within the buffer")
                    .to_vec(),
            )
        })
        .collect()
    }

    /// The messages of every frame ready to send, in order (for checks on what was sent).
    fn messages(&mut self) -> Vec<Message> {
        self.frames().iter().map(|f| decoded(f).1).collect()
    }
}

impl Transmit for Endpoint {
    fn transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        self.poll_transmit(buf)
    }
}

/// The envelope and the message of a frame a machine sent.
pub fn decoded(frame: &[u8]) -> (Envelope, Message) {
    wire::decode(frame).expect("a frame the machine encoded decodes")
}

// ---- The onboard geofence check's worst case (ICD §7; BENCHMARKS.md section 4) ----

/// Where the worst case lies: its local east/north metres are measured from here.
const WORST_CASE_ORIGIN: (f64, f64) = (48.27, 11.66);
/// Semi-axes of the worst case's no-fly-zone ellipses, metres: east-west, north-south.
const WORST_CASE_NFZ_AXES_M: (f64, f64) = (400.0, 6000.0);
/// Width of a corridor between two neighbouring zones (the fly-zone's west or east side and a
/// no-fly-zone, or two no-fly-zones), metres.
const WORST_CASE_CORRIDOR_M: f64 = 340.0;
/// Half the length of a lane, metres: lanes end 200 m beyond the no-fly-zones' tips, where the
/// legs between lanes pass them.
const WORST_CASE_LANE_HALF_M: f64 = 6200.0;
/// How far the fly-zone reaches past the lanes' ends, metres: south, and north (where the
/// radius-to-fix legs of [`geofence_worst_case_rf`] bulge 570 m past the lanes' ends).
const WORST_CASE_FLY_ZONE_BEYOND_M: (f64, f64) = (120.0, 690.0);

/// The speed of the worst case's waypoints, m/s (the slowest of the default profile).
pub const WORST_CASE_SPEED_MPS: f64 = 5.0;

/// The closest approach of the worst case's route to each of its 11 zones, metres: 15 m beyond
/// the safety offset of 25 m.
pub const WORST_CASE_CLOSEST_M: f64 = 40.0;
/// The farthest a lane of the worst case runs from the zones on either side, metres.
pub const WORST_CASE_FARTHEST_M: f64 = WORST_CASE_CORRIDOR_M - WORST_CASE_CLOSEST_M;

/// The position `east`, `north` metres from [`WORST_CASE_ORIGIN`] (azimuthal equidistant:
/// along the geodesic in that direction for that distance), latitude and longitude in degrees.
pub fn worst_case_local(east: f64, north: f64) -> (f64, f64) {
    let p = crate::geofence::earth::destination(
        point(WORST_CASE_ORIGIN),
        east.atan2(north).to_degrees(),
        east.hypot(north),
    );
    (p.y(), p.x())
}

/// East coordinate of no-fly-zone `k` (0..10)'s centre, metres: ten of them side by side,
/// centred on the origin.
fn worst_case_nfz_east(k: usize) -> f64 {
    let spacing = 2.0 * WORST_CASE_NFZ_AXES_M.0 + WORST_CASE_CORRIDOR_M;
    (k as f64 - 4.5) * spacing
}

/// East coordinate of corridor `c` (0..=10)'s west side, metres: corridor 0 lies between the
/// fly-zone's west side and no-fly-zone 0, corridor `c` between no-fly-zones `c - 1` and `c`,
/// corridor 10 between no-fly-zone 9 and the fly-zone's east side.
fn worst_case_corridor_west(c: usize) -> f64 {
    let spacing = 2.0 * WORST_CASE_NFZ_AXES_M.0 + WORST_CASE_CORRIDOR_M;
    worst_case_nfz_east(0) - WORST_CASE_NFZ_AXES_M.0 - WORST_CASE_CORRIDOR_M + c as f64 * spacing
}

/// The worst case's areas (ICD §7's largest list, every zone close to the route): the fly-zone
/// (area 1), a rectangle of about 11.7 km by 13.2 km with rounded corners (15 vertices per
/// corner, 60 in all), and ten no-fly-zone ellipses of 0.8 km by 12 km, 60 vertices each
/// (areas 2 to 11), side by side in it with corridors of 340 m between them and along the
/// fly-zone's west and east sides. `shift_m` moves no-fly-zone `k` east (negative: west) by
/// its value (to make a fixture that fails).
pub fn worst_case_areas(shift_m: [f64; 10]) -> Vec<AreaPolygonLoopSegment> {
    let west = worst_case_corridor_west(0);
    let east = worst_case_corridor_west(10) + WORST_CASE_CORRIDOR_M;
    let south = -WORST_CASE_LANE_HALF_M - WORST_CASE_FLY_ZONE_BEYOND_M.0;
    let north = WORST_CASE_LANE_HALF_M + WORST_CASE_FLY_ZONE_BEYOND_M.1;
    const CORNER_M: f64 = 100.0;
    const PER_CORNER: usize = MAX_POLYGON_VERTICES / 4;
    // Counter-clockwise from the south-east corner: each corner's centre and start angle.
    let corners = [
        (east - CORNER_M, south + CORNER_M, -90.0f64),
        (east - CORNER_M, north - CORNER_M, 0.0),
        (west + CORNER_M, north - CORNER_M, 90.0),
        (west + CORNER_M, south + CORNER_M, 180.0),
    ];
    let fly_zone: Vec<(f64, f64)> = corners
        .iter()
        .flat_map(|&(x, y, start)| {
            (0..PER_CORNER).map(move |i| {
                let a = (start + 90.0 * i as f64 / (PER_CORNER - 1) as f64).to_radians();
                worst_case_local(x + CORNER_M * a.cos(), y + CORNER_M * a.sin())
            })
        })
        .collect();
    let mut areas = vec![polygon(1, AreaType::FlyZone, &fly_zone)];
    areas.extend(shift_m.iter().enumerate().map(|(k, shift)| {
        let (ax, ay) = WORST_CASE_NFZ_AXES_M;
        let x = worst_case_nfz_east(k) + shift;
        // Vertex 0 and 30 at the ends of the east-west axis: the closest approach to the lanes
        // is exactly there.
        let vertices: Vec<(f64, f64)> = (0..MAX_POLYGON_VERTICES)
            .map(|i| {
                let t = core::f64::consts::TAU * i as f64 / MAX_POLYGON_VERTICES as f64;
                worst_case_local(x + ax * t.cos(), ay * t.sin())
            })
            .collect();
        polygon(k as u16 + 2, AreaType::NoFlyZone, &vertices)
    }));
    areas
}

/// The messages of the worst case's route: take-off 30 m, waypoints 1 -> 2 -> ... -> 256 (one
/// way, from 1), a survey flown over and over through the 11 corridors of
/// [`worst_case_areas`]. Each lane is one track-to-fix leg of 12.4 km up or down a corridor
/// (two waypoints); a pass flies all 11 corridors, west to east and then back, each pass at
/// another distance from the corridor's west side, from 40 m to 300 m in 12 steps (so its
/// east side sees 300 m to 40 m); 128 lanes in all. With `rf`, the legs between lanes at the
/// north end are radius-to-fix half circles of 570 m bulging north around the no-fly-zone's
/// tip (every fourth leg but at the turn between passes), the rest track-to-fix. Every waypoint
/// is fly-by at [`WORST_CASE_SPEED_MPS`]: the turns (`geofence::turn`) are arcs of 5.5 m radius
/// at 25° bank inside the corners, short enough for the 24 m legs between passes, so they come
/// no closer to any zone than the legs and the check looks at every one of them too.
pub fn worst_case_messages(rf: bool) -> Vec<Message> {
    use missionlink_interfaces::capacity::MAX_WAYPOINTS;
    const PASSES: usize = 12;
    let lanes = MAX_WAYPOINTS / 2;
    let mut sequence: Vec<(usize, f64)> = Vec::new();
    'passes: for pass in 0..PASSES {
        let offset = WORST_CASE_CLOSEST_M
            + (WORST_CASE_FARTHEST_M - WORST_CASE_CLOSEST_M) * pass as f64 / (PASSES - 1) as f64;
        for i in 0..=10 {
            if sequence.len() == lanes {
                break 'passes;
            }
            let corridor = if pass % 2 == 0 { i } else { 10 - i };
            sequence.push((corridor, worst_case_corridor_west(corridor) + offset));
        }
    }
    let mut messages = vec![take_off(30.0).into()];
    let mut previous: Option<(f64, f64)> = None;
    for (lane, &(_, east)) in sequence.iter().enumerate() {
        // Lane 0 flies north; lanes alternate.
        let north = if lane % 2 == 0 { 1.0 } else { -1.0 } * WORST_CASE_LANE_HALF_M;
        for (j, y) in [-north, north].into_iter().enumerate() {
            let number = (2 * lane + j + 1) as u16;
            let next = if usize::from(number) == MAX_WAYPOINTS {
                0
            } else {
                number + 1
            };
            let at = worst_case_local(east, y);
            // The leg into a lane's first waypoint at the north end, from another corridor.
            let arc = match previous {
                Some((x0, y0)) if rf && j == 0 && y > 0.0 && (x0 - east).abs() > 500.0 => {
                    let centre = worst_case_local((x0 + east) / 2.0, y0);
                    let direction = if east > x0 {
                        TurnDirection::Clockwise
                    } else {
                        TurnDirection::CounterClockwise
                    };
                    Some(rf_centre(number, centre, direction))
                }
                _ => None,
            };
            let leg = if arc.is_some() {
                LegType::RadiusToFix
            } else {
                LegType::TrackToFix
            };
            let waypoint = UaPositionWaypoint {
                speed: Speed::from_mps(WORST_CASE_SPEED_MPS).expect("a speed in range"),
                ..waypoint(number, next, at, leg)
            };
            messages.push(waypoint.into());
            messages.extend(arc.map(Message::from));
            previous = Some((east, y));
        }
    }
    messages.push(route(1, false).into());
    messages
}

/// The take-off position of the worst case: 60 m south and 80 m east of waypoint 1, clear of the
/// fly-zone's rounded corner.
pub fn worst_case_take_off() -> GeoPoint {
    point(worst_case_local(
        worst_case_corridor_west(0) + WORST_CASE_CLOSEST_M + 80.0,
        -WORST_CASE_LANE_HALF_M - 60.0,
    ))
}

/// `messages` and `areas` as mission data handling publishes them to guidance (assembled and
/// checked as an upload is: ICD §7), safety offset 25 m, generation 1.
pub fn published_lists(
    messages: &[Message],
    areas: &[AreaPolygonLoopSegment],
) -> (
    missionlink_interfaces::contracts::WaypointListPayload,
    missionlink_interfaces::contracts::AreaListPayload,
) {
    let waypoints = mission_buffer(messages)
        .assemble(None, None)
        .expect("a mission that assembles")
        .to_payload(1);
    let areas = area_buffer(areas)
        .assemble(
            areas.len() as u8,
            SafetyOffset::from_metres(25.0).expect("an offset in range"),
        )
        .expect("an area list that assembles")
        .to_payload(1);
    (waypoints, areas)
}

/// The worst case of the onboard geofence check (ICD §7; BENCHMARKS.md section 4): 256 waypoints
/// (255 track-to-fix legs: 128 lanes of 12.4 km, 116 of 1.1 km between corridors, 11 of 24 m
/// between passes; plus the climb and the way from the take-off
/// point) against 11 areas of 60 vertices, every zone within 40 m (the closest) to 300 m of
/// the legs beside it, and the check passes, so it looks at every leg and zone (a failing
/// check stops at its first violation). Every lane's ball holds most of every zone, so few
/// border pieces are culled. The waypoint list, the area list and the take-off position.
pub fn geofence_worst_case() -> (
    missionlink_interfaces::contracts::WaypointListPayload,
    missionlink_interfaces::contracts::AreaListPayload,
    GeoPoint,
) {
    let (waypoints, areas) =
        published_lists(&worst_case_messages(false), &worst_case_areas([0.0; 10]));
    (waypoints, areas, worst_case_take_off())
}

/// A 90° fly-by turn whose arc comes too close to a no-fly-zone (found in review): waypoints 1 (1500 m south of
/// C = 48.27 N, 11.65 E), 2 (C) and 3 (1500 m east of C), fly-by, 25 m/s; in the corner a
/// square no-fly-zone (area 4, 300 m a side) whose corner nearest C is 60 m from it, 42 m from
/// both legs; the demo fly-zone; safety offset 25 m; the take-off 1600 m south of C (no turn at
/// waypoint 1). The legs are clear; the fly-by arc of radius 136.7 m tangent to them passes
/// 3.4 m from the square's corner, well inside the safety offset. The plan, the take-off position.
pub fn fly_by_corner() -> MissionPlan {
    let c = point((48.27, 11.65));
    let at = |from: GeoPoint, bearing: f64, d: f64| {
        let p = crate::geofence::earth::destination(from, bearing, d);
        (p.y(), p.x())
    };
    let near = point(at(c, 135.0, 60.0));
    let east = point(at(near, 90.0, 300.0));
    let square = [
        at(near, 0.0, 0.0),
        at(east, 0.0, 0.0),
        at(east, 180.0, 300.0),
        at(near, 180.0, 300.0),
    ];
    let plan = plan(
        &[
            take_off(30.0).into(),
            waypoint(1, 2, at(c, 180.0, 1500.0), LegType::TrackToFix).into(),
            waypoint(2, 3, (48.27, 11.65), LegType::TrackToFix).into(),
            waypoint(3, 0, at(c, 90.0, 1500.0), LegType::TrackToFix).into(),
            route(1, false).into(),
        ],
        &[
            polygon(1, AreaType::FlyZone, &FLY_ZONE),
            polygon(4, AreaType::NoFlyZone, &square),
        ],
        "FLY-BY-CORNER",
    );
    MissionPlan {
        take_off_position: Some(point(at(c, 180.0, 1600.0))),
        ..plan
    }
}

/// [`geofence_worst_case`] as the GCS holds it: the plan the safety gateway validates before
/// an upload (take-off at [`worst_case_take_off`]).
pub fn geofence_worst_case_plan() -> MissionPlan {
    let plan = plan(
        &worst_case_messages(false),
        &worst_case_areas([0.0; 10]),
        "WORST-CASE",
    );
    MissionPlan {
        take_off_position: Some(worst_case_take_off()),
        ..plan
    }
}

/// [`geofence_worst_case`] with the legs between lanes at the north end flown as radius-to-fix
/// half circles (see [`worst_case_messages`]).
pub fn geofence_worst_case_rf() -> (
    missionlink_interfaces::contracts::WaypointListPayload,
    missionlink_interfaces::contracts::AreaListPayload,
    GeoPoint,
) {
    let (waypoints, areas) =
        published_lists(&worst_case_messages(true), &worst_case_areas([0.0; 10]));
    (waypoints, areas, worst_case_take_off())
}

// ---- Geometry ----

/// Distance from `at` to `path`, metres: to the point of the path at the foot of `at` (the
/// along-track position measured from the path's start, or the azimuth from an arc's centre),
/// clamped to the path; an upper bound on the distance that is exact to second order in the
/// (small) distance. What the tests of guidance measure flown positions against.
pub fn distance_to_path(
    path: &crate::geofence::path::Path,
    at: crate::geofence::earth::Site,
) -> f64 {
    match *path {
        crate::geofence::path::Path::Point(p) => p.inverse(&at).0,
        crate::geofence::path::Path::Geodesic { from, to } => {
            let (length, course) = from.inverse(&to);
            let (d, az) = from.inverse(&at);
            let along = (d * (az - course).to_radians().cos()).clamp(0.0, length);
            at.inverse(&from.direct(course, along)).0
        }
        crate::geofence::path::Path::Arc(crate::geofence::path::ArcLeg {
            from,
            to,
            centre,
            direction,
        }) => {
            let arc = crate::geofence::turn::ArcGeometry::of(&from, &to, &centre, direction);
            let az = centre.inverse(&at).1;
            let ends = at.inverse(&from).0.min(at.inverse(&to).0);
            if crate::geofence::turn::angle_to_go(arc.az0, az, arc.clockwise) <= arc.sweep {
                at.inverse(&arc.at(az)).0.min(ends)
            } else {
                ends
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_missions_assemble_as_their_files_say() {
        let m1 = mission_1();
        let m = m1.mission.assemble(Some(1), None).unwrap();
        assert_eq!(m.waypoints.len(), 1);
        assert_eq!(m.take_off_height().metres(), 30.0);
        let m2 = mission_2();
        let m = m2.mission.assemble(Some(3), None).unwrap();
        let numbers: Vec<u16> = m
            .waypoints
            .iter()
            .map(|r| r.waypoint.waypoint_number)
            .collect();
        assert_eq!(numbers, [1, 2, 3]);
        assert!(m.waypoints[2].rf_centre.is_some());
        let areas = m2.areas.assemble(3, m2.safety_offset).unwrap();
        assert_eq!(areas.areas.len(), 3);
    }

    #[test]
    fn generated_plans_have_n_waypoints_and_eleven_areas_of_60_vertices() {
        for n in [1u16, 2, 256] {
            let p = generated_plan(n);
            let m = p.mission.assemble(Some(n), None).unwrap();
            assert_eq!(m.waypoints.len(), usize::from(n));
            let list = p.areas.assemble(11, p.safety_offset).unwrap();
            assert_eq!(list.to_payload(1).no_fly_polygon_count, 10);
            for a in &list.areas {
                let AreaShape::Polygon(v) = &a.shape else {
                    panic!("area {} is not a polygon", a.area_id)
                };
                assert_eq!(v.len(), MAX_POLYGON_VERTICES);
            }
        }
    }

    #[test]
    fn full_messages_carry_every_field_through_the_wire() {
        let w: Message = full_waypoint().into();
        let p: Message = full_polygon().into();
        for m in [w, p] {
            let (envelope, decoded) = wire::decode(&uplink(&m)).unwrap();
            assert!(envelope.ack_requested);
            assert_eq!(decoded, m);
        }
        assert!(full_waypoint().arrival_time.is_some());
    }
}
