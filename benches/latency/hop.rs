//! The hop: how one frame crosses from the sender process to the receiver over each transport
//! (iceoryx2 event-driven or polling, the partitions' own loop, iceoryx2's own benchmark set-up,
//! datagram sockets, the shared-memory floor), and the ping-pong measurement they all share.

use super::*;
use missionlink_interfaces::contracts::{FramePayload, Link};

/// The sender: stamps and sends a frame, waits for its reply, repeats (at the sparse pace,
/// sleeping until the next frame is due). For a row measured as iceoryx2 measures
/// (`Transport::loop_mean`), then [`LOOP_ROUND_TRIPS`] more round trips without a clock read
/// per sample, their mean one-way time kept for [`take_loop_mean_ns`].
pub(super) fn drive_sender(
    run: &Run,
    mut send: impl FnMut(u64),
    mut receive_reply: impl FnMut() -> u64,
) {
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
    if run.transport.loop_mean() {
        let start = Instant::now();
        for i in 0..LOOP_ROUND_TRIPS {
            send(i);
            receive_reply();
        }
        let one_way = start.elapsed().as_nanos() as f64 / (2.0 * LOOP_ROUND_TRIPS as f64);
        if let Ok(mut mean) = LOOP_MEAN_NS.lock() {
            *mean = Some(one_way);
        }
    }
}

/// Round trips of the loop measured as iceoryx2's own publish-subscribe benchmark measures: the
/// time of the whole loop over twice the round trips, no clock read per sample.
pub(super) const LOOP_ROUND_TRIPS: u64 = 100_000;

/// The mean one-way time of the last loop of [`drive_sender`], nanoseconds.
static LOOP_MEAN_NS: std::sync::Mutex<Option<f64>> = std::sync::Mutex::new(None);

/// Takes what the sender's loop measured, if the row had one.
pub(super) fn take_loop_mean_ns() -> Option<f64> {
    LOOP_MEAN_NS.lock().ok().and_then(|mut m| m.take())
}

/// The receiver: takes a frame, records `now - stamp` (after the warm-up), replies, repeats;
/// then answers the sender's untimed loop ([`LOOP_ROUND_TRIPS`]) where the row has one.
pub(super) fn drive_receiver(
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
    if run.transport.loop_mean() {
        for _ in 0..LOOP_ROUND_TRIPS {
            let stamp = receive();
            reply(stamp);
        }
    }
    histogram
}

