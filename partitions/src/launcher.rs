//! The `fcc` launcher.
//!
//! The launcher starts the four partitions as child processes with one configuration (the
//! resolved settings, handed over in the environment: no file a `kill -9` could leave behind),
//! and on SIGINT, SIGTERM or a stop request ([`Control`]) stops them all: SIGTERM first, SIGKILL for one
//! that has not ended within the grace period, guidance first and the links last.
//!
//! Before it starts any partition the launcher checks what each needs of the configuration (a
//! wrong one is one error line and exit status 2, nothing started).
//!
//! Supervision (docs/design.md "Health"): a partition that dies is restarted (a log line names it
//! and its exit status), after a pause that doubles with each restart that did not last the
//! start-limit window, up to a longest pause; one started `start_limit_burst` times within the
//! window, or one that exits with status 2 (its configuration cannot work), is not started again:
//! the launcher says so once, by name, withdraws its announcement that the FCC is up and reports
//! the FCC degraded, and keeps supervising the others (systemd's `RestartSec`,
//! `StartLimitBurst` and `StartLimitIntervalSec` are the model). A partition that hangs (stopped, stuck in a step) is found by its
//! heartbeat (`fcc/health/<role>`, [`Liveness`]): silent for 2.5 heartbeat periods, or without a
//! first beat within the start timeout, it is logged by name, killed (SIGKILL ends a stopped
//! process too) and restarted like a dead one. A partition left out (`[launcher] without`, `fcc
//! --without guidance-stub`) is not started: another process fills its role, in any language;
//! the launcher still watches that role's heartbeat and logs when it is alive and when it falls
//! silent, but cannot restart what it did not start.
//!
//! The launcher announces that it is up once every partition has (the harness of the demo and
//! the tests waits for it: `missionlink::harness::fcc`).

use std::io;
use std::os::fd::OwnedFd;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, ExitStatus};
use std::time::{Duration, Instant};

use iceoryx2::prelude::ipc;
use missionlink_flight::health::Liveness;
use missionlink_interfaces::contracts::Partition;
use rustix::event::{PollFd, PollFlags};

use crate::config::{self, Config, FccArgs};
use crate::health::Watch;
use crate::ipc::Ipc;
use crate::runtime::{CONFIG_EXIT_CODE, Control, PartitionError, config_error};
use crate::state::{self};
use crate::voting_monitoring;
use missionlink_platform::clock::DriverClock;

/// The launcher's name (binary).
pub const NAME: &str = "fcc";

/// How long a partition may take to end after SIGTERM.
pub const GRACE: Duration = Duration::from_secs(5);
/// How often the launcher looks at its partitions while one is starting or due to be restarted
/// (their readiness announcements, their first heartbeats), and at a stopping one.
const SUPERVISION_PERIOD: Duration = Duration::from_millis(20);
/// How often it looks at their heartbeats once every partition is up: a hung one is found
/// within its liveness limit and this period. A partition that dies wakes it at once (it
/// sleeps on a pidfd of each child), so a restart waits for no period.
const SETTLED_PERIOD: Duration = Duration::from_millis(100);

/// The flag that makes a partition end with its parent (see `runtime::partition_main`).
const EXIT_WITH_PARENT: &str = "--exit-with-parent";

/// The partitions of `config` the launcher leaves out (`[launcher] without`, by their binary
/// names).
pub fn left_out(config: &Config) -> Result<Vec<Partition>, String> {
    config
        .launcher
        .without
        .iter()
        .map(|name| {
            Partition::from_binary(name).ok_or_else(|| {
                format!(
                    "[launcher] without: no partition {name:?} (the partitions: {})",
                    Partition::BINARIES.join(", ")
                )
            })
        })
        .collect()
}

/// One partition under supervision.
struct Supervised {
    partition: Partition,
    /// Its binary's name.
    name: &'static str,
    /// Started by the launcher (else left out: another process fills the role).
    started_here: bool,
    child: Option<Running>,
    restart_at: Option<Instant>,
    /// When it was started, within the start-limit window.
    starts: std::collections::VecDeque<Instant>,
    /// The pause before its next restart.
    delay: Duration,
    /// Not started again: the start limit was reached, or its configuration cannot work.
    given_up: bool,
    liveness: Liveness,
    /// A left-out role's heartbeat was heard since it was last silent.
    heard: bool,
}

