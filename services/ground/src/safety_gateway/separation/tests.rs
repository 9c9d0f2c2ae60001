//! The separation check's cases with their exact expectations: crossing, parallel and stacked
//! routes, a radius-to-fix arc, a turn the wind widens, the demo missions; the arc's distance
//! against the exact one; the sweep against every pair; the errors.

use super::*;
use crate::testkit::{self, CCP};
use missionlink_interfaces::wire::{
    Altitude, Angle, LegType, Message, TurnDirection, TurnType, UaPositionWaypoint,
};
use missionlink_protocol::geofence::path::ArcLeg;
use missionlink_protocol::geofence::turn::TurnKind;

/// A point of the tests' airspace, south of the demo's.
fn origin() -> Site {
    Site::new(48.20, 11.66)
}

fn wire(s: Site) -> GeoPoint {
    GeoPoint {
        latitude: Angle::from_degrees(s.lat).unwrap(),
        longitude: Angle::from_degrees(s.lon).unwrap(),
    }
}

#[derive(Clone, Copy)]
struct Wp {
    at: Site,
    alt: f64,
    rf: Option<(Site, TurnDirection)>,
}

fn wp(at: Site, alt: f64) -> Wp {
    Wp { at, alt, rf: None }
}

/// A one-way mission over `wps`, numbered 1, 2, ... in that order, take-off height 30 m, all
/// fly-by at 25 m/s, assembled (and so valid, ICD §7) as the FCC would.
fn mission(wps: &[Wp]) -> Mission {
    let n = wps.len() as u16;
    let mut messages: Vec<Message> = vec![
        testkit::take_off(30.0).into(),
        testkit::route(1, false).into(),
    ];
    for (i, w) in wps.iter().enumerate() {
        let number = i as u16 + 1;
        let next = if number == n { 0 } else { number + 1 };
        let leg = match w.rf {
            Some(_) => LegType::RadiusToFix,
            None => LegType::TrackToFix,
        };
        messages.push(
            UaPositionWaypoint {
                altitude: Altitude::from_metres(w.alt).unwrap(),
                ..testkit::waypoint(number, next, (w.at.lat, w.at.lon), leg)
            }
            .into(),
        );
        if let Some((centre, direction)) = w.rf {
            messages.push(testkit::rf_centre(number, (centre.lat, centre.lon), direction).into());
        }
    }
    testkit::mission_buffer(&messages)
        .assemble(Some(n), None)
        .unwrap()
}

fn flight<'a>(vehicle: &'a str, mission: &'a Mission) -> Flight<'a> {
    Flight {
        vehicle,
        mission,
        take_off: None,
    }
}

const SEPARATION: Separation = Separation {
    horizontal_m: 500.0,
    vertical_m: 150.0,
};

fn check(own: Flight<'_>, others: &[Flight<'_>], separation: Separation) -> Vec<Conflict> {
    conflicts(&SafetyGateway::default(), own, others, separation).unwrap()
}

fn leg(from: u16, to: u16) -> RouteElement {
    RouteElement::Leg { from, to }
}

/// The pairs of elements in conflict, in the order reported.
fn pairs(found: &[Conflict]) -> Vec<(RouteElement, RouteElement)> {
    found
        .iter()
        .map(|c| (c.own.element, c.other.element))
        .collect()
}

/// No conflict.
fn none(found: Vec<Conflict>) {
    assert!(found.is_empty(), "{found:#?}");
}

fn metres_between(a: (f64, f64), b: Site) -> f64 {
    Site::new(a.0, a.1).inverse(&b).0
}

