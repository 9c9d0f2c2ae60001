//! Per-frame latency of a partition, in HDR histograms (nanoseconds, 3 significant digits):
//! percentiles p50, p99, p99.9 and max, logged at shutdown and on SIGUSR1, and written as TOML
//! for the demo and the benchmarks.

use std::path::Path;

use hdrhistogram::Histogram;
use serde::{Deserialize, Serialize};

/// One histogram and its name, e.g. "uplink receive to published".
#[derive(Debug, Clone)]
pub struct Recorder {
    name: &'static str,
    histogram: Option<Histogram<u64>>,
}

/// Percentiles of one recorder, in microseconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    /// What was measured.
    pub name: String,
    /// Samples.
    pub count: u64,
    /// Median.
    pub p50_us: f64,
    /// 99th percentile.
    pub p99_us: f64,
    /// 99.9th percentile.
    pub p999_us: f64,
    /// Largest.
    pub max_us: f64,
}

impl std::fmt::Display for Percentiles {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: n={} p50={:.1}us p99={:.1}us p99.9={:.1}us max={:.1}us",
            self.name, self.count, self.p50_us, self.p99_us, self.p999_us, self.max_us
        )
    }
}

impl Recorder {
    /// An empty recorder of values from 1 ns to 60 s.
    pub fn new(name: &'static str) -> Self {
        Self {
            name,
            histogram: Histogram::new_with_bounds(1, 60_000_000_000, 3).ok(),
        }
    }

    /// Records one latency in nanoseconds (clamped into the histogram's range).
    pub fn record(&mut self, ns: u64) {
        if let Some(h) = self.histogram.as_mut() {
            h.saturating_record(ns.max(1));
        }
    }

    /// Records the time from `from_ns` to `to_ns` (CLOCK_MONOTONIC), if `from_ns` is set.
    pub fn record_between(&mut self, from_ns: u64, to_ns: u64) {
        if from_ns != 0 {
            self.record(to_ns.saturating_sub(from_ns));
        }
    }

    /// The percentiles so far.
    pub fn percentiles(&self) -> Percentiles {
        let us = |v: u64| v as f64 / 1000.0;
        match &self.histogram {
            Some(h) if !h.is_empty() => Percentiles {
                name: self.name.to_owned(),
                count: h.len(),
                p50_us: us(h.value_at_quantile(0.5)),
                p99_us: us(h.value_at_quantile(0.99)),
                p999_us: us(h.value_at_quantile(0.999)),
                max_us: us(h.max()),
            },
            _ => Percentiles {
                name: self.name.to_owned(),
                count: 0,
                p50_us: 0.0,
                p99_us: 0.0,
                p999_us: 0.0,
                max_us: 0.0,
            },
        }
    }
}

/// The latency summary of one partition, with its counters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The partition.
    pub partition: String,
    /// Its recorders.
    pub latencies: Vec<Percentiles>,
    /// Counters by name (frames forwarded, rejected by cause, ...).
    #[serde(default)]
    pub counters: std::collections::BTreeMap<String, u64>,
}

/// Logs every recorder of `partition`.
pub fn log(partition: &str, recorders: &[&Recorder]) {
    for r in recorders {
        tracing::info!(partition, "latency {}", r.percentiles());
    }
}

/// Writes `<dir>/<partition>.toml` (TOML, like the configuration: the FCC links no JSON code).
pub fn write_summary(
    dir: &Path,
    partition: &str,
    recorders: &[&Recorder],
    counters: &[(&str, u64)],
) {
    let summary = Summary {
        partition: partition.to_owned(),
        latencies: recorders.iter().map(|r| r.percentiles()).collect(),
        counters: counters
            .iter()
            .map(|(k, v)| ((*k).to_owned(), *v))
            .collect(),
    };
    let path = dir.join(format!("{partition}.toml"));
    let result = toml::to_string(&summary)
        .map_err(std::io::Error::other)
        .and_then(|text| std::fs::create_dir_all(dir).and_then(|()| std::fs::write(&path, text)));
    if let Err(e) = result {
        tracing::warn!(path = %path.display(), %e, "cannot write the latency summary");
    }
}

/// The summaries in `dir`, sorted by partition; files that do not read as a summary are
/// skipped.
pub fn read_summaries(dir: &Path) -> Vec<Summary> {
    let mut out: Vec<Summary> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "toml"))
        .filter_map(|e| std::fs::read_to_string(e.path()).ok())
        .filter_map(|text| toml::from_str(&text).ok())
        .collect();
    out.sort_by(|a, b| a.partition.cmp(&b.partition));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_in_microseconds() {
        let mut r = Recorder::new("hop");
        for ns in 1..=1000u64 {
            r.record(ns * 1000);
        }
        let p = r.percentiles();
        assert_eq!(p.count, 1000);
        assert!((p.p50_us - 500.0).abs() < 1.0, "{p}");
        assert!((p.p99_us - 990.0).abs() < 1.0, "{p}");
        assert!((p.max_us - 1000.0).abs() < 1.0, "{p}");
        r.record_between(0, 5);
        assert_eq!(r.percentiles().count, 1000, "unset start is not recorded");
    }

    #[test]
    fn summary_round_trip_through_the_file() {
        let dir = std::env::temp_dir().join(format!("missionlink-summary-{}", std::process::id()));
        let mut r = Recorder::new("hop");
        r.record(2_000);
        write_summary(&dir, "voting-monitoring", &[&r], &[("stale", 3)]);
        let read = read_summaries(&dir);
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(read.len(), 1);
        assert_eq!(read[0].partition, "voting-monitoring");
        assert_eq!(read[0].latencies[0].count, 1);
        assert_eq!(read[0].counters.get("stale"), Some(&3));
    }
}