/// A child the launcher started, with a pidfd of it that is readable once it ends
/// ([`wait_for_exit`]); no pidfd where the kernel has none (before Linux 5.3): the launcher then
/// finds its end at its next look. Kept together, so that no pidfd outlives its child.
struct Running {
    child: Child,
    pidfd: Option<OwnedFd>,
}

impl Running {
    fn new(child: Child) -> Self {
        let pidfd = rustix::process::pidfd_open(
            rustix::process::Pid::from_child(&child),
            rustix::process::PidfdFlags::empty(),
        )
        .ok();
        Self { child, pidfd }
    }
}

/// Sleeps until one of the children of `pidfds` ends, a signal arrives (a stop request), or
/// `period` has passed.
fn wait_for_exit<'a>(pidfds: impl Iterator<Item = &'a OwnedFd>, period: Duration) {
    let mut fds: Vec<PollFd<'_>> = pidfds.map(|fd| PollFd::new(fd, PollFlags::IN)).collect();
    let timeout = rustix::time::Timespec::try_from(period).ok();
    match rustix::event::poll(&mut fds, timeout.as_ref()) {
        // Interrupted by a signal: the loop looks at its stop request at once.
        Ok(_) | Err(rustix::io::Errno::INTR) => {}
        // The loop's next look a period later, as without pidfds.
        Err(_) => std::thread::sleep(period),
    }
}

fn signal(child: &Child, signal: rustix::process::Signal) {
    if let Some(pid) = i32::try_from(child.id())
        .ok()
        .and_then(rustix::process::Pid::from_raw)
    {
        let _ = rustix::process::kill_process(pid, signal);
    }
}

/// Sends SIGTERM, waits up to `grace`, then SIGKILL; the exit status.
pub fn terminate(child: &mut Child, grace: Duration) -> io::Result<ExitStatus> {
    signal(child, rustix::process::Signal::TERM);
    let deadline = Instant::now() + grace;
    loop {
        match child.try_wait()? {
            Some(status) => return Ok(status),
            None if Instant::now() < deadline => std::thread::sleep(SUPERVISION_PERIOD),
            None => {
                child.kill()?;
                return child.wait();
            }
        }
    }
}

/// Withdraws `name`'s announcement of readiness in `dir` if process `pid` made it; a failure
/// is logged.
fn withdraw_ready(dir: &Path, name: &str, pid: u32) {
    if let Err(e) = state::withdraw_ready(dir, name, pid) {
        tracing::warn!(%e, dir = %dir.display(), name, "cannot withdraw a readiness announcement");
    }
}

/// An exit status for a log line.
pub fn describe(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exit code {code}"),
        // The kernel's answer to a system call outside the partition's seccomp allow-list
        // (`isolation`, `on_violation = "kill"`).
        (None, Some(signal)) if signal == libc::SIGSYS => {
            format!("killed by signal {signal} (SIGSYS: a system call its isolation forbids)")
        }
        (None, Some(signal)) => format!("killed by signal {signal}"),
        _ => status.to_string(),
    }
}

/// The restart rules of `[launcher]`: the back-off and the start limit.
#[derive(Debug, Clone, Copy)]
struct StartLimit {
    first_delay: Duration,
    max_delay: Duration,
    burst: usize,
    interval: Duration,
}

impl StartLimit {
    fn of(config: &Config) -> Self {
        let l = &config.launcher;
        Self {
            first_delay: Duration::from_millis(l.restart_delay_ms),
            max_delay: Duration::from_millis(l.restart_delay_max_ms.max(l.restart_delay_ms)),
            burst: usize::try_from(l.start_limit_burst)
                .unwrap_or(usize::MAX)
                .max(1),
            interval: Duration::from_millis(l.start_limit_interval_ms),
        }
    }

    /// `p` ended with `status` at `now`: the pause before it is started again, or `None` when
    /// it is not (its configuration cannot work, or it was started `burst` times within the
    /// window). The pause doubles after a run shorter than the window and starts over after a
    /// longer one.
    fn after_death(
        &self,
        p: &mut Supervised,
        status: ExitStatus,
        now: Instant,
    ) -> Option<Duration> {
        while p
            .starts
            .front()
            .is_some_and(|t| now.saturating_duration_since(*t) > self.interval)
        {
            p.starts.pop_front();
        }
        if status.code() == Some(i32::from(CONFIG_EXIT_CODE)) || p.starts.len() >= self.burst {
            p.given_up = true;
            return None;
        }
        let delay = if p.starts.len() <= 1 {
            self.first_delay
        } else {
            p.delay.saturating_mul(2).min(self.max_delay)
        };
        p.delay = delay;
        Some(delay)
    }
}

