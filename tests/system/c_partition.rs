//! A partition in C through missionlink's C library (clib/, docs/hil.md):
//!
//! - **End to end**: the guidance in C (clib/partitions/guidance.c), built here with the system's C
//!   compiler (`cc`) against the static library Cargo built, started in place of the Rust stub
//!   (`fcc --without guidance-stub`), flies demo mission 2 uploaded and executed by the real GCS
//!   over UDP; FROM-TO-NEXT at the GCS is the Rust stub's sequence (the Rust model flown in
//!   simulated time on the same lists, as tests/python_guidance.rs flies it). The launcher hears
//!   its heartbeat and a Rust subscriber reads its heartbeat and progress with the Rust types.
//! - **The header**: clib/include/missionlink.h compiles as C11 and as C++17 with
//!   `-Wall -Wextra -Werror`, and a C++ program using it (clib/tests/c/uses_the_header.cpp) is
//!   built and publishes and takes through the library.
//! - **Bad arguments**: a C program (clib/tests/c/bad_arguments.c) passing null pointers, wrong
//!   lengths, unknown services and an invalid payload gets each error code, not a crash.
//!
//! They need `cc` and `c++` (which `tools/test` checks for) and fail, never skip, without them.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use iceoryx2::prelude::ipc;
use missionlink::harness::binaries;
use missionlink::harness::fcc::FccProcess;
use missionlink::harness::*;
use missionlink_flight::guidance::{Guidance, GuidanceConfig};
use missionlink_ground::ground_station::GcsError;
use missionlink_interfaces::contracts::{
    AutomationStatePayload, FccService, FlightPhase, GuidanceProgressPayload, HeartbeatPayload,
    Partition,
};
use missionlink_interfaces::wire;
use missionlink_partitions::config::Config;
use missionlink_partitions::ipc::Ipc;
use missionlink_protocol::link::time::Instant as SimInstant;

