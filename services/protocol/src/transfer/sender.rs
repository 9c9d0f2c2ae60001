//! The sender of a transfer, one implementation for both directions (paper §3.2, inverted use;
//! ICD §5.6): the GCS uploads with it what the FCC downloads with it. A transfer is a script of
//! messages sent one at a time, each after the answer to the one before (ICD §5), through the
//! one timeout-and-retry mechanism of [`crate::link::retry`].
//!
//! | script | sent by | messages (ICD) |
//! |---|---|---|
//! | mission upload | GCS | [#13000 clear or load buffer], #13006 take-off, #13002 (+ #13006 RF) ..., #13001, #13000 transmit or stage (§5.1, §8) |
//! | mission download | FCC | #13006 take-off, #13002 (+ #13006 RF) ..., #13001, #14000 complete (§5.2) |
//! | area upload | GCS | #2011 initiate upload, #2012 ..., #2011 upload complete or stage (§5.3, §8) |
//! | area download | FCC | #3013 ready, #2012 ..., #2011 download complete (§5.4) |
//! | mission clear | GCS | #13000 clear, #13000 transmit with 0 waypoints |
//! | mission report | FCC | #50001 for the active lists, then per staged mission (§8) |
//! | request | GCS | one message: download requests, report request, clear areas, execute, delete and activate a staged mission |
//!
//! The uploads serve the active lists and the staged missions of ICD §8 alike: only the opener
//! ([`Opener`]) and the closer (its [`Target`]) differ, and an edit sends a selection of the
//! mission's messages (the waypoint buffer keeps the rest, ICD §8).
//!
//! A script with a checksum (ICD §11) puts it into its closer: the GCS's transmit and upload
//! complete toward an edition-2 FCC, the FCC's #14000 and #2011 mode 4 to an edition-2 request.

use core::time::Duration;

use missionlink_interfaces::capacity::MAX_REPORT_ENTRIES;
use missionlink_interfaces::wire::{
    AreaDownloadStatus, AreaTransferMode, AreaTransmissionCommand, AreaTransmissionStatus,
    Checksum, ExecuteCommand, Message, MissionExecuteCommand, MissionPlanMode, MissionReport,
    MissionTransferCommand, MissionUploadDownloadStatus, Reason, Text, Timestamp, TransferStatus,
    TransferWindow, WindowOrChecksum,
};

use crate::link::endpoint::Endpoint;
use crate::link::retry::{Exchange, ExchangeError, Outcome};
use crate::link::time::Instant;
use crate::transfer::areas::AreaList;
use crate::transfer::mission::Mission;
use crate::transfer::staged::MissionId;

/// Which lists a transfer writes or reads (ICD §8): the active lists, or a staged mission.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The active waypoint list and area list: closers #13000 mode 2 and #2011 mode 2,
    /// downloads by #13000 mode 3 and #2011 mode 3.
    Active,
    /// The staged mission of this ID: closers #13000 mode 8 and #2011 mode 7, downloads by
    /// #13000 mode 9 and #2011 mode 8.
    Staged(MissionId),
}

impl Target {
    /// The Mission ID field that names the target: empty for the active lists (ICD §8, #13000
    /// mode 10 and the report).
    pub fn mission_id_field(&self) -> Text<20> {
        match self {
            Self::Active => Text::default(),
            Self::Staged(id) => id.text(),
        }
    }
}

impl core::fmt::Display for Target {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Active => f.write_str("the active lists"),
            Self::Staged(id) => write!(f, "staged mission {id:?}"),
        }
    }
}

/// What a mission upload sends before the mission's messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Opener {
    /// Nothing: the waypoint buffer holds what it held (an edition-1 edit, ICD §5.1, §8).
    None,
    /// #13000 mode 1 clear: empties the buffer and the active list (ICD §5.1).
    Clear,
    /// #13000 mode 10 (ICD §8): fills the buffer with the waypoint list of the target (the
    /// active list, or a staged mission's), or empties it when the target has none.
    LoadBuffer(Target),
}

