//! The active lists and the staged missions of mission data handling on disk, so that a
//! restarted partition (after a crash or `kill -9`) resumes with them instead of publishing
//! nothing or empty lists.
//!
//! Lists are kept as the STANAG frames that carry them (ICD §4), back to back like a datagram:
//! take-off height, waypoints, RF centres, route and the #13000 transmit for a waypoint list;
//! #2011 initiate upload, the #2012 areas and #2011 upload complete for an area list. Frames
//! keep every field, and reading them back goes through the same assembly as an upload.
//!
//! Both active lists and their generations are one file ([`save_active`],
//! `active-lists.frames`): an activation that replaces both (ICD §8) cannot be torn by a kill
//! between two writes. Each staged mission is a file of its own under `staged/`
//! ([`save_staged`]). Every file is replaced atomically: a staged mission's by a new file
//! ([`super::write_atomically`]), the active lists and the open upload's record, rewritten at
//! every upload, by exchanging them with their spare ([`super::rewrite_durably`]).
//!
//! Whether a mission upload is open is recorded too (`mission-upload.open`: `open` or `closed`;
//! empty, as an earlier version left it, reads as open): a partition
//! restarted in the middle of one must not take the rest of it as an edit of the active list
//! (`missionlink_flight::mission_data_handling`, "A restart never assembles a transfer it did not see from
//! the start").

use std::io;
use std::path::{Path, PathBuf};

use missionlink_interfaces::wire::{
    self, AreaTransferMode, AreaTransmissionCommand, Envelope, MAX_FRAME_LEN, Message,
    MissionPlanMode, Timestamp,
};
use missionlink_protocol::transfer::areas::{AreaBuffer, AreaList};
use missionlink_protocol::transfer::mission::{Mission, MissionBuffer};
use missionlink_protocol::transfer::sender::mission_command;
use missionlink_protocol::transfer::staged::MissionId;

use super::{remove_if_present, rewrite_durably, sync_dir, write_atomically};

const ACTIVE_LISTS: &str = "active-lists.frames";
const STAGED: &str = "staged";
const MISSION_UPLOAD_OPEN: &str = "mission-upload.open";

/// The messages that carry `mission`, as an upload does (ICD §5.1): take-off height, waypoints,
/// RF centres, route, and the #13000 transmit with the count and the Mission ID. None for no
/// mission.
fn mission_messages(mission: Option<&Mission>) -> Vec<Message> {
    match mission {
        Some(m) => m
            .messages()
            .chain(std::iter::once(mission_command(
                MissionPlanMode::TransmitMission,
                Some(m.waypoints.len() as u16),
                m.mission_id,
            )))
            .collect(),
        None => Vec::new(),
    }
}

/// The messages that carry `areas`, as an upload does (ICD §5.3): #2011 initiate upload with the
/// safety offset, the #2012 areas, #2011 upload complete with the count. None for no list.
fn area_messages(areas: Option<&AreaList>) -> Vec<Message> {
    let Some(list) = areas else {
        return Vec::new();
    };
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

/// `messages` encoded as frames back to back, appended to `out`.
fn encode_frames(out: &mut Vec<u8>, messages: &[Message]) -> io::Result<()> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    for m in messages {
        let len = wire::encode(&Envelope::new(0, 0), m, &mut buf)
            .map_err(|e| io::Error::other(e.to_string()))?;
        out.extend_from_slice(buf.get(..len).unwrap_or_default());
    }
    Ok(())
}

/// The messages of frames back to back; `None` (logged) when a frame is damaged.
fn decode_frames(path: &Path, bytes: &[u8]) -> Option<Vec<Message>> {
    let mut messages = Vec::new();
    for frame in wire::frames(bytes) {
        match frame.map(|f| f.message()) {
            Ok(Ok(m)) => messages.push(m),
            other => {
                tracing::warn!(path = %path.display(), ?other, "state file is damaged");
                return None;
            }
        }
    }
    Some(messages)
}

