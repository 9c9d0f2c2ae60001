#!/usr/bin/env python3
"""Guidance partition in Python: stands in for the Rust guidance stub (partitions/src/
guidance_stub.rs) in the rig, opening the same iceoryx2 services with the same payload types
(docs/design.md "Partitions": a partition is replaced by starting another process, in any
language iceoryx2 serves, that opens the same services with the same payload types).

It subscribes to the active waypoint and area lists (taken only as a pair of one activation,
as `ipc::ListPairing` takes them) and to the automation state, flies the list with the
point-mass model of services/flight/src/guidance/ (ported below: same phases, sub-steps, legs
tracked along their geodesics, radius-to-fix arcs, the turns of services/protocol/src/geofence/turn.rs
(fly-by arcs, fly-over intercepts), return to home and land-at, on the same WGS-84 geodesics),
time-scaled for demos, and publishes FROM / TO / NEXT, the position, the heading, bank,
pitch and climb rate (as the Rust model computes them) on `fcc/guidance/progress`, notifying
the event service of the same name as the Rust publishers do. It beats on
`fcc/health/guidance` with a HeartbeatPayload every period, from its event loop, so system
automation sees a live guidance.

Usage (the FCC started without its stub: `fcc --without guidance-stub`):

    python3 -m pip install -r partitions/python/requirements.txt
    python3 partitions/python/missionlink_guidance.py --service-prefix missionlink \
        --time-scale 20

Logs go to stderr; SIGTERM or SIGINT ends it cleanly (exit status 0).

Wind, as the Rust model (ICD §7 "Turns in wind"): every turn is sized for the wind the plan was
checked in (the list's `planning_wind`), at the radius (v + W)^2 / (g tan(bank)), which a
bank-limited aircraft holds over the ground whatever the wind's direction, so that the path
flown is the one path the geofence checked. The simulated aircraft flies in the steady wind of
`--wind-speed-mps` / `--wind-from-deg`: waypoint speeds are airspeeds, and each path is held
over the ground at the ground speed that wind leaves on its course.

Where the Rust model and this port differ (on purpose, to stay short): the zone tests. Rust
densifies every geodesic border and decides in the tangent plane with the geofence's pieces;
here a polygon is taken with straight edges in the azimuthal equidistant projection about the
aircraft (geodesics through the aircraft are straight there, the others bow by well under a
metre over the demo's few-kilometre zones). The zone flags are information only: nothing
decides on them.
"""

from __future__ import annotations

import argparse
import ctypes
import logging
import math
import os
import signal
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional, TypeVar, Union

try:
    import missionlink_contracts as contracts
except ImportError:  # run from the repository: the contracts live in interfaces/python
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "interfaces" / "python"))
    import missionlink_contracts as contracts

try:
    from geographiclib.geodesic import Geodesic
except ImportError as e:
    raise ImportError(
        f"{e}: install the requirements (python3 -m pip install -r "
        "partitions/python/requirements.txt)"
    ) from e

from missionlink_contracts import (
    AreaListPayload,
    AutomationStatePayload,
    FlightPhase,
    GuidanceProgressPayload,
    HeartbeatPayload,
    LegType,
    TurnDirection,
    TurnType,
    WaypointEntry,
    WaypointListPayload,
    enum_or_none,
)

log = logging.getLogger("missionlink_guidance")

# ---------------------------------------------------------------------------------------------
# The Earth model: WGS-84 geodesics, as services/protocol/src/geofence/earth.rs (Karney's algorithms; the
# Rust side uses geographiclib-rs, a port of this same library). Points are (latitude,
# longitude) in degrees.
# ---------------------------------------------------------------------------------------------

WGS84 = Geodesic(6_378_137.0, 1.0 / 298.257_223_563)

Point = tuple[float, float]


def distance_m(a: Point, b: Point) -> float:
    """Length of the geodesic from `a` to `b`, metres."""
    return WGS84.Inverse(a[0], a[1], b[0], b[1], Geodesic.DISTANCE)["s12"]


def bearing_deg(a: Point, b: Point) -> float:
    """Initial bearing of the geodesic from `a` to `b`, degrees clockwise from north, 0..360."""
    return WGS84.Inverse(a[0], a[1], b[0], b[1], Geodesic.AZIMUTH)["azi1"] % 360.0


def destination(start: Point, bearing: float, distance: float) -> Point:
    """The point `distance` metres from `start` along the geodesic leaving it at `bearing`."""
    r = WGS84.Direct(start[0], start[1], bearing, distance, Geodesic.LATITUDE | Geodesic.LONGITUDE)
    return (r["lat2"], r["lon2"])


def point(p: contracts.GeoPoint) -> Point:
    """A wire position as a point."""
    return p.lat_lon_deg()


# ---------------------------------------------------------------------------------------------
# The guidance model (services/flight/src/guidance/; its module documentation describes the model).
# ---------------------------------------------------------------------------------------------

#: Longest sub-step of the integration, simulated seconds.
MAX_SUB_STEP_S = 0.05
#: Speed flown towards a waypoint whose commanded speed is 0, m/s.
FALLBACK_SPEED_MPS = 10.0
#: A waypoint closer than this is reached, metres.
REACHED_M = 0.01
#: Climb and descent end this close to their target altitude, metres.
ALTITUDE_EPSILON_M = 1e-6
#: The shortest look-ahead of the cross-track law on a track-to-fix leg, metres.
MIN_LOOK_AHEAD_M = 10.0
#: Path ends (turn paths, leg switches, arrivals) handled within one sub-step at most.
MAX_LEGS_PER_SUB_STEP = 8
GRAVITY_MPS2 = 9.806_65


