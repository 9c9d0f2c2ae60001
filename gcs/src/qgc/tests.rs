//! Tests of the `.plan` import and export, on real QGroundControl files and the demo missions.

use super::*;
use missionlink_protocol::geofence::earth;
use missionlink_protocol::transfer::mission::Mission;

use crate::mission_file::tests::{MISSION_2, validated};

/// A real file saved by QGroundControl, kept in the repository (`missions/qgc/`, copied
/// from the shared mission documents).
fn real(name: &str) -> String {
    let path = format!("{}/../missions/qgc/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn assembled(plan: &MissionPlan) -> Mission {
    plan.mission
        .assemble(Some(plan.mission.len() as u16), None)
        .unwrap()
}

fn lines(dropped: &[Dropped]) -> Vec<String> {
    dropped.iter().map(ToString::to_string).collect()
}

/// The options that drop what the ICD cannot carry.
fn dropping() -> ImportOptions {
    ImportOptions {
        unsupported: Unsupported::Drop,
        ..ImportOptions::default()
    }
}

/// The elements a refused import names.
fn refused(result: Result<QgcImport, MissionFileError>) -> Vec<String> {
    match result {
        Err(MissionFileError::Unsupported { elements }) => lines(&elements),
        Err(other) => panic!("refused for another reason: {other}"),
        Ok(i) => panic!("imported, dropping {:?}", i.dropped),
    }
}

fn pos(lat: f64, lon: f64) -> GeoPoint {
    GeoPoint::from_degrees(lat, lon).unwrap()
}

/// (latitude, longitude, altitude, altitude type, speed, speed type, turn type) of each
/// waypoint in flight order.
type Row = (
    GeoPoint,
    f64,
    AltitudeType,
    f64,
    Option<SpeedType>,
    TurnType,
);

fn rows(m: &Mission) -> Vec<Row> {
    m.waypoints
        .iter()
        .map(|r| {
            let w = r.waypoint;
            (
                GeoPoint {
                    latitude: w.latitude,
                    longitude: w.longitude,
                },
                w.altitude.metres(),
                w.altitude_type.unwrap(),
                w.speed.mps(),
                w.speed_type,
                w.turn_type,
            )
        })
        .collect()
}

/// `m`'s waypoints are `expected`, altitudes within [`close`].
fn assert_rows(m: &Mission, expected: &[Row]) {
    let got = rows(m);
    assert_eq!(got.len(), expected.len());
    for (g, e) in got.iter().zip(expected) {
        assert!(close(g.1, e.1), "{g:?} {e:?}");
        assert_eq!((g.0, g.2, g.3, g.4, g.5), (e.0, e.2, e.3, e.4, e.5));
    }
}

/// The WGS-84 height of an altitude above mean sea level (the geoid is 47.16 m above the
/// ellipsoid at QGC's default home in Zurich).
fn amsl(metres: f64, lat: f64, lon: f64) -> f64 {
    crate::geoid::wgs84_from_amsl(metres, lat, lon)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.011
}

#[test]
fn ardu_plane_is_refused_for_its_loiters_or_imported_without_them() {
    let text = real("PX4SITL-ArduPlane.plan");
    let expected = [
        "mission.items[3]: command 18 (NAV_LOITER_TURNS) is not supported",
        "mission.items[5]: command 31 (NAV_LOITER_TO_ALT) is not supported",
    ];
    assert_eq!(
        refused(import_plan(&text, &ImportOptions::default())),
        expected
    );
    let import = import_plan(&text, &dropping()).unwrap();
    assert_eq!(lines(&import.dropped), expected);
    assert_eq!(
        import.home,
        Some(Home {
            latitude_deg: 47.397,
            longitude_deg: 8.5455,
            altitude_m: 488.056
        })
    );
    // The take-off item's own position (300 m south of the planned home) is the take-off
    // position: it is carried, not dropped.
    assert_eq!(import.plan.take_off_position, Some(pos(47.3996949, 8.5455)));
    assert!(import.plan.areas.is_empty());
    assert_eq!(import.plan.safety_offset, SafetyOffset::default());

    let m = assembled(&import.plan);
    assert_eq!(m.take_off_height().metres(), 50.0);
    assert!(!m.route.bidirectional);
    assert_eq!(m.route.initial_waypoint, 1);
    let numbers: Vec<(u16, u16)> = m
        .waypoints
        .iter()
        .map(|r| (r.waypoint.waypoint_number, r.waypoint.next_waypoint))
        .collect();
    assert_eq!(numbers, [(1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 0)]);
    use AltitudeType::{Agl, Wgs84};
    use TurnType::{FlyBy, FlyOver};
    let ground = Some(SpeedType::GroundSpeed);
    let expected: Vec<Row> = vec![
        (pos(47.4104747, 8.565406), 120.0, Agl, 15.0, None, FlyBy),
        // Frame 0, 688.06 m above mean sea level: its WGS-84 height there.
        (
            pos(47.397, 8.585312),
            amsl(688.06, 47.397, 8.585312),
            Wgs84,
            15.0,
            None,
            FlyBy,
        ),
        // Frame 10, above terrain.
        (pos(47.3700507, 8.5455), 100.0, Agl, 15.0, None, FlyBy),
        // After DO_CHANGE_SPEED (items[6]): 18 m/s ground speed.
        (pos(47.397, 8.505688), 60.0, Agl, 18.0, ground, FlyBy),
        (pos(47.4194578, 8.5189587), 40.0, Agl, 18.0, ground, FlyBy),
        // The land (items[9]) at the altitude of the waypoint before.
        (pos(47.3943051, 8.5455), 40.0, Agl, 18.0, ground, FlyOver),
    ];
    assert_rows(&m, &expected);
    assert!(
        m.waypoints
            .iter()
            .all(|r| r.waypoint.leg_type == LegType::TrackToFix)
    );
}

#[test]
fn multi_rotor_imports_with_hover_speed_and_terrain_altitudes() {
    let import = import_plan(
        &real("PX4SITL-PX4-MultiRotor.plan"),
        &ImportOptions {
            safety_offset_m: 20.0,
            bidirectional: true,
            unsupported: Unsupported::Drop,
        },
    )
    .unwrap();
    assert_eq!(
        lines(&import.dropped),
        [
            "mission.items[4]: command 195 (DO_SET_ROI_LOCATION) is not supported",
            "mission.items[6]: command 19 (NAV_LOITER_TIME) is not supported",
        ]
    );
    assert_eq!(import.plan.take_off_position, Some(pos(47.3996949, 8.5455)));
    assert_eq!(import.plan.safety_offset.metres(), 20.0);
    let m = assembled(&import.plan);
    assert!(m.route.bidirectional);
    assert_eq!(m.take_off_height().metres(), 30.0);
    use AltitudeType::{Agl, Wgs84};
    use TurnType::{FlyBy, FlyOver};
    let ground = Some(SpeedType::GroundSpeed);
    let expected: Vec<Row> = vec![
        // Multi-rotor (vehicleType 2): hoverSpeed 5 m/s until the speed change.
        (pos(47.4104747, 8.565406), 60.0, Agl, 5.0, None, FlyBy),
        (
            pos(47.397, 8.585312),
            amsl(638.06, 47.397, 8.585312),
            Wgs84,
            10.0,
            ground,
            FlyBy,
        ),
        // AltitudeMode 3 without terrain data: Altitude above terrain.
        (pos(47.3700507, 8.585312), 80.0, Agl, 10.0, ground, FlyBy),
        (pos(47.3700507, 8.505688), 40.0, Agl, 10.0, ground, FlyBy),
        (pos(47.397, 8.505688), 70.0, Agl, 10.0, ground, FlyBy),
        (pos(47.4194578, 8.5189587), 15.0, Agl, 10.0, ground, FlyBy),
        (pos(47.3996949, 8.5455), 15.0, Agl, 10.0, ground, FlyOver),
    ];
    assert_rows(&m, &expected);
}

#[test]
fn a_geofence_file_imports_as_areas_but_is_no_mission() {
    let text = real("ce_geofence_home_base.plan");
    let err = import_plan(&text, &ImportOptions::default()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "mission.items: no waypoints: none of the 0 mission items is a waypoint (command 16) \
         or a land (21); a file that holds only a geofence imports as areas"
    );
    let (areas, dropped) = import_areas(&text, Unsupported::Refuse).unwrap();
    assert!(dropped.is_empty(), "{dropped:?}");
    let list = areas.assemble(2, SafetyOffset::default()).unwrap();
    let [fly, no_fly] = list.areas.as_slice() else {
        panic!("{list:?}")
    };
    assert_eq!((fly.area_id, fly.area_type), (1, AreaType::FlyZone));
    assert_eq!((no_fly.area_id, no_fly.area_type), (2, AreaType::NoFlyZone));
    let (AreaShape::Polygon(f), AreaShape::Polygon(n)) = (&fly.shape, &no_fly.shape) else {
        panic!("{list:?}")
    };
    assert_eq!((f.len(), n.len()), (4, 4));
    assert_eq!(f[0], pos(38.7507608625056, -77.49735908548331));
    assert_eq!(f[3], pos(38.750551952470936, -77.49713235890398));
    assert_eq!(n[2], pos(38.7508358, -77.496979));
}

#[test]
fn export_then_import_gives_back_waypoints_and_areas() {
    let original = validated(MISSION_2);
    let home = Home {
        latitude_deg: 48.2748,
        longitude_deg: 11.6449,
        altitude_m: 510.5,
    };
    let take_off = pos(48.275, 11.645);
    let options = ExportOptions {
        take_off_position: Some(take_off),
        home: Some(home),
        ..ExportOptions::default()
    };
    let (text, notes) = export_plan(&original, &options);
    assert!(
        text.starts_with("{\n    \"fileType\": \"Plan\",\n"),
        "{text}"
    );
    assert!(text.contains("\"groundStation\": \"missionlink\""));
    let lost: Vec<String> = notes.iter().map(ToString::to_string).collect();
    assert_eq!(
        lost,
        [
            "route.bidirectional: QGC has no bidirectional route (return-to-home flying it \
             backwards): not written",
            "mission_id: \"MEDEVAC-2\": QGC has no mission ID: not written",
            "route.route_type: QGC has no route type: not written",
            "waypoints[2] (number 3): radius-to-fix leg: QGC has none, written as a \
             track-to-fix waypoint (the RF centre is not written)",
            "safety_offset_m: 25 m: QGC has no safety offset: not written",
        ]
    );

    let import = import_plan(
        &text,
        &ImportOptions {
            safety_offset_m: 25.0,
            bidirectional: true,
            unsupported: Unsupported::Refuse,
        },
    )
    .unwrap();
    assert!(import.dropped.is_empty(), "{:#?}", import.dropped);
    assert_eq!(import.home, Some(home));
    // The take-off item is at the take-off position, the planned home apart from it.
    assert_eq!(import.plan.take_off_position, Some(take_off));
    let m = assembled(&import.plan);
    assert_eq!(m.take_off_height(), original.mission.take_off_height());
    assert_eq!(m.waypoints.len(), original.mission.waypoints.len());
    for (a, b) in m.waypoints.iter().zip(&original.mission.waypoints) {
        let (a, b) = (a.waypoint, b.waypoint);
        assert_eq!(
            (a.waypoint_number, a.next_waypoint, a.latitude, a.longitude),
            (b.waypoint_number, b.next_waypoint, b.latitude, b.longitude)
        );
        assert_eq!((a.altitude, a.altitude_type), (b.altitude, b.altitude_type));
        assert_eq!(
            (a.speed, a.speed_type, a.turn_type),
            (b.speed, b.speed_type, b.turn_type)
        );
    }
    let areas = import
        .plan
        .areas
        .assemble(import.plan.areas.len() as u8, import.plan.safety_offset)
        .unwrap();
    assert_eq!(areas.safety_offset, original.areas.safety_offset);
    // QGC keeps polygons and circles apart: the import numbers the fly-zone, then the
    // exclusion polygons, then the circles (demo mission 2 has the circle before the
    // polygon).
    let mut expected = original.areas.areas.clone();
    expected.sort_by_key(|a| {
        (
            a.area_type != AreaType::FlyZone,
            matches!(a.shape, AreaShape::Circle { .. }),
        )
    });
    for (k, a) in expected.iter_mut().enumerate() {
        a.area_id = k as u16 + 1;
    }
    assert_same_areas(&areas.areas, &expected);

    // Exported twice, the same text: the export is a function of the plan.
    assert_eq!(export_plan(&original, &options).0, text);
}

/// Same IDs, types and polygons; circles with the same centre and radius (the border point
/// is placed due north again).
pub(crate) fn assert_same_areas(a: &[AreaPolygonLoopSegment], b: &[AreaPolygonLoopSegment]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!((x.area_id, x.area_type), (y.area_id, y.area_type));
        match (&x.shape, &y.shape) {
            (AreaShape::Polygon(p), AreaShape::Polygon(q)) => assert_eq!(p, q),
            (
                AreaShape::Circle { centre, border },
                AreaShape::Circle {
                    centre: c,
                    border: b,
                },
            ) => {
                assert_eq!(centre, c);
                let (r1, r2) = (
                    earth::distance_m(*centre, *border),
                    earth::distance_m(*c, *b),
                );
                assert!((r1 - r2).abs() < 0.02, "{r1} {r2}");
            }
            other => panic!("{other:?}"),
        }
    }
}

