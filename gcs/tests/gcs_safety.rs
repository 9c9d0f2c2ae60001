//! The safety gateway as the operator meets it: `gcs validate`, `gcs upload` refusing an
//! infeasible mission without sending anything, `gcs map`, `gcs convert`, and missions from
//! QGroundControl.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

fn gcs(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gcs"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("gcs runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(path)
        .display()
        .to_string()
}

/// A directory of the test's own, named after the test (and unique to this process and run), removed
/// when dropped: tests run in parallel, so no two may share a file name.
fn scratch(test: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gcs-safety-{test}-{}-", std::process::id()))
        .tempdir()
        .unwrap()
}

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
    assert!(
        text(&o.stderr).contains("infeasible: 4 violations"),
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
    // Two sockets stand in for the FCC's links: nothing may arrive on them.
    let direct = UdpSocket::bind("127.0.0.1:0").unwrap();
    let lte = UdpSocket::bind("127.0.0.1:0").unwrap();
    let dir = scratch("upload-refuses");
    let broken = broken_mission(dir.path());
    let o = gcs(&[
        "--fcc-direct",
        &direct.local_addr().unwrap().to_string(),
        "--fcc-lte",
        &lte.local_addr().unwrap().to_string(),
        "--gcs-direct",
        "127.0.0.1:0",
        "--gcs-lte",
        "127.0.0.1:0",
        "upload",
        broken.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("the safety gateway refused the mission"),
        "{err}"
    );
    assert!(err.contains("GEO-NFZ-WP waypoint 2"), "{err}");
    assert!(err.contains("nothing was sent"), "{err}");
    for s in [&direct, &lte] {
        s.set_read_timeout(Some(Duration::from_millis(200)))
            .unwrap();
        let mut buf = [0u8; 600];
        assert!(s.recv_from(&mut buf).is_err(), "a frame was sent");
    }
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
        text(&o.stdout).contains("3 violations marked"),
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
fn a_qgroundcontrol_plan_reports_what_it_cannot_fly_item_by_item() {
    let o = gcs(&["validate", &repo("missions/qgc/PX4SITL-ArduPlane.plan")]);
    let err = text(&o.stderr);
    assert!(err.contains("note: mission.items[3]: command 18"), "{err}");
    assert!(err.contains("note: mission.items[5]: command 31"), "{err}");
    // It has no geofence: without areas it is not a valid mission.
    assert_eq!(o.status.code(), Some(1));
    assert!(
        err.contains("the area list is invalid (ICD §7): BadGeometry"),
        "{err}"
    );
    let o = gcs(&["validate", &repo("missions/qgc/ce_geofence_home_base.plan")]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o.stderr).contains("no waypoints"),
        "{}",
        text(&o.stderr)
    );
}
