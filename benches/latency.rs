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
//!    receiver sleeps in the partitions' `WaitSet` (`runtime::waitset`, `Control::wait`) on the
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
//!    spin (sleep at once on the partition's semaphore doorbell, `doorbell`), on both sides.
//! 8. `iox2-own-pubsub`: iceoryx2's publish-subscribe ping-pong as its own benchmark sets it
//!    up (`benchmarks/publish-subscribe` of its repository): a service per direction, history
//!    0, subscriber buffer 1, one publisher and one subscriber, both sides busy-waiting on
//!    `receive`; the reference of `iox2-poll`.
//! 9. `partition-sparse`, `partition-block-sparse`, `partition-backoff-sparse`,
//!    `partition-doorbell-sparse`, `uds-sparse`: those rows and `uds` at the sparse pace: the next frame leaves 1 ms after the
//!    previous one was answered (as uplink frames arrive from a GCS), longer than any spin
//!    budget, so every frame meets a receiver asleep: the cold wake-up. They record a tenth of
//!    `--frames` (and warm up with a tenth of `--warmup`).
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

#[path = "support/log_axis.rs"]
mod log_axis;

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
    Config, DEFAULT_SPIN_US, FifoPriority, Idle, IdleMode, IdlePerPartition, RealtimeSettings,
};
use missionlink_partitions::ipc::{Ipc, Publisher, Subscriber};
use missionlink_partitions::realtime::{self, Scheduling};
use missionlink_partitions::runtime::{self, Control, Wake};
use missionlink_partitions::{mission_data_handling, voting_monitoring};
use missionlink_platform::clock::monotonic_ns;
use serde_json::{Value, json};

/// Recorded frames per transport and size unless `--frames` says otherwise.
const DEFAULT_FRAMES: u64 = 100_000;
/// Frames sent before recording unless `--warmup` says otherwise.
const DEFAULT_WARMUP: u64 = 2_000;
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
}

impl Transport {
    /// In the order of the tables; the first is the reference of the ratios.
    const ALL: [Transport; 15] = [
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
        )
        .then_some(SPARSE_PACE)
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
            Self::PartitionDoorbell | Self::PartitionDoorbellSparse => Some(Idle {
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
// The measurement, the same for every transport
// ---------------------------------------------------------------------------------------------

/// The sender: stamps and sends a frame, waits for its reply, repeats (at the sparse pace,
/// sleeping until the next frame is due).
fn drive_sender(run: &Run, mut send: impl FnMut(u64), mut receive_reply: impl FnMut() -> u64) {
    let mut next = Instant::now();
    for _ in 0..run.total() {
        if let Some(pace) = run.transport.pace() {
            let now = Instant::now();
            if next > now {
                std::thread::sleep(next - now);
            }
            next = Instant::now() + pace;
        }
        let stamp = monotonic_ns();
        send(stamp);
        let echoed = receive_reply();
        assert_eq!(echoed, stamp, "the reply answers the frame just sent");
    }
}

/// The receiver: takes a frame, records `now - stamp` (after the warm-up), replies, repeats.
fn drive_receiver(
    run: &Run,
    mut receive: impl FnMut() -> u64,
    mut reply: impl FnMut(u64),
) -> Histogram<u64> {
    let mut histogram =
        Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).expect("valid histogram bounds");
    for i in 0..run.total() {
        let stamp = receive();
        let now = monotonic_ns();
        if i >= run.warmup {
            histogram.saturating_record(now.saturating_sub(stamp).max(1));
        }
        reply(stamp);
    }
    histogram
}

/// Spins until `poll` gives a value; panics when nothing came for [`TIMEOUT`]. The clock is
/// read only every 2^16 empty polls, so spinning costs one poll per iteration. No
/// `spin_loop()` hint: the PAUSE it emits would add tens of nanoseconds to every detection,
/// there is no SMT sibling to yield to, and KVM may deschedule a vCPU that loops on PAUSE.
fn spin<T>(mut poll: impl FnMut() -> Option<T>) -> T {
    let mut deadline = None;
    let mut spins: u32 = 0;
    loop {
        if let Some(v) = poll() {
            return v;
        }
        spins = spins.wrapping_add(1);
        if spins % 65_536 == 0 {
            let deadline = *deadline.get_or_insert_with(|| Instant::now() + TIMEOUT);
            assert!(
                Instant::now() < deadline,
                "nothing for {TIMEOUT:?}: peer gone"
            );
        }
    }
}

/// Tells the parent that the receiver is listening, with what the sender needs to reach it.
fn announce_ready(info: &str) {
    println!("ready {info}");
}

fn stamp_of(bytes: &[u8]) -> u64 {
    let mut stamp = [0u8; 8];
    stamp.copy_from_slice(&bytes[..8]);
    u64::from_le_bytes(stamp)
}

// ---------------------------------------------------------------------------------------------
// 1 and 2: iceoryx2 publish-subscribe, event-driven or polling
// ---------------------------------------------------------------------------------------------

/// A fixed-size iceoryx2 payload: the send time and `FILL` bytes. The stamp is a byte array so
/// the type has no padding and exactly the size it is named after.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
struct StampedFrame<const FILL: usize> {
    /// CLOCK_MONOTONIC nanoseconds when the sender sent the frame, little endian.
    stamp_ns: [u8; 8],
    fill: [u8; FILL],
}

/// 64 B, also the reply of every transport.
type Frame64 = StampedFrame<{ REPLY_SIZE - 8 }>;
/// The largest STANAG frame.
type FrameStanag = StampedFrame<{ MAX_FRAME_LEN - 8 }>;
/// The full waypoint list.
type FrameWaypointList = StampedFrame<{ WAYPOINT_LIST_SIZE - 8 }>;

const _: () = assert!(size_of::<Frame64>() == 64);
const _: () = assert!(size_of::<FrameStanag>() == MAX_FRAME_LEN);
const _: () = assert!(size_of::<FrameWaypointList>() == WAYPOINT_LIST_SIZE);

trait Stamped: std::fmt::Debug + Copy + ZeroCopySend + 'static {
    fn zeroed() -> Self;
    fn stamp(&self) -> u64;
    fn set_stamp(&mut self, ns: u64);
}

impl<const FILL: usize> Stamped for StampedFrame<FILL> {
    fn zeroed() -> Self {
        Self {
            stamp_ns: [0; 8],
            fill: [0; FILL],
        }
    }

