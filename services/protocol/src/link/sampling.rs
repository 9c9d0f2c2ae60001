//! Message sampling (paper §3.1.1): every message is processed once. A redundant copy (same
//! Source ID, Message Type and Time Stamp, ICD §3), from the other link or repeated, is dropped.
//!
//! The sampler keeps the identities it processed, not only the newest stamp (ICD §10.2): with a
//! window of data messages in flight, a message may arrive after a newer one of its type, and it
//! is still new. Per (source, type) it keeps one bit per millisecond of stamp (ICD §3: stamps
//! are milliseconds, one more for each message a sender originates) for the [`HORIZON_MS`]
//! below the newest stamp processed: a stamp within it is a duplicate if its bit is set and
//! fresh if not; a stamp further below is *stale* (the sampler can no longer tell it from a
//! delayed duplicate) and dropped; a newer one is fresh. A window of 128 stamps a burst over
//! 128 ms at least, and a link that delays one copy by seconds behind the other is rare, so the
//! horizon holds both, where a memory of the last 64 stamps would take a message that LTE's
//! jitter let 64 newer ones overtake for a stale one. Edition 1 (one message in flight) sees the same
//! decisions as before for every copy but a reordered one, which it now processes instead of
//! dropping.
//!
//! Memory is bounded: at most [`SAMPLING_KEYS`] (source, type) keys of 512 bytes of bits each.
//! A key is forgotten after the sampling window without traffic, so a peer that restarts with a
//! clock behind its last stamps is heard again after one window instead of never.

use core::time::Duration;

use heapless::index_map::FnvIndexMap;
use missionlink_interfaces::wire::Timestamp;

use crate::link::time::Instant;

/// (Source ID, Message Type) pairs remembered at once: the 12 message types of the ICD from a
/// few peers.
pub const SAMPLING_KEYS: usize = 64;

/// How far below the newest stamp processed of a (source, type) the sampler still tells a
/// duplicate from a new message, in milliseconds of stamp (ICD §3).
pub const HORIZON_MS: u64 = 4096;

const WORDS: usize = (HORIZON_MS / 64) as usize;

/// What sampling decides for one message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sample {
    /// First copy: process it.
    Fresh,
    /// Same time stamp as one already processed: drop it.
    Duplicate,
    /// More than [`HORIZON_MS`] below the newest stamp processed: it cannot be told from a
    /// delayed duplicate, so it is dropped.
    Stale,
}

#[derive(Debug, Clone)]
struct Seen {
    /// The newest stamp processed, in milliseconds.
    newest: u64,
    /// Bit `stamp % HORIZON_MS` is set when `stamp`, within the horizon below `newest`, was
    /// processed.
    bits: [u64; WORDS],
    /// When the key last had a fresh message.
    at: Instant,
}

impl Seen {
    fn new(time_stamp: Timestamp, at: Instant) -> Self {
        let mut seen = Self {
            newest: time_stamp.millis(),
            bits: [0; WORDS],
            at,
        };
        seen.set(time_stamp.millis());
        seen
    }

    const fn slot(stamp: u64) -> (usize, u64) {
        let bit = stamp % HORIZON_MS;
        ((bit / 64) as usize, 1 << (bit % 64))
    }

    fn is_set(&self, stamp: u64) -> bool {
        let (word, mask) = Self::slot(stamp);
        self.bits.get(word).is_some_and(|w| w & mask != 0)
    }

    fn set(&mut self, stamp: u64) {
        let (word, mask) = Self::slot(stamp);
        if let Some(w) = self.bits.get_mut(word) {
            *w |= mask;
        }
    }

    fn clear(&mut self, stamp: u64) {
        let (word, mask) = Self::slot(stamp);
        if let Some(w) = self.bits.get_mut(word) {
            *w &= !mask;
        }
    }

    fn decide(&self, time_stamp: Timestamp) -> Sample {
        let stamp = time_stamp.millis();
        if stamp > self.newest {
            Sample::Fresh
        } else if self.newest - stamp >= HORIZON_MS {
            Sample::Stale
        } else if self.is_set(stamp) {
            Sample::Duplicate
        } else {
            Sample::Fresh
        }
    }

