//! The state directory of one FCC instance: what its processes keep on disk and tell each
//! other through it, one module per job.
//!
//! - [`lists`]: the active lists and the staged missions of mission data handling, so that a
//!   restarted partition (after a crash or `kill -9`) resumes with them instead of publishing
//!   nothing or empty lists; and the record of a mission upload that is open.
//! - [`links`]: where voting-monitoring bound the FCC's ends of the links (`links.toml`), for
//!   the GCS and for a restarted voting-monitoring.
//! - [`ready`]: each process's announcement that it is up (`ready/<binary>`), which the
//!   launcher, the demo and the tests wait for instead of sleeping.
//!
//! Every file is replaced atomically ([`write_atomically`]: written, flushed to the disk,
//! renamed), so a crash mid-write leaves the previous content.

pub mod links;
pub mod lists;
pub mod ready;

pub use links::{BoundLinks, forget_links, load_links, save_links, wait_for_links};
pub use lists::{
    ActiveLists, delete_staged, load_active, load_mission_upload_open, load_staged, save_active,
    save_mission_upload_open, save_staged,
};
pub use ready::{
    announce_ready, forget_ready, is_ready, ready_dir, wait_for_ready, withdraw_ready,
};

use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Polls `probe` until it gives a value, for at most `limit`, while `alive` says it may still
/// come (another process writes what it looks for: no event to sleep on).
pub(crate) fn wait_for<T>(
    limit: Duration,
    mut alive: impl FnMut() -> bool,
    mut probe: impl FnMut() -> Option<T>,
) -> Option<T> {
    let end = Instant::now() + limit;
    loop {
        if let Some(found) = probe() {
            return Some(found);
        }
        if Instant::now() >= end || !alive() {
            return None;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The directory of one FCC instance's state (`<temp>/missionlink-state/<prefix>` unless
/// configured).
pub fn default_dir(prefix: &str) -> PathBuf {
    let safe: String = prefix
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    std::env::temp_dir().join("missionlink-state").join(safe)
}

// One owner of whole writes for the FCC and the ground (`missionlink_platform::files`).
pub(crate) use missionlink_platform::files::{rewrite_durably, sync_dir, write_atomically};

/// Removes `path`; a file that is not there is removed already.
pub(crate) fn remove_if_present(path: &std::path::Path) -> std::io::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}
