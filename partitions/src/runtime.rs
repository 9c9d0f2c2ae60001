//! What every partition's event loop shares: the [`Control`] that starts and stops a loop (from
//! another thread, or by SIGINT/SIGTERM), sleeping in the WaitSet (or spinning with `--poll`)
//! until data, a deadline or a stop, after a bounded spin on the inputs when the partition's
//! idle strategy says so ([`Control::wait_idle`], `config::Idle`); [`run_loop`], the one loop
//! skeleton every partition runs; latency reports on an interval, on SIGUSR1 and at shutdown;
//! and the `main` of every partition binary.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;
use iceoryx2::waitset::{WaitSetRunError, WaitSetRunResult};

use missionlink_interfaces::contracts::Partition;

use crate::config::{Config, ConfigError, FccArgs, Idle, IdleMode};
use crate::doorbell::Doorbell;
use crate::health::Heartbeat;
use crate::ipc::{Ipc, IpcError};
use crate::isolation::{Fence, IsolationError};
use crate::latency::{self, Recorder};
use crate::state;
use missionlink_platform::udp::LinkError;

/// The longest a loop sleeps before it looks at its stop flag: a [`Control::stop`] from another
/// thread, or a signal that lands on another thread of the process, ends the loop within this.
pub const STOP_LATENCY: Duration = Duration::from_millis(50);