/// A small `.plan` with the given items and fence.
fn plan_with(items: &str, fence: &str) -> String {
    format!(
        r#"{{"fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
  "geoFence": {{ {fence} }},
  "mission": {{"cruiseSpeed": 15, "hoverSpeed": 5, "vehicleType": 1, "firmwareType": 12,
"plannedHomePosition": [47.397, 8.5455, 488],
"items": [
{items}
]}},
  "rallyPoints": {{"points": [[47.39, 8.54, 500]], "version": 2}}}}"#
    )
}

const WAYPOINT: &str = r#"{"type": "SimpleItem", "command": 16, "frame": 3,
    "params": [0, 0, 0, null, 47.41, 8.56, 100]}"#;

const TAKE_OFF: &str = r#"{"type": "SimpleItem", "command": 22, "frame": 3,
    "params": [0, 0, 0, null, 0, 0, 30]}"#;

/// A fence of `polygons` and `circles` (JSON objects).
fn fence(polygons: &[String], circles: &[String]) -> String {
    format!(
        r#""version": 2, "polygons": [{}], "circles": [{}]"#,
        polygons.join(", "),
        circles.join(", ")
    )
}

fn polygon(inclusion: bool, vertices: &[(f64, f64)]) -> String {
    let v: Vec<String> = vertices
        .iter()
        .map(|(lat, lon)| format!("[{lat}, {lon}]"))
        .collect();
    format!(
        r#"{{"inclusion": {inclusion}, "polygon": [{}], "version": 1}}"#,
        v.join(", ")
    )
}

