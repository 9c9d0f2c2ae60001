//! The iceoryx2 contracts between the FCC partitions (docs/design.md, "Contracts between
//! partitions"): the payload types, their services and QoS, and the service names.
//!
//! Every payload is `#[repr(C)]`, fixed size and iceoryx2's `ZeroCopySend` (with the feature
//! `ipc`, which the processes that publish or subscribe enable; the ground segment reads the
//! same types without linking iceoryx2), defined here once: iceoryx2 matches services by type
//! name, so a type defined twice would not connect. Each type name
//! carries [`CONTRACT_VERSION`], so partitions built against different layouts refuse to connect
//! instead of misreading each other.
//!
//! Enumerations cross shared memory as raw `u8` with typed accessors: the bytes are written by
//! another process, and an out-of-range discriminant must read as "unknown", never as undefined
//! behaviour. Optional values carry a `has_*` flag next to them for the same reason.
//!
//! No payload has padding: the bytes that alignment would add are fields of their own, named
//! `reserved*`, documented "Zero." and written as zero by every constructor and constant. Every
//! payload derives zerocopy's `IntoBytes`, which does not compile for a type with padding, so
//! every byte of a payload is a written byte: the bridge sends the bytes as they are across
//! hosts (docs/design.md "Across hosts", ICD §14) and never an uninitialised one, and a reader
//! may compare payloads by their bytes ([`GuidanceProgressPayload::same_report_as`]).

use core::fmt;

#[cfg(feature = "ipc")]
use iceoryx2::prelude::ZeroCopySend;

use crate::capacity::{MAX_NO_FLY_ZONES, MAX_POLYGON_VERTICES, MAX_WAYPOINTS};
use crate::wire::{
    Altitude, AltitudeType, Angle, GeoPoint, LegType, MAX_FRAME_LEN, SafetyOffset, Speed,
    SpeedType, TurnDirection, TurnType,
};

/// Version of the payload layouts; part of every type name.
pub const CONTRACT_VERSION: u32 = 5;

/// Service-name prefix used when none is configured.
pub const DEFAULT_SERVICE_PREFIX: &str = "missionlink";

/// Marks an optional enumeration byte as absent.
pub const ABSENT: u8 = 0xff;

fn enum_or_none<T: TryFrom<u8>>(raw: u8) -> Option<T> {
    T::try_from(raw).ok()
}

fn enum_to_raw<T: Into<u8>>(v: Option<T>) -> u8 {
    v.map_or(ABSENT, Into::into)
}

macro_rules! into_u8 {
    ($($t:ty),+) => {$(
        impl From<$t> for u8 {
            fn from(v: $t) -> u8 {
                v as u8
            }
        }
    )+};
}
into_u8!(AltitudeType, SpeedType, TurnType, LegType, TurnDirection);

/// The services of the FCC, by the path under the prefix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FccService {
    /// `fcc/link/uplink`: voted uplink frames, voting-monitoring to mission-data-handling.
    Uplink,
    /// `fcc/link/downlink`: downlink frames, mission-data-handling to voting-monitoring.
    Downlink,
    /// `fcc/mission/waypoint-list`: the active waypoint list, history 1.
    WaypointList,
    /// `fcc/mission/area-list`: the active area list, history 1.
    AreaList,
    /// `fcc/automation/state`: flight phase and active functions, history 1.
    AutomationState,
    /// `fcc/guidance/progress`: FROM / TO / NEXT and position, history 1.
    GuidanceProgress,
    /// `fcc/automation/command`: #50000 commands accepted by mission data handling, for system
    /// automation to carry out (queue, no history: a restarted automation must not replay an
    /// old command).
    AutomationCommand,
    /// `fcc/health/<partition>`: the partition's heartbeat on its fixed period (docs/design.md
    /// "Health"), history 1; the launcher and system automation watch it.
    Heartbeat(Partition),
}

/// A partition of the FCC: the one name of a partition everywhere (the launcher, the
/// configuration's per-partition sections, the fence, the heartbeat services, and the C and
/// Python contracts, which spell the same names). It has two names, because a role and the
/// process that fills it are not the same thing in the rig (docs/design.md "Contracts between
/// partitions": a partition is replaced by starting another process that opens the same
/// services):
///
/// - [`Partition::role`]: the role, whatever binary or language fills it; the services named
///   after a partition (`fcc/health/<role>`) carry it, so a guidance written in Python beats on
///   `fcc/health/guidance` as the Rust guidance stub does;
/// - [`Partition::binary`]: the Rust process of this workspace that fills the role: its binary,
///   its iceoryx2 node, its readiness announcement, its latency summary, what users type
///   (`fcc --without guidance-stub`) and the key of its configuration sections
///   (`[ipc.idle.guidance-stub]`).
///
/// And [`Partition::allowed`]: what its fence lets it do beyond every partition's loop
/// (docs/design.md "Isolation").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Partition {
    /// Voting and monitoring of the two links.
    VotingMonitoring,
    /// Mission data handling.
    MissionDataHandling,
    /// System automation.
    SystemAutomation,
    /// Flight guidance (the guidance stub, or its replacement in the rig).
    Guidance,
}

