"""The iceoryx2 contracts between the FCC partitions for Python.

The same payloads as interfaces/src/contracts.rs and the wire newtypes of interfaces/src/wire
(docs/design.md, "Contracts between partitions") as ctypes structures with the Rust type names, so
that a partition written in Python opens the same services as the Rust ones: iceoryx2 matches a
service's payload by type name, size and alignment, and each payload class here gives its type
name by `type_name()`, which iceoryx2's Python binding asks for.

Hand-written, kept in step with the Rust types by interfaces/tests/contracts_layout.rs, which
compares every structure, field, size, alignment and offset, type name, service path, QoS
number, capacity and enumeration value here with Rust's and with the C header's
(interfaces/c/missionlink_contracts.h). Change the three together.

Only ctypes is needed: the module imports no iceoryx2, so tools that only read or write the
payloads use it without iceoryx2 installed.

Enumerations cross shared memory as raw bytes (`c_uint8`): a byte written by another process
may hold anything, so readers map an unknown value to "unknown" (the IntEnums below name the
known values). Optional enumeration bytes hold ABSENT when absent.

No structure has padding: the bytes alignment would add are `reserved*` fields of their own,
zero in a new structure (ctypes zeroes it) and never to be set otherwise, so every byte a
partition publishes is a byte it wrote (the bridge sends the bytes as they lie across hosts,
ICD §14).
"""

from __future__ import annotations

import ctypes
import math
from enum import IntEnum
from typing import NamedTuple

#: Version of the payload layouts; part of every type name.
CONTRACT_VERSION = 5
#: Service-name prefix used when none is configured.
DEFAULT_SERVICE_PREFIX = "missionlink"
#: Marks an optional enumeration byte as absent.
ABSENT = 0xFF
#: The period partitions beat at when the configuration does not say (HeartbeatPayload).
DEFAULT_HEARTBEAT_PERIOD_MS = 100

# Capacities (interfaces/src/capacity.rs, and the wire layer's largest frame).
MAX_WAYPOINTS = 256
MAX_AREAS = 11
MAX_NO_FLY_ZONES = 10
MAX_POLYGON_VERTICES = 60
MIN_POLYGON_VERTICES = 3
MAX_FRAME_LEN = 548


class Qos(NamedTuple):
    """How every partition opens a service (FccService::qos())."""

    history_size: int
    subscriber_max_buffer_size: int
    max_publishers: int
    max_subscribers: int
    safe_overflow: bool

    @property
    def max_listeners(self) -> int:
        """Listeners of the event service: two per subscriber (Qos::max_listeners)."""
        return 2 * self.max_subscribers


class Service(NamedTuple):
    """A service of the FCC: its path under the prefix and its QoS.

    The same name serves the publish-subscribe service and its event service; the event service
    is opened with max notifiers = `qos.max_publishers` and max listeners =
    `qos.max_listeners`, and a publisher notifies it after every sample.
    """

    path: str
    qos: Qos

    def name(self, prefix: str) -> str:
        """The full service name, `{prefix}/{path}` (as FccService::name)."""
        return f"{prefix.rstrip('/')}/{self.path}"


_QUEUE = Qos(0, 256, 2, 4, False)
_STATE = Qos(1, 1, 2, 8, True)

#: Voted uplink frames (FramePayload), voting-monitoring to mission-data-handling.
SERVICE_LINK_UPLINK = Service("fcc/link/uplink", _QUEUE)
#: Downlink frames (FramePayload), mission-data-handling to voting-monitoring.
SERVICE_LINK_DOWNLINK = Service("fcc/link/downlink", _QUEUE)
#: The active waypoint list (WaypointListPayload), history 1.
SERVICE_MISSION_WAYPOINT_LIST = Service("fcc/mission/waypoint-list", _STATE)
#: The active area list (AreaListPayload), history 1.
SERVICE_MISSION_AREA_LIST = Service("fcc/mission/area-list", _STATE)
#: Flight phase and active functions (AutomationStatePayload), history 1.
SERVICE_AUTOMATION_STATE = Service("fcc/automation/state", _STATE)
#: FROM / TO / NEXT and position (GuidanceProgressPayload), history 1.
SERVICE_GUIDANCE_PROGRESS = Service("fcc/guidance/progress", _STATE)
#: #50000 commands accepted by mission data handling (AutomationCommandPayload), a queue.
SERVICE_AUTOMATION_COMMAND = Service("fcc/automation/command", _QUEUE)

