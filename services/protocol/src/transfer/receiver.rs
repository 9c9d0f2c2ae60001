//! The receivers of transfers, one per data kind for both directions (paper §3.2, inverted use;
//! ICD §5.6): the FCC receives a mission upload (paper §3.1.5) and an area upload (§3.1.8) with
//! them, the GCS a mission download (§3.1.6) and an area download (§3.1.9).
//!
//! The GCS receives the FCC's mission report (ICD §8) with [`ReportReceiver`].
//!
//! A receiver stores what arrives and assembles the list when the closing message comes: #13000
//! mode 2 (FCC) or #14000 complete (GCS) for missions, #2011 mode 2 (FCC) or mode 4 (GCS) for
//! areas. It never touches an active list: it hands a complete, valid list to its owner, who
//! activates it. A receiver that hears nothing from its peer for the transfer timeout abandons
//! the transfer (ICD §5).
//!
//! On the FCC, the closers of staging (ICD §8: #13000 mode 8, #2011 mode 7) assemble and check
//! as mode 2 does; what happens to the list (activated or staged) is the owner's business. Mode
//! 10 fills the waypoint buffer with a list of the owner's choice and opens the upload
//! ([`MissionReceiver::load`]).
//!
//! A closing message that carries a checksum (ICD §11: #13000 mode 2 or 8 and #2011 mode 2 or 7
//! from an edition-2 GCS, #14000 and #2011 mode 4 of a download to an edition-2 request) is accepted only
//! when the list assembled has that checksum; otherwise it is refused with `IntegrityMismatch`
//! and the buffer is emptied, so nothing of the transfer is left to assemble.

use core::time::Duration;

use missionlink_interfaces::capacity::{MAX_AREAS, MAX_REPORT_ENTRIES};
use missionlink_interfaces::wire::{
    AreaTransferMode, Checksum, Message, MissionPlanMode, MissionReport, Reason, SafetyOffset,
    TransferStatus,
};

use crate::link::time::Instant;
use crate::link::timer::TimerTable;
use crate::transfer::areas::{AreaBuffer, AreaList};
use crate::transfer::integrity::{areas_checksum, mission_checksum};
use crate::transfer::mission::{Mission, MissionBuffer};

/// What a receiver made of a message it accepted.
///
/// A completed list stays in the receiver until its owner takes it ([`MissionReceiver::take`],
/// [`AreaReceiver::take`]): returning a 256-waypoint mission by value would copy it on every
/// stored waypoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Received {
    /// Stored; the transfer goes on.
    Stored,
    /// The closing message came and the list is complete and valid: take it.
    Complete,
    /// The peer cancelled or aborted the transfer (with its reason, where it gave one).
    Abandoned(Option<Reason>),
    /// The closing message activates the empty list: #13000 mode 2 with Waypoint Number 0
    /// after a clear (how this project clears the active mission, see `missionlink_flight::mission_data_handling`).
    Emptied,
}

/// A transfer a receiver abandoned because the peer fell silent for the transfer timeout
/// (ICD §1: 3 s; ICD §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TransferTimedOut {
    /// When the peer was last heard.
    pub last_heard: Instant,
}

crate::timers! {
    /// The timer of a receiver.
    pub enum ReceiverTimer {
        /// The transfer timeout, restarted by every message of the transfer.
        Transfer,
    }
}

/// The silence watch both receivers keep: when the peer was last heard in an open transfer, and
/// the timer that abandons the transfer after the transfer timeout.
#[derive(Debug, Clone)]
struct Silence {
    last_heard: Option<Instant>,
    timers: TimerTable<ReceiverTimer, 1>,
    transfer_timeout: Duration,
}

impl Silence {
    const fn new(transfer_timeout: Duration) -> Self {
        Self {
            last_heard: None,
            timers: TimerTable::new(),
            transfer_timeout,
        }
    }

    /// The peer spoke at `now`: the transfer is open and its timeout restarts.
    fn heard(&mut self, now: Instant) {
        self.last_heard = Some(now);
        self.timers
            .set(ReceiverTimer::Transfer, now + self.transfer_timeout);
    }

    /// The transfer is closed: nothing to time out.
    fn close(&mut self) {
        self.last_heard = None;
        self.timers.stop(ReceiverTimer::Transfer);
    }

