//! The sender of a transfer, one implementation for both directions (paper §3.2, inverted use;
//! ICD §5.6): the GCS uploads with it what the FCC downloads with it. A transfer is a script of
//! messages sent one at a time, each after the answer to the one before (ICD §5), but for its
//! data messages, up to the window's in flight ([`Window`], ICD §10.2, §10.4), and, paced for
//! ICD §10.3 ([`Pacing`]), for the data behind an unanswered opener and the transfer behind the
//! one before; each through the one timeout-and-retry mechanism of [`crate::link::retry`].
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

use core::borrow::Borrow;
use core::time::Duration;

use missionlink_interfaces::capacity::MAX_REPORT_ENTRIES;
use missionlink_interfaces::wire::{
    self, AreaDownloadStatus, AreaTransferMode, AreaTransmissionCommand, AreaTransmissionStatus,
    Checksum, Envelope, ExecuteCommand, MAX_FRAME_LEN, Message, MissionExecuteCommand,
    MissionPlanMode, MissionReport, MissionTransferCommand, MissionUploadDownloadStatus, Reason,
    TRAILER_LEN, Text, Timestamp, TransferStatus, TransferWindow, WindowOrChecksum,
};

use crate::link::endpoint::{Endpoint, OUTBOX_RESERVE};
use crate::link::retry::{AttemptFailure, Exchange, ExchangeError, Outcome};
use crate::link::time::Instant;
use crate::transfer::areas::AreaList;
use crate::transfer::mission::Mission;
use crate::transfer::staged::MissionId;
use crate::transfer::window::Window;

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

    /// Whether the closer of an upload carries the checksum of the list it closes (ICD §11):
    /// only such a closer may go right behind its data (ICD §10.3), as the receiver then
    /// refuses it whenever a data message is missing.
    pub fn closer_has_checksum(&self) -> bool {
        match self {
            Self::MissionUpload { checksum, .. } | Self::AreaUpload { checksum, .. } => {
                checksum.is_some()
            }
            _ => false,
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

pub use crate::transfer::window::MAX_WINDOW;

/// Messages of a transfer in flight at most: a window of data messages and the opener they
/// were sent behind (ICD §10.3).
const IN_FLIGHT: usize = MAX_WINDOW + 1;

/// How a sender paces what it sends beside its window (ICD §10.2, §10.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Pacing {
    /// ICD §10.3: the data messages go right behind the opener, without waiting for its
    /// answer, and the closer right behind the data, without waiting for theirs (a closer
    /// that overtook one of them is refused and goes again after their answers). Otherwise
    /// (ICD §10.2, and always toward edition 1) each waits.
    pub pipelined: bool,
    /// ICD §10.3: the transfer is sent behind the closer (or the last message) of the one
    /// before it, whose answer is outstanding: its own closer waits for
    /// [`TransferSender::release`], and a message of it refused meanwhile waits for it too.
    pub behind: bool,
}

/// Where the opener of the script is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Opening {
    /// The script has none: its data messages may go from the start (a download, the report).
    Absent,
    /// Sent, not yet accepted; `retried`: its first attempt failed, and its data messages wait
    /// for it (ICD §10.3).
    Pending { retried: bool },
    /// Accepted.
    Accepted,
}

/// One message of the script in flight.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    /// Its index in the script (to send it again, and to tell data messages from the rest).
    index: usize,
    exchange: Exchange,
    /// When its first attempt went: a round trip, if that attempt is the one accepted.
    sent_at: Instant,
    /// Whether it was sent a second time (its answer then says nothing of the round trip,
    /// since it cannot tell which attempt it answers).
    retried: bool,
    /// Refused while what it was sent behind was unanswered (ICD §10.3): its retry waits for
    /// that answer.
    parked: bool,
    /// Its frame's bytes, signature trailer included (the window's rule 3); 0 when the window
    /// does not count bytes.
    bytes: u64,
}

/// A transfer in progress: the opener and the closer stop-and-wait, up to the window's data
/// messages in flight between them, each with its own ack timeout and one retry (ICD §5,
/// §10.2). The closer goes out only when every data message was accepted. Window 1 is
/// edition 1, message for message. [`Pacing`] sends the data behind an unanswered opener, the
/// closer right behind its data and the transfer behind the one before it (ICD §10.3).
///
/// The script is kept as `S`: in place (the default, what the FCC's per-frame path uses, which
/// allocates nothing), or boxed (`TransferSender<Box<Script>>`, the GCS's), so that a sender
/// moves and starts as a few kilobytes instead of the mission's 27: every frame a sender or a
/// script passes through is that much smaller, and a thread's stack touches that much less
/// fresh memory (the ground service runs each request on a thread of its own).
#[derive(Debug, Clone)]
pub struct TransferSender<S = Script> {
    script: S,
    /// The next message of the script to send.
    next: usize,
    /// Messages of the script answered with an acceptance (and not to be sent again).
    answered: usize,
    /// First attempts sent, messages sent again after their opener failed included.
    sent: usize,
    window: Window,
    in_flight: heapless::Vec<InFlight, IN_FLIGHT>,
    ack_timeout: Duration,
    pacing: Pacing,
    opener: Opening,
    /// Data messages (and their bytes) another transfer on the same link has in flight, which
    /// the window counts beside this one's (ICD §10.3: the area upload sent beside the mission
    /// upload's data, ICD §10.4).
    beside: (usize, u64),
}

