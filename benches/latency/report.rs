//! The report: the tables on stdout, the ratios the goals name, the JSON and the SVG plot in
//! `target/latency/`.
//!
//! The plot is drawn by hand on the shared log axis of `src/harness/log_axis.rs` rather than
//! with the `plotters` crate: see that module for the decision.

use super::*;

pub(super) fn us(result: &Value, key: &str) -> f64 {
    result[key].as_f64().unwrap_or(f64::NAN) / 1000.0
}

/// `value / reference` with two significant digits (at least two decimals).
pub(super) fn ratio(value: f64, reference: f64) -> String {
    let r = value / reference;
    if !(r.is_finite() && r > 0.0) {
        return "-".to_owned();
    }
    let decimals = (1.0 - r.log10().floor()).max(2.0) as usize;
    format!("{r:.decimals$}x")
}

pub(super) fn print_table(description: &str, results: &[&Value]) {
    println!("\nPayload {description}");
    let reference = results
        .iter()
        .find(|r| r["transport"] == Transport::Iox2Event.arg())
        .copied();
    print_rows("transport", "label", results, reference, "ev");
    for (name, value, reference) in goal_ratios(results) {
        println!(
            "  {name}: {value:.2} / {reference:.2} µs = {}",
            ratio(value, reference)
        );
    }
    let loop_mean = |t: Transport| {
        results
            .iter()
            .find(|r| r["transport"] == t.arg())
            .and_then(|r| r["loop_mean_ns"].as_f64())
    };
    if let (Some(ours), Some(theirs)) = (
        loop_mean(Transport::Iox2Poll),
        loop_mean(Transport::Iox2OwnPubsub),
    ) {
        println!(
            "  ping-pong loop, one-way mean without a clock read per sample ({} round trips, as \
             iceoryx2's benchmark-publish-subscribe measures): {} {ours:.0} ns, {} {theirs:.0} ns \
             = {}",
            hop::LOOP_ROUND_TRIPS,
            Transport::Iox2Poll.arg(),
            Transport::Iox2OwnPubsub.arg(),
            ratio(ours, theirs)
        );
    }
}

/// The ratios of p50 the goals name, for the rows present: (what, value µs, reference µs).
pub(super) fn goal_ratios(results: &[&Value]) -> Vec<(String, f64, f64)> {
    let p50 = |t: Transport| {
        results
            .iter()
            .find(|r| r["transport"] == t.arg())
            .map(|r| us(r, "p50_ns"))
    };
    [
        (Transport::Partition, Transport::Uds),
        (Transport::PartitionBlock, Transport::Uds),
        (Transport::PartitionBackoff, Transport::Uds),
        (Transport::PartitionDoorbell, Transport::Uds),
        (Transport::PartitionSparse, Transport::UdsSparse),
        (Transport::PartitionBlockSparse, Transport::UdsSparse),
        (Transport::PartitionBackoffSparse, Transport::UdsSparse),
        (Transport::PartitionDoorbellSparse, Transport::UdsSparse),
        (Transport::PartitionForeignSparse, Transport::UdsSparse),
        (Transport::PartitionUnrungSparse, Transport::UdsSparse),
        (
            Transport::PartitionForeignSparse,
            Transport::PartitionSparse,
        ),
        (Transport::Iox2Poll, Transport::Iox2OwnPubsub),
    ]
    .into_iter()
    .filter_map(|(a, b)| Some((format!("p50 {} / {}", a.arg(), b.arg()), p50(a)?, p50(b)?)))
    .collect()
}

/// One line per result, named by its `label_key`, with its percentiles and the ratios of its
/// p50 and p99.9 to `reference`'s (the columns `p50/<reference_name>`, `p99.9/<...>`): the
/// table of the transports and the table of the load cases alike.
pub(super) fn print_rows(
    first_column: &str,
    label_key: &str,
    results: &[&Value],
    reference: Option<&Value>,
    reference_name: &str,
) {
    println!(
        "{:<30} {:>8} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>9} {:>7}",
        first_column,
        "samples",
        "p50 µs",
        "p99 µs",
        "p99.9 µs",
        "max µs",
        format!("p50/{reference_name}"),
        format!("p99.9/{reference_name}"),
        "preempt",
        "others"
    );
    let (p50_ref, p999_ref) = reference.map_or((0.0, 0.0), |r| (us(r, "p50_ns"), us(r, "p999_ns")));
    for r in results {
        println!(
            "{:<30} {:>8} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>10} {:>10} {:>9} {:>6.0}%",
            r[label_key].as_str().unwrap_or_default(),
            r["samples"].as_u64().unwrap_or(0),
            us(r, "p50_ns"),
            us(r, "p99_ns"),
            us(r, "p999_ns"),
            us(r, "max_ns"),
            ratio(us(r, "p50_ns"), p50_ref),
            ratio(us(r, "p999_ns"), p999_ref),
            format!(
                "{}/{}",
                r["sender_involuntary_switches"], r["receiver_involuntary_switches"]
            ),
            r["others_cpu_percent"].as_f64().unwrap_or(f64::NAN),
        );
    }
}

