//! The cost of the onboard geofence check of ICD §7 (ext) in its worst case (the goal
//! is under 10 ms; BENCHMARKS.md section 4): 256 waypoints against 11 areas of 60 vertices, every
//! zone within 40 m to 300 m of the legs beside it, and the check passing, so it looks at every
//! leg and zone (`testkit::geofence_worst_case`; a failing check stops at its first violation).
//!
//! - `geofence/<case>/end_to_end`: `Fence::of_payload` of the published area list, then
//!   `onboard::check` of `flown_route::execute_route` from the take-off position: what the FCC does
//!   before it accepts #50000 execute;
//! - `geofence/<case>/check`: the check alone, the fence built beforehand;
//! - `<case>/check, legs only` (percentiles only): the same without the turns at the waypoints
//!   (`execute_route(.., None)`), to see what the turns cost;
//! - `geofence/<case>/return_check`: the check of `flown_route::return_route` from the take-off
//!   position back over the whole route (return to home), the fence built beforehand;
//! - `geofence/<case>/fence`: `Fence::of_payload` alone;
//! - `gateway/track_to_fix`: the GCS's whole safety gateway (`SafetyGateway::violations`, every
//!   group of checks, the reverse route not included: the route is one-way) on the same mission
//!   and areas, what `gcs validate` spends on them (its 3000 km exceed the energy budget: that
//!   one violation is expected; every geographic check passes).
//!
//! `<case>` is `track_to_fix` (every leg a geodesic), `radius_to_fix` (the legs between lanes
//! at the north end as half circles of 570 m: 60 of 255 legs) or `track_to_fix_in_wind` (the
//! first planned in a wind of [`WORST_CASE_WIND_MPS`], ICD §7 "Turns in wind"); every waypoint is
//! fly-by, so the check constructs and checks a turn at each (`geofence::turn`). Criterion gives means; before
//! them, the bench prints p50, p99, p99.9 and max of single runs of `end_to_end` and `check`
//! ([`RUNS`] runs each, after [`WARMUP`]), timed one by one (a run takes milliseconds, far above
//! the clock's cost). Zero allocations: `services/flight/tests/geofence_no_allocation.rs`. Run with
//! `cargo bench --bench geofence`.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink_protocol::geofence::flown_route;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::Criterion;
use hdrhistogram::Histogram;
use missionlink_flight::automation::fcc_turns;
use missionlink_flight::onboard::{self, Violation};
use missionlink_ground::safety_gateway::{SafetyGateway, ViolationCode};
use missionlink_interfaces::contracts::{AreaListPayload, WaypointListPayload};
use missionlink_interfaces::wire::{GeoPoint, Speed};
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::testkit::{
    geofence_worst_case, geofence_worst_case_plan, geofence_worst_case_rf,
};

/// Timed runs per row of the percentile table.
const RUNS: usize = 2000;
/// Untimed runs before them.
const WARMUP: usize = 100;

type Case = (WaypointListPayload, AreaListPayload, GeoPoint);

/// The planning wind of the `in_wind` case, m/s: the most the worst case's turns hold (ICD §7
/// "Turns in wind"). Its turns at 5 m/s are then `(5 + 2)²/(g·tan 25°)` = 10.7 m instead of
/// 5.5 m, the largest fly-by arcs its 24 m legs between passes have room for (half of each leg);
/// an arc of twice the radius has about √2 times the corners. In more wind they would be flown
/// over and leave the corridors, and the check would stop at the first.
const WORST_CASE_WIND_MPS: f64 = 2.0;

