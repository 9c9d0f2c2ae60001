//! One-way latency of a frame between two processes, over five transports, for three payload
//! sizes. Run with `cargo bench --bench latency` (`-- --frames N` to change the number of
//! recorded frames per transport and size, `-- --warmup N` the frames sent before recording).
//!
//! # What is measured
//!
//! The bench binary is the sender; it starts itself again (`--role receiver ...`) as the
//! receiver, one receiver process per transport and payload size. Before sending a frame the
//! sender reads CLOCK_MONOTONIC and writes the reading into the payload; the receiver reads the
//! clock as soon as the frame is in its hands and records the difference in an HDR histogram
//! (nanoseconds, 3 significant digits). Both processes read the same clock of the same host, so
//! the difference is the one-way latency. The receiver answers every frame over the same
//! transport (a 64 B reply, not measured) and the sender sends the next frame only after the
//! answer: every sample is a single frame crossing an idle path, never a frame queued behind
//! another. The first frames (2000 by default) warm caches and code paths and are not recorded.
//!
//! The payload sizes are 64 B, 548 B (the largest STANAG frame, `MAX_FRAME_LEN`) and the size of
//! `WaypointListPayload` (the full waypoint list, 8216 B with 256 waypoints). The transports:
//!
//! 1. `iox2-event`: iceoryx2 publish-subscribe through the partitions' own IPC code
//!    (`missionlink_partitions::ipc` on `ipc::Service`, the services and QoS of
//!    `fcc/link/uplink` and `fcc/link/downlink`): the sender copies the frame into a loaned
//!    sample, sends it and notifies the event service of the same name (`Publisher::send`); the
//!    receiver sleeps in the partitions' `WaitSet` (`runtime::waitset`, `runtime::wait_in_waitset`) on the
//!    listener and takes the sample as they do (`Subscriber::take_all`: zero-copy, it reads the
//!    stamp in place).
//! 2. `iox2-poll`: the same ports, publishing without the notification (`Publisher::publish`);
//!    the receiver spins on `Subscriber::take_one` (and the sender spins for the reply).
//! 3. `uds`: a Unix domain datagram socket (abstract address), blocking `recv_from`.
//! 4. `udp`: UDP over loopback, blocking `recv_from`.
//! 5. `shm-floor`: the floor of any shared-memory transport: the stamp alone, stored into an
//!    `AtomicU64` on its own cache line of a file mapped by both processes (under `/dev/shm`),
//!    both sides spinning. Nothing but the cache-line transfer between the two cores.
//! 6. `partition`: the partitions' own wait and wake path with its default settings: both
//!    sides run `runtime::run_loop` (the loop every partition runs, with its heartbeat), the
//!    sender as voting-monitoring publishing on the uplink service, the receiver as mission
//!    data handling taking the frames as it does (`take_all`) and answering on the downlink
//!    service; each waits as its partition's default idle strategy says (`config::Idle`:
//!    voting-monitoring spins 200 µs, then sleeps in the WaitSet; mission data handling sleeps
//!    on its doorbell at once).
//! 7. `partition-block`, `partition-backoff`, `partition-doorbell`: the same with each idle
//!    strategy (`config::IdleMode`): `block` (sleep in the WaitSet at once: the wait path
//!    before the idle strategies, the same as `iox2-event` through `run_loop`), `backoff`
//!    (spin for voting-monitoring's default budget, then the WaitSet) and `doorbell` without a
//!    spin (sleep at once on the partition's semaphore doorbell, `doorbell`), on both sides
//!    but for the doorbell on the sender's: as voting-monitoring it waits for its sockets too,
//!    so it sleeps in the WaitSet (`doorbell::waits`) and mission data handling's answer does
//!    not ring a doorbell; the hop measured, the uplink into the receiver, is the doorbell's.
//! 8. `iox2-own-pubsub`: iceoryx2's publish-subscribe ping-pong as its own benchmark sets it
//!    up (`benchmarks/publish-subscribe` of its repository): a service per direction, history
//!    0, subscriber buffer 1, one publisher and one subscriber, both sides busy-waiting on
//!    `receive`; the reference of `iox2-poll`.
//! 9. `partition-sparse`, `partition-block-sparse`, `partition-backoff-sparse`,
//!    `partition-doorbell-sparse`, `uds-sparse`: those rows and `uds` at the sparse pace: the next frame leaves 1 ms after the
//!    previous one was answered (as uplink frames arrive from a GCS), longer than any spin
//!    budget, so every frame meets a receiver asleep: the cold wake-up. They record a tenth of
//!    `--frames` (and warm up with a tenth of `--warmup`).
//! 10. `partition-foreign-sparse`: `partition-sparse` with the sender in C, a partition on
//!     missionlink's C library (`clib/`, docs/hil.md) in voting-monitoring's role
//!     (benches/latency/foreign_sender.c, built with `cc` against the static library of the
//!     bench's profile): it publishes the contract's `FramePayload` on the uplink service (the
//!     stamp in `origin_ns`, ringing mission data handling's doorbell as a Rust publisher does)
//!     and sleeps in its WaitSet for the reply; the receiver is mission
//!     data handling's loop with its default idle strategy, as in `partition-sparse`. Only at
//!     the STANAG frame's size. The sender's columns (preemptions, CPU) are the bench
//!     process's, which only waits for the C process: the C process's CPU counts as others'.
//! 11. `partition-unrung-sparse`: `partition-doorbell-sparse` with a sender that rings no
//!     doorbell, as a partition in Python or a program on iceoryx2's own bindings publishes:
//!     its configuration has mission data handling in the WaitSet, so it notifies the uplink's
//!     event with event ID 0 alone, and the receiver, on its doorbell, hears it through the
//!     doorbell's forwarder (`doorbell`), one thread wake-up more.
//!
//! The rows take turns: a run is `--rounds N` rounds (5 by default), in each of which every row
//! records its share of the frames (after its own warm-up); a row's percentiles are those of
//! all its rounds' frames together. This host's cold wake-ups are tens of percent slower in
//! some minutes than in others, which measured one row after the other moved a ratio by as
//! much as the transports differ.
//!
//! `--only T,T,...` runs only the named transports, `--sizes N,N` only the named payload sizes
//! (for example `--only partition,uds --sizes 548`). After each table the ratios of p50 that
//! the goals name are printed: `partition` / `uds`, `partition-sparse` / `uds-sparse`,
//! `iox2-poll` / `iox2-own-pubsub` (and the `partition-block` ones).
//!
//! # What limits the numbers
//!
//! - The clock: reading CLOCK_MONOTONIC through the vDSO costs about 20-30 ns on each side;
//!   every sample carries about one such read (the end of the sender's, the start of the
//!   receiver's), so the floor is mostly a clock read and one cache-line transfer.
//! - The machine: a 2 vCPU KVM guest. The sender and the receiver are pinned to the two CPUs
//!   (printed with the results), so anything else running on the host (a build, the other
//!   spinning side) shares a CPU with one of them: preemption shows in p99.9 and max. Each row
//!   reports the involuntary context switches of both processes during the recording and the
//!   CPU time the rest of the machine used meanwhile (from /proc), so a busy run is visible.
//! - Wake-ups: the event-driven iceoryx2 transport and both sockets put the receiver to sleep;
//!   their latency is mostly the kernel waking a thread on another CPU (an inter-processor
//!   interrupt, in a VM a virtual one) and, for iceoryx2, the sender's notify system call and
//!   the receiver's WaitSet (epoll) round, not the copy. The polling transports avoid the wake-up at
//!   the cost of a CPU spinning at 100 %.
//! - Copies: the iceoryx2 sender copies the whole payload into shared memory (as the
//!   partitions do) and the receiver reads only the stamp in place; the socket receivers get the
//!   whole payload copied into their buffer by the kernel. Larger payloads therefore cost the
//!   sockets two copies and iceoryx2 one.
//!
//! Results: a table per payload size on stdout, all numbers as JSON in
//! `target/latency/results.json` and a plot in `target/latency/latency.svg`.
//!
//! # Under CPU load (`-- --load`)
//!
//! `cargo bench --bench latency -- --load` measures instead the partition-to-partition hop of
//! the largest STANAG frame over `partition` (the partitions' own loop with its default idle
//! strategy; `--only T` names another transport, the first named) in three cases, one after
//! the other in one run:
//!
//! 1. no load, default scheduling (the reference);
//! 2. a CPU hog per CPU, default scheduling: what the partitions get without real-time
//!    settings;
//! 3. the same hogs, with the real-time settings applied to both sides through the partitions'
//!    own `missionlink_partitions::realtime::apply` (the sender on the first CPU, the receiver
//!    on the second, SCHED_FIFO priority 50, memory locked).
//!
//! A hog is this binary started again (`--role hog --cpu N`): a busy loop pinned to its CPU, at
//! default scheduling (it checks that it is SCHED_OTHER, so a real-time policy inherited by
//! mistake would end the run rather than measure the wrong thing). The hogs of a case are
//! killed when it ends, also when the bench panics (a drop guard), and a hog ends by itself
//! when the bench is gone (`kill -9`). Case 3 comes last since the sender keeps its real-time
//! settings to the end. Results: a table on stdout, the numbers in `target/latency/load.json`.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]
#![allow(
    unsafe_code,
    reason = "the shared-memory floor maps a file and views two of its cache lines as atomics"
)]

