//! The FCC's configuration: the link sections both sides read
//! ([`missionlink_platform::config`]: `[ids]`, `[links]`, `[timing]`, `[signing]`) and the
//! sections only the FCC has, in one TOML file. Every setting has a built-in default (ICD §1),
//! so no file is needed to start; a file may override any of them, and command-line flags
//! ([`FccArgs`]: the link's, the same for the FCC and the gcs tool, and the FCC's own) override
//! the file.
//!
//! ```toml
//! # [ids], [links], [timing], [signing]: see missionlink_platform::config
//!
//! [ipc]
//! service_prefix = "missionlink"  # every iceoryx2 service name starts with it
//! poll = false                    # true: spin instead of sleeping in the WaitSet (lowest latency)
//! state_dir = "/var/lib/missionlink"  # mission data handling's lists across restarts
//!
//! [ipc.idle.voting-monitoring]    # how the partition waits for its inputs (see `Idle`)
//! mode = "backoff"                # backoff (its default): spin, yield, then sleep in the
//!                                 # WaitSet; doorbell (the others' default): spin, yield, then
//!                                 # sleep on the partition's semaphore (`IdleMode::Doorbell`);
//!                                 # block: sleep in the WaitSet at once
//! spin_us = 200                   # spin this long after the last work (others' default: 0)
//! yield_us = 0                    # then yield between looks this long (default 0)
//! # and [ipc.idle.mission-data-handling], [ipc.idle.system-automation],
//! # [ipc.idle.guidance-stub]
//!
//! [guidance]
//! time_scale = 1.0                # simulated seconds per second
//! update_interval_ms = 50
//! start_latitude_deg = 48.26      # TROL
//! start_longitude_deg = 11.66
//! climb_rate_mps = 3.0
//! descent_rate_mps = 2.0
//! max_bank_deg = 25.0             # the bank of turns (their radius, ICD §7 "Turns in wind")
//! wind_speed_mps = 0.0            # the steady wind the simulated aircraft flies in
//! wind_from_deg = 0.0             # (turns are sized by the plan's wind, ICD §7)
//!
//! [latency]
//! report_interval_s = 0           # 0: report at shutdown and on SIGUSR1 only
//! summary_dir = "/tmp/stats"      # optional: each partition writes <name>.toml at shutdown
//!
//! [launcher]                      # restarts after systemd's RestartSec and StartLimitBurst
//! restart_delay_ms = 200          # the first pause; doubled after each short run
//! restart_delay_max_ms = 5000     # the longest pause
//! start_limit_burst = 5           # started this often within the window: not started again,
//! start_limit_interval_ms = 30000 # said once by name, the FCC reported degraded
//! without = []                    # partitions not to start, e.g. ["guidance-stub"] when a
//!                                 # replacement (a HIL rig's, another language's) fills the role
//!
//! [health]                        # docs/design.md "Health" (see `health`)
//! period_ms = 100                 # every partition beats on fcc/health/<role> this often
//! start_timeout_ms = 10000        # a partition started must beat within this
//!
//! [realtime.voting-monitoring]    # one table per partition (see `realtime`); default: none
//! cpus = [1]                      # CPU affinity; [] (the default): every CPU
//! fifo_priority = 50              # SCHED_FIFO 1..=99; left out (the default): SCHED_OTHER
//! lock_memory = true              # mlockall(MCL_CURRENT | MCL_FUTURE); default false
//! # and [realtime.mission-data-handling], [realtime.system-automation],
//! # [realtime.guidance-stub]
//!
//! [isolation]                     # each partition's fence (see `isolation`); on by default
//! enabled = true
//! on_violation = "kill"           # kill | errno: what a forbidden system call does
//! [isolation.voting-monitoring]   # and the other three: started as root, drop to this user
//! user = "missionlink"
//! ```

use std::path::{Path, PathBuf};
use std::time::Duration;

use missionlink_flight::guidance::GuidanceConfig;
use missionlink_flight::mission_data_handling::FccConfig;
use missionlink_interfaces::contracts::{
    DEFAULT_HEARTBEAT_PERIOD, DEFAULT_SERVICE_PREFIX, Partition,
};
use missionlink_interfaces::wire::Timestamp;
pub use missionlink_platform::config::{
    CONFIG_FILE_ENV, CONFIG_TOML_ENV, ConfigError, Ids, LinkArgs, LinkConfig, Links, PREFIX_ENV,
    Signing, SigningPolicy, Timing,
};
use serde::{Deserialize, Serialize};

