//! Tests of the mission file: the demo missions, every field's errors, the round trips.

use super::*;
use missionlink_ground::ground_station::InvalidPlan;
use missionlink_interfaces::wire::{Angle, Reason};
use missionlink_protocol::geofence::earth;

pub(crate) const MISSION_1: &str = include_str!("../../../missions/mission-1.toml");
pub(crate) const MISSION_2: &str = include_str!("../../../missions/mission-2.toml");

/// The plan of `text`, assembled as the GCS validation request does (ICD §7).
pub(crate) fn validated(text: &str) -> ValidatedPlan {
    let file = MissionFile::parse(text).unwrap();
    file.to_plan().unwrap().assemble().unwrap()
}

/// `text` with each `(from, to)` replaced once; every `from` must occur.
fn edit(text: &str, edits: &[(&str, &str)]) -> String {
    let mut t = text.to_owned();
    for (from, to) in edits {
        assert!(t.contains(from), "{from:?} not in the text");
        t = t.replacen(from, to, 1);
    }
    t
}

fn field_err(text: &str) -> (String, String) {
    let file = MissionFile::parse(text).unwrap();
    match file.to_plan() {
        Err(MissionFileError::Field { path, reason }) => (path, reason),
        other => panic!("expected a field error, got {other:?}"),
    }
}

fn syntax_err(text: &str) -> (usize, usize, String) {
    match MissionFile::parse(text) {
        Err(MissionFileError::Syntax {
            line,
            column,
            message,
        }) => (line, column, message),
        other => panic!("expected a syntax error, got {other:?}"),
    }
}

fn point(lat: f64, lon: f64) -> GeoPoint {
    GeoPoint::from_degrees(lat, lon).unwrap()
}

#[test]
fn demo_mission_1_validates() {
    let v = validated(MISSION_1);
    let m = &v.mission;
    assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-1");
    assert_eq!(m.take_off_height().metres(), 30.0);
    assert_eq!(m.route.initial_waypoint, 1);
    assert!(!m.route.bidirectional);
    assert_eq!(m.waypoints.len(), 1);
    let ccp = &m.waypoints[0].waypoint;
    assert_eq!((ccp.waypoint_number, ccp.next_waypoint), (1, 0));
    assert_eq!(ccp.latitude, Angle::from_degrees(48.275).unwrap());
    assert_eq!(ccp.longitude, Angle::from_degrees(11.645).unwrap());
    assert_eq!(ccp.altitude.metres(), 120.0);
    assert_eq!(ccp.altitude_type, Some(AltitudeType::Wgs84));
    assert_eq!(ccp.speed.mps(), 25.0);
    assert_eq!(ccp.speed_type, Some(SpeedType::IndicatedAirspeed));
    assert_eq!(ccp.turn_type, TurnType::FlyBy);
    assert_eq!(ccp.leg_type, LegType::TrackToFix);
    assert_eq!(v.areas.safety_offset.metres(), 25.0);
    assert_eq!(v.areas.areas.len(), 1);
    let fz = &v.areas.areas[0];
    assert_eq!((fz.area_id, fz.area_type), (1, AreaType::FlyZone));
    let corners = [
        point(48.255, 11.635),
        point(48.255, 11.690),
        point(48.285, 11.690),
        point(48.285, 11.635),
    ];
    assert_eq!(
        fz.shape,
        AreaShape::Polygon(PolygonVertices::from_slice(&corners).unwrap())
    );
}