impl<S: Borrow<Script>> TransferSender<S> {
    /// Starts sending `script` at `now`, one message at a time (ICD §5): its first message
    /// goes out.
    pub fn start(script: S, ack_timeout: Duration, endpoint: &mut Endpoint, now: Instant) -> Self {
        Self::start_windowed(script, 1, ack_timeout, endpoint, now)
    }

    /// Starts sending `script` at `now` with up to `window` data messages in flight (ICD
    /// §10.2; 0 counts as 1, above [`MAX_WINDOW`] as [`MAX_WINDOW`]).
    pub fn start_windowed(
        script: S,
        window: usize,
        ack_timeout: Duration,
        endpoint: &mut Endpoint,
        now: Instant,
    ) -> Self {
        Self::start_with(
            script,
            Window::fixed(window),
            Pacing::default(),
            ack_timeout,
            endpoint,
            now,
        )
    }

    /// Starts sending `script` at `now` with `window` (sized to the link, ICD §10.4) and
    /// `pacing` (ICD §10.3).
    pub fn start_with(
        script: S,
        window: Window,
        pacing: Pacing,
        ack_timeout: Duration,
        endpoint: &mut Endpoint,
        now: Instant,
    ) -> Self {
        Self::start_beside(script, window, pacing, ack_timeout, (0, 0), endpoint, now)
    }

    /// [`TransferSender::start_with`] beside another transfer on the same link that has
    /// `beside` data messages (count, bytes) in flight, which the window counts too
    /// ([`TransferSender::pace_beside`]).
    pub fn start_beside(
        script: S,
        window: Window,
        pacing: Pacing,
        ack_timeout: Duration,
        beside: (usize, u64),
        endpoint: &mut Endpoint,
        now: Instant,
    ) -> Self {
        let opener = if script.borrow().data_messages().start > 0 {
            Opening::Pending { retried: false }
        } else {
            Opening::Absent
        };
        let mut sender = Self {
            script,
            next: 0,
            answered: 0,
            sent: 0,
            window,
            in_flight: heapless::Vec::new(),
            ack_timeout,
            pacing,
            opener,
            beside,
        };
        sender.fill(endpoint, now);
        sender
    }

    /// The other transfer on the link now has `beside` data messages (count, bytes) in flight:
    /// sends what the window allows beside them.
    pub fn pace_beside(&mut self, endpoint: &mut Endpoint, now: Instant, beside: (usize, u64)) {
        self.beside = beside;
        self.fill(endpoint, now);
    }

    /// Whether message `index` is a closer that goes without waiting for the answers to its
    /// data messages (ICD §10.3): pipelined pacing, an upload with data messages, and a closer
    /// that carries its checksum.
    fn closes_behind_its_data(&self, index: usize) -> bool {
        let data = self.script().data_messages();
        self.pacing.pipelined
            && self.script().closer_has_checksum()
            && !data.is_empty()
            && index == data.end
            && index > 0
    }

    /// Whether the closer went behind its data and is unanswered, neither refused nor parked.
    fn closer_unanswered(&self) -> bool {
        let closer = self.script().data_messages().end;
        self.closes_behind_its_data(closer)
            && self
                .in_flight
                .iter()
                .any(|f| f.index == closer && !f.parked)
    }

    /// Whether a data message is unanswered.
    fn data_unanswered(&self) -> bool {
        let data = self.script().data_messages();
        self.in_flight.iter().any(|f| data.contains(&f.index))
    }

    /// Whether the data messages may go now: the opener was accepted, or it is pipelined
    /// behind (ICD §10.3) and its first attempt has not failed.
    fn data_may_go(&self) -> bool {
        match self.opener {
            Opening::Absent | Opening::Accepted => true,
            Opening::Pending { retried } => self.pacing.pipelined && !retried,
        }
    }

