//! Message sampling (paper §3.1.1): every message is processed once. A redundant copy (same
//! Source ID, Message Type and Time Stamp, ICD §3), from the other link or repeated, is dropped.
//!
//! The sampler keeps the identities it processed, not only the newest stamp (ICD §10.2): with a
//! window of data messages in flight, a message may arrive after a newer one of its type, and it
//! is still new. Per (source, type) the last [`RECENT_STAMPS`] stamps processed are remembered;
//! a stamp at or below the newest one forgotten to make room is *stale* (the sampler can no
//! longer tell it from a delayed duplicate), anything else not remembered is fresh. Edition 1
//! (one message in flight) sees the same decisions as before for every copy but a reordered
//! one, which it now processes instead of dropping.
//!
//! Memory is bounded: at most [`SAMPLING_KEYS`] (source, type) keys. A key is forgotten after
//! the sampling window without traffic, so a peer that restarts with a clock behind its last
//! stamps is heard again after one window instead of never.

use core::time::Duration;

use heapless::Deque;
use heapless::index_map::FnvIndexMap;
use missionlink_interfaces::wire::Timestamp;

use crate::link::time::Instant;

/// (Source ID, Message Type) pairs remembered at once: the 12 message types of the ICD from a
/// few peers.
pub const SAMPLING_KEYS: usize = 64;

/// Stamps remembered per (source, type): twice the largest window of ICD §10 (32 data messages
/// in flight, each on two links, and their retries).
pub const RECENT_STAMPS: usize = 64;

/// What sampling decides for one message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sample {
    /// First copy: process it.
    Fresh,
    /// Same time stamp as one already processed: drop it.
    Duplicate,
    /// At or below a stamp the sampler forgot to make room: it cannot be told from a delayed
    /// duplicate, so it is dropped.
    Stale,
}

#[derive(Debug, Clone)]
struct Seen {
    /// The stamps processed, oldest first.
    recent: Deque<Timestamp, RECENT_STAMPS>,
    /// The newest stamp forgotten to make room.
    forgotten: Option<Timestamp>,
    /// When the key last had a fresh message.
    at: Instant,
}

impl Seen {
    fn new(at: Instant) -> Self {
        Self {
            recent: Deque::new(),
            forgotten: None,
            at,
        }
    }

    fn decide(&self, time_stamp: Timestamp) -> Sample {
        if self.recent.iter().any(|t| *t == time_stamp) {
            Sample::Duplicate
        } else if self.forgotten.is_some_and(|f| time_stamp <= f) {
            Sample::Stale
        } else {
            Sample::Fresh
        }
    }

    fn remember(&mut self, time_stamp: Timestamp, now: Instant) {
        if self.recent.is_full() {
            if let Some(oldest) = self.recent.pop_front() {
                self.forgotten = Some(self.forgotten.map_or(oldest, |f| f.max(oldest)));
            }
        }
        // Room was made above.
        let _ = self.recent.push_back(time_stamp);
        self.at = now;
    }
}

/// The sampling table of one receiver.
#[derive(Debug, Clone)]
pub struct MessageSampler {
    /// Boxed (37 KB), allocated once with the sampler: it lives in every endpoint and voter,
    /// and those move by value.
    seen: Box<FnvIndexMap<(u32, u16), Seen, SAMPLING_KEYS>>,
    window: Duration,
}

impl MessageSampler {
    /// A sampler that forgets a (source, type) after `window` without traffic (the transfer
    /// timeout of ICD §1 is a good window).
    pub fn new(window: Duration) -> Self {
        Self {
            seen: Box::new(FnvIndexMap::new()),
            window,
        }
    }

    /// Decides on the message `(source, message_type, time_stamp)` received at `now`, and
    /// remembers it when fresh.
    pub fn sample(
        &mut self,
        now: Instant,
        source: u32,
        message_type: u16,
        time_stamp: Timestamp,
    ) -> Sample {
        let key = (source, message_type);
        if let Some(seen) = self.seen.get_mut(&key) {
            if now.saturating_since(seen.at) >= self.window {
                *seen = Seen::new(now);
            }
            let decision = seen.decide(time_stamp);
            if decision == Sample::Fresh {
                seen.remember(time_stamp, now);
            }
            return decision;
        }
        if self.seen.len() == SAMPLING_KEYS {
            self.forget_oldest();
        }
        let mut seen = Seen::new(now);
        seen.remember(time_stamp, now);
        // A slot is free now.
        let _ = self.seen.insert(key, seen);
        Sample::Fresh
    }