#[test]
fn demo_mission_2_validates() {
    let v = validated(MISSION_2);
    let m = &v.mission;
    assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-2");
    assert_eq!(m.take_off_height().metres(), 30.0);
    assert!(m.route.bidirectional);
    assert_eq!(m.route.route_type, Some(RouteType::Flight));
    let order: Vec<u16> = m
        .waypoints
        .iter()
        .map(|r| r.waypoint.waypoint_number)
        .collect();
    assert_eq!(order, [1, 2, 3], "CCP, W1, ROLE2");
    let role2 = &m.waypoints[2];
    assert_eq!(role2.waypoint.leg_type, LegType::RadiusToFix);
    assert_eq!(role2.waypoint.latitude, Angle::from_degrees(48.28).unwrap());
    assert_eq!(role2.waypoint.optional_messages, Some(1));
    assert_eq!(
        role2.rf_centre.map(|c| c.data),
        Some(SpecificData::RfCentre {
            waypoint_number: 3,
            latitude: Angle::from_degrees(48.27455).unwrap(),
            longitude: Angle::from_degrees(11.66991).unwrap(),
            turn_direction: TurnDirection::Clockwise,
        })
    );
    assert!(m.waypoints[..2].iter().all(|r| r.rf_centre.is_none()));
    let areas: Vec<(u16, AreaType)> = v
        .areas
        .areas
        .iter()
        .map(|a| (a.area_id, a.area_type))
        .collect();
    assert_eq!(
        areas,
        [
            (1, AreaType::FlyZone),
            (2, AreaType::NoFlyZone),
            (3, AreaType::NoFlyZone)
        ]
    );
    assert_eq!(
        v.areas.areas[1].shape,
        AreaShape::Circle {
            centre: point(48.268, 11.675),
            border: point(48.268, 11.679),
        }
    );
    assert!(matches!(&v.areas.areas[2].shape, AreaShape::Polygon(p) if p.len() == 4));
}

#[test]
fn read_reads_a_file_and_names_one_it_cannot() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../missions");
    let file = MissionFile::read(&dir.join("mission-2.toml")).unwrap();
    assert_eq!(file, MissionFile::parse(MISSION_2).unwrap());
    let missing = dir.join("no-such-mission.toml");
    let err = MissionFile::read(&missing).unwrap_err();
    assert!(matches!(&err, MissionFileError::Io { path, .. } if *path == missing));
    assert!(err.to_string().starts_with(&missing.display().to_string()));
}

/// The plan of the file `text` (before assembly).
fn plan_of(text: &str) -> MissionPlan {
    *MissionFile::parse(text).unwrap().to_plan().unwrap()
}

/// The file of `text` as an export writes it (the plan validated, with its take-off).
fn exported(text: &str) -> MissionFile {
    let plan = plan_of(text);
    MissionFile::from_plan(&plan.assemble().unwrap(), plan.take_off_position)
}

/// Export, parse, plan, validate: the same plan and take-off position, and the same file
/// again.
fn assert_round_trip(plan: &MissionPlan) {
    let v = plan.assemble().unwrap();
    let file = MissionFile::from_plan(&v, plan.take_off_position);
    let text = file.to_toml();
    let parsed = MissionFile::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(parsed, file, "{text}");
    let again = parsed.to_plan().unwrap();
    assert_eq!(again.take_off_position, plan.take_off_position, "{text}");
    let again_valid = again.assemble().unwrap();
    assert_eq!(again_valid, v, "{text}");
    assert_eq!(
        MissionFile::from_plan(&again_valid, again.take_off_position).to_toml(),
        text
    );
}

#[test]
fn export_round_trip_gives_back_the_plan() {
    for text in [MISSION_1, MISSION_2] {
        assert_round_trip(&plan_of(text));
    }
    // The export of a demo mission writes the same numbers as the file: the shortest
    // decimals of the wire values.
    let exported = exported(MISSION_2);
    let mut original = MissionFile::parse(MISSION_2).unwrap();
    assert_eq!(exported, original);
    original.waypoints[2].latitude_deg = 48.280_000_001;
    assert_ne!(exported, original);
    let text = exported.to_toml();
    assert!(text.starts_with("# missionlink mission file"), "{text}");
    assert!(
        text.contains(
            "polygon = [\n    [48.255, 11.635],\n    [48.255, 11.69],\n    \
             [48.285, 11.69],\n    [48.285, 11.635],\n]\n"
        ),
        "{text}"
    );
}