/// Two routes crossing at right angles at the same altitude: one conflict, at the crossing,
/// the paths at distance 0 so the margin is the whole separation.
#[test]
fn crossing_routes_conflict_at_the_crossing() {
    let x = origin();
    let north = mission(&[
        wp(x.direct(180.0, 1000.0), 120.0),
        wp(x.direct(0.0, 1000.0), 120.0),
    ]);
    // Both ends on the geodesic through the crossing point heading east: it passes through it.
    let east = mission(&[
        wp(x.direct(270.0, 1000.0), 120.0),
        wp(x.direct(90.0, 1000.0), 120.0),
    ]);
    let found = check(
        flight("alpha", &north),
        &[flight("bravo", &east)],
        SEPARATION,
    );
    assert_eq!(pairs(&found), [(leg(1, 2), leg(1, 2))]);
    let c = &found[0];
    assert_eq!(c.own.vehicle, "alpha");
    assert_eq!(c.other.vehicle, "bravo");
    assert_eq!(c.distance_m, 0.0);
    assert_eq!(c.margin_m, 500.0);
    assert_eq!(c.vertical_gap_m, 0.0);
    assert_eq!(c.own.altitudes_m, (120.0, 120.0));
    let off = metres_between(c.position, x);
    assert!(off < 1.0, "{off} m from the crossing");
    // As the gateway reports it.
    let v = c.violation();
    assert_eq!(v.code.code(), "FLEET-SEP");
    assert_eq!(v.element, Element::Route(leg(1, 2)));
    assert_eq!(v.margin_m, Some(-500.0));
    assert_eq!((v.value, v.limit), (Some(0.0), Some(500.0)));
    assert_eq!(v.position, Some(c.position));
    assert_eq!(
        v.detail,
        "leg 1->2 of alpha (120 to 120 m) comes within 0.0 m of leg 1->2 of bravo (120 to 120 m), \
         500.0 m inside the separation of 500 m, 0 m apart in altitude (vertical separation 150 m)"
    );
    // The other way round: the same pair, placed on bravo's path.
    let back = check(
        flight("bravo", &east),
        &[flight("alpha", &north)],
        SEPARATION,
    );
    assert_eq!(pairs(&back), [(leg(1, 2), leg(1, 2))]);
    assert!(metres_between(back[0].position, x) < 1.0);
}

/// Three waypoints due north, 1 km apart, and the same `east_m` east of each.
fn parallel(east_m: f64) -> (Mission, Mission) {
    let w: Vec<Site> = (0..3)
        .map(|k| origin().direct(0.0, 1000.0 * f64::from(k)))
        .collect();
    let own = mission(&w.iter().map(|s| wp(*s, 120.0)).collect::<Vec<_>>());
    let other = mission(
        &w.iter()
            .map(|s| wp(s.direct(90.0, east_m), 120.0))
            .collect::<Vec<_>>(),
    );
    (own, other)
}

/// Parallel routes 600 m apart keep a separation of 500 m; 400 m apart, every leg of the one
/// conflicts with every leg of the other (the legs that follow each other meet the other's at
/// the waypoint between them, 400 m away), once per pair, 100 m inside the separation.
#[test]
fn parallel_routes_conflict_once_per_pair_of_legs() {
    let (own, far) = parallel(600.0);
    none(check(
        flight("alpha", &own),
        &[flight("bravo", &far)],
        SEPARATION,
    ));
    let (own, near) = parallel(400.0);
    // Straight on at the middle waypoint: no turn, the legs only.
    let elements: Vec<RouteElement> = Flown::new(&SafetyGateway::default(), flight("b", &near))
        .elements()
        .map(|(e, _)| e)
        .collect();
    assert_eq!(elements, [leg(1, 2), leg(2, 3)]);
    let found = check(flight("alpha", &own), &[flight("bravo", &near)], SEPARATION);
    assert_eq!(
        pairs(&found),
        [
            (leg(1, 2), leg(1, 2)),
            (leg(1, 2), leg(2, 3)),
            (leg(2, 3), leg(1, 2)),
            (leg(2, 3), leg(2, 3)),
        ]
    );
    for c in &found {
        assert!((c.distance_m - 400.0).abs() < 0.01, "{c}");
        assert!((c.margin_m - 100.0).abs() < 0.01, "{c}");
    }
}