fn cases() -> [(&'static str, Case); 3] {
    let (mut windy, areas, take_off) = geofence_worst_case();
    windy.planning_wind = Speed::from_mps(WORST_CASE_WIND_MPS).expect("a speed");
    [
        ("track_to_fix", geofence_worst_case()),
        ("radius_to_fix", geofence_worst_case_rf()),
        ("track_to_fix_in_wind", (windy, areas, take_off)),
    ]
}

/// What the FCC does before execute: the fence of the published list, the execute route's check.
fn end_to_end(waypoints: &WaypointListPayload, areas: &AreaListPayload, take_off: Site) -> bool {
    let fence = Fence::of_payload(areas);
    check(&fence, waypoints, take_off).is_ok()
}

fn check(fence: &Fence, waypoints: &WaypointListPayload, take_off: Site) -> Result<(), Violation> {
    onboard::check(
        fence,
        flown_route::execute_route(
            flown_route::RouteView::from(waypoints),
            take_off,
            Some(fcc_turns()),
        ),
    )
}

fn criterion_benches(c: &mut Criterion) {
    for (name, (waypoints, areas, take_off)) in cases() {
        let site = Site::of(take_off);
        let fence = Fence::of_payload(&areas);
        assert_eq!(check(&fence, &waypoints, site), Ok(()), "{name} passes");
        let mut group = c.benchmark_group(format!("geofence/{name}"));
        group
            .sample_size(50)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(5));
        group.bench_function("end_to_end", |b| {
            b.iter(|| end_to_end(black_box(&waypoints), black_box(&areas), site))
        });
        group.bench_function("check", |b| {
            b.iter(|| check(black_box(&fence), black_box(&waypoints), site))
        });
        group.bench_function("return_check", |b| {
            b.iter(|| {
                onboard::check(
                    black_box(&fence),
                    flown_route::return_route(
                        flown_route::RouteView::from(black_box(&waypoints)),
                        site,
                        0,
                        Some(fcc_turns()),
                    ),
                )
            })
        });
        group.bench_function("fence", |b| b.iter(|| Fence::of_payload(black_box(&areas))));
        group.finish();
    }
}

/// Runs `f` `WARMUP` times, then `runs` times timed one by one, and prints the row.
fn percentiles(name: &str, runs: usize, mut f: impl FnMut() -> bool) {
    for _ in 0..WARMUP.min(runs) {
        assert!(black_box(f()));
    }
    let mut h = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).expect("valid bounds");
    for _ in 0..runs {
        let start = Instant::now();
        let passed = black_box(f());
        let ns = start.elapsed().as_nanos() as u64;
        assert!(passed, "{name} passes");
        h.record(ns.max(1)).expect("in bounds");
    }
    let us = |ns: u64| ns as f64 / 1000.0;
    println!(
        "{name:<36} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
        us(h.value_at_quantile(0.5)),
        us(h.value_at_quantile(0.99)),
        us(h.value_at_quantile(0.999)),
        us(h.max()),
        h.mean() / 1000.0,
    );
}

fn main() {
    // `cargo bench -- --test` (and criterion's test mode) runs everything once.
    let test_mode = std::env::args().any(|a| a == "--test");
    let runs = if test_mode { 1 } else { RUNS };
    let warmup = WARMUP.min(runs);
    println!(
        "onboard geofence check, worst case: µs per run, {runs} runs after {warmup} warm-up\n{:<36} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "", "p50", "p99", "p99.9", "max", "mean"
    );
    for (name, (waypoints, areas, take_off)) in cases() {
        let site = Site::of(take_off);
        let fence = Fence::of_payload(&areas);
        percentiles(&format!("{name}/end_to_end"), runs, || {
            end_to_end(black_box(&waypoints), black_box(&areas), site)
        });
        percentiles(&format!("{name}/check"), runs, || {
            check(black_box(&fence), black_box(&waypoints), site).is_ok()
        });
        percentiles(&format!("{name}/check, legs only"), runs, || {
            onboard::check(
                black_box(&fence),
                flown_route::execute_route(
                    flown_route::RouteView::from(black_box(&waypoints)),
                    site,
                    None,
                ),
            )
            .is_ok()
        });
    }
    let plan = geofence_worst_case_plan();
    let lists = plan.assemble().expect("the worst case assembles");
    let gateway = SafetyGateway::default();
    // 3000 km of survey: only the energy budget fails; every geographic check passes.
    percentiles("gateway/track_to_fix", runs.min(200), || {
        gateway
            .violations(
                black_box(&lists.mission),
                black_box(&lists.areas),
                plan.take_off_position,
            )
            .iter()
            .all(|v| v.code == ViolationCode::EnergyBudget)
    });
    println!();
    let mut c = Criterion::default().configure_from_args();
    criterion_benches(&mut c);
    c.final_summary();
}