use missionlink::harness::log_axis;

// The hop over each transport, the report, the load cases.
mod hop;
mod load;
mod report;

use hop::*;
use load::*;
use report::*;

use std::fmt::Write as _;
use std::io::{BufRead, BufReader};
use std::net::UdpSocket;
use std::os::linux::net::SocketAddrExt;
use std::os::unix::net::{SocketAddr, UnixDatagram};
use std::path::{Path, PathBuf};

use log_axis::LogAxis;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::Partition;
use missionlink_interfaces::contracts::{FccService, WaypointListPayload};
use missionlink_interfaces::wire::MAX_FRAME_LEN;
use missionlink_partitions::config::{
    Config, DEFAULT_SPIN_US, FifoPriority, Idle, IdleMode, PerPartition, RealtimeSettings,
};
use missionlink_partitions::ipc::{Ipc, Publisher, Subscriber};
use missionlink_partitions::realtime::{self, Scheduling};
use missionlink_partitions::runtime::{self, Control, Inputs};
use missionlink_platform::clock::monotonic_ns;
use serde_json::{Value, json};

/// Recorded frames per transport and size unless `--frames` says otherwise.
const DEFAULT_FRAMES: u64 = 100_000;
/// Frames sent before recording unless `--warmup` says otherwise.
const DEFAULT_WARMUP: u64 = 2_000;
/// Rounds a run takes unless `--rounds` says otherwise: every row records a share of its frames
/// in each, the rows taking turns.
const DEFAULT_ROUNDS: u64 = 5;
/// The SCHED_FIFO priority of both sides in the real-time case of `--load`.
const LOAD_FIFO_PRIORITY: u8 = 50;
/// The goal for the hop under load with real-time settings (BENCHMARKS.md section 7): p99.9 at
/// most this.
const LOAD_GOAL_P999: Duration = Duration::from_micros(100);
/// A side that hears nothing for this long gives up: the other process is gone.
const TIMEOUT: Duration = Duration::from_secs(10);
/// The sparse rows send a frame this long after the previous one was answered: longer than any
/// spin budget, as uplink frames arriving from a GCS.
const SPARSE_PACE: Duration = Duration::from_millis(1);
/// The sparse rows record this many times fewer frames (and warm up with this many times
/// fewer) than the others.
const SPARSE_DIVISOR: u64 = 10;
/// Size of the reply to every frame.
const REPLY_SIZE: usize = 64;
/// Size of the full waypoint list.
const WAYPOINT_LIST_SIZE: usize = size_of::<WaypointListPayload>();