/// Why a partition loop ended with an error.
#[derive(Debug, thiserror::Error)]
pub enum PartitionError {
    /// iceoryx2 refused a node, service or port, or a sample could not be sent.
    #[error("iceoryx2: {0}")]
    Ipc(#[from] IpcError),
    /// The WaitSet could not be created, attached to or waited on.
    #[error("WaitSet: {0}")]
    WaitSet(String),
    /// A UDP link could not be set up.
    #[error("link: {0}")]
    Link(#[from] LinkError),
    /// The configuration cannot work (for example a peer address without a port).
    #[error("configuration: {0}")]
    Config(String),
    /// A signal handler could not be installed.
    #[error("signal handler: {0}")]
    Signals(std::io::Error),
    /// The partition could not fence itself as configured (`isolation`).
    #[error("isolation: {0}")]
    Isolation(crate::isolation::IsolationError),
}

impl PartitionError {
    /// A WaitSet error (the iceoryx2 error types have `Debug` only).
    pub fn waitset(e: impl std::fmt::Debug) -> Self {
        Self::WaitSet(format!("{e:?}"))
    }
}

/// Starts and stops a partition loop and asks it for reports: the loop says when its ports are
/// open ([`Control::wait_ready`]), ends within [`STOP_LATENCY`] of [`Control::stop`] and logs
/// its latency percentiles after [`Control::request_report`]. In a process,
/// [`Control::handle_signals`] makes SIGINT and SIGTERM stop it and SIGUSR1 ask for a report.
/// Cloning gives another handle to the same loop.
#[derive(Debug, Clone, Default)]
pub struct Control {
    stop: Arc<AtomicBool>,
    report: Arc<AtomicBool>,
    ready: Arc<(Mutex<bool>, Condvar)>,
    /// Where and under which name readiness is announced to other processes, if it is.
    announce: Option<(PathBuf, String)>,
    /// The fence the loop applies once its ports are open, and the launcher to watch after it
    /// (`isolation`); taken when applied.
    fence: Arc<Mutex<PendingFence>>,
}

/// A fence not applied yet, and the launcher to watch once it is.
type PendingFence = Option<(Fence, Option<rustix::process::Pid>)>;

impl Control {
    /// A control of a loop not started yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the loop to end.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Whether the loop was asked to end.
    pub fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Asks the loop to log its latency percentiles now.
    pub fn request_report(&self) {
        self.report.store(true, Ordering::Relaxed);
    }

    /// Whether a report was asked for since the last call.
    pub fn take_report_request(&self) -> bool {
        self.report.swap(false, Ordering::Relaxed)
    }

    /// The signals of a partition process: SIGINT and SIGTERM stop the loop, SIGUSR1 asks for a
    /// report. These are this process's handlers, not iceoryx2's: the WaitSets run with its
    /// signal handling disabled ([`waitset`]), since iceoryx2's handler takes SIGUSR1 as well
    /// and any signal would end the wait as if it were a termination request.
    pub fn handle_signals(&self) -> Result<(), PartitionError> {
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            signal_hook::flag::register(signal, Arc::clone(&self.stop))
                .map_err(PartitionError::Signals)?;
        }
        self.report_on_sigusr1()
    }

    fn report_on_sigusr1(&self) -> Result<(), PartitionError> {
        signal_hook::flag::register(signal_hook::consts::SIGUSR1, Arc::clone(&self.report))
            .map_err(PartitionError::Signals)?;
        Ok(())
    }

    /// A control that also announces the loop's readiness in the state directory `dir` as
    /// `name` ([`state::announce_ready`]), for the processes that wait for a partition process
    /// to be up; [`Control::forget_ready`] withdraws it.
    pub fn announcing_ready(mut self, dir: PathBuf, name: &str) -> Self {
        self.announce = Some((dir, name.to_owned()));
        self
    }

    /// A control whose loop fences itself with `fence` once its ports are open
    /// ([`Control::fence`]) and then, with `parent`, starts the watch that ends the process
    /// when that parent is gone (after the fence, so that the watch's thread is fenced too).
    pub fn fencing(self, fence: Option<Fence>, parent: Option<rustix::process::Pid>) -> Self {
        if let Ok(mut slot) = self.fence.lock() {
            *slot = fence.map(|f| (f, parent)).or_else(|| {
                // No fence: the watch starts at once.
                if let Some(parent) = parent {
                    watch_parent(parent);
                }
                None
            });
        }
        self
    }

    /// Applies the fence of [`Control::fencing`], once (the loop calls it when its ports are
    /// open, before it announces that it is ready); nothing without one.
    pub fn fence(&self) -> Result<(), PartitionError> {
        let taken = self.fence.lock().ok().and_then(|mut slot| slot.take());
        if let Some((fence, parent)) = taken {
            fence.apply().map_err(PartitionError::Isolation)?;
            if let Some(parent) = parent {
                watch_parent(parent);
            }
        }
        Ok(())
    }

    /// Called by the loop once its ports are open and it is about to wait.
    pub fn set_ready(&self) {
        let (ready, changed) = &*self.ready;
        if let Ok(mut r) = ready.lock() {
            *r = true;
            changed.notify_all();
        }
        if let Some((dir, name)) = &self.announce {
            if let Err(e) = state::announce_ready(dir, name) {
                tracing::warn!(%e, dir = %dir.display(), "cannot announce readiness");
            }
        }
    }

    /// Withdraws the announcement of [`Control::announcing_ready`] (at shutdown).
    pub fn forget_ready(&self) {
        if let Some((dir, name)) = &self.announce {
            if let Err(e) = state::withdraw_ready(dir, name, std::process::id()) {
                tracing::warn!(%e, dir = %dir.display(), "cannot withdraw the readiness");
            }
        }
    }

    /// Waits until the loop is ready; `false` when `limit` passed first.
    pub fn wait_ready(&self, limit: Duration) -> bool {
        let (ready, changed) = &*self.ready;
        let Ok(guard) = ready.lock() else {
            return false;
        };
        changed
            .wait_timeout_while(guard, limit, |r| !*r)
            .is_ok_and(|(r, _)| *r)
    }

    /// Waits for the next event: data on an attachment, `timeout` (at most [`STOP_LATENCY`]),
    /// a signal, or with `poll` not at all. `false` when the loop must end.
    pub fn wait<S: Service>(
        &self,
        waitset: &WaitSet<S>,
        poll: bool,
        timeout: Duration,
    ) -> Result<bool, WaitSetRunError> {
        if self.stop_requested() {
            return Ok(false);
        }
        let timeout = if poll {
            Duration::ZERO
        } else {
            timeout.min(STOP_LATENCY)
        };
        let result = waitset
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, timeout)?;
        Ok(keeps_running(result) && !self.stop_requested())
    }

