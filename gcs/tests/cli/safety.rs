//! The safety gateway as the operator meets it: `gcs validate`, `gcs upload` refusing an
//! infeasible mission without sending anything, `gcs map`, `gcs convert`, and missions from
//! QGroundControl.

use std::path::{Path, PathBuf};

use crate::support::{SilentFcc, gcs, repo, scratch, text, text_of};

/// Demo mission 2 with waypoint 2 (W1) moved into the circular no-fly-zone, written into `dir`.
fn broken_mission(dir: &Path) -> PathBuf {
    let good = std::fs::read_to_string(repo("missions/mission-2.toml")).unwrap();
    let broken = good
        .replace("latitude_deg = 48.278\n", "latitude_deg = 48.2685\n")
        .replace("longitude_deg = 11.658\n", "longitude_deg = 11.675\n");
    assert_ne!(good, broken, "W1 is where the test expects it");
    let path = dir.join("broken.toml");
    std::fs::write(&path, broken).unwrap();
    path
}

#[test]
fn the_demo_missions_are_feasible() {
    for m in ["missions/mission-1.toml", "missions/mission-2.toml"] {
        let o = gcs(&["validate", &repo(m)]);
        assert!(
            o.status.success(),
            "{m}: {}{}",
            text(&o.stdout),
            text(&o.stderr)
        );
        assert!(text(&o.stdout).contains("feasible: every check of the safety gateway passes"));
    }
}

#[test]
fn a_broken_copy_names_every_defect_and_fails() {
    let dir = scratch("names-every-defect");
    let broken = broken_mission(dir.path());
    let o = gcs(&["validate", broken.to_str().unwrap(), "--wind-mps", "14"]);
    assert_eq!(o.status.code(), Some(1));
    let out = text(&o.stdout);
    assert!(out.contains("GEO-NFZ-WP waypoint 2:"), "{out}");
    assert!(out.contains("ENV-WIND environment:"), "{out}");
    // W1 in the zone takes its turns into it too, deeper than the waypoint, each reported on
    // its own: onto the arc (flown over: no fly-by arc fits between those legs) and round
    // for a return to home.
    for turn in ["intercepting the leg to 3", "intercepting the leg to 1"] {
        assert!(
            out.contains(&format!("GEO-NFZ-LEG fly-over turn at waypoint 2 {turn}")),
            "{out}"
        );
    }
    // In that wind every turn is flown at (25 + 14)²/(g·tan 25°) = 331 m (ICD §7 "Turns in
    // wind"): the turn round at waypoint 3 for a return to home leaves the fly-zone, which the
    // same turn in calm air does not.
    assert!(
        out.contains("GEO-FZ-LEG fly-over turn at waypoint 3 intercepting the leg to 2"),
        "{out}"
    );
    assert!(
        out.contains("turns checked in a wind of 14 m/s from any direction"),
        "{out}"
    );
    let calm = text(&gcs(&["validate", broken.to_str().unwrap()]).stdout);
    assert!(!calm.contains("GEO-FZ-LEG"), "{calm}");
    assert!(
        text(&o.stderr).contains("infeasible: 7 violations"),
        "{}",
        text(&o.stderr)
    );

    let o = gcs(&["validate", broken.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_str(text(&o.stdout).trim()).unwrap();
    assert_eq!(v["feasible"], false);
    let codes: Vec<&str> = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["code"].as_str().unwrap())
        .collect();
    assert!(codes.contains(&"GEO-NFZ-WP"), "{codes:?}");
    let wp = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["code"] == "GEO-NFZ-WP")
        .unwrap();
    assert_eq!(wp["element"], "waypoint 2");
    assert!(wp["margin_m"].as_f64().unwrap() < 0.0);
}

#[test]
fn upload_refuses_an_infeasible_mission_and_sends_nothing() {
    // Nothing may arrive on the FCC's links.
    let fcc = SilentFcc::bind();
    let dir = scratch("upload-refuses");
    let broken = broken_mission(dir.path());
    let mut args = fcc.args();
    args.extend(["upload".to_owned(), broken.to_str().unwrap().to_owned()]);
    let o = gcs(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("the safety gateway refused the mission"),
        "{err}"
    );
    assert!(err.contains("GEO-NFZ-WP waypoint 2"), "{err}");
    assert!(err.contains("nothing was sent"), "{err}");
    fcc.assert_nothing_sent();
}

