//! One doorbell per partition (docs/wait-path.md; docs/design.md "Services, payloads and
//! QoS"): an iceoryx2 event service named `{prefix}/doorbell/<role>` whose listener is the
//! partition and whose notifiers are the publishers of every service the partition consumes
//! ([`consumers`]). The event is
//! iceoryx2-cal's POSIX semaphore in shared memory (`SemaphoreShmCountingBitSet`), through the
//! service type [`DoorbellService`]: a ring is a `sem_post`, the wait a `sem_wait`, a futex
//! each, where the default event of `ipc::Service` is a Unix datagram plus an epoll round in the
//! WaitSet.
//!
//! The semaphore is not file-descriptor based, so it cannot join a WaitSet, and iceoryx2 0.10's
//! `timed_wait` on it is not a futex wait with a timeout but an adaptive wait (10 000
//! `sched_yield`s, then sleeps of 100 µs, then of 10 ms: `iceoryx2-bb-posix`'s
//! `adaptive_wait`), which would cost CPU when idle and wake late. So the partition blocks in
//! `blocking_wait`, and two threads of the [`Doorbell`] ring it:
//!
//! - the timer, at the loop's next deadline ([`Doorbell::wait`]);
//! - the forwarder, for a publisher that does not ring it: a partition in Python (iceoryx2's
//!   binding knows nothing of doorbells), a program on iceoryx2's own bindings, a process
//!   configured otherwise. It sleeps in a WaitSet on the events of the services the partition
//!   consumes ([`consumed_by`]), each through a listener of its own ([`Qos::max_listeners`]
//!   counts it), and rings when a notification's event ID does not carry the partition's bit:
//!   a publisher of this workspace notifies with the bits of the doorbells it rang
//!   ([`Ringers::event_id`]), any other with 0. So every publisher is heard at once, and a
//!   frame of a ringing publisher wakes the partition once.
//!
//! A partition on the doorbell still has its ordinary listeners, which the steps drain. Its
//! listeners and its forwarder's are named for it ([`listener_name`]), and a publisher that
//! rang its doorbell notifies only the event's other listeners, each alone (a test, the
//! launcher, a partition in Python or in the WaitSet: [`Ringers::notifies`]): a notification
//! of the whole event would wake the forwarder too, for nothing, on the partition's CPU as the
//! partition wakes (benches/latency: the doorbell's sparse hop 1.19-1.25x the Unix socket with
//! that wake-up, 0.95-1.09x without, three interleaved runs on 2026-12-07).
//!
//! [`waits`] is the one rule that says which partitions wait on their doorbells under a
//! configuration (by default every partition but voting-monitoring, `config::Idle`;
//! voting-monitoring never, it waits for its sockets); the runtime (which doorbell a loop waits on) and `ipc::Ipc::open`
//! (which doorbells its publishers ring) both ask it. A process under a configuration where no
//! partition waits on one opens no doorbell service, and its publishers ring nothing.
//!
//! [`Qos::max_listeners`]: missionlink_interfaces::contracts::Qos::max_listeners

use core::fmt::Debug;
use std::os::fd::OwnedFd;
use std::os::unix::net::UnixDatagram;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2_bb_elementary_traits::testing::abandonable::Abandonable;
use iceoryx2_cal::shm_allocator::bump_allocator::BumpAllocator;
use iceoryx2_cal::shm_allocator::pool_allocator::PoolAllocator;
use iceoryx2_cal::{
    arc_sync_policy, bag, dynamic_storage, event, hash, monitoring, reactor,
    resizable_shared_memory, serialize, shared_memory, static_storage, zero_copy_connection,
};
use missionlink_interfaces::contracts::{FccService, Partition};
use rustix::time::{
    Itimerspec, TimerfdClockId, TimerfdFlags, TimerfdTimerFlags, Timespec, timerfd_create,
    timerfd_settime,
};

use crate::config::{self, IdleMode, PerPartition};
use crate::wait_fd::SocketFd;

/// Something iceoryx2 refused about a doorbell, with what was being done.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct DoorbellError(pub String);

/// Whether `partition` waits on its doorbell under `ipc` (`[ipc]`): its idle mode is
/// [`IdleMode::Doorbell`], it does not poll, and it waits for no socket (a socket only the
/// WaitSet can wait for: the partition that owns the links, `Partition::allowed`, sleeps in the
/// WaitSet as with `backoff`). The one rule for the loop that waits and the publishers that
/// ring.
pub fn waits(ipc: &config::Ipc, partition: Partition) -> bool {
    ipc.idle[partition].mode == IdleMode::Doorbell && !ipc.poll && !partition.allowed().links
}

