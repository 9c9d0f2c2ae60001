//! `fcc`: the launcher of the FCC. It starts the four partitions (or those not left out with
//! `--without`) as child processes with one configuration, restarts a partition that dies or
//! hangs, and on SIGINT or SIGTERM stops them all (`missionlink_partitions::launcher`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use missionlink_interfaces::contracts::Partition;
use missionlink_partitions::config::FccArgs;
use missionlink_partitions::launcher;

/// Launcher of the FCC partitions.
#[derive(Debug, Parser)]
#[command(name = "fcc", version)]
struct Args {
    #[command(flatten)]
    config: FccArgs,
    /// Where the partition binaries are (default: next to this one).
    #[arg(long, value_name = "DIR")]
    bin_dir: Option<PathBuf>,
    /// Print the resolved configuration and exit.
    #[arg(long)]
    print_config: bool,
    /// Do not start this partition: another process (a HIL rig's, one in another language)
    /// fills its role. Repeatable; adds to `[launcher] without`.
    #[arg(long, value_name = "PARTITION", value_parser = clap::builder::PossibleValuesParser::new(Partition::BINARIES))]
    without: Vec<String>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    launcher::main(&args.config, &args.without, args.bin_dir, args.print_config)
}
