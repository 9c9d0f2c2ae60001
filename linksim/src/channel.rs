//! The one fault model of the links, for the simulated pair of the sans-IO tests (in
//! simulated time) and the link emulator of the cross-process tests and benches (in real time):
//! per direction of one link, seeded delay, jitter, loss (independent, or bursty after Gilbert
//! and Elliott), duplication, reordering and byte corruption, and a bandwidth (a rate and the
//! queue in front of it); a link can be cut. [`Channel`] decides, sans-IO, what becomes of each
//! datagram: after how long each copy arrives, and its bytes; the caller gives the time of the
//! send from its own clock (a rate needs it to know what is still queued) and adds the delay to
//! it.
//!
//! The bandwidth is the part of a real link that a window larger than what the link carries in
//! a round trip meets: the frames queue behind each other, each leaves the queue when the one
//! before it has been serialised (its bytes x 8 / rate), the serialisation adds to the one-way
//! delay, and a frame that would take the queue above its limit is dropped. Without a rate
//! ([`Impairments::bandwidth`] `None`), nothing queues: the time of the send changes nothing.

use std::collections::VecDeque;
use std::num::NonZeroU64;
use std::time::Duration;

use crate::Rng;

/// What a link does to the datagrams of one direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impairments {
    /// One-way delay.
    pub delay: Duration,
    /// Added to the delay, uniform in 0..=jitter (a jitter wider than the gap between two
    /// datagrams reorders them).
    pub jitter: Duration,
    /// Probability that a datagram is lost (in the good state of a bursty link).
    pub loss: f64,
    /// Bursty loss: the Gilbert-Elliott chain; `None`: independent loss.
    pub burst: Option<Burst>,
    /// Probability that a datagram arrives twice (the copy with its own delay).
    pub duplicate: f64,
    /// Probability that a datagram is held back by one more delay (reordered past the ones
    /// after it).
    pub reorder: f64,
    /// Probability that one byte of a datagram is changed.
    pub corrupt: f64,
    /// The link is cut: nothing gets through.
    pub cut: bool,
    /// The rate the link serialises at and the queue in front of it; `None`: no limit, a
    /// datagram is on its way the moment it is sent (the model before bandwidth, unchanged).
    pub bandwidth: Option<Bandwidth>,
}

/// The bandwidth of one direction of a link: the rate it serialises frames at, and the limit of
/// the queue where frames wait for the ones before them (drop-tail).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bandwidth {
    bits_per_second: NonZeroU64,
    /// Bytes the queue holds at most: the frames not yet wholly serialised, the one on the wire
    /// included. A frame that would take it above the limit is dropped (and counted,
    /// [`ChannelStats::overflowed`]), so a frame larger than the limit never gets through.
    pub queue_limit: u64,
}

/// Why a [`Bandwidth`] cannot be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BandwidthError {
    /// A rate of 0 bit/s would never serialise a frame; a link that carries nothing is a cut
    /// one ([`Impairments::cut`]).
    ZeroRate,
}

impl std::fmt::Display for BandwidthError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::ZeroRate => {
                f.write_str("a rate of 0 bit/s carries nothing (cut the link instead)")
            }
        }
    }
}

impl std::error::Error for BandwidthError {}

impl Bandwidth {
    /// The queue limit unless one is set: 64 KiB, room for the most this project's protocol
    /// keeps in flight one way (32 data messages, the most an edition-2 receiver accepts, of at
    /// most 564 bytes signed: 18 KB) twice over, resends included. So at the default the queue
    /// delays a transfer's window but does not drop it, on every profile. (The bytes a link
    /// carries in one round trip would not do as the default: on a 2.4 kbit/s link with a
    /// 1.5 s round trip they are 450, less than one frame.) A test that wants drops sets a
    /// smaller limit ([`Bandwidth::with_queue_limit`]).
    pub const DEFAULT_QUEUE_LIMIT: u64 = 64 * 1024;