pub use crate::per_partition::{PartitionDefault, PerPartition};

/// Shared memory between the partitions.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ipc {
    /// Prefix of every iceoryx2 service name: instances with different prefixes never meet.
    pub service_prefix: String,
    /// Spin instead of sleeping in the WaitSet (lowest latency, one core busy per partition).
    pub poll: bool,
    /// Where mission data handling keeps its active lists across restarts (default:
    /// `<temp>/missionlink-state/<prefix>`).
    pub state_dir: Option<PathBuf>,
    /// How each partition waits when its inputs are empty (`[ipc.idle.<partition>]`).
    pub idle: PerPartition<Idle>,
}

impl Default for Ipc {
    fn default() -> Self {
        Self {
            service_prefix: DEFAULT_SERVICE_PREFIX.to_owned(),
            poll: false,
            state_dir: None,
            idle: PerPartition::default(),
        }
    }
}

/// What a partition does when its inputs are empty, before the next frame, event or deadline
/// (`runtime::run_loop`; the doorbell where `doorbell::waits` says so).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum IdleMode {
    /// Sleep in the WaitSet at once: the wake-up of every frame costs the event's system calls
    /// and the kernel waking the thread (a Unix datagram and an epoll round with iceoryx2's
    /// default event).
    #[default]
    Block,
    /// Look at the inputs in a loop for `spin_us`, then yield the CPU between looks for
    /// `yield_us`, then sleep in the WaitSet as `Block` does (Aeron's BackoffIdleStrategy). A
    /// frame that comes within the budget after the last one is taken without a wake-up.
    Backoff,
    /// As `backoff`, then sleep on the partition's doorbell instead of the WaitSet: a POSIX
    /// semaphore in shared memory that every publisher of this workspace feeding the partition
    /// rings (the C library's too), with a timer thread that rings it at the loop's next
    /// deadline and a forwarder thread that rings it for a publisher that does not (a partition
    /// in Python, a program on iceoryx2's own bindings): `doorbell`. A partition that also
    /// waits for sockets (voting-monitoring) cannot: it sleeps in the WaitSet as `backoff`.
    Doorbell,
}

/// The idle strategy of one partition (`[ipc.idle.<partition>]`). A section names its `mode`:
/// the partitions' defaults differ, so a section without one would be ambiguous and is refused;
/// `spin_us` and `yield_us` left out are 0. The defaults of the partitions
/// ([`PartitionDefault`] of `Idle`) were chosen by measurement on the 2-vCPU development machine
/// (docs/wait-path.md, BENCHMARKS.md section 1):
///
/// - voting-monitoring: `backoff`, 200 µs of spinning. It waits for the UDP links as well, so it
///   cannot use the doorbell; mission data handling's answer to an uplink frame comes within the
///   spin, and so does the GCS's next frame of a transfer over loopback. Idle, it spins about
///   200 µs per wake-up (heartbeat and timers): 0.6 % of a CPU measured.
/// - mission-data-handling, system-automation, guidance-stub: `doorbell`, no spin. A publisher
///   of this workspace or on the C library rings it, one futex wake-up, and leaves its
///   listeners out of the event's notification (`doorbell::Ringers::notifies`); at the sparse
///   pace that hop was 0.98-1.07x the Unix socket against 1.09-1.28x for `block` in the same
///   runs (the rows in turns). A publisher that rings none (the Python guidance, a program on
///   iceoryx2's own bindings) is heard through the doorbell's forwarder, one thread wake-up
///   later (1.39-1.78x). It costs two threads per partition (the timer and the forwarder). On
///   two CPUs a second partition spinning takes the CPU the GCS and the other partitions
///   need, so they do not spin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Idle {
    /// `block`, `backoff` or `doorbell`.
    pub mode: IdleMode,
    /// With `backoff` and `doorbell`: how long the loop looks at its inputs without pausing
    /// before it sleeps, microseconds.
    #[serde(default)]
    pub spin_us: u64,
    /// With `backoff` and `doorbell`: how long it then looks, yielding the CPU between looks,
    /// microseconds.
    #[serde(default)]
    pub yield_us: u64,
}

/// voting-monitoring's default spin budget, microseconds.
pub const DEFAULT_SPIN_US: u64 = 200;

impl Default for Idle {
    fn default() -> Self {
        Self::BLOCK
    }
}

impl Idle {
    /// voting-monitoring's default: spin 200 µs, then sleep in the WaitSet.
    pub const VOTING_MONITORING: Self = Self {
        mode: IdleMode::Backoff,
        spin_us: DEFAULT_SPIN_US,
        yield_us: 0,
    };

