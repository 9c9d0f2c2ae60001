//! The safety gateway (paper §2.2): every check a mission must pass on the GCS before
//! it is uploaded. [`SafetyGateway::violations`] reports **every** violation, each with a stable code
//! ([`ViolationCode::code`]), the element concerned ([`Element`]), the margin in metres or the
//! value against its limit, and a position for the map.
//!
//! # The checks
//!
//! - **Plan** (`PLAN-*`): the plan must say where the aircraft takes off
//!   (`MissionPlan::take_off_position`); without it the climb and the way to the initial waypoint
//!   cannot be checked, and the plan is refused.
//! - **Geographic** (`GEO-*`), on the [geofence](crate::geofence) (ICD §4 "Geometry", §7): the
//!   take-off point (the vertical climb to the take-off height: areas are 2-D), the leg from the
//!   take-off point to the initial waypoint (flown direct, as guidance flies it), every waypoint,
//!   every leg in the direction flown (track-to-fix legs as WGS-84 geodesics, radius-to-fix legs
//!   as arcs around their centre in their turn direction), the turn at every waypoint as
//!   guidance flies it ([`crate::geofence::turn`], at the profile's bank: the fly-by arc of
//!   radius `r = v²/(g·tan(bank))` tangent to both legs, the fly-over's turn, intercept and turn
//!   onto the next leg), the reverse route of a bidirectional route back to its start with its
//!   turns and the turn round of a return to home at every waypoint, and the landing (a vertical descent at the last waypoint, checked
//!   as that waypoint's point) must stay inside the fly-zone shrunk by the safety offset and
//!   outside every no-fly-zone (polygon or circle) grown by it. The margin is the signed
//!   geodesic distance in metres beyond the offset: positive = clear by that much, negative =
//!   that deep into the forbidden band, with the position of the closest approach or of the
//!   deepest point.
//!   - *Reverse route*: a reversed track-to-fix leg is the same geodesic and a reversed
//!     radius-to-fix leg the same arc in the other direction. Where a reversed leg gives the
//!     same violation as the forward leg (same code and area, margin within
//!     [`SAME_MARGIN_M`]), it is reported once on the forward leg ([`RouteElement::Leg`]) with "also on the
//!     reverse route"; anything else is reported on the [`RouteElement::ReverseLeg`].
//!   - *One defect, one violation*: a leg that touches a waypoint already violating the same area
//!     is reported only if the leg goes deeper than that waypoint by more than
//!     [`SUBSUMED_M`] (a waypoint inside a no-fly-zone makes both its legs enter it; that is one
//!     defect). Geographic checks against an area whose geometry is invalid are skipped: the
//!     area's own violation says why.
//! - **Area geometry** (`AREA-*`): the rules of ICD §7 on the unchecked list, each defect a
//!   violation naming the area: exactly one fly-zone, a polygon; at most ten no-fly-zones;
//!   polygons of at least 3 vertices, no two consecutive vertices equal, simple (no two edges
//!   cross or touch except neighbours at their shared vertex, geodesic edges), with non-zero
//!   area; circles with a radius of at least [`MIN_CIRCLE_RADIUS_M`]; and beyond ICD §7: each
//!   no-fly-zone at least partly inside the fly-zone; lower altitude bound not above the upper;
//!   every waypoint altitude inside the fly-zone's altitude bounds where given.
//! - **Route** (`ROUTE-*`): radius-to-fix start and end radius equal within
//!   [`AircraftProfile::rf_radius_tolerance_m`]; radius-to-fix radius not below the minimum turn
//!   radius `r = v²/(g·tan(bank))` for the worst-case ground speed `v` = the leg's speed plus the
//!   wind speed; waypoint speeds inside the envelope; waypoint altitudes not above the maximum;
//!   take-off height inside its limits. A fly-by turn the legs are too short for is no route
//!   violation: guidance flies it over, and that path is checked geographically.
//! - **Energy** (`ENERGY-*`, [`SafetyGateway::estimate_energy`]): vertical climb to the take-off
//!   height at the climb rate and climb power; every leg (the one from the take-off point
//!   included) at its TO waypoint's speed as airspeed with the power model
//!   [`AircraftProfile::cruise_power_w`], its time from the ground speed along the track with the
//!   wind (per chord of the geofence's pieces); altitude gained on a leg costs climb power for
//!   `Δh / climb rate` on top (altitude lost is not credited); the landing a vertical descent
//!   from the last waypoint's altitude at the descent rate and descent power. Compared against
//!   usable energy × (1 − reserve). A leg whose track cannot be held against the wind (crosswind
//!   ≥ airspeed, or no forward ground speed) is its own violation (`ENERGY-TRACK`) and left out
//!   of the sum.
//! - **Environment** (`ENV-*`): wind speed and temperature inside the profile's limits.
//!
//! # Geometry
//!
//! All of it is the geofence's ([`crate::geofence`]): the same code the FCC runs for its
//! onboard check. How exact it is, and the table that shows it against GeographicLib, are
//! there.
//!
//! # What is approximated
//!
//! - Altitudes are heights above the take-off ground whatever their altitude type (as guidance
//!   takes them); no terrain, no geoid. Areas are 2-D (ICD §7): no-fly-zones are taken as
//!   unbounded in altitude; only the fly-zone's altitude bounds are checked against waypoints.
//! - Waypoint speeds are taken as true airspeed (indicated ≈ true at these altitudes).
//!
//! # Not checked
//!
//! - The energy of the turns (the legs are counted in full, which is longer than the turns'
//!   short cuts of the corners save, except behind fly-over intercepts).
//! - The energy of a return-to-home on a bidirectional route (covered by the reserve).

