//! The frame of the two state machines made of transfers, mission data handling on the FCC and
//! the GCS logic: one [`Endpoint`] whose received messages the machine routes to its transfers,
//! and one [`TimerTable`] whose timers mirror the transfers' deadlines (the ack timeout of a
//! sender's message in flight, the transfer timeout of a receiver).
//!
//! A machine says which deadline each of its timers mirrors (`Composite::deadline`), what
//! firing one means (`Composite::fire`) and where a message goes (`Composite::route`); the
//! rest is written once, here: keeping the table in step with the transfers after every call
//! that may have started, advanced or ended one, the firing loop, and the path of a received
//! frame.

use missionlink_interfaces::wire::{FrameError, Message};

use crate::link::endpoint::{Endpoint, Inbound};
use crate::link::time::Instant;
use crate::link::timer::{Timer, TimerTable};

/// A state machine of transfers on one endpoint, with the timers `T`.
pub(crate) trait Composite<T: Timer<N>, const N: usize> {
    /// The machine's timer table.
    fn timers(&mut self) -> &mut TimerTable<T, N>;

    /// The machine's endpoint.
    fn endpoint(&mut self) -> &mut Endpoint;

    /// The current deadline of the transfer behind `timer`, if it runs one.
    fn deadline(&self, timer: T) -> Option<Instant>;

    /// `timer` is due at `now`: its transfer handles the timeout.
    fn fire(&mut self, timer: T, now: Instant);

    /// Hands a message that passed preprocessing to the function that handles it (the moding
    /// of paper §3.1.2); `ack_requested` as its sender asked.
    fn route(&mut self, now: Instant, message: &Message, ack_requested: bool);

    /// The machine's `poll_timeout`: the earliest deadline of its `table`. The table mirrors the
    /// transfers, so every call that can start, advance or end a transfer must end in
    /// [`Composite::update_timers`]; debug builds check here that none forgot.
    fn mirrored_timeout(&self, table: &TimerTable<T, N>) -> Option<Instant> {
        debug_assert!(
            T::ALL
                .into_iter()
                .all(|timer| table.get(timer) == self.deadline(timer)),
            "the timer table lags its transfers"
        );
        table.next_timeout()
    }

    /// Copies every transfer's deadline into the table.
    fn update_timers(&mut self) {
        for timer in T::ALL {
            let at = self.deadline(timer);
            self.timers().set_or_stop(timer, at);
        }
    }

    /// Fires the timers due at `now`, in [`Timer::ALL`] order, then updates the table.
    fn fire_expired(&mut self, now: Instant) {
        for timer in T::ALL {
            // Checked one by one against the transfers as they are now: a timer that fires may
            // end other transfers, and with them their timers.
            self.update_timers();
            if self.timers().is_expired(timer, now) {
                self.fire(timer, now);
            }
        }
        self.update_timers();
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
            self.update_timers();
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

    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Part {
        Retry = 0,
        Idle = 1,
    }

    impl Timer<2> for Part {
        const ALL: [Self; 2] = [Self::Retry, Self::Idle];
        fn index(self) -> usize {
            self as usize
        }
    }

    /// Two transfers, where the retry's timeout ends the idle one, and a message that starts
    /// the retry.
    struct Machine {
        endpoint: Endpoint,
        timers: TimerTable<Part, 2>,
        retry: Option<Instant>,
        idle: Option<Instant>,
        fired: Vec<Part>,
        routed: Vec<(MessageType, bool)>,
    }

    impl Composite<Part, 2> for Machine {
        fn timers(&mut self) -> &mut TimerTable<Part, 2> {
            &mut self.timers
        }
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
            timers: TimerTable::new(),
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
    fn the_table_mirrors_the_transfers_and_fires_only_what_is_still_due() {
        let mut m = Machine {
            retry: Some(at(500)),
            idle: Some(at(400)),
            ..machine()
        };
        m.update_timers();
        assert_eq!(m.timers.next_timeout(), Some(at(400)));
        m.fire_expired(at(399));
        assert!(m.fired.is_empty(), "nothing at t - 1");
        // Both are due at 500, but the retry, checked first, ends the idle transfer.
        m.fire_expired(at(500));
        assert_eq!(m.fired, [Part::Retry]);
        assert_eq!(
            m.timers.next_timeout(),
            None,
            "the table follows the transfers"
        );
    }

    #[test]
    fn a_received_message_is_routed_and_its_timers_are_set() {
        let mut m = machine();
        let waypoint = testkit::uplink(&testkit::full_waypoint().into());
        m.receive_frame(at(10), &waypoint).unwrap();
        assert_eq!(m.routed, [(MessageType::UaPositionWaypoint, true)]);
        assert_eq!(m.timers.next_timeout(), Some(at(510)));
        // A frame that fails preprocessing reaches neither the machine nor its timers.
        let broken = &waypoint[..5];
        assert!(m.receive_frame(at(20), broken).is_err());
        assert_eq!(m.routed.len(), 1);
        assert_eq!(m.timers.next_timeout(), Some(at(510)));
    }
}