@dataclass(frozen=True)
class GuidanceConfig:
    """Settings of the guidance model (the defaults of missionlink_flight::guidance::GuidanceConfig)."""

    start_latitude_deg: float = 48.26
    start_longitude_deg: float = 11.66
    climb_rate_mps: float = 3.0
    descent_rate_mps: float = 2.0
    max_bank_deg: float = 25.0
    #: Simulated seconds per real second; 0 pauses.
    time_scale: float = 1.0
    #: Speed of the steady wind the simulated aircraft flies in, m/s; 0 calm. It sets the ground
    #: speed along each path; the turns' radius is the plan's wind's (ICD §7 "Turns in wind").
    wind_speed_mps: float = 0.0
    #: Direction that wind blows from, degrees clockwise from true north.
    wind_from_deg: float = 0.0

    def sanitized(self) -> "GuidanceConfig":
        """Every unusable value replaced by its default (as the Rust model does)."""
        d = GuidanceConfig()

        def positive(v: float, default: float) -> float:
            return v if math.isfinite(v) and v > 0.0 else default

        return GuidanceConfig(
            start_latitude_deg=self.start_latitude_deg
            if -90.0 <= self.start_latitude_deg <= 90.0
            else d.start_latitude_deg,
            start_longitude_deg=self.start_longitude_deg
            if -180.0 <= self.start_longitude_deg <= 180.0
            else d.start_longitude_deg,
            climb_rate_mps=positive(self.climb_rate_mps, d.climb_rate_mps),
            descent_rate_mps=positive(self.descent_rate_mps, d.descent_rate_mps),
            max_bank_deg=self.max_bank_deg if 0.0 < self.max_bank_deg < 90.0 else d.max_bank_deg,
            time_scale=self.time_scale
            if math.isfinite(self.time_scale) and self.time_scale >= 0.0
            else d.time_scale,
            wind_speed_mps=self.wind_speed_mps
            if math.isfinite(self.wind_speed_mps) and self.wind_speed_mps >= 0.0
            else d.wind_speed_mps,
            # Python's % on floats is Rust's rem_euclid (fmod, plus 360 when negative).
            wind_from_deg=self.wind_from_deg % 360.0
            if math.isfinite(self.wind_from_deg)
            else d.wind_from_deg,
        )

    def turn_radius_m(self, v: float) -> float:
        """Radius of a turn at ground speed `v` and the bank limit: v^2 / (g tan(bank)),
        metres."""
        return v * v / (GRAVITY_MPS2 * math.tan(math.radians(self.max_bank_deg)))

    def radius_in_wind_m(self, v: float, wind_mps: float) -> float:
        """Radius of the turn flown at airspeed `v` in a wind of `wind_mps` from any direction:
        (v + W)^2 / (g tan(bank)), metres (geofence::onboard::FlyBy::radius_in_wind_m). The
        tailwind part of the turn needs the most bank; sizing for it holds the ground path
        whichever way the wind blows, and a forecast's direction is its least certain part."""
        wind = max(wind_mps, 0.0) if math.isfinite(wind_mps) else 0.0
        return self.turn_radius_m(v + wind)

    def ground_speed_mps(self, v: float, course_deg: float) -> float:
        """Ground speed at airspeed `v` along a ground course of `course_deg` in the configured
        wind: the along-track wind plus what is left of `v` once the crab cancels the crosswind;
        a twentieth of `v` where the wind leaves less (the gateway refuses such a leg), so that
        the model keeps moving along its path (GuidanceConfig::ground_speed_mps)."""
        c = self.sanitized()
        w = c.wind_speed_mps
        # Angle between the course and where the wind blows to.
        delta = math.radians(course_deg - (c.wind_from_deg + 180.0))
        along, cross = w * math.cos(delta), w * math.sin(delta)
        ground = along + math.sqrt(max(v * v - cross * cross, 0.0))
        return ground if math.isfinite(ground) and ground > v / 20.0 else v / 20.0

    def crab_deg(self, v: float, course_deg: float) -> float:
        """The crab angle at airspeed `v` along a ground course of `course_deg` in the
        configured wind: asin(crosswind / v), degrees, positive clockwise; square to the course
        where the crosswind is stronger than `v` (GuidanceConfig::crab_deg)."""
        c = self.sanitized()
        # Angle between the course and where the wind blows to: a wind blowing to the right of
        # the course (sin < 0 here) is met with the nose turned left.
        delta = math.radians(course_deg - (c.wind_from_deg + 180.0))
        cross = c.wind_speed_mps * math.sin(delta)
        if v > 0.0:
            return math.degrees(math.asin(max(-1.0, min(1.0, cross / v))))
        return 0.0

    def heading_deg(self, v: float, course_deg: float) -> float:
        """The true heading at airspeed `v` along a ground course of `course_deg`: the course
        turned by the crab angle, degrees in 0..360 (GuidanceConfig::heading_deg)."""
        heading = (course_deg + self.crab_deg(v, course_deg)) % 360.0
        # % rounds a tiny negative angle up to 360 itself.
        return heading if heading < 360.0 else 0.0


def bank_on_radius_deg(ground_mps: float, radius_m: float, drift_deg: float) -> float:
    """The bank that holds a ground path curving at radius `radius_m` at ground speed
    `ground_mps` with the drift angle `drift_deg`: atan(V_g^2 / (g R cos(drift))), degrees in
    0..90; 0 for a radius not above 0 (geofence::onboard::FlyBy::bank_on_radius_deg)."""
    if math.isnan(radius_m) or radius_m <= 0.0:
        return 0.0
    cos_drift = math.cos(math.radians(drift_deg))
    # Rust divides by a cosine of 0 to infinity, which atan takes to 90 deg; Python raises.
    if cos_drift == 0.0:
        return 90.0
    acceleration = ground_mps * ground_mps / (radius_m * cos_drift)
    bank = math.degrees(math.atan(abs(acceleration) / GRAVITY_MPS2))
    return 0.0 if math.isnan(bank) else bank


def inverse(a: Point, b: Point) -> tuple[float, float, float]:
    """Length (metres), initial and final azimuth (degrees) of the geodesic from `a` to `b`."""
    g = WGS84.Inverse(a[0], a[1], b[0], b[1], Geodesic.DISTANCE | Geodesic.AZIMUTH)
    return (g["s12"], g["azi1"], g["azi2"])


# ---------------------------------------------------------------------------------------------
# Paths and turns: services/protocol/src/geofence/turn.rs, the one construction of the turn at a
# waypoint that guidance flies and the geofence checks (its module documentation describes it).
# ---------------------------------------------------------------------------------------------

#: A course change smaller than this is no turn, degrees.
STRAIGHT_DEG = 0.01
#: The intercept angle of a fly-over, degrees.
INTERCEPT_DEG = 45.0
#: Straight intercepts shorter than this are left out, metres.
MIN_STRAIGHT_M = 0.001
#: Legs shorter than this have no direction: no turn at their end, metres.
MIN_LEG_M = 0.01


@dataclass(frozen=True)
class GeodesicPath:
    """A track-to-fix leg (or part of one): the geodesic from `from_` to `to`."""

    from_: Point
    to: Point


@dataclass(frozen=True)
class ArcPath:
    """An arc from `from_` to `to` around `centre`, clockwise (azimuth from the centre growing)
    or not, its radius going linearly with the angle turned."""

    from_: Point
    to: Point
    centre: Point
    clockwise: bool


Path = Union[GeodesicPath, ArcPath]

#: How a turn is flown (geofence::turn::TurnKind).
STRAIGHT, FLY_BY, FLY_OVER, ON_THE_SPOT = "straight", "fly-by", "fly-over", "on-the-spot"


@dataclass(frozen=True)
class Turn:
    kind: str
    leave: Point
    join: Point
    paths: tuple


def angle_to_go(from_deg: float, to_deg: float, clockwise: bool) -> float:
    """Angle from bearing `from_deg` to `to_deg` in the turn direction, 0..360."""
    return (to_deg - from_deg) % 360.0 if clockwise else (from_deg - to_deg) % 360.0


def course_change(a: float, b: float) -> float:
    return (b - a + 180.0) % 360.0 - 180.0


class ArcGeometry:
    def __init__(self, path: ArcPath):
        self.centre = path.centre
        self.clockwise = path.clockwise
        self.r0, self.az0, _ = inverse(path.centre, path.from_)
        self.r1, self.az1, _ = inverse(path.centre, path.to)
        self.sweep = angle_to_go(self.az0, self.az1, self.clockwise)

    def radius_at(self, az: float) -> float:
        if self.sweep <= 0.0:
            return self.r1
        f = min(angle_to_go(self.az0, az, self.clockwise) / self.sweep, 1.0)
        return self.r0 + (self.r1 - self.r0) * f

    def at(self, az: float) -> Point:
        return destination(self.centre, az, self.radius_at(az))

    def length_m(self) -> float:
        return math.radians(self.sweep) * (self.r0 + self.r1) / 2.0

    def course_at(self, at: Point) -> float:
        radial = inverse(self.centre, at)[2]
        return radial + 90.0 if self.clockwise else radial - 90.0


def length_m(path: Path) -> float:
    if isinstance(path, GeodesicPath):
        return inverse(path.from_, path.to)[0]
    return ArcGeometry(path).length_m()


def rest_from(path: Path, at: Point) -> Path:
    if isinstance(path, GeodesicPath):
        return GeodesicPath(at, path.to)
    return ArcPath(at, path.to, path.centre, path.clockwise)


def reversed_path(path: Path) -> Path:
    if isinstance(path, GeodesicPath):
        return GeodesicPath(path.to, path.from_)
    return ArcPath(path.to, path.from_, path.centre, not path.clockwise)


def leg_path(a: WaypointEntry, b: WaypointEntry) -> Path:
    """The leg flown from `a` to `b` by `b`'s leg type (geofence::onboard::leg)."""
    if enum_or_none(LegType, b.leg_type) == LegType.RADIUS_TO_FIX:
        direction = enum_or_none(TurnDirection, b.rf_turn_direction)
        if direction is not None:
            return ArcPath(
                point(a.position),
                point(b.position),
                point(b.rf_centre),
                direction == TurnDirection.CLOCKWISE,
            )
    return GeodesicPath(point(a.position), point(b.position))


