//! Guidance kinematics (the guidance stub partition, docs/design.md "Partitions"): a point-mass
//! model that flies the active waypoint list through the flight phases of system automation and
//! reports its progress (FROM-TO-NEXT, position, fly-zone and no-fly-zone status) on
//! `fcc/guidance/progress`.
//!
//! Sans-IO like the rest of `services`: the driver passes the automation state, the waypoint
//! list and the area list when they arrive, and calls [`Guidance::step`] with the time; the
//! model integrates from the previous step in sub-steps of at most 50 ms of simulated time.
//! Stepping allocates nothing: the lists are the fixed payload arrays; only a new area list
//! builds (and keeps) its geofence.
//!
//! All geometry is the geofence's, the one Earth model (WGS-84, [`crate::geofence`]): distances,
//! bearings and destinations are geodesics ([`crate::geofence::earth`]), and whether the
//! aircraft is in a zone is [`Zone::contains`] on the [`Fence`] of the area list: polygon edges
//! are geodesics, circles are the points within the geodesic radius, as the safety gateway and
//! the onboard check take them (ICD §4 "Geometry").
//!
//! # The model and its simplifications
//!
//! - **Phases** (from [`AutomationStatePayload::flight_phase`]): on the ground (OnGround,
//!   Landed, or an unknown phase byte) the aircraft stays where it is at altitude 0 and reports
//!   no FROM-TO-NEXT. TakeOff is a vertical climb at the climb rate up to the list's take-off
//!   height; Cruise flies the route; Landing is a vertical descent at the descent rate to 0.
//!   Vertical and horizontal motion never mix except in Cruise.
//! - **Altitudes**: waypoint altitudes are taken as heights above the start ground, whatever
//!   their altitude type (no terrain, no geoid), without a vertical rate limit.
//! - **Speed**: the TO waypoint's commanded speed is flown as ground speed at once (no wind, no
//!   acceleration); a waypoint with speed 0 is flown at [`FALLBACK_SPEED_MPS`].
//! - **What is flown is what the geofence checks**: the legs between the waypoints and, at
//!   every waypoint, the turn of [`crate::geofence::turn`], the one construction the onboard
//!   check and the safety gateway check too. Guidance flies each of its paths exactly (to
//!   nanometres; `services/tests/flown_path.rs` measures it).
//! - **Track-to-fix legs** are tracked along the geodesic between the FROM and the TO waypoint
//!   (WGS-84). The law: the course is the one towards the point of that geodesic one look-ahead
//!   `L` beyond the aircraft's along-track position (`L` = the turn radius, at least
//!   10 m), capped at the end of the path being flown. On the geodesic that point lies on the
//!   same geodesic, so the aircraft stays on it; off it (a start beside the leg) the cross-track
//!   error `e` shrinks by the factor `1 − s/√(L² + e²)` with every step of `s` metres (at most
//!   1.25 m, far less than `L`): it goes to zero without ever changing sign, so there is no
//!   overshoot (bound: 0 m), and once smaller than `L` it decays as `exp(−x/L)` over the
//!   distance `x` flown.
//! - **Radius-to-fix legs** are flown in polar coordinates around the centre, in the turn
//!   direction, at the radius going linearly with the angle from the FROM waypoint's to the TO
//!   waypoint's (the geofence's arc); turns onto and off them are the turns below, with the arc
//!   as the leg turned off or onto.
//! - **Fly-by** (ARINC 424 fly-by): at the TO waypoint the aircraft turns on the arc of radius
//!   `r = v²/(g·tan(bank))` (`v` the speed flown in the turn: the next waypoint's, towards which
//!   the aircraft flies from the turn's start; the configured bank) tangent to the leg
//!   in and the leg out; FROM-TO-NEXT switches where the arc starts (`r·tan(Δψ/2)` before the
//!   waypoint between track-to-fix legs turning `Δψ`), and the next leg is joined where the
//!   arc ends. **Legs too short for the arc** (its tangent point farther from the waypoint than
//!   half a leg next to it, and always a U-turn, whose arc does not exist): the waypoint is flown
//!   over.
//! - **Fly-over**: the aircraft flies to the waypoint (FROM-TO-NEXT switches there), then turns
//!   at radius `r` (tangent to the leg in) through the course change and on to an intercept of
//!   the next leg itself at `χ = min(45°, acos(cos²(Δψ/2)))`, flies straight at that course, and
//!   turns at `r` the other way onto the leg. Where that intercept does not meet the next leg (a
//!   radius-to-fix arc curving away), the first turn goes straight into the turn onto the leg;
//!   where there is no room on half of the next leg, it turns round on the spot (a multicopter).
//! - **The first leg** of a route, from where the aircraft is (the take-off point after the
//!   climb) to the first TO waypoint, is the geodesic between them, whatever the leg type: what
//!   the onboard check checks from navigation's position, and the safety gateway from the
//!   plan's take-off position. The turn at the first waypoint is from that geodesic.
//! - **Altitude** moves linearly with the distance flown towards the TO waypoint's altitude,
//!   reached where the leg is left (the fly-by arc's start, or the waypoint).
//! - **Return to home** (`route_reversed`, honoured on bidirectional routes only): the aircraft
//!   keeps flying to its current TO waypoint, turns round there (a U-turn: flown over), then
//!   flies the route backwards to the initial waypoint, each waypoint at its own speed and with
//!   its turn; a reversed radius-to-fix leg is the same arc in the opposite direction. Reversed
//!   after the route was complete, it starts from the final waypoint (no turn: it was hovering
//!   there); a route started reversed starts at the waypoint nearest to the aircraft.
//! - **Land at** (`land_at` != 0) ends the route at that waypoint if it is still ahead (or is
//!   the TO waypoint); a waypoint already passed is ignored. The leg into it is flown to its end
//!   (the checks check every leg in full for this). A NEXT that changes after the fly-by arc's
//!   start has been passed makes that turn a fly-over.
//! - **New waypoint lists**: on the ground a new generation is taken at once. In the air the
//!   old list is kept until the automation state's `flown_waypoint_list` names the new
//!   generation; then the new list's route starts from its first waypoint (FROM 0).
//! - **Areas**: the fly-zone and the no-fly-zones are 2-D: altitude bounds and the safety offset
//!   are not applied. A circle's radius is the geodesic distance centre -> border point.
//!   Leaving the fly-zone and entering a no-fly-zone are logged once, on the change.

use geo::Point;
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationStatePayload, FlightPhase, GuidanceProgressPayload, WaypointEntry,
    WaypointListPayload,
};

use crate::geofence::earth::{Site, distance_m, point};
use crate::geofence::onboard::{self, FlyBy};
use crate::geofence::path::Path;
use crate::geofence::turn::{
    ArcGeometry, MAX_TURN_PATHS, Turn, TurnKind, angle_to_go, length_m, rest_from, turn,
};
use crate::geofence::zone::{Fence, Zone, ZoneKind};
use crate::link::time::Instant;

/// Longest sub-step of the integration, simulated seconds.
pub const MAX_SUB_STEP_S: f64 = 0.05;

/// Speed flown towards a waypoint whose commanded speed is 0, m/s (the geofence models the
/// same turns: [`FlyBy`]).
pub use crate::geofence::onboard::FALLBACK_SPEED_MPS;

/// A waypoint closer than this is reached, metres.
const REACHED_M: f64 = 0.01;

/// Climb and descent end this close to their target altitude, metres.
const ALTITUDE_EPSILON_M: f64 = 1e-6;

/// The shortest look-ahead of the cross-track law on a track-to-fix leg, metres.
const MIN_LOOK_AHEAD_M: f64 = 10.0;

/// Path ends (turn paths, leg switches, arrivals) handled within one sub-step at most.
const MAX_LEGS_PER_SUB_STEP: usize = 8;