/// What a partition's fence allows beyond what every partition's loop needs (docs/design.md
/// "Isolation": only voting-monitoring touches the network; none execs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Allowed {
    /// It owns the UDP links: it may create inet sockets, and its loop waits for its sockets
    /// as well as for its iceoryx2 inputs.
    pub links: bool,
    /// It writes the state directory: mission data handling its lists, voting-monitoring the
    /// ports it bound. Every partition writes its readiness announcement.
    pub state: bool,
}

impl Partition {
    /// Every partition, in start order.
    pub const ALL: [Partition; 4] = [
        Self::VotingMonitoring,
        Self::MissionDataHandling,
        Self::SystemAutomation,
        Self::Guidance,
    ];

    /// Every partition's binary ([`Partition::binary`]), in start order.
    pub const BINARIES: [&'static str; 4] = {
        let [a, b, c, d] = Self::ALL;
        [a.binary(), b.binary(), c.binary(), d.binary()]
    };

    /// The role's name, the last part of the path of the services named after a partition
    /// (`fcc/health/<role>`).
    pub const fn role(self) -> &'static str {
        match self {
            Self::VotingMonitoring => "voting-monitoring",
            Self::MissionDataHandling => "mission-data-handling",
            Self::SystemAutomation => "system-automation",
            Self::Guidance => "guidance",
        }
    }

    /// The name of the Rust binary that fills the role (its node, its readiness, its
    /// configuration sections; what `fcc --without` takes).
    pub const fn binary(self) -> &'static str {
        match self {
            Self::Guidance => "guidance-stub",
            other => other.role(),
        }
    }

    /// The partition whose binary is `name`.
    pub fn from_binary(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.binary() == name)
    }

    /// What its fence allows.
    pub const fn allowed(self) -> Allowed {
        match self {
            Self::VotingMonitoring => Allowed {
                links: true,
                state: true,
            },
            Self::MissionDataHandling => Allowed {
                links: false,
                state: true,
            },
            Self::SystemAutomation | Self::Guidance => Allowed {
                links: false,
                state: false,
            },
        }
    }
}

/// The role's name (as the services named after the partition spell it).
impl fmt::Display for Partition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.role())
    }
}

/// The quality of service of a service: every partition opens it with these, so that whoever
/// creates it creates it the same way. The contracts own the values; the partitions' IPC
/// (`missionlink_partitions::ipc`) is the one place that applies them to iceoryx2's builders,
/// and its tests check what they promise (a late subscriber gets the active list).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Samples a late subscriber receives on connecting.
    pub history_size: usize,
    /// Samples a subscriber buffers before the publisher blocks or drops.
    pub subscriber_max_buffer_size: usize,
    /// Publishers allowed at once (2: a restarted partition may meet its dead predecessor's port
    /// until the dead node is cleaned up).
    pub max_publishers: usize,
    /// Subscribers allowed at once.
    pub max_subscribers: usize,
    /// Overwrite the oldest sample when a subscriber's buffer is full (state services), or make
    /// the publisher fail so nothing is lost silently (frame queues).
    pub safe_overflow: bool,
}

impl Qos {
    /// Listeners the event service of the same name allows: two per subscriber, its own and
    /// the one through which a partition sleeping on its doorbell hears publishers that do not
    /// ring it (`missionlink_partitions::doorbell`, docs/wait-path.md).
    pub const fn max_listeners(self) -> usize {
        2 * self.max_subscribers
    }
}

impl FccService {
    /// Every service.
    pub const ALL: [FccService; 11] = [
        Self::Uplink,
        Self::Downlink,
        Self::WaypointList,
        Self::AreaList,
        Self::AutomationState,
        Self::GuidanceProgress,
        Self::AutomationCommand,
        Self::Heartbeat(Partition::VotingMonitoring),
        Self::Heartbeat(Partition::MissionDataHandling),
        Self::Heartbeat(Partition::SystemAutomation),
        Self::Heartbeat(Partition::Guidance),
    ];