// ---------------------------------------------------------------------------------------------
// Transports and payload sizes
// ---------------------------------------------------------------------------------------------

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Transport {
    Iox2Event,
    Partition,
    PartitionBlock,
    PartitionBackoff,
    PartitionDoorbell,
    Iox2Poll,
    Iox2OwnPubsub,
    Uds,
    Udp,
    ShmFloor,
    PartitionSparse,
    PartitionBlockSparse,
    PartitionBackoffSparse,
    PartitionDoorbellSparse,
    UdsSparse,
    PartitionForeignSparse,
    PartitionUnrungSparse,
}

impl Transport {
    /// In the order of the tables; the first is the reference of the ratios.
    const ALL: [Transport; 17] = [
        Self::Iox2Event,
        Self::Partition,
        Self::PartitionBlock,
        Self::PartitionBackoff,
        Self::PartitionDoorbell,
        Self::Iox2Poll,
        Self::Iox2OwnPubsub,
        Self::Uds,
        Self::Udp,
        Self::ShmFloor,
        Self::PartitionSparse,
        Self::PartitionBlockSparse,
        Self::PartitionBackoffSparse,
        Self::PartitionDoorbellSparse,
        Self::UdsSparse,
        Self::PartitionForeignSparse,
        Self::PartitionUnrungSparse,
    ];

