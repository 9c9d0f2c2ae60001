//! The real-time settings of a partition process (`[realtime.<partition>]` of the
//! configuration): the CPUs it runs on, SCHED_FIFO at a priority, and all of its memory locked.
//! [`apply_and_log`] is what a partition calls once at start, before its loop: it asks the
//! kernel for each setting, reads back what the thread and the process actually have, logs
//! that, and logs a warning naming each setting the kernel refused ([`Warning`]). A refusal is
//! never an error: a partition without its real-time settings still does its work, later than
//! it could.
//!
//! What a setting reaches: the affinity and the scheduling policy are per thread in Linux.
//! They are set on the calling thread (the one that goes on to run the partition's loop) and
//! every thread it starts afterwards inherits them. A thread started before keeps what it had:
//! in a partition that is only `runtime`'s watch-parent thread, which sleeps until the
//! launcher ends and is better left off the real-time priorities. iceoryx2 0.10 starts
//! no thread of its own in a node, a port or a WaitSet. Locked memory is per process.
//!
//! The benchmark of the partition-to-partition hop under CPU load (`benches/latency/load.rs`,
//! `--load`) applies its real-time case through this module too.

use std::fmt;
use std::io;

use rustix::thread::CpuSet;
use thread_priority::{
    NormalThreadSchedulePolicy, RealtimeThreadSchedulePolicy, ThreadPriority, ThreadPriorityValue,
    ThreadSchedulePolicy,
};

use crate::config::{FifoPriority, RealtimeSettings};

/// A setting the kernel did not grant in full, or granted under a limit that a later
/// allocation will meet. The process goes on without it.
#[derive(Debug)]
pub enum Warning {
    /// A CPU number at or beyond [`CpuSet::MAX_CPU`], which no CPU mask of this interface can
    /// hold: nothing was asked of the kernel and the affinity is as it was.
    CpuBeyondMask {
        /// The CPU number of the configuration.
        cpu: usize,
    },
    /// `sched_setaffinity(2)` refused the CPUs: `EINVAL` when none of them is online and
    /// allowed to the process (its cpuset), `EPERM` for a thread of another user. The affinity
    /// is as it was.
    Affinity {
        /// The CPUs asked for.
        cpus: Vec<usize>,
        /// The kernel's answer.
        error: io::Error,
    },
    /// The kernel set the affinity without these CPUs of the configuration (offline, or
    /// outside the process's cpuset): the thread runs on the others.
    CpusLeftOut {
        /// The CPUs asked for and not granted.
        cpus: Vec<usize>,
    },
    /// `pthread_setschedparam(3)` refused SCHED_FIFO at the priority: `EPERM` without
    /// CAP_SYS_NICE and with an RLIMIT_RTPRIO below it (or in a cgroup without real-time
    /// runtime). The scheduling is as it was.
    FifoPriority {
        /// The priority asked for.
        priority: FifoPriority,
        /// The answer.
        error: io::Error,
    },
    /// `mlockall(2)` refused: `EPERM` without CAP_IPC_LOCK and with an RLIMIT_MEMLOCK of 0,
    /// `ENOMEM` when the process's memory is above RLIMIT_MEMLOCK. Memory is not locked.
    LockMemory {
        /// The kernel's answer.
        error: io::Error,
    },
    /// Memory is locked, but under an RLIMIT_MEMLOCK and without CAP_IPC_LOCK: every later
    /// mapping is locked too (MCL_FUTURE) and counts against the limit, so a mapping that would
    /// pass it fails (`EAGAIN`), iceoryx2's shared memory for a port opened later included.
    LockMemoryLimit {
        /// The soft limit, in KiB.
        limit_kib: u64,
    },
}

