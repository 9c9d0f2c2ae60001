//! End-to-end transfer time: the real FCC (the `fcc` launcher and its four partitions, over
//! iceoryx2) and the real GCS link (`GcsLink`, both UDP links on loopback), each mission uploaded
//! both ways `gcs upload` can, in the same run: by the paper's sequence (`--paper-sequence`:
//! the report, clear, take-off height, waypoints, route, transmit, then the areas: initiate, one
//! #2012 per area, complete) and atomically (the default toward an edition-2 FCC, ICD §8: the
//! report, mode 10, the mission's messages, mode 8, the areas closed by #2011 mode 7, #50000
//! command 4, the staged copy deleted), with the ratio of the medians. Each message waits for
//! its answer before the next goes out (ICD §5, one message in flight), so the time is dominated
//! by round trips.
//!
//! Missions: demo mission 1 (one waypoint and its fly-zone; the paper reports about 0.4 s for
//! this transfer) and generated missions of 10, 100 and 256 waypoints, each with 11 areas of 60
//! vertices (the fly-zone and ten no-fly-zones). Prints a table and writes
//! `target/transfer/results.json`.
//!
//! ```sh
//! cargo bench --bench transfer                 # 30 runs per mission
//! cargo bench --bench transfer -- --runs 100
//! cargo bench --bench transfer -- --cpu-shares  # each partition's CPU share, idle 60 s and
//!                                               # during 256-waypoint uploads (20 s)
//! ```
//!
//! `--idle block|backoff|doorbell` (with `--spin-us N`, else no spin) runs every partition with
//! that idle strategy instead of each partition's default (`config::Idle`), to compare the wait
//! paths; `--vm-idle MODE` (with `--vm-spin-us N`) sets voting-monitoring's alone.
//!
//! `--case NAME` runs only the missions of that name (`mission-1`, `generated-10`,
//! `generated-100`, `generated-256`, `worst-case-256`, `mission-1 signed`, `generated-256
//! signed`), for many short runs to compare; `--no-isolation` starts the partitions unfenced
//! (`[isolation] enabled = false`), to measure what the fence costs an upload.
//!
//! `--cpu-shares` (`--idle-seconds N`, `--upload-seconds N`) measures instead each partition's
//! share of one CPU from /proc (its process's user and system time over the wall time): with
//! the FCC up and no traffic, then while the GCS uploads the generated 256-waypoint mission back
//! to back; written to `target/transfer/cpu_shares.json`.
//!
//! Without `--bench` (`cargo test --benches`) it makes one run per mission and writes nothing.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink::harness;

use std::time::{Duration, Instant};

use missionlink_gcs::gcs_link::Direction;
use missionlink_ground::ground_station::{MissionPlan, Sequence};
use missionlink_partitions::binaries;
use missionlink_partitions::config::{Idle, IdleMode, IdlePerPartition};
use missionlink_protocol::testkit;

const DEFAULT_RUNS: usize = 30;
const WARM_UP_RUNS: usize = 2;

#[derive(Clone)]
struct Case {
    name: String,
    waypoints: usize,
    areas: usize,
    plan: MissionPlan,
}