    /// Sleeping on the doorbell at once: the default of every partition but voting-monitoring.
    pub const DOORBELL: Self = Self {
        mode: IdleMode::Doorbell,
        spin_us: 0,
        yield_us: 0,
    };

    /// Sleeping in the WaitSet at once.
    pub const BLOCK: Self = Self {
        mode: IdleMode::Block,
        spin_us: 0,
        yield_us: 0,
    };

    /// The spin budget.
    pub fn spin(&self) -> Duration {
        Duration::from_micros(self.spin_us)
    }

    /// The yield budget that follows the spin.
    pub fn yield_for(&self) -> Duration {
        Duration::from_micros(self.yield_us)
    }
}

/// The defaults of [`Idle`]'s documentation: voting-monitoring spins, the others sleep in the
/// WaitSet at once.
impl PartitionDefault for Idle {
    fn default_for(partition: Partition) -> Self {
        match partition {
            Partition::VotingMonitoring => Self::VOTING_MONITORING,
            _ => Self::DOORBELL,
        }
    }
}

impl Ipc {
    /// The defaults with the service prefix `prefix` (a process of a test or a tool that opens
    /// the services of an FCC it did not configure).
    pub fn with_prefix(prefix: &str) -> Self {
        Self {
            service_prefix: prefix.to_owned(),
            ..Self::default()
        }
    }

    /// The state directory.
    pub fn state_dir(&self) -> PathBuf {
        self.state_dir
            .clone()
            .unwrap_or_else(|| crate::state::default_dir(&self.service_prefix))
    }
}

/// The flags of the FCC's binaries (the launcher, each partition, the Zenoh bridge): the link's,
/// which the gcs tool takes too, and the FCC's own.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct FccArgs {
    /// The link's flags (the configuration file among them).
    #[command(flatten)]
    pub link: LinkArgs,
    /// Prefix of the iceoryx2 service names.
    #[arg(long, value_name = "PREFIX", env = PREFIX_ENV)]
    pub prefix: Option<String>,
    /// Guidance time scale (simulated seconds per second).
    #[arg(long, value_name = "FACTOR")]
    pub time_scale: Option<f64>,
    /// Spin instead of sleeping (lowest latency).
    #[arg(long)]
    pub poll: bool,
    /// Directory for the latency summaries written at shutdown.
    #[arg(long, value_name = "DIR")]
    pub summary_dir: Option<PathBuf>,
    /// Heartbeat period of every partition, milliseconds (`[health] period_ms`).
    #[arg(long, value_name = "MS")]
    pub heartbeat_ms: Option<u64>,
    /// End when the parent process ends: the launcher passes it to its partitions, so that they
    /// do not outlive it even after a `kill -9` of the launcher; a test or a benchmark passes it
    /// to the launcher, so that the FCC does not outlive them.
    #[arg(long, hide = true)]
    pub exit_with_parent: bool,
}

/// Latency reports.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Latency {
    /// Log the percentiles every this many seconds; 0: only at shutdown and on SIGUSR1.
    pub report_interval_s: u64,
    /// Where each partition writes `<name>.toml` with its percentiles at shutdown.
    pub summary_dir: Option<PathBuf>,
}

/// The fcc launcher.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Launcher {
    /// Pause before a dead partition is started again the first time; doubled after each
    /// restart that did not last `start_limit_interval_ms`, up to `restart_delay_max_ms`
    /// (systemd's `RestartSec`, with its `RestartSteps` and `RestartMaxDelaySec`).
    pub restart_delay_ms: u64,
    /// The longest pause before a restart.
    pub restart_delay_max_ms: u64,
    /// A partition started this many times within `start_limit_interval_ms` is not started
    /// again: the launcher says so once, by name, and reports the FCC degraded (systemd's
    /// `StartLimitBurst`).
    pub start_limit_burst: u32,
    /// The window of `start_limit_burst` (systemd's `StartLimitIntervalSec`).
    pub start_limit_interval_ms: u64,
    /// Partitions (binary names, `Partition::binary`) the launcher does not start: their
    /// role is filled by another process, whose heartbeat it still watches.
    pub without: Vec<String>,
}

impl Default for Launcher {
    fn default() -> Self {
        Self {
            restart_delay_ms: 200,
            restart_delay_max_ms: 5_000,
            start_limit_burst: 5,
            start_limit_interval_ms: 30_000,
            without: Vec::new(),
        }
    }
}