/// `ipc::Service` with iceoryx2-cal's semaphore event, its ports thread-safe as those of
/// `ipc_threadsafe::Service` (the timer thread rings through a notifier of its own): the service
/// type of the doorbells only (every process of a service must use the same type; the data
/// services stay on `ipc::Service`).
#[derive(Debug, Clone)]
pub struct DoorbellService {}

impl iceoryx2::service::Service for DoorbellService {
    type StaticStorage = static_storage::recommended::Ipc;
    type ConfigSerializer = serialize::recommended::Recommended;
    type PersistentDynamicStorage<T: Debug + Send + Sync + ZeroCopySend + 'static> =
        dynamic_storage::recommended::PersistentIpc<T>;
    type Bag = bag::recommended::Recommended;
    type DynamicStorage<T: Debug + Send + Sync + ZeroCopySend + 'static> =
        dynamic_storage::recommended::Ipc<T>;
    type ServiceNameHasher = hash::recommended::Recommended;
    type SharedMemory = shared_memory::recommended::Ipc<PoolAllocator>;
    type ResizableSharedMemory = resizable_shared_memory::recommended::Ipc<PoolAllocator>;
    type Connection = zero_copy_connection::recommended::Ipc;
    type Event = event::SemaphoreShmCountingBitSet;
    type Monitoring = monitoring::recommended::Ipc;
    type Reactor = reactor::recommended::Ipc;
    type ArcThreadSafetyPolicy<T: Send + Debug + Abandonable> =
        arc_sync_policy::mutex_protected::MutexProtected<T>;
    type BlackboardMgmt<KeyType: Send + Sync + Debug + ZeroCopySend + 'static> =
        dynamic_storage::recommended::Ipc<KeyType>;
    type BlackboardPayload = shared_memory::recommended::Ipc<BumpAllocator>;
    type UniqueId = iceoryx2::unique_id_generator::unique_system_id::UniqueSystemId;
}

impl iceoryx2::service::internal::ServiceInternal<DoorbellService> for DoorbellService {}

/// The partitions whose doorbell a publisher of `service` rings: its subscribers among the
/// partitions (docs/design.md, "Contracts between partitions").
pub fn consumers(service: FccService) -> &'static [Partition] {
    match service {
        FccService::Uplink => &[Partition::MissionDataHandling],
        FccService::Downlink => &[Partition::VotingMonitoring],
        FccService::WaypointList | FccService::AreaList => {
            &[Partition::SystemAutomation, Partition::Guidance]
        }
        FccService::AutomationState => &[Partition::MissionDataHandling, Partition::Guidance],
        FccService::GuidanceProgress => {
            &[Partition::MissionDataHandling, Partition::SystemAutomation]
        }
        FccService::AutomationCommand => &[Partition::SystemAutomation],
        FccService::Heartbeat(Partition::Guidance) => &[Partition::SystemAutomation],
        FccService::Heartbeat(_) => &[],
    }
}

/// The services whose publishers feed `role` ([`consumers`]): what its forwarder listens to.
pub fn consumed_by(role: Partition) -> impl Iterator<Item = FccService> {
    FccService::ALL
        .into_iter()
        .filter(move |service| consumers(*service).contains(&role))
}

/// The bit of `role` in a notification's event ID ([`Ringers::event_id`]): its place in
/// `Partition::ALL` (four partitions, well within iceoryx2's default largest event ID, 255).
fn bit(role: Partition) -> usize {
    1 << Partition::ALL.iter().position(|p| *p == role).unwrap_or(0)
}

/// The port name of every listener of a partition that waits on its doorbell: its
/// subscribers' own listeners, which it only drains, and its forwarder's. A publisher that rang
/// the partition's doorbell leaves them out of its notification ([`Ringers::notifies`]): the
/// datagram would wake the forwarder for nothing, on the partition's CPU, as the partition
/// wakes. Every other listener (a test, the launcher, a partition in Python or in the WaitSet)
/// has another name or none, and is notified.
pub fn listener_name(role: Partition) -> String {
    format!("{RUNG_LISTENER}{}", role.binary())
}

/// What the name of a listener of a partition on its doorbell starts with ([`listener_name`]).
const RUNG_LISTENER: &str = "rung/";

/// Notifiers a doorbell allows: every publisher of a consumed service, with room for restarted
/// processes whose ports are not cleaned up yet.
const MAX_RINGERS: usize = 64;
/// Listeners a doorbell allows: its partition, and a restarted one while the dead one's port is
/// not cleaned up yet (a ring visits every listener slot).
const MAX_LISTENERS: usize = 2;

