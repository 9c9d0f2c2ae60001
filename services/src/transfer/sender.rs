//! The sender of a transfer, one implementation for both directions (paper §3.2, inverted use;
//! ICD §5.6): the GCS uploads with it what the FCC downloads with it. A transfer is a script of
//! messages sent one at a time, each after the answer to the one before (ICD §5), through the
//! one timeout-and-retry mechanism of [`crate::link::retry`].
//!
//! | script | sent by | messages (ICD) |
//! |---|---|---|
//! | mission upload | GCS | [#13000 clear], #13006 take-off, #13002 (+ #13006 RF) ..., #13001, #13000 transmit (§5.1) |
//! | mission download | FCC | #13006 take-off, #13002 (+ #13006 RF) ..., #13001, #14000 complete (§5.2) |
//! | area upload | GCS | #2011 initiate upload, #2012 ..., #2011 upload complete (§5.3) |
//! | area download | FCC | #3013 ready, #2012 ..., #2011 download complete (§5.4) |
//! | mission clear | GCS | #13000 clear, #13000 transmit with 0 waypoints |
//! | mission report | FCC | #50001 for the active lists, then per staged mission (§8) |
//! | request | GCS | one message: download requests, report request, clear areas, execute |
//!
//! A script with a checksum (ICD §11) puts it into its closer: the GCS's transmit and upload
//! complete toward an edition-2 FCC, the FCC's #14000 and #2011 mode 4 to an edition-2 request.

use core::time::Duration;

use missionlink_interfaces::capacity::MAX_REPORT_ENTRIES;
use missionlink_interfaces::wire::{
    AreaDownloadStatus, AreaTransferMode, AreaTransmissionCommand, AreaTransmissionStatus,
    Checksum, Message, MissionPlanMode, MissionReport, MissionTransferCommand,
    MissionUploadDownloadStatus, Reason, Timestamp, TransferStatus, WindowOrChecksum,
};

use crate::link::endpoint::Endpoint;
use crate::link::retry::{Exchange, ExchangeError, Outcome};
use crate::link::time::Instant;
use crate::transfer::areas::AreaList;
use crate::transfer::mission::Mission;

/// What a transfer sends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Script {
    /// GCS to FCC (ICD §5.1). Without `clear`, an edit: only the waypoints of `mission` change.
    MissionUpload {
        /// The mission.
        mission: Mission,
        /// Start with #13000 mode 1 clear.
        clear: bool,
        /// For the transmit (toward an edition-2 FCC).
        checksum: Option<Checksum>,
    },
    /// FCC to GCS (ICD §5.2).
    MissionDownload {
        /// The active mission.
        mission: Mission,
        /// For the #14000 (to an edition-2 request).
        checksum: Option<Checksum>,
    },
    /// GCS to FCC (ICD §5.3).
    AreaUpload {
        /// The area list.
        list: AreaList,
        /// For the upload complete (toward an edition-2 FCC).
        checksum: Option<Checksum>,
    },
    /// FCC to GCS (ICD §5.4): the #3013 that answers the GCS's request opens it.
    AreaDownload {
        /// The active area list.
        list: AreaList,
        /// For the download complete (to an edition-2 request).
        checksum: Option<Checksum>,
    },
    /// FCC to GCS (ICD §8): the entries of the report, in order, each acknowledged.
    MissionReport {
        /// One #50001 per entry, Report Index and Count set.
        entries: heapless::Vec<MissionReport, MAX_REPORT_ENTRIES>,
    },
    /// GCS to FCC: #13000 mode 1 clear, then #13000 mode 2 with Waypoint Number 0, which
    /// activates the empty list (see [`crate::mission_data_handling`]).
    MissionClear,
    /// One message and its answer.
    Request(Message),
}

fn ts0() -> Timestamp {
    Timestamp::default()
}

fn area_command(mode: AreaTransferMode, list: &AreaList, checksum: Option<Checksum>) -> Message {
    AreaTransmissionCommand {
        time_stamp: ts0(),
        mode,
        loop_count: Some(list.areas.len() as u8),
        area_id: None,
        safety_offset: Some(list.safety_offset),
        activity_id: None,
        mission_id: None,
        window_or_checksum: checksum.map(WindowOrChecksum::AreaChecksum),
    }
    .into()
}

impl Script {
    /// Messages the script sends.
    pub fn len(&self) -> usize {
        match self {
            Self::MissionUpload { mission, clear, .. } => {
                usize::from(*clear) + mission.message_count() + 1
            }
            Self::MissionDownload { mission, .. } => mission.message_count() + 1,
            Self::AreaUpload { list, .. } | Self::AreaDownload { list, .. } => list.areas.len() + 2,
            Self::MissionReport { entries } => entries.len(),
            Self::MissionClear => 2,
            Self::Request(_) => 1,
        }
    }