/// Settings of the guidance model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuidanceConfig {
    /// Start latitude on the ground (degrees); default: TROL 48.26 from the demo missions.
    pub start_latitude_deg: f64,
    /// Start longitude on the ground (degrees); default: TROL 11.66 from the demo missions.
    pub start_longitude_deg: f64,
    /// Climb rate of the take-off (m/s), default 3.0.
    pub climb_rate_mps: f64,
    /// Descent rate of the landing (m/s), default 2.0.
    pub descent_rate_mps: f64,
    /// Bank angle of the turns at waypoints (deg; their radius is `v²/(g·tan(bank))`),
    /// default 25.
    pub max_bank_deg: f64,
    /// Simulated seconds per real second (demo time scale), default 1.0; 0 pauses.
    pub time_scale: f64,
}

impl Default for GuidanceConfig {
    fn default() -> Self {
        Self {
            start_latitude_deg: 48.26,
            start_longitude_deg: 11.66,
            climb_rate_mps: 3.0,
            descent_rate_mps: 2.0,
            max_bank_deg: 25.0,
            time_scale: 1.0,
        }
    }
}

impl GuidanceConfig {
    /// How this guidance turns at waypoints, for the geofence ([`crate::geofence::turn`] at
    /// its bank: the construction [`Guidance`] flies).
    pub fn fly_by(&self) -> FlyBy {
        FlyBy {
            bank_deg: self.sanitized().max_bank_deg,
        }
    }

    /// The configuration with every unusable value replaced by its default: non-finite or
    /// non-positive rates, a bank outside 0..90 deg, a negative or non-finite time scale, a
    /// start position off the globe.
    fn sanitized(self) -> Self {
        let d = Self::default();
        let positive = |v: f64, default: f64| {
            if v.is_finite() && v > 0.0 { v } else { default }
        };
        Self {
            start_latitude_deg: if (-90.0..=90.0).contains(&self.start_latitude_deg) {
                self.start_latitude_deg
            } else {
                d.start_latitude_deg
            },
            start_longitude_deg: if (-180.0..=180.0).contains(&self.start_longitude_deg) {
                self.start_longitude_deg
            } else {
                d.start_longitude_deg
            },
            climb_rate_mps: positive(self.climb_rate_mps, d.climb_rate_mps),
            descent_rate_mps: positive(self.descent_rate_mps, d.descent_rate_mps),
            max_bank_deg: if self.max_bank_deg > 0.0 && self.max_bank_deg < 90.0 {
                self.max_bank_deg
            } else {
                d.max_bank_deg
            },
            time_scale: if self.time_scale.is_finite() && self.time_scale >= 0.0 {
                self.time_scale
            } else {
                d.time_scale
            },
        }
    }
}

/// A site that is no place, for a route not started.
const NOWHERE: Site = Site {
    lat: 0.0,
    lon: 0.0,
    ecef: [0.0; 3],
};

/// Where the aircraft is on the route. Indices are into [`WaypointListPayload::waypoints`].
#[derive(Debug, Clone, PartialEq)]
struct Route {
    /// The route has been started (take-off or cruise with this list).
    started: bool,
    /// Flown backwards (return to home).
    reversed: bool,
    /// FROM waypoint number, 0 for none.
    from: u16,
    /// Index of the TO waypoint; `None` when complete or without a list.
    to: Option<usize>,
    /// The last waypoint of the route is reached.
    complete: bool,
    /// The leg to TO in full (the geodesic from where the route started, for the first leg):
    /// what the turn at TO starts from.
    leg: Path,
    /// The part of the leg still ahead once the turn onto it is flown: from where the turn
    /// joined it.
    body: Path,
    /// The paths of the turn onto this leg not flown yet, the next one last.
    turn: heapless::Vec<Path, MAX_TURN_PATHS>,
    /// Counts the legs started, for the planned turn.
    serial: u64,
}

impl Route {
    const NOT_STARTED: Self = Self {
        started: false,
        reversed: false,
        from: 0,
        to: None,
        complete: false,
        leg: Path::Point(NOWHERE),
        body: Path::Point(NOWHERE),
        turn: heapless::Vec::new(),
        serial: 0,
    };
}

/// The turn at the TO waypoint, computed once per leg and NEXT waypoint.
#[derive(Debug, Clone, PartialEq)]
struct Planned {
    serial: u64,
    next: usize,
    /// Flown over whatever the turn type (the aircraft is past the fly-by arc's start).
    over: bool,
    turn: Turn,
}

/// The area list as the geofence holds it ([`Fence`]), built once when the list arrives so that
/// the zone test of each step allocates nothing.
#[derive(Debug, Clone, Default)]
struct Areas {
    /// `None` without an area list. Boxed: a fence holds every border in fixed capacity.
    fence: Option<Box<Fence>>,
}

impl Areas {
    fn new(list: &AreaListPayload) -> Self {
        Self {
            fence: (list.generation != 0).then(|| Box::new(Fence::of_payload(list))),
        }
    }

    fn zones(&self) -> impl Iterator<Item = &Zone> {
        self.fence.iter().flat_map(|f| f.zones.iter())
    }

    fn inside_fly_zone(&self, at: &Site) -> bool {
        self.zones()
            .any(|z| z.kind == ZoneKind::FlyZone && z.contains(at))
    }

    /// Area ID of the first no-fly-zone (polygons, then circles: the fence's order) containing
    /// `at`, else 0.
    fn no_fly_zone_at(&self, at: &Site) -> u16 {
        self.zones()
            .find(|z| z.kind == ZoneKind::NoFlyZone && z.contains(at))
            .map_or(0, |z| z.id)
    }
}

/// The remaining length of `path` from `here`, a point of it, metres.
fn remaining_on(path: &Path, here: &Site) -> f64 {
    match path {
        Path::Point(_) => 0.0,
        Path::Geodesic { to, .. } => here.inverse(to).0,
        Path::Arc {
            from,
            to,
            centre,
            direction,
        } => {
            let arc = ArcGeometry::of(from, to, centre, *direction);
            let az = centre.inverse(here).1;
            let alpha = to_go(&arc, az);
            alpha.to_radians() * (arc.radius_at(az) + arc.r1) / 2.0
        }
    }
}

/// Degrees still to turn on `arc` from azimuth `az`: 0 past the end (a wrap beyond the sweep).
fn to_go(arc: &ArcGeometry, az: f64) -> f64 {
    let alpha = angle_to_go(az, arc.az1, arc.clockwise);
    if alpha > arc.sweep && alpha > 180.0 {
        0.0
    } else {
        alpha
    }
}

/// The end of a path.
fn end_of(path: &Path) -> Site {
    match path {
        Path::Point(p) => *p,
        Path::Geodesic { to, .. } | Path::Arc { to, .. } => *to,
    }
}

/// The speed flown towards `e`.
fn leg_speed(e: &WaypointEntry) -> f64 {
    FlyBy::speed_mps(e)
}

/// The guidance model: flies the waypoint list through the flight phases (see the module
/// documentation for the model).
#[derive(Debug, Clone)]
pub struct Guidance {
    config: GuidanceConfig,
    /// The list flown.
    list: WaypointListPayload,
    /// A newer list received in the air, waiting for automation to fly it.
    pending: Option<WaypointListPayload>,
    areas: Areas,
    automation: AutomationStatePayload,
    /// Position, lon/lat degrees.
    position: Point<f64>,
    altitude_m: f64,
    ground_speed_mps: f64,
    climb_complete: bool,
    route: Route,
    /// The turn at the TO waypoint, once planned.
    planned: Option<Planned>,
    last_step: Option<Instant>,
    sequence: u64,
    /// Zone status of the last step (or of the last area list change).
    inside_fly_zone: bool,
    in_no_fly_zone: u16,
    /// Warnings logged for leaving the fly-zone or entering a no-fly-zone.
    zone_warnings: u32,
}

