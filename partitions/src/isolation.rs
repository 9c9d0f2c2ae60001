//! Isolation: each partition fences itself once it has opened its services, sockets and files
//! (docs/design.md "Isolation", docs/deployment.md "Isolation"), so that a fault or a compromise
//! in one partition reaches no more than that partition's inputs and outputs:
//!
//! 1. its user: started as root with `[isolation.<partition>] user = "..."`, it drops to that
//!    user (supplementary groups, group, user) after the real-time settings and the key files,
//!    which need root;
//! 2. no new privileges (`prctl(PR_SET_NO_NEW_PRIVS)`): no set-user-ID program or file
//!    capability can raise it again, and the kernel then lets an unprivileged process install
//!    the filters below;
//! 3. Landlock: the file system is read-only but for its own state (mission data handling's and
//!    voting-monitoring's state directory; the readiness announcements for all), the latency
//!    summaries and what iceoryx2 needs (its shared memory in `/dev/shm` and its root directory,
//!    `/tmp/iceoryx2` by default); nothing may be executed; no TCP port may be bound or connected
//!    (Landlock ABI 4); abstract Unix sockets and signals outside the partition are scoped out
//!    (ABI 6). Best effort: what the kernel does not support is logged as not applied;
//! 4. seccomp: an allow-list of the system calls its loop needs ([`allowed_syscalls`], grouped
//!    with their reasons); only voting-monitoring may create inet sockets; no partition may exec,
//!    fork or trace. A call outside the list kills the process (`SECCOMP_RET_KILL_PROCESS`, the
//!    default: the launcher sees SIGSYS, names the partition and restarts it after its back-off)
//!    or, with `on_violation = "errno"`, fails with EPERM.
//!
//! The fence is applied on the loop's thread while it is the only thread of the process (the
//! threads started later, the doorbell's timer and the watch of the launcher, inherit all of
//! it): Landlock below ABI 8 and the user drop act on the calling thread only.
//!
//! The bridge (`missionlink-bridge`, docs/two-hosts.md) is fenced the same way with a profile of
//! its own ([`Profile::Bridge`]): the same four steps, its user in `[isolation.bridge]`, the
//! iceoryx2 directories, its readiness file and the summaries writable, TCP bind and connect
//! only on the ports of its configured endpoints (Landlock ABI 4), and an allow-list that adds
//! what a Zenoh TCP/TLS client and server on a tokio runtime need. Zenoh starts its runtime's
//! threads when its session opens, and Landlock cannot be put on threads that already run
//! (`LANDLOCK_RESTRICT_SELF_TSYNC` is ABI 8; this code is written for ABI 6 and kernels with
//! ABI 7): so the bridge applies its fence before it opens the session, while it has one
//! thread ([`Fence::apply`] refuses otherwise), and every thread of Zenoh inherits all of it.
//! The seccomp filter is installed with `SECCOMP_FILTER_FLAG_TSYNC` all the same.
//!
//! ```toml
//! [isolation]
//! enabled = true                  # false: no fence at all (say why in the deployment)
//! on_violation = "kill"           # kill | errno
//! [isolation.voting-monitoring]
//! user = "missionlink"            # drop to this user when started as root; default: none
//! # and [isolation.mission-data-handling], [isolation.system-automation],
//! # [isolation.guidance-stub]
//! ```

use std::path::PathBuf;

use missionlink_interfaces::contracts::Partition;
pub use missionlink_platform::fence::{
    Applied, Fence, IsolationError, Profile, TcpPorts, Threads, UserIds, allowed_syscalls, filter,
    install_filter, lookup_user, lookup_user_in, may_write, status_shows_fence, writable_dirs,
};

use crate::config::{Config, PartitionIsolation};

/// Checks what the launcher can check before it starts any partition: every configured user
/// exists.
pub fn check_config(config: &Config) -> Result<(), IsolationError> {
    if !config.isolation.enabled {
        return Ok(());
    }
    let bridge = config
        .bridge
        .enabled
        .then_some(crate::bridge_config::BINARY);
    let bridge = bridge.map(|_| &config.isolation.bridge);
    let partitions = config.isolation.partitions.iter().map(|(_, p)| p);
    for user in partitions.chain(bridge).filter_map(|p| p.user.as_deref()) {
        lookup_user(user)?;
    }
    Ok(())
}