    /// `bits_per_second`, with the default queue limit ([`Bandwidth::DEFAULT_QUEUE_LIMIT`]).
    pub const fn new(bits_per_second: u64) -> Result<Self, BandwidthError> {
        match NonZeroU64::new(bits_per_second) {
            Some(bits_per_second) => Ok(Self {
                bits_per_second,
                queue_limit: Self::DEFAULT_QUEUE_LIMIT,
            }),
            None => Err(BandwidthError::ZeroRate),
        }
    }

    /// The same rate with a queue of at most `bytes`.
    pub const fn with_queue_limit(mut self, bytes: u64) -> Self {
        self.queue_limit = bytes;
        self
    }

    /// The rate, in bit/s.
    pub const fn bits_per_second(self) -> u64 {
        self.bits_per_second.get()
    }

    /// How long `bytes` take onto the wire: bytes x 8 / rate, rounded up to the nanosecond (a
    /// frame is never on the wire early).
    pub fn serialisation(self, bytes: u64) -> Duration {
        let bits = u128::from(bytes) * 8 * 1_000_000_000;
        let rate = u128::from(self.bits_per_second.get());
        let nanos = bits.div_ceil(rate);
        Duration::from_nanos(u64::try_from(nanos).unwrap_or(u64::MAX))
    }
}

/// Bursty loss after Gilbert and Elliott: a good and a bad state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Burst {
    /// Probability per datagram of going from good to bad.
    pub enter: f64,
    /// Probability per datagram of going from bad to good.
    pub leave: f64,
    /// Loss in the bad state.
    pub loss: f64,
}

impl Impairments {
    /// Nothing happens: loopback.
    pub const NONE: Self = Self {
        delay: Duration::ZERO,
        jitter: Duration::ZERO,
        loss: 0.0,
        burst: None,
        duplicate: 0.0,
        reorder: 0.0,
        corrupt: 0.0,
        cut: false,
        bandwidth: None,
    };

    /// The same, cut.
    pub const fn cut(mut self) -> Self {
        self.cut = true;
        self
    }
}

/// What became of the datagrams of one channel.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ChannelStats {
    /// Datagrams offered.
    pub offered: u64,
    /// Lost (or cut).
    pub lost: u64,
    /// Copies added.
    pub duplicated: u64,
    /// Held back to arrive after later ones.
    pub reordered: u64,
    /// With one byte changed.
    pub corrupted: u64,
    /// Bytes of the datagrams offered (what the sender put on the link, whatever became of it).
    pub bytes: u64,
    /// Dropped because the queue was full (not counted in `lost`, which is what the link lost
    /// on the way).
    pub overflowed: u64,
}

/// One direction of one link: for each datagram, after how long each copy arrives and with
/// which bytes. Deterministic for a seed and the times of the sends.
#[derive(Debug, Clone)]
pub struct Channel {
    /// The impairments from now on (changed to cut a link mid-run, say).
    pub impairments: Impairments,
    rng: Rng,
    bad: bool,
    stats: ChannelStats,
    /// The latest time of a send the channel was given (time never runs back in it).
    clock: Duration,
    /// With a rate: the frames queued or on the wire, oldest first, each as the time its last
    /// bit is on the wire and its bytes.
    queue: VecDeque<(Duration, u64)>,
    /// The bytes in `queue`.
    queued: u64,
}

impl Channel {
    /// A channel with `impairments`, its random draws from `seed`.
    pub fn new(impairments: Impairments, seed: u64) -> Self {
        Self {
            impairments,
            rng: Rng::new(seed),
            bad: false,
            stats: ChannelStats::default(),
            clock: Duration::ZERO,
            queue: VecDeque::new(),
            queued: 0,
        }
    }

    /// What happened so far.
    pub fn stats(&self) -> ChannelStats {
        self.stats
    }

    /// `datagram` sent at the time of the send before (time 0 for the first): each copy that
    /// arrives, with its delay after the send. For a channel without a rate, where the time of
    /// a send changes nothing; with one, [`Channel::transmit_at`] says when.
    pub fn transmit(&mut self, datagram: &[u8]) -> Vec<(Duration, Vec<u8>)> {
        self.transmit_at(self.clock, datagram)
    }

