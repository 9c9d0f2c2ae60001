//! The GCS's fixtures, beside the protocol's (re-exported here, so that a test of this level
//! takes every fixture from one place): the configuration of the ground station with the IDs
//! and timeouts of ICD §1, [`Transmit`] for it, and a fleet's missions ([`survey_fleet`]) for
//! the separation check. Compiled in this crate's own tests and, for other crates' tests and
//! benches, behind the cargo feature `testkit`.

pub use missionlink_protocol::testkit::*;

use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{Altitude, EncodeError, LegType, Message, UaPositionWaypoint};
use missionlink_protocol::transfer::mission::Mission;

use crate::ground_station::{GcsConfig, GroundStation, SafetyGateway};

/// The GCS logic with the IDs and timeouts of ICD §1.
pub fn gcs_config() -> GcsConfig {
    GcsConfig {
        endpoint: endpoint(defaults::GCS_ID, defaults::FCC_ID),
        ack_timeout: defaults::ACK_TIMEOUT,
        transfer_timeout: defaults::TRANSFER_TIMEOUT,
        // Stop-and-wait, so that the sequence tests see ICD §5 message by message; the
        // windowed tests set their window.
        transfer_window: 1,
        // One attempt, so that a test of a failure sees it; the tests of attempts set theirs.
        upload_attempts: 1,
    }
}

impl<G: SafetyGateway> Transmit for GroundStation<G> {
    fn transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        self.poll_transmit(buf)
    }
}

/// Where the first survey sector of [`survey_fleet`] starts (its south-west corner), degrees.
pub const SURVEY_ORIGIN: (f64, f64) = (48.0, 11.0);
/// A survey sector's extent, degrees of latitude and longitude (about 4.4 km by 4.5 km); the
/// sectors lie side by side on a grid four sectors wide. Each pattern keeps 0.004° of longitude
/// (some 300 m) from the next sector's in its row, and 0.008° of latitude (some 890 m, some
/// 600 m less the turns flown beyond the waypoints) from the next row's.
pub const SURVEY_SECTOR: (f64, f64) = (0.04, 0.06);

/// Mission `k` of [`survey_fleet`]: `waypoints` track-to-fix waypoints (2 <= `waypoints` <=
/// 256) zig-zagging between the south and the north edge of sector `k` (row `k / 4`, column
/// `k % 4`) from west to east, all fly-by (so every turn at an edge is a sharp one, flown over),
/// 25 m/s, at 100 m + 10 m × (`k` mod 4), take-off 30 m, one-way.
#[allow(
    clippy::expect_used,
    reason = "test-only fixture: the values are literals, a failure is a broken test"
)]
pub fn survey(k: usize, waypoints: u16) -> Mission {
    let (row, column) = ((k / 4) as f64, (k % 4) as f64);
    let south = SURVEY_ORIGIN.0 + row * SURVEY_SECTOR.0;
    let west = SURVEY_ORIGIN.1 + column * SURVEY_SECTOR.1;
    let altitude = Altitude::from_metres(100.0 + 10.0 * (k % 4) as f64).expect("an altitude");
    let mut messages: Vec<Message> = vec![take_off(30.0).into(), route(1, false).into()];
    messages.extend((0..waypoints).map(|i| {
        let lat = south + if i % 2 == 0 { 0.002 } else { 0.034 };
        let lon = west + 0.056 * f64::from(i) / f64::from(waypoints.saturating_sub(1).max(1));
        let next = if i + 1 == waypoints { 0 } else { i + 2 };
        Message::from(UaPositionWaypoint {
            altitude,
            ..waypoint(i + 1, next, (lat, lon), LegType::TrackToFix)
        })
    }));
    mission_buffer(&messages)
        .assemble(Some(waypoints), None)
        .expect("a survey mission assembles")
}

/// `vehicles` survey missions of `waypoints` waypoints each ([`survey`]), sector by sector:
/// neighbours in a row of the grid fly within some 300 m of each other, rows keep some 600 m
/// apart. 16 × 256 is the fleet the separation check is sized for.
pub fn survey_fleet(vehicles: usize, waypoints: u16) -> Vec<Mission> {
    (0..vehicles).map(|k| survey(k, waypoints)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_timer_enum_of_the_crate_has_one_slot_per_timer() {
        check_timer_slots::<crate::ground_station::GcsTimer, 5>();
    }
}