fn err(what: impl std::fmt::Display, e: impl Debug) -> DoorbellError {
    DoorbellError(format!("{what}: {e:?}"))
}

/// The doorbell event services of one process.
#[derive(Debug)]
pub struct Doorbells {
    node: Node<DoorbellService>,
    prefix: String,
    /// The partitions that wait on their doorbells ([`waits`]): only theirs are rung.
    waiting: PerPartition<bool>,
}

impl Doorbells {
    /// The doorbells of the process `name` under `ipc`: `None` when no partition waits on its
    /// doorbell ([`waits`]), so that nothing is opened and nothing rung.
    pub fn of(name: &str, ipc: &config::Ipc) -> Result<Option<Self>, DoorbellError> {
        let waiting = PerPartition::from_fn(|p| waits(ipc, p));
        if waiting.iter().all(|(_, w)| !w) {
            return Ok(None);
        }
        Self::open(name, &ipc.service_prefix, waiting).map(Some)
    }

    /// A node of the doorbell service type for the process `name`, ringing the doorbells of the
    /// partitions `waiting` says; removes what dead nodes of this type left behind.
    pub fn open(
        name: &str,
        prefix: &str,
        waiting: PerPartition<bool>,
    ) -> Result<Self, DoorbellError> {
        let node_name: NodeName = name.try_into().map_err(|e| err("node name", e))?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .create::<DoorbellService>()
            .map_err(|e| err(format_args!("creating the doorbell node {name}"), e))?;
        node.try_cleanup_dead_nodes();
        Ok(Self {
            node,
            prefix: prefix.to_owned(),
            waiting,
        })
    }

    fn event(
        &self,
        role: Partition,
    ) -> Result<iceoryx2::service::port_factory::event::PortFactory<DoorbellService>, DoorbellError>
    {
        let name = format!(
            "{}/doorbell/{}",
            self.prefix.trim_end_matches('/'),
            role.role()
        );
        let service: ServiceName = name
            .as_str()
            .try_into()
            .map_err(|e| err("doorbell service name", e))?;
        self.node
            .service_builder(&service)
            .event()
            .max_notifiers(MAX_RINGERS)
            .max_listeners(MAX_LISTENERS)
            // One event ID: a woken listener reads the activations of every ID there is, and
            // the ring says nothing but "look".
            .event_id_max_value(0)
            .open_or_create()
            .map_err(|e| err(format_args!("opening the doorbell of {role:?}"), e))
    }

    /// The ringers of the doorbells of `service`'s consumers that wait on theirs.
    pub fn ringers(&self, service: FccService) -> Result<Ringers, DoorbellError> {
        let mut ringers = Ringers::default();
        for role in consumers(service)
            .iter()
            .filter(|role| self.waiting[**role])
        {
            ringers.notifiers.push(
                self.event(*role)?
                    .notifier_builder()
                    .create()
                    .map_err(|e| err(format_args!("ringer of the doorbell of {role:?}"), e))?,
            );
            ringers.rung |= bit(*role);
        }
        Ok(ringers)
    }

    /// The doorbell of `role`, to wait on once [`Doorbell::start`] has started its threads.
    pub fn doorbell(&self, role: Partition) -> Result<Doorbell, DoorbellError> {
        let event = self.event(role)?;
        let listener = event
            .listener_builder()
            .create()
            .map_err(|e| err(format_args!("listener of the doorbell of {role:?}"), e))?;
        let notifier = || {
            event
                .notifier_builder()
                .create()
                .map_err(|e| err(format_args!("ringer of the doorbell of {role:?}"), e))
        };
        // The forwarder's end, made here: the fence allows no socket pair.
        let end = UnixDatagram::pair().map_err(|e| err("the forwarder's socket pair", e))?;
        Ok(Doorbell {
            listener,
            role,
            unstarted: Some(Unstarted {
                timer_ring: notifier()?,
                forward_ring: notifier()?,
                end,
            }),
            timer: Arc::new(Timer::new()?),
            threads: None,
        })
    }
}

/// What rings the doorbells of one service's consumers (those that wait on theirs); none
/// where no consumer waits on one (the default), which costs nothing per send.
#[derive(Debug, Default)]
pub struct Ringers {
    notifiers: Vec<Notifier<DoorbellService>>,
    /// The bits of the partitions whose doorbells they ring ([`bit`]).
    rung: usize,
}

