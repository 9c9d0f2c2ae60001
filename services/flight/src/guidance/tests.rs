//! The guidance model's tests: phases, legs, fly-by and fly-over turns, radius-to-fix legs,
//! return to home, land-at, new lists in the air and the zone status.

use core::time::Duration;
use missionlink_protocol::geofence::flown_route;

use missionlink_interfaces::contracts::{CircleArea, PolygonArea, WaypointEntry};
use missionlink_interfaces::wire::{
    Altitude, AltitudeType, GeoPoint, LegType, Speed, TurnDirection, TurnType,
};

use missionlink_protocol::geofence::earth::{Site, bearing_deg, destination, distance_m};
use missionlink_protocol::geofence::path::Path;
use missionlink_protocol::geofence::turn::{Turn, TurnKind};

use super::*;

const TROL: (f64, f64) = (48.26, 11.66);
const CCP: (f64, f64) = (48.275, 11.645);
const W1: (f64, f64) = (48.278, 11.658);
const ROLE2: (f64, f64) = (48.28, 11.68);
const RF_CENTRE: (f64, f64) = (48.27455, 11.66991);
const NFZ_CENTRE: (f64, f64) = (48.268, 11.675);
const NFZ_BORDER: (f64, f64) = (48.268, 11.679);
/// Real time between steps.
const DT: Duration = Duration::from_millis(100);
const SPEED: f64 = 25.0;

fn gp(p: (f64, f64)) -> GeoPoint {
    GeoPoint::from_degrees(p.0, p.1).unwrap()
}

fn pt(p: (f64, f64)) -> Point<f64> {
    Point::new(p.1, p.0)
}

fn here(p: &GuidanceProgressPayload) -> Point<f64> {
    Point::new(p.longitude_deg, p.latitude_deg)
}

fn config_at(p: (f64, f64)) -> GuidanceConfig {
    GuidanceConfig {
        start_latitude_deg: p.0,
        start_longitude_deg: p.1,
        ..GuidanceConfig::default()
    }
}

fn waypoint(number: u16, next: u16, at: (f64, f64), turn: TurnType) -> WaypointEntry {
    let mut w = WaypointEntry {
        number,
        next,
        position: gp(at),
        altitude: Altitude::from_metres(120.0).unwrap(),
        speed: Speed::from_mps(SPEED).unwrap(),
        turn_type: turn.into(),
        leg_type: LegType::TrackToFix.into(),
        ..WaypointEntry::EMPTY
    };
    w.set_altitude_type(Some(AltitudeType::Wgs84));
    w
}

fn list(generation: u64, waypoints: &[WaypointEntry]) -> WaypointListPayload {
    let mut l = WaypointListPayload::EMPTY;
    l.generation = generation;
    l.take_off_height = Altitude::from_metres(30.0).unwrap();
    l.count = waypoints.len() as u16;
    l.initial_waypoint = waypoints[0].number;
    l.waypoints[..waypoints.len()].copy_from_slice(waypoints);
    l
}

/// Demo mission 1: TROL -> CCP.
fn mission1() -> WaypointListPayload {
    list(1, &[waypoint(1, 0, CCP, TurnType::FlyBy)])
}

/// The richer demo mission 2: CCP -> W1 (TF) -> ROLE2 (RF, clockwise), bidirectional.
fn mission2(generation: u64, w1_turn: TurnType) -> WaypointListPayload {
    let mut role2 = waypoint(3, 0, ROLE2, TurnType::FlyBy);
    role2.leg_type = LegType::RadiusToFix.into();
    role2.set_rf_centre(Some((gp(RF_CENTRE), TurnDirection::Clockwise)));
    let mut l = list(
        generation,
        &[
            waypoint(1, 2, CCP, TurnType::FlyBy),
            waypoint(2, 3, W1, w1_turn),
            role2,
        ],
    );
    l.bidirectional = true;
    l
}

fn mission2_areas() -> AreaListPayload {
    let mut a = AreaListPayload::EMPTY;
    a.generation = 1;
    a.fly_zone.area_id = 1;
    a.fly_zone.vertex_count = 4;
    for (v, p) in a.fly_zone.vertices.iter_mut().zip([
        (48.255, 11.635),
        (48.255, 11.69),
        (48.285, 11.69),
        (48.285, 11.635),
    ]) {
        *v = gp(p);
    }
    a.no_fly_circle_count = 1;
    a.no_fly_circles[0] = CircleArea {
        area_id: 2,
        centre: gp(NFZ_CENTRE),
        border: gp(NFZ_BORDER),
        ..CircleArea::EMPTY
    };
    a.no_fly_polygon_count = 1;
    let mut poly = PolygonArea {
        area_id: 3,
        vertex_count: 4,
        ..PolygonArea::EMPTY
    };
    for (v, p) in poly.vertices.iter_mut().zip([
        (48.262, 11.64),
        (48.262, 11.646),
        (48.266, 11.646),
        (48.266, 11.64),
    ]) {
        *v = gp(p);
    }
    a.no_fly_polygons[0] = poly;
    a
}

