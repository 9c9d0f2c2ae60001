//! The FCC's fixtures, beside the protocol's (re-exported here, so that a test of this level
//! takes every fixture from one place): the configuration of mission data handling with the
//! IDs and timeouts of ICD §1, and [`Transmit`] for it. Compiled in this crate's own tests and,
//! for other crates' tests and benches, behind the cargo feature `testkit`.

pub use missionlink_protocol::testkit::*;

use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::EncodeError;

use crate::mission_data_handling::{FccConfig, MissionDataHandling};

/// Mission data handling with the IDs and timeouts of ICD §1, without the position downlink
/// (ICD §5.8): the sequences of ICD §5 are scripted frame by frame, and a periodic #101 between
/// their frames would only be skipped; the downlink's own tests set `position_period`.
pub fn fcc_config() -> FccConfig {
    FccConfig {
        endpoint: endpoint(defaults::FCC_ID, defaults::GCS_ID),
        ack_timeout: defaults::ACK_TIMEOUT,
        transfer_timeout: defaults::TRANSFER_TIMEOUT,
        position_period: None,
    }
}

impl Transmit for MissionDataHandling {
    fn transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        self.poll_transmit(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_timer_enum_of_the_crate_has_one_slot_per_timer() {
        check_timer_slots::<crate::mission_data_handling::FccTimer, 7>();
        check_timer_slots::<crate::position::PositionTimer, 1>();
    }
}
