//! Per-call percentiles of encode and decode (p50, p99, p99.9, max), which criterion's means do
//! not give. A single call takes tens of nanoseconds, close to the cost of reading the clock, so
//! each sample times a batch of `BATCH` calls and records the mean per call of that batch: the
//! tail shows batches hit by interrupts, preemption or cache misses. Run with
//! `cargo bench --bench wire_percentiles`.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::hint::black_box;
use std::time::Instant;

use missionlink_interfaces::wire::{self, Envelope, MAX_FRAME_LEN, Message};
use missionlink_protocol::testkit::{full_polygon, full_waypoint};

const BATCH: u32 = 32;
const SAMPLES: usize = 50_000;

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i]
}

fn measure(name: &str, mut f: impl FnMut()) {
    for _ in 0..10_000 {
        f();
    }
    let mut ns = Vec::with_capacity(SAMPLES);
    for _ in 0..SAMPLES {
        let start = Instant::now();
        for _ in 0..BATCH {
            f();
        }
        ns.push(start.elapsed().as_nanos() as f64 / f64::from(BATCH));
    }
    ns.sort_by(f64::total_cmp);
    println!(
        "{name:<36} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
        percentile(&ns, 0.5),
        percentile(&ns, 0.99),
        percentile(&ns, 0.999),
        ns[ns.len() - 1]
    );
}

fn bench_message(name: &str, message: &Message) {
    let envelope = Envelope::new(0x0A00_0001, 0x0B00_0001).with_ack(true);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(&envelope, message, &mut buf).expect("encodes");
    let frame = buf[..len].to_vec();
    let mut out = [0u8; MAX_FRAME_LEN];
    measure(&format!("{name} encode ({len} B)"), || {
        black_box(wire::encode(
            black_box(&envelope),
            black_box(message),
            &mut out,
        ))
        .ok();
    });
    measure(&format!("{name} decode ({len} B)"), || {
        black_box(wire::decode(black_box(&frame))).ok();
    });
}

fn main() {
    println!(
        "ns per call, {SAMPLES} samples of {BATCH} calls\n{:<36} {:>9} {:>9} {:>9} {:>9}",
        "", "p50", "p99", "p99.9", "max"
    );
    bench_message("#13002", &full_waypoint().into());
    bench_message("#2012 60 vertices", &full_polygon().into());
}
