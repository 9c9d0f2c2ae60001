//! What flies, sans-IO: the FCC's logic, driven by the partitions (`missionlink-partitions`),
//! which feed it frames and the time, take frames from `poll_transmit` and wake it at
//! `poll_timeout` (docs/design.md, "The sans-IO core"). Built on `missionlink-protocol`; nothing
//! of the ground's logic is linked here.
//!
//! Grouped by the functions of the paper:
//! - [`mission_data_handling`] (the FCC's side of the link, §3.1), [`position`] (the position
//!   downlink, ICD §5.8), [`from_to_next`] (§3.1.7);
//! - [`health`] (liveness from heartbeats);
//! - [`automation`] (§2.5) with [`onboard`], the onboard geofence check of ICD §7;
//! - [`guidance`]: the guidance stub's kinematics, flying the route as flown;
//! - `testkit` (feature `testkit`): the FCC's configuration of ICD §1 for tests.
// A `Message` (up to a 60-vertex #2012) lives inline wherever it goes, so that handling a frame
// allocates nothing; enums that carry one are large by design.
#![allow(clippy::large_enum_variant)]

pub mod automation;
pub mod from_to_next;
pub mod guidance;
pub mod health;
pub mod mission_data_handling;
pub mod onboard;
pub mod position;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
