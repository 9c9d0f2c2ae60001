//! The fence a process puts around itself once it has opened what it needs (docs/design.md
//! "Isolation", docs/deployment.md "Isolation"), for every program of missionlink that takes
//! input from outside: the FCC's partitions and its bridge (`missionlink_partitions::isolation`
//! builds theirs from the configuration) and the ground service (`gcs serve`). A fault or a
//! compromise then reaches no more than the process's own inputs and outputs:
//!
//! 1. its user: started as root with a user configured, it drops to that user;
//! 2. no new privileges (`prctl(PR_SET_NO_NEW_PRIVS)`);
//! 3. Landlock: the file system read-only but for the directories it may write, nothing
//!    executed, no TCP port bound or connected but those given (ABI 4), abstract Unix sockets
//!    and signals outside the process scoped out (ABI 6); best effort, what the kernel does not
//!    support is logged as not applied;
//! 4. seccomp: an allow-list of the system calls its [`Profile`] needs ([`allowed_syscalls`],
//!    grouped with their reasons); no exec, no fork, no trace. A call outside the list kills the
//!    process ([`Violation::Kill`], the default) or fails with EPERM.
//!
//! The fence is applied while the process has one thread (Landlock below ABI 8 and the user
//! drop act on the calling thread; the threads started later inherit all of it).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use landlock::{
    ABI, Access, AccessFs, AccessNet, CompatLevel, Compatible, NetPort, PathBeneath, PathFd,
    Ruleset, RulesetAttr, RulesetCreatedAttr, RulesetStatus, Scope,
};
use seccompiler::{
    BpfProgram, SeccompAction, SeccompCmpArgLen, SeccompCmpOp, SeccompCondition, SeccompFilter,
    SeccompRule, TargetArch,
};
use serde::{Deserialize, Serialize};

/// What the kernel does with a system call outside a fence's allow-list (the FCC's `[isolation]
/// on_violation`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Violation {
    /// Kill the process (`SECCOMP_RET_KILL_PROCESS`): the launcher sees SIGSYS, reports the
    /// partition by name and restarts it under its back-off and start limit. A process that
    /// tries what it must never do is not trusted to go on.
    #[default]
    Kill,
    /// Fail the call with EPERM: the process goes on and handles the error (for finding a
    /// missing system call in a rig without losing the process).
    Errno,
}

/// The TCP ports a fence lets its process bind and connect to (Landlock ABI 4): the bridge's
/// endpoints; none for every other process.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TcpPorts {
    /// The ports it may listen on.
    pub listen: Vec<u16>,
    /// The ports it may connect to.
    pub connect: Vec<u16>,
}

/// Why a process could not fence itself as asked.
#[derive(Debug, thiserror::Error)]
pub enum IsolationError {
    /// `user` names no user of `/etc/passwd`.
    #[error("[isolation] user {0:?}: no such user")]
    NoSuchUser(String),
    /// A user is configured but the process is neither root nor that user.
    #[error("[isolation] user {user:?}: started neither as root nor as that user")]
    NotRoot {
        /// The configured user.
        user: String,
    },
    /// The process has other threads, which a per-thread fence would leave out.
    #[error("{0} threads run: the fence needs the only one")]
    Threads(usize),
    /// setgroups/setgid/setuid failed.
    #[error("dropping to the configured user: {0}")]
    DropUser(std::io::Error),
    /// prctl(PR_SET_NO_NEW_PRIVS) failed.
    #[error("no_new_privs: {0}")]
    NoNewPrivs(std::io::Error),
    /// The Landlock ruleset could not be built or applied.
    #[error("Landlock: {0}")]
    Landlock(String),
    /// The seccomp filter could not be built or installed.
    #[error("seccomp: {0}")]
    Seccomp(String),
}

/// A user to drop to: its user and group IDs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UserIds {
    /// User ID.
    pub uid: u32,
    /// Primary group ID (the only group kept).
    pub gid: u32,
}

