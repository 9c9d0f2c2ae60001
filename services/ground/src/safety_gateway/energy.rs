//! The energy estimate and its checks (`ENERGY-*`, see the [module documentation](super)).
//!
//! The route is counted as it is flown: every leg, less the parts a turn cuts short (from where
//! a fly-by arc leaves the leg in to the waypoint, from the waypoint to where a turn joins the
//! leg out), plus the turn's own paths, each at the speed flown there, with the ground speed the
//! wind leaves on every chord. On a bidirectional route the return to home commanded at the
//! last waypoint, the longest one, is counted too: the reverse route with its turns and the
//! landing at the initial waypoint.

use super::*;
use missionlink_protocol::geofence::flown_route;
use missionlink_protocol::geofence::turn::{end, rest_from, start, up_to};

/// A path of the route as the estimate counts it: what it is, where it goes, the airspeed
/// flown on it and the altitude gained along it.
struct Flown {
    element: RouteElement,
    path: Path,
    speed_mps: f64,
    climb_m: f64,
}

/// The paths flown of `legs` (in the order flown, each ending where the next starts) with the
/// turns of `route` between them (`RouteElement::Turn` at a waypoint onto the leg to the next):
/// each turn's paths replace the end of the leg before it (from where the turn leaves it) and
/// the start of the leg after it (up to where the turn joins it).
fn as_flown(
    legs: Vec<Flown>,
    route: &[flown_route::RouteLeg],
    speed_of: impl Fn(u16) -> f64,
) -> Vec<Flown> {
    let mut out: Vec<Flown> = Vec::with_capacity(legs.len() * 2);
    let mut joined: Option<Site> = None;
    let mut legs = legs.into_iter().peekable();
    while let Some(mut leg) = legs.next() {
        if let Some(at) = joined.take() {
            leg.path = rest_from(&leg.path, at);
        }
        // The turn at this leg's end onto the next leg: its paths, in order.
        let next_to = legs.peek().and_then(|n| match n.element {
            RouteElement::Leg { to, .. } | RouteElement::ReverseLeg { to, .. } => Some(to),
            _ => None,
        });
        let at = match leg.element {
            RouteElement::Leg { to, .. } | RouteElement::ReverseLeg { to, .. } => Some(to),
            _ => None,
        };
        let turn: Vec<&flown_route::RouteLeg> = match (at, next_to) {
            (Some(at_n), Some(to_n)) => route
                .iter()
                .filter(|l| {
                    matches!(l.element, RouteElement::Turn { at, to, .. } if at == at_n && to == to_n)
                })
                .collect(),
            _ => Vec::new(),
        };
        match (turn.first(), turn.last()) {
            (Some(first), Some(last)) => {
                leg.path = up_to(&leg.path, start(&first.path));
                let element = first.element;
                out.push(leg);
                let speed = next_to.map_or(0.0, &speed_of);
                out.extend(turn.iter().map(|t| Flown {
                    element,
                    path: t.path,
                    speed_mps: speed,
                    climb_m: 0.0,
                }));
                joined = Some(end(&last.path));
            }
            _ => out.push(leg),
        }
    }
    out
}

impl SafetyGateway {
    /// Seconds to fly `path` at airspeed `v` in the wind, or where its track cannot be held
    /// (crosswind at or above the airspeed, or no forward ground speed).
    fn seconds(&self, path: &Path, v: f64) -> Result<f64, Option<Site>> {
        let env = &self.environment;
        // Wind vector (east, north) the air moves with.
        let from = env.wind_from_deg.to_radians();
        let wind = (
            -env.wind_speed_mps * from.sin(),
            -env.wind_speed_mps * from.cos(),
        );
        let track = Track::new(*path);
        let mut seconds = 0.0;
        for (patch, start, direction, length) in track.chords() {
            let t = (direction.to_radians().sin(), direction.to_radians().cos());
            let along = wind.0 * t.0 + wind.1 * t.1;
            let cross = wind.0 * t.1 - wind.1 * t.0;
            let disc = v * v - cross * cross;
            let ground = along + disc.max(0.0).sqrt();
            if disc <= 0.0 || ground <= 0.1 {
                return Err(track.site(patch, start));
            }
            seconds += length / ground;
        }
        Ok(seconds)
    }

    /// Cruise energy of `paths` (with the climbs along them), Wh, and the paths whose track
    /// cannot be held (left out of the sum).
    fn cruise(&self, paths: &[Flown]) -> (f64, Vec<(RouteElement, Option<Site>)>) {
        let p = &self.profile;
        let climb = |dh: f64| p.climb_power_w * dh.max(0.0) / p.climb_rate_mps / 3600.0;
        let mut wh = 0.0;
        let mut not_held: Vec<(RouteElement, Option<Site>)> = Vec::new();
        for f in paths {
            match self.seconds(&f.path, f.speed_mps) {
                Ok(s) => wh += p.cruise_power_w(f.speed_mps) * s / 3600.0 + climb(f.climb_m),
                Err(at) => {
                    if !not_held.iter().any(|(e, _)| *e == f.element) {
                        not_held.push((f.element, at));
                    }
                }
            }
        }
        (wh, not_held)
    }

