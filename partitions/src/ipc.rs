//! The iceoryx2 side of a partition: a node that cleans up dead nodes on start (so a partition
//! restarts after `kill -9`), and typed ports for the services of `interfaces::contracts`, each
//! a publish-subscribe port paired with an event port of the same name so that a subscriber can
//! sleep in a WaitSet until data arrives (docs/design.md, iceoryx2 notes).
//!
//! Generic over the service type: partitions run on `ipc::Service`, tests may use
//! `local::Service`.

use core::fmt::Debug;

use iceoryx2::port::backpressure_strategy::BackpressureStrategy;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::port_name::PortName;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{
    AreaListPayload, FccService, Partition, WaypointListPayload, same_activation,
};

use crate::config;
use crate::doorbell::{Doorbell, DoorbellError, Doorbells, Ringers};

/// Something iceoryx2 refused, with what was being done.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct IpcError(pub String);

impl From<DoorbellError> for IpcError {
    fn from(e: DoorbellError) -> Self {
        Self(e.0)
    }
}

impl From<IpcError> for DoorbellError {
    fn from(e: IpcError) -> Self {
        Self(e.0)
    }
}

fn err(what: impl std::fmt::Display, e: impl Debug) -> IpcError {
    IpcError(format!("{what}: {e:?}"))
}

/// Keeps iceoryx2's own log to errors unless `IOX2_LOG_LEVEL` says otherwise (without a config
/// file it warns at every start, which would bury the partitions' own output).
pub fn quiet_iceoryx2_log() {
    set_log_level_from_env_or(LogLevel::Error);
}

/// A partition's node and the service-name prefix.
#[derive(Debug)]
pub struct Ipc<S: Service> {
    node: Node<S>,
    prefix: String,
    /// The node of the partitions' doorbells (`doorbell`), where the configuration has a
    /// partition wait on its doorbell: every publisher rings the doorbells of its consumers that
    /// wait on them. `None` (the default configuration): no doorbell service is opened and no
    /// send rings one.
    doorbells: Option<Doorbells>,
    /// The partition this node's listeners belong to when it waits on its doorbell (or is its
    /// forwarder): they are named for it (`doorbell::listener_name`), so that a publisher that
    /// rang it does not notify them.
    rung_as: Option<Partition>,
}

impl<S: Service> Ipc<S> {
    /// Creates the node `name` under `ipc` (`[ipc]`: the service prefix, and which partitions
    /// wait on their doorbells, `doorbell::waits`) and removes what dead nodes left behind.
    pub fn open(name: &str, ipc: &config::Ipc) -> Result<Self, IpcError> {
        let mut opened = Self::without_doorbells(name, &ipc.service_prefix)?;
        opened.doorbells = Doorbells::of(name, ipc)?;
        Ok(opened)
    }

    /// The node of partition `role` under `ipc`, named as its binary ([`Ipc::open`]); where
    /// `role` waits on its doorbell (`doorbell::waits`), its listeners are named for it.
    pub fn for_partition(role: Partition, ipc: &config::Ipc) -> Result<Self, IpcError> {
        let mut opened = Self::open(role.binary(), ipc)?;
        if crate::doorbell::waits(ipc, role) {
            opened.rung_as = Some(role);
        }
        Ok(opened)
    }

    /// The node `name` under `prefix` whose publishers ring no doorbell (a doorbell's forwarder,
    /// which only listens); removes what dead nodes left behind.
    pub fn without_doorbells(name: &str, prefix: &str) -> Result<Self, IpcError> {
        let node_name: NodeName = name.try_into().map_err(|e| err("node name", e))?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .create::<S>()
            .map_err(|e| err(format_args!("creating node {name}"), e))?;
        let cleanup = node.try_cleanup_dead_nodes();
        if cleanup.cleanups > 0 || cleanup.failed_cleanups > 0 {
            tracing::info!(
                cleaned = cleanup.cleanups,
                failed = cleanup.failed_cleanups,
                "removed the resources of dead nodes"
            );
        }
        Ok(Self {
            node,
            prefix: prefix.to_owned(),
            doorbells: None,
            rung_as: None,
        })
    }