    /// The path under the prefix.
    pub const fn path(self) -> &'static str {
        match self {
            Self::Uplink => "fcc/link/uplink",
            Self::Downlink => "fcc/link/downlink",
            Self::WaypointList => "fcc/mission/waypoint-list",
            Self::AreaList => "fcc/mission/area-list",
            Self::AutomationState => "fcc/automation/state",
            Self::GuidanceProgress => "fcc/guidance/progress",
            Self::AutomationCommand => "fcc/automation/command",
            // `fcc/health/<role>` (`Partition::role`; a test checks the two agree).
            Self::Heartbeat(Partition::VotingMonitoring) => "fcc/health/voting-monitoring",
            Self::Heartbeat(Partition::MissionDataHandling) => "fcc/health/mission-data-handling",
            Self::Heartbeat(Partition::SystemAutomation) => "fcc/health/system-automation",
            Self::Heartbeat(Partition::Guidance) => "fcc/health/guidance",
        }
    }

    /// The full service name, `{prefix}/{path}`. The same name serves the publish-subscribe
    /// service and its event service.
    pub fn name(self, prefix: &str) -> String {
        format!("{}/{}", prefix.trim_end_matches('/'), self.path())
    }

    /// The QoS of the service.
    pub const fn qos(self) -> Qos {
        match self {
            // Frame queues: deep enough for a whole window of data messages in flight and
            // their answers (ICD §10.2: 128 toward this project's FCC), twice over, never
            // overwritten.
            Self::Uplink | Self::Downlink | Self::AutomationCommand => Qos {
                history_size: 0,
                subscriber_max_buffer_size: 256,
                max_publishers: 2,
                max_subscribers: 4,
                safe_overflow: false,
            },
            // State: the latest value is all that matters; late joiners get it.
            Self::WaypointList
            | Self::AreaList
            | Self::AutomationState
            | Self::GuidanceProgress
            | Self::Heartbeat(_) => Qos {
                history_size: 1,
                subscriber_max_buffer_size: 1,
                max_publishers: 2,
                max_subscribers: 8,
                safe_overflow: true,
            },
        }
    }
}

impl fmt::Display for FccService {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.path())
    }
}

/// The link a frame arrived on or leaves by (ICD §1: two independent links).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Link {
    /// The direct radio link.
    Direct = 0,
    /// The LTE link.
    Lte = 1,
    /// Both links (downlink frames are sent on both).
    Both = 2,
}

impl TryFrom<u8> for Link {
    type Error = u8;
    fn try_from(v: u8) -> Result<Self, u8> {
        match v {
            0 => Ok(Self::Direct),
            1 => Ok(Self::Lte),
            2 => Ok(Self::Both),
            other => Err(other),
        }
    }
}

/// A STANAG frame crossing shared memory: opaque bytes plus metadata. The protocol code views
/// the bytes with [`crate::wire::Frame`]; the payload itself never interprets them.
#[derive(
    Debug,
    Clone,
    Copy,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::FramePayload/v5"))]
pub struct FramePayload {
    /// CLOCK_MONOTONIC nanoseconds when the frame entered the FCC (socket receive) or was
    /// produced (downlink): the start of the per-frame latency measurement.
    pub origin_ns: u64,
    /// CLOCK_MONOTONIC nanoseconds when the frame was published on this service.
    pub published_ns: u64,
    /// Counts frames per publisher, from 1; a gap tells a subscriber it missed frames.
    pub sequence: u64,
    /// Bytes used of `bytes`.
    pub len: u16,
    /// [`Link`] as `u8`.
    pub link: u8,
    /// Zero.
    pub reserved: [u8; 5],
    /// The frame: wrapper, data, checksum.
    pub bytes: [u8; MAX_FRAME_LEN],
    /// Zero.
    pub reserved_tail: [u8; 4],
}

impl FramePayload {
    /// A payload holding `frame`, if it fits [`MAX_FRAME_LEN`].
    pub fn new(link: Link, frame: &[u8], origin_ns: u64) -> Option<Self> {
        let mut bytes = [0u8; MAX_FRAME_LEN];
        bytes.get_mut(..frame.len())?.copy_from_slice(frame);
        Some(Self {
            origin_ns,
            published_ns: 0,
            sequence: 0,
            len: frame.len() as u16,
            link: link as u8,
            reserved: [0; 5],
            bytes,
            reserved_tail: [0; 4],
        })
    }

    /// The frame bytes (clamped to the array, whatever `len` holds).
    pub fn frame(&self) -> &[u8] {
        let len = usize::from(self.len).min(MAX_FRAME_LEN);
        self.bytes.get(..len).unwrap_or_default()
    }

    /// The link, or `None` for a value no publisher of this version writes.
    pub fn link(&self) -> Option<Link> {
        Link::try_from(self.link).ok()
    }
}