    /// Whether the script sends nothing (never: every script has at least one message).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Message `index` of the script, time stamp not yet set.
    pub fn message(&self, index: usize) -> Option<Message> {
        match self {
            Self::MissionUpload {
                mission,
                clear,
                checksum,
            } => {
                let body = if *clear {
                    if index == 0 {
                        return Some(mission_command(MissionPlanMode::ClearMission, None, None));
                    }
                    index - 1
                } else {
                    index
                };
                mission.messages().nth(body).or_else(|| {
                    (body == mission.message_count()).then(|| {
                        MissionTransferCommand {
                            mission_checksum: *checksum,
                            ..transfer_command(
                                MissionPlanMode::TransmitMission,
                                Some(mission.waypoints.len() as u16),
                                mission.mission_id,
                            )
                        }
                        .into()
                    })
                })
            }
            Self::MissionDownload { mission, checksum } => {
                mission.messages().nth(index).or_else(|| {
                    (index == mission.message_count()).then(|| {
                        MissionUploadDownloadStatus {
                            time_stamp: ts0(),
                            mission_id: mission.mission_id,
                            status: TransferStatus::Complete,
                            percent_complete: Some(100),
                            waypoint_request: None,
                            mode: Some(MissionPlanMode::ReceiveMission),
                            reason: Some(Reason::None),
                            mission_checksum: *checksum,
                        }
                        .into()
                    })
                })
            }
            Self::AreaUpload { list, checksum } | Self::AreaDownload { list, checksum } => {
                let n = list.areas.len();
                match index {
                    0 if matches!(self, Self::AreaUpload { .. }) => {
                        Some(area_command(AreaTransferMode::InitiateUpload, list, None))
                    }
                    0 => Some(
                        AreaTransmissionStatus {
                            time_stamp: ts0(),
                            area_id: 0,
                            loop_count: n as u8,
                            safety_offset: list.safety_offset,
                            status: AreaDownloadStatus::Ready,
                        }
                        .into(),
                    ),
                    i if i <= n => list.areas.get(i - 1).cloned().map(Message::from),
                    i if i == n + 1 => Some(area_command(
                        if matches!(self, Self::AreaUpload { .. }) {
                            AreaTransferMode::UploadComplete
                        } else {
                            AreaTransferMode::DownloadComplete
                        },
                        list,
                        *checksum,
                    )),
                    _ => None,
                }
            }
            Self::MissionClear => match index {
                0 => Some(mission_command(MissionPlanMode::ClearMission, None, None)),
                1 => Some(mission_command(
                    MissionPlanMode::TransmitMission,
                    Some(0),
                    None,
                )),
                _ => None,
            },
            Self::MissionReport { entries } => entries.get(index).copied().map(Message::from),
            Self::Request(m) => (index == 0).then(|| m.clone()),
        }
    }

    /// The message that tells the peer the transfer is abandoned, sent once without waiting for
    /// an answer: #13000 mode 5 and #2011 mode 5 cancel, #14000 aborted for a mission download.
    fn abandon_message(&self, reason: Reason) -> Option<Message> {
        match self {
            Self::MissionUpload { .. } | Self::MissionClear => {
                Some(mission_command(MissionPlanMode::CancelTransfer, None, None))
            }
            Self::MissionDownload { mission, .. } => Some(
                MissionUploadDownloadStatus {
                    time_stamp: ts0(),
                    mission_id: mission.mission_id,
                    status: TransferStatus::Aborted,
                    percent_complete: None,
                    waypoint_request: None,
                    mode: Some(MissionPlanMode::ReceiveMission),
                    reason: Some(reason),
                    mission_checksum: None,
                }
                .into(),
            ),
            Self::AreaUpload { .. } | Self::AreaDownload { .. } => {
                Some(area_request(AreaTransferMode::Cancel, None))
            }
            // The report is only the FCC's answer: the GCS asks again if it wants it.
            Self::MissionReport { .. } | Self::Request(_) => None,
        }
    }
}

/// A #13000 of `mode`.
pub fn mission_command(
    mode: MissionPlanMode,
    waypoint_number: Option<u16>,
    mission_id: Option<missionlink_interfaces::wire::Text<20>>,
) -> Message {
    transfer_command(mode, waypoint_number, mission_id).into()
}