    /// The doorbell of `role`, for that partition's loop to wait on (`doorbell`); an error when
    /// the configuration this was opened with has no partition wait on its doorbell.
    pub fn doorbell(&self, role: Partition) -> Result<Doorbell, IpcError> {
        match &self.doorbells {
            Some(doorbells) => Ok(doorbells.doorbell(role)?),
            None => Err(IpcError(format!(
                "the doorbell of {role}: the configuration has no partition wait on one"
            ))),
        }
    }

    /// The node.
    pub fn node(&self) -> &Node<S> {
        &self.node
    }

    /// The full name of `service`.
    pub fn service_name(&self, service: FccService) -> String {
        service.name(&self.prefix)
    }

    fn names(&self, service: FccService) -> Result<ServiceName, IpcError> {
        self.service_name(service)
            .as_str()
            .try_into()
            .map_err(|e| err(format_args!("service name of {service}"), e))
    }

    fn pubsub<T: Debug + ZeroCopySend + 'static>(
        &self,
        service: FccService,
    ) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<S, T, ()>, IpcError>
    {
        let qos = service.qos();
        self.node
            .service_builder(&self.names(service)?)
            .publish_subscribe::<T>()
            .history_size(qos.history_size)
            .subscriber_max_buffer_size(qos.subscriber_max_buffer_size)
            .max_publishers(qos.max_publishers)
            .max_subscribers(qos.max_subscribers)
            .enable_safe_overflow(qos.safe_overflow)
            .open_or_create()
            .map_err(|e| err(format_args!("opening {service}"), e))
    }

    fn event(
        &self,
        service: FccService,
    ) -> Result<iceoryx2::service::port_factory::event::PortFactory<S>, IpcError> {
        let qos = service.qos();
        self.node
            .service_builder(&self.names(service)?)
            .event()
            .max_notifiers(qos.max_publishers)
            .max_listeners(qos.max_listeners())
            .open_or_create()
            .map_err(|e| err(format_args!("opening the event service {service}"), e))
    }

    /// A publisher of `service` that notifies its listeners after every sample.
    pub fn publisher<T: Debug + Copy + ZeroCopySend + 'static>(
        &self,
        service: FccService,
    ) -> Result<Publisher<S, T>, IpcError> {
        // A subscriber that stopped or hung (SIGSTOP, a HIL partition in a debugger) must never
        // block its publisher: iceoryx2's default retries until delivered, which would take the
        // link partition down with it. A frame a full queue cannot take is lost for that
        // subscriber alone, and the ICD's retry (paper §3.1.4) recovers it; the list services
        // overwrite their history (safe overflow) and never get here.
        let publisher = self
            .pubsub::<T>(service)?
            .publisher_builder()
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|e| err(format_args!("publisher of {service}"), e))?;
        let notifier = self
            .event(service)?
            .notifier_builder()
            .create()
            .map_err(|e| err(format_args!("notifier of {service}"), e))?;
        Ok(Publisher {
            service,
            publisher,
            ringers: self
                .doorbells
                .as_ref()
                .map(|d| d.ringers(service))
                .transpose()?
                .unwrap_or_default(),
            notifier,
        })
    }

    /// What a doorbell's forwarder opens on its own thread (`doorbell::Doorbell::start`): a
    /// node `name` under `prefix` and a listener of the event of every service `role` consumes
    /// (`doorbell::consumed_by`).
    pub fn forwarder_listeners(
        name: String,
        prefix: String,
        role: Partition,
    ) -> impl FnOnce() -> Result<(Self, Vec<Listener<S>>), DoorbellError> + Send + 'static {
        move || {
            let mut ipc = Self::without_doorbells(&name, &prefix)?;
            ipc.rung_as = Some(role);
            let listeners = crate::doorbell::consumed_by(role)
                .map(|service| ipc.listener(service))
                .collect::<Result<Vec<_>, _>>()?;
            Ok((ipc, listeners))
        }
    }

    /// A listener of `service`'s event alone, without a subscriber (a doorbell's forwarder).
    pub fn listener(&self, service: FccService) -> Result<Listener<S>, IpcError> {
        let event = self.event(service)?;
        let builder = event.listener_builder();
        let builder = match self.rung_as {
            Some(role) => builder.name(
                &PortName::new(&crate::doorbell::listener_name(role))
                    .map_err(|e| err("listener name", e))?,
            ),
            None => builder,
        };
        builder
            .create()
            .map_err(|e| err(format_args!("listener of {service}"), e))
    }

    /// A subscriber of `service` with the listener to attach to a WaitSet.
    pub fn subscriber<T: Debug + Copy + ZeroCopySend + 'static>(
        &self,
        service: FccService,
    ) -> Result<Subscriber<S, T>, IpcError> {
        let subscriber = self
            .pubsub::<T>(service)?
            .subscriber_builder()
            .create()
            .map_err(|e| err(format_args!("subscriber of {service}"), e))?;
        let listener = self.listener(service)?;
        Ok(Subscriber {
            service,
            subscriber,
            listener,
        })
    }

    /// Subscribers of the active lists that mission data handling publishes, the waypoint list
    /// and the area list (docs/design.md, "Contracts between partitions"): what system automation
    /// and guidance both follow.
    pub fn active_lists(&self) -> Result<ActiveLists<S>, IpcError> {
        Ok(ActiveLists {
            waypoints: self.subscriber(FccService::WaypointList)?,
            areas: self.subscriber(FccService::AreaList)?,
        })
    }
}