fn circle(inclusion: bool, (lat, lon): (f64, f64), radius: f64) -> String {
    format!(
        r#"{{"inclusion": {inclusion}, "circle": {{"center": [{lat}, {lon}], "radius": {radius}}}, "version": 1}}"#
    )
}

/// A small square with its south-west corner at (`lat`, `lon`).
fn square(lat: f64, lon: f64) -> Vec<(f64, f64)> {
    vec![
        (lat, lon),
        (lat, lon + 0.001),
        (lat + 0.001, lon + 0.001),
        (lat + 0.001, lon),
    ]
}

#[test]
fn everything_the_icd_cannot_carry_refuses_the_file_or_is_dropped() {
    let items = format!(
        r#"{TAKE_OFF},
    {WAYPOINT},
    {{"type": "ComplexItem", "complexItemType": "survey"}},
    {{"type": "SimpleItem", "command": 16, "frame": 3, "params": [5, 0, 0, null, 47.42, 8.56, 100]}},
    {{"type": "SimpleItem", "command": 20, "frame": 2, "params": [0, 0, 0, 0, 0, 0, 0]}},
    {{"type": "SimpleItem", "command": 16, "frame": 1, "params": [0, 0, 0, null, 47.43, 8.56, 100]}},
    {{"type": "SimpleItem", "command": 178, "frame": 2, "params": [2, 3, -1, 0, 0, 0, 0]}},
    {{"type": "SimpleItem", "command": 21, "frame": 3, "params": [0, 0, 0, null, 47.42, 8.56, 0]}},
    {WAYPOINT}"#
    );
    let fence = fence(
        &[polygon(
            false,
            &[(47.41, 8.56), (47.41, 8.57), (47.42, 8.57)],
        )],
        &[
            circle(true, (47.40, 8.55), 5000.0),
            circle(false, (47.41, 8.55), 200.0),
        ],
    );
    let text = plan_with(&items, &fence);
    let expected = [
        "mission.items[2]: complex item \"survey\" is not supported (only take-off, \
         waypoint, land and speed change)",
        "mission.items[3].params[0]: hold 5 s is not supported: the FCC flies through its \
         waypoints and stops at none (the ICD has no hold time; without the hold the \
         waypoint is fly-over)",
        "mission.items[4]: command 20 (NAV_RETURN_TO_LAUNCH) is not supported",
        "mission.items[5].frame: command 16 (NAV_WAYPOINT) in frame 1 (LOCAL_NED) is \
         not supported: only global (0, 5), relative (3, 6) and terrain (10, 11) frames",
        "mission.items[6].params[0]: speed type 2 (2 climb, 3 descent speed) is not \
         supported: only airspeed (0) and ground speed (1)",
        "mission.items[8]: after the land (mission.items[7]): the route ends at the land",
        "geoFence.circles[0]: an inclusion circle: the ICD's fly-zone is a polygon (draw \
         it as an inclusion polygon)",
        "rallyPoints.points[0]: a rally point is not supported (the ICD has none)",
    ];
    // Refused by default, every element named; the error says how many.
    let err = import_plan(&text, &ImportOptions::default()).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("not imported: 8 elements the ICD cannot carry"),
        "{err}"
    );
    assert_eq!(refused(Err(err)), expected);

    // Dropped on request: the plan is what remains.
    let import = import_plan(&text, &dropping()).unwrap();
    assert_eq!(lines(&import.dropped), expected);
    // Two waypoints: the land is at the second one, fly-over by its hold.
    let m = assembled(&import.plan);
    assert_eq!(m.take_off_height().metres(), 30.0);
    assert_eq!(
        rows(&m).iter().map(|r| (r.0, r.5)).collect::<Vec<_>>(),
        [
            (pos(47.41, 8.56), TurnType::FlyBy),
            (pos(47.42, 8.56), TurnType::FlyOver)
        ]
    );
    // The take-off item has no position (0, 0): the planned home is the take-off position.
    assert_eq!(import.plan.take_off_position, Some(pos(47.397, 8.5455)));
    // The inclusion circle is not approximated: no fly-zone is left, which validation
    // names.
    let list = import.plan.areas.unchecked(SafetyOffset::default());
    let kinds: Vec<(u16, AreaType, bool)> = list
        .areas
        .iter()
        .map(|a| {
            (
                a.area_id,
                a.area_type,
                matches!(a.shape, AreaShape::Circle { .. }),
            )
        })
        .collect();
    assert_eq!(
        kinds,
        [
            (1, AreaType::NoFlyZone, false),
            (2, AreaType::NoFlyZone, true)
        ]
    );
    let AreaShape::Circle { border, .. } = list.areas[1].shape else {
        panic!()
    };
    assert!((earth::distance_m(pos(47.41, 8.55), border) - 200.0).abs() < 0.01);
}