    /// The data messages in flight and their bytes (counted when the window counts bytes,
    /// ICD §10.4).
    pub fn data_in_flight(&self) -> (usize, u64) {
        let data = self.script().data_messages();
        self.in_flight
            .iter()
            .filter(|f| data.contains(&f.index))
            .fold((0, 0), |(n, bytes), f| (n + 1, bytes + f.bytes))
    }

    /// Sends what may go now (ICD §10.2, §10.3): data messages while the window has room and
    /// their opener allows them; an opener or a closer only when nothing is in flight, and then
    /// nothing after it until it is answered, but for the data a pipelined opener is followed
    /// by and the pipelined closer, which goes behind its data once its opener was accepted;
    /// the closer of a transfer sent behind another not before [`TransferSender::release`].
    fn fill(&mut self, endpoint: &mut Endpoint, now: Instant) {
        let data = self.script().data_messages();
        let last = self.script().len().saturating_sub(1);
        while self.next < self.script().len() {
            let index = self.next;
            let is_data = data.contains(&index);
            let (own, own_bytes) = self.data_in_flight();
            let in_flight = own + self.beside.0;
            let bytes_in_flight = own_bytes + self.beside.1;
            let room = if is_data {
                self.data_may_go()
                    && in_flight < self.window.messages()
                    && self
                        .in_flight
                        .iter()
                        .all(|f| data.contains(&f.index) || f.index < data.start)
            } else if self.closes_behind_its_data(index) {
                // ICD §10.3: the closer goes right behind its data; the FCC refuses it, and
                // it waits for their answers, if it overtakes one of them.
                !self.pacing.behind
                    && matches!(self.opener, Opening::Absent | Opening::Accepted)
                    && self
                        .in_flight
                        .iter()
                        .all(|f| data.contains(&f.index) && !f.parked)
            } else {
                self.in_flight.is_empty() && !(index == last && index > 0 && self.pacing.behind)
            };
            if !room {
                break;
            }
            let Some(message) = self.script().message(index) else {
                break;
            };
            let bytes = if is_data && self.window.bytes().is_some() {
                frame_bytes(&message)
            } else {
                0
            };
            if is_data
                && (!self.window.admits(in_flight, bytes_in_flight, bytes)
                    || (own > 0 && endpoint.outbox_room() <= OUTBOX_RESERVE))
            {
                // The next answer or timeout of what is in flight calls `fill` again.
                break;
            }
            let mut exchange = Exchange::new(self.ack_timeout);
            exchange.send(endpoint, now, message);
            // `room` checked the capacity (a window of at most MAX_WINDOW and the opener).
            let _ = self.in_flight.push(InFlight {
                index,
                exchange,
                sent_at: now,
                retried: false,
                parked: false,
                bytes,
            });
            self.next += 1;
            self.sent += 1;
            let pipelined_opener = index == 0 && self.pacing.pipelined && !data.is_empty();
            if !is_data && !pipelined_opener {
                break;
            }
        }
    }

    /// The script.
    pub fn script(&self) -> &Script {
        self.script.borrow()
    }

    /// The window (ICD §10.4): what it measured of the link, for the owner to carry to the next
    /// transfer.
    pub fn window(&self) -> &Window {
        &self.window
    }

    /// Messages of the script sent so far: first attempts (a retry is the same message again;
    /// data messages sent again after their opener failed count again, ICD §10.3).
    pub fn sent(&self) -> usize {
        self.sent
    }

    /// (messages answered, messages in the script).
    pub fn progress(&self) -> (usize, usize) {
        (self.answered, self.script().len())
    }

    /// Whether every data message was sent (and those whose opener failed sent again): only
    /// the closer is left to send. The area upload may then go beside this mission upload
    /// (ICD §10.3).
    pub fn sent_all_data(&self) -> bool {
        let data = self.script().data_messages();
        !data.is_empty() && self.next >= data.end
    }

    /// Whether everything but the last message (the closer, or a request) was answered and
    /// the last one is sent and unanswered: the owner may send its next transfer behind it
    /// (ICD §10.3).
    pub fn awaits_only_its_last(&self) -> bool {
        let last = self.script().len().saturating_sub(1);
        self.next == self.script().len()
            && matches!(self.in_flight.as_slice(), [only] if only.index == last && !only.parked)
    }

    /// The transfer this one was sent behind was accepted to its end (ICD §10.3): its closer
    /// may go, and what was refused meanwhile is sent again.
    pub fn release(&mut self, endpoint: &mut Endpoint, now: Instant) {
        self.pacing.behind = false;
        // The transfer it went beside is over.
        self.beside = (0, 0);
        self.unpark(endpoint, now);
        self.fill(endpoint, now);
    }