def _unit(course: float) -> tuple[float, float]:
    a = math.radians(course)
    return (math.sin(a), math.cos(a))


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1]


def _norm(a) -> float:
    return math.hypot(a[0], a[1])


class _Aeqd:
    """The azimuthal equidistant projection at `origin`: x east, y north, metres."""

    def __init__(self, origin: Point):
        self.origin = origin

    def xy(self, s: Point) -> tuple[float, float]:
        d, az, _ = inverse(self.origin, s)
        a = math.radians(az)
        return (d * math.sin(a), d * math.cos(a))

    def site(self, c) -> Point:
        d = math.hypot(c[0], c[1])
        if d == 0.0:
            return self.origin
        return destination(self.origin, math.degrees(math.atan2(c[0], c[1])), d)


# A leg near the waypoint: ("line", p, u) or ("circle", c, r, clockwise); an offset curve:
# ("line", n, k) or ("circle", c, r).


def _offset(local, side: float, d: float):
    if local[0] == "line":
        _, p, u = local
        n = (u[1], -u[0])
        return ("line", n, _dot(n, p) + side * d)
    _, c, r, clockwise = local
    towards = 1.0 if clockwise else -1.0
    return ("circle", c, r - side * towards * d)


def _foot(local, f):
    if local[0] == "line":
        _, p, u = local
        t = _dot(u, (f[0] - p[0], f[1] - p[1]))
        return (p[0] + u[0] * t, p[1] + u[1] * t)
    _, c, r, _ = local
    d = _norm((f[0] - c[0], f[1] - c[1]))
    if not d > 0.0:
        return None
    k = r / d
    return (c[0] + (f[0] - c[0]) * k, c[1] + (f[1] - c[1]) * k)


