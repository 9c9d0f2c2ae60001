//! The harness of the cross-process tests (`tests/system/`) and the benches: running the real
//! binaries, an FCC (the launcher and its partitions) under a prefix, ports and state directory
//! of its own, so tests run in parallel; and the GCS over UDP in the test. The GCS binds its
//! ends itself (port 0) and the FCC's voting-monitoring binds and announces its own: every port
//! is chosen by the process that binds it.
//!
//! - [`binaries`]: where the FCC's binaries are, built with cargo when missing;
//! - [`fcc`]: an FCC binary as a child process ([`fcc::FccProcess`], [`fcc::local_config`]);
//! - [`ground`]: the ground played message by message, for tests of the FCC's answers;
//! - [`netns`]: two hosts on one machine (network namespaces and a veth pair);
//! - [`log_axis`]: the benches' SVG plots.
//!
//! Test code: a setup that fails is a broken test or bench, not outside input, so this module
//! unwraps and panics where the product crates may not.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    missing_docs,
    reason = "the harness of tests and benches: a setup that fails is a broken test"
)]

pub mod binaries;
pub mod fcc;
pub mod ground;
pub mod log_axis;
pub mod netns;
pub mod service;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use fcc::{FccProcess, local_config};
use missionlink_gcs::gcs_link::{Direction, Finished, GcsLink};
use missionlink_gcs::mission_file::MissionFile;
use missionlink_ground::ground_station::{GcsError, MissionPlan, ValidatedPlan, WithoutGateway};
use missionlink_interfaces::wire::{Message, MissionPlanMode, MissionReport};
use missionlink_partitions::config::Config;
use missionlink_partitions::latency::Summary;
use missionlink_platform::udp::{LinkPair, LocalEnds};
use missionlink_protocol::transfer::sender::mission_command;

pub type Link = GcsLink<WithoutGateway>;
pub type Error = GcsError<core::convert::Infallible>;
pub type Process = FccProcess;

/// The directory of the partition binaries, built if missing.
pub fn bin_dir() -> PathBuf {
    let dir = binaries::build_dir().expect("build directory");
    binaries::ensure(&dir, &binaries::FCC_BINARIES, binaries::Build::IfMissing)
        .expect("partition binaries")
}

/// The Python interpreter the tests run: `MISSIONLINK_PYTHON` (set by `tools/test` to the
/// virtual environment it made), else that environment if an earlier `tools/test` made it
/// (`<target>/venv`), else `python3` from the path.
pub fn python() -> PathBuf {
    if let Some(python) = std::env::var_os("MISSIONLINK_PYTHON") {
        return PathBuf::from(python);
    }
    // The test runs as <target>/<profile>/deps/<test>.
    let exe = std::env::current_exe().expect("the test's own path");
    let venv = exe
        .ancestors()
        .nth(3)
        .map(|target| target.join("venv/bin/python3"));
    match venv {
        Some(venv) if venv.is_file() => venv,
        _ => PathBuf::from("python3"),
    }
}

/// One test's FCC setup: a configuration no other test shares (prefix, GCS ports, state and
/// summary directories) in a directory of its own.
pub struct Rig {
    pub config: Config,
    pub dir: PathBuf,
    gcs_ends: Option<LocalEnds>,
}

