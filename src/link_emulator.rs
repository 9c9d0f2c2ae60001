//! A link emulator in user space (this kernel has no netem) for the tests and benchmarks that
//! run the real GCS and the real FCC over UDP: per link (direct, LTE) and per direction, seeded
//! delay, jitter, loss (independent, or bursty after Gilbert and Elliott), duplication,
//! reordering, byte corruption and a bandwidth (a rate, and a queue that drops what does not
//! fit); a link can be cut. It counts what it carried (datagrams and bytes per flow) and the
//! round trips the GCS and the FCC took ([`Emulator::round_trips`]), so that a bench can set a
//! transfer's time beside the link's floor.
//!
//! Two parts, as everywhere in this project: [`Channel`], the testkit's one fault model of the
//! links (the simulated pair of the `services` tests uses it too), decides, sans-IO, what
//! becomes of each datagram of one direction of one link (after how long each copy arrives, and
//! its bytes), given the time of its send from the emulator's clock; [`Emulator`] only moves
//! bytes: it relays UDP between the GCS's ends and the FCC's ends through four sockets of its
//! own and a thread.
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

pub use missionlink_linksim::channel::{
    Bandwidth, BandwidthError, Burst, Channel, ChannelStats, Impairments,
};
use missionlink_linksim::round_trips::{RoundTrips, Way};

/// The named links of the tests and benchmarks (`tests/system/emulated_links.rs`,
/// `tests/system/link_faults.rs`, BENCHMARKS.md section 6), selected by [`Profile::name`] (the
/// links bench's `--profiles`). Where a profile has a rate, its figures are typical published
/// ones for that kind of link, not measurements of this project; the queue in front of each
/// rate is [`Bandwidth::DEFAULT_QUEUE_LIMIT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Profile {
    /// A LAN: 0.1 ms one way, nothing lost, no rate limit.
    Lan,
    /// LTE: 30 ms one way, 10 ms jitter, 1 % loss; 5 Mbit/s up (GCS to FCC), 20 Mbit/s down.
    /// The rates are of the order of the average LTE speeds that mobile network surveys (the
    /// regulators' and the crowd-sourced ones) publish for a cell shared with others, uploads a
    /// fraction of downloads; far below the peak of the standard (150 Mbit/s down and 50 up for
    /// a category 4 device).
    Lte,
    /// A geostationary satellite: 300 ms one way, 0.5 % loss; 64 kbit/s up (GCS to FCC),
    /// 256 kbit/s down. The rates are of the order of the guaranteed-rate (streaming) classes
    /// of an L-band terminal (32 to 256 kbit/s), the command link up narrower than the
    /// downlink that carries telemetry.
    Satcom,
    /// A narrowband satellite link: 750 ms one way (a 1.5 s round trip), 0.5 % loss, 2.4 kbit/s
    /// both ways. 2.4 kbit/s is the rate of circuit-switched data over a low-orbit
    /// constellation (Iridium's), the classic narrowband command link; round trips of a second
    /// and more are what such services show end to end, through their gateways, well above
    /// their propagation.
    SatcomNarrow,
    /// A bad LTE link: 30 ms, 10 ms jitter, 10 % loss in bursts, 5 % reordered, no rate limit.
    Bad,
}

/// A rate in bit/s with the default queue; `None` (no limit) for 0, which no profile has.
const fn rate(bits_per_second: u64) -> Option<Bandwidth> {
    match Bandwidth::new(bits_per_second) {
        Ok(bandwidth) => Some(bandwidth),
        Err(_) => None,
    }
}

impl Profile {
    /// Every profile.
    pub const ALL: [Self; 5] = [
        Self::Lan,
        Self::Lte,
        Self::Satcom,
        Self::SatcomNarrow,
        Self::Bad,
    ];