    /// Waits for the next event as `idle` says: with [`IdleMode::Block`] (or `poll`) as
    /// [`Control::wait`]; with [`IdleMode::Backoff`] it first looks at `pending` in a loop
    /// ([`Control::spin`]) and returns as soon as one of them has data, without the WaitSet;
    /// only then does it sleep in the WaitSet for the rest of `timeout`. The notifications of a
    /// frame taken while spinning stay queued on its listener until the step drains them
    /// (`Subscriber::take_all`), as after a wake-up. `false` when the loop must end.
    pub fn wait_idle<S: Service>(
        &self,
        waitset: &WaitSet<S>,
        poll: bool,
        timeout: Duration,
        idle: Idle,
        pending: &[&dyn Pending],
    ) -> Result<bool, WaitSetRunError> {
        if poll || idle.mode == IdleMode::Block || pending.is_empty() {
            return self.wait(waitset, poll, timeout);
        }
        match self.spin(timeout, idle, pending) {
            Spun::Data => Ok(!self.stop_requested()),
            Spun::Stop => Ok(false),
            Spun::Nothing(elapsed) => self.wait(waitset, poll, timeout.saturating_sub(elapsed)),
        }
    }

    /// Waits for the next event on `doorbell` ([`IdleMode::Doorbell`]): drains the rings of
    /// what the last step took, spins as [`Control::wait_idle`] does (at least one look at
    /// `pending`, so that a frame published before the drain is not left for the timer), then
    /// sleeps until a publisher or the doorbell's timer rings, the timer at `timeout` (at most
    /// [`STOP_LATENCY`]). `false` when the loop must end.
    pub fn wait_doorbell(
        &self,
        doorbell: &Doorbell,
        timeout: Duration,
        idle: Idle,
        pending: &[&dyn Pending],
    ) -> Result<bool, IpcError> {
        doorbell.drain();
        match self.spin(timeout, idle, pending) {
            Spun::Data => Ok(!self.stop_requested()),
            Spun::Stop => Ok(false),
            Spun::Nothing(elapsed) => {
                let rest = timeout.saturating_sub(elapsed).min(STOP_LATENCY);
                if !rest.is_zero() {
                    doorbell.wait(rest)?;
                }
                Ok(!self.stop_requested())
            }
        }
    }

    /// Looks at `pending` (at least once) until one has data, for the spin budget of `idle`
    /// and then, yielding the CPU between looks, for its yield budget (both cut to `timeout`).
    fn spin(&self, timeout: Duration, idle: Idle, pending: &[&dyn Pending]) -> Spun {
        let started = Instant::now();
        let spin = idle.spin().min(timeout);
        let budget = (idle.spin() + idle.yield_for()).min(timeout);
        let mut looks: u32 = 0;
        let mut elapsed = Duration::ZERO;
        loop {
            if pending.iter().any(|p| p.pending()) {
                return Spun::Data;
            }
            looks = looks.wrapping_add(1);
            // The clock every few looks: a look costs less than a clock read.
            if looks % LOOKS_PER_CLOCK_READ == 1 {
                elapsed = started.elapsed();
                if self.stop_requested() {
                    return Spun::Stop;
                }
            }
            if elapsed >= budget {
                return Spun::Nothing(elapsed);
            }
            if elapsed >= spin {
                std::thread::yield_now();
            }
        }
    }
}

/// What a spin on the inputs found.
enum Spun {
    /// Data on an input.
    Data,
    /// A stop was asked for.
    Stop,
    /// Nothing within the budget, which took this long.
    Nothing(Duration),
}

/// How many looks at the inputs a spinning loop makes between two reads of the clock.
const LOOKS_PER_CLOCK_READ: u32 = 8;

/// An input a spinning loop looks at without taking anything from it: an iceoryx2 subscriber
/// (`Subscriber::has_samples`) or the UDP links (`udp::LinkPair`).
pub trait Pending: std::fmt::Debug {
    /// Whether data waits to be taken.
    fn pending(&self) -> bool;
}

impl<S: Service, T: std::fmt::Debug + Copy + ZeroCopySend + 'static> Pending
    for crate::ipc::Subscriber<S, T>
{
    fn pending(&self) -> bool {
        self.has_samples()
    }
}

impl Pending for missionlink_platform::udp::LinkPair {
    fn pending(&self) -> bool {
        self.has_datagrams()
    }
}

/// A WaitSet for a partition loop, with iceoryx2's signal handling disabled (see
/// [`Control::handle_signals`]).
pub fn waitset<S: Service>() -> Result<WaitSet<S>, PartitionError> {
    WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<S>()
        .map_err(PartitionError::waitset)
}