#[test]
fn a_second_fly_zone_is_refused_or_dropped() {
    let big = [(47.3, 8.4), (47.3, 8.7), (47.5, 8.7), (47.5, 8.4)];
    let text = plan_with(
        WAYPOINT,
        &fence(
            &[
                polygon(true, &big),
                polygon(true, &[(47.3, 8.4), (47.3, 8.5), (47.4, 8.5)]),
            ],
            &[circle(true, (47.4, 8.5), 100.0)],
        ),
    );
    let expected = [
        "geoFence.polygons[1]: a second inclusion polygon: the ICD has one fly-zone \
         (geoFence.polygons[0])",
        "geoFence.circles[0]: an inclusion circle: the ICD has one fly-zone \
         (geoFence.polygons[0]), and it is a polygon",
    ];
    match import_areas(&text, Unsupported::Refuse) {
        Err(MissionFileError::Unsupported { elements }) => {
            assert_eq!(lines(&elements), expected);
        }
        other => panic!("{other:?}"),
    }
    let (areas, dropped) = import_areas(&text, Unsupported::Drop).unwrap();
    assert_eq!(lines(&dropped), expected, "rally points are no areas");
    assert_eq!(areas.len(), 1);
}

#[test]
fn an_eleventh_no_fly_zone_is_refused_or_dropped() {
    let fly = [(47.3, 8.4), (47.3, 8.7), (47.5, 8.7), (47.5, 8.4)];
    let mut polygons = vec![polygon(true, &fly)];
    // Ten exclusion polygons fill the FCC's area list with the fly-zone; the circle is
    // the eleventh no-fly-zone.
    for k in 0..10 {
        polygons.push(polygon(false, &square(47.35, 8.45 + 0.01 * f64::from(k))));
    }
    let text = plan_with(
        &format!("{TAKE_OFF},\n{WAYPOINT}"),
        &fence(&polygons, &[circle(false, (47.45, 8.6), 100.0)]),
    );
    let text = text.replace(r#""points": [[47.39, 8.54, 500]]"#, r#""points": []"#);
    let expected = [
        "geoFence.circles[0]: more than 10 no-fly-zones (polygons and circles): the FCC \
         holds 11 areas, one of them the fly-zone",
    ];
    assert_eq!(
        refused(import_plan(&text, &ImportOptions::default())),
        expected
    );
    let import = import_plan(&text, &dropping()).unwrap();
    assert_eq!(lines(&import.dropped), expected);
    let list = import
        .plan
        .areas
        .assemble(11, SafetyOffset::default())
        .unwrap();
    assert_eq!(list.areas.len(), 11);
    assert!(
        list.areas
            .iter()
            .all(|a| matches!(a.shape, AreaShape::Polygon(_)))
    );

    // Ten no-fly-zones fit exactly.
    let ten = text.replace(&circle(false, (47.45, 8.6), 100.0), "");
    let import = import_plan(&ten, &ImportOptions::default()).unwrap();
    assert_eq!(import.plan.areas.len(), 11);
}

#[test]
fn a_polygon_of_more_than_60_vertices_is_refused_or_dropped() {
    let ring: Vec<(f64, f64)> = (0..61)
        .map(|k| {
            let a = f64::from(k) * core::f64::consts::TAU / 61.0;
            (47.4 + 0.01 * a.cos(), 8.5 + 0.01 * a.sin())
        })
        .collect();
    let text = plan_with(WAYPOINT, &fence(&[polygon(false, &ring)], &[]));
    let expected = ["geoFence.polygons[0]: 61 vertices, at most 60 fit a #2012"];
    match import_areas(&text, Unsupported::Refuse) {
        Err(MissionFileError::Unsupported { elements }) => {
            assert_eq!(lines(&elements), expected);
        }
        other => panic!("{other:?}"),
    }
    let (areas, dropped) = import_areas(&text, Unsupported::Drop).unwrap();
    assert_eq!(lines(&dropped), expected);
    assert!(areas.is_empty());
}

#[test]
fn the_take_off_position_is_the_take_off_items_else_the_planned_home() {
    let take_off = |lat: &str, lon: &str| {
        format!(
            r#"{{"type": "SimpleItem", "command": 84, "frame": 3,
            "params": [0, 0, 0, null, {lat}, {lon}, 25]}},
            {WAYPOINT}"#
        )
    };
    let import = |text: &str| {
        let text = text.replace(r#""points": [[47.39, 8.54, 500]]"#, r#""points": []"#);
        import_plan(&text, &ImportOptions::default()).unwrap()
    };
    // VTOL take-off with its own position.
    let own = import(&plan_with(&take_off("47.398", "8.546"), ""));
    assert_eq!(own.plan.take_off_position, Some(pos(47.398, 8.546)));
    assert_eq!(assembled(&own.plan).take_off_height().metres(), 25.0);
    // No position (0, 0 or null): the planned home.
    for (lat, lon) in [("0", "0"), ("null", "null")] {
        let home = import(&plan_with(&take_off(lat, lon), ""));
        assert_eq!(home.plan.take_off_position, Some(pos(47.397, 8.5455)));
    }
    // Neither: none, which validation refuses.
    let none = import(
        &plan_with(&take_off("0", "0"), "")
            .replace(r#""plannedHomePosition": [47.397, 8.5455, 488],"#, ""),
    );
    assert_eq!(none.plan.take_off_position, None);
    assert_eq!(none.home, None);
    // A planned home of (0, 0) is QGC's "not set".
    let unset =
        import(&plan_with(&take_off("0", "0"), "").replace("[47.397, 8.5455, 488]", "[0, 0, 0]"));
    assert_eq!(unset.plan.take_off_position, None);
}

/// Found by fuzz_qgc_plan and fuzz_geojson: an empty file was "line 1, column 0".
#[test]
fn an_early_end_is_at_column_1() {
    for (text, line) in [("", 1), ("{\"fileType\": \"Plan\",\n", 2)] {
        match import_plan(text, &ImportOptions::default()).unwrap_err() {
            MissionFileError::Syntax {
                line: l, column, ..
            } => assert_eq!((l, column), (line, 1), "{text:?}"),
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn bad_files_name_the_position() {
    let err = import_plan(
        "{\"fileType\": \"Plan\",\n  \"mission\": [1,}",
        &ImportOptions::default(),
    )
    .unwrap_err();
    match err {
        MissionFileError::Syntax {
            line,
            column,
            message,
        } => {
            assert_eq!((line, column), (2, 17));
            assert_eq!(message, "expected value");
        }
        other => panic!("{other:?}"),
    }

    let with = |item: &str| {
        plan_with(&format!("{TAKE_OFF},\n{WAYPOINT},\n{item}"), "")
            .replace(r#""points": [[47.39, 8.54, 500]]"#, r#""points": []"#)
    };
    let cases: &[(&str, &str)] = &[
        (
            r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 95, 8.5, 10]}"#,
            "mission.items[2].params[4]: latitude 95 deg is outside -90..=90",
        ),
        (
            r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 47.4, null, 10]}"#,
            "mission.items[2].params[5]: expected a number, found null",
        ),
        (
            r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 47.4, 8.5, "high"]}"#,
            "mission.items[2].params[6]: expected a number, found the string \"high\"",
        ),
        (
            r#"{"type": "SimpleItem", "command": 16, "frame": 0, "params": [0, 0, 0, null, 47.4, 8.5, null]}"#,
            "mission.items[2].params[6]: expected a number, found null",
        ),
        (
            r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 47.4, 8.5, 10]}"#,
            "mission.items[2].params: 5 values, expected 7",
        ),
        (
            r#"{"type": "Simple", "command": 16}"#,
            "mission.items[2].type: \"Simple\" is not \"SimpleItem\" or \"ComplexItem\"",
        ),
        (
            r#"{"type": "SimpleItem", "frame": 3, "params": []}"#,
            "mission.items[2].command: missing",
        ),
        (
            r#"{"type": "SimpleItem", "command": 178, "frame": 2, "params": [1, 0.2, -1, 0, 0, 0, 0]}"#,
            "mission.items[2].params[1]: 0.2 m/s is 0 on the wire (steps of 0.5 m/s); the \
             speed must be above 0",
        ),
        (
            r#"{"type": "SimpleItem", "command": 22, "frame": 0, "params": [0, 0, 0, null, 0, 0, 400]}"#,
            "not imported: 1 element the ICD cannot carry or the FCC cannot hold; \
             mission.items[2]: command 22 (NAV_TAKEOFF): a second take-off (the first is \
             mission.items[0])",
        ),
        (
            r#"{"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 47.4, 181, 40]}"#,
            "not imported: 1 element the ICD cannot carry or the FCC cannot hold; \
             mission.items[2]: command 22 (NAV_TAKEOFF): a second take-off (the first is \
             mission.items[0])",
        ),
    ];
    for (item, expected) in cases {
        let got = import_plan(&with(item), &ImportOptions::default())
            .map(|i| i.dropped)
            .unwrap_err();
        assert_eq!(&got.to_string(), expected);
    }

    // A take-off after the waypoints: no take-off before the route, which is no mission.
    let late = plan_with(
        &format!(
            r#"{WAYPOINT},
{{"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 0, 0, 40]}}"#
        ),
        "",
    );
    assert_eq!(
        import_plan(&late, &dropping()).unwrap_err().to_string(),
        "mission.items[1]: command 22 (NAV_TAKEOFF): a take-off after waypoints is not \
         supported (the ICD's take-off comes before the route)"
    );
    // No take-off at all.
    assert_eq!(
        import_plan(&plan_with(WAYPOINT, ""), &dropping())
            .unwrap_err()
            .to_string(),
        "mission.items: no take-off (command 22 or 84): the ICD's mission needs its \
         take-off height"
    );
    // A take-off position outside the world.
    let far = plan_with(
        r#"{"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 47.4, 181, 40]}"#,
        "",
    );
    assert_eq!(
        import_plan(&far, &dropping()).unwrap_err().to_string(),
        "mission.items[0].params[5]: longitude 181 deg is outside -180..=180"
    );

    // A take-off below home, in AMSL.
    let below = plan_with(
        &format!(
            r#"{{"type": "SimpleItem", "command": 22, "frame": 0, "params": [0, 0, 0, null, 0, 0, 400]}},
{WAYPOINT}"#
        ),
        "",
    );
    assert_eq!(
        import_plan(&below, &ImportOptions::default())
            .unwrap_err()
            .to_string(),
        "mission.items[0].params[6]: take-off height -88 m is below the ground at home"
    );
    let fence = plan_with(
        WAYPOINT,
        r#""polygons": [{"inclusion": false, "polygon": [[47.3, 8.4], [47.3], [47.5, 8.7]]}]"#,
    );
    assert_eq!(
        import_areas(&fence, Unsupported::Drop)
            .unwrap_err()
            .to_string(),
        "geoFence.polygons[0].polygon[1]: 1 values, expected [latitude, longitude]"
    );
    assert_eq!(
        import_areas("{\"fileType\": \"Mission\"}", Unsupported::Refuse)
            .unwrap_err()
            .to_string(),
        "fileType: \"Mission\": not a QGroundControl plan (\"Plan\")"
    );
    assert_eq!(
        import_areas("[]", Unsupported::Refuse)
            .unwrap_err()
            .to_string(),
        "(top level): expected an object, found an array"
    );
}
