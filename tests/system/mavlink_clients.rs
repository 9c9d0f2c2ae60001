//! `gcs mavlink` against MAVLink clients that no one here wrote: the real FCC (launcher and
//! partitions), the GCS link with the safety gateway, the vehicle's driver on a UDP port the
//! system chooses, and a Python client in a child process (`tests/clients/`, packages from
//! partitions/python/requirements.txt, installed by tools/test). The client's checks are its
//! own; this test passes when it exits with status 0, and prints what it said.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use missionlink::harness::*;
use missionlink_gcs::gcs_link::GcsLink;
use missionlink_gcs::mavlink::driver::{self, MavlinkSocket};
use missionlink_gcs::mavlink::vehicle::{Vehicle, VehicleConfig};
use missionlink_ground::safety_gateway::SafetyGateway;

fn script(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/clients")
        .join(name)
}

/// A fresh FCC and the ground's link to it, for the vehicle to serve clients over.
struct Session {
    rig: Rig,
    fcc: Process,
    link: GcsLink<SafetyGateway>,
}

impl Session {
    fn new(test: &str) -> Self {
        let mut rig = Rig::new(test);
        // Slow enough that the flight lasts several seconds of the 2 Hz downlink.
        rig.config.guidance.time_scale = 10.0;
        let mut fcc = rig.start("fcc");
        rig.ready(&mut fcc);
        let links = rig.gcs_links(&mut fcc);
        let link = GcsLink::with_links(&rig.config.link(), links, SafetyGateway::default())
            .unwrap()
            .with_stamp_lease(&rig.dir.join("gcs-time-stamps"))
            .unwrap();
        Self { rig, fcc, link }
    }

    /// The vehicle's memory, in the state directory as `gcs mavlink` keeps it.
    fn memory(&self) -> PathBuf {
        self.rig.dir.join("mavlink-memory")
    }

    /// The session's capture.
    fn tlog(&self) -> PathBuf {
        self.rig.dir.join("session.tlog")
    }

    /// Starts a vehicle as `gcs mavlink` does (the FCC's lists read, then its memory) and runs
    /// `script` with `args` against it until the script exits; its output, after asserting it
    /// passed.
    fn serve(&mut self, script_name: &str, args: &[&str]) -> String {
        let mut vehicle = Vehicle::new(VehicleConfig::standard(
            missionlink_gcs::mavlink::vehicle::SYSTEM_ID,
            Duration::from_secs(3),
            25.0,
        ));
        // QGroundControl is not listening in a test: the vehicle answers the client that talks.
        let socket = MavlinkSocket::bind(
            "127.0.0.1:0".parse().unwrap(),
            "127.0.0.1:9".parse().unwrap(),
        )
        .unwrap()
        .with_tlog(&self.tlog())
        .unwrap();
        let port = socket.local_addr().unwrap().port();
        let child = Command::new(python())
            .arg(script(script_name))
            .arg(port.to_string())
            .args(args)
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
        let memory = self.memory();
        driver::read_lists(&mut self.link, &mut vehicle, Some(&memory));
        driver::run(&mut self.link, &mut vehicle, &socket, Some(&memory), &stop).unwrap();
        let out = waiter.join().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&out.stderr);
        println!("{stdout}");
        assert!(
            out.status.success(),
            "{script_name} failed ({}):\n{stdout}\n{stderr}",
            out.status
        );
        stdout
    }

    fn stop(mut self) {
        self.fcc.stop().unwrap();
    }
}

/// Runs `script` against a vehicle to a fresh FCC; its output, after asserting it passed.
fn run_client(test: &str, script_name: &str) -> String {
    let mut session = Session::new(test);
    let out = session.serve(script_name, &[]);
    session.stop();
    out
}

/// The message types the vehicle sent in a capture, and how many named system 0 as target,
/// read by pymavlink.
fn captured(tlog: &std::path::Path) -> (Vec<String>, usize) {
    let out = Command::new(python())
        .arg(script("tlog_messages.py"))
        .arg(tlog)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let kinds = text
        .lines()
        .next()
        .and_then(|l| l.split(": ").nth(1))
        .unwrap_or_default()
        .split(' ')
        .map(str::to_owned)
        .collect();
    let zero = text
        .lines()
        .find_map(|l| l.strip_prefix("addressed to system 0: "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap();
    (kinds, zero)
}

#[test]
fn pymavlink_uploads_downloads_is_refused_and_follows_the_flight_to_its_end() {
    let mut session = Session::new("mavlink-pymavlink");
    let out = session.serve("pymavlink_mission.py", &[]);
    // The session's capture, read by pymavlink: the telemetry a ground station asks for, and
    // no reply addressed to system 0.
    let (kinds, to_system_0) = captured(&session.tlog());
    for kind in [
        "HEARTBEAT",
        "HOME_POSITION",
        "SYS_STATUS",
        "EXTENDED_SYS_STATE",
        "ATTITUDE",
        "VFR_HUD",
        "GLOBAL_POSITION_INT",
        "MISSION_CURRENT",
        "MISSION_ITEM_REACHED",
    ] {
        assert!(kinds.iter().any(|k| k == kind), "no {kind} in {kinds:?}");
    }
    assert_eq!(to_system_0, 0);
    session.stop();
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

/// `gcs mavlink` restarted between an upload and a download (as it starts again: the
/// FCC's lists read, then its memory): the download returns the take-off and waypoints the
/// client uploaded, not the FCC's lists read back as items.
#[test]
fn a_restarted_gcs_mavlink_returns_what_the_client_uploaded() {
    let mut session = Session::new("mavlink-restart");
    let out = session.serve("pymavlink_mission.py", &["upload"]);
    assert!(out.contains("mission and fence active"), "{out}");
    assert!(session.memory().exists());
    let out = session.serve("pymavlink_mission.py", &["download"]);
    assert!(
        out.contains("after the restart, downloaded: equal"),
        "{out}"
    );
    session.stop();
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

/// MAVSDK's plugins as a script writer uses them: Telemetry, Geofence, Mission (a refusal
/// with its reason in `status_text`, an upload downloaded equal, progress to
/// `is_mission_finished`), Action, and the clears.
#[test]
fn mavsdk_plugins_upload_fly_and_clear() {
    let out = run_client("mavlink-mavsdk-plugins", "mavsdk_plugins.py");
    assert!(out.contains("stopping at waypoints refused"), "{out}");
    assert!(out.contains("downloaded: equal to the upload"), "{out}");
    assert!(out.contains("mission finished"), "{out}");
    assert!(out.contains("the FCC holds no mission"), "{out}");
}

/// MAVProxy, unmodified, with its own system and component IDs: it takes mission requests
/// only when addressed to itself, so its upload proves the vehicle answers whoever asked.
#[test]
fn mavproxy_loads_a_qgc_wpl_mission_and_fence_and_lists_it() {
    let out = run_client("mavlink-mavproxy", "mavproxy_mission.py");
    assert!(out.contains("fence uploaded"), "{out}");
    assert!(out.contains("wp list: equal to the upload"), "{out}");
    assert!(out.contains("wp clear: the FCC holds no mission"), "{out}");
}
