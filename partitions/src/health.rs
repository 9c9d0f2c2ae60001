//! The partitions' side of health (docs/design.md "Health"): the [`Heartbeat`] every partition's
//! event loop sends on its fixed period (`runtime::run_loop`), and the [`Watch`] of heartbeats
//! the launcher and system automation read. The rule that decides "silent" is
//! `missionlink_flight::health::Liveness`; this module only moves the beats.

use std::time::Duration;

use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{FccService, HeartbeatPayload, Partition};

use crate::ipc::{Ipc, IpcError, Publisher, Subscriber};
use missionlink_platform::clock::monotonic_ns;

/// A partition's heartbeat on `fcc/health/<role>`: one sample per period, sent from the event
/// loop (never a thread of its own, which would go on beating for a loop that is stuck).
#[derive(Debug)]
pub struct Heartbeat<S: Service> {
    publisher: Publisher<S, HeartbeatPayload>,
    period: Duration,
    next: std::time::Instant,
    sequence: u64,
}

impl<S: Service> Heartbeat<S> {
    /// The heartbeat of `role`, beating on `period` (the first beat is due at once).
    pub fn open(ipc: &Ipc<S>, role: Partition, period: Duration) -> Result<Self, IpcError> {
        Ok(Self {
            publisher: ipc.publisher(FccService::Heartbeat(role))?,
            period: period.max(Duration::from_millis(1)),
            next: std::time::Instant::now(),
            sequence: 0,
        })
    }

    /// Beats if one is due; how long until the next one is.
    pub fn beat_if_due(&mut self) -> Result<Duration, IpcError> {
        let now = std::time::Instant::now();
        if now >= self.next {
            self.sequence += 1;
            self.publisher.send(&HeartbeatPayload {
                sequence: self.sequence,
                time_ns: monotonic_ns(),
                period_ns: u64::try_from(self.period.as_nanos()).unwrap_or(u64::MAX),
                pid: std::process::id(),
                reserved: [0; 4],
            })?;
            // On the period's grid, unless the loop was late by a whole period (then from now,
            // rather than a burst of beats to catch up).
            self.next += self.period;
            if self.next <= now {
                self.next = now + self.period;
            }
            self.publisher.update_connections();
        }
        Ok(self.next.saturating_duration_since(now))
    }
}

/// The heartbeats of the partitions, as a watcher (the launcher, system automation) receives
/// them.
#[derive(Debug)]
pub struct Watch<S: Service> {
    subscribers: Vec<(Partition, Subscriber<S, HeartbeatPayload>)>,
}

impl<S: Service> Watch<S> {
    /// Subscribes to the heartbeats of `roles`.
    pub fn open(ipc: &Ipc<S>, roles: &[Partition]) -> Result<Self, IpcError> {
        let subscribers = roles
            .iter()
            .map(|&role| Ok((role, ipc.subscriber(FccService::Heartbeat(role))?)))
            .collect::<Result<_, IpcError>>()?;
        Ok(Self { subscribers })
    }

    /// The subscriber of `role`'s heartbeats (its listener wakes a WaitSet), if watched.
    pub fn subscriber(&self, role: Partition) -> Option<&Subscriber<S, HeartbeatPayload>> {
        self.subscribers
            .iter()
            .find(|(r, _)| *r == role)
            .map(|(_, s)| s)
    }

    /// Hands every beat that arrived to `f` with its role, draining the notifications.
    pub fn receive(&self, mut f: impl FnMut(Partition, &HeartbeatPayload)) {
        for (role, subscriber) in &self.subscribers {
            subscriber.drain_notifications();
            subscriber.for_each(|beat| f(*role, beat));
        }
    }
}