impl Guidance {
    /// On the ground at the configured start, altitude 0, no list, no areas.
    pub fn new(config: GuidanceConfig) -> Self {
        let config = config.sanitized();
        Self {
            config,
            list: WaypointListPayload::EMPTY,
            pending: None,
            areas: Areas::default(),
            automation: AutomationStatePayload::ON_GROUND,
            position: Point::new(config.start_longitude_deg, config.start_latitude_deg),
            altitude_m: 0.0,
            ground_speed_mps: 0.0,
            climb_complete: false,
            route: Route::NOT_STARTED,
            planned: None,
            last_step: None,
            sequence: 0,
            inside_fly_zone: false,
            in_no_fly_zone: 0,
            zone_warnings: 0,
        }
    }

    /// A waypoint list was published. A new generation is flown at once on the ground; in the
    /// air only once the automation state's `flown_waypoint_list` names it (until then the old
    /// list is flown).
    pub fn set_waypoint_list(&mut self, list: &WaypointListPayload) {
        if list.generation == self.list.generation {
            return;
        }
        if self.on_ground() || self.automation.flown_waypoint_list == list.generation {
            self.adopt(*list);
        } else {
            self.pending = Some(*list);
        }
    }

    /// An area list was published: its geofence is built and kept for the zone checks.
    pub fn set_area_list(&mut self, list: &AreaListPayload) {
        self.areas = Areas::new(list);
        // The aircraft did not move: the new status is taken without a warning.
        (self.inside_fly_zone, self.in_no_fly_zone) = self.zone_status();
    }

    /// The automation state changed.
    pub fn set_automation(&mut self, state: &AutomationStatePayload) {
        if state.route_reversed && !self.automation.route_reversed && !self.list.bidirectional {
            tracing::warn!(
                generation = self.list.generation,
                "return to home requested on a route that is not bidirectional: ignored"
            );
        }
        self.automation = *state;
        self.adopt_pending_if_due();
    }

    /// Integrates from the previous step to `now` (simulated elapsed = real elapsed x
    /// time_scale; nothing on the first call), in sub-steps of at most [`MAX_SUB_STEP_S`]
    /// simulated seconds, and returns the progress. `sequence` counts calls from 1, `time_ns`
    /// is `now` in nanoseconds, `waypoint_list` the generation of the list flown.
    pub fn step(&mut self, now: Instant) -> GuidanceProgressPayload {
        self.sequence = self.sequence.saturating_add(1);
        let elapsed = self
            .last_step
            .map_or(0.0, |t| now.saturating_since(t).as_secs_f64());
        self.last_step = Some(now);
        self.adopt_pending_if_due();

        let phase = self.automation.flight_phase();
        match phase {
            Some(FlightPhase::TakeOff | FlightPhase::Cruise) => self.start_route_if_needed(),
            Some(FlightPhase::Landing) => {}
            Some(FlightPhase::OnGround | FlightPhase::Landed) | None => {
                self.altitude_m = 0.0;
                self.reset_route();
                self.climb_complete = false;
            }
        }
        self.sync_direction();
        if phase != Some(FlightPhase::Cruise) {
            self.ground_speed_mps = 0.0;
        }

        let simulated = elapsed * self.config.time_scale;
        if simulated > 0.0 {
            let n = (simulated / MAX_SUB_STEP_S).ceil().max(1.0);
            let h = simulated / n;
            let mut i = 0.0;
            while i < n {
                let busy = match phase {
                    Some(FlightPhase::TakeOff) => self.climb(h),
                    Some(FlightPhase::Cruise) => self.fly(h),
                    Some(FlightPhase::Landing) => self.descend(h),
                    _ => false,
                };
                if !busy {
                    break;
                }
                i += 1.0;
            }
        }

        self.check_zones();
        let (from, to, next) = self.triple(phase);
        GuidanceProgressPayload {
            sequence: self.sequence,
            time_ns: now.micros().saturating_mul(1000),
            waypoint_list: self.list.generation,
            latitude_deg: self.position.y(),
            longitude_deg: self.position.x(),
            altitude_m: self.altitude_m,
            ground_speed_mps: self.ground_speed_mps,
            from,
            to,
            next,
            in_no_fly_zone: self.in_no_fly_zone,
            inside_fly_zone: self.inside_fly_zone,
            trajectory_generation_active: phase == Some(FlightPhase::Cruise),
            climb_complete: self.climb_complete,
            route_complete: self.route.complete,
            on_ground: self.on_ground(),
            reserved: [0; 3],
        }
    }

    /// On the ground: before take-off, after touchdown, or in an unknown phase.
    fn on_ground(&self) -> bool {
        match self.automation.flight_phase() {
            Some(FlightPhase::OnGround | FlightPhase::Landed) | None => true,
            Some(FlightPhase::TakeOff | FlightPhase::Landing) => self.altitude_m <= 0.0,
            Some(FlightPhase::Cruise) => false,
        }
    }

    /// Back to a route not started; the planned turn goes with it.
    fn reset_route(&mut self) {
        self.route = Route::NOT_STARTED.clone();
        self.planned = None;
    }

    fn adopt(&mut self, list: WaypointListPayload) {
        self.list = list;
        self.pending = None;
        self.reset_route();
    }

    fn adopt_pending_if_due(&mut self) {
        if let Some(p) = self.pending
            && (self.on_ground() || self.automation.flown_waypoint_list == p.generation)
        {
            self.adopt(p);
        }
    }

    fn reversal_wanted(&self) -> bool {
        self.automation.route_reversed && self.list.bidirectional
    }

    fn entry(&self, index: usize) -> Option<&WaypointEntry> {
        self.list.waypoints().get(index)
    }

    fn index_of(&self, number: u16) -> Option<usize> {
        self.list
            .waypoints()
            .iter()
            .position(|w| w.number == number)
    }

    fn number(&self, index: Option<usize>) -> u16 {
        index.and_then(|i| self.entry(i)).map_or(0, |w| w.number)
    }

