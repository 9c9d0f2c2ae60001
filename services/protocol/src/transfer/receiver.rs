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
//! **Stamp order (ICD §10.3).** The mission receiver applies the messages of an upload in the
//! order of their time stamps, not of their arrival: each entry of the waypoint buffer keeps the
//! stamp of the message that stored it, and an opener (#13000 mode 1 or 10) empties or reloads
//! only the entries stored by messages stamped before it, so the data a GCS sends right behind
//! its opener may overtake it on the link. A message stamped before the newest opener applied,
//! or before the entry it would replace, changes nothing and is refused (`WrongState`): it
//! belongs to an upload the opener ended. The area receiver refuses an opener stamped before a
//! message of the transfer it has open (`WrongState`): area data never open a transfer, so such
//! an opener can only be a late copy of one the transfer began with. For a sender that waits
//! for each answer (edition 1), stamp order is arrival order and nothing changes.
//!
//! A closing message that carries a checksum (ICD §11: #13000 mode 2 or 8 and #2011 mode 2 or 7
//! from an edition-2 GCS, #14000 and #2011 mode 4 of a download to an edition-2 request) is accepted only
//! when the list assembled has that checksum; otherwise it is refused with `IntegrityMismatch`
//! and the buffer stays as it is: an edition-2 GCS sends the closer right behind its data (ICD
//! §10.3), and a closer that overtook one of them is sent again once it was stored. The
//! sender's cancel, its next opener or the transfer timeout empties the buffer.

use core::time::Duration;

use heapless::index_map::FnvIndexMap;
use missionlink_interfaces::capacity::{MAX_AREAS, MAX_REPORT_ENTRIES, MAX_WAYPOINTS};
use missionlink_interfaces::wire::{
    AreaTransferMode, Checksum, Message, MissionPlanMode, MissionReport, Reason, SafetyOffset,
    Timestamp, TransferStatus,
};

use crate::link::time::Instant;
use crate::link::timer::TimerTable;
use crate::transfer::areas::{AreaBuffer, AreaList};
use crate::transfer::integrity::{areas_checksum, mission_checksum};
use crate::transfer::mission::{Entry, Mission, MissionBuffer};

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

/// The time stamps of the open transfer's waypoint buffer (ICD §10.3): the message that stored
/// each entry, and the newest opener applied. Empty outside a transfer, and for the entries a
/// transfer began with (the active mission of an edit, or the list an opener loaded, which take
/// the opener's stamp).
#[derive(Debug, Clone, Default)]
struct Stamps {
    opener: Option<Timestamp>,
    take_off: Option<Timestamp>,
    route: Option<Timestamp>,
    waypoints: FnvIndexMap<u16, Timestamp, MAX_WAYPOINTS>,
    rf_centres: FnvIndexMap<u16, Timestamp, MAX_WAYPOINTS>,
}

impl Stamps {
    fn get(&self, entry: Entry) -> Option<Timestamp> {
        match entry {
            Entry::TakeOff => self.take_off,
            Entry::Route => self.route,
            Entry::Waypoint(n) => self.waypoints.get(&n).copied(),
            Entry::RfCentre(n) => self.rf_centres.get(&n).copied(),
        }
    }

    /// `entry` was stored by a message stamped `stamp` (the buffer holds as many entries:
    /// `Capacity` only where it refused one).
    fn set(&mut self, entry: Entry, stamp: Timestamp) -> Result<(), Reason> {
        match entry {
            Entry::TakeOff => self.take_off = Some(stamp),
            Entry::Route => self.route = Some(stamp),
            Entry::Waypoint(n) => {
                self.waypoints
                    .insert(n, stamp)
                    .map_err(|_| Reason::Capacity)?;
            }
            Entry::RfCentre(n) => {
                self.rf_centres
                    .insert(n, stamp)
                    .map_err(|_| Reason::Capacity)?;
            }
        }
        Ok(())
    }

    /// The entries stored by messages stamped after `stamp`.
    fn after(&self, stamp: Timestamp) -> impl Iterator<Item = (Entry, Timestamp)> + '_ {
        let single = [
            self.take_off.map(|t| (Entry::TakeOff, t)),
            self.route.map(|t| (Entry::Route, t)),
        ];
        single
            .into_iter()
            .flatten()
            .chain(
                self.waypoints
                    .iter()
                    .map(|(n, t)| (Entry::Waypoint(*n), *t)),
            )
            .chain(
                self.rf_centres
                    .iter()
                    .map(|(n, t)| (Entry::RfCentre(*n), *t)),
            )
            .filter(move |(_, t)| *t > stamp)
    }
}