class Partition(NamedTuple):
    """A partition of the FCC (Partition): its role, which the services named after a partition
    carry (fcc/health/<role>, whatever fills the role: a partition in Python beats on its role's
    service), the Rust binary that fills it (what `fcc --without` takes to leave it out for a
    replacement), and what its fence allows beyond every partition's loop.
    """

    role: str
    binary: str
    #: It owns the UDP links (inet sockets).
    links: bool
    #: It writes the state directory.
    state: bool


PARTITION_VOTING_MONITORING = Partition("voting-monitoring", "voting-monitoring", True, True)
PARTITION_MISSION_DATA_HANDLING = Partition(
    "mission-data-handling", "mission-data-handling", False, True
)
PARTITION_SYSTEM_AUTOMATION = Partition("system-automation", "system-automation", False, False)
PARTITION_GUIDANCE = Partition("guidance", "guidance-stub", False, False)

#: Every partition, in start order.
PARTITIONS = (
    PARTITION_VOTING_MONITORING,
    PARTITION_MISSION_DATA_HANDLING,
    PARTITION_SYSTEM_AUTOMATION,
    PARTITION_GUIDANCE,
)

#: Heartbeats (HeartbeatPayload), one service per partition role, history 1.
SERVICE_HEALTH_VOTING_MONITORING = Service(
    "fcc/health/" + PARTITION_VOTING_MONITORING.role, _STATE
)
SERVICE_HEALTH_MISSION_DATA_HANDLING = Service(
    "fcc/health/" + PARTITION_MISSION_DATA_HANDLING.role, _STATE
)
SERVICE_HEALTH_SYSTEM_AUTOMATION = Service(
    "fcc/health/" + PARTITION_SYSTEM_AUTOMATION.role, _STATE
)
SERVICE_HEALTH_GUIDANCE = Service("fcc/health/" + PARTITION_GUIDANCE.role, _STATE)

#: Every service.
SERVICES = (
    SERVICE_LINK_UPLINK,
    SERVICE_LINK_DOWNLINK,
    SERVICE_MISSION_WAYPOINT_LIST,
    SERVICE_MISSION_AREA_LIST,
    SERVICE_AUTOMATION_STATE,
    SERVICE_GUIDANCE_PROGRESS,
    SERVICE_AUTOMATION_COMMAND,
    SERVICE_HEALTH_VOTING_MONITORING,
    SERVICE_HEALTH_MISSION_DATA_HANDLING,
    SERVICE_HEALTH_SYSTEM_AUTOMATION,
    SERVICE_HEALTH_GUIDANCE,
)


class Link(IntEnum):
    """The link a frame arrived on or leaves by (FramePayload.link)."""

    DIRECT = 0
    LTE = 1
    BOTH = 2


class FlightPhase(IntEnum):
    """Flight phases of system automation (AutomationStatePayload.flight_phase)."""

    ON_GROUND = 0
    TAKE_OFF = 1
    CRUISE = 2
    LANDING = 3
    LANDED = 4


class ExecuteCommand(IntEnum):
    """#50000 commands (AutomationCommandPayload.command)."""

    EXECUTE = 1
    RETURN_TO_HOME = 2
    LAND = 3
    ACTIVATE_STAGED = 4


class AltitudeType(IntEnum):
    """Altitude Type (WaypointEntry.altitude_type, AreaAltitudes.altitude_type)."""

    PRESSURE = 0
    BARO = 1
    AGL = 2
    WGS84 = 3


class SpeedType(IntEnum):
    """Speed Type (WaypointEntry.speed_type)."""

    INDICATED_AIRSPEED = 0
    TRUE_AIRSPEED = 1
    GROUND_SPEED = 2


class TurnType(IntEnum):
    """Turn Type (WaypointEntry.turn_type)."""

    FLY_BY = 0
    FLY_OVER = 1