/// Bound of every wait (a failure bound, never a timing assertion).
const LIMIT: Duration = Duration::from_secs(60);

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch directory of this test's own.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("missionlink-c-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs a compiler with `args` and the include paths of the two headers; panics with its
/// output unless it succeeds.
fn compile(compiler: &str, args: &[&str], sources: &[PathBuf], out: Option<&Path>, link: bool) {
    let mut command = Command::new(compiler);
    command
        .args(args)
        .args(["-Wall", "-Wextra", "-Werror"])
        .arg("-I")
        .arg(repo().join("interfaces/c"))
        .arg("-I")
        .arg(repo().join("clib/include"))
        .args(sources);
    if let Some(out) = out {
        command.arg("-o").arg(out);
    }
    if link {
        command
            .arg(binaries::c_static_library().unwrap())
            .args(binaries::C_NATIVE_LIBS);
    }
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("cannot run {compiler} (install a C and C++ compiler): {e}"));
    assert!(
        output.status.success(),
        "{compiler} {args:?} {sources:?} failed:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The C guidance, built once per test process with `cc` against the static library.
fn c_guidance() -> PathBuf {
    static BINARY: OnceLock<PathBuf> = OnceLock::new();
    BINARY
        .get_or_init(|| {
            let out = scratch("guidance-build").join("guidance-c");
            compile(
                "cc",
                &["-std=c11", "-O1"],
                &[repo().join("clib/partitions/guidance.c")],
                Some(&out),
                true,
            );
            out
        })
        .clone()
}

/// The command that starts the C guidance as `config` sets the guidance stub (prefix, time
/// scale, start position, rates, update interval, heartbeat period).
fn c_guidance_command(config: &Config) -> Command {
    let g = &config.guidance;
    let mut command = Command::new(c_guidance());
    command
        .args(["--service-prefix", &config.ipc.service_prefix])
        .args(["--time-scale", &g.time_scale.to_string()])
        .args(["--start-latitude", &g.start_latitude_deg.to_string()])
        .args(["--start-longitude", &g.start_longitude_deg.to_string()])
        .args(["--climb-rate", &g.climb_rate_mps.to_string()])
        .args(["--descent-rate", &g.descent_rate_mps.to_string()])
        .args(["--update-interval-ms", &g.update_interval_ms.to_string()])
        .args([
            "--heartbeat-period-ms",
            &config.health.period_ms.to_string(),
        ])
        .stdin(Stdio::null());
    command
}

/// The C guidance as a child process, its log (stderr) in a file; stopped with SIGTERM when
/// dropped.
struct CGuidance {
    child: Child,
    log: PathBuf,
}

impl CGuidance {
    fn start(rig: &Rig) -> Self {
        let log = rig.dir.join("guidance-c.log");
        let child = c_guidance_command(&rig.config)
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .unwrap();
        Self { child, log }
    }

    fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    fn wait_for_log(&mut self, text: &str) {
        let end = Instant::now() + LIMIT;
        while Instant::now() < end {
            if self.log_text().contains(text) {
                return;
            }
            if let Some(status) = self.child.try_wait().unwrap() {
                panic!(
                    "the C guidance ended ({status}) before logging {text:?}:\n{}",
                    self.log_text()
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        panic!("the C guidance never logged {text:?}:\n{}", self.log_text());
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

impl Drop for CGuidance {
    fn drop(&mut self) {
        self.stop();
    }
}

/// Execute, asked again (bounded) while refused with `WrongState` (guidance not heard yet, or
/// no position from it yet); the number of refusals.
fn execute_when_ready(
    link: &mut Link,
    seen: &mut Vec<(u16, u16, u16)>,
    log: &dyn Fn() -> String,
) -> usize {
    let start = Instant::now();
    let mut refusals = 0;
    loop {
        let now = link.now();
        link.station()
            .execute(now, wire::ExecuteCommand::Execute)
            .unwrap();
        match link.finish(|event| record(seen, event)) {
            Ok(_) => return refusals,
            Err(GcsError::Transfer { error, .. })
                if error.reason() == Some(wire::Reason::WrongState) && start.elapsed() < LIMIT =>
            {
                refusals += 1;
                std::thread::sleep(Duration::from_millis(100));
            }
            Err(e) => panic!("execute: {e}\n{}", log()),
        }
    }
}

/// FROM-TO-NEXT of the Rust stub's model (`services::guidance`) flying mission 2 from the
/// rig's start in simulated time, with system automation's phases scripted (take-off, cruise
/// once the climb is complete, landing once the route is, landed on the ground): each triple
/// once, in order, the idle one before take-off left out.
fn rust_stub_sequence(config: GuidanceConfig) -> Vec<(u16, u16, u16)> {
    let valid = plan("mission-2.toml").assemble().unwrap();
    let mut g = Guidance::new(GuidanceConfig {
        time_scale: 1.0,
        ..config
    });
    g.set_waypoint_list(&valid.mission.to_payload(1));
    g.set_area_list(&valid.areas.to_payload(1));
    let mut state = AutomationStatePayload {
        sequence: 1,
        flown_waypoint_list: 1,
        flight_phase: FlightPhase::TakeOff as u8,
        ..AutomationStatePayload::ON_GROUND
    };
    g.set_automation(&state);
    let mut now = SimInstant::ZERO;
    let mut seen: Vec<(u16, u16, u16)> = Vec::new();
    for _ in 0..100_000 {
        let p = g.step(now);
        if seen.last() != Some(&p.from_to_next()) {
            seen.push(p.from_to_next());
        }
        let next = match state.flight_phase() {
            Some(FlightPhase::TakeOff) if p.climb_complete => Some(FlightPhase::Cruise),
            Some(FlightPhase::Cruise) if p.route_complete => Some(FlightPhase::Landing),
            Some(FlightPhase::Landing) if p.on_ground => Some(FlightPhase::Landed),
            Some(FlightPhase::Landed) => break,
            _ => None,
        };
        if let Some(phase) = next {
            state.flight_phase = phase as u8;
            state.sequence += 1;
            g.set_automation(&state);
        }
        now = now + Duration::from_millis(100);
    }
    seen
}

#[test]
fn c_partition_guidance_flies_demo_mission_2_with_the_real_fcc_and_gcs_like_the_rust_stub() {
    let started = Instant::now();
    let mut rig = Rig::new("c-guidance");
    let expected = rust_stub_sequence(rig.config.guidance);
    assert_eq!(
        expected,
        [(0, 1, 2), (1, 2, 3), (2, 3, 0), (3, 0, 0), (0, 0, 0)],
        "the Rust stub's model"
    );
    let mut command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    command.args(["--without", "guidance-stub"]);
    let mut fcc = FccProcess::spawn(command, &rig.config, Some(&rig.dir.join("fcc.log"))).unwrap();
    rig.ready(&mut fcc);
    let mut guidance = CGuidance::start(&rig);
    guidance.wait_for_log("guidance up");
    let pid = guidance.child.id();

    // The launcher hears the heartbeat of a guidance it did not start, and left the stub out.
    wait_for_log(
        &fcc,
        &format!("alive (not started by the launcher) partition=guidance pid={pid}"),
        LIMIT,
    );
    assert!(
        !fcc.log_text()
            .contains("started partition=\"guidance-stub\""),
        "{}",
        fcc.log_text()
    );

    // A Rust subscriber reads the C publications with the Rust payload types.
    missionlink_partitions::ipc::quiet_iceoryx2_log();
    let watch = Ipc::<ipc::Service>::open("c-watch", &rig.config.ipc).unwrap();
    let heartbeats = watch
        .subscriber::<HeartbeatPayload>(FccService::Heartbeat(Partition::Guidance))
        .unwrap();
    let progress = watch
        .subscriber::<GuidanceProgressPayload>(FccService::GuidanceProgress)
        .unwrap();
    let beat = eventually(LIMIT, || heartbeats.latest()).expect("a heartbeat from the C guidance");
    assert_eq!(beat.pid, pid);
    assert_eq!(beat.period_ns, rig.config.health.period_ms * 1_000_000);
    let idle = eventually(LIMIT, || progress.latest()).expect("progress from the C guidance");
    assert!(
        idle.on_ground && idle.from_to_next() == (0, 0, 0),
        "{idle:?}"
    );
    let g = rig.config.guidance;
    assert_eq!(
        (idle.latitude_deg, idle.longitude_deg),
        (g.start_latitude_deg, g.start_longitude_deg)
    );

    // Upload and execute mission 2 (CCP, W1, ROLE2); execute is refused (WrongState) until
    // automation has heard guidance alive and mission data handling has its position.
    let mut link = rig.gcs(&mut fcc);
    upload(&mut link, &plan("mission-2.toml"))
        .unwrap_or_else(|e| panic!("upload: {e}\n{}", fcc.log_text()));
    let mut seen: Vec<(u16, u16, u16)> = Vec::new();
    let logs = || {
        format!(
            "{}\n--- guidance-c ---\n{}",
            fcc.log_text(),
            guidance.log_text()
        )
    };
    let refusals = execute_when_ready(&mut link, &mut seen, &logs);
    let landed = link.run_until(LIMIT, |event| {
        record(&mut seen, event);
        seen.contains(&(3, 0, 0)) && seen.last() == Some(&(0, 0, 0))
    });
    assert!(landed, "FROM-TO-NEXT at the GCS: {seen:?}\n{}", logs());
    // Before the take-off the idle (0, 0, 0) may be reported.
    let flown: Vec<_> = seen
        .iter()
        .copied()
        .skip_while(|t| *t == (0, 0, 0))
        .collect();
    assert_eq!(
        flown,
        expected,
        "C (left), the Rust stub (right)\n{}",
        logs()
    );
    // Landed at ROLE2, the list flown named.
    let at_role2 = |p: &GuidanceProgressPayload| {
        p.on_ground
            && p.waypoint_list == 1
            && (p.latitude_deg - 48.28).abs() < 1e-6
            && (p.longitude_deg - 11.68).abs() < 1e-6
    };
    eventually(LIMIT, || progress.latest().filter(at_role2)).expect("progress: landed at ROLE2");

    // SIGTERM ends it cleanly.
    let status = guidance.stop();
    assert!(status.success(), "{status}\n{}", guidance.log_text());
    assert!(guidance.log_text().contains("guidance stopping"));
    println!(
        "C guidance end to end: execute refused {refusals} times (WrongState) before guidance \
         was alive and had reported; FROM-TO-NEXT at the GCS {seen:?}; {:.1} s in all",
        started.elapsed().as_secs_f64()
    );
}

#[test]
fn c_partition_header_compiles_as_c11_and_cpp17_and_a_cpp_program_uses_the_library() {
    let dir = scratch("header");
    let c = dir.join("includes.c");
    std::fs::write(
        &c,
        "#include \"missionlink.h\"\n\
         int main(void) { return missionlink_payload_size(MISSIONLINK_SERVICE_ID_LINK_UPLINK) \
         == sizeof(FramePayload) ? 0 : 1; }\n",
    )
    .unwrap();
    let cpp = dir.join("includes.cpp");
    std::fs::copy(&c, &cpp).unwrap();
    compile(
        "cc",
        &["-std=c11", "-Wpedantic", "-fsyntax-only"],
        &[c],
        None,
        false,
    );
    compile(
        "c++",
        &["-std=c++17", "-Wpedantic", "-fsyntax-only"],
        &[cpp],
        None,
        false,
    );

    let program = dir.join("uses-the-header");
    compile(
        "c++",
        &["-std=c++17"],
        &[repo().join("clib/tests/c/uses_the_header.cpp")],
        Some(&program),
        true,
    );
    let prefix = format!("c-partition-cpp-{}", std::process::id());
    let out = run(&program, &prefix);
    assert!(
        out.status.success(),
        "{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "took from-to-next 1 2 3 at 48.275 11.645\n"
    );
}

#[test]
fn c_partition_null_pointers_and_wrong_lengths_get_error_codes_not_a_crash() {
    let dir = scratch("bad-arguments");
    let program = dir.join("bad-arguments");
    compile(
        "cc",
        &["-std=c11"],
        &[repo().join("clib/tests/c/bad_arguments.c")],
        Some(&program),
        true,
    );
    let prefix = format!("c-partition-bad-{}", std::process::id());
    let out = run(&program, &prefix);
    let stdout = String::from_utf8_lossy(&out.stdout);
    // Exited (no signal: no crash), with every code the expected one.
    assert!(
        out.status.success(),
        "{}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    for line in [
        "publish on a null partition: MISSIONLINK_ERROR_NULL_POINTER",
        "publish a null payload: MISSIONLINK_ERROR_NULL_POINTER",
        "publish a payload one byte short: MISSIONLINK_ERROR_WRONG_SIZE",
        "take into a length of 0: MISSIONLINK_ERROR_WRONG_SIZE",
        "publish a bool of 7: MISSIONLINK_ERROR_INVALID_PAYLOAD",
        "publisher_open of an unknown service: MISSIONLINK_ERROR_INVALID_ARGUMENT",
        "nothing was published by the refused calls: MISSIONLINK_NO_SAMPLE",
        "0 unexpected",
    ] {
        assert!(stdout.contains(line), "{line:?} missing:\n{stdout}");
    }
    // The messages say what was wrong.
    assert!(
        stdout.contains("fcc/guidance/progress: a payload of"),
        "{stdout}"
    );
}

/// Runs `program` with `prefix`, bounded by [`LIMIT`].
fn run(program: &Path, prefix: &str) -> Output {
    let mut child = Command::new(program)
        .arg(prefix)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let end = Instant::now() + LIMIT;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > end {
            let _ = child.kill();
            panic!("{program:?} did not end within {LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}