    /// The name on the command line and in the JSON.
    fn arg(self) -> &'static str {
        match self {
            Self::Iox2Event => "iox2-event",
            Self::Partition => "partition",
            Self::PartitionBlock => "partition-block",
            Self::PartitionBackoff => "partition-backoff",
            Self::PartitionDoorbell => "partition-doorbell",
            Self::Iox2Poll => "iox2-poll",
            Self::Iox2OwnPubsub => "iox2-own-pubsub",
            Self::Uds => "uds",
            Self::Udp => "udp",
            Self::ShmFloor => "shm-floor",
            Self::PartitionSparse => "partition-sparse",
            Self::PartitionBlockSparse => "partition-block-sparse",
            Self::PartitionBackoffSparse => "partition-backoff-sparse",
            Self::PartitionDoorbellSparse => "partition-doorbell-sparse",
            Self::UdsSparse => "uds-sparse",
            Self::PartitionForeignSparse => "partition-foreign-sparse",
            Self::PartitionUnrungSparse => "partition-unrung-sparse",
        }
    }

    /// The name in the table and the plot.
    fn label(self) -> &'static str {
        match self {
            Self::Iox2Event => "iceoryx2 event-driven",
            Self::Partition => "partition loop (default idle)",
            Self::PartitionBlock => "partition loop, idle = block",
            Self::PartitionBackoff => "partition loop, backoff",
            Self::PartitionDoorbell => "partition, doorbell, no spin",
            Self::Iox2Poll => "iceoryx2 polling",
            Self::Iox2OwnPubsub => "iceoryx2's own pub-sub setup",
            Self::Uds => "Unix datagram socket",
            Self::Udp => "UDP loopback",
            Self::ShmFloor => "shared cache line (floor)",
            Self::PartitionSparse => "partition loop, sparse",
            Self::PartitionBlockSparse => "partition, block, sparse",
            Self::PartitionBackoffSparse => "partition, backoff, sparse",
            Self::PartitionDoorbellSparse => "partition, doorbell, sparse",
            Self::UdsSparse => "Unix datagram, sparse",
            Self::PartitionForeignSparse => "C publisher, sparse",
            Self::PartitionUnrungSparse => "publisher ringing nothing",
        }
    }

    /// The pause between a reply and the next frame: `None` back to back, [`SPARSE_PACE`]
    /// for the sparse rows.
    fn pace(self) -> Option<Duration> {
        matches!(
            self,
            Self::PartitionSparse
                | Self::PartitionBlockSparse
                | Self::PartitionBackoffSparse
                | Self::PartitionDoorbellSparse
                | Self::UdsSparse
                | Self::PartitionForeignSparse
                | Self::PartitionUnrungSparse
        )
        .then_some(SPARSE_PACE)
    }

    /// Whether the row also runs the ping-pong loop that iceoryx2's own publish-subscribe
    /// benchmark times (the polling rows: its mean one-way time without a clock read per
    /// sample, `hop::LOOP_ROUND_TRIPS`).
    fn loop_mean(self) -> bool {
        matches!(self, Self::Iox2Poll | Self::Iox2OwnPubsub)
    }

    /// The idle strategy of every partition in a partition-loop row: `None` for each
    /// partition's default (the sender runs as voting-monitoring, the receiver as mission data
    /// handling); sleeping in the WaitSet at once; spinning for voting-monitoring's default
    /// budget, then the WaitSet; the doorbell without a spin.
    fn idle(self) -> Option<Idle> {
        match self {
            Self::PartitionBlock | Self::PartitionBlockSparse => Some(Idle::BLOCK),
            Self::PartitionBackoff | Self::PartitionBackoffSparse => Some(Idle {
                mode: IdleMode::Backoff,
                spin_us: DEFAULT_SPIN_US,
                yield_us: 0,
            }),
            Self::PartitionDoorbell
            | Self::PartitionDoorbellSparse
            | Self::PartitionUnrungSparse => Some(Idle {
                mode: IdleMode::Doorbell,
                spin_us: 0,
                yield_us: 0,
            }),
            _ => None,
        }
    }

    fn from_arg(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.arg() == s)
    }

    /// The hop that carries this transport's frames: every partition row is the same loop
    /// with another idle strategy or pace, every sparse row its dense row's hop.
    fn hop(self) -> Hop {
        match self {
            Self::Iox2Event => Hop::Iox2 { event: true },
            Self::Iox2Poll => Hop::Iox2 { event: false },
            Self::Partition
            | Self::PartitionBlock
            | Self::PartitionBackoff
            | Self::PartitionDoorbell
            | Self::PartitionSparse
            | Self::PartitionBlockSparse
            | Self::PartitionBackoffSparse
            | Self::PartitionDoorbellSparse
            | Self::PartitionUnrungSparse => Hop::Typed { own: false },
            Self::Iox2OwnPubsub => Hop::Typed { own: true },
            Self::Uds | Self::UdsSparse => Hop::Uds,
            Self::Udp => Hop::Udp,
            Self::ShmFloor => Hop::Shm,
            Self::PartitionForeignSparse => Hop::Foreign,
        }
    }
}

