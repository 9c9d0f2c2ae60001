//! Staged missions (ICD §8): the Mission ID that names one, and the FCC's store of them.
//!
//! The FCC holds up to [`MAX_STAGED_MISSIONS`] staged missions beside the active lists, each
//! named by a Mission ID: non-empty printable ASCII of at most 19 characters (#13000 field 1,
//! #2011 field 6, #50000 field 2, #50001 field 3, all Char20). The GCS and the FCC check an ID
//! with the one rule here ([`MissionId`]).
//!
//! [`StagedMissions`] is the store: per ID a waypoint list and an area list, each optional (an
//! ID counts as staged once either is stored, ICD §8), kept in ascending byte order of ID, the
//! order of the report (#50001). Its storage is allocated once, when the store is made, for
//! [`MAX_STAGED_MISSIONS`] entries: storing, replacing and deleting a list move it in place and
//! never allocate, so an FCC handling frames allocates nothing in steady state.

use core::fmt;

use missionlink_interfaces::capacity::MAX_STAGED_MISSIONS;
use missionlink_interfaces::wire::{Reason, Text};

use crate::transfer::areas::AreaList;
use crate::transfer::mission::Mission;

/// Characters of a Mission ID at most (Char20 holds 19 and its terminator).
pub const MAX_MISSION_ID_LEN: usize = 19;

/// The name of a staged mission (ICD §8). Ordered by its bytes, the order of the report.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MissionId(Text<20>);

/// Why a text is not a Mission ID.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MissionIdError {
    /// The ID is empty: an empty Mission ID names the active lists, never a staged mission.
    #[error("the Mission ID is empty")]
    Empty,
    /// Longer than [`MAX_MISSION_ID_LEN`] characters.
    #[error("the Mission ID has {len} characters, at most {MAX_MISSION_ID_LEN} fit")]
    TooLong {
        /// Bytes given.
        len: usize,
    },
    /// Holds a byte that is not printable ASCII (0x20..=0x7e).
    #[error("the Mission ID holds a character that is not printable ASCII at byte {at}")]
    NotPrintable {
        /// Byte offset of the first such byte.
        at: usize,
    },
}

impl MissionId {
    /// The Mission ID `s`, if it is non-empty printable ASCII of at most 19 characters.
    pub fn new(s: &str) -> Result<Self, MissionIdError> {
        if s.is_empty() {
            return Err(MissionIdError::Empty);
        }
        if let Some(at) = s.bytes().position(|b| !(0x20..=0x7e).contains(&b)) {
            return Err(MissionIdError::NotPrintable { at });
        }
        Text::new(s)
            .map(Self)
            .map_err(|_| MissionIdError::TooLong { len: s.len() })
    }

    /// The Mission ID a received field holds, by the same rule.
    pub fn of_text(text: &Text<20>) -> Result<Self, MissionIdError> {
        Self::new(text.as_str())
    }

    /// The ID as the Char20 field carries it.
    pub fn text(&self) -> Text<20> {
        self.0
    }

    /// The ID.
    pub fn as_str(&self) -> &str {
        self.0.as_str()
    }
}

impl fmt::Display for MissionId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl fmt::Debug for MissionId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

/// One staged mission (ICD §8): its name and the lists stored under it so far.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StagedMission {
    /// Its name.
    pub id: MissionId,
    /// Its waypoint list with take-off height and route (#13000 mode 8), if stored.
    pub mission: Option<Mission>,
    /// Its area list (#2011 mode 7), if stored.
    pub areas: Option<AreaList>,
}

impl StagedMission {
    /// Whether both lists are stored: only then can it be activated (ICD §8).
    pub fn is_complete(&self) -> bool {
        self.mission.is_some() && self.areas.is_some()
    }
}

/// The staged missions of the FCC (ICD §8), at most [`MAX_STAGED_MISSIONS`], in ascending byte
/// order of Mission ID.
#[derive(Debug, PartialEq, Eq)]
pub struct StagedMissions {
    /// Sorted by ID; capacity [`MAX_STAGED_MISSIONS`] from the start, so it never grows.
    entries: Vec<StagedMission>,
}

impl Default for StagedMissions {
    fn default() -> Self {
        Self::new()
    }
}