    fn stamp(&self) -> u64 {
        u64::from_le_bytes(self.stamp_ns)
    }

    fn set_stamp(&mut self, ns: u64) {
        self.stamp_ns = ns.to_le_bytes();
    }
}

type S = ipc::Service;

/// One side of an iceoryx2 ping-pong through the shipping IPC code
/// (`missionlink_partitions::ipc`): frames go out on the service of `fcc/link/uplink` or
/// `fcc/link/downlink` (the frame queues' QoS) under a prefix of the run, replies on the other.
struct Iox2End<Out: Stamped, In: Stamped> {
    publisher: Publisher<S, Out>,
    subscriber: Subscriber<S, In>,
    event: bool,
    /// Dropped last: the node owns the ports' resources.
    _ipc: Ipc<S>,
}

impl<Out: Stamped, In: Stamped> Iox2End<Out, In> {
    fn open(run: &Run, node_name: &str, out: FccService, input: FccService, event: bool) -> Self {
        let prefix = format!("missionlink-latency-{}", run.id);
        let ipc = Ipc::<S>::open(node_name, &prefix).expect("iceoryx2 node");
        Self {
            publisher: ipc.publisher(out).expect("publisher"),
            subscriber: ipc.subscriber(input).expect("subscriber"),
            event,
            _ipc: ipc,
        }
    }

    /// Runs `f` with the partitions' WaitSet, attached to the subscriber's listener when
    /// event-driven (polling never waits in it).
    fn with_waitset<R>(&self, f: impl FnOnce(&WaitSet<S>) -> R) -> R {
        let waitset = runtime::waitset::<S>().expect("waitset");
        let _guard = self.event.then(|| {
            waitset
                .attach_notification(self.subscriber.listener())
                .expect("attach")
        });
        f(&waitset)
    }

    /// Copies `value` into a loaned sample and sends it; event-driven, notifies too (what every
    /// partition does); polling, only publishes.
    fn send(&self, value: &Out) {
        if self.event {
            self.publisher.send(value).expect("send");
        } else {
            self.publisher.publish(value).expect("publish");
        }
    }

    /// The stamp of the next sample, read in place: event-driven, as the partitions take their
    /// frames (`take_all`: data first, then the drain, then a second look) sleeping in
    /// `waitset` until notified; polling, spinning on the subscriber.
    fn receive(&self, waitset: &WaitSet<S>) -> u64 {
        let take = || {
            let mut stamp = None;
            self.subscriber
                .take_one(|sample| stamp = Some(sample.stamp()));
            stamp
        };
        if !self.event {
            return spin(take);
        }
        let control = Control::new();
        let mut deadline = None;
        loop {
            let mut stamp = None;
            self.subscriber
                .take_all(|sample| stamp = Some(sample.stamp()));
            if let Some(stamp) = stamp {
                return stamp;
            }
            let deadline = *deadline.get_or_insert_with(|| Instant::now() + TIMEOUT);
            assert!(
                Instant::now() < deadline,
                "nothing for {TIMEOUT:?}: peer gone"
            );
            control.wait(waitset, false, TIMEOUT).expect("wait");
        }
    }
}

fn iox2_sender<F: Stamped>(run: &Run, event: bool) {
    let end = Iox2End::<F, Frame64>::open(
        run,
        "latency-sender",
        FccService::Uplink,
        FccService::Downlink,
        event,
    );
    let mut frame = F::zeroed();
    end.with_waitset(|waitset| {
        drive_sender(
            run,
            |stamp| {
                frame.set_stamp(stamp);
                end.send(&frame);
            },
            || end.receive(waitset),
        );
    });
}

fn iox2_receiver<F: Stamped>(run: &Run, event: bool) -> Histogram<u64> {
    let end = Iox2End::<Frame64, F>::open(
        run,
        "latency-receiver",
        FccService::Downlink,
        FccService::Uplink,
        event,
    );
    let mut reply = Frame64::zeroed();
    end.with_waitset(|waitset| {
        announce_ready("");
        drive_receiver(
            run,
            || end.receive(waitset),
            |stamp| {
                reply.set_stamp(stamp);
                end.send(&reply);
            },
        )
    })
}

/// Runs the iceoryx2 side `role` with the frame type of the run's size.
fn iox2(run: &Run, role: Role, event: bool) -> Option<Histogram<u64>> {
    fn with<F: Stamped>(run: &Run, role: Role, event: bool) -> Option<Histogram<u64>> {
        match role {
            Role::Sender => {
                iox2_sender::<F>(run, event);
                None
            }
            Role::Receiver => Some(iox2_receiver::<F>(run, event)),
        }
    }
    match run.size {
        s if s == size_of::<Frame64>() => with::<Frame64>(run, role, event),
        s if s == size_of::<FrameStanag>() => with::<FrameStanag>(run, role, event),
        s if s == size_of::<FrameWaypointList>() => with::<FrameWaypointList>(run, role, event),
        other => panic!("no iceoryx2 frame type of {other} B"),
    }
}

// ---------------------------------------------------------------------------------------------
// The partitions' loop: `runtime::run_loop` with the idle strategy of the row
// ---------------------------------------------------------------------------------------------

/// The configuration of both ends of a partition-loop row: the defaults (heartbeat, reports,
/// each partition's idle strategy) with the run's prefix; a row of one idle strategy sets it
/// for every partition.
fn partition_config(run: &Run) -> Config {
    let mut config = Config::default();
    config.ipc.service_prefix = format!("missionlink-latency-{}", run.id);
    if let Some(idle) = run.transport.idle() {
        config.ipc.idle = IdlePerPartition::all(idle);
    }
    config
}

/// The longest a partition-loop end sleeps between two looks at its peer.
const LOOP_TIMEOUT: Duration = Duration::from_secs(1);

/// The sending end as voting-monitoring runs it: `run_loop` as that partition (its heartbeat
/// and idle strategy), publishing a frame on the uplink service whenever the previous one was
/// answered on the downlink service (at the sparse pace, after the pause).
fn partition_sender<F: Stamped>(run: &Run) {
    let config = partition_config(run);
    let ipc = Ipc::<S>::open("latency-sender", &config.ipc.service_prefix).expect("node");
    let publisher = ipc.publisher::<F>(FccService::Uplink).expect("publisher");
    let replies = ipc
        .subscriber::<Frame64>(FccService::Downlink)
        .expect("subscriber");
    let control = Control::new();
    let mut frame = F::zeroed();
    let mut sent = 0;
    let mut outstanding: Option<(u64, Instant)> = None;
    let mut next = Instant::now();
    let wake = Wake {
        on: &[replies.listener()],
        pending: &[&replies],
        every: None,
        sockets: false,
        first_timeout: Duration::ZERO,
    };
    runtime::run_loop::<S>(
        voting_monitoring::NAME,
        Partition::VotingMonitoring,
        &ipc,
        &config,
        &control,
        wake,
        |_| {
            replies.take_all(|reply| {
                let (stamp, _) = outstanding.take().expect("a reply to a frame sent");
                assert_eq!(
                    reply.stamp(),
                    stamp,
                    "the reply answers the frame just sent"
                );
            });
            if let Some((_, at)) = outstanding {
                assert!(
                    at.elapsed() < TIMEOUT,
                    "no reply for {TIMEOUT:?}: peer gone"
                );
                return Ok(LOOP_TIMEOUT);
            }
            if sent == run.total() {
                control.stop();
                return Ok(Duration::ZERO);
            }
            let now = Instant::now();
            if let Some(pace) = run.transport.pace() {
                if next > now {
                    return Ok(next - now);
                }
                next = now + pace;
            }
            let stamp = monotonic_ns();
            frame.set_stamp(stamp);
            publisher.send(&frame).expect("send");
            outstanding = Some((stamp, now));
            sent += 1;
            Ok(LOOP_TIMEOUT)
        },
    )
    .expect("the sender's loop");
}

/// The receiving end as mission data handling runs it: `run_loop` as that partition, taking
/// the frames of the uplink service as it does (`take_all`, the stamp read in place) and
/// answering each on the downlink service.
fn partition_receiver<F: Stamped>(run: &Run) -> Histogram<u64> {
    let config = partition_config(run);
    let ipc = Ipc::<S>::open("latency-receiver", &config.ipc.service_prefix).expect("node");
    let frames = ipc.subscriber::<F>(FccService::Uplink).expect("subscriber");
    let publisher = ipc
        .publisher::<Frame64>(FccService::Downlink)
        .expect("publisher");
    let control = Control::new();
    let mut histogram =
        Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).expect("valid histogram bounds");
    let mut reply = Frame64::zeroed();
    let mut received = 0;
    let mut last = Instant::now();
    let wake = Wake {
        on: &[frames.listener()],
        pending: &[&frames],
        every: None,
        sockets: false,
        first_timeout: LOOP_TIMEOUT,
    };
    announce_ready("");
    runtime::run_loop::<S>(
        mission_data_handling::NAME,
        Partition::MissionDataHandling,
        &ipc,
        &config,
        &control,
        wake,
        |_| {
            let taken = frames.take_all(|sample| {
                let now = monotonic_ns();
                let stamp = sample.stamp();
                if received >= run.warmup {
                    histogram.saturating_record(now.saturating_sub(stamp).max(1));
                }
                received += 1;
                reply.set_stamp(stamp);
                publisher.send(&reply).expect("reply");
            });
            if taken > 0 {
                last = Instant::now();
            } else {
                assert!(
                    last.elapsed() < TIMEOUT,
                    "nothing for {TIMEOUT:?}: peer gone"
                );
            }
            if received == run.total() {
                control.stop();
            }
            Ok(LOOP_TIMEOUT)
        },
    )
    .expect("the receiver's loop");
    histogram
}