    fn forget_oldest(&mut self) {
        let oldest = self.seen.iter().min_by_key(|(_, s)| s.at).map(|(k, _)| *k);
        if let Some(k) = oldest {
            self.seen.remove(&k);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ts(ms: u64) -> Timestamp {
        Timestamp::from_millis(ms).unwrap()
    }

    const GCS: u32 = 0x0A00_0001;

    #[test]
    fn redundant_copy_is_processed_once() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        let t = Instant::from_millis(10);
        assert_eq!(s.sample(t, GCS, 13002, ts(100)), Sample::Fresh);
        assert_eq!(s.sample(t, GCS, 13002, ts(100)), Sample::Duplicate);
        // Same time stamp, other type or other source: another message.
        assert_eq!(s.sample(t, GCS, 13006, ts(100)), Sample::Fresh);
        assert_eq!(s.sample(t, 7, 13002, ts(100)), Sample::Fresh);
    }

    /// ICD §10.2: a message that arrives after a newer one of its type is still new.
    #[test]
    fn an_older_stamp_not_processed_is_fresh_once() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        let t = Instant::from_millis(10);
        // 32 in flight, arriving in reverse, each twice (both links).
        for stamp in (100..132).rev() {
            assert_eq!(s.sample(t, GCS, 13002, ts(stamp)), Sample::Fresh);
            assert_eq!(s.sample(t, GCS, 13002, ts(stamp)), Sample::Duplicate);
        }
        assert_eq!(s.sample(t, GCS, 13002, ts(132)), Sample::Fresh);
    }

    #[test]
    fn a_stamp_at_or_below_one_forgotten_is_stale() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        let t = Instant::from_millis(10);
        for stamp in 0..RECENT_STAMPS as u64 + 10 {
            assert_eq!(s.sample(t, GCS, 13002, ts(1000 + stamp)), Sample::Fresh);
        }
        // 1000..=1009 were forgotten: they and anything below are stale, the rest duplicates.
        assert_eq!(s.sample(t, GCS, 13002, ts(1009)), Sample::Stale);
        assert_eq!(s.sample(t, GCS, 13002, ts(500)), Sample::Stale);
        assert_eq!(s.sample(t, GCS, 13002, ts(1010)), Sample::Duplicate);
    }

    /// Time stamps are identities (ICD §3): a GCS started right after another one stamps below the
    /// first one's last (bumped) stamps; its first #13000 is new, not stale.
    #[test]
    fn a_new_sender_behind_the_last_ones_stamps_is_heard_at_once() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        assert_eq!(
            s.sample(Instant::from_millis(0), GCS, 13000, ts(9_000)),
            Sample::Fresh
        );
        assert_eq!(
            s.sample(Instant::from_millis(5), GCS, 13000, ts(8_500)),
            Sample::Fresh
        );
    }

    #[test]
    fn a_key_is_forgotten_after_the_window_without_traffic() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        assert_eq!(
            s.sample(Instant::from_millis(0), GCS, 13000, ts(10)),
            Sample::Fresh
        );
        assert_eq!(
            s.sample(Instant::from_millis(2_999), GCS, 13000, ts(10)),
            Sample::Duplicate
        );
        // 3 s after the last fresh message the key expires (a duplicate does not refresh it).
        assert_eq!(
            s.sample(Instant::from_millis(3_000), GCS, 13000, ts(10)),
            Sample::Fresh
        );
    }

    #[test]
    fn memory_is_bounded() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        for source in 0..(SAMPLING_KEYS as u32 * 4) {
            let now = Instant::from_millis(u64::from(source));
            assert_eq!(s.sample(now, source, 13002, ts(1)), Sample::Fresh);
        }
        assert_eq!(s.seen.len(), SAMPLING_KEYS);
        // The newest keys are kept.
        let last = SAMPLING_KEYS as u32 * 4 - 1;
        let now = Instant::from_millis(u64::from(last));
        assert_eq!(s.sample(now, last, 13002, ts(1)), Sample::Duplicate);
    }
}