    /// The energy estimate (see the module documentation), with the paths whose track cannot
    /// be held against the wind (left out of the sum).
    pub(super) fn energy(
        &self,
        mission: &Mission,
        take_off: Option<GeoPoint>,
        legs: &[Leg],
    ) -> (EnergyEstimate, Vec<(RouteElement, Option<Site>)>) {
        let p = &self.profile;
        let toh = mission.take_off_height().metres().max(0.0);
        let climb = |dh: f64| p.climb_power_w * dh.max(0.0) / p.climb_rate_mps / 3600.0;
        let descend = |dh: f64| p.descent_power_w * dh.max(0.0) / p.descent_rate_mps / 3600.0;
        let mut take_off_wh = climb(toh);
        // Without a take-off point the route starts at the initial waypoint: climb (or descend)
        // there to its altitude.
        if take_off.is_none()
            && let Some(first) = mission.waypoints.first()
        {
            let dh = first.waypoint.altitude.metres() - toh;
            take_off_wh += if dh >= 0.0 { climb(dh) } else { descend(-dh) };
        }
        let route = RouteView {
            wind_mps: self.turn_wind_mps(mission),
            ..RouteView::from(mission)
        };
        let fly_by = flown_route::FlyBy {
            bank_deg: p.max_bank_deg,
        };
        let speed_of = |n: u16| {
            route
                .waypoints
                .iter()
                .find(|w| w.number() == n)
                .map_or(0.0, |w| w.speed().mps())
        };
        let forward_legs: Vec<Flown> = legs
            .iter()
            .map(|l| Flown {
                element: l.element,
                path: l.path,
                speed_mps: l.speed_mps,
                climb_m: l.climb_m,
            })
            .collect();
        let start = take_off
            .map(Site::of)
            .or(route.waypoints.first().map(|w| Site::of(w.position())));
        let forward_turns: Vec<flown_route::RouteLeg> = start
            .into_iter()
            .flat_map(|s| flown_route::execute_route(route, s, Some(fly_by)))
            .collect();
        let (cruise_wh, mut not_held) =
            self.cruise(&as_flown(forward_legs, &forward_turns, speed_of));
        let last = route.waypoints.last();
        let landing_wh = last.map_or(0.0, |w| descend(w.altitude().metres()));
        // The return to home from the last waypoint (the route complete): the reverse route
        // with its turns, then the landing at the initial waypoint.
        let return_wh = last.filter(|_| route.bidirectional).map(|w| {
            let back: Vec<flown_route::RouteLeg> =
                flown_route::return_route(route, Site::of(w.position()), 0, Some(fly_by)).collect();
            let reverse: Vec<Flown> = back
                .iter()
                .filter_map(|l| match l.element {
                    RouteElement::ReverseLeg { from, to } => Some(Flown {
                        element: l.element,
                        path: l.path,
                        speed_mps: speed_of(to),
                        climb_m: altitude_of(&route, to) - altitude_of(&route, from),
                    }),
                    _ => None,
                })
                .collect();
            let (wh, held) = self.cruise(&as_flown(reverse, &back, speed_of));
            not_held.extend(held);
            let home = route
                .waypoints
                .first()
                .map_or(0.0, |w| w.altitude().metres());
            wh + descend(home)
        });
        let total_wh = take_off_wh + cruise_wh + landing_wh;
        (
            EnergyEstimate {
                take_off_wh,
                cruise_wh,
                landing_wh,
                total_wh,
                limit_wh: p.energy_limit_wh(),
                return_wh,
            },
            not_held,
        )
    }

    /// The energy checks: every path whose track cannot be held, the estimate against the
    /// usable energy less the reserve, and on a bidirectional route the flight with the return
    /// to home from the last waypoint against it too.
    pub(super) fn check_energy(
        &self,
        mission: &Mission,
        take_off: Option<GeoPoint>,
        legs: &[Leg],
        c: &mut Collector,
    ) {
        let (p, env) = (&self.profile, &self.environment);
        let (estimate, not_held) = self.energy(mission, take_off, legs);
        for (element, at) in not_held {
            c.push(
                ViolationCode::TrackNotHeld,
                Element::Route(element),
                format!(
                    "the track cannot be held against {} m/s wind from {} deg",
                    env.wind_speed_mps, env.wind_from_deg
                ),
                None,
            );
            if let Some(at) = at {
                c.at(at);
            }
        }
        if exceeds(estimate.total_wh, estimate.limit_wh) {
            c.push(
                ViolationCode::EnergyBudget,
                Element::Mission,
                format!(
                    "estimated energy {:.0} Wh (take-off {:.0}, cruise {:.0}, landing {:.0}) above usable {:.0} Wh minus {:.0} % reserve",
                    estimate.total_wh,
                    estimate.take_off_wh,
                    estimate.cruise_wh,
                    estimate.landing_wh,
                    p.usable_energy_wh,
                    p.reserve_fraction * 100.0
                ),
                Some((estimate.total_wh, estimate.limit_wh)),
            );
        } else if let Some(home) = estimate.with_return_wh()
            && exceeds(home, estimate.limit_wh)
        {
            c.push(
                ViolationCode::EnergyReturn,
                Element::Mission,
                format!(
                    "with a return to home from the last waypoint {home:.0} Wh (take-off {:.0}, cruise {:.0}, the way back and the landing at the initial waypoint {:.0}) above usable {:.0} Wh minus {:.0} % reserve",
                    estimate.take_off_wh,
                    estimate.cruise_wh,
                    estimate.return_wh.unwrap_or_default(),
                    p.usable_energy_wh,
                    p.reserve_fraction * 100.0
                ),
                Some((home, estimate.limit_wh)),
            );
        }
    }
}

/// The altitude of waypoint `n` of `route`, metres (0 where there is none).
fn altitude_of<W: RouteWaypoint>(route: &RouteView<'_, W>, n: u16) -> f64 {
    route
        .waypoints
        .iter()
        .find(|w| w.number() == n)
        .map_or(0.0, |w| w.altitude().metres())
}
