//! Guidance flies what the geofence checks (ICD §7 "the legs as flown", `geofence::turn`): the
//! demo missions and a set of turns (fly-by at 30°, 90° and 150°, a U-turn, a fly-over, a
//! fly-by onto and off a radius-to-fix leg, and a return to home on mission 2) are flown by
//! `guidance::Guidance` in simulated time (steps of 100 ms), from the plan's take-off point as
//! execute flies them, and compared with the paths the onboard check and the safety gateway
//! check:
//!
//! - every flown position lies within [`FLOWN_TOLERANCE_M`] of one of the checked paths;
//! - for every zone, the margin the geofence finds on the checked paths, and the margin the
//!   safety gateway reports where it reports one, is never larger than the margin actually
//!   flown (the smallest over the flown positions) by more than [`FLOWN_TOLERANCE_M`]; a zone
//!   the flight comes closer to than the safety offset is always reported.
//!
//! Each turn has a no-fly circle placed 10 m inside its arc (the turn enters it while the legs
//! clear it), so the margins compared are the turns' own.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use core::time::Duration;

use missionlink_interfaces::contracts::{AutomationStatePayload, FlightPhase, WaypointListPayload};
use missionlink_interfaces::wire::{
    AreaType, GeoPoint, LegType, Message, TurnDirection, TurnType, UaPositionWaypoint,
};
use missionlink_services::automation::fcc_turns;
use missionlink_services::geofence::clearance::clearance;
use missionlink_services::geofence::earth::Site;
use missionlink_services::geofence::onboard::{self, RouteElement, RouteLeg, RouteView};
use missionlink_services::geofence::path::{ArcLeg, Path, Track};
use missionlink_services::geofence::turn::TurnKind;
use missionlink_services::geofence::zone::Fence;
use missionlink_services::ground_station::MissionPlan;
use missionlink_services::guidance::{Guidance, GuidanceConfig};
use missionlink_services::link::time::Instant;
use missionlink_services::safety_gateway::SafetyGateway;
use missionlink_services::testkit::{
    self, CCP, FLY_ZONE, NFZ_POLYGON, circle, distance_to_path, plan, polygon, rf_centre, route,
    take_off, waypoint,
};

/// Flown and checked paths agree within this, metres.
const FLOWN_TOLERANCE_M: f64 = 1.0;
/// Real (= simulated) time between steps.
const STEP: Duration = Duration::from_millis(100);

fn point(at: (f64, f64)) -> GeoPoint {
    GeoPoint::from_degrees(at.0, at.1).unwrap()
}

fn lat_lon(s: Site) -> (f64, f64) {
    (s.lat, s.lon)
}

/// One flight: the plan, and when (after how many cruise steps) return to home is commanded.
struct Flight {
    name: String,
    plan: MissionPlan,
    return_home_after: Option<usize>,
}

/// The checked paths of `plan`: what execute checks from the take-off point, and on a
/// bidirectional route what the gateway checks of a return to home (the reverse route from the
/// last waypoint and the turn round at every waypoint), or what return to home checks from
/// `home_from` (position, TO waypoint).
fn checked(
    list: &WaypointListPayload,
    take_off: Site,
    home_from: Option<(Site, u16)>,
) -> Vec<RouteLeg> {
    let turns = Some(fcc_turns());
    let mut legs: Vec<RouteLeg> =
        onboard::execute_route(RouteView::from(list), take_off, turns).collect();
    if list.bidirectional {
        if let Some(last) = list.waypoints().last() {
            // As the gateway: the route complete at the last waypoint (`to` 0).
            legs.extend(onboard::return_route(
                RouteView::from(list),
                Site::of(last.position),
                0,
                turns,
            ));
        }
        legs.extend(onboard::turns_round(RouteView::from(list), fcc_turns()));
    }
    if let Some((at, to)) = home_from {
        legs.extend(onboard::return_route(RouteView::from(list), at, to, turns));
    }
    legs
}

