//! What the safety gateway reports: each violation with its code, the element it concerns,
//! the margin or the value against its limit and a position for the map; the report of them
//! all, and the mission's energy estimate.

use core::fmt;

use missionlink_protocol::geofence::flown_route::RouteElement;

/// What a violation concerns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Element {
    /// A waypoint, by number.
    Waypoint(u16),
    /// A leg of the route, forward or on the reverse route (the geofence's names for them:
    /// `from` 0 is the leg from the take-off position).
    Route(RouteElement),
    /// The take-off (point or height).
    TakeOff,
    /// An area, by ID.
    Area(u16),
    /// The area list as a whole (no fly-zone, too many no-fly-zones).
    AreaList,
    /// The mission as a whole.
    Mission,
    /// The environment.
    Environment,
}

impl fmt::Display for Element {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Waypoint(n) => write!(f, "waypoint {n}"),
            Self::Route(leg) => write!(f, "{leg}"),
            Self::TakeOff => f.write_str("take-off"),
            Self::Area(id) => write!(f, "area {id}"),
            Self::AreaList => f.write_str("area list"),
            Self::Mission => f.write_str("mission"),
            Self::Environment => f.write_str("environment"),
        }
    }
}

/// One check that failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ViolationCode {
    /// `PLAN-TAKEOFF`: the plan has no take-off position.
    TakeOffMissing,
    /// `GEO-FZ-WP`: a waypoint outside the fly-zone shrunk by the safety offset.
    FlyZoneWaypoint,
    /// `GEO-FZ-LEG`: a leg (line or arc) leaves the fly-zone shrunk by the safety offset.
    FlyZoneLeg,
    /// `GEO-FZ-TO`: the take-off point outside the fly-zone shrunk by the safety offset.
    FlyZoneTakeOff,
    /// `GEO-NFZ-WP`: a waypoint inside a no-fly-zone grown by the safety offset.
    NoFlyZoneWaypoint,
    /// `GEO-NFZ-LEG`: a leg (line or arc) enters a no-fly-zone grown by the safety offset.
    NoFlyZoneLeg,
    /// `GEO-NFZ-TO`: the take-off point inside a no-fly-zone grown by the safety offset.
    NoFlyZoneTakeOff,
    /// `AREA-SELF-INTERSECT`: a polygon's border crosses or touches itself.
    SelfIntersection,
    /// `AREA-REPEATED-VERTEX`: two consecutive vertices of a polygon are the same point.
    RepeatedVertex,
    /// `AREA-DEGENERATE`: a polygon with (nearly) zero area, its vertices collinear.
    DegeneratePolygon,
    /// `AREA-CIRCLE-RADIUS`: a circle whose radius is (nearly) zero.
    CircleRadius,
    /// `AREA-VERTEX-COUNT`: a polygon with fewer than 3 vertices.
    VertexCount,
    /// `AREA-NFZ-COUNT`: more than ten no-fly-zones.
    NoFlyZoneCount,
    /// `AREA-FZ-COUNT`: not exactly one fly-zone.
    FlyZoneCount,
    /// `AREA-FZ-SHAPE`: the fly-zone is not a polygon.
    FlyZoneShape,
    /// `AREA-NFZ-OUTSIDE`: a no-fly-zone entirely outside the fly-zone.
    NoFlyZoneOutside,
    /// `AREA-ALT-BOUNDS`: an area's lower altitude bound above its upper one.
    AltitudeBounds,
    /// `AREA-ALT`: a waypoint altitude outside the fly-zone's altitude bounds.
    AreaAltitude,
    /// `ROUTE-RF-RADIUS`: a radius-to-fix leg's start and end radius differ beyond tolerance.
    RfRadiusMismatch,
    /// `ROUTE-TURN-RADIUS`: a radius-to-fix radius below the minimum turn radius.
    TurnRadius,
    /// `ROUTE-SPEED-MIN`: a waypoint speed below the envelope.
    SpeedLow,
    /// `ROUTE-SPEED-MAX`: a waypoint speed above the envelope.
    SpeedHigh,
    /// `ROUTE-ALT-MAX`: a waypoint altitude above the aircraft's maximum.
    AltitudeHigh,
    /// `ROUTE-TOH-MIN`: take-off height below its limit.
    TakeOffHeightLow,
    /// `ROUTE-TOH-MAX`: take-off height above its limit.
    TakeOffHeightHigh,
    /// `ENERGY-BUDGET`: the estimated energy exceeds usable energy minus reserve.
    EnergyBudget,
    /// `ENERGY-TRACK`: a leg's or a turn's track cannot be held against the wind.
    TrackNotHeld,
    /// `ENERGY-RETURN`: the mission with a return to home from its last waypoint (a
    /// bidirectional route) exceeds usable energy minus reserve.
    EnergyReturn,
    /// `ENV-WIND`: wind above the limit.
    Wind,
    /// `ENV-TEMP`: temperature outside the limits.
    Temperature,
    /// `FLEET-SEP`: a path of the mission comes closer to a path of another vehicle's active
    /// mission than the fleet's separation, horizontally and vertically
    /// ([`super::separation`]).
    Separation,
}

