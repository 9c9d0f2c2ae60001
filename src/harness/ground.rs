//! The ground played message by message over a rig's links (stop and wait, one retry, ICD §3),
//! for the tests whose subject is the FCC's answers, not the GCS logic's sequences: it sends
//! what the test says, as an edition-1 peer or a third-party GCS would, and signs as the rig's
//! configuration says (ICD §9).

use std::time::Duration;

use missionlink_ground::ground_station::ValidatedPlan;
use missionlink_interfaces::wire::{
    AckType, AreaListStatus, AreaTransferMode, AreaTransmissionCommand, ExecuteCommand,
    MAX_FRAME_LEN, Message, MissionExecuteCommand, MissionPlanMode, Reason, Text, Timestamp,
};
use missionlink_partitions::config::Config;
use missionlink_platform::clock::DriverClock;
use missionlink_platform::keys::LinkSigning;
use missionlink_platform::udp::LinkPair;
use missionlink_protocol::link::endpoint::{Endpoint, Inbound};
use missionlink_protocol::transfer::sender::mission_command;

/// The ground, played message by message over the rig's links.
pub struct Ground {
    endpoint: Endpoint,
    links: LinkPair,
    clock: DriverClock,
    ack_timeout: Duration,
}

impl Ground {
    pub fn new(config: &Config, links: LinkPair) -> Self {
        let signing = LinkSigning::load(&config.signing).unwrap();
        let links = links.with_signer(signing.signer);
        let clock = DriverClock::start();
        let core = missionlink_gcs::gcs_link::gcs_core(&config.link(), clock.utc_at_zero());
        // Answers come on both links; the direct one is read, with a timeout.
        let direct = links.sockets()[0];
        direct.set_nonblocking(false).unwrap();
        Self {
            endpoint: Endpoint::new(core.endpoint),
            links,
            clock,
            ack_timeout: core.ack_timeout,
        }
    }

    /// Sends `message` with "acknowledgement requested" and returns its answer: the #17000 of
    /// the same type and time stamp, or the #3012 to an area closer. After the ack timeout the
    /// message goes once more with a new time stamp (ICD §3).
    pub fn exchange(&mut self, message: Message) -> Message {
        let closes_areas = matches!(&message, Message::AreaTransmissionCommand(c)
            if matches!(c.mode, AreaTransferMode::UploadComplete | AreaTransferMode::UploadCompleteStaged));
        for _attempt in 0..2 {
            let stamp = self.endpoint.send(self.clock.now(), message.clone(), true);
            let mut buf = [0u8; MAX_FRAME_LEN];
            while let Some(frame) = self.endpoint.poll_transmit(&mut buf) {
                self.links.send_both(&buf[..frame.unwrap()]);
            }
            let deadline = std::time::Instant::now() + self.ack_timeout;
            while let Some(answer) = self.receive_until(deadline) {
                let is_answer = match &answer {
                    Message::MessageAcknowledgement(ack) => {
                        ack.original_message_type == message.message_type() as u16
                            && ack.original_time_stamp == stamp
                    }
                    Message::AreaStatusAlert(_) => closes_areas,
                    _ => false,
                };
                if is_answer {
                    return answer;
                }
            }
        }
        panic!("no answer to {message}");
    }

    /// The next fresh message from the FCC, until `deadline`.
    pub fn receive_until(&mut self, deadline: std::time::Instant) -> Option<Message> {
        let direct = self.links.sockets()[0];
        let mut buf = [0u8; 2048];
        loop {
            let left = deadline.checked_duration_since(std::time::Instant::now())?;
            direct
                .set_read_timeout(Some(left.max(Duration::from_millis(1))))
                .unwrap();
            let Ok((len, _)) = direct.recv_from(&mut buf) else {
                continue;
            };
            if let Ok(Inbound::Message { message, .. }) =
                self.endpoint.receive(self.clock.now(), &buf[..len])
            {
                return Some(message);
            }
        }
    }

