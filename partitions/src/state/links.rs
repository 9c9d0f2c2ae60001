//! Voting-monitoring announces here where it bound the FCC's ends of the links
//! ([`BoundLinks`], `links.toml`): with port 0 in the configuration the system chooses them, the
//! GCS (the demo, the tests) reads them here, and a restarted voting-monitoring binds the same
//! ports again so the GCS keeps talking to them.

use std::io;
use std::net::SocketAddr;
use std::path::Path;
use std::time::Duration;

use super::{wait_for, write_atomically};

const LINKS: &str = "links.toml";

/// Where voting-monitoring bound the FCC's ends of the two links.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundLinks {
    /// The FCC receives the direct link here.
    pub fcc_direct: SocketAddr,
    /// The FCC receives the LTE link here.
    pub fcc_lte: SocketAddr,
}

impl BoundLinks {
    /// Points the FCC ends of `links` (a configuration's `[links]`) at these (for the GCS that
    /// talks to this FCC).
    pub fn apply(&self, links: &mut missionlink_platform::config::Links) {
        links.fcc_direct = self.fcc_direct;
        links.fcc_lte = self.fcc_lte;
    }
}

/// Announces `links` in `dir` (atomically: a reader sees the old file or the new one).
pub fn save_links(dir: &Path, links: &BoundLinks) -> io::Result<()> {
    let text = toml::to_string(links).map_err(io::Error::other)?;
    write_atomically(&dir.join(LINKS), text.as_bytes())
}

/// The links announced in `dir`, if any.
pub fn load_links(dir: &Path) -> Option<BoundLinks> {
    let text = std::fs::read_to_string(dir.join(LINKS)).ok()?;
    toml::from_str(&text).ok()
}

/// Removes the announcement in `dir`, so that the next one read is a new one.
pub fn forget_links(dir: &Path) -> io::Result<()> {
    match std::fs::remove_file(dir.join(LINKS)) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// Waits until links are announced in `dir` (the file is polled), for at most `limit`, while
/// `alive` says the announcing process may still come.
pub fn wait_for_links(
    dir: &Path,
    limit: Duration,
    alive: impl FnMut() -> bool,
) -> Option<BoundLinks> {
    wait_for(limit, alive, || load_links(dir))
}
