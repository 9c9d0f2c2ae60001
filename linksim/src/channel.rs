//! The one fault model of the links, for the simulated pair of the sans-IO tests (in
//! simulated time) and the link emulator of the cross-process tests and benches (in real time):
//! per direction of one link, seeded delay, jitter, loss (independent, or bursty after Gilbert
//! and Elliott), duplication, reordering and byte corruption; a link can be cut. [`Channel`]
//! decides, sans-IO, what becomes of each datagram: after how long each copy arrives, and its
//! bytes; the caller adds its own clock's time of the send.

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
}

/// One direction of one link: for each datagram, after how long each copy arrives and with
/// which bytes. Deterministic for a seed.
#[derive(Debug, Clone)]
pub struct Channel {
    /// The impairments from now on (changed to cut a link mid-run, say).
    pub impairments: Impairments,
    rng: Rng,
    bad: bool,
    stats: ChannelStats,
}

impl Channel {
    /// A channel with `impairments`, its random draws from `seed`.
    pub fn new(impairments: Impairments, seed: u64) -> Self {
        Self {
            impairments,
            rng: Rng::new(seed),
            bad: false,
            stats: ChannelStats::default(),
        }
    }

    /// What happened so far.
    pub fn stats(&self) -> ChannelStats {
        self.stats
    }

    /// `datagram` sent now: each copy that arrives, with its delay after the send.
    pub fn transmit(&mut self, datagram: &[u8]) -> Vec<(Duration, Vec<u8>)> {
        let i = self.impairments;
        self.stats.offered += 1;
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
                let mut after = i.delay + Duration::from_micros(jitter);
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