/// Receives missions: a mission upload on the FCC, a mission download on the GCS.
#[derive(Debug, Clone)]
pub struct MissionReceiver {
    buffer: MissionBuffer,
    /// ICD §10.3: the stamps of the open transfer's entries.
    stamps: Stamps,
    complete: Option<Mission>,
    silence: Silence,
}

impl MissionReceiver {
    /// A receiver with an empty buffer.
    pub fn new(transfer_timeout: Duration) -> Self {
        Self {
            buffer: MissionBuffer::new(),
            stamps: Stamps::default(),
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
        self.stamps = Stamps::default();
        self.silence.heard(now);
    }

    /// Ends the transfer in progress and resets the buffer to `base` (the active mission, or
    /// nothing): an abandoned edit must not leak into the next one.
    pub fn abandon(&mut self, base: Option<&Mission>) {
        self.silence.close();
        self.stamps = Stamps::default();
        self.buffer = base.map(MissionBuffer::from_mission).unwrap_or_default();
    }

    /// Empties the buffer (#13000 mode 1, stamped `stamp`; the owner checks guidance first),
    /// but for the entries stored by messages stamped after it (ICD §10.3). An opener stamped
    /// before one applied in this transfer changes nothing (`WrongState`).
    pub fn clear(&mut self, now: Instant, stamp: Timestamp) -> Result<(), Reason> {
        self.open(now, None, stamp)
    }

    /// Fills the buffer with `base`, or empties it when there is none, and opens an upload that
    /// edits it (#13000 mode 10 stamped `stamp`, ICD §8: the owner chooses the staged or the
    /// active list); the entries stored by messages stamped after it stay (ICD §10.3). An
    /// opener stamped before one applied in this transfer changes nothing (`WrongState`).
    pub fn load(
        &mut self,
        now: Instant,
        base: Option<&Mission>,
        stamp: Timestamp,
    ) -> Result<(), Reason> {
        self.open(now, base, stamp)
    }

    /// An opener stamped `stamp` with the buffer's new `base` (ICD §10.3).
    fn open(
        &mut self,
        now: Instant,
        base: Option<&Mission>,
        stamp: Timestamp,
    ) -> Result<(), Reason> {
        if self.stamps.opener.is_some_and(|newest| stamp < newest) {
            return Err(Reason::WrongState);
        }
        let mut buffer = base.map(MissionBuffer::from_mission).unwrap_or_default();
        let mut stamps = Stamps {
            opener: Some(stamp),
            ..Stamps::default()
        };
        // The data sent after the opener that overtook it on the link stay, as if the opener
        // had come first.
        for (entry, at) in self.stamps.after(stamp) {
            if let Some(message) = self.buffer.entry(entry) {
                buffer.store(&message)?;
                stamps.set(entry, at)?;
            }
        }
        self.buffer = buffer;
        self.stamps = stamps;
        self.silence.heard(now);
        Ok(())
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
            // The buffer stays: data sent before the closer may still be on their way (ICD
            // §10.3); the sender's cancel or the transfer timeout empties it.
            return Err(Reason::IntegrityMismatch);
        }
        self.complete = Some(mission);
        self.stamps = Stamps::default();
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
                    self.stamps = Stamps::default();
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
            other => self.store(other),
        }
    }

    /// A data message, in stamp order (ICD §10.3): one stamped before the newest opener applied
    /// or before the entry it would replace changes nothing (`WrongState`).
    fn store(&mut self, message: &Message) -> Result<Received, Reason> {
        let Some(entry) = Entry::of(message) else {
            return self.buffer.store(message).map(|()| Received::Stored);
        };
        let stamp = message.time_stamp();
        let older = |newer: Option<Timestamp>| newer.is_some_and(|n| stamp < n);
        if older(self.stamps.opener) || older(self.stamps.get(entry)) {
            return Err(Reason::WrongState);
        }
        self.buffer.store(message)?;
        self.stamps.set(entry, stamp)?;
        Ok(Received::Stored)
    }
}