class LegType(IntEnum):
    """Leg type of the leg that ends at a waypoint (WaypointEntry.leg_type)."""

    TRACK_TO_FIX = 0
    RADIUS_TO_FIX = 1


class TurnDirection(IntEnum):
    """Turn direction of a radius-to-fix leg (WaypointEntry.rf_turn_direction)."""

    CLOCKWISE = 0
    COUNTER_CLOCKWISE = 1


def enum_or_none(enum: type[IntEnum], raw: int) -> IntEnum | None:
    """The enumeration value of a raw byte, or None for ABSENT or a value it does not know."""
    try:
        return enum(raw)
    except ValueError:
        return None


# The wire newtypes: raw values in the ICD's units (ICD §3).


class Angle(ctypes.Structure):
    """BAM4 angle: degrees = raw * 180 / 2^31."""

    _fields_ = [("raw", ctypes.c_int32)]

    LSB_DEGREES = 180.0 / 2_147_483_648.0

    def degrees(self) -> float:
        """The angle in degrees, -180..180."""
        return self.raw * Angle.LSB_DEGREES


class Altitude(ctypes.Structure):
    """ALT3 altitude or height: metres = raw * 0.02 (24 bits used, sign-extended)."""

    _fields_ = [("raw", ctypes.c_int32)]

    def metres(self) -> float:
        """The altitude in metres."""
        return self.raw / 50.0


class Speed(ctypes.Structure):
    """SPD2 speed: m/s = raw * 0.5."""

    _fields_ = [("raw", ctypes.c_uint16)]

    def mps(self) -> float:
        """The speed in metres per second."""
        return self.raw * 0.5


class SafetyOffset(ctypes.Structure):
    """Safety offset: metres = raw * 0.1."""

    _fields_ = [("raw", ctypes.c_uint16)]

    def metres(self) -> float:
        """The offset in metres."""
        return self.raw / 10.0


class GeoPoint(ctypes.Structure):
    """A latitude and longitude on WGS-84."""

    _fields_ = [("latitude", Angle), ("longitude", Angle)]

    def lat_lon_deg(self) -> tuple[float, float]:
        """(latitude, longitude), degrees."""
        return (self.latitude.degrees(), self.longitude.degrees())


# The payloads. Each one's type_name() is what iceoryx2 matches across languages.


