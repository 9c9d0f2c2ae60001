//! The onboard geofence check of ICD §7 (ext), and the legs of a route as they are flown (the
//! safety gateway walks the same legs).
//!
//! Before it accepts #50000 execute, the FCC checks the vertical climb at the take-off point
//! (where navigation says the aircraft is), the way from there to the initial waypoint (flown
//! direct, whatever its leg type: see guidance), every leg in the direction flown and the
//! straight cut of every fly-by turn between track-to-fix legs ([`FlyBy`]: what guidance flies
//! there instead of the corner); before return to home, the way from the aircraft to its TO
//! waypoint and the reverse route from there back to the initial waypoint, its turns too. Each inside the fly-zone shrunk by the safety offset and
//! outside every no-fly-zone grown by it. No allocation; at most 2 + 256 legs against 11
//! zones.

use missionlink_interfaces::contracts::{WaypointEntry, WaypointListPayload};
use missionlink_interfaces::wire::{LegType, TurnType};

use super::clearance::{Clearance, clearance};
use super::earth::Site;
use super::path::{Path, Track};
use super::zone::Fence;

/// What a path of the route is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RouteElement {
    /// The vertical climb at the take-off point.
    Climb,
    /// A leg flown from `from` to `to` (`from` 0: from the take-off point or the aircraft).
    Leg {
        /// FROM Waypoint Number (0: from where the aircraft is).
        from: u16,
        /// TO Waypoint Number.
        to: u16,
    },
    /// A leg of the reverse route (return to home), flown from `from` to `to`.
    ReverseLeg {
        /// FROM Waypoint Number.
        from: u16,
        /// TO Waypoint Number.
        to: u16,
    },
    /// The straight cut of a fly-by turn at waypoint `at`: from where guidance switches to the
    /// next leg to the next waypoint `to` ([`FlyBy`]).
    FlyByTurn {
        /// The fly-by waypoint.
        at: u16,
        /// The waypoint flown to from the switch.
        to: u16,
    },
}

impl core::fmt::Display for RouteElement {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Climb => f.write_str("climb at the take-off point"),
            Self::Leg { from: 0, to } => write!(f, "leg to waypoint {to} from the take-off point"),
            Self::Leg { from, to } => write!(f, "leg {from}->{to}"),
            Self::ReverseLeg { from, to } => write!(f, "reverse leg {from}->{to}"),
            Self::FlyByTurn { at, to } => {
                write!(
                    f,
                    "fly-by turn at waypoint {at}, cutting across to waypoint {to}"
                )
            }
        }
    }
}

/// One path of the route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteLeg {
    /// What it is.
    pub element: RouteElement,
    /// Where it goes.
    pub path: Path,
}

fn site(w: &WaypointEntry) -> Site {
    Site::of(w.position)
}

/// The leg flown from `from` to `to` by `to`'s leg type (a radius-to-fix leg as its arc).
fn leg(from: &WaypointEntry, to: &WaypointEntry) -> Path {
    match (to.leg_type(), to.rf_centre()) {
        (Some(LegType::RadiusToFix), Some((centre, direction))) => Path::Arc {
            from: site(from),
            to: site(to),
            centre: Site::of(centre),
            direction,
        },
        _ => Path::Geodesic {
            from: site(from),
            to: site(to),
        },
    }
}

/// The legs between consecutive waypoints, in flight-plan order.
pub fn legs(list: &WaypointListPayload) -> impl Iterator<Item = RouteLeg> + '_ {
    list.waypoints().windows(2).filter_map(|w| match w {
        [a, b] => Some(RouteLeg {
            element: RouteElement::Leg {
                from: a.number,
                to: b.number,
            },
            path: leg(a, b),
        }),
        _ => None,
    })
}

/// The legs of the reverse route back from the last of `waypoints` to the first.
fn back_over(waypoints: &[WaypointEntry]) -> impl Iterator<Item = RouteLeg> + '_ {
    waypoints.windows(2).rev().filter_map(|w| match w {
        [a, b] => Some(RouteLeg {
            element: RouteElement::ReverseLeg {
                from: b.number,
                to: a.number,
            },
            path: leg(a, b).reversed(),
        }),
        _ => None,
    })
}

