//! Tests of the mission map.

use super::local_frame::Coord;
use super::*;
use crate::mission_file::MissionFile;
use crate::mission_file::tests::{MISSION_1, MISSION_2, validated};
use missionlink_ground::safety_gateway::{AircraftProfile, Environment};
use missionlink_protocol::geofence::earth;
use missionlink_protocol::geofence::path::ArcLeg;

fn example_markers() -> Vec<Marker> {
    vec![
        Marker {
            code: "LEG_IN_NFZ".into(),
            label: "leg 1-2 <cuts> NFZ 3 by 12.5 m".into(),
            position: Some((48.278, 11.658)),
        },
        Marker {
            code: "NFZ_CENTRE".into(),
            label: "area 2".into(),
            position: Some((48.268, 11.675)),
        },
        Marker {
            code: "ENERGY".into(),
            label: "needs 1.9 kWh of 1.6 kWh usable with 20 % reserve".into(),
            position: None,
        },
    ]
}

/// Every number in the document is finite, and the tags balance.
fn assert_well_formed(svg: &str) {
    assert!(svg.starts_with("<svg "), "{svg}");
    assert!(svg.trim_end().ends_with("</svg>"));
    for bad in ["NaN", "inf"] {
        assert!(!svg.contains(bad), "{bad} in {svg}");
    }
    for tag in ["g", "text", "svg", "clipPath", "title"] {
        let open =
            svg.matches(&format!("<{tag} ")).count() + svg.matches(&format!("<{tag}>")).count();
        let close = svg.matches(&format!("</{tag}>")).count();
        assert_eq!(open, close, "<{tag}> opened {open}, closed {close}");
    }
    // Every attribute value is closed: quotes come in pairs on each line.
    for line in svg.lines() {
        assert_eq!(line.matches('"').count() % 2, 0, "{line}");
    }
}