    /// Sends again the parked messages that may go now: data messages once their opener was
    /// accepted, the closer once every data message was answered, anything else once nothing
    /// is sent behind another transfer. Each goes as a new message with its own retry (ICD
    /// §10.3): the refusal answered a message that overtook what it depends on, and says
    /// nothing of the message itself.
    fn unpark(&mut self, endpoint: &mut Endpoint, now: Instant) {
        let data = self.script().data_messages();
        let data_go = matches!(self.opener, Opening::Absent | Opening::Accepted);
        let data_unanswered = self.data_unanswered();
        let closer_unanswered = self.closer_unanswered();
        let behind = self.pacing.behind;
        let closer_behind_data = self.closes_behind_its_data(data.end);
        for f in self.in_flight.iter_mut() {
            // Data refused before their opener's acceptance go after it, also in a transfer
            // sent behind another (they overtook their own opener); the closer after every
            // data message was answered; anything else once nothing is sent behind another.
            let may_go = if data.contains(&f.index) {
                data_go && !closer_unanswered
            } else if closer_behind_data && f.index == data.end {
                !behind && !data_unanswered
            } else {
                !behind
            };
            if f.parked && may_go {
                let Some(message) = Borrow::<Script>::borrow(&self.script).message(f.index) else {
                    // The script gave this message before; it cannot fail to now.
                    f.exchange.cancel();
                    continue;
                };
                f.parked = false;
                f.retried = false;
                f.sent_at = now;
                f.exchange = Exchange::new(self.ack_timeout);
                f.exchange.send(endpoint, now, message);
                self.sent += 1;
            }
        }
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
        // One due timer at a time: handling one may drop others (an opener that failed drops
        // its data, ICD §10.3); each handled timer is stopped or set later, so this ends.
        loop {
            let (slot, outcome) = self
                .in_flight
                .iter_mut()
                .enumerate()
                .find_map(|(i, f)| f.exchange.handle_timeout(now).map(|o| (i, o)))?;
            if let Some(event) = self.after(endpoint, now, slot, outcome) {
                return Some(event);
            }
        }
    }

    fn after(
        &mut self,
        endpoint: &mut Endpoint,
        now: Instant,
        slot: usize,
        outcome: Outcome,
    ) -> Option<SenderEvent> {
        let data = self.script().data_messages();
        let f = *self.in_flight.get(slot)?;
        let is_data = data.contains(&f.index);
        let is_opener = f.index == 0 && matches!(self.opener, Opening::Pending { .. });
        match outcome {
            Outcome::Accepted(answer) => {
                self.in_flight.remove(slot);
                if !f.retried {
                    self.window.measured(f.sent_at, now);
                }
                if is_data {
                    self.window.accepted();
                }
                self.answered += 1;
                if self.closes_behind_its_data(f.index) {
                    // ICD §10.3, §11: the FCC accepted the closer only with the list its
                    // checksum names assembled, every data message stored: answers still on
                    // their way say nothing more, and a retry of one of them would open an
                    // edit of the list just closed.
                    self.answered += self.in_flight.len();
                    self.in_flight.clear();
                }
                if is_opener {
                    self.opener = Opening::Accepted;
                    self.unpark(endpoint, now);
                } else if is_data && !self.data_unanswered() {
                    // A closer refused for overtaking its data goes again now.
                    self.unpark(endpoint, now);
                }
                self.fill(endpoint, now);
                if self.next >= self.script().len() && self.in_flight.is_empty() {
                    Some(SenderEvent::Completed(answer))
                } else {
                    let (sent, total) = self.progress();
                    Some(SenderEvent::Progress { sent, total })
                }
            }
            Outcome::Retry(failure) => {
                if is_data && failure == AttemptFailure::Timeout {
                    self.window.lost(f.sent_at, now);
                }
                if is_opener && self.pacing.pipelined {
                    self.restart(slot);
                }
                let refused = matches!(failure, AttemptFailure::Rejected(_));
                // ICD §10.3: refused while what it was sent behind is unanswered, it may only
                // have overtaken that on the link; its retry waits for that answer.
                let behind_opener =
                    is_data && !matches!(self.opener, Opening::Accepted | Opening::Absent);
                let behind_data = self.closes_behind_its_data(f.index) && self.data_unanswered();
                let waits = refused && (self.pacing.behind || behind_opener || behind_data);
                if let Some(f) = self.in_flight.iter_mut().find(|g| g.index == f.index) {
                    if waits {
                        f.parked = true;
                    } else {
                        f.retried = true;
                        match Borrow::<Script>::borrow(&self.script).message(f.index) {
                            Some(message) => f.exchange.resend(endpoint, now, message),
                            // The script gave this message before; it cannot fail to now.
                            None => f.exchange.cancel(),
                        }
                    }
                }
                if behind_data && waits {
                    // The closer refused: data that waited for its answer go again.
                    self.unpark(endpoint, now);
                }
                None
            }
            Outcome::Failed(error)
                if self.closes_behind_its_data(f.index)
                    && self.data_unanswered()
                    && matches!(error.second, Some(AttemptFailure::Rejected(_))) =>
            {
                // ICD §10.3: the closer's first attempt was lost and its retry overtook a data
                // message sent before it (lost in the same burst, say): the refusal says
                // nothing of the closer, which waits for its data as a new message.
                if let Some(g) = self.in_flight.iter_mut().find(|g| g.index == f.index) {
                    g.parked = true;
                }
                self.unpark(endpoint, now);
                None
            }
            Outcome::Failed(error)
                if is_data
                    && self.closer_unanswered()
                    && matches!(error.second, Some(AttemptFailure::Rejected(_))) =>
            {
                // ICD §10.3: a data message whose answer was lost, sent again behind its
                // closer, finds the transfer the closer closed: the refusal says nothing until
                // the closer is answered. Accepted, the closer answers for it; refused, it
                // waits for this message, which goes again first.
                if let Some(g) = self.in_flight.iter_mut().find(|g| g.index == f.index) {
                    g.parked = true;
                }
                None
            }
            Outcome::Failed(error) => {
                self.abandon(endpoint, now, error.reason().unwrap_or(Reason::None));
                Some(SenderEvent::Failed(error))
            }
        }
    }

