//! Transfers over emulated links (BENCHMARKS.md section 6): the real FCC (the `fcc` launcher and
//! its partitions) and the real GCS link, through the user-space link emulator
//! (`missionlink::link_emulator`) with a named profile on both links, both ways. Each case is
//! uploaded (the paper's sequence, clear first) over another demo mission, so that both lists
//! change, and downloaded, stop-and-wait (window 1, ICD §5)
//! against windowed (window 32, ICD §10), in the same run. Reports per profile, case and window:
//! the median and p99 of the upload and the download, the completion rate, the ratio of the
//! windowed median to stop-and-wait's, and the ratio to n x RTT (messages up times the
//! profile's round trip, what any stop-and-wait protocol needs).
//!
//! ```sh
//! cargo bench --bench links                                   # every profile, 10 runs
//! cargo bench --bench links -- --profiles lte,satcom --runs 5 --cases 1,256
//! cargo bench --bench links -- --profiles bad --cases 2 --windows 32 --runs 200 --attempts 1,2
//! ```
//!
//! `--attempts` names how often the GCS may attempt each upload in all (`[timing]
//! upload_attempts`, default 2): `1,2` measures one attempt against the default in one run.
//!
//! Cases: 1 and 2 are demo missions 1 and 2, any other number a generated mission of that many
//! waypoints with 11 areas of 60 vertices.
//!
//! The ack timeout is set per profile above its round trip (ICD §1 lets every peer change it):
//! 500 ms (lan, lte, bad), 1500 ms (satcom). Results: `target/links/results.json`, and the plot
//! of the upload medians `target/links/links.svg` (committed as `docs/links.svg`).
// A benchmark stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink::harness;
use missionlink::harness::log_axis;

use std::time::{Duration, Instant};

use missionlink::link_emulator::Profile;
use missionlink_gcs::gcs_link::{Direction, Finished};
use missionlink_ground::ground_station::{MissionPlan, Sequence};
use missionlink_interfaces::wire::TransferWindow;
use missionlink_protocol::testkit;

/// Stop-and-wait and the default window, unless `--windows` names others.
const WINDOWS: [u8; 2] = [1, 32];

#[derive(Clone)]
struct Case {
    name: String,
    plan: MissionPlan,
}