/// iceoryx2's root directory (its services, nodes and event sockets) as its configuration says:
/// `/tmp/iceoryx2` by default.
pub fn iceoryx2_root() -> PathBuf {
    let root = iceoryx2::config::Config::global_config()
        .global
        .root_path()
        .to_string();
    PathBuf::from(root)
}

/// Where iceoryx2 0.10 keeps its shared memory on Linux (POSIX shared memory).
pub const SHARED_MEMORY_DIR: &str = "/dev/shm";

/// The fence of `partition` under `config` (what [`Partition::allowed`] allows it); `None` when
/// isolation is off.
pub fn fence_of(partition: Partition, config: &Config) -> Option<Fence> {
    let allowed = partition.allowed();
    fence(
        partition.binary(),
        Profile::Partition {
            inet: allowed.links,
        },
        &config.isolation.partitions[partition],
        allowed.state,
        TcpPorts::default(),
        config,
    )
}

/// The fence of the bridge (`bridge_config::BINARY`) under `config`; `None` when isolation is
/// off.
pub fn bridge_fence(config: &Config) -> Option<Fence> {
    // The bridge checked its endpoints before it fences itself (exit status 2 otherwise); a
    // port that cannot be read is then not allowed, and Zenoh's bind or connect fails.
    let ports = config.bridge.endpoints().unwrap_or_default();
    fence(
        crate::bridge_config::BINARY,
        Profile::Bridge,
        &config.isolation.bridge,
        false,
        ports,
        config,
    )
}