/// Receives area lists: an area upload on the FCC, an area download on the GCS.
#[derive(Debug, Clone)]
pub struct AreaReceiver {
    buffer: AreaBuffer,
    complete: Option<AreaList>,
    /// Loop count and safety offset of the opening message, while a transfer is open.
    open: Option<(u8, SafetyOffset)>,
    /// The newest time stamp of the open transfer's messages (ICD §10.3).
    newest: Option<Timestamp>,
    silence: Silence,
}

impl AreaReceiver {
    /// A receiver with no transfer open.
    pub fn new(transfer_timeout: Duration) -> Self {
        Self {
            buffer: AreaBuffer::new(),
            complete: None,
            open: None,
            newest: None,
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
        self.newest = None;
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
            self.newest = self.newest.max(Some(message.time_stamp()));
        } else {
            self.silence.close();
            self.newest = None;
        }
        received
    }

    fn route(&mut self, message: &Message) -> Result<Received, Reason> {
        // ICD §10.3: an opener stamped before a message of the open transfer is a late copy of
        // one it began with (area data never open a transfer): it changes nothing.
        let is_opener = matches!(message, Message::AreaTransmissionStatus(_))
            || matches!(message, Message::AreaTransmissionCommand(c)
                if c.mode == AreaTransferMode::InitiateUpload);
        if is_opener && self.open.is_some() && self.newest.is_some_and(|n| message.time_stamp() < n)
        {
            return Err(Reason::WrongState);
        }
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
                    if c.area_checksum()
                        .is_some_and(|sum| sum != areas_checksum(&list))
                    {
                        // As for missions: the buffer stays for data still on their way.
                        return Err(Reason::IntegrityMismatch);
                    }
                    self.abandon();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{self, mission_1};
    use missionlink_interfaces::wire::{AreaTransmissionCommand, LegType};

    const TIMEOUT: Duration = Duration::from_secs(3);

    fn stamped(message: impl Into<Message>, ms: u64) -> Message {
        let mut m = message.into();
        m.set_time_stamp(testkit::ts(ms));
        m
    }

    fn waypoint(number: u16, next: u16, ms: u64) -> Message {
        let at = (48.27 + f64::from(number) * 0.001, 11.65);
        stamped(testkit::waypoint(number, next, at, LegType::TrackToFix), ms)
    }

    fn numbers(receiver: &MissionReceiver) -> std::vec::Vec<u16> {
        (1..=9)
            .filter(|n| receiver.buffer.entry(Entry::Waypoint(*n)).is_some())
            .collect()
    }

    /// ICD §10.3: the opener applies beneath the data stamped after it that overtook it, and
    /// resets what was stored before it.
    #[test]
    fn an_overtaken_opener_keeps_the_data_sent_after_it() {
        let at = Instant::from_millis(1);
        let base = mission_1().assemble().unwrap().mission;
        // An edit open on the active mission (waypoint 1) and a data message of an upload
        // abandoned earlier (waypoint 7, stamped 5).
        let mut r = MissionReceiver::new(TIMEOUT);
        r.abandon(Some(&base));
        assert_eq!(r.handle(at, &waypoint(7, 0, 5)), Ok(Received::Stored));
        // The new upload: clear at 10, waypoints 2 and 3 at 11 and 12, which arrive first.
        assert_eq!(r.handle(at, &waypoint(2, 3, 11)), Ok(Received::Stored));
        assert_eq!(r.handle(at, &waypoint(3, 0, 12)), Ok(Received::Stored));
        assert_eq!(numbers(&r), [1, 2, 3, 7]);
        assert_eq!(r.clear(at, testkit::ts(10)), Ok(()));
        assert_eq!(numbers(&r), [2, 3], "the base and the older data are gone");
        // Late messages of before the clear change nothing.
        assert_eq!(
            r.handle(at, &waypoint(4, 0, 9)),
            Err(Reason::WrongState),
            "data stamped before the opener"
        );
        assert_eq!(
            r.clear(at, testkit::ts(8)),
            Err(Reason::WrongState),
            "an opener stamped before the one applied"
        );
        assert_eq!(
            r.handle(at, &waypoint(3, 4, 11)),
            Err(Reason::WrongState),
            "stamped before the message that stored its entry"
        );
        assert_eq!(numbers(&r), [2, 3]);
        // The rest of the upload in any order.
        for m in [
            stamped(testkit::route(2, false), 14),
            stamped(testkit::take_off(30.0), 13),
        ] {
            assert_eq!(r.handle(at, &m), Ok(Received::Stored));
        }
        let closer = stamped(
            crate::transfer::sender::mission_command(
                MissionPlanMode::TransmitMission,
                Some(2),
                None,
            ),
            15,
        );
        assert_eq!(r.handle(at, &closer), Ok(Received::Complete));
        let mission = r.take().unwrap();
        assert_eq!(
            mission
                .waypoints
                .iter()
                .map(|w| w.waypoint.waypoint_number)
                .collect::<std::vec::Vec<_>>(),
            [2, 3]
        );
    }

    /// ICD §10.3, mode 10: the list loaded fills what no later message stored.
    #[test]
    fn a_buffer_load_overtaken_by_its_data_loads_beneath_them() {
        let at = Instant::from_millis(1);
        let base = mission_1().assemble().unwrap().mission;
        let mut r = MissionReceiver::new(TIMEOUT);
        r.abandon(None);
        let mut moved = waypoint(1, 0, 21);
        if let Message::UaPositionWaypoint(w) = &mut moved {
            w.latitude = base.waypoints[0].waypoint.latitude;
            w.longitude = base.waypoints[0].waypoint.longitude;
            w.altitude = missionlink_interfaces::wire::Altitude::from_metres(321.0).unwrap();
        }
        assert_eq!(r.handle(at, &moved), Ok(Received::Stored));
        assert_eq!(r.load(at, Some(&base), testkit::ts(20)), Ok(()));
        let closer = stamped(
            crate::transfer::sender::mission_command(
                MissionPlanMode::TransmitMission,
                Some(1),
                None,
            ),
            22,
        );
        assert_eq!(r.handle(at, &closer), Ok(Received::Complete));
        let mission = r.take().unwrap();
        assert_eq!(mission.take_off, base.take_off, "from the list loaded");
        assert_eq!(mission.route, base.route);
        assert_eq!(
            mission.waypoints[0].waypoint.altitude.metres(),
            321.0,
            "the data kept"
        );
    }

    /// Stop and wait (edition 1): stamp order is arrival order, and an opener resets all.
    #[test]
    fn in_arrival_order_an_opener_resets_everything() {
        let at = Instant::from_millis(1);
        let mut r = MissionReceiver::new(TIMEOUT);
        r.abandon(None);
        assert_eq!(r.handle(at, &waypoint(1, 0, 1)), Ok(Received::Stored));
        assert_eq!(r.clear(at, testkit::ts(2)), Ok(()));
        assert_eq!(numbers(&r), []);
        assert_eq!(r.handle(at, &waypoint(2, 0, 3)), Ok(Received::Stored));
        assert_eq!(r.clear(at, testkit::ts(4)), Ok(()));
        assert_eq!(numbers(&r), []);
    }

    /// ICD §10.3: an area opener stamped before a message of the open transfer changes nothing.
    #[test]
    fn a_late_area_opener_changes_nothing() {
        let at = Instant::from_millis(1);
        let opener = |ms| {
            stamped(
                AreaTransmissionCommand {
                    loop_count: Some(1),
                    ..crate::transfer::sender::area_transfer_command(
                        AreaTransferMode::InitiateUpload,
                        None,
                    )
                },
                ms,
            )
        };
        let area = stamped(
            testkit::polygon(
                1,
                missionlink_interfaces::wire::AreaType::FlyZone,
                &testkit::FLY_ZONE,
            ),
            12,
        );
        let mut r = AreaReceiver::new(TIMEOUT);
        assert_eq!(
            r.handle(at, &area),
            Err(Reason::WrongState),
            "no transfer open"
        );
        assert_eq!(r.handle(at, &opener(11)), Ok(Received::Stored));
        assert_eq!(r.handle(at, &area), Ok(Received::Stored));
        assert_eq!(r.handle(at, &opener(10)), Err(Reason::WrongState));
        assert_eq!(r.buffer.len(), 1, "the area stays");
        // A newer opener begins again.
        assert_eq!(r.handle(at, &opener(13)), Ok(Received::Stored));
        assert_eq!(r.buffer.len(), 0);
    }
}