/// Health (docs/design.md "Health"): the heartbeat every partition sends, and how long a partition
/// may take to send its first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Health {
    /// Every partition beats this often; one silent for 2.5 periods counts as hung
    /// (`missionlink_flight::health`). At least 1.
    pub period_ms: u64,
    /// A partition started must send its first beat within this.
    pub start_timeout_ms: u64,
}

impl Default for Health {
    fn default() -> Self {
        Self {
            period_ms: u64::try_from(DEFAULT_HEARTBEAT_PERIOD.as_millis()).unwrap_or(100),
            start_timeout_ms: 10_000,
        }
    }
}

impl Health {
    /// The heartbeat period (at least 1 ms).
    pub fn period(&self) -> Duration {
        Duration::from_millis(self.period_ms.max(1))
    }

    /// The start timeout.
    pub fn start_timeout(&self) -> Duration {
        Duration::from_millis(self.start_timeout_ms)
    }
}

/// Every setting.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// Node IDs.
    pub ids: Ids,
    /// UDP links.
    pub links: Links,
    /// Timeouts.
    pub timing: Timing,
    /// iceoryx2.
    pub ipc: Ipc,
    /// The guidance stub's model (`[guidance]`: the services' own settings, read as they are).
    pub guidance: GuidanceConfig,
    /// Latency reports.
    pub latency: Latency,
    /// Launcher.
    pub launcher: Launcher,
    /// Heartbeats.
    pub health: Health,
    /// Link signing.
    pub signing: Signing,
    /// Real-time settings per partition (`[realtime.<partition>]`, applied by each partition to
    /// itself at start, `realtime::apply`; none by default).
    pub realtime: PerPartition<RealtimeSettings>,
    /// How each partition fences itself (`isolation`).
    pub isolation: Isolation,
    /// The bridge to another host (off by default; docs/two-hosts.md).
    pub bridge: crate::bridge_config::Bridge,
    /// Periodic downlink of mission data handling.
    pub downlink: Downlink,
}

/// The periodic downlink of mission data handling (ICD §5.8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Downlink {
    /// #101 Inertial States per second, the position downlink; 0 sends none.
    pub position_rate_hz: f64,
}

impl Default for Downlink {
    fn default() -> Self {
        Self {
            position_rate_hz: 2.0,
        }
    }
}

impl Downlink {
    /// The period of the position downlink; `None` when it is off (a rate of 0, or one that is
    /// not a positive finite number).
    pub fn position_period(&self) -> Option<Duration> {
        let hz = self.position_rate_hz;
        (hz.is_finite() && hz > 0.0)
            .then(|| Duration::try_from_secs_f64(1.0 / hz).ok())
            .flatten()
    }
}

impl Config {
    /// Parses a configuration; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        missionlink_platform::config::parse(text, path)
    }

    /// The configuration of `path`, or the defaults without one.
    pub fn load(path: Option<&Path>) -> Result<Self, ConfigError> {
        missionlink_platform::config::load(path)
    }

    /// The configuration `args` name (handed over as TOML, a file or the defaults) with every
    /// flag applied, the link's and the FCC's.
    pub fn resolve(args: &FccArgs) -> Result<Self, ConfigError> {
        let mut c: Self = args.link.load()?;
        args.link
            .apply_link(&mut c.ids, &mut c.links, &mut c.timing, &mut c.signing);
        if let Some(p) = &args.prefix {
            c.ipc.service_prefix = p.clone();
        }
        if let Some(v) = args.time_scale {
            c.guidance.time_scale = v;
        }
        if args.poll {
            c.ipc.poll = true;
        }
        if let Some(d) = &args.summary_dir {
            c.latency.summary_dir = Some(d.clone());
        }
        if let Some(ms) = args.heartbeat_ms {
            c.health.period_ms = ms;
        }
        // A resolved configuration can always be handed on (see `hand_to`).
        c.to_toml()?;
        Ok(c)
    }

    /// The configuration as TOML (what `--print-config` shows, and what the launcher hands to
    /// the partitions).
    pub fn to_toml(&self) -> Result<String, ConfigError> {
        toml::to_string_pretty(self).map_err(|e| ConfigError::Unrepresentable {
            message: e.to_string(),
        })
    }

    /// The link sections, what the ground reads of this configuration (a GCS link of the demo
    /// or of a test talking to this FCC).
    pub fn link(&self) -> LinkConfig {
        LinkConfig::new(self.ids, self.links, self.timing, self.signing.clone())
    }

    /// The core of mission data handling as this configuration says (IDs and timeouts), its
    /// instant zero at `utc_at_zero` (the driver's clock).
    pub fn fcc_core(&self, utc_at_zero: Timestamp) -> FccConfig {
        FccConfig {
            endpoint: self.ids.fcc_endpoint(utc_at_zero),
            ack_timeout: self.timing.ack_timeout(),
            transfer_timeout: self.timing.transfer_timeout(),
            position_period: self.downlink.position_period(),
        }
    }
}