#[test]
fn the_map_marks_the_violations() {
    let dir = scratch("map-marks");
    let good = dir.path().join("good.svg");
    let o = gcs(&[
        "map",
        &repo("missions/mission-2.toml"),
        "-o",
        good.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let svg = std::fs::read_to_string(&good).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(!svg.contains("GEO-NFZ-WP"));

    let bad = dir.path().join("bad.svg");
    let broken = broken_mission(dir.path());
    let o = gcs(&["map", broken.to_str().unwrap(), "-o", bad.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("5 violations marked"),
        "{}",
        text(&o.stdout)
    );
    let svg = std::fs::read_to_string(&bad).unwrap();
    assert!(svg.contains("GEO-NFZ-WP"));
}

#[test]
fn convert_to_plan_and_geojson_and_validate_from_them() {
    let dir = scratch("convert");
    let plan = dir.path().join("mission-2.plan");
    let areas = dir.path().join("areas.geojson");
    let m2 = repo("missions/mission-2.toml");
    for out in [&plan, &areas] {
        let o = gcs(&["convert", &m2, out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    // The .plan carries the mission (radius-to-fix as track-to-fix, noted) and the areas come
    // from the GeoJSON with the safety offset given again.
    let o = gcs(&[
        "validate",
        plan.to_str().unwrap(),
        "--areas",
        areas.to_str().unwrap(),
        "--safety-offset-m",
        "25",
    ]);
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    assert!(
        text(&o.stdout).contains("3 waypoints"),
        "{}",
        text(&o.stdout)
    );
    assert!(text(&o.stdout).contains("3 areas"), "{}", text(&o.stdout));
}

#[test]
fn a_qgroundcontrol_plan_is_refused_for_what_it_cannot_fly_unless_dropped() {
    let ardu_plane = repo("missions/qgc/PX4SITL-ArduPlane.plan");
    let o = gcs(&["validate", &ardu_plane]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("\n  mission.items[3]: command 18 (NAV_LOITER_TURNS) is not supported\n"),
        "{err}"
    );
    assert!(err.contains("\n  mission.items[5]: command 31"), "{err}");
    assert!(err.contains("--drop unsupported"), "{err}");
    assert!(text(&o.stdout).is_empty(), "{}", text(&o.stdout));

    // Dropped knowingly: listed, and the verdict is about the rest. It has no geofence:
    // without areas it is not a valid mission.
    let o = gcs(&["validate", &ardu_plane, "--drop", "unsupported"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("PX4SITL-ArduPlane.plan: dropped: mission.items[3]: command 18"),
        "{err}"
    );
    assert!(
        err.contains("PX4SITL-ArduPlane.plan: dropped: mission.items[5]: command 31"),
        "{err}"
    );
    assert!(
        text(&o.stdout).contains("the area list is invalid (ICD §7): BadGeometry"),
        "{}",
        text(&o.stdout)
    );

    // A file that holds only a geofence is no mission: unusable input.
    let o = gcs(&["validate", &repo("missions/qgc/ce_geofence_home_base.plan")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("no waypoints"),
        "{}",
        text(&o.stderr)
    );
}

/// Demo mission 2 converted to a `.plan` in `dir`, as JSON to edit.
fn mission_2_plan(dir: &Path) -> serde_json::Value {
    let path = dir.join("converted.plan");
    let o = gcs(&[
        "convert",
        &repo("missions/mission-2.toml"),
        path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn write_json(dir: &Path, name: &str, value: &serde_json::Value) -> String {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(value).unwrap()).unwrap();
    path.to_str().unwrap().to_owned()
}

#[test]
fn a_return_to_launch_item_fails_validate_unless_dropped() {
    let dir = scratch("rtl");
    let mut plan = mission_2_plan(dir.path());
    let items = plan["mission"]["items"].as_array_mut().unwrap();
    let land = items.iter().position(|i| i["command"] == 21).unwrap();
    // MAV_CMD_NAV_RETURN_TO_LAUNCH before the land.
    items.insert(
        land,
        serde_json::json!({"type": "SimpleItem", "command": 20, "frame": 2,
                           "params": [0, 0, 0, 0, 0, 0, 0], "autoContinue": true}),
    );
    let path = write_json(dir.path(), "rtl.plan", &plan);
    let element =
        format!("mission.items[{land}]: command 20 (NAV_RETURN_TO_LAUNCH) is not supported");

    let o = gcs(&["validate", &path, "--safety-offset-m", "25"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains(&element), "{}", text(&o.stderr));

    // `--json`: unreadable, and the refused element.
    let o = gcs(&["validate", &path, "--json"]);
    assert_eq!(o.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_str(text(&o.stdout).trim()).unwrap();
    assert_eq!(v["readable"], false);
    assert_eq!(v["refused"][0]["path"], format!("mission.items[{land}]"));

    // Every command that reads a plan refuses it the same way, upload before it sends.
    let out = dir.path().join("out.svg");
    let toml = dir.path().join("out.toml");
    for args in [
        vec!["map", &path, "-o", out.to_str().unwrap()],
        vec!["convert", &path, toml.to_str().unwrap()],
        vec![
            "--fcc-direct",
            "127.0.0.1:9",
            "--fcc-lte",
            "127.0.0.1:9",
            "--gcs-direct",
            "127.0.0.1:0",
            "--gcs-lte",
            "127.0.0.1:0",
            "upload",
            &path,
        ],
    ] {
        let o = gcs(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains(&element),
            "{args:?}: {}",
            text(&o.stderr)
        );
    }
    assert!(!out.exists() && !toml.exists());

    // Dropped knowingly: listed on stderr, and the verdict is the mission's (feasible).
    let o = gcs(&[
        "validate",
        &path,
        "--safety-offset-m",
        "25",
        "--drop",
        "unsupported",
    ]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{}{err}", text(&o.stdout));
    assert!(
        err.contains(&format!("rtl.plan: dropped: {element}")),
        "{err}"
    );
    assert_eq!(err.matches("dropped:").count(), 1, "{err}");
    assert!(text(&o.stdout).contains("feasible"), "{}", text(&o.stdout));

    let o = gcs(&[
        "validate",
        &path,
        "--safety-offset-m",
        "25",
        "--drop",
        "unsupported",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&o.stdout).trim()).unwrap();
    assert_eq!(v["feasible"], true);
    assert_eq!(v["violations"], serde_json::json!([]));
    assert_eq!(v["dropped"][0]["path"], format!("mission.items[{land}]"));
    assert_eq!(
        v["dropped"][0]["reason"],
        "command 20 (NAV_RETURN_TO_LAUNCH) is not supported"
    );
    assert_eq!(v["take_off_position"], serde_json::json!([48.275, 11.645]));

    // The same verdict by exit status when the rest is infeasible: 1.
    let o = gcs(&[
        "validate",
        &path,
        "--safety-offset-m",
        "25",
        "--drop",
        "unsupported",
        "--wind-mps",
        "30",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stdout));

    // An unknown value of --drop is a bad flag.
    let o = gcs(&["validate", &path, "--drop", "everything"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_second_fly_zone_or_an_eleventh_no_fly_zone_is_refused_by_name() {
    let dir = scratch("fence-capacity");
    let mut plan = mission_2_plan(dir.path());
    let square = |lat: f64, lon: f64, inclusion: bool| {
        serde_json::json!({"inclusion": inclusion, "version": 1, "polygon": [
            [lat, lon], [lat, lon + 0.001], [lat + 0.001, lon + 0.001], [lat + 0.001, lon]]})
    };

    let mut two = plan.clone();
    two["geoFence"]["polygons"]
        .as_array_mut()
        .unwrap()
        .push(square(48.26, 11.65, true));
    let path = write_json(dir.path(), "two-fly-zones.plan", &two);
    let o = gcs(&["validate", &path]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains(
            "\n  geoFence.polygons[2]: a second inclusion polygon: the ICD has one fly-zone \
             (geoFence.polygons[0])\n"
        ),
        "{}",
        text(&o.stderr)
    );

    // Ten exclusion polygons (the demo's one and nine more) and one circle: the circle is the
    // eleventh no-fly-zone.
    let polygons = plan["geoFence"]["polygons"].as_array_mut().unwrap();
    for k in 0..9 {
        polygons.push(square(48.257, 11.637 + 0.002 * f64::from(k), false));
    }
    let path = write_json(dir.path(), "eleven.plan", &plan);
    let o = gcs(&["validate", &path]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "\n  geoFence.circles[0]: more than 10 no-fly-zones (polygons and circles): the FCC \
             holds 11 areas, one of them the fly-zone\n"
        ),
        "{err}"
    );
    let o = gcs(&["validate", &path, "--drop", "unsupported", "--json"]);
    let v: serde_json::Value = serde_json::from_str(text(&o.stdout).trim()).unwrap();
    assert_eq!(v["dropped"][0]["path"], "geoFence.circles[0]");
    assert!(
        v["summary"].as_str().unwrap().contains("11 areas"),
        "{}",
        v["summary"]
    );
}

#[test]
fn the_take_off_position_survives_toml_to_plan_to_toml() {
    let dir = scratch("take-off-round-trip");
    let plan = dir.path().join("mission-1.plan");
    let back = dir.path().join("mission-1.toml");
    let o = gcs(&[
        "convert",
        &repo("missions/mission-1.toml"),
        plan.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // TROL is the take-off item's position and the planned home; CCP the waypoint.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&plan).unwrap()).unwrap();
    let take_off = &json["mission"]["items"][0];
    assert_eq!(take_off["command"], 22);
    assert_eq!(take_off["params"][4], 48.26);
    assert_eq!(take_off["params"][5], 11.66);
    assert_eq!(
        json["mission"]["plannedHomePosition"],
        serde_json::json!([48.26, 11.66, 0.0])
    );

    let o = gcs(&["convert", plan.to_str().unwrap(), back.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let toml = std::fs::read_to_string(&back).unwrap();
    assert!(
        toml.contains("\ntake_off_position = [48.26, 11.66]\n"),
        "{toml}"
    );
    let o = gcs(&["validate", back.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(text(&o.stdout).trim()).unwrap();
    assert_eq!(v["take_off_position"], serde_json::json!([48.26, 11.66]));
}

#[test]
fn exit_status_two_is_for_input_that_cannot_be_read() {
    let dir = scratch("exit-two");
    let missing = dir.path().join("no-such-mission.toml");
    let o = gcs(&["validate", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "take_off_height_m = \n").unwrap();
    let o = gcs(&["validate", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("line 1, column"),
        "{}",
        text(&o.stderr)
    );
    let o = gcs(&[
        "validate",
        &repo("missions/mission-2.toml"),
        "--profile",
        missing.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    let o = gcs(&["validate", "--frobnicate", &repo("missions/mission-2.toml")]);
    assert_eq!(o.status.code(), Some(2));
    // The help documents the statuses.
    let o = gcs(&["validate", "--help"]);
    let help = text(&o.stdout);
    assert!(help.contains("Exit status:"), "{help}");
    assert!(help.contains("2  unreadable input"), "{help}");
    assert!(help.contains("--drop <WHAT>"), "{help}");
}

/// Area defects (ICD §7) are violations of the safety gateway. Demo mission 2 with its fly-zone
/// taken out and its polygonal no-fly-zone cut to two vertices: `--json` names both defects with
/// their area, and the verdict is infeasible (exit 1), the ICD reason beside them.
#[test]
fn a_plan_without_a_fly_zone_lists_area_violations_with_the_area() {
    let dir = scratch("no-fly-zone");
    let good = std::fs::read_to_string(repo("missions/mission-2.toml")).unwrap();
    // The [[areas]] tables: drop the first (the fly-zone, area 1), keep the circle (area 2), and
    // keep only the first two vertices of the polygon (area 3).
    let (head, areas) = good.split_once("[[areas]]").unwrap();
    let tables: Vec<&str> = areas.split("[[areas]]").collect();
    assert!(tables[0].contains("fly-zone"), "{}", tables[0]);
    let polygon = tables[2];
    let start = polygon.find("polygon = [").unwrap();
    let first_two: Vec<&str> = polygon[start..]
        .lines()
        .skip(1)
        .filter(|l| l.trim_start().starts_with('['))
        .take(2)
        .collect();
    let cut = format!(
        "{}polygon = [\n{}\n]\n",
        &polygon[..start],
        first_two.join("\n")
    );
    let file = format!("{head}[[areas]]{}[[areas]]{cut}", tables[1]);
    let path = dir.path().join("no-fly-zone.toml");
    std::fs::write(&path, file).unwrap();
    let o = gcs(&["validate", path.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", text_of(&o));
    let v: serde_json::Value = serde_json::from_str(text(&o.stdout).trim()).unwrap();
    assert_eq!(v["feasible"], false);
    let found: Vec<(String, String)> = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| {
            (
                x["code"].as_str().unwrap().to_owned(),
                x["element"].as_str().unwrap().to_owned(),
            )
        })
        .collect();
    assert!(
        found.contains(&("AREA-FZ-COUNT".into(), "area list".into())),
        "{found:?}"
    );
    assert!(
        found.contains(&("AREA-VERTEX-COUNT".into(), "area 3".into())),
        "{found:?}"
    );
    assert!(v["error"].as_str().unwrap().contains("BadGeometry"), "{v}");
}