    /// ICD §10.3: the first attempt of a pipelined opener failed (no answer, or refused). The
    /// data messages sent behind it may have been stored where the opener's retry will reset
    /// them, or refused: they are dropped (an answer to one of them now matches nothing) and
    /// sent again from the first, each with a new time stamp, after the retry is accepted.
    fn restart(&mut self, opener_slot: usize) {
        let Some(opener) = self.in_flight.get(opener_slot).map(|f| f.index) else {
            return;
        };
        self.in_flight.retain(|f| f.index == opener);
        self.next = opener + 1;
        self.answered = 0;
        self.opener = Opening::Pending { retried: true };
    }

    /// Abandons the transfer and tells the peer, once, without waiting for an answer.
    pub fn abandon(&mut self, endpoint: &mut Endpoint, now: Instant, reason: Reason) {
        self.cancel();
        if let Some(m) = self.script().abandon_message(reason) {
            endpoint.send(now, m, false);
        }
    }

    /// Drops the transfer without telling the peer (the peer cancelled it).
    pub fn cancel(&mut self) {
        self.in_flight.clear();
    }
}

/// The bytes `message` takes on the link: its frame and the signature trailer (ICD §2, §9),
/// which a link may or may not carry; the larger, so that the window never counts short.
fn frame_bytes(message: &Message) -> u64 {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let frame = wire::encode(&Envelope::new(0, 0), message, &mut buf).unwrap_or(MAX_FRAME_LEN);
    (frame + TRAILER_LEN) as u64
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

    // ---- Pacing (ICD §10.3) and the window (ICD §10.4) ----

    use crate::testkit::{Transmit, endpoint, generated_plan};
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_interfaces::wire::{AckType, MessageAcknowledgement};

    const ACK_TIMEOUT: Duration = Duration::from_millis(500);

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    fn gcs() -> Endpoint {
        Endpoint::new(endpoint(GCS_ID, FCC_ID))
    }

    /// The FCC's #17000 to `m`.
    fn ack(m: &Message, outcome: Result<(), Reason>) -> Message {
        let (ack_type, reason) = match outcome {
            Ok(()) => (AckType::Completed, Reason::None),
            Err(r) => (AckType::Rejected, r),
        };
        MessageAcknowledgement {
            time_stamp: Timestamp::default(),
            original_time_stamp: m.time_stamp(),
            original_message_type: m.message_type() as u16,
            ack_type,
            reject_reason: Some(reason),
        }
        .into()
    }

    fn sent(e: &mut Endpoint) -> Vec<Message> {
        e.messages()
    }

    fn names(messages: &[Message]) -> Vec<String> {
        messages.iter().map(describe).collect()
    }

    /// Mission 1 after a clear: the clear, take-off height, waypoint 1, route, transmit.
    fn upload() -> Script {
        let plan = mission_1().assemble().unwrap_or_else(|e| panic!("{e}"));
        Script::MissionUpload {
            mission: plan.mission,
            opener: Opener::Clear,
            selection: None,
            target: Target::Active,
            checksum: None,
        }
    }

    const PIPELINED: Pacing = Pacing {
        pipelined: true,
        behind: false,
    };

    #[test]
    fn stop_and_wait_keeps_the_data_behind_the_opener_s_answer() {
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            upload(),
            Window::fixed(32),
            Pacing::default(),
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let clear = sent(&mut e);
        assert_eq!(names(&clear), ["13000 mode 1 -"]);
        s.handle_answer(&mut e, at(10), &ack(&clear[0], Ok(())));
        assert_eq!(names(&sent(&mut e)), ["13006", "13002", "13001"]);
    }

    #[test]
    fn a_pipelined_opener_goes_with_the_first_window_and_the_closer_waits_for_all() {
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            upload(),
            Window::fixed(32),
            PIPELINED,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        assert_eq!(names(&out), ["13000 mode 1 -", "13006", "13002", "13001"]);
        // The data are answered before the opener: the closer still waits for it.
        for m in &out[1..] {
            assert!(matches!(
                s.handle_answer(&mut e, at(10), &ack(m, Ok(()))),
                Some(SenderEvent::Progress { .. })
            ));
        }
        assert!(sent(&mut e).is_empty());
        s.handle_answer(&mut e, at(11), &ack(&out[0], Ok(())));
        let closer = sent(&mut e);
        assert_eq!(names(&closer), ["13000 mode 2 MEDEVAC-1"]);
        assert!(s.awaits_only_its_last());
        assert!(matches!(
            s.handle_answer(&mut e, at(20), &ack(&closer[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));
        assert_eq!(s.sent(), 5);
        // The shortest round trip: the closer's, 11 ms to 20 ms.
        assert_eq!(s.window().min_rtt(), Some(Duration::from_millis(9)));
    }

    /// ICD §10.3: the opener's answer lost (or the opener): it goes again alone, then every
    /// data message again with a new time stamp, answered or not.
    #[test]
    fn an_opener_that_fails_once_goes_again_alone_and_its_data_after_it() {
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            upload(),
            Window::fixed(32),
            PIPELINED,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let first = sent(&mut e);
        s.handle_answer(&mut e, at(10), &ack(&first[1], Ok(())));
        assert_eq!(s.handle_timeout(&mut e, at(500)), None);
        let retry = sent(&mut e);
        assert_eq!(names(&retry), ["13000 mode 1 -"], "alone");
        assert!(retry[0].time_stamp() > first[3].time_stamp());
        assert_eq!(s.progress(), (0, 5));
        // A late answer to a data message of the first round matches nothing.
        assert_eq!(
            s.handle_answer(&mut e, at(510), &ack(&first[2], Ok(()))),
            None
        );
        s.handle_answer(&mut e, at(520), &ack(&retry[0], Ok(())));
        let again = sent(&mut e);
        assert_eq!(names(&again), ["13006", "13002", "13001"]);
        assert!(again.iter().all(|m| m.time_stamp() > retry[0].time_stamp()));
        for m in &again {
            s.handle_answer(&mut e, at(530), &ack(m, Ok(())));
        }
        let closer = sent(&mut e);
        assert!(matches!(
            s.handle_answer(&mut e, at(540), &ack(&closer[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));
        assert_eq!(s.sent(), 8, "clear, 3 data twice, transmit");
        // The opener's retry says nothing of the round trip; the data did.
        assert_eq!(s.window().min_rtt(), Some(Duration::from_millis(10)));
    }

    /// Mission 1 with its checksum (ICD §11) by a pipelined sender: the clear accepted at 10 ms
    /// and the take-off height and waypoint at 11 ms; the closer went behind the data. The
    /// messages sent first (clear, 3 data) and the closer.
    fn behind_its_data() -> (Endpoint, TransferSender, Vec<Message>, Vec<Message>) {
        let plan = mission_1().assemble().unwrap_or_else(|e| panic!("{e}"));
        let script = Script::MissionUpload {
            checksum: Some(crate::transfer::integrity::mission_checksum(&plan.mission)),
            mission: plan.mission,
            opener: Opener::Clear,
            selection: None,
            target: Target::Active,
        };
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            script,
            Window::fixed(32),
            PIPELINED,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        assert_eq!(names(&out), ["13000 mode 1 -", "13006", "13002", "13001"]);
        s.handle_answer(&mut e, at(10), &ack(&out[0], Ok(())));
        let closer = sent(&mut e);
        assert_eq!(
            names(&closer),
            ["13000 mode 2 MEDEVAC-1"],
            "behind its data"
        );
        s.handle_answer(&mut e, at(11), &ack(&out[1], Ok(())));
        s.handle_answer(&mut e, at(11), &ack(&out[2], Ok(())));
        (e, s, out, closer)
    }

    /// ICD §10.3: a closer that carries its checksum goes right behind its data once its
    /// opener was accepted; refused while data are unanswered, it waits for their answers and
    /// goes again as a new message; accepted, it answers for the data still unanswered.
    #[test]
    fn a_closer_with_its_checksum_goes_behind_its_data() {
        // It overtook the route: refused, it waits (no retry, no timer of its own)...
        let (mut e, mut s, out, closer) = behind_its_data();
        assert_eq!(
            s.handle_answer(
                &mut e,
                at(12),
                &ack(&closer[0], Err(Reason::MissingInitial))
            ),
            None
        );
        assert!(sent(&mut e).is_empty(), "parked");
        // ...and goes again, a new message, when the route was accepted.
        s.handle_answer(&mut e, at(13), &ack(&out[3], Ok(())));
        let again = sent(&mut e);
        assert_eq!(names(&again), ["13000 mode 2 MEDEVAC-1"]);
        assert!(again[0].time_stamp() > closer[0].time_stamp());
        assert!(matches!(
            s.handle_answer(&mut e, at(20), &ack(&again[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));

        // Accepted while the route's answer is still on its way: complete at once, and no
        // data message is sent again.
        let (mut e, mut s, _, closer) = behind_its_data();
        assert!(matches!(
            s.handle_answer(&mut e, at(20), &ack(&closer[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));
        assert_eq!(s.poll_timeout(), None);
        assert_eq!(s.progress(), (5, 5));

        // Its first attempt lost and its retry refused while a data message is unanswered:
        // it waits for the data, as a new message, instead of failing the transfer.
        let (mut e, mut s, _, _) = behind_its_data();
        assert_eq!(s.handle_timeout(&mut e, at(10 + 500)), None);
        let retries = sent(&mut e);
        assert_eq!(names(&retries), ["13001", "13000 mode 2 MEDEVAC-1"]);
        assert!(retries[0].time_stamp() < retries[1].time_stamp());
        assert_eq!(
            s.handle_answer(
                &mut e,
                at(520),
                &ack(&retries[1], Err(Reason::MissingInitial))
            ),
            None
        );
        assert!(sent(&mut e).is_empty(), "parked, not failed");
        s.handle_answer(&mut e, at(530), &ack(&retries[0], Ok(())));
        let again = sent(&mut e);
        assert_eq!(names(&again), ["13000 mode 2 MEDEVAC-1"]);
        assert!(matches!(
            s.handle_answer(&mut e, at(540), &ack(&again[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));

        // A data message whose answer was lost goes again behind the closer, which closed the
        // transfer: its retry refused, it waits for the closer, whose acceptance answers for it.
        let (mut e, mut s, _, closer) = behind_its_data();
        assert_eq!(s.handle_timeout(&mut e, at(500)), None);
        let retry = sent(&mut e);
        assert_eq!(names(&retry), ["13001"]);
        assert_eq!(
            s.handle_answer(&mut e, at(505), &ack(&retry[0], Err(Reason::WrongState))),
            None,
            "parked, not failed"
        );
        assert!(sent(&mut e).is_empty());
        assert!(matches!(
            s.handle_answer(&mut e, at(506), &ack(&closer[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));

        // The same, the closer refused: the data message goes again first, then the closer.
        let (mut e, mut s, _, closer) = behind_its_data();
        assert_eq!(s.handle_timeout(&mut e, at(500)), None);
        let retry = sent(&mut e);
        s.handle_answer(&mut e, at(505), &ack(&retry[0], Err(Reason::WrongState)));
        assert_eq!(
            s.handle_answer(
                &mut e,
                at(506),
                &ack(&closer[0], Err(Reason::MissingInitial))
            ),
            None
        );
        let again = sent(&mut e);
        assert_eq!(names(&again), ["13001"]);
        s.handle_answer(&mut e, at(510), &ack(&again[0], Ok(())));
        let closer_again = sent(&mut e);
        assert_eq!(names(&closer_again), ["13000 mode 2 MEDEVAC-1"]);
        assert!(matches!(
            s.handle_answer(&mut e, at(520), &ack(&closer_again[0], Ok(()))),
            Some(SenderEvent::Completed(_))
        ));

        // Without a checksum (edition 1's closer) it waits for every answer (ICD §10.2).
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            upload(),
            Window::fixed(32),
            PIPELINED,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        s.handle_answer(&mut e, at(10), &ack(&out[0], Ok(())));
        assert!(sent(&mut e).is_empty());
    }

    /// ICD §10.3: a data message refused while its opener is unanswered may have overtaken it:
    /// its retry waits for the opener's acceptance.
    #[test]
    fn data_refused_before_the_opener_s_answer_go_again_after_it() {
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            upload(),
            Window::fixed(32),
            PIPELINED,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        assert_eq!(
            s.handle_answer(&mut e, at(10), &ack(&out[2], Err(Reason::WrongState))),
            None
        );
        assert!(sent(&mut e).is_empty(), "parked, no timer");
        assert_eq!(s.poll_timeout(), Some(at(500)));
        s.handle_answer(&mut e, at(11), &ack(&out[0], Ok(())));
        let again = sent(&mut e);
        assert_eq!(names(&again), ["13002"]);
        // Sent as a new message: the refusal did not count, it keeps its one retry.
        s.handle_answer(&mut e, at(12), &ack(&out[1], Ok(())));
        s.handle_answer(&mut e, at(12), &ack(&out[3], Ok(())));
        assert_eq!(
            s.handle_answer(&mut e, at(20), &ack(&again[0], Err(Reason::WrongState))),
            None
        );
        let retry = sent(&mut e);
        assert_eq!(names(&retry), ["13002"]);
        assert!(matches!(
            s.handle_answer(&mut e, at(30), &ack(&retry[0], Err(Reason::WrongState))),
            Some(SenderEvent::Failed(_))
        ));
        assert_eq!(s.sent(), 5, "clear, 3 data, the one parked again");
    }

    /// ICD §10.3: a transfer sent behind the last message of the one before: its closer waits
    /// for the release, and what is refused meanwhile waits too.
    #[test]
    fn a_transfer_sent_behind_another_waits_for_its_release() {
        let plan = mission_1().assemble().unwrap_or_else(|e| panic!("{e}"));
        let areas = || Script::AreaUpload {
            list: plan.areas.clone(),
            target: Target::Active,
            checksum: None,
        };
        let behind = Pacing {
            pipelined: true,
            behind: true,
        };
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            areas(),
            Window::fixed(32),
            behind,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        assert_eq!(names(&out), ["2011 mode 1 -", "2012"]);
        s.handle_answer(&mut e, at(10), &ack(&out[0], Ok(())));
        s.handle_answer(&mut e, at(10), &ack(&out[1], Ok(())));
        assert!(sent(&mut e).is_empty(), "the closer is held");
        s.release(&mut e, at(20));
        assert_eq!(names(&sent(&mut e)), ["2011 mode 2 -"]);

        // The opener refused meanwhile: parked with its data dropped; released, it goes again.
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            areas(),
            Window::fixed(32),
            behind,
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        s.handle_answer(&mut e, at(10), &ack(&out[0], Err(Reason::Busy)));
        assert!(sent(&mut e).is_empty());
        assert_eq!(s.poll_timeout(), None, "nothing waits for a timer");
        s.release(&mut e, at(20));
        let retry = sent(&mut e);
        assert_eq!(names(&retry), ["2011 mode 1 -"]);
        s.handle_answer(&mut e, at(30), &ack(&retry[0], Ok(())));
        assert_eq!(names(&sent(&mut e)), ["2012"]);
    }

    /// ICD §10.4 rule 3: what the link carries in a round trip, at 2.4 kbit/s and 1.5 s.
    #[test]
    fn the_window_keeps_what_the_link_carries_in_a_round_trip() {
        let plan = generated_plan(20)
            .assemble()
            .unwrap_or_else(|e| panic!("{e}"));
        let script = Script::MissionUpload {
            mission: plan.mission,
            opener: Opener::None,
            selection: None,
            target: Target::Active,
            checksum: None,
        };
        let frames: Vec<u64> = (0..4)
            .filter_map(|i| script.message(i))
            .map(|m| frame_bytes(&m))
            .collect();
        // Take-off height 48 bytes, each waypoint 65 (the 16 of the signature included).
        assert_eq!(frames, [48, 65, 65, 65]);
        let mut window = Window::adaptive(32, Some(2_400));
        window.measured(at(0), at(1500));
        assert_eq!(window.bytes(), Some(450));
        let mut e = gcs();
        let mut s = TransferSender::start_with(
            script,
            window,
            Pacing::default(),
            ACK_TIMEOUT,
            &mut e,
            at(0),
        );
        let out = sent(&mut e);
        // 48 + 6 x 65 = 438 bytes; a seventh waypoint would make 503.
        assert_eq!(
            names(&out),
            [
                "13006", "13002", "13002", "13002", "13002", "13002", "13002"
            ]
        );
        s.handle_answer(&mut e, at(1500), &ack(&out[0], Ok(())));
        assert!(sent(&mut e).is_empty(), "65 bytes more would make 455");
        s.handle_answer(&mut e, at(1500), &ack(&out[1], Ok(())));
        assert_eq!(names(&sent(&mut e)), ["13002"], "5 x 65 + 65 = 390");
    }
}