impl Ringers {
    /// Whether a listener of the service's event named `listener` (its port name) needs the
    /// notification after [`Ringers::ring`]: every listener does but those of the partitions
    /// whose doorbells were just rung ([`listener_name`]), which nobody sleeps on (the
    /// partition sleeps on its doorbell; its forwarder ignores a notification of a publisher
    /// that rang it).
    /// Read at every send: it compares names in place and allocates nothing.
    pub fn notifies(&self, listener: &str) -> bool {
        match listener
            .strip_prefix(RUNG_LISTENER)
            .and_then(Partition::from_binary)
        {
            Some(rung) => self.rung & bit(rung) == 0,
            None => true,
        }
    }

    /// Whether there is no doorbell to ring.
    pub fn is_empty(&self) -> bool {
        self.notifiers.is_empty()
    }

    /// The event ID a publisher notifies its service's event with after [`Ringers::ring`]: the
    /// bits of the partitions whose doorbells it rang, so that their forwarders do not ring
    /// again (0, as any publisher that rings nothing: every forwarder rings).
    pub fn event_id(&self) -> EventId {
        EventId::new(self.rung)
    }

    /// Rings every consumer's doorbell (a `sem_post` per listening consumer).
    pub fn ring(&self) -> Result<(), DoorbellError> {
        for notifier in &self.notifiers {
            notifier
                .notify()
                .map_err(|e| err("ringing a doorbell", e))?;
        }
        Ok(())
    }
}

/// How late the timer may ring rather than be armed again for an earlier deadline.
const TIMER_SLACK: Duration = Duration::from_millis(1);

/// The doorbell's timer: a timerfd that the loop arms for its next deadline (a system call on
/// the loop's thread, no wake-up of another), and the thread that sleeps in the timerfd's read
/// and rings when the loop's deadline has come. Before, a condition variable told the thread
/// of every new deadline, and a deadline after a ring woke it twice: to be told, then to ring
/// (an idle mission data handling's timer thread woke about 80 times a second for its loop's
/// 20 deadlines).
#[derive(Debug)]
struct Timer {
    fd: OwnedFd,
    state: Mutex<TimerState>,
}

#[derive(Debug, Default)]
struct TimerState {
    /// The loop's deadline, until it is rung.
    deadline: Option<Instant>,
    /// When the timerfd fires; `None` when it is disarmed (it fired, or was never armed).
    armed: Option<Instant>,
    /// The doorbell is dropped: the thread ends at the next firing.
    end: bool,
}

impl Timer {
    fn new() -> Result<Self, DoorbellError> {
        let fd = timerfd_create(TimerfdClockId::Monotonic, TimerfdFlags::CLOEXEC)
            .map_err(|e| err("the doorbell's timerfd", e))?;
        Ok(Self {
            fd,
            state: Mutex::default(),
        })
    }

    /// Arms the timerfd to fire at `at` (at once when `at` has passed: a zero value would
    /// disarm it). `Instant` is CLOCK_MONOTONIC, the timerfd's clock.
    fn arm(&self, at: Instant) -> Result<(), DoorbellError> {
        let after = at
            .saturating_duration_since(Instant::now())
            .max(Duration::from_nanos(1));
        let zero = Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        let it_value = Timespec::try_from(after).unwrap_or(Timespec {
            tv_sec: i64::MAX,
            tv_nsec: 0,
        });
        timerfd_settime(
            &self.fd,
            TimerfdTimerFlags::empty(),
            &Itimerspec {
                it_interval: zero,
                it_value,
            },
        )
        .map(|_| ())
        .map_err(|e| err("arming the doorbell's timerfd", e))
    }

    /// Makes `deadline` the loop's next one. The timerfd is armed again only when it would
    /// fire more than [`TIMER_SLACK`] after the deadline, or not at all: a later deadline the
    /// thread finds when the timerfd fires, and arms it for, without ringing.
    fn set(&self, deadline: Instant) -> Result<(), DoorbellError> {
        let mut state = self
            .state
            .lock()
            .map_err(|_| DoorbellError("the doorbell's timer is poisoned".to_owned()))?;
        state.deadline = Some(deadline);
        if state.armed.is_none_or(|a| deadline + TIMER_SLACK < a) {
            self.arm(deadline)?;
            state.armed = Some(deadline);
        }
        Ok(())
    }

    /// Ends the thread: it sees the end at the next firing, which is now.
    fn end(&self) {
        if let Ok(mut state) = self.state.lock() {
            state.end = true;
            if self.arm(Instant::now()).is_ok() {
                state.armed = None;
            }
        }
    }

