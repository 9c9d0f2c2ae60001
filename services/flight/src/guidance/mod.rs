//! Guidance kinematics (the guidance stub partition, docs/design.md "Partitions"): a point-mass
//! model that flies the active waypoint list through the flight phases of system automation and
//! reports its progress (FROM-TO-NEXT, position, heading, bank, pitch and climb rate, fly-zone
//! and no-fly-zone status) on `fcc/guidance/progress`.
//!
//! Sans-IO like the rest of `services`: the driver passes the automation state, the waypoint
//! list and the area list when they arrive, and calls [`Guidance::step`] with the time; the
//! model integrates from the previous step in sub-steps of at most 50 ms of simulated time.
//! Stepping allocates nothing: the lists are the fixed payload arrays; only a new area list
//! builds (and keeps) its geofence.
//!
//! All geometry is the geofence's, the one Earth model (WGS-84, [`missionlink_protocol::geofence`]): distances,
//! bearings and destinations are geodesics ([`missionlink_protocol::geofence::earth`]), and whether the
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
//! - **Speed and wind**: the TO waypoint's commanded speed is flown as airspeed at once (no
//!   acceleration); a waypoint with speed 0 is flown at [`FALLBACK_SPEED_MPS`]. The aircraft
//!   flies in the steady wind of its configuration ([`GuidanceConfig::wind_speed_mps`]): it
//!   holds each path over the ground, crabbing into the crosswind, at the ground speed the wind
//!   leaves on the path's course there ([`GuidanceConfig::ground_speed_mps`]).
//! - **Turns in wind**: every turn is sized for the wind the plan was checked in (the list's
//!   `planning_wind`, #13001 field 5): radius `(v + W)²/(g·tan(bank))`, which a bank-limited
//!   aircraft holds over the ground in a wind of up to `W` from any direction
//!   ([`missionlink_protocol::geofence::flown_route::FlyBy`] proves it); `services/ground/tests/sans_io/flown_path.rs` flies the
//!   turns in winds from eight directions and measures the bank each step took.
//! - **What is flown is what the geofence checks**: the legs between the waypoints and, at
//!   every waypoint, the turn of [`missionlink_protocol::geofence::turn`], the one construction the onboard
//!   check and the safety gateway check too. Guidance flies each of its paths exactly (to
//!   nanometres; `services/ground/tests/sans_io/flown_path.rs` measures it).
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
//!   `r = (v + W)²/(g·tan(bank))` (`v` the speed flown in the turn: the next waypoint's, towards
//!   which the aircraft flies from the turn's start; `W` the plan's wind; the configured bank)
//!   tangent to the leg
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
//! - **Attitude and climb rate** (reported for the position downlink, ICD §4 #101), each of the
//!   last stretch flown, as the ground speed is:
//!   - *heading*: the course of the path flown turned into the crosswind by the crab angle
//!     ([`GuidanceConfig::crab_deg`]); the course itself in calm air. It is kept while the
//!     aircraft does not move over the ground (climb, descent, hover, on the ground), and not
//!     known (NaN) before its first movement: a point mass that never moved points nowhere.
//!   - *roll*: the bank that holds the path flown at the ground speed, `atan(V_g²/(g·R·cos β))`
//!     with `R` the radius of the arc there and `β` the crab angle
//!     ([`missionlink_protocol::geofence::flown_route::FlyBy`] sizes the turns by the same relation: in calm air
//!     a turn at the plan's speed takes exactly the configured bank), positive to the right; 0
//!     on geodesics, on the spot and when not moving over the ground.
//!   - *climb rate*: the altitude gained over the last sub-step per simulated second (so a
//!     time scale does not scale it), 0 once the model holds (climb done, route complete).
//!   - *pitch*: the flight-path angle through the air mass, `atan2(climb rate, airspeed)`, the
//!     airspeed being the TO waypoint's speed while moving over the ground and 0 otherwise: the
//!     vertical climb of take-off reads +90 deg and the descent of the landing -90 deg.
//!   - On the ground roll, pitch and climb rate are 0.

