//! The ground service (`gcs serve`): one long-running process that owns the links of every
//! vehicle of a fleet, keeps each vehicle's state, and serves the `gcs` commands as its clients.

pub mod fleet;
pub mod request;
