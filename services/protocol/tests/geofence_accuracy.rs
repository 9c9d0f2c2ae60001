//! The geofence's margins against an independent reference: every row of
//! `tests/data/geofence_accuracy.csv`, computed with GeographicLib by
//! `tests/data/geofence_reference.py` (how, in `tests/data/README.md`), must agree within
//! [`TOLERANCE_M`]. The fly-by rows check the turn construction too: the reference finds the
//! arc tangent to both legs on the ellipsoid by itself, the geofence takes the arc of
//! `geofence::turn`; the fly-by rows in wind check its radius in wind too (ICD §7 "Turns in
//! wind"). Run with `--nocapture` to see the table.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink_interfaces::wire::{Angle, GeoPoint, TurnDirection};
use missionlink_protocol::geofence::clearance::{Clearance, clearance};
use missionlink_protocol::geofence::earth::{self, Site};
use missionlink_protocol::geofence::flown_route::FlyBy;
use missionlink_protocol::geofence::path::{ArcLeg, Path, Track};
use missionlink_protocol::geofence::turn::{TurnKind, turn};
use missionlink_protocol::geofence::zone::{Zone, ZoneKind};

/// The largest difference allowed between the geofence's margin and the reference's.
const TOLERANCE_M: f64 = 0.5;

const TABLE: &str = include_str!("data/geofence_accuracy.csv");

fn numbers(text: &str) -> Vec<(f64, f64)> {
    text.split(';')
        .map(|p| {
            let mut it = p.split_whitespace().map(|x| x.parse::<f64>().unwrap());
            (it.next().unwrap(), it.next().unwrap())
        })
        .collect()
}

fn wire((lat, lon): (f64, f64)) -> GeoPoint {
    GeoPoint {
        latitude: Angle::from_degrees(lat).unwrap(),
        longitude: Angle::from_degrees(lon).unwrap(),
    }
}

fn site((lat, lon): (f64, f64)) -> Site {
    Site::new(lat, lon)
}

fn path(text: &str) -> Path {
    let (kind, rest) = text.split_once(':').unwrap();
    match kind {
        "point" => Path::Point(site(numbers(rest)[0])),
        "leg" => {
            let p = numbers(rest);
            Path::Geodesic {
                from: site(p[0]),
                to: site(p[1]),
            }
        }
        "arc" => {
            let (points, direction) = rest.rsplit_once(';').unwrap();
            let p = numbers(points);
            Path::Arc(ArcLeg {
                centre: site(p[0]),
                from: site(p[1]),
                to: site(p[2]),
                direction: match direction {
                    "cw" => TurnDirection::Clockwise,
                    "ccw" => TurnDirection::CounterClockwise,
                    other => panic!("turn direction {other}"),
                },
            })
        }
        // A fly-by turn: the arc the geofence's turn construction gives (what guidance flies
        // and the checks check) at the waypoint between the two legs, at the radius given.
        "flyby" => {
            let (points, radius) = rest.rsplit_once(';').unwrap();
            let p = numbers(points);
            let (a, w, b) = (site(p[0]), site(p[1]), site(p[2]));
            let t = turn(
                &Path::Geodesic { from: a, to: w },
                &Path::Geodesic { from: w, to: b },
                false,
                radius.parse().unwrap(),
            );
            assert_eq!(t.kind, TurnKind::FlyBy, "{text}");
            t.paths[0]
        }
        // A fly-by turn in wind: the radius is the geofence's (`FlyBy::radius_in_wind_m`), the
        // reference computes `(v + W)²/(g·tan(bank))` itself.
        "flyby-wind" => {
            let (points, bank) = rest.rsplit_once(';').unwrap();
            let p = numbers(points);
            let (a, w, b, (v, wind)) = (site(p[0]), site(p[1]), site(p[2]), p[3]);
            let fly_by = FlyBy {
                bank_deg: bank.parse().unwrap(),
            };
            let t = turn(
                &Path::Geodesic { from: a, to: w },
                &Path::Geodesic { from: w, to: b },
                false,
                fly_by.radius_in_wind_m(v, wind),
            );
            assert_eq!(t.kind, TurnKind::FlyBy, "{text}");
            t.paths[0]
        }
        other => panic!("path kind {other}"),
    }
}

/// The zone as the FCC would hold it: its vertices on the wire's grid (BAM4, about 9 mm), a
/// circle's border point due north of its centre at the radius.
fn zone(text: &str) -> Zone {
    let (kind, rest) = text.split_once(':').unwrap();
    match kind {
        "nfz-polygon" | "fz-polygon" => {
            let kind = if kind == "fz-polygon" {
                ZoneKind::FlyZone
            } else {
                ZoneKind::NoFlyZone
            };
            let vertices: Vec<GeoPoint> = numbers(rest).into_iter().map(wire).collect();
            Zone::polygon(1, kind, &vertices)
        }
        "nfz-circle" => {
            let (centre, radius) = rest.split_once(';').unwrap();
            let centre = wire(numbers(centre)[0]);
            let border = earth::due_north(centre, radius.trim().parse().unwrap()).unwrap();
            Zone::circle(1, ZoneKind::NoFlyZone, centre, border)
        }
        other => panic!("zone kind {other}"),
    }
}

#[test]
fn margins_agree_with_geographiclib_within_half_a_metre() {
    let mut rows = 0;
    let mut worst: (f64, String) = (0.0, String::new());
    let mut failures = Vec::new();
    println!(
        "{:<44} {:>11} {:>11} {:>8} {:>9}",
        "row", "reference", "geofence", "diff", "at (m)"
    );
    for line in TABLE.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let [name, path_text, zone_text, margin, at_lat, at_lon] = f[..] else {
            panic!("a row of 6 fields: {line}");
        };
        let reference: f64 = margin.parse().unwrap();
        let track = Track::new(path(path_text));
        let found = clearance(&track, &zone(zone_text), f64::INFINITY, true);
        let Clearance::Margin { metres, at } = found else {
            panic!("{name}: {found:?}");
        };
        let diff = metres - reference;
        let at_diff = earth::distance_m(
            at,
            Site::new(at_lat.parse().unwrap(), at_lon.parse().unwrap()),
        );
        println!("{name:<44} {reference:>11.3} {metres:>11.3} {diff:>8.3} {at_diff:>9.1}");
        if diff.abs() > worst.0 {
            worst = (diff.abs(), name.to_owned());
        }
        if diff.abs() > TOLERANCE_M {
            failures.push(format!("{name}: reference {reference}, geofence {metres}"));
        }
        rows += 1;
    }
    println!(
        "{rows} rows; largest difference {:.3} m ({})",
        worst.0, worst.1
    );
    assert!(rows >= 20, "the table has {rows} rows");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
