//! Two hosts through the bridge (docs/two-hosts.md): two network namespaces joined by a veth
//! pair, made by this test and removed by it (also when it fails: [`Hosts`] is a drop guard),
//! with the link-local pair 169.254.77.1 (host A) and 169.254.77.2 (host B) on the test's own
//! veth and nothing else; Zenoh's multicast scouting is off and the bridges use explicit
//! endpoints, so no other address is ever a target.
//!
//! - Host A: the FCC (`fcc --without guidance-stub`) with its bridge, started by the launcher
//!   from `[bridge]`; the real GCS over UDP on host A's loopback.
//! - Host B: a guidance and a bridge: the Rust stub and the bridge started by the launcher
//!   with the FCC's three other partitions left out, as
//!   deploy/systemd/missionlink-guidance-host.service runs them; or the Python guidance and a
//!   bridge started apart.
//!
//! Both hosts share this machine's /dev/shm: each uses a service prefix of its own, so their
//! iceoryx2 services never meet and only the bridges carry data between them. The bridges
//! authenticate each other by mutual TLS with credentials the real `bridge credentials` makes
//! for the test (docs/two-hosts.md, "Credentials").
//!
//! The flights upload and execute demo mission 2, check the whole FROM-TO-NEXT sequence at the
//! GCS, then set the veth down: the launcher reports the remote guidance not alive and execute
//! is refused (`WrongState`); then up again: the launcher hears it alive and execute is accepted,
//! without a restart of any process. Both bridges show the fence in `/proc/<pid>/status`, on
//! every thread.
//!
//! The stranger: a guidance stub on host B behind two bridges that the FCC's must refuse, one
//! with a certificate of another authority (it trusts the FCC's certificate, so only the FCC's
//! check can refuse it), one without credentials (plain TCP). Each tries and fails again and
//! again; meanwhile the FCC never takes the stranger's guidance as its own and refuses execute.
//! Then the same guidance behind a bridge with the deployment's credentials is heard at once:
//! only the authentication kept it out.
//!
//! Network namespaces need root: run as root (CI's `.ci/run` does). Without root each test fails
//! at once with one line saying so.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use missionlink::harness::netns::{ADDR_A, Hosts};
use missionlink::harness::*;
use missionlink_ground::ground_station::GcsError;
use missionlink_interfaces::wire;
use missionlink_partitions::binaries;
use missionlink_partitions::bridge_config::{Authentication, Bridge, Mode};
use missionlink_partitions::config::Config;
use missionlink_partitions::isolation::status_shows_fence;
use missionlink_partitions::launcher::FccProcess;

/// Bound of every wait (a failure bound, never a timing assertion).
const LIMIT: Duration = Duration::from_secs(60);

/// The Zenoh port host A's bridge listens on, inside the test's own namespace (no other
/// process can hold it there).
const ZENOH_PORT: u16 = 7447;
/// [`ZENOH_PORT`] as it appears in the endpoints of a log line.
const ZENOH_PORT_TEXT: &str = ":7447";

/// Makes a set of credentials with the real `bridge credentials`: under `dir/<set>`, host `a`
/// (which listens on [`ADDR_A`]) and host `b`, signed by an authority of the set's own.
fn credentials(dir: &Path, set: &str) -> PathBuf {
    let out = dir.join(set);
    let made = Command::new(bin_dir().join("bridge"))
        .arg("credentials")
        .arg("--out")
        .arg(&out)
        .args(["--host", &format!("a={ADDR_A}"), "--host", "b"])
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "bridge credentials: {}",
        String::from_utf8_lossy(&made.stderr)
    );
    out
}

/// Host A's configuration (the rig's) with the bridge listening on the veth, with host `a`'s
/// credentials of the set `credentials`: the lists and automation state go out, guidance's
/// progress and heartbeat come in.
fn bridge_a(config: &mut Config, credentials: &Path) {
    config.launcher.without = vec!["guidance-stub".to_owned()];
    // Two FCC hosts, four bridges and two guidances run on this machine at once (and the
    // other test beside): a heartbeat period of 200 ms (hung after 500 ms) keeps a partition
    // that is merely scheduled late from being taken for a hung one.
    config.health.period_ms = 200;
    config.bridge = Bridge {
        enabled: true,
        mode: Mode::Peer,
        listen: vec![format!("tls/{ADDR_A}:{ZENOH_PORT}")],
        connect: Vec::new(),
        key_prefix: format!("{}-vehicle", config.ipc.service_prefix),
        out: [
            "fcc/mission/waypoint-list",
            "fcc/mission/area-list",
            "fcc/automation/state",
        ]
        .map(str::to_owned)
        .to_vec(),
        inbound: ["fcc/guidance/progress", "fcc/health/guidance"]
            .map(str::to_owned)
            .to_vec(),
        credentials: Some(credentials.join("a")),
        ..Bridge::default()
    };
}