/// Hands `config` to the child process `command` starts: as TOML in [`CONFIG_TOML_ENV`], and
/// without the inherited variables of `--config` and `--prefix`, which would override it. A
/// configuration TOML cannot represent is an error, never an empty hand-over (the child would
/// start with the defaults: another FCC's prefix and ports).
pub fn hand_to(command: &mut std::process::Command, config: &Config) -> Result<(), ConfigError> {
    command
        .env(CONFIG_TOML_ENV, config.to_toml()?)
        .env_remove(CONFIG_FILE_ENV)
        .env_remove(PREFIX_ENV);
    Ok(())
}

/// What the kernel does with a system call outside a partition's allow-list (`[isolation]
/// on_violation`): the fence's own type.
pub use missionlink_platform::fence::Violation;

/// The isolation of one partition (`[isolation.<partition>]`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PartitionIsolation {
    /// The user (a name of `/etc/passwd`, or a number) the partition drops to when it was
    /// started as root; `None`: it keeps the user it was started as.
    pub user: Option<String>,
}

/// No user to drop to unless the file names one.
impl PartitionDefault for PartitionIsolation {
    fn default_for(_: Partition) -> Self {
        Self::default()
    }
}

/// `[isolation]`: each partition's fence (`isolation`), on by default.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct Isolation {
    /// Fence every partition (no new privileges, Landlock, seccomp, the user).
    pub enabled: bool,
    /// What a forbidden system call does.
    pub on_violation: Violation,
    /// `[isolation.<partition>]`, beside the two settings above (a key that is neither they nor
    /// a partition nor `bridge` is refused by the table).
    #[serde(flatten)]
    pub partitions: PerPartition<PartitionIsolation>,
    /// The bridge (`[bridge]`), fenced as a partition.
    pub bridge: PartitionIsolation,
}

impl Default for Isolation {
    fn default() -> Self {
        Self {
            enabled: true,
            on_violation: Violation::Kill,
            partitions: PerPartition::default(),
            bridge: PartitionIsolation::default(),
        }
    }
}

/// The real-time settings of one partition process. Each one left at its default leaves the
/// process as the system started it.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RealtimeSettings {
    /// The CPUs the partition runs on (its affinity); empty: every CPU it was started with.
    pub cpus: Vec<usize>,
    /// SCHED_FIFO at this priority; `None`: the default scheduling (SCHED_OTHER).
    pub fifo_priority: Option<FifoPriority>,
    /// Lock all memory, current and future (`mlockall(MCL_CURRENT | MCL_FUTURE)`), so that no
    /// page fault to swap or to a dropped file page stalls the loop.
    pub lock_memory: bool,
}

/// None for every partition: each runs as any other process.
impl PartitionDefault for RealtimeSettings {
    fn default_for(_: Partition) -> Self {
        Self::default()
    }
}

impl RealtimeSettings {
    /// Whether any setting asks for something (else applying them changes nothing).
    pub fn any(&self) -> bool {
        !self.cpus.is_empty() || self.fifo_priority.is_some() || self.lock_memory
    }
}

/// A SCHED_FIFO priority, 1 (lowest) to 99 (highest): the range Linux gives SCHED_FIFO
/// (`sched_get_priority_min/max(2)`). A configuration with another number is refused when it
/// is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct FifoPriority(u8);

impl FifoPriority {
    /// The lowest priority.
    pub const MIN: u8 = 1;
    /// The highest priority.
    pub const MAX: u8 = 99;

    /// The priority `value`, if it is in 1..=99.
    pub fn new(value: u8) -> Option<Self> {
        (Self::MIN..=Self::MAX)
            .contains(&value)
            .then_some(Self(value))
    }

    /// The number.
    pub fn get(self) -> u8 {
        self.0
    }
}

impl TryFrom<u8> for FifoPriority {
    type Error = String;

    fn try_from(value: u8) -> Result<Self, Self::Error> {
        Self::new(value).ok_or_else(|| {
            format!(
                "a SCHED_FIFO priority is {} to {}, not {value}",
                Self::MIN,
                Self::MAX
            )
        })
    }
}

