//! The FCC of missionlink: the drivers of the four partitions and the fcc launcher. They move
//! bytes between sockets, iceoryx2 and the sans-IO services and inject the time; the logic lives
//! in `missionlink-flight` over `missionlink-protocol`. No ground tooling or ground logic is linked here (that is `missionlink-gcs`); what
//! both sides share (the link configuration, the UDP pair, keys, clock, logging) is
//! `missionlink-platform`'s.
//!
//! Each partition's loop is a library function generic over the iceoryx2 service type
//! (`voting_monitoring::run::<S>` and so on): the binaries run it on `ipc::Service`, the tests
//! in one process on `local::Service`, and a [`runtime::Control`] stops it from another thread.

pub mod binaries;
pub mod bridge_config;
pub mod config;
pub mod doorbell;
pub mod guidance_stub;
pub mod health;
pub mod ipc;
pub mod isolation;
pub mod latency;
pub mod launcher;
pub mod mission_data_handling;
pub mod realtime;
pub mod runtime;
pub mod state;
pub mod system_automation;
pub mod voting_monitoring;
pub mod wait_fd;