/// Looks `user` up in `passwd` (the text of `/etc/passwd`): a name, or a number (then its
/// group is the passwd entry's, else the same number).
pub fn lookup_user_in(passwd: &str, user: &str) -> Option<UserIds> {
    let entries = passwd.lines().filter_map(|line| {
        let mut f = line.split(':');
        let name = f.next()?;
        let _password = f.next()?;
        let uid = f.next()?.parse().ok()?;
        let gid = f.next()?.parse().ok()?;
        Some((name, UserIds { uid, gid }))
    });
    let number: Option<u32> = user.parse().ok();
    let mut found = None;
    for (name, ids) in entries {
        if name == user || number == Some(ids.uid) {
            found = Some(ids);
            break;
        }
    }
    found.or_else(|| number.map(|n| UserIds { uid: n, gid: n }))
}

/// Looks `user` up in `/etc/passwd`.
pub fn lookup_user(user: &str) -> Result<UserIds, IsolationError> {
    let passwd = std::fs::read_to_string("/etc/passwd").unwrap_or_default();
    lookup_user_in(&passwd, user).ok_or_else(|| IsolationError::NoSuchUser(user.to_owned()))
}

/// Which allow-list a fence installs ([`allowed_syscalls`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Profile {
    /// A partition's loop; `inet`: it may create inet sockets (voting-monitoring's UDP links).
    Partition {
        /// Inet sockets allowed.
        inet: bool,
    },
    /// The bridge: a partition's calls with inet sockets, and what Zenoh's TCP and TLS links on
    /// a tokio runtime add (listening, accepting, the runtime's wake-up eventfd).
    Bridge,
    /// The ground service (`gcs serve`): a partition's calls with inet sockets (the vehicles'
    /// UDP links, the MAVLink side), and listening on and accepting from its Unix socket.
    GroundService,
}

impl Profile {
    /// The allow-list's name in the log line of [`Fence::apply`].
    fn describe(self) -> &'static str {
        match self {
            Self::Partition { inet: true } => "inet sockets allowed",
            Self::Partition { inet: false } => "Unix sockets only",
            Self::Bridge => "the bridge's: Zenoh over TCP and TLS",
            Self::GroundService => "the ground service's: UDP links and its Unix socket",
        }
    }
}

/// The fence of one process, built before it opens anything ([`Fence::new`]) and applied once
/// by [`Fence::apply`].
#[derive(Debug, Clone)]
pub struct Fence {
    name: String,
    profile: Profile,
    user: Option<String>,
    on_violation: Violation,
    /// Directories the partition may write beneath.
    writable: Vec<PathBuf>,
    /// The TCP ports it may bind and connect to (Landlock ABI 4); none for a partition.
    ports: TcpPorts,
}

/// What the fence applied, for the one log line at start.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Applied {
    /// The user dropped to, if any.
    pub user: Option<String>,
    /// no_new_privs is set.
    pub no_new_privs: bool,
    /// How far Landlock was enforced ("full", "partial (...)", "not enforced (...)").
    pub landlock: String,
    /// The seccomp filter is installed.
    pub seccomp: bool,
}

impl Fence {
    /// The fence of the process `name` with `profile`: dropping to `user` (when started as
    /// root), writing beneath `writable` alone, binding and connecting TCP on `ports` alone, a
    /// call outside the allow-list answered by `on_violation`.
    pub fn new(
        name: &str,
        profile: Profile,
        user: Option<String>,
        on_violation: Violation,
        writable: Vec<PathBuf>,
        ports: TcpPorts,
    ) -> Self {
        Self {
            name: name.to_owned(),
            profile,
            user,
            on_violation,
            writable,
            ports,
        }
    }

    /// Its allow-list.
    pub fn profile(&self) -> Profile {
        self.profile
    }

    /// The TCP ports it allows.
    pub fn ports(&self) -> &TcpPorts {
        &self.ports
    }