impl Warning {
    /// The configuration key of the setting (in `[realtime.<partition>]`).
    pub fn setting(&self) -> &'static str {
        match self {
            Self::CpuBeyondMask { .. } | Self::Affinity { .. } | Self::CpusLeftOut { .. } => "cpus",
            Self::FifoPriority { .. } => "fifo_priority",
            Self::LockMemory { .. } | Self::LockMemoryLimit { .. } => "lock_memory",
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::CpuBeyondMask { cpu } => write!(
                f,
                "cpus: CPU {cpu} is beyond the largest CPU number a mask holds ({}); affinity \
                 unchanged",
                CpuSet::MAX_CPU - 1
            ),
            Self::Affinity { cpus, error } => write!(
                f,
                "cpus = {}: sched_setaffinity refused: {error}; affinity unchanged",
                CpuList(cpus)
            ),
            Self::CpusLeftOut { cpus } => write!(
                f,
                "cpus: the kernel left out CPU {} (offline or outside the cpuset)",
                CpuList(cpus)
            ),
            Self::FifoPriority { priority, error } => write!(
                f,
                "fifo_priority = {priority}: SCHED_FIFO refused: {error}; scheduling unchanged"
            ),
            Self::LockMemory { error } => {
                write!(
                    f,
                    "lock_memory: mlockall refused: {error}; memory not locked"
                )
            }
            Self::LockMemoryLimit { limit_kib } => write!(
                f,
                "lock_memory: locked, but under RLIMIT_MEMLOCK {limit_kib} KiB without \
                 CAP_IPC_LOCK: a later mapping beyond it (an iceoryx2 port) will fail"
            ),
        }
    }
}

/// A thread's scheduling policy, with the priority where the policy has one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Scheduling {
    /// SCHED_OTHER, the default.
    Other,
    /// SCHED_BATCH.
    Batch,
    /// SCHED_IDLE.
    Idle,
    /// SCHED_FIFO at this priority.
    Fifo(i32),
    /// SCHED_RR at this priority.
    RoundRobin(i32),
    /// SCHED_DEADLINE.
    Deadline,
    /// Could not be read: why.
    Unknown(String),
}

impl fmt::Display for Scheduling {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Other => f.write_str("SCHED_OTHER"),
            Self::Batch => f.write_str("SCHED_BATCH"),
            Self::Idle => f.write_str("SCHED_IDLE"),
            Self::Fifo(p) => write!(f, "SCHED_FIFO priority {p}"),
            Self::RoundRobin(p) => write!(f, "SCHED_RR priority {p}"),
            Self::Deadline => f.write_str("SCHED_DEADLINE"),
            Self::Unknown(why) => write!(f, "unknown ({why})"),
        }
    }
}

/// What the calling thread and its process have, read back from the kernel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Observed {
    /// The CPUs the thread may run on; `None` when they could not be read.
    pub cpus: Option<Vec<usize>>,
    /// The thread's scheduling policy and priority.
    pub scheduling: Scheduling,
    /// The process's locked memory (`VmLck` of `/proc/self/status`) in KiB; `None` when it
    /// could not be read.
    pub locked_kib: Option<u64>,
}

impl Observed {
    /// Whether the process has memory locked.
    pub fn memory_locked(&self) -> bool {
        self.locked_kib.is_some_and(|k| k > 0)
    }
}

impl fmt::Display for Observed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.cpus {
            Some(cpus) => write!(f, "CPUs {}", CpuList(cpus))?,
            None => f.write_str("CPUs unknown")?,
        }
        write!(f, ", {}, ", self.scheduling)?;
        match self.locked_kib {
            Some(0) => f.write_str("memory not locked"),
            Some(kib) => write!(f, "memory locked ({kib} KiB)"),
            None => f.write_str("locked memory unknown"),
        }
    }
}

/// What [`apply`] did: the warnings, and what the thread has now.
#[derive(Debug)]
pub struct Applied {
    /// The settings the kernel did not grant in full (or granted with a limit that will bite).
    pub warnings: Vec<Warning>,
    /// What the thread and the process have after the calls.
    pub got: Observed,
}

/// A CPU list as `taskset -c` and the kernel's cpuset files write it: `0-3,6`.
#[derive(Debug, Clone, Copy)]
pub struct CpuList<'a>(pub &'a [usize]);

