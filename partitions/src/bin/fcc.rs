//! `fcc`: the launcher of the FCC. It starts the four partitions as child processes with one
//! configuration (the resolved settings, written to one file they all read), restarts a partition
//! that dies (a log line names it and its exit status), and on SIGINT or SIGTERM stops them all:
//! SIGTERM first, SIGKILL for one that has not ended within the grace period.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, ExitStatus};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use clap::Parser;
use missionlink_partitions::config::{Config, ConfigArgs};

/// The partitions, in start order.
const PARTITIONS: [&str; 4] = [
    "voting-monitoring",
    "mission-data-handling",
    "system-automation",
    "guidance-stub",
];

/// How long a partition may take to end after SIGTERM.
const GRACE: Duration = Duration::from_secs(5);
const SUPERVISION_PERIOD: Duration = Duration::from_millis(20);

/// Launcher of the FCC partitions.
#[derive(Debug, Parser)]
#[command(name = "fcc", version, about)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
    /// Where the partition binaries are (default: next to this one).
    #[arg(long, value_name = "DIR")]
    bin_dir: Option<PathBuf>,
    /// Print the resolved configuration and exit.
    #[arg(long)]
    print_config: bool,
}

struct Partition {
    name: &'static str,
    child: Option<Child>,
    restart_at: Option<Instant>,
    restarts: u32,
}

fn spawn(bin_dir: &Path, name: &str, config_file: &Path) -> std::io::Result<Child> {
    Command::new(bin_dir.join(name))
        .args(ConfigArgs::for_file(config_file))
        .spawn()
}

fn terminate(p: &mut Partition) {
    let Some(child) = p.child.as_mut() else {
        return;
    };
    if let Some(pid) = rustix::process::Pid::from_raw(child.id() as i32) {
        let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
    }
    let deadline = Instant::now() + GRACE;
    loop {
        match child.try_wait() {
            Ok(Some(status)) => {
                tracing::info!(partition = p.name, %status, "stopped");
                break;
            }
            Ok(None) if Instant::now() < deadline => std::thread::sleep(SUPERVISION_PERIOD),
            _ => {
                tracing::warn!(partition = p.name, "did not stop in time: killed");
                let _ = child.kill();
                let _ = child.wait();
                break;
            }
        }
    }
    p.child = None;
}

fn describe(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exit code {code}"),
        (None, Some(signal)) => format!("killed by signal {signal}"),
        _ => status.to_string(),
    }
}

fn run(config: &Config, bin_dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let stop = Arc::new(AtomicBool::new(false));
    signal_hook::flag::register(signal_hook::consts::SIGINT, Arc::clone(&stop))?;
    signal_hook::flag::register(signal_hook::consts::SIGTERM, Arc::clone(&stop))?;

    let config_file = std::env::temp_dir().join(format!(
        "missionlink-fcc-{}-{}.toml",
        config.ipc.service_prefix.replace('/', "_"),
        std::process::id()
    ));
    std::fs::write(&config_file, config.to_toml())?;
    let restart_delay = Duration::from_millis(config.launcher.restart_delay_ms);

    let mut partitions: Vec<Partition> = PARTITIONS
        .iter()
        .map(|name| Partition {
            name,
            child: None,
            restart_at: Some(Instant::now()),
            restarts: 0,
        })
        .collect();
    tracing::info!(
        prefix = %config.ipc.service_prefix,
        direct = %config.links.fcc_direct,
        lte = %config.links.fcc_lte,
        "starting the FCC partitions"
    );

    while !stop.load(Ordering::Relaxed) {
        for p in &mut partitions {
            if let Some(child) = p.child.as_mut() {
                if let Ok(Some(status)) = child.try_wait() {
                    tracing::error!(
                        partition = p.name,
                        status = %describe(status),
                        "partition died; restarting in {} ms",
                        restart_delay.as_millis()
                    );
                    p.child = None;
                    p.restart_at = Some(Instant::now() + restart_delay);
                    p.restarts += 1;
                }
            }
            if p.restart_at.is_some_and(|t| Instant::now() >= t) {
                p.restart_at = None;
                match spawn(bin_dir, p.name, &config_file) {
                    Ok(child) => {
                        tracing::info!(partition = p.name, pid = child.id(), "started");
                        p.child = Some(child);
                    }
                    Err(e) => {
                        tracing::error!(partition = p.name, %e, "cannot start; retrying");
                        p.restart_at = Some(Instant::now() + restart_delay);
                    }
                }
            }
        }
        std::thread::sleep(SUPERVISION_PERIOD);
    }
    tracing::info!("stopping the FCC partitions");
    // Stop in reverse order: guidance first, the links last.
    for p in partitions.iter_mut().rev() {
        terminate(p);
    }
    let _ = std::fs::remove_file(&config_file);
    Ok(())
}

fn main() -> ExitCode {
    missionlink_partitions::init_logging();
    let args = Args::parse();
    let config = match args.config.resolve() {
        Ok(c) => c,
        Err(e) => {
            tracing::error!(%e, "configuration");
            return ExitCode::from(2);
        }
    };
    if args.print_config {
        print!("{}", config.to_toml());
        return ExitCode::SUCCESS;
    }
    let bin_dir = match args
        .bin_dir
        .or_else(missionlink_partitions::binaries::build_dir)
    {
        Some(d) => d,
        None => {
            tracing::error!("cannot find the partition binaries: give --bin-dir");
            return ExitCode::from(2);
        }
    };
    match run(&config, &bin_dir) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!(%e, "fcc launcher failed");
            ExitCode::FAILURE
        }
    }
}