#[test]
fn mission_2_draws_every_element() {
    let plan = validated(MISSION_2);
    let svg = render(
        &plan,
        None,
        &[],
        "Demo mission 2",
        &SafetyGateway::default(),
    );
    assert_well_formed(&svg);
    assert_eq!(
        svg.matches(r#"<circle class="waypoint""#).count(),
        plan.mission.waypoints.len()
    );
    for n in 1..=3 {
        assert!(svg.contains(&format!(r#"data-waypoint="{n}""#)));
        assert!(svg.contains(&format!(">{n}</text>")), "waypoint number {n}");
    }
    for label in ["fly-zone 1", "NFZ 2", "NFZ 3"] {
        assert!(svg.contains(label), "{label}");
    }
    // The TF leg CCP-W1 and the RF arc W1-ROLE2 (a sampled path), clockwise.
    assert!(svg.contains(r#"class="leg tf" data-leg="1-2""#));
    assert!(svg.contains(r#"class="leg rf" data-leg="2-3" data-turn="clockwise" d="M "#));
    assert_eq!(svg.matches(r#"class="rf-centre""#).count(), 1);
    assert_eq!(svg.matches(r#"class="arrow""#).count(), 2 + 1); // two legs + legend
    assert!(svg.contains("take-off, 30 m AGL"));
    assert!(svg.contains("MEDEVAC-2"));
    assert!(svg.contains("3 waypoints"));
    assert!(svg.contains("3 areas (1 fly-zone, 2 no-fly-zones)"));
    // Circle NFZ and its grown outline; polygon NFZ, its grown outline, fly-zone and its
    // shrunk outline.
    assert_eq!(
        svg.matches(r#"<polygon class="area" data-shape="circle""#)
            .count(),
        2
    );
    assert_eq!(
        svg.matches(r#"<polygon class="area" data-shape="polygon""#)
            .count(),
        4
    );
    assert!(svg.contains("scale-bar") && svg.contains("north-arrow"));
    assert!(!svg.contains("Violations"));
}

#[test]
fn mission_1_draws_its_single_waypoint() {
    let plan = validated(MISSION_1);
    let svg = render(
        &plan,
        None,
        &[],
        "Demo mission 1",
        &SafetyGateway::default(),
    );
    assert_well_formed(&svg);
    assert_eq!(svg.matches(r#"<circle class="waypoint""#).count(), 1);
    assert!(svg.contains(">1</text>"));
    assert!(svg.contains("fly-zone 1"));
    assert!(svg.contains("MEDEVAC-1"));
    assert!(svg.contains("1 waypoint ·"));
    assert!(svg.contains("take-off, 30 m AGL"));
    assert!(!svg.contains("class=\"leg "));
    // From its take-off position (TROL) the way to CCP is drawn, as the gateway checks it.
    let trol = MissionFile::parse(MISSION_1).unwrap().to_plan().unwrap();
    let svg = render(
        &plan,
        trol.take_off_position,
        &[],
        "Demo mission 1",
        &SafetyGateway::default(),
    );
    assert_well_formed(&svg);
    assert_eq!(svg.matches(r#"class="leg tf" data-leg="0-1""#).count(), 1);
}

#[test]
fn markers_are_drawn_and_listed() {
    let plan = validated(MISSION_2);
    let svg = render(
        &plan,
        None,
        &example_markers(),
        "Mission 2 <& markers>",
        &SafetyGateway::default(),
    );
    assert_well_formed(&svg);
    assert!(svg.contains("Mission 2 &lt;&amp; markers&gt;"));
    // Two on the map, all three in the box.
    assert_eq!(svg.matches(r#"<circle class="marker""#).count(), 2);
    assert!(svg.contains("Violations (3)"));
    for code in ["LEG_IN_NFZ", "NFZ_CENTRE", "ENERGY"] {
        assert!(svg.matches(code).count() >= 1, "{code}");
    }
    assert_eq!(svg.matches(">LEG_IN_NFZ</text>").count(), 2); // map and box
    assert!(svg.contains("&lt;cuts&gt;"));
    assert!(svg.contains("(no position)"));
}

#[test]
fn rf_arc_turns_the_right_way_and_ends_at_the_waypoints() {
    let (centre, w1, role2) = (
        Site::new(48.27455, 11.66991),
        Site::new(48.278, 11.658),
        Site::new(48.28, 11.68),
    );
    let arc = |direction| {
        drawn_sites(Path::Arc(ArcLeg {
            from: w1,
            to: role2,
            centre,
            direction,
        }))
    };
    let cw = arc(TurnDirection::Clockwise);
    let close = |a: &Site, b: &Site| a.inverse(b).0 < 1e-6;
    assert!(close(&cw[0], &w1) && close(cw.last().unwrap(), &role2));
    // Clockwise from W1 (north-west of the centre) to ROLE2 (north-east): over the top, at
    // the geodesic radius all along.
    let r = centre.inverse(&w1).0;
    let top = cw.iter().map(|s| s.lat).fold(f64::MIN, f64::max);
    let north = centre.direct(0.0, r);
    // (1e-5° of latitude is 1.1 m; the radius goes from W1's distance to ROLE2's.)
    assert!((top - north.lat).abs() < 1e-5, "{top} vs {}", north.lat);
    for s in &cw {
        assert!((centre.inverse(s).0 - r).abs() < 1.0);
    }
    // Counter-clockwise: the long way round, under the centre.
    let ccw = arc(TurnDirection::CounterClockwise);
    let low = ccw.iter().map(|s| s.lat).fold(f64::MAX, f64::min);
    assert!((low - centre.direct(180.0, r).lat).abs() < 1e-5);
    assert!(ccw.len() > cw.len());
}

/// A 35 km track-to-fix leg along 71° N is drawn as the geodesic the gateway checks: its
/// middle about 70 m north of the parallel (and of the straight line between its ends in
/// the drawing projection), where the geodesic's midpoint is, within a metre.
#[test]
fn a_long_east_west_leg_at_71_north_bows_north() {
    let (from, to) = (Site::new(71.0, 25.0), Site::new(71.0, 25.0 + 0.97));
    let (length, azimuth) = from.inverse(&to);
    assert!((length - 35_000.0).abs() < 300.0, "{length}");
    let sites = drawn_sites(Path::Geodesic { from, to });
    assert!(sites.len() >= 71, "{}", sites.len());
    for w in sites.windows(2) {
        assert!(w[0].inverse(&w[1]).0 <= DRAW_STEP_M + 1e-6);
    }
    let mid = earth::destination(from, azimuth, length / 2.0);
    let bow = earth::distance_m(mid, Site::new(71.0, mid.x()));
    assert!((60.0..80.0).contains(&bow), "{bow} m");

    // The drawn line halfway along is the geodesic's midpoint, latitude within a metre
    // (1e-5° is 1.1 m), and lies that far above the chord between the ends on the screen.
    let proj = Projection::new(71.0, 25.5);
    let points = drawn(Path::Geodesic { from, to }, &proj);
    let (m, _) = midway(&points).unwrap();
    let (lat, lon) = proj.0.deg(Coord { x: m.0, y: m.1 });
    assert!((lat - mid.y()).abs() < 0.9e-5, "{lat} vs {}", mid.y());
    assert!((lon - mid.x()).abs() < 1e-4, "{lon} vs {}", mid.x());
    let (a, b) = (points[0], *points.last().unwrap());
    let chord_y = a.1 + (b.1 - a.1) * (m.0 - a.0) / (b.0 - a.0);
    assert!(
        (m.1 - chord_y - bow).abs() < 1.0,
        "{} vs {bow}",
        m.1 - chord_y
    );
}

#[test]
fn polygon_offsets_move_every_edge_by_the_offset() {
    let ccw = vec![(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)];
    let cw: Vec<P> = ccw.iter().rev().copied().collect();
    for square in [&ccw, &cw] {
        let grown = offset_polygon(square, 10.0);
        let (lo, hi) = bounds(grown).unwrap();
        assert!((lo.0 + 10.0).abs() < 1e-9 && (hi.1 - 110.0).abs() < 1e-9);
        let shrunk = offset_polygon(square, -10.0);
        let (lo, hi) = bounds(shrunk).unwrap();
        assert!((lo.0 - 10.0).abs() < 1e-9 && (hi.1 - 90.0).abs() < 1e-9);
    }
    // A circle shrunk past its centre is the centre.
    let proj = Projection::new(48.0, 11.0);
    let centre = Site::new(48.0, 11.0);
    let circle = Shape::Circle {
        centre,
        radius: 5.0,
        outline: ring(&proj, &centre, 5.0),
    };
    assert!(
        circle
            .offset(-10.0, &proj)
            .outline()
            .iter()
            .all(|p| len(*p) < 1e-6)
    );
}

#[test]
fn scale_bar_lengths_are_round() {
    assert_eq!(nice_length(1234.0), 1000.0);
    assert_eq!(nice_length(2600.0), 2000.0);
    assert_eq!(nice_length(730.0), 500.0);
    assert_eq!(metres_text(1000.0), "1 km");
    assert_eq!(metres_text(500.0), "500 m");
}

const DOCS_MAP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/mission-2.svg");

fn docs_map() -> String {
    let file = MissionFile::parse(MISSION_2).unwrap();
    render(
        &validated(MISSION_2),
        file.to_plan().unwrap().take_off_position,
        &[],
        "missionlink demo mission 2: CCP to ROLE2",
        &SafetyGateway::default(),
    )
}

/// Writes docs/mission-2.svg, and an example with markers to the temporary directory:
/// `cargo test -p missionlink-gcs map::tests::write_maps -- --ignored`.
#[test]
#[ignore = "generator: writes docs/mission-2.svg"]
fn write_maps() {
    std::fs::write(DOCS_MAP, docs_map()).unwrap();
    let markers = render(
        &validated(MISSION_2),
        None,
        &example_markers(),
        "missionlink demo mission 2 with example markers",
        &SafetyGateway::default(),
    );
    std::fs::write(std::env::temp_dir().join("mission-2-markers.svg"), markers).unwrap();
}

/// The committed map is what the renderer draws today.
#[test]
fn docs_map_is_current() {
    let committed = std::fs::read_to_string(DOCS_MAP).unwrap();
    assert!(
        committed == docs_map(),
        "docs/mission-2.svg is stale: cargo test -p missionlink-gcs map::tests::write_maps -- --ignored"
    );
}

/// In wind the map draws each turn as checked in that wind, the same turn in calm air dashed,
/// and the band between them (ICD §7 "Turns in wind"); in calm air none of the two.
#[test]
fn in_wind_the_band_of_every_turn_is_drawn() {
    let plan = validated(MISSION_2);
    let take_off = MissionFile::parse(MISSION_2)
        .unwrap()
        .to_plan()
        .unwrap()
        .take_off_position;
    let windy = SafetyGateway::new(
        AircraftProfile::default(),
        Environment {
            wind_speed_mps: 12.0,
            ..Environment::default()
        },
    );
    let svg = render(&plan, take_off, &[], "in wind", &windy);
    assert_well_formed(&svg);
    let turns = svg.matches(r#"<path class="turn fly-by""#).count();
    assert!(turns >= 1, "{svg}");
    assert_eq!(svg.matches(r#"class="turn-band""#).count(), turns);
    assert_eq!(svg.matches(r#"class="turn calm""#).count(), turns);
    let calm = render(&plan, take_off, &[], "calm", &SafetyGateway::default());
    assert!(!calm.contains("turn-band") && !calm.contains("turn calm"));
    // The turn in wind is the wider one: its band is drawn where the calm arc is not.
    assert_ne!(
        svg.matches(r#"d="M"#).count(),
        calm.matches(r#"d="M"#).count()
    );
}
