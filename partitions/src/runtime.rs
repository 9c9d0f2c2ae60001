//! What every partition's event loop shares: the [`Control`] a loop is given (its [`Requests`]
//! to stop and report, from another thread or by SIGINT/SIGTERM/SIGUSR1; its [`Readiness`]; its
//! [`Fencing`]); its [`Inputs`], each registered once; [`run_loop`], the one loop skeleton every
//! partition runs, which sleeps in the WaitSet (or spins with `--poll`) until data, a deadline
//! or a stop, after a bounded spin on the inputs or on the partition's doorbell when its idle
//! strategy says so (`config::Idle`); latency reports on an interval, on SIGUSR1 and at
//! shutdown; and the `main` of every partition binary.

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
use crate::ipc::{ActiveLists, Ipc, IpcError, Subscriber};
use crate::isolation::{Fence, IsolationError};
use crate::latency::{self, Recorder};
use crate::state;
use crate::wait_fd::SocketFd;
use iceoryx2::port::listener::Listener;
use missionlink_platform::parent::watch_parent;
use missionlink_platform::udp::{LinkError, LinkPair};

/// The longest a loop sleeps before it looks at its stop flag: a [`Requests::stop`] from another
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

/// What a partition loop is given by whoever runs it, one small type per job: the requests to
/// stop and to report ([`Requests`]), its readiness ([`Readiness`]), and the fence it applies
/// once its ports are open, with the watch of its parent ([`Fencing`]). How the loop waits is
/// its own business ([`run_loop`], `config::Idle`). Cloning gives another handle to the same
/// loop.
#[derive(Debug, Clone, Default)]
pub struct Control {
    /// Stop and report requests (from another thread, or by the signals of the process).
    pub requests: Requests,
    /// Whether the loop has its ports open and waits for data.
    pub ready: Readiness,
    /// The fence the loop applies once its ports are open.
    pub fence: Fencing,
}

impl Control {
    /// A control of a loop not started yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// A control whose readiness is also announced in the state directory `dir` as `name`
    /// ([`Readiness::announcing`]).
    pub fn announcing_ready(mut self, dir: PathBuf, name: &str) -> Self {
        self.ready = Readiness::announcing(dir, name);
        self
    }

    /// A control whose loop fences itself with `fence` and then watches `parent`
    /// ([`Fencing::new`]).
    pub fn fencing(mut self, fence: Option<Fence>, parent: Option<rustix::process::Pid>) -> Self {
        self.fence = Fencing::new(fence, parent);
        self
    }
}

/// The requests a loop looks at between its waits: stop (it ends within [`STOP_LATENCY`]) and
/// report (it logs its latency percentiles). In a process, [`Requests::from_signals`] makes
/// SIGINT and SIGTERM ask it to stop and SIGUSR1 ask for a report. Cloning gives another handle
/// to the same flags.
#[derive(Debug, Clone, Default)]
pub struct Requests {
    stop: Arc<AtomicBool>,
    report: Arc<AtomicBool>,
}

impl Requests {
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
    pub fn from_signals(&self) -> Result<(), PartitionError> {
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
}

/// Whether a loop is ready (its ports open, about to wait), seen by every handle, and where it
/// is announced to other processes. Cloning gives another handle to the same loop.
#[derive(Debug, Clone, Default)]
pub struct Readiness {
    ready: Arc<(Mutex<bool>, Condvar)>,
    /// Where and under which name readiness is announced to other processes, if it is.
    announce: Option<(PathBuf, String)>,
}

impl Readiness {
    /// Readiness that is also announced in the state directory `dir` as `name`
    /// ([`state::announce_ready`]), for the processes that wait for a partition process to be
    /// up; [`Readiness::forget`] withdraws it.
    pub fn announcing(dir: PathBuf, name: &str) -> Self {
        Self {
            ready: Arc::default(),
            announce: Some((dir, name.to_owned())),
        }
    }