def _intersect(a, b) -> list:
    out = []
    if a[0] == "line" and b[0] == "line":
        (_, n1, k1), (_, n2, k2) = a, b
        det = n1[0] * n2[1] - n1[1] * n2[0]
        if abs(det) > 1e-12:
            out.append(((k1 * n2[1] - k2 * n1[1]) / det, (n1[0] * k2 - n2[0] * k1) / det))
    elif a[0] != b[0]:
        (_, n, k), (_, c, r) = (a, b) if a[0] == "line" else (b, a)
        s = k - _dot(n, c)
        foot = (c[0] + n[0] * s, c[1] + n[1] * s)
        h = _norm((foot[0] - c[0], foot[1] - c[1]))
        if r > 0.0 and h <= r:
            t = math.sqrt(r * r - h * h)
            along = (-n[1], n[0])
            out.append((foot[0] + along[0] * t, foot[1] + along[1] * t))
            out.append((foot[0] - along[0] * t, foot[1] - along[1] * t))
    else:
        (_, c1, r1), (_, c2, r2) = a, b
        d = _norm((c2[0] - c1[0], c2[1] - c1[1]))
        if r1 > 0.0 and r2 > 0.0 and d > 0.0 and d <= r1 + r2 and d >= abs(r1 - r2):
            aa = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
            h = math.sqrt(max(r1 * r1 - aa * aa, 0.0))
            e = ((c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d)
            m = (c1[0] + e[0] * aa, c1[1] + e[1] * aa)
            perp = (-e[1], e[0])
            out.append((m[0] + perp[0] * h, m[1] + perp[1] * h))
            out.append((m[0] - perp[0] * h, m[1] - perp[1] * h))
    return out


class _LegNear:
    def __init__(self, path: Path, local, course: float, room: float):
        self.path, self.local, self.course, self.room = path, local, course, room

    @staticmethod
    def of(path: Path, at: Point, proj: _Aeqd, inbound: bool) -> Optional["_LegNear"]:
        if isinstance(path, GeodesicPath):
            length, start, end = inverse(path.from_, path.to)
            course = end if inbound else start
            local = ("line", (0.0, 0.0), _unit(course))
        else:
            arc = ArcGeometry(path)
            r = inverse(path.centre, at)[0]
            local = ("circle", proj.xy(path.centre), r, arc.clockwise)
            course = arc.course_at(at)
            length = arc.length_m()
        if length < MIN_LEG_M or math.isnan(length):
            return None
        return _LegNear(path, local, course, length / 2.0)

    def site_of(self, t, proj: _Aeqd, inbound: bool) -> Optional[Point]:
        if self.local[0] == "line":
            along = _dot(self.local[2], t)
            distance = -along if inbound else along
            if not (distance >= 0.0 and distance <= self.room):
                return None
            course = self.course + 180.0 if inbound else self.course
            return destination(proj.origin, course, distance)
        path = self.path
        arc = ArcGeometry(path)
        az = inverse(path.centre, proj.site(t))[1]
        az_w = inverse(path.centre, proj.origin)[1]
        if inbound:
            turned = angle_to_go(az, az_w, arc.clockwise)
        else:
            turned = angle_to_go(az_w, az, arc.clockwise)
        r = arc.radius_at(az)
        if turned <= 180.0 and math.radians(turned) * r <= self.room:
            return arc.at(az)
        return None


def _fillets(a, b, side: float, r: float) -> list:
    """The fillets (centre, tangent point on `a`, on `b`), nearest the origin first."""
    centres = _intersect(_offset(a, side, r), _offset(b, side, r))
    if len(centres) == 2 and _norm(centres[1]) < _norm(centres[0]):
        centres = [centres[1], centres[0]]
    out = []
    for f in centres:
        t1, t2 = _foot(a, f), _foot(b, f)
        if t1 is not None and t2 is not None:
            out.append((f, t1, t2))
    return out


def turn(inbound: Path, outbound: Path, fly_over: bool, radius_m: float) -> Turn:
    """The turn at the end of `inbound` onto `outbound` (geofence::turn::turn)."""
    at = inbound.to
    straight = Turn(STRAIGHT, at, at, ())
    proj = _Aeqd(at)
    a = _LegNear.of(inbound, at, proj, True)
    b = _LegNear.of(outbound, at, proj, False)
    if a is None or b is None:
        return straight
    delta = course_change(a.course, b.course)
    if abs(delta) < STRAIGHT_DEG or not radius_m > 0.0 or outbound.from_ != at:
        return straight
    side = 1.0 if delta > 0.0 else -1.0
    if not fly_over:
        t = _fly_by(a, b, proj, side, radius_m)
        if t is not None:
            return t
    t = _over(a, b, proj, delta, side, radius_m)
    return t if t is not None else Turn(ON_THE_SPOT, at, at, ())


def _fly_by(a: _LegNear, b: _LegNear, proj: _Aeqd, side: float, r: float) -> Optional[Turn]:
    for f, t1, t2 in _fillets(a.local, b.local, side, r):
        leave = a.site_of(t1, proj, True)
        if leave is None:
            continue
        join = b.site_of(t2, proj, False)
        if join is None:
            continue
        return Turn(FLY_BY, leave, join, (ArcPath(leave, join, proj.site(f), side > 0.0),))
    return None


def _over(
    a: _LegNear, b: _LegNear, proj: _Aeqd, delta: float, side: float, r: float
) -> Optional[Turn]:
    at = proj.origin
    half = math.cos(math.radians(abs(delta) / 2.0))
    chi = min(INTERCEPT_DEG, math.degrees(math.acos(min(max(half * half, -1.0), 1.0))))
    # The first turn: tangent to the inbound course at the waypoint, through delta + chi.
    centre = destination(at, a.course + side * 90.0, r)
    az_w = inverse(centre, at)[1]
    az_p = az_w + side * (abs(delta) + chi)
    p1 = destination(centre, az_p, r)
    course = a.course + side * (abs(delta) + chi)
    p, u = proj.xy(p1), _unit(course)
    for f, t1, t2 in _fillets(("line", p, u), b.local, -side, r):
        straight = _dot(u, (t1[0] - p[0], t1[1] - p[1]))
        if straight < -MIN_STRAIGHT_M:
            continue
        join = b.site_of(t2, proj, False)
        if join is None:
            continue
        paths = [ArcPath(at, p1, centre, side > 0.0)]
        if straight > MIN_STRAIGHT_M:
            e = proj.site(t1)
            paths.append(GeodesicPath(p1, e))
            intercept_end = e
        else:
            intercept_end = p1
        paths.append(ArcPath(intercept_end, join, proj.site(f), side < 0.0))
        return Turn(FLY_OVER, at, join, tuple(paths))
    return _s_turn(b, proj, centre, side, r)


def _s_turn(b: _LegNear, proj: _Aeqd, centre: Point, side: float, r: float) -> Optional[Turn]:
    """The fly-over's first turn straight into the reverse turn onto the outbound leg."""
    at = proj.origin
    first = ("circle", proj.xy(centre), r, side > 0.0)
    az_w = inverse(centre, at)[1]
    best = None
    for f, t1, t2 in _fillets(first, b.local, -side, r):
        join = b.site_of(t2, proj, False)
        if join is None:
            continue
        t1 = proj.site(t1)
        turned = angle_to_go(az_w, inverse(centre, t1)[1], side > 0.0)
        if best is not None and best[0] <= turned:
            continue
        paths = (ArcPath(at, t1, centre, side > 0.0), ArcPath(t1, join, proj.site(f), side < 0.0))
        best = (turned, Turn(FLY_OVER, at, join, paths))
    return None if best is None else best[1]


def remaining_on(path: Path, here: Point) -> float:
    """The remaining length of `path` from `here`, a point of it, metres."""
    if isinstance(path, GeodesicPath):
        return inverse(here, path.to)[0]
    arc = ArcGeometry(path)
    az = inverse(path.centre, here)[1]
    alpha = _to_go(arc, az)
    return math.radians(alpha) * (arc.radius_at(az) + arc.r1) / 2.0


def course_on(path: Path, here: Point) -> float:
    """The course over the ground at `here` (a point of `path`) flying along it, degrees:
    towards the geodesic's end, along the arc's tangent (guidance::tracking::course_on)."""
    if isinstance(path, GeodesicPath):
        return inverse(here, path.to)[1]
    return ArcGeometry(path).course_at(here)


def bank_on(path: Path, here: Point, v: float, crab_deg: float) -> float:
    """The bank flying along `path` at `here` at ground speed `v` with the crab angle
    `crab_deg`, degrees, positive right wing down: 0 on a geodesic; on an arc the bank that
    holds its radius there, to the right when it runs clockwise (guidance::tracking::bank_on)."""
    if isinstance(path, GeodesicPath):
        return 0.0
    arc = ArcGeometry(path)
    az = inverse(path.centre, here)[1]
    bank = bank_on_radius_deg(v, arc.radius_at(az), crab_deg)
    return bank if arc.clockwise else -bank


def heading_f32(heading_deg: float) -> float:
    """A heading in 0..360 as the payload's float, in 0..360 too: headings just below 360 that
    round to 360 in single precision are north, 0 (guidance::heading_f32)."""
    h = ctypes.c_float(heading_deg).value
    return h if h < 360.0 else 0.0


def _to_go(arc: ArcGeometry, az: float) -> float:
    alpha = angle_to_go(az, arc.az1, arc.clockwise)
    return 0.0 if alpha > arc.sweep and alpha > 180.0 else alpha


@dataclass
class Route:
    """Where the aircraft is on the route; indices are into the list's waypoints (see
    services/flight/src/guidance/route.rs `Route`)."""

    started: bool = False
    reversed: bool = False
    from_: int = 0
    to: Optional[int] = None
    complete: bool = False
    #: The leg to TO in full.
    leg: Optional[Path] = None
    #: The part of the leg still ahead once the turn onto it is flown.
    body: Optional[Path] = None
    #: The paths of the turn onto this leg not flown yet.
    turn: list = field(default_factory=list)
    serial: int = 0


def leg_speed(e: WaypointEntry) -> float:
    """The speed flown towards `e`: its commanded speed, or the fallback."""
    v = e.speed.mps()
    return v if v > 0.0 else FALLBACK_SPEED_MPS


def copy_of(payload: ctypes.Structure) -> ctypes.Structure:
    """A copy of a payload in this process's memory (a sample goes back to iceoryx2)."""
    return type(payload).from_buffer_copy(payload)


class Areas:
    """The area list for the zone tests (see the module documentation for the geometry)."""

    def __init__(self, areas: Optional[AreaListPayload] = None):
        self.fly_zone: Optional[list[Point]] = None
        #: (area ID, vertices) of every polygonal no-fly-zone, then circles as (ID, centre,
        #: radius): the fence's order.
        self.polygons: list[tuple[int, list[Point]]] = []
        self.circles: list[tuple[int, Point, float]] = []
        if areas is None or areas.generation == 0:
            return
        self.fly_zone = [point(v) for v in areas.fly_zone.used()]
        self.polygons = [(p.area_id, [point(v) for v in p.used()]) for p in areas.polygons()]
        self.circles = [
            (c.area_id, point(c.centre), distance_m(point(c.centre), point(c.border)))
            for c in areas.circles()
        ]

    @staticmethod
    def polygon_contains(vertices: list[Point], at: Point) -> bool:
        """Even-odd rule in the azimuthal equidistant projection about `at`."""
        if len(vertices) < contracts.MIN_POLYGON_VERTICES:
            return False
        xy = []
        for v in vertices:
            g = WGS84.Inverse(at[0], at[1], v[0], v[1], Geodesic.DISTANCE | Geodesic.AZIMUTH)
            a = math.radians(g["azi1"])
            xy.append((g["s12"] * math.sin(a), g["s12"] * math.cos(a)))
        inside = False
        for (x1, y1), (x2, y2) in zip(xy, xy[1:] + xy[:1]):
            # Does the edge cross the ray from the origin towards +x?
            if (y1 > 0.0) != (y2 > 0.0):
                x = x1 + (0.0 - y1) * (x2 - x1) / (y2 - y1)
                if x > 0.0:
                    inside = not inside
        return inside

    def inside_fly_zone(self, at: Point) -> bool:
        return self.fly_zone is not None and self.polygon_contains(self.fly_zone, at)

    def no_fly_zone_at(self, at: Point) -> int:
        """Area ID of the first no-fly-zone (polygons, then circles) containing `at`, else 0."""
        for area_id, vertices in self.polygons:
            if self.polygon_contains(vertices, at):
                return area_id
        for area_id, centre, radius in self.circles:
            if distance_m(centre, at) <= radius:
                return area_id
        return 0


def _empty_list() -> WaypointListPayload:
    return WaypointListPayload()


def _on_ground_state() -> AutomationStatePayload:
    state = AutomationStatePayload()
    state.flight_phase = FlightPhase.ON_GROUND
    return state


class Guidance:
    """The guidance model: flies the waypoint list through the flight phases of system
    automation (a port of missionlink_flight::guidance::Guidance; sans-IO like it: the driver hands it
    the lists and the automation state and calls `step` with the time)."""

    def __init__(self, config: GuidanceConfig):
        self.config = config.sanitized()
        self.list = _empty_list()
        self.waypoints: list[WaypointEntry] = []
        self.pending: Optional[WaypointListPayload] = None
        self.areas = Areas()
        self.automation = _on_ground_state()
        self.position: Point = (self.config.start_latitude_deg, self.config.start_longitude_deg)
        self.altitude_m = 0.0
        self.ground_speed_mps = 0.0
        #: Airspeed of the last stretch flown, m/s; 0 when not moving over the ground.
        self.airspeed_mps = 0.0
        #: Where the nose points, degrees 0..360; None before the first movement over the ground.
        self.heading_deg: Optional[float] = None
        #: Bank of the last stretch flown, degrees, positive right.
        self.roll_deg = 0.0
        #: Altitude gained over the last sub-step per simulated second, m/s.
        self.climb_rate_mps = 0.0
        self.climb_complete = False
        self.route = Route()
        self.planned = None
        self.last_step_ns: Optional[int] = None
        self.sequence = 0
        self.inside_fly_zone = False
        self.in_no_fly_zone = 0
        #: Warnings logged for leaving the fly-zone or entering a no-fly-zone.
        self.zone_warnings = 0

    # The inputs.

    def set_waypoint_list(self, waypoints: WaypointListPayload) -> None:
        """A waypoint list was published: a new generation is flown at once on the ground, in
        the air only once the automation state's `flown_waypoint_list` names it."""
        if waypoints.generation == self.list.generation:
            return
        if self.on_ground() or self.automation.flown_waypoint_list == waypoints.generation:
            self.adopt(copy_of(waypoints))
        else:
            self.pending = copy_of(waypoints)

    def set_area_list(self, areas: AreaListPayload) -> None:
        """An area list was published: kept for the zone tests."""
        self.areas = Areas(areas)
        # The aircraft did not move: the new status is taken without a warning.
        self.inside_fly_zone, self.in_no_fly_zone = self.zone_status()

    def set_automation(self, state: AutomationStatePayload) -> None:
        """The automation state changed."""
        turned = state.route_reversed and not self.automation.route_reversed
        if turned and not self.list.bidirectional:
            log.warning(
                "return to home requested on a route that is not bidirectional: ignored "
                "generation=%d",
                self.list.generation,
            )
        self.automation = copy_of(state)
        self.adopt_pending_if_due()

    def phase(self) -> Optional[FlightPhase]:
        return enum_or_none(FlightPhase, self.automation.flight_phase)

    # The step.

    def step(self, now_ns: int) -> GuidanceProgressPayload:
        """Integrates from the previous step to `now_ns` (CLOCK_MONOTONIC nanoseconds;
        simulated elapsed = real elapsed x time scale; nothing on the first call), in sub-steps
        of at most MAX_SUB_STEP_S simulated seconds, and returns the progress."""
        self.sequence += 1
        elapsed = 0.0 if self.last_step_ns is None else max(0, now_ns - self.last_step_ns) / 1e9
        self.last_step_ns = now_ns
        self.adopt_pending_if_due()

        phase = self.phase()
        if phase in (FlightPhase.TAKE_OFF, FlightPhase.CRUISE):
            self.start_route_if_needed()
        elif phase == FlightPhase.LANDING:
            pass
        else:
            self.altitude_m = 0.0
            self.climb_rate_mps = 0.0
            self.reset_route()
            self.climb_complete = False
        self.sync_direction()
        if phase != FlightPhase.CRUISE:
            self.hold_position()

        simulated = elapsed * self.config.time_scale
        if simulated > 0.0:
            n = max(math.ceil(simulated / MAX_SUB_STEP_S), 1)
            h = simulated / n
            for _ in range(n):
                before = self.altitude_m
                if phase == FlightPhase.TAKE_OFF:
                    busy = self.climb(h)
                elif phase == FlightPhase.CRUISE:
                    busy = self.fly(h)
                elif phase == FlightPhase.LANDING:
                    busy = self.descend(h)
                else:
                    busy = False
                # A sub-step that ends holding ends with no vertical speed.
                self.climb_rate_mps = (self.altitude_m - before) / h if busy else 0.0
                if not busy:
                    break

        self.check_zones()
        from_, to, next_ = self.triple(phase)
        on_ground = self.on_ground()
        if on_ground:
            roll, pitch, climb = 0.0, 0.0, 0.0
        else:
            pitch = math.degrees(math.atan2(self.climb_rate_mps, self.airspeed_mps))
            roll, climb = self.roll_deg, self.climb_rate_mps
        p = GuidanceProgressPayload(
            sequence=self.sequence,
            time_ns=now_ns,
            waypoint_list=self.list.generation,
            latitude_deg=self.position[0],
            longitude_deg=self.position[1],
            altitude_m=self.altitude_m,
            ground_speed_mps=self.ground_speed_mps,
            to=to,
            next=next_,
            in_no_fly_zone=self.in_no_fly_zone,
            inside_fly_zone=self.inside_fly_zone,
            trajectory_generation_active=phase == FlightPhase.CRUISE,
            climb_complete=self.climb_complete,
            route_complete=self.route.complete,
            on_ground=on_ground,
            heading_deg=math.nan if self.heading_deg is None else heading_f32(self.heading_deg),
            roll_deg=roll,
            pitch_deg=pitch,
            climb_rate_mps=climb,
        )
        p.from_ = from_
        return p

    def hold_position(self) -> None:
        """Not moving over the ground: no ground speed, no airspeed, no bank; the nose keeps
        pointing where it did."""
        self.ground_speed_mps = 0.0
        self.airspeed_mps = 0.0
        self.roll_deg = 0.0

    def on_ground(self) -> bool:
        """On the ground: before take-off, after touchdown, or in an unknown phase."""
        phase = self.phase()
        if phase in (FlightPhase.TAKE_OFF, FlightPhase.LANDING):
            return self.altitude_m <= 0.0
        return phase != FlightPhase.CRUISE

    # The route.

    def reset_route(self) -> None:
        """Back to a route not started; the planned turn goes with it."""
        self.route = Route()
        self.planned = None

    def adopt(self, waypoints: WaypointListPayload) -> None:
        self.list = waypoints
        self.waypoints = waypoints.used()
        self.pending = None
        self.reset_route()

    def adopt_pending_if_due(self) -> None:
        p = self.pending
        if p is not None and (
            self.on_ground() or self.automation.flown_waypoint_list == p.generation
        ):
            self.adopt(p)

    def reversal_wanted(self) -> bool:
        return bool(self.automation.route_reversed and self.list.bidirectional)

    def entry(self, index: Optional[int]) -> Optional[WaypointEntry]:
        if index is None or not 0 <= index < len(self.waypoints):
            return None
        return self.waypoints[index]

    def index_of(self, number: int) -> Optional[int]:
        for i, w in enumerate(self.waypoints):
            if w.number == number:
                return i
        return None

    def number(self, index: Optional[int]) -> int:
        e = self.entry(index)
        return 0 if e is None else e.number

    def start_route_if_needed(self) -> None:
        """Starts the route of the list flown: FROM 0, TO the first waypoint (or, reversed, the
        nearest one), flown direct."""
        if self.route.started:
            return
        reversed_ = self.reversal_wanted()
        if not self.waypoints:
            to = None
        elif reversed_:
            distances = [distance_m(self.position, point(w.position)) for w in self.waypoints]
            to = min(range(len(distances)), key=distances.__getitem__)
        else:
            to = 0
        here = self.position
        e = self.entry(to)
        first = GeodesicPath(here, here if e is None else point(e.position))
        self.route = Route(
            started=True,
            reversed=reversed_,
            from_=0,
            to=to,
            leg=first,
            body=first,
            turn=[],
            serial=self.route.serial + 1,
        )

    def sync_direction(self) -> None:
        """Applies a change of `route_reversed`: the TO waypoint stays, what follows it turns
        round; a complete route restarts from its final waypoint."""
        wanted = self.reversal_wanted()
        if not self.route.started or wanted == self.route.reversed:
            return
        self.route.reversed = wanted
        if self.route.complete:
            i = self.index_of(self.route.from_)
            nxt = None if i is None else self.next_index(i)
            if nxt is not None:
                self.route.complete = False
                self.enter(i, nxt, None)

    def end_index(self, to: int) -> int:
        """Index of the last waypoint of the route, seen from TO at `to`."""
        reversed_ = self.route.reversed
        land_at = self.automation.land_at
        if land_at != 0:
            i = self.index_of(land_at)
            if i is not None and ((not reversed_ and i >= to) or (reversed_ and i <= to)):
                return i
        return 0 if reversed_ else max(len(self.waypoints) - 1, 0)

    def next_index(self, to: int) -> Optional[int]:
        """Index of the waypoint after `to` on the route, None on the last leg."""
        end = self.end_index(to)
        if self.route.reversed:
            return to - 1 if to > end else None
        return to + 1 if to < end else None

    def leg_between(self, from_: int, to: int) -> Optional[Path]:
        """The leg flown from the waypoint at `from_` to the adjacent one at `to`."""
        a, b = self.entry(from_), self.entry(to)
        if a is None or b is None:
            return None
        if to > from_:
            return leg_path(a, b)
        return reversed_path(leg_path(b, a))

    def enter(self, from_: int, to: int, turn_: Optional[Turn]) -> None:
        """Starts the leg from the waypoint at `from_` to the one at `to`, joined after
        `turn_`."""
        self.route.from_ = self.number(from_)
        self.route.to = to
        self.route.serial += 1
        leg = self.leg_between(from_, to)
        if leg is None:
            return
        self.route.leg = leg
        self.route.body = leg if turn_ is None else rest_from(leg, turn_.join)
        self.route.turn = [] if turn_ is None else list(turn_.paths)

    def triple(self, phase: Optional[FlightPhase]) -> tuple[int, int, int]:
        if (
            phase in (FlightPhase.TAKE_OFF, FlightPhase.CRUISE, FlightPhase.LANDING)
            and self.route.started
        ):
            to = self.route.to
            nxt = None if to is None else self.next_index(to)
            return (self.route.from_, self.number(to), self.number(nxt))
        return (0, 0, 0)

    # The motion.

    def climb(self, h: float) -> bool:
        """One climb sub-step; False once at (or above) the take-off height."""
        target = max(self.list.take_off_height.metres(), 0.0)
        if self.altitude_m >= target:
            self.climb_complete = True
            return False
        self.altitude_m = min(self.altitude_m + self.config.climb_rate_mps * h, target)
        # Sums of sub-steps miss the height by rounding: a micrometre short is there.
        if self.altitude_m >= target - ALTITUDE_EPSILON_M:
            self.altitude_m = target
            self.climb_complete = True
        return True

    def descend(self, h: float) -> bool:
        """One descent sub-step; False once on the ground."""
        if self.altitude_m <= 0.0:
            self.altitude_m = 0.0
            return False
        self.altitude_m = max(self.altitude_m - self.config.descent_rate_mps * h, 0.0)
        if self.altitude_m <= ALTITUDE_EPSILON_M:
            self.altitude_m = 0.0
        return True

    def fly(self, h: float) -> bool:
        """One cruise sub-step of `h` seconds; False when holding (route complete, no list)."""
        left = h
        for _ in range(MAX_LEGS_PER_SUB_STEP):
            if left <= 0.0:
                break
            used = self.fly_leg(left)
            if used is None:
                self.hold_position()
                return False
            left -= used
        return True

    def planned_turn(self, to: int, nxt: int, over: bool) -> Optional[Turn]:
        """The turn at the TO waypoint (index `to`) onto the leg to `nxt`, planned once per
        leg."""
        p = self.planned
        if p is not None and p[0] == self.route.serial and p[1] == nxt and p[2] == over:
            return p[3]
        w, after = self.entry(to), self.entry(nxt)
        outbound = self.leg_between(to, nxt)
        if w is None or after is None or outbound is None:
            return None
        fly_over = over or enum_or_none(TurnType, w.turn_type) == TurnType.FLY_OVER
        # The radius at the speed flown in the turn (the next waypoint's) in the plan's wind.
        t = turn(self.route.leg, outbound, fly_over, self.turn_radius(leg_speed(after)))
        self.planned = (self.route.serial, nxt, over, t)
        return t

    def fly_leg(self, dt: float) -> Optional[float]:
        """Flies the route for up to `dt` seconds: the turn onto the leg, then the leg up to
        where the turn at TO starts. Returns the time used, None with nothing to fly."""
        to_index = self.route.to
        to = self.entry(to_index)
        if to_index is None or to is None:
            return None
        target = point(to.position)
        here = self.position
        # The TO waypoint's speed is the airspeed; the ground speed is the one on the course of
        # the path flown here, in the configured wind, and so are the heading and the bank.
        airspeed = leg_speed(to)
        flying = self.route.turn[0] if self.route.turn else self.route.body
        course = course_on(flying, here)
        v = self.config.ground_speed_mps(airspeed, course)
        crab = self.config.crab_deg(airspeed, course)
        self.ground_speed_mps = v
        self.airspeed_mps = airspeed
        self.heading_deg = self.config.heading_deg(airspeed, course)
        self.roll_deg = bank_on(flying, here, v, crab)
        budget = v * dt
        target_alt = to.altitude.metres()

        # The turn onto this leg.
        if self.route.turn:
            path = self.route.turn[0]
            remaining = remaining_on(path, here)
            ahead = remaining
            for other in self.route.turn[1:]:
                ahead += length_m(other)
            ahead += length_m(self.route.body)
            if remaining <= budget + REACHED_M:
                self.climb_towards(target_alt, max(remaining, 0.0), ahead)
                self.position = path.to
                self.route.turn.pop(0)
                return max(remaining, 0.0) / v
            self.climb_towards(target_alt, budget, ahead)
            self.advance(path, here, budget, airspeed)
            return dt

        # The leg, to the start of the turn at TO.
        nxt = self.next_index(to_index)
        planned = None if nxt is None else self.planned_turn(to_index, nxt, False)
        body_left = remaining_on(self.route.body, here)
        if (
            planned is not None
            and planned.kind == FLY_BY
            and body_left < remaining_on(self.route.body, planned.leave) - REACHED_M
        ):
            # Past the arc's start (NEXT changed late): over the waypoint instead.
            planned = self.planned_turn(to_index, nxt, True)
        if planned is not None and planned.kind == FLY_BY:
            end = planned.leave
            to_end = body_left - remaining_on(self.route.body, planned.leave)
        else:
            end, to_end = target, body_left
        if to_end <= budget + REACHED_M:
            used = max(to_end, 0.0)
            self.climb_towards(target_alt, used, used)
            self.position = end
            if end == target:
                self.altitude_m = target_alt
            if nxt is not None:
                self.enter(to_index, nxt, planned)
            else:
                self.route.from_ = to.number
                self.route.to = None
                self.route.complete = True
            return used / v
        self.climb_towards(target_alt, budget, to_end)
        self.advance(self.route.body, here, budget, airspeed)
        return dt

    def climb_towards(self, target: float, distance: float, ahead: float) -> None:
        """The altitude after `distance` metres of `ahead` still to fly to `target`."""
        if ahead <= distance or ahead <= 0.0:
            self.altitude_m = target
        else:
            self.altitude_m += (target - self.altitude_m) * distance / ahead

    def advance(self, path: Path, here: Point, distance: float, v: float) -> None:
        """Moves `distance` metres (less than what is left) along `path` from `here` (the
        look-ahead law on a geodesic, polar coordinates on an arc: services/flight/src/guidance/tracking.rs
        `advance`); `v` is the airspeed, which sizes the look-ahead."""
        if isinstance(path, GeodesicPath):
            length, course, _ = inverse(path.from_, path.to)
            d, az, _ = inverse(path.from_, here)
            along = d * math.cos(math.radians(az - course))
            look_ahead = max(self.turn_radius(v), MIN_LOOK_AHEAD_M)
            if along + look_ahead >= length:
                aim = path.to
            else:
                aim = destination(path.from_, course, along + look_ahead)
            self.position = destination(here, inverse(here, aim)[1], distance)
            return
        arc = ArcGeometry(path)
        az = inverse(path.centre, here)[1]
        rho = arc.radius_at(az)
        slope = (arc.r1 - arc.r0) / math.radians(arc.sweep) if arc.sweep > 0.0 else 0.0
        step = min(math.degrees(distance / math.hypot(rho, slope)), _to_go(arc, az))
        az = az + step if arc.clockwise else az - step
        self.position = arc.at(az)

    def turn_radius(self, v: float) -> float:
        """Radius of a turn flown at airspeed `v` in the plan's wind (the list's
        `planning_wind`), metres."""
        return self.config.radius_in_wind_m(v, self.list.planning_wind.mps())

    # The zones.

    def zone_status(self) -> tuple[bool, int]:
        return (
            self.areas.inside_fly_zone(self.position),
            self.areas.no_fly_zone_at(self.position),
        )

    def check_zones(self) -> None:
        """Updates the zone status; logs leaving the fly-zone and entering a no-fly-zone."""
        inside, nfz = self.zone_status()
        if self.inside_fly_zone and not inside:
            self.zone_warnings += 1
            log.warning(
                "left the fly-zone latitude_deg=%.7f longitude_deg=%.7f", *self.position
            )
        if nfz != 0 and nfz != self.in_no_fly_zone:
            self.zone_warnings += 1
            log.warning(
                "entered a no-fly-zone area_id=%d latitude_deg=%.7f longitude_deg=%.7f",
                nfz,
                *self.position,
            )
        self.inside_fly_zone = inside
        self.in_no_fly_zone = nfz


# ---------------------------------------------------------------------------------------------
# Pairing the lists (partitions/src/ipc.rs, ListPairing; docs/design.md "Activation is atomic").
# ---------------------------------------------------------------------------------------------


class ListPairing:
    """Releases the newest waypoint list and area list only as a pair of one activation, newer
    than the pair released before; until then the partition keeps the pair it has. Lists
    older than those held or released (a dead predecessor's port) are ignored."""

    def __init__(self) -> None:
        self.waypoints: Optional[WaypointListPayload] = None
        self.areas: Optional[AreaListPayload] = None
        self.released: Optional[int] = None
        #: How often the newest lists were of different activations.
        self.mismatched = 0

    def _newest(self, held: Optional[ctypes.Structure]) -> Optional[int]:
        known = [] if held is None else [held.activation]
        if self.released is not None:
            known.append(self.released)
        return max(known) if known else None

    def offer_waypoints(self, waypoints: WaypointListPayload) -> None:
        newest = self._newest(self.waypoints)
        if newest is not None and waypoints.activation < newest:
            log.debug("an older waypoint list arrived: ignored activation=%d", waypoints.activation)
            return
        self.waypoints = copy_of(waypoints)

    def offer_areas(self, areas: AreaListPayload) -> None:
        newest = self._newest(self.areas)
        if newest is not None and areas.activation < newest:
            log.debug("an older area list arrived: ignored activation=%d", areas.activation)
            return
        self.areas = copy_of(areas)

    def take(self) -> Optional[tuple[WaypointListPayload, AreaListPayload]]:
        w, a = self.waypoints, self.areas
        if w is None or a is None:
            return None
        if not contracts.same_activation(w, a):
            self.mismatched += 1
            return None
        if self.released is not None and w.activation <= self.released:
            return None
        self.released = w.activation
        return (w, a)


# ---------------------------------------------------------------------------------------------
# The partition: iceoryx2 services opened as partitions/src/ipc.rs opens them.
# ---------------------------------------------------------------------------------------------

T = TypeVar("T", bound=ctypes.Structure)

#: The node's name (iceoryx2's node list shows it).
NODE_NAME = "guidance-py"
#: Progress is published on every change and at least this often, nanoseconds.
REPUBLISH_NS = 1_000_000_000
#: The position is logged this often, nanoseconds.
POSITION_LOG_NS = 5_000_000_000


class Ports:
    """The iceoryx2 side: a node that cleans up dead nodes on start, and each service's
    publish-subscribe port paired with an event port of the same name, with the QoS of
    `FccService::qos()` (missionlink_contracts.SERVICE_*) so that Rust and Python open the
    same services whoever comes first."""

    def __init__(self, iox2, prefix: str):
        self.iox2 = iox2
        self.prefix = prefix
        self.node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(NODE_NAME))
            .create(iox2.ServiceType.Ipc)
        )
        cleanup = self.node.try_cleanup_dead_nodes()
        if getattr(cleanup, "cleanups", 0) or getattr(cleanup, "failed_cleanups", 0):
            log.info("removed the resources of dead nodes %s", cleanup)
        self._ports: list = []

    def _name(self, service: contracts.Service):
        return self.iox2.ServiceName.new(service.name(self.prefix))

    def _pubsub(self, service: contracts.Service, payload: type[T]):
        q = service.qos
        return (
            self.node.service_builder(self._name(service))
            .publish_subscribe(payload)
            .history_size(q.history_size)
            .subscriber_max_buffer_size(q.subscriber_max_buffer_size)
            .max_publishers(q.max_publishers)
            .max_subscribers(q.max_subscribers)
            .enable_safe_overflow(q.safe_overflow)
            .open_or_create()
        )

    def _event(self, service: contracts.Service):
        q = service.qos
        return (
            self.node.service_builder(self._name(service))
            .event()
            .max_notifiers(q.max_publishers)
            .max_listeners(q.max_listeners)
            .open_or_create()
        )

    def publisher(self, service: contracts.Service, payload: type[T]) -> "Publisher":
        # A subscriber that stopped must never block this publisher (ipc.rs: DiscardData).
        publisher = (
            self._pubsub(service, payload)
            .publisher_builder()
            .backpressure_strategy(self.iox2.BackpressureStrategy.DiscardData)
            .create()
        )
        notifier = self._event(service).notifier_builder().create()
        self._ports += [notifier, publisher]
        return Publisher(service, publisher, notifier)

    def subscriber(self, service: contracts.Service, payload: type[T]) -> "Subscriber":
        subscriber = self._pubsub(service, payload).subscriber_builder().create()
        listener = self._event(service).listener_builder().create()
        self._ports += [listener, subscriber]
        return Subscriber(service, payload, subscriber, listener)

    def close(self) -> None:
        """Releases every port, newest first (the node goes with the last reference)."""
        for port in reversed(self._ports):
            port.delete()
        self._ports = []


