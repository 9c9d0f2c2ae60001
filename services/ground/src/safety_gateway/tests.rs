//! The safety gateway's table of missions and the violations each must give, margins,
//! positions, the energy estimate and the codes.

use super::*;
use crate::ground_station::SafetyGateway as _;
use crate::testkit::{self, CCP, FLY_ZONE, NFZ_POLYGON, TROL, circle, polygon};
use missionlink_interfaces::wire::{Angle, AreaPolygonLoopSegment, TurnDirection};

fn geo((lat, lon): (f64, f64)) -> GeoPoint {
    GeoPoint {
        latitude: Angle::from_degrees(lat).unwrap(),
        longitude: Angle::from_degrees(lon).unwrap(),
    }
}
use missionlink_interfaces::wire::{Altitude, SafetyOffset, Speed, UaPositionWaypoint};
use proptest::prelude::*;

const W1: (f64, f64) = (48.278, 11.658);
const ROLE2: (f64, f64) = (48.28, 11.68);
const RF_CENTRE: (f64, f64) = (48.27455, 11.66991);

#[derive(Clone, Copy)]
struct Wp {
    at: (f64, f64),
    alt: f64,
    speed: f64,
    rf: Option<((f64, f64), TurnDirection)>,
}

fn tf(at: (f64, f64)) -> Wp {
    Wp {
        at,
        alt: 120.0,
        speed: 25.0,
        rf: None,
    }
}

fn rf(at: (f64, f64), centre: (f64, f64), dir: TurnDirection) -> Wp {
    Wp {
        rf: Some((centre, dir)),
        ..tf(at)
    }
}

/// Waypoints numbered 1, 2, ... in flight-plan order, the route starting at 1.
fn mission(take_off_height: f64, bidirectional: bool, wps: &[Wp]) -> Mission {
    let mut waypoints = heapless::Vec::new();
    for (i, w) in wps.iter().enumerate() {
        let n = i as u16 + 1;
        let next = if i + 1 == wps.len() { 0 } else { n + 1 };
        let leg = if w.rf.is_some() {
            LegType::RadiusToFix
        } else {
            LegType::TrackToFix
        };
        let waypoint = UaPositionWaypoint {
            altitude: Altitude::from_metres(w.alt).unwrap(),
            speed: Speed::from_mps(w.speed).unwrap(),
            ..testkit::waypoint(n, next, w.at, leg)
        };
        let rf_centre = w.rf.map(|(centre, dir)| testkit::rf_centre(n, centre, dir));
        waypoints
            .push(WaypointRecord {
                waypoint,
                rf_centre,
            })
            .unwrap();
    }
    Mission {
        take_off: testkit::take_off(take_off_height),
        route: testkit::route(1, bidirectional),
        waypoints,
        mission_id: None,
    }
}

fn area_list(areas: &[AreaPolygonLoopSegment]) -> AreaList {
    AreaList {
        safety_offset: SafetyOffset::from_metres(25.0).unwrap(),
        areas: areas.iter().cloned().collect(),
    }
}

fn fly_zone() -> AreaPolygonLoopSegment {
    polygon(1, AreaType::FlyZone, &FLY_ZONE)
}

fn mission_2_areas() -> Vec<AreaPolygonLoopSegment> {
    vec![
        fly_zone(),
        circle(2, (48.268, 11.675), (48.268, 11.679)),
        polygon(3, AreaType::NoFlyZone, &NFZ_POLYGON),
    ]
}

fn mission_1() -> Mission {
    mission(30.0, false, &[tf(CCP)])
}

fn mission_2_with(w1: Wp, role2: Wp) -> Mission {
    mission(30.0, true, &[tf(CCP), w1, role2])
}

fn mission_2() -> Mission {
    mission_2_with(tf(W1), rf(ROLE2, RF_CENTRE, TurnDirection::Clockwise))
}