/// The mission `messages` carry, through the same assembly as an upload: `Some(None)` for no
/// messages (no mission), `None` when they do not make a mission.
fn assemble_mission(messages: &[Message]) -> Option<Option<Mission>> {
    let mut buffer = MissionBuffer::new();
    for m in messages {
        if let Message::MissionTransferCommand(c) = m {
            return buffer
                .assemble(c.waypoint_number, c.mission_id)
                .ok()
                .map(Some);
        }
        buffer.store(m).ok()?;
    }
    messages.is_empty().then_some(None)
}

/// The area list `messages` carry, through the same assembly as an upload: `Some(None)` for no
/// messages (no list), `None` when they do not make a list.
fn assemble_areas(messages: &[Message]) -> Option<Option<AreaList>> {
    let mut buffer = AreaBuffer::new();
    // The opener carries the safety offset: areas without it are not the list that was saved.
    let mut offset = None;
    for m in messages {
        match m {
            Message::AreaTransmissionCommand(c) if c.mode == AreaTransferMode::InitiateUpload => {
                offset = Some(c.safety_offset.unwrap_or_default());
            }
            Message::AreaTransmissionCommand(c) => {
                return buffer
                    .assemble(c.loop_count.unwrap_or(0), offset?)
                    .ok()
                    .map(Some);
            }
            Message::AreaPolygonLoopSegment(a) if offset.is_some() => buffer.store(a).ok()?,
            _ => return None,
        }
    }
    messages.is_empty().then_some(None)
}

/// A waypoint list and an area list in one file's bytes: the length of the waypoint list's
/// frames (4 bytes, big-endian), those frames, then the area list's frames to the end.
fn encode_lists(
    out: &mut Vec<u8>,
    mission: Option<&Mission>,
    areas: Option<&AreaList>,
) -> io::Result<()> {
    let mut mission_frames = Vec::new();
    encode_frames(&mut mission_frames, &mission_messages(mission))?;
    let len = u32::try_from(mission_frames.len()).map_err(io::Error::other)?;
    out.extend_from_slice(&len.to_be_bytes());
    out.extend_from_slice(&mission_frames);
    encode_frames(out, &area_messages(areas))
}

/// The two lists of [`encode_lists`]; `None` (logged) when the bytes do not hold them.
fn decode_lists(path: &Path, bytes: &[u8]) -> Option<(Option<Mission>, Option<AreaList>)> {
    let damaged = |what: &str| {
        tracing::warn!(path = %path.display(), what, "state file is damaged");
    };
    let Some((len, rest)) = bytes.split_first_chunk::<4>() else {
        damaged("too short for the length of the waypoint list");
        return None;
    };
    let Some((mission_bytes, area_bytes)) = usize::try_from(u32::from_be_bytes(*len))
        .ok()
        .and_then(|len| rest.split_at_checked(len))
    else {
        damaged("shorter than the waypoint list it announces");
        return None;
    };
    let Some(mission) = assemble_mission(&decode_frames(path, mission_bytes)?) else {
        damaged("the waypoint list does not assemble");
        return None;
    };
    let Some(areas) = assemble_areas(&decode_frames(path, area_bytes)?) else {
        damaged("the area list does not assemble");
        return None;
    };
    Some((mission, areas))
}

/// The active lists of mission data handling, as saved by [`save_active`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ActiveLists {
    /// The active waypoint list, if any.
    pub mission: Option<Mission>,
    /// Its generation (counts clears too).
    pub mission_generation: u64,
    /// The active area list, if any.
    pub areas: Option<AreaList>,
    /// Its generation.
    pub area_generation: u64,
}

/// Saves the active lists and their generations in one file (`active-lists.frames`), replaced
/// atomically: an activation that changes both lists (ICD §8) is on disk whole or not at all,
/// never torn by a kill between two writes. The file: the mission generation and the area
/// generation (8 bytes each, big-endian), then the two lists as [`encode_lists`] lays them out.
pub fn save_active(
    dir: &Path,
    mission: Option<&Mission>,
    mission_generation: u64,
    areas: Option<&AreaList>,
    area_generation: u64,
) -> io::Result<()> {
    let mut bytes = mission_generation.to_be_bytes().to_vec();
    bytes.extend_from_slice(&area_generation.to_be_bytes());
    encode_lists(&mut bytes, mission, areas)?;
    rewrite_durably(&dir.join(ACTIVE_LISTS), &bytes)
}

