//! Ending with the process that started this one: a partition with its launcher, the launcher
//! and the ground service with a test or a benchmark that asked for it (`--exit-with-parent`),
//! so that none outlives what started it, even after a `kill -9` of that.

use std::os::fd::OwnedFd;
use std::time::Duration;

use rustix::event::{PollFd, PollFlags};
use rustix::process::Pid;

/// How often the parent is looked for where the kernel cannot say when it ends (no pidfd).
const WATCH_PERIOD: Duration = Duration::from_millis(100);

/// Sends this process SIGTERM once its parent `parent` is gone (the process is re-parented and
/// its parent ID changes), so it stops through its normal shutdown path: a safe stand-in for
/// PR_SET_PDEATHSIG, which is tied to the thread that started this process, not to the
/// process. A thread of its own sleeps on a pidfd of the parent, which the kernel makes
/// readable when the parent ends, so it costs nothing until then (a kernel before Linux 5.3,
/// without pidfds: it looks every 100 ms instead). The fences of the partitions and of the
/// ground service allow its calls (pidfd_open, poll, getppid, kill of itself).
pub fn watch_parent(parent: Pid) {
    let spawned = std::thread::Builder::new()
        .name("watch-parent".to_owned())
        .spawn(move || {
            let pidfd = rustix::process::pidfd_open(parent, rustix::process::PidfdFlags::empty());
            // Opened after the parent ended, the pidfd is of another process or of none: the
            // parent ID, read after it, tells.
            while rustix::process::getppid() == Some(parent) {
                match &pidfd {
                    Ok(fd) => wait_for_end(fd),
                    Err(_) => std::thread::sleep(WATCH_PERIOD),
                }
            }
            tracing::warn!("the parent process is gone: stopping");
            let _ = rustix::process::kill_process(
                rustix::process::getpid(),
                rustix::process::Signal::TERM,
            );
        });
    if let Err(e) = spawned {
        tracing::warn!(%e, "cannot watch the parent process");
    }
}

/// Sleeps until the process of `pidfd` ends (or a signal or an error returns the wait, after
/// which the caller looks at the parent ID again; an error waits a period first, so that a
/// pidfd that cannot be polled does not spin).
fn wait_for_end(pidfd: &OwnedFd) {
    let mut fds = [PollFd::new(pidfd, PollFlags::IN)];
    match rustix::event::poll(&mut fds, None) {
        Ok(_) | Err(rustix::io::Errno::INTR) => {}
        Err(_) => std::thread::sleep(WATCH_PERIOD),
    }
}

/// Watches the parent of this process as [`watch_parent`] does, if it has one.
pub fn exit_with_parent() {
    if let Some(parent) = rustix::process::getppid() {
        watch_parent(parent);
    }
}