    /// Sends `message` and expects it accepted (#17000 type 2, or #3012 valid).
    pub fn accepted(&mut self, message: Message) {
        let what = message.to_string();
        match self.exchange(message) {
            Message::MessageAcknowledgement(ack) => assert_eq!(
                ack.ack_type,
                AckType::Completed,
                "{what}: refused, {:?}",
                ack.reject_reason
            ),
            Message::AreaStatusAlert(alert) => assert_eq!(
                alert.status,
                AreaListStatus::Valid,
                "{what}: refused, {:?}",
                alert.reason
            ),
            other => panic!("{what}: answered by {other}"),
        }
    }

    /// Stages `plan` under `id` (ICD §8): #13000 mode 10 (a new mission: the buffer emptied),
    /// the waypoint messages, #13000 mode 8; #2011 mode 1, the #2012 areas, #2011 mode 7.
    pub fn stage(&mut self, id: &str, plan: &ValidatedPlan) {
        let id = Some(Text::new(id).unwrap());
        let opener = mission_command(MissionPlanMode::LoadWaypointBuffer, None, id);
        self.send_lists(plan, opener, MissionPlanMode::StageMission, id);
    }

    /// Sends `plan`, every message accepted: `opener`, the waypoint messages, the #13000 of
    /// `closer` (with `id`); #2011 mode 1, the #2012 areas, and the area closer that goes with
    /// the mission's (mode 7 with `id` when staging, else mode 2).
    fn send_lists(
        &mut self,
        plan: &ValidatedPlan,
        opener: Message,
        closer: MissionPlanMode,
        id: Option<Text<20>>,
    ) {
        self.accepted(opener);
        for m in plan.mission.messages() {
            self.accepted(m);
        }
        let count = plan.mission.waypoints.len() as u16;
        self.accepted(mission_command(closer, Some(count), id));
        let areas = |mode, mission_id| {
            Message::from(AreaTransmissionCommand {
                time_stamp: Timestamp::default(),
                mode,
                loop_count: Some(plan.areas.areas.len() as u8),
                area_id: None,
                safety_offset: Some(plan.areas.safety_offset),
                activity_id: None,
                mission_id,
                window_or_checksum: None,
            })
        };
        self.accepted(areas(AreaTransferMode::InitiateUpload, None));
        for a in &plan.areas.areas {
            self.accepted(a.clone().into());
        }
        let area_closer = match closer {
            MissionPlanMode::StageMission => AreaTransferMode::UploadCompleteStaged,
            _ => AreaTransferMode::UploadComplete,
        };
        self.accepted(areas(area_closer, id));
    }

    /// Sends `message` and returns the reason the FCC refused it with (#17000 type 3), or `None`
    /// when it accepted it.
    pub fn refused(&mut self, message: Message) -> Option<Reason> {
        let what = message.to_string();
        match self.exchange(message) {
            Message::MessageAcknowledgement(ack) => match ack.ack_type {
                AckType::Completed => None,
                _ => Some(ack.reject_reason.unwrap_or(Reason::None)),
            },
            other => panic!("{what}: answered by {other}"),
        }
    }

    /// Uploads `plan` by the paper's sequence as edition 1 sends it (ICD §5.1, §5.3): the clear,
    /// the waypoint messages, the transmit; the area upload.
    pub fn upload(&mut self, plan: &ValidatedPlan) {
        let clear = mission_command(MissionPlanMode::ClearMission, None, None);
        self.send_lists(plan, clear, MissionPlanMode::TransmitMission, None);
    }

    /// Activates staged mission `id` (#50000 command 4).
    pub fn activate(&mut self, id: &str) {
        self.accepted(
            MissionExecuteCommand {
                time_stamp: Timestamp::default(),
                command: ExecuteCommand::ActivateStaged,
                mission_id: Some(Text::new(id).unwrap()),
            }
            .into(),
        );
    }
}
