//! The onboard geofence check of ICD §7 (ext): the route as flown ([`missionlink_protocol::geofence::flown_route`])
//! against the fence.
//!
//! Before it accepts #50000 execute, the FCC checks the vertical climb at the take-off point
//! (where navigation says the aircraft is), the way from there to the initial waypoint (the
//! geodesic, whatever its leg type: see guidance), every leg in the direction flown, in full
//! (a leg is flown to its end when the aircraft is told to land at its waypoint), and every
//! turn at a waypoint as guidance flies it ([`missionlink_protocol::geofence::turn`]: the fly-by arc tangent to both
//! legs, or the fly-over's turn, intercept and turn onto the next leg); before return to home,
//! the way from the aircraft to its TO waypoint with the turn onto that leg (the aircraft may be
//! on it), the turn round there, and the reverse route from there back to the initial waypoint
//! with its turns. Each inside the fly-zone shrunk by the
//! safety offset and outside every no-fly-zone grown by it. No allocation; at most
//! 2 + 256 legs and 3 paths per turn against 11 zones.
//!
//! The areas are the [`Fence`], which both sides build from their area list; the paths are
//! [`missionlink_protocol::geofence::flown_route`]'s, which the safety gateway and the map walk too.

use missionlink_protocol::geofence::clearance::{Clearance, clearance};
use missionlink_protocol::geofence::flown_route::{RouteElement, RouteLeg};
use missionlink_protocol::geofence::path::Track;
use missionlink_protocol::geofence::zone::Fence;

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
    use crate::testkit;
    use missionlink_protocol::geofence::earth::Site;
    use missionlink_protocol::geofence::flown_route::*;
    use missionlink_protocol::geofence::turn::TurnKind;
    use missionlink_protocol::geofence::zone::Fence;

    /// The FCC checks the fly-by arc too: execute from the plan's take-off is refused on it,
    /// and with the turns left out it would pass.
    #[test]
    fn the_arc_of_a_fly_by_turn_is_checked() {
        let corner = testkit::fly_by_corner();
        let lists = corner.assemble().unwrap();
        let (waypoints, areas) = (lists.mission.to_payload(1), lists.areas.to_payload(1));
        let fence = Fence::of_payload(&areas);
        let take_off = Site::of(corner.take_off_position.unwrap());
        let turns = crate::automation::fcc_turns();
        let route = RouteView::from(&waypoints);
        let refused = check(&fence, execute_route(route, take_off, Some(turns)));
        assert!(
            matches!(
                refused,
                Err(Violation {
                    element: RouteElement::Turn {
                        at: 2,
                        to: 3,
                        kind: TurnKind::FlyBy
                    },
                    area_id: 4,
                    ..
                })
            ),
            "{refused:?}"
        );
        assert_eq!(check(&fence, execute_route(route, take_off, None)), Ok(()));
    }

    /// The bank of a turn is the inverse of its radius: at the radius of the bank limit the
    /// limit, in calm air; drift needs more bank on the same radius; no radius, no bank.
    #[test]
    fn the_bank_on_a_radius_inverts_the_turn_radius() {
        let fly_by = FlyBy { bank_deg: 25.0 };
        let r = fly_by.turn_radius_m(25.0);
        assert!((FlyBy::bank_on_radius_deg(25.0, r, 0.0) - 25.0).abs() < 1e-12);
        assert!(FlyBy::bank_on_radius_deg(25.0, r, 20.0) > 25.0);
        assert!((FlyBy::bank_on_radius_deg(25.0, r, 90.0) - 90.0).abs() < 1e-9);
        assert_eq!(FlyBy::bank_on_radius_deg(25.0, 0.0, 0.0), 0.0);
        assert_eq!(FlyBy::bank_on_radius_deg(f64::NAN, r, 0.0), 0.0);
    }

    /// The ground's plan and the FCC's published list are one route: every path of execute,
    /// return to home and the turns round is the same from either view.
    #[test]
    fn the_plan_and_the_published_list_give_the_same_route() {
        let turns = crate::automation::fcc_turns();
        for plan in [
            testkit::mission_1(),
            testkit::mission_2(),
            testkit::fly_by_corner(),
        ] {
            let mission = plan.assemble().unwrap().mission;
            let payload = mission.to_payload(1);
            let (ground, fcc) = (RouteView::from(&mission), RouteView::from(&payload));
            assert_eq!(ground.bidirectional, fcc.bidirectional);
            assert_eq!(ground.take_off_height, fcc.take_off_height);
            let start = Site::of(plan.take_off_position.unwrap());
            let last = fcc.waypoints.last().unwrap();
            let at = Site::of(last.position);
            assert!(execute_route(ground, start, Some(turns)).eq(execute_route(
                fcc,
                start,
                Some(turns)
            )));
            for to in [0, last.number] {
                assert!(return_route(ground, at, to, Some(turns)).eq(return_route(
                    fcc,
                    at,
                    to,
                    Some(turns)
                )));
            }
            assert!(turns_round(ground, turns).eq(turns_round(fcc, turns)));
            assert!(execute_route(fcc, start, Some(turns)).count() > fcc.waypoints.len());
        }
    }
}
