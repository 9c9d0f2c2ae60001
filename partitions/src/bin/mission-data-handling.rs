//! `mission-data-handling`: the FCC partition of paper §3.1, a thin driver around
//! `services::mission_data_handling::MissionDataHandling`. It consumes voted uplink frames, the automation state
//! and guidance progress; it publishes downlink frames, the active waypoint and area lists
//! (history 1: late joiners get them) and accepted #50000 commands. After a restart it resumes
//! with the lists it published last, so guidance never sees them change.
//!
//! The loop is `missionlink_partitions::mission_data_handling::run`; this file parses the flags and runs it
//! on `ipc::Service`.

use std::process::ExitCode;

use clap::Parser;
use iceoryx2::prelude::ipc;
use missionlink_partitions::config::ConfigArgs;
use missionlink_partitions::mission_data_handling;
use missionlink_partitions::runtime::partition_main;

/// Mission data handling of the FCC.
#[derive(Debug, Parser)]
#[command(name = "mission-data-handling", version)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

fn main() -> ExitCode {
    partition_main(
        mission_data_handling::NAME,
        &Args::parse().config,
        mission_data_handling::run::<ipc::Service>,
    )
}