    /// Starts the route of the list flown: FROM 0, TO the first waypoint (or, reversed, the
    /// nearest one), flown direct.
    fn start_route_if_needed(&mut self) {
        if self.route.started {
            return;
        }
        let reversed = self.reversal_wanted();
        let waypoints = self.list.waypoints();
        let to = if waypoints.is_empty() {
            None
        } else if reversed {
            waypoints
                .iter()
                .map(|w| distance_m(self.position, point(w.position)))
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(i, _)| i)
        } else {
            Some(0)
        };
        let here = Site::of(self.position);
        let first = Path::Geodesic {
            from: here,
            to: to
                .and_then(|i| self.entry(i))
                .map_or(here, |w| Site::of(w.position)),
        };
        self.route = Route {
            started: true,
            reversed,
            from: 0,
            to,
            complete: false,
            leg: first,
            body: first,
            turn: heapless::Vec::new(),
            serial: self.route.serial.wrapping_add(1),
        };
    }

    /// Applies a change of `route_reversed`: the TO waypoint stays, what follows it turns
    /// round; a complete route restarts from its final waypoint.
    fn sync_direction(&mut self) {
        let wanted = self.reversal_wanted();
        if !self.route.started || wanted == self.route.reversed {
            return;
        }
        self.route.reversed = wanted;
        if self.route.complete
            && let Some(next) = self
                .index_of(self.route.from)
                .and_then(|i| self.next_index(i))
        {
            self.route.complete = false;
            if let Some(from) = self.index_of(self.route.from) {
                self.enter(from, next, None);
            }
        }
    }

    /// Index of the last waypoint of the route, seen from TO at `to`.
    fn end_index(&self, to: usize) -> usize {
        let reversed = self.route.reversed;
        let land_at = self.automation.land_at;
        if land_at != 0
            && let Some(i) = self.index_of(land_at)
            && ((!reversed && i >= to) || (reversed && i <= to))
        {
            return i;
        }
        if reversed {
            0
        } else {
            self.list.waypoints().len().saturating_sub(1)
        }
    }

    /// Index of the waypoint after `to` on the route, `None` on the last leg.
    fn next_index(&self, to: usize) -> Option<usize> {
        let end = self.end_index(to);
        if self.route.reversed {
            (to > end).then(|| to - 1)
        } else {
            (to < end).then(|| to + 1)
        }
    }

    /// The leg flown from the waypoint at `from` to the adjacent one at `to`: forwards by the
    /// leg type of `to`, backwards the leg from `to` to `from` turned round.
    fn leg_between(&self, from: usize, to: usize) -> Option<Path> {
        if to > from {
            Some(onboard::leg(self.entry(from)?, self.entry(to)?))
        } else {
            Some(onboard::leg(self.entry(to)?, self.entry(from)?).reversed())
        }
    }

    /// Starts the leg from the waypoint at `from` to the one at `to`, joined after `turn`.
    fn enter(&mut self, from: usize, to: usize, turn: Option<&Turn>) {
        self.route.from = self.number(Some(from));
        self.route.to = Some(to);
        self.route.serial = self.route.serial.wrapping_add(1);
        let Some(leg) = self.leg_between(from, to) else {
            return;
        };
        self.route.leg = leg;
        self.route.body = match turn {
            Some(t) => rest_from(&leg, t.join),
            None => leg,
        };
        self.route.turn = turn
            .map(|t| t.paths.iter().rev().copied().collect())
            .unwrap_or_default();
    }

    fn triple(&self, phase: Option<FlightPhase>) -> (u16, u16, u16) {
        match phase {
            Some(FlightPhase::TakeOff | FlightPhase::Cruise | FlightPhase::Landing)
                if self.route.started =>
            {
                let next = self.route.to.and_then(|t| self.next_index(t));
                (
                    self.route.from,
                    self.number(self.route.to),
                    self.number(next),
                )
            }
            _ => (0, 0, 0),
        }
    }

    /// One climb sub-step; false once at (or above) the take-off height.
    fn climb(&mut self, h: f64) -> bool {
        let target = self.list.take_off_height.metres().max(0.0);
        if self.altitude_m >= target {
            self.climb_complete = true;
            return false;
        }
        self.altitude_m = (self.altitude_m + self.config.climb_rate_mps * h).min(target);
        // Sums of sub-steps miss the height by rounding: a micrometre short is there.
        if self.altitude_m >= target - ALTITUDE_EPSILON_M {
            self.altitude_m = target;
            self.climb_complete = true;
        }
        true
    }

    /// One descent sub-step; false once on the ground.
    fn descend(&mut self, h: f64) -> bool {
        if self.altitude_m <= 0.0 {
            self.altitude_m = 0.0;
            return false;
        }
        self.altitude_m = (self.altitude_m - self.config.descent_rate_mps * h).max(0.0);
        if self.altitude_m <= ALTITUDE_EPSILON_M {
            self.altitude_m = 0.0;
        }
        true
    }

    /// One cruise sub-step of `h` seconds; false when holding (route complete or no list).
    fn fly(&mut self, h: f64) -> bool {
        let mut left = h;
        for _ in 0..MAX_LEGS_PER_SUB_STEP {
            if left <= 0.0 {
                break;
            }
            match self.fly_leg(left) {
                Some(used) => left -= used,
                None => {
                    self.ground_speed_mps = 0.0;
                    return false;
                }
            }
        }
        true
    }

    /// The turn at the TO waypoint (index `to`) onto the leg to `next`, planned once per leg.
    fn planned_turn(&mut self, to: usize, next: usize, over: bool) -> Option<Turn> {
        if let Some(p) = &self.planned
            && p.serial == self.route.serial
            && p.next == next
            && p.over == over
        {
            return Some(p.turn.clone());
        }
        let (w, after) = (*self.entry(to)?, *self.entry(next)?);
        let outbound = self.leg_between(to, next)?;
        let t = if over {
            turn(
                &self.route.leg,
                &outbound,
                true,
                self.turn_radius(leg_speed(&after)),
            )
        } else {
            self.config
                .fly_by()
                .turn(&w, &after, &self.route.leg, &outbound)
        };
        self.planned = Some(Planned {
            serial: self.route.serial,
            next,
            over,
            turn: t.clone(),
        });
        Some(t)
    }

    /// Flies the route for up to `dt` seconds: the turn onto the leg, then the leg up to where
    /// the turn at TO starts. Returns the time used (0 on a switch at a path's end), `None`
    /// when there is nothing to fly.
    fn fly_leg(&mut self, dt: f64) -> Option<f64> {
        let to_index = self.route.to?;
        let to = *self.entry(to_index)?;
        let target = Site::of(to.position);
        let v = leg_speed(&to);
        self.ground_speed_mps = v;
        let budget = v * dt;
        let target_alt = to.altitude.metres();
        let here = Site::of(self.position);

        // The turn onto this leg.
        if let Some(path) = self.route.turn.last().copied() {
            let remaining = remaining_on(&path, &here);
            let ahead: f64 = remaining
                + self
                    .route
                    .turn
                    .iter()
                    .rev()
                    .skip(1)
                    .map(length_m)
                    .sum::<f64>()
                + length_m(&self.route.body);
            if remaining <= budget + REACHED_M {
                self.climb_towards(target_alt, remaining.max(0.0), ahead);
                self.set_position(end_of(&path));
                self.route.turn.pop();
                return Some(remaining.max(0.0) / v);
            }
            self.climb_towards(target_alt, budget, ahead);
            self.advance(&path, &here, budget, v);
            return Some(dt);
        }

        // The leg, to the start of the turn at TO.
        let next = self.next_index(to_index);
        let mut planned = next.and_then(|n| self.planned_turn(to_index, n, false));
        let body_left = remaining_on(&self.route.body, &here);
        if let Some(t) = &planned
            && t.kind == TurnKind::FlyBy
            && body_left < remaining_on(&self.route.body, &t.leave) - REACHED_M
        {
            // Past the arc's start (NEXT changed late): over the waypoint instead.
            planned = next.and_then(|n| self.planned_turn(to_index, n, true));
        }
        let (end, to_end) = match &planned {
            Some(t) if t.kind == TurnKind::FlyBy => (
                t.leave,
                body_left - remaining_on(&self.route.body, &t.leave),
            ),
            _ => (target, body_left),
        };
        if to_end <= budget + REACHED_M {
            let used = to_end.max(0.0);
            self.climb_towards(target_alt, used, used);
            self.set_position(end);
            if end == target {
                self.altitude_m = target_alt;
            }
            match (next, planned) {
                (Some(n), Some(t)) => self.enter(to_index, n, Some(&t)),
                (Some(n), None) => self.enter(to_index, n, None),
                (None, _) => {
                    self.route.from = to.number;
                    self.route.to = None;
                    self.route.complete = true;
                }
            }
            return Some(used / v);
        }
        self.climb_towards(target_alt, budget, to_end);
        let body = self.route.body;
        self.advance(&body, &here, budget, v);
        Some(dt)
    }

    /// The altitude after `distance` metres of `ahead` still to fly to `target`'s altitude.
    fn climb_towards(&mut self, target: f64, distance: f64, ahead: f64) {
        if ahead <= distance || ahead <= 0.0 {
            self.altitude_m = target;
        } else {
            self.altitude_m += (target - self.altitude_m) * distance / ahead;
        }
    }

    fn set_position(&mut self, at: Site) {
        self.position = Point::new(at.lon, at.lat);
    }

    /// Moves `distance` metres (less than what is left) along `path` from `here`.
    ///
    /// A geodesic (a track-to-fix leg) is tracked by a look-ahead law: the course is the one to
    /// the point of the geodesic one look-ahead `L` (the turn radius, at least
    /// [`MIN_LOOK_AHEAD_M`]) beyond the aircraft's along-track position, capped at the path's
    /// end. On the geodesic that point is on the same geodesic, so the aircraft stays on it;
    /// off it, the cross-track error `e` shrinks by the factor `1 − s/√(L² + e²)` per step of
    /// `s` metres (less than `L`): it goes to zero without changing sign, no overshoot. An arc
    /// (a turn, a radius-to-fix leg) is followed exactly in polar coordinates around its
    /// centre: the azimuth advances by the step over the radius, the radius is the arc's there.
    fn advance(&mut self, path: &Path, here: &Site, distance: f64, v: f64) {
        let next = match *path {
            Path::Point(p) => p,
            Path::Geodesic { from, to } => {
                let (length, course) = from.inverse(&to);
                let (d, az) = from.inverse(here);
                let along = d * (az - course).to_radians().cos();
                let look_ahead = self.turn_radius(v).max(MIN_LOOK_AHEAD_M);
                let aim = if along + look_ahead >= length {
                    to
                } else {
                    from.direct(course, along + look_ahead)
                };
                here.direct(here.inverse(&aim).1, distance)
            }
            Path::Arc {
                from,
                to,
                centre,
                direction,
            } => {
                let arc = ArcGeometry::of(&from, &to, &centre, direction);
                let az = centre.inverse(here).1;
                let rho = arc.radius_at(az);
                let slope = if arc.sweep > 0.0 {
                    (arc.r1 - arc.r0) / arc.sweep.to_radians()
                } else {
                    0.0
                };
                let step = (distance / rho.hypot(slope))
                    .to_degrees()
                    .min(to_go(&arc, az));
                let az = if arc.clockwise { az + step } else { az - step };
                arc.at(az)
            }
        };
        self.set_position(next);
    }

    /// Turn radius at speed `v` and the bank limit, metres.
    fn turn_radius(&self, v: f64) -> f64 {
        self.config.fly_by().turn_radius_m(v)
    }

    /// Inside the fly-zone, and the no-fly-zone the aircraft is in (0: none), where it is now.
    fn zone_status(&self) -> (bool, u16) {
        let at = Site::of(self.position);
        (
            self.areas.inside_fly_zone(&at),
            self.areas.no_fly_zone_at(&at),
        )
    }

    /// Updates the zone status and logs leaving the fly-zone and entering a no-fly-zone.
    fn check_zones(&mut self) {
        let (inside, nfz) = self.zone_status();
        if self.inside_fly_zone && !inside {
            self.zone_warnings = self.zone_warnings.saturating_add(1);
            tracing::warn!(
                latitude_deg = self.position.y(),
                longitude_deg = self.position.x(),
                "left the fly-zone"
            );
        }
        if nfz != 0 && nfz != self.in_no_fly_zone {
            self.zone_warnings = self.zone_warnings.saturating_add(1);
            tracing::warn!(
                area_id = nfz,
                latitude_deg = self.position.y(),
                longitude_deg = self.position.x(),
                "entered a no-fly-zone"
            );
        }
        self.inside_fly_zone = inside;
        self.in_no_fly_zone = nfz;
    }
}

