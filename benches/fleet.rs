//! One ground service for a fleet (BENCHMARKS.md section 8, docs/fleet.md): `gcs serve` with its
//! MAVLink side on N vehicles, each with its own links, every vehicle sending its position at
//! 2 Hz (ICD §5.8), the bench the MAVLink client that hears every GLOBAL_POSITION_INT.
//!
//! The vehicles are real FCCs (the `fcc` launcher and its partitions, each its own process
//! group of processes, prefix, ports and state) or FCCs simulated in this process: a thread per
//! vehicle with the FCC's own voting (paper §2.4), signing (ICD §9) and mission data handling
//! (`MissionDataHandling`, the sans-IO machine of the partition) over two UDP sockets, guidance
//! replaced by a position that moves 1 m every 100 ms near the demo's take-off position. A simulated FCC has no shared memory
//! between partitions, so 250 of them (MAVLink's limit of system IDs) fit this 2-core machine
//! beside the service; what the service does per vehicle is the same.
//!
//! Reported per fleet:
//! - **upload**: wall time of `gcs upload --vehicle vNNN` (one vehicle, the last, the others
//!   idle) and of `gcs upload --vehicle v001,...,vNNN` (all at once, through the service), demo
//!   missions 1 and 2 in turn so that both lists change every time; medians of `--runs` and
//!   their ratio; beside each, the machine's busy CPU time meanwhile (every process: the
//!   client, the service, the FCCs), which tells an upload bound by the cores from one that
//!   waits for its links;
//! - **the floor of all/one**: 30 uploads to one vehicle in a row tell one upload's wall time
//!   and its work (the machine's busy CPU time per upload, less what the idle fleet keeps busy
//!   meanwhile); the uploads to all tell the work per vehicle of an upload to all. Spread over
//!   the cores the idle fleet leaves, that work cannot take less than `N x workN / ((cores -
//!   idle) x one)` times one upload: where one upload keeps a core busy all its time (loopback),
//!   no concurrency brings 16 vehicles on 2 cores near one;
//! - **others beside a bad link** (`--first-behind PROFILE`: the first vehicle behind an
//!   emulated link of that profile, the others as `--profile` says): the upload to all but the
//!   first alone, and while an upload to the first runs over its link, another client at once;
//! - **CPU**: the service's CPU time over `--idle-s` seconds of positions and heartbeats, no
//!   request running, as a share of one core (`/proc/<pid>/stat` utime + stime);
//! - **memory**: the service's resident set (`VmRSS`) after the uploads and the idle window, per
//!   vehicle, and the increment per vehicle over the fleet of one of the same kind measured in
//!   the same run;
//! - **position latency** (simulated fleets): from the simulated FCC's send of a #101 (the frame
//!   on the link, just before its `sendto`) to the GLOBAL_POSITION_INT the service makes of it
//!   on the bench's MAVLink socket, matched by system ID and latitude; p50, p99, p99.9 and max
//!   over the idle window. A real FCC's send time is not seen from here;
//! - **positions**: GLOBAL_POSITION_INT per second per vehicle over the idle window, least and
//!   most (2 Hz each when every vehicle is heard).
//!
//! ```sh
//! cargo bench --bench fleet                                     # real 1,4,16; simulated 1,16,250
//! cargo bench --bench fleet -- --real 1,4 --simulated 1,250 --runs 3 --idle-s 20
//! cargo bench --bench fleet -- --soak-s 3600 --real 16          # the hour: no growth
//! cargo bench --bench fleet -- --real 16 --simulated "" --first-behind bad
//! ```
//!
//! `--sharing-cores` configures the real FCCs as several FCCs on one simulation PC are
//! configured: voting-monitoring sleeps on its sockets at once instead of spinning after every
//! frame (`[ipc.idle.voting-monitoring] mode = "block"`, docs/fleet.md).
//!
//! `--soak-s S` runs one fleet (the largest of `--real`, or with `--real ""` of `--simulated`)
//! for S seconds instead: positions
//! at 2 Hz, an upload to every vehicle every 10 s (`--upload-every-s` another period: a shorter
//! one makes a leak per request show sooner), and every minute the service's resident set, the
//! resident part of its allocator's heap (`[heap]` in `/proc/<pid>/smaps`: the one arena, see
//! `one_allocator_arena` in the `gcs` binary), open file descriptors, threads and CPU share since
//! the minute before (`--sample-s` another period); then the growth from the first minute to the last, the means of the first and the
//! last sixth of the samples, the slope of each half, and every upload's outcome.
// A benchmark stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::collections::HashMap;
use std::net::{SocketAddr, UdpSocket};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use mavlink::dialects::common::MavMessage;
use missionlink::harness::binaries;
use missionlink::harness::service::{FleetEntry, GroundService, fleet_text};
use missionlink::harness::{Process, Rig, eventually};
use missionlink::link_emulator::{Emulator, EmulatorConfig, Profile};
use missionlink_flight::mission_data_handling::MissionDataHandling;
use missionlink_gcs::mavlink::vehicle::read_datagram;
use missionlink_interfaces::contracts::{GuidanceProgressPayload, Link, Partition};
use missionlink_interfaces::wire::{self, MAX_FRAME_LEN, Message};
use missionlink_partitions::config::{Config, Idle};
use missionlink_platform::clock::DriverClock;
use missionlink_platform::keys::LinkSigning;
use missionlink_platform::udp::{LinkPair, MAX_DATAGRAM};

/// How many uploads to one vehicle in a row tell the work of one upload: their busy CPU time in
/// ticks of 10 ms adds up to a time worth comparing with the upload's few milliseconds.
const ONE_SERIES: usize = 30;
/// How often an upload goes to every vehicle in the soak, unless `--upload-every-s` says.
const SOAK_UPLOAD_EVERY: Duration = Duration::from_secs(10);
/// How far a simulated vehicle moves between its guidance updates: 1e-5 degrees of latitude
/// (about 1 m), so that every #101 carries a latitude of its own.
const STEP_DEG: f64 = 1e-5;
/// How often a simulated vehicle's guidance updates its position.
const GUIDANCE_PERIOD: Duration = Duration::from_millis(100);