    fn is_open(&self) -> bool {
        self.last_heard.is_some()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.timers.next_timeout()
    }

    /// `Some` (and closed) when the transfer timeout has passed at `now`.
    fn expire(&mut self, now: Instant) -> Option<TransferTimedOut> {
        if !self.timers.is_expired(ReceiverTimer::Transfer, now) {
            return None;
        }
        let last_heard = self.last_heard?;
        self.close();
        Some(TransferTimedOut { last_heard })
    }
}

/// Receives missions: a mission upload on the FCC, a mission download on the GCS.
#[derive(Debug, Clone)]
pub struct MissionReceiver {
    buffer: MissionBuffer,
    complete: Option<Mission>,
    silence: Silence,
}

impl MissionReceiver {
    /// A receiver with an empty buffer.
    pub fn new(transfer_timeout: Duration) -> Self {
        Self {
            buffer: MissionBuffer::new(),
            complete: None,
            silence: Silence::new(transfer_timeout),
        }
    }

    /// Whether a transfer is in progress (something arrived and it is neither complete nor
    /// abandoned).
    pub fn in_transfer(&self) -> bool {
        self.silence.is_open()
    }

    /// Starts a transfer (the GCS's download request was accepted) with an empty buffer.
    pub fn begin(&mut self, now: Instant) {
        self.buffer.clear();
        self.silence.heard(now);
    }

    /// Ends the transfer in progress and resets the buffer to `base` (the active mission, or
    /// nothing): an abandoned edit must not leak into the next one.
    pub fn abandon(&mut self, base: Option<&Mission>) {
        self.silence.close();
        self.buffer = base.map(MissionBuffer::from_mission).unwrap_or_default();
    }

    /// Empties the buffer (#13000 mode 1; the owner checks guidance first).
    pub fn clear(&mut self, now: Instant) {
        self.buffer.clear();
        self.silence.heard(now);
    }

    /// Fills the buffer with `base`, or empties it when there is none, and opens an upload that
    /// edits it (#13000 mode 10, ICD §8: the owner chooses the staged or the active list).
    pub fn load(&mut self, now: Instant, base: Option<&Mission>) {
        match base {
            Some(mission) => self.buffer = MissionBuffer::from_mission(mission),
            None => self.buffer.clear(),
        }
        self.silence.heard(now);
    }

    /// When [`MissionReceiver::handle_timeout`] must be called: the transfer timeout of the
    /// transfer in progress.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.silence.poll_timeout()
    }

    /// The transfer timeout may have passed at `now`: the transfer in progress is abandoned
    /// and the buffer emptied (the owner's next transfer starts from its active mission).
    /// `None` before the deadline or without a transfer.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<TransferTimedOut> {
        let timed_out = self.silence.expire(now)?;
        self.abandon(None);
        Some(timed_out)
    }

    /// The mission the last [`Received::Complete`] assembled.
    pub fn take(&mut self) -> Option<Mission> {
        self.complete.take()
    }

    /// The closing message assembled `mission`: complete, unless the sender's `checksum` says it
    /// meant another (ICD §11).
    fn complete(
        &mut self,
        mission: Mission,
        checksum: Option<Checksum>,
    ) -> Result<Received, Reason> {
        if checksum.is_some_and(|c| c != mission_checksum(&mission)) {
            self.abandon(None);
            return Err(Reason::IntegrityMismatch);
        }
        self.complete = Some(mission);
        self.silence.close();
        Ok(Received::Complete)
    }

    /// Handles mission data: #13006, #13002, #13001, #13000 mode 2 transmit or mode 8 stage
    /// (ICD §8: assembled alike), #14000. The answer to the message is `Ok` (acknowledge type 2)
    /// or the reason (type 3).
    pub fn handle(&mut self, now: Instant, message: &Message) -> Result<Received, Reason> {
        self.silence.heard(now);
        match message {
            Message::MissionTransferCommand(c)
                if matches!(
                    c.mode,
                    MissionPlanMode::TransmitMission | MissionPlanMode::StageMission
                ) =>
            {
                // Only mode 2 activates the empty list; staged, an empty list fails §7.
                if c.mode == MissionPlanMode::TransmitMission && c.waypoint_number == Some(0) {
                    // The empty list has no canonical form in ICD §11 (its report carries no
                    // checksum): a checksum here contradicts the clear (our choice).
                    if c.mission_checksum.is_some() {
                        return Err(Reason::Malformed);
                    }
                    if !self.buffer.is_empty() {
                        return Err(Reason::CountMismatch);
                    }
                    self.silence.close();
                    return Ok(Received::Emptied);
                }
                let mission = self.buffer.assemble(c.waypoint_number, c.mission_id)?;
                self.complete(mission, c.mission_checksum)
            }
            Message::MissionUploadDownloadStatus(s) => match s.status {
                TransferStatus::Complete => {
                    let mission = self.buffer.assemble(None, s.mission_id)?;
                    self.complete(mission, s.mission_checksum)
                }
                TransferStatus::Aborted => {
                    self.abandon(None);
                    Ok(Received::Abandoned(s.reason))
                }
                TransferStatus::InProgress => Ok(Received::Stored),
            },
            other => self.buffer.store(other).map(|()| Received::Stored),
        }
    }
}