use core::fmt;

use missionlink_interfaces::wire::{AreaShape, AreaType, GeoPoint, LegType, SpecificData};

use crate::geofence::earth::{self, Site};
use crate::geofence::onboard::{self, RouteElement, RouteView, RouteWaypoint};
use crate::geofence::path::{Path, Track};
use crate::geofence::zone::Fence;
use crate::transfer::areas::AreaList;
use crate::transfer::mission::{Mission, WaypointRecord};

// The five check groups of the module documentation, each with the code it alone uses.
mod area;
mod energy;
mod environment;
mod geography;
mod route;

/// Standard gravity, m/s².
const GRAVITY_MPS2: f64 = 9.806_65;

/// A leg reversed gives "the same" margin as forward within this, metres.
pub const SAME_MARGIN_M: f64 = 0.5;
/// A leg ending at a waypoint that violates the same area is reported only if it goes deeper
/// than that waypoint by more than this, metres.
pub const SUBSUMED_M: f64 = 1.0;
/// Smallest circle radius accepted, metres.
pub const MIN_CIRCLE_RADIUS_M: f64 = 1.0;
/// Smallest polygon area accepted (below: collinear or degenerate), square metres.
pub const MIN_POLYGON_AREA_M2: f64 = 1.0;
/// No-fly-zones the FCC holds at most (ICD §7).
const MAX_NO_FLY_ZONES: usize = missionlink_interfaces::capacity::MAX_NO_FLY_ZONES;

/// The aircraft's limits and its power model.
///
/// The [`Default`] is the demo eVTOL of the medical evacuation (the paper gives no figures;
/// these are this project's plausible choice for a ~150 kg multicopter-type cargo eVTOL):
///
/// | field | default |
/// |---|---|
/// | speed envelope | 5 to 40 m/s |
/// | bank limit | 25° (minimum turn radius 137 m at 25 m/s; the guidance stub's bank, so that the fly-by turns checked are the ones flown) |
/// | take-off height | 10 to 100 m above ground |
/// | maximum altitude | 150 m |
/// | usable battery energy, reserve | 6000 Wh, 30 % |
/// | climb rate, climb power | 3 m/s, 22 kW |
/// | descent rate, descent power | 2 m/s, 12 kW |
/// | cruise power | `P(v) = 8 kW + 20 W/(m/s)²·(v − 25 m/s)²` |
/// | wind limit | 12 m/s |
/// | temperature | −20 to 45 °C |
/// | RF radius tolerance | 5 m |
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AircraftProfile {
    /// Lowest commanded speed on a leg, m/s.
    pub min_speed_mps: f64,
    /// Highest commanded speed on a leg, m/s.
    pub max_speed_mps: f64,
    /// Bank angle limit, degrees (0 < bank < 90).
    pub max_bank_deg: f64,
    /// Lowest take-off height, metres above ground.
    pub min_take_off_height_m: f64,
    /// Highest take-off height, metres above ground.
    pub max_take_off_height_m: f64,
    /// Highest waypoint altitude, metres.
    pub max_altitude_m: f64,
    /// Usable battery energy, Wh.
    pub usable_energy_wh: f64,
    /// Fraction of the usable energy kept as reserve (0..1).
    pub reserve_fraction: f64,
    /// Vertical climb rate, m/s.
    pub climb_rate_mps: f64,
    /// Power in hover and vertical climb, W.
    pub climb_power_w: f64,
    /// Vertical descent rate, m/s.
    pub descent_rate_mps: f64,
    /// Power in vertical descent, W.
    pub descent_power_w: f64,
    /// Cruise power at the best-endurance speed, W.
    pub cruise_min_power_w: f64,
    /// Speed of least cruise power, m/s.
    pub best_speed_mps: f64,
    /// Cruise power growth away from the best speed, W/(m/s)².
    pub cruise_power_k_w_per_mps2: f64,
    /// Highest wind speed, m/s.
    pub max_wind_mps: f64,
    /// Lowest operating temperature, °C.
    pub min_temperature_c: f64,
    /// Highest operating temperature, °C.
    pub max_temperature_c: f64,
    /// Largest difference of a radius-to-fix leg's start and end radius, metres.
    pub rf_radius_tolerance_m: f64,
}

