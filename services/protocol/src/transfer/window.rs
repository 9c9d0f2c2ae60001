//! The window of a transfer's sender, sized to the link (ICD §10.4): how many data messages
//! ([`super::sender::Script::data_messages`]) it keeps unanswered at once. Sans-IO: the sender
//! passes in the instants of its sends, answers and timeouts.
//!
//! The rule, in the order the sender applies it before each data message it would send:
//!
//! 1. **Never above the window agreed** (`max`: at most [`MAX_WINDOW`], what this project's
//!    receivers accept in flight, ICD §10.2).
//! 2. **Shrinks on loss, grows back** (the congestion window, `cwnd`, from `max`): the ack
//!    timeout of a data message halves it (never below 1), once per loss: a timeout of a message
//!    sent before the last halving does not halve it again, since the messages of one window
//!    lost together are one loss. Each data message accepted adds `1 / cwnd` (one more message
//!    after a window's worth of acceptances), up to `max`. A refusal is an answer, not a loss.
//! 3. **Never more than the link carries in a round trip**, when its rate is known: the frames
//!    in flight hold at most `rate x round trip / 8` bytes, the round trip being the shortest
//!    the sender measured (the time from sending a message to its acceptance, first attempts
//!    only, so that an answer is never matched to the wrong attempt). The shortest, not the
//!    mean: the measured times include the queue a window builds at the rate, and a window
//!    sized from them would grow that queue. One data message may always be in flight. Before
//!    the first measurement, with a rate, one data message is in flight at a time.
//!
//! Without a rate, rule 3 does not limit; with a fixed window ([`Window::fixed`], the FCC's
//! downloads: the window the GCS asked for) only rule 1 does.

use core::num::NonZeroU64;
use core::time::Duration;

use crate::link::time::Instant;

/// Data messages in flight at most: what this project's receivers accept (ICD §10.2; the
/// shared contract's receivers accept 32, ICD §13). Over a link whose round trip carries more
/// (satellite at 64 kbit/s: about 75 waypoints; LTE: a whole mission), a window of 32 left the
/// link idle most of each round trip. Download requests ask for at most 32, the most their
/// wire field holds ([`TransferWindow::MAX`](missionlink_interfaces::wire::TransferWindow::MAX)).
pub const MAX_WINDOW: usize = 128;

/// The window of one sender, carried from one transfer to the next by its owner (the GCS keeps
/// one for the link).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// The window agreed: 1 to [`MAX_WINDOW`].
    max: usize,
    /// Whether rules 2 and 3 apply (else the window is `max`).
    adaptive: bool,
    /// The congestion window: 1 to `max`.
    cwnd: usize,
    /// Acceptances since `cwnd` last grew.
    acked: usize,
    /// When `cwnd` was last halved: a loss of a message sent before then is the same loss.
    halved_at: Option<Instant>,
    /// The shortest round trip measured.
    min_rtt: Option<Duration>,
    /// The smoothed round trip (RFC 6298's 1/8 gain), for the operator's log.
    srtt: Option<Duration>,
    /// The link's rate toward the receiver, bit/s, when known.
    rate: Option<NonZeroU64>,
}

impl Window {
    /// Always `window` data messages in flight (0 counts as 1, above [`MAX_WINDOW`] as
    /// [`MAX_WINDOW`]): the FCC's downloads, which use the window the request carries.
    pub const fn fixed(window: usize) -> Self {
        let max = clamp(window);
        Self {
            max,
            adaptive: false,
            cwnd: max,
            acked: 0,
            halved_at: None,
            min_rtt: None,
            srtt: None,
            rate: None,
        }
    }

    /// A window sized to the link (the module's rule) of at most `max` data messages, starting
    /// at `max`; `rate_bps` is the link's rate toward the receiver, if known.
    pub const fn adaptive(max: usize, rate_bps: Option<u64>) -> Self {
        let mut window = Self::fixed(max);
        window.adaptive = true;
        window.rate = match rate_bps {
            Some(bps) => NonZeroU64::new(bps),
            None => None,
        };
        window
    }