/// Flies `f` from its take-off point through take-off, cruise (return to home if asked) until
/// the route is complete; the positions of every step in cruise, and where (position, TO)
/// return to home was commanded.
fn fly(f: &Flight, list: &WaypointListPayload) -> (Vec<Site>, Option<(Site, u16)>) {
    let t = Site::of(f.plan.take_off_position.unwrap());
    let mut g = Guidance::new(GuidanceConfig {
        start_latitude_deg: t.lat,
        start_longitude_deg: t.lon,
        ..GuidanceConfig::default()
    });
    g.set_waypoint_list(list);
    let mut a = AutomationStatePayload::ON_GROUND;
    a.flown_waypoint_list = list.generation;
    let mut now = Instant::ZERO;
    let set = |g: &mut Guidance,
               a: &mut AutomationStatePayload,
               change: &dyn Fn(&mut AutomationStatePayload)| {
        change(a);
        a.sequence += 1;
        g.set_automation(a);
    };
    g.step(now);
    set(&mut g, &mut a, &|a| {
        a.flight_phase = FlightPhase::TakeOff as u8
    });
    for _ in 0..10_000 {
        now = now + STEP;
        if g.step(now).climb_complete {
            break;
        }
    }
    set(&mut g, &mut a, &|a| {
        a.flight_phase = FlightPhase::Cruise as u8
    });
    let mut flown = Vec::new();
    let mut home = None;
    for n in 0..100_000 {
        if Some(n) == f.return_home_after {
            let p = flown.last().copied().unwrap();
            let last = g.step(now);
            home = Some((p, last.to));
            set(&mut g, &mut a, &|a| a.route_reversed = true);
        }
        now = now + STEP;
        let p = g.step(now);
        flown.push(Site::new(p.latitude_deg, p.longitude_deg));
        if p.route_complete {
            return (flown, home);
        }
    }
    panic!("{}: the route is not complete", f.name);
}

/// The area ID a gateway violation names ("... (no-fly-zone 4)").
fn area_of(detail: &str) -> Option<u16> {
    let i = detail.rfind("zone ")?;
    detail[i + 5..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect::<String>()
        .parse()
        .ok()
}

struct Outcome {
    worst_distance: f64,
    worst_excess: f64,
    worst_gateway_excess: f64,
}

fn check(f: &Flight) -> Outcome {
    let lists = f.plan.assemble().unwrap();
    let list = lists.mission.to_payload(1);
    let fence = Fence::of_list(&lists.areas);
    let offset = fence.safety_offset_m;
    let take_off = Site::of(f.plan.take_off_position.unwrap());
    let (flown, home) = fly(f, &list);
    let route = checked(&list, take_off, home);
    let tracks: Vec<Track> = route.iter().map(|l| Track::new(l.path)).collect();

    // Every flown position near a checked path; after a return to home is commanded, near a
    // path of what the FCC checks then (`onboard::return_route` from there).
    let home_route: Vec<RouteLeg> = home
        .map(|(at, to)| {
            onboard::return_route(RouteView::from(&list), at, to, Some(fcc_turns())).collect()
        })
        .unwrap_or_default();
    let mut worst_distance: f64 = 0.0;
    for (i, at) in flown.iter().enumerate() {
        let paths = match f.return_home_after {
            Some(n) if i >= n => &home_route,
            _ => &route,
        };
        let d = paths
            .iter()
            .map(|l| distance_to_path(&l.path, *at))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d <= FLOWN_TOLERANCE_M,
            "{}: step {i} at {at:?} is {d} m from the checked paths",
            f.name
        );
        worst_distance = worst_distance.max(d);
    }

    // Margins: checked, reported, flown.
    let points: Vec<Track> = flown.iter().map(|s| Track::new(Path::Point(*s))).collect();
    let violations =
        SafetyGateway::default().violations(&lists.mission, &lists.areas, f.plan.take_off_position);
    let mut worst_excess = f64::NEG_INFINITY;
    let mut worst_gateway_excess = f64::NEG_INFINITY;
    for zone in &fence.zones {
        let flown_margin = points
            .iter()
            .map(|p| clearance(p, zone, f64::INFINITY, true).metres())
            .fold(f64::INFINITY, f64::min);
        let checked_margin = tracks
            .iter()
            .map(|t| clearance(t, zone, f64::INFINITY, true).metres())
            .fold(f64::INFINITY, f64::min);
        assert!(
            checked_margin <= flown_margin + FLOWN_TOLERANCE_M,
            "{}: zone {}: checked {checked_margin} m, flown {flown_margin} m",
            f.name,
            zone.id
        );
        worst_excess = worst_excess.max(checked_margin - flown_margin);
        let reported = violations
            .iter()
            .filter(|v| area_of(&v.detail) == Some(zone.id))
            .filter_map(|v| v.margin_m)
            .fold(f64::INFINITY, f64::min);
        if flown_margin < offset {
            assert!(
                reported.is_finite(),
                "{}: zone {} flown at {flown_margin} m, inside the offset {offset} m, not reported",
                f.name,
                zone.id
            );
            let onboard = onboard::check(&fence, route.iter().copied());
            assert!(onboard.is_err(), "{}: the onboard check passes", f.name);
        }
        if reported.is_finite() {
            // The gateway reports the margin beyond the offset.
            let excess = reported - (flown_margin - offset);
            assert!(
                excess <= FLOWN_TOLERANCE_M,
                "{}: zone {}: reported {reported} m beyond the offset, flown {} m",
                f.name,
                zone.id,
                flown_margin - offset
            );
            worst_gateway_excess = worst_gateway_excess.max(excess);
        }
        println!(
            "{}: zone {}: flown margin {flown_margin:.3} m, checked {checked_margin:.3} m, \
             reported {reported:.3} m beyond the offset",
            f.name, zone.id
        );
    }
    Outcome {
        worst_distance,
        worst_excess,
        worst_gateway_excess,
    }
}

