//! `gcs mavlink` against MAVLink clients that no one here wrote: the real FCC (launcher and
//! partitions), the GCS link with the safety gateway, the bridge's driver on a UDP port the
//! system chooses, and a Python client in a child process (`tests/clients/`, packages from
//! partitions/python/requirements.txt, installed by tools/test). The client's checks are its
//! own; this test passes when it exits with status 0, and prints what it said.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

mod common;

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use common::*;
use missionlink_gcs::gcs_link::GcsLink;
use missionlink_gcs::mavlink::bridge::{Bridge, BridgeConfig};
use missionlink_gcs::mavlink::driver::{self, MavlinkSocket};
use missionlink_gcs::mavlink::plan::PlanContext;
use missionlink_gcs::qgc::ImportOptions;
use missionlink_services::safety_gateway::SafetyGateway;

fn script(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/clients")
        .join(name)
}

/// Runs `script` against a bridge to a fresh FCC; its output, after asserting it passed.
fn run_client(test: &str, script_name: &str) -> String {
    let mut rig = Rig::new(test);
    // Slow enough that the flight lasts several seconds of the 2 Hz downlink.
    rig.config.guidance.time_scale = 10.0;
    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    let links = rig.gcs_links(&mut fcc);
    let mut link = GcsLink::with_links(&rig.config.link(), links, SafetyGateway::default())
        .unwrap()
        .with_stamp_lease(&rig.dir.join("gcs-time-stamps"))
        .unwrap();
    let mut bridge = Bridge::new(BridgeConfig {
        heartbeat: Duration::from_secs(1),
        item_timeout: Duration::from_millis(1500),
        item_retries: 3,
        fence_wait: Duration::from_secs(3),
        plan: PlanContext {
            cruise_speed_mps: 25.0,
            home: None,
            import: ImportOptions::default(),
        },
    });
    // QGroundControl is not listening in a test: the bridge answers the client that talks.
    let mut socket = MavlinkSocket::bind(
        "127.0.0.1:0".parse().unwrap(),
        "127.0.0.1:9".parse().unwrap(),
    )
    .unwrap();
    let port = socket.local_addr().unwrap().port();
    let child = Command::new(python())
        .arg(script(script_name))
        .arg(port.to_string())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{:?}: {e}; run the tests with tools/test", python()));
    let stop = Arc::new(AtomicBool::new(false));
    let waiter = {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || {
            let out = child.wait_with_output().unwrap();
            stop.store(true, Ordering::Relaxed);
            out
        })
    };
    driver::read_lists(&mut link, &mut bridge);
    driver::run(&mut link, &mut bridge, &mut socket, &stop).unwrap();
    let out = waiter.join().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{script_name} failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    fcc.stop().unwrap();
    stdout
}

#[test]
fn pymavlink_uploads_downloads_is_refused_and_follows_the_flight_to_its_end() {
    let out = run_client("mavlink-pymavlink", "pymavlink_mission.py");
    assert!(out.contains("downloaded: equal to the upload"), "{out}");
    assert!(out.contains("infeasible mission refused"), "{out}");
    // The violation, named by the safety gateway, reached the client in the STATUSTEXT.
    assert!(out.contains("inside no-fly-zone"), "{out}");
    assert!(out.contains("clear while flying refused"), "{out}");
    assert!(out.contains("mission complete on item 2 of 3"), "{out}");
    assert!(out.contains("reached [0, 1, 2]"), "{out}");
    assert!(out.contains("'MISSION'"), "{out}");
    // The client checked the target of every reply; it saw some.
    assert!(out.contains("every one addressed to 255/190"), "{out}");
}

#[test]
fn mavsdk_uploads_with_mission_raw_starts_and_sees_progress_and_positions() {
    let out = run_client("mavlink-mavsdk", "mavsdk_mission.py");
    assert!(out.contains("started"), "{out}");
    assert!(out.contains("distinct"), "{out}");
    assert!(
        out.contains("flight modes: ") && out.contains("'MISSION'"),
        "{out}"
    );
}

/// MAVProxy, unmodified, with its own system and component IDs: it takes mission requests
/// only when addressed to itself, so its upload proves the bridge answers whoever asked.
#[test]
fn mavproxy_loads_a_qgc_wpl_mission_and_fence_and_lists_it() {
    let out = run_client("mavlink-mavproxy", "mavproxy_mission.py");
    assert!(out.contains("fence uploaded"), "{out}");
    assert!(out.contains("wp list: equal to the upload"), "{out}");
    assert!(out.contains("wp clear: the FCC holds no mission"), "{out}");
}