struct Case {
    name: &'static str,
    gateway: SafetyGateway,
    take_off: Option<GeoPoint>,
    mission: Mission,
    areas: AreaList,
    expected: Vec<(ViolationCode, Element)>,
}

fn case(
    name: &'static str,
    mission: Mission,
    areas: &[AreaPolygonLoopSegment],
    expected: &[(ViolationCode, Element)],
) -> Case {
    Case {
        name,
        gateway: SafetyGateway::default(),
        take_off: Some(geo(TROL)),
        mission,
        areas: area_list(areas),
        expected: expected.to_vec(),
    }
}

fn leg(from: u16, to: u16) -> Element {
    Element::Route(RouteElement::Leg { from, to })
}

/// The turn round of a return to home at `at` back to `to` (a U-turn: flown over).
fn turn_round(at: u16, to: u16) -> Element {
    Element::Route(RouteElement::Turn {
        at,
        to,
        kind: missionlink_protocol::geofence::turn::TurnKind::FlyOver,
    })
}

/// In a function of its own: a debug build keeps every case's temporaries in the frame of
/// the function that builds it, and test threads have 2 MB of stack.
fn fly_by_corner_case() -> Case {
    let corner = testkit::fly_by_corner();
    let lists = corner.assemble().unwrap();
    Case {
        take_off: corner.take_off_position,
        ..case(
            "a fly-by arc enters a no-fly-zone inside its corner (testkit::fly_by_corner)",
            lists.mission,
            &lists.areas.areas,
            &[(
                ViolationCode::NoFlyZoneLeg,
                Element::Route(RouteElement::Turn {
                    at: 2,
                    to: 3,
                    kind: missionlink_protocol::geofence::turn::TurnKind::FlyBy,
                }),
            )],
        )
    }
}