/// One waypoint of the assembled list, in flight-plan order.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::WaypointEntry/v5"))]
pub struct WaypointEntry {
    /// Waypoint Number.
    pub number: u16,
    /// Next Waypoint; 0 on the last.
    pub next: u16,
    /// Position.
    pub position: GeoPoint,
    /// Waypoint to Altitude.
    pub altitude: Altitude,
    /// Waypoint to Speed.
    pub speed: Speed,
    /// [`AltitudeType`] or [`ABSENT`].
    pub altitude_type: u8,
    /// [`SpeedType`] or [`ABSENT`].
    pub speed_type: u8,
    /// [`TurnType`].
    pub turn_type: u8,
    /// [`LegType`] of the leg that ends here.
    pub leg_type: u8,
    /// [`TurnDirection`] of a radius-to-fix leg, or [`ABSENT`].
    pub rf_turn_direction: u8,
    /// Zero.
    pub reserved: u8,
    /// Centre of a radius-to-fix leg (zero for track-to-fix).
    pub rf_centre: GeoPoint,
}

impl WaypointEntry {
    /// An all-zero entry (unused slots).
    pub const EMPTY: Self = Self {
        number: 0,
        next: 0,
        position: GeoPoint {
            latitude: Angle::from_raw(0),
            longitude: Angle::from_raw(0),
        },
        altitude: Altitude::ZERO,
        speed: Speed::from_raw(0),
        altitude_type: ABSENT,
        speed_type: ABSENT,
        turn_type: 0,
        leg_type: 0,
        rf_turn_direction: ABSENT,
        reserved: 0,
        rf_centre: GeoPoint {
            latitude: Angle::from_raw(0),
            longitude: Angle::from_raw(0),
        },
    };

    /// Altitude Type, if given.
    pub fn altitude_type(&self) -> Option<AltitudeType> {
        enum_or_none(self.altitude_type)
    }

    /// Sets the Altitude Type.
    pub fn set_altitude_type(&mut self, v: Option<AltitudeType>) {
        self.altitude_type = enum_to_raw(v);
    }

    /// Speed Type, if given.
    pub fn speed_type(&self) -> Option<SpeedType> {
        enum_or_none(self.speed_type)
    }

    /// Sets the Speed Type.
    pub fn set_speed_type(&mut self, v: Option<SpeedType>) {
        self.speed_type = enum_to_raw(v);
    }

    /// Turn Type (`None` only for a corrupted byte).
    pub fn turn_type(&self) -> Option<TurnType> {
        enum_or_none(self.turn_type)
    }

    /// Leg type of the leg that ends here (`None` only for a corrupted byte).
    pub fn leg_type(&self) -> Option<LegType> {
        enum_or_none(self.leg_type)
    }

    /// Centre and turn direction of a radius-to-fix leg.
    pub fn rf_centre(&self) -> Option<(GeoPoint, TurnDirection)> {
        enum_or_none(self.rf_turn_direction).map(|d| (self.rf_centre, d))
    }

    /// Sets or clears the radius-to-fix centre.
    pub fn set_rf_centre(&mut self, rf: Option<(GeoPoint, TurnDirection)>) {
        self.rf_centre = rf.map(|(c, _)| c).unwrap_or_default();
        self.rf_turn_direction = enum_to_raw(rf.map(|(_, d)| d));
    }
}

/// `fcc/mission/waypoint-list`: the active waypoint list with its take-off height and route
/// properties, as assembled and validated by mission data handling (ICD §5.1, §7).
#[derive(
    Debug,
    Clone,
    Copy,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::WaypointListPayload/v5"))]
pub struct WaypointListPayload {
    /// Counts activations of a new list since mission data handling started, from 1; 0 means
    /// no mission is active (after start or a clear).
    pub generation: u64,
    /// The activation this list was published under: see [`same_activation`].
    pub activation: u64,
    /// Take-off height above ground (#13006 type 1).
    pub take_off_height: Altitude,
    /// Waypoints used of `waypoints`.
    pub count: u16,
    /// Initial Waypoint Number (#13001).
    pub initial_waypoint: u16,
    /// The route may be flown backwards for return to home (#13001 Activity ID bit 0).
    pub bidirectional: bool,
    /// Zero.
    pub reserved0: u8,
    /// The wind speed the mission was checked in (#13001 field 5; zero: calm): every turn is
    /// flown and checked at the radius this wind forces (ICD §7 "Turns in wind").
    pub planning_wind: Speed,
    /// Zero.
    pub reserved: [u8; 4],
    /// The waypoints in flight-plan order, from the initial one to the one with Next 0.
    pub waypoints: [WaypointEntry; MAX_WAYPOINTS],
}

impl WaypointListPayload {
    /// No active mission.
    pub const EMPTY: Self = Self {
        generation: 0,
        activation: 0,
        take_off_height: Altitude::ZERO,
        count: 0,
        initial_waypoint: 0,
        bidirectional: false,
        reserved0: 0,
        planning_wind: Speed::from_raw(0),
        reserved: [0; 4],
        waypoints: [WaypointEntry::EMPTY; MAX_WAYPOINTS],
    };