struct Row {
    profile: Profile,
    case: String,
    window: u8,
    /// Attempts the GCS may make per upload.
    attempts: u8,
    /// Uploads that completed in their second attempt or later.
    again: usize,
    messages_up: usize,
    upload_ms: Vec<f64>,
    download_ms: Vec<f64>,
    runs: usize,
    failures: Vec<String>,
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = (p * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

fn sorted(v: &[f64]) -> Vec<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s
}

/// The profile's round trip: twice the one-way delay and the mean jitter.
fn rtt(profile: Profile) -> Duration {
    let i = profile.impairments();
    2 * (i.delay + i.jitter / 2)
}

fn cases(sizes: &[u16]) -> Vec<Case> {
    sizes
        .iter()
        .map(|&n| match n {
            1 => Case {
                name: "mission-1".to_owned(),
                plan: harness::plan("mission-1.toml"),
            },
            2 => Case {
                name: "mission-2".to_owned(),
                plan: harness::plan("mission-2.toml"),
            },
            n => Case {
                name: format!("generated-{n}"),
                plan: testkit::generated_plan(n),
            },
        })
        .collect()
}

fn measure(
    profile: Profile,
    cases: &[Case],
    windows: &[u8],
    attempts: &[u8],
    runs: usize,
    seed: u64,
) -> Vec<Row> {
    let mut rig = harness::Rig::new(&format!("bench-links-{}", profile.name()));
    let ack = match profile {
        Profile::Satcom => 1500,
        _ => 500,
    };
    rig.config.timing.ack_timeout_ms = ack;
    rig.config.timing.transfer_timeout_ms = 3 * ack + 2 * rtt(profile).as_millis() as u64;
    let (mut fcc, mut link, emulator) = rig.start_through([profile.impairments(); 4], seed);
    link.enable_log();

    let mut rows = Vec::new();
    for case in cases {
        let valid = link.station().validate(&case.plan).unwrap();
        // Every measured upload changes both lists: before it the FCC holds another demo
        // mission. Uploaded over the lists it equals, a failed transfer would leave them as
        // they were and still count as complete.
        let base = harness::plan(if case.name == "mission-1" {
            "mission-2.toml"
        } else {
            "mission-1.toml"
        });
        let base = link.station().validate(&base).unwrap();
        for (&window, &attempts) in windows
            .iter()
            .flat_map(|w| attempts.iter().map(move |a| (w, a)))
        {
            link.station()
                .set_transfer_window(TransferWindow::new(window).unwrap());
            link.station().set_upload_attempts(attempts);
            let mut row = Row {
                profile,
                case: case.name.clone(),
                window,
                attempts,
                again: 0,
                messages_up: 0,
                upload_ms: Vec::new(),
                download_ms: Vec::new(),
                runs,
                failures: Vec::new(),
            };
            for run in 0..runs {
                let mut based = false;
                for _ in 0..5 {
                    let now = link.now();
                    let up = link
                        .station()
                        .upload_validated(now, base.clone(), Sequence::Paper { clear: true })
                        .and_then(|()| harness::finish(&mut link));
                    if matches!(&up, Ok(Finished::Uploaded(r)) if r.is_complete()) {
                        based = true;
                        break;
                    }
                }
                assert!(
                    based,
                    "run {run}: the other mission did not go up in 5 uploads"
                );
                link.log.clear();
                let now = link.now();
                let start = Instant::now();
                let up = link
                    .station()
                    .upload_validated(now, valid.clone(), Sequence::Paper { clear: true })
                    .and_then(|()| harness::finish(&mut link));
                let took = start.elapsed();
                match up {
                    Ok(Finished::Uploaded(r)) if r.is_complete() => {
                        row.upload_ms.push(took.as_secs_f64() * 1e3);
                        if let Some((phase, e)) = r.failure {
                            row.failures.push(format!(
                                "run {run} upload: complete, confirmed by the report after {phase}: {e}"
                            ));
                        }
                        if r.attempts > 1 {
                            row.again += 1;
                            row.failures.push(format!(
                                "run {run} upload: complete in attempt {}",
                                r.attempts
                            ));
                        } else {
                            row.messages_up = link
                                .log
                                .iter()
                                .filter(|l| l.direction == Direction::Up)
                                .count();
                        }
                    }
                    other => row.failures.push(format!("run {run} upload: {other:?}")),
                }
                let now = link.now();
                let start = Instant::now();
                let down = link
                    .station()
                    .download(now)
                    .and_then(|()| harness::finish(&mut link));
                let took = start.elapsed();
                match down {
                    Ok(Finished::Downloaded(plan)) if *plan == valid => {
                        row.download_ms.push(took.as_secs_f64() * 1e3)
                    }
                    other => row.failures.push(format!("run {run} download: {other:?}")),
                }
            }
            eprintln!(
                "{} {} window {window}, {attempts} attempt(s): {} of {runs} uploads ({} in a later attempt), {} downloads",
                profile.name(),
                case.name,
                row.upload_ms.len(),
                row.again,
                row.download_ms.len()
            );
            rows.push(row);
        }
    }
    fcc.stop().unwrap();
    println!(
        "{}: emulator flows (up direct, up LTE, down direct, down LTE): {:?}",
        profile.name(),
        emulator.stats()
    );
    rows
}

fn arg<'a>(args: &'a [String], name: &str) -> Option<&'a str> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(String::as_str)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bench = args.iter().any(|a| a == "--bench");
    let runs: usize = arg(&args, "--runs")
        .map(|v| v.parse().expect("--runs N"))
        .unwrap_or(if bench { 10 } else { 1 });
    let profiles: Vec<Profile> = arg(&args, "--profiles")
        .map(|v| {
            v.split(',')
                .map(|p| Profile::named(p).expect("lan, lte, satcom or bad"))
                .collect()
        })
        .unwrap_or_else(|| {
            if bench {
                Profile::ALL.to_vec()
            } else {
                vec![Profile::Lte]
            }
        });
    let sizes: Vec<u16> = arg(&args, "--cases")
        .map(|v| {
            v.split(',')
                .map(|n| n.parse().expect("--cases 1,10,100,256"))
                .collect()
        })
        .unwrap_or_else(|| {
            if bench {
                vec![1, 10, 100, 256]
            } else {
                vec![1]
            }
        });
    let cases = cases(&sizes);
    let windows: Vec<u8> = arg(&args, "--windows")
        .map(|v| {
            v.split(',')
                .map(|n| n.parse().expect("--windows 1,32"))
                .collect()
        })
        .unwrap_or_else(|| WINDOWS.to_vec());
    let attempts: Vec<u8> = arg(&args, "--attempts")
        .map(|v| {
            v.split(',')
                .map(|n| n.parse().expect("--attempts 1,2"))
                .collect()
        })
        .unwrap_or_else(|| vec![2]);

    let mut rows = Vec::new();
    for (i, profile) in profiles.iter().enumerate() {
        rows.extend(measure(
            *profile,
            &cases,
            &windows,
            &attempts,
            runs,
            15 + i as u64,
        ));
    }

    println!(
        "\n{:<7} {:<14} {:>3} {:>3} {:>5} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>5} {:>8} {:>9}",
        "profile",
        "case",
        "W",
        "att",
        "msgs",
        "up p50 ms",
        "up p99 ms",
        "dn p50 ms",
        "dn p99 ms",
        "up ok",
        "down ok",
        "later",
        "/ W=1",
        "/ n x RTT"
    );
    let mut json = Vec::new();
    for row in &rows {
        let up = sorted(&row.upload_ms);
        let down = sorted(&row.download_ms);
        let up50 = percentile(&up, 0.5);
        let stop_and_wait = rows
            .iter()
            .find(|r| {
                r.profile == row.profile
                    && r.case == row.case
                    && r.window == 1
                    && r.attempts == row.attempts
            })
            .map(|r| percentile(&sorted(&r.upload_ms), 0.5))
            .unwrap_or(f64::NAN);
        let n_rtt = row.messages_up as f64 * rtt(row.profile).as_secs_f64() * 1e3;
        println!(
            "{:<7} {:<14} {:>3} {:>3} {:>5} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>4}/{:<4} {:>4}/{:<4} {:>5} {:>8.2} {:>9.2}",
            row.profile.name(),
            row.case,
            row.window,
            row.attempts,
            row.messages_up,
            up50,
            percentile(&up, 0.99),
            percentile(&down, 0.5),
            percentile(&down, 0.99),
            row.upload_ms.len(),
            row.runs,
            row.download_ms.len(),
            row.runs,
            row.again,
            up50 / stop_and_wait,
            up50 / n_rtt,
        );
        for f in &row.failures {
            println!("    {f}");
        }
        json.push(serde_json::json!({
            "profile": row.profile.name(),
            "case": row.case,
            "window": row.window,
            "attempts": row.attempts,
            "completed_in_a_later_attempt": row.again,
            "messages_up": row.messages_up,
            "runs": row.runs,
            "uploads_completed": row.upload_ms.len(),
            "downloads_completed": row.download_ms.len(),
            "upload_ms": row.upload_ms,
            "download_ms": row.download_ms,
            "failures": row.failures,
            "rtt_ms": rtt(row.profile).as_secs_f64() * 1e3,
        }));
    }
    if bench {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/links");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("results.json");
        std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
        let plot = dir.join("links.svg");
        std::fs::write(&plot, svg(&rows)).unwrap();
        println!("written to {} and {}", path.display(), plot.display());
    }
}

