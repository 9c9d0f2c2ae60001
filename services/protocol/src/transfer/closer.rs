//! Idempotent closers (ICD §11): the receiver of an upload remembers the last closer it answered
//! and its answer, so that the sender's retry of a closer whose answer was lost gets the same
//! answer and changes nothing. Without it a lost "valid and active" turns into a reported
//! failure: the retry finds no transfer open and is refused (`WrongState`), although the list it
//! closed is active.
//!
//! The closer's content is what identifies it (ICD §11: message type, mode, Mission ID, Waypoint
//! Number or Area Loop Count, checksum or none); its time stamp is not, since a retry carries a
//! new one (ICD §3). There is one memory per kind of list, missions (#13000 closers) and areas
//! (#2011 closers): each holds until the receiver accepts an opener or a data message of a
//! transfer of its kind (ICD §10.2), so that the GCS may send the area opener behind the mission
//! closer (ICD §10.3) and still get the closer's answer again. Its owner also forgets both when
//! an active list changes by another way (this project's choice: a clear of the areas, for
//! instance, makes "valid and active" of the last area closer untrue, and a retry must then be
//! judged afresh).

use missionlink_interfaces::wire::{Checksum, Message, MessageType, Reason, Text};

/// What identifies a closer (ICD §11).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Closer {
    message_type: MessageType,
    mode: u8,
    mission_id: Option<Text<20>>,
    count: Option<u16>,
    checksum: Option<Checksum>,
}

impl Closer {
    /// The closer `message` is, if it is one: #13000 mode 2 (transmit) or 8 (stage, ICD §8),
    /// #2011 mode 2 (upload complete) or 7 (upload complete, staged).
    pub fn of(message: &Message) -> Option<Self> {
        use missionlink_interfaces::wire::{AreaTransferMode, MissionPlanMode};
        match message {
            Message::MissionTransferCommand(c)
                if matches!(
                    c.mode,
                    MissionPlanMode::TransmitMission | MissionPlanMode::StageMission
                ) =>
            {
                Some(Self {
                    message_type: MessageType::MissionTransferCommand,
                    mode: c.mode as u8,
                    mission_id: c.mission_id,
                    count: c.waypoint_number,
                    checksum: c.mission_checksum,
                })
            }
            Message::AreaTransmissionCommand(c)
                if matches!(
                    c.mode,
                    AreaTransferMode::UploadComplete | AreaTransferMode::UploadCompleteStaged
                ) =>
            {
                Some(Self {
                    message_type: MessageType::AreaTransmissionCommand,
                    mode: c.mode as u8,
                    mission_id: c.mission_id,
                    count: c.loop_count.map(u16::from),
                    checksum: c.area_checksum(),
                })
            }
            _ => None,
        }
    }
}

/// How a closer was answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClosingAnswer {
    /// By #17000: accepted (type 2) or refused with the reason (type 3). #13000 closers.
    Acknowledgement(Result<(), Reason>),
    /// By #3012 (ICD §5.3 step 3): the loop count of the active list and valid, or invalid with
    /// the reason. #2011 closers.
    AreaStatus {
        /// Areas in the active list (0 when invalid).
        loop_count: u8,
        /// Valid, or why not.
        outcome: Result<(), Reason>,
    },
}

/// Which kind of list a transfer carries, for the memory of its closers: missions (#13000,
/// #13001, #13002, #13006) or areas (#2011, #2012).
fn kind(message_type: MessageType) -> Option<usize> {
    match message_type {
        MessageType::MissionTransferCommand
        | MessageType::UaRoute
        | MessageType::UaPositionWaypoint
        | MessageType::VehicleSpecificWaypoint => Some(0),
        MessageType::AreaTransmissionCommand | MessageType::AreaPolygonLoopSegment => Some(1),
        _ => None,
    }
}

/// The last closer answered of each kind of list, and its answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CloserMemory {
    /// `[missions, areas]`.
    last: [Option<(Closer, ClosingAnswer)>; 2],
}

impl CloserMemory {
    /// Nothing remembered.
    pub const fn new() -> Self {
        Self { last: [None; 2] }
    }

    /// The answer to give again when `closer` is the closer of its kind answered last.
    pub fn repeat(&self, closer: &Closer) -> Option<ClosingAnswer> {
        kind(closer.message_type)
            .and_then(|k| self.last.get(k).copied().flatten())
            .filter(|(last, _)| last == closer)
            .map(|(_, answer)| answer)
    }

    /// `closer` was answered with `answer`.
    pub fn remember(&mut self, closer: Closer, answer: ClosingAnswer) {
        if let Some(slot) = kind(closer.message_type).and_then(|k| self.last.get_mut(k)) {
            *slot = Some((closer, answer));
        }
    }

    /// `message`, an opener or a data message, was accepted: the closer of its kind is
    /// forgotten (an opener or data message of the other kind leaves it, ICD §11).
    pub fn accepted(&mut self, message: &Message) {
        if let Some(slot) = kind(message.message_type()).and_then(|k| self.last.get_mut(k)) {
            *slot = None;
        }
    }

    /// An active list changed otherwise: both are forgotten.
    pub fn forget(&mut self) {
        self.last = [None; 2];
    }