/// The active lists saved last, `None` when there are none or the file is damaged (logged).
pub fn load_active(dir: &Path) -> Option<ActiveLists> {
    let path = dir.join(ACTIVE_LISTS);
    match std::fs::read(&path) {
        Ok(bytes) => {
            let Some((mission_generation, rest)) = bytes.split_first_chunk::<8>() else {
                tracing::warn!(path = %path.display(), "state file is damaged: too short");
                return None;
            };
            let Some((area_generation, rest)) = rest.split_first_chunk::<8>() else {
                tracing::warn!(path = %path.display(), "state file is damaged: too short");
                return None;
            };
            let (mission, areas) = decode_lists(&path, rest)?;
            Some(ActiveLists {
                mission,
                mission_generation: u64::from_be_bytes(*mission_generation),
                areas,
                area_generation: u64::from_be_bytes(*area_generation),
            })
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => {
            tracing::warn!(path = %path.display(), %e, "cannot read the state file");
            None
        }
    }
}

/// The file of staged mission `id`: `staged/<hex of the ID's bytes>.frames`. Hex keeps every
/// printable ID (a slash, a dot, a space) a plain file name and reads back to the same ID.
fn staged_path(dir: &Path, id: &MissionId) -> PathBuf {
    let name: String = id.as_str().bytes().map(|b| format!("{b:02x}")).collect();
    dir.join(STAGED).join(format!("{name}.frames"))
}

/// The Mission ID a file name of [`staged_path`] stands for.
fn staged_id(file_name: &str) -> Option<MissionId> {
    let hex = file_name.strip_suffix(".frames")?;
    if hex.len() % 2 != 0 || !hex.is_ascii() {
        return None;
    }
    let bytes = (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(hex.get(i..i + 2)?, 16).ok())
        .collect::<Option<Vec<u8>>>()?;
    MissionId::new(std::str::from_utf8(&bytes).ok()?).ok()
}

/// Saves staged mission `id` (ICD §8) with the lists stored under it so far, in one file of its
/// own replaced atomically (`staged/<hex of the ID>.frames`, laid out as the lists of the active
/// file without the generations). A staged mission is kept across a restart of mission data
/// handling like the active lists.
pub fn save_staged(
    dir: &Path,
    id: &MissionId,
    mission: Option<&Mission>,
    areas: Option<&AreaList>,
) -> io::Result<()> {
    let mut bytes = Vec::new();
    encode_lists(&mut bytes, mission, areas)?;
    write_atomically(&staged_path(dir, id), &bytes)
}

/// Removes staged mission `id` (nothing to do when it is not saved).
pub fn delete_staged(dir: &Path, id: &MissionId) -> io::Result<()> {
    let path = staged_path(dir, id);
    remove_if_present(&path)?;
    match path.parent().map(sync_dir) {
        Some(Err(e)) if e.kind() != io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// The staged missions saved in `dir`, in ascending byte order of Mission ID. A file that is
/// damaged, or whose name is no Mission ID, is logged and skipped: the other staged missions are
/// still restored.
pub fn load_staged(dir: &Path) -> Vec<(MissionId, Option<Mission>, Option<AreaList>)> {
    let staged_dir = dir.join(STAGED);
    let entries = match std::fs::read_dir(&staged_dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Vec::new(),
        Err(e) => {
            tracing::warn!(dir = %staged_dir.display(), %e, "cannot read the staged missions");
            return Vec::new();
        }
    };
    let mut staged = Vec::new();
    for entry in entries {
        let path = match entry {
            Ok(entry) => entry.path(),
            Err(e) => {
                tracing::warn!(dir = %staged_dir.display(), %e, "cannot read the staged missions");
                continue;
            }
        };
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        // A temporary file a crash left behind was never renamed: it is not a staged mission.
        if !name.ends_with(".frames") {
            continue;
        }
        let Some(id) = staged_id(name) else {
            tracing::warn!(path = %path.display(), "not the file of a Mission ID: skipped");
            continue;
        };
        let lists = match std::fs::read(&path) {
            Ok(bytes) => decode_lists(&path, &bytes),
            Err(e) => {
                tracing::warn!(path = %path.display(), %e, "cannot read the staged mission");
                None
            }
        };
        match lists {
            Some((mission, areas)) => staged.push((id, mission, areas)),
            None => tracing::warn!(%id, path = %path.display(), "staged mission skipped"),
        }
    }
    staged.sort_by_key(|(id, _, _)| *id);
    staged
}

/// Records that a mission upload is open (`true`) or that none is: the same file rewritten
/// (`open`, `closed`), so that an upload makes and deletes no file.
pub fn save_mission_upload_open(dir: &Path, open: bool) -> io::Result<()> {
    let text: &[u8] = if open { b"open\n" } else { b"closed\n" };
    rewrite_durably(&dir.join(MISSION_UPLOAD_OPEN), text)
}

/// Whether a mission upload was recorded open. Anything but `closed` is open: a file that cannot
/// be read whole must not let a restart take the rest of an upload as an edit.
pub fn load_mission_upload_open(dir: &Path) -> bool {
    match std::fs::read(dir.join(MISSION_UPLOAD_OPEN)) {
        Ok(text) => text != b"closed\n",
        Err(e) => e.kind() != io::ErrorKind::NotFound,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_protocol::testkit;

    /// Demo mission 1 and demo mission 2, each as (waypoint list, area list).
    fn missions() -> [(Mission, AreaList); 2] {
        [testkit::mission_1(), testkit::mission_2()].map(|plan| {
            let lists = plan.lists_to_check().unwrap();
            assert!(lists.invalid.is_none());
            (lists.mission, lists.areas)
        })
    }

    fn id(s: &str) -> MissionId {
        MissionId::new(s).unwrap()
    }

    #[test]
    fn the_active_lists_read_back_whole_with_their_generations() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(load_active(dir.path()), None, "nothing saved");
        let [(m1, a1), (m2, a2)] = missions();
        save_active(dir.path(), Some(&m1), 3, Some(&a1), 2).unwrap();
        let expected = ActiveLists {
            mission: Some(m1),
            mission_generation: 3,
            areas: Some(a1),
            area_generation: 2,
        };
        assert_eq!(load_active(dir.path()), Some(expected));
        // An activation replaces both in one write.
        save_active(dir.path(), Some(&m2), 4, Some(&a2), 3).unwrap();
        let active = load_active(dir.path()).unwrap();
        assert_eq!((active.mission, active.areas), (Some(m2), Some(a2)));
        assert_eq!((active.mission_generation, active.area_generation), (4, 3));
        // Cleared lists are saved as none, their generations kept.
        save_active(dir.path(), None, 5, None, 4).unwrap();
        let cleared = ActiveLists {
            mission_generation: 5,
            area_generation: 4,
            ..ActiveLists::default()
        };
        assert_eq!(load_active(dir.path()), Some(cleared));
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [ACTIVE_LISTS, "active-lists.spare"],
            "the file and its spare, no temporary file"
        );
    }

    #[test]
    fn an_open_upload_is_recorded_in_one_file_and_anything_but_closed_reads_open() {
        let dir = tempfile::tempdir().unwrap();
        assert!(!load_mission_upload_open(dir.path()), "never recorded");
        for open in [true, false, true, false] {
            save_mission_upload_open(dir.path(), open).unwrap();
            assert_eq!(load_mission_upload_open(dir.path()), open);
        }
        // The empty file an earlier version made for an open upload, or a cut one.
        for text in [&b""[..], b"clo"] {
            std::fs::write(dir.path().join(MISSION_UPLOAD_OPEN), text).unwrap();
            assert!(load_mission_upload_open(dir.path()));
        }
    }

    #[test]
    fn a_damaged_or_cut_active_file_is_not_taken_for_lists() {
        let dir = tempfile::tempdir().unwrap();
        let [(m1, a1), _] = missions();
        save_active(dir.path(), Some(&m1), 1, Some(&a1), 1).unwrap();
        let path = dir.path().join(ACTIVE_LISTS);
        let whole = std::fs::read(&path).unwrap();
        // Cut anywhere: too short for the header, inside the waypoint list, between two frames
        // of the area list (the closer missing), inside an area frame.
        for len in [0, 7, 15, 19, 40, whole.len() - 30, whole.len() - 1] {
            std::fs::write(&path, &whole[..len]).unwrap();
            assert_eq!(load_active(dir.path()), None, "cut at {len}");
        }
        // One bit flipped in every byte of the frames in turn: the frames' checksums, lengths
        // or the assembly refuse it (never a panic, never other lists).
        for at in 20..whole.len() {
            let mut damaged = whole.clone();
            damaged[at] ^= 0x10;
            std::fs::write(&path, &damaged).unwrap();
            if let Some(read) = load_active(dir.path()) {
                panic!("flipped at {at}: read {read:?}");
            }
        }
    }

    #[test]
    fn staged_missions_are_saved_replaced_deleted_and_read_back_in_id_order() {
        let dir = tempfile::tempdir().unwrap();
        assert!(load_staged(dir.path()).is_empty(), "nothing staged");
        let [(m1, a1), (m2, a2)] = missions();
        // IDs a file name could not hold as they are.
        let (slash, dots, space) = (id("a/b"), id(".."), id("survey north"));
        save_staged(dir.path(), &slash, Some(&m1), None).unwrap();
        save_staged(dir.path(), &dots, None, Some(&a2)).unwrap();
        save_staged(dir.path(), &space, Some(&m2), Some(&a1)).unwrap();
        let staged = load_staged(dir.path());
        let expected = vec![
            (dots, None, Some(a2.clone())),
            (slash, Some(m1.clone()), None),
            (space, Some(m2.clone()), Some(a1.clone())),
        ];
        assert_eq!(staged, expected, "ascending byte order of Mission ID");

        // A closer for an ID already staged replaces that list.
        save_staged(dir.path(), &slash, Some(&m1), Some(&a2)).unwrap();
        save_staged(dir.path(), &dots, None, Some(&a1)).unwrap();
        delete_staged(dir.path(), &space).unwrap();
        delete_staged(dir.path(), &space).unwrap();
        let staged = load_staged(dir.path());
        assert_eq!(
            staged,
            vec![(dots, None, Some(a1)), (slash, Some(m1), Some(a2))]
        );
    }

    #[test]
    fn a_damaged_staged_file_or_a_stray_name_is_skipped_and_the_others_read() {
        let dir = tempfile::tempdir().unwrap();
        let [(m1, a1), (m2, a2)] = missions();
        save_staged(dir.path(), &id("GOOD"), Some(&m1), Some(&a1)).unwrap();
        save_staged(dir.path(), &id("CUT"), Some(&m2), Some(&a2)).unwrap();
        let cut = staged_path(dir.path(), &id("CUT"));
        let bytes = std::fs::read(&cut).unwrap();
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let staged_dir = dir.path().join(STAGED);
        // Names no Mission ID has: not hex, odd, empty, not printable ("\t"); and a temporary
        // file a crash left.
        for name in [
            "zz.frames",
            "414.frames",
            ".frames",
            "09.frames",
            "4142.tmp.1",
        ] {
            std::fs::write(staged_dir.join(name), &bytes).unwrap();
        }
        let staged = load_staged(dir.path());
        assert_eq!(staged, vec![(id("GOOD"), Some(m1), Some(a1))]);
    }

    #[test]
    fn the_file_name_of_a_mission_id_reads_back_to_it() {
        for s in ["A", "survey-north", " ~!\"#$%&'()*+,-./", &"z".repeat(19)] {
            let id = id(s);
            let path = staged_path(Path::new("/x"), &id);
            let name = path.file_name().unwrap().to_str().unwrap();
            assert!(name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'.'));
            assert_eq!(staged_id(name), Some(id), "{s:?}");
        }
    }
}
