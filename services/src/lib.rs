//! The sans-IO logic of missionlink: state machines that never read a clock or a socket
//! (docs/design.md, "The sans-IO core"). Drivers (the FCC partitions in `missionlink-partitions`,
//! the GCS link in `missionlink-gcs`) feed them frames and the time, take frames from
//! `poll_transmit` and wake them at `poll_timeout`.
//!
//! Grouped by the functions of the paper:
//! - [`link`]: what both ends of the link share: preprocessing, acknowledgement, sampling,
//!   timeout and retry, the timer table, rejected-input counters, time stamps (paper §3.1.1-4);
//! - [`transfer`]: the one sender and the mission and area receivers, buffers and assembly
//!   (§3.1.5-9, inverted use §3.2);
//! - [`mission_data_handling`] (the FCC, §3.1) and [`ground_station`] (the GCS logic, §3.2);
//! - [`voting`] (§2.4), [`from_to_next`] (§3.1.7), [`automation`] (§2.5), [`guidance`] (the
//!   guidance stub's kinematics), [`health`] (liveness from heartbeats);
//! - [`geofence`]: the one Earth model; [`safety_gateway`] (§2.2) on it;
//! - `testkit` (feature `testkit`): the fixtures tests and benches share.
// A `Message` (up to a 60-vertex #2012) lives inline wherever it goes, so that handling a frame
// allocates nothing; enums that carry one are large by design.
#![allow(clippy::large_enum_variant)]

pub mod automation;
pub mod from_to_next;
pub mod geofence;
pub mod ground_station;
pub mod guidance;
pub mod health;
pub mod link;
pub mod mission_data_handling;
pub mod position;
pub mod safety_gateway;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
pub mod transfer;
pub mod voting;
