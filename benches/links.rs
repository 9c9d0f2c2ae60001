//! Transfers over emulated links (BENCHMARKS.md section 6): the real FCC (the `fcc` launcher and
//! its partitions) and the real GCS link, through the user-space link emulator
//! (`missionlink::link_emulator`) with a named profile on both links, both ways (`lan`, `lte`,
//! `satcom`, `satcom-narrow`, `bad`; the rates of `lte`, `satcom` and `satcom-narrow` limit
//! what the links carry). Each case is uploaded (the paper's sequence, clear first) over
//! another demo mission, so that both lists change, and downloaded, stop-and-wait (window 1,
//! ICD §5) against windowed (window 128, ICD §10), in the same run. Reports per profile, case
//! and window: the median and p99 of the upload and the download, the completion rate, the
//! ratio of the windowed median to stop-and-wait's, the ratio to n x RTT (messages up times the
//! profile's round trip, what any stop-and-wait protocol needs), and beside each median the
//! link's floor and the ratio of the median to it.
//!
//! ```sh
//! cargo bench --bench links                                   # every profile, 10 runs
//! cargo bench --bench links -- --profiles lte,satcom --runs 5 --cases 1,256
//! cargo bench --bench links -- --profiles satcom-narrow --cases 1 --windows 1,128
//! cargo bench --bench links -- --profiles bad --cases 2 --windows 128 --runs 200 --attempts 1,2
//! cargo bench --bench links -- --profiles satcom --cases 256 --runs 1 --trace  # every message
//! ```
//!
//! `--trace` prints every message of each measured upload with its time (stderr).
//!
//! `--attempts` names how often the GCS may attempt each upload in all (`[timing]
//! upload_attempts`, default 2): `1,2` measures one attempt against the default in one run.
//!
//! Cases: 1 and 2 are demo missions 1 and 2, any other number a generated mission of that many
//! waypoints with 11 areas of 60 vertices. Without `--cases`, 1, 10, 100 and 256, but on
//! `satcom-narrow` mission 1 alone: at 2.4 kbit/s the generated missions' areas take minutes a
//! transfer.
//!
//! **The floor** of a transfer is a time no protocol that needs the same round trips and sends
//! the same bytes can beat on the link: the larger of (round trips) x (the profile's round
//! trip) and (bytes) / (rate) + (the profile's round trip). Both are lower bounds: each round
//! begins only when an answer of the round before has come back, so R rounds take R round
//! trips; and the last byte of the transfer leaves the sender only after all the bytes before
//! it were serialised, then travels one way, and the transfer ends only when what answers it
//! (or, for a download, the request that began it) has travelled the other. Their sum is not a
//! bound: a window sends its bytes while it waits for answers. Each term is counted from what
//! the transfer sent, read off the emulator across it, not from a table:
//! - the round trips are the emulator's count (`Emulator::round_trips`, the rule of
//!   `missionlink_linksim::round_trips`): a datagram up belongs to the round after the latest
//!   answer delivered before it was sent, an answer to the latest round its sender received.
//!   The rule reads times, not contents, so where the round trip is shorter than the time the
//!   GCS takes to send a window (lan) it counts high and the floor means nothing;
//! - the round trip is the profile's without serialisation (both one-way delays and the mean
//!   jitters);
//! - bytes / rate is, over the four flows, the longest time one flow's bytes (every datagram
//!   the emulator was offered on it during the transfer, resends included) take at that flow's
//!   rate: the two ways and the two links serialise side by side. A flow without a rate adds
//!   nothing.
//!
//! The floor is computed per run; a row shows the median of its runs' floors, and "/ floor" is
//! the median time over that. The FCC's position downlink (#101, ICD §5.8) is off in this
//! bench, so that what the links carry during a transfer is the transfer's: traffic of its
//! own would fill the idle round trips and, counted in the bytes, lift the floor above what
//! the transfer needs.
//!
//! The ack timeout is set per profile above its round trip and the queue a window can build
//! (ICD §1 lets every peer change it): the larger of 500 ms and 2.5 round trips, plus the
//! longest queue of frames of the largest signed size (564 bytes) at a rate: toward the FCC the
//! largest window measured, but at most two round trips' worth and a frame (what the GCS keeps
//! in flight, ICD §10.3, §10.4), toward the GCS the download's window (at most 32). With windows
//! up to 128: 500 ms on lan and bad, 615 ms on lte, 2770 ms on satcom, 63 910 ms on
//! satcom-narrow (its download window of 32 frames takes 60 s at 2.4 kbit/s). Results:
//! `target/links/results.json`, and the plot of the upload medians `target/links/links.svg`.
// A benchmark stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink::harness;
use missionlink::harness::log_axis;

use std::time::{Duration, Instant};

use missionlink::link_emulator::{Emulator, Profile};
use missionlink_gcs::gcs_link::{Direction, Finished};
use missionlink_ground::ground_station::{MissionPlan, Sequence};
use missionlink_interfaces::wire::{MAX_SIGNED_FRAME_LEN, TransferWindow};
use missionlink_protocol::testkit;