/// The plot: per payload size a group of bar triples (p50, p99, p99.9) per transport, on a
/// logarithmic µs axis.
pub(super) fn svg(results: &[Value], subtitle: &str) -> String {
    const PERCENTILES: [(&str, &str, &str); 3] = [
        ("p50_ns", "p50", "#4c78a8"),
        ("p99_ns", "p99", "#f58518"),
        ("p999_ns", "p99.9", "#e45756"),
    ];
    const BAR: f64 = 10.0;
    const CLUSTER: f64 = 3.0 * BAR + 14.0;
    const GROUP_GAP: f64 = 40.0;
    const LEFT: f64 = 80.0;
    const TOP: f64 = 84.0;
    const PLOT_H: f64 = 360.0;
    let sizes = sizes();
    let group_w = CLUSTER * Transport::ALL.len() as f64;
    let width = LEFT + sizes.len() as f64 * (group_w + GROUP_GAP) + 20.0;
    let height = TOP + PLOT_H + 180.0;
    let bottom = TOP + PLOT_H;

    let values: Vec<f64> = results
        .iter()
        .flat_map(|r| PERCENTILES.iter().map(move |(k, _, _)| us(r, k)))
        .collect();
    let axis = LogAxis::new(values.iter().copied(), bottom, PLOT_H);
    let y = |v: f64| axis.y(v);

    let mut s = log_axis::begin(
        width,
        height,
        LEFT,
        24.0,
        "One-way frame latency between two processes",
    );
    let w = &mut s;
    let _ = writeln!(
        w,
        r##"<text x="{LEFT}" y="44" fill="#555">{subtitle}</text>"##
    );
    // Legend.
    for (i, (_, name, colour)) in PERCENTILES.iter().enumerate() {
        log_axis::legend_entry(w, width - 260.0 + i as f64 * 80.0, 56.0, colour, name);
    }
    // Decades of the µs axis, with faint lines at 2 and 5.
    axis.grid(w, LEFT, width - 20.0, "µs");
    let _ = writeln!(
        w,
        r#"<text transform="translate(20,{}) rotate(-90)" text-anchor="middle">latency (µs)</text>"#,
        TOP + PLOT_H / 2.0
    );
    // Bars.
    for (g, (size, description)) in sizes.iter().enumerate() {
        let gx = LEFT + 10.0 + g as f64 * (group_w + GROUP_GAP);
        for (t, transport) in Transport::ALL.iter().enumerate() {
            let Some(r) = results
                .iter()
                .find(|r| r["transport"] == transport.arg() && r["payload_bytes"] == json!(size))
            else {
                continue;
            };
            let cx = gx + t as f64 * CLUSTER;
            for (i, (key, name, colour)) in PERCENTILES.iter().enumerate() {
                let v = us(r, key);
                let top = y(v);
                let _ = writeln!(
                    w,
                    r#"<rect x="{:.1}" y="{top:.1}" width="{BAR}" height="{:.1}" fill="{colour}"><title>{}, {size} B: {name} = {v:.2} µs</title></rect>"#,
                    cx + i as f64 * BAR,
                    bottom - top,
                    transport.label()
                );
            }
            let _ = writeln!(
                w,
                r#"<text transform="translate({:.1},{:.1}) rotate(-45)" text-anchor="end">{}</text>"#,
                cx + 1.5 * BAR,
                bottom + 12.0,
                transport.label()
            );
        }
        let short = description.split(',').next().unwrap_or(description);
        let what = description.split_once(", ").map_or("", |(_, w)| w);
        let mid = gx + group_w / 2.0 - 7.0;
        let _ = writeln!(
            w,
            r##"<text x="{mid:.1}" y="{:.1}" text-anchor="middle" font-weight="bold">{short}</text><text x="{mid:.1}" y="{:.1}" text-anchor="middle" fill="#555">{}</text>"##,
            bottom + 150.0,
            bottom + 166.0,
            what.replace(" (WaypointListPayload)", "")
        );
    }
    let _ = writeln!(
        w,
        r#"<line x1="{LEFT}" x2="{}" y1="{bottom}" y2="{bottom}" stroke="black"/>"#,
        width - 20.0
    );
    let _ = writeln!(w, "</svg>");
    s
}

/// `target/latency`: next to the bench binary (`<target>/release/deps/latency-*`), so that
/// `CARGO_TARGET_DIR` is followed.
pub(super) fn output_dir() -> PathBuf {
    std::env::current_exe()
        .ok()
        .and_then(|exe| exe.ancestors().nth(3).map(Path::to_path_buf))
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"))
        .join("latency")
}

/// Writes `contents` to `name` in the [`output_dir`] (created if missing); the path.
pub(super) fn write_output(name: &str, contents: &str) -> PathBuf {
    let dir = output_dir();
    std::fs::create_dir_all(&dir).expect("create the output directory");
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap_or_else(|e| panic!("write {name}: {e}"));
    path
}