#[test]
fn round_trip_variations() {
    let all_optional = edit(
        MISSION_2,
        &[
            (
                "safety_offset_m = 25.0",
                "safety_offset_m = 0.3\ntake_off_activity_id = 16777215",
            ),
            (
                "route_type = \"flight\"",
                "route_type = \"contingency-b\"\nroute_id = \"CCP-ROLE2 über W1\"\n\
                 planning_wind_mps = 12.5",
            ),
            (
                "leg_type = \"track-to-fix\"",
                "leg_type = \"track-to-fix\"\n\
                 location_type = \"absolute\"\n\
                 altitude_change_behaviour = 255\n\
                 limit_type = 2\n\
                 loop_limit = 65535\n\
                 arrival_time = 2026-11-21T12:06:00.300Z\n\
                 activity_id = 42\n\
                 optional_messages = 0",
            ),
            (
                "turn_direction = \"clockwise\"",
                "turn_direction = \"counter-clockwise\"\nactivity_id = 7",
            ),
            (
                "area_type = \"fly-zone\"",
                "area_type = \"fly-zone\"\n\
                 lower_altitude_m = -12.34\n\
                 upper_altitude_m = 300\n\
                 altitude_type = \"agl\"",
            ),
        ],
    );
    let cases: [(&str, String); 7] = [
        ("every optional field", all_optional),
        (
            "circle given by radius_m",
            edit(
                MISSION_2,
                &[("border = [48.268, 11.679]", "radius_m = 296.07")],
            ),
        ),
        (
            "off-grid values, extremes, other enumeration words",
            edit(
                MISSION_2,
                &[
                    ("latitude_deg = 48.275", "latitude_deg = 48.123456789"),
                    ("longitude_deg = 11.645", "longitude_deg = -180"),
                    ("altitude_m = 120.0", "altitude_m = -123.457"),
                    ("speed_mps = 25.0", "speed_mps = 0.3"),
                    ("altitude_type = \"wgs84\"", "altitude_type = \"pressure\""),
                    (
                        "speed_type = \"indicated-airspeed\"",
                        "speed_type = \"ground-speed\"",
                    ),
                    ("turn_type = \"fly-by\"", "turn_type = \"fly-over\""),
                    ("[48.255, 11.635]", "[-90, 179.99999999]"),
                    ("take_off_height_m = 30.0", "take_off_height_m = 0.01"),
                ],
            ),
        ),
        (
            "optional fields absent",
            edit(
                MISSION_2,
                &[
                    ("mission_id = \"MEDEVAC-2\"", ""),
                    ("route_type = \"flight\"", ""),
                    ("optional_messages = 1", ""),
                    ("altitude_type = \"wgs84\"", ""),
                    ("speed_type = \"indicated-airspeed\"", ""),
                ],
            ),
        ),
        (
            "empty texts are kept, not dropped",
            edit(
                MISSION_2,
                &[
                    ("mission_id = \"MEDEVAC-2\"", "mission_id = \"\""),
                    (
                        "route_type = \"flight\"",
                        "route_type = \"flight\"\nroute_id = \"\"",
                    ),
                ],
            ),
        ),
        (
            "arrival time as a string with an offset, without milliseconds",
            edit(
                MISSION_1,
                &[(
                    "leg_type = \"track-to-fix\"",
                    "leg_type = \"track-to-fix\"\narrival_time = \"2026-11-21T13:06:00+01:00\"",
                )],
            ),
        ),
        (
            "file order is free; the export lists the flight plan",
            edit(
                MISSION_2,
                &[
                    // CCP becomes waypoint 40 and starts the route; ROLE2 is listed first.
                    ("initial_waypoint = 1", "initial_waypoint = 40"),
                    ("number = 1\n", "number = 40\n"),
                    ("number = 3\n", "number = 7\n"),
                    ("next = 3 ", "next = 7 "),
                ],
            ),
        ),
    ];
    for (name, text) in &cases {
        let file = MissionFile::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
        let plan = file.to_plan().unwrap_or_else(|e| panic!("{name}: {e}"));
        plan.assemble().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_round_trip(&plan);
    }

    // Spot checks of what the cases hold.
    let v = validated(&cases[0].1);
    let w1 = &v.mission.waypoints[0].waypoint;
    assert_eq!(
        w1.arrival_time.unwrap().to_string(),
        "2026-11-21T12:06:00.300Z"
    );
    assert_eq!(w1.activity_id, U3::new(42));
    assert_eq!(w1.loop_limit, Some(65535));
    assert_eq!(
        v.mission.route.route_id.unwrap().as_str(),
        "CCP-ROLE2 über W1"
    );
    assert_eq!(v.mission.take_off.activity_id, U3::new(16_777_215));
    assert_eq!(v.areas.safety_offset.raw(), 3);
    assert_eq!(v.areas.areas[0].lower_altitude.unwrap().raw(), -617);
    let text = MissionFile::from_plan(&v, None).to_toml();
    assert!(
        text.contains("arrival_time = 2026-11-21T12:06:00.3Z\n"),
        "{text}"
    );
    assert!(text.contains("lower_altitude_m = -12.34\n"), "{text}");

    let v = validated(&cases[2].1);
    let text = MissionFile::from_plan(&v, None).to_toml();
    // BAM4 keeps about 7 decimals; the export writes the shortest decimal of the wire value.
    assert!(text.contains("latitude_deg = 48.1234568\n"), "{text}");
    assert!(text.contains("longitude_deg = -180.0\n"), "{text}");
    assert!(text.contains("altitude_m = -123.46\n"), "{text}");
    assert!(text.contains("speed_mps = 0.5\n"), "{text}");
    assert!(text.contains("take_off_height_m = 0.02\n"), "{text}");

    let v = validated(&cases[4].1);
    assert_eq!(v.mission.mission_id.map(|t| t.as_str().len()), Some(0));
    assert_eq!(v.mission.route.route_id.map(|t| t.as_str().len()), Some(0));

    let v = validated(&cases[5].1);
    let t = v.mission.waypoints[0].waypoint.arrival_time.unwrap();
    assert_eq!(t.to_string(), "2026-11-21T12:06:00.000Z");
    let text = MissionFile::from_plan(&v, None).to_toml();
    assert!(
        text.contains("arrival_time = 2026-11-21T12:06:00Z\n"),
        "{text}"
    );

    let v = validated(&cases[6].1);
    let order: Vec<u16> = v
        .mission
        .waypoints
        .iter()
        .map(|r| r.waypoint.waypoint_number)
        .collect();
    assert_eq!(order, [40, 2, 7]);
}

