//! Round trips as a link sees them: how often a conversation between two ends had to wait for
//! an answer, counted from when each datagram was sent and when each arrived, without reading
//! them. The links bench puts a transfer's time beside its floor, (round trips) x (round trip
//! time) + (bytes) / (rate), and takes the round trips from here: what the transfer did, not
//! what a table says it should.
//!
//! The rule. Of the two ends, one asks (the GCS: it opens every transfer) and one answers (the
//! FCC). Each datagram belongs to a round:
//! - one the asking end sends belongs to the round after the latest round it has received (it
//!   may have waited for any answer that arrived before it; the first is round 1);
//! - one the answering end sends belongs to the latest round it has received (it answers within
//!   that round; what it sends before it heard anything is round 0).
//!
//! The round trips completed are the latest round the asking end has received. Stop and wait over
//! n messages counts n; a window of W over n messages, ceil(n / W); datagrams the answering end
//! sends unasked add none; an asking datagram that nothing answers adds none (the closing
//! acknowledgement of a download).
//!
//! The rule reads times, not contents: a datagram sent after an answer arrived counts as having
//! waited for it, whether or not it did. Where a round trip is shorter than the time a sender
//! takes to send a window (a LAN), the count is high; over the long links it is meant for, a
//! window leaves its sender long before the first answer can return.

/// Which way a datagram goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Way {
    /// From the asking end (the GCS) to the answering one (the FCC).
    Up,
    /// From the answering end to the asking one.
    Down,
}

/// The rounds of one conversation (both ways of every link between the same two ends).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RoundTrips {
    /// The latest round the answering end has received.
    up: u64,
    /// The latest round the asking end has received.
    down: u64,
}

impl RoundTrips {
    /// No datagram yet.
    pub const fn new() -> Self {
        Self { up: 0, down: 0 }
    }

    /// The round of a datagram sent `way` now (kept with it until it arrives).
    pub const fn sent(&self, way: Way) -> u64 {
        match way {
            Way::Up => self.down + 1,
            Way::Down => self.up,
        }
    }

    /// A datagram of `round` that went `way` arrived.
    pub fn arrived(&mut self, way: Way, round: u64) {
        let latest = match way {
            Way::Up => &mut self.up,
            Way::Down => &mut self.down,
        };
        *latest = (*latest).max(round);
    }

    /// The round trips completed so far: a transfer's are the difference between this after it
    /// and before it.
    pub const fn completed(&self) -> u64 {
        self.down
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One message up and its answer down, each arriving before anything else is sent.
    fn exchange(r: &mut RoundTrips) {
        let up = r.sent(Way::Up);
        r.arrived(Way::Up, up);
        let down = r.sent(Way::Down);
        r.arrived(Way::Down, down);
    }

    #[test]
    fn stop_and_wait_counts_one_round_trip_per_message() {
        let mut r = RoundTrips::new();
        for _ in 0..7 {
            exchange(&mut r);
        }
        assert_eq!(r.completed(), 7);
    }

    #[test]
    fn a_window_counts_one_round_trip_per_window() {
        // 10 messages, a window of 4, on a link whose round trip is longer than sending a
        // window: 4 go, the first answer lets the fifth go, and so on (a sliding window).
        let mut r = RoundTrips::new();
        let window = 4;
        let mut in_flight = std::collections::VecDeque::new();
        let mut sent = 0;
        while sent < 10 || !in_flight.is_empty() {
            while sent < 10 && in_flight.len() < window {
                in_flight.push_back(r.sent(Way::Up));
                sent += 1;
            }
            // The oldest arrives and its answer comes back before the next is sent.
            if let Some(round) = in_flight.pop_front() {
                r.arrived(Way::Up, round);
                let answer = r.sent(Way::Down);
                r.arrived(Way::Down, answer);
            }
        }
        // Rounds 1 (messages 1-4), 2 (5-8, sent on the answers of round 1), 3 (9-10).
        assert_eq!(r.completed(), 3);
    }

    #[test]
    fn what_the_answering_end_sends_unasked_and_an_unanswered_message_add_nothing() {
        let mut r = RoundTrips::new();
        let report = r.sent(Way::Down);
        r.arrived(Way::Down, report);
        assert_eq!(r.completed(), 0);
        exchange(&mut r);
        exchange(&mut r);
        for _ in 0..3 {
            let report = r.sent(Way::Down);
            r.arrived(Way::Down, report);
        }
        // The last acknowledgement up, answered by nothing.
        let ack = r.sent(Way::Up);
        r.arrived(Way::Up, ack);
        assert_eq!(r.completed(), 2);
        // A transfer's round trips: the difference across it.
        let before = r.completed();
        exchange(&mut r);
        assert_eq!(r.completed() - before, 1);
    }
}