class Publisher:
    """A publisher with its notifier: every sample is followed by a notification."""

    def __init__(self, service: contracts.Service, publisher, notifier):
        self.service = service
        self.publisher = publisher
        self.notifier = notifier

    def send(self, value: ctypes.Structure) -> None:
        self.publisher.loan_uninit().write_payload(value).send()
        self.notifier.notify()

    def update_connections(self) -> None:
        """Connects subscribers that joined since the last send (late joiners get history)."""
        self.publisher.update_connections()


class Subscriber:
    """A subscriber with the listener to attach to the WaitSet."""

    def __init__(self, service: contracts.Service, payload: type[T], subscriber, listener):
        self.service = service
        self.payload = payload
        self.subscriber = subscriber
        self.listener = listener

    def drain_notifications(self) -> None:
        """Consumes the pending notifications (a WaitSet spins on a listener not drained)."""
        self.listener.try_wait()

    def for_each(self, f: Callable[[ctypes.Structure], None]) -> int:
        """Hands a copy of every waiting sample to `f`, oldest first."""
        n = 0
        while True:
            sample = self.subscriber.receive()
            if sample is None:
                return n
            value = self.payload.from_buffer_copy(sample.payload().contents)
            sample.delete()
            f(value)
            n += 1

    def take_all(self, f: Callable[[ctypes.Structure], None]) -> int:
        """Every waiting sample, the notifications drained, then a second look (as ipc.rs)."""
        first = self.for_each(f)
        self.drain_notifications()
        return first + self.for_each(f)

    def latest(self) -> Optional[ctypes.Structure]:
        last = []
        self.for_each(last.append)
        return last[-1] if last else None