fn arg<'a>(args: &'a [String], name: &str) -> Option<&'a str> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(String::as_str)
}

fn list(args: &[String], name: &str, default: &[usize]) -> Vec<usize> {
    arg(args, name).map_or_else(
        || default.to_vec(),
        |v| {
            v.split(',')
                .filter(|s| !s.is_empty())
                .map(|n| n.parse().expect("a list of numbers: 1,4,16"))
                .collect()
        },
    )
}

fn mission(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("missions")
        .join(name)
        .display()
        .to_string()
}

fn vehicle_name(i: usize) -> String {
    format!("v{:03}", i + 1)
}

// ---- The service, as /proc shows it ----

/// CPU time of process `pid` so far (user + system, all threads).
fn cpu_time(pid: u32) -> Duration {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // The fields after the command's closing parenthesis: utime and stime are the 12th and
    // 13th of them (fields 14 and 15 of proc(5)).
    let rest = &stat[stat.rfind(')').unwrap() + 2..];
    let fields: Vec<&str> = rest.split(' ').collect();
    let ticks: u64 = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    // In USER_HZ, which Linux fixes at 100 for what it shows user space.
    Duration::from_secs_f64(ticks as f64 / 100.0)
}

/// Page faults of process `pid` so far that read nothing from disk (every thread, ended ones
/// included): a count, not a time, so the fresh memory an upload touches is measured alike on a
/// busy and on a quiet machine.
fn minor_faults(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // minflt is field 10 of proc(5): the 8th after the command's closing parenthesis.
    let rest = &stat[stat.rfind(')').unwrap() + 2..];
    rest.split(' ').nth(7).unwrap().parse().unwrap()
}

/// A `kB` field of `/proc/<pid>/status` (VmRSS, VmHWM), in bytes.
fn status_kb(pid: u32, field: &str) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    status
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .unwrap()
}

/// The machine's busy CPU time so far, all cores (`harness::machine_ticks`).
fn machine_busy() -> Duration {
    Duration::from_secs_f64(missionlink::harness::machine_ticks().0 as f64 / 100.0)
}

/// The resident part of the process's `[heap]` mapping, KiB: the C library's main arena, where
/// every thread of the service allocates (one arena).
fn heap_kb(pid: u32) -> u64 {
    let smaps = std::fs::read_to_string(format!("/proc/{pid}/smaps")).unwrap_or_default();
    let mut in_heap = false;
    for line in smaps.lines() {
        if line.ends_with("[heap]") {
            in_heap = true;
        } else if in_heap && let Some(rss) = line.strip_prefix("Rss:") {
            return rss
                .trim()
                .trim_end_matches("kB")
                .trim()
                .parse()
                .unwrap_or(0);
        }
    }
    0
}

fn open_fds(pid: u32) -> usize {
    std::fs::read_dir(format!("/proc/{pid}/fd"))
        .unwrap()
        .count()
}

fn threads(pid: u32) -> usize {
    std::fs::read_dir(format!("/proc/{pid}/task"))
        .unwrap()
        .count()
}

// ---- The MAVLink client ----

/// When each simulated FCC sent each #101, by (system ID, latitude in 1e-7 degrees).
type SentPositions = Arc<Mutex<HashMap<(u8, i32), Instant>>>;

/// The bench's MAVLink socket: counts GLOBAL_POSITION_INT per system and, for the positions a
/// simulated FCC recorded, the latency from its send.
struct MavlinkClient {
    addr: SocketAddr,
    sent: SentPositions,
    stop: Arc<AtomicBool>,
    heard: Arc<Mutex<Heard>>,
    thread: Option<JoinHandle<()>>,
}

#[derive(Default)]
struct Heard {
    /// GLOBAL_POSITION_INT per system ID.
    positions: HashMap<u8, u64>,
    /// Latencies measured, nanoseconds.
    latencies_ns: Vec<u64>,
    /// Whether latencies are recorded now.
    recording: bool,
}

impl MavlinkClient {
    fn start(sent: SentPositions) -> Self {
        let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
        socket
            .set_read_timeout(Some(Duration::from_millis(100)))
            .unwrap();
        let addr = socket.local_addr().unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let heard = Arc::new(Mutex::new(Heard::default()));
        let thread = {
            let (stop, heard, sent) = (stop.clone(), heard.clone(), sent.clone());
            std::thread::spawn(move || {
                let mut buf = [0u8; 2048];
                while !stop.load(Ordering::Relaxed) {
                    let Ok(len) = socket.recv(&mut buf) else {
                        continue;
                    };
                    let at = Instant::now();
                    for (header, message) in read_datagram(&buf[..len]) {
                        let MavMessage::GLOBAL_POSITION_INT(p) = message else {
                            continue;
                        };
                        let Ok(system) = u8::try_from(header.system_id) else {
                            continue;
                        };
                        let mut heard = heard.lock().unwrap();
                        *heard.positions.entry(system).or_default() += 1;
                        if !heard.recording {
                            continue;
                        }
                        let sent_at = {
                            let mut sent = sent.lock().unwrap();
                            [p.lat, p.lat - 1, p.lat + 1]
                                .iter()
                                .find_map(|lat| sent.remove(&(system, *lat)))
                        };
                        if let Some(sent_at) = sent_at {
                            heard
                                .latencies_ns
                                .push(at.duration_since(sent_at).as_nanos() as u64);
                        }
                    }
                }
            })
        };
        Self {
            addr,
            sent,
            stop,
            heard,
            thread: Some(thread),
        }
    }