    /// Called by the loop once its ports are open and it is about to wait.
    pub fn set(&self) {
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

    /// Withdraws the announcement of [`Readiness::announcing`] (at shutdown).
    pub fn forget(&self) {
        if let Some((dir, name)) = &self.announce {
            if let Err(e) = state::withdraw_ready(dir, name, std::process::id()) {
                tracing::warn!(%e, dir = %dir.display(), "cannot withdraw the readiness");
            }
        }
    }

    /// Waits until the loop is ready; `false` when `limit` passed first.
    pub fn wait(&self, limit: Duration) -> bool {
        let (ready, changed) = &*self.ready;
        let Ok(guard) = ready.lock() else {
            return false;
        };
        changed
            .wait_timeout_while(guard, limit, |r| !*r)
            .is_ok_and(|(r, _)| *r)
    }
}

/// The fence a loop applies once its ports are open (`isolation`), and the parent to watch
/// after it; taken when applied. Cloning gives another handle to the same pending fence.
#[derive(Debug, Clone, Default)]
pub struct Fencing {
    pending: Arc<Mutex<PendingFence>>,
}

/// A fence not applied yet, and the launcher to watch once it is.
type PendingFence = Option<(Fence, Option<rustix::process::Pid>)>;

impl Fencing {
    /// The loop fences itself with `fence` once its ports are open ([`Fencing::apply`]) and
    /// then, with `parent`, starts the watch that ends the process when that parent is gone
    /// (after the fence, so that the watch's thread is fenced too). Without a fence the watch
    /// starts at once.
    pub fn new(fence: Option<Fence>, parent: Option<rustix::process::Pid>) -> Self {
        let pending = match fence {
            Some(fence) => Some((fence, parent)),
            None => {
                if let Some(parent) = parent {
                    watch_parent(parent);
                }
                None
            }
        };
        Self {
            pending: Arc::new(Mutex::new(pending)),
        }
    }