/// Spins until `poll` gives a value; panics when nothing came for [`TIMEOUT`]. The clock is
/// read only every 2^16 empty polls, so spinning costs one poll per iteration. No
/// `spin_loop()` hint: the PAUSE it emits would add tens of nanoseconds to every detection,
/// there is no SMT sibling to yield to, and KVM may deschedule a vCPU that loops on PAUSE.
pub(super) fn spin<T>(mut poll: impl FnMut() -> Option<T>) -> T {
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
pub(super) fn announce_ready(info: &str) {
    println!("ready {info}");
}

pub(super) fn stamp_of(bytes: &[u8]) -> u64 {
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
pub(super) struct StampedFrame<const FILL: usize> {
    /// CLOCK_MONOTONIC nanoseconds when the sender sent the frame, little endian.
    stamp_ns: [u8; 8],
    fill: [u8; FILL],
}

/// 64 B, also the reply of every transport.
pub(super) type Frame64 = StampedFrame<{ REPLY_SIZE - 8 }>;
/// The largest STANAG frame.
pub(super) type FrameStanag = StampedFrame<{ MAX_FRAME_LEN - 8 }>;
/// The full waypoint list.
pub(super) type FrameWaypointList = StampedFrame<{ WAYPOINT_LIST_SIZE - 8 }>;

const _: () = assert!(size_of::<Frame64>() == 64);
const _: () = assert!(size_of::<FrameStanag>() == MAX_FRAME_LEN);
const _: () = assert!(size_of::<FrameWaypointList>() == WAYPOINT_LIST_SIZE);

pub(super) trait Stamped: std::fmt::Debug + Copy + ZeroCopySend + 'static {
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

pub(super) type S = ipc::Service;

/// One side of an iceoryx2 ping-pong through the shipping IPC code
/// (`missionlink_partitions::ipc`): frames go out on the service of `fcc/link/uplink` or
/// `fcc/link/downlink` (the frame queues' QoS) under a prefix of the run, replies on the other.
pub(super) struct Iox2End<Out: Stamped, In: Stamped> {
    publisher: Publisher<S, Out>,
    subscriber: Subscriber<S, In>,
    event: bool,
    /// Dropped last: the node owns the ports' resources.
    _ipc: Ipc<S>,
}

impl<Out: Stamped, In: Stamped> Iox2End<Out, In> {
    fn open(run: &Run, node_name: &str, out: FccService, input: FccService, event: bool) -> Self {
        let prefix = format!("missionlink-latency-{}", run.id);
        let ipc = Ipc::<S>::open(
            node_name,
            &missionlink_partitions::config::Ipc::with_prefix(&prefix),
        )
        .expect("iceoryx2 node");
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
            runtime::wait_in_waitset(&control.requests, waitset, false, TIMEOUT).expect("wait");
        }
    }
}

pub(super) fn iox2_sender<F: Stamped>(run: &Run, event: bool) {
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

pub(super) fn iox2_receiver<F: Stamped>(run: &Run, event: bool) -> Histogram<u64> {
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
pub(super) fn iox2(run: &Run, role: Role, event: bool) -> Option<Histogram<u64>> {
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
pub(super) fn partition_config(run: &Run) -> Config {
    let mut config = Config::default();
    config.ipc.service_prefix = format!("missionlink-latency-{}", run.id);
    if let Some(idle) = run.transport.idle() {
        config.ipc.idle = PerPartition::all(idle);
    }
    config
}

/// The longest a partition-loop end sleeps between two looks at its peer.
pub(super) const LOOP_TIMEOUT: Duration = Duration::from_secs(1);

/// The sending end as voting-monitoring runs it: `run_loop` as that partition (its heartbeat
/// and idle strategy), publishing a frame on the uplink service whenever the previous one was
/// answered on the downlink service (at the sparse pace, after the pause).
pub(super) fn partition_sender<F: Stamped>(run: &Run) {
    let mut config = partition_config(run);
    if run.transport == super::Transport::PartitionUnrungSparse {
        // A publisher that knows no doorbell: it rings nothing and notifies with event ID 0.
        config.ipc.idle[Partition::MissionDataHandling] =
            missionlink_partitions::config::Idle::BLOCK;
    }
    let ipc = Ipc::<S>::for_partition(Partition::VotingMonitoring, &config.ipc).expect("node");
    let publisher = ipc.publisher::<F>(FccService::Uplink).expect("publisher");
    let replies = ipc
        .subscriber::<Frame64>(FccService::Downlink)
        .expect("subscriber");
    let control = Control::new();
    let mut frame = F::zeroed();
    let mut sent = 0;
    let mut outstanding: Option<(u64, Instant)> = None;
    let mut next = Instant::now();
    let inputs = Inputs::new(Duration::ZERO).subscriber(&replies);
    runtime::run_loop::<S>(
        Partition::VotingMonitoring,
        &ipc,
        &config,
        &control,
        inputs,
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
                control.requests.stop();
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
pub(super) fn partition_receiver<F: Stamped>(run: &Run) -> Histogram<u64> {
    partition_receiver_replying::<F, Frame64>(run)
}

/// [`partition_receiver`] with the frames of type `F` answered by a reply of type `R`.
fn partition_receiver_replying<F: Stamped, R: Stamped>(run: &Run) -> Histogram<u64> {
    let config = partition_config(run);
    let ipc = Ipc::<S>::for_partition(Partition::MissionDataHandling, &config.ipc).expect("node");
    let frames = ipc.subscriber::<F>(FccService::Uplink).expect("subscriber");
    let publisher = ipc.publisher::<R>(FccService::Downlink).expect("publisher");
    let control = Control::new();
    let mut histogram =
        Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).expect("valid histogram bounds");
    let mut reply = R::zeroed();
    let mut received = 0;
    let mut last = Instant::now();
    let inputs = Inputs::new(LOOP_TIMEOUT).subscriber(&frames);
    announce_ready("");
    runtime::run_loop::<S>(
        Partition::MissionDataHandling,
        &ipc,
        &config,
        &control,
        inputs,
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
                control.requests.stop();
            }
            Ok(LOOP_TIMEOUT)
        },
    )
    .expect("the receiver's loop");
    histogram
}

// ---------------------------------------------------------------------------------------------
// A sender in C on the C library (`partition-foreign-sparse`)
// ---------------------------------------------------------------------------------------------

/// The contract's frame, as the C sender publishes it: the stamp is `origin_ns`.
impl Stamped for FramePayload {
    fn zeroed() -> Self {
        FramePayload::new(Link::Direct, &[0; MAX_FRAME_LEN], 0)
            .expect("a frame of the largest size")
    }

    fn stamp(&self) -> u64 {
        self.origin_ns
    }

    fn set_stamp(&mut self, ns: u64) {
        self.origin_ns = ns;
    }
}

/// benches/latency/foreign_sender.c built with `cc` against `libmissionlink_c.a` of the bench's
/// own build (`harness::binaries::c_static_library`); once per process,
/// before the receiver starts (which gives up after [`TIMEOUT`] without a frame).
pub(super) fn foreign_sender_program() -> PathBuf {
    static PROGRAM: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    PROGRAM.get_or_init(build_foreign_sender).clone()
}

fn build_foreign_sender() -> PathBuf {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = missionlink::harness::binaries::build_dir().expect("the build directory");
    let program = dir.join("latency-foreign-sender");
    let output = Command::new("cc")
        .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"])
        .arg("-I")
        .arg(repo.join("interfaces/c"))
        .arg("-I")
        .arg(repo.join("clib/include"))
        .arg(repo.join("benches/latency/foreign_sender.c"))
        .arg(missionlink::harness::binaries::c_static_library().expect("the C library"))
        .args(missionlink::harness::binaries::C_NATIVE_LIBS)
        .arg("-o")
        .arg(&program)
        .output()
        .expect("cc runs");
    assert!(
        output.status.success(),
        "cc foreign_sender.c:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    program
}

/// The sending end in C: the C sender, pinned as this process is (it inherits the affinity),
/// sends the run's frames at its pace and ends.
pub(super) fn foreign_sender(run: &Run) {
    let program = foreign_sender_program();
    let pace = run.transport.pace().unwrap_or(Duration::ZERO);
    let status = Command::new(program)
        .arg(partition_config(run).ipc.service_prefix)
        .arg(run.total().to_string())
        .arg(pace.as_nanos().to_string())
        .status()
        .expect("start the C sender");
    assert!(status.success(), "the C sender failed: {status}");
}

/// The receiving end of the C sender's frames: mission data handling's loop, as for
/// `partition-sparse`, taking the contract's `FramePayload` and answering with one.
pub(super) fn foreign_receiver(run: &Run) -> Histogram<u64> {
    partition_receiver_replying::<FramePayload, FramePayload>(run)
}

// ---------------------------------------------------------------------------------------------
// iceoryx2's own publish-subscribe benchmark setup: busy-wait, history 0, buffer 1
// ---------------------------------------------------------------------------------------------

/// One end of a ping-pong as iceoryx2's publish-subscribe benchmark sets it up: a service per
/// direction with history 0, a subscriber buffer of 1, one publisher and one subscriber, and
/// both sides spinning on `receive`; no event service, no notification.
pub(super) struct OwnEnd<Out: Stamped, In: Stamped> {
    publisher: iceoryx2::port::publisher::Publisher<S, Out, ()>,
    subscriber: iceoryx2::port::subscriber::Subscriber<S, In, ()>,
    _node: Node<S>,
}

/// A publish-subscribe service of `T` as iceoryx2's own benchmark sets it up: history 0,
/// subscriber buffer 1, one publisher, one subscriber.
fn own_service<T: Stamped>(
    node: &Node<S>,
    name: &ServiceName,
) -> iceoryx2::service::port_factory::publish_subscribe::PortFactory<S, T, ()> {
    node.service_builder(name)
        .publish_subscribe::<T>()
        .history_size(0)
        .subscriber_max_buffer_size(1)
        .max_publishers(1)
        .max_subscribers(1)
        .open_or_create()
        .expect("service")
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
        let publisher = own_service::<Out>(&node, &service(out))
            .publisher_builder()
            .create()
            .expect("publisher");
        let subscriber = own_service::<In>(&node, &service(input))
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

pub(super) fn own_sender<F: Stamped>(run: &Run) {
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

pub(super) fn own_receiver<F: Stamped>(run: &Run) -> Histogram<u64> {
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
pub(super) fn typed(run: &Run, role: Role, own: bool) -> Option<Histogram<u64>> {
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
pub(super) trait Datagram {
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
pub(super) fn datagram_sender(run: &Run, socket: &impl Datagram) {
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
pub(super) fn datagram_receiver(run: &Run, socket: &impl Datagram) -> Histogram<u64> {
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

pub(super) fn uds_address(run: &Run, side: &str) -> SocketAddr {
    SocketAddr::from_abstract_name(format!("missionlink-latency/{}/{side}", run.id))
        .expect("abstract socket address")
}

pub(super) fn uds_sender(run: &Run) {
    let socket = UnixDatagram::bind_addr(&uds_address(run, "sender")).expect("bind");
    socket
        .connect_addr(&uds_address(run, "receiver"))
        .expect("connect");
    datagram_sender(run, &socket);
}

pub(super) fn uds_receiver(run: &Run) -> Histogram<u64> {
    let socket = UnixDatagram::bind_addr(&uds_address(run, "receiver")).expect("bind");
    announce_ready("");
    datagram_receiver(run, &socket)
}

// 4: UDP over loopback (the receiver announces the port the system chose).

pub(super) fn udp_sender(run: &Run, receiver_port: &str) {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    socket
        .connect(format!("127.0.0.1:{receiver_port}"))
        .expect("connect");
    datagram_sender(run, &socket);
}

pub(super) fn udp_receiver(run: &Run) -> Histogram<u64> {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    announce_ready(&socket.local_addr().expect("address").port().to_string());
    datagram_receiver(run, &socket)
}

// ---------------------------------------------------------------------------------------------
// 5: the floor, one cache line each way
// ---------------------------------------------------------------------------------------------

/// Two `AtomicU64`s in a file mapped shared by both processes: `ping` (sender to receiver) and
/// `pong` (back), 128 bytes apart so that they never share a cache line or its prefetch pair.
pub(super) struct SharedLines {
    ptr: *mut core::ffi::c_void,
    path: PathBuf,
    owner: bool,
}

pub(super) const MAP_LEN: usize = 4096;
pub(super) const LINE_STRIDE: usize = 128;

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
pub(super) fn spin_for_change(line: &AtomicU64, last: &mut u64) -> u64 {
    let seen = *last;
    *last = spin(|| {
        let v = line.load(Ordering::Acquire);
        (v != seen).then_some(v)
    });
    *last
}

pub(super) fn shm_sender(run: &Run) {
    let lines = SharedLines::map(run, false);
    let mut last_pong = lines.pong().load(Ordering::Acquire);
    drive_sender(
        run,
        |stamp| lines.ping().store(stamp, Ordering::Release),
        || spin_for_change(lines.pong(), &mut last_pong),
    );
}

pub(super) fn shm_receiver(run: &Run) -> Histogram<u64> {
    let lines = SharedLines::map(run, true);
    let mut last_ping = 0;
    announce_ready("");
    drive_receiver(
        run,
        || spin_for_change(lines.ping(), &mut last_ping),
        |stamp| lines.pong().store(stamp, Ordering::Release),
    )
}