/// What a transfer sends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Script {
    /// GCS to FCC (ICD §5.1; §8 for a staged mission): the opener, the mission's messages (all,
    /// or a selection for an edit), the closer of `target` (#13000 mode 2 or mode 8).
    MissionUpload {
        /// The mission.
        mission: Mission,
        /// What goes first.
        opener: Opener,
        /// For an edit: the indices into [`Mission::messages`] to send, ascending; `None`
        /// sends every message.
        selection: Option<Vec<u16>>,
        /// Whose closer ends it: the active list (mode 2) or a staged mission (mode 8).
        target: Target,
        /// For the closer (toward an edition-2 FCC).
        checksum: Option<Checksum>,
    },
    /// FCC to GCS (ICD §5.2).
    MissionDownload {
        /// The active mission.
        mission: Mission,
        /// For the #14000 (to an edition-2 request).
        checksum: Option<Checksum>,
    },
    /// GCS to FCC (ICD §5.3; §8 for a staged mission, closed by #2011 mode 7).
    AreaUpload {
        /// The area list.
        list: AreaList,
        /// Whose closer ends it: the active list (mode 2) or a staged mission (mode 7).
        target: Target,
        /// For the upload complete (toward an edition-2 FCC).
        checksum: Option<Checksum>,
    },
    /// FCC to GCS (ICD §5.4): the #3013 that answers the GCS's request opens it.
    AreaDownload {
        /// The areas sent: the active list, a staged one, or the one area requested.
        list: AreaList,
        /// The Area ID requested (#3013 field 1: as requested, 0 = all).
        area_id: u16,
        /// For the download complete (to an edition-2 request).
        checksum: Option<Checksum>,
    },
    /// FCC to GCS (ICD §8): the entries of the report, in order, each acknowledged.
    MissionReport {
        /// One #50001 per entry, Report Index and Count set.
        entries: heapless::Vec<MissionReport, MAX_REPORT_ENTRIES>,
    },
    /// One message and its answer.
    Request(Message),
}

fn ts0() -> Timestamp {
    Timestamp::default()
}

fn area_command(
    mode: AreaTransferMode,
    list: &AreaList,
    mission_id: Option<Text<20>>,
    checksum: Option<Checksum>,
) -> Message {
    AreaTransmissionCommand {
        time_stamp: ts0(),
        mode,
        loop_count: Some(list.areas.len() as u8),
        area_id: None,
        safety_offset: Some(list.safety_offset),
        activity_id: None,
        mission_id,
        window_or_checksum: checksum.map(WindowOrChecksum::AreaChecksum),
    }
    .into()
}

/// The closer of a mission upload to `target`: #13000 mode 2 (transmit, the plan's Mission ID
/// informational) or mode 8 (stage under the Mission ID), with the count and the checksum.
fn mission_closer(mission: &Mission, target: Target, checksum: Option<Checksum>) -> Message {
    let (mode, mission_id) = match target {
        Target::Active => (MissionPlanMode::TransmitMission, mission.mission_id),
        Target::Staged(id) => (MissionPlanMode::StageMission, Some(id.text())),
    };
    MissionTransferCommand {
        mission_checksum: checksum,
        ..transfer_command(mode, Some(mission.waypoints.len() as u16), mission_id)
    }
    .into()
}

impl Script {
    /// Messages the script sends.
    pub fn len(&self) -> usize {
        match self {
            Self::MissionUpload {
                mission,
                opener,
                selection,
                ..
            } => {
                usize::from(*opener != Opener::None)
                    + selection.as_ref().map_or(mission.message_count(), Vec::len)
                    + 1
            }
            Self::MissionDownload { mission, .. } => mission.message_count() + 1,
            Self::AreaUpload { list, .. } | Self::AreaDownload { list, .. } => list.areas.len() + 2,
            Self::MissionReport { entries } => entries.len(),
            Self::Request(_) => 1,
        }
    }

