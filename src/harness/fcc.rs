//! An FCC binary (the `fcc` launcher or one partition) as a child process of the demo or a test,
//! the one way they run one: started under a configuration of its own ([`local_config`]: prefix,
//! state, the GCS's ends, a link key), waited for until it announces that it is up, the ports
//! voting-monitoring announces read back, stopped with SIGTERM as the launcher stops its
//! partitions (`missionlink_partitions::launcher::terminate`).

use std::io;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::Duration;

use missionlink_interfaces::contracts::Partition;
use missionlink_partitions::config::{self, Config};
use missionlink_partitions::launcher::{GRACE, NAME, terminate};
use missionlink_partitions::state::{self, BoundLinks};
use missionlink_platform::udp::{LinkError, LocalEnds};

/// The configuration of a local FCC of its own (the demo's, a test's): service prefix `prefix`,
/// state and latency summaries under `dir` (`state/`, `latency/`), the GCS's ends as `gcs` bound
/// them, the FCC's ends on port 0 of loopback (voting-monitoring chooses and announces them:
/// read them with [`FccProcess::links`]). The links are signed as by default (ICD §9: policy
/// `require`) with a key made for it, `<dir>/link.key`, which the FCC and the GCS on this
/// configuration share; one made before in `dir` is used again.
pub fn local_config(dir: &Path, prefix: String, gcs: &LocalEnds) -> Result<Config, LinkError> {
    let key_file = dir.join("link.key");
    if !key_file.exists() {
        missionlink_platform::keys::generate_key_file(&key_file, 1)
            .map_err(|e| LinkError(e.to_string()))?;
    }
    let [direct, lte] = gcs.addrs()?;
    let any = std::net::SocketAddr::from(([127, 0, 0, 1], 0));
    let mut config = Config::default();
    config.links.gcs_direct = direct;
    config.links.gcs_lte = lte;
    config.links.fcc_direct = any;
    config.links.fcc_lte = any;
    config.ipc.service_prefix = prefix;
    config.ipc.state_dir = Some(dir.join("state"));
    config.latency.summary_dir = Some(dir.join("latency"));
    config.signing.key_files = vec![key_file];
    Ok(config)
}

/// An FCC binary (the `fcc` launcher or one partition) running as a child process under a
/// configuration handed over in its environment; stopped with SIGTERM when dropped.
#[derive(Debug)]
pub struct FccProcess {
    child: Child,
    /// The binary's name, under which it announces its readiness.
    name: String,
    log: Option<PathBuf>,
    state_dir: PathBuf,
}

impl FccProcess {
    /// Starts `binary` of `bin_dir` with `config` (see [`FccProcess::command`] and
    /// [`FccProcess::spawn`]).
    pub fn start(
        bin_dir: &Path,
        binary: &str,
        config: &Config,
        log: Option<&Path>,
    ) -> io::Result<Self> {
        Self::spawn(Self::command(bin_dir, binary, config)?, config, log)
    }

    /// The command that starts `binary` of `bin_dir` with `config`, to add to before
    /// [`FccProcess::spawn`]. It removes a previous announcement of the binary's readiness, and
    /// for the launcher or voting-monitoring of the links, so that [`FccProcess::wait_ready`]
    /// and [`FccProcess::links`] read this one's.
    pub fn command(bin_dir: &Path, binary: &str, config: &Config) -> io::Result<Command> {
        let state_dir = config.ipc.state_dir();
        state::forget_ready(&state_dir, binary)?;
        if binary == NAME || binary == Partition::VotingMonitoring.binary() {
            state::forget_links(&state_dir)?;
        }
        let mut command = Command::new(bin_dir.join(binary));
        config::hand_to(&mut command, config).map_err(io::Error::other)?;
        // An FCC ends with whatever started it, even a test or a benchmark killed by a signal.
        if binary == NAME {
            command.arg("--exit-with-parent");
        }
        Ok(command)
    }

    /// Spawns `command` (from [`FccProcess::command`] with `config`). Its log goes to `log` (at
    /// `info` unless `RUST_LOG` says otherwise) or, without one, to this process's stderr (at
    /// `warn` unless `RUST_LOG` says otherwise).
    pub fn spawn(mut command: Command, config: &Config, log: Option<&Path>) -> io::Result<Self> {
        let default_level = if log.is_some() { "info" } else { "warn" };
        command.env(
            "RUST_LOG",
            std::env::var("RUST_LOG").unwrap_or_else(|_| default_level.to_owned()),
        );
        if let Some(path) = log {
            command
                .stdout(Stdio::null())
                .stderr(std::fs::File::create(path)?);
        }
        let child = command.spawn().map_err(|e| {
            io::Error::new(
                e.kind(),
                format!(
                    "cannot start {}: {e}",
                    command.get_program().to_string_lossy()
                ),
            )
        })?;
        let name = Path::new(command.get_program())
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        Ok(Self {
            child,
            name,
            log: log.map(Path::to_path_buf),
            state_dir: config.ipc.state_dir(),
        })
    }

    /// The process ID.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// What it logged so far (empty without a log file).
    pub fn log_text(&self) -> String {
        self.log
            .as_deref()
            .and_then(|p| std::fs::read_to_string(p).ok())
            .unwrap_or_default()
    }

    /// The log file, if any.
    pub fn log_path(&self) -> Option<&Path> {
        self.log.as_deref()
    }

    /// The FCC's ends of the links as voting-monitoring announced them, waiting for the
    /// announcement up to `limit`; `None` when it did not come or the process ended.
    pub fn links(&mut self, limit: Duration) -> Option<BoundLinks> {
        let child = &mut self.child;
        state::wait_for_links(&self.state_dir, limit, || {
            matches!(child.try_wait(), Ok(None))
        })
    }

    /// Waits up to `limit` until it is up: a partition with its ports open and waiting for
    /// data, the launcher with every partition up (see [`state::announce_ready`]). `false`
    /// when it did not come up in time or the process ended.
    pub fn wait_ready(&mut self, limit: Duration) -> bool {
        let child = &mut self.child;
        state::wait_for_ready(&self.state_dir, &self.name, limit, || {
            matches!(child.try_wait(), Ok(None))
        })
    }

    /// The exit status, if it has ended.
    pub fn try_wait(&mut self) -> io::Result<Option<ExitStatus>> {
        self.child.try_wait()
    }

    /// Stops it with SIGTERM (SIGKILL after a grace period) and returns its exit status.
    pub fn stop(&mut self) -> io::Result<ExitStatus> {
        match self.child.try_wait()? {
            Some(status) => Ok(status),
            None => terminate(&mut self.child, GRACE * 2),
        }
    }

    /// Kills it with SIGKILL (as a crash would) and reaps it.
    pub fn kill(&mut self) -> io::Result<ExitStatus> {
        self.child.kill()?;
        self.child.wait()
    }
}

impl Drop for FccProcess {
    fn drop(&mut self) {
        let _ = self.stop();
    }
}
