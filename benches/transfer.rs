//! End-to-end transfer time: the real FCC (the `fcc` launcher and its four partitions, over
//! iceoryx2) and the real GCS link (`GcsLink`, both UDP links on loopback), an upload request as
//! `gcs upload` makes it: validation, clear, take-off height, waypoints, route, transmit, then
//! the areas (initiate, one #2012 per area, complete). Each message waits for its answer before
//! the next goes out (ICD §5, one message in flight), so the time is dominated by round trips.
//!
//! Missions: demo mission 1 (one waypoint and its fly-zone; the paper reports about 0.4 s for
//! this transfer) and generated missions of 10, 100 and 256 waypoints, each with 11 areas of 60
//! vertices (the fly-zone and ten no-fly-zones). Prints a table and writes
//! `target/transfer/results.json`.
//!
//! ```sh
//! cargo bench --bench transfer                 # 30 runs per mission
//! cargo bench --bench transfer -- --runs 100
//! ```
//!
//! Without `--bench` (`cargo test --benches`) it makes one run per mission and writes nothing.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use missionlink_gcs::gcs_link::Direction;
use missionlink_partitions::binaries;
use missionlink_services::ground_station::MissionPlan;
use missionlink_services::testkit;

const DEFAULT_RUNS: usize = 30;
const WARM_UP_RUNS: usize = 2;

struct Case {
    name: String,
    waypoints: usize,
    areas: usize,
    plan: MissionPlan,
}

struct Measured {
    case: Case,
    /// Messages the upload request sends (computed from the plan).
    expected: usize,
    up: Vec<usize>,
    down: Vec<usize>,
    ms: Vec<f64>,
}

/// Nearest-rank percentile of sorted samples.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let rank = (p * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