    /// Applies the fence, once (the loop calls it when its ports are open, before it announces
    /// that it is ready); nothing without one.
    pub fn apply(&self) -> Result<(), PartitionError> {
        let taken = self.pending.lock().ok().and_then(|mut slot| slot.take());
        if let Some((fence, parent)) = taken {
            fence.apply().map_err(PartitionError::Isolation)?;
            if let Some(parent) = parent {
                watch_parent(parent);
            }
        }
        Ok(())
    }
}

/// Waits in `waitset` for the next event: data on an attachment, `timeout` (at most
/// [`STOP_LATENCY`]), a signal, or with `poll` not at all. `false` when the loop must end.
pub fn wait_in_waitset<S: Service>(
    requests: &Requests,
    waitset: &WaitSet<S>,
    poll: bool,
    timeout: Duration,
) -> Result<bool, WaitSetRunError> {
    if requests.stop_requested() {
        return Ok(false);
    }
    let timeout = if poll {
        Duration::ZERO
    } else {
        timeout.min(STOP_LATENCY)
    };
    let result =
        waitset.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, timeout)?;
    Ok(keeps_running(result) && !requests.stop_requested())
}

/// How a loop waits when its inputs are empty: one of three strategies (`config::IdleMode`),
/// chosen once when the loop starts.
enum Waiter<'w, S: Service> {
    /// Sleep in the WaitSet at once (`block`), or with `poll` look and go on.
    WaitSet { waitset: &'w WaitSet<S>, poll: bool },
    /// Look at the inputs in a loop first, then sleep in the WaitSet (`backoff`).
    Backoff { waitset: &'w WaitSet<S>, idle: Idle },
    /// Look at the inputs in a loop first, then sleep on the partition's doorbell (`doorbell`).
    /// The WaitSet's interval does not fire there: the loop keeps its own (`tick`).
    Doorbell {
        doorbell: Box<Doorbell>,
        idle: Idle,
        tick: Option<(Duration, Instant)>,
    },
}

impl<S: Service> Waiter<'_, S> {
    /// Waits for the next event, at most `timeout`; `false` when the loop must end.
    fn wait(
        &mut self,
        requests: &Requests,
        timeout: Duration,
        pending: &[&dyn Pending],
    ) -> Result<bool, PartitionError> {
        match self {
            Self::WaitSet { waitset, poll } => {
                wait_in_waitset(requests, waitset, *poll, timeout).map_err(PartitionError::waitset)
            }
            Self::Backoff { waitset, idle } => match spin(requests, timeout, *idle, pending) {
                Spun::Data => Ok(!requests.stop_requested()),
                Spun::Stop => Ok(false),
                Spun::Nothing(elapsed) => {
                    wait_in_waitset(requests, waitset, false, timeout.saturating_sub(elapsed))
                        .map_err(PartitionError::waitset)
                }
            },
            Self::Doorbell {
                doorbell,
                idle,
                tick,
            } => {
                let mut limit = timeout;
                if let Some((every, next)) = tick.as_mut() {
                    let now = Instant::now();
                    if *next <= now {
                        *next = now + *every;
                    }
                    limit = limit.min(next.saturating_duration_since(now));
                }
                wait_doorbell(requests, doorbell, limit, *idle, pending)
            }
        }
    }
}

/// Waits for the next event on `doorbell` ([`IdleMode::Doorbell`]): drains the rings of what
/// the last step took, spins as `backoff` does (at least one look at `pending`, so that a frame
/// published before the drain is not left for the timer), then sleeps until a publisher or the
/// doorbell's timer rings, the timer at `timeout` (at most [`STOP_LATENCY`]). `false` when the
/// loop must end.
fn wait_doorbell(
    requests: &Requests,
    doorbell: &Doorbell,
    timeout: Duration,
    idle: Idle,
    pending: &[&dyn Pending],
) -> Result<bool, PartitionError> {
    doorbell.drain();
    match spin(requests, timeout, idle, pending) {
        Spun::Data => Ok(!requests.stop_requested()),
        Spun::Stop => Ok(false),
        Spun::Nothing(elapsed) => {
            let rest = timeout.saturating_sub(elapsed).min(STOP_LATENCY);
            if !rest.is_zero() {
                doorbell.wait(rest).map_err(IpcError::from)?;
            }
            Ok(!requests.stop_requested())
        }
    }
}

/// Looks at `pending` (at least once) until one has data, for the spin budget of `idle` and
/// then, yielding the CPU between looks, for its yield budget (both cut to `timeout`). The
/// notifications of a frame taken while spinning stay queued on its listener until the step
/// drains them (`Subscriber::take_all`), as after a wake-up.
fn spin(requests: &Requests, timeout: Duration, idle: Idle, pending: &[&dyn Pending]) -> Spun {
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
            if requests.stop_requested() {
                return Spun::Stop;
            }
        }
        if elapsed >= budget {
            return Spun::Nothing(elapsed);
        }
        if elapsed >= spin {
            std::thread::yield_now();
        } else {
            // PAUSE: a spin-wait on a guest lets the hypervisor see it as one (pause-loop
            // exiting) and run the peer it is waiting for, which it just woke on the other
            // vCPU, sooner; on any x86 it spares the sibling hyper-thread.
            std::hint::spin_loop();
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
/// [`Requests::from_signals`]).
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

/// The inputs of a partition loop, each registered once: what wakes it (an iceoryx2 listener
/// or a socket, attached to the WaitSet) and, unless registered as [`Inputs::waking`], what the
/// spin of `backoff` and `doorbell` looks at. Whether the loop waits for sockets follows from
/// what was registered.
#[derive(Debug)]
pub struct Inputs<'a> {
    /// Listeners attached to the WaitSet.
    listeners: Vec<&'a dyn Attachment>,
    /// The sockets' attachments (owned: the link pair owns the sockets).
    sockets: Vec<SocketFd>,
    /// What a spinning loop looks at.
    pending: Vec<&'a dyn Pending>,
    every: Option<Duration>,
    first_timeout: Duration,
}

impl<'a> Inputs<'a> {
    /// No input yet; the loop's first sleep is at most `first_timeout` (after it, each step says
    /// how long the next may be).
    pub fn new(first_timeout: Duration) -> Self {
        Self {
            listeners: Vec::new(),
            sockets: Vec::new(),
            pending: Vec::new(),
            every: None,
            first_timeout,
        }
    }

    /// Periodic work (connecting late subscribers, stepping a model) every `period`.
    pub fn every(mut self, period: Duration) -> Self {
        self.every = Some(period);
        self
    }