/// Something a partition loop sleeps on: an iceoryx2 listener or a socket
/// (`wait_fd::SocketFd`). A trait of its own so that listeners and sockets share one slice.
pub trait Attachment: SynchronousMultiplexing + std::fmt::Debug {}

impl<T: SynchronousMultiplexing + std::fmt::Debug + ?Sized> Attachment for T {}

/// What wakes a partition loop besides a stop.
#[derive(Debug, Clone, Copy)]
pub struct Wake<'a> {
    /// The listeners and sockets whose data wakes it.
    pub on: &'a [&'a dyn Attachment],
    /// The same inputs as the spin of [`IdleMode::Backoff`] looks at them (the subscribers
    /// and sockets of `on`).
    pub pending: &'a [&'a dyn Pending],
    /// Periodic work (connecting late subscribers, stepping a model), if any.
    pub every: Option<Duration>,
    /// Whether some input of `on` is a socket, which only the WaitSet can wait for: then
    /// [`IdleMode::Doorbell`] sleeps in the WaitSet as [`IdleMode::Backoff`] does.
    pub sockets: bool,
    /// The longest first sleep; after it each step says how long the next may be.
    pub first_timeout: Duration,
}

/// The event loop of every partition: attaches `wake` to a [`waitset`], logs "`name` up",
/// tells `control` it is ready, then calls `step` after every wake-up until `control` or a
/// termination request stops it. `step` does the partition's work, may log through the
/// [`Report`], and returns how long the loop may sleep next. Between the steps the loop beats
/// `role`'s heartbeat on the configured period ([`Heartbeat`], docs/design.md "Health"): from the
/// loop itself, so a partition stuck in a step or stopped falls silent. Returns the report, for the
/// caller's [`Report::finish`] with its final counters.
#[allow(
    clippy::too_many_arguments,
    reason = "what every partition hands its loop, each once"
)]
pub fn run_loop<S: Service>(
    name: &'static str,
    role: Partition,
    ipc: &Ipc<S>,
    config: &Config,
    control: &Control,
    wake: Wake<'_>,
    mut step: impl FnMut(&mut Report) -> Result<Duration, PartitionError>,
) -> Result<Report, PartitionError> {
    let waitset = waitset::<S>()?;
    let _guards = wake
        .on
        .iter()
        .map(|a| waitset.attach_notification(*a))
        .collect::<Result<Vec<_>, _>>()
        .map_err(PartitionError::waitset)?;
    let _tick = wake
        .every
        .map(|every| waitset.attach_interval(every))
        .transpose()
        .map_err(PartitionError::waitset)?;
    let mut heartbeat = Heartbeat::open(ipc, role, config.health.period())?;
    let mut report = Report::new(config, name, control);
    let idle = config.ipc.idle.of(name);
    let doorbell = (idle.mode == IdleMode::Doorbell && !wake.sockets && !config.ipc.poll)
        .then(|| ipc.doorbell(role))
        .transpose()?;
    // Everything is open: from here on the partition can do only its job (`isolation`).
    control.fence()?;
    tracing::info!(
        prefix = %config.ipc.service_prefix,
        heartbeat_ms = config.health.period().as_millis(),
        "{name} up"
    );
    control.set_ready();
    tracing::info!(
        mode = ?idle.mode,
        spin_us = idle.spin_us,
        yield_us = idle.yield_us,
        poll = config.ipc.poll,
        doorbell = doorbell.is_some(),
        "{name} waits for its inputs"
    );
    let mut until_beat = heartbeat.beat_if_due()?;
    let mut timeout = wake.first_timeout;
    // On the doorbell the WaitSet's interval does not fire: the loop keeps its own.
    let mut next_tick = wake.every.map(|every| Instant::now() + every);
    loop {
        let mut limit = timeout.min(until_beat);
        let running = match &doorbell {
            Some(doorbell) => {
                if let (Some(tick), Some(every)) = (next_tick.as_mut(), wake.every) {
                    let now = Instant::now();
                    if *tick <= now {
                        *tick = now + every;
                    }
                    limit = limit.min(tick.saturating_duration_since(now));
                }
                control.wait_doorbell(doorbell, limit, idle, wake.pending)?
            }
            None => control
                .wait_idle(&waitset, config.ipc.poll, limit, idle, wake.pending)
                .map_err(PartitionError::waitset)?,
        };
        if !running {
            break;
        }
        until_beat = heartbeat.beat_if_due()?;
        timeout = step(&mut report)?;
    }
    Ok(report)
}