impl Default for AircraftProfile {
    fn default() -> Self {
        Self {
            min_speed_mps: 5.0,
            max_speed_mps: 40.0,
            max_bank_deg: 25.0,
            min_take_off_height_m: 10.0,
            max_take_off_height_m: 100.0,
            max_altitude_m: 150.0,
            usable_energy_wh: 6000.0,
            reserve_fraction: 0.3,
            climb_rate_mps: 3.0,
            climb_power_w: 22_000.0,
            descent_rate_mps: 2.0,
            descent_power_w: 12_000.0,
            cruise_min_power_w: 8_000.0,
            best_speed_mps: 25.0,
            cruise_power_k_w_per_mps2: 20.0,
            max_wind_mps: 12.0,
            min_temperature_c: -20.0,
            max_temperature_c: 45.0,
            rf_radius_tolerance_m: 5.0,
        }
    }
}

impl AircraftProfile {
    /// Cruise power at airspeed `v`: `P_min + k·(v − v_best)²`, W.
    pub fn cruise_power_w(&self, airspeed_mps: f64) -> f64 {
        let dv = airspeed_mps - self.best_speed_mps;
        self.cruise_min_power_w + self.cruise_power_k_w_per_mps2 * dv * dv
    }

    /// Minimum turn radius at ground speed `v` and the bank limit: `v²/(g·tan(bank))`, metres.
    pub fn min_turn_radius_m(&self, speed_mps: f64) -> f64 {
        speed_mps * speed_mps / (GRAVITY_MPS2 * self.max_bank_deg.to_radians().tan())
    }

    /// Energy the mission may use: usable energy minus the reserve, Wh.
    pub fn energy_limit_wh(&self) -> f64 {
        self.usable_energy_wh * (1.0 - self.reserve_fraction)
    }
}

/// The conditions at the time of the flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Environment {
    /// Wind speed, m/s.
    pub wind_speed_mps: f64,
    /// Direction the wind blows from, degrees clockwise from true north.
    pub wind_from_deg: f64,
    /// Outside air temperature, °C.
    pub temperature_c: f64,
}

impl Default for Environment {
    /// Calm, 15 °C (ISA sea level).
    fn default() -> Self {
        Self {
            wind_speed_mps: 0.0,
            wind_from_deg: 0.0,
            temperature_c: 15.0,
        }
    }
}

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
    /// `ENERGY-TRACK`: a leg's track cannot be held against the wind.
    TrackNotHeld,
    /// `ENV-WIND`: wind above the limit.
    Wind,
    /// `ENV-TEMP`: temperature outside the limits.
    Temperature,
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
            Self::Wind => "ENV-WIND",
            Self::Temperature => "ENV-TEMP",
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
}

impl fmt::Display for Report {
    /// One line per violation.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, v) in self.violations.iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "{v}")?;
        }
        Ok(())
    }
}

/// The energy estimate of a mission, Wh.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyEstimate {
    /// Vertical climb to the take-off height and on to the first waypoint's altitude.
    pub take_off_wh: f64,
    /// Legs, with the climbs along them.
    pub cruise_wh: f64,
    /// Vertical descent from the last waypoint.
    pub landing_wh: f64,
    /// The sum.
    pub total_wh: f64,
    /// Usable energy minus the reserve.
    pub limit_wh: f64,
}

/// The safety gateway.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SafetyGateway {
    /// The aircraft.
    pub profile: AircraftProfile,
    /// The conditions.
    pub environment: Environment,
}

impl crate::ground_station::SafetyGateway for SafetyGateway {
    type Report = Report;

