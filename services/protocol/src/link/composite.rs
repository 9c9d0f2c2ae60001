//! The frame of the two state machines made of transfers, mission data handling on the FCC and
//! the GCS logic: one [`Endpoint`] whose received messages the machine routes to its transfers,
//! and one `enum` of timers, one per transfer, that names the transfers' deadlines (the ack
//! timeout of a sender's message in flight, the transfer timeout of a receiver).
//!
//! Each transfer owns its deadline (in the one-slot timer table of its `Exchange` or
//! `Silence`); the machine holds no copy of it. A machine says where each timer's deadline is
//! (`Composite::deadline`), what firing one means (`Composite::fire`) and where a message goes
//! (`Composite::route`); the rest is written once, here: `poll_timeout` as the earliest of the
//! transfers' own deadlines, the firing loop, and the path of a received frame.

use missionlink_interfaces::wire::{FrameError, Message};

use crate::link::endpoint::{Endpoint, Inbound};
use crate::link::time::Instant;
use crate::link::timer::Timer;

/// A state machine of transfers on one endpoint, with the timers `T`.
pub trait Composite<T: Timer<N>, const N: usize> {
    /// The machine's endpoint.
    fn endpoint(&mut self) -> &mut Endpoint;

    /// The current deadline of the transfer behind `timer`, if it runs one: read from the
    /// transfer itself, which owns it.
    fn deadline(&self, timer: T) -> Option<Instant>;

    /// `timer` is due at `now`: its transfer handles the timeout.
    fn fire(&mut self, timer: T, now: Instant);

    /// Hands a message that passed preprocessing to the function that handles it (the moding
    /// of paper §3.1.2); `ack_requested` as its sender asked.
    fn route(&mut self, now: Instant, message: &Message, ack_requested: bool);

    /// The machine's `poll_timeout`: the earliest deadline of its transfers.
    fn earliest_deadline(&self) -> Option<Instant> {
        T::ALL
            .into_iter()
            .filter_map(|timer| self.deadline(timer))
            .min()
    }

    /// Fires the timers due at `now` (a deadline is due at its instant, not after), in
    /// [`Timer::ALL`] order.
    fn fire_expired(&mut self, now: Instant) {
        for timer in T::ALL {
            // Checked one by one against the transfers as they are now: a timer that fires may
            // end other transfers, and with them their deadlines.
            if self.deadline(timer).is_some_and(|at| at <= now) {
                self.fire(timer, now);
            }
        }
    }

    /// One frame (wrapper to checksum) received at `now`: preprocessing by the endpoint, then
    /// [`Composite::route`] for a message that passed it. A frame error is returned for the
    /// driver to count and log; it is never answered (ICD §2).
    fn receive_frame(&mut self, now: Instant, bytes: &[u8]) -> Result<(), FrameError> {
        if let Inbound::Message {
            message,
            ack_requested,
        } = self.endpoint().receive(now, bytes)?
        {
            self.route(now, &message, ack_requested);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_interfaces::wire::MessageType;

    use super::*;
    use crate::testkit;

    crate::timers! {
        enum Part {
            Retry,
            Idle,
        }
    }

    /// Two transfers, where the retry's timeout ends the idle one, and a message that starts
    /// the retry.
    struct Machine {
        endpoint: Endpoint,
        retry: Option<Instant>,
        idle: Option<Instant>,
        fired: Vec<Part>,
        routed: Vec<(MessageType, bool)>,
    }

    impl Composite<Part, 2> for Machine {
        fn endpoint(&mut self) -> &mut Endpoint {
            &mut self.endpoint
        }
        fn deadline(&self, timer: Part) -> Option<Instant> {
            match timer {
                Part::Retry => self.retry,
                Part::Idle => self.idle,
            }
        }
        fn fire(&mut self, timer: Part, _: Instant) {
            self.fired.push(timer);
            if timer == Part::Retry {
                self.retry = None;
                self.idle = None;
            }
        }
        fn route(&mut self, now: Instant, message: &Message, ack_requested: bool) {
            self.routed.push((message.message_type(), ack_requested));
            self.retry = Some(now + core::time::Duration::from_millis(500));
        }
    }

    fn machine() -> Machine {
        Machine {
            endpoint: Endpoint::new(testkit::endpoint(FCC_ID, GCS_ID)),
            retry: None,
            idle: None,
            fired: Vec::new(),
            routed: Vec::new(),
        }
    }

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    #[test]
    fn the_timeout_is_the_earliest_transfer_deadline_and_only_what_is_still_due_fires() {
        let mut m = Machine {
            retry: Some(at(500)),
            idle: Some(at(400)),
            ..machine()
        };
        assert_eq!(m.earliest_deadline(), Some(at(400)));
        m.fire_expired(at(399));
        assert!(m.fired.is_empty(), "nothing at t - 1");
        // Both are due at 500, but the retry, checked first, ends the idle transfer.
        m.fire_expired(at(500));
        assert_eq!(m.fired, [Part::Retry]);
        assert_eq!(m.earliest_deadline(), None, "the retry ended both");
    }

    #[test]
    fn a_received_message_is_routed_and_its_deadlines_count() {
        let mut m = machine();
        let waypoint = testkit::uplink(&testkit::full_waypoint().into());
        m.receive_frame(at(10), &waypoint).unwrap();
        assert_eq!(m.routed, [(MessageType::UaPositionWaypoint, true)]);
        assert_eq!(m.earliest_deadline(), Some(at(510)));
        // A frame that fails preprocessing reaches neither the machine nor its timers.
        let broken = &waypoint[..5];
        assert!(m.receive_frame(at(20), broken).is_err());
        assert_eq!(m.routed.len(), 1);
        assert_eq!(m.earliest_deadline(), Some(at(510)));
    }
}
