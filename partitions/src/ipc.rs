//! The iceoryx2 side of a partition: a node that cleans up dead nodes on start (so a partition
//! restarts after `kill -9`), and typed ports for the services of `interfaces::contracts`, each
//! a publish-subscribe port paired with an event port of the same name so that a subscriber can
//! sleep in a WaitSet until data arrives (DESIGN.md, iceoryx2 notes).
//!
//! Generic over the service type: partitions run on `ipc::Service`, tests may use
//! `local::Service`.

use core::fmt::Debug;

use iceoryx2::port::backpressure_strategy::BackpressureStrategy;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{AreaListPayload, FccService, WaypointListPayload};

/// Something iceoryx2 refused, with what was being done.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IpcError(pub String);

impl std::fmt::Display for IpcError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for IpcError {}

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
}

impl<S: Service> Ipc<S> {
    /// Creates the node `name` and removes what dead nodes left behind.
    pub fn open(name: &str, prefix: &str) -> Result<Self, IpcError> {
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
        })
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
            .max_listeners(qos.max_subscribers)
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
            notifier,
        })
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
        let listener = self
            .event(service)?
            .listener_builder()
            .create()
            .map_err(|e| err(format_args!("listener of {service}"), e))?;
        Ok(Subscriber {
            service,
            subscriber,
            listener,
        })
    }

    /// Subscribers of the active lists that mission data handling publishes, the waypoint list
    /// and the area list (DESIGN.md, "Contracts between partitions"): what system automation
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

/// A typed publisher with its notifier.
#[derive(Debug)]
pub struct Publisher<S: Service, T: Debug + ZeroCopySend + 'static> {
    service: FccService,
    publisher: iceoryx2::port::publisher::Publisher<S, T, ()>,
    notifier: Notifier<S>,
}

impl<S: Service, T: Debug + Copy + ZeroCopySend + 'static> Publisher<S, T> {
    /// Publishes `value` (copied into shared memory once) and wakes the subscribers: what every
    /// partition does.
    pub fn send(&self, value: &T) -> Result<(), IpcError> {
        self.publish(value)?;
        self.notify()
    }

    /// Publishes `value` without waking anyone: for subscribers that poll (the polling
    /// transport of benches/latency.rs); [`Publisher::notify`] wakes them later.
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

    /// Wakes the subscribers sleeping on this service's event.
    pub fn notify(&self) -> Result<(), IpcError> {
        self.notifier
            .notify()
            .map_err(|e| err(format_args!("notify on {}", self.service), e))?;
        Ok(())
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

    /// Hands every waiting sample to `f`, drains the notifications, then looks once more: the
    /// drain's system calls stay off the path of a sample that is already there, and a sample
    /// published between the first look and the drain is not left for the next wake-up
    /// (benches/latency.rs measures the difference). Returns how many samples there were.
    pub fn take_all(&self, mut f: impl FnMut(&T)) -> usize {
        let first = self.for_each(&mut f);
        self.drain_notifications();
        first + self.for_each(f)
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
    use missionlink_interfaces::contracts::{FramePayload, Link, WaypointListPayload};

    /// A late subscriber of a history-1 service receives the active list (the contract the
    /// guidance partition relies on), through the QoS of the contracts as the ports here apply
    /// it, on the in-process iceoryx2 service variant.
    #[test]
    fn a_late_subscriber_receives_the_active_waypoint_list() {
        let prefix = format!("ipc-test-{}", std::process::id());
        let ipc = Ipc::<local::Service>::open("ipc-test", &prefix).unwrap();
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

    /// A subscriber that never reads (stopped, hung) does not block the publisher of a frame
    /// queue: past the queue's capacity, frames are lost for it and sending goes on.
    #[test]
    fn a_subscriber_that_never_reads_does_not_block_the_frame_queue() {
        let prefix = format!("ipc-test-full-{}", std::process::id());
        let ipc = Ipc::<local::Service>::open("ipc-test-full", &prefix).unwrap();
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
