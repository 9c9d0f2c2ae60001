//! `bridge`: forwards chosen iceoryx2 services of this host to Zenoh and back (`[bridge]` of the
//! configuration, docs/two-hosts.md). The launcher starts it when `[bridge] enabled`; it runs
//! on its own too (`bridge --config fcc.toml`). The process is `missionlink_bridge::main`.

use std::process::ExitCode;

use clap::Parser;
use missionlink_partitions::config::ConfigArgs;

/// Bridge between the FCC's iceoryx2 services and Zenoh.
#[derive(Debug, Parser)]
#[command(name = "bridge", version)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

fn main() -> ExitCode {
    missionlink_bridge::main(&Args::parse().config)
}