impl From<FifoPriority> for u8 {
    fn from(p: FifoPriority) -> Self {
        p.0
    }
}

impl std::fmt::Display for FifoPriority {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One file serves both sides: every section of the FCC's configuration is one the ground's
    /// `LinkConfig` reads or passes over (a new FCC section must be added there).
    #[test]
    fn the_ground_reads_every_fcc_configuration() {
        let text = toml::to_string(&Config::default()).unwrap();
        let ground: Result<missionlink_platform::config::LinkConfig, _> =
            missionlink_platform::config::parse(&text, Path::new("fcc.toml"));
        assert!(ground.is_ok(), "{ground:?}");
    }

    #[test]
    fn a_configuration_toml_cannot_carry_is_refused_not_handed_on_as_the_defaults() {
        use std::os::unix::ffi::OsStrExt;
        let args = FccArgs {
            summary_dir: Some(PathBuf::from(std::ffi::OsStr::from_bytes(b"/tmp/\xff"))),
            ..FccArgs::default()
        };
        let error = Config::resolve(&args).unwrap_err();
        assert!(
            matches!(error, ConfigError::Unrepresentable { .. }),
            "{error}"
        );
        let mut config = Config::default();
        config.latency.summary_dir = args.summary_dir.clone();
        let mut command = std::process::Command::new("true");
        assert!(hand_to(&mut command, &config).is_err());
        assert!(
            command
                .get_envs()
                .all(|(k, _)| k != std::ffi::OsStr::new(CONFIG_TOML_ENV)),
            "nothing handed over"
        );
    }