/// A local point `east`, `north` metres from `origin` (along the geodesics).
fn at(origin: Site, bearing: f64, distance: f64) -> (f64, f64) {
    lat_lon(origin.direct(bearing, distance))
}

const CORNER: (f64, f64) = (48.27, 11.66);
/// A leg's length in the turn cases, metres.
const LEG_M: f64 = 1600.0;

/// A turn at waypoint 2 of `turn_deg` (positive: right), waypoint 2 flown `turn_type`; the
/// no-fly circles placed 10 m inside each arc of the turn.
fn turn_case(name: &str, turn_deg: f64, turn_type: TurnType, expected: TurnKind) -> Flight {
    turn_case_with(name, turn_deg, turn_type, expected, false)
}

/// [`turn_case`], the route bidirectional or not.
fn turn_case_with(
    name: &str,
    turn_deg: f64,
    turn_type: TurnType,
    expected: TurnKind,
    bidirectional: bool,
) -> Flight {
    let c = Site::new(CORNER.0, CORNER.1);
    let w1 = at(c, 180.0, LEG_M);
    let (_, _, course_in) = Site::new(w1.0, w1.1).inverse_azimuths(&c);
    let w3 = at(c, course_in + turn_deg, LEG_M);
    let mut w2 = waypoint(2, 3, CORNER, LegType::TrackToFix);
    w2.turn_type = turn_type;
    let messages = [
        take_off(30.0).into(),
        waypoint(1, 2, w1, LegType::TrackToFix).into(),
        w2.into(),
        waypoint(3, 0, w3, LegType::TrackToFix).into(),
        route(1, bidirectional).into(),
    ];
    let f = with_circles_in_turns(name, &messages, at(c, 180.0, LEG_M + 300.0));
    assert_eq!(turn_kinds(&f), [expected], "{name}");
    f
}

/// The kinds of the turns of the execute route of `f`, one per waypoint turned at.
fn turn_kinds(f: &Flight) -> Vec<TurnKind> {
    let list = f.plan.assemble().unwrap().mission.to_payload(1);
    let take_off = Site::of(f.plan.take_off_position.unwrap());
    let mut kinds: Vec<(u16, TurnKind)> =
        onboard::execute_route(RouteView::from(&list), take_off, Some(fcc_turns()))
            .filter_map(|l| match l.element {
                RouteElement::Turn { at, kind, .. } => Some((at, kind)),
                _ => None,
            })
            .collect();
    kinds.dedup();
    kinds.into_iter().map(|(_, k)| k).collect()
}