    /// The waypoints in flight-plan order (clamped to the capacity, whatever `count` holds).
    pub fn waypoints(&self) -> &[WaypointEntry] {
        let n = usize::from(self.count).min(MAX_WAYPOINTS);
        self.waypoints.get(..n).unwrap_or_default()
    }

    /// Whether a mission is active.
    pub fn is_active(&self) -> bool {
        self.generation != 0 && self.count != 0
    }
}

/// Whether a waypoint list and an area list belong together (docs/design.md "Activation is
/// atomic"): they were published under the same activation.
///
/// Mission data handling publishes both lists together whenever either changes (an upload's
/// closer, a clear, the activation of a staged mission, ICD §8), each under the same activation
/// number, which grows with every change (it is the sum of the two generations, so it survives a
/// restart of mission data handling without a record of its own). Publication on two services
/// is not one step: a subscriber can hold the new waypoint list while the old area list is still
/// its newest. A subscriber that uses both lists therefore uses a pair only when this holds, and
/// keeps the pair it used before until the other list of the new activation arrives: so no
/// partition ever acts on the new waypoint list with the old area list or the reverse.
pub fn same_activation(waypoints: &WaypointListPayload, areas: &AreaListPayload) -> bool {
    waypoints.activation == areas.activation
}

/// Altitude bounds of an area (#2012 bits 4 to 6), each optional.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::AreaAltitudes/v5"))]
pub struct AreaAltitudes {
    /// Lower Altitude, valid when `has_lower`.
    pub lower: Altitude,
    /// Upper Altitude, valid when `has_upper`.
    pub upper: Altitude,
    /// Whether `lower` is given.
    pub has_lower: bool,
    /// Whether `upper` is given.
    pub has_upper: bool,
    /// [`AltitudeType`] or [`ABSENT`].
    pub altitude_type: u8,
    /// Zero.
    pub reserved: u8,
}

impl AreaAltitudes {
    /// No bounds.
    pub const NONE: Self = Self {
        lower: Altitude::ZERO,
        upper: Altitude::ZERO,
        has_lower: false,
        has_upper: false,
        altitude_type: ABSENT,
        reserved: 0,
    };

    /// Bounds from the optional fields of a #2012.
    pub fn new(
        lower: Option<Altitude>,
        upper: Option<Altitude>,
        altitude_type: Option<AltitudeType>,
    ) -> Self {
        Self {
            lower: lower.unwrap_or_default(),
            upper: upper.unwrap_or_default(),
            has_lower: lower.is_some(),
            has_upper: upper.is_some(),
            altitude_type: enum_to_raw(altitude_type),
            reserved: 0,
        }
    }

    /// Lower Altitude.
    pub fn lower(&self) -> Option<Altitude> {
        self.has_lower.then_some(self.lower)
    }

    /// Upper Altitude.
    pub fn upper(&self) -> Option<Altitude> {
        self.has_upper.then_some(self.upper)
    }

    /// Altitude Type.
    pub fn altitude_type(&self) -> Option<AltitudeType> {
        enum_or_none(self.altitude_type)
    }
}

/// A polygonal area: the fly-zone or a polygonal no-fly-zone.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::PolygonArea/v5"))]
pub struct PolygonArea {
    /// Area ID.
    pub area_id: u16,
    /// Vertices used of `vertices`, 3..=60.
    pub vertex_count: u8,
    /// Zero.
    pub reserved: u8,
    /// Altitude bounds.
    pub altitudes: AreaAltitudes,
    /// The vertices in order, not closed.
    pub vertices: [GeoPoint; MAX_POLYGON_VERTICES],
}

impl PolygonArea {
    /// An unused slot.
    pub const EMPTY: Self = Self {
        area_id: 0,
        vertex_count: 0,
        reserved: 0,
        altitudes: AreaAltitudes::NONE,
        vertices: [GeoPoint {
            latitude: Angle::from_raw(0),
            longitude: Angle::from_raw(0),
        }; MAX_POLYGON_VERTICES],
    };

    /// The vertices (clamped to the capacity).
    pub fn vertices(&self) -> &[GeoPoint] {
        let n = usize::from(self.vertex_count).min(MAX_POLYGON_VERTICES);
        self.vertices.get(..n).unwrap_or_default()
    }
}

/// A circular no-fly-zone, kept apart from the polygons as the paper's Figure 8 does.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::CircleArea/v5"))]
pub struct CircleArea {
    /// Area ID.
    pub area_id: u16,
    /// Zero.
    pub reserved: [u8; 2],
    /// Altitude bounds.
    pub altitudes: AreaAltitudes,
    /// Centre (first vertex of the #2012).
    pub centre: GeoPoint,
    /// A point on the border (second vertex).
    pub border: GeoPoint,
}