/// The subscribers of the two active lists.
#[derive(Debug)]
pub struct ActiveLists<S: Service> {
    /// `fcc/mission/waypoint-list`.
    pub waypoints: Subscriber<S, WaypointListPayload>,
    /// `fcc/mission/area-list`.
    pub areas: Subscriber<S, AreaListPayload>,
}

impl<S: Service> ActiveLists<S> {
    /// Hands every sample that arrived on either service to `pairing` (draining the
    /// notifications) and returns the pair it releases, if any: a waypoint list and an area list
    /// of the same activation, newer than the pair released before (see [`ListPairing`]).
    pub fn receive<'p>(
        &self,
        pairing: &'p mut ListPairing,
    ) -> Option<(&'p WaypointListPayload, &'p AreaListPayload)> {
        self.waypoints.take_all(|w| pairing.offer_waypoints(w));
        self.areas.take_all(|a| pairing.offer_areas(a));
        pairing.take()
    }
}

/// Pairs the active waypoint list with the active area list on the subscriber's side, so that a
/// partition never acts on the new waypoint list with the old area list or the reverse
/// (docs/design.md "Activation is atomic", ICD §8 "Activate").
///
/// Mission data handling publishes both lists whenever either changes, under one activation
/// number that grows with every change (`contracts::same_activation`). The two services deliver
/// independently, so the newest sample of one may belong to a newer activation than the newest
/// of the other. The pairing keeps the newest sample of each (by activation; copies, since a
/// sample must go back to iceoryx2) and releases them as a pair only when they belong to the same
/// activation and it is newer than the pair released last. Until then the partition keeps the
/// pair it has.
///
/// - A sample of an older activation than the one held or the one released (a dead
///   predecessor's port still delivering) is ignored.
/// - A restarted mission data handling publishes again the lists it resumed with, under the same
///   activation (it is the sum of the two generations, which are saved with the lists): that is
///   not a new pair, and nothing is released.
/// - Limit: the activation comes from mission data handling's state directory. If that
///   directory is lost, the activation starts again from zero and subscribers that kept running
///   hold their pair until the activation passes it: restart them with it (the launcher restarts
///   the whole FCC).
///
/// The copies are made once on the heap and overwritten in place afterwards, so a running
/// partition does not allocate per list.
#[derive(Debug, Default)]
pub struct ListPairing {
    waypoints: Option<Box<WaypointListPayload>>,
    areas: Option<Box<AreaListPayload>>,
    released: Option<u64>,
    mismatched: u64,
}

/// Keeps `list` in `held` unless it is older than what is held or was released (`activation`
/// gives a list's activation); whether it was kept.
fn keep_newest<T: Copy>(
    held: &mut Option<Box<T>>,
    list: &T,
    released: Option<u64>,
    activation: impl Fn(&T) -> u64,
) -> bool {
    let newest = held
        .as_deref()
        .map(&activation)
        .into_iter()
        .chain(released)
        .max();
    if newest.is_some_and(|n| activation(list) < n) {
        return false;
    }
    match held {
        Some(copy) => **copy = *list,
        None => *held = Some(Box::new(*list)),
    }
    true
}