    /// The name on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Lan => "lan",
            Self::Lte => "lte",
            Self::Satcom => "satcom",
            Self::SatcomNarrow => "satcom-narrow",
            Self::Bad => "bad",
        }
    }

    /// The profile named `name`.
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// Its impairments on every flow, in [`Flow::ALL`] order: the uplink's on both links up,
    /// the downlink's on both links down.
    pub const fn flows(self) -> [Impairments; 4] {
        let (up, down) = (self.up(), self.down());
        [up, up, down, down]
    }

    /// Its round trip without serialisation: both one-way delays and the mean of each jitter.
    pub fn round_trip(self) -> Duration {
        let (up, down) = (self.up(), self.down());
        up.delay + up.jitter / 2 + down.delay + down.jitter / 2
    }

    /// Its impairments from the GCS to the FCC.
    pub const fn up(self) -> Impairments {
        // The same as down but for the rate, where the link is asymmetric.
        match self {
            Self::Lte => Impairments {
                bandwidth: rate(5_000_000),
                ..Self::Lte.down()
            },
            Self::Satcom => Impairments {
                bandwidth: rate(64_000),
                ..Self::Satcom.down()
            },
            other => other.down(),
        }
    }

    /// Its impairments from the FCC to the GCS.
    pub const fn down(self) -> Impairments {
        match self {
            Self::Lan => Impairments {
                delay: Duration::from_micros(100),
                ..Impairments::NONE
            },
            Self::Lte => Impairments {
                delay: Duration::from_millis(30),
                jitter: Duration::from_millis(10),
                loss: 0.01,
                bandwidth: rate(20_000_000),
                ..Impairments::NONE
            },
            Self::Satcom => Impairments {
                delay: Duration::from_millis(300),
                loss: 0.005,
                bandwidth: rate(256_000),
                ..Impairments::NONE
            },
            Self::SatcomNarrow => Impairments {
                delay: Duration::from_millis(750),
                loss: 0.005,
                bandwidth: rate(2_400),
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
            flows: profile.flows(),
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
    /// The round trip it belongs to ([`RoundTrips`]), counted when it arrives.
    round: u64,
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
    /// The rounds of the conversation between the GCS (which asks) and the FCC, over both
    /// links.
    rounds: RoundTrips,
}

/// The way of flow `flow` (an index in [`Flow::ALL`] order): the first two go up.
fn way(flow: usize) -> Way {
    if flow < 2 { Way::Up } else { Way::Down }
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
            rounds: RoundTrips::new(),
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
            c.impairments = impairments;
        }
    }

    /// What happened on each flow, in [`Flow::ALL`] order.
    pub fn stats(&self) -> [ChannelStats; 4] {
        self.shared
            .lock()
            .map(|s| s.channels.each_ref().map(Channel::stats))
            .unwrap_or_default()
    }

    /// The round trips between the GCS and the FCC so far, over both links, counted from the
    /// times of the datagrams the emulator carried (`missionlink_linksim::round_trips`: a
    /// datagram up belongs to the round after the latest answer delivered before it): a
    /// transfer's are the difference across it.
    pub fn round_trips(&self) -> u64 {
        self.shared
            .lock()
            .map(|s| s.rounds.completed())
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

/// The relay's loop: reads every socket, hands each datagram to its flow's channel with the time
/// it was read, sends what is due. Sleeps in poll(2) until a datagram or the next delivery, at
/// most 5 ms (to see `stop`).
fn relay(sockets: [UdpSocket; 4], gcs: [SocketAddr; 2], shared: &Mutex<Shared>, stop: &AtomicBool) {
    // The channels' clock: time since the relay started.
    let epoch = Instant::now();
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
                let round = s.rounds.sent(way(flow));
                let Some(channel) = s.channels.get_mut(flow) else {
                    continue;
                };
                let datagram = buf.get(..len).unwrap_or_default();
                for (after, bytes) in
                    channel.transmit_at(now.saturating_duration_since(epoch), datagram)
                {
                    let at = now + after;
                    order += 1;
                    queue.push(Pending {
                        at,
                        order,
                        flow,
                        round,
                        bytes,
                    });
                }
            }
        }
        let now = Instant::now();
        while queue.peek().is_some_and(|p| p.at <= now) {
            let Some(p) = queue.pop() else { break };
            let fcc = match shared.lock() {
                Ok(mut s) => {
                    s.rounds.arrived(way(p.flow), p.round);
                    s.fcc
                }
                Err(_) => None,
            };
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