impl fmt::Display for CpuList<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut sorted = self.0.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.is_empty() {
            return f.write_str("none");
        }
        let mut first = true;
        let mut i = 0;
        while let Some(&start) = sorted.get(i) {
            let mut end = start;
            while sorted.get(i + 1) == Some(&(end + 1)) {
                end += 1;
                i += 1;
            }
            if !first {
                f.write_str(",")?;
            }
            first = false;
            if end == start {
                write!(f, "{start}")?;
            } else {
                write!(f, "{start}-{end}")?;
            }
            i += 1;
        }
        Ok(())
    }
}

/// Applies `settings` to the calling thread (affinity, scheduling) and its process (locked
/// memory), in that order: memory is locked before the thread may take a CPU from everyone
/// else, since locking faults every page in. Settings left at their defaults are not touched.
/// Never fails: what the kernel refuses is in [`Applied::warnings`].
pub fn apply(settings: &RealtimeSettings) -> Applied {
    let mut warnings = Vec::new();
    if !settings.cpus.is_empty() {
        warnings.extend(set_affinity(&settings.cpus));
    }
    if settings.lock_memory {
        let flags = rustix::mm::MlockAllFlags::CURRENT | rustix::mm::MlockAllFlags::FUTURE;
        match rustix::mm::mlockall(flags) {
            Err(e) => warnings.push(Warning::LockMemory { error: e.into() }),
            Ok(()) => warnings
                .extend(memlock_limit().map(|limit_kib| Warning::LockMemoryLimit { limit_kib })),
        }
    }
    if let Some(priority) = settings.fifo_priority {
        if let Err(error) = set_fifo(priority) {
            warnings.push(Warning::FifoPriority { priority, error });
        }
    }
    Applied {
        warnings,
        got: observe(),
    }
}

/// [`apply`], then a log line of what the partition got (at info when it asked for anything,
/// else at debug) and a warning per [`Warning`], naming its setting.
pub fn apply_and_log(partition: &str, settings: &RealtimeSettings) -> Applied {
    let applied = apply(settings);
    for r in &applied.warnings {
        tracing::warn!(
            setting = r.setting(),
            "{partition}: real-time setting not granted in full, going on: {r}"
        );
    }
    let got = &applied.got;
    if settings.any() {
        tracing::info!(
            cpus = %got.cpus.as_deref().map_or("unknown".to_owned(), |c| CpuList(c).to_string()),
            scheduling = %got.scheduling,
            locked_kib = got.locked_kib,
            "{partition}: real-time settings in force"
        );
    } else {
        tracing::debug!("{partition}: no real-time settings: {got}");
    }
    applied
}

/// Sets the calling thread's affinity to `cpus` (not empty); the warnings.
fn set_affinity(cpus: &[usize]) -> Vec<Warning> {
    if let Some(&cpu) = cpus.iter().find(|&&c| c >= CpuSet::MAX_CPU) {
        return vec![Warning::CpuBeyondMask { cpu }];
    }
    let mut set = CpuSet::new();
    for &cpu in cpus {
        set.set(cpu);
    }
    if let Err(e) = rustix::thread::sched_setaffinity(None, &set) {
        return vec![Warning::Affinity {
            cpus: cpus.to_vec(),
            error: e.into(),
        }];
    }
    // The kernel drops the CPUs that are offline or outside the cpuset, as long as one is
    // left: say which.
    let granted = rustix::thread::sched_getaffinity(None).ok();
    let left_out: Vec<usize> = cpus
        .iter()
        .copied()
        .filter(|&c| granted.as_ref().is_some_and(|g| !g.is_set(c)))
        .collect();
    if left_out.is_empty() {
        Vec::new()
    } else {
        vec![Warning::CpusLeftOut { cpus: left_out }]
    }
}

/// The RLIMIT_MEMLOCK in KiB that locked memory counts against: `None` when there is no limit
/// or the process holds CAP_IPC_LOCK (which lifts it).
fn memlock_limit() -> Option<u64> {
    let limit = rustix::process::getrlimit(rustix::process::Resource::Memlock).current?;
    let privileged = rustix::thread::capabilities(None).is_ok_and(|c| {
        c.effective
            .contains(rustix::thread::CapabilitySet::IPC_LOCK)
    });
    (!privileged).then_some(limit / 1024)
}