impl CircleArea {
    /// An unused slot.
    pub const EMPTY: Self = Self {
        area_id: 0,
        reserved: [0; 2],
        altitudes: AreaAltitudes::NONE,
        centre: GeoPoint {
            latitude: Angle::from_raw(0),
            longitude: Angle::from_raw(0),
        },
        border: GeoPoint {
            latitude: Angle::from_raw(0),
            longitude: Angle::from_raw(0),
        },
    };
}

/// `fcc/mission/area-list`: the active area list (ICD §5.3, §7): one fly-zone polygon, the
/// no-fly-zone polygons, the no-fly-zone circles, and the safety offset.
#[derive(
    Debug,
    Clone,
    Copy,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::AreaListPayload/v5"))]
pub struct AreaListPayload {
    /// Counts activations of a new list, from 1; 0 means no area list is active.
    pub generation: u64,
    /// The activation this list was published under: see [`same_activation`].
    pub activation: u64,
    /// Distance the geofence keeps from every area border.
    pub safety_offset: SafetyOffset,
    /// No-fly-zone polygons used.
    pub no_fly_polygon_count: u8,
    /// No-fly-zone circles used.
    pub no_fly_circle_count: u8,
    /// Zero.
    pub reserved: [u8; 4],
    /// The fly-zone (stay-in).
    pub fly_zone: PolygonArea,
    /// Polygonal no-fly-zones, in list order.
    pub no_fly_polygons: [PolygonArea; MAX_NO_FLY_ZONES],
    /// Circular no-fly-zones, in list order.
    pub no_fly_circles: [CircleArea; MAX_NO_FLY_ZONES],
}

impl AreaListPayload {
    /// No active area list.
    pub const EMPTY: Self = Self {
        generation: 0,
        activation: 0,
        safety_offset: SafetyOffset::from_raw(0),
        no_fly_polygon_count: 0,
        no_fly_circle_count: 0,
        reserved: [0; 4],
        fly_zone: PolygonArea::EMPTY,
        no_fly_polygons: [PolygonArea::EMPTY; MAX_NO_FLY_ZONES],
        no_fly_circles: [CircleArea::EMPTY; MAX_NO_FLY_ZONES],
    };

    /// Polygonal no-fly-zones (clamped to the capacity).
    pub fn no_fly_polygons(&self) -> &[PolygonArea] {
        let n = usize::from(self.no_fly_polygon_count).min(MAX_NO_FLY_ZONES);
        self.no_fly_polygons.get(..n).unwrap_or_default()
    }

    /// Circular no-fly-zones (clamped to the capacity).
    pub fn no_fly_circles(&self) -> &[CircleArea] {
        let n = usize::from(self.no_fly_circle_count).min(MAX_NO_FLY_ZONES);
        self.no_fly_circles.get(..n).unwrap_or_default()
    }

    /// Areas in the list: the fly-zone and every no-fly-zone.
    pub fn area_count(&self) -> usize {
        if self.generation == 0 {
            0
        } else {
            1 + self.no_fly_polygons().len() + self.no_fly_circles().len()
        }
    }
}

/// Flight phases of system automation (paper §2.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum FlightPhase {
    /// On ground, motors off: missions and areas may be uploaded and cleared.
    OnGround = 0,
    /// ATOL take-off: vertical climb to the take-off height.
    TakeOff = 1,
    /// Cruise: trajectory generation flies the waypoint list.
    Cruise = 2,
    /// Landing at the last (or the next) waypoint.
    Landing = 3,
    /// Landed after a mission.
    Landed = 4,
}

impl TryFrom<u8> for FlightPhase {
    type Error = u8;
    fn try_from(v: u8) -> Result<Self, u8> {
        match v {
            0 => Ok(Self::OnGround),
            1 => Ok(Self::TakeOff),
            2 => Ok(Self::Cruise),
            3 => Ok(Self::Landing),
            4 => Ok(Self::Landed),
            other => Err(other),
        }
    }
}

/// `fcc/automation/state`: the flight phase and which functions are active (paper §2.5).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::AutomationStatePayload/v5"))]
pub struct AutomationStatePayload {
    /// Counts state changes, from 1.
    pub sequence: u64,
    /// CLOCK_MONOTONIC nanoseconds of the change.
    pub changed_ns: u64,
    /// Generation of the waypoint list being flown, 0 for none.
    pub flown_waypoint_list: u64,
    /// [`FlightPhase`] as `u8`.
    pub flight_phase: u8,
    /// Trajectory generation is active: a clear is refused (`GuidanceActive`).
    pub trajectory_generation_active: bool,
    /// Fly the route backwards, to its initial waypoint (return to home, #50000 command 2).
    pub route_reversed: bool,
    /// Zero.
    pub reserved0: u8,
    /// Land at this waypoint instead of the last one (#50000 command 3), 0 for the last.
    pub land_at: u16,
    /// Guidance's heartbeat ([`HeartbeatPayload`] on `fcc/health/guidance`) came within its
    /// limit: without it the flight commands of #50000 are refused (`WrongState`).
    pub guidance_alive: bool,
    /// Zero.
    pub reserved: [u8; 9],
}