/// The same route flown by two vehicles 300 m apart in altitude keeps a vertical separation
/// of 150 m (the climb at the take-off point and the leg from there included); with a
/// vertical separation of 350 m every element of the one conflicts with those of the other
/// it meets.
#[test]
fn the_same_route_300_m_apart_in_altitude_keeps_150_m() {
    let w: Vec<Site> = (0..3)
        .map(|k| origin().direct(45.0, 1500.0 * f64::from(k)))
        .collect();
    let low = mission(&w.iter().map(|s| wp(*s, 100.0)).collect::<Vec<_>>());
    let high = mission(&w.iter().map(|s| wp(*s, 400.0)).collect::<Vec<_>>());
    let take_off = Some(wire(origin().direct(225.0, 800.0)));
    let own = Flight {
        take_off,
        ..flight("alpha", &low)
    };
    // Bravo on its route: where it took off is behind it.
    let other = flight("bravo", &high);
    none(check(own, &[other], SEPARATION));
    let found = check(
        own,
        &[other],
        Separation {
            vertical_m: 350.0,
            ..SEPARATION
        },
    );
    assert!(!found.is_empty());
    for c in &found {
        assert_eq!(c.vertical_gap_m, 300.0, "{c}");
        assert_eq!(c.margin_m, 500.0 - c.distance_m);
    }
    assert!(found.contains_pair(leg(0, 1), leg(1, 2), 0.0));
    assert!(found.contains_pair(leg(1, 2), leg(1, 2), 0.0));
    assert!(found.contains_pair(leg(2, 3), leg(2, 3), 0.0));
    // The climb to 30 m at the take-off point is 370 m below bravo's route.
    assert!(found.iter().all(|c| c.own.element != RouteElement::Climb));
}

trait Pairs {
    /// Whether the pair is in conflict with the paths `distance_m` apart (to a micrometre).
    fn contains_pair(&self, own: RouteElement, other: RouteElement, distance_m: f64) -> bool;
}

impl Pairs for Vec<Conflict> {
    fn contains_pair(&self, own: RouteElement, other: RouteElement, distance_m: f64) -> bool {
        self.iter().any(|c| {
            c.own.element == own
                && c.other.element == other
                && (c.distance_m - distance_m).abs() < 1e-6
        })
    }
}

/// A leg climbing from 100 m to 300 m spans both: against a route at 400 m it is 100 m apart,
/// within a vertical separation of 150 m, though its lower end is 300 m below.
#[test]
fn a_leg_spans_the_altitudes_of_its_ends() {
    let (a, b) = (origin(), origin().direct(0.0, 1000.0));
    let climbing = mission(&[wp(a, 100.0), wp(b, 300.0)]);
    let level = mission(&[wp(a, 400.0), wp(b, 400.0)]);
    let found = check(
        flight("alpha", &climbing),
        &[flight("bravo", &level)],
        SEPARATION,
    );
    assert_eq!(pairs(&found), [(leg(1, 2), leg(1, 2))]);
    assert_eq!(found[0].own.altitudes_m, (100.0, 300.0));
    assert_eq!(found[0].vertical_gap_m, 100.0);
    let level = mission(&[wp(a, 460.0), wp(b, 460.0)]);
    none(check(
        flight("alpha", &climbing),
        &[flight("bravo", &level)],
        SEPARATION,
    ));
}

