//! `voting-monitoring`: the FCC partition that owns the two data links (paper §2.4). It votes
//! every step's datagrams from the direct and the LTE link (integrity and validity checks of ICD
//! §2, newest by time stamp, the direct link on a tie, never waiting for the other link),
//! publishes the voted uplink frames on `fcc/link/uplink`, and sends every frame of
//! `fcc/link/downlink` on both links.
//!
//! The loop is `missionlink_partitions::voting_monitoring::run`; this file parses the flags and runs it
//! on `ipc::Service`.

use std::process::ExitCode;

use clap::Parser;
use iceoryx2::prelude::ipc;
use missionlink_partitions::config::ConfigArgs;
use missionlink_partitions::runtime::partition_main;
use missionlink_partitions::voting_monitoring;

/// Voting and monitoring of the direct and LTE links.
#[derive(Debug, Parser)]
#[command(name = "voting-monitoring", version)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

fn main() -> ExitCode {
    partition_main(
        voting_monitoring::NAME,
        &Args::parse().config,
        voting_monitoring::run::<ipc::Service>,
    )
}