/// The code in `hop.rs` that carries a transport's frames, for the sender and the receiver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Hop {
    /// iceoryx2 publish-subscribe through the partitions' IPC, woken by an event or polling.
    Iox2 { event: bool },
    /// The partitions' loop (`own: false`) or iceoryx2's own benchmark set-up.
    Typed { own: bool },
    /// A Unix datagram socket.
    Uds,
    /// UDP over loopback.
    Udp,
    /// The shared cache line.
    Shm,
    /// A sender in C on the C library (`clib/`), the receiver the partitions' loop.
    Foreign,
}

/// The payload sizes with their description.
fn sizes() -> [(usize, String); 3] {
    [
        (64, "64 B".to_owned()),
        (
            MAX_FRAME_LEN,
            format!("{MAX_FRAME_LEN} B, the largest STANAG frame"),
        ),
        (
            WAYPOINT_LIST_SIZE,
            format!("{WAYPOINT_LIST_SIZE} B, the full waypoint list (WaypointListPayload)"),
        ),
    ]
}

/// One measurement: a transport, a payload size, and the names that keep it apart from every
/// other run.
#[derive(Debug, Clone)]
struct Run {
    transport: Transport,
    size: usize,
    frames: u64,
    warmup: u64,
    /// Unique per run and host: the parent's pid, the transport and the size.
    id: String,
    /// The receiver applies the real-time settings of `--load` (on its `--cpu`) instead of
    /// only pinning itself.
    realtime: bool,
}

impl Run {
    fn total(&self) -> u64 {
        self.warmup + self.frames
    }

    fn args(&self) -> Vec<String> {
        vec![
            "--role".into(),
            "receiver".into(),
            "--transport".into(),
            self.transport.arg().into(),
            "--size".into(),
            self.size.to_string(),
            "--frames".into(),
            self.frames.to_string(),
            "--warmup".into(),
            self.warmup.to_string(),
            "--id".into(),
            self.id.clone(),
        ]
        .into_iter()
        .chain(self.realtime.then(|| "--realtime".into()))
        .collect()
    }
}

// ---------------------------------------------------------------------------------------------
// Processes: the receiver child, the sender parent, CPU pinning
// ---------------------------------------------------------------------------------------------

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Sender,
    Receiver,
}

/// The two CPUs to pin the sender and the receiver to, if this process may use two.
fn cpu_pair() -> Option<(usize, usize)> {
    let allowed = rustix::thread::sched_getaffinity(None).ok()?;
    let mut cpus = (0..rustix::thread::CpuSet::MAX_CPU).filter(|&c| allowed.is_set(c));
    Some((cpus.next()?, cpus.next()?))
}

/// Pins the calling thread to `cpu`; says why not on failure.
fn pin_to(cpu: usize) -> Result<(), String> {
    let mut set = rustix::thread::CpuSet::new();
    set.set(cpu);
    rustix::thread::sched_setaffinity(None, &set).map_err(|e| e.to_string())
}

/// What this process has used so far, from /proc: involuntary context switches (preemptions)
/// and CPU time in clock ticks.
#[derive(Debug, Clone, Copy)]
struct Usage {
    switches: u64,
    ticks: u64,
}

impl Usage {
    fn now() -> Self {
        let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        let switches = status
            .lines()
            .find_map(|l| l.strip_prefix("nonvoluntary_ctxt_switches:"))
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(0);
        // Fields 14 and 15 of /proc/self/stat (utime, stime), counted after the command name.
        let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
        let ticks = stat.rsplit_once(')').map_or(0, |(_, rest)| {
            rest.split_whitespace()
                .skip(11)
                .take(2)
                .filter_map(|v| v.parse::<u64>().ok())
                .sum()
        });
        Self { switches, ticks }
    }