#[cfg(test)]
mod tests {
    use core::time::Duration;

    use missionlink_interfaces::contracts::{CircleArea, PolygonArea};
    use missionlink_interfaces::wire::{
        Altitude, AltitudeType, GeoPoint, LegType, Speed, TurnDirection, TurnType,
    };

    use crate::geofence::earth::{bearing_deg, destination};

    use super::*;

    const TROL: (f64, f64) = (48.26, 11.66);
    const CCP: (f64, f64) = (48.275, 11.645);
    const W1: (f64, f64) = (48.278, 11.658);
    const ROLE2: (f64, f64) = (48.28, 11.68);
    const RF_CENTRE: (f64, f64) = (48.27455, 11.66991);
    const NFZ_CENTRE: (f64, f64) = (48.268, 11.675);
    const NFZ_BORDER: (f64, f64) = (48.268, 11.679);
    /// Real time between steps.
    const DT: Duration = Duration::from_millis(100);
    const SPEED: f64 = 25.0;

    fn gp(p: (f64, f64)) -> GeoPoint {
        GeoPoint::from_degrees(p.0, p.1).unwrap()
    }

    fn pt(p: (f64, f64)) -> Point<f64> {
        Point::new(p.1, p.0)
    }

    fn here(p: &GuidanceProgressPayload) -> Point<f64> {
        Point::new(p.longitude_deg, p.latitude_deg)
    }

    fn config_at(p: (f64, f64)) -> GuidanceConfig {
        GuidanceConfig {
            start_latitude_deg: p.0,
            start_longitude_deg: p.1,
            ..GuidanceConfig::default()
        }
    }

    fn waypoint(number: u16, next: u16, at: (f64, f64), turn: TurnType) -> WaypointEntry {
        let mut w = WaypointEntry {
            number,
            next,
            position: gp(at),
            altitude: Altitude::from_metres(120.0).unwrap(),
            speed: Speed::from_mps(SPEED).unwrap(),
            turn_type: turn.into(),
            leg_type: LegType::TrackToFix.into(),
            ..WaypointEntry::EMPTY
        };
        w.set_altitude_type(Some(AltitudeType::Wgs84));
        w
    }

    fn list(generation: u64, waypoints: &[WaypointEntry]) -> WaypointListPayload {
        let mut l = WaypointListPayload::EMPTY;
        l.generation = generation;
        l.take_off_height = Altitude::from_metres(30.0).unwrap();
        l.count = waypoints.len() as u16;
        l.initial_waypoint = waypoints[0].number;
        l.waypoints[..waypoints.len()].copy_from_slice(waypoints);
        l
    }

    /// Demo mission 1: TROL -> CCP.
    fn mission1() -> WaypointListPayload {
        list(1, &[waypoint(1, 0, CCP, TurnType::FlyBy)])
    }

    /// The richer demo mission 2: CCP -> W1 (TF) -> ROLE2 (RF, clockwise), bidirectional.
    fn mission2(generation: u64, w1_turn: TurnType) -> WaypointListPayload {
        let mut role2 = waypoint(3, 0, ROLE2, TurnType::FlyBy);
        role2.leg_type = LegType::RadiusToFix.into();
        role2.set_rf_centre(Some((gp(RF_CENTRE), TurnDirection::Clockwise)));
        let mut l = list(
            generation,
            &[
                waypoint(1, 2, CCP, TurnType::FlyBy),
                waypoint(2, 3, W1, w1_turn),
                role2,
            ],
        );
        l.bidirectional = true;
        l
    }

    fn mission2_areas() -> AreaListPayload {
        let mut a = AreaListPayload::EMPTY;
        a.generation = 1;
        a.fly_zone.area_id = 1;
        a.fly_zone.vertex_count = 4;
        for (v, p) in a.fly_zone.vertices.iter_mut().zip([
            (48.255, 11.635),
            (48.255, 11.69),
            (48.285, 11.69),
            (48.285, 11.635),
        ]) {
            *v = gp(p);
        }
        a.no_fly_circle_count = 1;
        a.no_fly_circles[0] = CircleArea {
            area_id: 2,
            centre: gp(NFZ_CENTRE),
            border: gp(NFZ_BORDER),
            ..CircleArea::EMPTY
        };
        a.no_fly_polygon_count = 1;
        let mut poly = PolygonArea {
            area_id: 3,
            vertex_count: 4,
            ..PolygonArea::EMPTY
        };
        for (v, p) in poly.vertices.iter_mut().zip([
            (48.262, 11.64),
            (48.262, 11.646),
            (48.266, 11.646),
            (48.266, 11.64),
        ]) {
            *v = gp(p);
        }
        a.no_fly_polygons[0] = poly;
        a
    }

    /// A guidance driven through simulated time, every progress kept.
    struct Sim {
        g: Guidance,
        now: Instant,
        automation: AutomationStatePayload,
        log: Vec<GuidanceProgressPayload>,
    }

    impl Sim {
        fn new(config: GuidanceConfig, l: &WaypointListPayload) -> Self {
            let mut g = Guidance::new(config);
            g.set_waypoint_list(l);
            let mut s = Self {
                g,
                now: Instant::ZERO,
                automation: AutomationStatePayload::ON_GROUND,
                log: Vec::new(),
            };
            s.automation.flown_waypoint_list = l.generation;
            s.step();
            s
        }

        fn set(&mut self, f: impl FnOnce(&mut AutomationStatePayload)) {
            f(&mut self.automation);
            self.automation.sequence += 1;
            self.g.set_automation(&self.automation);
        }

