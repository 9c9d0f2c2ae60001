//! The FCC's mission report (ICD §8, #50001) as a table, one line per entry: what `gcs missions`
//! and the demo print.

use std::fmt::Write;

use missionlink_interfaces::wire::{Checksum, GeofenceCheck, MissionReport};

/// The entries as a table with a header line; every line ends with a newline.
pub fn render(entries: &[MissionReport]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<20} {:>9} {:>5} {:<24} {:<10} {:<10}",
        "mission", "waypoints", "areas", "geofence check", "mission", "areas"
    );
    let checksum = |c: Option<Checksum>| c.map_or_else(|| "-".to_owned(), |c| c.to_string());
    for e in entries {
        let name = match e.mission_id.as_ref().map(|t| t.as_str()) {
            None | Some("") => "(active)".to_owned(),
            Some(id) => id.to_owned(),
        };
        let check = match (e.geofence_check, e.reason) {
            (GeofenceCheck::NotRun, _) => "not run".to_owned(),
            (GeofenceCheck::Passed, _) => "passed".to_owned(),
            (GeofenceCheck::Failed, Some(r)) => format!("failed: {r}"),
            (GeofenceCheck::Failed, None) => "failed".to_owned(),
        };
        let _ = writeln!(
            out,
            "{:<20} {:>9} {:>5} {:<24} {:<10} {:<10}",
            name,
            e.waypoint_count,
            e.area_count,
            check,
            checksum(e.mission_checksum),
            checksum(e.area_checksum)
        );
    }
    out
}