fn cases() -> Vec<Case> {
    use ViolationCode as V;
    let m2 = mission_2_areas();
    let mut with_outside_nfz = m2.clone();
    with_outside_nfz.push(circle(4, (48.30, 11.66), (48.30, 11.663)));
    let bow_tie = [
        (48.255, 11.635),
        (48.285, 11.690),
        (48.255, 11.690),
        (48.285, 11.635),
    ];
    let mut self_intersecting = m2.clone();
    self_intersecting[0] = polygon(1, AreaType::FlyZone, &bow_tie);
    let mut repeated = m2.clone();
    repeated[2] = polygon(
        3,
        AreaType::NoFlyZone,
        &[
            (48.262, 11.640),
            (48.262, 11.646),
            (48.266, 11.646),
            (48.262, 11.646),
        ],
    );
    let mut collinear = m2.clone();
    collinear[2] = polygon(
        3,
        AreaType::NoFlyZone,
        &[(48.262, 11.640), (48.263, 11.641), (48.264, 11.642)],
    );
    let mut bounded = fly_zone();
    bounded.upper_altitude = Some(Altitude::from_metres(100.0).unwrap());
    let mut gateway_small_battery = SafetyGateway::default();
    gateway_small_battery.profile.usable_energy_wh = 600.0;
    let windy = SafetyGateway::new(
        AircraftProfile::default(),
        Environment {
            wind_speed_mps: 15.0,
            wind_from_deg: 270.0,
            temperature_c: 15.0,
        },
    );
    let hot = SafetyGateway::new(
        AircraftProfile::default(),
        Environment {
            temperature_c: 50.0,
            ..Environment::default()
        },
    );
    let fast_w1 = Wp {
        speed: 45.0,
        ..tf(W1)
    };
    let role2_rf = rf(ROLE2, RF_CENTRE, TurnDirection::Clockwise);
    vec![
        case("demo mission 1", mission_1(), &[fly_zone()], &[]),
        Case {
            take_off: None,
            ..case(
                "demo mission 1 without a take-off position",
                mission_1(),
                &[fly_zone()],
                &[(V::TakeOffMissing, Element::TakeOff)],
            )
        },
        Case {
            take_off: Some(geo((48.264, 11.643))),
            ..case(
                "take-off inside a no-fly-zone",
                mission_2(),
                &m2,
                &[(V::NoFlyZoneTakeOff, Element::TakeOff)],
            )
        },
        Case {
            take_off: Some(geo((48.250, 11.660))),
            ..case(
                "take-off outside the fly-zone (the way in is the same defect)",
                mission_2(),
                &m2,
                &[(V::FlyZoneTakeOff, Element::TakeOff)],
            )
        },
        Case {
            take_off: Some(geo((48.258, 11.643))),
            ..case(
                "the way from the take-off point to the initial waypoint crosses a no-fly-zone",
                mission_2(),
                &m2,
                &[(V::NoFlyZoneLeg, leg(0, 1))],
            )
        },
        case(
            "no fly-zone",
            mission_2(),
            &m2[1..],
            &[(V::FlyZoneCount, Element::AreaList)],
        ),
        fly_by_corner_case(),
        case(
            "a no-fly-zone of two vertices",
            mission_2(),
            &[
                fly_zone(),
                polygon(
                    3,
                    AreaType::NoFlyZone,
                    &[(48.262, 11.640), (48.266, 11.646)],
                ),
            ],
            &[(V::VertexCount, Element::Area(3))],
        ),
        case("demo mission 2", mission_2(), &m2, &[]),
        case(
            "demo mission 2, last leg track-to-fix",
            mission_2_with(tf(W1), tf(ROLE2)),
            &m2,
            &[],
        ),
        case(
            "leg cuts a no-fly-zone corner, both waypoints outside",
            mission(
                30.0,
                true,
                &[
                    tf(CCP),
                    tf((48.268, 11.643)),
                    tf((48.263, 11.650)),
                    tf(W1),
                    role2_rf,
                ],
            ),
            &m2,
            &[(V::NoFlyZoneLeg, leg(2, 3))],
        ),
        case(
            "RF arc bulges out of the fly-zone",
            mission_2_with(
                tf(W1),
                rf(ROLE2, (48.279, 11.669), TurnDirection::Clockwise),
            ),
            &m2,
            &[(V::FlyZoneLeg, leg(2, 3))],
        ),
        case(
            "self-intersecting fly-zone",
            mission_2(),
            &self_intersecting,
            &[(V::SelfIntersection, Element::Area(1))],
        ),
        case(
            "no-fly-zone with a repeated vertex",
            mission_2(),
            &repeated,
            &[(V::RepeatedVertex, Element::Area(3))],
        ),
        case(
            "collinear no-fly-zone",
            mission_2(),
            &collinear,
            &[(V::DegeneratePolygon, Element::Area(3))],
        ),
        Case {
            gateway: gateway_small_battery,
            ..case(
                "energy budget infeasible",
                mission_2(),
                &m2,
                &[(V::EnergyBudget, Element::Mission)],
            )
        },
        case(
            "turn too tight",
            mission(
                30.0,
                true,
                &[
                    tf(CCP),
                    tf(W1),
                    rf(
                        (48.27854, 11.658809),
                        (48.278, 11.658809),
                        TurnDirection::Clockwise,
                    ),
                    tf(ROLE2),
                ],
            ),
            &m2,
            &[(V::TurnRadius, leg(2, 3))],
        ),
        case(
            "waypoint inside a no-fly-zone",
            mission_2_with(tf((48.268, 11.675)), tf(ROLE2)),
            &m2,
            &[(V::NoFlyZoneWaypoint, Element::Waypoint(2))],
        ),
        case(
            "RF start and end radii differ",
            mission_2_with(
                tf(W1),
                rf(ROLE2, (48.27455, 11.67021), TurnDirection::Clockwise),
            ),
            &m2,
            &[(V::RfRadiusMismatch, leg(2, 3))],
        ),
        // At 45 m/s the turn round at ROLE2 back to W1 (flown at W1's speed) has a radius
        // of 443 m and leaves the fly-zone.
        case(
            "speed above the envelope",
            mission_2_with(fast_w1, role2_rf),
            &m2,
            &[
                (V::SpeedHigh, Element::Waypoint(2)),
                (V::FlyZoneLeg, turn_round(3, 2)),
            ],
        ),
        case(
            "take-off height too high",
            mission(150.0, true, &[tf(CCP), tf(W1), role2_rf]),
            &m2,
            &[(V::TakeOffHeightHigh, Element::TakeOff)],
        ),
        case(
            "no-fly-zone completely outside the fly-zone",
            mission_2(),
            &with_outside_nfz,
            &[(V::NoFlyZoneOutside, Element::Area(4))],
        ),
        case(
            "waypoint above the fly-zone's upper altitude",
            mission_1(),
            &[bounded],
            &[(V::AreaAltitude, Element::Waypoint(1))],
        ),
        Case {
            gateway: windy,
            ..case(
                "wind over the limit",
                mission_2(),
                &m2,
                // In 15 m/s every turn is flown at (25 + 15)²/(g·tan 25°) = 350 m (ICD §7
                // "Turns in wind"): the turn round at ROLE2 leaves the fly-zone.
                &[
                    (V::Wind, Element::Environment),
                    (V::FlyZoneLeg, turn_round(3, 2)),
                ],
            )
        },
        Case {
            gateway: hot,
            ..case(
                "temperature over the limit",
                mission_2(),
                &m2,
                &[(V::Temperature, Element::Environment)],
            )
        },
        Case {
            gateway: windy,
            ..case(
                "two defects: speed and wind",
                mission_2_with(fast_w1, role2_rf),
                &m2,
                &[
                    (V::Wind, Element::Environment),
                    (V::SpeedHigh, Element::Waypoint(2)),
                    (V::FlyZoneLeg, turn_round(3, 2)),
                ],
            )
        },
    ]
}