/// Checks what each partition the launcher starts needs of `config`, before any is started.
fn check_partitions(config: &Config, without: &[Partition]) -> Result<(), PartitionError> {
    if !without.contains(&Partition::VotingMonitoring) {
        voting_monitoring::check_config(config).map_err(|e| {
            let why = match e {
                PartitionError::Config(why) => why,
                other => other.to_string(),
            };
            PartitionError::Config(format!("{}: {why}", Partition::VotingMonitoring.binary()))
        })?;
    }
    crate::isolation::check_config(config).map_err(|e| PartitionError::Config(e.to_string()))?;
    Ok(())
}

/// Supervises the partitions of `bin_dir` under `config` until `control` (or SIGINT/SIGTERM,
/// with `Requests::from_signals`) stops it.
pub fn run(config: &Config, bin_dir: &Path, control: &Control) -> Result<(), PartitionError> {
    let restart_delay = Duration::from_millis(config.launcher.restart_delay_ms);
    let limits = StartLimit::of(config);
    let without = left_out(config).map_err(PartitionError::Config)?;
    check_partitions(config, &without)?;
    let mut partitions = Partition::ALL
        .into_iter()
        .map(|partition| {
            let started_here = !without.contains(&partition);
            Supervised {
                partition,
                name: partition.binary(),
                started_here,
                child: None,
                restart_at: started_here.then(Instant::now),
                starts: std::collections::VecDeque::new(),
                delay: restart_delay,
                given_up: false,
                liveness: Liveness::new(config.health.period()),
                heard: false,
            }
        })
        .collect::<Vec<_>>();
    tracing::info!(
        prefix = %config.ipc.service_prefix,
        direct = %config.links.fcc_direct,
        lte = %config.links.fcc_lte,
        heartbeat_ms = config.health.period().as_millis(),
        without = ?without,
        "starting the FCC partitions"
    );
    let ipc = Ipc::<ipc::Service>::open(NAME, &config.ipc)?;
    let health = Watch::open(&ipc, &Partition::ALL)?;
    let clock = DriverClock::start();
    // Announcements of an earlier instance in the same directory say nothing about this one.
    let state_dir = config.ipc.state_dir();
    for name in Partition::BINARIES.iter().chain([&NAME]) {
        if let Err(e) = state::forget_ready(&state_dir, name) {
            tracing::warn!(%e, dir = %state_dir.display(), name, "cannot clear an old announcement");
        }
    }
    let own = std::process::id();
    let mut bridge = BridgeChild::of(config);
    let mut all_up = false;
    // A partition was given up: the FCC stays announced down.
    let mut degraded = false;
    control.ready.set();
    while !control.requests.stop_requested() {
        let now = clock.now();
        health.receive(|role, beat| {
            for p in partitions.iter_mut().filter(|p| p.partition == role) {
                if p.liveness.handle_beat(now, beat) && !p.started_here && !p.heard {
                    p.heard = true;
                    tracing::info!(partition = %role, pid = beat.pid, "alive (not started by the launcher)");
                }
            }
        });
        for p in &mut partitions {
            if let Some(silence) = p.liveness.poll(now) {
                match p.child.as_ref().map(|r| &r.child) {
                    Some(child) => {
                        tracing::error!(
                            partition = p.name,
                            pid = child.id(),
                            %silence,
                            limit_ms = p.liveness.limit().as_millis(),
                            "partition hung: killing it to restart it"
                        );
                        signal(child, rustix::process::Signal::KILL);
                    }
                    None if !p.started_here => {
                        p.heard = false;
                        tracing::warn!(
                            partition = %p.partition,
                            %silence,
                            "not alive (not started by the launcher, so not restarted)"
                        );
                    }
                    None => {}
                }
            }
            if let Some(Running { child, .. }) = p.child.as_mut() {
                if let Ok(Some(status)) = child.try_wait() {
                    let pid = child.id();
                    p.child = None;
                    p.liveness.forget();
                    match limits.after_death(p, status, Instant::now()) {
                        Some(delay) => {
                            tracing::error!(
                                partition = p.name,
                                status = %describe(status),
                                "partition died; restarting in {} ms",
                                delay.as_millis()
                            );
                            p.restart_at = Some(Instant::now() + delay);
                        }
                        None => {
                            degraded = true;
                            tracing::error!(
                                partition = p.name,
                                status = %describe(status),
                                starts = p.starts.len(),
                                window_s = limits.interval.as_secs_f64(),
                                "partition not started again ({}): the FCC is degraded",
                                if status.code() == Some(i32::from(CONFIG_EXIT_CODE)) {
                                    "its configuration cannot work"
                                } else {
                                    "start limit reached"
                                }
                            );
                        }
                    }
                    // Killed, it could not withdraw its announcement itself.
                    withdraw_ready(&state_dir, p.name, pid);
                    if all_up {
                        withdraw_ready(&state_dir, NAME, own);
                        all_up = false;
                    }
                }
            }
            if p.restart_at.is_some_and(|t| Instant::now() >= t) {
                p.restart_at = None;
                let mut command = Command::new(bin_dir.join(p.name));
                command.arg(EXIT_WITH_PARENT);
                let spawned = config::hand_to(&mut command, config)
                    .map_err(io::Error::other)
                    .and_then(|()| command.spawn());
                match spawned {
                    Ok(child) => {
                        tracing::info!(partition = p.name, pid = child.id(), "started");
                        p.starts.push_back(Instant::now());
                        p.liveness
                            .expect(clock.now(), child.id(), config.health.start_timeout());
                        p.child = Some(Running::new(child));
                    }
                    Err(e) => {
                        tracing::error!(partition = p.name, %e, "cannot start; retrying");
                        p.restart_at = Some(Instant::now() + restart_delay);
                    }
                }
            }
        }
        if !all_up
            && !degraded
            && partitions
                .iter()
                .filter(|p| p.started_here)
                .all(|p| state::is_ready(&state_dir, p.name) && p.liveness.is_alive(now))
        {
            all_up = true;
            tracing::info!("all partitions up");
            if let Err(e) = state::announce_ready(&state_dir, NAME) {
                tracing::warn!(%e, dir = %state_dir.display(), "cannot announce readiness");
            }
        }
        if bridge.supervise(config, bin_dir, restart_delay) {
            // The other host's partitions are out of reach for good: not up, degraded.
            degraded = true;
            if all_up {
                withdraw_ready(&state_dir, NAME, own);
                all_up = false;
            }
        }
        let settled = (all_up || degraded)
            && partitions.iter().all(|p| p.restart_at.is_none())
            && bridge.start_at.is_none();
        let pidfds = partitions
            .iter()
            .filter_map(|p| p.child.as_ref())
            .chain(bridge.child.as_ref())
            .filter_map(|r| r.pidfd.as_ref());
        wait_for_exit(
            pidfds,
            if settled {
                SETTLED_PERIOD
            } else {
                SUPERVISION_PERIOD
            },
        );
    }
    tracing::info!("stopping the FCC partitions");
    bridge.stop();
    withdraw_ready(&state_dir, NAME, own);
    for p in partitions.iter_mut().rev() {
        if let Some(Running { mut child, .. }) = p.child.take() {
            match terminate(&mut child, GRACE) {
                Ok(status) if status.signal() == Some(9) => {
                    tracing::warn!(partition = p.name, "did not stop in time: killed");
                }
                Ok(status) => {
                    tracing::info!(partition = p.name, status = %describe(status), "stopped")
                }
                Err(e) => tracing::warn!(partition = p.name, %e, "cannot stop"),
            }
        }
    }
    Ok(())
}