    /// The timer thread: sleeps until the timerfd fires, then rings through `notifier` if the
    /// loop's deadline has come, or arms the timerfd for the later deadline the loop set since;
    /// until the end.
    fn run(&self, notifier: &Notifier<DoorbellService>) {
        let mut expirations = [0_u8; 8];
        loop {
            match rustix::io::read(&self.fd, &mut expirations) {
                Ok(_) => {}
                // A signal (SIGUSR1 for a report) landed on this thread.
                Err(rustix::io::Errno::INTR) => continue,
                Err(e) => {
                    tracing::warn!(%e, "the doorbell's timer cannot wait");
                    return;
                }
            }
            let Ok(mut state) = self.state.lock() else {
                return;
            };
            if state.end {
                return;
            }
            state.armed = None;
            match state.deadline {
                Some(d) if d <= Instant::now() => {
                    state.deadline = None;
                    drop(state);
                    if let Err(e) = notifier.notify() {
                        tracing::warn!(?e, "the doorbell's timer cannot ring");
                    }
                }
                Some(d) => match self.arm(d) {
                    Ok(()) => state.armed = Some(d),
                    Err(e) => tracing::warn!(%e, "the doorbell's timer cannot wait"),
                },
                None => {}
            }
        }
    }
}

/// A partition's doorbell: its listener, and the two threads that ring it besides the
/// publishers (the timer at the loop's next deadline, the forwarder for publishers that do not
/// ring), started by [`Doorbell::start`] once the partition is fenced and ended when the
/// doorbell is dropped.
#[derive(Debug)]
pub struct Doorbell {
    listener: Listener<DoorbellService>,
    role: Partition,
    /// What the threads take when they start, opened with the listener before the fence.
    unstarted: Option<Unstarted>,
    timer: Arc<Timer>,
    threads: Option<Threads>,
}

/// What a doorbell's threads are given: the timer's and the forwarder's notifiers, and the
/// socket pair that ends the forwarder (its two ends).
#[derive(Debug)]
struct Unstarted {
    timer_ring: Notifier<DoorbellService>,
    forward_ring: Notifier<DoorbellService>,
    end: (UnixDatagram, UnixDatagram),
}

/// The running threads of a doorbell.
#[derive(Debug)]
struct Threads {
    timer: std::thread::JoinHandle<()>,
    forwarder: Forwarder,
}

impl Doorbell {
    /// Starts the timer and the forwarder (once; again does nothing). A fence wants the only
    /// thread of the process (`isolation`), so the loop calls this after its fence: the
    /// forwarder calls `open` on its thread then, within the fence's allowances, for its
    /// listeners of the data services' type `S` (one per service in [`consumed_by`]) and what
    /// keeps them open (`ipc::Ipc::forwarder_listeners`). Returns once the forwarder listens,
    /// or with what it could not open.
    pub fn start<S, K, O>(&mut self, open: O) -> Result<(), DoorbellError>
    where
        S: Service,
        Listener<S>: SynchronousMultiplexing,
        O: FnOnce() -> Result<(K, Vec<Listener<S>>), DoorbellError> + Send + 'static,
    {
        let Some(Unstarted {
            timer_ring,
            forward_ring,
            end,
        }) = self.unstarted.take()
        else {
            return Ok(());
        };
        let forwarder = Forwarder::start(open, self.role, forward_ring, end)?;
        let timer = Arc::clone(&self.timer);
        let timer = std::thread::Builder::new()
            .name("doorbell-timer".to_owned())
            .spawn(move || timer.run(&timer_ring))
            .map_err(|e| err("starting the doorbell's timer thread", e))?;
        self.threads = Some(Threads { timer, forwarder });
        Ok(())
    }

    /// Sleeps until a publisher, the forwarder or the timer rings, the timer at `timeout` from
    /// now. Consumes every pending ring. An error before [`Doorbell::start`]: nothing would
    /// ring at the deadline.
    pub fn wait(&self, timeout: Duration) -> Result<(), DoorbellError> {
        if self.threads.is_none() {
            return Err(DoorbellError(
                "waiting on a doorbell whose threads were not started".to_owned(),
            ));
        }
        self.timer.set(Instant::now() + timeout)?;
        match self.listener.blocking_wait(|_| {}) {
            // A signal (SIGUSR1 for a report, SIGTERM): the loop looks at its control.
            Ok(_) | Err(iceoryx2_cal::event::ListenerWaitError::InterruptSignal) => Ok(()),
            Err(e) => Err(err("waiting on the doorbell", e)),
        }
    }

