//! A link emulator in user space (this kernel has no netem) for the tests and benchmarks that
//! run the real GCS and the real FCC over UDP: per link (direct, LTE) and per direction, seeded
//! delay, jitter, loss (independent, or bursty after Gilbert and Elliott), duplication,
//! reordering and byte corruption; a link can be cut.
//!
//! Two parts, as everywhere in this project: [`Channel`] decides, sans-IO, what becomes of each
//! datagram of one direction of one link (when each copy arrives, and its bytes); [`Emulator`]
//! only moves bytes: it relays UDP between the GCS's ends and the FCC's ends through four
//! sockets of its own and a thread.
//!
//! ```text
//!  GCS ends ----> [gcs-facing socket] --Channel (up)--> FCC's port       (per link)
//!  GCS ends <---- [gcs-facing socket] <--Channel (down)-- [fcc-facing socket] <---- FCC
//! ```
//!
//! The GCS sends to the emulator's gcs-facing sockets as if they were the FCC's ports; the FCC
//! is configured with the emulator's fcc-facing sockets as the GCS's ports.

use std::collections::BinaryHeap;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use missionlink_services::testkit::Rng;

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

/// The named links of the tests and benchmarks (`tests/emulated_links.rs`, `tests/link_faults.rs`,
/// BENCHMARKS.md section 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Profile {
    /// A LAN: 0.1 ms one way, nothing lost.
    Lan,
    /// LTE: 30 ms one way, 10 ms jitter, 1 % loss.
    Lte,
    /// A geostationary satellite: 300 ms one way, 0.5 % loss.
    Satcom,
    /// A bad LTE link: 30 ms, 10 ms jitter, 10 % loss in bursts, 5 % reordered.
    Bad,
}

impl Profile {
    /// Every profile.
    pub const ALL: [Self; 4] = [Self::Lan, Self::Lte, Self::Satcom, Self::Bad];

    /// The name on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Lan => "lan",
            Self::Lte => "lte",
            Self::Satcom => "satcom",
            Self::Bad => "bad",
        }
    }

    /// The profile named `name`.
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Its impairments, the same both ways.
    pub const fn impairments(self) -> Impairments {
        match self {
            Self::Lan => Impairments {
                delay: Duration::from_micros(100),
                ..Impairments::NONE
            },
            Self::Lte => Impairments {
                delay: Duration::from_millis(30),
                jitter: Duration::from_millis(10),
                loss: 0.01,
                ..Impairments::NONE
            },
            Self::Satcom => Impairments {
                delay: Duration::from_millis(300),
                loss: 0.005,
                ..Impairments::NONE
            },
            // 10 % loss on average: the chain is bad a fifth of the time (enter 0.05, leave
            // 0.2) and loses half there.
            Self::Bad => Impairments {
                delay: Duration::from_millis(30),
                jitter: Duration::from_millis(10),
                loss: 0.0,
                burst: Some(Burst {
                    enter: 0.05,
                    leave: 0.2,
                    loss: 0.5,
                }),
                reorder: 0.05,
                ..Impairments::NONE
            },
        }
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

/// One direction of one link, sans-IO: for each datagram, when each copy arrives and with
/// which bytes. Deterministic for a seed.
#[derive(Debug, Clone)]
pub struct Channel {
    impairments: Impairments,
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

    /// Changes the impairments from now on (to cut a link mid-run, say).
    pub fn set(&mut self, impairments: Impairments) {
        self.impairments = impairments;
    }

    /// What happened so far.
    pub fn stats(&self) -> ChannelStats {
        self.stats
    }

    /// `datagram` sent at `now`: each copy that arrives, with its arrival time.
    pub fn transmit(&mut self, now: Instant, datagram: &[u8]) -> Vec<(Instant, Vec<u8>)> {
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
                let mut at = now + i.delay + Duration::from_micros(jitter);
                if self.rng.chance(i.reorder) {
                    self.stats.reordered += 1;
                    at += i.delay.max(Duration::from_millis(1));
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
                (at, bytes)
            })
            .collect()
    }
}

/// Which way and which link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Flow {
    /// GCS to FCC, direct link.
    UpDirect = 0,
    /// GCS to FCC, LTE link.
    UpLte = 1,
    /// FCC to GCS, direct link.
    DownDirect = 2,
    /// FCC to GCS, LTE link.
    DownLte = 3,
}