/// A radius-to-fix leg, a half circle of 500 m north about its centre, and a leg 580 m north
/// of the centre: the arc passes 80 m from it (its chord, through the centre, 580 m). With a
/// separation of 100 m the pair conflicts, 20 m inside it, at the arc's northernmost point;
/// with 75 m it does not.
#[test]
fn a_radius_to_fix_arc_is_measured_as_the_arc() {
    let centre = origin();
    let arc = mission(&[
        wp(centre.direct(270.0, 500.0), 120.0),
        Wp {
            rf: Some((centre, TurnDirection::Clockwise)),
            ..wp(centre.direct(90.0, 500.0), 120.0)
        },
    ]);
    // Both ends on the geodesic through the point 580 m north, perpendicular to the meridian
    // there: its closest approach to the centre is that point.
    let north = centre.direct(0.0, 580.0);
    let across = mission(&[
        wp(north.direct(270.0, 1000.0), 120.0),
        wp(north.direct(90.0, 1000.0), 120.0),
    ]);
    let separation = Separation {
        horizontal_m: 100.0,
        ..SEPARATION
    };
    let found = check(
        flight("alpha", &arc),
        &[flight("bravo", &across)],
        separation,
    );
    assert_eq!(pairs(&found), [(leg(1, 2), leg(1, 2))]);
    let c = &found[0];
    // Never more than the true 80 m, and at most the sag of the arc's chords less.
    assert!(c.distance_m <= 80.0 + 0.005, "{c}");
    assert!(c.distance_m >= 80.0 - 2.0 * ARC_SAG_M - 0.005, "{c}");
    assert_eq!(c.margin_m, 100.0 - c.distance_m);
    let apex = centre.direct(0.0, 500.0);
    assert!(metres_between(c.position, apex) < 1.0);
    // Measured from the straight leg's side, the same.
    let back = check(
        flight("bravo", &across),
        &[flight("alpha", &arc)],
        separation,
    );
    assert_eq!(pairs(&back), [(leg(1, 2), leg(1, 2))]);
    assert!((back[0].distance_m - c.distance_m).abs() < 0.01);
    assert!(metres_between(back[0].position, north) < 1.0);
    let tighter = Separation {
        horizontal_m: 75.0,
        ..SEPARATION
    };
    none(check(
        flight("alpha", &arc),
        &[flight("bravo", &across)],
        tighter,
    ));
}

