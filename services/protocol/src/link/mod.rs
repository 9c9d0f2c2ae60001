//! The link functions both ends share (paper §3.1.1-§3.1.4): preprocessing and acknowledgement
//! in the [`endpoint`], message [`sampling`], timeout and [`retry`], the [`timer`] table of every
//! state machine, the sender's [`time_stamp`]s, the [`time`] the driver injects, the counters
//! and rate-limited log of [`rejects`], link [`signing`] (ICD §9), and the frame of the machines made of transfers
//! ([`composite`]).

pub mod composite;
pub mod endpoint;
pub mod rejects;
pub mod retry;
pub mod sampling;
pub mod signing;
pub mod time;
pub mod time_stamp;
pub mod timer;
