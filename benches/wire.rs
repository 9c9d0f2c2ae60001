//! Encode and decode of the two messages that dominate a transfer: #13002 UA Position Waypoint
//! with all 18 fields, and #2012 Area Polygon Loop Segment with 60 vertices (the largest frame of
//! a mission upload). Each iteration handles one whole frame: wrapper, presence vector, fields,
//! checksum. Run with `cargo bench --bench wire`.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use missionlink_interfaces::wire::{self, Envelope, MAX_FRAME_LEN, Message};
use missionlink_protocol::testkit::{full_polygon, full_waypoint};

fn bench_message(c: &mut Criterion, name: &str, message: &Message) {
    let envelope = Envelope::new(0x0A00_0001, 0x0B00_0001).with_ack(true);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(&envelope, message, &mut buf).expect("encodes");
    let frame = buf[..len].to_vec();

    let mut group = c.benchmark_group(name);
    group.throughput(Throughput::Bytes(len as u64));
    group.bench_function("encode", |b| {
        let mut out = [0u8; MAX_FRAME_LEN];
        b.iter(|| wire::encode(black_box(&envelope), black_box(message), &mut out))
    });
    group.bench_function("decode", |b| b.iter(|| wire::decode(black_box(&frame))));
    group.finish();
}

fn wire_benches(c: &mut Criterion) {
    bench_message(c, "13002_ua_position_waypoint", &full_waypoint().into());
    bench_message(c, "2012_polygon_60_vertices", &full_polygon().into());
}

criterion_group!(benches, wire_benches);
criterion_main!(benches);