struct Measured {
    case: Case,
    /// The paper's sequence, or the atomic upload of ICD §8.
    sequence: Sequence,
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

fn generated(n: u16) -> Case {
    Case {
        name: format!("generated-{n}"),
        waypoints: usize::from(n),
        areas: 11,
        plan: testkit::generated_plan(n),
    }
}

/// Starts an FCC whose guidance starts at `start` (latitude, longitude; the configuration's
/// default when `None`) and uploads each case `runs` times after `warm_up` runs, once per
/// sequence given; how the FCC launcher stopped.
fn measure(
    name: &str,
    start: Option<(f64, f64)>,
    signed: bool,
    cases: Vec<(Case, Vec<Sequence>)>,
    warm_up: usize,
    runs: usize,
) -> (Vec<Measured>, Option<std::process::ExitStatus>) {
    let cases: Vec<_> = cases
        .into_iter()
        .filter(|(case, _)| chosen(&case.name))
        .collect();
    if cases.is_empty() {
        return (Vec::new(), None);
    }
    let mut rig = harness::Rig::new(name);
    rig.config.ipc.idle = idle_override();
    rig.config.isolation.enabled = fenced();
    if let Some((latitude, longitude)) = start {
        rig.config.guidance.start_latitude_deg = latitude;
        rig.config.guidance.start_longitude_deg = longitude;
    }
    if !signed {
        // The rig signs both links, both ways, as the defaults do (ICD §9); the unsigned rows
        // say so in writing, as a deployment would have to, and hold no key.
        rig.config.signing = missionlink_partitions::config::Signing {
            policy: missionlink_partitions::config::SigningPolicy::Off,
            key_files: Vec::new(),
            send_key_id: None,
        };
    }
    let mut fcc = rig.start("fcc");
    for partition in [
        "voting-monitoring",
        "mission-data-handling",
        "system-automation",
        "guidance-stub",
    ] {
        harness::wait_for_log(&fcc, &format!("{partition} up"), Duration::from_secs(30));
    }
    let mut link = rig.gcs(&mut fcc);
    link.enable_log();

    let mut results = Vec::new();
    for (case, sequences) in cases {
        let valid = link.station().validate(&case.plan).unwrap();
        assert_eq!(valid.mission.waypoints.len(), case.waypoints);
        assert_eq!(valid.areas.areas.len(), case.areas);
        // The paper's sequence (ICD §5): the report request and the acknowledgement of its one
        // entry (ICD §10.1, the edition discovery before every upload); clear, take-off,
        // waypoints (+ RF centres), route, transmit; initiate, areas, complete. The atomic
        // upload (ICD §8): the report; mode 10, the mission's messages, mode 8; initiate, areas,
        // mode 7; activate; delete the staged copy.
        let body = valid.mission.message_count() + 1 + 1 + case.areas + 1;
        for sequence in sequences {
            let expected = match sequence {
                Sequence::Paper { .. } => 2 + 1 + body,
                Sequence::Atomic => 2 + 1 + body + 2,
            };
            let mut result = Measured {
                case: case.clone(),
                sequence,
                expected,
                up: Vec::new(),
                down: Vec::new(),
                ms: Vec::new(),
            };
            for run in 0..warm_up + runs {
                link.log.clear();
                let start = Instant::now();
                let now = link.now();
                let outcome = link
                    .station()
                    .upload_with(now, &result.case.plan, sequence)
                    .and_then(|()| harness::finish(&mut link));
                let elapsed = start.elapsed();
                match outcome {
                    Ok(missionlink_gcs::gcs_link::Finished::Uploaded(report))
                        if report.failure.is_none() => {}
                    other => panic!("{} run {run}: {other:?}", result.case.name),
                }
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
    }
    let status = fcc.stop().ok();
    let _ = std::fs::remove_dir_all(&rig.dir);
    (results, status)
}

/// The partitions' idle strategies: each partition's default unless `--idle
/// block|backoff|doorbell` (with `--spin-us N`, else no spin) names one for every partition (to
/// compare the wait paths).
fn idle_override() -> IdlePerPartition {
    let args: Vec<String> = std::env::args().collect();
    let mode_after = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map(|mode| match mode.as_str() {
                "block" => IdleMode::Block,
                "backoff" => IdleMode::Backoff,
                "doorbell" => IdleMode::Doorbell,
                other => panic!("{flag} {other}: block, backoff or doorbell"),
            })
    };
    let mut idle = match mode_after("--idle") {
        Some(mode) => IdlePerPartition::all(Idle {
            mode,
            spin_us: number_after(&args, "--spin-us").unwrap_or(0),
            yield_us: 0,
        }),
        None => IdlePerPartition::default(),
    };
    if let Some(mode) = mode_after("--vm-idle") {
        idle.voting_monitoring = Idle {
            mode,
            spin_us: number_after(&args, "--vm-spin-us").unwrap_or(0),
            yield_us: 0,
        };
    }
    idle
}

/// How the partitions wait, for the output: mission data handling's strategy, and
/// voting-monitoring's where it differs.
fn idle_label(idle: &IdlePerPartition) -> String {
    let (vm, mdh) = (idle.voting_monitoring, idle.mission_data_handling);
    let show = |i: Idle| format!("{:?} spin {} µs", i.mode, i.spin_us).to_lowercase();
    if vm == mdh {
        format!("every partition {}", show(mdh))
    } else {
        format!("voting-monitoring {}, the others {}", show(vm), show(mdh))
    }
}

/// The partitions of the FCC, as the launcher names them.
const PARTITIONS: [&str; 4] = [
    "voting-monitoring",
    "mission-data-handling",
    "system-automation",
    "guidance-stub",
];

/// CPU time (user + system) of process `pid` so far, in clock ticks, from /proc.
fn cpu_ticks(pid: i32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // utime and stime: fields 14 and 15, the 12th and 13th after the command name.
    let (_, rest) = stat.rsplit_once(')').unwrap();
    rest.split_whitespace()
        .skip(11)
        .take(2)
        .map(|v| v.parse::<u64>().unwrap())
        .sum()
}

/// Clock ticks per second of /proc's CPU times (USER_HZ, 100 on Linux for x86 and ARM).
const TICKS_PER_SECOND: f64 = 100.0;

/// Each partition's share of one CPU while `during` runs, in %, from /proc: the CPU time its
/// process used over the wall time `during` took.
fn cpu_shares(pids: &[(&str, i32)], during: impl FnOnce()) -> (Vec<f64>, f64) {
    let before: Vec<u64> = pids.iter().map(|(_, pid)| cpu_ticks(*pid)).collect();
    let start = Instant::now();
    during();
    let seconds = start.elapsed().as_secs_f64();
    let shares = pids
        .iter()
        .zip(before)
        .map(|((_, pid), b)| 100.0 * (cpu_ticks(*pid) - b) as f64 / TICKS_PER_SECOND / seconds)
        .collect();
    (shares, seconds)
}

/// `--cpu-shares`: each partition's CPU share with no traffic for `idle` (the FCC up, nothing
/// sent), then during back-to-back uploads of the generated 256-waypoint mission (the paper's
/// sequence) for at least `busy`, from /proc. Prints a table and writes
/// `target/transfer/cpu_shares.json` in bench mode.
fn cpu_shares_main(idle: Duration, busy: Duration, bench_mode: bool) {
    let mut rig = harness::Rig::new("bench-cpu-shares");
    rig.config.ipc.idle = idle_override();
    let idle_strategy = idle_label(&rig.config.ipc.idle);
    let mut fcc = rig.start("fcc");
    for partition in PARTITIONS {
        harness::wait_for_log(&fcc, &format!("{partition} up"), Duration::from_secs(30));
    }
    let pids: Vec<(&str, i32)> = PARTITIONS
        .iter()
        .map(|p| (*p, harness::partition_pid(&fcc, p)))
        .collect();
    let mut link = rig.gcs(&mut fcc);
    // Settle: the start's work (the first beats, late joiners) is not idle.
    std::thread::sleep(Duration::from_secs(2));
    let load_before = load_average();
    let (idle_shares, idle_s) = cpu_shares(&pids, || std::thread::sleep(idle));
    let case = generated(256);
    let mut uploads = 0;
    let (busy_shares, busy_s) = cpu_shares(&pids, || {
        let start = Instant::now();
        while start.elapsed() < busy {
            let now = link.now();
            let outcome = link
                .station()
                .upload_with(now, &case.plan, Sequence::Paper { clear: true })
                .and_then(|()| harness::finish(&mut link));
            match outcome {
                Ok(missionlink_gcs::gcs_link::Finished::Uploaded(report))
                    if report.failure.is_none() => {}
                other => panic!("upload {uploads}: {other:?}"),
            }
            uploads += 1;
        }
    });
    let load_after = load_average();
    let _ = fcc.stop();
    println!(
        "CPU share of one CPU per partition, from /proc ({idle_strategy}; load average \
         before {load_before}, after {load_after})"
    );
    println!(
        "{:<24} {:>16} {:>24}",
        "partition",
        format!("idle {idle_s:.0} s"),
        format!("256-waypoint uploads ({uploads} in {busy_s:.1} s)")
    );
    let mut json = Vec::new();
    for (((name, _), idle), busy) in pids.iter().zip(&idle_shares).zip(&busy_shares) {
        println!("{name:<24} {:>15.2}% {:>23.2}%", idle, busy);
        json.push(serde_json::json!({
            "partition": name,
            "idle_percent_of_one_cpu": idle,
            "upload_percent_of_one_cpu": busy,
        }));
    }
    if bench_mode {
        let out = output_dir();
        let path = out.join("cpu_shares.json");
        let doc = serde_json::json!({
            "what": "CPU time of each partition process over wall time, in % of one CPU, from /proc: idle (no traffic) and during back-to-back uploads of a generated 256-waypoint mission (the paper's sequence)",
            "idle_seconds": idle_s,
            "upload_seconds": busy_s,
            "uploads": uploads,
            "load_average_before": load_before,
            "load_average_after": load_after,
            "idle_strategy": idle_strategy,
            "partitions": json,
        });
        std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        println!("written to {}", path.display());
    }
}

/// `target/transfer`, created if missing.
fn output_dir() -> std::path::PathBuf {
    let target = binaries::build_dir()
        .and_then(|d| d.parent().map(|p| p.to_path_buf()))
        .unwrap_or_else(|| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    let out = target.join("transfer");
    std::fs::create_dir_all(&out).unwrap();
    out
}

/// Whether the partitions run fenced: the default, unless `--no-isolation`.
fn fenced() -> bool {
    !std::env::args().any(|a| a == "--no-isolation")
}

/// [`fenced`] in words, for the table's header and the results file.
fn fence_label() -> &'static str {
    if !fenced() {
        "partitions not fenced"
    } else {
        "partitions fenced"
    }
}

/// Whether the case `name` runs: every case, or the one `--case NAME` names.
fn chosen(name: &str) -> bool {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--case")
        .and_then(|i| args.get(i + 1))
        .is_none_or(|only| only == name)
}

/// The number after `flag` on the command line, if given.
fn number_after(args: &[String], flag: &str) -> Option<u64> {
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse().unwrap_or_else(|_| panic!("{flag} N")))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bench_mode = args.iter().any(|a| a == "--bench");
    if args.iter().any(|a| a == "--cpu-shares") {
        let idle = number_after(&args, "--idle-seconds").unwrap_or(60);
        let busy = number_after(&args, "--upload-seconds").unwrap_or(20);
        cpu_shares_main(
            Duration::from_secs(idle),
            Duration::from_secs(busy),
            bench_mode,
        );
        return;
    }
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse::<usize>().expect("--runs N"))
        .unwrap_or(if bench_mode { DEFAULT_RUNS } else { 1 })
        .max(1);
    let warm_up = if bench_mode { WARM_UP_RUNS } else { 0 };