/// The bridge to another host (`[bridge]`, docs/two-hosts.md), when enabled: started with the
/// partitions, restarted after the restart delay when it dies, stopped last. It has no role and
/// no heartbeat: the heartbeats of the remote partitions it carries are its health.
struct BridgeChild {
    enabled: bool,
    child: Option<Running>,
    start_at: Option<Instant>,
}

impl BridgeChild {
    fn of(config: &Config) -> Self {
        Self {
            enabled: config.bridge.enabled,
            child: None,
            start_at: config.bridge.enabled.then(Instant::now),
        }
    }

    /// Starts, watches and restarts the bridge; `true` when it gives it up now (its
    /// configuration cannot work, or there is no binary): the FCC is degraded from then on.
    fn supervise(&mut self, config: &Config, bin_dir: &Path, restart_delay: Duration) -> bool {
        if !self.enabled {
            return false;
        }
        let died = self
            .child
            .as_mut()
            .and_then(|r| r.child.try_wait().ok().flatten());
        if let Some(status) = died {
            self.child = None;
            if status.code() == Some(i32::from(CONFIG_EXIT_CODE)) {
                // Starting it again cannot help: its configuration cannot work.
                tracing::error!(
                    status = %describe(status),
                    "bridge not started again (its configuration cannot work): the FCC is degraded"
                );
                self.enabled = false;
                return true;
            }
            tracing::error!(status = %describe(status), "bridge died; restarting it");
            self.start_at = Some(Instant::now() + restart_delay);
        }
        if self.start_at.is_some_and(|t| Instant::now() >= t) {
            self.start_at = None;
            let mut command = Command::new(bin_dir.join(crate::bridge_config::BINARY));
            command.arg(EXIT_WITH_PARENT);
            let spawned = config::hand_to(&mut command, config)
                .map_err(io::Error::other)
                .and_then(|()| command.spawn());
            match spawned {
                Ok(child) => {
                    tracing::info!(partition = "bridge", pid = child.id(), "started");
                    self.child = Some(Running::new(child));
                }
                Err(e) if e.kind() == io::ErrorKind::NotFound => {
                    // Retrying cannot help: the bridge is a package of its own, built apart.
                    tracing::error!(
                        %e,
                        dir = %bin_dir.display(),
                        "no bridge binary: build it with `cargo build --release -p missionlink-bridge`; the FCC runs without it, degraded"
                    );
                    self.enabled = false;
                    return true;
                }
                Err(e) => {
                    tracing::error!(%e, "cannot start the bridge; retrying");
                    self.start_at = Some(Instant::now() + restart_delay);
                }
            }
        }
        false
    }