    /// Waits until every system of 1..=n was heard, or panics after `limit`.
    fn wait_for_all(&self, n: usize, limit: Duration) {
        let all = eventually(limit, || {
            let heard = self.heard.lock().unwrap();
            (1..=n as u8)
                .all(|s| heard.positions.contains_key(&s))
                .then_some(())
        });
        if all.is_none() {
            let heard = self.heard.lock().unwrap();
            panic!(
                "not every vehicle heard on the MAVLink side within {limit:?}: {} of {n}",
                heard.positions.len()
            );
        }
    }

    /// Starts a window: counts from zero, latencies recorded.
    fn begin(&self) {
        self.sent.lock().unwrap().clear();
        let mut heard = self.heard.lock().unwrap();
        heard.positions.clear();
        heard.latencies_ns.clear();
        heard.recording = true;
    }

    /// Ends the window: positions per system, latencies.
    fn end(&self) -> (HashMap<u8, u64>, Vec<u64>) {
        let mut heard = self.heard.lock().unwrap();
        heard.recording = false;
        (
            std::mem::take(&mut heard.positions),
            std::mem::take(&mut heard.latencies_ns),
        )
    }
}

impl Drop for MavlinkClient {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

// ---- Simulated FCCs ----

/// FCCs simulated in this process, a thread each.
struct SimulatedFleet {
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
    _emulators: Vec<Emulator>,
}

impl SimulatedFleet {
    /// `n` vehicles, their fleet entries (key file `key`), sending their positions' send times
    /// to `sent`; each behind a link emulator of its profile in `links`, if one.
    fn start(n: usize, dir: &Path, sent: &SentPositions, links: Links) -> (Self, Vec<FleetEntry>) {
        let key = dir.join("link.key");
        missionlink_platform::keys::generate_key_file(&key, 1).unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let mut entries = Vec::new();
        let mut threads = Vec::new();
        let mut emulators = Vec::new();
        let mut ground_ends = Vec::new();
        for i in 0..n {
            let mut config = Config::default();
            config.ids.fcc = 0x0B00_0001 + i as u32;
            config.signing.key_files = vec![key.clone()];
            // The service's ends, bound here and released for it to bind (as a rig's): held
            // until every vehicle has its own, so that no two are given the same port.
            let ends = missionlink_platform::udp::LocalEnds::bind_loopback().unwrap();
            let ground = ends.addrs().unwrap();
            ground_ends.push(ends);
            let direct = UdpSocket::bind("127.0.0.1:0").unwrap();
            let lte = UdpSocket::bind("127.0.0.1:0").unwrap();
            let own = [direct.local_addr().unwrap(), lte.local_addr().unwrap()];
            // Behind an emulator, each end talks to the emulator's side that faces it.
            let (fcc, peer) = match links.of(i) {
                Some(profile) => {
                    let emulator =
                        Emulator::start(EmulatorConfig::profile(ground, profile, i as u64))
                            .unwrap();
                    emulator.set_fcc(own);
                    let ends = (emulator.gcs_facing(), emulator.fcc_facing());
                    emulators.push(emulator);
                    ends
                }
                None => (own, ground),
            };
            entries.push(FleetEntry {
                name: vehicle_name(i),
                vehicle_id: config.ids.fcc,
                ground,
                fcc,
                key_file: key.clone(),
            });
            let links = LinkPair::from_sockets(direct, lte, peer[0], peer[1]).unwrap();
            let (stop, sent) = (stop.clone(), sent.clone());
            let system = (i + 1) as u8;
            threads.push(
                std::thread::Builder::new()
                    .name(format!("fcc-{}", i + 1))
                    .spawn(move || simulated_fcc(&config, links, system, &stop, &sent))
                    .unwrap(),
            );
        }
        (
            Self {
                stop,
                threads,
                _emulators: emulators,
            },
            entries,
        )
    }
}

impl Drop for SimulatedFleet {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// One simulated FCC: voting-monitoring and mission data handling of one partition each in
/// the real FCC, here one loop; the position moves north [`STEP_DEG`] every
/// [`GUIDANCE_PERIOD`], back and forth.
fn simulated_fcc(
    config: &Config,
    links: LinkPair,
    system: u8,
    stop: &AtomicBool,
    sent: &SentPositions,
) {
    let signing = LinkSigning::load(&config.signing).unwrap();
    let links = links.with_signer(signing.signer.clone());
    let clock = DriverClock::start();
    let mut voter = missionlink_partitions::voting_monitoring::fcc_voter(config, &signing, &clock);
    let mut core = Box::new(MissionDataHandling::new(
        config.fcc_core(clock.utc_at_zero()),
    ));
    // At the demo's take-off position (TROL), inside the demo missions' fly-zone, so that the
    // onboard geofence check passes what the bench uploads; it moves back and forth within
    // 200 steps (about 220 m), each #101 with a latitude of its own within 20 s.
    let mut progress = GuidanceProgressPayload::IDLE;
    progress.longitude_deg = 11.66;
    progress.altitude_m = 30.0;
    progress.ground_speed_mps = 10.0;
    let mut next_guidance = clock.now();
    let mut frame = [0u8; MAX_FRAME_LEN];
    let mut buf = [0u8; MAX_DATAGRAM];
    let mut received: Vec<(Link, Vec<u8>)> = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        let now = clock.now();
        if now >= next_guidance {
            progress.sequence += 1;
            progress.time_ns = missionlink_platform::clock::monotonic_ns();
            progress.latitude_deg = 48.26 + STEP_DEG * (progress.sequence % 200) as f64;
            core.handle_progress(now, &progress);
            next_guidance = now + GUIDANCE_PERIOD;
        }
        if core.poll_timeout().is_some_and(|t| t <= now) {
            core.handle_timeout(now);
        }
        while let Some(Ok(len)) = core.poll_transmit(&mut frame) {
            let bytes = &frame[..len];
            if let Ok((_, Message::InertialStates(p))) = wire::decode(bytes)
                && let Some(lat) = p.latitude
            {
                let lat = (lat.degrees() * 1e7).round() as i32;
                sent.lock().unwrap().insert((system, lat), Instant::now());
            }
            links.send_both(bytes);
        }
        while core.poll_event().is_some() {}
        let wake = core
            .poll_timeout()
            .map_or(next_guidance, |t| t.min(next_guidance));
        let wait = wake
            .saturating_since(clock.now())
            .min(Duration::from_millis(100));
        let [direct, lte] = links.sockets();
        let mut fds = [
            rustix::event::PollFd::new(direct, rustix::event::PollFlags::IN),
            rustix::event::PollFd::new(lte, rustix::event::PollFlags::IN),
        ];
        let timeout = rustix::event::Timespec::try_from(wait).unwrap();
        let _ = rustix::event::poll(&mut fds, Some(&timeout));
        received.clear();
        links.receive(&mut buf, |link, datagram, _| {
            received.push((link, datagram.to_vec()));
        });
        if !received.is_empty() {
            let now = clock.now();
            let arrivals: Vec<(Link, &[u8])> =
                received.iter().map(|(l, d)| (*l, d.as_slice())).collect();
            voter.vote_step(now, &arrivals, |_, _, bytes| {
                let _ = core.handle_frame(now, bytes);
            });
        }
    }
}

// ---- Real FCCs ----

/// How the real FCCs are configured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fccs {
    /// As each on a computer of its own: the defaults (voting-monitoring spins 200 µs after
    /// every frame, `[ipc.idle]`, which takes nothing another process of that computer needs).
    OwnComputer,
    /// As several FCCs sharing a simulation PC's cores are (`--sharing-cores`):
    /// voting-monitoring sleeps on its sockets at once (`[ipc.idle.voting-monitoring] mode =
    /// "block"`), so that no FCC's wait for a frame takes a core another FCC's work needs.
    SharingCores,
}