/// Onto (`onto`) or off a clockwise radius-to-fix leg of 900 m radius, fly-by at its start or
/// end.
fn rf_case(name: &str, onto: bool) -> Flight {
    let centre = Site::new(CORNER.0, CORNER.1);
    let radius = 900.0;
    let start = at(centre, 270.0, radius);
    let end = at(centre, 0.0, radius);
    // Onto: a leg from the south-west, turning 40° onto the arc at its start. Off: from the
    // arc's end a leg to the south-east, turning 70°.
    let messages: Vec<_> = if onto {
        let s = Site::new(start.0, start.1);
        let before = at(s, 180.0 + 40.0, 1500.0);
        vec![
            take_off(30.0).into(),
            waypoint(1, 2, before, LegType::TrackToFix).into(),
            waypoint(2, 3, start, LegType::TrackToFix).into(),
            waypoint(3, 0, end, LegType::RadiusToFix).into(),
            rf_centre(3, CORNER, TurnDirection::Clockwise).into(),
            route(1, false).into(),
        ]
    } else {
        let e = Site::new(end.0, end.1);
        let after = at(e, 90.0 + 70.0, 1500.0);
        vec![
            take_off(30.0).into(),
            waypoint(1, 2, start, LegType::TrackToFix).into(),
            waypoint(2, 3, end, LegType::RadiusToFix).into(),
            rf_centre(2, CORNER, TurnDirection::Clockwise).into(),
            waypoint(3, 0, after, LegType::TrackToFix).into(),
            route(1, false).into(),
        ]
    };
    let take_off_at = if onto {
        at(Site::new(start.0, start.1), 180.0 + 40.0, 1800.0)
    } else {
        at(Site::new(start.0, start.1), 180.0, 400.0)
    };
    let f = with_circles_in_turns(name, &messages, take_off_at);
    // The take-off point is in line with the first leg: the one turn is onto or off the arc.
    assert_eq!(turn_kinds(&f), [TurnKind::FlyBy], "{name}");
    f
}

/// The plan of `messages` in the demo fly-zone moved to the corner, taking off at `take_off`,
/// with a no-fly circle of 40 m radius 10 m inside the middle of every turn arc (fly-by arcs,
/// the fly-over's first turn), the turns as the geofence constructs them.
fn with_circles_in_turns(name: &str, messages: &[Message], take_off: (f64, f64)) -> Flight {
    let c = Site::new(CORNER.0, CORNER.1);
    let fly_zone = [
        at(c, 225.0, 4000.0),
        at(c, 135.0, 4000.0),
        at(c, 45.0, 4000.0),
        at(c, 315.0, 4000.0),
    ];
    let bare = MissionPlan {
        take_off_position: Some(point(take_off)),
        ..plan(
            messages,
            &[polygon(1, AreaType::FlyZone, &fly_zone)],
            "TURN",
        )
    };
    let list = bare.assemble().unwrap().mission.to_payload(1);
    let mut areas = vec![polygon(1, AreaType::FlyZone, &fly_zone)];
    for leg in onboard::execute_route(
        RouteView::from(&list),
        Site::of(point(take_off)),
        Some(fcc_turns()),
    ) {
        let (
            RouteElement::Turn { kind, .. },
            Path::Arc(ArcLeg {
                from,
                to,
                centre,
                direction,
            }),
        ) = (leg.element, leg.path)
        else {
            continue;
        };
        let (r, a0) = centre.inverse(&from);
        let (_, a1) = centre.inverse(&to);
        let sweep = match direction {
            TurnDirection::Clockwise => (a1 - a0).rem_euclid(360.0),
            TurnDirection::CounterClockwise => -(a0 - a1).rem_euclid(360.0),
        };
        if sweep.abs() < 20.0 || areas.len() >= 4 || kind == TurnKind::Straight {
            continue;
        }
        let mid = a0 + sweep / 2.0;
        // Inside the arc (towards its centre) for a fly-by, outside for the fly-over's turns
        // (the legs are inside those).
        let inside = kind == TurnKind::FlyBy;
        let depth = if inside { r - 30.0 } else { r + 30.0 };
        let zone_centre = centre.direct(mid, depth.max(1.0));
        let border = zone_centre.direct(0.0, 40.0);
        let id = areas.len() as u16 + 1;
        areas.push(circle(id, lat_lon(zone_centre), lat_lon(border)));
    }
    Flight {
        name: name.into(),
        plan: MissionPlan {
            take_off_position: Some(point(take_off)),
            ..plan(messages, &areas, "TURN")
        },
        return_home_after: None,
    }
}