#[test]
fn radius_m_places_the_border_due_north() {
    let text = edit(
        MISSION_2,
        &[("border = [48.268, 11.679]", "radius_m = 296.07")],
    );
    let v = validated(&text);
    let AreaShape::Circle { centre, border } = v.areas.areas[1].shape else {
        panic!("not a circle");
    };
    assert_eq!(centre, point(48.268, 11.675));
    assert_eq!(border.longitude, centre.longitude);
    let metres = earth::distance_m(centre, border);
    // One BAM4 step of latitude is about 9.3 mm.
    assert!((metres - 296.07).abs() < 0.01, "{metres}");
    // Exported, the circle has its exact border point and no radius.
    let file = MissionFile::from_plan(&v, None);
    let circle = file.areas[1].circle.as_ref().unwrap();
    assert_eq!(circle.radius_m, None);
    assert_eq!(
        point(circle.border.unwrap()[0], circle.border.unwrap()[1]),
        border
    );
}

#[test]
fn syntax_and_type_errors_give_line_and_column() {
    /// 1-based number of the first line of `text` that starts with `start`.
    fn line_of(text: &str, start: &str) -> usize {
        text.lines().position(|l| l.starts_with(start)).unwrap() + 1
    }
    let broken = edit(
        MISSION_2,
        &[("latitude_deg = 48.275", "latitude_deg = 48.275 deg")],
    );
    let (line, column, message) = syntax_err(&broken);
    let expected = line_of(MISSION_2, "latitude_deg = 48.275");
    // The value `48.275 deg` starts after `latitude_deg = `, 15 characters.
    assert_eq!((line, column), (expected, 16), "{message}");
    assert!(
        message.contains("string values must be quoted"),
        "{message}"
    );

    let typed = edit(MISSION_2, &[("speed_mps = 25.0", "speed_mps = \"fast\"")]);
    let (line, column, message) = syntax_err(&typed);
    assert_eq!(
        (line, column),
        (line_of(MISSION_2, "speed_mps"), 13),
        "{message}"
    );
    assert!(message.contains("invalid type"), "{message}");

    let unknown = edit(MISSION_2, &[("altitude_m = 120.0", "altitud_m = 120.0")]);
    let (line, column, message) = syntax_err(&unknown);
    assert_eq!(
        (line, column),
        (line_of(MISSION_2, "altitude_m"), 1),
        "{message}"
    );
    assert!(message.contains("unknown field `altitud_m`"), "{message}");

    let missing = edit(MISSION_2, &[("turn_type = \"fly-by\"\n", "")]);
    let (line, _, message) = syntax_err(&missing);
    assert_eq!(
        line,
        line_of(MISSION_2, "[[waypoints]]"),
        "the table of CCP: {message}"
    );
    assert!(message.contains("missing field `turn_type`"), "{message}");

    // Columns count characters, not bytes.
    let (line, column, _) = syntax_err("mission_id = \"ü\" x\n");
    assert_eq!((line, column), (1, 18));

    let e = MissionFileError::Syntax {
        line: 12,
        column: 5,
        message: "expected `=`".into(),
    };
    assert_eq!(e.to_string(), "line 12, column 5: expected `=`");
}

