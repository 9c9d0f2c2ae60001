//! What the two sides of missionlink share and nothing else: the FCC (`missionlink-partitions`)
//! and the ground (`missionlink-gcs`) both depend on this crate, never on each other, and it
//! links no iceoryx2, so the ground tool carries no shared-memory code.
//!
//! - [`config`]: the link sections of the one configuration file (IDs, UDP ports, timeouts,
//!   signing), their parsing with line and column in errors, and the flags every binary takes.
//! - [`udp`]: the two UDP links as one pair of non-blocking sockets.
//! - [`keys`]: link key files and a node's signing (ICD §9).
//! - [`clock`]: the drivers' clock (CLOCK_MONOTONIC, UTC at start).
//! - [`parent`]: ending with the process that started this one.
//! - [`init_logging`]: the `tracing` subscriber of every binary.

pub mod clock;
pub mod config;
pub mod fence;
pub mod files;
pub mod keys;
pub mod parent;
pub mod udp;

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