impl ListPairing {
    /// Nothing received yet, nothing released.
    pub fn new() -> Self {
        Self::default()
    }

    /// A waypoint list arrived.
    pub fn offer_waypoints(&mut self, list: &WaypointListPayload) {
        if !keep_newest(&mut self.waypoints, list, self.released, |l| l.activation) {
            tracing::debug!(
                activation = list.activation,
                "an older waypoint list arrived: ignored"
            );
        }
    }

    /// An area list arrived.
    pub fn offer_areas(&mut self, list: &AreaListPayload) {
        if !keep_newest(&mut self.areas, list, self.released, |l| l.activation) {
            tracing::debug!(
                activation = list.activation,
                "an older area list arrived: ignored"
            );
        }
    }

    /// The newest lists as a pair, if they belong to the same activation and it is newer than
    /// the pair released last; then that pair counts as released.
    pub fn take(&mut self) -> Option<(&WaypointListPayload, &AreaListPayload)> {
        let (Some(w), Some(a)) = (self.waypoints.as_deref(), self.areas.as_deref()) else {
            return None;
        };
        if !same_activation(w, a) {
            self.mismatched += 1;
            return None;
        }
        if self.released.is_some_and(|r| w.activation <= r) {
            return None;
        }
        self.released = Some(w.activation);
        Some((w, a))
    }

    /// The activation of the pair released last.
    pub fn released(&self) -> Option<u64> {
        self.released
    }

    /// How often [`ListPairing::take`] found the newest lists of different activations: the
    /// times a partition without the pairing would have held a mix.
    pub fn mismatched(&self) -> u64 {
        self.mismatched
    }
}

/// A typed publisher with its notifier.
#[derive(Debug)]
pub struct Publisher<S: Service, T: Debug + ZeroCopySend + 'static> {
    service: FccService,
    publisher: iceoryx2::port::publisher::Publisher<S, T, ()>,
    ringers: Ringers,
    notifier: Notifier<S>,
}

impl<S: Service, T: Debug + Copy + ZeroCopySend + 'static> Publisher<S, T> {
    /// Publishes `value` (copied into shared memory once) and wakes the subscribers: rings the
    /// doorbells of the partitions that consume the service (`doorbell::consumers`) and wait on
    /// them (by default all but voting-monitoring), then notifies each listener of the
    /// service's event but those of the partitions it rang (`doorbell::Ringers::notifies`): a
    /// test, the launcher, a partition in Python or in the WaitSet. Each listener alone: the
    /// forwarder of a partition it rang is not woken for nothing when someone else listens on
    /// the event too (the launcher on a heartbeat, say). What every partition does.
    pub fn send(&self, value: &T) -> Result<(), IpcError> {
        self.publish(value)?;
        if self.ringers.is_empty() {
            return self.notify();
        }
        self.ringers.ring()?;
        // The event ID names the doorbells rung (`Ringers::event_id`): a partition's forwarder
        // rings its doorbell only for a notification whose publisher did not.
        let id = self.ringers.event_id();
        let mut failed = None;
        self.notifier.for_each_listener(|listener, details| {
            if self.ringers.notifies(details.listener_name.as_str())
                && let Err(e) = listener.notify_with_custom_event_id(id)
            {
                failed.get_or_insert(e);
            }
            CallbackProgression::Continue
        });
        match failed {
            Some(e) => Err(err(format_args!("notify on {}", self.service), e)),
            None => Ok(()),
        }
    }

    /// Publishes `value` without waking anyone: for subscribers that poll (the polling
    /// transport of benches/latency/hop.rs); [`Publisher::notify`] wakes them later.
    pub fn publish(&self, value: &T) -> Result<(), IpcError> {
        let sample = self
            .publisher
            .loan_uninit()
            .map_err(|e| err(format_args!("loan on {}", self.service), e))?;
        sample
            .write_payload(*value)
            .send()
            .map_err(|e| err(format_args!("send on {}", self.service), e))?;
        Ok(())
    }

    /// Wakes the subscribers sleeping on this service's event (saying that no doorbell was
    /// rung).
    pub fn notify(&self) -> Result<(), IpcError> {
        self.notifier
            .notify()
            .map_err(|e| err(format_args!("notify on {}", self.service), e))?;
        Ok(())
    }

    /// The port's unique ID, which every sample it sends carries: how the bridge recognises
    /// its own samples and never sends them back (docs/two-hosts.md, "No loops").
    pub fn id(&self) -> iceoryx2::identifiers::UniquePublisherId {
        self.publisher.id()
    }

    /// Connects subscribers that joined since the last send, so they receive the history
    /// (late joiners of the list services).
    pub fn update_connections(&self) {
        if let Err(e) = self.publisher.update_connections() {
            tracing::warn!(service = %self.service, ?e, "update_connections failed");
        }
    }
}