    #[test]
    fn the_idle_strategy_is_set_per_partition_and_a_partition_left_out_takes_its_default() {
        let c = Config::parse(
            "[ipc.idle.voting-monitoring]\nmode = \"block\"\n\
             [ipc.idle.guidance-stub]\nmode = \"backoff\"\nspin_us = 50\nyield_us = 20\n",
            Path::new("f"),
        )
        .unwrap();
        assert_eq!(
            c.ipc.idle[Partition::VotingMonitoring].mode,
            IdleMode::Block
        );
        let guidance = c.ipc.idle[Partition::Guidance];
        assert_eq!(guidance.mode, IdleMode::Backoff);
        assert_eq!(guidance.spin(), Duration::from_micros(50));
        assert_eq!(guidance.yield_for(), Duration::from_micros(20));
        let mdh = c.ipc.idle[Partition::MissionDataHandling];
        assert_eq!(mdh, Idle::DOORBELL);
        assert_eq!(mdh.mode, IdleMode::Doorbell);
        assert_eq!(mdh.spin_us, 0);
        // A section without its mode is refused (the partitions' defaults differ), saying
        // where; the spin and yield budgets left out are 0.
        let e = Config::parse("[ipc.idle.guidance-stub]\nspin_us = 10\n", Path::new("h"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("h:1:") && e.contains("missing field `mode`"),
            "{e}"
        );
        let mode_only = Config::parse(
            "[ipc.idle.guidance-stub]\nmode = \"backoff\"\n",
            Path::new("i"),
        )
        .unwrap();
        assert_eq!(
            mode_only.ipc.idle[Partition::Guidance],
            Idle {
                mode: IdleMode::Backoff,
                spin_us: 0,
                yield_us: 0,
            }
        );
        let defaults = Config::default();
        assert_eq!(
            defaults.ipc.idle[Partition::VotingMonitoring],
            Idle::VOTING_MONITORING
        );
        assert_eq!(Idle::VOTING_MONITORING.spin_us, DEFAULT_SPIN_US);
        assert_eq!(
            Config::parse(&c.to_toml().unwrap(), Path::new("y")).unwrap(),
            c
        );
        assert!(
            Config::parse(
                "[ipc.idle.voting-monitoring]\nmode = \"spin\"\n",
                Path::new("g")
            )
            .is_err()
        );
    }

    #[test]
    fn defaults_are_the_icd_defaults() {
        let c = Config::default();
        assert_eq!(c.ids.gcs, 0x0A00_0001);
        assert_eq!(c.links.fcc_direct.to_string(), "127.0.0.1:4586");
        assert_eq!(c.links.gcs_lte.to_string(), "127.0.0.1:4589");
        assert_eq!(c.timing.ack_timeout(), Duration::from_millis(500));
        assert_eq!(c.timing.transfer_timeout(), Duration::from_secs(3));
        // ICD §5.8: the position downlink at 2 Hz.
        assert_eq!(
            c.downlink.position_period(),
            Some(Duration::from_millis(500))
        );
    }

    #[test]
    fn a_position_rate_of_zero_or_no_number_turns_the_downlink_off() {
        for text in [
            "[downlink]\nposition_rate_hz = 0.0\n",
            "[downlink]\nposition_rate_hz = -1.0\n",
            "[downlink]\nposition_rate_hz = nan\n",
        ] {
            let c = Config::parse(text, Path::new("d.toml")).unwrap();
            assert_eq!(c.downlink.position_period(), None, "{text}");
        }
        let c =
            Config::parse("[downlink]\nposition_rate_hz = 10.0\n", Path::new("d.toml")).unwrap();
        assert_eq!(
            c.downlink.position_period(),
            Some(Duration::from_millis(100))
        );
    }

    /// `[guidance]` is the model's own settings: every one of them, the bank limit included,
    /// and nothing else.
    #[test]
    fn guidance_reads_into_the_models_settings() {
        let c = Config::parse(
            "[guidance]\nmax_bank_deg = 30.0\nupdate_interval_ms = 20\n",
            Path::new("g.toml"),
        )
        .unwrap();
        assert_eq!(c.guidance.max_bank_deg, 30.0);
        assert_eq!(c.guidance.update_interval_ms, 20);
        assert_eq!(
            c.guidance.climb_rate_mps,
            GuidanceConfig::default().climb_rate_mps
        );
        let e = Config::parse("[guidance]\nbank = 30.0\n", Path::new("g.toml")).unwrap_err();
        assert!(e.to_string().contains("g.toml:2:1"), "{e}");
    }

    #[test]
    fn a_file_overrides_what_it_names_and_round_trips() {
        let c = Config::parse(
            "[ids]\nfcc = 0x0B000002\n[guidance]\ntime_scale = 20.0\n",
            Path::new("x.toml"),
        )
        .unwrap();
        assert_eq!(c.ids.fcc, 0x0B00_0002);
        assert_eq!(c.ids.gcs, 0x0A00_0001);
        assert_eq!(c.guidance.time_scale, 20.0);
        assert_eq!(
            Config::parse(&c.to_toml().unwrap(), Path::new("y")).unwrap(),
            c
        );
    }

    #[test]
    fn the_signing_section_names_key_files_and_the_flags_override_it() {
        let c = Config::parse(
            "[signing]\npolicy = \"require\"\nkey_files = [\"/k/1.key\", \"/k/2.key\"]\nsend_key_id = 2\n",
            Path::new("f"),
        )
        .unwrap();
        assert_eq!(c.signing.policy, SigningPolicy::Require);
        assert_eq!(c.signing.key_files.len(), 2);
        assert_eq!(c.signing.send_key_id, Some(2));
        // What --print-config shows and the partitions receive: paths, no key.
        let text = c.to_toml().unwrap();
        assert!(
            text.contains("/k/2.key") && text.contains("require"),
            "{text}"
        );
        assert_eq!(Config::parse(&text, Path::new("y")).unwrap(), c);
        let e = Config::parse("[signing]\npolicy = \"always\"\n", Path::new("f")).unwrap_err();
        assert!(e.to_string().contains("f:2:10"), "{e}");
        let args = FccArgs {
            link: LinkArgs {
                config_toml: Some(text),
                signing: Some(SigningPolicy::Accept),
                key_files: vec![PathBuf::from("/other.key")],
                send_key_id: Some(7),
                ..LinkArgs::default()
            },
            ..FccArgs::default()
        };
        let resolved = Config::resolve(&args).unwrap();
        assert_eq!(resolved.signing.policy, SigningPolicy::Accept);
        assert_eq!(resolved.signing.key_files, [PathBuf::from("/other.key")]);
        assert_eq!(resolved.signing.send_key_id, Some(7));
        // Signing is required unless a person writes otherwise (ICD §9).
        assert_eq!(Config::default().signing.policy, SigningPolicy::Require);
        let off = Config::parse("[signing]\npolicy = \"off\"\n", Path::new("f")).unwrap();
        assert_eq!(off.signing.policy, SigningPolicy::Off);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = Config::parse("[ids]\ngcs = 1\nfcc = \"x\"\n", Path::new("fcc.toml")).unwrap_err();
        let text = e.to_string();
        assert!(text.starts_with("fcc.toml:3:7: "), "{text}");
        let e = Config::parse("[timing]\nack_timeout = 5\n", Path::new("f")).unwrap_err();
        assert!(e.to_string().contains("unknown field `ack_timeout`"), "{e}");
    }

    #[test]
    fn a_configuration_handed_over_as_toml_replaces_the_file_and_flags_still_apply() {
        let mut handed = Config::default();
        handed.ipc.service_prefix = "handed".to_owned();
        handed.guidance.time_scale = 7.0;
        let args = FccArgs {
            link: LinkArgs {
                config: Some(PathBuf::from("/nonexistent/missionlink.toml")),
                config_toml: Some(handed.to_toml().unwrap()),
                fcc_id: Some(5),
                ..LinkArgs::default()
            },
            ..FccArgs::default()
        };
        let resolved = Config::resolve(&args).unwrap();
        handed.ids.fcc = 5;
        assert_eq!(resolved, handed);
    }

    #[test]
    fn health_and_the_partitions_left_out_come_from_the_file_and_the_flags() {
        let c = Config::parse(
            "[launcher]\nwithout = [\"guidance-stub\"]\n[health]\nperiod_ms = 50\n",
            Path::new("f"),
        )
        .unwrap();
        assert_eq!(c.launcher.without, ["guidance-stub"]);
        assert_eq!(c.health.period(), Duration::from_millis(50));
        assert_eq!(c.health.start_timeout(), Duration::from_secs(10));
        assert_eq!(
            Config::parse(&c.to_toml().unwrap(), Path::new("y")).unwrap(),
            c
        );
        let args = FccArgs {
            link: LinkArgs {
                config_toml: Some(c.to_toml().unwrap()),
                ..LinkArgs::default()
            },
            heartbeat_ms: Some(0),
            ..FccArgs::default()
        };
        let resolved = Config::resolve(&args).unwrap();
        assert_eq!(
            resolved.health.period(),
            Duration::from_millis(1),
            "at least 1 ms"
        );
        assert_eq!(
            Config::default().health.period(),
            Duration::from_millis(100)
        );
    }

    #[test]
    fn the_realtime_section_is_per_partition_and_empty_by_default() {
        let defaults = Config::default();
        for (p, settings) in defaults.realtime.iter() {
            assert!(!settings.any(), "{p}: no real-time settings by default");
        }
        // --print-config shows the section, one table per partition.
        let text = defaults.to_toml().unwrap();
        for name in Partition::BINARIES {
            assert!(text.contains(&format!("[realtime.{name}]")), "{text}");
        }
        let c = Config::parse(
            "[realtime.voting-monitoring]\ncpus = [1]\nfifo_priority = 50\nlock_memory = true\n\
             [realtime.guidance-stub]\ncpus = [0, 1]\n",
            Path::new("f"),
        )
        .unwrap();
        let voting = &c.realtime[Partition::VotingMonitoring];
        assert_eq!(voting.cpus, [1]);
        assert_eq!(voting.fifo_priority.map(FifoPriority::get), Some(50));
        assert!(voting.lock_memory);
        let guidance = &c.realtime[Partition::Guidance];
        assert_eq!(guidance.cpus, [0, 1]);
        assert_eq!(guidance.fifo_priority, None);
        assert!(!guidance.lock_memory);
        assert!(!c.realtime[Partition::MissionDataHandling].any());
        // The hand-over to the partitions carries it.
        assert_eq!(
            Config::parse(&c.to_toml().unwrap(), Path::new("y")).unwrap(),
            c
        );
        // A priority outside 1..=99, a partition or a key that does not exist: refused, with
        // the place.
        for (text, expected) in [
            (
                "[realtime.voting-monitoring]\nfifo_priority = 0\n",
                "f:2:17: ",
            ),
            (
                "[realtime.voting-monitoring]\nfifo_priority = 100\n",
                "f:2:17: ",
            ),
            (
                "[realtime.voting-monitoring]\nfifo_priority = 300\n",
                "f:2:17: ",
            ),
            ("[realtime.voting-monitoring]\ncpus = [-1]\n", "f:2:"),
            ("[realtime.gcs]\ncpus = [1]\n", "f:1:"),
            ("[realtime.guidance-stub]\npriority = 5\n", "f:2:1: "),
        ] {
            let e = Config::parse(text, Path::new("f")).unwrap_err();
            assert!(e.to_string().starts_with(expected), "{text:?}: {e}");
        }
        let e = Config::parse(
            "[realtime.system-automation]\nfifo_priority = 0\n",
            Path::new("f"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("1 to 99, not 0"), "{e}");
    }
}