#[test]
fn bad_values_name_their_path() {
    let lat = edit(MISSION_2, &[("latitude_deg = 48.275", "latitude_deg = 95")]);
    let (path, reason) = field_err(&lat);
    assert_eq!(path, "waypoints[0].latitude_deg");
    assert_eq!(reason, "latitude 95 deg is outside -90..=90");
    assert_eq!(
        MissionFile::parse(&lat)
            .unwrap()
            .to_plan()
            .unwrap_err()
            .to_string(),
        "waypoints[0].latitude_deg: latitude 95 deg is outside -90..=90"
    );

    /// Edits of mission 2, the path named, the end of the reason.
    type Case<'a> = (&'a [(&'a str, &'a str)], &'a str, &'a str);
    let cases: &[Case] = &[
        (
            &[("turn_type = \"fly-by\"", "turn_type = \"fly_by\"")],
            "waypoints[0].turn_type",
            "\"fly_by\" is not one of \"fly-by\", \"fly-over\"",
        ),
        (
            &[("number = 3\n", "number = 1\n")],
            "waypoints[2].number",
            "waypoint number 1 is also waypoints[0].number",
        ),
        (
            &[("area_id = 3", "area_id = 2")],
            "areas[2].area_id",
            "area ID 2 is also areas[1].area_id",
        ),
        (
            &[(
                "mission_id = \"MEDEVAC-2\"",
                "mission_id = \"MEDEVAC-2-CCP-TO-ROLE2\"",
            )],
            "mission_id",
            "\"MEDEVAC-2-CCP-TO-ROLE2\": text of 22 bytes, at most 19 fit",
        ),
        (
            &[(
                "route_type = \"flight\"",
                "route_id = \"CCP-W1-ROLE2-CCP-W1-ROLE2-CCP-W1X\"",
            )],
            "route.route_id",
            "text of 33 bytes, at most 32 fit",
        ),
        (
            &[("speed_mps = 25.0", "speed_mps = -25.0")],
            "waypoints[0].speed_mps",
            "speed (m/s) -25 is outside 0..=32767.5",
        ),
        (
            &[("speed_mps = 25.0", "speed_mps = 0.2")],
            "waypoints[0].speed_mps",
            "the speed must be above 0",
        ),
        (
            &[("longitude_deg = 11.66991", "longitude_deg = 181")],
            "waypoints[2].rf_centre.longitude_deg",
            "longitude 181 deg is outside -180..=180",
        ),
        (
            &[(
                "turn_direction = \"clockwise\"",
                "turn_direction = \"right\"",
            )],
            "waypoints[2].rf_centre.turn_direction",
            "\"right\" is not one of \"clockwise\", \"counter-clockwise\"",
        ),
        (
            &[("take_off_height_m = 30.0", "take_off_height_m = -1")],
            "take_off_height_m",
            "-1 m is below ground (0)",
        ),
        (
            &[(
                "take_off_position = [48.275, 11.645]",
                "take_off_position = [95, 11.645]",
            )],
            "take_off_position",
            "latitude 95 deg is outside -90..=90",
        ),
        (
            &[(
                "take_off_position = [48.275, 11.645]",
                "take_off_position = [48.275, -180.5]",
            )],
            "take_off_position",
            "longitude -180.5 deg is outside -180..=180",
        ),
        (
            &[("safety_offset_m = 25.0", "safety_offset_m = 7000")],
            "safety_offset_m",
            "safety offset (m) 7000 is outside 0..=6553.5",
        ),
        (
            &[("initial_waypoint = 1", "initial_waypoint = 0")],
            "route.initial_waypoint",
            "0 is outside 1..=65534",
        ),
        (
            &[("next = 0 ", "next = 65535 ")],
            "waypoints[2].next",
            "65535 is outside 0..=65534",
        ),
        (
            &[("leg_type = \"radius-to-fix\"", "leg_type = \"arc\"")],
            "waypoints[2].leg_type",
            "\"arc\" is not one of \"track-to-fix\", \"radius-to-fix\"",
        ),
        (
            &[("optional_messages = 1", "optional_messages = 256")],
            "waypoints[2].optional_messages",
            "256 is outside 0..=255",
        ),
        (
            &[("optional_messages = 1", "activity_id = 16777216")],
            "waypoints[2].activity_id",
            "16777216 is outside 0..=16777215",
        ),
        (
            &[("optional_messages = 1", "location_type = \"relative\"")],
            "waypoints[2].location_type",
            "\"relative\" is not one of \"absolute\"",
        ),
        (
            &[(
                "optional_messages = 1",
                "arrival_time = 2026-11-21T12:06:00",
            )],
            "waypoints[2].arrival_time",
            "2026-11-21T12:06:00: give date, time and UTC offset (RFC 3339), e.g. 2026-11-21T12:06:00Z",
        ),
        (
            &[(
                "optional_messages = 1",
                "arrival_time = 2040-01-01T00:00:00Z",
            )],
            "waypoints[2].arrival_time",
            "2040-01-01T00:00:00Z is outside what a TS holds (2000-01-01 to 2034-11-01)",
        ),
        (
            &[("area_type = \"fly-zone\"", "area_type = \"stay-in\"")],
            "areas[0].area_type",
            "\"stay-in\" is not one of \"fly-zone\", \"no-fly-zone\"",
        ),
        (
            &[("[48.262, 11.646],", "[95, 11.646],")],
            "areas[2].polygon[1]",
            "latitude 95 deg is outside -90..=90",
        ),
        (
            &[(
                "area_type = \"fly-zone\"",
                "area_type = \"fly-zone\"\nlower_altitude_m = 300\nupper_altitude_m = 0",
            )],
            "areas[0].upper_altitude_m",
            "0 m is below lower_altitude_m (300 m)",
        ),
        (
            &[(
                "border = [48.268, 11.679]",
                "border = [48.268, 11.679], radius_m = 300",
            )],
            "areas[1].circle",
            "give either border or radius_m, not both",
        ),
        (
            &[("border = [48.268, 11.679]", "radius_m = 0")],
            "areas[1].circle.radius_m",
            "0 m: the radius must be above 0",
        ),
        (
            &[(
                "centre = [48.268, 11.675], border = [48.268, 11.679]",
                "centre = [89.99, 0], radius_m = 2000",
            )],
            "areas[1].circle.radius_m",
            "2000 m north of the centre is beyond the pole",
        ),
        (
            &[(
                "area_type = \"no-fly-zone\"\ncircle",
                "area_type = \"no-fly-zone\"\npolygon = []\ncircle",
            )],
            "areas[1]",
            "give either polygon or circle, not both",
        ),
        (
            &[(
                "circle = { centre = [48.268, 11.675], border = [48.268, 11.679] }",
                "",
            )],
            "areas[1]",
            "give polygon or circle",
        ),
    ];
    for (edits, path, reason) in cases {
        let (p, r) = field_err(&edit(MISSION_2, edits));
        assert_eq!(&p, path, "{edits:?}: {r}");
        assert!(
            r.ends_with(reason),
            "{edits:?}: {r:?} does not end with {reason:?}"
        );
    }

    // More than a #2012 holds.
    let many: Vec<String> = (0..61)
        .map(|k| format!("[48.26, {}]", 11.64 + f64::from(k) * 1e-4))
        .collect();
    let text = edit(
        MISSION_2,
        &[("[48.262, 11.640],", &format!("{},", many.join(", ")))],
    );
    let (path, reason) = field_err(&text);
    assert_eq!(path, "areas[2].polygon");
    assert_eq!(reason, "64 vertices, at most 60 fit a #2012");
}

