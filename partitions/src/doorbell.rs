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
//! `blocking_wait`, and a timer thread of the [`Doorbell`] rings it at the loop's next deadline
//! ([`Doorbell::wait`]).
//!
//! A partition on the doorbell still has its ordinary listeners, which the publishers notify as
//! before (a test, the launcher, a WaitSet elsewhere may sleep on them); the steps drain them.
//! A publisher that does not ring (another language's guidance in the rig) is seen at the
//! partition's next deadline, within its timer period.
//!
//! The doorbell costs nothing where it is not used: [`waits`] is the one rule that says which
//! partitions wait on their doorbells under a configuration (none by default: `config::Idle`),
//! and the runtime (which doorbell a loop waits on) and `ipc::Ipc::open` (which doorbells its
//! publishers ring) both ask it. A process under a configuration where no partition waits on one
//! opens no doorbell service, and its publishers ring nothing.

use core::fmt::Debug;
use std::sync::{Arc, Condvar, Mutex};
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

use crate::config::{self, IdleMode, PerPartition};

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
        let notifiers = consumers(service)
            .iter()
            .filter(|role| self.waiting[**role])
            .map(|role| {
                self.event(*role)?
                    .notifier_builder()
                    .create()
                    .map_err(|e| err(format_args!("ringer of the doorbell of {role:?}"), e))
            })
            .collect::<Result<_, _>>()?;
        Ok(Ringers { notifiers })
    }

    /// The doorbell of `role`, to wait on, with its timer thread.
    pub fn doorbell(&self, role: Partition) -> Result<Doorbell, DoorbellError> {
        let event = self.event(role)?;
        let listener = event
            .listener_builder()
            .create()
            .map_err(|e| err(format_args!("listener of the doorbell of {role:?}"), e))?;
        let timer = Arc::new(Timer::default());
        let notifier = event
            .notifier_builder()
            .create()
            .map_err(|e| err(format_args!("timer of the doorbell of {role:?}"), e))?;
        let ring = Arc::clone(&timer);
        let thread = std::thread::Builder::new()
            .name("doorbell-timer".to_owned())
            .spawn(move || ring.run(&notifier))
            .map_err(|e| err("starting the doorbell's timer thread", e))?;
        Ok(Doorbell {
            listener,
            timer,
            thread: Some(thread),
        })
    }
}

/// What rings the doorbells of one service's consumers (those that wait on theirs); none
/// where no consumer waits on one (the default), which costs nothing per send.
#[derive(Debug, Default)]
pub struct Ringers {
    notifiers: Vec<Notifier<DoorbellService>>,
}

impl Ringers {
    /// Whether there is no doorbell to ring.
    pub fn is_empty(&self) -> bool {
        self.notifiers.is_empty()
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

/// How late the timer may ring rather than be woken to ring earlier.
const TIMER_SLACK: Duration = Duration::from_millis(1);

/// The deadline the timer thread rings the doorbell at, and the end of the thread.
#[derive(Debug, Default)]
struct Timer {
    state: Mutex<TimerState>,
    changed: Condvar,
}

#[derive(Debug, Default)]
struct TimerState {
    deadline: Option<Instant>,
    end: bool,
}

impl Timer {
    /// The timer thread: rings through `notifier` whenever the deadline passes, until the end.
    fn run(&self, notifier: &Notifier<DoorbellService>) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        loop {
            if state.end {
                return;
            }
            let now = Instant::now();
            match state.deadline {
                Some(d) if d <= now => {
                    state.deadline = None;
                    if let Err(e) = notifier.notify() {
                        tracing::warn!(?e, "the doorbell's timer cannot ring");
                    }
                }
                Some(d) => match self.changed.wait_timeout(state, d - now) {
                    Ok((s, _)) => state = s,
                    Err(_) => return,
                },
                None => match self.changed.wait(state) {
                    Ok(s) => state = s,
                    Err(_) => return,
                },
            }
        }
    }
}

/// A partition's doorbell: its listener and the timer thread that rings it at the loop's next
/// deadline. The thread ends when the doorbell is dropped.
#[derive(Debug)]
pub struct Doorbell {
    listener: Listener<DoorbellService>,
    timer: Arc<Timer>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Doorbell {
    /// Sleeps until a publisher or the timer rings, the timer at `timeout` from now. Consumes
    /// every pending ring.
    pub fn wait(&self, timeout: Duration) -> Result<(), DoorbellError> {
        let deadline = Instant::now() + timeout;
        if let Ok(mut state) = self.timer.state.lock() {
            // The timer thread is woken only for a deadline earlier by more than TIMER_SLACK
            // (waking it costs a context switch on the loop's path): a later one it finds when
            // the one it waits for passes, a slightly earlier one it rings at most TIMER_SLACK
            // late.
            let earlier = state.deadline.is_none_or(|d| deadline + TIMER_SLACK < d);
            state.deadline = Some(deadline);
            if earlier {
                self.timer.changed.notify_one();
            }
        }
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
        if let Ok(mut state) = self.timer.state.lock() {
            state.end = true;
            self.timer.changed.notify_one();
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_publisher_of_a_consumed_service_rings_and_the_timer_rings_at_the_deadline() {
        let prefix = format!("doorbell-test-{}", std::process::id());
        let bells = Doorbells::open("doorbell-test", &prefix, PerPartition::all(true)).unwrap();
        let doorbell = bells.doorbell(Partition::MissionDataHandling).unwrap();
        let uplink = bells.ringers(FccService::Uplink).unwrap();
        let downlink = bells.ringers(FccService::Downlink).unwrap();

        // A ring before the wait is kept: the wait returns at once, long before its timer.
        uplink.ring().unwrap();
        let start = Instant::now();
        doorbell.wait(Duration::from_secs(5)).unwrap();
        assert!(
            start.elapsed() < Duration::from_secs(1),
            "{:?}",
            start.elapsed()
        );

        // A ring from another thread wakes the wait.
        let ringer = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            uplink.ring().unwrap();
        });
        let start = Instant::now();
        doorbell.wait(Duration::from_secs(5)).unwrap();
        assert!(
            start.elapsed() < Duration::from_secs(1),
            "{:?}",
            start.elapsed()
        );
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

    /// The default configuration uses no doorbell: no process opens one or rings one.
    #[test]
    fn only_a_partition_configured_for_the_doorbell_waits_on_it() {
        let mut ipc = config::Ipc::default();
        assert!(Partition::ALL.iter().all(|p| !waits(&ipc, *p)));
        assert!(Doorbells::of("doorbell-none", &ipc).unwrap().is_none());
        ipc.idle = PerPartition::all(config::Idle {
            mode: IdleMode::Doorbell,
            ..config::Idle::BLOCK
        });
        // The link partition waits for its sockets in the WaitSet.
        assert!(!waits(&ipc, Partition::VotingMonitoring));
        assert!(waits(&ipc, Partition::MissionDataHandling));
        ipc.poll = true;
        assert!(Partition::ALL.iter().all(|p| !waits(&ipc, *p)));
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