mod config;
mod route;
mod tracking;
mod zones;

pub use config::GuidanceConfig;

use geo::Point;
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationStatePayload, FlightPhase, GuidanceProgressPayload,
    WaypointListPayload,
};

use missionlink_protocol::link::time::Instant;
use route::{Planned, Route};
use zones::Areas;

/// Longest sub-step of the integration, simulated seconds.
pub const MAX_SUB_STEP_S: f64 = 0.05;

/// Speed flown towards a waypoint whose commanded speed is 0, m/s (the geofence models the
/// same turns: [`FlyBy`]).
pub use missionlink_protocol::geofence::flown_route::{self, FALLBACK_SPEED_MPS};

/// Climb and descent end this close to their target altitude, metres.
const ALTITUDE_EPSILON_M: f64 = 1e-6;

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
    /// Airspeed of the last stretch flown, m/s; 0 when not moving over the ground.
    airspeed_mps: f64,
    /// Where the nose points, degrees clockwise from north, 0..360; `None` before the first
    /// movement over the ground.
    heading_deg: Option<f64>,
    /// Bank of the last stretch flown, degrees, positive right; 0 when not moving over the
    /// ground.
    roll_deg: f64,
    /// Altitude gained over the last sub-step per simulated second, m/s.
    climb_rate_mps: f64,
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
            airspeed_mps: 0.0,
            heading_deg: None,
            roll_deg: 0.0,
            climb_rate_mps: 0.0,
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
                self.climb_rate_mps = 0.0;
                self.reset_route();
                self.climb_complete = false;
            }
        }
        self.sync_direction();
        if phase != Some(FlightPhase::Cruise) {
            self.hold_position();
        }

        let simulated = elapsed * self.config.time_scale;
        if simulated > 0.0 {
            let n = (simulated / MAX_SUB_STEP_S).ceil().max(1.0);
            let h = simulated / n;
            let mut i = 0.0;
            while i < n {
                let before = self.altitude_m;
                let busy = match phase {
                    Some(FlightPhase::TakeOff) => self.climb(h),
                    Some(FlightPhase::Cruise) => self.fly(h),
                    Some(FlightPhase::Landing) => self.descend(h),
                    _ => false,
                };
                // A sub-step that ends holding (climb done, on the ground, route complete)
                // ends with no vertical speed, whatever it climbed before it stopped.
                self.climb_rate_mps = if busy {
                    (self.altitude_m - before) / h
                } else {
                    0.0
                };
                if !busy {
                    break;
                }
                i += 1.0;
            }
        }

        self.check_zones();
        let (from, to, next) = self.triple(phase);
        let on_ground = self.on_ground();
        let (roll, pitch, climb) = if on_ground {
            (0.0, 0.0, 0.0)
        } else {
            let pitch = self.climb_rate_mps.atan2(self.airspeed_mps).to_degrees();
            (self.roll_deg, pitch, self.climb_rate_mps)
        };
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
            on_ground,
            reserved: [0; 3],
            heading_deg: self.heading_deg.map_or(f32::NAN, heading_f32),
            roll_deg: roll as f32,
            pitch_deg: pitch as f32,
            climb_rate_mps: climb as f32,
        }
    }

    /// Not moving over the ground (climb, descent, hover, on the ground): no ground speed, no
    /// airspeed, no bank; the nose keeps pointing where it did.
    fn hold_position(&mut self) {
        self.ground_speed_mps = 0.0;
        self.airspeed_mps = 0.0;
        self.roll_deg = 0.0;
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
}

/// A heading in 0..360 as the payload's `f32`, in 0..360 too: the few headings just below 360
/// that round to 360 in `f32` are north, 0.
fn heading_f32(heading_deg: f64) -> f32 {
    let h = heading_deg as f32;
    if h < 360.0 { h } else { 0.0 }
}

#[cfg(test)]
mod tests;