    /// Applies the fence to this process (which must have one thread) and logs once what was
    /// applied and what was not, with why. An error leaves the process as fenced as it got: the
    /// caller ends it.
    pub fn apply(&self) -> Result<Applied, IsolationError> {
        let threads = thread_count();
        if threads > 1 {
            return Err(IsolationError::Threads(threads));
        }
        let mut applied = Applied::default();
        // Root needed: look the user up and create the directories before dropping.
        let drop_to = match &self.user {
            Some(user) => Some((user.clone(), lookup_user(user)?)),
            None => None,
        };
        for dir in &self.writable {
            if let Err(e) = std::fs::create_dir_all(dir) {
                tracing::warn!(dir = %dir.display(), %e, "cannot create a writable directory");
            }
        }
        let ruleset = self.landlock_ruleset();
        if let Some((user, ids)) = drop_to {
            drop_user(&user, ids)?;
            applied.user = Some(user);
        }
        rustix::thread::set_no_new_privs(true).map_err(|e| IsolationError::NoNewPrivs(e.into()))?;
        applied.no_new_privs = true;
        applied.landlock = match ruleset {
            Ok(created) => match created.restrict_self() {
                Ok(status) => match status.ruleset {
                    RulesetStatus::FullyEnforced => "full".to_owned(),
                    RulesetStatus::PartiallyEnforced => format!(
                        "partial (the kernel's Landlock lacks some rights: {:?})",
                        status.landlock
                    ),
                    RulesetStatus::NotEnforced => {
                        format!("not enforced (the kernel: {:?})", status.landlock)
                    }
                },
                Err(e) => return Err(IsolationError::Landlock(e.to_string())),
            },
            // A path that cannot be opened, a ruleset the kernel refuses: not applied, said.
            Err(e) => format!("not applied ({e})"),
        };
        install_filter(self.profile, self.on_violation, Threads::All)?;
        applied.seccomp = true;
        tracing::info!(
            partition = %self.name,
            user = applied.user.as_deref().unwrap_or("(unchanged)"),
            no_new_privs = applied.no_new_privs,
            landlock = %applied.landlock,
            tcp = %format_args!(
                "bind {:?}, connect {:?}",
                self.ports.listen, self.ports.connect
            ),
            seccomp = %format_args!(
                "allow-list ({}), violation: {:?}",
                self.profile.describe(),
                self.on_violation
            ),
            "isolation applied"
        );
        Ok(applied)
    }

    fn landlock_ruleset(&self) -> Result<landlock::RulesetCreated, String> {
        // The newest ABI this code was written and tested for; best effort below it.
        let abi = ABI::V6;
        let read = AccessFs::ReadFile | AccessFs::ReadDir;
        let mut ruleset = Ruleset::default()
            .set_compatibility(CompatLevel::BestEffort)
            .handle_access(AccessFs::from_all(abi))
            .map_err(|e| e.to_string())?
            .handle_access(AccessNet::from_all(abi))
            .map_err(|e| e.to_string())?
            .scope(Scope::from_all(abi))
            .map_err(|e| e.to_string())?
            .create()
            .map_err(|e| e.to_string())?
            .add_rule(PathBeneath::new(
                PathFd::new("/").map_err(|e| e.to_string())?,
                read,
            ))
            .map_err(|e| e.to_string())?;
        // Everything but executing beneath the writable directories.
        let write = AccessFs::from_all(abi) & !AccessFs::Execute;
        for dir in &self.writable {
            match PathFd::new(dir) {
                Ok(fd) => {
                    ruleset = ruleset
                        .add_rule(PathBeneath::new(fd, write))
                        .map_err(|e| e.to_string())?;
                }
                Err(e) => tracing::warn!(dir = %dir.display(), %e, "not writable: cannot open it"),
            }
        }
        // TCP: only the bridge's endpoints; a partition binds and connects no TCP port at all.
        for (ports, access) in [
            (&self.ports.listen, AccessNet::BindTcp),
            (&self.ports.connect, AccessNet::ConnectTcp),
        ] {
            for port in ports {
                ruleset = ruleset
                    .add_rule(NetPort::new(*port, access))
                    .map_err(|e| e.to_string())?;
            }
        }
        Ok(ruleset)
    }
}

/// The number of threads of this process (`/proc/self/task`); 1 when it cannot be read.
fn thread_count() -> usize {
    std::fs::read_dir("/proc/self/task").map_or(1, |d| d.count())
}