    /// The window agreed for the next transfer (rule 1). What rule 2 found stays: a transfer
    /// without data messages (a request, agreed at 1) says nothing of the link.
    pub fn set_max(&mut self, max: usize) {
        self.max = clamp(max);
        if !self.adaptive {
            self.cwnd = self.max;
        }
    }

    /// The link's rate toward the receiver in bit/s, `None` when not known (rule 3).
    pub fn set_rate(&mut self, rate_bps: Option<u64>) {
        self.rate = rate_bps.and_then(NonZeroU64::new);
    }

    /// Forgets what was measured of the link (the round trips), keeping the settings: the peer
    /// was silent long enough that the path may have changed.
    pub fn forget_path(&mut self) {
        self.min_rtt = None;
        self.srtt = None;
        self.cwnd = self.max;
        self.acked = 0;
        self.halved_at = None;
    }

    /// The window agreed.
    pub const fn max(&self) -> usize {
        self.max
    }

    /// Data messages that may be unanswered now (rules 1 and 2).
    pub fn messages(&self) -> usize {
        if self.adaptive {
            self.cwnd.min(self.max)
        } else {
            self.max
        }
    }

    /// The bytes the link carries in the shortest round trip measured (rule 3); `None` when it
    /// does not limit: no rate, or a fixed window. `Some(0)` before the first measurement.
    pub fn bytes(&self) -> Option<u64> {
        let rate = self.rate.filter(|_| self.adaptive)?;
        let rtt = self.min_rtt.unwrap_or(Duration::ZERO);
        let bits = u128::from(rate.get()) * rtt.as_nanos() / 1_000_000_000;
        Some(u64::try_from(bits / 8).unwrap_or(u64::MAX))
    }

    /// Whether one more data message of `bytes` may go when `in_flight` data messages holding
    /// `bytes_in_flight` bytes are unanswered.
    pub fn admits(&self, in_flight: usize, bytes_in_flight: u64, bytes: u64) -> bool {
        if in_flight >= self.messages() {
            return false;
        }
        match self.bytes() {
            Some(budget) => in_flight == 0 || bytes_in_flight.saturating_add(bytes) <= budget,
            None => true,
        }
    }

    /// A message sent at `sent_at` was accepted at `now` on its first attempt: one round trip
    /// measured. Every message counts, openers and closers too: each is a round trip of the link.
    pub fn measured(&mut self, sent_at: Instant, now: Instant) {
        let rtt = now.saturating_since(sent_at);
        self.min_rtt = Some(self.min_rtt.map_or(rtt, |m| m.min(rtt)));
        self.srtt = Some(match self.srtt {
            Some(s) => (s * 7 + rtt) / 8,
            None => rtt,
        });
    }

    /// A data message was accepted (rule 2: grow back).
    pub fn accepted(&mut self) {
        if !self.adaptive {
            return;
        }
        self.acked += 1;
        if self.acked >= self.cwnd {
            self.acked = 0;
            self.cwnd = (self.cwnd + 1).min(self.max.max(self.cwnd));
        }
    }

    /// The ack timeout of a data message sent at `sent_at` passed at `now` (rule 2: shrink,
    /// once per loss).
    pub fn lost(&mut self, sent_at: Instant, now: Instant) {
        if !self.adaptive || self.halved_at.is_some_and(|at| sent_at < at) {
            return;
        }
        self.cwnd = (self.messages() / 2).max(1);
        self.acked = 0;
        self.halved_at = Some(now);
    }

    /// The shortest round trip measured.
    pub const fn min_rtt(&self) -> Option<Duration> {
        self.min_rtt
    }

    /// The smoothed round trip.
    pub const fn srtt(&self) -> Option<Duration> {
        self.srtt
    }

    /// Takes what `other`, a window of the same link, measured: the shorter round trip.
    pub fn absorb(&mut self, other: &Self) {
        if let Some(rtt) = other.min_rtt {
            self.min_rtt = Some(self.min_rtt.map_or(rtt, |m| m.min(rtt)));
        }
        if self.srtt.is_none() {
            self.srtt = other.srtt;
        }
    }
}