/// Stop-and-wait and the default window, unless `--windows` names others.
const WINDOWS: [u8; 2] = [1, 128];

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
    /// What each completed upload carried, beside its time.
    upload_carried: Vec<Carried>,
    /// What each complete download carried.
    download_carried: Vec<Carried>,
    runs: usize,
    failures: Vec<String>,
}

/// What one transfer did on the links: the emulator's counters across it.
#[derive(Debug, Clone, Copy)]
struct Carried {
    round_trips: u64,
    /// Bytes offered per flow, in `Flow::ALL` order.
    bytes: [u64; 4],
}

/// The emulator's counters now, to take a transfer's as the difference across it.
fn counters(emulator: &Emulator) -> Carried {
    Carried {
        round_trips: emulator.round_trips(),
        bytes: emulator.stats().map(|s| s.bytes),
    }
}

impl Carried {
    /// What was carried since `before`.
    fn since(self, before: Self) -> Self {
        Self {
            round_trips: self.round_trips - before.round_trips,
            bytes: std::array::from_fn(|i| self.bytes[i] - before.bytes[i]),
        }
    }

    /// The link's floor for it (the bench's doc): the larger of round trips x round trip and
    /// the longest time one flow's bytes take at its rate plus a round trip.
    fn floor(self, profile: Profile) -> Duration {
        let serialisation = profile
            .flows()
            .iter()
            .zip(self.bytes)
            .filter_map(|(flow, bytes)| flow.bandwidth.map(|b| b.serialisation(bytes)))
            .max()
            .unwrap_or_default();
        let round_trip = profile.round_trip();
        (round_trip * self.round_trips as u32).max(serialisation + round_trip)
    }
}

/// The median of the floors of `carried` on `profile`, in ms.
fn median_floor(profile: Profile, carried: &[Carried]) -> f64 {
    let floors: Vec<f64> = carried
        .iter()
        .map(|c| c.floor(profile).as_secs_f64() * 1e3)
        .collect();
    percentile(&sorted(&floors), 0.5)
}