/// A typed subscriber with its listener.
#[derive(Debug)]
pub struct Subscriber<S: Service, T: Debug + ZeroCopySend + 'static> {
    service: FccService,
    subscriber: iceoryx2::port::subscriber::Subscriber<S, T, ()>,
    listener: Listener<S>,
}

impl<S: Service, T: Debug + Copy + ZeroCopySend + 'static> Subscriber<S, T> {
    /// The listener, to attach to a WaitSet.
    pub fn listener(&self) -> &Listener<S> {
        &self.listener
    }

    /// Consumes the pending notifications (a WaitSet spins on a listener that is not drained).
    pub fn drain_notifications(&self) {
        if let Err(e) = self.listener.try_wait(|_| {}) {
            tracing::warn!(service = %self.service, ?e, "listener failed");
        }
    }

    /// Whether a sample waits to be taken, without taking it or a notification (what a
    /// spinning loop looks at, `runtime::Pending`); `false` when iceoryx2 cannot tell.
    pub fn has_samples(&self) -> bool {
        self.subscriber.has_samples().unwrap_or(false)
    }

    /// Hands every waiting sample to `f`, oldest first, without copying it out of shared
    /// memory; returns how many there were.
    pub fn for_each(&self, mut f: impl FnMut(&T)) -> usize {
        let mut n = 0;
        loop {
            match self.subscriber.receive() {
                Ok(Some(sample)) => {
                    f(sample.payload());
                    n += 1;
                }
                Ok(None) => return n,
                Err(e) => {
                    tracing::warn!(service = %self.service, ?e, "receive failed");
                    return n;
                }
            }
        }
    }

    /// Hands the oldest waiting sample to `f`, if there is one, without copying it; whether
    /// there was (a spinning reader that wants the first sample in hand at once: the polling
    /// transport of benches/latency/hop.rs).
    pub fn take_one(&self, f: impl FnOnce(&T)) -> bool {
        match self.subscriber.receive() {
            Ok(Some(sample)) => {
                f(sample.payload());
                true
            }
            Ok(None) => false,
            Err(e) => {
                tracing::warn!(service = %self.service, ?e, "receive failed");
                false
            }
        }
    }

    /// Hands every waiting sample to `f`, drains the notifications, then looks once more: the
    /// drain's system calls stay off the path of a sample that is already there, and a sample
    /// published between the first look and the drain is not left for the next wake-up
    /// (benches/latency/hop.rs measures the difference). Returns how many samples there were.
    pub fn take_all(&self, mut f: impl FnMut(&T)) -> usize {
        let first = self.for_each(&mut f);
        self.drain_notifications();
        first + self.for_each(f)
    }

    /// Hands every waiting sample to `f` with the ID of the publisher that sent it (the bridge
    /// leaves out its own), oldest first, then drains the notifications and looks once more as
    /// [`Subscriber::take_all`] does; returns how many samples there were.
    pub fn take_all_with_origin(
        &self,
        mut f: impl FnMut(&T, iceoryx2::identifiers::UniquePublisherId),
    ) -> usize {
        let mut n = 0;
        for pass in 0..2 {
            loop {
                match self.subscriber.receive() {
                    Ok(Some(sample)) => {
                        f(sample.payload(), sample.origin());
                        n += 1;
                    }
                    Ok(None) => break,
                    Err(e) => {
                        tracing::warn!(service = %self.service, ?e, "receive failed");
                        break;
                    }
                }
            }
            if pass == 0 {
                self.drain_notifications();
            }
        }
        n
    }

    /// The newest waiting sample, copied (state services: only the latest matters).
    pub fn latest(&self) -> Option<T> {
        let mut last = None;
        self.for_each(|v| last = Some(*v));
        last
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_interfaces::contracts::{FramePayload, Link};

    /// A late subscriber of a history-1 service receives the active list (the contract the
    /// guidance partition relies on), through the QoS of the contracts as the ports here apply
    /// it, on the in-process iceoryx2 service variant.
    #[test]
    fn a_late_subscriber_receives_the_active_waypoint_list() {
        let prefix = format!("ipc-test-{}", std::process::id());
        let ipc =
            Ipc::<local::Service>::open("ipc-test", &config::Ipc::with_prefix(&prefix)).unwrap();
        let publisher = ipc
            .publisher::<WaypointListPayload>(FccService::WaypointList)
            .unwrap();
        let mut list = WaypointListPayload::EMPTY;
        list.generation = 1;
        list.count = 2;
        list.waypoints[0].number = 1;
        list.waypoints[0].next = 2;
        list.waypoints[1].number = 2;
        publisher.send(&list).unwrap();

        let subscriber = ipc
            .subscriber::<WaypointListPayload>(FccService::WaypointList)
            .unwrap();
        publisher.update_connections();
        let received = subscriber.latest().expect("history delivers the list");
        assert!(received.is_active());
        let numbers: Vec<_> = received
            .waypoints()
            .iter()
            .map(|w| (w.number, w.next))
            .collect();
        assert_eq!(numbers, [(1, 2), (2, 0)]);
    }

    /// With every partition in the WaitSet a process opens no doorbell node and its publishers
    /// ring nothing; under the defaults (mission data handling on its doorbell) the uplink's
    /// publisher rings it and says so in its event ID.
    #[test]
    fn a_configuration_without_a_doorbell_opens_none_and_the_default_rings_mission_data_handling() {
        let prefix = format!("ipc-test-quiet-{}", std::process::id());
        let in_the_waitset = config::Ipc {
            idle: crate::config::PerPartition::all(config::Idle::BLOCK),
            ..config::Ipc::with_prefix(&prefix)
        };
        let ipc = Ipc::<local::Service>::open("ipc-test-quiet", &in_the_waitset).unwrap();
        assert!(ipc.doorbells.is_none());
        assert!(ipc.doorbell(Partition::MissionDataHandling).is_err());
        let uplink = ipc.publisher::<FramePayload>(FccService::Uplink).unwrap();
        assert!(uplink.ringers.is_empty());
        assert_eq!(uplink.ringers.event_id().as_value(), 0);

        let ipc = Ipc::<local::Service>::open("ipc-test-rings", &config::Ipc::with_prefix(&prefix))
            .unwrap();
        let uplink = ipc.publisher::<FramePayload>(FccService::Uplink).unwrap();
        assert!(!uplink.ringers.is_empty());
        assert_ne!(uplink.ringers.event_id().as_value(), 0);
    }

    /// A publisher that rang mission data handling's doorbell does not notify the listeners
    /// named for it (nobody sleeps on them), not even when another listener is on the event
    /// (a partition in the WaitSet, a test, a partition in Python), which it does notify.
    #[test]
    fn a_ringing_publisher_notifies_only_listeners_it_did_not_ring() {
        let prefix = format!("ipc-test-spare-{}", std::process::id());
        let defaults = config::Ipc::with_prefix(&prefix);
        let mission_data =
            Ipc::<local::Service>::for_partition(Partition::MissionDataHandling, &defaults)
                .unwrap();
        let frames = mission_data
            .subscriber::<FramePayload>(FccService::Uplink)
            .unwrap();
        let sender = Ipc::<local::Service>::open("ipc-test-spare-sender", &defaults).unwrap();
        let uplink = sender
            .publisher::<FramePayload>(FccService::Uplink)
            .unwrap();
        let frame = FramePayload::new(Link::Direct, &[1], 0).unwrap();
        let notified = |listener: &Listener<local::Service>| {
            let mut n = 0;
            listener.try_wait(|_| n += 1).unwrap();
            n
        };

        uplink.send(&frame).unwrap();
        assert_eq!(notified(frames.listener()), 0, "no notification");
        assert_eq!(frames.take_all(|_| {}), 1, "the sample is there");

        let stranger = Ipc::<local::Service>::open("ipc-test-spare-stranger", &defaults).unwrap();
        let stranger = stranger.listener(FccService::Uplink).unwrap();
        uplink.send(&frame).unwrap();
        assert_eq!(notified(&stranger), 1);
        assert_eq!(
            notified(frames.listener()),
            0,
            "left out even so: each listener is notified alone"
        );
        assert_eq!(frames.take_all(|_| {}), 1);
    }

    fn waypoints(activation: u64, count: u16) -> WaypointListPayload {
        WaypointListPayload {
            generation: activation,
            activation,
            count,
            ..WaypointListPayload::EMPTY
        }
    }

    fn areas(activation: u64, polygons: u8) -> AreaListPayload {
        AreaListPayload {
            generation: activation,
            activation,
            no_fly_polygon_count: polygons,
            ..AreaListPayload::EMPTY
        }
    }

    /// What `pairing` releases now, as (activation, waypoint count, polygon count).
    fn released(pairing: &mut ListPairing) -> Option<(u64, u16, u8)> {
        pairing
            .take()
            .map(|(w, a)| (w.activation, w.count, a.no_fly_polygon_count))
    }

    #[test]
    fn a_new_waypoint_list_waits_for_its_area_list_and_the_old_pair_holds_meanwhile() {
        let mut pairing = ListPairing::new();
        assert_eq!(released(&mut pairing), None, "nothing received");
        pairing.offer_waypoints(&waypoints(1, 3));
        assert_eq!(
            released(&mut pairing),
            None,
            "the areas of activation 1 missing"
        );
        pairing.offer_areas(&areas(1, 1));
        assert_eq!(released(&mut pairing), Some((1, 3, 1)));
        assert_eq!(released(&mut pairing), None, "released once");

        pairing.offer_waypoints(&waypoints(2, 5));
        assert_eq!(released(&mut pairing), None, "W2 with A1 is a mix");
        assert_eq!(
            pairing.released(),
            Some(1),
            "the pair of activation 1 holds"
        );
        pairing.offer_areas(&areas(2, 4));
        assert_eq!(released(&mut pairing), Some((2, 5, 4)));
        assert_eq!(pairing.mismatched(), 1);

        // The areas may come first as well.
        pairing.offer_areas(&areas(3, 0));
        assert_eq!(released(&mut pairing), None);
        pairing.offer_waypoints(&waypoints(3, 2));
        assert_eq!(released(&mut pairing), Some((3, 2, 0)));
        assert_eq!(pairing.mismatched(), 2);
    }

    #[test]
    fn several_activations_between_two_looks_release_only_the_newest_whole_pair() {
        let mut pairing = ListPairing::new();
        for activation in 1..=3 {
            pairing.offer_waypoints(&waypoints(activation, activation as u16));
            pairing.offer_areas(&areas(activation, activation as u8));
        }
        pairing.offer_waypoints(&waypoints(4, 4));
        assert_eq!(released(&mut pairing), None, "W4 with A3");
        assert_eq!(pairing.released(), None, "no pair yet");
        pairing.offer_areas(&areas(4, 4));
        assert_eq!(released(&mut pairing), Some((4, 4, 4)));
    }

    #[test]
    fn lists_older_than_those_held_or_released_are_ignored() {
        let mut pairing = ListPairing::new();
        pairing.offer_waypoints(&waypoints(5, 5));
        pairing.offer_areas(&areas(5, 5));
        assert_eq!(released(&mut pairing), Some((5, 5, 5)));
        // A dead predecessor's port delivers an old pair: not released, and the held lists stay.
        pairing.offer_waypoints(&waypoints(4, 9));
        pairing.offer_areas(&areas(4, 9));
        assert_eq!(released(&mut pairing), None);
        pairing.offer_waypoints(&waypoints(6, 6));
        // Older than the waypoint list held (6), though newer than the pair released (5).
        pairing.offer_waypoints(&waypoints(5, 9));
        pairing.offer_areas(&areas(6, 6));
        assert_eq!(released(&mut pairing), Some((6, 6, 6)));
    }

    #[test]
    fn a_restarted_publisher_that_publishes_the_same_activation_again_is_not_a_new_pair() {
        let mut pairing = ListPairing::new();
        pairing.offer_waypoints(&waypoints(7, 3));
        pairing.offer_areas(&areas(7, 2));
        assert_eq!(released(&mut pairing), Some((7, 3, 2)));
        // Mission data handling resumed with the lists it saved and publishes them again.
        pairing.offer_waypoints(&waypoints(7, 3));
        assert_eq!(released(&mut pairing), None);
        pairing.offer_areas(&areas(7, 2));
        assert_eq!(released(&mut pairing), None);
        assert_eq!(pairing.released(), Some(7));
        assert_eq!(pairing.mismatched(), 0);
    }

    #[test]
    fn lists_of_no_mission_are_a_pair_like_any_other() {
        // A resumed mission data handling with nothing active publishes the empty lists.
        let mut pairing = ListPairing::new();
        pairing.offer_waypoints(&WaypointListPayload::EMPTY);
        pairing.offer_areas(&AreaListPayload::EMPTY);
        assert_eq!(released(&mut pairing), Some((0, 0, 0)));
    }

    /// The pairing over iceoryx2: the subscriber side of both list services, as guidance and
    /// system automation use it, on the in-process service variant.
    #[test]
    fn active_lists_release_a_pair_only_once_both_lists_of_an_activation_arrived() {
        let prefix = format!("ipc-test-pair-{}", std::process::id());
        let ipc = Ipc::<local::Service>::open("ipc-test-pair", &config::Ipc::with_prefix(&prefix))
            .unwrap();
        let w = ipc
            .publisher::<WaypointListPayload>(FccService::WaypointList)
            .unwrap();
        let a = ipc
            .publisher::<AreaListPayload>(FccService::AreaList)
            .unwrap();
        w.send(&waypoints(1, 2)).unwrap();
        a.send(&areas(1, 1)).unwrap();

        // A late subscriber: the history gives it the pair.
        let lists = ipc.active_lists().unwrap();
        w.update_connections();
        a.update_connections();
        let mut pairing = ListPairing::new();
        let pair = lists
            .receive(&mut pairing)
            .map(|(w, a)| (w.count, a.no_fly_polygon_count));
        assert_eq!(pair, Some((2, 1)));

        w.send(&waypoints(2, 4)).unwrap();
        assert!(lists.receive(&mut pairing).is_none(), "W2 alone");
        a.send(&areas(2, 3)).unwrap();
        let pair = lists
            .receive(&mut pairing)
            .map(|(w, a)| (w.count, a.no_fly_polygon_count));
        assert_eq!(pair, Some((4, 3)));
        assert!(lists.receive(&mut pairing).is_none(), "nothing new");
    }

    /// A subscriber that never reads (stopped, hung) does not block the publisher of a frame
    /// queue: past the queue's capacity, frames are lost for it and sending goes on.
    #[test]
    fn a_subscriber_that_never_reads_does_not_block_the_frame_queue() {
        let prefix = format!("ipc-test-full-{}", std::process::id());
        let ipc = Ipc::<local::Service>::open("ipc-test-full", &config::Ipc::with_prefix(&prefix))
            .unwrap();
        let uplink = ipc.publisher::<FramePayload>(FccService::Uplink).unwrap();
        let stalled = ipc.subscriber::<FramePayload>(FccService::Uplink).unwrap();
        uplink.update_connections();
        let capacity = FccService::Uplink.qos().subscriber_max_buffer_size;
        let frame = FramePayload::new(Link::Direct, &[0u8; 16], 1).unwrap();
        // Returns at all (with RetryUntilDelivered it would wait here for ever).
        for _ in 0..3 * capacity {
            uplink.send(&frame).unwrap();
        }
        let mut delivered = 0;
        stalled.take_all(|_| delivered += 1);
        assert_eq!(delivered, capacity);
    }
}