/// A fence of the process `name` with `profile`, dropping to the user of `settings`, writing
/// the state directory with `state`, binding and connecting TCP on `ports`.
fn fence(
    name: &str,
    profile: Profile,
    settings: &PartitionIsolation,
    state: bool,
    ports: TcpPorts,
    config: &Config,
) -> Option<Fence> {
    if !config.isolation.enabled {
        return None;
    }
    let state_dir = config.ipc.state_dir();
    let mut writable = vec![
        PathBuf::from(SHARED_MEMORY_DIR),
        iceoryx2_root(),
        crate::state::ready_dir(&state_dir),
    ];
    if state {
        writable.push(state_dir);
    }
    if let Some(dir) = &config.latency.summary_dir {
        writable.push(dir.clone());
    }
    Some(Fence::new(
        name,
        profile,
        settings.user.clone(),
        config.isolation.on_violation,
        writable,
        ports,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Violation;
    use std::path::Path;

    #[test]
    fn the_section_is_on_by_default_and_per_partition() {
        let defaults = Config::default();
        assert!(defaults.isolation.enabled);
        assert_eq!(defaults.isolation.on_violation, Violation::Kill);
        let c = Config::parse(
            "[isolation]\non_violation = \"errno\"\n[isolation.guidance-stub]\nuser = \"nobody\"\n",
            Path::new("f"),
        )
        .unwrap();
        assert_eq!(c.isolation.on_violation, Violation::Errno);
        assert_eq!(
            c.isolation.partitions[Partition::Guidance].user.as_deref(),
            Some("nobody")
        );
        assert_eq!(
            c.isolation.partitions[Partition::VotingMonitoring].user,
            None
        );
        assert_eq!(
            Config::parse(&c.to_toml().unwrap(), Path::new("y")).unwrap(),
            c
        );
        assert!(Config::parse("[isolation.gcs]\nuser = \"x\"\n", Path::new("f")).is_err());
    }

    #[test]
    fn only_voting_monitoring_may_create_inet_sockets_and_no_partition_may_exec() {
        let vm = allowed_syscalls(Profile::Partition { inet: true });
        let other = allowed_syscalls(Profile::Partition { inet: false });
        assert_eq!(vm.get(&libc::SYS_socket).unwrap().len(), 3);
        assert_eq!(other.get(&libc::SYS_socket).unwrap().len(), 1);
        for forbidden in [
            libc::SYS_execve,
            libc::SYS_execveat,
            libc::SYS_ptrace,
            libc::SYS_setuid,
            libc::SYS_socketpair,
            libc::SYS_mount,
            libc::SYS_bpf,
        ] {
            assert!(!vm.contains_key(&forbidden) && !other.contains_key(&forbidden));
        }
        #[cfg(target_arch = "x86_64")]
        for forbidden in [libc::SYS_fork, libc::SYS_vfork] {
            assert!(!vm.contains_key(&forbidden));
        }
        assert_eq!(
            filter(Profile::Partition { inet: true }, Violation::Kill)
                .unwrap()
                .len(),
            2
        );
        assert_eq!(
            filter(Profile::Partition { inet: false }, Violation::Errno)
                .unwrap()
                .len(),
            2
        );
    }

    #[test]
    fn the_bridge_may_listen_and_accept_but_never_exec_and_no_partition_may_listen() {
        let bridge = allowed_syscalls(Profile::Bridge);
        let vm = allowed_syscalls(Profile::Partition { inet: true });
        for call in [libc::SYS_listen, libc::SYS_accept4] {
            assert!(bridge.contains_key(&call) && !vm.contains_key(&call));
        }
        for forbidden in [
            libc::SYS_execve,
            libc::SYS_execveat,
            libc::SYS_ptrace,
            libc::SYS_setuid,
            libc::SYS_mount,
            libc::SYS_bpf,
            libc::SYS_seccomp,
        ] {
            assert!(!bridge.contains_key(&forbidden), "{forbidden}");
        }
        // Threads only, as a partition.
        assert_eq!(bridge.get(&libc::SYS_clone), vm.get(&libc::SYS_clone));
        // A netlink socket is on the list only to fail with EPERM in a filter of its own.
        assert_eq!(bridge.get(&libc::SYS_socket).unwrap().len(), 4);
        assert_eq!(filter(Profile::Bridge, Violation::Kill).unwrap().len(), 3);
    }

    #[test]
    fn the_writable_directories_are_the_partitions_own() {
        let mut config = Config::default();
        config.ipc.state_dir = Some(PathBuf::from("/var/lib/missionlink"));
        let mdh = fence_of(Partition::MissionDataHandling, &config).unwrap();
        let sa = fence_of(Partition::SystemAutomation, &config).unwrap();
        let lists = Path::new("/var/lib/missionlink/active-lists.frames");
        assert!(may_write(&mdh, lists));
        assert!(!may_write(&sa, lists), "{:?}", writable_dirs(&sa));
        assert!(may_write(
            &sa,
            Path::new("/var/lib/missionlink/ready/system-automation")
        ));
        assert!(may_write(&sa, Path::new("/dev/shm/iox2_x")));
        config.isolation.enabled = false;
        assert!(fence_of(Partition::SystemAutomation, &config).is_none());
    }

    #[test]
    fn the_bridge_is_fenced_as_a_partition_with_its_endpoints_ports() {
        let mut config = Config::default();
        config.ipc.state_dir = Some(PathBuf::from("/var/lib/missionlink"));
        config.bridge.enabled = true;
        config.bridge.credentials = Some(PathBuf::from("/etc/missionlink/bridge"));
        config.bridge.listen = vec!["tls/169.254.77.1:7447".to_owned()];
        config.bridge.connect = vec!["tls/169.254.77.2:7448".to_owned()];
        let bridge = bridge_fence(&config).unwrap();
        assert_eq!(bridge.profile(), Profile::Bridge);
        assert_eq!(
            (
                bridge.ports().listen.as_slice(),
                bridge.ports().connect.as_slice()
            ),
            ([7447].as_slice(), [7448].as_slice())
        );
        // Its readiness and iceoryx2's shared memory, not mission data handling's lists.
        assert!(may_write(
            &bridge,
            Path::new("/var/lib/missionlink/ready/bridge")
        ));
        assert!(may_write(&bridge, Path::new("/dev/shm/iox2_x")));
        assert!(!may_write(
            &bridge,
            Path::new("/var/lib/missionlink/active-lists.frames")
        ));
        assert!(!may_write(
            &bridge,
            Path::new("/etc/missionlink/bridge/ca.pem")
        ));
        // A partition binds and connects no TCP port.
        let vm = fence_of(Partition::VotingMonitoring, &config).unwrap();
        assert_eq!(vm.ports(), &TcpPorts::default());
        assert_eq!(vm.profile(), Profile::Partition { inet: true });
        // `[isolation.bridge] user`, and the launcher checks that user when the bridge is on.
        let c = Config::parse(
            "[bridge]\nenabled = true\n[isolation.bridge]\nuser = \"no-such-user-here\"\n",
            Path::new("f"),
        )
        .unwrap();
        assert_eq!(
            c.isolation.bridge.user.as_deref(),
            Some("no-such-user-here")
        );
        assert!(matches!(
            check_config(&c),
            Err(IsolationError::NoSuchUser(_))
        ));
        config.isolation.enabled = false;
        assert!(bridge_fence(&config).is_none());
    }
}