impl ViolationCode {
    /// The stable short code.
    pub fn code(&self) -> &'static str {
        match self {
            Self::TakeOffMissing => "PLAN-TAKEOFF",
            Self::FlyZoneWaypoint => "GEO-FZ-WP",
            Self::FlyZoneLeg => "GEO-FZ-LEG",
            Self::FlyZoneTakeOff => "GEO-FZ-TO",
            Self::NoFlyZoneWaypoint => "GEO-NFZ-WP",
            Self::NoFlyZoneLeg => "GEO-NFZ-LEG",
            Self::NoFlyZoneTakeOff => "GEO-NFZ-TO",
            Self::SelfIntersection => "AREA-SELF-INTERSECT",
            Self::RepeatedVertex => "AREA-REPEATED-VERTEX",
            Self::DegeneratePolygon => "AREA-DEGENERATE",
            Self::CircleRadius => "AREA-CIRCLE-RADIUS",
            Self::VertexCount => "AREA-VERTEX-COUNT",
            Self::NoFlyZoneCount => "AREA-NFZ-COUNT",
            Self::FlyZoneCount => "AREA-FZ-COUNT",
            Self::FlyZoneShape => "AREA-FZ-SHAPE",
            Self::NoFlyZoneOutside => "AREA-NFZ-OUTSIDE",
            Self::AltitudeBounds => "AREA-ALT-BOUNDS",
            Self::AreaAltitude => "AREA-ALT",
            Self::RfRadiusMismatch => "ROUTE-RF-RADIUS",
            Self::TurnRadius => "ROUTE-TURN-RADIUS",
            Self::SpeedLow => "ROUTE-SPEED-MIN",
            Self::SpeedHigh => "ROUTE-SPEED-MAX",
            Self::AltitudeHigh => "ROUTE-ALT-MAX",
            Self::TakeOffHeightLow => "ROUTE-TOH-MIN",
            Self::TakeOffHeightHigh => "ROUTE-TOH-MAX",
            Self::EnergyBudget => "ENERGY-BUDGET",
            Self::TrackNotHeld => "ENERGY-TRACK",
            Self::EnergyReturn => "ENERGY-RETURN",
            Self::Wind => "ENV-WIND",
            Self::Temperature => "ENV-TEMP",
            Self::Separation => "FLEET-SEP",
        }
    }
}

impl fmt::Display for ViolationCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.code())
    }
}

/// One violation.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// Which check.
    pub code: ViolationCode,
    /// What it concerns.
    pub element: Element,
    /// Readable explanation.
    pub detail: String,
    /// Signed closest approach, metres (negative: that deep into the forbidden band).
    pub margin_m: Option<f64>,
    /// The value checked (unit in `detail`).
    pub value: Option<f64>,
    /// Its limit.
    pub limit: Option<f64>,
    /// Latitude and longitude (degrees) of the closest approach or of the element, for the map.
    pub position: Option<(f64, f64)>,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}: {}", self.code, self.element, self.detail)?;
        if let Some(m) = self.margin_m {
            write!(f, "; margin {m:.1} m")?;
        }
        if let (Some(v), Some(l)) = (self.value, self.limit) {
            write!(f, "; value {v:.2}, limit {l:.2}")?;
        }
        if let Some((lat, lon)) = self.position {
            write!(f, " at ({lat:.6}, {lon:.6})")?;
        }
        Ok(())
    }
}

/// Everything the gateway found against a mission.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// Every violation, in check order: plan, environment, areas, route, geography, energy.
    pub violations: Vec<Violation>,
    /// The wind speed the turns were checked in, m/s (ICD §7 "Turns in wind"; 0: calm).
    pub turn_wind_mps: f64,
}

impl fmt::Display for Report {
    /// One line per violation, then the wind the turns were checked in.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for v in &self.violations {
            writeln!(f, "{v}")?;
        }
        match self.turn_wind_mps {
            w if w > 0.0 => write!(
                f,
                "(turns checked in a wind of {w} m/s from any direction, ICD §7 \"Turns in wind\")"
            ),
            _ => f.write_str("(turns checked in calm air)"),
        }
    }
}

/// The energy estimate of a mission, Wh.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyEstimate {
    /// Vertical climb to the take-off height and on to the first waypoint's altitude.
    pub take_off_wh: f64,
    /// Legs and turns as flown, with the climbs along them.
    pub cruise_wh: f64,
    /// Vertical descent from the last waypoint.
    pub landing_wh: f64,
    /// The sum.
    pub total_wh: f64,
    /// Usable energy minus the reserve.
    pub limit_wh: f64,
    /// On a bidirectional route: a return to home from the last waypoint, the reverse route
    /// with its turns and the landing at the initial waypoint (in place of [`Self::landing_wh`]).
    pub return_wh: Option<f64>,
}

impl EnergyEstimate {
    /// The flight with the return to home from the last waypoint, Wh (a bidirectional route).
    pub fn with_return_wh(&self) -> Option<f64> {
        self.return_wh
            .map(|r| self.take_off_wh + self.cruise_wh + r)
    }
}