#[test]
fn safety_gateway_table() {
    // The table is built as one array of some thirty missions of 27 kB each: more than a
    // test thread's 2 MB of stack in a debug build.
    std::thread::Builder::new()
        .stack_size(32 << 20)
        .spawn(run_safety_gateway_table)
        .unwrap()
        .join()
        .unwrap();
}

fn run_safety_gateway_table() {
    let mut failures = Vec::new();
    for c in cases() {
        let found: Vec<(ViolationCode, Element)> =
            match c.gateway.check(&c.mission, &c.areas, c.take_off) {
                Ok(()) => vec![],
                Err(report) => {
                    assert!(!report.violations.is_empty(), "{}", c.name);
                    report
                        .violations
                        .iter()
                        .map(|v| (v.code, v.element))
                        .collect()
                }
            };
        let report = c.gateway.violations(&c.mission, &c.areas, c.take_off);
        println!("{}:", c.name);
        for v in &report {
            println!("    {v}");
        }
        if found != c.expected {
            failures.push(format!(
                "{}: expected {:?}, found {:?}",
                c.name, c.expected, found
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn safety_gateway_margins_and_positions() {
    let g = SafetyGateway::default();
    // The corner cut: the leg passes the corner (48.266, 11.646) inside by a few tens of
    // metres plus the offset.
    let m = mission(
        30.0,
        false,
        &[tf(CCP), tf((48.268, 11.643)), tf((48.263, 11.650))],
    );
    let v = g.violations(&m, &area_list(&mission_2_areas()), Some(geo(TROL)));
    let [cut] = v.as_slice() else { panic!("{v:?}") };
    let margin = cut.margin_m.unwrap();
    assert!(margin < -25.0 && margin > -80.0, "{margin}");
    let (lat, lon) = cut.position.unwrap();
    assert!((lat - 48.266).abs() < 0.0005 && (lon - 11.646).abs() < 0.0005);
    // A circle: the exact depth is radius + offset at the centre.
    let m = mission_2_with(tf((48.268, 11.675)), tf(ROLE2));
    let v = g.violations(&m, &area_list(&mission_2_areas()), Some(geo(TROL)));
    let radius = earth::distance_m(geo((48.268, 11.675)), geo((48.268, 11.679)));
    assert!(
        (v[0].margin_m.unwrap() + radius + 25.0).abs() < 0.5,
        "{v:?}"
    );
    // The report prints one line per violation.
    let report = Report {
        violations: v,
        turn_wind_mps: 0.0,
    };
    // And the wind the turns were checked in.
    assert_eq!(
        report.to_string().lines().count(),
        report.violations.len() + 1
    );
    assert!(report.to_string().ends_with("(turns checked in calm air)"));
}

#[test]
fn safety_gateway_energy_estimate_of_mission_2() {
    let g = SafetyGateway::default();
    let e = g.estimate_energy(&mission_2(), Some(geo(CCP)));
    // 10 s + 30 s of climb at 22 kW, ~3 km at 25 m/s at 8 kW, 60 s of descent at 12 kW.
    assert!(e.total_wh > 600.0 && e.total_wh < 800.0, "{e:?}");
    assert_eq!(e.limit_wh, 4200.0);
    // Headwind on the whole route costs more than calm air.
    let windy = SafetyGateway::new(
        AircraftProfile::default(),
        Environment {
            wind_speed_mps: 10.0,
            wind_from_deg: 90.0,
            temperature_c: 15.0,
        },
    );
    let w = windy.estimate_energy(&mission_2(), Some(geo(CCP)));
    assert!(w.cruise_wh > e.cruise_wh, "{w:?} {e:?}");
}

/// A 90° fly-by between two legs of 2 km is counted as flown: the legs less `r·tan(45°) = r`
/// each next to the corner, plus the arc's `π·r/2`, at 25 m/s in calm air; in a 12 m/s wind
/// the turn is flown at `(25 + 12)²/(g·tan 25°)` and counted so.
#[test]
fn safety_gateway_energy_counts_the_turn_as_flown() {
    let corner = earth::destination(geo(CCP), 90.0, 3000.0);
    let corner = (corner.y(), corner.x());
    let w1 = earth::destination(geo(corner), 180.0, 2000.0);
    let (_, _, course_in) =
        Site::of(geo((w1.y(), w1.x()))).inverse_azimuths(&Site::of(geo(corner)));
    let w3 = earth::destination(geo(corner), course_in + 90.0, 2000.0);
    let m = mission(
        30.0,
        false,
        &[tf((w1.y(), w1.x())), tf(corner), tf((w3.y(), w3.x()))],
    );
    let p = AircraftProfile::default();
    for wind in [0.0, 12.0] {
        let g = SafetyGateway::new(
            p,
            Environment {
                wind_speed_mps: wind,
                ..Environment::default()
            },
        );
        // Without a take-off point the route starts at waypoint 1: the two legs and the turn.
        let e = g.estimate_energy(&m, None);
        let r = p.min_turn_radius_m(25.0 + wind);
        let metres = 2.0 * (2000.0 - r) + core::f64::consts::FRAC_PI_2 * r;
        let wh = p.cruise_power_w(25.0) * metres / 25.0 / 3600.0;
        if wind == 0.0 {
            assert!((e.cruise_wh - wh).abs() < 1e-3 * wh, "{e:?}: {wh} Wh");
        } else {
            // The wind (from the north) changes the ground speed on every chord; the distance
            // counted is still the turn's.
            assert!(e.cruise_wh > wh * 0.9, "{e:?}: {wh} Wh");
        }
        assert_eq!(e.return_wh, None, "one-way");
    }
}

/// On a bidirectional route the return to home from the last waypoint is counted: with a
/// battery between the flight out and the flight out and back, `ENERGY-RETURN`.
#[test]
fn safety_gateway_energy_of_a_return_to_home() {
    let g = SafetyGateway::default();
    let e = g.estimate_energy(&mission_2(), Some(geo(CCP)));
    let home = e.with_return_wh().unwrap();
    assert!(home > e.total_wh, "{e:?}");
    let mut small = g;
    let usable = (e.total_wh + home) / 2.0 / (1.0 - small.profile.reserve_fraction);
    small.profile.usable_energy_wh = usable;
    let v = small.violations(&mission_2(), &area_list(&mission_2_areas()), Some(geo(CCP)));
    let codes: Vec<&str> = v.iter().map(|v| v.code.code()).collect();
    assert_eq!(codes, ["ENERGY-RETURN"], "{v:?}");
    let one_way = mission(30.0, false, &[tf(CCP), tf(W1), tf(ROLE2)]);
    assert_eq!(
        small.estimate_energy(&one_way, Some(geo(CCP))).return_wh,
        None
    );
}

#[test]
fn safety_gateway_codes_are_distinct() {
    use ViolationCode as V;
    let all = [
        V::TakeOffMissing,
        V::VertexCount,
        V::NoFlyZoneCount,
        V::FlyZoneWaypoint,
        V::FlyZoneLeg,
        V::FlyZoneTakeOff,
        V::NoFlyZoneWaypoint,
        V::NoFlyZoneLeg,
        V::NoFlyZoneTakeOff,
        V::SelfIntersection,
        V::RepeatedVertex,
        V::DegeneratePolygon,
        V::CircleRadius,
        V::FlyZoneCount,
        V::FlyZoneShape,
        V::NoFlyZoneOutside,
        V::AltitudeBounds,
        V::AreaAltitude,
        V::RfRadiusMismatch,
        V::TurnRadius,
        V::SpeedLow,
        V::SpeedHigh,
        V::AltitudeHigh,
        V::TakeOffHeightLow,
        V::TakeOffHeightHigh,
        V::EnergyBudget,
        V::TrackNotHeld,
        V::EnergyReturn,
        V::Wind,
        V::Temperature,
        V::Separation,
    ];
    let codes: std::collections::HashSet<&str> = all.iter().map(|c| c.code()).collect();
    assert_eq!(codes.len(), all.len());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Waypoints well inside the fly-zone and far from both no-fly-zones (the box
    /// 48.270..48.282 N, 11.640..11.660 E: over 400 m from every border) give no violation.
    #[test]
    fn safety_gateway_waypoints_well_inside_pass(
        a in (48.270f64..48.282, 11.640f64..11.660),
        b in (48.270f64..48.282, 11.640f64..11.660),
        bidirectional in any::<bool>(),
    ) {
        let m = mission(30.0, bidirectional, &[tf(CCP), tf(a), tf(b)]);
        let v = SafetyGateway::default().violations(&m, &area_list(&mission_2_areas()), Some(geo(TROL)));
        prop_assert!(v.is_empty(), "{:?}", v);
    }

    /// A waypoint at distance d from the circular no-fly-zone's centre violates it exactly
    /// when d < radius + offset (away from the boundary by more than the sampling).
    #[test]
    fn safety_gateway_circle_boundary(bearing in 0.0f64..360.0, d in 150.0f64..500.0) {
        let centre = geo((48.268, 11.675));
        let radius = earth::distance_m(centre, geo((48.268, 11.679)));
        prop_assume!((d - radius - 25.0).abs() > 0.01);
        let at = earth::destination(centre, bearing, d);
        let m = mission(30.0, false, &[tf((at.y(), at.x()))]);
        let areas = area_list(&mission_2_areas());
        let v = SafetyGateway::default().violations(&m, &areas, Some(geo(TROL)));
        let inside = v.iter().any(|v| v.code == ViolationCode::NoFlyZoneWaypoint);
        prop_assert_eq!(inside, d < radius + 25.0, "{:?}", v);
    }
}
