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

pub mod areas;
pub mod endpoint;
pub mod mission;
pub mod retry;
pub mod sampling;
pub mod time;
pub mod time_stamp;