/// Puts the calling thread under SCHED_FIFO at `priority`.
fn set_fifo(priority: FifoPriority) -> Result<(), io::Error> {
    let value = ThreadPriorityValue::try_from(priority.get()).map_err(io::Error::other)?;
    thread_priority::set_thread_priority_and_policy(
        thread_priority::thread_native_id(),
        ThreadPriority::Crossplatform(value),
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    )
    .map_err(|e| match e {
        // pthread functions return the error number.
        thread_priority::Error::OS(code) => io::Error::from_raw_os_error(code),
        other => io::Error::other(other.to_string()),
    })
}

/// What the calling thread and its process have now.
pub fn observe() -> Observed {
    let cpus = rustix::thread::sched_getaffinity(None)
        .ok()
        .map(|set| (0..CpuSet::MAX_CPU).filter(|&c| set.is_set(c)).collect());
    Observed {
        cpus,
        scheduling: scheduling(),
        locked_kib: locked_kib(),
    }
}

/// The calling thread's scheduling policy and priority.
fn scheduling() -> Scheduling {
    let (policy, params) =
        match thread_priority::thread_schedule_policy_param(thread_priority::thread_native_id()) {
            Ok(p) => p,
            Err(e) => return Scheduling::Unknown(e.to_string()),
        };
    match policy {
        ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Other) => Scheduling::Other,
        ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Batch) => Scheduling::Batch,
        ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Idle) => Scheduling::Idle,
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo) => {
            Scheduling::Fifo(params.sched_priority)
        }
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::RoundRobin) => {
            Scheduling::RoundRobin(params.sched_priority)
        }
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Deadline) => {
            Scheduling::Deadline
        }
    }
}

