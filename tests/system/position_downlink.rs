//! The position downlink end to end (ICD §5.8): the real FCC (launcher, partitions, guidance
//! stub) sends #101 from guidance's progress, through voting-monitoring's UDP links and the
//! seccomp filter of mission data handling, and the real GCS link receives it while demo mission
//! 1 (TROL to CCP) flies. The rate itself is tested in simulated time
//! (`missionlink_flight::position`, `services/ground/tests/sans_io/mission_pair.rs`); here what the GCS sees:
//! the aircraft on the ground at TROL, then positions on the way to CCP with the course towards
//! it, FROM-TO-NEXT among them, and the aircraft at CCP at the end; with each position what
//! guidance knows of its vertical speed and attitude (ICD §4 #101): nothing of the heading
//! before it moved, level on the ground, on the way the nose towards CCP (no wind), wings level
//! on the straight leg, climbing from the take-off height to CCP's altitude.

use std::time::{Duration, Instant};

use missionlink::harness::*;
use missionlink_ground::ground_station::{GcsError, GcsEvent};
use missionlink_interfaces::wire::{self, GeoPoint, InertialStates};
use missionlink_protocol::geofence::earth::{bearing_deg, distance_m};

const LIMIT: Duration = Duration::from_secs(60);

/// TROL, the start position (missions/mission-1.toml).
fn trol() -> GeoPoint {
    GeoPoint::from_degrees(48.26, 11.66).unwrap()
}

/// CCP, waypoint 1 of mission 1, where it lands.
fn ccp() -> GeoPoint {
    GeoPoint::from_degrees(48.275, 11.645).unwrap()
}

/// Execute, asked again (bounded) while refused with `WrongState`: guidance may not have been
/// heard yet (docs/design.md "Health").
fn execute(link: &mut Link) {
    let start = Instant::now();
    loop {
        let now = link.now();
        link.station()
            .execute(now, wire::ExecuteCommand::Execute)
            .unwrap();
        match finish(link) {
            Ok(_) => return,
            Err(GcsError::Transfer { error, .. })
                if error.reason() == Some(wire::Reason::WrongState) && start.elapsed() < LIMIT =>
            {
                std::thread::sleep(Duration::from_millis(100));
            }
            Err(other) => panic!("execute: {other}"),
        }
    }
}

/// What the GCS heard, in order.
#[derive(Debug)]
enum Heard {
    Position(InertialStates),
    /// The TO waypoint of a #4001.
    FromToNext(u16),
}

#[test]
fn the_gcs_sees_the_aircraft_fly_demo_mission_1() {
    let mut rig = Rig::new("position-downlink");
    // Slow enough that the flight lasts several seconds of the 2 Hz downlink.
    rig.config.guidance.time_scale = 10.0;
    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    let mut link = rig.gcs(&mut fcc);

    // On the ground, before any mission: the aircraft at TROL, standing.
    let mut on_ground = None;
    link.run_until(LIMIT, |event| {
        if let GcsEvent::Position(p) = event {
            on_ground = Some(*p);
            true
        } else {
            false
        }
    });
    let p = on_ground.expect("no #101 within the limit");
    let at = p.position().unwrap();
    assert!(distance_m(at, trol()) < 1.0, "{p}");
    assert_eq!(p.ground_speed_mps(), Some(0.0), "{p}");
    // Standing, level; where the nose points is not known before the first movement.
    assert_eq!(p.climb_rate_mps(), Some(0.0), "{p}");
    assert_eq!((p.roll_rad(), p.pitch_rad()), (Some(0.0), Some(0.0)), "{p}");
    assert_eq!(p.heading_rad(), None, "{p}");

    upload(&mut link, &plan("mission-1.toml")).unwrap();
    execute(&mut link);
    let mut heard = Vec::new();
    let arrived = link.run_until(LIMIT, |event| {
        match event {
            GcsEvent::Position(p) => heard.push(Heard::Position(*p)),
            GcsEvent::FromToNext(f) => {
                heard.push(Heard::FromToNext(f.to.waypoint_number.unwrap_or(0)));
            }
            _ => {}
        }
        // Arrived at CCP: no longer moving over the ground there (it descends to land).
        matches!(heard.last(), Some(Heard::Position(p))
            if p.ground_speed_mps() == Some(0.0)
                && p.position().is_some_and(|at| distance_m(at, ccp()) < 5.0))
    });
    assert!(
        arrived,
        "the GCS did not see the aircraft arrive at CCP: {heard:#?}"
    );

    // On the way: positions between TROL and CCP, coming closer, the course towards CCP.
    let positions: Vec<&InertialStates> = heard
        .iter()
        .filter_map(|h| match h {
            Heard::Position(p) => Some(p),
            Heard::FromToNext(_) => None,
        })
        .collect();
    let cruising: Vec<&&InertialStates> = positions
        .iter()
        .filter(|p| {
            let at = p.position().unwrap();
            p.ground_speed_mps().is_some_and(|v| v > 1.0)
                && distance_m(at, trol()) > 50.0
                && distance_m(at, ccp()) > 50.0
        })
        .collect();
    assert!(
        cruising.len() >= 3,
        "{} positions on the way: {positions:#?}",
        cruising.len()
    );
    let towards_ccp = bearing_deg(trol(), ccp());
    let mut closer = f64::INFINITY;
    for p in &cruising {
        let at = p.position().unwrap();
        let left = distance_m(at, ccp());
        assert!(left <= closer + 1.0, "moving away from CCP: {p}");
        closer = left;
        let off = (p.course_deg().unwrap() - towards_ccp + 540.0).rem_euclid(360.0) - 180.0;
        assert!(off.abs() < 5.0, "course {p} vs {towards_ccp:.1} deg");
        assert_eq!(p.altitude_type, Some(wire::AltitudeType::Wgs84));
        // In calm air the nose points along the course; the leg is straight; it climbs from
        // the take-off height (30 m) to CCP's altitude on the way.
        let off = (p.heading_deg().unwrap() - towards_ccp + 540.0).rem_euclid(360.0) - 180.0;
        assert!(off.abs() < 5.0, "heading {p} vs {towards_ccp:.1} deg");
        assert_eq!(p.roll_rad(), Some(0.0), "{p}");
        assert!(p.climb_rate_mps().is_some_and(|c| c > 0.0), "{p}");
        assert!(p.pitch_rad().is_some_and(|t| t > 0.0), "{p}");
    }
    // FROM-TO-NEXT among the positions: towards CCP (TO 1), shown with them by `gcs monitor`.
    assert!(
        heard.iter().any(|h| matches!(h, Heard::FromToNext(1))),
        "{heard:#?}"
    );
    println!(
        "the GCS heard {} positions ({} on the way) and {} FROM-TO-NEXT reports during the flight",
        positions.len(),
        cruising.len(),
        heard.len() - positions.len()
    );
}