// ---------------------------------------------------------------------------------------------
// iceoryx2's own publish-subscribe benchmark setup: busy-wait, history 0, buffer 1
// ---------------------------------------------------------------------------------------------

/// One end of a ping-pong as iceoryx2's publish-subscribe benchmark sets it up: a service per
/// direction with history 0, a subscriber buffer of 1, one publisher and one subscriber, and
/// both sides spinning on `receive`; no event service, no notification.
struct OwnEnd<Out: Stamped, In: Stamped> {
    publisher: iceoryx2::port::publisher::Publisher<S, Out, ()>,
    subscriber: iceoryx2::port::subscriber::Subscriber<S, In, ()>,
    _node: Node<S>,
}

impl<Out: Stamped, In: Stamped> OwnEnd<Out, In> {
    fn open(run: &Run, out: &str, input: &str) -> Self {
        let node = NodeBuilder::new().create::<S>().expect("node");
        let service = |name: &str| -> ServiceName {
            format!("missionlink-latency-{}/{name}", run.id)
                .as_str()
                .try_into()
                .expect("service name")
        };
        let publisher = node
            .service_builder(&service(out))
            .publish_subscribe::<Out>()
            .history_size(0)
            .subscriber_max_buffer_size(1)
            .max_publishers(1)
            .max_subscribers(1)
            .open_or_create()
            .expect("service")
            .publisher_builder()
            .create()
            .expect("publisher");
        let subscriber = node
            .service_builder(&service(input))
            .publish_subscribe::<In>()
            .history_size(0)
            .subscriber_max_buffer_size(1)
            .max_publishers(1)
            .max_subscribers(1)
            .open_or_create()
            .expect("service")
            .subscriber_builder()
            .create()
            .expect("subscriber");
        Self {
            publisher,
            subscriber,
            _node: node,
        }
    }

    fn send(&self, value: &Out) {
        self.publisher
            .loan_uninit()
            .expect("loan")
            .write_payload(*value)
            .send()
            .expect("send");
    }

    fn receive(&self) -> u64 {
        spin(|| {
            self.subscriber
                .receive()
                .expect("receive")
                .map(|sample| sample.stamp())
        })
    }
}

fn own_sender<F: Stamped>(run: &Run) {
    let end = OwnEnd::<F, Frame64>::open(run, "a2b", "b2a");
    let mut frame = F::zeroed();
    drive_sender(
        run,
        |stamp| {
            frame.set_stamp(stamp);
            end.send(&frame);
        },
        || end.receive(),
    );
}