/// What execute flies from `take_off`: the climb there, the way to the initial waypoint, every
/// leg, and with `fly_by` the cut of every fly-by turn.
pub fn execute_route(
    list: &WaypointListPayload,
    take_off: Site,
    fly_by: Option<FlyBy>,
) -> impl Iterator<Item = RouteLeg> + '_ {
    let first = list.waypoints().first().map(|w| RouteLeg {
        element: RouteElement::Leg {
            from: 0,
            to: w.number,
        },
        path: Path::Geodesic {
            from: take_off,
            to: site(w),
        },
    });
    let climb = RouteLeg {
        element: RouteElement::Climb,
        path: Path::Point(take_off),
    };
    let cuts = fly_by
        .into_iter()
        .flat_map(move |f| f.cuts(list.waypoints(), take_off, false));
    core::iter::once(climb)
        .chain(first)
        .chain(legs(list))
        .chain(cuts)
}

/// What return to home flies from `position` with `to` the TO waypoint (0: the route is
/// complete, the way back starts at the last waypoint): direct to that waypoint, then the
/// reverse route from there to the initial waypoint (guidance's return to home).
pub fn return_route(
    list: &WaypointListPayload,
    position: Site,
    to: u16,
    fly_by: Option<FlyBy>,
) -> impl Iterator<Item = RouteLeg> + '_ {
    let waypoints = list.waypoints();
    let index = waypoints
        .iter()
        .position(|w| w.number == to)
        .unwrap_or(waypoints.len().saturating_sub(1));
    let direct = waypoints.get(index).map(|w| RouteLeg {
        element: RouteElement::Leg {
            from: 0,
            to: w.number,
        },
        path: Path::Geodesic {
            from: position,
            to: site(w),
        },
    });
    let back = waypoints.get(..=index).unwrap_or_default();
    let cuts = fly_by
        .into_iter()
        .flat_map(move |f| f.cuts(back, position, true));
    direct.into_iter().chain(back_over(back)).chain(cuts)
}

/// How guidance turns at a fly-by waypoint between two track-to-fix legs (the guidance stub's
/// rule, `guidance.rs` "Fly-by"): it switches to the next leg `d = r·tan(Δψ/2)` before the
/// waypoint (at most half the next leg; all of it for a U-turn), `r = v²/(g·tan(bank))` at the
/// waypoint's speed, and flies straight from there to the next waypoint. That cut leaves the
/// legs, inside the corner, by up to about `d·sin(Δψ)`; the checks add it to the legs.
/// A turn onto or off a radius-to-fix leg is not modelled (guidance joins the arc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlyBy {
    /// Guidance's bank angle in the turn, degrees (0 < bank < 90).
    pub bank_deg: f64,
}

/// Standard gravity, m/s².
const GRAVITY_MPS2: f64 = 9.806_65;
/// The speed guidance flies towards a waypoint whose speed is 0, m/s.
pub const FALLBACK_SPEED_MPS: f64 = 10.0;

impl FlyBy {
    /// The speed guidance flies towards `w`: its commanded speed, or [`FALLBACK_SPEED_MPS`].
    pub fn speed_mps(w: &WaypointEntry) -> f64 {
        match w.speed.mps() {
            v if v > 0.0 => v,
            _ => FALLBACK_SPEED_MPS,
        }
    }

    /// Radius of a turn at `v` and the bank: `v²/(g·tan(bank))`, metres.
    pub fn turn_radius_m(&self, v: f64) -> f64 {
        v * v / (GRAVITY_MPS2 * self.bank_deg.to_radians().tan())
    }

    /// How far before a fly-by waypoint guidance switches to the next leg, flying at `v` and
    /// turning `turn_deg` onto a next leg of `next_length` metres.
    pub fn anticipation_m(&self, v: f64, turn_deg: f64, next_length: f64) -> f64 {
        let r = self.turn_radius_m(v);
        let cap = next_length / 2.0;
        if turn_deg >= 179.999 {
            cap
        } else {
            (r * (turn_deg / 2.0).to_radians().tan()).min(cap)
        }
    }