    /// `datagram` sent at `now` (on the caller's clock, from any origin it keeps; a time before
    /// the latest one given counts as that one): each copy that arrives, with its delay after
    /// `now`. With a rate, the delay includes the wait behind the frames still queued and the
    /// datagram's own serialisation; a datagram that would take the queue above its limit is
    /// dropped.
    pub fn transmit_at(&mut self, now: Duration, datagram: &[u8]) -> Vec<(Duration, Vec<u8>)> {
        let i = self.impairments;
        let now = now.max(self.clock);
        self.clock = now;
        let len = datagram.len() as u64;
        self.stats.offered += 1;
        self.stats.bytes += len;
        // The queue comes before the link's own losses: a frame lost on the way (or into a cut
        // link) was still sent, and took its time on the wire.
        let serialised = match i.bandwidth {
            None => Duration::ZERO,
            Some(bandwidth) => match self.enqueue(now, len, bandwidth) {
                Some(wait) => wait,
                None => {
                    self.stats.overflowed += 1;
                    return Vec::new();
                }
            },
        };
        let loss = match i.burst {
            None => i.loss,
            Some(b) => {
                let flip = if self.bad { b.leave } else { b.enter };
                if self.rng.chance(flip) {
                    self.bad = !self.bad;
                }
                if self.bad { b.loss } else { i.loss }
            }
        };
        if i.cut || self.rng.chance(loss) {
            self.stats.lost += 1;
            return Vec::new();
        }
        let copies = if self.rng.chance(i.duplicate) {
            self.stats.duplicated += 1;
            2
        } else {
            1
        };
        (0..copies)
            .map(|_| {
                let jitter = self.rng.range(0, i.jitter.as_micros() as u64);
                // A copy is made on the way, after the wire: both copies share the original's
                // serialisation.
                let mut after = serialised + i.delay + Duration::from_micros(jitter);
                if self.rng.chance(i.reorder) {
                    self.stats.reordered += 1;
                    after += i.delay.max(Duration::from_millis(1));
                }
                let mut bytes = datagram.to_vec();
                if !bytes.is_empty() && self.rng.chance(i.corrupt) {
                    self.stats.corrupted += 1;
                    let k = self.rng.range(0, bytes.len() as u64 - 1) as usize;
                    let flip = self.rng.range(1, 255) as u8;
                    if let Some(b) = bytes.get_mut(k) {
                        *b ^= flip;
                    }
                }
                (after, bytes)
            })
            .collect()
    }

