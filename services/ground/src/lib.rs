//! What stays on the ground, sans-IO: the GCS's logic, driven by `missionlink-gcs` (docs/design.md,
//! "The sans-IO core"). Built on `missionlink-protocol`; nothing of the FCC's logic is linked
//! here.
//!
//! - [`ground_station`]: the GCS's side of the link (paper §3.2): upload, download, staging,
//!   activation and the outcome of each;
//! - [`safety_gateway`] (§2.2): the checks of a plan before it is sent;
//! - `testkit` (feature `testkit`): the GCS's configuration of ICD §1 for tests.
// A `Message` (up to a 60-vertex #2012) lives inline wherever it goes, so that handling a frame
// allocates nothing; enums that carry one are large by design.
#![allow(clippy::large_enum_variant)]

pub mod ground_station;
pub mod safety_gateway;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