fn own_receiver<F: Stamped>(run: &Run) -> Histogram<u64> {
    let end = OwnEnd::<Frame64, F>::open(run, "b2a", "a2b");
    let mut reply = Frame64::zeroed();
    announce_ready("");
    drive_receiver(
        run,
        || end.receive(),
        |stamp| {
            reply.set_stamp(stamp);
            end.send(&reply);
        },
    )
}

/// Runs a partition-loop end or an end of iceoryx2's own setup (`own`), with the frame type
/// of the run's size.
fn typed(run: &Run, role: Role, own: bool) -> Option<Histogram<u64>> {
    fn with<F: Stamped>(run: &Run, role: Role, own: bool) -> Option<Histogram<u64>> {
        match (role, own) {
            (Role::Sender, false) => {
                partition_sender::<F>(run);
                None
            }
            (Role::Sender, true) => {
                own_sender::<F>(run);
                None
            }
            (Role::Receiver, false) => Some(partition_receiver::<F>(run)),
            (Role::Receiver, true) => Some(own_receiver::<F>(run)),
        }
    }
    match run.size {
        s if s == size_of::<Frame64>() => with::<Frame64>(run, role, own),
        s if s == size_of::<FrameStanag>() => with::<FrameStanag>(run, role, own),
        s if s == size_of::<FrameWaypointList>() => with::<FrameWaypointList>(run, role, own),
        other => panic!("no iceoryx2 frame type of {other} B"),
    }
}

// ---------------------------------------------------------------------------------------------
// 3 and 4: datagram sockets
// ---------------------------------------------------------------------------------------------

/// What the Unix domain and the UDP socket share: both sides of a datagram transport are written
/// once, over this.
trait Datagram {
    type Addr;
    fn send(&self, buf: &[u8]) -> std::io::Result<usize>;
    fn recv(&self, buf: &mut [u8]) -> std::io::Result<usize>;
    fn recv_from(&self, buf: &mut [u8]) -> std::io::Result<(usize, Self::Addr)>;
    fn connect_to(&self, peer: &Self::Addr) -> std::io::Result<()>;
    fn set_read_timeout(&self, timeout: Option<Duration>) -> std::io::Result<()>;
}

impl Datagram for UnixDatagram {
    type Addr = SocketAddr;
    fn send(&self, buf: &[u8]) -> std::io::Result<usize> {
        UnixDatagram::send(self, buf)
    }
    fn recv(&self, buf: &mut [u8]) -> std::io::Result<usize> {
        UnixDatagram::recv(self, buf)
    }
    fn recv_from(&self, buf: &mut [u8]) -> std::io::Result<(usize, SocketAddr)> {
        UnixDatagram::recv_from(self, buf)
    }
    fn connect_to(&self, peer: &SocketAddr) -> std::io::Result<()> {
        self.connect_addr(peer)
    }
    fn set_read_timeout(&self, timeout: Option<Duration>) -> std::io::Result<()> {
        UnixDatagram::set_read_timeout(self, timeout)
    }
}

impl Datagram for UdpSocket {
    type Addr = std::net::SocketAddr;
    fn send(&self, buf: &[u8]) -> std::io::Result<usize> {
        UdpSocket::send(self, buf)
    }
    fn recv(&self, buf: &mut [u8]) -> std::io::Result<usize> {
        UdpSocket::recv(self, buf)
    }
    fn recv_from(&self, buf: &mut [u8]) -> std::io::Result<(usize, std::net::SocketAddr)> {
        UdpSocket::recv_from(self, buf)
    }
    fn connect_to(&self, peer: &std::net::SocketAddr) -> std::io::Result<()> {
        self.connect(peer)
    }
    fn set_read_timeout(&self, timeout: Option<Duration>) -> std::io::Result<()> {
        UdpSocket::set_read_timeout(self, timeout)
    }
}

/// The sending side over `socket`, connected to the receiver: the stamp in the first 8 bytes
/// of a frame of the run's size, the reply's stamp back.
fn datagram_sender(run: &Run, socket: &impl Datagram) {
    socket.set_read_timeout(Some(TIMEOUT)).expect("timeout");
    let mut frame = vec![0u8; run.size];
    let mut reply = [0u8; REPLY_SIZE];
    drive_sender(
        run,
        |stamp| {
            frame[..8].copy_from_slice(&stamp.to_le_bytes());
            socket.send(&frame).expect("send");
        },
        || {
            socket.recv(&mut reply).expect("reply");
            stamp_of(&reply)
        },
    );
}

/// The receiving side over `socket`, bound and announced: replies go to whoever sent the first
/// frame.
fn datagram_receiver(run: &Run, socket: &impl Datagram) -> Histogram<u64> {
    socket.set_read_timeout(Some(TIMEOUT)).expect("timeout");
    let mut frame = vec![0u8; run.size];
    let mut reply = [0u8; REPLY_SIZE];
    let mut connected = false;
    drive_receiver(
        run,
        || {
            let (n, from) = socket.recv_from(&mut frame).expect("receive");
            assert_eq!(n, run.size, "a whole frame");
            if !connected {
                socket.connect_to(&from).expect("connect");
                connected = true;
            }
            stamp_of(&frame)
        },
        |stamp| {
            reply[..8].copy_from_slice(&stamp.to_le_bytes());
            socket.send(&reply).expect("reply");
        },
    )
}

// 3: Unix domain datagram socket (abstract addresses named after the run).

fn uds_address(run: &Run, side: &str) -> SocketAddr {
    SocketAddr::from_abstract_name(format!("missionlink-latency/{}/{side}", run.id))
        .expect("abstract socket address")
}

fn uds_sender(run: &Run) {
    let socket = UnixDatagram::bind_addr(&uds_address(run, "sender")).expect("bind");
    socket
        .connect_addr(&uds_address(run, "receiver"))
        .expect("connect");
    datagram_sender(run, &socket);
}

fn uds_receiver(run: &Run) -> Histogram<u64> {
    let socket = UnixDatagram::bind_addr(&uds_address(run, "receiver")).expect("bind");
    announce_ready("");
    datagram_receiver(run, &socket)
}

// 4: UDP over loopback (the receiver announces the port the system chose).

fn udp_sender(run: &Run, receiver_port: &str) {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    socket
        .connect(format!("127.0.0.1:{receiver_port}"))
        .expect("connect");
    datagram_sender(run, &socket);
}

fn udp_receiver(run: &Run) -> Histogram<u64> {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    announce_ready(&socket.local_addr().expect("address").port().to_string());
    datagram_receiver(run, &socket)
}

