//! Every partition process announces here when it is up (its ports open, waiting for data), and
//! the launcher once all its partitions are ([`announce_ready`], `ready/<binary>`): the demo and
//! the tests wait for that instead of sleeping.

use std::io;
use std::path::{Path, PathBuf};
use std::time::Duration;

use super::{wait_for, write_atomically};

const READY: &str = "ready";

/// The directory of the readiness announcements under the state directory `dir`.
pub fn ready_dir(dir: &Path) -> PathBuf {
    dir.join(READY)
}

fn ready_path(dir: &Path, binary: &str) -> PathBuf {
    dir.join(READY).join(binary)
}

/// Announces in `dir` that `binary` is up: a partition once its ports are open and it waits
/// for data, the launcher once every partition it started is. The file holds the process ID.
pub fn announce_ready(dir: &Path, binary: &str) -> io::Result<()> {
    write_atomically(
        &ready_path(dir, binary),
        std::process::id().to_string().as_bytes(),
    )
}

/// Removes `binary`'s announcement in `dir` (it stopped, died or is about to start again).
pub fn forget_ready(dir: &Path, binary: &str) -> io::Result<()> {
    match std::fs::remove_file(ready_path(dir, binary)) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// Removes `binary`'s announcement in `dir` if process `pid` made it: a process that ends
/// withdraws its own announcement, never the one of a newer instance started meanwhile in the
/// same directory (a launcher restarted at once after `kill -9`, while the old partitions are
/// still on their way out).
pub fn withdraw_ready(dir: &Path, binary: &str, pid: u32) -> io::Result<()> {
    let path = ready_path(dir, binary);
    match std::fs::read_to_string(&path) {
        Ok(text) if text.trim() == pid.to_string() => match std::fs::remove_file(&path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        },
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// Whether `binary` announced in `dir` that it is up.
pub fn is_ready(dir: &Path, binary: &str) -> bool {
    ready_path(dir, binary).is_file()
}

/// Waits until `binary` announces in `dir` that it is up (the file is polled), for at most
/// `limit`, while `alive` says it may still come; whether it did.
pub fn wait_for_ready(
    dir: &Path,
    binary: &str,
    limit: Duration,
    alive: impl FnMut() -> bool,
) -> bool {
    wait_for(limit, alive, || is_ready(dir, binary).then_some(())).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_process_withdraws_only_its_own_announcement() {
        let dir =
            std::env::temp_dir().join(format!("missionlink-state-own-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        announce_ready(&dir, "voting-monitoring").unwrap();
        // The old instance of a partition on its way out meets the new one's announcement.
        withdraw_ready(&dir, "voting-monitoring", std::process::id() + 1).unwrap();
        assert!(is_ready(&dir, "voting-monitoring"), "not its announcement");
        withdraw_ready(&dir, "voting-monitoring", std::process::id()).unwrap();
        assert!(!is_ready(&dir, "voting-monitoring"));
        withdraw_ready(&dir, "voting-monitoring", std::process::id()).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn readiness_is_announced_withdrawn_and_waited_for() {
        let dir =
            std::env::temp_dir().join(format!("missionlink-state-ready-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        assert!(!is_ready(&dir, "fcc"));
        forget_ready(&dir, "fcc").unwrap();
        // A process that is gone is not waited for.
        assert!(!wait_for_ready(
            &dir,
            "fcc",
            Duration::from_secs(20),
            || false
        ));
        announce_ready(&dir, "fcc").unwrap();
        assert!(is_ready(&dir, "fcc"));
        assert!(!is_ready(&dir, "guidance-stub"), "each binary its own");
        assert!(wait_for_ready(&dir, "fcc", Duration::ZERO, || true));
        forget_ready(&dir, "fcc").unwrap();
        assert!(!is_ready(&dir, "fcc"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
