//! Tracking: flying the route's paths in cruise (the turn onto a leg, the leg to the start of
//! the turn at TO), the look-ahead law on geodesics, arcs in polar coordinates, and the
//! altitude along the way.

use geo::Point;
use missionlink_interfaces::contracts::WaypointEntry;

use super::Guidance;
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::flown_route::FlyBy;
use missionlink_protocol::geofence::path::Path;
use missionlink_protocol::geofence::turn::{ArcGeometry, TurnKind, angle_to_go, end, length_m};

/// Path ends (turn paths, leg switches, arrivals) handled within one sub-step at most.
const MAX_LEGS_PER_SUB_STEP: usize = 8;

/// The shortest look-ahead of the cross-track law on a track-to-fix leg, metres.
const MIN_LOOK_AHEAD_M: f64 = 10.0;

/// A waypoint closer than this is reached, metres.
const REACHED_M: f64 = 0.01;

/// The remaining length of `path` from `here`, a point of it, metres.
pub(super) fn remaining_on(path: &Path, here: &Site) -> f64 {
    match path {
        Path::Point(_) => 0.0,
        Path::Geodesic { to, .. } => here.inverse(to).0,
        Path::Arc(leg) => {
            let arc = leg.geometry();
            let az = arc.centre.inverse(here).1;
            let alpha = to_go(&arc, az);
            alpha.to_radians() * (arc.radius_at(az) + arc.r1) / 2.0
        }
    }
}

/// Degrees still to turn on `arc` from azimuth `az`: 0 past the end (a wrap beyond the sweep).
pub(super) fn to_go(arc: &ArcGeometry, az: f64) -> f64 {
    let alpha = angle_to_go(az, arc.az1, arc.clockwise);
    if alpha > arc.sweep && alpha > 180.0 {
        0.0
    } else {
        alpha
    }
}

/// The course over the ground at `here` (a point of `path`) flying along it, degrees: towards
/// the geodesic's end, along the arc's tangent.
pub(super) fn course_on(path: &Path, here: &Site) -> f64 {
    match path {
        Path::Point(_) => 0.0,
        Path::Geodesic { to, .. } => here.inverse(to).1,
        Path::Arc(leg) => leg.geometry().course_at(here),
    }
}

/// The bank flying along `path` at `here` (a point of it) at ground speed `v` with the crab
/// angle `crab_deg`, degrees, positive right wing down: 0 on a geodesic and on the spot; on an
/// arc (a turn, a radius-to-fix leg) the bank that holds the arc's radius there
/// ([`FlyBy::bank_on_radius_deg`], the relation the turns are sized by), to the right when
/// the arc runs clockwise.
pub(super) fn bank_on(path: &Path, here: &Site, v: f64, crab_deg: f64) -> f64 {
    match path {
        Path::Point(_) | Path::Geodesic { .. } => 0.0,
        Path::Arc(leg) => {
            let arc = leg.geometry();
            let az = arc.centre.inverse(here).1;
            let bank = FlyBy::bank_on_radius_deg(v, arc.radius_at(az), crab_deg);
            if arc.clockwise { bank } else { -bank }
        }
    }
}

/// The speed flown towards `e`.
pub(super) fn leg_speed(e: &WaypointEntry) -> f64 {
    FlyBy::speed_mps(e)
}

impl Guidance {
    /// One cruise sub-step of `h` seconds; false when holding (route complete or no list).
    pub(super) fn fly(&mut self, h: f64) -> bool {
        let mut left = h;
        for _ in 0..MAX_LEGS_PER_SUB_STEP {
            if left <= 0.0 {
                break;
            }
            match self.fly_leg(left) {
                Some(used) => left -= used,
                None => {
                    self.hold_position();
                    return false;
                }
            }
        }
        true
    }

    /// Flies the route for up to `dt` seconds: the turn onto the leg, then the leg up to where
    /// the turn at TO starts. Returns the time used (0 on a switch at a path's end), `None`
    /// when there is nothing to fly.
    pub(super) fn fly_leg(&mut self, dt: f64) -> Option<f64> {
        let to_index = self.route.to?;
        let to = *self.entry(to_index)?;
        let target = Site::of(to.position);
        let here = Site::of(self.position);
        // The TO waypoint's speed is the airspeed; the ground speed is the one on the course
        // of the path flown here, in the configured wind, and so are the heading (the course
        // turned into the crosswind) and the bank the path takes.
        let airspeed = leg_speed(&to);
        let flying = self.route.turn.last().copied().unwrap_or(self.route.body);
        let course = course_on(&flying, &here);
        let v = self.config.ground_speed_mps(airspeed, course);
        let crab = self.config.crab_deg(airspeed, course);
        self.ground_speed_mps = v;
        self.airspeed_mps = airspeed;
        self.heading_deg = Some(self.config.heading_deg(airspeed, course));
        self.roll_deg = bank_on(&flying, &here, v, crab);
        let budget = v * dt;
        let target_alt = to.altitude.metres();

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
                self.set_position(end(&path));
                self.route.turn.pop();
                return Some(remaining.max(0.0) / v);
            }
            self.climb_towards(target_alt, budget, ahead);
            self.advance(&path, &here, budget, airspeed);
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
        self.advance(&body, &here, budget, airspeed);
        Some(dt)
    }

    /// The altitude after `distance` metres of `ahead` still to fly to `target`'s altitude.
    pub(super) fn climb_towards(&mut self, target: f64, distance: f64, ahead: f64) {
        if ahead <= distance || ahead <= 0.0 {
            self.altitude_m = target;
        } else {
            self.altitude_m += (target - self.altitude_m) * distance / ahead;
        }
    }

    pub(super) fn set_position(&mut self, at: Site) {
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
    pub(super) fn advance(&mut self, path: &Path, here: &Site, distance: f64, v: f64) {
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
            Path::Arc(leg) => {
                let arc = leg.geometry();
                let az = arc.centre.inverse(here).1;
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

    /// Radius of a turn flown at airspeed `v` in the plan's wind, metres
    /// ([`FlyBy::radius_in_wind_m`]).
    pub(super) fn turn_radius(&self, v: f64) -> f64 {
        self.config
            .fly_by()
            .radius_in_wind_m(v, self.list.planning_wind.mps())
    }
}