def changed(last: Optional[GuidanceProgressPayload], p: GuidanceProgressPayload) -> bool:
    """Whether `p` differs from `last` in anything but the counters (sequence, time)."""
    if last is None:
        return True
    a, b = copy_of(last), copy_of(p)
    for x in (a, b):
        x.sequence = 0
        x.time_ns = 0
    return bytes(a) != bytes(b)


def run(args: argparse.Namespace) -> int:
    """Runs the partition until SIGTERM or SIGINT; the exit status."""
    import iceoryx2 as iox2

    # Without a config file iceoryx2 warns at every start: errors only, unless IOX2_LOG_LEVEL.
    iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
    ports = Ports(iox2, args.service_prefix)
    waypoints = ports.subscriber(contracts.SERVICE_MISSION_WAYPOINT_LIST, WaypointListPayload)
    areas = ports.subscriber(contracts.SERVICE_MISSION_AREA_LIST, AreaListPayload)
    automation = ports.subscriber(contracts.SERVICE_AUTOMATION_STATE, AutomationStatePayload)
    progress = ports.publisher(contracts.SERVICE_GUIDANCE_PROGRESS, GuidanceProgressPayload)
    heartbeat = ports.publisher(contracts.SERVICE_HEALTH_GUIDANCE, HeartbeatPayload)

    guidance = Guidance(
        GuidanceConfig(
            start_latitude_deg=args.start_latitude,
            start_longitude_deg=args.start_longitude,
            climb_rate_mps=args.climb_rate,
            descent_rate_mps=args.descent_rate,
            max_bank_deg=args.max_bank_deg,
            time_scale=args.time_scale,
            wind_speed_mps=args.wind_speed_mps,
            wind_from_deg=args.wind_from_deg,
        )
    )
    pairing = ListPairing()
    period_ns = args.heartbeat_period_ms * 1_000_000
    pid = os.getpid()
    beats = 0

    def beat() -> None:
        nonlocal beats
        beats += 1
        heartbeat.send(
            HeartbeatPayload(
                sequence=beats, time_ns=time.monotonic_ns(), period_ns=period_ns, pid=pid
            )
        )

    last_published: Optional[GuidanceProgressPayload] = None
    last_sent_ns = 0
    last_position_log_ns = 0

    def step() -> None:
        nonlocal last_published, last_sent_ns, last_position_log_ns
        automation.drain_notifications()
        waypoints.take_all(pairing.offer_waypoints)
        areas.take_all(pairing.offer_areas)
        # Only whole pairs of one activation, both set before the next step.
        pair = pairing.take()
        if pair is not None:
            w, a = pair
            log.info(
                "waypoint list received generation=%d waypoints=%d activation=%d",
                w.generation,
                w.count,
                w.activation,
            )
            log.info(
                "area list received generation=%d areas=%d activation=%d",
                a.generation,
                a.area_count(),
                a.activation,
            )
            guidance.set_waypoint_list(w)
            guidance.set_area_list(a)
        state = automation.latest()
        if state is not None:
            guidance.set_automation(state)
        now = time.monotonic_ns()
        p = guidance.step(now)
        if last_published is None or p.from_to_next() != last_published.from_to_next():
            log.info("from-to-next from=%d to=%d next=%d", *p.from_to_next())
        if changed(last_published, p) or now - last_sent_ns >= REPUBLISH_NS:
            progress.send(p)
            last_published = p
            last_sent_ns = now
        progress.update_connections()
        heartbeat.update_connections()
        if now - last_position_log_ns >= POSITION_LOG_NS:
            last_position_log_ns = now
            log.info(
                "position latitude=%.7f longitude=%.7f altitude=%.2f from=%d to=%d next=%d",
                p.latitude_deg,
                p.longitude_deg,
                p.altitude_m,
                *p.from_to_next(),
            )

    waitset = iox2.WaitSetBuilder.new().create(iox2.ServiceType.Ipc)
    guards = [waitset.attach_notification(s.listener) for s in (waypoints, areas, automation)]
    tick = waitset.attach_interval(iox2.Duration.from_millis(args.update_interval_ms))
    pulse = waitset.attach_interval(iox2.Duration.from_millis(args.heartbeat_period_ms))

    log.info(
        "guidance up prefix=%s time_scale=%s heartbeat_period_ms=%d pid=%d",
        args.service_prefix,
        args.time_scale,
        args.heartbeat_period_ms,
        pid,
    )
    # The first heartbeat and progress at once: automation and mission data handling need not
    # wait a period for them.
    beat()
    step()
    try:
        while True:
            attachments, result = waitset.wait_and_process()
            if result in (
                iox2.WaitSetRunResult.TerminationRequest,
                iox2.WaitSetRunResult.Interrupt,
            ):
                break
            if any(a.has_event_from(pulse) for a in attachments):
                beat()
            step()
    except KeyboardInterrupt:
        pass
    log.info("guidance stopping heartbeats=%d steps=%d", beats, guidance.sequence)
    for guard in [pulse, tick, *guards]:
        guard.delete()
    waitset.delete()
    ports.close()
    return 0