    /// The indices of the script's data messages (ICD §10.2), which may be in flight together:
    /// between the opener and the closer of an upload or a download. Reports and single
    /// requests have none.
    pub fn data_messages(&self) -> core::ops::Range<usize> {
        let len = self.len();
        match self {
            Self::MissionUpload { opener, .. } => {
                let first = usize::from(*opener != Opener::None);
                first..len.saturating_sub(1)
            }
            Self::MissionDownload { .. } => 0..len.saturating_sub(1),
            Self::AreaUpload { .. } | Self::AreaDownload { .. } => 1..len.saturating_sub(1),
            Self::MissionReport { .. } | Self::Request(_) => 0..0,
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
                opener,
                selection,
                target,
                checksum,
            } => {
                let body = match opener {
                    Opener::None => index,
                    _ if index > 0 => index - 1,
                    Opener::Clear => {
                        return Some(mission_command(MissionPlanMode::ClearMission, None, None));
                    }
                    Opener::LoadBuffer(from) => return Some(load_buffer(*from)),
                };
                let (data, count) = match selection {
                    Some(selection) => (
                        selection
                            .get(body)
                            .and_then(|i| mission.messages().nth(usize::from(*i))),
                        selection.len(),
                    ),
                    None => (mission.messages().nth(body), mission.message_count()),
                };
                data.or_else(|| {
                    (body == count).then(|| mission_closer(mission, *target, *checksum))
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
            Self::AreaUpload { list, checksum, .. } | Self::AreaDownload { list, checksum, .. } => {
                let n = list.areas.len();
                match index {
                    0 if matches!(self, Self::AreaUpload { .. }) => Some(area_command(
                        AreaTransferMode::InitiateUpload,
                        list,
                        None,
                        None,
                    )),
                    0 => Some(
                        AreaTransmissionStatus {
                            time_stamp: ts0(),
                            area_id: match self {
                                Self::AreaDownload { area_id, .. } => *area_id,
                                _ => 0,
                            },
                            loop_count: n as u8,
                            safety_offset: list.safety_offset,
                            status: AreaDownloadStatus::Ready,
                        }
                        .into(),
                    ),
                    i if i <= n => list.areas.get(i - 1).cloned().map(Message::from),
                    i if i == n + 1 => {
                        let (mode, mission_id) = match self {
                            Self::AreaUpload {
                                target: Target::Staged(id),
                                ..
                            } => (AreaTransferMode::UploadCompleteStaged, Some(id.text())),
                            Self::AreaUpload { .. } => (AreaTransferMode::UploadComplete, None),
                            _ => (AreaTransferMode::DownloadComplete, None),
                        };
                        Some(area_command(mode, list, mission_id, *checksum))
                    }
                    _ => None,
                }
            }
            Self::MissionReport { entries } => entries.get(index).copied().map(Message::from),
            Self::Request(m) => (index == 0).then(|| m.clone()),
        }
    }

    /// The message that tells the peer the transfer is abandoned, sent once without waiting for
    /// an answer: #13000 mode 5 and #2011 mode 5 cancel, #14000 aborted for a mission download.
    fn abandon_message(&self, reason: Reason) -> Option<Message> {
        match self {
            Self::MissionUpload { .. } => {
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

/// #13000 mode 10 (ICD §8): load the waypoint buffer from `target`'s waypoint list (empty
/// Mission ID: the active list), or empty it when the target has none.
pub fn load_buffer(target: Target) -> Message {
    mission_command(
        MissionPlanMode::LoadWaypointBuffer,
        None,
        Some(target.mission_id_field()),
    )
}

/// #13000 mode 6 (ICD §8): delete the staged mission `id`.
pub fn delete_staged(id: MissionId) -> Message {
    mission_command(MissionPlanMode::DeleteStagedMission, None, Some(id.text()))
}

/// #50000 command 4 (ICD §8): make the staged mission `id` the active waypoint and area lists
/// in one step.
pub fn activate_staged(id: MissionId) -> Message {
    MissionExecuteCommand {
        time_stamp: ts0(),
        command: ExecuteCommand::ActivateStaged,
        mission_id: Some(id.text()),
    }
    .into()
}

/// The request of a mission download from `target`: #13000 mode 3 (active) or mode 9 (staged),
/// with the Transfer Window when given (an edition-2 request, ICD §10.2).
pub fn mission_download_request(target: Target, window: Option<TransferWindow>) -> Message {
    let command = match target {
        Target::Active => transfer_command(MissionPlanMode::ReceiveMission, None, None),
        Target::Staged(id) => {
            transfer_command(MissionPlanMode::ReceiveStagedMission, None, Some(id.text()))
        }
    };
    MissionTransferCommand {
        transfer_window: window,
        ..command
    }
    .into()
}

/// The request of an area download (all areas) from `target`: #2011 mode 3 (active) or mode 8
/// (staged), with the Transfer Window when given (ICD §10.2).
pub fn area_download_request(target: Target, window: Option<TransferWindow>) -> Message {
    let (mode, mission_id) = match target {
        Target::Active => (AreaTransferMode::InitiateDownload, None),
        Target::Staged(id) => (AreaTransferMode::InitiateStagedDownload, Some(id.text())),
    };
    AreaTransmissionCommand {
        mission_id,
        window_or_checksum: window.map(WindowOrChecksum::TransferWindow),
        ..area_transfer_command(mode, Some(0))
    }
    .into()
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

/// Data messages in flight at most (ICD §10.2: receivers of edition 2 accept up to 32).
pub const MAX_WINDOW: usize = 32;

/// One message of the script in flight.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    /// Its index in the script (to send it again, and to tell data messages from the rest).
    index: usize,
    exchange: Exchange,
}

/// A transfer in progress: the opener and the closer stop-and-wait, up to `window` data
/// messages in flight between them, each with its own ack timeout and one retry (ICD §5,
/// §10.2). The closer goes out only when every data message was accepted. Window 1 is
/// edition 1, message for message.
#[derive(Debug, Clone)]
pub struct TransferSender {
    script: Script,
    /// The next message of the script to send.
    next: usize,
    /// Messages of the script answered with an acceptance.
    answered: usize,
    window: usize,
    in_flight: heapless::Vec<InFlight, MAX_WINDOW>,
    ack_timeout: Duration,
}

impl TransferSender {
    /// Starts sending `script` at `now`, one message at a time (ICD §5): its first message
    /// goes out.
    pub fn start(
        script: Script,
        ack_timeout: Duration,
        endpoint: &mut Endpoint,
        now: Instant,
    ) -> Self {
        Self::start_windowed(script, 1, ack_timeout, endpoint, now)
    }

    /// Starts sending `script` at `now` with up to `window` data messages in flight (ICD
    /// §10.2; 0 counts as 1, above [`MAX_WINDOW`] as [`MAX_WINDOW`]).
    pub fn start_windowed(
        script: Script,
        window: usize,
        ack_timeout: Duration,
        endpoint: &mut Endpoint,
        now: Instant,
    ) -> Self {
        let mut sender = Self {
            script,
            next: 0,
            answered: 0,
            window: window.clamp(1, MAX_WINDOW),
            in_flight: heapless::Vec::new(),
            ack_timeout,
        };
        sender.fill(endpoint, now);
        sender
    }

    /// Sends what may go now: data messages while the window has room and no opener waits;
    /// an opener or a closer only when nothing is in flight, and then nothing after it until
    /// it is answered.
    fn fill(&mut self, endpoint: &mut Endpoint, now: Instant) {
        let data = self.script.data_messages();
        while self.next < self.script.len() {
            let is_data = data.contains(&self.next);
            let room = if is_data {
                self.in_flight.len() < self.window
                    && self.in_flight.iter().all(|f| data.contains(&f.index))
            } else {
                self.in_flight.is_empty()
            };
            if !room {
                break;
            }
            let Some(message) = self.script.message(self.next) else {
                break;
            };
            let mut exchange = Exchange::new(self.ack_timeout);
            exchange.send(endpoint, now, message);
            // `room` checked the capacity (window <= MAX_WINDOW).
            let _ = self.in_flight.push(InFlight {
                index: self.next,
                exchange,
            });
            self.next += 1;
            if !is_data {
                break;
            }
        }
    }

    /// The script.
    pub fn script(&self) -> &Script {
        &self.script
    }

    /// The window of data messages in flight.
    pub fn window(&self) -> usize {
        self.window
    }

    /// Messages of the script sent so far: first attempts (a retry is the same message again).
    pub fn sent(&self) -> usize {
        self.next
    }

    /// (messages answered, messages in the script).
    pub fn progress(&self) -> (usize, usize) {
        (self.answered, self.script.len())
    }

    /// When [`TransferSender::handle_timeout`] must be called: the earliest ack timeout in
    /// flight.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.in_flight
            .iter()
            .filter_map(|f| f.exchange.poll_timeout())
            .min()
    }

    /// Offers `message` as the answer to a message in flight; `None` when it answers none.
    pub fn handle_answer(
        &mut self,
        endpoint: &mut Endpoint,
        now: Instant,
        message: &Message,
    ) -> Option<SenderEvent> {
        let (slot, outcome) = self
            .in_flight
            .iter_mut()
            .enumerate()
            .find_map(|(i, f)| f.exchange.handle_answer(message).map(|o| (i, o)))?;
        self.after(endpoint, now, slot, outcome)
    }

    /// The ack timeouts due at `now`: retries, or the failure of the transfer.
    pub fn handle_timeout(&mut self, endpoint: &mut Endpoint, now: Instant) -> Option<SenderEvent> {
        let mut slot = 0;
        while slot < self.in_flight.len() {
            let outcome = self
                .in_flight
                .get_mut(slot)
                .and_then(|f| f.exchange.handle_timeout(now));
            if let Some(outcome) = outcome {
                if let Some(event) = self.after(endpoint, now, slot, outcome) {
                    return Some(event);
                }
            }
            slot += 1;
        }
        None
    }

    fn after(
        &mut self,
        endpoint: &mut Endpoint,
        now: Instant,
        slot: usize,
        outcome: Outcome,
    ) -> Option<SenderEvent> {
        match outcome {
            Outcome::Accepted(answer) => {
                if slot < self.in_flight.len() {
                    self.in_flight.swap_remove(slot);
                }
                self.answered += 1;
                self.fill(endpoint, now);
                if self.next >= self.script.len() && self.in_flight.is_empty() {
                    Some(SenderEvent::Completed(answer))
                } else {
                    let (sent, total) = self.progress();
                    Some(SenderEvent::Progress { sent, total })
                }
            }
            Outcome::Retry(_) => {
                if let Some(f) = self.in_flight.get_mut(slot) {
                    match self.script.message(f.index) {
                        Some(message) => f.exchange.resend(endpoint, now, message),
                        // The script gave this message before; it cannot fail to now.
                        None => f.exchange.cancel(),
                    }
                }
                None
            }
            Outcome::Failed(error) => {
                self.abandon(endpoint, now, error.reason().unwrap_or(Reason::None));
                Some(SenderEvent::Failed(error))
            }
        }
    }

    /// Abandons the transfer and tells the peer, once, without waiting for an answer.
    pub fn abandon(&mut self, endpoint: &mut Endpoint, now: Instant, reason: Reason) {
        self.cancel();
        if let Some(m) = self.script.abandon_message(reason) {
            endpoint.send(now, m, false);
        }
    }

    /// Drops the transfer without telling the peer (the peer cancelled it).
    pub fn cancel(&mut self) {
        self.in_flight.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::mission_1;

    fn describe(m: &Message) -> String {
        match m {
            Message::MissionTransferCommand(c) => format!(
                "13000 mode {} {}",
                c.mode as u8,
                c.mission_id.as_ref().map_or("-", |t| t.as_str())
            ),
            Message::AreaTransmissionCommand(c) => format!(
                "2011 mode {} {}",
                c.mode as u8,
                c.mission_id.as_ref().map_or("-", |t| t.as_str())
            ),
            other => format!("{}", other.message_type() as u16),
        }
    }

    fn script(s: &Script) -> Vec<String> {
        assert_eq!(
            (0..).map_while(|i| s.message(i)).count(),
            s.len(),
            "len counts every message"
        );
        (0..s.len())
            .filter_map(|i| s.message(i))
            .map(|m| describe(&m))
            .collect()
    }

    /// ICD §8: the openers and closers of a staged upload name the Mission ID; an edit sends
    /// only its selection between them.
    #[test]
    fn staged_scripts_name_their_mission() {
        let plan = mission_1().assemble().unwrap_or_else(|e| panic!("{e}"));
        let id = MissionId::new("next").unwrap_or_else(|e| panic!("{e}"));
        let staged = Script::MissionUpload {
            mission: plan.mission.clone(),
            opener: Opener::LoadBuffer(Target::Staged(id)),
            selection: None,
            target: Target::Staged(id),
            checksum: None,
        };
        assert_eq!(
            script(&staged),
            [
                "13000 mode 10 next",
                "13006",
                "13002",
                "13001",
                "13000 mode 8 next"
            ]
        );
        let edit = Script::MissionUpload {
            mission: plan.mission.clone(),
            opener: Opener::LoadBuffer(Target::Active),
            selection: Some(vec![1]),
            target: Target::Active,
            checksum: None,
        };
        assert_eq!(
            script(&edit),
            ["13000 mode 10 ", "13002", "13000 mode 2 MEDEVAC-1"]
        );
        let areas = Script::AreaUpload {
            list: plan.areas.clone(),
            target: Target::Staged(id),
            checksum: None,
        };
        assert_eq!(
            script(&areas),
            ["2011 mode 1 -", "2012", "2011 mode 7 next"]
        );
        assert_eq!(
            describe(&area_download_request(Target::Staged(id), None)),
            "2011 mode 8 next"
        );
        assert_eq!(
            describe(&mission_download_request(Target::Staged(id), None)),
            "13000 mode 9 next"
        );
        assert_eq!(describe(&delete_staged(id)), "13000 mode 6 next");
        assert!(matches!(
            activate_staged(id),
            Message::MissionExecuteCommand(c)
                if c.command == ExecuteCommand::ActivateStaged && c.mission_id == Some(id.text())
        ));
    }
}