    /// Consumes pending rings without sleeping.
    pub fn drain(&self) {
        let _ = self.listener.try_wait(|_| {});
    }
}

impl Drop for Doorbell {
    fn drop(&mut self) {
        self.timer.end();
        if let Some(threads) = self.threads.take() {
            threads.forwarder.stop();
            let _ = threads.timer.join();
        }
    }
}

/// The forwarder's thread and what ends it: a flag and a datagram on a socket pair whose other
/// end is in its WaitSet.
#[derive(Debug)]
struct Forwarder {
    stop: Arc<AtomicBool>,
    wake: UnixDatagram,
    thread: std::thread::JoinHandle<()>,
}

impl Forwarder {
    /// Starts the forwarder of `role`'s doorbell on the listeners `open` gives on its thread,
    /// ringing through `ring`, ended through the socket pair `(wake, woken)`; returns once it
    /// listens.
    fn start<S, K, O>(
        open: O,
        role: Partition,
        ring: Notifier<DoorbellService>,
        (wake, woken): (UnixDatagram, UnixDatagram),
    ) -> Result<Self, DoorbellError>
    where
        S: Service,
        Listener<S>: SynchronousMultiplexing,
        O: FnOnce() -> Result<(K, Vec<Listener<S>>), DoorbellError> + Send + 'static,
    {
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let (listening, listens) = std::sync::mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("doorbell-forward".to_owned())
            .spawn(move || {
                // The ports of `S` are the thread's own (they need not be `Send`).
                let (_keep, listeners) = match open() {
                    Ok(opened) => opened,
                    Err(e) => {
                        let _ = listening.send(Err(e));
                        return;
                    }
                };
                if let Err(e) = forward(&listeners, &woken, &stopped, bit(role), &ring, || {
                    let _ = listening.send(Ok(()));
                }) {
                    tracing::error!(%e, "the doorbell's forwarder stopped");
                }
            })
            .map_err(|e| err("starting the doorbell's forwarder", e))?;
        match listens.recv() {
            Ok(Ok(())) => Ok(Self { stop, wake, thread }),
            Ok(Err(e)) => {
                let _ = thread.join();
                Err(e)
            }
            Err(_) => {
                let _ = thread.join();
                Err(DoorbellError(
                    "the doorbell's forwarder ended at its start".to_owned(),
                ))
            }
        }
    }

    /// Ends the thread and waits for it.
    fn stop(self) {
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.wake.send(&[0]);
        let _ = self.thread.join();
    }
}

