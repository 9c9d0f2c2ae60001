//! Staged missions (ICD §8): stage, load the waypoint buffer, delete, and activate a staged
//! mission's lists in one step.

use super::*;

impl MissionDataHandling {
    /// #13000 mode 8 (ICD §8): assembles the waypoint buffer as mode 2 does and stores the list
    /// under the Mission ID; the active lists do not change. A ninth ID is refused (`Capacity`)
    /// before the assembly, so the upload stays as it was.
    pub(super) fn stage_mission(
        &mut self,
        now: Instant,
        message: &Message,
        id: Option<Text<20>>,
    ) -> Result<(), Reason> {
        let id = staged_id(id)?;
        if !self.staged.can_store(&id) {
            return Err(Reason::Capacity);
        }
        match self.upload_step(now, message)? {
            Received::Complete => {
                let mission = self.mission_upload.take().ok_or(Reason::WrongState)?;
                if self.staged.store_mission(id, mission)? {
                    self.event(FccEvent::StagedStored {
                        id,
                        kind: DataKind::Mission,
                    });
                }
                Ok(())
            }
            // Mode 8 never empties (the receiver activates the empty list for mode 2 only).
            Received::Emptied | Received::Stored | Received::Abandoned(_) => {
                Err(Reason::WrongState)
            }
        }
    }

    /// #13000 mode 10 (ICD §8): the waypoint buffer becomes the staged mission's waypoint list,
    /// the active one (empty Mission ID), or empty (no such list), and an upload that edits it
    /// opens. Allowed while trajectory generation is active (nothing active changes); refused
    /// during a mission download as the clear is (`Busy`). Like the clear, it opens a new
    /// upload, so an upload cut by a restart is over. Stamped `stamp`, it leaves what the data
    /// sent behind it stored when they overtook it, and one stamped before an opener this upload
    /// applied changes nothing (`WrongState`, ICD §10.3).
    pub(super) fn load_buffer(
        &mut self,
        now: Instant,
        id: Option<Text<20>>,
        stamp: Timestamp,
    ) -> Result<(), Reason> {
        if self.mission_download.is_some() {
            return Err(Reason::Busy);
        }
        let id = id.ok_or(Reason::MissingField)?;
        let base = if id.is_empty() {
            self.active_mission.as_ref()
        } else {
            let id = staged_id(Some(id))?;
            self.staged.get(&id).and_then(|e| e.mission.as_ref())
        };
        self.mission_upload.load(now, base, stamp)?;
        self.interrupted_until = None;
        Ok(())
    }

    /// #13000 mode 6 (ICD §8): deletes the staged mission (`WrongState` when there is none).
    pub(super) fn delete_staged(&mut self, id: Option<Text<20>>) -> Result<(), Reason> {
        let id = staged_id(id)?;
        if !self.staged.delete(&id) {
            return Err(Reason::WrongState);
        }
        // A retried closer of that mission must be judged afresh (see `CloserMemory`).
        self.closers.forget();
        self.event(FccEvent::StagedDeleted { id });
        Ok(())
    }

    /// #50000 command 4 (ICD §8): replaces both active lists by the staged mission's in one
    /// step, when it has both, trajectory generation is not active and the onboard geofence
    /// check passes for them ([`automation::check_activation`]); else `WrongState` or
    /// `GeofenceViolation`, and nothing changes. The staged copy stays.
    pub(super) fn activate_staged(&mut self, id: Option<Text<20>>) -> Result<(), Reason> {
        let id = staged_id(id)?;
        let Some(entry) = self.staged.get(&id) else {
            return Err(Reason::WrongState);
        };
        let (Some(mission), Some(areas)) = (&entry.mission, &entry.areas) else {
            return Err(Reason::WrongState);
        };
        // The check sees the lists as they would be published (the generation does not enter it).
        let area_list = areas.to_payload(self.area_generation + 1);
        self.staged_fence.set_payload(&area_list);
        automation::check_activation(
            &self.automation,
            &mission.to_payload(self.mission_generation + 1),
            &area_list,
            &self.staged_fence,
            &self.navigation,
        )?;
        let (mission, areas) = (mission.clone(), areas.clone());
        self.activate(Activation::Staged { id, mission, areas });
        // The last closer's "valid and active" is no longer true (see `CloserMemory`); a staged
        // closer's answer still is: the GCS may have sent this activation behind it (ICD §10.3).
        self.closers.activated();
        Ok(())
    }
}

/// The staged mission a request names (ICD §8: #13000 modes 6, 8, 9, #2011 modes 7, 8, #50000
/// command 4): absent is `MissingField`; empty, or not printable ASCII, is `Malformed` (our
/// choice: the ICD names the rule of the ID, not the reason; an empty ID names the active lists
/// only with mode 10).
pub(super) fn staged_id(id: Option<Text<20>>) -> Result<MissionId, Reason> {
    let id = id.ok_or(Reason::MissingField)?;
    MissionId::of_text(&id).map_err(|_| Reason::Malformed)
}