/// Whether a loop goes on after the WaitSet returned `result`. `Interrupt` means that a signal
/// interrupted the wait, SIGUSR1 asking for a report too: the loop goes on and looks at its
/// [`Control`]. Only a termination request (reported by a WaitSet with iceoryx2's signal
/// handling on) ends it.
fn keeps_running(result: WaitSetRunResult) -> bool {
    !matches!(result, WaitSetRunResult::TerminationRequest)
}

/// Periodic latency reports (on the configured interval and when the [`Control`] asks) and the
/// summary file at shutdown.
#[derive(Debug)]
pub struct Report {
    partition: &'static str,
    interval: Option<Duration>,
    last: Instant,
    summary_dir: Option<PathBuf>,
    control: Control,
}

impl Report {
    /// Reports of `partition` as `config` says and `control` asks.
    pub fn new(config: &Config, partition: &'static str, control: &Control) -> Self {
        Self {
            partition,
            interval: (config.latency.report_interval_s > 0)
                .then(|| Duration::from_secs(config.latency.report_interval_s)),
            last: Instant::now(),
            summary_dir: config.latency.summary_dir.clone(),
            control: control.clone(),
        }
    }

    /// Whether a report is due: the interval has passed (then it starts again) or one was
    /// asked for.
    pub fn due(&mut self) -> bool {
        let requested = self.control.take_report_request();
        match self.interval {
            Some(i) if self.last.elapsed() >= i => {
                self.last = Instant::now();
                true
            }
            _ => requested,
        }
    }

    /// Logs `recorders` if a report is due (see [`Report::due`]); `true` when it did.
    pub fn log_if_due(&mut self, recorders: &[&Recorder]) -> bool {
        let due = self.due();
        if due {
            latency::log(self.partition, recorders);
        }
        due
    }

    /// Logs the recorders and writes the summary file with the counters, if configured (at
    /// shutdown).
    pub fn finish(&self, recorders: &[&Recorder], counters: &[(&str, u64)]) {
        latency::log(self.partition, recorders);
        if let Some(dir) = &self.summary_dir {
            latency::write_summary(dir, self.partition, recorders, counters);
        }
    }
}

/// The `main` of every partition binary: its command line ([`FccArgs`] under the name
/// `name`, `about` its one-line help), logging, the configuration (exit status 2 when it is
/// wrong), the partition's real-time settings (`realtime`: a refused one is a warning), then
/// `run` with a [`Control`] driven by the signals that announces the partition's
/// readiness in the state directory while it runs (exit status 1 with the error when it fails,
/// 2 when its configuration cannot work: the launcher does not start it again).
pub fn partition_main(
    name: &'static str,
    about: &'static str,
    run: impl FnOnce(&Config, &Control) -> Result<(), PartitionError>,
) -> std::process::ExitCode {
    use clap::{Args, FromArgMatches};
    let command = clap::Command::new(name)
        .about(about)
        .version(env!("CARGO_PKG_VERSION"));
    let args = match FccArgs::from_arg_matches(&FccArgs::augment_args(command).get_matches()) {
        Ok(args) => args,
        Err(e) => e.exit(),
    };
    missionlink_platform::init_logging();
    crate::ipc::quiet_iceoryx2_log();
    // The launcher at start: the watch compares against it once the fence is up.
    let parent = args
        .exit_with_parent
        .then(rustix::process::getppid)
        .flatten();
    let config = match Config::resolve(&args) {
        Ok(c) => c,
        Err(e) => return config_error(&e),
    };
    // On this thread, which runs the loop; the watch-parent thread keeps the defaults.
    if let Some(settings) = config.realtime.of(name) {
        crate::realtime::apply_and_log(name, settings);
    }
    let control = Control::new()
        .announcing_ready(config.ipc.state_dir(), name)
        .fencing(Fence::of(name, &config), parent);
    if let Err(e) = control.handle_signals() {
        tracing::error!(%e, "{name} failed");
        return std::process::ExitCode::FAILURE;
    }
    let result = run(&config, &control);
    control.forget_ready();
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(
            e @ (PartitionError::Config(_)
            | PartitionError::Isolation(
                IsolationError::NoSuchUser(_) | IsolationError::NotRoot { .. },
            )),
        ) => {
            tracing::error!(%e, "{name} failed");
            std::process::ExitCode::from(CONFIG_EXIT_CODE)
        }
        Err(e) => {
            tracing::error!(%e, "{name} failed");
            std::process::ExitCode::FAILURE
        }
    }
}

