//! Isolation (`partitions/src/isolation.rs`, docs/deployment.md "Isolation"), on by default:
//! every partition of a running FCC shows no_new_privs and a seccomp filter in
//! `/proc/<pid>/status`, and only voting-monitoring holds inet sockets; each partition killed
//! with SIGKILL comes back fenced and the FCC still takes and gives missions; and a partition
//! that tries what it must never do after its start (open an inet socket, write outside its own
//! directories, run a program) is refused or killed by the kernel, and the launcher names it.
//! The misbehaving partition is `examples/isolation_probe.rs`, a test-only program that fences
//! itself as a named partition does.

use std::collections::BTreeSet;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use missionlink::harness::*;
use missionlink_partitions::config;
use missionlink_partitions::isolation::{Violation, status_shows_fence};
use missionlink_partitions::launcher::{FccProcess, PARTITIONS};

/// Bound of every wait (a failure bound, never a timing assertion).
const LIMIT: Duration = Duration::from_secs(30);

/// The inodes of the sockets process `pid` holds.
fn socket_inodes(pid: i32) -> BTreeSet<u64> {
    std::fs::read_dir(format!("/proc/{pid}/fd"))
        .unwrap()
        .filter_map(|e| std::fs::read_link(e.ok()?.path()).ok())
        .filter_map(|target| {
            let t = target.to_string_lossy().into_owned();
            t.strip_prefix("socket:[")?.strip_suffix(']')?.parse().ok()
        })
        .collect()
}

/// The inodes of the inet sockets (UDP, TCP, both IP versions) in `pid`'s network namespace.
fn inet_inodes(pid: i32) -> BTreeSet<u64> {
    ["udp", "udp6", "tcp", "tcp6"]
        .iter()
        .filter_map(|table| std::fs::read_to_string(format!("/proc/{pid}/net/{table}")).ok())
        .flat_map(|text| {
            text.lines()
                .skip(1)
                .filter_map(|l| l.split_whitespace().nth(9)?.parse().ok())
                .collect::<Vec<u64>>()
        })
        .collect()
}

/// How many inet sockets process `pid` holds.
fn inet_sockets(pid: i32) -> usize {
    socket_inodes(pid).intersection(&inet_inodes(pid)).count()
}

fn assert_fenced(fcc: &Process, partition: &str) -> i32 {
    let pid = partition_pid(fcc, partition);
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    assert!(
        status_shows_fence(&status),
        "{partition} (pid {pid}) is not fenced:\n{status}"
    );
    pid
}

#[test]
fn every_partition_is_fenced_and_only_voting_monitoring_holds_inet_sockets() {
    let rig = Rig::new("isolation-status");
    assert!(rig.config.isolation.enabled, "on by default");
    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    for partition in PARTITIONS {
        let pid = assert_fenced(&fcc, partition);
        let inet = inet_sockets(pid);
        if partition == "voting-monitoring" {
            assert_eq!(inet, 2, "voting-monitoring holds the two links");
        } else {
            assert_eq!(inet, 0, "{partition} holds an inet socket");
        }
    }
    // Said once per partition at start, with what was applied.
    let text = fcc.log_text();
    for partition in PARTITIONS {
        let lines = text
            .lines()
            .filter(|l| {
                l.contains("isolation applied") && l.contains(&format!("partition={partition}"))
            })
            .count();
        assert_eq!(lines, 1, "{partition}:\n{text}");
    }
}

#[test]
fn each_partition_killed_comes_back_fenced_and_the_fcc_still_works() {
    let mut rig = Rig::new("isolation-restart");
    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    let mut link = rig.gcs(&mut fcc);
    let (mission_1, mission_2) = (plan("mission-1.toml"), plan("mission-2.toml"));
    for (i, partition) in PARTITIONS.into_iter().enumerate() {
        signal_partition(&fcc, partition, rustix::process::Signal::KILL);
        wait_for_starts(&fcc, partition, 2, LIMIT);
        rig.ready(&mut fcc);
        assert_fenced(&fcc, partition);
        // Mission data handling takes a mission and gives it back through every restarted
        // peer (every second one the other mission, so each upload changes the lists).
        let plan = if i % 2 == 0 { &mission_2 } else { &mission_1 };
        upload(&mut link, plan).unwrap_or_else(|e| panic!("after {partition}'s restart: {e}"));
        let expected = link.station().validate(plan).unwrap();
        let active = download(&mut link).unwrap();
        assert_eq!(
            active.mission, expected.mission,
            "after {partition}'s restart"
        );
        assert_eq!(active.areas, expected.areas, "after {partition}'s restart");
    }
    let text = fcc.log_text();
    assert!(
        !text.contains("SIGSYS"),
        "a fenced partition was killed:\n{text}"
    );
}

/// The test-only partition, an example of this package: `cargo test` builds it with the rest
/// (examples are part of a test build), so it is built here only when missing. Building it with
/// a `cargo build` of its own would resolve the features of the shared dependencies for this
/// package alone, not for the workspace as the test build does, and so compile iceoryx2 and the
/// rest a second time.
fn probe() -> PathBuf {
    let dir = missionlink_partitions::binaries::build_dir().unwrap();
    let probe = dir.join("examples").join("isolation_probe");
    if !probe.is_file() {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
        let mut command = Command::new(cargo);
        command
            .args([
                "build",
                "-q",
                "--example",
                "isolation_probe",
                "--manifest-path",
            ])
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml"));
        if !cfg!(debug_assertions) {
            command.arg("--release");
        }
        assert!(command.status().unwrap().success(), "building the probe");
    }
    probe
}

