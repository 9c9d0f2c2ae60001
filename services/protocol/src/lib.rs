//! What both ends of the link share, sans-IO: state machines and geometry that never read a
//! clock or a socket (docs/design.md, "The sans-IO core"). The FCC's logic
//! (`missionlink-flight`) and the ground's (`missionlink-ground`) are built on it, and neither
//! on the other: flight software is reviewed by what is in the flight binary.
//!
//! - [`link`]: preprocessing, acknowledgement, sampling, timeout and retry, the timer table,
//!   rejected-input counters, time stamps, signing (paper §3.1.1-4; ICD §9);
//! - [`transfer`]: the one sender and the mission and area receivers, buffers, assembly and
//!   integrity (paper §3.1.5-9, inverted use §3.2; ICD §7, §10, §11), and the plan an operator
//!   makes of them;
//! - [`voting`]: the voter of the two links (paper §2.4), on the FCC (voting and monitoring)
//!   and on the ground alike;
//! - [`geofence`]: the one Earth model, zones and clearance, and the route as flown (legs and
//!   turns), which the FCC's onboard check and the ground's safety gateway both measure;
//! - `testkit` (feature `testkit`): the fixtures every level's tests and benches share.
// A `Message` (up to a 60-vertex #2012) lives inline wherever it goes, so that handling a frame
// allocates nothing; enums that carry one are large by design.
#![allow(clippy::large_enum_variant)]

pub mod geofence;
pub mod link;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
pub mod transfer;
pub mod voting;