    // The paper's sequence for every mission. The atomic upload only where the activation's
    // onboard geofence check (ICD §7, §8) passes from where guidance starts: demo mission 1
    // from TROL, and the geofence worst case (256 waypoints, 11 areas of 60 vertices) from its
    // take-off point, on an FCC of its own. The generated zig-zags cross their no-fly-zones
    // (they were made to measure transfers, not to be flown), so an activation refuses them.
    let paper = Sequence::Paper { clear: true };
    let trol = vec![
        (
            Case {
                name: "mission-1".to_owned(),
                waypoints: 1,
                areas: 1,
                plan: harness::plan("mission-1.toml"),
            },
            vec![paper, Sequence::Atomic],
        ),
        (generated(10), vec![paper]),
        (generated(100), vec![paper]),
        (generated(256), vec![paper]),
    ];
    let worst = testkit::geofence_worst_case_plan();
    let take_off = worst
        .take_off_position
        .expect("the worst case has a take-off point");
    let worst_case = vec![(
        Case {
            name: "worst-case-256".to_owned(),
            waypoints: 256,
            areas: 11,
            plan: worst,
        },
        vec![paper, Sequence::Atomic],
    )];

    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load_before = load_average();
    let mut results = measure("bench-transfer", None, false, trol, warm_up, runs);
    let status = results.1;
    let worst = measure(
        "bench-transfer-worst",
        Some((take_off.latitude.degrees(), take_off.longitude.degrees())),
        false,
        worst_case,
        warm_up,
        runs,
    );
    results.0.extend(worst.0);
    // The same transfers with signed links (ICD §9), on an FCC of their own that requires
    // them: the ratio column compares with the unsigned run of the same case above.
    let signed_cases = vec![
        (
            Case {
                name: "mission-1 signed".to_owned(),
                waypoints: 1,
                areas: 1,
                plan: harness::plan("mission-1.toml"),
            },
            vec![paper],
        ),
        (
            Case {
                name: "generated-256 signed".to_owned(),
                ..generated(256)
            },
            vec![paper],
        ),
    ];
    let signed = measure(
        "bench-transfer-signed",
        None,
        true,
        signed_cases,
        warm_up,
        runs,
    );
    results.0.extend(signed.0);
    let results = results.0;
    let load_after = load_average();