    /// Remembers a fresh `time_stamp`: a newer one moves the horizon up, forgetting the slots
    /// it leaves.
    fn remember(&mut self, time_stamp: Timestamp, now: Instant) {
        let stamp = time_stamp.millis();
        if stamp > self.newest {
            if stamp - self.newest >= HORIZON_MS {
                self.bits = [0; WORDS];
            } else {
                // A word at a time where the range covers it: a position at 2 Hz moves the
                // horizon 500 stamps a message.
                let mut passed = self.newest + 1;
                while passed <= stamp {
                    if passed % 64 == 0 && stamp - passed >= 63 {
                        if let Some(w) = self.bits.get_mut(Self::slot(passed).0) {
                            *w = 0;
                        }
                        passed += 64;
                    } else {
                        self.clear(passed);
                        passed += 1;
                    }
                }
            }
            self.newest = stamp;
        }
        self.set(stamp);
        self.at = now;
    }
}

/// The sampling table of one receiver.
#[derive(Debug, Clone)]
pub struct MessageSampler {
    /// Boxed (35 KB), allocated once with the sampler: it lives in every endpoint and voter,
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
                *seen = Seen::new(time_stamp, now);
                return Sample::Fresh;
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
        // A slot is free now.
        let _ = self.seen.insert(key, Seen::new(time_stamp, now));
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
        // A window of 128 in flight, arriving in reverse, each twice (both links).
        for stamp in (100..228).rev() {
            assert_eq!(s.sample(t, GCS, 13002, ts(stamp)), Sample::Fresh);
            assert_eq!(s.sample(t, GCS, 13002, ts(stamp)), Sample::Duplicate);
        }
        assert_eq!(s.sample(t, GCS, 13002, ts(228)), Sample::Fresh);
    }

    /// A message overtaken by hundreds of newer ones of its type (LTE's jitter over a window
    /// of 128 on two links) is still new within the horizon.
    #[test]
    fn a_message_overtaken_by_many_is_fresh_within_the_horizon() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        let t = Instant::from_millis(10);
        for stamp in 1001..1500 {
            assert_eq!(s.sample(t, GCS, 13002, ts(stamp)), Sample::Fresh);
        }
        assert_eq!(s.sample(t, GCS, 13002, ts(1000)), Sample::Fresh);
        assert_eq!(s.sample(t, GCS, 13002, ts(1000)), Sample::Duplicate);
    }

    #[test]
    fn a_stamp_below_the_horizon_is_stale() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        let t = Instant::from_millis(10);
        let newest = 10_000 + HORIZON_MS;
        for stamp in [10_000, 10_001, newest] {
            assert_eq!(s.sample(t, GCS, 13002, ts(stamp)), Sample::Fresh);
        }
        // 10 000 fell below the horizon: it and anything below are stale; 10 001 is the
        // oldest stamp still told apart.
        assert_eq!(s.sample(t, GCS, 13002, ts(10_000)), Sample::Stale);
        assert_eq!(s.sample(t, GCS, 13002, ts(500)), Sample::Stale);
        assert_eq!(s.sample(t, GCS, 13002, ts(10_001)), Sample::Duplicate);
        assert_eq!(s.sample(t, GCS, 13002, ts(10_002)), Sample::Fresh);
        // Moving the horizon up forgets the slots it leaves: the slot of 10 000 + 2 x horizon
        // is the one of 10 000 and of `newest`, and is new.
        let further = 10_000 + 2 * HORIZON_MS;
        assert_eq!(s.sample(t, GCS, 13002, ts(further)), Sample::Fresh);
        assert_eq!(s.sample(t, GCS, 13002, ts(further)), Sample::Duplicate);
        assert_eq!(s.sample(t, GCS, 13002, ts(newest)), Sample::Stale);
        assert_eq!(s.sample(t, GCS, 13002, ts(further - 1)), Sample::Fresh);
    }

    /// The bits decide as a set of every stamp processed would, within the horizon: stamps
    /// moving up by up to 700 ms a message (a position at 2 Hz moves 500) and back by up to
    /// 300, so that the horizon moves a bit, a word and many words at a time.
    #[test]
    fn the_bits_decide_as_the_set_of_stamps_processed() {
        let mut s = MessageSampler::new(Duration::from_secs(3600));
        let t = Instant::from_millis(10);
        let mut processed = std::collections::HashSet::new();
        let mut newest = 0u64;
        let mut stamp = 100_000u64;
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..20_000 {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            stamp = (stamp + rng % 1000).saturating_sub(300);
            let expected = if stamp > newest {
                Sample::Fresh
            } else if newest - stamp >= HORIZON_MS {
                Sample::Stale
            } else if processed.contains(&stamp) {
                Sample::Duplicate
            } else {
                Sample::Fresh
            };
            assert_eq!(
                s.sample(t, GCS, 13002, ts(stamp)),
                expected,
                "stamp {stamp}"
            );
            if expected == Sample::Fresh {
                processed.insert(stamp);
                newest = newest.max(stamp);
            }
        }
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
