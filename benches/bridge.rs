//! The hop across hosts (BENCHMARKS.md, "Across hosts"): a partition's sample on host A through
//! the bridge there, Zenoh over TCP on a veth pair, the bridge on host B, to a partition on host
//! B, one way; beside a plain UDP datagram over the same veth, in the same run. Two sizes: a
//! 548 B frame (`fcc/link/uplink`) and the 8 KiB waypoint list (`fcc/mission/waypoint-list`).
//! Hosts A and B are two network namespaces made for the run (src/harness/netns.rs, the same
//! as tests/system/two_hosts.rs); both share this machine's clock, so one CLOCK_MONOTONIC stamp in the
//! payload gives the one-way time. One sample is in flight at a time; the receiver polls (the
//! wake-up of a sleeping receiver is measured in benches/latency.rs, not here). Needs root.
//!
//! ```sh
//! cargo bench --bench bridge                      # 2000 samples per case
//! cargo bench --bench bridge -- --samples 200     # a short run
//! ```
//!
//! Prints p50, p99 and p99.9 in microseconds per case.
// A benchmark stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink::harness;

use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use harness::netns::{ADDR_A, ADDR_B, Hosts};
use hdrhistogram::Histogram;
use iceoryx2::prelude::ipc;
use missionlink_interfaces::capacity::MAX_WAYPOINTS;
use missionlink_interfaces::contracts::{FccService, FramePayload, Link, WaypointListPayload};
use missionlink_partitions::binaries;
use missionlink_partitions::bridge_config::{Authentication, Bridge};
use missionlink_partitions::config::Config;
use missionlink_partitions::ipc::Ipc;
use missionlink_partitions::launcher::FccProcess;

const DEFAULT_SAMPLES: usize = 2000;
const WARMUP: usize = 100;
const ZENOH_PORT: u16 = 7447;
/// A sample not received within this counts as lost (and is not in the percentiles).
const LOST_AFTER: Duration = Duration::from_secs(1);

fn now_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
}

fn histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, 60_000_000_000, 3).unwrap()
}

/// Runs `f` on a thread inside namespace `ns` (sockets and processes made there belong there).
fn in_ns<T: Send + 'static>(ns: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let ns = ns.to_owned();
    std::thread::spawn(move || {
        Hosts::enter(&ns);
        f()
    })
    .join()
    .unwrap()
}

fn config(dir: &Path, host: &str, bridge: Bridge) -> Config {
    let mut c = Config::default();
    c.ipc.service_prefix = format!("bench-bridge-{}-{host}", std::process::id());
    c.ipc.state_dir = Some(dir.join(format!("state-{host}")));
    c.latency.summary_dir = Some(dir.join("latency"));
    c.bridge = bridge;
    c
}

fn start_bridge(ns: &str, bin: &Path, config: &Config, log: PathBuf) -> FccProcess {
    let (bin, config) = (bin.to_owned(), config.clone());
    let mut p = in_ns(ns, move || {
        let command = FccProcess::command(&bin, "bridge", &config).unwrap();
        FccProcess::spawn(command, &config, Some(&log)).unwrap()
    });
    assert!(
        p.wait_ready(Duration::from_secs(30)),
        "the bridge did not come up:\n{}",
        p.log_text()
    );
    p
}

struct Row {
    hop: &'static str,
    size: usize,
    h: Histogram<u64>,
    lost: usize,
}