/// Demo mission 2 (`testkit::mission_2`) with W1 (waypoint 2) fly-over: over W1, then the
/// turn straight into the reverse turn onto the radius-to-fix arc.
fn fly_over_at_w1() -> MissionPlan {
    let w1 = UaPositionWaypoint {
        turn_type: TurnType::FlyOver,
        ..waypoint(2, 3, (48.278, 11.658), LegType::TrackToFix)
    };
    MissionPlan {
        take_off_position: Some(point(CCP)),
        ..plan(
            &[
                take_off(30.0).into(),
                waypoint(1, 2, CCP, LegType::TrackToFix).into(),
                w1.into(),
                waypoint(3, 0, (48.280, 11.680), LegType::RadiusToFix).into(),
                rf_centre(3, (48.27455, 11.66991), TurnDirection::Clockwise).into(),
                route(1, true).into(),
            ],
            &[
                polygon(1, AreaType::FlyZone, &FLY_ZONE),
                circle(2, (48.268, 11.675), (48.268, 11.679)),
                polygon(3, AreaType::NoFlyZone, &NFZ_POLYGON),
            ],
            "MEDEVAC-2-OVER",
        )
    }
}

#[test]
fn guidance_flies_what_the_geofence_checks() {
    let mut flights = vec![
        Flight {
            name: "demo mission 1".into(),
            plan: testkit::mission_1(),
            return_home_after: None,
        },
        Flight {
            name: "demo mission 2".into(),
            plan: testkit::mission_2(),
            return_home_after: None,
        },
        Flight {
            name: "demo mission 2, return to home on the leg to W1".into(),
            plan: testkit::mission_2(),
            return_home_after: Some(200),
        },
        Flight {
            name: "the fly-by corner".into(),
            plan: testkit::fly_by_corner(),
            return_home_after: None,
        },
    ];
    flights.push(turn_case(
        "fly-by 30°",
        30.0,
        TurnType::FlyBy,
        TurnKind::FlyBy,
    ));
    flights.push(turn_case(
        "fly-by 90°",
        90.0,
        TurnType::FlyBy,
        TurnKind::FlyBy,
    ));
    flights.push(turn_case(
        "fly-by 150° left",
        -150.0,
        TurnType::FlyBy,
        TurnKind::FlyBy,
    ));
    flights.push(turn_case(
        "U-turn (fly-by, 180°): flown over",
        180.0,
        TurnType::FlyBy,
        TurnKind::FlyOver,
    ));
    flights.push(turn_case(
        "fly-over 90°",
        90.0,
        TurnType::FlyOver,
        TurnKind::FlyOver,
    ));
    flights.push(turn_case(
        "fly-over 30°",
        30.0,
        TurnType::FlyOver,
        TurnKind::FlyOver,
    ));
    flights.push(rf_case("fly-by onto a radius-to-fix leg", true));
    flights.push(rf_case("fly-by off a radius-to-fix leg", false));
    // Return to home while on the fly-by arc at waypoint 2 (it starts 137 m before it, about
    // 1763 m and 70.5 s from the take-off): the rest of the arc, the leg on to waypoint 3, the
    // turn round there and the way back are what the FCC checks then.
    let mut on_the_arc = turn_case_with(
        "fly-by 90°, return to home on the arc",
        90.0,
        TurnType::FlyBy,
        TurnKind::FlyBy,
        true,
    );
    on_the_arc.return_home_after = Some(740);
    {
        let list = on_the_arc.plan.assemble().unwrap().mission.to_payload(1);
        let take_off = Site::of(on_the_arc.plan.take_off_position.unwrap());
        let (_, home) = fly(&on_the_arc, &list);
        let (here, to) = home.unwrap();
        let arc = onboard::execute_route(RouteView::from(&list), take_off, Some(fcc_turns()))
            .find(|l| matches!(l.element, RouteElement::Turn { at: 2, .. }))
            .unwrap()
            .path;
        let Path::Arc(ArcLeg { from, to: end, .. }) = arc else {
            panic!("{arc:?}");
        };
        assert_eq!(to, 3, "TO when return to home is commanded");
        assert!(distance_to_path(&arc, here) < 1e-6, "on the arc");
        assert!(here.inverse(&from).0 > 10.0 && here.inverse(&end).0 > 10.0);
    }
    flights.push(on_the_arc);
    let over_w1 = Flight {
        name: "demo mission 2, W1 flown over (onto the radius-to-fix arc)".into(),
        plan: fly_over_at_w1(),
        return_home_after: None,
    };
    assert_eq!(turn_kinds(&over_w1), [TurnKind::FlyOver]);
    flights.push(over_w1);
    let mut worst = (0.0f64, f64::NEG_INFINITY, f64::NEG_INFINITY);
    for f in &flights {
        let o = check(f);
        println!(
            "{}: farthest flown position {:.2e} m from the checked paths; checked margin minus \
             flown margin at most {:.3} m; reported minus flown at most {:.3} m",
            f.name, o.worst_distance, o.worst_excess, o.worst_gateway_excess
        );
        worst = (
            worst.0.max(o.worst_distance),
            worst.1.max(o.worst_excess),
            worst.2.max(o.worst_gateway_excess),
        );
    }
    println!(
        "all {} flights: farthest flown position {:.2e} m from the checked paths; checked \
         margin minus flown at most {:.3} m; reported minus flown at most {:.3} m",
        flights.len(),
        worst.0,
        worst.1,
        worst.2
    );
}

