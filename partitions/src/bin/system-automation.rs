//! `system-automation`: the FCC partition of paper §2.5, a thin driver around
//! `services::automation::SystemAutomation`. It follows the active lists and guidance's
//! progress, carries out the #50000 commands mission data handling accepted, and publishes the
//! flight phase and which functions are active (`fcc/automation/state`, history 1). A restarted
//! automation adopts the phase guidance's progress shows, so it never drops an aircraft in the
//! air back to "on ground".
//!
//! The loop is `missionlink_partitions::system_automation::run`; this file parses the flags and runs it
//! on `ipc::Service`.

use std::process::ExitCode;

use clap::Parser;
use iceoryx2::prelude::ipc;
use missionlink_partitions::config::ConfigArgs;
use missionlink_partitions::runtime::partition_main;
use missionlink_partitions::system_automation;

/// System automation of the FCC.
#[derive(Debug, Parser)]
#[command(name = "system-automation", version)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

fn main() -> ExitCode {
    partition_main(
        system_automation::NAME,
        &Args::parse().config,
        system_automation::run::<ipc::Service>,
    )
}