/// The links of a fleet's vehicles: each behind an emulated link of `all` (none: loopback), the
/// first behind one of `first` instead, if one (`--first-behind`: a vehicle whose link is bad
/// among vehicles whose links are not).
#[derive(Debug, Clone, Copy)]
struct Links {
    all: Option<Profile>,
    first: Option<Profile>,
}

impl Links {
    /// The profile of vehicle `i`'s link, none for loopback.
    fn of(self, i: usize) -> Option<Profile> {
        match (i, self.first) {
            (0, Some(first)) => Some(first),
            _ => self.all,
        }
    }
}

/// A fleet that runs: what keeps its vehicles alive (rigs, FCCs, emulators, simulated FCCs),
/// and its fleet file's entries.
struct Fleet {
    _real: Vec<(Rig, Process, Option<Emulator>)>,
    _simulated: Option<SimulatedFleet>,
    entries: Vec<FleetEntry>,
}

impl Fleet {
    /// `n` vehicles of `kind`, each behind a link emulator of its profile in `links`; a simulated
    /// fleet's files in `dir`, its positions' send times to `sent`.
    fn start(
        kind: Kind,
        n: usize,
        links: Links,
        fccs: Fccs,
        dir: &Path,
        sent: &SentPositions,
    ) -> Self {
        match kind {
            Kind::Real => {
                let (real, entries) = real_fleet(n, links, fccs);
                Self {
                    _real: real,
                    _simulated: None,
                    entries,
                }
            }
            Kind::Simulated => {
                let (simulated, entries) = SimulatedFleet::start(n, dir, sent, links);
                Self {
                    _real: Vec::new(),
                    _simulated: Some(simulated),
                    entries,
                }
            }
        }
    }
}

/// `n` real FCCs, each with a rig of its own (behind a link emulator of its profile in `links`);
/// their fleet entries.
#[allow(clippy::type_complexity)]
fn real_fleet(
    n: usize,
    links: Links,
    fccs: Fccs,
) -> (Vec<(Rig, Process, Option<Emulator>)>, Vec<FleetEntry>) {
    let mut real = Vec::new();
    let mut entries = Vec::new();
    for i in 0..n {
        let mut rig = Rig::new(&format!("fleet-bench-{}", i + 1));
        rig.config.ids.fcc = 0x0B00_0001 + i as u32;
        // Guidance in real time: positions as an aircraft flies them.
        rig.config.guidance.time_scale = 1.0;
        if fccs == Fccs::SharingCores {
            rig.config.ipc.idle[Partition::VotingMonitoring] = Idle::BLOCK;
        }
        let (fcc, emulator) = match links.of(i) {
            Some(profile) => {
                let (fcc, emulator, _) = rig.start_fcc_behind(profile.flows(), i as u64);
                (fcc, Some(emulator))
            }
            None => {
                let mut fcc = rig.start_fcc();
                rig.learn_links(&mut fcc);
                (fcc, None)
            }
        };
        real.push((rig, fcc, emulator));
    }
    // The GCS ends released once every FCC is up, right before the service binds them: an FCC
    // started after a release could be given a released port for its own links.
    for (i, (rig, _, _)) in real.iter_mut().enumerate() {
        entries.push(FleetEntry {
            name: vehicle_name(i),
            vehicle_id: rig.config.ids.fcc,
            ground: rig.release_gcs_ends(),
            fcc: [rig.config.links.fcc_direct, rig.config.links.fcc_lte],
            key_file: rig.dir.join("link.key"),
        });
    }
    (real, entries)
}

// ---- The measurements ----

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Real,
    Simulated,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Self::Real => "real",
            Self::Simulated => "simulated",
        }
    }
}

