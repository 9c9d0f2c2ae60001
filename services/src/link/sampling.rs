//! Message sampling (paper §3.1.1): every message is processed once. A redundant copy (same
//! Source ID, Message Type and Time Stamp, ICD §3), from the other link or repeated, is dropped;
//! so is a stale copy, one older than the newest already processed of its source and type
//! (senders stamp strictly increasing, so only a delayed duplicate or a reordered frame can be
//! older).
//!
//! Memory is bounded: one entry per (source, type), at most [`SAMPLING_KEYS`]. An entry is
//! forgotten after the sampling window without traffic of its key, so a peer that restarts with
//! a clock behind its last stamps is heard again after one window instead of never.

use core::time::Duration;

use heapless::index_map::FnvIndexMap;
use missionlink_interfaces::wire::Timestamp;

use crate::link::time::Instant;

/// (Source ID, Message Type) pairs remembered at once: the 12 message types of the ICD from a
/// few peers.
pub const SAMPLING_KEYS: usize = 64;

/// What sampling decides for one message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sample {
    /// First copy: process it.
    Fresh,
    /// Same time stamp as one already processed: drop it.
    Duplicate,
    /// Older than one already processed: drop it.
    Stale,
}

#[derive(Debug, Clone, Copy)]
struct Seen {
    newest: Timestamp,
    at: Instant,
}

/// The sampling table of one receiver.
#[derive(Debug, Clone)]
pub struct MessageSampler {
    seen: FnvIndexMap<(u32, u16), Seen, SAMPLING_KEYS>,
    window: Duration,
}

impl MessageSampler {
    /// A sampler that forgets a (source, type) after `window` without traffic (the transfer
    /// timeout of ICD §1 is a good window).
    pub fn new(window: Duration) -> Self {
        Self {
            seen: FnvIndexMap::new(),
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
            let expired = now.saturating_since(seen.at) >= self.window;
            if !expired && time_stamp == seen.newest {
                return Sample::Duplicate;
            }
            if !expired && time_stamp < seen.newest {
                return Sample::Stale;
            }
            *seen = Seen {
                newest: time_stamp,
                at: now,
            };
            return Sample::Fresh;
        }
        if self.seen.len() == SAMPLING_KEYS {
            self.forget_oldest();
        }
        // A slot is free now.
        let _ = self.seen.insert(
            key,
            Seen {
                newest: time_stamp,
                at: now,
            },
        );
        Sample::Fresh
    }

    /// Would `sample` call this message fresh? (Decides without remembering.)
    pub fn is_fresh(&self, now: Instant, source: u32, message_type: u16, ts: Timestamp) -> bool {
        match self.seen.get(&(source, message_type)) {
            Some(seen) => now.saturating_since(seen.at) >= self.window || ts > seen.newest,
            None => true,
        }
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

    #[test]
    fn older_copy_is_stale_newer_is_fresh() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        let t = Instant::from_millis(10);
        assert_eq!(s.sample(t, GCS, 13002, ts(200)), Sample::Fresh);
        assert_eq!(s.sample(t, GCS, 13002, ts(150)), Sample::Stale);
        assert_eq!(s.sample(t, GCS, 13002, ts(201)), Sample::Fresh);
        assert!(!s.is_fresh(t, GCS, 13002, ts(201)));
    }

    #[test]
    fn a_restarted_peer_is_heard_after_the_window() {
        let mut s = MessageSampler::new(Duration::from_secs(3));
        assert_eq!(
            s.sample(Instant::from_millis(0), GCS, 13000, ts(9_000)),
            Sample::Fresh
        );
        assert_eq!(
            s.sample(Instant::from_millis(2_999), GCS, 13000, ts(10)),
            Sample::Stale
        );
        // The stale copy did not refresh the entry: 3 s after the last fresh message it expires.
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