/// A #13000 of `mode` without the extension fields, to set them on.
pub fn transfer_command(
    mode: MissionPlanMode,
    waypoint_number: Option<u16>,
    mission_id: Option<missionlink_interfaces::wire::Text<20>>,
) -> MissionTransferCommand {
    MissionTransferCommand {
        time_stamp: ts0(),
        mission_id,
        mode,
        waypoint_number,
        route_id: None,
        activity_id: None,
        transfer_window: None,
        mission_checksum: None,
    }
}

/// A #2011 of `mode` that carries no list: cancel, clear areas, or the download request (which
/// names the area to start from, ICD §5.4).
pub fn area_request(mode: AreaTransferMode, area_id: Option<u16>) -> Message {
    area_transfer_command(mode, area_id).into()
}

/// A #2011 of `mode` that carries no list, without the extension fields, to set them on.
pub fn area_transfer_command(
    mode: AreaTransferMode,
    area_id: Option<u16>,
) -> AreaTransmissionCommand {
    AreaTransmissionCommand {
        time_stamp: ts0(),
        mode,
        loop_count: None,
        area_id,
        safety_offset: None,
        activity_id: None,
        mission_id: None,
        window_or_checksum: None,
    }
}

/// What became of a transfer after a message or a timeout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SenderEvent {
    /// Message `sent` of `total` was answered; the next one is on its way.
    Progress {
        /// Messages answered.
        sent: usize,
        /// Messages in the script.
        total: usize,
    },
    /// Every message was answered; the answer to the last one.
    Completed(Message),
    /// A message failed twice; the transfer is abandoned and the peer told so.
    Failed(ExchangeError),
}

/// A transfer in progress.
#[derive(Debug, Clone)]
pub struct TransferSender {
    script: Script,
    next: usize,
    exchange: Exchange,
}

impl TransferSender {
    /// Starts sending `script` at `now`: its first message goes out.
    pub fn start(
        script: Script,
        ack_timeout: Duration,
        endpoint: &mut Endpoint,
        now: Instant,
    ) -> Self {
        let mut sender = Self {
            script,
            next: 0,
            exchange: Exchange::new(ack_timeout),
        };
        sender.send_next(endpoint, now);
        sender
    }

    fn send_next(&mut self, endpoint: &mut Endpoint, now: Instant) -> bool {
        match self.script.message(self.next) {
            Some(m) => {
                self.exchange.send(endpoint, now, m);
                self.next += 1;
                true
            }
            None => false,
        }
    }

    /// The script.
    pub fn script(&self) -> &Script {
        &self.script
    }

    /// (messages answered, messages in the script).
    pub fn progress(&self) -> (usize, usize) {
        (self.next.saturating_sub(1), self.script.len())
    }

    /// When [`TransferSender::handle_timeout`] must be called.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.exchange.poll_timeout()
    }

    /// Offers `message` as the answer to the outstanding message; `None` when it is not one.
    pub fn handle_answer(
        &mut self,
        endpoint: &mut Endpoint,
        now: Instant,
        message: &Message,
    ) -> Option<SenderEvent> {
        let outcome = self.exchange.handle_answer(endpoint, now, message)?;
        self.after(endpoint, now, outcome)
    }

    /// The ack timeout may have passed.
    pub fn handle_timeout(&mut self, endpoint: &mut Endpoint, now: Instant) -> Option<SenderEvent> {
        let outcome = self.exchange.handle_timeout(endpoint, now)?;
        self.after(endpoint, now, outcome)
    }

    fn after(
        &mut self,
        endpoint: &mut Endpoint,
        now: Instant,
        outcome: Outcome,
    ) -> Option<SenderEvent> {
        match outcome {
            Outcome::Accepted(answer) => {
                if self.send_next(endpoint, now) {
                    let (sent, total) = self.progress();
                    Some(SenderEvent::Progress { sent, total })
                } else {
                    Some(SenderEvent::Completed(answer))
                }
            }
            Outcome::Retried(_) => None,
            Outcome::Failed(error) => {
                self.abandon(endpoint, now, error.reason().unwrap_or(Reason::None));
                Some(SenderEvent::Failed(error))
            }
        }
    }

    /// Abandons the transfer and tells the peer, once, without waiting for an answer.
    pub fn abandon(&mut self, endpoint: &mut Endpoint, now: Instant, reason: Reason) {
        self.exchange.cancel();
        if let Some(m) = self.script.abandon_message(reason) {
            endpoint.send(now, m, false);
        }
    }

    /// Drops the transfer without telling the peer (the peer cancelled it).
    pub fn cancel(&mut self) {
        self.exchange.cancel();
    }
}