/// Receives area lists: an area upload on the FCC, an area download on the GCS.
#[derive(Debug, Clone)]
pub struct AreaReceiver {
    buffer: AreaBuffer,
    complete: Option<AreaList>,
    /// Loop count and safety offset of the opening message, while a transfer is open.
    open: Option<(u8, SafetyOffset)>,
    silence: Silence,
}

impl AreaReceiver {
    /// A receiver with no transfer open.
    pub fn new(transfer_timeout: Duration) -> Self {
        Self {
            buffer: AreaBuffer::new(),
            complete: None,
            open: None,
            silence: Silence::new(transfer_timeout),
        }
    }

    /// Whether a transfer is open.
    pub fn in_transfer(&self) -> bool {
        self.open.is_some()
    }

    /// Ends the transfer in progress; what was stored is dropped (an area transfer always
    /// carries the whole list).
    pub fn abandon(&mut self) {
        self.buffer = AreaBuffer::new();
        self.open = None;
        self.silence.close();
    }

    /// When [`AreaReceiver::handle_timeout`] must be called: the transfer timeout of the
    /// transfer in progress.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.silence.poll_timeout()
    }

    /// The transfer timeout may have passed at `now`: the transfer in progress is abandoned
    /// with what it stored. `None` before the deadline or without a transfer.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<TransferTimedOut> {
        let timed_out = self.silence.expire(now)?;
        self.abandon();
        Some(timed_out)
    }

    /// The area list the last [`Received::Complete`] assembled.
    pub fn take(&mut self) -> Option<AreaList> {
        self.complete.take()
    }

    /// Handles area data: #2011 mode 1 (opens, FCC) or #3013 ready (opens, GCS), #2012, #2011
    /// mode 2 or 7 (closes, FCC; ICD §8: mode 7 assembles as mode 2 does) or mode 4 (closes,
    /// GCS), #2011 mode 5 cancel.
    pub fn handle(&mut self, now: Instant, message: &Message) -> Result<Received, Reason> {
        let received = self.route(message);
        // The transfer timeout runs exactly while a transfer is open: a stray message outside
        // one starts no timer.
        if self.open.is_some() {
            self.silence.heard(now);
        } else {
            self.silence.close();
        }
        received
    }

    fn route(&mut self, message: &Message) -> Result<Received, Reason> {
        let opening = match message {
            Message::AreaTransmissionCommand(c) => match c.mode {
                AreaTransferMode::InitiateUpload => Some((
                    c.loop_count.unwrap_or(0),
                    c.safety_offset.unwrap_or_default(),
                )),
                AreaTransferMode::UploadComplete
                | AreaTransferMode::UploadCompleteStaged
                | AreaTransferMode::DownloadComplete => {
                    let (announced, offset) = self.open.ok_or(Reason::WrongState)?;
                    if c.loop_count != Some(announced) {
                        return Err(Reason::CountMismatch);
                    }
                    let list = self.buffer.assemble(announced, offset)?;
                    self.abandon();
                    if c.area_checksum()
                        .is_some_and(|sum| sum != areas_checksum(&list))
                    {
                        return Err(Reason::IntegrityMismatch);
                    }
                    self.complete = Some(list);
                    return Ok(Received::Complete);
                }
                AreaTransferMode::Cancel => {
                    self.abandon();
                    return Ok(Received::Abandoned(None));
                }
                AreaTransferMode::InitiateDownload
                | AreaTransferMode::ClearAreas
                | AreaTransferMode::InitiateStagedDownload => {
                    return Err(Reason::WrongState);
                }
            },
            Message::AreaTransmissionStatus(s) => Some((s.loop_count, s.safety_offset)),
            Message::AreaPolygonLoopSegment(a) => {
                if self.open.is_none() {
                    return Err(Reason::WrongState);
                }
                return self.buffer.store(a).map(|()| Received::Stored);
            }
            _ => return Err(Reason::WrongState),
        };
        if let Some((count, offset)) = opening {
            // ICD §5.3 step 1: more than the FCC holds is refused at once.
            if usize::from(count) > MAX_AREAS {
                self.abandon();
                return Err(Reason::Capacity);
            }
            self.buffer = AreaBuffer::new();
            self.open = Some((count, offset));
        }
        Ok(Received::Stored)
    }
}

