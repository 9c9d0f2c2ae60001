//! `guidance-stub`: the FCC partition that stands in for flight guidance in the rig, a thin
//! driver around `services::guidance::Guidance`. It flies the active waypoint and area lists
//! with a simple kinematic model when system automation says so, time-scaled for demos, and
//! publishes FROM / TO / NEXT and the position on `fcc/guidance/progress`. It reports when the
//! position leaves the fly-zone or enters a no-fly-zone.
//!
//! The loop is `missionlink_partitions::guidance_stub::run`; this file parses the flags and runs it
//! on `ipc::Service`.

use std::process::ExitCode;

use clap::Parser;
use iceoryx2::prelude::ipc;
use missionlink_partitions::config::ConfigArgs;
use missionlink_partitions::guidance_stub;
use missionlink_partitions::runtime::partition_main;

/// Guidance stub of the FCC.
#[derive(Debug, Parser)]
#[command(name = "guidance-stub", version)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

fn main() -> ExitCode {
    partition_main(
        guidance_stub::NAME,
        &Args::parse().config,
        guidance_stub::run::<ipc::Service>,
    )
}