/// The arc's distance to a point against the exact one (the geodesic distance from the centre
/// less the radius, where the point lies within the arc's sweep): never more, and at most
/// twice [`ARC_SAG_M`] less (the chords stray up to that from the arc, either way, and the
/// distance found is lowered by it), wherever the point is, inside the circle or out, from
/// either side.
#[test]
fn an_arcs_distance_is_within_its_sag_of_the_exact_one() {
    let centre = origin();
    let radius = 500.0;
    let path = Path::Arc(ArcLeg {
        from: centre.direct(270.0, radius),
        to: centre.direct(90.0, radius),
        centre,
        direction: TurnDirection::Clockwise,
    });
    let arc = FlownElement::new(leg(1, 2), (0.0, 0.0), &path);
    let mut scratch = Scratch::default();
    let mut checked = 0;
    for k in 0..60 {
        // Azimuths across the sweep, from west through north to east.
        let azimuth = 271.0 + 178.0 * f64::from(k) / 59.0;
        for distance in [300.0, 420.0, 480.0, 499.0, 501.0, 520.0, 600.0, 900.0] {
            let at = centre.direct(azimuth, distance);
            let exact = (centre.inverse(&at).0 - radius).abs();
            let point = FlownElement::new(RouteElement::Climb, (0.0, 0.0), &Path::Point(at));
            for (a, b) in [(&arc, &point), (&point, &arc)] {
                let (found, _) = approach(a, b, 1000.0, &mut scratch).unwrap();
                assert!(
                    found <= exact + 0.002,
                    "{found} against {exact} at {azimuth}"
                );
                assert!(
                    found >= exact - 2.0 * ARC_SAG_M - 0.002,
                    "{found} against {exact} at {azimuth}"
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 60 * 8 * 2);
}

/// A right turn at waypoint 2 and a leg from inside its corner, 120 m from both legs, away
/// along the bisector. In calm air the fly-by arc (radius 137 m) passes 113 m from that leg's
/// start; in a 12 m/s wind it is flown at `(25 + 12)²/(g·tan 25°)` = 299 m and cuts 74 m
/// deeper into the corner, 46 m from it: a conflict with a separation of 100 m, on the turn.
#[test]
fn wind_widens_a_turn_into_a_conflict() {
    let w = origin();
    let own = mission(&[
        wp(w.direct(180.0, 2000.0), 120.0),
        wp(w, 120.0),
        wp(w.direct(90.0, 2000.0), 120.0),
    ]);
    let inside = w.direct(135.0, 120.0 * 2f64.sqrt());
    let other = mission(&[wp(inside, 120.0), wp(inside.direct(135.0, 1000.0), 120.0)]);
    let separation = Separation {
        horizontal_m: 100.0,
        ..SEPARATION
    };
    let calm = SafetyGateway::default();
    let found = conflicts(
        &calm,
        flight("alpha", &own),
        &[flight("bravo", &other)],
        separation,
    )
    .unwrap();
    none(found);
    let windy = SafetyGateway {
        environment: Environment {
            wind_speed_mps: 12.0,
            ..Environment::default()
        },
        ..calm
    };
    let found = conflicts(
        &windy,
        flight("alpha", &own),
        &[flight("bravo", &other)],
        separation,
    )
    .unwrap();
    let turn = RouteElement::Turn {
        at: 2,
        to: 3,
        kind: TurnKind::FlyBy,
    };
    assert_eq!(pairs(&found), [(turn, leg(1, 2))]);
    // The arc flown: centre r·√2 from the corner on the bisector (to millimetres: the turn's
    // construction), radius r. The leg starts inside the circle, so the arc's closest point
    // is the one facing the corner: r − |centre − start| away.
    let r = windy.profile.min_turn_radius_m(25.0 + 12.0);
    assert!((r - 299.4).abs() < 0.1, "{r}");
    let arc = windy
        .turns(&own, None)
        .into_iter()
        .find_map(|t| match t.path {
            Path::Arc(arc) => Some(arc.geometry()),
            _ => None,
        })
        .unwrap();
    assert!((arc.r0 - r).abs() < 0.001 && (arc.r1 - r).abs() < 0.001);
    assert!(arc.centre.inverse(&w.direct(135.0, r * 2f64.sqrt())).0 < 0.01);
    let (to_start, azimuth) = arc.centre.inverse(&inside);
    let exact = arc.r0 - to_start;
    assert!((exact - 45.7).abs() < 0.1, "{exact}");
    let c = &found[0];
    assert!(
        c.distance_m <= exact + 0.005 && c.distance_m >= exact - 2.0 * ARC_SAG_M - 0.005,
        "{} against {exact}",
        c.distance_m
    );
    let closest = arc.centre.direct(azimuth, arc.r0);
    assert!(metres_between(c.position, closest) < 1.0);
    // The calm turn, for the record: 113 m.
    let r0 = calm.profile.min_turn_radius_m(25.0);
    let calm_distance = r0 - w.direct(135.0, r0 * 2f64.sqrt()).inverse(&inside).0;
    assert!((calm_distance - 113.1).abs() < 0.1, "{calm_distance}");
}

/// The demo missions flown at once (`missions/mission-1.toml` by bravo, from TROL to CCP;
/// `missions/mission-2.toml` by alpha, from CCP): they meet at CCP, where bravo's mission ends
/// and alpha's begins. Resolved by flying alpha's after bravo has landed (its mission no longer
/// active), not by altitude: alpha climbs through every altitude bravo arrives at.
#[test]
fn the_demo_missions_meet_at_ccp() {
    let (one, two) = (testkit::mission_1(), testkit::mission_2());
    let (m1, m2) = (
        one.assemble().unwrap().mission,
        two.assemble().unwrap().mission,
    );
    let alpha = Flight {
        take_off: two.take_off_position,
        ..flight("alpha", &m2)
    };
    let bravo = Flight {
        take_off: one.take_off_position,
        ..flight("bravo", &m1)
    };
    let ccp = Site::new(CCP.0, CCP.1);
    let found = check(alpha, &[bravo], SEPARATION);
    let to_ccp = leg(0, 1);
    // Alpha's climb at CCP (0 to 30 m), its way on from there (30 to 120 m, CCP being
    // waypoint 1) and its first leg, from CCP, against bravo's leg to CCP (30 to 120 m): at
    // distance 0, at CCP. Bravo's climb at TROL is 2 km away, alpha's turn at W1 1 km.
    assert_eq!(
        pairs(&found),
        [
            (RouteElement::Climb, to_ccp),
            (to_ccp, to_ccp),
            (leg(1, 2), to_ccp)
        ]
    );
    for c in &found {
        assert!(c.distance_m < 1e-6, "{c}");
        assert_eq!(c.margin_m, 500.0 - c.distance_m);
        assert!(metres_between(c.position, ccp) < 1.0, "{c}");
    }
    // Bravo landed: nothing left to conflict with.
    none(check(alpha, &[], SEPARATION));
}

/// What the check compares of demo mission 2 (ICD §7's route as flown): the climb at CCP, the
/// leg from there (CCP is waypoint 1), the legs, the fly-by turn at W1 onto the arc, and, the
/// route being bidirectional, the turns of a return to home: the fly-by at W1 from the arc back
/// onto the leg to CCP, and the turns round at W1 and ROLE2, each a fly-over (a U-turn). No
/// turn at CCP (the leg from the take-off point there has no length) nor at ROLE2 on the way
/// back from the route's end (the aircraft hovers there).
#[test]
fn demo_mission_2_is_its_legs_and_turns_with_their_altitudes() {
    let two = testkit::mission_2();
    let m2 = two.assemble().unwrap().mission;
    let flown = Flown::new(
        &SafetyGateway::default(),
        Flight {
            take_off: two.take_off_position,
            ..flight("alpha", &m2)
        },
    );
    let turn = |at, to, kind| RouteElement::Turn { at, to, kind };
    let elements: Vec<(RouteElement, (f64, f64))> = flown.elements().collect();
    assert_eq!(
        elements,
        [
            (RouteElement::Climb, (0.0, 30.0)),
            (leg(0, 1), (30.0, 120.0)),
            (leg(1, 2), (120.0, 120.0)),
            (leg(2, 3), (120.0, 120.0)),
            (turn(2, 3, TurnKind::FlyBy), (120.0, 120.0)),
            (turn(2, 1, TurnKind::FlyBy), (120.0, 120.0)),
            (turn(2, 1, TurnKind::FlyOver), (120.0, 120.0)),
            (turn(3, 2, TurnKind::FlyOver), (120.0, 120.0)),
        ]
    );
}

/// A fly-over turn's three paths (turn, intercept, turn onto the leg) are one element.
#[test]
fn a_fly_over_turn_is_one_element() {
    let w = origin();
    let mut own = mission(&[
        wp(w.direct(180.0, 2000.0), 120.0),
        wp(w, 120.0),
        wp(w.direct(90.0, 2000.0), 120.0),
    ]);
    own.waypoints[1].waypoint.turn_type = TurnType::FlyOver;
    let flown = Flown::new(&SafetyGateway::default(), flight("alpha", &own));
    let turns: Vec<RouteElement> = flown
        .elements()
        .map(|(e, _)| e)
        .filter(|e| matches!(e, RouteElement::Turn { .. }))
        .collect();
    assert_eq!(
        turns,
        [RouteElement::Turn {
            at: 2,
            to: 3,
            kind: TurnKind::FlyOver
        }]
    );
    assert_eq!(flown.elements.last().map(|e| e.patches.len()), Some(3));
}

/// The sweep finds exactly the conflicts that measuring every pair of elements finds: five
/// survey missions (`testkit::survey_fleet`: four side by side in a row, one in the next row),
/// each against the others.
#[test]
fn the_sweep_finds_what_every_pair_finds() {
    let gateway = SafetyGateway::default();
    let fleet = testkit::survey_fleet(5, 24);
    let names: Vec<String> = (0..fleet.len()).map(|k| format!("v{k}")).collect();
    let flown: Vec<Flown> = fleet
        .iter()
        .zip(&names)
        .map(|(m, name)| Flown::new(&gateway, flight(name, m)))
        .collect();
    let mut total = 0;
    for own in &flown {
        let others: Vec<&Flown> = flown
            .iter()
            .filter(|f| f.vehicle() != own.vehicle())
            .collect();
        let found = own.conflicts(others.iter().copied(), SEPARATION).unwrap();
        let mut every = Vec::new();
        let mut scratch = Scratch::default();
        for other in &others {
            for mine in &own.elements {
                for theirs in &other.elements {
                    if vertical_gap(mine.band, theirs.band) >= SEPARATION.vertical_m {
                        continue;
                    }
                    if let Some((d, _)) = approach(mine, theirs, 500.0, &mut scratch) {
                        every.push((other.vehicle(), mine.part, theirs.part, d));
                    }
                }
            }
        }
        let swept: Vec<_> = found
            .iter()
            .map(|c| {
                (
                    c.other.vehicle.as_str(),
                    c.own.element,
                    c.other.element,
                    c.distance_m,
                )
            })
            .collect();
        assert_eq!(swept, every, "{}", own.vehicle());
        total += found.len();
    }
    // Neighbours in a row of the grid come within 300 m; the rows keep some 600 m apart.
    assert!(total > 0);
    let row_apart = flown
        .first()
        .unwrap()
        .conflicts(flown.get(4), SEPARATION)
        .unwrap();
    none(row_apart);
}

/// A separation that is no distance, and a vehicle named twice, are refused, each as its own
/// error.
#[test]
fn unusable_separations_and_a_vehicle_named_twice_are_refused() {
    let m = mission(&[wp(origin(), 120.0), wp(origin().direct(0.0, 1000.0), 120.0)]);
    let gateway = SafetyGateway::default();
    let run = |own: &str, others: &[&str], separation| {
        let others: Vec<Flight> = others.iter().map(|v| flight(v, &m)).collect();
        conflicts(&gateway, flight(own, &m), &others, separation)
    };
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let horizontal = Separation {
            horizontal_m: bad,
            ..SEPARATION
        };
        assert!(matches!(
            run("a", &["b"], horizontal),
            Err(SeparationError::Horizontal(_))
        ));
        let vertical = Separation {
            vertical_m: bad,
            ..SEPARATION
        };
        assert!(matches!(
            run("a", &["b"], vertical),
            Err(SeparationError::Vertical(_))
        ));
    }
    assert_eq!(
        run("a", &["b", "a"], SEPARATION),
        Err(SeparationError::DuplicateVehicle("a".into()))
    );
    assert_eq!(
        run("a", &["b", "c", "b"], SEPARATION),
        Err(SeparationError::DuplicateVehicle("b".into()))
    );
    assert_eq!(run("a", &[], SEPARATION), Ok(vec![]));
}

/// The runs of a patch's chords hold every chord once, in order, a point's one chord too.
#[test]
fn runs_hold_every_chord_once() {
    for n in [0usize, 1, 2, 3, RUN, RUN + 1, RUN + 2, 3 * RUN + 5] {
        let corners: Vec<Coord> = (0..n)
            .map(|k| Coord {
                x: k as f64,
                y: (k * k) as f64,
            })
            .collect();
        let mut out = Vec::new();
        runs(&corners, &mut out);
        let held: Vec<usize> = out.iter().flat_map(|r| r.first..r.last).collect();
        let chords = match n {
            0 => 0,
            1 => 1,
            n => n - 1,
        };
        assert_eq!(held, (0..chords).collect::<Vec<_>>(), "{n} corners");
        for r in &out {
            for k in r.first..r.last {
                let (p, q) = chord(&corners, k).unwrap();
                for c in [p, q] {
                    assert!(c.x >= r.lo.x && c.x <= r.hi.x && c.y >= r.lo.y && c.y <= r.hi.y);
                }
            }
        }
    }
}
