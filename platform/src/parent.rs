//! Ending with the process that started this one: a partition with its launcher, the launcher
//! and the ground service with a test or a benchmark that asked for it (`--exit-with-parent`),
//! so that none outlives what started it, even after a `kill -9` of that.

use std::time::Duration;

/// How often the parent is looked for.
const WATCH_PERIOD: Duration = Duration::from_millis(100);

/// Sends this process SIGTERM once its parent `parent` is gone (the process is re-parented and
/// its parent ID changes), so it stops through its normal shutdown path: a safe stand-in for
/// PR_SET_PDEATHSIG, which would need unsafe code (and is tied to the thread that started this
/// process, not to the process). A thread of its own looks every 100 ms; the fences of the
/// partitions and of the ground service allow its two calls (getppid, kill of itself).
pub fn watch_parent(parent: rustix::process::Pid) {
    let parent = Some(parent);
    let spawned = std::thread::Builder::new()
        .name("watch-parent".to_owned())
        .spawn(move || {
            loop {
                std::thread::sleep(WATCH_PERIOD);
                if rustix::process::getppid() != parent {
                    tracing::warn!("the parent process is gone: stopping");
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

/// Watches the parent of this process as [`watch_parent`] does, if it has one.
pub fn exit_with_parent() {
    if let Some(parent) = rustix::process::getppid() {
        watch_parent(parent);
    }
}