    /// A staged mission was activated (ICD §8): the closers of the active lists (#13000 mode 2,
    /// #2011 mode 2) are forgotten, their "valid and active" no longer true; a staged closer's
    /// (mode 8, mode 7) stays, as the list it stored is still staged. So the area closer whose
    /// answer was lost still gets it when the activation the GCS sent behind it (ICD §10.3) was
    /// carried out first.
    pub fn activated(&mut self) {
        use missionlink_interfaces::wire::{AreaTransferMode, MissionPlanMode};
        for slot in &mut self.last {
            let staged = slot.is_some_and(|(closer, _)| {
                closer.mode == MissionPlanMode::StageMission as u8
                    && closer.message_type == MessageType::MissionTransferCommand
                    || closer.mode == AreaTransferMode::UploadCompleteStaged as u8
                        && closer.message_type == MessageType::AreaTransmissionCommand
            });
            if !staged {
                *slot = None;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::sender::{area_request, mission_command};
    use missionlink_interfaces::wire::{AreaTransferMode, MissionPlanMode, Timestamp};

    fn transmit(n: u16) -> Message {
        mission_command(MissionPlanMode::TransmitMission, Some(n), None)
    }

    #[test]
    fn a_closer_is_its_content_not_its_time_stamp() {
        let first = transmit(3);
        let mut retry = first.clone();
        retry.set_time_stamp(Timestamp::from_millis(1_000).unwrap());
        assert_eq!(Closer::of(&first), Closer::of(&retry));
        assert_ne!(Closer::of(&first), Closer::of(&transmit(4)));
        let mut with_checksum = first.clone();
        if let Message::MissionTransferCommand(c) = &mut with_checksum {
            c.mission_checksum = Some(Checksum::new(0x1234_5678));
        }
        assert_ne!(
            Closer::of(&first),
            Closer::of(&with_checksum),
            "the checksum counts"
        );
        let area_closer = area_request(AreaTransferMode::UploadComplete, None);
        assert!(Closer::of(&area_closer).is_some());
        assert_ne!(Closer::of(&first), Closer::of(&area_closer));
        for not_a_closer in [
            mission_command(MissionPlanMode::ClearMission, None, None),
            area_request(AreaTransferMode::InitiateUpload, None),
        ] {
            assert_eq!(Closer::of(&not_a_closer), None, "{not_a_closer}");
        }
    }

    #[test]
    fn the_memory_repeats_the_last_answer_until_it_forgets() {
        let mut memory = CloserMemory::new();
        let closer = Closer::of(&transmit(3)).unwrap();
        assert_eq!(memory.repeat(&closer), None);
        let refused = ClosingAnswer::Acknowledgement(Err(Reason::BrokenChain));
        memory.remember(closer, refused);
        assert_eq!(memory.repeat(&closer), Some(refused), "a refusal too");
        let other = Closer::of(&transmit(4)).unwrap();
        assert_eq!(memory.repeat(&other), None);
        memory.forget();
        assert_eq!(memory.repeat(&closer), None);
    }

    /// ICD §10.3, §11: the area opener sent beside the mission upload leaves the mission
    /// closer's memory; a mission message ends it; each kind keeps its own.
    #[test]
    fn each_kind_of_list_has_its_own_memory() {
        let mut memory = CloserMemory::new();
        let mission = Closer::of(&transmit(3)).unwrap();
        let areas = Closer::of(&area_request(AreaTransferMode::UploadComplete, None)).unwrap();
        let valid = ClosingAnswer::Acknowledgement(Ok(()));
        let area_valid = ClosingAnswer::AreaStatus {
            loop_count: 1,
            outcome: Ok(()),
        };
        memory.remember(mission, valid);
        memory.remember(areas, area_valid);
        memory.accepted(&area_request(AreaTransferMode::InitiateUpload, None));
        assert_eq!(memory.repeat(&mission), Some(valid));
        assert_eq!(memory.repeat(&areas), None);
        memory.remember(areas, area_valid);
        memory.accepted(&mission_command(MissionPlanMode::ClearMission, None, None));
        assert_eq!(memory.repeat(&mission), None);
        assert_eq!(memory.repeat(&areas), Some(area_valid));
        memory.forget();
        assert_eq!(memory.repeat(&areas), None);
    }

    /// An activation ends the memory of the active lists' closers, not of the staged ones.
    #[test]
    fn an_activation_leaves_the_staged_closers() {
        let id = Some(Text::new("next").unwrap());
        let staged_mission =
            Closer::of(&mission_command(MissionPlanMode::StageMission, Some(3), id)).unwrap();
        let mut staged_areas = area_request(AreaTransferMode::UploadCompleteStaged, None);
        if let Message::AreaTransmissionCommand(c) = &mut staged_areas {
            c.mission_id = id;
        }
        let staged_areas = Closer::of(&staged_areas).unwrap();
        let valid = ClosingAnswer::Acknowledgement(Ok(()));
        let area_valid = ClosingAnswer::AreaStatus {
            loop_count: 1,
            outcome: Ok(()),
        };
        let mut memory = CloserMemory::new();
        memory.remember(staged_mission, valid);
        memory.remember(staged_areas, area_valid);
        memory.activated();
        assert_eq!(memory.repeat(&staged_mission), Some(valid));
        assert_eq!(memory.repeat(&staged_areas), Some(area_valid));
        let active = Closer::of(&transmit(3)).unwrap();
        let active_areas =
            Closer::of(&area_request(AreaTransferMode::UploadComplete, None)).unwrap();
        memory.remember(active, valid);
        memory.remember(active_areas, area_valid);
        memory.activated();
        assert_eq!(memory.repeat(&active), None);
        assert_eq!(memory.repeat(&active_areas), None);
    }
}
