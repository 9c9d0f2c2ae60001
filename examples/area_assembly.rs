//! Assembles the fly-zone and ten no-fly-zones of 60 vertices (`testkit::eleven_areas`, the
//! case of `benches/per_frame.rs` "assembly/11_areas_60_vertices") N times (the first argument,
//! 200 by default), for counting the instructions of the assembly under callgrind, where a
//! timing on this guest varies by a third from one run to the next:
//!
//! ```sh
//! cargo build --release --example area_assembly
//! valgrind --tool=callgrind target/release/examples/area_assembly 50
//! ```
//!
//! Not a product binary: a measuring aid.
// An aid stops at its first failure.
#![allow(clippy::expect_used)]

use std::hint::black_box;

use missionlink_interfaces::wire::SafetyOffset;
use missionlink_services::testkit;

fn main() {
    let areas = testkit::area_buffer(&testkit::eleven_areas());
    let offset = SafetyOffset::from_metres(25.0).expect("25 m is a safety offset");
    let times: usize = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(200);
    for _ in 0..times {
        let _ = black_box(black_box(&areas).assemble(11, offset));
    }
}