    fn since(self, start: Self) -> Self {
        Self {
            switches: self.switches.saturating_sub(start.switches),
            ticks: self.ticks.saturating_sub(start.ticks),
        }
    }
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

/// The receiver process: pins itself, listens, records, prints the result as one JSON line.
fn receiver_main(run: &Run, cpu: Option<usize>) {
    let mut realtime = Value::Null;
    match cpu {
        Some(cpu) if run.realtime => realtime = apply_realtime("receiver", cpu),
        Some(cpu) => {
            if let Err(e) = pin_to(cpu) {
                eprintln!("receiver: cannot pin to CPU {cpu}: {e}");
            }
        }
        None => {}
    }
    let start = Usage::now();
    let histogram = match run.transport.hop() {
        Hop::Iox2 { event } => iox2(run, Role::Receiver, event).expect("histogram"),
        Hop::Typed { own } => typed(run, Role::Receiver, own).expect("histogram"),
        Hop::Uds => uds_receiver(run),
        Hop::Udp => udp_receiver(run),
        Hop::Shm => shm_receiver(run),
        Hop::Foreign => foreign_receiver(run),
    };
    let usage = Usage::now().since(start);
    let h = &histogram;
    let result = json!({
        "samples": h.len(),
        "min_ns": h.min(),
        "p50_ns": h.value_at_quantile(0.5),
        "p99_ns": h.value_at_quantile(0.99),
        "p999_ns": h.value_at_quantile(0.999),
        "max_ns": h.max(),
        "mean_ns": h.mean(),
        "receiver_involuntary_switches": usage.switches,
        "receiver_cpu_ticks": usage.ticks,
        "receiver_realtime": realtime,
        // Every recorded value with its count: what the sender merges the rounds of a row from.
        "recorded": h
            .iter_recorded()
            .map(|v| [v.value_iterated_to(), v.count_at_value()])
            .collect::<Vec<_>>(),
    });
    println!("result {result}");
}

/// Kills the receiver if the sender panics, so that no process is left behind.
struct ChildGuard(Child);

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            self.0.kill().ok();
            self.0.wait().ok();
        }
    }
}

/// One measurement: starts the receiver, sends, collects the receiver's result.
fn measure(run: &Run, receiver_cpu: Option<usize>) -> Value {
    if run.transport.hop() == Hop::Foreign {
        foreign_sender_program();
    }
    let mut command = Command::new(std::env::current_exe().expect("own executable"));
    command.args(run.args()).stdout(Stdio::piped());
    if let Some(cpu) = receiver_cpu {
        command.args(["--cpu", &cpu.to_string()]);
    }
    let mut child = ChildGuard(command.spawn().expect("start the receiver"));
    let mut lines = BufReader::new(child.0.stdout.take().expect("piped stdout")).lines();
    // Anything else the child prints goes to stderr; "ready ..." and "result ..." are ours.
    let mut next = |tag: &str| loop {
        let line = lines
            .next()
            .unwrap_or_else(|| panic!("the receiver ended before `{tag}`"))
            .expect("the receiver's output");
        match line.strip_prefix(tag) {
            Some(rest) => return rest.trim().to_owned(),
            None => eprintln!("receiver: {line}"),
        }
    };
    let info = next("ready");
    let (start, machine_start) = (Usage::now(), missionlink::harness::machine_ticks());
    match run.transport.hop() {
        Hop::Iox2 { event } => {
            iox2(run, Role::Sender, event);
        }
        Hop::Typed { own } => {
            typed(run, Role::Sender, own);
        }
        Hop::Uds => uds_sender(run),
        Hop::Udp => udp_sender(run, &info),
        Hop::Shm => shm_sender(run),
        Hop::Foreign => foreign_sender(run),
    }
    let sender = Usage::now().since(start);
    let machine_end = missionlink::harness::machine_ticks();
    let loop_mean = hop::take_loop_mean_ns();
    let mut result: Value = serde_json::from_str(&next("result")).expect("the receiver's JSON");
    let status = child.0.wait().expect("the receiver's exit");
    assert!(status.success(), "the receiver failed: {status}");
    result["transport"] = json!(run.transport.arg());
    result["label"] = json!(run.transport.label());
    result["payload_bytes"] = json!(run.size);
    if let Some(mean) = loop_mean {
        result["loop_mean_ns"] = json!(mean);
    }
    result["sender_involuntary_switches"] = json!(sender.switches);
    result["sender_cpu_ticks"] = json!(sender.ticks);
    result["machine_busy_ticks"] = json!(machine_end.0.saturating_sub(machine_start.0));
    result["machine_total_ticks"] = json!(machine_end.1.saturating_sub(machine_start.1));
    // What the rest of the machine used meanwhile, in % of all CPUs.
    let busy = machine_end.0.saturating_sub(machine_start.0);
    let total = machine_end.1.saturating_sub(machine_start.1).max(1);
    let ours = sender.ticks + result["receiver_cpu_ticks"].as_u64().unwrap_or(0);
    result["others_cpu_percent"] = json!(100.0 * busy.saturating_sub(ours) as f64 / total as f64);
    result
}