/// The forwarder's loop: sleeps in a WaitSet on `listeners` and on `woken` (the end of the
/// forwarder), and rings through `ring` whenever a notification's event ID lacks `bit` (its
/// publisher did not ring this doorbell), until `stop`. Calls `listening` once it sleeps on
/// everything.
fn forward<S: Service>(
    listeners: &[Listener<S>],
    woken: &UnixDatagram,
    stop: &AtomicBool,
    bit: usize,
    ring: &Notifier<DoorbellService>,
    listening: impl FnOnce(),
) -> Result<(), DoorbellError>
where
    Listener<S>: SynchronousMultiplexing,
{
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<S>()
        .map_err(|e| err("the forwarder's WaitSet", e))?;
    let _guards = listeners
        .iter()
        .map(|l| waitset.attach_notification(l))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| err("attaching the forwarder's listeners", e))?;
    let end = SocketFd::of(woken).ok_or_else(|| DoorbellError("the forwarder's socket".into()))?;
    let _end = waitset
        .attach_notification(&end)
        .map_err(|e| err("attaching the forwarder's end", e))?;
    listening();
    while !stop.load(Ordering::Relaxed) {
        // Blocking: no deadline of its own, so an idle forwarder costs nothing. A signal that
        // lands on this thread returns it (`Interrupt`), and it looks again.
        waitset
            .wait_and_process_once(|_| CallbackProgression::Continue)
            .map_err(|e| err("the forwarder's wait", e))?;
        let mut unrung = false;
        for listener in listeners {
            let _ = listener.try_wait(|a| unrung |= a.id.as_value() & bit == 0);
        }
        if unrung {
            ring.notify().map_err(|e| err("the forwarder's ring", e))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ipc::Ipc;
    use missionlink_interfaces::contracts::FramePayload;

    #[test]
    fn a_publisher_that_rang_a_partition_spares_only_that_partitions_listeners() {
        let rang_mission_data = Ringers {
            notifiers: Vec::new(),
            rung: bit(Partition::MissionDataHandling),
        };
        assert!(!rang_mission_data.notifies(&listener_name(Partition::MissionDataHandling)));
        // Another partition's, a nameless one (a test, a partition in Python), any other name.
        assert!(rang_mission_data.notifies(&listener_name(Partition::SystemAutomation)));
        assert!(rang_mission_data.notifies(""));
        assert!(rang_mission_data.notifies("mission-data-handling"));
        // A publisher that rang nothing notifies everyone.
        assert!(Ringers::default().notifies(&listener_name(Partition::MissionDataHandling)));
    }

    /// What the runtime gives a doorbell of mission data handling under `prefix`.
    fn forwarder_of<S: Service>(
        prefix: &str,
    ) -> impl FnOnce() -> Result<(Ipc<S>, Vec<Listener<S>>), DoorbellError> + Send + 'static {
        Ipc::<S>::forwarder_listeners(
            "doorbell-test-forwarder".to_owned(),
            prefix.to_owned(),
            Partition::MissionDataHandling,
        )
    }

    /// Mission data handling's doorbell under a prefix of its own (`name` and this process),
    /// its threads started; the prefix, and the doorbells that keep it open.
    fn started(name: &str) -> (String, Doorbells, Doorbell) {
        let prefix = format!("{name}-{}", std::process::id());
        let bells = Doorbells::open(name, &prefix, PerPartition::all(true)).unwrap();
        let mut doorbell = bells.doorbell(Partition::MissionDataHandling).unwrap();
        doorbell
            .start(forwarder_of::<ipc::Service>(&prefix))
            .unwrap();
        (prefix, bells, doorbell)
    }

    /// Waits on `doorbell` for `timeout`, which only its timer may end: not before the
    /// timeout (within a millisecond of the clocks' rounding), and within a few seconds.
    fn wait_is_timed(doorbell: &Doorbell, start: Instant, timeout: Duration) {
        doorbell
            .wait(timeout.saturating_sub(start.elapsed()))
            .unwrap();
        let waited = start.elapsed();
        assert!(
            waited + Duration::from_millis(1) >= timeout && waited < Duration::from_secs(3),
            "{waited:?}"
        );
    }

    /// Waits on `doorbell` with a timer far away: a ring must end the wait long before it.
    fn wait_is_rung(doorbell: &Doorbell) {
        let start = Instant::now();
        doorbell.wait(Duration::from_secs(5)).unwrap();
        assert!(
            start.elapsed() < Duration::from_secs(1),
            "{:?}",
            start.elapsed()
        );
    }

    #[test]
    fn a_publisher_of_a_consumed_service_rings_and_the_timer_rings_at_the_deadline() {
        let prefix = format!("doorbell-test-{}", std::process::id());
        let bells = Doorbells::open("doorbell-test", &prefix, PerPartition::all(true)).unwrap();
        let mut doorbell = bells.doorbell(Partition::MissionDataHandling).unwrap();
        assert!(
            doorbell.wait(Duration::ZERO).is_err(),
            "no wait before the threads run"
        );
        doorbell
            .start(forwarder_of::<ipc::Service>(&prefix))
            .unwrap();
        let uplink = bells.ringers(FccService::Uplink).unwrap();
        let downlink = bells.ringers(FccService::Downlink).unwrap();

        // A ring before the wait is kept: the wait returns at once, long before its timer.
        uplink.ring().unwrap();
        wait_is_rung(&doorbell);

        // A ring from another thread wakes the wait.
        let ringer = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            uplink.ring().unwrap();
        });
        wait_is_rung(&doorbell);
        ringer.join().unwrap();

        // The downlink feeds voting-monitoring, not this doorbell: only the timer ends the
        // wait, at its deadline (within the timer's slack and the scheduler's).
        downlink.ring().unwrap();
        let start = Instant::now();
        doorbell.wait(Duration::from_millis(30)).unwrap();
        let waited = start.elapsed();
        assert!(
            waited >= Duration::from_millis(29) && waited < Duration::from_millis(500),
            "{waited:?}"
        );
    }

    /// The loop's deadline moved later after the timerfd was armed for an earlier one: the
    /// timer rings at the later deadline, not before (a ring before it would wake the loop for
    /// nothing); an earlier deadline is armed at once.
    #[test]
    fn the_timer_rings_at_the_loops_latest_deadline() {
        let (_prefix, _bells, doorbell) = started("doorbell-test-timer");

        let start = Instant::now();
        doorbell
            .timer
            .set(start + Duration::from_millis(20))
            .unwrap();
        wait_is_timed(&doorbell, start, Duration::from_millis(300));

        let start = Instant::now();
        doorbell.timer.set(start + Duration::from_secs(60)).unwrap();
        wait_is_timed(&doorbell, start, Duration::from_millis(30));
    }

    /// By default every partition but voting-monitoring (its sockets) waits on its doorbell;
    /// with every partition in the WaitSet no process opens one or rings one.
    #[test]
    fn only_a_partition_configured_for_the_doorbell_waits_on_it() {
        let mut ipc = config::Ipc::default();
        assert!(!waits(&ipc, Partition::VotingMonitoring));
        for p in [
            Partition::MissionDataHandling,
            Partition::SystemAutomation,
            Partition::Guidance,
        ] {
            assert!(waits(&ipc, p), "{p}");
        }
        ipc.idle = PerPartition::all(config::Idle::BLOCK);
        assert!(Partition::ALL.iter().all(|p| !waits(&ipc, *p)));
        assert!(Doorbells::of("doorbell-none", &ipc).unwrap().is_none());
        ipc.idle = PerPartition::all(config::Idle::DOORBELL);
        // The link partition waits for its sockets in the WaitSet.
        assert!(!waits(&ipc, Partition::VotingMonitoring));
        assert!(waits(&ipc, Partition::MissionDataHandling));
        ipc.poll = true;
        assert!(Partition::ALL.iter().all(|p| !waits(&ipc, *p)));
    }

    /// A publisher that rings no doorbell (a partition in Python, a process configured
    /// otherwise) is heard through the forwarder at once; a publisher that rang is not rung for
    /// a second time.
    #[test]
    fn the_forwarder_rings_for_a_publisher_that_does_not_and_only_for_it() {
        let (prefix, _bells, doorbell) = started("doorbell-test-forward");
        let frame =
            FramePayload::new(missionlink_interfaces::contracts::Link::Direct, &[1], 0).unwrap();

        // Rings nothing: its configuration has every partition in the WaitSet.
        let in_the_waitset = config::Ipc {
            idle: PerPartition::all(config::Idle::BLOCK),
            ..config::Ipc::with_prefix(&prefix)
        };
        let foreign = Ipc::<ipc::Service>::open("doorbell-foreign", &in_the_waitset).unwrap();
        let foreign = foreign
            .publisher::<FramePayload>(FccService::Uplink)
            .unwrap();
        foreign.send(&frame).unwrap();
        wait_is_rung(&doorbell);

        // Rings the doorbell itself (the defaults have mission data handling on its doorbell)
        // and notifies no one, the forwarder's listener being named for mission data handling:
        // the wait returns at once for its ring, and nothing else is pending: the next wait
        // ends at its deadline.
        let rust =
            Ipc::<ipc::Service>::open("doorbell-rust", &config::Ipc::with_prefix(&prefix)).unwrap();
        let rust = rust.publisher::<FramePayload>(FccService::Uplink).unwrap();
        rust.send(&frame).unwrap();
        doorbell.wait(Duration::from_secs(5)).unwrap();
        std::thread::sleep(Duration::from_millis(100));
        wait_is_timed(&doorbell, Instant::now(), Duration::from_millis(30));
    }

    /// A publisher rings only the doorbells of consumers that wait on them.
    #[test]
    fn ringers_ring_only_the_consumers_that_wait() {
        let prefix = format!("doorbell-test-some-{}", std::process::id());
        let waiting = PerPartition::from_fn(|p| p == Partition::Guidance);
        let bells = Doorbells::open("doorbell-test-some", &prefix, waiting).unwrap();
        assert_eq!(
            bells
                .ringers(FccService::WaypointList)
                .unwrap()
                .notifiers
                .len(),
            1
        );
        assert!(
            bells
                .ringers(FccService::Uplink)
                .unwrap()
                .notifiers
                .is_empty()
        );
    }

    #[test]
    fn every_service_but_the_heartbeats_of_others_than_guidance_feeds_a_partition() {
        for service in [
            FccService::Uplink,
            FccService::Downlink,
            FccService::WaypointList,
            FccService::AreaList,
            FccService::AutomationState,
            FccService::GuidanceProgress,
            FccService::AutomationCommand,
            FccService::Heartbeat(Partition::Guidance),
        ] {
            assert!(!consumers(service).is_empty(), "{service}");
        }
        assert!(consumers(FccService::Heartbeat(Partition::VotingMonitoring)).is_empty());
    }
}