struct Row {
    kind: Kind,
    n: usize,
    one_ms: Vec<f64>,
    all_ms: Vec<f64>,
    /// The machine's busy CPU time (all cores, all processes) during each upload to one and to
    /// all: what an upload costs, and whether the uploads to all were bound by the cores.
    one_busy_ms: Vec<f64>,
    all_busy_ms: Vec<f64>,
    /// [`ONE_SERIES`] uploads to one vehicle in a row: their wall time and the machine's busy
    /// CPU time meanwhile, in all (ticks of 10 ms add up to a time worth comparing).
    series: (Duration, Duration),
    /// The machine's busy cores while the fleet idles (positions and heartbeats, every FCC's
    /// and the service's loops): what an upload shares the cores with.
    background_cores: f64,
    /// The service's CPU time per vehicle and upload, over the uploads to all.
    service_ms_per_upload: f64,
    /// The service's page faults per vehicle and upload, over the uploads to all: the pages of
    /// fresh memory (a request thread's stack, the allocator's growth) each request touches.
    service_faults_per_upload: f64,
    /// With `--first-behind`: the upload to all but the first alone, and beside an upload to
    /// the first over its link; how many of the first's did not complete.
    others_alone_ms: Vec<f64>,
    others_beside_ms: Vec<f64>,
    first_failed: usize,
    failed: usize,
    cpu_percent: f64,
    rss: u64,
    positions_per_s: (f64, f64),
    latency_ns: Vec<u64>,
}

fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[v.len() / 2]
}