/// The plot: per profile and case the upload medians of each window (and number of attempts)
/// measured, bars on a logarithmic ms axis, the n x RTT of stop-and-wait as a tick.
fn svg(rows: &[Row]) -> String {
    use std::fmt::Write as _;
    const COLOURS: [&str; 4] = ["#e45756", "#4c78a8", "#72b7b2", "#f58518"];
    const BAR: f64 = 16.0;
    const GAP: f64 = 28.0;
    const LEFT: f64 = 70.0;
    const TOP: f64 = 70.0;
    const PLOT_H: f64 = 320.0;
    let mut groups: Vec<(Profile, &str)> = Vec::new();
    let mut series: Vec<(u8, u8)> = Vec::new();
    for r in rows {
        if !groups.contains(&(r.profile, r.case.as_str())) {
            groups.push((r.profile, r.case.as_str()));
        }
        if !series.contains(&(r.window, r.attempts)) {
            series.push((r.window, r.attempts));
        }
    }
    let group_w = BAR * series.len() as f64 + GAP;
    let width = LEFT + groups.len() as f64 * group_w + 20.0;
    let height = TOP + PLOT_H + 110.0;
    let bottom = TOP + PLOT_H;
    let axis = log_axis::LogAxis::new(
        rows.iter().map(|r| percentile(&sorted(&r.upload_ms), 0.5)),
        bottom,
        PLOT_H,
    );
    let y = |v: f64| axis.y(v);
    let mut s = log_axis::begin(
        width,
        height,
        LEFT,
        22.0,
        "Upload over emulated links, median (log scale)",
    );
    let w = &mut s;
    for (i, (window, attempts)) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let label = format!("window {window}, {attempts} attempt(s)");
        log_axis::legend_entry(w, LEFT + i as f64 * 170.0, 36.0, colour, &label);
    }
    let _ = writeln!(
        w,
        r#"<text x="{}" y="46">| n x RTT</text>"#,
        LEFT + series.len() as f64 * 170.0
    );
    axis.grid(w, LEFT, width - 20.0, "ms");
    for (g, (profile, case)) in groups.iter().enumerate() {
        let x0 = LEFT + g as f64 * group_w + GAP / 2.0;
        for (i, key) in series.iter().enumerate() {
            let Some(row) = rows.iter().find(|r| {
                r.profile == *profile && r.case == *case && (r.window, r.attempts) == *key
            }) else {
                continue;
            };
            let median = percentile(&sorted(&row.upload_ms), 0.5);
            if median.is_nan() {
                continue;
            }
            let (x, top) = (x0 + i as f64 * BAR, y(median));
            let colour = COLOURS[i % COLOURS.len()];
            let _ = writeln!(
                w,
                r#"<rect x="{x}" y="{top}" width="{}" height="{}" fill="{colour}"><title>{} {case} W={} attempts {}: {median:.0} ms</title></rect>"#,
                BAR - 2.0,
                bottom - top,
                profile.name(),
                row.window,
                row.attempts
            );
            let n_rtt = row.messages_up as f64 * rtt(row.profile).as_secs_f64() * 1e3;
            if n_rtt > 0.0 {
                let ty = y(n_rtt);
                let _ = writeln!(
                    w,
                    r#"<line x1="{}" x2="{}" y1="{ty}" y2="{ty}" stroke="black" stroke-width="2"/>"#,
                    x - 1.0,
                    x + BAR - 1.0
                );
            }
        }
        let cx = x0 + BAR * series.len() as f64 / 2.0;
        let _ = writeln!(
            w,
            r##"<text x="{cx}" y="{}" text-anchor="middle">{}</text><text x="{cx}" y="{}" text-anchor="middle" fill="#555">{case}</text>"##,
            bottom + 18.0,
            profile.name(),
            bottom + 34.0
        );
    }
    let _ = writeln!(w, "</svg>");
    s
}
