//! The cost of a partition's seccomp filter (`partitions/src/isolation.rs`) per frame: the
//! system calls one frame's hop makes in a partition (a Unix datagram sent and received, as
//! iceoryx2's event does; an epoll round of the WaitSet; a look at the clock and the process ID),
//! timed on a thread without the filter and on a thread with the partition's filter installed
//! (seccomp filters are per thread unless synchronised), in blocks that alternate within one
//! run, so both see the same machine. Prints p50, p99, p99.9 and max per frame, nanoseconds.
//!
//! Run with `cargo bench --bench isolation` (`-- --quick` for a short run that shows the
//! format). The numbers are in BENCHMARKS.md, measured on a quiet machine.
// A bench stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::os::unix::net::UnixDatagram;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use missionlink_partitions::config::Violation;
use missionlink_partitions::isolation::{Profile, Threads, install_filter};
use rustix::event::epoll;

/// One frame's system calls, as a partition makes them: notify (sendto), wake (epoll_wait),
/// drain (recvfrom), the clock (vDSO) and getpid (iceoryx2's liveness checks).
struct Frame {
    tx: UnixDatagram,
    rx: UnixDatagram,
    epoll: rustix::fd::OwnedFd,
    events: Vec<epoll::Event>,
}

impl Frame {
    fn new() -> Self {
        let (tx, rx) = UnixDatagram::pair().unwrap();
        rx.set_nonblocking(true).unwrap();
        let epoll = epoll::create(epoll::CreateFlags::CLOEXEC).unwrap();
        epoll::add(
            &epoll,
            &rx,
            epoll::EventData::new_u64(1),
            epoll::EventFlags::IN,
        )
        .unwrap();
        Self {
            tx,
            rx,
            epoll,
            events: Vec::with_capacity(4),
        }
    }

    fn hop(&mut self) {
        self.events.clear();
        let mut buf = [0u8; 16];
        let now = rustix::event::Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        self.tx.send(&[1u8; 8]).unwrap();
        epoll::wait(
            &self.epoll,
            rustix::buffer::spare_capacity(&mut self.events),
            Some(&now),
        )
        .unwrap();
        self.rx.recv(&mut buf).unwrap();
        std::hint::black_box(Instant::now());
        std::hint::black_box(rustix::process::getpid());
    }
}

/// A thread that times blocks of `per_block` frames when asked, with or without the filter.
fn worker(filtered: bool, per_block: usize) -> (mpsc::Sender<()>, mpsc::Receiver<Vec<u64>>) {
    let (ask, asked) = mpsc::channel::<()>();
    let (give, given) = mpsc::channel::<Vec<u64>>();
    std::thread::spawn(move || {
        let mut frame = Frame::new();
        if filtered {
            install_filter(
                Profile::Partition { inet: false },
                Violation::Kill,
                Threads::This,
            )
            .unwrap();
        }
        while asked.recv().is_ok() {
            let mut ns = Vec::with_capacity(per_block);
            for _ in 0..per_block {
                let start = Instant::now();
                frame.hop();
                ns.push(start.elapsed().as_nanos() as u64);
            }
            give.send(ns).unwrap();
        }
    });
    (ask, given)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let (blocks, per_block) = if quick { (4, 2_000) } else { (40, 25_000) };
    let workers = [
        ("without the filter", worker(false, per_block)),
        ("with the filter", worker(true, per_block)),
    ];
    let mut histograms: Vec<Histogram<u64>> = workers
        .iter()
        .map(|_| {
            Histogram::new_with_bounds(1, Duration::from_secs(1).as_nanos() as u64, 3).unwrap()
        })
        .collect();
    // A warm-up block each, not recorded.
    for (_, (ask, given)) in &workers {
        ask.send(()).unwrap();
        given.recv().unwrap();
    }
    for _ in 0..blocks {
        for ((_, (ask, given)), histogram) in workers.iter().zip(&mut histograms) {
            ask.send(()).unwrap();
            for ns in given.recv().unwrap() {
                histogram.saturating_record(ns);
            }
        }
    }
    println!("one frame's system calls (sendto, epoll_wait, recvfrom, getpid), ns per frame");
    println!(
        "{:<22} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "", "frames", "p50", "p99", "p99.9", "max"
    );
    for ((name, _), h) in workers.iter().zip(&histograms) {
        println!(
            "{name:<22} {:>9} {:>9} {:>9} {:>9} {:>9}",
            h.len(),
            h.value_at_quantile(0.5),
            h.value_at_quantile(0.99),
            h.value_at_quantile(0.999),
            h.max()
        );
    }
}