/// A guidance driven through simulated time, every progress kept.
struct Sim {
    g: Guidance,
    now: Instant,
    automation: AutomationStatePayload,
    log: Vec<GuidanceProgressPayload>,
}

impl Sim {
    fn new(config: GuidanceConfig, l: &WaypointListPayload) -> Self {
        let mut g = Guidance::new(config);
        g.set_waypoint_list(l);
        let mut s = Self {
            g,
            now: Instant::ZERO,
            automation: AutomationStatePayload::ON_GROUND,
            log: Vec::new(),
        };
        s.automation.flown_waypoint_list = l.generation;
        s.step();
        s
    }

    fn set(&mut self, f: impl FnOnce(&mut AutomationStatePayload)) {
        f(&mut self.automation);
        self.automation.sequence += 1;
        self.g.set_automation(&self.automation);
    }

    fn phase(&mut self, phase: FlightPhase) {
        self.set(|a| a.flight_phase = phase as u8);
    }

    fn step(&mut self) -> GuidanceProgressPayload {
        self.now = self.now + DT;
        let p = self.g.step(self.now);
        self.log.push(p);
        p
    }

    /// Steps until `done`; returns the progress and the steps taken.
    fn run_until(
        &mut self,
        max_steps: usize,
        done: impl Fn(&GuidanceProgressPayload) -> bool,
    ) -> (GuidanceProgressPayload, usize) {
        for n in 1..=max_steps {
            let p = self.step();
            if done(&p) {
                return (p, n);
            }
        }
        panic!("not done in {max_steps} steps: {:?}", self.log.last());
    }

    /// Steps `n` times.
    fn run(&mut self, n: usize) {
        for _ in 0..n {
            self.step();
        }
    }

    /// The FROM-TO-NEXT triples logged from `start`, repetitions removed.
    fn triples(&self, start: usize) -> Vec<(u16, u16, u16)> {
        let mut t: Vec<_> = self.log[start..].iter().map(|p| p.from_to_next()).collect();
        t.dedup();
        t
    }

    /// Take-off and climb to the take-off height.
    fn take_off(&mut self) -> usize {
        self.phase(FlightPhase::TakeOff);
        self.run_until(1000, |p| p.climb_complete).1
    }
}

fn secs(steps: usize) -> f64 {
    steps as f64 * DT.as_secs_f64()
}

/// Bearing from `centre` to each point, unwrapped (no jumps of 360 deg).
fn unwrapped_bearings(centre: Point<f64>, points: &[Point<f64>]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(points.len());
    for p in points {
        let b = bearing_deg(centre, *p);
        out.push(match out.last() {
            Some(prev) => prev + ((b - prev + 180.0).rem_euclid(360.0) - 180.0),
            None => b,
        });
    }
    out
}

#[test]
fn on_the_ground_nothing_moves() {
    let mut s = Sim::new(GuidanceConfig::default(), &mission1());
    for _ in 0..50 {
        let p = s.step();
        assert!(p.on_ground && !p.trajectory_generation_active);
        assert_eq!((p.latitude_deg, p.longitude_deg), TROL);
        assert_eq!(p.altitude_m, 0.0);
        assert_eq!(p.ground_speed_mps, 0.0);
        assert_eq!(p.from_to_next(), (0, 0, 0));
        assert_eq!(p.waypoint_list, 1);
    }
    let p = s.log.last().unwrap();
    assert_eq!(p.sequence, 51);
    assert_eq!(p.time_ns, 5_100_000_000);
}