// ---------------------------------------------------------------------------------------------
// 5: the floor, one cache line each way
// ---------------------------------------------------------------------------------------------

/// Two `AtomicU64`s in a file mapped shared by both processes: `ping` (sender to receiver) and
/// `pong` (back), 128 bytes apart so that they never share a cache line or its prefetch pair.
struct SharedLines {
    ptr: *mut core::ffi::c_void,
    path: PathBuf,
    owner: bool,
}

const MAP_LEN: usize = 4096;
const LINE_STRIDE: usize = 128;

impl SharedLines {
    fn path(run: &Run) -> PathBuf {
        let dir = Path::new("/dev/shm");
        let dir = if dir.is_dir() {
            dir.to_path_buf()
        } else {
            std::env::temp_dir()
        };
        dir.join(format!("missionlink-latency-{}", run.id))
    }

    /// Creates (the receiver) or opens (the sender) the file and maps it.
    fn map(run: &Run, create: bool) -> Self {
        let path = Self::path(run);
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(create)
            .truncate(create)
            .open(&path)
            .expect("shared-memory file");
        file.set_len(MAP_LEN as u64).expect("size the file");
        // SAFETY: a fresh shared mapping chosen by the kernel (null hint), of a file that is
        // MAP_LEN bytes long; it aliases no Rust object. The mapping outlives the file handle.
        let ptr = unsafe {
            rustix::mm::mmap(
                core::ptr::null_mut(),
                MAP_LEN,
                rustix::mm::ProtFlags::READ | rustix::mm::ProtFlags::WRITE,
                rustix::mm::MapFlags::SHARED,
                &file,
                0,
            )
        }
        .expect("map the file");
        Self {
            ptr,
            path,
            owner: create,
        }
    }

    fn line(&self, index: usize) -> &AtomicU64 {
        assert!((index + 1) * LINE_STRIDE <= MAP_LEN);
        // SAFETY: the mapping is page aligned and MAP_LEN bytes long, so the offset is inside it
        // and 8-byte aligned; it stays mapped while `self` lives, which bounds the reference.
        // Both processes access these bytes only through atomics, which is what AtomicU64
        // requires of memory shared with others.
        unsafe {
            &*self
                .ptr
                .cast::<u8>()
                .add(index * LINE_STRIDE)
                .cast::<AtomicU64>()
        }
    }

    fn ping(&self) -> &AtomicU64 {
        self.line(0)
    }

    fn pong(&self) -> &AtomicU64 {
        self.line(1)
    }
}

impl Drop for SharedLines {
    fn drop(&mut self) {
        // SAFETY: `ptr` is the mapping of MAP_LEN bytes made in `map`, unmapped only here; no
        // reference from `line` outlives `self`.
        if let Err(e) = unsafe { rustix::mm::munmap(self.ptr, MAP_LEN) } {
            eprintln!("munmap: {e}");
        }
        if self.owner {
            std::fs::remove_file(&self.path).ok();
        }
    }
}

/// Spins until `line` holds something other than `*last`, and returns it.
fn spin_for_change(line: &AtomicU64, last: &mut u64) -> u64 {
    let seen = *last;
    *last = spin(|| {
        let v = line.load(Ordering::Acquire);
        (v != seen).then_some(v)
    });
    *last
}

fn shm_sender(run: &Run) {
    let lines = SharedLines::map(run, false);
    let mut last_pong = lines.pong().load(Ordering::Acquire);
    drive_sender(
        run,
        |stamp| lines.ping().store(stamp, Ordering::Release),
        || spin_for_change(lines.pong(), &mut last_pong),
    );
}