/// The route the straight cut refused: a 90° fly-by turn at C between a leg from 1500 m south
/// and a leg of 700 m east, and a no-fly circle of 8 m radius in the corner on the line from
/// where the cut started (137 m before C) to the last waypoint. The legs clear it by 60 m and
/// the arc by 79 m, 35 m and 54 m beyond the safety offset: the gateway and the onboard check
/// pass it now, and the flight keeps that far.
#[test]
fn a_zone_only_the_old_straight_cut_crossed_is_no_violation() {
    let c = Site::new(CORNER.0, CORNER.1);
    let w1 = at(c, 180.0, LEG_M);
    let (_, _, course_in) = Site::new(w1.0, w1.1).inverse_azimuths(&c);
    let w3 = at(c, course_in + 90.0, 700.0);
    // The middle of the old cut: from 137 m before C to waypoint 3.
    let r = fcc_turns().turn_radius_m(25.0);
    let cut_start = c.direct(course_in + 180.0, r);
    let (length, azimuth) = cut_start.inverse(&Site::new(w3.0, w3.1));
    let zone_centre = cut_start.direct(azimuth, length / 2.0);
    let fly_zone = [
        at(c, 225.0, 4000.0),
        at(c, 135.0, 4000.0),
        at(c, 45.0, 4000.0),
        at(c, 315.0, 4000.0),
    ];
    let plan = MissionPlan {
        take_off_position: Some(point(at(c, 180.0, LEG_M + 300.0))),
        ..plan(
            &[
                take_off(30.0).into(),
                waypoint(1, 2, w1, LegType::TrackToFix).into(),
                waypoint(2, 3, CORNER, LegType::TrackToFix).into(),
                waypoint(3, 0, w3, LegType::TrackToFix).into(),
                route(1, false).into(),
            ],
            &[
                polygon(1, AreaType::FlyZone, &fly_zone),
                circle(
                    2,
                    lat_lon(zone_centre),
                    lat_lon(zone_centre.direct(0.0, 8.0)),
                ),
            ],
            "OLD-CUT",
        )
    };
    let lists = plan.assemble().unwrap();
    let violations =
        SafetyGateway::default().violations(&lists.mission, &lists.areas, plan.take_off_position);
    let geo: Vec<String> = violations
        .iter()
        .filter(|v| v.code.code().starts_with("GEO"))
        .map(|v| v.to_string())
        .collect();
    assert!(geo.is_empty(), "{geo:?}");
    let list = lists.mission.to_payload(1);
    let fence = Fence::of_list(&lists.areas);
    let take_off = Site::of(plan.take_off_position.unwrap());
    assert_eq!(
        onboard::check(&fence, checked(&list, take_off, None).into_iter()),
        Ok(())
    );
    let f = Flight {
        name: "the old cut's zone".into(),
        plan,
        return_home_after: None,
    };
    let (flown, _) = fly(&f, &list);
    let zone = &fence.zones[1];
    let flown_margin = flown
        .iter()
        .map(|s| clearance(&Track::new(Path::Point(*s)), zone, f64::INFINITY, true).metres())
        .fold(f64::INFINITY, f64::min);
    assert!(
        flown_margin > fence.safety_offset_m + 35.0,
        "{flown_margin}"
    );
    println!("the old cut's zone: flown {flown_margin:.1} m from it, no violation reported");
}
