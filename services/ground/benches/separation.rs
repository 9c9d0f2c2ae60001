//! What the fleet separation check costs (`safety_gateway::separation`): sixteen survey
//! missions of 256 waypoints each, side by side (`testkit::survey_fleet`: neighbours in a row
//! within some 300 m, so that the check finds conflicts, and every element has hundreds of
//! others within a few kilometres), separation 500 m horizontally and 150 m vertically.
//!
//! - `separation/16x256/fleet`: every mission's paths built (`Flown::new`) and each checked
//!   against the other fifteen: the whole fleet checked against each other;
//! - `separation/16x256/build`: the paths of the sixteen missions alone;
//! - `separation/16x256/check`: the sixteen checks alone, the paths built beforehand;
//! - `separation/16x256/upload`: what one upload asks, `separation::conflicts` of one new
//!   mission against the fifteen active ones, every mission's paths built in the call.
//!
//! Before them the bench prints how many elements and conflicts the fleet has. Run with
//! `cargo bench -p missionlink-ground --bench separation`.
// A benchmark stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use missionlink_ground::safety_gateway::SafetyGateway;
use missionlink_ground::safety_gateway::separation::{self, Flight, Flown, Separation};
use missionlink_ground::testkit::survey_fleet;
use missionlink_protocol::transfer::mission::Mission;

const VEHICLES: usize = 16;
const WAYPOINTS: u16 = 256;
const SEPARATION: Separation = Separation {
    horizontal_m: 500.0,
    vertical_m: 150.0,
};

fn build(gateway: &SafetyGateway, fleet: &[Mission], names: &[String]) -> Vec<Flown> {
    fleet
        .iter()
        .zip(names)
        .map(|(mission, vehicle)| {
            Flown::new(
                gateway,
                Flight {
                    vehicle,
                    mission,
                    take_off: None,
                },
            )
        })
        .collect()
}

/// Each mission against the others; the number of conflicts.
fn check(flown: &[Flown]) -> usize {
    flown
        .iter()
        .map(|own| {
            let others = flown.iter().filter(|f| f.vehicle() != own.vehicle());
            own.conflicts(others, SEPARATION).unwrap().len()
        })
        .sum()
}

fn main() {
    let gateway = SafetyGateway::default();
    let fleet = survey_fleet(VEHICLES, WAYPOINTS);
    let names: Vec<String> = (0..VEHICLES).map(|k| format!("v{k:02}")).collect();

    let flown = build(&gateway, &fleet, &names);
    let elements: usize = flown.iter().map(|f| f.elements().count()).sum();
    println!(
        "{VEHICLES} missions of {WAYPOINTS} waypoints: {elements} elements, {} conflicts (each counted from both sides)\n",
        check(&flown)
    );
    let mut c = Criterion::default().configure_from_args();
    let mut group = c.benchmark_group(format!("separation/{VEHICLES}x{WAYPOINTS}"));
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    group.bench_function("fleet", |b| {
        b.iter(|| check(&build(&gateway, black_box(&fleet), &names)))
    });
    group.bench_function("build", |b| {
        b.iter(|| build(&gateway, black_box(&fleet), &names))
    });
    group.bench_function("check", |b| b.iter(|| check(black_box(&flown))));
    group.bench_function("upload", |b| {
        b.iter(|| {
            let flights: Vec<Flight> = fleet
                .iter()
                .zip(&names)
                .map(|(mission, vehicle)| Flight {
                    vehicle,
                    mission,
                    take_off: None,
                })
                .collect();
            let (own, others) = flights.split_first().unwrap();
            separation::conflicts(&gateway, *own, black_box(others), SEPARATION)
                .unwrap()
                .len()
        })
    });
    group.finish();
    c.final_summary();
}