class FramePayload(ctypes.Structure):
    """fcc/link/uplink, fcc/link/downlink: a STANAG frame as opaque bytes plus metadata."""

    _fields_ = [
        ("origin_ns", ctypes.c_uint64),
        ("published_ns", ctypes.c_uint64),
        ("sequence", ctypes.c_uint64),
        ("len", ctypes.c_uint16),
        ("link", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8 * 5),
        ("bytes", ctypes.c_uint8 * MAX_FRAME_LEN),
        ("reserved_tail", ctypes.c_uint8 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::FramePayload/v5"

    def frame(self) -> bytes:
        """The frame bytes (clamped to the array, whatever `len` holds)."""
        return bytes(self.bytes[: min(self.len, MAX_FRAME_LEN)])


class WaypointEntry(ctypes.Structure):
    """One waypoint of the assembled list, in flight-plan order."""

    _fields_ = [
        ("number", ctypes.c_uint16),
        ("next", ctypes.c_uint16),
        ("position", GeoPoint),
        ("altitude", Altitude),
        ("speed", Speed),
        ("altitude_type", ctypes.c_uint8),
        ("speed_type", ctypes.c_uint8),
        ("turn_type", ctypes.c_uint8),
        ("leg_type", ctypes.c_uint8),
        ("rf_turn_direction", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8),
        ("rf_centre", GeoPoint),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::WaypointEntry/v5"


class WaypointListPayload(ctypes.Structure):
    """fcc/mission/waypoint-list: the active waypoint list."""

    _fields_ = [
        ("generation", ctypes.c_uint64),
        ("activation", ctypes.c_uint64),
        ("take_off_height", Altitude),
        ("count", ctypes.c_uint16),
        ("initial_waypoint", ctypes.c_uint16),
        ("bidirectional", ctypes.c_bool),
        ("reserved0", ctypes.c_uint8),
        ("planning_wind", Speed),
        ("reserved", ctypes.c_uint8 * 4),
        ("waypoints", WaypointEntry * MAX_WAYPOINTS),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::WaypointListPayload/v5"

    def used(self) -> list[WaypointEntry]:
        """The waypoints in flight-plan order (clamped to the capacity, whatever `count` holds)."""
        return list(self.waypoints[: min(self.count, MAX_WAYPOINTS)])


class AreaAltitudes(ctypes.Structure):
    """Altitude bounds of an area, each optional."""

    _fields_ = [
        ("lower", Altitude),
        ("upper", Altitude),
        ("has_lower", ctypes.c_bool),
        ("has_upper", ctypes.c_bool),
        ("altitude_type", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::AreaAltitudes/v5"


class PolygonArea(ctypes.Structure):
    """A polygonal area: the fly-zone or a polygonal no-fly-zone."""

    _fields_ = [
        ("area_id", ctypes.c_uint16),
        ("vertex_count", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8),
        ("altitudes", AreaAltitudes),
        ("vertices", GeoPoint * MAX_POLYGON_VERTICES),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::PolygonArea/v5"

    def used(self) -> list[GeoPoint]:
        """The vertices (clamped to the capacity)."""
        return list(self.vertices[: min(self.vertex_count, MAX_POLYGON_VERTICES)])


class CircleArea(ctypes.Structure):
    """A circular no-fly-zone: its centre and a point on its border."""

    _fields_ = [
        ("area_id", ctypes.c_uint16),
        ("reserved", ctypes.c_uint8 * 2),
        ("altitudes", AreaAltitudes),
        ("centre", GeoPoint),
        ("border", GeoPoint),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::CircleArea/v5"


class AreaListPayload(ctypes.Structure):
    """fcc/mission/area-list: the active area list."""

    _fields_ = [
        ("generation", ctypes.c_uint64),
        ("activation", ctypes.c_uint64),
        ("safety_offset", SafetyOffset),
        ("no_fly_polygon_count", ctypes.c_uint8),
        ("no_fly_circle_count", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8 * 4),
        ("fly_zone", PolygonArea),
        ("no_fly_polygons", PolygonArea * MAX_NO_FLY_ZONES),
        ("no_fly_circles", CircleArea * MAX_NO_FLY_ZONES),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::AreaListPayload/v5"

    def polygons(self) -> list[PolygonArea]:
        """Polygonal no-fly-zones (clamped to the capacity)."""
        return list(self.no_fly_polygons[: min(self.no_fly_polygon_count, MAX_NO_FLY_ZONES)])

    def circles(self) -> list[CircleArea]:
        """Circular no-fly-zones (clamped to the capacity)."""
        return list(self.no_fly_circles[: min(self.no_fly_circle_count, MAX_NO_FLY_ZONES)])

    def area_count(self) -> int:
        """Areas in the list: the fly-zone and every no-fly-zone (0 without a list)."""
        if self.generation == 0:
            return 0
        return 1 + len(self.polygons()) + len(self.circles())


def same_activation(waypoints: WaypointListPayload, areas: AreaListPayload) -> bool:
    """Whether a waypoint list and an area list belong together (contracts::same_activation).

    A subscriber that uses both lists uses a pair only when this holds, and keeps the pair it
    used before until the other list of the new activation arrives.
    """
    return waypoints.activation == areas.activation


class AutomationStatePayload(ctypes.Structure):
    """fcc/automation/state: the flight phase and which functions are active."""

    _fields_ = [
        ("sequence", ctypes.c_uint64),
        ("changed_ns", ctypes.c_uint64),
        ("flown_waypoint_list", ctypes.c_uint64),
        ("flight_phase", ctypes.c_uint8),
        ("trajectory_generation_active", ctypes.c_bool),
        ("route_reversed", ctypes.c_bool),
        ("reserved0", ctypes.c_uint8),
        ("land_at", ctypes.c_uint16),
        ("guidance_alive", ctypes.c_bool),
        ("reserved", ctypes.c_uint8 * 9),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::AutomationStatePayload/v5"


class AutomationCommandPayload(ctypes.Structure):
    """fcc/automation/command: a #50000 command that mission data handling accepted."""

    _fields_ = [
        ("sequence", ctypes.c_uint64),
        ("accepted_ns", ctypes.c_uint64),
        ("command", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8 * 7),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::AutomationCommandPayload/v5"


class HeartbeatPayload(ctypes.Structure):
    """fcc/health/<partition>: a partition shows it is alive, once per period."""

    _fields_ = [
        ("sequence", ctypes.c_uint64),
        ("time_ns", ctypes.c_uint64),
        ("period_ns", ctypes.c_uint64),
        ("pid", ctypes.c_uint32),
        ("reserved", ctypes.c_uint8 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::HeartbeatPayload/v5"


class GuidanceProgressPayload(ctypes.Structure):
    """fcc/guidance/progress: FROM, TO and NEXT, the position and the attitude, from guidance.

    The four floats (heading, roll, pitch, climb rate) are NaN where guidance does not know
    one: a guidance that does not compute one sends NaN, and so does every payload made here
    until it is set (`__init__` below). A reader takes any value that is not finite as not
    known."""

    _fields_ = [
        ("sequence", ctypes.c_uint64),
        ("time_ns", ctypes.c_uint64),
        ("waypoint_list", ctypes.c_uint64),
        ("latitude_deg", ctypes.c_double),
        ("longitude_deg", ctypes.c_double),
        ("altitude_m", ctypes.c_double),
        ("ground_speed_mps", ctypes.c_double),
        # "from" is a Python keyword: read it as `from_` (the property below) or getattr.
        ("from", ctypes.c_uint16),
        ("to", ctypes.c_uint16),
        ("next", ctypes.c_uint16),
        ("in_no_fly_zone", ctypes.c_uint16),
        ("inside_fly_zone", ctypes.c_bool),
        ("trajectory_generation_active", ctypes.c_bool),
        ("climb_complete", ctypes.c_bool),
        ("route_complete", ctypes.c_bool),
        ("on_ground", ctypes.c_bool),
        ("reserved", ctypes.c_uint8 * 3),
        #: True heading (where the nose points), degrees clockwise from north, 0..360.
        ("heading_deg", ctypes.c_float),
        #: Bank, degrees, positive right wing down.
        ("roll_deg", ctypes.c_float),
        #: Pitch, degrees, positive nose up.
        ("pitch_deg", ctypes.c_float),
        #: Vertical speed, m/s, positive up.
        ("climb_rate_mps", ctypes.c_float),
    ]

    #: The fields that are NaN until set ("not known", as the Rust IDLE value).
    UNKNOWN_UNTIL_SET = ("heading_deg", "roll_deg", "pitch_deg", "climb_rate_mps")

    def __init__(self, *args, **kwargs):
        # ctypes zeroes every field; 0 would read as a real heading, bank, pitch and climb rate.
        for name in self.UNKNOWN_UNTIL_SET:
            kwargs.setdefault(name, math.nan)
        super().__init__(*args, **kwargs)

    @staticmethod
    def type_name() -> str:
        """The iceoryx2 type name."""
        return "missionlink::GuidanceProgressPayload/v5"

    @property
    def from_(self) -> int:
        """FROM Waypoint Number, 0 = none (the field `from`)."""
        return getattr(self, "from")

    @from_.setter
    def from_(self, value: int) -> None:
        setattr(self, "from", value)

    def from_to_next(self) -> tuple[int, int, int]:
        """The FROM-TO-NEXT triple."""
        return (self.from_, self.to, self.next)


#: Every structure, wire newtypes first, then the payloads.
STRUCTURES = (
    Angle,
    Altitude,
    Speed,
    SafetyOffset,
    GeoPoint,
    FramePayload,
    WaypointEntry,
    WaypointListPayload,
    AreaAltitudes,
    PolygonArea,
    CircleArea,
    AreaListPayload,
    AutomationStatePayload,
    AutomationCommandPayload,
    HeartbeatPayload,
    GuidanceProgressPayload,
)