impl Flow {
    /// Every flow, in index order.
    pub const ALL: [Self; 4] = [Self::UpDirect, Self::UpLte, Self::DownDirect, Self::DownLte];
}

/// The emulator's configuration: where the GCS receives, and the impairments of each flow.
#[derive(Debug, Clone, Copy)]
pub struct EmulatorConfig {
    /// The GCS's direct and LTE ends.
    pub gcs: [SocketAddr; 2],
    /// Impairments per [`Flow`], in [`Flow::ALL`] order.
    pub flows: [Impairments; 4],
    /// Seed of every random draw (each flow its own stream).
    pub seed: u64,
}

impl EmulatorConfig {
    /// `profile` on every flow.
    pub fn profile(gcs: [SocketAddr; 2], profile: Profile, seed: u64) -> Self {
        Self {
            gcs,
            flows: [profile.impairments(); 4],
            seed,
        }
    }
}

/// A datagram on its way.
#[derive(Debug, PartialEq, Eq)]
struct Pending {
    at: Instant,
    order: u64,
    flow: usize,
    bytes: Vec<u8>,
}

impl Ord for Pending {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        // The earliest first: BinaryHeap pops the greatest.
        (other.at, other.order).cmp(&(self.at, self.order))
    }
}

impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

struct Shared {
    channels: [Channel; 4],
    /// Where the FCC receives (direct, LTE), once known.
    fcc: Option<[SocketAddr; 2]>,
}

/// The relay, running on a thread of its own until dropped.
pub struct Emulator {
    gcs_facing: [SocketAddr; 2],
    fcc_facing: [SocketAddr; 2],
    shared: Arc<Mutex<Shared>>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl std::fmt::Debug for Emulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Emulator")
            .field("gcs_facing", &self.gcs_facing)
            .field("fcc_facing", &self.fcc_facing)
            .finish_non_exhaustive()
    }
}

fn bind() -> std::io::Result<UdpSocket> {
    let socket = UdpSocket::bind(SocketAddr::from(([127, 0, 0, 1], 0)))?;
    socket.set_nonblocking(true)?;
    Ok(socket)
}