impl AutomationStatePayload {
    /// On ground, nothing active.
    pub const ON_GROUND: Self = Self {
        sequence: 0,
        changed_ns: 0,
        flown_waypoint_list: 0,
        flight_phase: FlightPhase::OnGround as u8,
        trajectory_generation_active: false,
        route_reversed: false,
        reserved0: 0,
        land_at: 0,
        guidance_alive: false,
        reserved: [0; 9],
    };

    /// The flight phase, or `None` for a value no publisher of this version writes.
    pub fn flight_phase(&self) -> Option<FlightPhase> {
        FlightPhase::try_from(self.flight_phase).ok()
    }
}

/// `fcc/automation/command`: a #50000 command that mission data handling accepted (ICD §4).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::AutomationCommandPayload/v5"))]
pub struct AutomationCommandPayload {
    /// Counts commands, from 1.
    pub sequence: u64,
    /// CLOCK_MONOTONIC nanoseconds when the command was accepted.
    pub accepted_ns: u64,
    /// [`crate::wire::ExecuteCommand`] as `u8`.
    pub command: u8,
    /// Zero.
    pub reserved: [u8; 7],
}

impl AutomationCommandPayload {
    /// The command, or `None` for a value no publisher of this version writes.
    pub fn command(&self) -> Option<crate::wire::ExecuteCommand> {
        crate::wire::ExecuteCommand::try_from(self.command).ok()
    }
}

/// The period partitions beat at when the configuration does not say (docs/design.md "Health").
pub const DEFAULT_HEARTBEAT_PERIOD: core::time::Duration = core::time::Duration::from_millis(100);

/// `fcc/health/<partition>`: a partition shows it is alive (docs/design.md "Health"). It sends one
/// from its event loop on a fixed period, so a partition that is stopped (SIGSTOP), stuck in a
/// step or dead sends none; whoever watches it takes the time the sample arrived, not
/// `time_ns`, and the period the partition says it beats at.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::HeartbeatPayload/v5"))]
pub struct HeartbeatPayload {
    /// Counts heartbeats of this process, from 1.
    pub sequence: u64,
    /// CLOCK_MONOTONIC nanoseconds when it was sent.
    pub time_ns: u64,
    /// The period the partition beats at, nanoseconds (above 0).
    pub period_ns: u64,
    /// The process ID of the partition.
    pub pid: u32,
    /// Zero.
    pub reserved: [u8; 4],
}

/// `fcc/guidance/progress`: the FROM, TO and NEXT waypoints, the position and how the aircraft
/// moves and lies, from guidance.
///
/// The heading, bank, pitch and climb rate are `f32` and NaN where guidance does not know one
/// (a guidance that does not compute it sends NaN; [`Self::IDLE`] has NaN in all four). A
/// reader takes any value that is not finite as not known: the bytes are written by another
/// process. Mission data handling sends them in #101 (ICD §4 #101).
///
/// `IntoBytes` (as on every payload: no byte is padding) lets [`Self::same_report_as`] compare
/// the bytes.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "ipc", type_name("missionlink::GuidanceProgressPayload/v5"))]
pub struct GuidanceProgressPayload {
    /// Counts updates, from 1.
    pub sequence: u64,
    /// CLOCK_MONOTONIC nanoseconds of the update.
    pub time_ns: u64,
    /// Generation of the waypoint list flown, 0 for none.
    pub waypoint_list: u64,
    /// Latitude, degrees.
    pub latitude_deg: f64,
    /// Longitude, degrees.
    pub longitude_deg: f64,
    /// Altitude, metres (of the waypoint list's altitude type).
    pub altitude_m: f64,
    /// Ground speed, m/s.
    pub ground_speed_mps: f64,
    /// FROM Waypoint Number, 0 = none (before the first waypoint).
    pub from: u16,
    /// TO Waypoint Number, 0 = none.
    pub to: u16,
    /// NEXT Waypoint Number, 0 = none (on the last leg).
    pub next: u16,
    /// Area ID of the no-fly-zone the position is in, 0 for none.
    pub in_no_fly_zone: u16,
    /// The position is inside the fly-zone.
    pub inside_fly_zone: bool,
    /// Trajectory generation is active.
    pub trajectory_generation_active: bool,
    /// The climb to the take-off height is complete (take-off phase).
    pub climb_complete: bool,
    /// The last waypoint of the route (or the landing waypoint) is reached.
    pub route_complete: bool,
    /// On the ground (before take-off or after touchdown).
    pub on_ground: bool,
    /// Zero.
    pub reserved: [u8; 3],
    /// True heading, where the nose points: degrees clockwise from true north, 0..360. In wind
    /// it differs from the course over the ground by the crab angle. NaN: not known.
    pub heading_deg: f32,
    /// Bank, degrees, positive right wing down. NaN: not known.
    pub roll_deg: f32,
    /// Pitch, degrees, positive nose up. NaN: not known.
    pub pitch_deg: f32,
    /// Vertical speed, m/s, positive up. NaN: not known.
    pub climb_rate_mps: f32,
}