/// The median of the round trips of `carried`.
fn median_round_trips(carried: &[Carried]) -> f64 {
    let counts: Vec<f64> = carried.iter().map(|c| c.round_trips as f64).collect();
    percentile(&sorted(&counts), 0.5)
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

/// The profile's round trip without serialisation: both one-way delays and the mean jitters.
fn rtt(profile: Profile) -> Duration {
    profile.round_trip()
}

/// The ack timeout on `profile` for windows up to `window` (the bench's doc): above the round
/// trip, and above the wait of the last frame behind the queue the transfers can build at the
/// slowest rate: toward the FCC, the GCS keeps at most what the link carries in a round trip
/// in flight per transfer (ICD §10.4), two transfers at once (ICD §10.3), so at most two round
/// trips' worth and one more frame, when the window holds that much; toward the GCS, the FCC's
/// download keeps its window (at most 32, ICD §10.2) of the largest frames.
fn ack_timeout(profile: Profile, window: u8) -> Duration {
    let above_round_trip = Duration::from_millis(500).max(rtt(profile) * 5 / 2);
    let frame = MAX_SIGNED_FRAME_LEN as u64;
    let window_bytes = u64::from(window) * frame;
    let up = profile.up().bandwidth.map(|b| {
        let round_trip_bytes = u64::try_from(
            u128::from(b.bits_per_second()) * rtt(profile).as_nanos() / 8_000_000_000,
        )
        .unwrap_or(u64::MAX);
        b.serialisation(window_bytes.min(2 * round_trip_bytes + frame))
    });
    let down = profile
        .down()
        .bandwidth
        .map(|b| b.serialisation(u64::from(window.min(TransferWindow::MAX)) * frame));
    above_round_trip + up.into_iter().chain(down).max().unwrap_or_default()
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
    trace: bool,
) -> Vec<Row> {
    let mut rig = harness::Rig::new(&format!("bench-links-{}", profile.name()));
    let widest = windows.iter().copied().max().unwrap_or(1);
    let ack = ack_timeout(profile, widest).as_millis() as u64;
    rig.config.timing.ack_timeout_ms = ack;
    rig.config.timing.transfer_timeout_ms = 3 * ack + 2 * rtt(profile).as_millis() as u64;
    // The links carry the transfers alone, so that the bytes the floor counts are theirs: the
    // position downlink (#101 at 2 Hz, ICD §5.8) would fill the downlink's idle time between
    // answers, some 40 % of it at 2.4 kbit/s, and be counted as if it were on the transfer's path.
    rig.config.downlink.position_rate_hz = 0.0;
    eprintln!("{}: ack timeout {ack} ms", profile.name());
    let (mut fcc, mut link, emulator) = rig.start_through(profile.flows(), seed);
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
            link.station().set_transfer_window(window);
            link.station().set_upload_attempts(attempts);
            // The GCS knows the uplink's rate: its window keeps in flight what the link
            // carries in a round trip (ICD §10.4).
            link.station()
                .set_link_rate(profile.up().bandwidth.map(|b| b.bits_per_second()));
            let mut row = Row {
                profile,
                case: case.name.clone(),
                window,
                attempts,
                again: 0,
                messages_up: 0,
                upload_ms: Vec::new(),
                download_ms: Vec::new(),
                upload_carried: Vec::new(),
                download_carried: Vec::new(),
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
                let before = counters(&emulator);
                let now = link.now();
                let start = Instant::now();
                let up = link
                    .station()
                    .upload_validated(now, valid.clone(), Sequence::Paper { clear: true })
                    .and_then(|()| harness::finish(&mut link));
                let took = start.elapsed();
                let carried = counters(&emulator).since(before);
                if trace {
                    for l in &link.log {
                        eprintln!(
                            "trace {run} {:9.1} ms {:?} {:?}",
                            l.at.as_secs_f64() * 1e3,
                            l.direction,
                            l.message
                        );
                    }
                }
                match up {
                    Ok(Finished::Uploaded(r)) if r.is_complete() => {
                        row.upload_ms.push(took.as_secs_f64() * 1e3);
                        row.upload_carried.push(carried);
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
                let before = counters(&emulator);
                let now = link.now();
                let start = Instant::now();
                let down = link
                    .station()
                    .download(now)
                    .and_then(|()| harness::finish(&mut link));
                let took = start.elapsed();
                let carried = counters(&emulator).since(before);
                match down {
                    Ok(Finished::Downloaded(plan)) if *plan == valid => {
                        row.download_ms.push(took.as_secs_f64() * 1e3);
                        row.download_carried.push(carried);
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
                .map(|p| Profile::named(p).expect("lan, lte, satcom, satcom-narrow or bad"))
                .collect()
        })
        .unwrap_or_else(|| {
            if bench {
                Profile::ALL.to_vec()
            } else {
                vec![Profile::Lte]
            }
        });
    let sizes: Option<Vec<u16>> = arg(&args, "--cases").map(|v| {
        v.split(',')
            .map(|n| n.parse().expect("--cases 1,10,100,256"))
            .collect()
    });
    // Without --cases: every size, but mission 1 alone where the rate makes the others take
    // minutes a transfer.
    let sizes_on = |profile: Profile| match &sizes {
        Some(sizes) => sizes.clone(),
        None if bench && profile != Profile::SatcomNarrow => vec![1, 10, 100, 256],
        None => vec![1],
    };
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
    let trace = args.iter().any(|a| a == "--trace");

    let mut rows = Vec::new();
    for (i, profile) in profiles.iter().enumerate() {
        rows.extend(measure(
            *profile,
            &cases(&sizes_on(*profile)),
            &windows,
            &attempts,
            runs,
            15 + i as u64,
            trace,
        ));
    }

    println!(
        "\n{:<13} {:<14} {:>3} {:>3} {:>5} {:>10} {:>10} {:>4} {:>10} {:>7} {:>10} {:>10} {:>4} {:>10} {:>7} {:>9} {:>9} {:>5} {:>8} {:>9}",
        "profile",
        "case",
        "W",
        "att",
        "msgs",
        "up p50 ms",
        "up p99 ms",
        "up rt",
        "floor ms",
        "/ floor",
        "dn p50 ms",
        "dn p99 ms",
        "dn rt",
        "floor ms",
        "/ floor",
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
        let down50 = percentile(&down, 0.5);
        let up_floor = median_floor(row.profile, &row.upload_carried);
        let down_floor = median_floor(row.profile, &row.download_carried);
        println!(
            "{:<13} {:<14} {:>3} {:>3} {:>5} {:>10.1} {:>10.1} {:>4.0} {:>10.1} {:>7.2} {:>10.1} {:>10.1} {:>4.0} {:>10.1} {:>7.2} {:>4}/{:<4} {:>4}/{:<4} {:>5} {:>8.2} {:>9.2}",
            row.profile.name(),
            row.case,
            row.window,
            row.attempts,
            row.messages_up,
            up50,
            percentile(&up, 0.99),
            median_round_trips(&row.upload_carried),
            up_floor,
            up50 / up_floor,
            down50,
            percentile(&down, 0.99),
            median_round_trips(&row.download_carried),
            down_floor,
            down50 / down_floor,
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
            "upload_round_trips": row.upload_carried.iter().map(|c| c.round_trips).collect::<Vec<_>>(),
            "upload_bytes_per_flow": row.upload_carried.iter().map(|c| c.bytes).collect::<Vec<_>>(),
            "upload_floor_ms": row.upload_carried.iter().map(|c| c.floor(row.profile).as_secs_f64() * 1e3).collect::<Vec<_>>(),
            "download_round_trips": row.download_carried.iter().map(|c| c.round_trips).collect::<Vec<_>>(),
            "download_bytes_per_flow": row.download_carried.iter().map(|c| c.bytes).collect::<Vec<_>>(),
            "download_floor_ms": row.download_carried.iter().map(|c| c.floor(row.profile).as_secs_f64() * 1e3).collect::<Vec<_>>(),
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