impl Emulator {
    /// Binds the emulator's four sockets on loopback and starts relaying.
    pub fn start(config: EmulatorConfig) -> std::io::Result<Self> {
        // [gcs-facing direct, gcs-facing LTE, fcc-facing direct, fcc-facing LTE]
        let sockets = [bind()?, bind()?, bind()?, bind()?];
        let addr = |i: usize| sockets.get(i).map_or(Ok(config.gcs[0]), |s| s.local_addr());
        let gcs_facing = [addr(0)?, addr(1)?];
        let fcc_facing = [addr(2)?, addr(3)?];
        let channels = [0u64, 1, 2, 3].map(|i| {
            let impairments = config
                .flows
                .get(i as usize)
                .copied()
                .unwrap_or(Impairments::NONE);
            Channel::new(impairments, config.seed ^ (i.wrapping_mul(0x9E37_79B9)))
        });
        let shared = Arc::new(Mutex::new(Shared {
            channels,
            fcc: None,
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let (shared, stop, gcs) = (shared.clone(), stop.clone(), config.gcs);
            std::thread::Builder::new()
                .name("link-emulator".to_owned())
                .spawn(move || relay(sockets, gcs, &shared, &stop))?
        };
        Ok(Self {
            gcs_facing,
            fcc_facing,
            shared,
            stop,
            thread: Some(thread),
        })
    }

    /// Where the GCS sends (in place of the FCC's direct and LTE ports).
    pub fn gcs_facing(&self) -> [SocketAddr; 2] {
        self.gcs_facing
    }

    /// Where the FCC sends (in place of the GCS's direct and LTE ports).
    pub fn fcc_facing(&self) -> [SocketAddr; 2] {
        self.fcc_facing
    }

    /// Where the FCC receives: uplink datagrams go there from now on (dropped before).
    pub fn set_fcc(&self, fcc: [SocketAddr; 2]) {
        if let Ok(mut s) = self.shared.lock() {
            s.fcc = Some(fcc);
        }
    }

    /// Changes the impairments of `flow` from now on (cut a link, say).
    pub fn set(&self, flow: Flow, impairments: Impairments) {
        if let Ok(mut s) = self.shared.lock()
            && let Some(c) = s.channels.get_mut(flow as usize)
        {
            c.set(impairments);
        }
    }

    /// What happened on each flow, in [`Flow::ALL`] order.
    pub fn stats(&self) -> [ChannelStats; 4] {
        self.shared
            .lock()
            .map(|s| s.channels.each_ref().map(Channel::stats))
            .unwrap_or_default()
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The relay's loop: reads every socket, hands each datagram to its flow's channel, sends what
/// is due. Sleeps in poll(2) until a datagram or the next delivery, at most 5 ms (to see
/// `stop`).
fn relay(sockets: [UdpSocket; 4], gcs: [SocketAddr; 2], shared: &Mutex<Shared>, stop: &AtomicBool) {
    let mut queue: BinaryHeap<Pending> = BinaryHeap::new();
    let mut order = 0u64;
    let mut buf = vec![0u8; 65_536];
    while !stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        let wait = queue
            .peek()
            .map_or(Duration::from_millis(5), |p| {
                p.at.saturating_duration_since(now)
            })
            .min(Duration::from_millis(5));
        {
            let mut fds = sockets
                .each_ref()
                .map(|s| rustix::event::PollFd::new(s, rustix::event::PollFlags::IN));
            let timeout = rustix::time::Timespec {
                tv_sec: wait.as_secs() as _,
                tv_nsec: wait.subsec_nanos() as _,
            };
            let _ = rustix::event::poll(&mut fds, Some(&timeout));
        }
        // Socket i's datagrams go through flow i: gcs-facing sockets carry the uplink, the
        // fcc-facing ones the downlink.
        for (flow, socket) in sockets.iter().enumerate() {
            while let Ok((len, _from)) = socket.recv_from(&mut buf) {
                let now = Instant::now();
                let Ok(mut s) = shared.lock() else { return };
                let Some(channel) = s.channels.get_mut(flow) else {
                    continue;
                };
                for (at, bytes) in channel.transmit(now, buf.get(..len).unwrap_or_default()) {
                    order += 1;
                    queue.push(Pending {
                        at,
                        order,
                        flow,
                        bytes,
                    });
                }
            }
        }
        let now = Instant::now();
        while queue.peek().is_some_and(|p| p.at <= now) {
            let Some(p) = queue.pop() else { break };
            let fcc = shared.lock().ok().and_then(|s| s.fcc);
            // Up: from the fcc-facing socket of the link to the FCC; down: from the gcs-facing
            // socket to the GCS, so each side sees the other's stand-in as the sender.
            let (from, to) = match p.flow {
                0 => (sockets.get(2), fcc.map(|f| f[0])),
                1 => (sockets.get(3), fcc.map(|f| f[1])),
                2 => (sockets.first(), Some(gcs[0])),
                _ => (sockets.get(1), Some(gcs[1])),
            };
            if let (Some(socket), Some(to)) = (from, to) {
                let _ = socket.send_to(&p.bytes, to);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_channel_is_deterministic_for_a_seed_and_keeps_its_rates() {
        let run = |seed| {
            let mut c = Channel::new(Profile::Bad.impairments(), seed);
            let t0 = Instant::now();
            let arrivals: Vec<_> = (0..10_000)
                .map(|i| c.transmit(t0 + Duration::from_millis(i), &[1, 2, 3]).len())
                .collect();
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
        let mut c = Channel::new(Profile::Lte.impairments(), 1);
        let t0 = Instant::now();
        for (at, bytes) in (0..1000).flat_map(|_| c.transmit(t0, &[9])) {
            assert!(at >= t0 + Duration::from_millis(30));
            assert!(at <= t0 + Duration::from_millis(40));
            assert_eq!(bytes, [9]);
        }
        c.set(Profile::Lte.impairments().cut());
        assert!((0..100).all(|_| c.transmit(t0, &[9]).is_empty()));
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
        for (_, got) in (0..100).flat_map(|_| c.transmit(Instant::now(), &sent)) {
            assert_eq!(got.iter().filter(|b| **b != 0).count(), 1);
        }
    }
}