/// Receives the mission report (ICD §8, #50001) on the GCS: the entries in order, the active
/// lists first; complete when the entry of index Report Count has arrived.
#[derive(Debug, Clone)]
pub struct ReportReceiver {
    entries: heapless::Vec<MissionReport, MAX_REPORT_ENTRIES>,
    complete: bool,
    silence: Silence,
}

impl ReportReceiver {
    /// A receiver with no report open.
    pub fn new(transfer_timeout: Duration) -> Self {
        Self {
            entries: heapless::Vec::new(),
            complete: false,
            silence: Silence::new(transfer_timeout),
        }
    }

    /// The FCC accepted the request at `now`: its entries follow.
    pub fn begin(&mut self, now: Instant) {
        self.entries.clear();
        self.complete = false;
        self.silence.heard(now);
    }

    /// Whether a report is open.
    pub fn in_transfer(&self) -> bool {
        self.silence.is_open()
    }

    /// Ends the report in progress.
    pub fn abandon(&mut self) {
        self.entries.clear();
        self.complete = false;
        self.silence.close();
    }

    /// When [`ReportReceiver::handle_timeout`] must be called.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.silence.poll_timeout()
    }

    /// The transfer timeout may have passed at `now`: the report is abandoned.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<TransferTimedOut> {
        let timed_out = self.silence.expire(now)?;
        self.abandon();
        Some(timed_out)
    }

    /// The entries of the complete report, once.
    pub fn take(&mut self) -> Option<heapless::Vec<MissionReport, MAX_REPORT_ENTRIES>> {
        if !self.complete {
            return None;
        }
        self.complete = false;
        Some(core::mem::take(&mut self.entries))
    }

    /// Handles one entry. Entries come one at a time, in index order (each waits for the
    /// acknowledgement of the one before, ICD §8): the next index is stored, the last one stored
    /// again (its retry, whose acknowledgement was lost) is accepted without change, any other
    /// is refused (`WrongState`), as is a Report Count that changes within the report
    /// (`Malformed`).
    pub fn handle(&mut self, now: Instant, entry: &MissionReport) -> Result<Received, Reason> {
        if !self.silence.is_open() {
            return Err(Reason::WrongState);
        }
        self.silence.heard(now);
        let count = self
            .entries
            .first()
            .map_or(entry.report_count, |e| e.report_count);
        if entry.report_count != count || usize::from(count) > MAX_REPORT_ENTRIES {
            return Err(Reason::Malformed);
        }
        let stored = self.entries.len();
        match usize::from(entry.report_index) {
            i if i == stored + 1 => {
                let mut e = *entry;
                e.time_stamp = Default::default();
                self.entries.push(e).map_err(|_| Reason::Capacity)?;
            }
            i if i == stored && stored > 0 => return Ok(Received::Stored),
            _ => return Err(Reason::WrongState),
        }
        if self.entries.len() == usize::from(count) {
            self.complete = true;
            self.silence.close();
            return Ok(Received::Complete);
        }
        Ok(Received::Stored)
    }
}