/// Host B's configuration: host A's, under a service prefix and directories of its own, the
/// bridge connecting to host A with the directions swapped and host `b`'s credentials of the
/// set `credentials`.
fn host_b(a: &Config, dir: &Path, credentials: &Path) -> Config {
    let mut b = a.clone();
    b.ipc.service_prefix = format!("{}-b", a.ipc.service_prefix);
    b.ipc.state_dir = Some(dir.join("state-b"));
    b.latency.summary_dir = Some(dir.join("latency-b"));
    b.bridge.listen = Vec::new();
    b.bridge.connect = vec![format!("tls/{ADDR_A}:{ZENOH_PORT}")];
    b.bridge.credentials = Some(credentials.join("b"));
    std::mem::swap(&mut b.bridge.out, &mut b.bridge.inbound);
    // Mission 2 starts at CCP.
    b.guidance.start_latitude_deg = 48.275;
    b.guidance.start_longitude_deg = 11.645;
    b
}

/// Waits until `process`'s log holds more than `before` lines with every one of `parts`.
fn wait_for(process: &Process, parts: &[&str], before: usize) -> Duration {
    wait_for_line(process, parts, before, LIMIT)
}

/// Execute once; the reason of a refusal, `None` when accepted. FROM-TO-NEXT heard meanwhile
/// goes to `seen`.
fn execute(link: &mut Link, seen: &mut Vec<(u16, u16, u16)>) -> Option<wire::Reason> {
    let now = link.now();
    link.station()
        .execute(now, wire::ExecuteCommand::Execute)
        .unwrap();
    match link.finish(|event| record(seen, event)) {
        Ok(_) => None,
        Err(GcsError::Transfer { error, .. }) => {
            Some(error.reason().expect("a refusal with a reason"))
        }
        Err(other) => panic!("execute: {other}"),
    }
}

/// Execute, asked again (bounded) while refused with `WrongState` (guidance not heard yet).
fn execute_when_ready(link: &mut Link, seen: &mut Vec<(u16, u16, u16)>) -> Option<wire::Reason> {
    let start = Instant::now();
    loop {
        match execute(link, seen) {
            Some(wire::Reason::WrongState) if start.elapsed() < LIMIT => {
                std::thread::sleep(Duration::from_millis(100));
            }
            outcome => return outcome,
        }
    }
}

/// What host B runs as guidance.
#[derive(Clone, Copy)]
enum RemoteGuidance {
    Stub,
    Python,
}

/// A process of host B: a guidance or its bridge, its log in the rig's directory; stopped with
/// SIGTERM when dropped.
struct Remote {
    child: Child,
    log: PathBuf,
}

impl Remote {
    fn spawn(command: Command, log: PathBuf) -> Self {
        let level = std::env::var("RUST_LOG").unwrap_or_else(|_| "info".to_owned());
        Self::spawn_logging(command, log, &level)
    }