    /// The cuts of the fly-by turns along `waypoints` flown from `start` in their order, or
    /// (`reverse`) backwards from the last, each leg then of the type of the waypoint it leaves.
    fn cuts(
        self,
        waypoints: &[WaypointEntry],
        start: Site,
        reverse: bool,
    ) -> impl Iterator<Item = RouteLeg> + '_ {
        let n = waypoints.len();
        // The k-th waypoint flown.
        let flown = move |k: usize| {
            let i = if reverse { n.checked_sub(k + 1)? } else { k };
            waypoints.get(i)
        };
        let mut from = start;
        (0..n).filter_map(move |k| {
            let (w, next) = (flown(k)?, flown(k + 1));
            let here = site(w);
            let inbound_from = from;
            from = here;
            let next = next?;
            // The leg out of `w`: its type is the one of the waypoint it ends at (forward), or
            // of the waypoint it leaves (reverse).
            let out_type = if reverse {
                w.leg_type()
            } else {
                next.leg_type()
            };
            let in_type = if k == 0 {
                Some(LegType::TrackToFix) // the way from `start`, flown direct
            } else if reverse {
                flown(k - 1).and_then(|p| p.leg_type())
            } else {
                w.leg_type()
            };
            if w.turn_type() == Some(TurnType::FlyOver)
                || out_type != Some(LegType::TrackToFix)
                || in_type != Some(LegType::TrackToFix)
            {
                return None;
            }
            let (inbound_length, _, inbound) = inbound_from.inverse_azimuths(&here);
            if inbound_length <= 0.0 {
                return None;
            }
            let there = site(next);
            let (next_length, outbound) = here.inverse(&there);
            let turn = ((outbound - inbound + 180.0).rem_euclid(360.0) - 180.0).abs();
            let d = self
                .anticipation_m(Self::speed_mps(w), turn, next_length)
                .min(inbound_length);
            let switch = here.direct(inbound + 180.0, d);
            from = switch;
            Some(RouteLeg {
                element: RouteElement::FlyByTurn {
                    at: w.number,
                    to: next.number,
                },
                path: Path::Geodesic {
                    from: switch,
                    to: there,
                },
            })
        })
    }
}

/// The first path of `route` that comes closer than the safety offset to a zone's border or
/// crosses to its forbidden side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// The path.
    pub element: RouteElement,
    /// Area ID of the zone.
    pub area_id: u16,
    /// The clearance found (its margin is below the safety offset).
    pub clearance: Clearance,
}

/// The onboard check of ICD §7: every path of `route` against every zone of `fence`. Stops at
/// the first violation.
pub fn check(fence: &Fence, route: impl Iterator<Item = RouteLeg>) -> Result<(), Violation> {
    let offset = fence.safety_offset_m;
    for leg in route {
        let track = Track::new(leg.path);
        for zone in &fence.zones {
            let c = clearance(&track, zone, offset, false);
            // Fail closed: a margin that is not a number (a position that is not one) is no
            // clearance.
            let m = c.metres();
            if m.is_nan() || m < offset {
                return Err(Violation {
                    element: leg.element,
                    area_id: zone.id,
                    clearance: c,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geofence::zone::Fence;
    use crate::testkit;

    /// The FCC flies the fly-by turn's cut too: execute from the plan's take-off is refused on
    /// it, and with the turns left out (what the check did before) it would pass.
    #[test]
    fn the_cut_of_a_fly_by_turn_is_checked() {
        let corner = testkit::fly_by_corner();
        let lists = corner.assemble().unwrap();
        let (waypoints, areas) = (lists.mission.to_payload(1), lists.areas.to_payload(1));
        let fence = Fence::of_payload(&areas);
        let take_off = Site::of(corner.take_off_position.unwrap());
        let turns = crate::automation::fcc_turns();
        let refused = check(&fence, execute_route(&waypoints, take_off, Some(turns)));
        assert!(
            matches!(
                refused,
                Err(Violation {
                    element: RouteElement::FlyByTurn { at: 2, to: 3 },
                    area_id: 4,
                    ..
                })
            ),
            "{refused:?}"
        );
        assert_eq!(
            check(&fence, execute_route(&waypoints, take_off, None)),
            Ok(())
        );
    }
}