/// A copy with the full capacity of its own (a derived clone would reserve only what is used,
/// and the next store would allocate).
impl Clone for StagedMissions {
    fn clone(&self) -> Self {
        let mut copy = Self::new();
        copy.entries.extend(self.entries.iter().cloned());
        copy
    }
}

impl StagedMissions {
    /// No staged mission; the storage for all of them is allocated now.
    pub fn new() -> Self {
        Self {
            entries: Vec::with_capacity(MAX_STAGED_MISSIONS),
        }
    }

    /// How many IDs are staged.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether none is.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The staged mission `id`.
    pub fn get(&self, id: &MissionId) -> Option<&StagedMission> {
        self.position(id).ok().and_then(|i| self.entries.get(i))
    }

    /// The staged missions in ascending byte order of ID (the order of the report, ICD §8).
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &StagedMission> + '_ {
        self.entries.iter()
    }

    /// Whether a list can be stored under `id`: it is staged already, or there is room for one
    /// more ID. A closer checks this before it assembles, so that a refusal (`Capacity`) leaves
    /// its transfer as it was.
    pub fn can_store(&self, id: &MissionId) -> bool {
        self.position(id).is_ok() || self.entries.len() < MAX_STAGED_MISSIONS
    }

    /// Stores `mission` as the waypoint list of `id`, replacing the one stored there. A ninth ID
    /// is refused (`Capacity`) and nothing changes. `Ok(true)` when the store changed.
    pub fn store_mission(&mut self, id: MissionId, mission: Mission) -> Result<bool, Reason> {
        let entry = self.entry(id)?;
        let changed = entry.mission.as_ref() != Some(&mission);
        entry.mission = Some(mission);
        Ok(changed)
    }

    /// Stores `areas` as the area list of `id`, as [`StagedMissions::store_mission`] does.
    pub fn store_areas(&mut self, id: MissionId, areas: AreaList) -> Result<bool, Reason> {
        let entry = self.entry(id)?;
        let changed = entry.areas.as_ref() != Some(&areas);
        entry.areas = Some(areas);
        Ok(changed)
    }

    /// Deletes the staged mission `id`, both lists; `false` when there is none.
    pub fn delete(&mut self, id: &MissionId) -> bool {
        match self.position(id) {
            Ok(i) => {
                // In place: the elements after it move down, the capacity stays.
                self.entries.remove(i);
                true
            }
            Err(_) => false,
        }
    }

    /// Where `id` is (`Ok`) or would go (`Err`) in the sorted entries.
    fn position(&self, id: &MissionId) -> Result<usize, usize> {
        self.entries.binary_search_by(|e| e.id.cmp(id))
    }

    /// The entry of `id`, made (empty) if it is not staged yet and there is room.
    fn entry(&mut self, id: MissionId) -> Result<&mut StagedMission, Reason> {
        let i = match self.position(&id) {
            Ok(i) => i,
            Err(_) if self.entries.len() >= MAX_STAGED_MISSIONS => return Err(Reason::Capacity),
            Err(i) => {
                self.entries.insert(
                    i,
                    StagedMission {
                        id,
                        mission: None,
                        areas: None,
                    },
                );
                i
            }
        };
        self.entries.get_mut(i).ok_or(Reason::Capacity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_of_icd_8() {
        assert_eq!(
            MissionId::new("survey-north").map(|i| i.to_string()),
            Ok("survey-north".into())
        );
        assert_eq!(MissionId::new(""), Err(MissionIdError::Empty));
        assert_eq!(
            MissionId::new(&"a".repeat(19)).map(|i| i.as_str().len()),
            Ok(19)
        );
        assert_eq!(
            MissionId::new(&"a".repeat(20)),
            Err(MissionIdError::TooLong { len: 20 })
        );
        assert_eq!(
            MissionId::new("ab\tc"),
            Err(MissionIdError::NotPrintable { at: 2 })
        );
        assert_eq!(
            MissionId::new("né"),
            Err(MissionIdError::NotPrintable { at: 1 })
        );
        assert_eq!(
            MissionId::of_text(&Text::default()),
            Err(MissionIdError::Empty)
        );
    }

    #[test]
    fn ordered_by_bytes_as_the_report_is() {
        let mut ids =
            ["b", "B", "a1", "a"].map(|s| MissionId::new(s).unwrap_or_else(|e| panic!("{e}")));
        ids.sort();
        assert_eq!(
            ids.map(|i| i.to_string()),
            ["B", "a", "a1", "b"].map(String::from)
        );
    }

    fn id(s: &str) -> MissionId {
        MissionId::new(s).unwrap_or_else(|e| panic!("{e}"))
    }

    fn mission(id: &str, waypoints: u16) -> Mission {
        use crate::testkit::{mission_buffer, zigzag};
        mission_buffer(&zigzag(waypoints))
            .assemble(Some(waypoints), Text::new(id).ok())
            .unwrap_or_else(|r| panic!("{r:?}"))
    }

    fn areas() -> AreaList {
        use crate::testkit::{area_buffer, eleven_areas};
        area_buffer(&eleven_areas())
            .assemble(11, Default::default())
            .unwrap_or_else(|r| panic!("{r:?}"))
    }

    #[test]
    fn an_id_is_staged_once_either_list_is_stored() {
        let mut staged = StagedMissions::new();
        assert!(staged.is_empty());
        assert_eq!(staged.store_mission(id("A"), mission("A", 3)), Ok(true));
        assert_eq!(staged.store_areas(id("B"), areas()), Ok(true));
        assert_eq!(staged.len(), 2);
        let a = staged.get(&id("A")).unwrap_or_else(|| panic!("A staged"));
        assert_eq!((a.mission.is_some(), a.areas.is_some()), (true, false));
        assert!(!a.is_complete());
        assert_eq!(staged.store_areas(id("A"), areas()), Ok(true));
        assert!(staged.get(&id("A")).is_some_and(StagedMission::is_complete));
        assert_eq!(staged.get(&id("C")), None);
    }

    #[test]
    fn the_same_id_replaces_its_list() {
        let mut staged = StagedMissions::new();
        assert_eq!(staged.store_mission(id("A"), mission("A", 3)), Ok(true));
        assert_eq!(
            staged.store_mission(id("A"), mission("A", 3)),
            Ok(false),
            "the same list again changes nothing"
        );
        assert_eq!(staged.store_mission(id("A"), mission("A", 5)), Ok(true));
        assert_eq!(staged.len(), 1);
        assert_eq!(
            staged
                .get(&id("A"))
                .and_then(|e| e.mission.as_ref())
                .map(|m| m.waypoints.len()),
            Some(5)
        );
    }

    #[test]
    fn a_ninth_id_is_refused_and_changes_nothing() {
        let mut staged = StagedMissions::new();
        for i in 0..MAX_STAGED_MISSIONS {
            assert_eq!(staged.store_areas(id(&format!("M{i}")), areas()), Ok(true));
        }
        let before = staged.clone();
        assert!(!staged.can_store(&id("M9")));
        assert_eq!(
            staged.store_mission(id("M9"), mission("M9", 2)),
            Err(Reason::Capacity)
        );
        assert_eq!(staged.store_areas(id("M9"), areas()), Err(Reason::Capacity));
        assert_eq!(staged, before);
        // An ID already staged still takes its other list.
        assert!(staged.can_store(&id("M3")));
        assert_eq!(staged.store_mission(id("M3"), mission("M3", 2)), Ok(true));
        // After a delete there is room again.
        assert!(staged.delete(&id("M0")));
        assert!(!staged.delete(&id("M0")), "deleted once");
        assert_eq!(staged.store_mission(id("M9"), mission("M9", 2)), Ok(true));
        assert_eq!(staged.len(), MAX_STAGED_MISSIONS);
    }

    #[test]
    fn iterated_in_ascending_byte_order_of_id() {
        let mut staged = StagedMissions::new();
        for name in ["b", "B", "a1", "a"] {
            assert_eq!(staged.store_areas(id(name), areas()), Ok(true));
        }
        let names: Vec<String> = staged.iter().map(|e| e.id.to_string()).collect();
        assert_eq!(names, ["B", "a", "a1", "b"]);
        assert!(staged.delete(&id("a")));
        let names: Vec<String> = staged.iter().map(|e| e.id.to_string()).collect();
        assert_eq!(names, ["B", "a1", "b"]);
    }

    #[test]
    fn the_storage_is_allocated_once() {
        let staged = StagedMissions::new();
        let copy = staged.clone();
        for s in [&staged, &copy] {
            assert!(s.entries.capacity() >= MAX_STAGED_MISSIONS);
        }
    }
}
