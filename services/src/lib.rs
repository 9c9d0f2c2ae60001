//! The sans-IO logic of missionlink: state machines that never read a clock or a socket
//! (DESIGN.md, "The sans-IO core"). Drivers in `partitions/` feed them frames and the time.
// A `Message` (up to a 60-vertex #2012) lives inline wherever it goes, so that handling a frame
// allocates nothing; enums that carry one are large by design.
#![allow(clippy::large_enum_variant)]

pub mod automation;
pub mod from_to_next;
pub mod geofence;
pub mod ground_station;
pub mod guidance;
pub mod link;
pub mod mission_data_handling;
pub mod safety_gateway;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
pub mod transfer;
pub mod voting;