/// Runs the probe fenced as `partition` under `rig`'s configuration, trying `attempt`.
fn run_probe(rig: &Rig, partition: &str, attempt: &str) -> Output {
    let outside = rig.dir.join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    let mut command = Command::new(probe());
    config::hand_to(&mut command, &rig.config).unwrap();
    command
        .env("MISSIONLINK_PROBE_AS", partition)
        .env("MISSIONLINK_PROBE_TRY", attempt)
        .env("MISSIONLINK_PROBE_OUTSIDE", &outside)
        .env("RUST_LOG", "warn");
    command.output().unwrap()
}

fn describe(output: &Output) -> String {
    format!(
        "{:?}\nstdout:\n{}\nstderr:\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

#[test]
fn a_partition_that_tries_what_it_must_never_do_is_refused_or_killed() {
    let mut rig = Rig::new("isolation-violations");
    // The probe's own state: as a partition's, beneath the rig's directory.
    for attempt in ["inet", "exec"] {
        let output = run_probe(&rig, "guidance-stub", attempt);
        assert_eq!(
            output.status.signal(),
            Some(libc_sigsys()),
            "{attempt}: {}",
            describe(&output)
        );
        assert!(
            String::from_utf8_lossy(&output.stdout).contains("fenced as guidance-stub"),
            "{attempt}: killed after the fence, not before: {}",
            describe(&output)
        );
    }
    // Landlock refuses a write outside the partition's directories (the kernel answers EACCES).
    let output = run_probe(&rig, "system-automation", "write");
    assert_eq!(output.status.code(), Some(0), "{}", describe(&output));
    assert!(
        String::from_utf8_lossy(&output.stdout).contains("write: refused"),
        "{}",
        describe(&output)
    );
    assert!(!rig.dir.join("outside/written").exists());
    // voting-monitoring may open its links' sockets; the others may not.
    let output = run_probe(&rig, "voting-monitoring", "inet");
    assert_eq!(output.status.code(), Some(3), "{}", describe(&output));
    // With `on_violation = "errno"` the call fails with EPERM and the partition goes on.
    rig.config.isolation.on_violation = Violation::Errno;
    let output = run_probe(&rig, "mission-data-handling", "inet");
    assert_eq!(output.status.code(), Some(0), "{}", describe(&output));
    assert!(
        String::from_utf8_lossy(&output.stdout).contains("inet: refused: Operation not permitted"),
        "{}",
        describe(&output)
    );
}

#[test]
fn started_as_root_a_partition_drops_to_its_configured_user() {
    let mut rig = Rig::new("isolation-user");
    rig.config.isolation.guidance_stub.user = Some("nobody".to_owned());
    let output = run_probe(&rig, "guidance-stub", "whoami");
    if rustix::process::geteuid().is_root() {
        let nobody = missionlink_partitions::isolation::lookup_user("nobody").unwrap();
        assert!(
            String::from_utf8_lossy(&output.stdout)
                .contains(&format!("uid={} gid={}", nobody.uid, nobody.gid)),
            "{}",
            describe(&output)
        );
    } else {
        // Not root and not that user: the partition refuses to start unfenced.
        assert!(!output.status.success(), "{}", describe(&output));
    }
}

fn libc_sigsys() -> i32 {
    rustix::process::Signal::SYS.as_raw()
}

#[test]
fn the_launcher_names_the_partition_the_kernel_killed_and_gives_up_after_its_start_limit() {
    let mut rig = Rig::new("isolation-launcher");
    rig.config.launcher.start_limit_burst = 2;
    rig.config.launcher.start_limit_interval_ms = 60_000;
    // The real FCC, with the probe in guidance's place: it opens an inet socket once fenced.
    let bin = rig.dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let real = bin_dir();
    for name in [
        "fcc",
        "voting-monitoring",
        "mission-data-handling",
        "system-automation",
    ] {
        std::os::unix::fs::symlink(real.join(name), bin.join(name)).unwrap();
    }
    std::os::unix::fs::symlink(probe(), bin.join("guidance-stub")).unwrap();
    let mut command = FccProcess::command(&bin, "fcc", &rig.config).unwrap();
    command
        .arg("--bin-dir")
        .arg(&bin)
        .env("MISSIONLINK_PROBE_TRY", "inet");
    let log = rig.dir.join("fcc.log");
    let fcc = FccProcess::spawn(command, &rig.config, Some(&log)).unwrap();
    wait_for_log(&fcc, "start limit reached", LIMIT);
    let text = fcc.log_text();
    let killed = text
        .lines()
        .filter(|l| l.contains("partition=\"guidance-stub\"") && l.contains("SIGSYS"))
        .count();
    assert_eq!(killed, 2, "two starts, both killed, each named:\n{text}");
    assert!(
        text.lines()
            .any(|l| l.contains("partition died; restarting")
                && l.contains("guidance-stub")
                && l.contains("SIGSYS")),
        "{text}"
    );
    // The real partitions are not touched by it.
    assert!(
        !text
            .lines()
            .any(|l| l.contains("SIGSYS") && !l.contains("guidance-stub")),
        "{text}"
    );
}

#[test]
fn the_systemd_units_verify() {
    let fcc = bin_dir().join("fcc");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let output = Command::new(root.join("tools/check-units"))
        .arg(&fcc)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", describe(&output));
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("missionlink-fcc.service: verified"),
        "{}",
        describe(&output)
    );
}