const fn clamp(window: usize) -> usize {
    if window == 0 {
        1
    } else if window > MAX_WINDOW {
        MAX_WINDOW
    } else {
        window
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    #[test]
    fn a_fixed_window_is_the_window_agreed_whatever_happens() {
        let mut w = Window::fixed(8);
        w.lost(at(0), at(500));
        w.measured(at(0), at(600));
        assert_eq!(w.messages(), 8);
        assert_eq!(w.bytes(), None);
        assert!(w.admits(7, 1_000_000, 1_000));
        assert!(!w.admits(8, 0, 1));
        assert_eq!(Window::fixed(0).messages(), 1);
        assert_eq!(Window::fixed(40).messages(), 40);
        assert_eq!(Window::fixed(MAX_WINDOW + 1).messages(), MAX_WINDOW);
    }

    #[test]
    fn loss_halves_once_per_loss_and_acceptances_grow_it_back() {
        let mut w = Window::adaptive(32, None);
        assert_eq!(w.messages(), 32);
        // A whole window sent at 0 ms times out at 500 ms: one loss, one halving.
        for _ in 0..32 {
            w.lost(at(0), at(500));
        }
        assert_eq!(w.messages(), 16);
        // A message sent after the halving and lost too: another loss.
        w.lost(at(501), at(1001));
        assert_eq!(w.messages(), 8);
        // 8 acceptances: 9; 9 more: 10.
        for _ in 0..8 {
            w.accepted();
        }
        assert_eq!(w.messages(), 9);
        for _ in 0..8 {
            w.accepted();
        }
        assert_eq!(w.messages(), 9);
        w.accepted();
        assert_eq!(w.messages(), 10);
        // Never above the window agreed, never below 1.
        for _ in 0..10_000 {
            w.accepted();
        }
        assert_eq!(w.messages(), 32);
        for ms in 0..20 {
            w.lost(at(2000 + ms * 1000), at(2500 + ms * 1000));
        }
        assert_eq!(w.messages(), 1);
        // A smaller window agreed for the next transfer caps it; a request's window of 1 does
        // not shrink it for the transfer after.
        let mut w = Window::adaptive(32, None);
        w.set_max(4);
        assert_eq!(w.messages(), 4);
        w.set_max(1);
        w.set_max(32);
        assert_eq!(w.messages(), 32);
    }

    #[test]
    fn the_bytes_in_flight_are_what_the_link_carries_in_the_shortest_round_trip() {
        // 64 kbit/s, round trips of 600 ms and then 900 ms (a queue): 4800 bytes.
        let mut w = Window::adaptive(32, Some(64_000));
        assert_eq!(w.bytes(), Some(0), "before a round trip was measured");
        assert!(w.admits(0, 0, 80), "one message always");
        assert!(!w.admits(1, 80, 80));
        w.measured(at(0), at(600));
        w.measured(at(1000), at(1900));
        assert_eq!(w.min_rtt(), Some(Duration::from_millis(600)));
        assert_eq!(w.srtt(), Some(Duration::from_micros(637_500)));
        assert_eq!(w.bytes(), Some(4800));
        // 60 frames of 80 bytes would fit; the window of 32 messages limits first.
        assert!(w.admits(31, 31 * 80, 80));
        assert!(!w.admits(32, 32 * 80, 80));
        // 2.4 kbit/s, 1.5 s: 450 bytes, five frames of 80 bytes.
        let mut narrow = Window::adaptive(32, Some(2_400));
        narrow.measured(at(0), at(1500));
        assert_eq!(narrow.bytes(), Some(450));
        assert!(narrow.admits(4, 320, 80));
        assert!(!narrow.admits(5, 400, 80));
        // Without a rate, bytes do not limit.
        let mut unknown = Window::adaptive(32, None);
        unknown.measured(at(0), at(600));
        assert_eq!(unknown.bytes(), None);
        assert!(unknown.admits(31, u64::MAX - 1, 80));
        // What another window of the link measured is taken: the shorter round trip.
        let mut other = Window::adaptive(32, Some(64_000));
        other.measured(at(0), at(500));
        w.absorb(&other);
        assert_eq!(w.bytes(), Some(4000));
        w.forget_path();
        assert_eq!(w.bytes(), Some(0));
    }
}