#[test]
fn the_take_off_position_is_read_written_and_may_be_absent() {
    let point_of = |text: &str| plan_of(text).take_off_position;
    assert_eq!(point_of(MISSION_1), Some(point(48.26, 11.66)), "TROL");
    assert_eq!(point_of(MISSION_2), Some(point(48.275, 11.645)), "CCP");
    let text = exported(MISSION_1).to_toml();
    assert!(
        text.contains("take_off_height_m = 30.0\ntake_off_position = [48.26, 11.66]\n"),
        "{text}"
    );
    assert!(!text.contains("No take_off_position"), "{text}");
    // Not a pair of numbers: a syntax error at the key.
    let (line, _, message) = syntax_err(&edit(
        MISSION_1,
        &[(
            "take_off_position = [48.26, 11.66]",
            "take_off_position = [48.26]",
        )],
    ));
    assert_eq!(line, 10, "{message}");
    // Absent (a download): read, and written with a comment that says why it is missing.
    let without = edit(MISSION_1, &[("take_off_position = [48.26, 11.66]", "")]);
    assert_eq!(point_of(&without), None);
    let downloaded = MissionFile::from_plan(&validated(MISSION_1), None);
    assert_eq!(downloaded.take_off_position, None);
    let text = downloaded.to_toml();
    assert!(
        text.contains("# No take_off_position: the FCC does not hold it"),
        "{text}"
    );
    assert!(!text.contains("\ntake_off_position"), "{text}");
    assert_round_trip(&plan_of(&without));
}

