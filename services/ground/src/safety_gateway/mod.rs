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
//! - **Geographic** (`GEO-*`), on the [geofence](missionlink_protocol::geofence) (ICD §4 "Geometry", §7): the
//!   take-off point (the vertical climb to the take-off height: areas are 2-D), the leg from the
//!   take-off point to the initial waypoint (flown direct, as guidance flies it), every waypoint,
//!   every leg in the direction flown (track-to-fix legs as WGS-84 geodesics, radius-to-fix legs
//!   as arcs around their centre in their turn direction), the turn at every waypoint as
//!   guidance flies it ([`missionlink_protocol::geofence::turn`], at the profile's bank: the fly-by arc of
//!   radius `r = (v + W)²/(g·tan(bank))` tangent to both legs, the fly-over's turn, intercept
//!   and turn onto the next leg; `W` the wind, below), the reverse route of a bidirectional route back to its start with its
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
//!   wind speed the turns are checked in; waypoint speeds inside the envelope; waypoint altitudes not above the maximum;
//!   take-off height inside its limits. A fly-by turn the legs are too short for is no route
//!   violation: guidance flies it over, and that path is checked geographically.
//! - **Energy** (`ENERGY-*`, [`SafetyGateway::estimate_energy`]): vertical climb to the take-off
//!   height at the climb rate and climb power; the route as flown (the one from the take-off
//!   point included): every leg at its TO waypoint's speed as airspeed, less the parts its turns
//!   cut short, and every turn's paths at the speed flown in it, with the power model
//!   [`AircraftProfile::cruise_power_w`], their time from the ground speed along the track with
//!   the wind (per chord of the geofence's pieces); altitude gained on a leg costs climb power for
//!   `Δh / climb rate` on top (altitude lost is not credited); the landing a vertical descent
//!   from the last waypoint's altitude at the descent rate and descent power. Compared against
//!   usable energy × (1 − reserve) (`ENERGY-BUDGET`). On a bidirectional route the flight with a
//!   return to home from the last waypoint (the longest: the reverse route with its turns, then
//!   the landing at the initial waypoint) is compared too (`ENERGY-RETURN`). A leg or turn whose
//!   track cannot be held against the wind (crosswind ≥ airspeed, or no forward ground speed) is
//!   its own violation (`ENERGY-TRACK`) and left out of the sum.
//! - **Wind** (ICD §7 "Turns in wind"): every turn is checked at the radius a bank-limited
//!   aircraft holds over the ground in a wind of speed `W` from any direction, `(v + W)²/(g·tan
//!   (bank))` ([`missionlink_protocol::geofence::flown_route::FlyBy`] proves it), with `W` the larger of the
//!   environment's wind and the plan's planning wind (#13001 field 5), rounded up to the wire's
//!   0.5 m/s ([`SafetyGateway::turn_wind_mps`]): the wind the validation sends to the FCC, whose
//!   guidance flies and whose onboard check checks the same turns. The direction is not used for
//!   the turns (the bank it takes is within the limit whatever it is) but is for the energy.
//! - **Environment** (`ENV-*`): wind speed and temperature inside the profile's limits.
//! - **Fleet separation** (`FLEET-SEP`, [`separation`]): a mission for one vehicle against the
//!   active missions of the fleet's other vehicles, every path flown (legs and turns as above,
//!   in the same wind) at least the fleet's separation from every path of theirs wherever
//!   their altitudes are closer than its vertical separation; time-independent, and so
//!   conservative. A check of its own ([`separation::conflicts`]): it needs the other
//!   vehicles' missions, which [`SafetyGateway::violations`] is not given.
//!
//! # Geometry
//!
//! All of it is the geofence's ([`missionlink_protocol::geofence`]): the same code the FCC runs for its
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
//! - The extra power of a banked turn (its load factor `1/cos(bank)` is 1.10 at 25°): a
//!   turn is counted at the cruise power of its speed.
//! - A return to home commanded before the last waypoint: it flies a turn round and less of the
//!   route, and is bounded by the one from the last waypoint counted.

use missionlink_interfaces::wire::{AreaShape, AreaType, GeoPoint, LegType, SpecificData};

use missionlink_protocol::geofence::earth::{self, Site};
use missionlink_protocol::geofence::flown_route::{self, RouteElement, RouteView, RouteWaypoint};
use missionlink_protocol::geofence::path::{Path, Track};
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::mission::{Mission, WaypointRecord};

// The check groups of the module documentation, each with the code it alone uses; fleet
// separation is public, since it is called on its own with the fleet's missions.
mod area;
mod energy;
mod environment;
mod geography;
mod profile;
mod report;
mod route;
pub mod separation;

pub use profile::{AircraftProfile, Environment};
pub use report::{Element, EnergyEstimate, Report, Violation, ViolationCode};

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
            Err(Report {
                violations,
                turn_wind_mps: self.turn_wind_mps(mission),
            })
        }
    }

    fn planning_wind(&self) -> Option<missionlink_interfaces::wire::Speed> {
        self.environment.planning_wind()
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
        for (i, (leg, w)) in flown_route::legs(route).zip(entries.windows(2)).enumerate() {
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
    /// [`missionlink_protocol::geofence::turn`]): forward from the take-off point, and on a bidirectional
    /// route the way back from the last waypoint and the turn round at every waypoint where a
    /// return to home may start. Paths the legs between the waypoints do not cover.
    fn turns(&self, mission: &Mission, take_off: Option<GeoPoint>) -> Vec<Leg> {
        let route = RouteView {
            wind_mps: self.turn_wind_mps(mission),
            ..RouteView::from(mission)
        };
        let entries = route.waypoints;
        let fly_by = flown_route::FlyBy {
            bank_deg: self.profile.max_bank_deg,
        };
        let index = |n: u16| entries.iter().position(|w| w.number() == n);
        let start = take_off
            .map(Site::of)
            .or(entries.first().map(|w| Site::of(w.position())));
        let last = entries.last();
        let forward = start
            .into_iter()
            .flat_map(|s| flown_route::execute_route(route, s, Some(fly_by)));
        let bidirectional = route.bidirectional;
        // The way back from the last waypoint (`to` 0: the route complete); the turns round
        // at the waypoints are `turns_round`'s.
        let back = last.filter(|_| bidirectional).into_iter().flat_map(|w| {
            flown_route::return_route(route, Site::of(w.position()), 0, Some(fly_by))
        });
        let round = bidirectional
            .then(|| flown_route::turns_round(route, fly_by))
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

    /// The wind speed every turn of `mission` is checked in (ICD §7 "Turns in wind"): the larger
    /// of the plan's planning wind (#13001 field 5) and the environment's, as the validation
    /// sends it to the FCC ([`Environment::planning_wind`]), m/s.
    pub fn turn_wind_mps(&self, mission: &Mission) -> f64 {
        let plan = RouteView::from(mission).wind_mps;
        let environment = self.environment.planning_wind().map_or(0.0, |w| w.mps());
        plan.max(environment)
    }

    /// The energy estimate of `mission` flown from `take_off`.
    pub fn estimate_energy(&self, mission: &Mission, take_off: Option<GeoPoint>) -> EnergyEstimate {
        let legs = Self::legs(mission, take_off);
        self.energy(mission, take_off, &legs).0
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
        self.check_energy(mission, take_off, &legs, &mut c);
        c.out
    }
}

#[cfg(test)]
mod tests;