/// One row's result from the results of its rounds: the percentiles of all their recorded
/// frames together, the counts of all rounds summed.
fn merge_rounds(rounds: Vec<Value>) -> Value {
    let mut histogram =
        Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).expect("valid histogram bounds");
    let mut merged = rounds.first().cloned().unwrap_or(Value::Null);
    let sum = |key: &str| -> u64 { rounds.iter().filter_map(|r| r[key].as_u64()).sum() };
    for round in &rounds {
        for pair in round["recorded"].as_array().into_iter().flatten() {
            if let (Some(value), Some(count)) = (pair[0].as_u64(), pair[1].as_u64()) {
                histogram.saturating_record_n(value, count);
            }
        }
    }
    let h = &histogram;
    for (key, value) in [
        ("samples", h.len()),
        ("min_ns", h.min()),
        ("p50_ns", h.value_at_quantile(0.5)),
        ("p99_ns", h.value_at_quantile(0.99)),
        ("p999_ns", h.value_at_quantile(0.999)),
        ("max_ns", h.max()),
    ] {
        merged[key] = json!(value);
    }
    merged["mean_ns"] = json!(h.mean());
    for key in [
        "receiver_involuntary_switches",
        "receiver_cpu_ticks",
        "sender_involuntary_switches",
        "sender_cpu_ticks",
        "machine_busy_ticks",
        "machine_total_ticks",
    ] {
        merged[key] = json!(sum(key));
    }
    let ours = sum("sender_cpu_ticks") + sum("receiver_cpu_ticks");
    let busy = sum("machine_busy_ticks");
    let total = sum("machine_total_ticks").max(1);
    merged["others_cpu_percent"] = json!(100.0 * busy.saturating_sub(ours) as f64 / total as f64);
    let loop_means: Vec<f64> = rounds
        .iter()
        .filter_map(|r| r["loop_mean_ns"].as_f64())
        .collect();
    if !loop_means.is_empty() {
        merged["loop_mean_ns"] = json!(loop_means.iter().sum::<f64>() / loop_means.len() as f64);
    }
    merged["rounds"] = json!(rounds.len());
    if let Some(fields) = merged.as_object_mut() {
        fields.remove("recorded");
    }
    merged
}

// ---------------------------------------------------------------------------------------------
// main
// ---------------------------------------------------------------------------------------------

#[derive(Debug, Default)]
struct Args {
    role: Option<String>,
    transport: Option<String>,
    size: Option<usize>,
    frames: Option<u64>,
    warmup: Option<u64>,
    id: Option<String>,
    cpu: Option<usize>,
    load: bool,
    realtime: bool,
    only: Option<Vec<Transport>>,
    sizes: Option<Vec<usize>>,
    rounds: Option<u64>,
}

fn parse_args() -> Args {
    let mut args = Args::default();
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        let number =
            |v: String| -> u64 { v.parse().unwrap_or_else(|_| panic!("not a number: {v}")) };
        match arg.as_str() {
            "--role" => args.role = Some(value()),
            "--transport" => args.transport = Some(value()),
            "--size" => args.size = Some(number(value()) as usize),
            "--frames" => args.frames = Some(number(value())),
            "--warmup" => args.warmup = Some(number(value())),
            "--id" => args.id = Some(value()),
            "--cpu" => args.cpu = Some(number(value()) as usize),
            "--load" => args.load = true,
            "--only" => {
                args.only = Some(
                    value()
                        .split(',')
                        .map(|t| {
                            Transport::from_arg(t).unwrap_or_else(|| panic!("no transport {t}"))
                        })
                        .collect(),
                )
            }
            "--sizes" => {
                args.sizes = Some(
                    value()
                        .split(',')
                        .map(|v| number(v.to_owned()) as usize)
                        .collect(),
                )
            }
            "--rounds" => args.rounds = Some(number(value()).max(1)),
            "--realtime" => args.realtime = true,
            // `cargo bench` adds it.
            "--bench" => {}
            other => {
                eprintln!(
                    "latency: ignoring `{other}` (options: --frames N, --warmup N, --rounds N, \
                 --load, --only T,T, --sizes N,N)"
                )
            }
        }
    }
    args
}