        fn phase(&mut self, phase: FlightPhase) {
            self.set(|a| a.flight_phase = phase as u8);
        }

        fn step(&mut self) -> GuidanceProgressPayload {
            self.now = self.now + DT;
            let p = self.g.step(self.now);
            self.log.push(p);
            p
        }

        /// Steps until `done`; returns the progress and the steps taken.
        fn run_until(
            &mut self,
            max_steps: usize,
            done: impl Fn(&GuidanceProgressPayload) -> bool,
        ) -> (GuidanceProgressPayload, usize) {
            for n in 1..=max_steps {
                let p = self.step();
                if done(&p) {
                    return (p, n);
                }
            }
            panic!("not done in {max_steps} steps: {:?}", self.log.last());
        }

        /// Steps `n` times.
        fn run(&mut self, n: usize) {
            for _ in 0..n {
                self.step();
            }
        }

        /// The FROM-TO-NEXT triples logged from `start`, repetitions removed.
        fn triples(&self, start: usize) -> Vec<(u16, u16, u16)> {
            let mut t: Vec<_> = self.log[start..].iter().map(|p| p.from_to_next()).collect();
            t.dedup();
            t
        }

        /// Take-off and climb to the take-off height.
        fn take_off(&mut self) -> usize {
            self.phase(FlightPhase::TakeOff);
            self.run_until(1000, |p| p.climb_complete).1
        }
    }

    fn secs(steps: usize) -> f64 {
        steps as f64 * DT.as_secs_f64()
    }

    /// Bearing from `centre` to each point, unwrapped (no jumps of 360 deg).
    fn unwrapped_bearings(centre: Point<f64>, points: &[Point<f64>]) -> Vec<f64> {
        let mut out: Vec<f64> = Vec::with_capacity(points.len());
        for p in points {
            let b = bearing_deg(centre, *p);
            out.push(match out.last() {
                Some(prev) => prev + ((b - prev + 180.0).rem_euclid(360.0) - 180.0),
                None => b,
            });
        }
        out
    }

    #[test]
    fn on_the_ground_nothing_moves() {
        let mut s = Sim::new(GuidanceConfig::default(), &mission1());
        for _ in 0..50 {
            let p = s.step();
            assert!(p.on_ground && !p.trajectory_generation_active);
            assert_eq!((p.latitude_deg, p.longitude_deg), TROL);
            assert_eq!(p.altitude_m, 0.0);
            assert_eq!(p.ground_speed_mps, 0.0);
            assert_eq!(p.from_to_next(), (0, 0, 0));
            assert_eq!(p.waypoint_list, 1);
        }
        let p = s.log.last().unwrap();
        assert_eq!(p.sequence, 51);
        assert_eq!(p.time_ns, 5_100_000_000);
    }

    /// Demo mission 1 through every phase: climb 30 m at 3 m/s, the TF leg TROL -> CCP at
    /// 25 m/s, descent from 120 m at 2 m/s.
    #[test]
    fn mission1_take_off_cruise_landing() {
        let mut s = Sim::new(GuidanceConfig::default(), &mission1());

        s.phase(FlightPhase::TakeOff);
        let (p, steps) = s.run_until(1000, |p| p.climb_complete);
        assert!((secs(steps) - 30.0 / 3.0).abs() <= 0.1 + 1e-9, "{steps}");
        assert_eq!(p.altitude_m, 30.0);
        assert_eq!((p.latitude_deg, p.longitude_deg), TROL);
        assert_eq!(p.from_to_next(), (0, 1, 0));
        assert!(!p.on_ground && !p.trajectory_generation_active);
        assert_eq!(p.ground_speed_mps, 0.0);
        // Holds at the take-off height.
        assert_eq!(s.step().altitude_m, 30.0);

        s.phase(FlightPhase::Cruise);
        let start = s.log.len();
        let (p, steps) = s.run_until(2000, |p| p.route_complete);
        let leg = distance_m(pt(TROL), pt(CCP));
        assert!((leg - 2004.0).abs() < 5.0, "{leg}");
        assert!((secs(steps) - leg / SPEED).abs() <= 0.1 + 1e-9, "{steps}");
        assert!(distance_m(here(&p), pt(CCP)) < 0.01);
        assert_eq!(p.altitude_m, 120.0);
        assert_eq!(p.from_to_next(), (1, 0, 0));
        assert_eq!(s.triples(start), [(0, 1, 0), (1, 0, 0)]);
        let mid = s.log[start + steps / 2];
        assert_eq!(mid.ground_speed_mps, SPEED);
        assert!(mid.trajectory_generation_active && !mid.on_ground);
        // Altitude linear in distance: half way, half way from 30 to 120 m.
        assert!((mid.altitude_m - 75.0).abs() < 1.0, "{}", mid.altitude_m);
        // Hovers at CCP.
        let p = s.step();
        assert_eq!(p.ground_speed_mps, 0.0);
        assert!(distance_m(here(&p), pt(CCP)) < 0.01);

        s.phase(FlightPhase::Landing);
        let (p, steps) = s.run_until(2000, |p| p.on_ground);
        assert!((secs(steps) - 120.0 / 2.0).abs() <= 0.1 + 1e-9, "{steps}");
        assert_eq!(p.altitude_m, 0.0);
        assert!(!p.trajectory_generation_active);

        s.phase(FlightPhase::Landed);
        let p = s.step();
        assert!(p.on_ground);
        assert_eq!(p.from_to_next(), (0, 0, 0));
        assert!(distance_m(here(&p), pt(CCP)) < 0.01);
    }

    /// Expected fly-by anticipation at W1 of mission 2: TF inbound from CCP, tangent of the
    /// clockwise arc outbound.
    fn w1_anticipation() -> f64 {
        let inbound = bearing_deg(pt(W1), pt(CCP)) + 180.0;
        let outbound = bearing_deg(pt(RF_CENTRE), pt(W1)) + 90.0;
        let turn = ((outbound - inbound + 180.0).rem_euclid(360.0) - 180.0).abs();
        let r = SPEED * SPEED / (9.80665 * 25f64.to_radians().tan());
        r * (turn / 2.0).to_radians().tan()
    }

    /// Flies mission 2 from CCP to ROLE2; returns the simulation and the log index where the
    /// take-off started.
    fn fly_mission2(w1_turn: TurnType) -> (Sim, usize) {
        let mut s = Sim::new(config_at(CCP), &mission2(2, w1_turn));
        let start = s.log.len();
        s.take_off();
        assert_eq!(s.log.last().unwrap().from_to_next(), (0, 1, 2));
        s.phase(FlightPhase::Cruise);
        let (p, _) = s.run_until(3000, |p| p.route_complete);
        assert!(distance_m(here(&p), pt(ROLE2)) < 0.01);
        assert_eq!(p.altitude_m, 120.0);
        assert_eq!(
            s.triples(start),
            [(0, 1, 2), (1, 2, 3), (2, 3, 0), (3, 0, 0)]
        );
        (s, start)
    }

    /// Distances of the samples on the RF leg to the centre, relative to the radius, and the
    /// points.
    fn rf_leg(
        s: &Sim,
        on_leg: impl Fn(&GuidanceProgressPayload) -> bool,
    ) -> (Vec<f64>, Vec<Point<f64>>) {
        let radius = distance_m(pt(RF_CENTRE), pt(ROLE2));
        let points: Vec<_> = s.log.iter().filter(|p| on_leg(p)).map(here).collect();
        let rel = points
            .iter()
            .map(|p| (distance_m(pt(RF_CENTRE), *p) - radius).abs() / radius)
            .collect();
        (rel, points)
    }

