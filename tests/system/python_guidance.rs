//! The guidance partition in Python (partitions/python/missionlink_guidance.py) in place of the
//! Rust guidance stub (docs/deployment.md, "The Python guidance"):
//!
//! - **End to end**: the FCC started without its stub (`fcc --without guidance-stub`), the
//!   Python guidance started with the test's service prefix, mission 1 uploaded and executed by
//!   the real GCS over UDP: FROM-TO-NEXT reaches the GCS through mission data handling, from
//!   progress the Python process published; the launcher hears its heartbeat, and a Rust
//!   subscriber reads its heartbeat and progress with the Rust payload types.
//! - **Same kinematics**: the Python model and `missionlink_flight::guidance` fly demo missions 1 and 2
//!   (and mission 2 with return to home and with land-at, a route through mission 2's
//!   no-fly-zones and out of its fly-zone, and mission 2 planned for and flown in a 12 m/s wind,
//!   ICD §7 "Turns in wind") from the same lists, each in its own process but in simulated
//!   time: the same steps of 100 ms, the same scripted system automation (execute, then the
//!   next phase whenever guidance reports the current one complete). The FROM-TO-NEXT
//!   sequences must be equal; steps, flags, zones, ground speeds, positions, heading, bank,
//!   pitch and climb rate are compared too. Simulated time makes this exact and independent of the machine's load, which flying
//!   both time-scaled through the FCC would not be.
//!
//! Both need a Python 3 with the packages of partitions/python/requirements.txt: the one
//! `tools/test` sets up in `target/venv` (`harness::python`); without them they fail and say how
//! to get them, never skip.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use iceoryx2::prelude::ipc;
use missionlink::harness::fcc::FccProcess;
use missionlink::harness::*;
use missionlink_flight::guidance::{Guidance, GuidanceConfig};
use missionlink_ground::ground_station::GcsError;
use missionlink_interfaces::contracts::{
    AreaAltitudes, AreaListPayload, AutomationStatePayload, CircleArea, FccService, FlightPhase,
    GuidanceProgressPayload, HeartbeatPayload, Partition, PolygonArea, WaypointEntry,
    WaypointListPayload,
};
use missionlink_interfaces::wire::{self, GeoPoint, Speed};
use missionlink_partitions::ipc::Ipc;
use missionlink_protocol::geofence::earth::{Site, distance_m};
use missionlink_protocol::link::time::Instant as SimInstant;
use serde_json::{Value, json};

/// Bound of every wait (a failure bound, never a timing assertion).
const LIMIT: Duration = Duration::from_secs(60);

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn guidance_script() -> PathBuf {
    python_guidance_script()
}

/// Fails, saying what to install, unless `python3` runs and imports the Python guidance's
/// requirements (iceoryx2 0.10.0, geographiclib).
fn require_python() {
    const HOW: &str = "run the tests with tools/test, which installs the Python guidance's \
                       packages (partitions/python/requirements.txt) into target/venv";
    let out = Command::new(python())
        .arg("-c")
        .arg(
            "import importlib.metadata as m, iceoryx2, geographiclib.geodesic\n\
             print(m.version('iceoryx2'))",
        )
        .output();
    let out = match out {
        Ok(out) => out,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            panic!(
                "{:?} is not installed; the Python guidance tests need it: {HOW}",
                python()
            )
        }
        Err(e) => panic!("cannot run python3: {e}"),
    };
    assert!(
        out.status.success(),
        "{:?} cannot import the Python guidance's packages:\n{}\n{HOW}",
        python(),
        String::from_utf8_lossy(&out.stderr)
    );
    let version = String::from_utf8_lossy(&out.stdout).trim().to_owned();
    assert_eq!(
        version, "0.10.0",
        "the Python guidance needs iceoryx2 0.10.0 (the Rust crate's release), found {version}: \
         {HOW}"
    );
}

// ---------------------------------------------------------------------------------------------
// End to end
// ---------------------------------------------------------------------------------------------

/// The Python guidance as a child process, its log (stderr) in a file; stopped with SIGTERM
/// when dropped.
struct PythonGuidance {
    child: Child,
    log: PathBuf,
}

impl PythonGuidance {
    /// Starts it under the rig's prefix, time scale, start position, rates and heartbeat period.
    fn start(rig: &Rig) -> Self {
        let log = rig.dir.join("guidance-py.log");
        let child = python_guidance_command(&rig.config)
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start python3 {:?}: {e}", guidance_script()));
        Self { child, log }
    }

    fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    /// Waits until its log says `text`, or panics (also when it ended).
    fn wait_for_log(&mut self, text: &str) {
        let end = Instant::now() + LIMIT;
        while Instant::now() < end {
            if self.log_text().contains(text) {
                return;
            }
            if let Some(status) = self.child.try_wait().unwrap() {
                panic!(
                    "the Python guidance ended ({status}) before logging {text:?}:\n{}",
                    self.log_text()
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        panic!(
            "the Python guidance never logged {text:?}:\n{}",
            self.log_text()
        );
    }

    /// SIGTERM, then its exit status (SIGKILL after the limit).
    fn stop(&mut self) -> std::process::ExitStatus {
        if let Some(status) = self.child.try_wait().unwrap() {
            return status;
        }
        let pid = rustix::process::Pid::from_raw(self.child.id() as i32).unwrap();
        let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
        let end = Instant::now() + LIMIT;
        while Instant::now() < end {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        self.child.wait().unwrap()
    }
}

impl Drop for PythonGuidance {
    fn drop(&mut self) {
        self.stop();
    }
}

#[test]
fn the_python_guidance_replaces_the_stub_and_from_to_next_reaches_the_gcs() {
    require_python();
    let started = Instant::now();
    let mut rig = Rig::new("python-guidance");
    let mut command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    command.args(["--without", "guidance-stub"]);
    let mut fcc = FccProcess::spawn(command, &rig.config, Some(&rig.dir.join("fcc.log"))).unwrap();
    rig.ready(&mut fcc);
    let mut guidance = PythonGuidance::start(&rig);
    guidance.wait_for_log("guidance up");
    let pid = guidance.child.id();

    // The launcher hears the heartbeat of a guidance it did not start.
    wait_for_log(
        &fcc,
        &format!("alive (not started by the launcher) partition=guidance pid={pid}"),
        LIMIT,
    );
    assert!(
        !fcc.log_text()
            .contains("started partition=\"guidance-stub\""),
        "the stub was left out:\n{}",
        fcc.log_text()
    );

    missionlink_partitions::ipc::quiet_iceoryx2_log();
    // A Rust subscriber reads the Python publications with the Rust payload types (iceoryx2
    // refuses to open a service whose type name, size or alignment differ).
    let watch = Ipc::<ipc::Service>::open("python-watch", &rig.config.ipc).unwrap();
    let heartbeats = watch
        .subscriber::<HeartbeatPayload>(FccService::Heartbeat(Partition::Guidance))
        .unwrap();
    let progress = watch
        .subscriber::<GuidanceProgressPayload>(FccService::GuidanceProgress)
        .unwrap();
    let beat =
        eventually(LIMIT, || heartbeats.latest()).expect("a heartbeat from the Python guidance");
    assert_eq!(beat.pid, pid);
    assert_eq!(
        beat.period_ns,
        rig.config.health.period_ms * 1_000_000,
        "{beat:?}"
    );
    assert!(beat.sequence >= 1, "{beat:?}");
    let idle = eventually(LIMIT, || progress.latest()).expect("progress from the Python guidance");
    assert!(
        idle.on_ground && idle.from_to_next() == (0, 0, 0),
        "{idle:?}"
    );
    assert_eq!(
        (idle.latitude_deg, idle.longitude_deg),
        (48.26, 11.66),
        "at TROL"
    );

    // Upload and execute mission 1 (TROL -> CCP); execute is refused (WrongState) until
    // automation has heard guidance alive and mission data handling has its position.
    let mut link = rig.gcs(&mut fcc);
    upload(&mut link, &plan("mission-1.toml")).unwrap();
    let mut seen: Vec<(u16, u16, u16)> = Vec::new();
    let mut refusals = 0;
    loop {
        let now = link.now();
        link.station()
            .execute(now, wire::ExecuteCommand::Execute)
            .unwrap();
        match link.finish(|event| record(&mut seen, event)) {
            Ok(_) => break,
            Err(GcsError::Transfer { error, .. })
                if error.reason() == Some(wire::Reason::WrongState)
                    && started.elapsed() < LIMIT =>
            {
                refusals += 1;
                std::thread::sleep(Duration::from_millis(100));
            }
            Err(e) => panic!("execute: {e}\n{}", guidance.log_text()),
        }
    }

    // FROM-TO-NEXT at the GCS: climbing and cruising to CCP (0, 1, 0), there (1, 0, 0), and
    // after the landing nothing flown (0, 0, 0). Each lasts many progress samples, so none is
    // missed however late a process is scheduled. Before the flight the FCC may report the new
    // lists' "nothing flown" (0, 0, 0), when guidance's first progress on them comes after the
    // upload ended: not part of the flight.
    let flown = |seen: &[(u16, u16, u16)]| -> Vec<(u16, u16, u16)> {
        seen.iter()
            .copied()
            .skip_while(|t| *t == (0, 0, 0))
            .collect()
    };
    let landed = link.run_until(LIMIT, |event| {
        record(&mut seen, event);
        flown(&seen).len() >= 3
    });
    assert!(
        landed,
        "FROM-TO-NEXT at the GCS: {seen:?}\n{}",
        guidance.log_text()
    );
    assert_eq!(flown(&seen), [(0, 1, 0), (1, 0, 0), (0, 0, 0)]);
    let at_ccp = |p: &GuidanceProgressPayload| {
        p.on_ground
            && p.waypoint_list == 1
            && (p.latitude_deg - 48.275).abs() < 1e-6
            && (p.longitude_deg - 11.645).abs() < 1e-6
    };
    eventually(LIMIT, || progress.latest().filter(at_ccp)).expect("progress: landed at CCP");

    // SIGTERM ends it cleanly.
    let status = guidance.stop();
    assert!(status.success(), "{status}\n{}", guidance.log_text());
    assert!(guidance.log_text().contains("guidance stopping"));
    println!(
        "python guidance end to end: execute refused {refusals} times (WrongState) before \
         guidance was alive and had reported; FROM-TO-NEXT at the GCS {seen:?}; {:.1} s in all",
        started.elapsed().as_secs_f64()
    );
}

// ---------------------------------------------------------------------------------------------
// The same kinematics: Rust and Python flying the same lists in simulated time
// ---------------------------------------------------------------------------------------------

/// Real time between steps.
const STEP: Duration = Duration::from_millis(100);
/// Steps at most per flight.
const MAX_STEPS: usize = 20_000;
/// No wind: (speed m/s, from degrees).
const CALM: (f64, f64) = (0.0, 0.0);
/// How far apart the two models' ground speeds may be in wind, m/s. In calm air the ground
/// speed is the TO waypoint's speed, and the two agree exactly. In wind it is a function of the
/// course at the aircraft's position, and the positions differ in their last bits (the two
/// geodesic libraries round differently: the positions' micrometre below), so the speeds do
/// too (by about 1e-9 m/s at most on these flights). A speed this far off moves the aircraft a
/// nanometre further in a step, a thousandth of the positions' tolerance.
const SPEED_IN_WIND_MPS: f64 = 1e-8;
/// How far apart the two models' heading, bank, pitch (degrees) and climb rate (m/s) may be.
/// Each is computed in double precision from the same positions and altitudes (within a
/// micrometre of each other), then rounded to the payload's `f32`, whose step is 3e-5 deg at
/// 360 deg: on these flights they are equal or one step apart (4e-6 deg at 100 deg).
const ATTITUDE_TOLERANCE: [f64; 4] = [1e-4, 1e-4, 1e-4, 1e-5];
/// The names of the attitude values, for the failures.
const ATTITUDE: [&str; 4] = ["heading", "roll", "pitch", "climb rate"];

/// A flight: the lists, where it starts, and what automation commands on the way.
struct Scenario {
    name: &'static str,
    waypoints: WaypointListPayload,
    areas: AreaListPayload,
    start: (f64, f64),
    /// Set `land_at` to this waypoint when cruise starts (0: never).
    land_at: u16,
    /// Set `route_reversed` (return to home) when guidance first reports this triple in
    /// cruise.
    return_home_at: Option<(u16, u16, u16)>,
    /// The steady wind both models fly in: speed (m/s) and the direction it blows from
    /// (degrees); the turns are sized by the list's `planning_wind` (ICD §7 "Turns in wind").
    wind: (f64, f64),
}

/// What one step reported, as both sides print it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Record {
    triple: (u16, u16, u16),
    /// climb_complete, route_complete, on_ground.
    flags: (bool, bool, bool),
    latitude: f64,
    longitude: f64,
    altitude: f64,
    speed: f64,
    /// inside_fly_zone, in_no_fly_zone.
    zones: (bool, u16),
    /// heading, roll, pitch (degrees) and climb rate (m/s): the payload's `f32`s, NaN when not
    /// known.
    attitude: [f64; 4],
}

impl Record {
    fn of(p: &GuidanceProgressPayload) -> Self {
        Self {
            triple: p.from_to_next(),
            flags: (p.climb_complete, p.route_complete, p.on_ground),
            latitude: p.latitude_deg,
            longitude: p.longitude_deg,
            altitude: p.altitude_m,
            speed: p.ground_speed_mps,
            zones: (p.inside_fly_zone, p.in_no_fly_zone),
            attitude: [p.heading_deg, p.roll_deg, p.pitch_deg, p.climb_rate_mps].map(f64::from),
        }
    }

    fn parse(line: &Value) -> Self {
        let v = line.as_array().unwrap();
        let n = |i: usize| v[i].as_u64().unwrap() as u16;
        let b = |i: usize| v[i].as_bool().unwrap();
        // The floats come as text: serde_json's own float parsing may be an ulp off (without
        // its `float_roundtrip` feature), the standard library's is exact.
        let f = |i: usize| v[i].as_str().unwrap().parse::<f64>().unwrap();
        Self {
            triple: (n(0), n(1), n(2)),
            flags: (b(3), b(4), b(5)),
            latitude: f(6),
            longitude: f(7),
            altitude: f(8),
            speed: f(9),
            zones: (b(10), n(11)),
            // `nan` parses as NaN.
            attitude: [f(12), f(13), f(14), f(15)],
        }
    }
}

/// The scripted system automation both sides run: execute at once, then the next phase when
/// guidance reports the current one complete; the scenario's commands on the way. Returns
/// whether the state changed and whether the flight is over (landed).
fn automate(
    s: &Scenario,
    state: &mut AutomationStatePayload,
    p: &GuidanceProgressPayload,
) -> (bool, bool) {
    let before = *state;
    let mut landed = false;
    match state.flight_phase() {
        Some(FlightPhase::TakeOff) if p.climb_complete => {
            state.flight_phase = FlightPhase::Cruise as u8;
            state.land_at = s.land_at;
        }
        Some(FlightPhase::Cruise)
            if s.return_home_at == Some(p.from_to_next()) && !state.route_reversed =>
        {
            state.route_reversed = true;
        }
        Some(FlightPhase::Cruise) if p.route_complete => {
            state.flight_phase = FlightPhase::Landing as u8;
        }
        Some(FlightPhase::Landing) if p.on_ground => {
            state.flight_phase = FlightPhase::Landed as u8;
            landed = true;
        }
        _ => {}
    }
    let changed = *state != before;
    if changed {
        state.sequence += 1;
    }
    (changed, landed)
}

/// The flight with `missionlink_flight::guidance`, one record per step.
fn fly_rust(s: &Scenario) -> Vec<Record> {
    let mut g = Guidance::new(GuidanceConfig {
        start_latitude_deg: s.start.0,
        start_longitude_deg: s.start.1,
        wind_speed_mps: s.wind.0,
        wind_from_deg: s.wind.1,
        ..GuidanceConfig::default()
    });
    g.set_waypoint_list(&s.waypoints);
    g.set_area_list(&s.areas);
    let mut state = AutomationStatePayload {
        sequence: 1,
        flown_waypoint_list: s.waypoints.generation,
        ..AutomationStatePayload::ON_GROUND
    };
    g.set_automation(&state);
    let mut now = SimInstant::ZERO;
    let mut log = vec![Record::of(&g.step(now))];
    state.flight_phase = FlightPhase::TakeOff as u8;
    state.sequence += 1;
    g.set_automation(&state);
    let mut landed = false;
    for _ in 0..MAX_STEPS {
        now = now + STEP;
        let p = g.step(now);
        log.push(Record::of(&p));
        if landed {
            return log;
        }
        let (changed, now_landed) = automate(s, &mut state, &p);
        landed = now_landed;
        if changed {
            g.set_automation(&state);
        }
    }
    panic!(
        "{}: the Rust model did not land in {MAX_STEPS} steps",
        s.name
    );
}

/// The same flight with the Python model: the scenario as JSON on stdin, a JSON array per
/// step on stdout. The script mirrors `fly_rust` and `automate` line by line.
const PYTHON_FLIGHT: &str = r#"
import json, sys
sys.path[:0] = sys.argv[1:3]
import missionlink_contracts as c
import missionlink_guidance as mg

def fill(obj, value):
    for name, v in value.items():
        if isinstance(v, dict):
            fill(getattr(obj, name), v)
        elif isinstance(v, list):
            array = getattr(obj, name)
            for i, item in enumerate(v):
                if isinstance(item, dict):
                    fill(array[i], item)
                else:
                    array[i] = item
        else:
            setattr(obj, name, v)

s = json.load(sys.stdin)
w = c.WaypointListPayload(); fill(w, s["waypoints"])
a = c.AreaListPayload(); fill(a, s["areas"])
g = mg.Guidance(mg.GuidanceConfig(start_latitude_deg=s["start"][0], start_longitude_deg=s["start"][1],
    wind_speed_mps=s["wind"][0], wind_from_deg=s["wind"][1]))
g.set_waypoint_list(w)
g.set_area_list(a)
state = c.AutomationStatePayload(sequence=1, flown_waypoint_list=w.generation, flight_phase=c.FlightPhase.ON_GROUND)
g.set_automation(state)
out = []
# The floats as their shortest round-trip text (repr), which Rust parses exactly.
def record(p):
    out.append(json.dumps([p.from_, p.to, p.next, p.climb_complete, p.route_complete, p.on_ground,
        repr(p.latitude_deg), repr(p.longitude_deg), repr(p.altitude_m), repr(p.ground_speed_mps),
        p.inside_fly_zone, p.in_no_fly_zone,
        repr(p.heading_deg), repr(p.roll_deg), repr(p.pitch_deg), repr(p.climb_rate_mps)]))
now = 0
record(g.step(now))
state.flight_phase = c.FlightPhase.TAKE_OFF; state.sequence += 1
g.set_automation(state)
home_at = tuple(s["return_home_at"]) if s["return_home_at"] else None
landed = False
for _ in range(s["max_steps"]):
    now += s["step_ns"]
    p = g.step(now)
    record(p)
    if landed:
        break
    before = bytes(state)
    phase = state.flight_phase
    if phase == c.FlightPhase.TAKE_OFF and p.climb_complete:
        state.flight_phase = c.FlightPhase.CRUISE
        state.land_at = s["land_at"]
    elif phase == c.FlightPhase.CRUISE and home_at == p.from_to_next() and not state.route_reversed:
        state.route_reversed = True
    elif phase == c.FlightPhase.CRUISE and p.route_complete:
        state.flight_phase = c.FlightPhase.LANDING
    elif phase == c.FlightPhase.LANDING and p.on_ground:
        state.flight_phase = c.FlightPhase.LANDED
        landed = True
    if bytes(state) != before:
        state.sequence += 1
        g.set_automation(state)
print("\n".join(out))
"#;

fn geo(p: GeoPoint) -> Value {
    json!({ "latitude": { "raw": p.latitude.raw() }, "longitude": { "raw": p.longitude.raw() } })
}

fn waypoint(w: &WaypointEntry) -> Value {
    json!({
        "number": w.number,
        "next": w.next,
        "position": geo(w.position),
        "altitude": { "raw": w.altitude.raw() },
        "speed": { "raw": w.speed.raw() },
        "altitude_type": w.altitude_type,
        "speed_type": w.speed_type,
        "turn_type": w.turn_type,
        "leg_type": w.leg_type,
        "rf_turn_direction": w.rf_turn_direction,
        "reserved": w.reserved,
        "rf_centre": geo(w.rf_centre),
    })
}

fn altitudes(a: &AreaAltitudes) -> Value {
    json!({
        "lower": { "raw": a.lower.raw() },
        "upper": { "raw": a.upper.raw() },
        "has_lower": a.has_lower,
        "has_upper": a.has_upper,
        "altitude_type": a.altitude_type,
    })
}

fn polygon(p: &PolygonArea) -> Value {
    json!({
        "area_id": p.area_id,
        "vertex_count": p.vertex_count,
        "altitudes": altitudes(&p.altitudes),
        "vertices": p.vertices().iter().map(|v| geo(*v)).collect::<Vec<_>>(),
    })
}

fn circle(c: &CircleArea) -> Value {
    json!({
        "area_id": c.area_id,
        "altitudes": altitudes(&c.altitudes),
        "centre": geo(c.centre),
        "border": geo(c.border),
    })
}

/// The scenario for the Python side: every field of the lists the model may read, raw.
fn scenario_json(s: &Scenario) -> Value {
    let w = &s.waypoints;
    let a = &s.areas;
    json!({
        "waypoints": {
            "generation": w.generation,
            "activation": w.activation,
            "take_off_height": { "raw": w.take_off_height.raw() },
            "count": w.count,
            "initial_waypoint": w.initial_waypoint,
            "bidirectional": w.bidirectional,
            "planning_wind": { "raw": w.planning_wind.raw() },
            "waypoints": w.waypoints().iter().map(waypoint).collect::<Vec<_>>(),
        },
        "areas": {
            "generation": a.generation,
            "activation": a.activation,
            "safety_offset": { "raw": a.safety_offset.raw() },
            "no_fly_polygon_count": a.no_fly_polygon_count,
            "no_fly_circle_count": a.no_fly_circle_count,
            "fly_zone": polygon(&a.fly_zone),
            "no_fly_polygons": a.no_fly_polygons().iter().map(polygon).collect::<Vec<_>>(),
            "no_fly_circles": a.no_fly_circles().iter().map(circle).collect::<Vec<_>>(),
        },
        "start": [s.start.0, s.start.1],
        "land_at": s.land_at,
        "return_home_at": s.return_home_at.map(|(f, t, n)| vec![f, t, n]),
        "wind": [s.wind.0, s.wind.1],
        "step_ns": STEP.as_nanos() as u64,
        "max_steps": MAX_STEPS,
    })
}

/// The flight with the Python model, one record per step.
fn fly_python(s: &Scenario) -> Vec<Record> {
    use std::io::Write;
    let mut child = Command::new(python())
        .arg("-c")
        .arg(PYTHON_FLIGHT)
        .arg(repo().join("interfaces/python"))
        .arg(repo().join("partitions/python"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let input = serde_json::to_vec(&scenario_json(s)).unwrap();
    child.stdin.take().unwrap().write_all(&input).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}: the Python model failed:\n{}",
        s.name,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| Record::parse(&serde_json::from_str(l).unwrap()))
        .collect()
}

/// `values` with repetitions in a row removed.
fn changes<T: PartialEq + Copy>(values: impl Iterator<Item = T>) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for v in values {
        if out.last() != Some(&v) {
            out.push(v);
        }
    }
    out
}

fn lists(file: &str) -> (WaypointListPayload, AreaListPayload) {
    let valid = plan(file).assemble().unwrap();
    (valid.mission.to_payload(1), valid.areas.to_payload(1))
}

fn scenarios() -> Vec<Scenario> {
    let (m1, a1) = lists("mission-1.toml");
    let (m2, a2) = lists("mission-2.toml");
    let trol = (48.26, 11.66);
    let ccp = (48.275, 11.645);
    let mission_2 = |name, land_at, return_home_at| Scenario {
        name,
        waypoints: m2,
        areas: a2,
        start: ccp,
        land_at,
        return_home_at,
        wind: CALM,
    };
    // Mission 2 planned for a 12 m/s wind (#13001 field 5): every turn at (v + W)²/(g·tan bank).
    let mut m2_in_wind = m2;
    m2_in_wind.planning_wind = Speed::from_raw(24);
    vec![
        Scenario {
            name: "mission 1",
            waypoints: m1,
            areas: a1,
            start: trol,
            land_at: 0,
            return_home_at: None,
            wind: CALM,
        },
        mission_2("mission 2", 0, None),
        mission_2("mission 2, return to home at W1", 0, Some((1, 2, 3))),
        mission_2("mission 2, land at W1", 2, None),
        Scenario {
            name: "mission 2, W1 flown over (the turns onto the arc)",
            waypoints: fly_over_at_w1(&m2),
            ..mission_2("", 0, None)
        },
        Scenario {
            name: "mission 2's areas, a route through both no-fly-zones and out of the fly-zone",
            waypoints: through_the_zones(&m2),
            areas: a2,
            start: trol,
            land_at: 0,
            return_home_at: None,
            wind: CALM,
        },
        // In wind: the turns sized for the planning wind, flown at the ground speed the
        // simulated wind leaves on each path's course. CCP to W1 runs about 070: from 060 the
        // wind is nearly head-on there, from 250 behind (and head-on on the way home); the
        // turns and the arc meet it from every side.
        Scenario {
            name: "mission 2 planned for 12 m/s, in 12 m/s from 060",
            waypoints: m2_in_wind,
            wind: (12.0, 60.0),
            ..mission_2("", 0, None)
        },
        Scenario {
            name: "mission 2 planned for 12 m/s, in 12 m/s from 250, return to home at W1",
            waypoints: m2_in_wind,
            wind: (12.0, 250.0),
            ..mission_2("", 0, Some((1, 2, 3)))
        },
    ]
}

/// Mission 2 with W1 (waypoint 2) fly-over: over W1, then the turn straight into the reverse
/// turn onto the radius-to-fix arc (`geofence::turn`).
fn fly_over_at_w1(m2: &WaypointListPayload) -> WaypointListPayload {
    let mut list = *m2;
    list.waypoints[1].turn_type = wire::TurnType::FlyOver as u8;
    list
}

/// A route in mission 2's airspace that the safety gateway would refuse, to compare the zone
/// tests: over a fly-over waypoint in the polygonal no-fly-zone (area 3), through the circular
/// one (area 2), then north out of the fly-zone.
fn through_the_zones(like: &WaypointListPayload) -> WaypointListPayload {
    let mut list = *like;
    let points = [(48.264, 11.643), (48.268, 11.675), (48.29, 11.675)];
    list.count = points.len() as u16;
    list.bidirectional = false;
    for (i, (lat, lon)) in points.into_iter().enumerate() {
        let w = &mut list.waypoints[i];
        *w = like.waypoints[0];
        w.number = i as u16 + 1;
        w.next = if i + 1 < points.len() {
            i as u16 + 2
        } else {
            0
        };
        w.position = GeoPoint::from_degrees(lat, lon).unwrap();
    }
    // Fly-over: over the waypoint in the polygon (a fly-by arc would turn short of it).
    list.waypoints[0].turn_type = wire::TurnType::FlyOver as u8;
    list
}

#[test]
fn the_python_model_flies_the_demo_missions_with_the_same_from_to_next_as_the_rust_model() {
    require_python();
    for s in scenarios() {
        let started = Instant::now();
        let rust = fly_rust(&s);
        let python = fly_python(&s);
        let rust_triples = changes(rust.iter().map(|r| r.triple));
        let python_triples = changes(python.iter().map(|r| r.triple));
        assert_eq!(
            python_triples, rust_triples,
            "{}: FROM-TO-NEXT of the Python model (left) and the Rust model (right)",
            s.name
        );
        // The flags change in the same order (climb complete, route complete, on the ground),
        // and the zones the same way.
        assert_eq!(
            changes(python.iter().map(|r| r.flags)),
            changes(rust.iter().map(|r| r.flags)),
            "{}",
            s.name
        );
        assert_eq!(
            changes(python.iter().map(|r| r.zones)),
            changes(rust.iter().map(|r| r.zones)),
            "{}",
            s.name
        );
        // The same flight, step by step: same length, the same triple, flags and zones at
        // every step, the same ground speed (exactly in calm air, within SPEED_IN_WIND_MPS in
        // wind), and the positions and altitudes (geodesics of the same algorithms, the same
        // turn construction) within a micrometre.
        assert_eq!(python.len(), rust.len(), "{}: steps", s.name);
        let mut worst_m: f64 = 0.0;
        let mut worst_alt: f64 = 0.0;
        let mut worst_speed: f64 = 0.0;
        let mut worst_attitude = [0.0f64; 4];
        for (i, (p, r)) in python.iter().zip(&rust).enumerate() {
            for k in 0..4 {
                let (a, b) = (p.attitude[k], r.attitude[k]);
                assert_eq!(
                    a.is_nan(),
                    b.is_nan(),
                    "{}: step {i}: {} {a} (Python) and {b} (Rust)",
                    s.name,
                    ATTITUDE[k]
                );
                if a.is_nan() {
                    continue;
                }
                let diff = if k == 0 {
                    // Headings either side of north are close.
                    ((a - b + 540.0).rem_euclid(360.0) - 180.0).abs()
                } else {
                    (a - b).abs()
                };
                assert!(
                    diff <= ATTITUDE_TOLERANCE[k],
                    "{}: step {i}: {} {a} (Python) and {b} (Rust)",
                    s.name,
                    ATTITUDE[k]
                );
                worst_attitude[k] = worst_attitude[k].max(diff);
            }
            assert_eq!(p.triple, r.triple, "{}: step {i}", s.name);
            if s.wind == CALM {
                assert_eq!(p.speed, r.speed, "{}: step {i}", s.name);
            } else {
                assert!(
                    (p.speed - r.speed).abs() < SPEED_IN_WIND_MPS,
                    "{}: step {i}: ground speed {} (Python) and {} (Rust)",
                    s.name,
                    p.speed,
                    r.speed
                );
            }
            worst_speed = worst_speed.max((p.speed - r.speed).abs());
            assert_eq!(p.flags, r.flags, "{}: step {i}", s.name);
            assert_eq!(p.zones, r.zones, "{}: step {i}", s.name);
            let d = distance_m(
                Site::new(p.latitude, p.longitude),
                Site::new(r.latitude, r.longitude),
            );
            worst_m = worst_m.max(d);
            worst_alt = worst_alt.max((p.altitude - r.altitude).abs());
        }
        assert!(worst_m < 1e-6, "{}: positions {worst_m} m apart", s.name);
        assert!(
            worst_alt < 1e-6,
            "{}: altitudes {worst_alt} m apart",
            s.name
        );
        println!(
            "{}: {} steps of {} ms, FROM-TO-NEXT {rust_triples:?}, zones (inside the fly-zone, \
             in no-fly-zone) {:?}; worst position difference {worst_m:.2e} m, altitude \
             {worst_alt:.2e} m, ground speed {worst_speed:.2e} m/s, heading, roll, pitch \
             {:.1e} {:.1e} {:.1e} deg, climb rate {:.1e} m/s ({:.1} s)",
            s.name,
            rust.len(),
            STEP.as_millis(),
            changes(rust.iter().map(|r| r.zones)),
            worst_attitude[0],
            worst_attitude[1],
            worst_attitude[2],
            worst_attitude[3],
            started.elapsed().as_secs_f64()
        );
    }
}

/// The test's own check that the scenarios differ where they should: return to home and
/// land-at change the sequence of mission 2, the wind changes the ground speed, and the flights
/// bank both ways, climb and descend (otherwise comparing them would prove little).
#[test]
fn the_scenarios_exercise_return_to_home_and_land_at() {
    let all = scenarios();
    let triples = |s: &Scenario| changes(fly_rust(s).iter().map(|r| r.triple));
    assert_eq!(
        triples(&all[0]),
        [(0, 0, 0), (0, 1, 0), (1, 0, 0), (0, 0, 0)]
    );
    assert_eq!(
        triples(&all[1]),
        [
            (0, 0, 0),
            (0, 1, 2),
            (1, 2, 3),
            (2, 3, 0),
            (3, 0, 0),
            (0, 0, 0)
        ]
    );
    assert_eq!(
        triples(&all[2]),
        [
            (0, 0, 0),
            (0, 1, 2),
            (1, 2, 3),
            (1, 2, 1),
            (2, 1, 0),
            (1, 0, 0),
            (0, 0, 0)
        ]
    );
    assert_eq!(
        triples(&all[3]),
        [(0, 0, 0), (0, 1, 2), (1, 2, 0), (2, 0, 0), (0, 0, 0)]
    );
    // The flights in wind: the calm flights' sequences, at ground speeds well off the 25 m/s
    // airspeed (from 060 a headwind all the way, from 250 a tailwind out and a headwind home),
    // so the wind is flown, not left out.
    for (s, calm) in [(&all[6], &all[1]), (&all[7], &all[2])] {
        assert_ne!(s.wind, CALM, "{}", s.name);
        assert_eq!(triples(s), triples(calm), "{}", s.name);
        let cruise: Vec<f64> = fly_rust(s)
            .iter()
            .map(|r| r.speed)
            .filter(|v| *v > 0.0)
            .collect();
        let slowest = cruise.iter().copied().fold(f64::INFINITY, f64::min);
        let fastest = cruise.iter().copied().fold(0.0, f64::max);
        assert!(
            slowest < 20.0 || fastest > 30.0,
            "{}: ground speeds {slowest}..{fastest} m/s",
            s.name
        );
    }
    // Mission 2 turns left at W1 onto the clockwise arc: the bank of the fly-by (25 deg) to
    // the left, the arc's to the right; the heading is known once it moves, and the climb and
    // the descent show in the climb rate.
    let flight = fly_rust(&all[1]);
    let most = |k: usize, f: fn(f64, f64) -> f64| {
        flight
            .iter()
            .map(|r| r.attitude[k])
            .filter(|v| !v.is_nan())
            .fold(0.0, f)
    };
    assert!(most(1, f64::min) < -24.0, "{}", most(1, f64::min));
    assert!(most(1, f64::max) > 3.0, "{}", most(1, f64::max));
    assert!(most(3, f64::max) > 1.0 && most(3, f64::min) < -1.0);
    assert!(flight.first().is_some_and(|r| r.attitude[0].is_nan()));
    assert!(flight.last().is_some_and(|r| !r.attitude[0].is_nan()));
    assert!(Path::new(&guidance_script()).is_file());
}

/// The pairing of the lists in Python (`ListPairing`) by the cases of the Rust pairing's tests
/// (partitions/src/ipc.rs): a pair only of one activation, newer than the one released; older
/// lists ignored; the same activation published again is no new pair.
const PYTHON_PAIRING: &str = r#"
import sys
sys.path[:0] = sys.argv[1:3]
import missionlink_contracts as c
import missionlink_guidance as mg

def w(activation, count):
    return c.WaypointListPayload(generation=activation, activation=activation, count=count)

def a(activation, polygons):
    return c.AreaListPayload(generation=activation, activation=activation, no_fly_polygon_count=polygons)

def released(p):
    pair = p.take()
    return None if pair is None else (pair[0].activation, pair[0].count, pair[1].no_fly_polygon_count)

p = mg.ListPairing()
assert released(p) is None
p.offer_waypoints(w(1, 3))
assert released(p) is None, "the areas of activation 1 missing"
p.offer_areas(a(1, 1))
assert released(p) == (1, 3, 1)
assert released(p) is None, "released once"
p.offer_waypoints(w(2, 5))
assert released(p) is None, "W2 with A1 is a mix"
assert p.released == 1
p.offer_areas(a(2, 4))
assert released(p) == (2, 5, 4)
p.offer_areas(a(3, 0))
assert released(p) is None
p.offer_waypoints(w(3, 2))
assert released(p) == (3, 2, 0)
assert p.mismatched == 2, p.mismatched

# Older than held or released: ignored.
p = mg.ListPairing()
p.offer_waypoints(w(5, 5)); p.offer_areas(a(5, 5))
assert released(p) == (5, 5, 5)
p.offer_waypoints(w(4, 9)); p.offer_areas(a(4, 9))
assert released(p) is None
p.offer_waypoints(w(6, 6))
p.offer_waypoints(w(5, 9))
p.offer_areas(a(6, 6))
assert released(p) == (6, 6, 6)

# The same activation again (a restarted mission data handling): no new pair.
p = mg.ListPairing()
p.offer_waypoints(w(7, 3)); p.offer_areas(a(7, 2))
assert released(p) == (7, 3, 2)
p.offer_waypoints(w(7, 3))
assert released(p) is None
p.offer_areas(a(7, 2))
assert released(p) is None and p.released == 7 and p.mismatched == 0

# The lists of no mission are a pair like any other.
p = mg.ListPairing()
p.offer_waypoints(c.WaypointListPayload()); p.offer_areas(c.AreaListPayload())
assert released(p) == (0, 0, 0)

# A copy is kept: the offered payload may be a sample that goes back to iceoryx2.
p = mg.ListPairing()
x = w(8, 1)
p.offer_waypoints(x)
x.count = 99
p.offer_areas(a(8, 0))
assert released(p) == (8, 1, 0)
print("ok")
"#;

#[test]
fn the_python_list_pairing_releases_only_whole_pairs_of_one_activation() {
    require_python();
    let out = Command::new(python())
        .arg("-c")
        .arg(PYTHON_PAIRING)
        .arg(repo().join("interfaces/python"))
        .arg(repo().join("partitions/python"))
        .output()
        .unwrap();
    assert!(
        out.status.success() && String::from_utf8_lossy(&out.stdout).trim() == "ok",
        "the Python pairing:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