    fn stop(&mut self) {
        if let Some(Running { mut child, .. }) = self.child.take() {
            match terminate(&mut child, GRACE) {
                Ok(status) => {
                    tracing::info!(partition = "bridge", status = %describe(status), "stopped")
                }
                Err(e) => tracing::warn!(partition = "bridge", %e, "cannot stop"),
            }
        }
    }
}

/// The `main` of `fcc`: the configuration (exit status 2 when it is wrong) with the partitions
/// `without` added to those it leaves out, `--print-config`, then [`run`] until SIGINT or
/// SIGTERM.
pub fn main(
    args: &FccArgs,
    without: &[String],
    bin_dir: Option<PathBuf>,
    print_config: bool,
) -> ExitCode {
    missionlink_platform::init_logging();
    crate::ipc::quiet_iceoryx2_log();
    let mut config = match Config::resolve(args) {
        Ok(c) => c,
        Err(e) => return config_error(&e),
    };
    config.launcher.without.extend(without.iter().cloned());
    if let Err(e) = left_out(&config) {
        tracing::error!(%e, "configuration");
        return ExitCode::from(2);
    }
    if print_config {
        return match config.to_toml() {
            Ok(text) => {
                print!("{text}");
                ExitCode::SUCCESS
            }
            Err(e) => config_error(&e),
        };
    }
    // Beside the launcher, where `cargo build` and the installation both put them.
    let own_dir = || {
        std::env::current_exe()
            .ok()?
            .parent()
            .map(Path::to_path_buf)
    };
    let Some(bin_dir) = bin_dir.or_else(own_dir) else {
        tracing::error!("cannot find the partition binaries: give --bin-dir");
        return ExitCode::from(2);
    };
    if args.exit_with_parent {
        missionlink_platform::parent::exit_with_parent();
    }
    let control = Control::new();
    let result = control
        .requests
        .from_signals()
        .and_then(|()| run(&config, &bin_dir, &control));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e @ PartitionError::Config(_)) => {
            tracing::error!(%e, "the FCC cannot come up");
            ExitCode::from(CONFIG_EXIT_CODE)
        }
        Err(e) => {
            tracing::error!(%e, "fcc launcher failed");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partition_left_out_must_be_one_of_the_partitions() {
        let mut config = Config::default();
        assert!(left_out(&config).unwrap().is_empty());
        config.launcher.without = vec!["guidance-stub".to_owned()];
        assert_eq!(left_out(&config).unwrap(), [Partition::Guidance]);
        config.launcher.without.push("guidance".to_owned());
        let e = left_out(&config).unwrap_err();
        assert!(
            e.contains("no partition \"guidance\"") && e.contains("guidance-stub"),
            "{e}"
        );
    }
}
