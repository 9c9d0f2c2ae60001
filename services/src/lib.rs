//! The sans-IO logic of missionlink: state machines that never read a clock or a socket
//! (DESIGN.md, "The sans-IO core"). Drivers in `partitions/` feed them frames and the time.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
// A `Message` (up to a 60-vertex #2012) lives inline wherever it goes, so that handling a frame
// allocates nothing; enums that carry one are large by design.
#![allow(clippy::large_enum_variant)]

pub mod areas;
pub mod automation;
pub mod endpoint;
pub mod fcc;
pub mod from_to_next;
pub mod gcs;
pub mod guidance;
pub mod local_frame;
pub mod mission;
pub mod receiver;
pub mod retry;
pub mod safety_gateway;
pub mod sampling;
pub mod sender;
pub mod time;
pub mod time_stamp;
pub mod voting;