    println!();
    println!(
        "Upload transfer through the real FCC partitions and GcsLink over UDP loopback \
         ({runs} runs per mission after {warm_up} warm-up runs; {cpus} CPUs; load average \
         before {load_before}, after {load_after}; {}; {})",
        idle_label(&idle_override()),
        fence_label()
    );
    println!(
        "{:<14} {:<7} {:>4} {:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>9} {:>8}",
        "mission",
        "upload",
        "wps",
        "areas",
        "msgs up",
        "median",
        "p99",
        "min",
        "max",
        "msg/s",
        "RTT/msg",
        "/ paper"
    );
    println!(
        "{:<14} {:<7} {:>4} {:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>9} {:>8}",
        "", "", "", "", "(+down)", "ms", "ms", "ms", "ms", "both dirs", "ms", "median"
    );
    let mut json = Vec::new();
    // The paper's sequence by waypoints: the growth and the atomic upload's ratio.
    let mut paper_medians = std::collections::HashMap::new();
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
        let atomic = matches!(r.sequence, Sequence::Atomic);
        let signed = r.case.name.ends_with(" signed");
        let ratio = if atomic || signed {
            paper_medians
                .get(&r.case.waypoints)
                .map_or_else(String::new, |(p, _)| format!("{:.2}", med / p))
        } else {
            paper_medians.insert(r.case.waypoints, (med, up));
            "1.00".to_owned()
        };
        println!(
            "{:<14} {:<7} {:>4} {:>5} {:>9} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>10.0} {:>9.3} {:>8}",
            r.case.name,
            if atomic { "atomic" } else { "paper" },
            r.case.waypoints,
            r.case.areas,
            format!("{up}+{down}"),
            med,
            p99,
            min,
            max,
            per_s,
            per_message,
            ratio
        );
        if retried > 0 {
            println!(
                "  note: {retried} runs sent other than the {} messages expected (retries?), \
                 {up} up, {down} down",
                r.expected
            );
        }
        json.push(serde_json::json!({
            "mission": r.case.name,
            "upload": if matches!(r.sequence, Sequence::Atomic) { "atomic (ICD §8: stage, activate, delete the copy)" } else { "paper's sequence (ICD §5.1, §5.3)" },
            "signed": signed,
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
    let growth = match (paper_medians.get(&10), paper_medians.get(&256)) {
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
        let path = output_dir().join("results.json");
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
            "idle_strategy": idle_label(&idle_override()),
            "isolation": fence_label(),
            "missions": json,
        });
        std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        println!("written to {}", path.display());
    }
}