    /// A subscriber whose data wakes the loop and which a spinning loop looks at.
    pub fn subscriber<S, T>(mut self, subscriber: &'a Subscriber<S, T>) -> Self
    where
        S: Service,
        T: std::fmt::Debug + Copy + ZeroCopySend + 'static,
        Listener<S>: SynchronousMultiplexing,
    {
        self.listeners.push(subscriber.listener());
        self.pending.push(subscriber);
        self
    }

    /// A subscriber whose data wakes the loop but is not urgent enough to spin for (a
    /// heartbeat, which comes every period).
    pub fn waking<S, T>(mut self, subscriber: &'a Subscriber<S, T>) -> Self
    where
        S: Service,
        T: std::fmt::Debug + Copy + ZeroCopySend + 'static,
        Listener<S>: SynchronousMultiplexing,
    {
        self.listeners.push(subscriber.listener());
        self
    }

    /// Both active lists (`ipc::ActiveLists`).
    pub fn lists<S: Service>(self, lists: &'a ActiveLists<S>) -> Self
    where
        Listener<S>: SynchronousMultiplexing,
    {
        self.subscriber(&lists.waypoints).subscriber(&lists.areas)
    }

    /// The UDP links: their sockets wake the loop, and a spinning loop looks at them. Only the
    /// WaitSet waits for sockets, so the loop then never sleeps on a doorbell.
    pub fn links(mut self, links: &'a LinkPair) -> Result<Self, LinkError> {
        self.sockets.extend(crate::wait_fd::attachments(links)?);
        self.pending.push(links);
        Ok(self)
    }

    /// Whether a socket is among the inputs.
    fn has_sockets(&self) -> bool {
        !self.sockets.is_empty()
    }
}

/// The event loop of every partition: attaches `inputs` to a [`waitset`], logs "`partition`
/// up", fences itself and says it is ready through `control`, then calls `step` after every
/// wake-up until `control` or a termination request stops it. `step` does the partition's work,
/// may log through the [`Report`], and returns how long the loop may sleep next. Between the
/// steps the loop beats the partition's heartbeat on the configured period ([`Heartbeat`],
/// docs/design.md "Health"): from the loop itself, so a partition stuck in a step or stopped
/// falls silent. It waits as the partition's idle strategy says (`config::Idle`), on its
/// doorbell where `doorbell::waits` says so. Returns the report, for the caller's
/// [`Report::finish`] with its final counters.
pub fn run_loop<S: Service>(
    partition: Partition,
    ipc: &Ipc<S>,
    config: &Config,
    control: &Control,
    inputs: Inputs<'_>,
    mut step: impl FnMut(&mut Report) -> Result<Duration, PartitionError>,
) -> Result<Report, PartitionError>
where
    Listener<S>: SynchronousMultiplexing,
{
    let name = partition.binary();
    let waitset = waitset::<S>()?;
    let _guards = inputs
        .listeners
        .iter()
        .map(|a| waitset.attach_notification(*a))
        .chain(
            inputs
                .sockets
                .iter()
                .map(|s| waitset.attach_notification(s)),
        )
        .collect::<Result<Vec<_>, _>>()
        .map_err(PartitionError::waitset)?;
    let _tick = inputs
        .every
        .map(|every| waitset.attach_interval(every))
        .transpose()
        .map_err(PartitionError::waitset)?;
    let mut heartbeat = Heartbeat::open(ipc, partition, config.health.period())?;
    let mut report = Report::new(config, name, &control.requests);
    let idle = config.ipc.idle[partition];
    let mut waiter = if crate::doorbell::waits(&config.ipc, partition) && !inputs.has_sockets() {
        Waiter::Doorbell {
            doorbell: Box::new(ipc.doorbell(partition)?),
            idle,
            tick: inputs.every.map(|every| (every, Instant::now() + every)),
        }
    } else if config.ipc.poll || idle.mode == IdleMode::Block || inputs.pending.is_empty() {
        Waiter::WaitSet {
            waitset: &waitset,
            poll: config.ipc.poll,
        }
    } else {
        Waiter::Backoff {
            waitset: &waitset,
            idle,
        }
    };
    // Everything is open: from here on the partition can do only its job (`isolation`).
    control.fence.apply()?;
    // The doorbell's threads after the fence, which wants the only thread.
    if let Waiter::Doorbell { doorbell, .. } = &mut waiter {
        let open = Ipc::<S>::forwarder_listeners(
            format!("{name}-forwarder"),
            config.ipc.service_prefix.clone(),
            partition,
        );
        doorbell.start(open).map_err(IpcError::from)?;
    }
    tracing::info!(
        prefix = %config.ipc.service_prefix,
        heartbeat_ms = config.health.period().as_millis(),
        "{name} up"
    );
    control.ready.set();
    tracing::info!(
        mode = ?idle.mode,
        spin_us = idle.spin_us,
        yield_us = idle.yield_us,
        poll = config.ipc.poll,
        doorbell = matches!(waiter, Waiter::Doorbell { .. }),
        "{name} waits for its inputs"
    );
    let mut until_beat = heartbeat.beat_if_due()?;
    let mut timeout = inputs.first_timeout;
    loop {
        let limit = timeout.min(until_beat);
        if !waiter.wait(&control.requests, limit, &inputs.pending)? {
            break;
        }
        until_beat = heartbeat.beat_if_due()?;
        timeout = step(&mut report)?;
    }
    Ok(report)
}

/// Whether a loop goes on after the WaitSet returned `result`. `Interrupt` means that a signal
/// interrupted the wait, SIGUSR1 asking for a report too: the loop goes on and looks at its
/// [`Requests`]. Only a termination request (reported by a WaitSet with iceoryx2's signal
/// handling on) ends it.
fn keeps_running(result: WaitSetRunResult) -> bool {
    !matches!(result, WaitSetRunResult::TerminationRequest)
}

/// Periodic latency reports (on the configured interval and when the [`Requests`] ask) and the
/// summary file at shutdown.
#[derive(Debug)]
pub struct Report {
    partition: &'static str,
    interval: Option<Duration>,
    last: Instant,
    summary_dir: Option<PathBuf>,
    requests: Requests,
}

impl Report {
    /// Reports of `partition` as `config` says and `requests` ask.
    pub fn new(config: &Config, partition: &'static str, requests: &Requests) -> Self {
        Self {
            partition,
            interval: (config.latency.report_interval_s > 0)
                .then(|| Duration::from_secs(config.latency.report_interval_s)),
            last: Instant::now(),
            summary_dir: config.latency.summary_dir.clone(),
            requests: requests.clone(),
        }
    }

    /// Whether a report is due: the interval has passed (then it starts again) or one was
    /// asked for.
    pub fn due(&mut self) -> bool {
        let requested = self.requests.take_report_request();
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

/// The `main` of every partition binary: its command line ([`FccArgs`] under the name of
/// `partition`'s binary, `about` its one-line help), logging, the configuration (exit status 2 when it is
/// wrong), the partition's real-time settings (`realtime`: a refused one is a warning), then
/// `run` with a [`Control`] driven by the signals that announces the partition's
/// readiness in the state directory while it runs (exit status 1 with the error when it fails,
/// 2 when its configuration cannot work: the launcher does not start it again).
pub fn partition_main(
    partition: Partition,
    about: &'static str,
    run: impl FnOnce(&Config, &Control) -> Result<(), PartitionError>,
) -> std::process::ExitCode {
    use clap::{Args, FromArgMatches};
    let name = partition.binary();
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
    crate::realtime::apply_and_log(name, &config.realtime[partition]);
    let control = Control::new()
        .announcing_ready(config.ipc.state_dir(), name)
        .fencing(crate::isolation::fence_of(partition, &config), parent);
    if let Err(e) = control.requests.from_signals() {
        tracing::error!(%e, "{name} failed");
        return std::process::ExitCode::FAILURE;
    }
    let result = run(&config, &control);
    control.ready.forget();
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

/// The `main` of a partition binary: [`partition_main`] with the partition module's
/// `PARTITION` and its `run` on `ipc::Service`; `about` is the one-line help.
#[macro_export]
macro_rules! partition_binary {
    ($partition:ident, $about:literal) => {
        fn main() -> ::std::process::ExitCode {
            $crate::runtime::partition_main(
                $crate::$partition::PARTITION,
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
        let requests = Requests::default();
        requests.report_on_sigusr1().unwrap();
        let waitset = waitset::<iceoryx2::prelude::local::Service>().unwrap();
        let _tick = waitset.attach_interval(Duration::from_millis(1)).unwrap();
        // Thread-directed: handled before `raise` returns.
        signal_hook::low_level::raise(signal_hook::consts::SIGUSR1).unwrap();
        assert!(requests.take_report_request());
        assert!(!requests.take_report_request(), "one request, one report");
        assert!(wait_in_waitset(&requests, &waitset, false, Duration::from_millis(1)).unwrap());
    }

    #[test]
    fn a_stopped_control_ends_the_wait_and_ready_is_seen_by_other_handles() {
        let control = Control::new();
        let other = control.clone();
        assert!(!other.ready.wait(Duration::ZERO));
        control.ready.set();
        assert!(other.ready.wait(Duration::ZERO));
        let waitset = waitset::<iceoryx2::prelude::local::Service>().unwrap();
        let _tick = waitset.attach_interval(Duration::from_millis(1)).unwrap();
        let requests = &control.requests;
        assert!(wait_in_waitset(requests, &waitset, true, Duration::ZERO).unwrap());
        other.requests.stop();
        assert!(!wait_in_waitset(requests, &waitset, true, Duration::ZERO).unwrap());
    }
}