/// Demo mission 1 through every phase: climb 30 m at 3 m/s, the TF leg TROL -> CCP at
/// 25 m/s, descent from 120 m at 2 m/s.
#[test]
fn mission1_take_off_cruise_landing() {
    let mut s = Sim::new(GuidanceConfig::default(), &mission1());

    s.phase(FlightPhase::TakeOff);
    let (p, steps) = s.run_until(1000, |p| p.climb_complete);
    assert!((secs(steps) - 30.0 / 3.0).abs() <= 0.1 + 1e-9, "{steps}");
    assert_eq!(p.altitude_m, 30.0);
    assert_eq!((p.latitude_deg, p.longitude_deg), TROL);
    assert_eq!(p.from_to_next(), (0, 1, 0));
    assert!(!p.on_ground && !p.trajectory_generation_active);
    assert_eq!(p.ground_speed_mps, 0.0);
    // Holds at the take-off height.
    assert_eq!(s.step().altitude_m, 30.0);

    s.phase(FlightPhase::Cruise);
    let start = s.log.len();
    let (p, steps) = s.run_until(2000, |p| p.route_complete);
    let leg = distance_m(pt(TROL), pt(CCP));
    assert!((leg - 2004.0).abs() < 5.0, "{leg}");
    assert!((secs(steps) - leg / SPEED).abs() <= 0.1 + 1e-9, "{steps}");
    assert!(distance_m(here(&p), pt(CCP)) < 0.01);
    assert_eq!(p.altitude_m, 120.0);
    assert_eq!(p.from_to_next(), (1, 0, 0));
    assert_eq!(s.triples(start), [(0, 1, 0), (1, 0, 0)]);
    let mid = s.log[start + steps / 2];
    assert_eq!(mid.ground_speed_mps, SPEED);
    assert!(mid.trajectory_generation_active && !mid.on_ground);
    // Altitude linear in distance: half way, half way from 30 to 120 m.
    assert!((mid.altitude_m - 75.0).abs() < 1.0, "{}", mid.altitude_m);
    // Hovers at CCP.
    let p = s.step();
    assert_eq!(p.ground_speed_mps, 0.0);
    assert!(distance_m(here(&p), pt(CCP)) < 0.01);

    s.phase(FlightPhase::Landing);
    let (p, steps) = s.run_until(2000, |p| p.on_ground);
    assert!((secs(steps) - 120.0 / 2.0).abs() <= 0.1 + 1e-9, "{steps}");
    assert_eq!(p.altitude_m, 0.0);
    assert!(!p.trajectory_generation_active);

    s.phase(FlightPhase::Landed);
    let p = s.step();
    assert!(p.on_ground);
    assert_eq!(p.from_to_next(), (0, 0, 0));
    assert!(distance_m(here(&p), pt(CCP)) < 0.01);
}

/// Expected fly-by anticipation at W1 of mission 2: TF inbound from CCP, tangent of the
/// clockwise arc outbound.
fn w1_anticipation() -> f64 {
    let inbound = bearing_deg(pt(W1), pt(CCP)) + 180.0;
    let outbound = bearing_deg(pt(RF_CENTRE), pt(W1)) + 90.0;
    let turn = ((outbound - inbound + 180.0).rem_euclid(360.0) - 180.0).abs();
    let r = SPEED * SPEED / (9.80665 * 25f64.to_radians().tan());
    r * (turn / 2.0).to_radians().tan()
}

/// Flies mission 2 from CCP to ROLE2; returns the simulation and the log index where the
/// take-off started.
fn fly_mission2(w1_turn: TurnType) -> (Sim, usize) {
    let mut s = Sim::new(config_at(CCP), &mission2(2, w1_turn));
    let start = s.log.len();
    s.take_off();
    assert_eq!(s.log.last().unwrap().from_to_next(), (0, 1, 2));
    s.phase(FlightPhase::Cruise);
    let (p, _) = s.run_until(3000, |p| p.route_complete);
    assert!(distance_m(here(&p), pt(ROLE2)) < 0.01);
    assert_eq!(p.altitude_m, 120.0);
    assert_eq!(
        s.triples(start),
        [(0, 1, 2), (1, 2, 3), (2, 3, 0), (3, 0, 0)]
    );
    (s, start)
}

/// Distances of the samples on the RF leg to the centre, relative to the radius, and the
/// points.
fn rf_leg(
    s: &Sim,
    on_leg: impl Fn(&GuidanceProgressPayload) -> bool,
) -> (Vec<f64>, Vec<Point<f64>>) {
    let radius = distance_m(pt(RF_CENTRE), pt(ROLE2));
    let points: Vec<_> = s.log.iter().filter(|p| on_leg(p)).map(here).collect();
    let rel = points
        .iter()
        .map(|p| (distance_m(pt(RF_CENTRE), *p) - radius).abs() / radius)
        .collect();
    (rel, points)
}