impl GuidanceProgressPayload {
    /// Nothing flown yet.
    pub const IDLE: Self = Self {
        sequence: 0,
        time_ns: 0,
        waypoint_list: 0,
        latitude_deg: 0.0,
        longitude_deg: 0.0,
        altitude_m: 0.0,
        ground_speed_mps: 0.0,
        from: 0,
        to: 0,
        next: 0,
        in_no_fly_zone: 0,
        inside_fly_zone: false,
        trajectory_generation_active: false,
        climb_complete: false,
        route_complete: false,
        on_ground: true,
        reserved: [0; 3],
        heading_deg: f32::NAN,
        roll_deg: f32::NAN,
        pitch_deg: f32::NAN,
        climb_rate_mps: f32::NAN,
    };

    /// The FROM-TO-NEXT triple.
    pub fn from_to_next(&self) -> (u16, u16, u16) {
        (self.from, self.to, self.next)
    }

    /// Whether `other` reports what `self` does, the counters (`sequence`, `time_ns`) aside.
    /// The bytes are compared, not the values: a NaN ("not known") is the same as the same NaN,
    /// where `==` would call every report with an unknown value a change.
    pub fn same_report_as(&self, other: &Self) -> bool {
        use zerocopy::IntoBytes;
        let without_counters = |p: &Self| Self {
            sequence: 0,
            time_ns: 0,
            ..*p
        };
        without_counters(self).as_bytes() == without_counters(other).as_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One name per partition and role: the heartbeat's path is the role's, the binaries are
    /// found by their names, and only the link partition may create inet sockets.
    #[test]
    fn a_partition_names_its_heartbeat_and_its_binary() {
        for p in Partition::ALL {
            assert_eq!(
                FccService::Heartbeat(p).path(),
                format!("fcc/health/{}", p.role())
            );
            assert_eq!(Partition::from_binary(p.binary()), Some(p));
        }
        assert_eq!(Partition::Guidance.binary(), "guidance-stub");
        assert_eq!(Partition::from_binary("guidance"), None);
        let links: Vec<_> = Partition::ALL
            .into_iter()
            .filter(|p| p.allowed().links)
            .collect();
        assert_eq!(links, [Partition::VotingMonitoring]);
    }

    #[test]
    fn service_names_carry_the_prefix() {
        assert_eq!(
            FccService::WaypointList.name("test-1/"),
            "test-1/fcc/mission/waypoint-list"
        );
        let names: std::collections::HashSet<_> =
            FccService::ALL.iter().map(|s| s.name("p")).collect();
        assert_eq!(names.len(), FccService::ALL.len());
    }

    #[test]
    fn frame_payload_holds_the_largest_frame_and_refuses_more() {
        let big = [7u8; MAX_FRAME_LEN];
        let p = FramePayload::new(Link::Lte, &big, 5).unwrap();
        assert_eq!(p.frame(), &big[..]);
        assert_eq!(p.link(), Some(Link::Lte));
        assert!(FramePayload::new(Link::Direct, &[0; MAX_FRAME_LEN + 1], 0).is_none());
    }

    #[test]
    fn a_report_is_the_same_whatever_its_counters_and_unknown_values() {
        let a = GuidanceProgressPayload {
            sequence: 1,
            time_ns: 5,
            ..GuidanceProgressPayload::IDLE
        };
        let b = GuidanceProgressPayload {
            sequence: 2,
            time_ns: 9,
            ..GuidanceProgressPayload::IDLE
        };
        // NaN != NaN: a copy of a report with an unknown value is not `==` to it.
        let copy = a;
        assert_ne!(a, copy);
        assert!(a.same_report_as(&copy));
        assert!(a.same_report_as(&b));
        let turning = GuidanceProgressPayload {
            roll_deg: 25.0,
            ..b
        };
        assert!(!a.same_report_as(&turning));
    }

    #[test]
    #[cfg(feature = "ipc")]
    #[allow(
        unsafe_code,
        reason = "type_name is unsafe only to discourage overriding it"
    )]
    fn type_names_carry_the_contract_version() {
        // SAFETY: type_name only returns a static string.
        let name = unsafe { <WaypointListPayload as ZeroCopySend>::type_name() };
        assert!(name.ends_with(&format!("/v{CONTRACT_VERSION}")));
    }
}
