//! The active lists of mission data handling on disk, so that a restarted partition (after a
//! crash or `kill -9`) resumes with them instead of publishing nothing or empty lists.
//!
//! Each list is one file: its generation (8 bytes, big-endian), then the list as the STANAG
//! frames that carry it (ICD §4), back to back like a datagram: take-off height, waypoints, RF
//! centres, route and the #13000 transmit for the waypoint list; #2011 initiate upload, the
//! #2012 areas and #2011 upload complete for the area list. Frames keep every field, and reading
//! them back goes through the same assembly as an upload. A file is replaced atomically (write,
//! then rename), so a crash mid-write leaves the previous list.
//!
//! A mission upload that is open is recorded too (`mission-upload.open`, empty): a partition
//! restarted in the middle of one must not take the rest of it as an edit of the active list
//! (`services::mission_data_handling`, "A restart never assembles a transfer it did not see from
//! the start").
//!
//! Voting-monitoring announces here where it bound the FCC's ends of the links
//! ([`BoundLinks`], `links.toml`): with port 0 in the configuration the system chooses them, the
//! GCS (the demo, the tests) reads them here, and a restarted voting-monitoring binds the same
//! ports again so the GCS keeps talking to them.
//!
//! Every partition process announces here when it is up (its ports open, waiting for data), and
//! the launcher once all its partitions are ([`announce_ready`], `ready/<binary>`): the demo and
//! the tests wait for that instead of sleeping.

use std::io;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use missionlink_interfaces::wire::{
    self, AreaTransferMode, AreaTransmissionCommand, Envelope, MAX_FRAME_LEN, Message,
    MissionPlanMode, Timestamp,
};
use missionlink_services::transfer::areas::{AreaBuffer, AreaList};
use missionlink_services::transfer::mission::{Mission, MissionBuffer};
use missionlink_services::transfer::sender::mission_command;

const WAYPOINT_LIST: &str = "waypoint-list.frames";
const AREA_LIST: &str = "area-list.frames";
const MISSION_UPLOAD_OPEN: &str = "mission-upload.open";
const LINKS: &str = "links.toml";
const READY: &str = "ready";

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
    /// Points `config`'s FCC ends at these (for the GCS that talks to this FCC).
    pub fn apply(&self, config: &mut crate::config::Config) {
        config.links.fcc_direct = self.fcc_direct;
        config.links.fcc_lte = self.fcc_lte;
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

/// Polls `probe` until it gives a value, for at most `limit`, while `alive` says it may still
/// come (another process writes what it looks for: no event to sleep on).
fn wait_for<T>(
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

fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    // A name of this process's own: two processes writing the same file never share a
    // half-written one.
    let tmp = path.with_extension(format!("tmp.{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

fn frames(generation: u64, messages: impl Iterator<Item = Message>) -> io::Result<Vec<u8>> {
    let mut out = generation.to_be_bytes().to_vec();
    let mut buf = [0u8; MAX_FRAME_LEN];
    for m in messages {
        let len = wire::encode(&Envelope::new(0, 0), &m, &mut buf)
            .map_err(|e| io::Error::other(e.to_string()))?;
        out.extend_from_slice(buf.get(..len).unwrap_or_default());
    }
    Ok(out)
}

fn read(path: &Path) -> Option<(u64, Vec<Message>)> {
    let bytes = std::fs::read(path).ok()?;
    let (generation, rest) = bytes.split_first_chunk::<8>()?;
    let mut messages = Vec::new();
    for frame in wire::frames(rest) {
        match frame.map(|f| f.message()) {
            Ok(Ok(m)) => messages.push(m),
            other => {
                tracing::warn!(path = %path.display(), ?other, "state file is damaged");
                return None;
            }
        }
    }
    Some((u64::from_be_bytes(*generation), messages))
}

/// Saves the active waypoint list (or none) under `generation`.
pub fn save_mission(dir: &Path, mission: Option<&Mission>, generation: u64) -> io::Result<()> {
    let messages: Vec<Message> = match mission {
        Some(m) => m
            .messages()
            .chain(std::iter::once(mission_command(
                MissionPlanMode::TransmitMission,
                Some(m.waypoints.len() as u16),
                m.mission_id,
            )))
            .collect(),
        None => Vec::new(),
    };
    write_atomically(
        &dir.join(WAYPOINT_LIST),
        &frames(generation, messages.into_iter())?,
    )
}

/// Saves the active area list (or none) under `generation`.
pub fn save_areas(dir: &Path, areas: Option<&AreaList>, generation: u64) -> io::Result<()> {
    let messages: Vec<Message> = match areas {
        Some(list) => {
            let command = |mode| {
                Message::from(AreaTransmissionCommand {
                    time_stamp: Timestamp::default(),
                    mode,
                    loop_count: Some(list.areas.len() as u8),
                    area_id: None,
                    safety_offset: Some(list.safety_offset),
                    activity_id: None,
                    mission_id: None,
                    window_or_checksum: None,
                })
            };
            std::iter::once(command(AreaTransferMode::InitiateUpload))
                .chain(list.areas.iter().cloned().map(Message::from))
                .chain(std::iter::once(command(AreaTransferMode::UploadComplete)))
                .collect()
        }
        None => Vec::new(),
    };
    write_atomically(
        &dir.join(AREA_LIST),
        &frames(generation, messages.into_iter())?,
    )
}

/// Records that a mission upload is open (`true`) or that none is.
pub fn save_mission_upload_open(dir: &Path, open: bool) -> io::Result<()> {
    let path = dir.join(MISSION_UPLOAD_OPEN);
    if open {
        write_atomically(&path, &[])
    } else {
        match std::fs::remove_file(path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        }
    }
}

/// Whether a mission upload was recorded open.
pub fn load_mission_upload_open(dir: &Path) -> bool {
    dir.join(MISSION_UPLOAD_OPEN).is_file()
}

/// The waypoint list saved last and its generation.
pub fn load_mission(dir: &Path) -> Option<(Option<Mission>, u64)> {
    let (generation, messages) = read(&dir.join(WAYPOINT_LIST))?;
    let mut buffer = MissionBuffer::new();
    for m in &messages {
        if let Message::MissionTransferCommand(c) = m {
            let mission = buffer.assemble(c.waypoint_number, c.mission_id).ok()?;
            return Some((Some(mission), generation));
        }
        buffer.store(m).ok()?;
    }
    messages.is_empty().then_some((None, generation))
}

/// The area list saved last and its generation.
pub fn load_areas(dir: &Path) -> Option<(Option<AreaList>, u64)> {
    let (generation, messages) = read(&dir.join(AREA_LIST))?;
    let mut buffer = AreaBuffer::new();
    let mut offset = Default::default();
    for m in &messages {
        match m {
            Message::AreaTransmissionCommand(c) if c.mode == AreaTransferMode::InitiateUpload => {
                offset = c.safety_offset.unwrap_or_default();
            }
            Message::AreaTransmissionCommand(c) => {
                let list = buffer.assemble(c.loop_count.unwrap_or(0), offset).ok()?;
                return Some((Some(list), generation));
            }
            Message::AreaPolygonLoopSegment(a) => buffer.store(a).ok()?,
            _ => return None,
        }
    }
    messages.is_empty().then_some((None, generation))
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