    fn check(
        &self,
        mission: &Mission,
        areas: &AreaList,
        take_off: Option<GeoPoint>,
    ) -> Result<(), Report> {
        let violations = self.violations(mission, areas, take_off);
        if violations.is_empty() {
            Ok(())
        } else {
            Err(Report { violations })
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Legs.

/// One leg as the checks take it.
#[derive(Debug, Clone, Copy)]
struct Leg {
    /// What it is (a leg, or a path of a turn at a waypoint).
    element: RouteElement,
    from: u16,
    to: u16,
    /// Index in the mission of the FROM waypoint (None: the take-off point).
    from_index: Option<usize>,
    to_index: usize,
    path: Path,
    /// Flown backwards on return to home too (a bidirectional route; not the way from the
    /// take-off point).
    reversible: bool,
    speed_mps: f64,
    climb_m: f64,
}

fn rf_centre(record: &WaypointRecord) -> Option<GeoPoint> {
    match record.rf_centre.map(|c| c.data) {
        Some(SpecificData::RfCentre {
            latitude,
            longitude,
            ..
        }) => Some(GeoPoint {
            latitude,
            longitude,
        }),
        _ => None,
    }
}

fn position(record: &WaypointRecord) -> GeoPoint {
    GeoPoint {
        latitude: record.waypoint.latitude,
        longitude: record.waypoint.longitude,
    }
}

fn exceeds(value: f64, limit: f64) -> bool {
    value.is_nan() || value > limit
}

fn below(value: f64, limit: f64) -> bool {
    value.is_nan() || value < limit
}

// ---------------------------------------------------------------------------------------------
// The checks.

#[derive(Default)]
struct Collector {
    out: Vec<Violation>,
}

impl Collector {
    fn push(
        &mut self,
        code: ViolationCode,
        element: Element,
        detail: String,
        value_limit: Option<(f64, f64)>,
    ) {
        self.out.push(Violation {
            code,
            element,
            detail,
            margin_m: None,
            value: value_limit.map(|v| v.0),
            limit: value_limit.map(|v| v.1),
            position: None,
        });
    }

    fn at(&mut self, p: impl earth::Position) {
        if let Some(v) = self.out.last_mut() {
            v.position = Some(p.lat_lon_deg());
        }
    }
}

impl SafetyGateway {
    /// A gateway for `profile` in `environment`.
    pub fn new(profile: AircraftProfile, environment: Environment) -> Self {
        Self {
            profile,
            environment,
        }
    }

    /// The legs in the order flown: from the take-off point to the initial waypoint (when the
    /// plan says where that is), then between the waypoints; the geofence's route
    /// ([`onboard`]), which the FCC checks too.
    fn legs(mission: &Mission, take_off: Option<GeoPoint>) -> Vec<Leg> {
        let route = RouteView::from(mission);
        let entries = route.waypoints;
        let toh = route.take_off_height.metres();
        let mut legs = Vec::with_capacity(entries.len() + 1);
        if let (Some(t), Some(first)) = (take_off, entries.first()) {
            legs.push(Leg {
                element: RouteElement::Leg {
                    from: 0,
                    to: first.number(),
                },
                from: 0,
                to: first.number(),
                from_index: None,
                to_index: 0,
                path: Path::Geodesic {
                    from: Site::of(t),
                    to: Site::of(first.position()),
                },
                reversible: false,
                speed_mps: first.speed().mps(),
                climb_m: (first.altitude().metres() - toh).max(0.0),
            });
        }
        for (i, (leg, w)) in onboard::legs(route).zip(entries.windows(2)).enumerate() {
            let [a, b] = w else { continue };
            legs.push(Leg {
                element: leg.element,
                from: a.number(),
                to: b.number(),
                from_index: Some(i),
                to_index: i + 1,
                path: leg.path,
                reversible: route.bidirectional,
                speed_mps: b.speed().mps(),
                climb_m: (b.altitude().metres() - a.altitude().metres()).max(0.0),
            });
        }
        legs
    }

    /// The turns at the waypoints as guidance flies them (at the profile's bank,
    /// [`crate::geofence::turn`]): forward from the take-off point, and on a bidirectional
    /// route the way back from the last waypoint and the turn round at every waypoint where a
    /// return to home may start. Paths the legs between the waypoints do not cover.
    fn turns(&self, mission: &Mission, take_off: Option<GeoPoint>) -> Vec<Leg> {
        let route = RouteView::from(mission);
        let entries = route.waypoints;
        let fly_by = onboard::FlyBy {
            bank_deg: self.profile.max_bank_deg,
        };
        let index = |n: u16| entries.iter().position(|w| w.number() == n);
        let start = take_off
            .map(Site::of)
            .or(entries.first().map(|w| Site::of(w.position())));
        let last = entries.last();
        let forward = start
            .into_iter()
            .flat_map(|s| onboard::execute_route(route, s, Some(fly_by)));
        let bidirectional = route.bidirectional;
        // The way back from the last waypoint (`to` 0: the route complete); the turns round
        // at the waypoints are `turns_round`'s.
        let back = last
            .filter(|_| bidirectional)
            .into_iter()
            .flat_map(|w| onboard::return_route(route, Site::of(w.position()), 0, Some(fly_by)));
        let round = bidirectional
            .then(|| onboard::turns_round(route, fly_by))
            .into_iter()
            .flatten();
        forward
            .chain(back)
            .chain(round)
            .filter_map(|leg| match leg.element {
                RouteElement::Turn { at, to, .. } => {
                    let (from_index, to_index) = (index(at)?, index(to)?);
                    let speed_mps = entries.get(to_index).map_or(0.0, |w| w.speed().mps());
                    Some(Leg {
                        element: leg.element,
                        from: at,
                        to,
                        from_index: Some(from_index),
                        to_index,
                        path: leg.path,
                        reversible: false,
                        speed_mps,
                        climb_m: 0.0,
                    })
                }
                _ => None,
            })
            .collect()
    }

    /// The energy estimate of `mission` flown from `take_off`.
    pub fn estimate_energy(&self, mission: &Mission, take_off: Option<GeoPoint>) -> EnergyEstimate {
        let legs = Self::legs(mission, take_off);
        self.energy(mission, take_off.is_some(), &legs).0
    }

    /// Every violation of `mission` in `areas` flown from `take_off` (empty: the mission
    /// passes).
    pub fn violations(
        &self,
        mission: &Mission,
        areas: &AreaList,
        take_off: Option<GeoPoint>,
    ) -> Vec<Violation> {
        let mut c = Collector::default();
        // The groups in report order: plan, environment, area geometry, route, geography,
        // energy.
        if take_off.is_none() {
            c.push(
                ViolationCode::TakeOffMissing,
                Element::TakeOff,
                "the plan does not say where the aircraft takes off: the climb and the way to the initial waypoint cannot be checked".into(),
                None,
            );
        }
        self.check_environment(&mut c);
        let fence = Fence::of_list(areas);
        let valid = self.check_areas(areas, &fence, &mut c);
        let legs = Self::legs(mission, take_off);
        self.check_route(mission, areas, &legs, &mut c);
        let mut flown = legs.clone();
        flown.extend(self.turns(mission, take_off));
        self.check_geography(mission, take_off, &fence, &valid, &flown, &mut c);
        self.check_energy(mission, take_off.is_some(), &legs, &mut c);
        c.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ground_station::SafetyGateway as _;
    use crate::testkit::{self, CCP, FLY_ZONE, NFZ_POLYGON, TROL, circle, polygon};
    use missionlink_interfaces::wire::{Angle, AreaPolygonLoopSegment, TurnDirection};

    fn geo((lat, lon): (f64, f64)) -> GeoPoint {
        GeoPoint {
            latitude: Angle::from_degrees(lat).unwrap(),
            longitude: Angle::from_degrees(lon).unwrap(),
        }
    }
    use missionlink_interfaces::wire::{Altitude, SafetyOffset, Speed, UaPositionWaypoint};
    use proptest::prelude::*;

    const W1: (f64, f64) = (48.278, 11.658);
    const ROLE2: (f64, f64) = (48.28, 11.68);
    const RF_CENTRE: (f64, f64) = (48.27455, 11.66991);

    #[derive(Clone, Copy)]
    struct Wp {
        at: (f64, f64),
        alt: f64,
        speed: f64,
        rf: Option<((f64, f64), TurnDirection)>,
    }

    fn tf(at: (f64, f64)) -> Wp {
        Wp {
            at,
            alt: 120.0,
            speed: 25.0,
            rf: None,
        }
    }

    fn rf(at: (f64, f64), centre: (f64, f64), dir: TurnDirection) -> Wp {
        Wp {
            rf: Some((centre, dir)),
            ..tf(at)
        }
    }

    /// Waypoints numbered 1, 2, ... in flight-plan order, the route starting at 1.
    fn mission(take_off_height: f64, bidirectional: bool, wps: &[Wp]) -> Mission {
        let mut waypoints = heapless::Vec::new();
        for (i, w) in wps.iter().enumerate() {
            let n = i as u16 + 1;
            let next = if i + 1 == wps.len() { 0 } else { n + 1 };
            let leg = if w.rf.is_some() {
                LegType::RadiusToFix
            } else {
                LegType::TrackToFix
            };
            let waypoint = UaPositionWaypoint {
                altitude: Altitude::from_metres(w.alt).unwrap(),
                speed: Speed::from_mps(w.speed).unwrap(),
                ..testkit::waypoint(n, next, w.at, leg)
            };
            let rf_centre = w.rf.map(|(centre, dir)| testkit::rf_centre(n, centre, dir));
            waypoints
                .push(WaypointRecord {
                    waypoint,
                    rf_centre,
                })
                .unwrap();
        }
        Mission {
            take_off: testkit::take_off(take_off_height),
            route: testkit::route(1, bidirectional),
            waypoints,
            mission_id: None,
        }
    }

    fn area_list(areas: &[AreaPolygonLoopSegment]) -> AreaList {
        AreaList {
            safety_offset: SafetyOffset::from_metres(25.0).unwrap(),
            areas: areas.iter().cloned().collect(),
        }
    }

    fn fly_zone() -> AreaPolygonLoopSegment {
        polygon(1, AreaType::FlyZone, &FLY_ZONE)
    }

    fn mission_2_areas() -> Vec<AreaPolygonLoopSegment> {
        vec![
            fly_zone(),
            circle(2, (48.268, 11.675), (48.268, 11.679)),
            polygon(3, AreaType::NoFlyZone, &NFZ_POLYGON),
        ]
    }

    fn mission_1() -> Mission {
        mission(30.0, false, &[tf(CCP)])
    }

    fn mission_2_with(w1: Wp, role2: Wp) -> Mission {
        mission(30.0, true, &[tf(CCP), w1, role2])
    }

    fn mission_2() -> Mission {
        mission_2_with(tf(W1), rf(ROLE2, RF_CENTRE, TurnDirection::Clockwise))
    }

    struct Case {
        name: &'static str,
        gateway: SafetyGateway,
        take_off: Option<GeoPoint>,
        mission: Mission,
        areas: AreaList,
        expected: Vec<(ViolationCode, Element)>,
    }

    fn case(
        name: &'static str,
        mission: Mission,
        areas: &[AreaPolygonLoopSegment],
        expected: &[(ViolationCode, Element)],
    ) -> Case {
        Case {
            name,
            gateway: SafetyGateway::default(),
            take_off: Some(geo(TROL)),
            mission,
            areas: area_list(areas),
            expected: expected.to_vec(),
        }
    }

    fn leg(from: u16, to: u16) -> Element {
        Element::Route(RouteElement::Leg { from, to })
    }

    /// The turn round of a return to home at `at` back to `to` (a U-turn: flown over).
    fn turn_round(at: u16, to: u16) -> Element {
        Element::Route(RouteElement::Turn {
            at,
            to,
            kind: crate::geofence::turn::TurnKind::FlyOver,
        })
    }

    /// In a function of its own: a debug build keeps every case's temporaries in the frame of
    /// the function that builds it, and test threads have 2 MB of stack.
    fn fly_by_corner_case() -> Case {
        let corner = testkit::fly_by_corner();
        let lists = corner.assemble().unwrap();
        Case {
            take_off: corner.take_off_position,
            ..case(
                "a fly-by arc enters a no-fly-zone inside its corner (testkit::fly_by_corner)",
                lists.mission,
                &lists.areas.areas,
                &[(
                    ViolationCode::NoFlyZoneLeg,
                    Element::Route(RouteElement::Turn {
                        at: 2,
                        to: 3,
                        kind: crate::geofence::turn::TurnKind::FlyBy,
                    }),
                )],
            )
        }
    }

    fn cases() -> Vec<Case> {
        use ViolationCode as V;
        let m2 = mission_2_areas();
        let mut with_outside_nfz = m2.clone();
        with_outside_nfz.push(circle(4, (48.30, 11.66), (48.30, 11.663)));
        let bow_tie = [
            (48.255, 11.635),
            (48.285, 11.690),
            (48.255, 11.690),
            (48.285, 11.635),
        ];
        let mut self_intersecting = m2.clone();
        self_intersecting[0] = polygon(1, AreaType::FlyZone, &bow_tie);
        let mut repeated = m2.clone();
        repeated[2] = polygon(
            3,
            AreaType::NoFlyZone,
            &[
                (48.262, 11.640),
                (48.262, 11.646),
                (48.266, 11.646),
                (48.262, 11.646),
            ],
        );
        let mut collinear = m2.clone();
        collinear[2] = polygon(
            3,
            AreaType::NoFlyZone,
            &[(48.262, 11.640), (48.263, 11.641), (48.264, 11.642)],
        );
        let mut bounded = fly_zone();
        bounded.upper_altitude = Some(Altitude::from_metres(100.0).unwrap());
        let mut gateway_small_battery = SafetyGateway::default();
        gateway_small_battery.profile.usable_energy_wh = 600.0;
        let windy = SafetyGateway::new(
            AircraftProfile::default(),
            Environment {
                wind_speed_mps: 15.0,
                wind_from_deg: 270.0,
                temperature_c: 15.0,
            },
        );
        let hot = SafetyGateway::new(
            AircraftProfile::default(),
            Environment {
                temperature_c: 50.0,
                ..Environment::default()
            },
        );
        let fast_w1 = Wp {
            speed: 45.0,
            ..tf(W1)
        };
        let role2_rf = rf(ROLE2, RF_CENTRE, TurnDirection::Clockwise);
        vec![
            case("demo mission 1", mission_1(), &[fly_zone()], &[]),
            Case {
                take_off: None,
                ..case(
                    "demo mission 1 without a take-off position",
                    mission_1(),
                    &[fly_zone()],
                    &[(V::TakeOffMissing, Element::TakeOff)],
                )
            },
            Case {
                take_off: Some(geo((48.264, 11.643))),
                ..case(
                    "take-off inside a no-fly-zone",
                    mission_2(),
                    &m2,
                    &[(V::NoFlyZoneTakeOff, Element::TakeOff)],
                )
            },
            Case {
                take_off: Some(geo((48.250, 11.660))),
                ..case(
                    "take-off outside the fly-zone (the way in is the same defect)",
                    mission_2(),
                    &m2,
                    &[(V::FlyZoneTakeOff, Element::TakeOff)],
                )
            },
            Case {
                take_off: Some(geo((48.258, 11.643))),
                ..case(
                    "the way from the take-off point to the initial waypoint crosses a no-fly-zone",
                    mission_2(),
                    &m2,
                    &[(V::NoFlyZoneLeg, leg(0, 1))],
                )
            },
            case(
                "no fly-zone",
                mission_2(),
                &m2[1..],
                &[(V::FlyZoneCount, Element::AreaList)],
            ),
            fly_by_corner_case(),
            case(
                "a no-fly-zone of two vertices",
                mission_2(),
                &[
                    fly_zone(),
                    polygon(
                        3,
                        AreaType::NoFlyZone,
                        &[(48.262, 11.640), (48.266, 11.646)],
                    ),
                ],
                &[(V::VertexCount, Element::Area(3))],
            ),
            case("demo mission 2", mission_2(), &m2, &[]),
            case(
                "demo mission 2, last leg track-to-fix",
                mission_2_with(tf(W1), tf(ROLE2)),
                &m2,
                &[],
            ),
            case(
                "leg cuts a no-fly-zone corner, both waypoints outside",
                mission(
                    30.0,
                    true,
                    &[
                        tf(CCP),
                        tf((48.268, 11.643)),
                        tf((48.263, 11.650)),
                        tf(W1),
                        role2_rf,
                    ],
                ),
                &m2,
                &[(V::NoFlyZoneLeg, leg(2, 3))],
            ),
            case(
                "RF arc bulges out of the fly-zone",
                mission_2_with(
                    tf(W1),
                    rf(ROLE2, (48.279, 11.669), TurnDirection::Clockwise),
                ),
                &m2,
                &[(V::FlyZoneLeg, leg(2, 3))],
            ),
            case(
                "self-intersecting fly-zone",
                mission_2(),
                &self_intersecting,
                &[(V::SelfIntersection, Element::Area(1))],
            ),
            case(
                "no-fly-zone with a repeated vertex",
                mission_2(),
                &repeated,
                &[(V::RepeatedVertex, Element::Area(3))],
            ),
            case(
                "collinear no-fly-zone",
                mission_2(),
                &collinear,
                &[(V::DegeneratePolygon, Element::Area(3))],
            ),
            Case {
                gateway: gateway_small_battery,
                ..case(
                    "energy budget infeasible",
                    mission_2(),
                    &m2,
                    &[(V::EnergyBudget, Element::Mission)],
                )
            },
            case(
                "turn too tight",
                mission(
                    30.0,
                    true,
                    &[
                        tf(CCP),
                        tf(W1),
                        rf(
                            (48.27854, 11.658809),
                            (48.278, 11.658809),
                            TurnDirection::Clockwise,
                        ),
                        tf(ROLE2),
                    ],
                ),
                &m2,
                &[(V::TurnRadius, leg(2, 3))],
            ),
            case(
                "waypoint inside a no-fly-zone",
                mission_2_with(tf((48.268, 11.675)), tf(ROLE2)),
                &m2,
                &[(V::NoFlyZoneWaypoint, Element::Waypoint(2))],
            ),
            case(
                "RF start and end radii differ",
                mission_2_with(
                    tf(W1),
                    rf(ROLE2, (48.27455, 11.67021), TurnDirection::Clockwise),
                ),
                &m2,
                &[(V::RfRadiusMismatch, leg(2, 3))],
            ),
            // At 45 m/s the turn round at ROLE2 back to W1 (flown at W1's speed) has a radius
            // of 443 m and leaves the fly-zone.
            case(
                "speed above the envelope",
                mission_2_with(fast_w1, role2_rf),
                &m2,
                &[
                    (V::SpeedHigh, Element::Waypoint(2)),
                    (V::FlyZoneLeg, turn_round(3, 2)),
                ],
            ),
            case(
                "take-off height too high",
                mission(150.0, true, &[tf(CCP), tf(W1), role2_rf]),
                &m2,
                &[(V::TakeOffHeightHigh, Element::TakeOff)],
            ),
            case(
                "no-fly-zone completely outside the fly-zone",
                mission_2(),
                &with_outside_nfz,
                &[(V::NoFlyZoneOutside, Element::Area(4))],
            ),
            case(
                "waypoint above the fly-zone's upper altitude",
                mission_1(),
                &[bounded],
                &[(V::AreaAltitude, Element::Waypoint(1))],
            ),
            Case {
                gateway: windy,
                ..case(
                    "wind over the limit",
                    mission_2(),
                    &m2,
                    &[(V::Wind, Element::Environment)],
                )
            },
            Case {
                gateway: hot,
                ..case(
                    "temperature over the limit",
                    mission_2(),
                    &m2,
                    &[(V::Temperature, Element::Environment)],
                )
            },
            Case {
                gateway: windy,
                ..case(
                    "two defects: speed and wind",
                    mission_2_with(fast_w1, role2_rf),
                    &m2,
                    &[
                        (V::Wind, Element::Environment),
                        (V::SpeedHigh, Element::Waypoint(2)),
                        (V::FlyZoneLeg, turn_round(3, 2)),
                    ],
                )
            },
        ]
    }

    #[test]
    fn safety_gateway_table() {
        // The table is built as one array of some thirty missions of 27 kB each: more than a
        // test thread's 2 MB of stack in a debug build.
        std::thread::Builder::new()
            .stack_size(32 << 20)
            .spawn(run_safety_gateway_table)
            .unwrap()
            .join()
            .unwrap();
    }

    fn run_safety_gateway_table() {
        let mut failures = Vec::new();
        for c in cases() {
            let found: Vec<(ViolationCode, Element)> =
                match c.gateway.check(&c.mission, &c.areas, c.take_off) {
                    Ok(()) => vec![],
                    Err(report) => {
                        assert!(!report.violations.is_empty(), "{}", c.name);
                        report
                            .violations
                            .iter()
                            .map(|v| (v.code, v.element))
                            .collect()
                    }
                };
            let report = c.gateway.violations(&c.mission, &c.areas, c.take_off);
            println!("{}:", c.name);
            for v in &report {
                println!("    {v}");
            }
            if found != c.expected {
                failures.push(format!(
                    "{}: expected {:?}, found {:?}",
                    c.name, c.expected, found
                ));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    #[test]
    fn safety_gateway_margins_and_positions() {
        let g = SafetyGateway::default();
        // The corner cut: the leg passes the corner (48.266, 11.646) inside by a few tens of
        // metres plus the offset.
        let m = mission(
            30.0,
            false,
            &[tf(CCP), tf((48.268, 11.643)), tf((48.263, 11.650))],
        );
        let v = g.violations(&m, &area_list(&mission_2_areas()), Some(geo(TROL)));
        let [cut] = v.as_slice() else { panic!("{v:?}") };
        let margin = cut.margin_m.unwrap();
        assert!(margin < -25.0 && margin > -80.0, "{margin}");
        let (lat, lon) = cut.position.unwrap();
        assert!((lat - 48.266).abs() < 0.0005 && (lon - 11.646).abs() < 0.0005);
        // A circle: the exact depth is radius + offset at the centre.
        let m = mission_2_with(tf((48.268, 11.675)), tf(ROLE2));
        let v = g.violations(&m, &area_list(&mission_2_areas()), Some(geo(TROL)));
        let radius = earth::distance_m(geo((48.268, 11.675)), geo((48.268, 11.679)));
        assert!(
            (v[0].margin_m.unwrap() + radius + 25.0).abs() < 0.5,
            "{v:?}"
        );
        // The report prints one line per violation.
        let report = Report { violations: v };
        assert_eq!(report.to_string().lines().count(), report.violations.len());
    }

    #[test]
    fn safety_gateway_energy_estimate_of_mission_2() {
        let g = SafetyGateway::default();
        let e = g.estimate_energy(&mission_2(), Some(geo(CCP)));
        // 10 s + 30 s of climb at 22 kW, ~3 km at 25 m/s at 8 kW, 60 s of descent at 12 kW.
        assert!(e.total_wh > 600.0 && e.total_wh < 800.0, "{e:?}");
        assert_eq!(e.limit_wh, 4200.0);
        // Headwind on the whole route costs more than calm air.
        let windy = SafetyGateway::new(
            AircraftProfile::default(),
            Environment {
                wind_speed_mps: 10.0,
                wind_from_deg: 90.0,
                temperature_c: 15.0,
            },
        );
        let w = windy.estimate_energy(&mission_2(), Some(geo(CCP)));
        assert!(w.cruise_wh > e.cruise_wh, "{w:?} {e:?}");
    }

    #[test]
    fn safety_gateway_codes_are_distinct() {
        use ViolationCode as V;
        let all = [
            V::TakeOffMissing,
            V::VertexCount,
            V::NoFlyZoneCount,
            V::FlyZoneWaypoint,
            V::FlyZoneLeg,
            V::FlyZoneTakeOff,
            V::NoFlyZoneWaypoint,
            V::NoFlyZoneLeg,
            V::NoFlyZoneTakeOff,
            V::SelfIntersection,
            V::RepeatedVertex,
            V::DegeneratePolygon,
            V::CircleRadius,
            V::FlyZoneCount,
            V::FlyZoneShape,
            V::NoFlyZoneOutside,
            V::AltitudeBounds,
            V::AreaAltitude,
            V::RfRadiusMismatch,
            V::TurnRadius,
            V::SpeedLow,
            V::SpeedHigh,
            V::AltitudeHigh,
            V::TakeOffHeightLow,
            V::TakeOffHeightHigh,
            V::EnergyBudget,
            V::TrackNotHeld,
            V::Wind,
            V::Temperature,
        ];
        let codes: std::collections::HashSet<&str> = all.iter().map(|c| c.code()).collect();
        assert_eq!(codes.len(), all.len());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Waypoints well inside the fly-zone and far from both no-fly-zones (the box
        /// 48.270..48.282 N, 11.640..11.660 E: over 400 m from every border) give no violation.
        #[test]
        fn safety_gateway_waypoints_well_inside_pass(
            a in (48.270f64..48.282, 11.640f64..11.660),
            b in (48.270f64..48.282, 11.640f64..11.660),
            bidirectional in any::<bool>(),
        ) {
            let m = mission(30.0, bidirectional, &[tf(CCP), tf(a), tf(b)]);
            let v = SafetyGateway::default().violations(&m, &area_list(&mission_2_areas()), Some(geo(TROL)));
            prop_assert!(v.is_empty(), "{:?}", v);
        }

        /// A waypoint at distance d from the circular no-fly-zone's centre violates it exactly
        /// when d < radius + offset (away from the boundary by more than the sampling).
        #[test]
        fn safety_gateway_circle_boundary(bearing in 0.0f64..360.0, d in 150.0f64..500.0) {
            let centre = geo((48.268, 11.675));
            let radius = earth::distance_m(centre, geo((48.268, 11.679)));
            prop_assume!((d - radius - 25.0).abs() > 0.01);
            let at = earth::destination(centre, bearing, d);
            let m = mission(30.0, false, &[tf((at.y(), at.x()))]);
            let areas = area_list(&mission_2_areas());
            let v = SafetyGateway::default().violations(&m, &areas, Some(geo(TROL)));
            let inside = v.iter().any(|v| v.code == ViolationCode::NoFlyZoneWaypoint);
            prop_assert_eq!(inside, d < radius + 25.0, "{:?}", v);
        }
    }
}