impl Rig {
    pub fn new(test: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("missionlink-test-{test}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let gcs_ends = LocalEnds::bind_loopback().unwrap();
        let prefix = format!("test-{test}-{}", std::process::id());
        let mut config = local_config(&dir, prefix, &gcs_ends).unwrap();
        config.guidance.time_scale = 50.0;
        config.launcher.restart_delay_ms = 100;
        // Tests kill partitions many times in a row (restart_safety, link_faults): no growing
        // pause and no start limit there (tests/system/supervision.rs sets its own).
        config.launcher.restart_delay_max_ms = 100;
        config.launcher.start_limit_burst = 1000;
        Self {
            config,
            dir,
            gcs_ends: Some(gcs_ends),
        }
    }

    /// Starts `binary` under the rig's configuration, its log in `<dir>/<binary>.log`.
    pub fn start(&self, binary: &str) -> Process {
        let log = self.dir.join(format!("{binary}.log"));
        FccProcess::start(&bin_dir(), binary, &self.config, Some(&log)).unwrap()
    }

    /// Starts the launcher `fcc` under the rig's configuration and waits until every partition
    /// is up.
    pub fn start_fcc(&self) -> Process {
        let mut fcc = self.start("fcc");
        self.ready(&mut fcc);
        fcc
    }

    /// A rig for `test` with its FCC up and a GCS talking to it: where most tests begin.
    pub fn with_gcs(test: &str) -> (Self, Process, Link) {
        let mut rig = Self::new(test);
        let mut fcc = rig.start_fcc();
        let link = rig.gcs(&mut fcc);
        (rig, fcc, link)
    }

    /// Waits until `process` (the launcher or a partition) is up: for the launcher, every
    /// partition's services are open.
    pub fn ready(&self, process: &mut Process) {
        assert!(
            process.wait_ready(Duration::from_secs(20)),
            "{:?} did not come up:\n{}",
            process.log_path(),
            process.log_text()
        );
    }

    /// Waits for `fcc` (the launcher or voting-monitoring) to announce its ports and points the
    /// configuration at them.
    pub fn learn_links(&mut self, fcc: &mut Process) {
        let links = fcc
            .links(Duration::from_secs(20))
            .unwrap_or_else(|| panic!("no links announced:\n{}", fcc.log_text()));
        links.apply(&mut self.config.links);
    }

    /// The GCS over the rig's GCS ends, talking to the ports `fcc` announced (once per rig).
    pub fn gcs(&mut self, fcc: &mut Process) -> Link {
        let links = self.gcs_links(fcc);
        self.gcs_on(links)
    }

    /// A GCS on `links`, its time stamps reserved in the rig's directory as the gcs tool
    /// reserves them: a GCS started again on the same links continues after them.
    pub fn gcs_on(&self, links: LinkPair) -> Link {
        GcsLink::with_links(&self.config.link(), links, WithoutGateway)
            .unwrap()
            .with_stamp_lease(&self.dir.join("gcs-time-stamps"))
            .unwrap()
    }

    /// Where the rig's GCS ends are bound (direct, LTE).
    pub fn gcs_addrs(&self) -> [std::net::SocketAddr; 2] {
        self.gcs_ends
            .as_ref()
            .expect("the GCS ends are not taken yet")
            .addrs()
            .unwrap()
    }

    /// The rig's GCS ends connected to `peer` (direct, LTE): the link emulator's ports, say
    /// (once per rig).
    pub fn gcs_links_to(&mut self, peer: [std::net::SocketAddr; 2]) -> LinkPair {
        let ends = self.gcs_ends.take().expect("one GCS per rig");
        ends.connect(peer[0], peer[1]).unwrap()
    }

    /// The rig's GCS ends connected to the ports `fcc` announced, for a test that plays the
    /// ground itself (once per rig, like [`Rig::gcs`]).
    pub fn gcs_links(&mut self, fcc: &mut Process) -> LinkPair {
        self.learn_links(fcc);
        let ends = self.gcs_ends.take().expect("one GCS per rig");
        ends.connect(self.config.links.fcc_direct, self.config.links.fcc_lte)
            .unwrap()
    }

    /// Starts the FCC behind a link emulator with `flows` (a profile's, say) and points the
    /// configuration's FCC ends at the emulator's ground-facing ports, so that a fleet file
    /// written from the rig (`service::fleet_file`) sends through it. Gives the FCC, the
    /// emulator and the FCC's own ends (to start it again on them).
    pub fn start_fcc_behind(
        &mut self,
        flows: [missionlink_linksim::channel::Impairments; 4],
        seed: u64,
    ) -> (
        Process,
        crate::link_emulator::Emulator,
        [std::net::SocketAddr; 2],
    ) {
        use crate::link_emulator::{Emulator, EmulatorConfig};
        let emulator = Emulator::start(EmulatorConfig {
            gcs: self.gcs_addrs(),
            flows,
            seed,
        })
        .unwrap();
        let [direct, lte] = emulator.fcc_facing();
        self.config.links.gcs_direct = direct;
        self.config.links.gcs_lte = lte;
        let mut fcc = self.start_fcc();
        self.learn_links(&mut fcc);
        let own = [self.config.links.fcc_direct, self.config.links.fcc_lte];
        emulator.set_fcc(own);
        [self.config.links.fcc_direct, self.config.links.fcc_lte] = emulator.gcs_facing();
        (fcc, emulator, own)
    }

    /// Releases the rig's GCS ends and gives where they were bound (direct, LTE), for a ground
    /// service to bind them: the FCC sends there.
    pub fn release_gcs_ends(&mut self) -> [std::net::SocketAddr; 2] {
        let ends = self.gcs_ends.take().expect("one GCS per rig");
        ends.addrs().unwrap()
    }

    /// The summaries the partitions wrote at shutdown.
    pub fn summaries(&self) -> Vec<Summary> {
        missionlink_partitions::latency::read_summaries(&self.dir.join("latency"))
    }

    /// The counters `partition` wrote in its summary at shutdown.
    pub fn counters(&self, partition: &str) -> std::collections::BTreeMap<String, u64> {
        self.summaries()
            .into_iter()
            .find(|s| s.partition == partition)
            .unwrap_or_else(|| panic!("no summary of {partition}"))
            .counters
    }

    /// Starts the FCC (the `fcc` launcher) behind a link emulator with `config` (its `gcs`
    /// taken from the rig's GCS ends): the FCC sends to the emulator's fcc-facing ports, the
    /// GCS to its gcs-facing ones. The rig's configuration (timeouts, say) is set before.
    pub fn start_through(
        &mut self,
        flows: [crate::link_emulator::Impairments; 4],
        seed: u64,
    ) -> (Process, Link, crate::link_emulator::Emulator) {
        let (fcc, emulator, _) = self.start_fcc_behind(flows, seed);
        let links = self.gcs_links_to(emulator.gcs_facing());
        let link = self.gcs_on(links);
        (fcc, link, emulator)
    }
}

/// The rig's directory (state, logs, summaries) goes with it, unless
/// `MISSIONLINK_KEEP_TEST_DIRS` is set (to read the partitions' logs after a failure).
impl Drop for Rig {
    fn drop(&mut self) {
        if std::env::var_os("MISSIONLINK_KEEP_TEST_DIRS").is_some() {
            eprintln!("kept {}", self.dir.display());
            return;
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// CPU time of the whole machine from /proc/stat, in clock ticks (USER_HZ, 100 a second):
/// (busy, total). Busy counts everything but idle and I/O wait, including time stolen by the
/// hypervisor.
pub fn machine_ticks() -> (u64, u64) {
    let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
    let fields: Vec<u64> = stat
        .lines()
        .next()
        .unwrap_or_default()
        .split_whitespace()
        .skip(1)
        .take(8)
        .filter_map(|v| v.parse().ok())
        .collect();
    let total: u64 = fields.iter().sum();
    let idle = fields.get(3).copied().unwrap_or(0) + fields.get(4).copied().unwrap_or(0);
    (total.saturating_sub(idle), total)
}

/// Whether process `pid` runs: it exists and is no zombie (a process that ended and waits to
/// be reaped runs no more).
pub fn runs(pid: i32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        !stat
            .rsplit(')')
            .next()
            .unwrap_or("")
            .trim_start()
            .starts_with('Z')
    })
}

/// Polls `f` every 10 ms until it gives a value or `limit` passes.
pub fn eventually<T>(limit: Duration, mut f: impl FnMut() -> Option<T>) -> Option<T> {
    let end = Instant::now() + limit;
    while Instant::now() < end {
        if let Some(v) = f() {
            return Some(v);
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    None
}

/// Two commands that would change the active mission if the FCC processed them, not yet
/// stamped: a clear (which deletes it, ICD §5.1), and a transmit of the empty list (Waypoint
/// Number 0). The attacks of the tests send them from where the FCC must not take them.
pub fn clearing_commands() -> [Message; 2] {
    [
        mission_command(MissionPlanMode::ClearMission, None, None),
        mission_command(MissionPlanMode::TransmitMission, Some(0), None),
    ]
}

/// Waits until `process`'s log says `text`, or panics after `limit`.
pub fn wait_for_log(process: &Process, text: &str, limit: Duration) {
    wait_for_logs(process, text, 1, limit);
}

/// Waits until `process`'s log says `text` `times` times, or panics after `limit`.
pub fn wait_for_logs(process: &Process, text: &str, times: usize, limit: Duration) {
    let end = Instant::now() + limit;
    while Instant::now() < end {
        if process.log_text().matches(text).count() >= times {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    panic!(
        "{:?} never logged {text:?} {times} times:\n{}",
        process.log_path(),
        process.log_text()
    );
}

pub fn plan(file: &str) -> MissionPlan {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("missions")
        .join(file);
    *MissionFile::read(&path).unwrap().to_plan().unwrap()
}

/// Runs the link until the request ends.
pub fn finish(link: &mut Link) -> Result<Finished, Error> {
    link.finish(|_| {})
}

pub fn upload(link: &mut Link, plan: &MissionPlan) -> Result<(), Error> {
    let now = link.now();
    link.station().upload(now, plan, true)?;
    finish(link).map(|_| ())
}

pub fn download(link: &mut Link) -> Result<ValidatedPlan, Error> {
    let now = link.now();
    link.station().download(now)?;
    finish(link).map(|f| f.into_plan().expect("lists"))
}

/// The FCC's report (ICD §8): the active lists, then each staged mission.
pub fn report(link: &mut Link) -> Vec<MissionReport> {
    let now = link.now();
    link.station().report(now).unwrap();
    match finish(link) {
        Ok(Finished::Reported(entries)) => entries,
        other => panic!("no report: {other:?}"),
    }
}

/// The process ID of the running `partition` (the last one the launcher `fcc` started).
pub fn partition_pid(fcc: &Process, partition: &str) -> i32 {
    let tag = format!("partition=\"{partition}\"");
    fcc.log_text()
        .lines()
        .rev()
        .filter(|l| l.contains("started") && l.contains(&tag))
        .filter_map(|l| l.split("pid=").nth(1))
        .find_map(|p| p.trim().parse().ok())
        .expect("pid of the partition")
}

/// Waits until the launcher `fcc` has started `partition` `times` times (once, and once per
/// restart), or panics after `limit`.
pub fn wait_for_starts(fcc: &Process, partition: &str, times: usize, limit: Duration) {
    wait_for_logs(
        fcc,
        &format!("started partition=\"{partition}\""),
        times,
        limit,
    );
}

/// Sends `signal` to the running `partition` of the launcher `fcc`.
pub fn signal_partition(fcc: &Process, partition: &str, signal: rustix::process::Signal) {
    let pid = rustix::process::Pid::from_raw(partition_pid(fcc, partition)).unwrap();
    rustix::process::kill_process(pid, signal).unwrap();
}

/// The checksums of the active lists (mission, areas), as the FCC reports them (ICD §11).
pub fn active_checksums(link: &mut Link) -> (Option<u32>, Option<u32>) {
    let entries = report(link);
    let active = &entries[0];
    assert!(
        active.mission_id.is_some_and(|t| t.is_empty()),
        "{active:?}"
    );
    (
        active.mission_checksum.map(|c| c.value()),
        active.area_checksum.map(|c| c.value()),
    )
}

/// The checksums of `plan`'s lists (mission, areas), as the FCC computes them (ICD §11).
pub fn plan_checksums(plan: &ValidatedPlan) -> (Option<u32>, Option<u32>) {
    use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
    (
        Some(mission_checksum(&plan.mission).value()),
        Some(areas_checksum(&plan.areas).value()),
    )
}

/// Messages logged in `direction` since log entry `from` (the GCS's log, `enable_log`).
pub fn logged_since(link: &Link, from: usize, direction: Direction) -> usize {
    link.log
        .get(from..)
        .unwrap_or_default()
        .iter()
        .filter(|l| l.direction == direction)
        .count()
}

/// Lines of `text` holding every one of `parts`.
pub fn count_lines(text: &str, parts: &[&str]) -> usize {
    text.lines()
        .filter(|l| parts.iter().all(|p| l.contains(p)))
        .count()
}

/// Waits until `process`'s log holds a line with every one of `parts` (more than `before`
/// such lines), or panics after `limit`; the time it took.
pub fn wait_for_line(
    process: &Process,
    parts: &[&str],
    before: usize,
    limit: Duration,
) -> Duration {
    let start = Instant::now();
    while start.elapsed() < limit {
        if count_lines(&process.log_text(), parts) > before {
            return start.elapsed();
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!(
        "{:?} never logged a line with {parts:?}:\n{}",
        process.log_path(),
        process.log_text()
    );
}

/// The Python guidance (partitions/python/missionlink_guidance.py).
pub fn python_guidance_script() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("partitions/python/missionlink_guidance.py")
}

/// The command that starts the Python guidance as `config` sets the guidance stub (prefix,
/// time scale, start position, rates, heartbeat period); stdin closed, the rest the caller's.
pub fn python_guidance_command(config: &Config) -> std::process::Command {
    let g = &config.guidance;
    let mut command = std::process::Command::new(python());
    command
        .arg(python_guidance_script())
        .args(["--service-prefix", &config.ipc.service_prefix])
        .args(["--time-scale", &g.time_scale.to_string()])
        .args(["--start-latitude", &g.start_latitude_deg.to_string()])
        .args(["--start-longitude", &g.start_longitude_deg.to_string()])
        .args(["--climb-rate", &g.climb_rate_mps.to_string()])
        .args(["--descent-rate", &g.descent_rate_mps.to_string()])
        .args(["--max-bank-deg", &g.max_bank_deg.to_string()])
        .args(["--update-interval-ms", &g.update_interval_ms.to_string()])
        .args(["--wind-speed-mps", &g.wind_speed_mps.to_string()])
        .args(["--wind-from-deg", &g.wind_from_deg.to_string()])
        .args([
            "--heartbeat-period-ms",
            &config.health.period_ms.to_string(),
        ])
        .stdin(std::process::Stdio::null());
    command
}

/// Keeps the waypoint numbers (0 for none) of a #4001 the GCS received.
pub fn record<R>(
    seen: &mut Vec<(u16, u16, u16)>,
    event: &missionlink_ground::ground_station::GcsEvent<R>,
) {
    if let missionlink_ground::ground_station::GcsEvent::FromToNext(f) = event {
        seen.push((
            f.from.waypoint_number.unwrap_or(0),
            f.to.waypoint_number.unwrap_or(0),
            f.next.waypoint_number.unwrap_or(0),
        ));
    }
}