    /// Queues `len` bytes sent at `now` behind the frames still queued: how long after `now`
    /// its last bit is on the wire, or `None` if the queue has no room for it.
    fn enqueue(&mut self, now: Duration, len: u64, bandwidth: Bandwidth) -> Option<Duration> {
        while let Some(&(done, bytes)) = self.queue.front()
            && done <= now
        {
            self.queue.pop_front();
            self.queued = self.queued.saturating_sub(bytes);
        }
        if self.queued + len > bandwidth.queue_limit {
            return None;
        }
        // It starts when the frame before it is wholly on the wire, or now if none is.
        let start = self.queue.back().map_or(now, |&(done, _)| done.max(now));
        let done = start + bandwidth.serialisation(len);
        self.queue.push_back((done, len));
        self.queued += len;
        Some(done - now)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An LTE link: 30 ms one way, 10 ms jitter, 1 % loss.
    const LTE: Impairments = Impairments {
        delay: Duration::from_millis(30),
        jitter: Duration::from_millis(10),
        loss: 0.01,
        ..Impairments::NONE
    };

    /// A bad link: 10 % loss in bursts, 5 % reordered.
    const BAD: Impairments = Impairments {
        burst: Some(Burst {
            enter: 0.05,
            leave: 0.2,
            loss: 0.5,
        }),
        reorder: 0.05,
        ..LTE
    };

    #[test]
    fn a_channel_is_deterministic_for_a_seed_and_keeps_its_rates() {
        let run = |seed| {
            let mut c = Channel::new(BAD, seed);
            let arrivals: Vec<_> = (0..10_000).map(|_| c.transmit(&[1, 2, 3]).len()).collect();
            (arrivals, c.stats())
        };
        assert_eq!(run(7), run(7));
        let (_, stats) = run(7);
        let loss = stats.lost as f64 / stats.offered as f64;
        assert!(
            (0.07..0.13).contains(&loss),
            "bursty loss about 10 %: {loss}"
        );
        let reordered = stats.reordered as f64 / stats.offered as f64;
        assert!((0.03..0.07).contains(&reordered), "{reordered}");
    }

    #[test]
    fn delay_and_jitter_bound_the_arrival_and_a_cut_link_loses_everything() {
        let mut c = Channel::new(LTE, 1);
        for (after, bytes) in (0..1000).flat_map(|_| c.transmit(&[9])) {
            assert!(after >= Duration::from_millis(30));
            assert!(after <= Duration::from_millis(40));
            assert_eq!(bytes, [9]);
        }
        c.impairments = LTE.cut();
        assert!((0..100).all(|_| c.transmit(&[9]).is_empty()));
    }

    /// A geostationary satellite's uplink: 300 ms one way, 64 kbit/s, nothing lost, so that
    /// every arrival is a value computed from the rate.
    fn satcom_up() -> Impairments {
        Impairments {
            delay: Duration::from_millis(300),
            bandwidth: Bandwidth::new(64_000).ok(),
            ..Impairments::NONE
        }
    }

    const MS: fn(u64) -> Duration = Duration::from_millis;

    /// What a send gives: each copy's delay and bytes.
    type Arrivals = Vec<(Duration, Vec<u8>)>;

    #[test]
    fn a_frame_at_a_rate_arrives_after_its_serialisation_and_the_delay() {
        let mut c = Channel::new(satcom_up(), 1);
        // 100 bytes at 64 kbit/s: 800 bits / 64 000 bit/s = 12.5 ms on the wire.
        let got = c.transmit_at(MS(1_000), &[7; 100]);
        assert_eq!(got, vec![(Duration::from_micros(312_500), vec![7; 100])]);
        // The rate's arithmetic, rounded up to the nanosecond: 1 byte at 3 bit/s is 8/3 s.
        let odd = Bandwidth::new(3).unwrap();
        assert_eq!(odd.serialisation(1), Duration::from_nanos(2_666_666_667));
        assert_eq!(Bandwidth::new(0), Err(BandwidthError::ZeroRate));
        assert_eq!(c.stats().bytes, 100);
    }

    #[test]
    fn frames_back_to_back_queue_behind_each_other() {
        let mut c = Channel::new(satcom_up(), 1);
        let at = |c: &mut Channel, now, len| -> Vec<Duration> {
            c.transmit_at(now, &vec![0; len])
                .into_iter()
                .map(|(after, _)| after)
                .collect()
        };
        // Three of 100 bytes at once: each leaves the queue when the one before has been
        // serialised (12.5 ms each).
        assert_eq!(at(&mut c, MS(0), 100), [Duration::from_micros(312_500)]);
        assert_eq!(at(&mut c, MS(0), 100), [Duration::from_micros(325_000)]);
        assert_eq!(at(&mut c, MS(0), 100), [Duration::from_micros(337_500)]);
        // Sent at 30 ms, while the third is on the wire (until 37.5 ms): on the wire from
        // 37.5 to 50 ms, there 300 ms later; 320 ms after its send.
        assert_eq!(at(&mut c, MS(30), 100), [MS(320)]);
        // Sent once the queue is empty: no wait.
        assert_eq!(at(&mut c, MS(1_000), 100), [Duration::from_micros(312_500)]);
        // `transmit` sends at the time of the send before: back to back with it.
        let queued: Vec<_> = c.transmit(&[0; 100]).into_iter().map(|(a, _)| a).collect();
        assert_eq!(queued, [Duration::from_micros(325_000)]);
        // A time before the latest one counts as the latest.
        assert_eq!(at(&mut c, MS(0), 100), [Duration::from_micros(337_500)]);
    }

    #[test]
    fn a_full_queue_drops_and_counts_what_does_not_fit() {
        let limited = Impairments {
            bandwidth: Bandwidth::new(64_000).ok().map(|b| b.with_queue_limit(250)),
            ..satcom_up()
        };
        let mut c = Channel::new(limited, 1);
        // 100 and 200 bytes queued; 100 more would make 300 > 250.
        assert_eq!(c.transmit_at(MS(0), &[0; 100]).len(), 1);
        assert_eq!(c.transmit_at(MS(0), &[0; 100]).len(), 1);
        assert!(c.transmit_at(MS(0), &[0; 100]).is_empty());
        // 50 bytes fit (250): the limit is inclusive.
        assert_eq!(
            c.transmit_at(MS(0), &[0; 50]),
            vec![(Duration::from_micros(331_250), vec![0; 50])]
        );
        // At 12.5 ms the first is wholly on the wire and leaves the queue: 150 bytes queued,
        // 100 more fit, behind the 50: on the wire from 31.25 to 43.75 ms, there 300 ms later,
        // 331.25 ms after its send.
        assert_eq!(
            c.transmit_at(Duration::from_micros(12_500), &[0; 100]),
            vec![(Duration::from_micros(331_250), vec![0; 100])]
        );
        // A frame larger than the limit never fits.
        assert!(c.transmit_at(MS(10_000), &[0; 251]).is_empty());
        let stats = c.stats();
        assert_eq!((stats.offered, stats.overflowed, stats.lost), (6, 2, 0));
        assert_eq!(stats.bytes, 100 + 100 + 100 + 50 + 100 + 251);
    }

    #[test]
    fn without_a_rate_the_time_of_a_send_changes_nothing() {
        // Every impairment but a rate, drawn as the model drew them before it had one: the
        // fingerprint of 10 000 datagrams' arrivals (delays and bytes) was recorded from the
        // model without bandwidth, and `transmit_at` at any times gives the same.
        let every = Impairments {
            duplicate: 0.05,
            corrupt: 0.05,
            ..BAD
        };
        let fingerprint = |send: &mut dyn FnMut(&mut Channel, u64, &[u8]) -> Arrivals| {
            let mut c = Channel::new(every, 7);
            // FNV-1a over every arrival's delay in ns, length and bytes, and a mark per send.
            let mut h: u64 = 0xcbf2_9ce4_8422_2325;
            let mut eat = |v: u64| {
                for b in v.to_le_bytes() {
                    h ^= u64::from(b);
                    h = h.wrapping_mul(0x100_0000_01b3);
                }
            };
            for n in 0..10_000u64 {
                let datagram: Vec<u8> = (0..n % 40).map(|k| (n + k) as u8).collect();
                for (after, bytes) in send(&mut c, n, &datagram) {
                    eat(after.as_nanos() as u64);
                    eat(bytes.len() as u64);
                    bytes.into_iter().for_each(|b| eat(u64::from(b)));
                }
                eat(u64::MAX);
            }
            (h, c.stats().lost, c.stats().duplicated)
        };
        let before_bandwidth = (0xf867_ab8a_ebb7_ac7e, 1066, 479);
        assert_eq!(fingerprint(&mut |c, _, d| c.transmit(d)), before_bandwidth);
        assert_eq!(
            fingerprint(&mut |c, n, d| c.transmit_at(MS(n * 3 % 17), d)),
            before_bandwidth
        );
    }

    #[test]
    fn corruption_changes_one_byte() {
        let mut c = Channel::new(
            Impairments {
                corrupt: 1.0,
                ..Impairments::NONE
            },
            3,
        );
        let sent = [0u8; 32];
        for (_, got) in (0..100).flat_map(|_| c.transmit(&sent)) {
            assert_eq!(got.iter().filter(|b| **b != 0).count(), 1);
        }
    }
}