/// The turn at W1 of mission 2 (inbound the leg from CCP, outbound the RF arc to ROLE2)
/// as the geofence constructs it, and the farthest a sample of the leg to ROLE2 (TO = 3)
/// lies from that turn's paths and the arc.
fn turn_at_w1(s: &Sim, w1_turn: TurnType) -> (Turn, f64) {
    let l = mission2(2, w1_turn);
    let w = l.waypoints();
    let (inbound, outbound) = (
        flown_route::leg(&w[0], &w[1]),
        flown_route::leg(&w[1], &w[2]),
    );
    let t = GuidanceConfig::default()
        .fly_by()
        .turn(&w[1], &w[2], &inbound, &outbound, 0.0);
    let paths: Vec<Path> = t.paths.iter().copied().chain([outbound]).collect();
    let worst = s
        .log
        .iter()
        .filter(|p| p.to == 3)
        .map(|p| {
            paths
                .iter()
                .map(|path| crate::testkit::distance_to_path(path, Site::of(here(p))))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    (t, worst)
}

/// Fly-by at W1, track-to-fix onto radius-to-fix: FROM-TO-NEXT switches where the arc
/// tangent to the leg and to the RF circle starts (about `r·tan(Δψ/2)` before W1), the
/// arc and then the RF leg are flown on their paths, clockwise.
#[test]
fn mission2_fly_by_tf_then_rf_arc() {
    let radius = distance_m(pt(RF_CENTRE), pt(ROLE2));
    assert!((radius - 962.0).abs() < 2.0, "{radius}");
    let (s, start) = fly_mission2(TurnType::FlyBy);
    let (t, worst) = turn_at_w1(&s, TurnType::FlyBy);
    assert_eq!(t.kind, TurnKind::FlyBy);
    assert!(worst < 0.001, "{worst} m off the turn and the arc");

    // The leg CCP -> W1 is left at the arc's start, about the anticipation before W1.
    let switch = start + s.log[start..].iter().position(|p| p.to == 3).unwrap();
    let anticipation = w1_anticipation();
    assert!((55.0..65.0).contains(&anticipation), "{anticipation}");
    let leave = distance_m(t.leave, pt(W1));
    assert!((leave - anticipation).abs() < 5.0, "{leave} {anticipation}");
    let step = SPEED * DT.as_secs_f64();
    let before = distance_m(here(&s.log[switch - 1]), pt(W1));
    assert!(
        before >= leave - 0.01 && before <= leave + step + 0.01,
        "{before}"
    );

    // On the RF leg once the turn is flown (off the turn's arc), clockwise.
    let points: Vec<Point<f64>> = s
        .log
        .iter()
        .filter(|p| p.to == 3)
        .map(here)
        .filter(|p| crate::testkit::distance_to_path(&t.paths[0], Site::of(*p)) > 0.001)
        .collect();
    let bearings = unwrapped_bearings(pt(RF_CENTRE), &points);
    assert!(bearings.windows(2).all(|w| w[1] > w[0]), "not clockwise");
    let swept = bearings.last().unwrap() - bearings.first().unwrap();
    assert!((100.0..125.0).contains(&swept), "{swept}");
    eprintln!(
        "mission 2: anticipation r·tan(Δψ/2) {anticipation:.1} m, the arc onto the RF \
         circle leaves the leg {leave:.1} m before W1; samples at most {worst:.1e} m off \
         the turn and the arc; swept {swept:.1} deg on the RF circle"
    );
}

/// Fly-over at W1: the leg is flown to W1, FROM-TO-NEXT switches there, then the turn, the
/// intercept and the turn onto the RF circle, each on its path.
#[test]
fn fly_over_switches_at_the_waypoint() {
    let (s, start) = fly_mission2(TurnType::FlyOver);
    let (t, worst) = turn_at_w1(&s, TurnType::FlyOver);
    assert_eq!(t.kind, TurnKind::FlyOver);
    assert!(distance_m(t.leave, pt(W1)) < 0.01, "{:?}", t.leave);
    assert!(worst < 0.001, "{worst} m off the turn and the arc");
    let switch = start + s.log[start..].iter().position(|p| p.to == 3).unwrap();
    let step_travel = SPEED * DT.as_secs_f64();
    assert!(distance_m(here(&s.log[switch]), pt(W1)) <= step_travel + 0.01);
    assert!(distance_m(here(&s.log[switch - 1]), pt(W1)) > 0.01);
}

/// The look-ahead law: put 200 m beside the leg CCP -> W1 (to the left, then to the
/// right), the aircraft comes back to the geodesic with the cross-track error shrinking at
/// every step and never changing sign (no overshoot), to under a metre by the turn at W1
/// (about 800 m on: the error decays as `exp(-s/L)`, `L` the turn radius, once it is
/// smaller than `L`).
#[test]
fn the_cross_track_error_goes_to_zero_without_overshoot() {
    for side in [-90.0, 90.0] {
        let mut s = Sim::new(config_at(CCP), &mission2(2, TurnType::FlyBy));
        s.take_off();
        s.phase(FlightPhase::Cruise);
        s.run_until(100, |p| p.from_to_next() == (1, 2, 3));
        let (a, b) = (Site::of(pt(CCP)), Site::of(pt(W1)));
        let (_, course) = a.inverse(&b);
        let xte = |p: &GuidanceProgressPayload| {
            let (d, az) = a.inverse(&Site::of(here(p)));
            d * (az - course).to_radians().sin()
        };
        let now = *s.log.last().unwrap();
        s.g.position = destination(here(&now), course + side, 200.0);
        let start = s.log.len();
        s.run_until(1000, |p| p.to == 3);
        let errors: Vec<f64> = s.log[start..]
            .iter()
            .take_while(|p| p.to == 2)
            .map(xte)
            .collect();
        let first = errors[0];
        assert!(first.abs() > 150.0, "{first}");
        assert!(
            errors.windows(2).all(|w| w[1].abs() <= w[0].abs() + 1e-9),
            "not shrinking"
        );
        assert!(
            errors.iter().all(|e| e * first >= -1e-9),
            "overshoot: {:?}",
            errors
                .iter()
                .cloned()
                .fold(0.0, |m: f64, e| if e * first < 0.0 {
                    m.max(e.abs())
                } else {
                    m
                })
        );
        let last = errors.last().unwrap().abs();
        assert!(last < 1.0, "{last}");
        eprintln!(
            "cross-track error {first:.1} m: {:.1} m after 10 s, {:.2e} m when the turn at \
             W1 starts",
            errors[100.min(errors.len() - 1)],
            last
        );
    }
}

#[test]
fn return_to_home_flies_the_route_backwards() {
    let (mut s, _) = fly_mission2(TurnType::FlyBy);
    s.set(|a| a.route_reversed = true);
    let start = s.log.len();
    let (p, _) = s.run_until(3000, |p| p.route_complete);
    assert!(
        distance_m(here(&p), pt(CCP)) < 0.01,
        "ends at the initial waypoint"
    );
    assert_eq!(s.triples(start), [(3, 2, 1), (2, 1, 0), (1, 0, 0)]);
    // The reversed RF leg ROLE2 -> W1 is the same arc, counter-clockwise.
    let (rel, points) = rf_leg(&s, |p| p.from_to_next() == (3, 2, 1));
    assert!(points.len() > 700, "{}", points.len());
    assert!(rel.iter().all(|r| *r <= 0.02));
    let bearings = unwrapped_bearings(pt(RF_CENTRE), &points);
    assert!(
        bearings.windows(2).all(|w| w[1] < w[0]),
        "not counter-clockwise"
    );
}

#[test]
fn reversal_mid_leg_keeps_to_and_turns_round_after_it() {
    let mut s = Sim::new(config_at(CCP), &mission2(2, TurnType::FlyBy));
    s.take_off();
    s.phase(FlightPhase::Cruise);
    s.run_until(100, |p| p.from_to_next() == (1, 2, 3));
    s.step();
    s.set(|a| a.route_reversed = true);
    let start = s.log.len();
    let p = s.step();
    assert_eq!(p.from_to_next(), (1, 2, 1));
    let (p, _) = s.run_until(3000, |p| p.route_complete);
    assert_eq!(s.triples(start), [(1, 2, 1), (2, 1, 0), (1, 0, 0)]);
    assert!(distance_m(here(&p), pt(CCP)) < 0.01);

    // A route that is not bidirectional is not reversed.
    let mut l = mission2(3, TurnType::FlyBy);
    l.bidirectional = false;
    let mut s = Sim::new(config_at(CCP), &l);
    s.take_off();
    s.phase(FlightPhase::Cruise);
    s.set(|a| a.route_reversed = true);
    let (p, _) = s.run_until(3000, |p| p.route_complete);
    assert_eq!(p.from_to_next(), (3, 0, 0));
}

#[test]
fn land_at_ends_the_route_there() {
    let mut s = Sim::new(config_at(CCP), &mission2(2, TurnType::FlyBy));
    s.take_off();
    s.phase(FlightPhase::Cruise);
    s.set(|a| a.land_at = 2);
    let start = s.log.len();
    let (p, _) = s.run_until(3000, |p| p.route_complete);
    assert_eq!(s.triples(start), [(1, 2, 0), (2, 0, 0)]);
    assert!(distance_m(here(&p), pt(W1)) < 0.01);
}

#[test]
fn time_scale_ten_flies_the_same_path_ten_times_faster() {
    let fly = |time_scale: f64| {
        let mut s = Sim::new(
            GuidanceConfig {
                time_scale,
                ..GuidanceConfig::default()
            },
            &mission1(),
        );
        let climb = s.take_off();
        s.phase(FlightPhase::Cruise);
        let (p, cruise) = s.run_until(2000, |p| p.route_complete);
        (climb, cruise, p)
    };
    let (climb1, cruise1, p1) = fly(1.0);
    let (climb10, cruise10, p10) = fly(10.0);
    assert_eq!((climb1, climb10), (100, 10));
    assert!(
        cruise1.abs_diff(cruise10 * 10) <= 10,
        "{cruise1} {cruise10}"
    );
    assert_eq!(here(&p1), here(&p10));
    assert_eq!(p1.altitude_m, p10.altitude_m);
}

/// Angle from `b` to `a`, degrees in -180..180.
fn angle_between(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

/// Heading, bank, pitch and climb rate through mission 1's phases: on the ground nothing is
/// known of the heading and the rest is 0; the take-off is a vertical climb at the climb rate;
/// the cruise climbs along the leg at the heading of the course (calm air), wings level; the
/// landing descends at the descent rate; landed, the nose points where it did.
#[test]
fn attitude_and_climb_rate_through_the_phases() {
    let mut s = Sim::new(GuidanceConfig::default(), &mission1());
    let p = s.step();
    assert!(p.heading_deg.is_nan(), "{p:?}");
    assert_eq!((p.roll_deg, p.pitch_deg, p.climb_rate_mps), (0.0, 0.0, 0.0));

    s.phase(FlightPhase::TakeOff);
    let p = s.step();
    assert_eq!(p.climb_rate_mps, 3.0);
    assert_eq!((p.roll_deg, p.pitch_deg), (0.0, 90.0));
    assert!(
        p.heading_deg.is_nan(),
        "no movement over the ground yet: {p:?}"
    );
    let (p, _) = s.run_until(1000, |p| p.climb_complete);
    assert!(p.climb_rate_mps > 0.0, "{p:?}");
    // Holding at the take-off height.
    let p = s.step();
    assert_eq!((p.climb_rate_mps, p.pitch_deg), (0.0, 0.0));

    s.phase(FlightPhase::Cruise);
    let start = s.log.len();
    let (_, steps) = s.run_until(2000, |p| p.route_complete);
    let mid = s.log[start + steps / 2];
    let course = bearing_deg(here(&mid), pt(CCP));
    let off = angle_between(f64::from(mid.heading_deg), course);
    assert!(
        off.abs() < 1e-3,
        "heading {} course {course}",
        mid.heading_deg
    );
    assert_eq!(mid.roll_deg, 0.0);
    // 30 m to 120 m over the 2004 m leg at 25 m/s: about 1.12 m/s, at its flight-path angle.
    let climb = f64::from(mid.climb_rate_mps);
    assert!((climb - 90.0 / 2004.0 * SPEED).abs() < 0.01, "{climb}");
    let pitch = (climb / SPEED).atan().to_degrees();
    assert!((f64::from(mid.pitch_deg) - pitch).abs() < 1e-4, "{mid:?}");
    // Hovering at CCP: no bank, no climb, the heading of the arrival kept.
    let arrival = s.log[s.log.len() - 1].heading_deg;
    assert!((0.0..360.0).contains(&arrival), "{arrival}");
    let p = s.step();
    assert_eq!((p.roll_deg, p.pitch_deg, p.climb_rate_mps), (0.0, 0.0, 0.0));
    assert_eq!(p.heading_deg, arrival);

    s.phase(FlightPhase::Landing);
    let p = s.step();
    assert_eq!((p.climb_rate_mps, p.pitch_deg), (-2.0, -90.0));
    let (p, _) = s.run_until(2000, |p| p.on_ground);
    assert_eq!((p.roll_deg, p.pitch_deg, p.climb_rate_mps), (0.0, 0.0, 0.0));
    assert_eq!(p.heading_deg, arrival);
}

/// The nose points along the course in calm air and is turned into a crosswind by the crab
/// angle `asin(W/v)`; the ground speed is what is left of the airspeed.
#[test]
fn heading_is_the_course_turned_into_the_crosswind() {
    let course = bearing_deg(pt(TROL), pt(CCP));
    let fly = |wind_speed_mps: f64, wind_from_deg: f64| {
        let mut s = Sim::new(
            GuidanceConfig {
                wind_speed_mps,
                wind_from_deg,
                ..GuidanceConfig::default()
            },
            &mission1(),
        );
        s.take_off();
        s.phase(FlightPhase::Cruise);
        let start = s.log.len();
        let (_, steps) = s.run_until(3000, |p| p.route_complete);
        let mid = s.log[start + steps / 2];
        let course_there = bearing_deg(here(&mid), pt(CCP));
        assert!(angle_between(course_there, course).abs() < 0.1);
        (mid, course_there)
    };

    let (calm, course_there) = fly(0.0, 0.0);
    let off = angle_between(f64::from(calm.heading_deg), course_there);
    assert!(
        off.abs() < 1e-3,
        "calm: heading {} course {course_there}",
        calm.heading_deg
    );

    // 10 m/s from the right of the course: the nose turns right, into it.
    let (windy, course_there) = fly(10.0, (course + 90.0).rem_euclid(360.0));
    let crab = (10.0 / SPEED).asin().to_degrees();
    let off = angle_between(f64::from(windy.heading_deg), course_there);
    assert!((off - crab).abs() < 0.01, "crab {off} expected {crab}");
    assert!((0.0..360.0).contains(&windy.heading_deg));
    let ground = (SPEED * SPEED - 100.0).sqrt();
    assert!((windy.ground_speed_mps - ground).abs() < 0.01, "{windy:?}");
    assert_eq!(windy.roll_deg, 0.0);

    // From the left: the nose turns left.
    let (windy, course_there) = fly(10.0, (course - 90.0).rem_euclid(360.0));
    let off = angle_between(f64::from(windy.heading_deg), course_there);
    assert!((off + crab).abs() < 0.01, "crab {off} expected {}", -crab);
}

/// Wings level on the legs; in the fly-by turn at W1 of mission 2 the configured bank (the
/// turn is sized for it: `v²/(g·tan(bank))` in calm air), to the side the turn goes; on the
/// radius-to-fix arc the bank its radius takes, `atan(v²/(g·R))`.
#[test]
fn roll_is_the_bank_of_the_turn_flown() {
    let (s, start) = fly_mission2(TurnType::FlyBy);
    let (t, _) = turn_at_w1(&s, TurnType::FlyBy);
    let Path::Arc(arc) = t.paths[0] else {
        panic!("the fly-by turn is an arc: {:?}", t.paths[0]);
    };
    let right = arc.direction == TurnDirection::Clockwise;
    let bank = GuidanceConfig::default().max_bank_deg;

    // The leg CCP -> W1, away from its ends.
    let on_leg: Vec<_> = s.log[start..]
        .iter()
        .filter(|p| p.to == 2 && p.trajectory_generation_active)
        .collect();
    assert!(on_leg.len() > 100, "{}", on_leg.len());
    for p in &on_leg[..on_leg.len() - 1] {
        assert_eq!(p.roll_deg, 0.0, "{p:?}");
    }

    // The turn: the samples on its arc, but the first and the last (the step that leaves the
    // leg, the step that joins the radius-to-fix arc).
    let in_turn: Vec<_> = s
        .log
        .iter()
        .filter(|p| {
            p.to == 3 && crate::testkit::distance_to_path(&t.paths[0], Site::of(here(p))) < 0.001
        })
        .collect();
    assert!(in_turn.len() > 10, "{}", in_turn.len());
    for p in &in_turn[1..in_turn.len() - 1] {
        let roll = f64::from(p.roll_deg);
        assert!((roll.abs() - bank).abs() < 0.5, "bank {roll} in the turn");
        assert_eq!(roll > 0.0, right, "bank {roll}, turning right: {right}");
    }

    // The radius-to-fix arc (clockwise, 962 m): a gentle bank to the right.
    let radius = distance_m(pt(RF_CENTRE), pt(ROLE2));
    let rf_bank = (SPEED * SPEED / (9.806_65 * radius)).atan().to_degrees();
    let on_rf: Vec<_> = s
        .log
        .iter()
        .filter(|p| {
            p.to == 3
                && !p.route_complete
                && crate::testkit::distance_to_path(&t.paths[0], Site::of(here(p))) > 1.0
        })
        .collect();
    assert!(on_rf.len() > 10, "{}", on_rf.len());
    for p in &on_rf[1..on_rf.len() - 1] {
        assert!(
            (f64::from(p.roll_deg) - rf_bank).abs() < 0.05,
            "bank {} on the arc, {rf_bank} expected",
            p.roll_deg
        );
    }
    eprintln!(
        "mission 2: wings level on {} samples of the leg; bank {:?} deg on {} samples of the \
         turn at W1 (limit {bank}); {:.2} deg on {} samples of the arc ({rf_bank:.2} expected)",
        on_leg.len(),
        in_turn[in_turn.len() / 2].roll_deg,
        in_turn.len(),
        on_rf[on_rf.len() / 2].roll_deg,
        on_rf.len()
    );
}

#[test]
fn new_list_in_the_air_waits_for_automation() {
    let mut s = Sim::new(GuidanceConfig::default(), &mission1());
    s.take_off();
    s.phase(FlightPhase::Cruise);
    s.run(10);
    let m2 = mission2(2, TurnType::FlyBy);
    s.g.set_waypoint_list(&m2);
    let p = s.step();
    assert_eq!((p.waypoint_list, p.from_to_next()), (1, (0, 1, 0)));
    s.set(|a| a.flown_waypoint_list = 2);
    let p = s.step();
    assert_eq!((p.waypoint_list, p.from_to_next()), (2, (0, 1, 2)));
    let (p, _) = s.run_until(5000, |p| p.route_complete);
    assert!(distance_m(here(&p), pt(ROLE2)) < 0.01);

    // On the ground a new list is taken at once.
    s.phase(FlightPhase::Landing);
    s.run_until(1000, |p| p.on_ground);
    s.g.set_waypoint_list(&mission1());
    assert_eq!(s.step().waypoint_list, 1);
}

#[test]
fn zones_are_detected_and_changes_logged_once() {
    // Inside the polygonal no-fly-zone from the start.
    let mut g = Guidance::new(config_at((48.264, 11.643)));
    g.set_area_list(&mission2_areas());
    let p = g.step(Instant::ZERO);
    assert_eq!((p.inside_fly_zone, p.in_no_fly_zone), (true, 3));

    // Without an area list: outside any fly-zone, in no no-fly-zone.
    let mut s = Sim::new(
        GuidanceConfig::default(),
        &list(1, &[waypoint(1, 0, NFZ_CENTRE, TurnType::FlyBy)]),
    );
    assert_eq!(
        (s.log[0].inside_fly_zone, s.log[0].in_no_fly_zone),
        (false, 0)
    );
    s.g.set_area_list(&mission2_areas());
    assert_eq!(
        (
            s.step().inside_fly_zone,
            s.log.last().unwrap().in_no_fly_zone
        ),
        (true, 0)
    );

    // Fly into the circle: detected at its border (radius = geodesic centre -> border).
    let radius = distance_m(pt(NFZ_CENTRE), pt(NFZ_BORDER));
    // 0.004° of longitude at 48.268° N on WGS-84 (the sphere of the mean radius said 296.06).
    assert!((radius - 296.95).abs() < 0.01, "{radius}");
    s.take_off();
    s.phase(FlightPhase::Cruise);
    let (p, _) = s.run_until(2000, |p| p.in_no_fly_zone != 0);
    assert_eq!(p.in_no_fly_zone, 2);
    let d = distance_m(here(&p), pt(NFZ_CENTRE));
    assert!(
        d <= radius && d > radius - SPEED * DT.as_secs_f64() - 0.01,
        "{d}"
    );
    s.run_until(2000, |p| p.route_complete);
    s.run(20);
    assert_eq!(s.g.zone_warnings, 1, "logged once, not every step");

    // Then out of the fly-zone to the north.
    let out = list(2, &[waypoint(1, 0, (48.29, 11.675), TurnType::FlyBy)]);
    s.g.set_waypoint_list(&out);
    s.set(|a| a.flown_waypoint_list = 2);
    let (p, _) = s.run_until(2000, |p| !p.inside_fly_zone);
    assert!(
        (p.latitude_deg - 48.285).abs() < 0.0001,
        "{}",
        p.latitude_deg
    );
    assert_eq!(p.in_no_fly_zone, 0);
    s.run_until(2000, |p| p.route_complete);
    assert!(!s.log.last().unwrap().inside_fly_zone);
    assert_eq!(s.g.zone_warnings, 2);
}

/// The zones are the geofence's: a fly-zone across the antimeridian whose northern edge,
/// 72 km along 71° N, is a geodesic bowing about 280 m north of the parallel, and a circle
/// whose geodesic radius reaches across the antimeridian. Containment in degrees got every
/// one of these points wrong.
#[test]
fn zones_are_geodesic_and_cross_the_antimeridian() {
    let mut a = AreaListPayload::EMPTY;
    a.generation = 1;
    a.fly_zone.area_id = 1;
    a.fly_zone.vertex_count = 4;
    let corners = [(70.9, 179.0), (70.9, -179.0), (71.0, -179.0), (71.0, 179.0)];
    for (v, p) in a.fly_zone.vertices.iter_mut().zip(corners) {
        *v = gp(p);
    }
    a.no_fly_circle_count = 1;
    a.no_fly_circles[0] = CircleArea {
        area_id: 2,
        centre: gp((70.95, 179.99)),
        border: gp((70.95, -179.99)),
        ..CircleArea::EMPTY
    };
    let status = |at: Point<f64>| {
        let mut g = Guidance::new(config_at((at.y(), at.x())));
        g.set_area_list(&a);
        let p = g.step(Instant::ZERO);
        (p.inside_fly_zone, p.in_no_fly_zone)
    };

    // The northern edge's midpoint, on the antimeridian, well north of 71°.
    let (east, west) = (pt((71.0, -179.0)), pt((71.0, 179.0)));
    let mid = destination(east, bearing_deg(east, west), distance_m(east, west) / 2.0);
    assert!((mid.x().abs() - 180.0).abs() < 1e-6, "{mid:?}");
    assert!(mid.y() - 71.0 > 0.0024, "{mid:?}");
    assert_eq!(status(destination(mid, 180.0, 20.0)), (true, 0));
    assert_eq!(status(destination(mid, 0.0, 20.0)), (false, 0));

    // The circle: its centre west of the antimeridian, points due east across it.
    let centre = pt((70.95, 179.99));
    let radius = distance_m(centre, pt((70.95, -179.99)));
    let inside = destination(centre, 90.0, radius - 5.0);
    assert!(inside.x() < -179.99, "{inside:?}");
    assert_eq!(status(inside), (true, 2));
    assert_eq!(status(destination(centre, 90.0, radius + 5.0)), (true, 0));
}
