//! What the ground service knows of each vehicle, as `gcs status` shows it: one row per vehicle.
//!
//! The ICD carries no health message (§12 "Health": the GCS sees the FCC's health only in the
//! refusals of execute); what a row says of the FCC is what the ground hears: frames on each
//! link and how old the last is, the position reports (#101, 2 Hz by default: one older than
//! [`POSITION_STALE`] means the FCC's navigation downlink stopped), FROM-TO-NEXT (#4001), and
//! the FCC's report of its lists (ICD §8), asked at start and after every request that may have
//! changed them.

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use missionlink_interfaces::wire::{Checksum, FromToNext, InertialStates, MissionReport};
use serde::{Deserialize, Serialize};

use crate::gcs_link::LinkActivity;

/// A position report older than this is stale: at the default 2 Hz, four reports missed.
pub const POSITION_STALE: Duration = Duration::from_secs(2);
/// A link that brought nothing for this long is silent.
pub const LINK_SILENT: Duration = Duration::from_secs(2);

/// What a vehicle's worker keeps for the status, with the instants things came.
#[derive(Debug, Clone, Default)]
pub struct Snapshot {
    /// The direct and the LTE link.
    pub links: [LinkActivity; 2],
    /// Messages the voter handed on (each once, whichever link brought it first).
    pub messages: u64,
    /// The last position and when it came.
    pub position: Option<(InertialStates, Instant)>,
    /// The last FROM-TO-NEXT.
    pub from_to_next: Option<FromToNext>,
    /// The FCC's last report, `None` before the first answer.
    pub report: Option<Vec<MissionReport>>,
    /// Why the last report was not had, if it was not.
    pub report_failed: Option<String>,
    /// The checksums of the lists this ground last uploaded to the active lists.
    pub planned: Option<(Checksum, Checksum)>,
    /// A request in progress, by name.
    pub busy: Option<String>,
}

/// One row of `gcs status`, as the service sends it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VehicleStatus {
    /// The vehicle's name in the fleet.
    pub name: String,
    /// Its Vehicle ID.
    pub vehicle_id: u32,
    /// The direct and the LTE link.
    pub links: [LinkStatus; 2],
    /// The last position, `None` before the first.
    pub position: Option<InertialStates>,
    /// Its age, milliseconds.
    pub position_age_ms: Option<u64>,
    /// FROM-TO-NEXT as (from, to, next) waypoint numbers, 0 for none.
    pub from_to_next: Option<(u16, u16, u16)>,
    /// The active lists' checksums (ICD §11) as the FCC reported them.
    pub active: Option<(Option<Checksum>, Option<Checksum>)>,
    /// Whether the active lists are the ones this ground uploaded last (`None`: it uploaded
    /// none, or the FCC gave no report).
    pub planned: Option<bool>,
    /// The staged missions' IDs.
    pub staged: Vec<String>,
    /// Why there is no report, if there is none.
    pub report_failed: Option<String>,
    /// A request in progress.
    pub busy: Option<String>,
}

/// One link's row part.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinkStatus {
    /// Age of the last datagram, milliseconds; `None` before the first.
    pub last_age_ms: Option<u64>,
    /// Of the FCC's messages, the share this link did not bring, percent (`None` before any).
    pub loss_percent: Option<f64>,
}

impl Snapshot {
    /// The staged missions' IDs of the last report.
    pub fn staged_ids(&self) -> impl Iterator<Item = &str> {
        self.report
            .iter()
            .flatten()
            .skip(1)
            .filter_map(|e| e.mission_id.as_ref().map(|id| id.as_str()))
    }