    /// The turn at W1 of mission 2 (inbound the leg from CCP, outbound the RF arc to ROLE2)
    /// as the geofence constructs it, and the farthest a sample of the leg to ROLE2 (TO = 3)
    /// lies from that turn's paths and the arc.
    fn turn_at_w1(s: &Sim, w1_turn: TurnType) -> (Turn, f64) {
        let l = mission2(2, w1_turn);
        let w = l.waypoints();
        let (inbound, outbound) = (onboard::leg(&w[0], &w[1]), onboard::leg(&w[1], &w[2]));
        let t = GuidanceConfig::default()
            .fly_by()
            .turn(&w[1], &w[2], &inbound, &outbound);
        let paths: Vec<Path> = t.paths.iter().copied().chain([outbound]).collect();
        let worst = s
            .log
            .iter()
            .filter(|p| p.to == 3)
            .map(|p| {
                paths
                    .iter()
                    .map(|path| crate::testkit::distance_to_path(path, Site::of(here(p))))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        (t, worst)
    }

    /// Fly-by at W1, track-to-fix onto radius-to-fix: FROM-TO-NEXT switches where the arc
    /// tangent to the leg and to the RF circle starts (about `r·tan(Δψ/2)` before W1), the
    /// arc and then the RF leg are flown on their paths, clockwise.
    #[test]
    fn mission2_fly_by_tf_then_rf_arc() {
        let radius = distance_m(pt(RF_CENTRE), pt(ROLE2));
        assert!((radius - 962.0).abs() < 2.0, "{radius}");
        let (s, start) = fly_mission2(TurnType::FlyBy);
        let (t, worst) = turn_at_w1(&s, TurnType::FlyBy);
        assert_eq!(t.kind, TurnKind::FlyBy);
        assert!(worst < 0.001, "{worst} m off the turn and the arc");

        // The leg CCP -> W1 is left at the arc's start, about the anticipation before W1.
        let switch = start + s.log[start..].iter().position(|p| p.to == 3).unwrap();
        let anticipation = w1_anticipation();
        assert!((55.0..65.0).contains(&anticipation), "{anticipation}");
        let leave = distance_m(t.leave, pt(W1));
        assert!((leave - anticipation).abs() < 5.0, "{leave} {anticipation}");
        let step = SPEED * DT.as_secs_f64();
        let before = distance_m(here(&s.log[switch - 1]), pt(W1));
        assert!(
            before >= leave - 0.01 && before <= leave + step + 0.01,
            "{before}"
        );

        // On the RF leg once the turn is flown (off the turn's arc), clockwise.
        let points: Vec<Point<f64>> = s
            .log
            .iter()
            .filter(|p| p.to == 3)
            .map(here)
            .filter(|p| crate::testkit::distance_to_path(&t.paths[0], Site::of(*p)) > 0.001)
            .collect();
        let bearings = unwrapped_bearings(pt(RF_CENTRE), &points);
        assert!(bearings.windows(2).all(|w| w[1] > w[0]), "not clockwise");
        let swept = bearings.last().unwrap() - bearings.first().unwrap();
        assert!((100.0..125.0).contains(&swept), "{swept}");
        eprintln!(
            "mission 2: anticipation r·tan(Δψ/2) {anticipation:.1} m, the arc onto the RF \
             circle leaves the leg {leave:.1} m before W1; samples at most {worst:.1e} m off \
             the turn and the arc; swept {swept:.1} deg on the RF circle"
        );
    }

    /// Fly-over at W1: the leg is flown to W1, FROM-TO-NEXT switches there, then the turn, the
    /// intercept and the turn onto the RF circle, each on its path.
    #[test]
    fn fly_over_switches_at_the_waypoint() {
        let (s, start) = fly_mission2(TurnType::FlyOver);
        let (t, worst) = turn_at_w1(&s, TurnType::FlyOver);
        assert_eq!(t.kind, TurnKind::FlyOver);
        assert!(distance_m(t.leave, pt(W1)) < 0.01, "{:?}", t.leave);
        assert!(worst < 0.001, "{worst} m off the turn and the arc");
        let switch = start + s.log[start..].iter().position(|p| p.to == 3).unwrap();
        let step_travel = SPEED * DT.as_secs_f64();
        assert!(distance_m(here(&s.log[switch]), pt(W1)) <= step_travel + 0.01);
        assert!(distance_m(here(&s.log[switch - 1]), pt(W1)) > 0.01);
    }

    /// The look-ahead law: put 200 m beside the leg CCP -> W1 (to the left, then to the
    /// right), the aircraft comes back to the geodesic with the cross-track error shrinking at
    /// every step and never changing sign (no overshoot), to under a metre by the turn at W1
    /// (about 800 m on: the error decays as `exp(-s/L)`, `L` the turn radius, once it is
    /// smaller than `L`).
    #[test]
    fn the_cross_track_error_goes_to_zero_without_overshoot() {
        for side in [-90.0, 90.0] {
            let mut s = Sim::new(config_at(CCP), &mission2(2, TurnType::FlyBy));
            s.take_off();
            s.phase(FlightPhase::Cruise);
            s.run_until(100, |p| p.from_to_next() == (1, 2, 3));
            let (a, b) = (Site::of(pt(CCP)), Site::of(pt(W1)));
            let (_, course) = a.inverse(&b);
            let xte = |p: &GuidanceProgressPayload| {
                let (d, az) = a.inverse(&Site::of(here(p)));
                d * (az - course).to_radians().sin()
            };
            let now = *s.log.last().unwrap();
            s.g.position = destination(here(&now), course + side, 200.0);
            let start = s.log.len();
            s.run_until(1000, |p| p.to == 3);
            let errors: Vec<f64> = s.log[start..]
                .iter()
                .take_while(|p| p.to == 2)
                .map(xte)
                .collect();
            let first = errors[0];
            assert!(first.abs() > 150.0, "{first}");
            assert!(
                errors.windows(2).all(|w| w[1].abs() <= w[0].abs() + 1e-9),
                "not shrinking"
            );
            assert!(
                errors.iter().all(|e| e * first >= -1e-9),
                "overshoot: {:?}",
                errors
                    .iter()
                    .cloned()
                    .fold(0.0, |m: f64, e| if e * first < 0.0 {
                        m.max(e.abs())
                    } else {
                        m
                    })
            );
            let last = errors.last().unwrap().abs();
            assert!(last < 1.0, "{last}");
            eprintln!(
                "cross-track error {first:.1} m: {:.1} m after 10 s, {:.2e} m when the turn at \
                 W1 starts",
                errors[100.min(errors.len() - 1)],
                last
            );
        }
    }

    #[test]
    fn return_to_home_flies_the_route_backwards() {
        let (mut s, _) = fly_mission2(TurnType::FlyBy);
        s.set(|a| a.route_reversed = true);
        let start = s.log.len();
        let (p, _) = s.run_until(3000, |p| p.route_complete);
        assert!(
            distance_m(here(&p), pt(CCP)) < 0.01,
            "ends at the initial waypoint"
        );
        assert_eq!(s.triples(start), [(3, 2, 1), (2, 1, 0), (1, 0, 0)]);
        // The reversed RF leg ROLE2 -> W1 is the same arc, counter-clockwise.
        let (rel, points) = rf_leg(&s, |p| p.from_to_next() == (3, 2, 1));
        assert!(points.len() > 700, "{}", points.len());
        assert!(rel.iter().all(|r| *r <= 0.02));
        let bearings = unwrapped_bearings(pt(RF_CENTRE), &points);
        assert!(
            bearings.windows(2).all(|w| w[1] < w[0]),
            "not counter-clockwise"
        );
    }

    #[test]
    fn reversal_mid_leg_keeps_to_and_turns_round_after_it() {
        let mut s = Sim::new(config_at(CCP), &mission2(2, TurnType::FlyBy));
        s.take_off();
        s.phase(FlightPhase::Cruise);
        s.run_until(100, |p| p.from_to_next() == (1, 2, 3));
        s.step();
        s.set(|a| a.route_reversed = true);
        let start = s.log.len();
        let p = s.step();
        assert_eq!(p.from_to_next(), (1, 2, 1));
        let (p, _) = s.run_until(3000, |p| p.route_complete);
        assert_eq!(s.triples(start), [(1, 2, 1), (2, 1, 0), (1, 0, 0)]);
        assert!(distance_m(here(&p), pt(CCP)) < 0.01);

        // A route that is not bidirectional is not reversed.
        let mut l = mission2(3, TurnType::FlyBy);
        l.bidirectional = false;
        let mut s = Sim::new(config_at(CCP), &l);
        s.take_off();
        s.phase(FlightPhase::Cruise);
        s.set(|a| a.route_reversed = true);
        let (p, _) = s.run_until(3000, |p| p.route_complete);
        assert_eq!(p.from_to_next(), (3, 0, 0));
    }

    #[test]
    fn land_at_ends_the_route_there() {
        let mut s = Sim::new(config_at(CCP), &mission2(2, TurnType::FlyBy));
        s.take_off();
        s.phase(FlightPhase::Cruise);
        s.set(|a| a.land_at = 2);
        let start = s.log.len();
        let (p, _) = s.run_until(3000, |p| p.route_complete);
        assert_eq!(s.triples(start), [(1, 2, 0), (2, 0, 0)]);
        assert!(distance_m(here(&p), pt(W1)) < 0.01);
    }

    #[test]
    fn time_scale_ten_flies_the_same_path_ten_times_faster() {
        let fly = |time_scale: f64| {
            let mut s = Sim::new(
                GuidanceConfig {
                    time_scale,
                    ..GuidanceConfig::default()
                },
                &mission1(),
            );
            let climb = s.take_off();
            s.phase(FlightPhase::Cruise);
            let (p, cruise) = s.run_until(2000, |p| p.route_complete);
            (climb, cruise, p)
        };
        let (climb1, cruise1, p1) = fly(1.0);
        let (climb10, cruise10, p10) = fly(10.0);
        assert_eq!((climb1, climb10), (100, 10));
        assert!(
            cruise1.abs_diff(cruise10 * 10) <= 10,
            "{cruise1} {cruise10}"
        );
        assert_eq!(here(&p1), here(&p10));
        assert_eq!(p1.altitude_m, p10.altitude_m);
    }

    #[test]
    fn new_list_in_the_air_waits_for_automation() {
        let mut s = Sim::new(GuidanceConfig::default(), &mission1());
        s.take_off();
        s.phase(FlightPhase::Cruise);
        s.run(10);
        let m2 = mission2(2, TurnType::FlyBy);
        s.g.set_waypoint_list(&m2);
        let p = s.step();
        assert_eq!((p.waypoint_list, p.from_to_next()), (1, (0, 1, 0)));
        s.set(|a| a.flown_waypoint_list = 2);
        let p = s.step();
        assert_eq!((p.waypoint_list, p.from_to_next()), (2, (0, 1, 2)));
        let (p, _) = s.run_until(5000, |p| p.route_complete);
        assert!(distance_m(here(&p), pt(ROLE2)) < 0.01);

        // On the ground a new list is taken at once.
        s.phase(FlightPhase::Landing);
        s.run_until(1000, |p| p.on_ground);
        s.g.set_waypoint_list(&mission1());
        assert_eq!(s.step().waypoint_list, 1);
    }

    #[test]
    fn zones_are_detected_and_changes_logged_once() {
        // Inside the polygonal no-fly-zone from the start.
        let mut g = Guidance::new(config_at((48.264, 11.643)));
        g.set_area_list(&mission2_areas());
        let p = g.step(Instant::ZERO);
        assert_eq!((p.inside_fly_zone, p.in_no_fly_zone), (true, 3));

        // Without an area list: outside any fly-zone, in no no-fly-zone.
        let mut s = Sim::new(
            GuidanceConfig::default(),
            &list(1, &[waypoint(1, 0, NFZ_CENTRE, TurnType::FlyBy)]),
        );
        assert_eq!(
            (s.log[0].inside_fly_zone, s.log[0].in_no_fly_zone),
            (false, 0)
        );
        s.g.set_area_list(&mission2_areas());
        assert_eq!(
            (
                s.step().inside_fly_zone,
                s.log.last().unwrap().in_no_fly_zone
            ),
            (true, 0)
        );

        // Fly into the circle: detected at its border (radius = geodesic centre -> border).
        let radius = distance_m(pt(NFZ_CENTRE), pt(NFZ_BORDER));
        // 0.004° of longitude at 48.268° N on WGS-84 (the sphere of the mean radius said 296.06).
        assert!((radius - 296.95).abs() < 0.01, "{radius}");
        s.take_off();
        s.phase(FlightPhase::Cruise);
        let (p, _) = s.run_until(2000, |p| p.in_no_fly_zone != 0);
        assert_eq!(p.in_no_fly_zone, 2);
        let d = distance_m(here(&p), pt(NFZ_CENTRE));
        assert!(
            d <= radius && d > radius - SPEED * DT.as_secs_f64() - 0.01,
            "{d}"
        );
        s.run_until(2000, |p| p.route_complete);
        s.run(20);
        assert_eq!(s.g.zone_warnings, 1, "logged once, not every step");

        // Then out of the fly-zone to the north.
        let out = list(2, &[waypoint(1, 0, (48.29, 11.675), TurnType::FlyBy)]);
        s.g.set_waypoint_list(&out);
        s.set(|a| a.flown_waypoint_list = 2);
        let (p, _) = s.run_until(2000, |p| !p.inside_fly_zone);
        assert!(
            (p.latitude_deg - 48.285).abs() < 0.0001,
            "{}",
            p.latitude_deg
        );
        assert_eq!(p.in_no_fly_zone, 0);
        s.run_until(2000, |p| p.route_complete);
        assert!(!s.log.last().unwrap().inside_fly_zone);
        assert_eq!(s.g.zone_warnings, 2);
    }

    /// The zones are the geofence's: a fly-zone across the antimeridian whose northern edge,
    /// 72 km along 71° N, is a geodesic bowing about 280 m north of the parallel, and a circle
    /// whose geodesic radius reaches across the antimeridian. Containment in degrees got every
    /// one of these points wrong.
    #[test]
    fn zones_are_geodesic_and_cross_the_antimeridian() {
        let mut a = AreaListPayload::EMPTY;
        a.generation = 1;
        a.fly_zone.area_id = 1;
        a.fly_zone.vertex_count = 4;
        let corners = [(70.9, 179.0), (70.9, -179.0), (71.0, -179.0), (71.0, 179.0)];
        for (v, p) in a.fly_zone.vertices.iter_mut().zip(corners) {
            *v = gp(p);
        }
        a.no_fly_circle_count = 1;
        a.no_fly_circles[0] = CircleArea {
            area_id: 2,
            centre: gp((70.95, 179.99)),
            border: gp((70.95, -179.99)),
            ..CircleArea::EMPTY
        };
        let status = |at: Point<f64>| {
            let mut g = Guidance::new(config_at((at.y(), at.x())));
            g.set_area_list(&a);
            let p = g.step(Instant::ZERO);
            (p.inside_fly_zone, p.in_no_fly_zone)
        };

        // The northern edge's midpoint, on the antimeridian, well north of 71°.
        let (east, west) = (pt((71.0, -179.0)), pt((71.0, 179.0)));
        let mid = destination(east, bearing_deg(east, west), distance_m(east, west) / 2.0);
        assert!((mid.x().abs() - 180.0).abs() < 1e-6, "{mid:?}");
        assert!(mid.y() - 71.0 > 0.0024, "{mid:?}");
        assert_eq!(status(destination(mid, 180.0, 20.0)), (true, 0));
        assert_eq!(status(destination(mid, 0.0, 20.0)), (false, 0));

        // The circle: its centre west of the antimeridian, points due east across it.
        let centre = pt((70.95, 179.99));
        let radius = distance_m(centre, pt((70.95, -179.99)));
        let inside = destination(centre, 90.0, radius - 5.0);
        assert!(inside.x() < -179.99, "{inside:?}");
        assert_eq!(status(inside), (true, 2));
        assert_eq!(status(destination(centre, 90.0, radius + 5.0)), (true, 0));
    }
}