fn shm_receiver(run: &Run) -> Histogram<u64> {
    let lines = SharedLines::map(run, true);
    let mut last_ping = 0;
    announce_ready("");
    drive_receiver(
        run,
        || spin_for_change(lines.ping(), &mut last_ping),
        |stamp| lines.pong().store(stamp, Ordering::Release),
    )
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

/// CPU time of the whole machine from /proc/stat, in clock ticks: (busy, total). Busy counts
/// everything but idle and I/O wait, including time stolen by the hypervisor.
fn machine_ticks() -> (u64, u64) {
    let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
    let fields: Vec<u64> = stat
        .lines()
        .next()
        .unwrap_or_default()
        .split_whitespace()
        .skip(1)
        .take(8)
        .filter_map(|v| v.parse().ok())
        .collect();
    let total: u64 = fields.iter().sum();
    let idle = fields.get(3).copied().unwrap_or(0) + fields.get(4).copied().unwrap_or(0);
    (total.saturating_sub(idle), total)
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
    let histogram = match run.transport {
        Transport::Iox2Event => iox2(run, Role::Receiver, true).expect("histogram"),
        Transport::Iox2Poll => iox2(run, Role::Receiver, false).expect("histogram"),
        Transport::Partition
        | Transport::PartitionBlock
        | Transport::PartitionBackoff
        | Transport::PartitionDoorbell
        | Transport::PartitionSparse
        | Transport::PartitionBlockSparse
        | Transport::PartitionBackoffSparse
        | Transport::PartitionDoorbellSparse => {
            typed(run, Role::Receiver, false).expect("histogram")
        }
        Transport::Iox2OwnPubsub => typed(run, Role::Receiver, true).expect("histogram"),
        Transport::Uds | Transport::UdsSparse => uds_receiver(run),
        Transport::Udp => udp_receiver(run),
        Transport::ShmFloor => shm_receiver(run),
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
    let (start, machine_start) = (Usage::now(), machine_ticks());
    match run.transport {
        Transport::Iox2Event => {
            iox2(run, Role::Sender, true);
        }
        Transport::Iox2Poll => {
            iox2(run, Role::Sender, false);
        }
        Transport::Partition
        | Transport::PartitionBlock
        | Transport::PartitionBackoff
        | Transport::PartitionDoorbell
        | Transport::PartitionSparse
        | Transport::PartitionBlockSparse
        | Transport::PartitionBackoffSparse
        | Transport::PartitionDoorbellSparse => {
            typed(run, Role::Sender, false);
        }
        Transport::Iox2OwnPubsub => {
            typed(run, Role::Sender, true);
        }
        Transport::Uds | Transport::UdsSparse => uds_sender(run),
        Transport::Udp => udp_sender(run, &info),
        Transport::ShmFloor => shm_sender(run),
    }
    let sender = Usage::now().since(start);
    let machine_end = machine_ticks();
    let mut result: Value = serde_json::from_str(&next("result")).expect("the receiver's JSON");
    let status = child.0.wait().expect("the receiver's exit");
    assert!(status.success(), "the receiver failed: {status}");
    result["transport"] = json!(run.transport.arg());
    result["label"] = json!(run.transport.label());
    result["payload_bytes"] = json!(run.size);
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

// ---------------------------------------------------------------------------------------------
// Output: tables, JSON, SVG
// ---------------------------------------------------------------------------------------------

fn us(result: &Value, key: &str) -> f64 {
    result[key].as_f64().unwrap_or(f64::NAN) / 1000.0
}

/// `value / reference` with two significant digits (at least two decimals).
fn ratio(value: f64, reference: f64) -> String {
    let r = value / reference;
    if !(r.is_finite() && r > 0.0) {
        return "-".to_owned();
    }
    let decimals = (1.0 - r.log10().floor()).max(2.0) as usize;
    format!("{r:.decimals$}x")
}

fn print_table(description: &str, results: &[&Value]) {
    println!("\nPayload {description}");
    let reference = results
        .iter()
        .find(|r| r["transport"] == Transport::Iox2Event.arg())
        .copied();
    print_rows("transport", "label", results, reference, "ev");
    for (name, value, reference) in goal_ratios(results) {
        println!(
            "  {name}: {value:.2} / {reference:.2} µs = {}",
            ratio(value, reference)
        );
    }
}

/// The ratios of p50 the goals name, for the rows present: (what, value µs, reference µs).
fn goal_ratios(results: &[&Value]) -> Vec<(String, f64, f64)> {
    let p50 = |t: Transport| {
        results
            .iter()
            .find(|r| r["transport"] == t.arg())
            .map(|r| us(r, "p50_ns"))
    };
    [
        (Transport::Partition, Transport::Uds),
        (Transport::PartitionBlock, Transport::Uds),
        (Transport::PartitionBackoff, Transport::Uds),
        (Transport::PartitionDoorbell, Transport::Uds),
        (Transport::PartitionSparse, Transport::UdsSparse),
        (Transport::PartitionBlockSparse, Transport::UdsSparse),
        (Transport::PartitionBackoffSparse, Transport::UdsSparse),
        (Transport::PartitionDoorbellSparse, Transport::UdsSparse),
        (Transport::Iox2Poll, Transport::Iox2OwnPubsub),
    ]
    .into_iter()
    .filter_map(|(a, b)| Some((format!("p50 {} / {}", a.arg(), b.arg()), p50(a)?, p50(b)?)))
    .collect()
}

/// One line per result, named by its `label_key`, with its percentiles and the ratios of its
/// p50 and p99.9 to `reference`'s (the columns `p50/<reference_name>`, `p99.9/<...>`): the
/// table of the transports and the table of the load cases alike.
fn print_rows(
    first_column: &str,
    label_key: &str,
    results: &[&Value],
    reference: Option<&Value>,
    reference_name: &str,
) {
    println!(
        "{:<30} {:>8} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>9} {:>7}",
        first_column,
        "samples",
        "p50 µs",
        "p99 µs",
        "p99.9 µs",
        "max µs",
        format!("p50/{reference_name}"),
        format!("p99.9/{reference_name}"),
        "preempt",
        "others"
    );
    let (p50_ref, p999_ref) = reference.map_or((0.0, 0.0), |r| (us(r, "p50_ns"), us(r, "p999_ns")));
    for r in results {
        println!(
            "{:<30} {:>8} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>10} {:>10} {:>9} {:>6.0}%",
            r[label_key].as_str().unwrap_or_default(),
            r["samples"].as_u64().unwrap_or(0),
            us(r, "p50_ns"),
            us(r, "p99_ns"),
            us(r, "p999_ns"),
            us(r, "max_ns"),
            ratio(us(r, "p50_ns"), p50_ref),
            ratio(us(r, "p999_ns"), p999_ref),
            format!(
                "{}/{}",
                r["sender_involuntary_switches"], r["receiver_involuntary_switches"]
            ),
            r["others_cpu_percent"].as_f64().unwrap_or(f64::NAN),
        );
    }
}

/// The plot: per payload size a group of bar triples (p50, p99, p99.9) per transport, on a
/// logarithmic µs axis.
fn svg(results: &[Value], subtitle: &str) -> String {
    const PERCENTILES: [(&str, &str, &str); 3] = [
        ("p50_ns", "p50", "#4c78a8"),
        ("p99_ns", "p99", "#f58518"),
        ("p999_ns", "p99.9", "#e45756"),
    ];
    const BAR: f64 = 10.0;
    const CLUSTER: f64 = 3.0 * BAR + 14.0;
    const GROUP_GAP: f64 = 40.0;
    const LEFT: f64 = 80.0;
    const TOP: f64 = 84.0;
    const PLOT_H: f64 = 360.0;
    let sizes = sizes();
    let group_w = CLUSTER * Transport::ALL.len() as f64;
    let width = LEFT + sizes.len() as f64 * (group_w + GROUP_GAP) + 20.0;
    let height = TOP + PLOT_H + 180.0;
    let bottom = TOP + PLOT_H;

    let values: Vec<f64> = results
        .iter()
        .flat_map(|r| PERCENTILES.iter().map(move |(k, _, _)| us(r, k)))
        .collect();
    let axis = LogAxis::new(values.iter().copied(), bottom, PLOT_H);
    let y = |v: f64| axis.y(v);

    let mut s = log_axis::begin(
        width,
        height,
        LEFT,
        24.0,
        "One-way frame latency between two processes",
    );
    let w = &mut s;
    let _ = writeln!(
        w,
        r##"<text x="{LEFT}" y="44" fill="#555">{subtitle}</text>"##
    );
    // Legend.
    for (i, (_, name, colour)) in PERCENTILES.iter().enumerate() {
        let x = width - 260.0 + i as f64 * 80.0;
        let _ = writeln!(
            w,
            r#"<rect x="{x}" y="56" width="12" height="12" fill="{colour}"/><text x="{}" y="66">{name}</text>"#,
            x + 16.0
        );
    }
    // Decades of the µs axis, with faint lines at 2 and 5.
    axis.grid(w, LEFT, width - 20.0, "µs");
    let _ = writeln!(
        w,
        r#"<text transform="translate(20,{}) rotate(-90)" text-anchor="middle">latency (µs)</text>"#,
        TOP + PLOT_H / 2.0
    );
    // Bars.
    for (g, (size, description)) in sizes.iter().enumerate() {
        let gx = LEFT + 10.0 + g as f64 * (group_w + GROUP_GAP);
        for (t, transport) in Transport::ALL.iter().enumerate() {
            let Some(r) = results
                .iter()
                .find(|r| r["transport"] == transport.arg() && r["payload_bytes"] == json!(size))
            else {
                continue;
            };
            let cx = gx + t as f64 * CLUSTER;
            for (i, (key, name, colour)) in PERCENTILES.iter().enumerate() {
                let v = us(r, key);
                let top = y(v);
                let _ = writeln!(
                    w,
                    r#"<rect x="{:.1}" y="{top:.1}" width="{BAR}" height="{:.1}" fill="{colour}"><title>{}, {size} B: {name} = {v:.2} µs</title></rect>"#,
                    cx + i as f64 * BAR,
                    bottom - top,
                    transport.label()
                );
            }
            let _ = writeln!(
                w,
                r#"<text transform="translate({:.1},{:.1}) rotate(-45)" text-anchor="end">{}</text>"#,
                cx + 1.5 * BAR,
                bottom + 12.0,
                transport.label()
            );
        }
        let short = description.split(',').next().unwrap_or(description);
        let what = description.split_once(", ").map_or("", |(_, w)| w);
        let mid = gx + group_w / 2.0 - 7.0;
        let _ = writeln!(
            w,
            r##"<text x="{mid:.1}" y="{:.1}" text-anchor="middle" font-weight="bold">{short}</text><text x="{mid:.1}" y="{:.1}" text-anchor="middle" fill="#555">{}</text>"##,
            bottom + 150.0,
            bottom + 166.0,
            what.replace(" (WaypointListPayload)", "")
        );
    }
    let _ = writeln!(
        w,
        r#"<line x1="{LEFT}" x2="{}" y1="{bottom}" y2="{bottom}" stroke="black"/>"#,
        width - 20.0
    );
    let _ = writeln!(w, "</svg>");
    s
}

/// `target/latency`: next to the bench binary (`<target>/release/deps/latency-*`), so that
/// `CARGO_TARGET_DIR` is followed.
fn output_dir() -> PathBuf {
    std::env::current_exe()
        .ok()
        .and_then(|exe| exe.ancestors().nth(3).map(Path::to_path_buf))
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"))
        .join("latency")
}

/// Writes `contents` to `name` in the [`output_dir`] (created if missing); the path.
fn write_output(name: &str, contents: &str) -> PathBuf {
    let dir = output_dir();
    std::fs::create_dir_all(&dir).expect("create the output directory");
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap_or_else(|e| panic!("write {name}: {e}"));
    path
}

// ---------------------------------------------------------------------------------------------
// Under CPU load (--load)
// ---------------------------------------------------------------------------------------------

/// Applies the real-time settings of `--load` to the calling thread and process, through the
/// partitions' own module, with `cpu` as the affinity; what it got (and the warnings of what
/// was not granted) for the results.
fn apply_realtime(side: &str, cpu: usize) -> Value {
    let settings = RealtimeSettings {
        cpus: vec![cpu],
        fifo_priority: FifoPriority::new(LOAD_FIFO_PRIORITY),
        lock_memory: true,
    };
    let applied = realtime::apply(&settings);
    let warnings: Vec<String> = applied.warnings.iter().map(ToString::to_string).collect();
    for w in &warnings {
        eprintln!("{side}: real-time setting not granted in full: {w}");
    }
    json!({ "got": applied.got.to_string(), "warnings": warnings })
}

/// A hog: pins itself to `cpu`, says it is ready, and spins until it is killed or its parent,
/// the bench, is gone.
fn hog_main(cpu: Option<usize>) {
    if let Some(cpu) = cpu {
        if let Err(e) = pin_to(cpu) {
            eprintln!("hog: cannot pin to CPU {cpu}: {e}");
        }
    }
    let scheduling = realtime::observe().scheduling;
    assert_eq!(
        scheduling,
        Scheduling::Other,
        "a hog must run at default scheduling"
    );
    println!("ready");
    let parent = rustix::process::getppid();
    let mut x: u64 = 0;
    loop {
        for _ in 0..10_000_000 {
            x = std::hint::black_box(x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1));
        }
        if rustix::process::getppid() != parent {
            return;
        }
    }
}

/// The hogs of a case, one per CPU; killed when dropped (see [`ChildGuard`]), so a panic of
/// the bench leaves none behind.
struct Hogs {
    _guards: Vec<ChildGuard>,
}

impl Hogs {
    /// Starts a hog on each of `cpus` and waits until each is spinning.
    fn start(cpus: &[usize]) -> Self {
        let mut hogs = Vec::new();
        for &cpu in cpus {
            let mut command = Command::new(std::env::current_exe().expect("own executable"));
            command
                .args(["--role", "hog", "--cpu", &cpu.to_string()])
                .stdout(Stdio::piped());
            let mut hog = ChildGuard(command.spawn().expect("start a hog"));
            let stdout = hog.0.stdout.take().expect("piped stdout");
            // Pushed first, so that a hog that fails to start is killed with the others.
            hogs.push(hog);
            let mut line = String::new();
            BufReader::new(stdout)
                .read_line(&mut line)
                .expect("the hog's output");
            assert_eq!(line.trim(), "ready", "the hog on CPU {cpu} did not start");
        }
        Self { _guards: hogs }
    }
}

/// The cases of `--load`, in the order they run: the real-time one last, since the sender (this
/// process) keeps its settings.
const LOAD_CASES: [(&str, &str, bool, bool); 3] = [
    ("idle-default", "no load, default scheduling", false, false),
    ("load-default", "CPU hogs, default scheduling", true, false),
    ("load-realtime", "CPU hogs, real-time settings", true, true),
];

/// `--load`: the hop of the largest STANAG frame over iceoryx2 event-driven in the cases of
/// [`LOAD_CASES`].
fn load_main(transport: Transport, frames: u64, warmup: u64) {
    let allowed: Vec<usize> = rustix::thread::sched_getaffinity(None)
        .map(|set| {
            (0..rustix::thread::CpuSet::MAX_CPU)
                .filter(|&c| set.is_set(c))
                .collect()
        })
        .unwrap_or_default();
    let (sender_cpu, receiver_cpu) = cpu_pair().expect("two CPUs for the real-time case");
    let load_before = load_average();
    println!(
        "Partition-to-partition hop under CPU load: {} ({}), {MAX_FRAME_LEN} B frames, {frames} frames per case \
         after {warmup} warm-up frames, each sent after the previous one was answered. CPU hogs: \
         one busy process per CPU ({}), default scheduling. Real-time settings (the partitions' \
         realtime module): sender on CPU {sender_cpu}, receiver on CPU {receiver_cpu}, \
         SCHED_FIFO priority {LOAD_FIFO_PRIORITY}, memory locked; default scheduling: not \
         pinned. Load average before: {load_before}",
        transport.label(),
        transport.arg(),
        realtime::CpuList(&allowed)
    );
    let pid = std::process::id();
    let mut results = Vec::new();
    for (key, label, load, rt) in LOAD_CASES {
        let started = Instant::now();
        let hogs = load.then(|| Hogs::start(&allowed));
        let sender_realtime = if rt {
            apply_realtime("sender", sender_cpu)
        } else {
            Value::Null
        };
        let run = Run {
            transport,
            size: MAX_FRAME_LEN,
            frames,
            warmup,
            id: format!("{pid}-load-{key}"),
            realtime: rt,
        };
        let mut result = measure(&run, rt.then_some(receiver_cpu));
        drop(hogs);
        result["case"] = json!(key);
        result["case_label"] = json!(label);
        result["hogs"] = json!(if load { allowed.len() } else { 0 });
        result["sender_realtime"] = sender_realtime;
        eprintln!(
            "  {label:<30} p50 {:>9.2} µs  p99.9 {:>9.2} µs  ({:.1} s)",
            us(&result, "p50_ns"),
            us(&result, "p999_ns"),
            started.elapsed().as_secs_f64()
        );
        results.push(result);
    }
    print_load_table(&results);
    let load_after = load_average();
    println!("Load average after: {load_after}");

    let document = json!({
        "what": "one-way latency of the largest STANAG frame between two processes, without and with a CPU hog per CPU, default scheduling and real-time settings",
        "transport": transport.arg(),
        "frames": frames,
        "warmup": warmup,
        "payload_bytes": MAX_FRAME_LEN,
        "fifo_priority": LOAD_FIFO_PRIORITY,
        "sender_cpu_realtime": sender_cpu,
        "receiver_cpu_realtime": receiver_cpu,
        "load_average_before": load_before,
        "load_average_after": load_after,
        "goal_p999_us": LOAD_GOAL_P999.as_secs_f64() * 1e6,
        "results": results,
    });
    let path = write_output(
        "load.json",
        &serde_json::to_string_pretty(&document).expect("JSON"),
    );
    println!("Results: {}", path.display());
}

fn print_load_table(results: &[Value]) {
    println!();
    let rows: Vec<&Value> = results.iter().collect();
    let reference = results.iter().find(|r| r["case"] == "load-default");
    print_rows("case", "case_label", &rows, reference, "load");
    println!(
        "(µs; p50/load and p99.9/load: ratio to CPU hogs with default scheduling; preempt: \
         involuntary context switches of sender/receiver while measuring; others: CPU time used \
         by other processes meanwhile, the hogs included, in % of all CPUs)"
    );
    for r in results.iter().filter(|r| !r["sender_realtime"].is_null()) {
        for side in ["sender", "receiver"] {
            let got = &r[format!("{side}_realtime")];
            println!(
                "{side} with real-time settings: {}{}",
                got["got"].as_str().unwrap_or("unknown"),
                match got["warnings"].as_array() {
                    Some(warnings) if !warnings.is_empty() => format!(
                        "; NOT GRANTED IN FULL: {}",
                        warnings
                            .iter()
                            .filter_map(Value::as_str)
                            .collect::<Vec<_>>()
                            .join("; ")
                    ),
                    _ => String::new(),
                }
            );
        }
    }
    if let Some(r) = results.iter().find(|r| r["case"] == "load-realtime") {
        let p999 = us(r, "p999_ns");
        let goal = LOAD_GOAL_P999.as_secs_f64() * 1e6;
        println!(
            "Goal (BENCHMARKS.md section 7): under load with real-time settings p99.9 at most \
             {goal:.0} µs: {p999:.2} µs, {}",
            if p999 <= goal { "met" } else { "NOT met" }
        );
    }
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
            "--realtime" => args.realtime = true,
            // `cargo bench` adds it.
            "--bench" => {}
            other => {
                eprintln!(
                    "latency: ignoring `{other}` (options: --frames N, --warmup N, --load, \
                 --only T,T, --sizes N,N)"
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
         after {warmup} warm-up frames, each sent after the previous one was answered; {cpus}; \
         load average before: {load_before}"
    );
    let pid = std::process::id();
    let mut results = Vec::new();
    let wanted = |t: &Transport| args.only.as_ref().is_none_or(|only| only.contains(t));
    for (size, description) in sizes() {
        if args.sizes.as_ref().is_some_and(|s| !s.contains(&size)) {
            continue;
        }
        for transport in Transport::ALL.into_iter().filter(wanted) {
            // At the sparse pace a frame takes a millisecond: a tenth of the frames.
            let (frames, warmup) = match transport.pace() {
                Some(_) => ((frames / SPARSE_DIVISOR).max(1), warmup / SPARSE_DIVISOR),
                None => (frames, warmup),
            };
            let run = Run {
                transport,
                size,
                frames,
                warmup,
                id: format!("{pid}-{}-{size}", transport.arg()),
                realtime: false,
            };
            let started = Instant::now();
            let result = measure(&run, receiver_cpu);
            eprintln!(
                "  {:<27} {size:>6} B  p50 {:>8.2} µs  ({:.1} s)",
                transport.label(),
                us(&result, "p50_ns"),
                started.elapsed().as_secs_f64()
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