def parse_args(argv: Optional[list[str]] = None) -> argparse.Namespace:
    d = GuidanceConfig()
    parser = argparse.ArgumentParser(
        description="Guidance partition of the FCC in Python (replaces guidance-stub)."
    )
    parser.add_argument(
        "--service-prefix",
        default=contracts.DEFAULT_SERVICE_PREFIX,
        help="iceoryx2 service-name prefix of the FCC (default: %(default)s)",
    )
    parser.add_argument(
        "--time-scale",
        type=float,
        default=d.time_scale,
        help="simulated seconds per second (default: %(default)s)",
    )
    for flag, default, what in [
        ("--start-latitude", d.start_latitude_deg, "start latitude, degrees (TROL)"),
        ("--start-longitude", d.start_longitude_deg, "start longitude, degrees (TROL)"),
        ("--climb-rate", d.climb_rate_mps, "take-off climb rate, m/s"),
        ("--descent-rate", d.descent_rate_mps, "landing descent rate, m/s"),
        ("--max-bank-deg", d.max_bank_deg, "bank of the turns, degrees (their radius)"),
        (
            "--wind-speed-mps",
            d.wind_speed_mps,
            "speed of the steady wind flown in, m/s (turns are sized by the plan's wind)",
        ),
        ("--wind-from-deg", d.wind_from_deg, "direction the wind blows from, degrees true"),
    ]:
        text = what + " (default: %(default)s)"
        parser.add_argument(flag, type=float, default=default, help=text)
    parser.add_argument(
        "--update-interval-ms",
        type=int,
        default=50,
        help="integrate and publish at least this often (default: %(default)s, as the stub)",
    )
    parser.add_argument(
        "--heartbeat-period-ms",
        type=int,
        default=contracts.DEFAULT_HEARTBEAT_PERIOD_MS,
        help="beat on fcc/health/guidance this often; at most the FCC's [health] period_ms "
        "(default: %(default)s)",
    )
    parser.add_argument(
        "--log-level", default="INFO", help="DEBUG, INFO, WARNING or ERROR (default: %(default)s)"
    )
    args = parser.parse_args(argv)
    if args.update_interval_ms <= 0 or args.heartbeat_period_ms <= 0:
        parser.error("--update-interval-ms and --heartbeat-period-ms must be above 0")
    return args


def _terminate(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def main(argv: Optional[list[str]] = None) -> int:
    # SIGTERM before the WaitSet exists (iceoryx2 then handles SIGTERM and SIGINT itself and
    # ends the loop) ends the start as SIGINT does: cleanly.
    signal.signal(signal.SIGTERM, _terminate)
    args = parse_args(argv)
    logging.basicConfig(
        stream=sys.stderr,
        level=getattr(logging, str(args.log_level).upper(), logging.INFO),
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    try:
        return run(args)
    except KeyboardInterrupt:
        log.info("guidance stopped while starting")
        return 0
    except ImportError as e:
        log.error(
            "%s: install the requirements "
            "(python3 -m pip install -r partitions/python/requirements.txt)",
            e,
        )
        return 2


if __name__ == "__main__":
    sys.exit(main())