fn main() {
    missionlink_partitions::ipc::quiet_iceoryx2_log();
    let args = parse_args();
    let frames = args.frames.unwrap_or(DEFAULT_FRAMES).max(1);
    let warmup = args.warmup.unwrap_or(DEFAULT_WARMUP);
    let rounds = args.rounds.unwrap_or(DEFAULT_ROUNDS);

    if args.role.as_deref() == Some("hog") {
        hog_main(args.cpu);
        return;
    }
    if args.role.as_deref() == Some("receiver") {
        let transport = args.transport.as_deref().and_then(Transport::from_arg);
        let run = Run {
            transport: transport.expect("--transport"),
            size: args.size.expect("--size"),
            frames,
            warmup,
            id: args.id.expect("--id"),
            realtime: args.realtime,
        };
        receiver_main(&run, args.cpu);
        return;
    }
    if args.load {
        let transport = args
            .only
            .as_ref()
            .and_then(|only| only.first().copied())
            .unwrap_or(Transport::Partition);
        load_main(transport, frames, warmup);
        return;
    }

    let (sender_cpu, receiver_cpu, cpus) = match cpu_pair() {
        Some((a, b)) => match pin_to(a) {
            Ok(()) => (
                Some(a),
                Some(b),
                format!("sender on CPU {a}, receiver on CPU {b}"),
            ),
            Err(e) => (None, None, format!("not pinned ({e})")),
        },
        None => (
            None,
            None,
            "not pinned (fewer than two CPUs allowed)".to_owned(),
        ),
    };
    let load_before = load_average();
    println!(
        "One-way latency, sender to receiver process: {frames} frames per transport and size \
         in {rounds} rounds, the rows taking turns, each round after {warmup} warm-up frames, \
         each frame sent after the previous one was answered; {cpus}; load average before: \
         {load_before}"
    );
    let pid = std::process::id();
    let mut results = Vec::new();
    let wanted = |t: &Transport| args.only.as_ref().is_none_or(|only| only.contains(t));
    for (size, description) in sizes() {
        if args.sizes.as_ref().is_some_and(|s| !s.contains(&size)) {
            continue;
        }
        let runs: Vec<Run> = Transport::ALL
            .into_iter()
            .filter(wanted)
            // The C sender publishes the contract's FramePayload: a STANAG frame, one size.
            .filter(|t| t.hop() != Hop::Foreign || size == MAX_FRAME_LEN)
            .map(|transport| {
                // At the sparse pace a frame takes a millisecond: a tenth of the frames.
                let (frames, warmup) = match transport.pace() {
                    Some(_) => ((frames / SPARSE_DIVISOR).max(1), warmup / SPARSE_DIVISOR),
                    None => (frames, warmup),
                };
                Run {
                    transport,
                    size,
                    // Each round records its share; every round warms up again.
                    frames: (frames / rounds).max(1),
                    warmup,
                    id: format!("{pid}-{}-{size}", transport.arg()),
                    realtime: false,
                }
            })
            .collect();
        // The rows take turns, a share of each row's frames per round: what the host does
        // over a run (its wake-ups are several times slower in some minutes than in others)
        // falls on every row alike, so the ratios compare the transports, not the minutes.
        let mut rounds_of: Vec<Vec<Value>> = vec![Vec::new(); runs.len()];
        let mut took = vec![Duration::ZERO; runs.len()];
        for round in 0..rounds {
            for (i, run) in runs.iter().enumerate() {
                let run = Run {
                    id: format!("{}-r{round}", run.id),
                    ..run.clone()
                };
                let started = Instant::now();
                rounds_of[i].push(measure(&run, receiver_cpu));
                took[i] += started.elapsed();
            }
            if rounds > 1 {
                eprintln!("  {size} B: round {} of {rounds} done", round + 1);
            }
        }
        for ((run, of_run), took) in runs.iter().zip(rounds_of).zip(took) {
            let result = merge_rounds(of_run);
            eprintln!(
                "  {:<27} {size:>6} B  p50 {:>8.2} µs  ({:.1} s)",
                run.transport.label(),
                us(&result, "p50_ns"),
                took.as_secs_f64()
            );
            results.push(result);
        }
        let of_size: Vec<&Value> = results
            .iter()
            .filter(|r| r["payload_bytes"] == json!(size))
            .collect();
        print_table(&description, &of_size);
    }
    let load_after = load_average();
    println!(
        "\n(µs; p50/ev and p99.9/ev: ratio to iceoryx2 event-driven at the same size; preempt: \
         involuntary context switches of sender/receiver while measuring; others: CPU time used \
         by other processes meanwhile, in % of all CPUs. Load average after: {load_after})"
    );

    let document = json!({
        "what": "one-way latency of a frame between two processes, CLOCK_MONOTONIC stamp to receipt, ping-pong paced",
        "frames": frames,
        "warmup": warmup,
        "sender_cpu": sender_cpu,
        "receiver_cpu": receiver_cpu,
        "load_average_before": load_before,
        "load_average_after": load_after,
        "results": results,
    });
    let json_path = write_output(
        "results.json",
        &serde_json::to_string_pretty(&document).expect("JSON"),
    );
    let subtitle = format!(
        "CLOCK_MONOTONIC stamp to receipt, ping-pong paced, {frames} frames per bar, {cpus}; log scale"
    );
    let svg_path = write_output("latency.svg", &svg(&results, &subtitle));
    println!(
        "Results: {}\nPlot:    {}",
        json_path.display(),
        svg_path.display()
    );
}