/// `VmLck` of `/proc/self/status`, in KiB.
fn locked_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmLck:"))?
        .trim()
        .strip_suffix("kB")?
        .trim()
        .parse()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `f` on a thread of its own, so that what it applies to its thread stays there.
    fn on_own_thread<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
        std::thread::spawn(f).join().unwrap()
    }

    #[test]
    fn nothing_asked_nothing_changed() {
        let (before, applied) = on_own_thread(|| (observe(), apply(&RealtimeSettings::default())));
        assert!(applied.warnings.is_empty(), "{:?}", applied.warnings);
        assert_eq!(applied.got.cpus, before.cpus);
        assert_eq!(applied.got.scheduling, before.scheduling);
    }

    #[test]
    fn a_cpu_the_kernel_refuses_is_a_warning_and_the_affinity_stays() {
        // CPU 1023 fits a mask but exists on no machine this runs on: EINVAL.
        let last = CpuSet::MAX_CPU - 1;
        let (before, applied) = on_own_thread(move || {
            let before = observe();
            let settings = RealtimeSettings {
                cpus: vec![last],
                ..RealtimeSettings::default()
            };
            (before, apply_and_log("test", &settings))
        });
        let [refused] = applied.warnings.as_slice() else {
            panic!("one warning: {:?}", applied.warnings)
        };
        assert!(
            matches!(refused, Warning::Affinity { cpus, error }
                if *cpus == [last] && error.raw_os_error() == Some(rustix::io::Errno::INVAL.raw_os_error())),
            "{refused:?}"
        );
        assert_eq!(refused.setting(), "cpus");
        assert!(refused.to_string().contains("cpus = 1023"), "{refused}");
        assert_eq!(applied.got.cpus, before.cpus, "affinity unchanged");
    }

    #[test]
    fn a_cpu_beyond_any_mask_is_a_warning_not_a_panic() {
        let applied = on_own_thread(|| {
            apply(&RealtimeSettings {
                cpus: vec![0, 5000],
                ..RealtimeSettings::default()
            })
        });
        let [refused] = applied.warnings.as_slice() else {
            panic!("one warning: {:?}", applied.warnings)
        };
        assert!(
            matches!(refused, Warning::CpuBeyondMask { cpu: 5000 }),
            "{refused:?}"
        );
        assert_eq!(refused.setting(), "cpus");
    }

    #[test]
    fn cpus_that_are_not_there_are_named_when_the_others_are_granted() {
        let allowed = observe().cpus.unwrap();
        let first = allowed[0];
        let applied = on_own_thread(move || {
            apply(&RealtimeSettings {
                cpus: vec![first, CpuSet::MAX_CPU - 1],
                ..RealtimeSettings::default()
            })
        });
        assert_eq!(applied.got.cpus, Some(vec![first]));
        let [refused] = applied.warnings.as_slice() else {
            panic!("one warning: {:?}", applied.warnings)
        };
        assert!(
            matches!(refused, Warning::CpusLeftOut { cpus } if *cpus == [CpuSet::MAX_CPU - 1]),
            "{refused:?}"
        );
    }

    #[test]
    fn fifo_is_granted_and_read_back_or_refused_as_a_warning() {
        // Granted as root or with CAP_SYS_NICE or RLIMIT_RTPRIO (on its own thread, which then
        // ends), refused otherwise: either way `apply` returns, and says which.
        let (before, applied) = on_own_thread(|| {
            let before = observe();
            let settings = RealtimeSettings {
                fifo_priority: FifoPriority::new(10),
                ..RealtimeSettings::default()
            };
            (before, apply(&settings))
        });
        match applied.warnings.as_slice() {
            [] => assert_eq!(applied.got.scheduling, Scheduling::Fifo(10)),
            [Warning::FifoPriority { priority, .. }] => {
                assert_eq!(priority.get(), 10);
                assert_eq!(applied.got.scheduling, before.scheduling);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(applied.got.cpus, before.cpus);
    }

    #[test]
    fn a_refused_fifo_priority_and_memory_lock_name_their_settings() {
        let fifo = Warning::FifoPriority {
            priority: FifoPriority::new(50).unwrap(),
            error: io::Error::from_raw_os_error(rustix::io::Errno::PERM.raw_os_error()),
        };
        assert_eq!(fifo.setting(), "fifo_priority");
        assert!(
            fifo.to_string()
                .starts_with("fifo_priority = 50: SCHED_FIFO refused: Operation not permitted"),
            "{fifo}"
        );
        let lock = Warning::LockMemory {
            error: io::Error::from_raw_os_error(rustix::io::Errno::NOMEM.raw_os_error()),
        };
        assert_eq!(lock.setting(), "lock_memory");
        assert!(lock.to_string().contains("mlockall refused"), "{lock}");
        let limit = Warning::LockMemoryLimit { limit_kib: 8192 };
        assert_eq!(limit.setting(), "lock_memory");
        assert!(
            limit.to_string().contains("RLIMIT_MEMLOCK 8192 KiB"),
            "{limit}"
        );
    }

    #[test]
    fn a_memlock_limit_counts_only_without_cap_ipc_lock() {
        // Capabilities are per thread: dropping CAP_IPC_LOCK here leaves the others' alone.
        let (limit, with_cap) = on_own_thread(|| {
            let with_cap = memlock_limit();
            let mut sets = rustix::thread::capabilities(None).unwrap();
            sets.effective
                .remove(rustix::thread::CapabilitySet::IPC_LOCK);
            rustix::thread::set_capabilities(None, sets).unwrap();
            (memlock_limit(), with_cap)
        });
        let soft = rustix::process::getrlimit(rustix::process::Resource::Memlock).current;
        assert_eq!(limit, soft.map(|l| l / 1024));
        let privileged = rustix::thread::capabilities(None)
            .unwrap()
            .effective
            .contains(rustix::thread::CapabilitySet::IPC_LOCK);
        if privileged {
            assert_eq!(with_cap, None);
        } else {
            assert_eq!(with_cap, limit);
        }
    }

    #[test]
    fn cpu_lists_are_written_as_ranges() {
        assert_eq!(CpuList(&[]).to_string(), "none");
        assert_eq!(CpuList(&[1]).to_string(), "1");
        assert_eq!(CpuList(&[3, 0, 1, 2, 6, 8, 9]).to_string(), "0-3,6,8-9");
    }
}
