//! The benches' SVG plots (`benches/latency/report.rs`, `benches/links.rs`): the document with its
//! title, and the logarithmic value axis (the decades that hold the values, where a value sits,
//! the grid).
//!
//! # Why by hand and not with the `plotters` crate
//!
//! Evaluated against `plotters` 0.3.7: with its default features it brings 46 crates (bitmap,
//! GIF, fonts, images, chrono); with `svg_backend` alone, 4 (`plotters`, `plotters-backend`,
//! `plotters-svg`, `num-traits`), which a dev-dependency of the benches could carry. It would
//! not do the job better: both plots are grouped bars on a logarithmic axis (latency
//! percentiles per transport and size; upload medians per link profile and window), and
//! plotters has no grouped-bar series, so each bar would still be a rectangle placed by our code;
//! what it would take over is the decade ticks and the grid, most of this module. Its
//! SVG would also differ from the plots committed under `docs/` and described in
//! BENCHMARKS.md, which only the lead's re-measurement replaces. So the plots stay plain SVG
//! text written here, with no dependency.

use std::fmt::Write as _;

/// A legend entry at (`x`, `y`): a 12 px square in `colour`, `label` to its right.
pub fn legend_entry(w: &mut String, x: f64, y: f64, colour: &str, label: &str) {
    let _ = writeln!(
        w,
        r#"<rect x="{x}" y="{y}" width="12" height="12" fill="{colour}"/><text x="{}" y="{}">{label}</text>"#,
        x + 16.0,
        y + 10.0
    );
}

/// An SVG document `width` x `height` on white, its title in bold at (`x`, `y`); the caller
/// closes it with `</svg>`.
pub fn begin(width: f64, height: f64, x: f64, y: f64, title: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{x}" y="{y}" font-size="16" font-weight="bold">{title}</text>"#
    );
    s
}

/// A vertical axis of whole decades, `height` pixels high above `bottom`.
pub struct LogAxis {
    /// The lowest decade (log10).
    lo: f64,
    /// The highest decade (log10), above `lo`.
    hi: f64,
    bottom: f64,
    height: f64,
}

impl LogAxis {
    /// The decades around every positive value of `values`.
    pub fn new(values: impl Iterator<Item = f64> + Clone, bottom: f64, height: f64) -> Self {
        let positive = values.filter(|v| *v > 0.0);
        let lo = positive
            .clone()
            .fold(f64::INFINITY, f64::min)
            .log10()
            .floor();
        let hi = positive.fold(0.0, f64::max).log10().ceil().max(lo + 1.0);
        Self {
            lo,
            hi,
            bottom,
            height,
        }
    }

    /// Where `v` sits (values below the lowest decade sit on it).
    pub fn y(&self, v: f64) -> f64 {
        self.bottom
            - (v.max(10f64.powf(self.lo)).log10() - self.lo) / (self.hi - self.lo) * self.height
    }

    /// Lines from `left` to `right` at every decade, labelled with `unit`, and faint ones at 2
    /// and 5 times each decade.
    pub fn grid(&self, w: &mut String, left: f64, right: f64, unit: &str) {
        for decade in (self.lo as i32)..=(self.hi as i32) {
            let v = 10f64.powi(decade);
            let label = if decade < 0 {
                format!("{v:.*}", decade.unsigned_abs() as usize)
            } else {
                format!("{v:.0}")
            };
            let at = self.y(v);
            let _ = writeln!(
                w,
                r##"<line x1="{left}" x2="{right}" y1="{at:.1}" y2="{at:.1}" stroke="#bbb"/><text x="{:.1}" y="{:.1}" text-anchor="end">{label} {unit}</text>"##,
                left - 6.0,
                at + 4.0,
            );
            if decade < self.hi as i32 {
                for m in [2.0, 5.0] {
                    let at = self.y(v * m);
                    let _ = writeln!(
                        w,
                        r##"<line x1="{left}" x2="{right}" y1="{at:.1}" y2="{at:.1}" stroke="#eee"/>"##
                    );
                }
            }
        }
    }
}
