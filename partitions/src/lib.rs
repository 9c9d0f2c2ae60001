//! The FCC of missionlink: the drivers of the four partitions and the fcc launcher. They move
//! bytes between sockets, iceoryx2 and the sans-IO services and inject the time; the logic lives
//! in `missionlink-services`. No ground tooling is linked here (that is `missionlink-gcs`).
//!
//! Each partition's loop is a library function generic over the iceoryx2 service type
//! (`voting_monitoring::run::<S>` and so on): the binaries run it on `ipc::Service`, the tests
//! in one process on `local::Service`, and a [`runtime::Control`] stops it from another thread.

pub mod binaries;
pub mod bridge_config;
pub mod clock;
pub mod config;
pub mod doorbell;
pub mod guidance_stub;
pub mod health;
pub mod ipc;
pub mod keys;
pub mod latency;
pub mod launcher;
pub mod mission_data_handling;
pub mod realtime;
pub mod runtime;
pub mod state;
pub mod system_automation;
pub mod udp;
pub mod voting_monitoring;

/// Installs the `tracing` subscriber of every binary: human-readable lines on stderr, filtered by
/// `RUST_LOG` (default `info`), so stdout carries only the tool's output.
pub fn init_logging() {
    init_logging_at("info");
}

/// As [`init_logging`], with `default` as the filter when `RUST_LOG` is not set.
pub fn init_logging_at(default: &str) {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .try_init();
}
