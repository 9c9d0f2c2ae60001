//! The route of the list flown: where the aircraft is on it (FROM, TO, the leg and the turn
//! onto it), which waypoint comes next (forwards, reversed for return to home, cut short by
//! land-at), the legs between waypoints and the turn planned at TO.

use missionlink_interfaces::contracts::{FlightPhase, WaypointEntry};
use missionlink_protocol::geofence::flown_route;

use super::Guidance;
use super::tracking::leg_speed;
use missionlink_protocol::geofence::earth::{Site, distance_m, point};
use missionlink_protocol::geofence::path::Path;
use missionlink_protocol::geofence::turn::{MAX_TURN_PATHS, Turn, rest_from, turn};

pub(super) const NOWHERE: Site = Site {
    lat: 0.0,
    lon: 0.0,
    ecef: [0.0; 3],
};

/// Where the aircraft is on the route. Indices are into [`WaypointListPayload::waypoints`].
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Route {
    /// The route has been started (take-off or cruise with this list).
    pub(super) started: bool,
    /// Flown backwards (return to home).
    pub(super) reversed: bool,
    /// FROM waypoint number, 0 for none.
    pub(super) from: u16,
    /// Index of the TO waypoint; `None` when complete or without a list.
    pub(super) to: Option<usize>,
    /// The last waypoint of the route is reached.
    pub(super) complete: bool,
    /// The leg to TO in full (the geodesic from where the route started, for the first leg):
    /// what the turn at TO starts from.
    pub(super) leg: Path,
    /// The part of the leg still ahead once the turn onto it is flown: from where the turn
    /// joined it.
    pub(super) body: Path,
    /// The paths of the turn onto this leg not flown yet, the next one last.
    pub(super) turn: heapless::Vec<Path, MAX_TURN_PATHS>,
    /// Counts the legs started, for the planned turn.
    pub(super) serial: u64,
}

impl Route {
    pub(super) const NOT_STARTED: Self = Self {
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
pub(super) struct Planned {
    pub(super) serial: u64,
    pub(super) next: usize,
    /// Flown over whatever the turn type (the aircraft is past the fly-by arc's start).
    pub(super) over: bool,
    pub(super) turn: Turn,
}

impl Guidance {
    pub(super) fn reversal_wanted(&self) -> bool {
        self.automation.route_reversed && self.list.bidirectional
    }

    pub(super) fn entry(&self, index: usize) -> Option<&WaypointEntry> {
        self.list.waypoints().get(index)
    }

    pub(super) fn index_of(&self, number: u16) -> Option<usize> {
        self.list
            .waypoints()
            .iter()
            .position(|w| w.number == number)
    }

    pub(super) fn number(&self, index: Option<usize>) -> u16 {
        index.and_then(|i| self.entry(i)).map_or(0, |w| w.number)
    }

    /// Starts the route of the list flown: FROM 0, TO the first waypoint (or, reversed, the
    /// nearest one), flown direct.
    pub(super) fn start_route_if_needed(&mut self) {
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
    pub(super) fn sync_direction(&mut self) {
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
    pub(super) fn end_index(&self, to: usize) -> usize {
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
    pub(super) fn next_index(&self, to: usize) -> Option<usize> {
        let end = self.end_index(to);
        if self.route.reversed {
            (to > end).then(|| to - 1)
        } else {
            (to < end).then(|| to + 1)
        }
    }

    /// The leg flown from the waypoint at `from` to the adjacent one at `to`: forwards by the
    /// leg type of `to`, backwards the leg from `to` to `from` turned round.
    pub(super) fn leg_between(&self, from: usize, to: usize) -> Option<Path> {
        if to > from {
            Some(flown_route::leg(self.entry(from)?, self.entry(to)?))
        } else {
            Some(flown_route::leg(self.entry(to)?, self.entry(from)?).reversed())
        }
    }

    /// Starts the leg from the waypoint at `from` to the one at `to`, joined after `turn`.
    pub(super) fn enter(&mut self, from: usize, to: usize, turn: Option<&Turn>) {
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

    pub(super) fn triple(&self, phase: Option<FlightPhase>) -> (u16, u16, u16) {
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

    /// The turn at the TO waypoint (index `to`) onto the leg to `next`, planned once per leg.
    pub(super) fn planned_turn(&mut self, to: usize, next: usize, over: bool) -> Option<Turn> {
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
            self.config.fly_by().turn(
                &w,
                &after,
                &self.route.leg,
                &outbound,
                self.list.planning_wind.mps(),
            )
        };
        self.planned = Some(Planned {
            serial: self.route.serial,
            next,
            over,
            turn: t.clone(),
        });
        Some(t)
    }
}