fn drop_user(user: &str, ids: UserIds) -> Result<(), IsolationError> {
    use rustix::process::{Gid, Uid, geteuid};
    let current = geteuid().as_raw();
    if current == ids.uid {
        return Ok(());
    }
    if !geteuid().is_root() {
        return Err(IsolationError::NotRoot {
            user: user.to_owned(),
        });
    }
    // The process has one thread (checked by the caller), so the thread's credentials are the
    // process's.
    let gid = Gid::from_raw(ids.gid);
    let uid = Uid::from_raw(ids.uid);
    rustix::thread::set_thread_groups(&[gid]).map_err(|e| IsolationError::DropUser(e.into()))?;
    rustix::thread::set_thread_res_gid(gid, gid, gid)
        .map_err(|e| IsolationError::DropUser(e.into()))?;
    rustix::thread::set_thread_res_uid(uid, uid, uid)
        .map_err(|e| IsolationError::DropUser(e.into()))?;
    Ok(())
}

/// A system call allowed under a condition on its arguments (all must hold).
type Conditions = Vec<(u8, SeccompCmpOp, u64)>;

/// The system calls of `profile`, each with the conditions on its arguments (empty: any
/// arguments), grouped by why. A partition's were found by running every partition under
/// `strace -ff` through the demo, kill -9 and restarts of peers, and reading what iceoryx2 0.10
/// does then; the bridge's by running two bridges under `strace -ff` through a connection,
/// refused strangers and shutdown, and held by tests/system/two_hosts.rs (the flights, a cut of the
/// link and its return, under `on_violation = "kill"`); docs/deployment.md "Isolation" lists
/// the groups.
pub fn allowed_syscalls(profile: Profile) -> BTreeMap<i64, Vec<Conditions>> {
    let inet = match profile {
        Profile::Partition { inet } => inet,
        Profile::Bridge | Profile::GroundService => true,
    };
    let mut allowed: BTreeMap<i64, Vec<Conditions>> = BTreeMap::new();
    let mut any = |calls: &[libc::c_long]| {
        for call in calls {
            allowed.insert(*call, Vec::new());
        }
    };
    // Memory: the allocator, thread stacks.
    any(&[
        libc::SYS_brk,
        libc::SYS_mmap,
        libc::SYS_munmap,
        libc::SYS_mremap,
        libc::SYS_mprotect,
        libc::SYS_madvise,
    ]);
    // Files: iceoryx2's shared memory (/dev/shm), its root directory (services, nodes, locks,
    // event sockets; created, locked, listed and removed again when a peer restarts or a dead
    // node is cleaned up), the state directory, the latency summaries, /proc/self reads.
    // Landlock decides where.
    any(&[
        libc::SYS_openat,
        libc::SYS_close,
        libc::SYS_read,
        libc::SYS_pread64,
        libc::SYS_write,
        libc::SYS_pwrite64,
        libc::SYS_readv,
        libc::SYS_writev,
        libc::SYS_lseek,
        libc::SYS_newfstatat,
        libc::SYS_fstat,
        libc::SYS_statx,
        libc::SYS_faccessat,
        libc::SYS_faccessat2,
        libc::SYS_getdents64,
        libc::SYS_readlinkat,
        libc::SYS_fcntl,
        libc::SYS_flock,
        libc::SYS_fsync,
        libc::SYS_fdatasync,
        libc::SYS_ftruncate,
        libc::SYS_fallocate,
        libc::SYS_fchmod,
        libc::SYS_umask,
        libc::SYS_unlinkat,
        libc::SYS_mkdirat,
        libc::SYS_renameat,
        libc::SYS_renameat2,
        libc::SYS_fstatfs,
        libc::SYS_statfs,
        libc::SYS_getcwd,
        libc::SYS_dup,
        libc::SYS_dup3,
    ]);
    #[cfg(target_arch = "x86_64")]
    any(&[
        libc::SYS_access,
        libc::SYS_stat,
        libc::SYS_lstat,
        libc::SYS_readlink,
        libc::SYS_unlink,
        libc::SYS_mkdir,
        libc::SYS_rmdir,
        libc::SYS_rename,
        libc::SYS_poll,
        libc::SYS_epoll_wait,
        libc::SYS_dup2,
    ]);
    // Waiting: the WaitSet (epoll), timers, the doorbell's semaphore (futex) and timerfd (armed
    // by the loop, read by the doorbell's timer thread), the spin's yield.
    any(&[
        libc::SYS_timerfd_settime,
        libc::SYS_epoll_create1,
        libc::SYS_epoll_ctl,
        libc::SYS_epoll_pwait,
        libc::SYS_epoll_pwait2,
        libc::SYS_ppoll,
        libc::SYS_futex,
        libc::SYS_sched_yield,
        libc::SYS_nanosleep,
        libc::SYS_clock_nanosleep,
        libc::SYS_clock_gettime,
        libc::SYS_clock_getres,
        libc::SYS_gettimeofday,
    ]);
    // Sockets: iceoryx2's events are Unix datagram sockets in its root directory; only
    // voting-monitoring's UDP links are inet. Creating one is what the domain condition checks;
    // the calls on a socket need no condition (no other partition holds an inet socket).
    let mut domains: Vec<Conditions> = vec![vec![(0, SeccompCmpOp::Eq, libc::AF_UNIX as u64)]];
    if inet {
        domains.push(vec![(0, SeccompCmpOp::Eq, libc::AF_INET as u64)]);
        domains.push(vec![(0, SeccompCmpOp::Eq, libc::AF_INET6 as u64)]);
    }
    allowed.insert(libc::SYS_socket, domains);
    let mut any = |calls: &[libc::c_long]| {
        for call in calls {
            allowed.insert(*call, Vec::new());
        }
    };
    any(&[
        libc::SYS_bind,
        libc::SYS_connect,
        libc::SYS_sendto,
        libc::SYS_recvfrom,
        libc::SYS_sendmsg,
        libc::SYS_recvmsg,
        libc::SYS_sendmmsg,
        libc::SYS_recvmmsg,
        libc::SYS_getsockname,
        libc::SYS_getpeername,
        libc::SYS_setsockopt,
        libc::SYS_getsockopt,
        libc::SYS_shutdown,
        libc::SYS_ioctl,
    ]);
    // Signals and the process: SIGTERM/SIGINT/SIGUSR1 handlers, the watch of the launcher
    // (a pidfd of it to sleep on, getppid, and SIGTERM to itself), abort on a fatal error,
    // identity queries.
    any(&[
        libc::SYS_rt_sigaction,
        libc::SYS_rt_sigprocmask,
        libc::SYS_rt_sigreturn,
        libc::SYS_sigaltstack,
        libc::SYS_restart_syscall,
        libc::SYS_getpid,
        libc::SYS_gettid,
        libc::SYS_getppid,
        libc::SYS_pidfd_open,
        libc::SYS_getuid,
        libc::SYS_geteuid,
        libc::SYS_getgid,
        libc::SYS_getegid,
        libc::SYS_getrandom,
        libc::SYS_sched_getaffinity,
        libc::SYS_sched_getscheduler,
        libc::SYS_sched_getparam,
        libc::SYS_prlimit64,
        libc::SYS_uname,
        libc::SYS_exit,
        libc::SYS_exit_group,
        libc::SYS_set_robust_list,
        libc::SYS_rseq,
    ]);
    let own = rustix::process::getpid().as_raw_nonzero().get() as u64;
    // Signals to itself only (the watch's SIGTERM, abort's SIGABRT).
    allowed.insert(libc::SYS_kill, vec![vec![(0, SeccompCmpOp::Eq, own)]]);
    allowed.insert(libc::SYS_tgkill, vec![vec![(0, SeccompCmpOp::Eq, own)]]);
    // Threads (the doorbell's timer, the watch of the launcher) but never a new process: clone
    // only with CLONE_THREAD; clone3 passes its flags in memory a filter cannot read, so it
    // fails with ENOSYS (the second filter) and the C library falls back to clone.
    let thread = libc::CLONE_THREAD as u64;
    allowed.insert(
        libc::SYS_clone,
        vec![vec![(0, SeccompCmpOp::MaskedEq(thread), thread)]],
    );
    allowed.insert(libc::SYS_clone3, Vec::new());
    // Naming a new thread (PR_SET_NAME) and nothing else of prctl.
    allowed.insert(
        libc::SYS_prctl,
        vec![vec![(0, SeccompCmpOp::Eq, libc::PR_SET_NAME as u64)]],
    );
    if profile == Profile::GroundService {
        // Its clients: the Unix socket listens and accepts.
        allowed.insert(libc::SYS_listen, Vec::new());
        allowed.insert(libc::SYS_accept4, Vec::new());
    }
    if profile == Profile::Bridge {
        let mut any = |calls: &[libc::c_long]| {
            for call in calls {
                allowed.insert(*call, Vec::new());
            }
        };
        // Zenoh's links: the listening endpoint's TCP socket listens and accepts (TLS on top
        // is computation in the process); the runtime's reactor is woken through an eventfd.
        any(&[libc::SYS_listen, libc::SYS_accept4, libc::SYS_eventfd2]);
        // Zenoh asks for the host's interfaces (getifaddrs: a NETLINK_ROUTE socket) to name a
        // link's interface in its link information. Allowed here only to be answered EPERM by
        // the filter before this one ([`filter`]): Zenoh goes on without the names, and the
        // bridge never reads or changes the host's routes.
        if let Some(domains) = allowed.get_mut(&libc::SYS_socket) {
            domains.push(vec![(0, SeccompCmpOp::Eq, libc::AF_NETLINK as u64)]);
        }
    }
    allowed
}