fn percentile(sorted: &[u64], p: f64) -> u64 {
    if sorted.is_empty() {
        return 0;
    }
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// `gcs upload` of `file` to `vehicles` through `service`: wall time, the machine's busy CPU
/// time meanwhile (every process: the client, the service, the FCCs), and whether every
/// vehicle completed.
fn upload(service: &GroundService, vehicles: &str, file: &str) -> (Duration, Duration, bool) {
    let start = Instant::now();
    let busy = machine_busy();
    let out = service.gcs(&["--vehicle", vehicles, "upload", &mission(file)]);
    let took = start.elapsed();
    let busy = machine_busy().saturating_sub(busy);
    if !out.status.success() {
        eprintln!(
            "upload to {vehicles} did not complete:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    (took, busy, out.status.success())
}

/// The service on `entries` with its MAVLink side toward `client`.
fn service(dir: &Path, entries: &[FleetEntry], client: &MavlinkClient) -> GroundService {
    let fleet = fleet_text(Config::default().ids.gcs, entries);
    let to = client.addr.to_string();
    GroundService::start(
        dir,
        &fleet,
        &[
            "--mavlink",
            "--mavlink-bind",
            "127.0.0.1:0",
            "--mavlink-to",
            &to,
        ],
    )
}

/// A directory of the bench's own, removed when dropped.
struct Scratch(std::path::PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// One fleet and the ground service on it, the bench's MAVLink client hearing every vehicle:
/// what [`measure`] and [`soak`] both run. Dropped in this order: the service, the fleet, the
/// client, the directory.
struct Setup {
    service: GroundService,
    _fleet: Fleet,
    client: MavlinkClient,
    /// Every vehicle's name, as `gcs --vehicle` takes them.
    all: String,
    _dir: Scratch,
}

impl Setup {
    /// `n` vehicles of `kind` (behind the emulated links of `links`) in a directory named after
    /// `name`, the service started on them, every vehicle heard on MAVLink.
    fn start(kind: Kind, n: usize, links: Links, fccs: Fccs, name: &str) -> Self {
        let dir = Scratch::new(name);
        let sent: SentPositions = Arc::default();
        let client = MavlinkClient::start(sent.clone());
        let fleet = Fleet::start(kind, n, links, fccs, &dir.0, &sent);
        let service = service(&dir.0, &fleet.entries, &client);
        client.wait_for_all(n, Duration::from_secs(60));
        let all: Vec<String> = (0..n).map(vehicle_name).collect();
        Self {
            service,
            _fleet: fleet,
            client,
            all: all.join(","),
            _dir: dir,
        }
    }
}

fn measure(kind: Kind, n: usize, links: Links, fccs: Fccs, runs: usize, idle: Duration) -> Row {
    eprintln!("{} fleet of {n}: starting", kind.name());
    let setup = Setup::start(
        kind,
        n,
        links,
        fccs,
        &format!("missionlink-bench-fleet-{}-{n}", kind.name()),
    );
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let (service, client, all) = (&setup.service, &setup.client, &setup.all);
    let mut one_ms = Vec::new();
    let mut all_ms = Vec::new();
    let (mut one_busy_ms, mut all_busy_ms) = (Vec::new(), Vec::new());
    // The service's CPU time over every upload to all.
    let mut service_ms = 0.0;
    let mut service_faults = 0;
    let mut failed = 0;
    // Both lists change at every upload: missions 1 and 2 in turn.
    let files = ["mission-2.toml", "mission-1.toml"];
    let mut turn = 0;
    for _ in 0..runs {
        for (to_all, vehicles, times, busy_ms) in [
            // The last: with `--first-behind`, the first's link is not the others'.
            (false, vehicle_name(n - 1), &mut one_ms, &mut one_busy_ms),
            (true, all.clone(), &mut all_ms, &mut all_busy_ms),
        ] {
            // One vehicle alone; first every vehicle with the mission the next upload replaces.
            if vehicles != *all || turn == 0 {
                let (_, _, done) = upload(service, all, files[turn % 2]);
                failed += usize::from(!done);
                turn += 1;
            }
            let service_before = (cpu_time(service.pid()), minor_faults(service.pid()));
            let (took, busy, done) = upload(service, &vehicles, files[turn % 2]);
            // The upload to all only (in a fleet of one, the upload to one names all too).
            if to_all {
                service_ms += ms(cpu_time(service.pid()) - service_before.0);
                service_faults += minor_faults(service.pid()) - service_before.1;
            }
            failed += usize::from(!done);
            turn += 1;
            times.push(ms(took));
            busy_ms.push(ms(busy));
        }
    }

    // The work of one upload: uploads to the last vehicle in a row, the fleet idle beside them.
    let series_start = (Instant::now(), machine_busy());
    for _ in 0..ONE_SERIES {
        let (_, _, done) = upload(service, &vehicle_name(n - 1), files[turn % 2]);
        failed += usize::from(!done);
        turn += 1;
    }
    let series = (
        series_start.0.elapsed(),
        machine_busy().saturating_sub(series_start.1),
    );

    // The others beside a vehicle whose link is bad (`--first-behind`): the upload to all but
    // the first alone, and while an upload to the first runs over its link (another client,
    // started 20 ms before). Every vehicle first holds the same mission, which every upload
    // then replaces.
    let (mut others_alone_ms, mut others_beside_ms) = (Vec::new(), Vec::new());
    let mut first_failed = 0;
    if links.first.is_some() && n > 1 {
        let others: Vec<String> = (1..n).map(vehicle_name).collect();
        let (others, first) = (others.join(","), vehicle_name(0));
        let (_, _, done) = upload(service, all, files[turn % 2]);
        failed += usize::from(!done);
        turn += 1;
        let first_start = turn;
        for first_turn in first_start..first_start + runs {
            let (took, _, done) = upload(service, &others, files[turn % 2]);
            failed += usize::from(!done);
            turn += 1;
            others_alone_ms.push(ms(took));
            std::thread::scope(|scope| {
                let file = files[first_turn % 2];
                let first_upload = scope.spawn(|| upload(service, &first, file));
                std::thread::sleep(Duration::from_millis(20));
                let (took, _, done) = upload(service, &others, files[turn % 2]);
                failed += usize::from(!done);
                others_beside_ms.push(ms(took));
                let (_, _, first_done) = first_upload.join().unwrap();
                first_failed += usize::from(!first_done);
            });
            turn += 1;
        }
    }

    // Idle: positions and heartbeats only.
    std::thread::sleep(Duration::from_secs(2));
    let pid = service.pid();
    client.begin();
    let cpu_before = cpu_time(pid);
    let (start, busy_before) = (Instant::now(), machine_busy());
    std::thread::sleep(idle);
    let cpu = cpu_time(pid) - cpu_before;
    let wall = start.elapsed();
    let background_cores =
        machine_busy().saturating_sub(busy_before).as_secs_f64() / wall.as_secs_f64();
    let (positions, mut latency_ns) = client.end();
    let rss = status_kb(pid, "VmRSS:");
    let rates: Vec<f64> = (1..=n as u8)
        .map(|s| positions.get(&s).copied().unwrap_or(0) as f64 / wall.as_secs_f64())
        .collect();
    latency_ns.sort_unstable();
    drop(setup);
    Row {
        kind,
        n,
        one_ms,
        all_ms,
        one_busy_ms,
        all_busy_ms,
        series,
        background_cores,
        service_ms_per_upload: service_ms / (runs * n) as f64,
        service_faults_per_upload: service_faults as f64 / (runs * n) as f64,
        others_alone_ms,
        others_beside_ms,
        first_failed,
        failed,
        cpu_percent: 100.0 * cpu.as_secs_f64() / wall.as_secs_f64(),
        rss,
        positions_per_s: (
            rates.iter().copied().fold(f64::INFINITY, f64::min),
            rates.iter().copied().fold(0.0, f64::max),
        ),
        latency_ns: if kind == Kind::Simulated {
            latency_ns
        } else {
            Vec::new()
        },
    }
}

fn print(rows: &[Row]) {
    let cores = std::thread::available_parallelism().map_or(1, usize::from) as f64;
    println!(
        "\n{:<10} {:>4} {:>9} {:>9} {:>6} {:>9} {:>9} {:>6} {:>6} {:>6} {:>5} {:>7} {:>9} {:>10} {:>11} {:>13} {:>8} {:>8} {:>8} {:>8} {:>7}",
        "fleet",
        "N",
        "one ms",
        "all ms",
        "all/1",
        "cpu1 ms",
        "cpuN ms",
        "busy%",
        "svc ms",
        "svc pf",
        "fail",
        "CPU %",
        "RSS MiB",
        "KiB/veh",
        "KiB/veh +",
        "GPI/s min-max",
        "lat p50",
        "p99",
        "p99.9",
        "max µs",
        "samples"
    );
    for r in rows {
        let base = rows
            .iter()
            .find(|b| b.kind == r.kind && b.n == 1)
            .filter(|_| r.n > 1);
        let marginal = base.map_or_else(
            || "-".to_owned(),
            |b| {
                format!(
                    "{:.0}",
                    (r.rss as f64 - b.rss as f64) / (r.n - 1) as f64 / 1024.0
                )
            },
        );
        let us = |p: f64| {
            if r.latency_ns.is_empty() {
                "-".to_owned()
            } else {
                format!("{:.0}", percentile(&r.latency_ns, p) as f64 / 1e3)
            }
        };
        let (one, all) = (median(&r.one_ms), median(&r.all_ms));
        let all_busy = median(&r.all_busy_ms);
        println!(
            "{:<10} {:>4} {:>9.0} {:>9.0} {:>6.2} {:>9.0} {:>9.0} {:>6.0} {:>6.2} {:>6.0} {:>5} {:>7.2} {:>9.1} {:>10.0} {:>11} {:>6.2}-{:<6.2} {:>8} {:>8} {:>8} {:>8} {:>7}",
            r.kind.name(),
            r.n,
            one,
            all,
            all / one,
            median(&r.one_busy_ms),
            all_busy,
            100.0 * all_busy / (all * cores),
            r.service_ms_per_upload,
            r.service_faults_per_upload,
            r.failed,
            r.cpu_percent,
            r.rss as f64 / (1 << 20) as f64,
            r.rss as f64 / r.n as f64 / 1024.0,
            marginal,
            r.positions_per_s.0,
            r.positions_per_s.1,
            us(0.5),
            us(0.99),
            us(0.999),
            us(1.0),
            r.latency_ns.len(),
        );
    }
    // What the cores allow: the upload to all's work, spread over the cores the idle fleet
    // leaves, cannot take less time than that; against one upload's time it is the least
    // all/one this machine can show with the work an upload costs now.
    println!(
        "\n{:<10} {:>4} {:>9} {:>9} {:>7} {:>11} {:>7} {:>7} {:>6}",
        "fleet", "N", "one ms", "work1 ms", "cores1", "workN ms/v", "idle", "floor", "all/1"
    );
    for r in rows {
        let count = ONE_SERIES as f64;
        let b = r.background_cores;
        let one = r.series.0.as_secs_f64() * 1e3 / count;
        let work1 = (r.series.1.as_secs_f64() - b * r.series.0.as_secs_f64()) * 1e3 / count;
        let (all_wall, all_busy): (f64, f64) = (r.all_ms.iter().sum(), r.all_busy_ms.iter().sum());
        let work_n = (all_busy - b * all_wall) / (r.all_ms.len() * r.n) as f64;
        let floor = (r.n as f64 * work_n / ((cores - b) * one)).max(1.0);
        // In a fleet of one the upload to all is an upload to one: its few ticks say nothing.
        let (work_n, floor) = if r.n > 1 {
            (format!("{work_n:.2}"), format!("{floor:.2}"))
        } else {
            ("-".to_owned(), "-".to_owned())
        };
        println!(
            "{:<10} {:>4} {:>9.2} {:>9.2} {:>7.2} {:>11} {:>7.2} {:>7} {:>6.2}",
            r.kind.name(),
            r.n,
            one,
            work1,
            work1 / one,
            work_n,
            b,
            floor,
            median(&r.all_ms) / median(&r.one_ms),
        );
    }
    println!(
        "\none: mean wall time of {ONE_SERIES} uploads to one vehicle in a row; work1: the machine's \
         busy CPU time per upload over them, less what the idle fleet keeps busy meanwhile; cores1: \
         work1 / one, the cores one upload keeps busy; workN: the same per vehicle over the \
         uploads to all; idle: the cores the idle fleet keeps busy; floor: N x workN / ((cores - \
         idle) x one), the least all/one the cores allow for that work"
    );
    if rows.iter().any(|r| !r.others_beside_ms.is_empty()) {
        println!(
            "\n{:<10} {:>4} {:>14} {:>15} {:>7} {:>13}",
            "fleet", "N", "others ms", "beside ms", "ratio", "first failed"
        );
        for r in rows.iter().filter(|r| !r.others_beside_ms.is_empty()) {
            let (alone, beside) = (median(&r.others_alone_ms), median(&r.others_beside_ms));
            println!(
                "{:<10} {:>4} {:>14.0} {:>15.0} {:>7.2} {:>8} of {:<3}",
                r.kind.name(),
                r.n,
                alone,
                beside,
                beside / alone,
                r.first_failed,
                r.others_beside_ms.len(),
            );
        }
        println!(
            "\nothers: median wall time of `gcs upload` to every vehicle but the first, alone; \
             beside: while an upload to the first runs over its own link (--first-behind)"
        );
    }
    println!(
        "\none, all: median wall time of `gcs upload` to one vehicle and to all at once; cpu1, cpuN: \
         the machine's busy CPU time meanwhile (every process, all cores; in 10 ms ticks); busy%: \
         cpuN as a share of all cores over the upload to all; svc: the service's CPU time per \
         vehicle and upload, over the uploads to all; pf: its page faults per vehicle and upload \
         (pages of fresh memory touched); CPU: the \
         service's share of one core while idle; KiB/veh +: resident set added per vehicle over \
         the fleet of one; lat: #101 sent to its GLOBAL_POSITION_INT, µs"
    );
}

/// How a soak runs: how long, how often it samples, how often it uploads to all.
struct SoakPlan {
    duration: Duration,
    sample_every: Duration,
    upload_every: Duration,
}

/// The hour: one fleet of `n` of `kind`, an upload to all every `plan.upload_every`, a sample
/// every `plan.sample_every`.
fn soak(kind: Kind, n: usize, links: Links, fccs: Fccs, plan: &SoakPlan) {
    let SoakPlan {
        duration,
        sample_every,
        upload_every,
    } = *plan;
    let setup = Setup::start(kind, n, links, fccs, "missionlink-bench-soak");
    let (service, client, all) = (&setup.service, &setup.client, &setup.all);
    let pid = service.pid();
    let files = ["mission-2.toml", "mission-1.toml"];
    println!(
        "{:>7} {:>9} {:>9} {:>5} {:>8} {:>7} {:>8} {:>7} {:>13}",
        "sample",
        "RSS KiB",
        "heap KiB",
        "fds",
        "threads",
        "CPU %",
        "uploads",
        "failed",
        "GPI/s min-max"
    );
    let start = Instant::now();
    let mut samples: Vec<(u64, usize, usize, u64)> = Vec::new();
    let (mut uploads, mut failed) = (0usize, 0usize);
    let mut next_upload = start;
    let mut next_sample = start + sample_every;
    let mut cpu_before = cpu_time(pid);
    client.begin();
    while start.elapsed() < duration {
        let now = Instant::now();
        if now >= next_upload {
            let (_, _, done) = upload(service, all, files[uploads % 2]);
            uploads += 1;
            failed += usize::from(!done);
            next_upload += upload_every;
        }
        if now >= next_sample {
            let cpu = cpu_time(pid);
            let (positions, _) = client.end();
            client.begin();
            let rates: Vec<f64> = (1..=n as u8)
                .map(|s| {
                    positions.get(&s).copied().unwrap_or(0) as f64 / sample_every.as_secs_f64()
                })
                .collect();
            let sample = (
                status_kb(pid, "VmRSS:") / 1024,
                open_fds(pid),
                threads(pid),
                heap_kb(pid),
            );
            println!(
                "{:>7} {:>9} {:>9} {:>5} {:>8} {:>7.2} {:>8} {:>7} {:>6.2}-{:<6.2}",
                samples.len() + 1,
                sample.0,
                sample.3,
                sample.1,
                sample.2,
                100.0 * (cpu - cpu_before).as_secs_f64() / sample_every.as_secs_f64(),
                uploads,
                failed,
                rates.iter().copied().fold(f64::INFINITY, f64::min),
                rates.iter().copied().fold(0.0, f64::max),
            );
            samples.push(sample);
            cpu_before = cpu;
            next_sample += sample_every;
        }
        std::thread::sleep(
            next_upload
                .min(next_sample)
                .saturating_duration_since(Instant::now()),
        );
    }
    let (first, last) = (samples.first().unwrap(), samples.last().unwrap());
    let max_rss = samples.iter().map(|s| s.0).max().unwrap();
    println!(
        "\n{n} vehicles for {:.0} min: RSS {} KiB at minute 1, {} KiB at the end (max {} KiB, \
         growth {:+} KiB); fds {} -> {}; threads {} -> {}; {uploads} uploads to all, {failed} \
         not complete",
        duration.as_secs_f64() / 60.0,
        first.0,
        last.0,
        max_rss,
        last.0 as i64 - first.0 as i64,
        first.1,
        last.1,
        first.2,
        last.2,
    );
    // Growth told apart from the spread of single samples: the means of the first and the last
    // sixth, and the least-squares slope of each half (memory that settles has a slope in the
    // first half only).
    let per_hour = 3600.0 / sample_every.as_secs_f64();
    let trend = |name: &str, values: Vec<f64>| {
        let sixth = (values.len() / 6).max(1);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let half = values.len() / 2;
        let (early, late) = (
            mean(&values[..sixth]),
            mean(&values[values.len() - sixth..]),
        );
        println!(
            "{name} mean of the first sixth {early:.0} KiB, of the last sixth {late:.0} KiB \
             ({:+.0} KiB); slope {:+.0} KiB/h over the first half, {:+.0} KiB/h over the second",
            late - early,
            slope(&values[..half]) * per_hour,
            slope(&values[half..]) * per_hour,
        );
    };
    trend("RSS", samples.iter().map(|s| s.0 as f64).collect());
    trend("heap", samples.iter().map(|s| s.3 as f64).collect());
}

/// The least-squares slope of `values` against their index; 0 for fewer than two.
fn slope(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    if values.len() < 2 {
        return 0.0;
    }
    let mean_x = (n - 1.0) / 2.0;
    let mean_y = values.iter().sum::<f64>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for (i, y) in values.iter().enumerate() {
        let dx = i as f64 - mean_x;
        num += dx * (y - mean_y);
        den += dx * dx;
    }
    num / den
}

fn main() {
    // The FCC and the ground service of this build, as the sources are now.
    let dir = binaries::build_dir().unwrap();
    binaries::ensure(&dir, &binaries::FCC_BINARIES, binaries::Build::UnderCargo).unwrap();
    binaries::ensure_gcs(&dir, binaries::Build::UnderCargo).unwrap();
    let args: Vec<String> = std::env::args().collect();
    let bench = args.iter().any(|a| a == "--bench");
    let real = list(&args, "--real", if bench { &[1, 4, 16] } else { &[1] });
    let simulated = list(
        &args,
        "--simulated",
        if bench { &[1, 16, 250] } else { &[1] },
    );
    let runs: usize =
        arg(&args, "--runs").map_or(if bench { 5 } else { 1 }, |v| v.parse().expect("--runs N"));
    let idle = Duration::from_secs_f64(
        arg(&args, "--idle-s").map_or(if bench { 30.0 } else { 3.0 }, |v| {
            v.parse().expect("--idle-s S")
        }),
    );
    // Each vehicle behind its own emulated link of this profile; none: loopback.
    let named = |flag: &str| {
        arg(&args, flag).map(|p| {
            Profile::named(p)
                .unwrap_or_else(|| panic!("{flag} lan, lte, satcom, satcom-narrow or bad"))
        })
    };
    // The first vehicle behind a link of its own profile instead (`--first-behind bad`): the
    // others' uploads beside its upload.
    let links = Links {
        all: named("--profile"),
        first: named("--first-behind"),
    };
    // Real FCCs as on their own computers, or as several on one simulation PC are configured.
    let fccs = if args.iter().any(|a| a == "--sharing-cores") {
        Fccs::SharingCores
    } else {
        Fccs::OwnComputer
    };
    // A fleet of 250 behind emulators holds some 2000 sockets in this process.
    let limit = rustix::process::getrlimit(rustix::process::Resource::Nofile);
    let _ = rustix::process::setrlimit(
        rustix::process::Resource::Nofile,
        rustix::process::Rlimit {
            current: limit.maximum,
            maximum: limit.maximum,
        },
    );
    if let Some(seconds) = arg(&args, "--soak-s") {
        let duration = Duration::from_secs_f64(seconds.parse().expect("--soak-s S"));
        let sample_every = Duration::from_secs_f64(
            arg(&args, "--sample-s").map_or(60.0, |v| v.parse().expect("--sample-s S")),
        );
        let plan = SoakPlan {
            duration,
            sample_every,
            upload_every: arg(&args, "--upload-every-s").map_or(SOAK_UPLOAD_EVERY, |v| {
                Duration::from_secs_f64(v.parse().expect("--upload-every-s S"))
            }),
        };
        match real.iter().copied().max() {
            Some(n) => soak(Kind::Real, n, links, fccs, &plan),
            None => soak(
                Kind::Simulated,
                simulated.iter().copied().max().unwrap_or(16),
                links,
                fccs,
                &plan,
            ),
        }
        return;
    }
    assert!(
        simulated.iter().all(|n| (1..=250).contains(n)),
        "a MAVLink fleet has at most 250 systems here"
    );
    let mut rows = Vec::new();
    for n in real {
        rows.push(measure(Kind::Real, n, links, fccs, runs, idle));
    }
    for n in simulated {
        rows.push(measure(Kind::Simulated, n, links, fccs, runs, idle));
    }
    print(&rows);
}