/// The `main` of a partition binary: [`partition_main`] with the partition module's `NAME`
/// and its `run` on `ipc::Service`; `about` is the one-line help.
#[macro_export]
macro_rules! partition_binary {
    ($partition:ident, $about:literal) => {
        fn main() -> ::std::process::ExitCode {
            $crate::runtime::partition_main(
                $crate::$partition::NAME,
                $about,
                $crate::$partition::run::<::iceoryx2::prelude::ipc::Service>,
            )
        }
    };
}

/// The exit status of a process whose configuration is wrong or cannot work: starting it again
/// cannot help (the launcher gives up on it at once).
pub const CONFIG_EXIT_CODE: u8 = 2;

/// Logs a configuration error; exit status 2.
pub fn config_error(e: &ConfigError) -> std::process::ExitCode {
    tracing::error!(%e, "configuration");
    std::process::ExitCode::from(CONFIG_EXIT_CODE)
}

/// Sends this process SIGTERM once its parent `parent` is gone (the process is re-parented and
/// its parent ID changes), so it stops through its normal shutdown path: a safe stand-in for
/// PR_SET_PDEATHSIG, which would need unsafe code in the launcher.
pub fn watch_parent(parent: rustix::process::Pid) {
    let parent = Some(parent);
    let spawned = std::thread::Builder::new()
        .name("watch-parent".to_owned())
        .spawn(move || {
            loop {
                std::thread::sleep(Duration::from_millis(100));
                if rustix::process::getppid() != parent {
                    tracing::warn!("the launcher is gone: stopping");
                    let _ = rustix::process::kill_process(
                        rustix::process::getpid(),
                        rustix::process::Signal::TERM,
                    );
                    return;
                }
            }
        });
    if let Err(e) = spawned {
        tracing::warn!(%e, "cannot watch the parent process");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_termination_request_ends_a_loop() {
        // SIGUSR1 interrupts the WaitSet's wait (`Interrupt`); the loop must go on and report.
        assert!(keeps_running(WaitSetRunResult::Interrupt));
        assert!(keeps_running(WaitSetRunResult::AllEventsHandled));
        assert!(keeps_running(WaitSetRunResult::StopRequest));
        assert!(!keeps_running(WaitSetRunResult::TerminationRequest));
    }

    #[test]
    fn sigusr1_asks_for_a_report_and_the_wait_goes_on() {
        let control = Control::new();
        control.report_on_sigusr1().unwrap();
        let waitset = waitset::<iceoryx2::prelude::local::Service>().unwrap();
        let _tick = waitset.attach_interval(Duration::from_millis(1)).unwrap();
        // Thread-directed: handled before `raise` returns.
        signal_hook::low_level::raise(signal_hook::consts::SIGUSR1).unwrap();
        assert!(control.take_report_request());
        assert!(!control.take_report_request(), "one request, one report");
        assert!(
            control
                .wait(&waitset, false, Duration::from_millis(1))
                .unwrap()
        );
    }

    #[test]
    fn a_stopped_control_ends_the_wait_and_ready_is_seen_by_other_handles() {
        let control = Control::new();
        let other = control.clone();
        assert!(!other.wait_ready(Duration::ZERO));
        control.set_ready();
        assert!(other.wait_ready(Duration::ZERO));
        let waitset = waitset::<iceoryx2::prelude::local::Service>().unwrap();
        let _tick = waitset.attach_interval(Duration::from_millis(1)).unwrap();
        assert!(control.wait(&waitset, true, Duration::ZERO).unwrap());
        other.stop();
        assert!(!control.wait(&waitset, true, Duration::ZERO).unwrap());
    }
}