    /// As [`Remote::spawn`], logging at `level` (`RUST_LOG`).
    fn spawn_logging(mut command: Command, log: PathBuf, level: &str) -> Self {
        command
            .env("RUST_LOG", level)
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap());
        let child = command
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {:?}: {e}", command.get_program()));
        Self { child, log }
    }

    fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    /// Waits until its log holds `times` lines with every one of `parts`.
    fn wait_for_lines(&self, parts: &[&str], times: usize) {
        let end = Instant::now() + LIMIT;
        while count_lines(&self.log_text(), parts) < times {
            assert!(
                Instant::now() < end,
                "{} never logged {times} lines with {parts:?}:\n{}",
                self.log.display(),
                self.log_text()
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Remote {
    fn drop(&mut self) {
        if let Ok(pid) = i32::try_from(self.child.id()) {
            if let Some(pid) = rustix::process::Pid::from_raw(pid) {
                let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
            }
        }
        let end = Instant::now() + Duration::from_secs(10);
        while Instant::now() < end {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts host B in namespace `ns` (from a thread that moves there): with the stub, as
/// deploy/systemd/missionlink-guidance-host.service runs it, the `fcc` launcher with the FCC's
/// other three partitions left out, which starts the stub and the bridge; with the Python
/// guidance, the bridge and the guidance apart. The first process is the one whose log names
/// the bridge's process ID, or the bridge itself.
fn start_host_b(
    ns: String,
    mut config: Config,
    dir: PathBuf,
    guidance: RemoteGuidance,
) -> Vec<Remote> {
    let bin = bin_dir();
    // The test build's own bridge (its package's test, bridge/tests/cli.rs, makes cargo build
    // it): a `cargo build` of the bridge alone would resolve the shared dependencies' features
    // otherwise and compile them all again.
    binaries::ensure_bridge(&bin, binaries::Build::IfMissing).unwrap();
    std::thread::spawn(move || {
        Hosts::enter(&ns);
        match guidance {
            RemoteGuidance::Stub => {
                config.launcher.without = [
                    "voting-monitoring",
                    "mission-data-handling",
                    "system-automation",
                ]
                .map(str::to_owned)
                .to_vec();
                let launcher = FccProcess::command(&bin, "fcc", &config).unwrap();
                vec![Remote::spawn(launcher, dir.join("fcc-b.log"))]
            }
            RemoteGuidance::Python => {
                let bridge = FccProcess::command(&bin, "bridge", &config).unwrap();
                vec![
                    Remote::spawn(bridge, dir.join("bridge-b.log")),
                    Remote::spawn(python_guidance_command(&config), dir.join("guidance-b.log")),
                ]
            }
        }
    })
    .join()
    .unwrap()
}

/// The process ID of host B's bridge: the launcher's child (its log says which), or the first
/// process itself.
fn bridge_b_pid(remote: &[Remote], guidance: RemoteGuidance) -> u32 {
    match guidance {
        RemoteGuidance::Python => remote[0].child.id(),
        RemoteGuidance::Stub => remote[0]
            .log_text()
            .lines()
            .rev()
            .filter(|l| l.contains("started") && l.contains("partition=\"bridge\""))
            .filter_map(|l| l.split("pid=").nth(1))
            .find_map(|p| p.trim().parse().ok())
            .expect("host B's launcher started its bridge"),
    }
}

/// Starts `binary` of the partitions' directory under `config` in namespace `ns`, its log at
/// `log` (`RUST_LOG` = `level`).
fn start_in(ns: &str, binary: &str, config: &Config, log: PathBuf, level: &str) -> Remote {
    let (ns, binary, config, level) = (
        ns.to_owned(),
        binary.to_owned(),
        config.clone(),
        level.to_owned(),
    );
    std::thread::spawn(move || {
        Hosts::enter(&ns);
        let command = FccProcess::command(&bin_dir(), &binary, &config).unwrap();
        Remote::spawn_logging(command, log, &level)
    })
    .join()
    .unwrap()
}

/// The fence of process `pid`, on every one of its threads (Zenoh's runtime threads too):
/// `NoNewPrivs` and `Seccomp` of each `/proc/<pid>/task/<tid>/status`, and the process's own
/// two lines as they read.
fn fence_of(pid: u32) -> (String, Vec<(String, bool)>) {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let lines: Vec<&str> = status
        .lines()
        .filter(|l| l.starts_with("NoNewPrivs:") || l.starts_with("Seccomp:"))
        .collect();
    let threads = std::fs::read_dir(format!("/proc/{pid}/task"))
        .unwrap()
        .filter_map(|t| {
            let t = t.ok()?;
            let status = std::fs::read_to_string(t.path().join("status")).ok()?;
            let name = status
                .lines()
                .find_map(|l| l.strip_prefix("Name:"))
                .unwrap_or("")
                .trim()
                .to_owned();
            Some((name, status_shows_fence(&status)))
        })
        .collect();
    (lines.join(" "), threads)
}

/// Asserts that the bridge `pid` (`which`, for the message) is fenced on every thread, and
/// prints the status lines seen.
fn assert_fenced(which: &str, pid: u32) {
    let (lines, threads) = fence_of(pid);
    println!(
        "{which} (pid {pid}): {lines:?}, {} threads, all fenced: {}",
        threads.len(),
        threads.iter().all(|(_, fenced)| *fenced)
    );
    assert!(
        lines.contains("NoNewPrivs:\t1") && lines.contains("Seccomp:\t2"),
        "{which}: {lines:?}"
    );
    // Zenoh's runtime runs threads of its own: they must be fenced too.
    assert!(threads.len() > 2, "{which}: {threads:?}");
    assert!(
        threads.iter().all(|(_, fenced)| *fenced),
        "{which}: threads not fenced: {threads:?}"
    );
}

fn two_hosts(tag: &str, guidance: RemoteGuidance) {
    let hosts = Hosts::new(tag);
    // This thread is host A from here on: the rig binds the GCS's ends on host A's loopback,
    // and every process it starts runs on host A.
    Hosts::enter(&hosts.a);
    let mut rig = Rig::new(&format!("two-hosts-{tag}"));
    binaries::ensure_bridge(&bin_dir(), binaries::Build::IfMissing).unwrap();
    let deployment = credentials(&rig.dir, "credentials");
    bridge_a(&mut rig.config, &deployment);
    let config_b = host_b(&rig.config, &rig.dir, &deployment);
    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    let mut remote = start_host_b(hosts.b.clone(), config_b, rig.dir.clone(), guidance);
    let logs = |fcc: &Process| {
        let b: Vec<String> = remote
            .iter()
            .map(|r| format!("\n--- host B: {} ---\n{}", r.log.display(), r.log_text()))
            .collect();
        format!("\n--- fcc ---\n{}{}", fcc.log_text(), b.concat())
    };

    // The launcher hears the remote guidance's heartbeat through the bridges.
    wait_for(
        &fcc,
        &["alive (not started by the launcher)", "partition=guidance"],
        0,
    );
    // Both bridges authenticated each other (nothing crosses otherwise) and are fenced.
    assert_fenced("host A's bridge", partition_pid(&fcc, "bridge") as u32);
    assert_fenced("host B's bridge", bridge_b_pid(&remote, guidance));
    let mut link = rig.gcs(&mut fcc);
    upload(&mut link, &plan("mission-2.toml"))
        .unwrap_or_else(|e| panic!("upload: {e}{}", logs(&fcc)));
    let mut seen = Vec::new();
    assert_eq!(
        execute_when_ready(&mut link, &mut seen),
        None,
        "{}",
        logs(&fcc)
    );
    let landed = link.run_until(LIMIT, |event| {
        record(&mut seen, event);
        seen.contains(&(3, 0, 0)) && seen.last() == Some(&(0, 0, 0))
    });
    assert!(landed, "FROM-TO-NEXT at the GCS: {seen:?}{}", logs(&fcc));
    // Mission 2: CCP (1), W1 (2), ROLE2 (3); climbing at CCP towards W1, then each leg, at
    // ROLE2, then landed with nothing flown. Before it, the idle (0, 0, 0) may be reported.
    let flown: Vec<_> = seen
        .iter()
        .copied()
        .skip_while(|t| *t == (0, 0, 0))
        .collect();
    assert_eq!(
        flown,
        [(0, 1, 2), (1, 2, 3), (2, 3, 0), (3, 0, 0), (0, 0, 0)],
        "{}",
        logs(&fcc)
    );

    // The link is cut: the remote guidance falls silent for host A. (Lines logged before the
    // cut, by a heartbeat late on a loaded machine, do not count.)
    let alive = ["alive (not started by the launcher)", "partition=guidance"];
    let silent = [
        "not alive (not started by the launcher",
        "partition=guidance",
    ];
    let refusing = ["guidance not alive"];
    let text = fcc.log_text();
    let (silent_before, refusing_before) =
        (count_lines(&text, &silent), count_lines(&text, &refusing));
    let cut = Instant::now();
    hosts.link(false);
    let silent_after = wait_for(&fcc, &silent, silent_before);
    wait_for(&fcc, &refusing, refusing_before);
    assert_eq!(
        execute(&mut link, &mut seen),
        Some(wire::Reason::WrongState),
        "{}",
        logs(&fcc)
    );
    println!(
        "{tag}: the launcher logged the remote guidance not alive {} ms after the veth went down (heartbeat period {} ms)",
        silent_after.as_millis(),
        rig.config.health.period_ms
    );

    // Alive lines from here on are the link's return (the link is down: nothing beats).
    let alive_down = count_lines(&fcc.log_text(), &alive);
    // The link is back: the same processes recover.
    hosts.link(true);
    wait_for(&fcc, &alive, alive_down);
    let before = seen.len();
    assert_eq!(
        execute_when_ready(&mut link, &mut seen),
        None,
        "{}",
        logs(&fcc)
    );
    let flying = link.run_until(LIMIT, |event| {
        record(&mut seen, event);
        seen.len() > before
    });
    assert!(
        flying,
        "no FROM-TO-NEXT after the link came back: {seen:?}{}",
        logs(&fcc)
    );
    println!(
        "{tag}: recovered {:.1} s after the cut; FROM-TO-NEXT at the GCS {seen:?}",
        cut.elapsed().as_secs_f64()
    );
    // No process died on the way: a bridge killed by its own fence (SIGSYS) would show here.
    let died = ["died"];
    let text = logs(&fcc);
    assert_eq!(count_lines(&fcc.log_text(), &died), 0, "{text}");
    for r in &mut remote {
        assert_eq!(count_lines(&r.log_text(), &died), 0, "{text}");
        assert!(
            r.child.try_wait().unwrap().is_none(),
            "{} ended{text}",
            r.log.display()
        );
    }
    drop(link);
    fcc.stop().unwrap();
    drop(remote);
    let bridge = rig.counters("bridge");
    assert!(bridge["in fcc/health/guidance forwarded"] > 0, "{bridge:?}");
    assert!(
        bridge["in fcc/guidance/progress forwarded"] > 0,
        "{bridge:?}"
    );
    assert_eq!(bridge["in fcc/guidance/progress refused"], 0, "{bridge:?}");
    assert!(
        bridge["out fcc/mission/waypoint-list forwarded"] > 0,
        "{bridge:?}"
    );
}

/// The stranger (see the module's documentation): refused, and the FCC's guidance stays silent.
#[test]
fn a_stranger_bridge_is_refused_and_its_guidance_never_reaches_the_fcc() {
    let hosts = Hosts::new("st");
    Hosts::enter(&hosts.a);
    let mut rig = Rig::new("two-hosts-stranger");
    binaries::ensure_bridge(&bin_dir(), binaries::Build::IfMissing).unwrap();
    let deployment = credentials(&rig.dir, "credentials");
    bridge_a(&mut rig.config, &deployment);
    let config_b = host_b(&rig.config, &rig.dir, &deployment);
    // The stranger with another authority's certificate, trusting the FCC's: only the FCC's
    // check of the client certificate stands in its way.
    let other = credentials(&rig.dir, "other-authority");
    std::fs::copy(deployment.join("b/ca.pem"), other.join("b/ca.pem")).unwrap();
    let mut other_ca = config_b.clone();
    other_ca.bridge.credentials = Some(other.join("b"));
    other_ca.latency.summary_dir = Some(rig.dir.join("latency-other-ca"));
    // The stranger without credentials, over plain TCP to the FCC's TLS endpoint.
    let mut plain = config_b.clone();
    plain.bridge.authentication = Authentication::None;
    plain.bridge.credentials = None;
    plain.bridge.connect = vec![format!("tcp/{ADDR_A}:{ZENOH_PORT}")];
    plain.latency.summary_dir = Some(rig.dir.join("latency-plain"));

    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    // The FCC's bridge listens before any stranger knocks.
    wait_for(&fcc, &["bridge up", "authentication=Mtls"], 0);
    let dir = rig.dir.clone();
    // Each failed attempt of a stranger's bridge is a debug line of Zenoh's orchestrator.
    let attempts = "info,zenoh::net::runtime::orchestrator=debug";
    let guidance = start_in(
        &hosts.b,
        "guidance-stub",
        &config_b,
        dir.join("stranger-guidance.log"),
        "info",
    );
    let strangers = [
        start_in(
            &hosts.b,
            "bridge",
            &other_ca,
            dir.join("stranger-other-ca.log"),
            attempts,
        ),
        start_in(
            &hosts.b,
            "bridge",
            &plain,
            dir.join("stranger-plain.log"),
            attempts,
        ),
    ];
    let logs = |fcc: &Process| {
        format!(
            "\n--- fcc ---\n{}\n--- stranger, other authority ---\n{}\n--- stranger, plain ---\n{}\n--- stranger's guidance ---\n{}",
            fcc.log_text(),
            strangers[0].log_text(),
            strangers[1].log_text(),
            guidance.log_text()
        )
    };
    // The stranger's guidance runs and beats; its bridges come up (fenced too) and knock.
    guidance.wait_for_lines(&["isolation applied", "guidance-stub"], 1);
    let refused = ["Unable to connect to configured peer", ZENOH_PORT_TEXT];
    // Zenoh tries again at its retry period (at most 1 s): three refusals each.
    for stranger in &strangers {
        stranger.wait_for_lines(&["bridge up"], 1);
        stranger.wait_for_lines(&refused, 3);
    }
    let alive = ["alive (not started by the launcher)", "partition=guidance"];
    let text = fcc.log_text();
    assert_eq!(
        count_lines(&text, &alive),
        0,
        "the FCC took the stranger's guidance{}",
        logs(&fcc)
    );
    // The FCC's guidance is silent: execute is refused.
    let mut link = rig.gcs(&mut fcc);
    upload(&mut link, &plan("mission-2.toml"))
        .unwrap_or_else(|e| panic!("upload: {e}{}", logs(&fcc)));
    let mut seen = Vec::new();
    assert_eq!(
        execute(&mut link, &mut seen),
        Some(wire::Reason::WrongState),
        "{}",
        logs(&fcc)
    );
    // Still refused after that, and still nothing taken.
    for stranger in &strangers {
        let before = count_lines(&stranger.log_text(), &refused);
        stranger.wait_for_lines(&refused, before + 1);
    }
    assert_eq!(count_lines(&fcc.log_text(), &alive), 0, "{}", logs(&fcc));
    assert!(seen.is_empty(), "FROM-TO-NEXT from a stranger: {seen:?}");
    println!(
        "stranger: refused {} times (other authority) and {} times (no credentials); the FCC never heard its guidance",
        count_lines(&strangers[0].log_text(), &refused),
        count_lines(&strangers[1].log_text(), &refused)
    );

    // Nothing reached the strangers either: the lists and the automation state the FCC published
    // stayed on its side (their summaries, written when they stop).
    drop(strangers);
    for config in [&other_ca, &plain] {
        let dir = config.latency.summary_dir.as_deref().unwrap();
        let summaries = missionlink_partitions::latency::read_summaries(dir);
        let counters = &summaries
            .iter()
            .find(|s| s.partition == "bridge")
            .unwrap_or_else(|| panic!("no summary in {}", dir.display()))
            .counters;
        // What came in from Zenoh (what went out found no one: Zenoh counts a put to no
        // subscriber as done).
        let forwarded: Vec<_> = counters
            .iter()
            .filter(|(name, _)| name.starts_with("in ") && name.ends_with(" forwarded"))
            .collect();
        assert_eq!(forwarded.len(), 3, "{counters:?}");
        assert!(
            forwarded.iter().all(|(_, n)| **n == 0),
            "a stranger forwarded: {counters:?}"
        );
    }

    // The same guidance behind a bridge with the deployment's credentials is heard.
    let bridge = start_in(
        &hosts.b,
        "bridge",
        &config_b,
        dir.join("bridge-b.log"),
        "info",
    );
    wait_for(&fcc, &alive, 0);
    assert_eq!(
        execute_when_ready(&mut link, &mut seen),
        None,
        "\n--- fcc ---\n{}\n--- host B's bridge ---\n{}",
        fcc.log_text(),
        bridge.log_text()
    );
    drop(link);
    fcc.stop().unwrap();
    drop(bridge);
    drop(guidance);
}

#[test]
fn the_fcc_on_one_host_flies_with_the_guidance_stub_on_another() {
    two_hosts("stub", RemoteGuidance::Stub);
}

#[test]
fn the_fcc_on_one_host_flies_with_the_python_guidance_on_another() {
    two_hosts("py", RemoteGuidance::Python);
}