/// The BPF programs of a fence of `profile`, in the order they are installed: the one that
/// makes clone3 fail with ENOSYS, for the bridge the one that makes a netlink socket fail with
/// EPERM, and the allow-list ([`allowed_syscalls`]). The kernel runs them all and takes the
/// strictest answer.
pub fn filter(
    profile: Profile,
    on_violation: Violation,
) -> Result<Vec<BpfProgram>, IsolationError> {
    let arch = TargetArch::try_from(std::env::consts::ARCH)
        .map_err(|e| IsolationError::Seccomp(e.to_string()))?;
    let err = |e: seccompiler::BackendError| IsolationError::Seccomp(e.to_string());
    let mut rules: BTreeMap<i64, Vec<SeccompRule>> = BTreeMap::new();
    for (call, alternatives) in allowed_syscalls(profile) {
        let mut chain = Vec::new();
        for conditions in alternatives {
            let conditions = conditions
                .into_iter()
                .map(|(arg, op, value)| {
                    SeccompCondition::new(arg, SeccompCmpArgLen::Qword, op, value)
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(err)?;
            chain.push(SeccompRule::new(conditions).map_err(err)?);
        }
        rules.insert(call, chain);
    }
    let violation = match on_violation {
        Violation::Kill => SeccompAction::KillProcess,
        Violation::Errno => SeccompAction::Errno(libc::EPERM as u32),
    };
    let allow_list: BpfProgram = SeccompFilter::new(rules, violation, SeccompAction::Allow, arch)
        .map_err(err)?
        .try_into()
        .map_err(|e: seccompiler::BackendError| err(e))?;
    let clone3: BpfProgram = SeccompFilter::new(
        BTreeMap::from([(libc::SYS_clone3, Vec::new())]),
        SeccompAction::Allow,
        SeccompAction::Errno(libc::ENOSYS as u32),
        arch,
    )
    .map_err(err)?
    .try_into()
    .map_err(|e: seccompiler::BackendError| err(e))?;
    let mut programs = vec![clone3];
    if profile == Profile::Bridge {
        // The bridge's netlink socket fails with EPERM (see [`allowed_syscalls`]).
        let netlink: BpfProgram = SeccompFilter::new(
            BTreeMap::from([(
                libc::SYS_socket,
                vec![
                    SeccompRule::new(vec![
                        SeccompCondition::new(
                            0,
                            SeccompCmpArgLen::Qword,
                            SeccompCmpOp::Eq,
                            libc::AF_NETLINK as u64,
                        )
                        .map_err(err)?,
                    ])
                    .map_err(err)?,
                ],
            )]),
            SeccompAction::Allow,
            SeccompAction::Errno(libc::EPERM as u32),
            arch,
        )
        .map_err(err)?
        .try_into()
        .map_err(|e: seccompiler::BackendError| err(e))?;
        programs.push(netlink);
    }
    // The allow-list last: installing a filter calls prctl and seccomp, which it forbids.
    programs.push(allow_list);
    Ok(programs)
}

/// Which threads a filter is installed on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Threads {
    /// Every thread of the process (`SECCOMP_FILTER_FLAG_TSYNC`): a partition.
    All,
    /// The calling thread only: the benchmark that runs the same calls with and without the
    /// filter in one process (benches/isolation.rs).
    This,
}

/// Installs the seccomp filter of `profile` on `threads`; sets no_new_privs on the calling
/// thread first (the kernel requires it of an unprivileged process).
pub fn install_filter(
    profile: Profile,
    on_violation: Violation,
    threads: Threads,
) -> Result<(), IsolationError> {
    rustix::thread::set_no_new_privs(true).map_err(|e| IsolationError::NoNewPrivs(e.into()))?;
    for program in &filter(profile, on_violation)? {
        match threads {
            Threads::All => seccompiler::apply_filter_all_threads(program),
            Threads::This => seccompiler::apply_filter(program),
        }
        .map_err(|e| IsolationError::Seccomp(e.to_string()))?;
    }
    Ok(())
}

/// Whether `/proc/<pid>/status` (its text) shows no_new_privs and a seccomp filter.
pub fn status_shows_fence(status: &str) -> bool {
    let field = |name: &str| {
        status
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .map(str::trim)
    };
    field("NoNewPrivs:") == Some("1") && field("Seccomp:") == Some("2")
}

/// The directories `fence` may write beneath.
pub fn writable_dirs(fence: &Fence) -> &[PathBuf] {
    &fence.writable
}

/// Whether `path` lies beneath a writable directory of `fence`.
pub fn may_write(fence: &Fence, path: &Path) -> bool {
    fence.writable.iter().any(|d| path.starts_with(d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn users_are_found_by_name_or_number() {
        let passwd =
            "root:x:0:0:root:/root:/bin/bash\nmissionlink:x:990:985::/:/usr/sbin/nologin\n";
        assert_eq!(
            lookup_user_in(passwd, "missionlink"),
            Some(UserIds { uid: 990, gid: 985 })
        );
        assert_eq!(
            lookup_user_in(passwd, "990"),
            Some(UserIds { uid: 990, gid: 985 })
        );
        assert_eq!(
            lookup_user_in(passwd, "4242"),
            Some(UserIds {
                uid: 4242,
                gid: 4242
            })
        );
        assert_eq!(lookup_user_in(passwd, "nobody-here"), None);
    }

    #[test]
    fn the_ground_service_may_listen_and_accept_and_use_udp_but_never_exec_or_fork() {
        let service = allowed_syscalls(Profile::GroundService);
        for call in [libc::SYS_listen, libc::SYS_accept4] {
            assert!(service.contains_key(&call));
        }
        assert_eq!(service.get(&libc::SYS_socket).unwrap().len(), 3);
        for forbidden in [
            libc::SYS_execve,
            libc::SYS_execveat,
            libc::SYS_ptrace,
            libc::SYS_setuid,
            libc::SYS_mount,
            libc::SYS_bpf,
            libc::SYS_seccomp,
        ] {
            assert!(!service.contains_key(&forbidden), "{forbidden}");
        }
        let vm = allowed_syscalls(Profile::Partition { inet: true });
        assert_eq!(service.get(&libc::SYS_clone), vm.get(&libc::SYS_clone));
        assert_eq!(
            filter(Profile::GroundService, Violation::Kill)
                .unwrap()
                .len(),
            2
        );
    }

    #[test]
    fn a_status_shows_the_fence() {
        assert!(status_shows_fence(
            "Name:\tx\nNoNewPrivs:\t1\nSeccomp:\t2\n"
        ));
        assert!(!status_shows_fence("NoNewPrivs:\t0\nSeccomp:\t0\n"));
    }
}