    /// The row of vehicle `name` (`vehicle_id`) at `now`.
    pub fn status(&self, name: &str, vehicle_id: u32, now: Instant) -> VehicleStatus {
        let age = |t: Instant| now.saturating_duration_since(t).as_millis() as u64;
        let link = |a: &LinkActivity| LinkStatus {
            last_age_ms: a.last.map(age),
            loss_percent: (self.messages > 0).then(|| {
                let brought = a.datagrams.min(self.messages) as f64;
                100.0 * (1.0 - brought / self.messages as f64)
            }),
        };
        let active = self
            .report
            .as_ref()
            .and_then(|r| r.first())
            .map(|e| (e.mission_checksum, e.area_checksum));
        VehicleStatus {
            name: name.to_owned(),
            vehicle_id,
            links: [link(&self.links[0]), link(&self.links[1])],
            position: self.position.map(|(p, _)| p),
            position_age_ms: self.position.map(|(_, t)| age(t)),
            from_to_next: self.from_to_next.map(|f| {
                let n = |w: Option<u16>| w.unwrap_or(0);
                (
                    n(f.from.waypoint_number),
                    n(f.to.waypoint_number),
                    n(f.next.waypoint_number),
                )
            }),
            active,
            planned: match (active, self.planned) {
                (Some((mission, areas)), Some(planned)) => {
                    Some((mission, areas) == (Some(planned.0), Some(planned.1)))
                }
                _ => None,
            },
            staged: self.staged_ids().map(str::to_owned).collect(),
            report_failed: self.report_failed.clone(),
            busy: self.busy.clone(),
        }
    }
}

/// The rows as a table, a header first; every line ends with a newline.
pub fn render(rows: &[VehicleStatus]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<12} {:<10} {:<16} {:<16} {:<42} {:<14} {:<24} staged / FCC",
        "vehicle", "ID", "direct", "LTE", "position", "FROM-TO-NEXT", "active lists"
    );
    for r in rows {
        let link = |l: &LinkStatus| match l.last_age_ms {
            None => "never heard".to_owned(),
            Some(ms) => format!(
                "{} ago{}",
                age(ms),
                l.loss_percent
                    .map_or_else(String::new, |p| format!(", {p:.0}% lost"))
            ),
        };
        let position = match (&r.position, r.position_age_ms) {
            (Some(p), Some(ms)) => {
                let place = match (p.latitude, p.longitude) {
                    (Some(lat), Some(lon)) => {
                        format!("{:.6} {:.6}", lat.degrees(), lon.degrees())
                    }
                    _ => "no fix".to_owned(),
                };
                let height = p
                    .altitude
                    .map_or_else(String::new, |a| format!(" {:.0} m", a.metres()));
                let stale = if ms > POSITION_STALE.as_millis() as u64 {
                    " (stale)"
                } else {
                    ""
                };
                format!("{place}{height}, {} ago{stale}", age(ms))
            }
            _ => "not yet reported".to_owned(),
        };
        let ftn = r.from_to_next.map_or_else(
            || "not yet reported".to_owned(),
            |(f, t, n)| format!("{f} -> {t} -> {n}"),
        );
        let checksum = |c: Option<Checksum>| c.map_or_else(|| "none".to_owned(), |c| c.to_string());
        let active = match (r.active, r.planned) {
            (None, _) => "no report".to_owned(),
            (Some((m, a)), planned) => format!(
                "{}/{}{}",
                checksum(m),
                checksum(a),
                match planned {
                    Some(true) => " planned",
                    Some(false) => " NOT planned",
                    None => "",
                }
            ),
        };
        let mut last = if r.staged.is_empty() {
            "none staged".to_owned()
        } else {
            format!("staged {}", r.staged.join(", "))
        };
        let silent = r.links.iter().all(|l| {
            l.last_age_ms
                .is_none_or(|ms| ms > LINK_SILENT.as_millis() as u64)
        });
        if silent {
            last.push_str("; FCC silent on both links");
        } else if r
            .position_age_ms
            .is_none_or(|ms| ms > POSITION_STALE.as_millis() as u64)
        {
            last.push_str("; FCC heard, its position not");
        }
        if let Some(why) = &r.report_failed {
            let _ = write!(last, "; no report: {why}");
        }
        if let Some(busy) = &r.busy {
            let _ = write!(last, "; busy: {busy}");
        }
        let _ = writeln!(
            out,
            "{:<12} {:<10} {:<16} {:<16} {:<42} {:<14} {:<24} {}",
            r.name,
            format!("{:#010X}", r.vehicle_id),
            link(&r.links[0]),
            link(&r.links[1]),
            position,
            ftn,
            active,
            last
        );
    }
    out
}

/// An age in words: `850 ms`, `12.3 s`, `4 min`.
fn age(ms: u64) -> String {
    match ms {
        0..1_000 => format!("{ms} ms"),
        1_000..120_000 => format!("{:.1} s", ms as f64 / 1000.0),
        _ => format!("{} min", ms / 60_000),
    }
}