#[test]
fn a_two_vertex_polygon_is_a_file_but_not_a_valid_plan() {
    let text = edit(
        MISSION_2,
        &[("    [48.266, 11.646],\n    [48.266, 11.640],\n", "")],
    );
    let plan = MissionFile::parse(&text).unwrap().to_plan().unwrap();
    assert_eq!(
        plan.assemble().unwrap_err(),
        InvalidPlan::Areas(Reason::BadGeometry)
    );
}

#[test]
fn plan_level_faults_are_left_to_validation() {
    // A broken chain and a circular fly-zone are well-formed files.
    let broken = edit(MISSION_2, &[("next = 3 ", "next = 9 ")]);
    let plan = MissionFile::parse(&broken).unwrap().to_plan().unwrap();
    assert_eq!(
        plan.assemble().unwrap_err(),
        InvalidPlan::Mission(Reason::BrokenChain)
    );
    let no_centre = edit(
        MISSION_2,
        &[(
            "[waypoints.rf_centre]\nlatitude_deg = 48.27455\nlongitude_deg = 11.66991\n\
             turn_direction = \"clockwise\"\n",
            "",
        )],
    );
    let plan = MissionFile::parse(&no_centre).unwrap().to_plan().unwrap();
    assert_eq!(
        plan.assemble().unwrap_err(),
        InvalidPlan::Mission(Reason::MissingRfCentre)
    );
    let round_fz = edit(
        MISSION_2,
        &[
            ("area_type = \"fly-zone\"", "area_type = \"no-fly-zone\""),
            (
                "area_type = \"no-fly-zone\"\ncircle",
                "area_type = \"fly-zone\"\ncircle",
            ),
        ],
    );
    let plan = MissionFile::parse(&round_fz).unwrap().to_plan().unwrap();
    assert_eq!(
        plan.assemble().unwrap_err(),
        InvalidPlan::Areas(Reason::BadGeometry)
    );
}

#[test]
fn the_documented_example_validates() {
    // The first `toml` block of the format's document is its complete example.
    let source = include_str!("../../../docs/mission-files.md");
    let example: String = source
        .lines()
        .skip_while(|l| *l != "```toml")
        .skip(1)
        .take_while(|l| *l != "```")
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(example.contains("[[areas]]"));
    let v = validated(&example);
    assert_round_trip(&plan_of(&example));
    // The example is demo mission 2 plus optional fields.
    let demo = validated(MISSION_2);
    assert_eq!(v.mission.waypoints.len(), demo.mission.waypoints.len());
    assert_eq!(v.areas.areas.len(), demo.areas.areas.len());
    for (a, b) in v.areas.areas.iter().zip(&demo.areas.areas) {
        assert_eq!(a.shape, b.shape);
    }
}

fn check_words<T: Word + core::fmt::Debug>(all: &[T]) {
    assert_eq!(T::WORDS.len(), all.len());
    for v in all {
        let w = word(*v);
        assert!(
            w.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
            "{w}"
        );
        assert_eq!(from_word::<T>("x", &w).unwrap(), *v);
    }
}

#[test]
fn every_wire_value_has_a_kebab_case_word() {
    check_words(AltitudeType::ALL);
    check_words(SpeedType::ALL);
    check_words(TurnType::ALL);
    check_words(LegType::ALL);
    check_words(TurnDirection::ALL);
    check_words(LocationType::ALL);
    check_words(RouteType::ALL);
    check_words(AreaType::ALL);
}