fn median(sorted: &[f64]) -> f64 {
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0
    }
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".to_owned())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bench_mode = args.iter().any(|a| a == "--bench");
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse::<usize>().expect("--runs N"))
        .unwrap_or(if bench_mode { DEFAULT_RUNS } else { 1 })
        .max(1);
    let warm_up = if bench_mode { WARM_UP_RUNS } else { 0 };

    let mut cases = vec![Case {
        name: "mission-1".to_owned(),
        waypoints: 1,
        areas: 1,
        plan: common::plan("mission-1.toml"),
    }];
    for n in [10u16, 100, 256] {
        cases.push(Case {
            name: format!("generated-{n}"),
            waypoints: usize::from(n),
            areas: 11,
            plan: testkit::generated_plan(n),
        });
    }

    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load_before = load_average();
    let mut rig = common::Rig::new("bench-transfer");
    let mut fcc = rig.start("fcc");
    for partition in [
        "voting-monitoring",
        "mission-data-handling",
        "system-automation",
        "guidance-stub",
    ] {
        common::wait_for_log(&fcc, &format!("{partition} up"), Duration::from_secs(30));
    }
    let mut link = rig.gcs(&mut fcc);
    link.enable_log();

    let mut results = Vec::new();
    for case in cases {
        let valid = link.station().validate(&case.plan).unwrap();
        assert_eq!(valid.mission.waypoints.len(), case.waypoints);
        assert_eq!(valid.areas.areas.len(), case.areas);
        // The report request and the acknowledgement of its one entry (ICD §10.1: the edition
        // discovery before every upload, issue 12); clear, take-off, waypoints (+ RF centres),
        // route, transmit; initiate, areas, complete.
        let expected = 2 + 1 + valid.mission.message_count() + 1 + 1 + case.areas + 1;
        let mut result = Measured {
            case,
            expected,
            up: Vec::new(),
            down: Vec::new(),
            ms: Vec::new(),
        };
        for run in 0..warm_up + runs {
            link.log.clear();
            let start = Instant::now();
            common::upload(&mut link, &result.case.plan)
                .unwrap_or_else(|e| panic!("{} run {run}: {e}", result.case.name));
            let elapsed = start.elapsed();
            if run < warm_up {
                continue;
            }
            let up = link
                .log
                .iter()
                .filter(|l| l.direction == Direction::Up)
                .count();
            result.up.push(up);
            result.down.push(link.log.len() - up);
            result.ms.push(elapsed.as_secs_f64() * 1e3);
        }
        results.push(result);
    }
    let load_after = load_average();
    let status = fcc.stop().ok();

    println!();
    println!(
        "Upload transfer through the real FCC partitions and GcsLink over UDP loopback \
         ({runs} runs per mission after {warm_up} warm-up runs; {cpus} CPUs; load average \
         before {load_before}, after {load_after})"
    );
    println!(
        "{:<14} {:>4} {:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>9}",
        "mission", "wps", "areas", "msgs up", "median", "p99", "min", "max", "msg/s", "RTT/msg"
    );
    println!(
        "{:<14} {:>4} {:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>9}",
        "", "", "", "(+down)", "ms", "ms", "ms", "ms", "both dirs", "ms"
    );
    let mut json = Vec::new();
    let mut medians = std::collections::HashMap::new();
    for r in &results {
        let mut sorted = r.ms.clone();
        sorted.sort_by(f64::total_cmp);
        let (med, p99) = (median(&sorted), percentile(&sorted, 0.99));
        let (min, max) = (sorted[0], sorted[sorted.len() - 1]);
        let up = *r.up.iter().max().unwrap();
        let down = *r.down.iter().max().unwrap();
        let retried = r.up.iter().filter(|&&u| u != r.expected).count();
        let per_s = (up + down) as f64 / (med / 1e3);
        let per_message = med / up as f64;
        medians.insert(r.case.waypoints, (med, up));
        println!(
            "{:<14} {:>4} {:>5} {:>9} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>10.0} {:>9.3}",
            r.case.name,
            r.case.waypoints,
            r.case.areas,
            format!("{up}+{down}"),
            med,
            p99,
            min,
            max,
            per_s,
            per_message
        );
        if retried > 0 || up != down {
            println!(
                "  note: {retried} runs sent other than the {} messages expected (retries?), \
                 {up} up, {down} down",
                r.expected
            );
        }
        json.push(serde_json::json!({
            "mission": r.case.name,
            "waypoints": r.case.waypoints,
            "areas": r.case.areas,
            "messages_up": up,
            "messages_down": down,
            "messages_expected_each_way": r.expected,
            "runs": r.ms.len(),
            "runs_with_other_message_count": retried,
            "median_ms": med,
            "p99_ms": p99,
            "min_ms": min,
            "max_ms": max,
            "messages_per_second_both_directions_at_median": per_s,
            "ms_per_uplink_message_at_median": per_message,
            "samples_ms": r.ms,
        }));
    }
    let growth = match (medians.get(&10), medians.get(&256)) {
        (Some((t10, m10)), Some((t256, m256))) => {
            let per = (t256 - t10) / (m256 - m10) as f64;
            println!();
            println!(
                "Growth: 10 -> 256 waypoints adds {} waypoint messages and {:.2} ms: {per:.3} ms \
                 per waypoint message (and its answer).",
                m256 - m10,
                t256 - t10
            );
            Some(per)
        }
        _ => None,
    };
    println!(
        "Stop-and-wait (ICD §5): one message in flight, the next goes out when the answer is \
         in, so the upload time is about (messages) x (round trip GCS -> UDP -> voting-monitoring \
         -> iceoryx2 -> mission-data-handling -> iceoryx2 -> voting-monitoring -> UDP -> GCS); the \
         per-frame processing (microseconds) is a small part of it. p99 is nearest-rank: with \
         fewer than 100 runs it is the maximum."
    );
    println!("FCC launcher stopped with SIGTERM: {status:?}");

    if bench_mode {
        let target = binaries::build_dir()
            .and_then(|d| d.parent().map(|p| p.to_path_buf()))
            .unwrap_or_else(|| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
        let out = target.join("transfer");
        std::fs::create_dir_all(&out).unwrap();
        let path = out.join("results.json");
        let doc = serde_json::json!({
            "description": "upload request (validate, clear, waypoints, route, transmit, areas) \
                            through the real FCC partitions and GcsLink over UDP loopback; \
                            stop-and-wait, one message in flight (ICD §5)",
            "runs": runs,
            "warm_up_runs": warm_up,
            "cpus": cpus,
            "load_average_before": load_before,
            "load_average_after": load_after,
            "ms_per_waypoint_message_10_to_256": growth,
            "missions": json,
        });
        std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        println!("written to {}", path.display());
    }
    let _ = std::fs::remove_dir_all(&rig.dir);
}
