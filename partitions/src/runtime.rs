//! What every partition's event loop shares: sleeping in the WaitSet (or spinning with
//! `--poll`) until data, a deadline or a termination request; latency reports on an interval, on
//! SIGUSR1 and at shutdown.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;
use iceoryx2::waitset::{WaitSetRunError, WaitSetRunResult};

use crate::config::{Config, ConfigArgs};
use crate::latency::{self, Recorder};

/// Waits for the next event: data on an attachment, `timeout`, or (with `poll`) not at all.
/// `false` when the process was asked to terminate (SIGINT, SIGTERM).
pub fn wait<S: Service>(
    waitset: &WaitSet<S>,
    poll: bool,
    timeout: Duration,
) -> Result<bool, WaitSetRunError> {
    let timeout = if poll { Duration::ZERO } else { timeout };
    let result =
        waitset.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, timeout)?;
    Ok(!matches!(
        result,
        WaitSetRunResult::TerminationRequest | WaitSetRunResult::Interrupt
    ))
}

/// SIGUSR1 asks a partition to log its latency percentiles now.
#[derive(Debug)]
pub struct Shutdown {
    report: Arc<AtomicBool>,
}

impl Shutdown {
    /// Installs the SIGUSR1 handler.
    pub fn install() -> std::io::Result<Self> {
        let report = Arc::new(AtomicBool::new(false));
        signal_hook::flag::register(signal_hook::consts::SIGUSR1, Arc::clone(&report))?;
        Ok(Self { report })
    }

    /// Whether SIGUSR1 arrived since the last call.
    pub fn report_requested(&self) -> bool {
        self.report.swap(false, Ordering::Relaxed)
    }
}

/// Periodic latency reports and the summary file at shutdown.
#[derive(Debug)]
pub struct Report {
    partition: &'static str,
    interval: Option<Duration>,
    last: Instant,
    summary_dir: Option<PathBuf>,
}

impl Report {
    /// Reports of `partition` as `config` says.
    pub fn new(config: &Config, partition: &'static str) -> Self {
        Self {
            partition,
            interval: (config.latency.report_interval_s > 0)
                .then(|| Duration::from_secs(config.latency.report_interval_s)),
            last: Instant::now(),
            summary_dir: config.latency.summary_dir.clone(),
        }
    }

    /// Whether the report interval has passed (then it starts again).
    pub fn due(&mut self) -> bool {
        match self.interval {
            Some(i) if self.last.elapsed() >= i => {
                self.last = Instant::now();
                true
            }
            _ => false,
        }
    }

    /// Logs the recorders and writes the summary file with the counters, if configured (at
    /// shutdown).
    pub fn finish(&self, recorders: &[&Recorder], counters: &[(&str, u64)]) {
        latency::log(self.partition, recorders);
        if let Some(dir) = &self.summary_dir {
            latency::write_summary(dir, self.partition, recorders, counters);
        }
    }
}

/// The `main` of every partition: logging, the configuration (exit status 2 when it is wrong),
/// then `run` (exit status 1 with the error when it fails).
pub fn partition_main(
    name: &str,
    args: &ConfigArgs,
    run: impl FnOnce(&Config) -> Result<(), Box<dyn std::error::Error>>,
) -> std::process::ExitCode {
    crate::init_logging();
    crate::ipc::quiet_iceoryx2_log();
    if args.exit_with_parent {
        watch_parent(name);
    }
    let config = match args.resolve() {
        Ok(c) => c,
        Err(e) => {
            tracing::error!(%e, "configuration");
            return std::process::ExitCode::from(2);
        }
    };
    match run(&config) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!(%e, "{name} failed");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Sends this process SIGTERM once its parent is gone (the process is re-parented and its parent
/// ID changes), so it stops through its normal shutdown path: a safe stand-in for
/// PR_SET_PDEATHSIG, which would need unsafe code in the launcher.
fn watch_parent(name: &str) {
    let parent = rustix::process::getppid();
    let name = name.to_owned();
    let spawned = std::thread::Builder::new()
        .name("watch-parent".to_owned())
        .spawn(move || {
            loop {
                std::thread::sleep(Duration::from_millis(100));
                if rustix::process::getppid() != parent {
                    tracing::warn!(partition = %name, "the launcher is gone: stopping");
                    let _ = rustix::process::kill_process(
                        rustix::process::getpid(),
                        rustix::process::Signal::TERM,
                    );
                    return;
                }
            }
        });
    if let Err(e) = spawned {
        tracing::warn!(%e, "cannot watch the parent process");
    }
}