/// Sends `samples` (after the warm-up) one at a time: `send(i, stamp)` sends sample `i` with
/// the stamp, `receive()` gives the stamp of a sample that arrived, if one did.
fn measure(
    samples: usize,
    mut send: impl FnMut(u64, u64),
    mut receive: impl FnMut() -> Option<(u64, u64)>,
) -> (Histogram<u64>, usize) {
    let mut h = histogram();
    let mut lost = 0;
    for i in 1..=(WARMUP + samples) as u64 {
        let stamp = now_ns();
        send(i, stamp);
        let deadline = Instant::now() + LOST_AFTER;
        loop {
            if let Some((seq, at)) = receive() {
                if seq == i {
                    if i as usize > WARMUP {
                        h.record(now_ns().saturating_sub(at).max(1)).unwrap();
                    }
                    break;
                }
                continue;
            }
            if Instant::now() > deadline {
                if i as usize > WARMUP {
                    lost += 1;
                }
                break;
            }
            std::hint::spin_loop();
        }
    }
    (h, lost)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let samples = args
        .iter()
        .position(|a| a == "--samples")
        .and_then(|i| args.get(i + 1))
        .map_or(DEFAULT_SAMPLES, |n| n.parse().expect("--samples N"));
    if !rustix::process::geteuid().is_root() {
        eprintln!(
            "benches/bridge.rs needs root (network namespaces and a veth pair): run it as root"
        );
        std::process::exit(1);
    }
    missionlink_partitions::ipc::quiet_iceoryx2_log();
    let hosts = Hosts::new("bn");
    let dir = std::env::temp_dir().join(format!("missionlink-bench-bridge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin = harness::bin_dir();
    binaries::ensure_bridge(&bin, binaries::Build::UnderCargo).unwrap();

    let services = ["fcc/link/uplink", "fcc/mission/waypoint-list"]
        .map(str::to_owned)
        .to_vec();
    let key_prefix = format!("bench-bridge-{}", std::process::id());
    let a = config(
        &dir,
        "a",
        Bridge {
            enabled: true,
            listen: vec![format!("tcp/{ADDR_A}:{ZENOH_PORT}")],
            key_prefix: key_prefix.clone(),
            out: services.clone(),
            // The numbers of BENCHMARKS.md "Across hosts" are over plain TCP; a deployment's
            // bridges authenticate by mutual TLS (the default), whose hop is not measured here.
            authentication: Authentication::None,
            ..Bridge::default()
        },
    );
    let b = config(
        &dir,
        "b",
        Bridge {
            enabled: true,
            connect: vec![format!("tcp/{ADDR_A}:{ZENOH_PORT}")],
            key_prefix,
            inbound: services,
            authentication: Authentication::None,
            ..Bridge::default()
        },
    );
    let mut bridge_a = start_bridge(&hosts.a, &bin, &a, dir.join("bridge-a.log"));
    let mut bridge_b = start_bridge(&hosts.b, &bin, &b, dir.join("bridge-b.log"));

    let host_a = Ipc::<ipc::Service>::open("bench-partition-a", &a.ipc.service_prefix).unwrap();
    let host_b = Ipc::<ipc::Service>::open("bench-partition-b", &b.ipc.service_prefix).unwrap();
    let mut rows = Vec::new();

    // 548 B frames, fcc/link/uplink.
    {
        let publisher = host_a
            .publisher::<FramePayload>(FccService::Uplink)
            .unwrap();
        let subscriber = host_b
            .subscriber::<FramePayload>(FccService::Uplink)
            .unwrap();
        let mut frame = FramePayload::new(Link::Direct, &[0x5a; 548], 0).unwrap();
        let (h, lost) = measure(
            samples,
            |i, stamp| {
                frame.sequence = i;
                frame.published_ns = stamp;
                publisher.send(&frame).unwrap();
            },
            || {
                let mut got = None;
                subscriber.take_one(|f| got = Some((f.sequence, f.published_ns)));
                got
            },
        );
        rows.push(Row {
            hop: "bridge (Zenoh/TCP)",
            size: size_of::<FramePayload>(),
            h,
            lost,
        });
    }
    // The 8 KiB waypoint list, fcc/mission/waypoint-list (history 1: only the newest counts).
    {
        let publisher = host_a
            .publisher::<WaypointListPayload>(FccService::WaypointList)
            .unwrap();
        let subscriber = host_b
            .subscriber::<WaypointListPayload>(FccService::WaypointList)
            .unwrap();
        let mut list = WaypointListPayload::EMPTY;
        list.count = MAX_WAYPOINTS as u16;
        let (h, lost) = measure(
            samples,
            |i, stamp| {
                // The bench's own use of the counters: sequence and stamp.
                list.generation = i;
                list.activation = stamp;
                publisher.send(&list).unwrap();
            },
            || subscriber.latest().map(|l| (l.generation, l.activation)),
        );
        rows.push(Row {
            hop: "bridge (Zenoh/TCP)",
            size: size_of::<WaypointListPayload>(),
            h,
            lost,
        });
    }
    // A plain UDP datagram over the same veth, the same sizes.
    let tx = in_ns(&hosts.a, || UdpSocket::bind((ADDR_A, 0)).unwrap());
    let rx = in_ns(&hosts.b, || UdpSocket::bind((ADDR_B, 0)).unwrap());
    rx.set_nonblocking(true).unwrap();
    tx.connect(rx.local_addr().unwrap()).unwrap();
    for size in [size_of::<FramePayload>(), size_of::<WaypointListPayload>()] {
        let mut out = vec![0x5a; size];
        let mut buf = vec![0; size + 1];
        let (h, lost) = measure(
            samples,
            |i, stamp| {
                out[..8].copy_from_slice(&i.to_le_bytes());
                out[8..16].copy_from_slice(&stamp.to_le_bytes());
                tx.send(&out).unwrap();
            },
            || match rx.recv(&mut buf) {
                Ok(n) if n >= 16 => Some((
                    u64::from_le_bytes(buf[..8].try_into().unwrap()),
                    u64::from_le_bytes(buf[8..16].try_into().unwrap()),
                )),
                _ => None,
            },
        );
        rows.push(Row {
            hop: "UDP datagram",
            size,
            h,
            lost,
        });
    }

    println!("one-way hop host A -> host B over a veth pair, {samples} samples per case (µs)");
    println!(
        "{:<20} {:>7} {:>9} {:>9} {:>9} {:>6}",
        "hop", "bytes", "p50", "p99", "p99.9", "lost"
    );
    for r in &rows {
        let us = |q: f64| r.h.value_at_quantile(q) as f64 / 1000.0;
        println!(
            "{:<20} {:>7} {:>9.1} {:>9.1} {:>9.1} {:>6}",
            r.hop,
            r.size,
            us(0.5),
            us(0.99),
            us(0.999),
            r.lost
        );
    }
    bridge_a.stop().unwrap();
    bridge_b.stop().unwrap();
    drop(hosts);
    let _ = std::fs::remove_dir_all(&dir);
}
