//! The onboard geofence check of ICD §7 (ext), and the legs of a route as they are flown (the
//! safety gateway walks the same legs).
//!
//! Before it accepts #50000 execute, the FCC checks the vertical climb at the take-off point
//! (where navigation says the aircraft is), the way from there to the initial waypoint (flown
//! direct, whatever its leg type: see guidance) and every leg in the direction flown; before
//! return to home, the way from the aircraft to its TO waypoint and the reverse route from there
//! back to the initial waypoint. Each inside the fly-zone shrunk by the safety offset and
//! outside every no-fly-zone grown by it. No allocation; at most 2 + 256 legs against 11
//! zones.

use missionlink_interfaces::contracts::{WaypointEntry, WaypointListPayload};
use missionlink_interfaces::wire::LegType;

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
}

impl core::fmt::Display for RouteElement {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Climb => f.write_str("climb at the take-off point"),
            Self::Leg { from: 0, to } => write!(f, "leg to waypoint {to} from the take-off point"),
            Self::Leg { from, to } => write!(f, "leg {from}->{to}"),
            Self::ReverseLeg { from, to } => write!(f, "reverse leg {from}->{to}"),
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

/// The legs of the reverse route, from the last waypoint back to the initial one.
pub fn reverse_legs(list: &WaypointListPayload) -> impl Iterator<Item = RouteLeg> + '_ {
    back_over(list.waypoints())
}

/// What execute flies from `take_off`: the climb there, the way to the initial waypoint, every
/// leg.
pub fn execute_route(
    list: &WaypointListPayload,
    take_off: Site,
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
    core::iter::once(climb).chain(first).chain(legs(list))
}

/// What return to home flies from `position` with `to` the TO waypoint (0: the route is
/// complete, the way back starts at the last waypoint): direct to that waypoint, then the
/// reverse route from there to the initial waypoint (guidance's return to home).
pub fn return_route(
    list: &WaypointListPayload,
    position: Site,
    to: u16,
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
    direct.into_iter().chain(back_over(back))
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
