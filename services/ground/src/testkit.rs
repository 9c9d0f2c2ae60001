//! The GCS's fixtures, beside the protocol's (re-exported here, so that a test of this level
//! takes every fixture from one place): the configuration of the ground station with the IDs
//! and timeouts of ICD §1, and [`Transmit`] for it. Compiled in this crate's own tests and, for
//! other crates' tests and benches, behind the cargo feature `testkit`.

pub use missionlink_protocol::testkit::*;

use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::EncodeError;

use crate::ground_station::{GcsConfig, GroundStation, SafetyGateway};

/// The GCS logic with the IDs and timeouts of ICD §1.
pub fn gcs_config() -> GcsConfig {
    GcsConfig {
        endpoint: endpoint(defaults::GCS_ID, defaults::FCC_ID),
        ack_timeout: defaults::ACK_TIMEOUT,
        transfer_timeout: defaults::TRANSFER_TIMEOUT,
        // Stop-and-wait, so that the sequence tests see ICD §5 message by message; the
        // windowed tests set their window.
        transfer_window: missionlink_interfaces::wire::TransferWindow::ONE,
        // One attempt, so that a test of a failure sees it; the tests of attempts set theirs.
        upload_attempts: 1,
    }
}

impl<G: SafetyGateway> Transmit for GroundStation<G> {
    fn transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        self.poll_transmit(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_timer_enum_of_the_crate_has_one_slot_per_timer() {
        check_timer_slots::<crate::ground_station::GcsTimer, 4>();
    }
}
