//! Mission data handling on the FCC (paper §3.1): the partition's whole logic, sans-IO.
//!
//! Every uplink frame goes through preprocessing ([`Endpoint::receive`]: integrity, addressing,
//! decoding, message sampling), then the moding of paper §3.1.2 routes it to the function that
//! handles it:
//!
//! | message | function |
//! |---|---|
//! | #13000 mode 1 clear, mode 2 transmit, #13001, #13002, #13006 | mission upload ([`MissionReceiver`]) |
//! | #13000 mode 3 receive | mission download ([`TransferSender`], [`Script::MissionDownload`]) |
//! | #2011 mode 1, 2, #2012 | area upload ([`AreaReceiver`]); mode 2 answered by #3012 |
//! | #2011 mode 3 | area download ([`Script::AreaDownload`]), opened by #3013 |
//! | #2011 mode 6 | clear areas |
//! | #13000 mode 5, #2011 mode 5 | cancel the transfer in progress |
//! | #17000 | the download in progress |
//! | #50000 | mission execute: answered here by the rule of [`automation::check_command`], carried out by system automation |
//!
//! Active lists change only when a complete new list is valid; a failed or abandoned transfer
//! leaves them as they were. Steady-state handling allocates nothing.
//!
//! **Activation.** Every way lists become active (the closer of a mission or an area upload, a
//! clear of either, a staged mission's activation of ICD §8, the resume after a restart) is one
//! call of `activate` with an `Activation` that says which: it sets the lists and their
//! generations (each list's counts its every change, clears included), rebuilds the payloads
//! guidance reads with the *activation* of the pair (the sum of both generations, so a pair of
//! lists is never mixed with another's), the onboard check's fence and FROM-TO-NEXT, and queues
//! the one event ([`FccEvent`]) from which the driver publishes and records them.
//!
//! The deadlines of the transfers (the download messages' ack timeouts, the uploads' transfer
//! timeouts) are owned by the transfers; [`FccTimer`] names them, one per transfer, as in the
//! GCS logic (`link::composite::Composite`): `poll_timeout` is their earliest, and
//! `handle_timeout` fires the transfers whose deadlines are due.
//!
//! The clear of ICD §5.1 step 1 (#13000 mode 1) empties the waypoint buffer at once, but the
//! active list only with the #13000 mode 2 that closes the transfer. This project's choice where
//! the ICD's "empties ... the active list" meets the rule above: a full upload that fails after
//! its clear would otherwise leave the FCC without its mission. To clear the active mission, a
//! GCS sends the clear and then #13000 mode 2 with Waypoint Number 0, which activates the empty
//! list ([`crate::transfer::sender::Script::MissionClear`]). A clear whose transfer is abandoned changes
//! nothing.
//!
//! **A newer opener ends what is left open.** A transfer opener from the GCS ends the download of
//! the same kind whose request it is stamped after, and the upload of the same kind whose newest
//! message it is stamped after: the GCS is done with them (this project's choice where the ICD
//! is silent; see `end_transfers_before`).
//!
//! **Closers are idempotent (ICD §11).** The last closer answered and its answer are remembered
//! ([`CloserMemory`]): its retry, until an opener or a data message is accepted, gets the same
//! answer and changes nothing, so a lost "valid and active" never turns into a reported failure.
//!
//! **A restart never assembles a transfer it did not see from the start.** A mission
//! upload has no opener when it is an edit (ICD §5.1 step 1 is optional), so a restarted
//! partition cannot tell the rest of an upload cut by its restart from a new edit: taken as an
//! edit of the active list, it assembled a list that was neither the old mission nor the new one.
//! The driver therefore records, before any answer leaves, that a mission upload is open
//! ([`FccEvent::MissionUploadOpened`], [`FccEvent::MissionUploadClosed`]); a partition that
//! resumes with that record set holds the upload *interrupted*: it refuses the upload's data
//! messages and its transmit (`WrongState`) until the GCS opens a new one (clear), cancels, or
//! falls silent for the transfer timeout, the time after which the upload would have been
//! abandoned anyway (ICD §5). The GCS's retry is refused as well and it aborts with the active
//! lists as they were. Keeping the whole buffer on disk so the transfer could resume exactly would
//! cost a write per message; the record costs two per upload, and with the checksum of ICD §11
//! an edition-2 GCS would detect such a list anyway.

use core::time::Duration;

use heapless::Deque;
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationStatePayload, GuidanceProgressPayload, WaypointListPayload,
};
use missionlink_interfaces::wire::{
    AreaDownloadStatus, AreaListStatus, AreaStatusAlert, AreaTransferMode, AreaTransmissionCommand,
    AreaTransmissionStatus, EncodeError, ExecuteCommand, FrameError, Message, MissionPlanMode,
    MissionReport, MissionTransferCommand, Reason, SafetyOffset, Text, Timestamp,
};

use crate::automation;
use crate::from_to_next::FromToNextReporter;
use crate::geofence::zone::Fence;
use crate::link::composite::Composite;
use crate::link::endpoint::{Endpoint, EndpointConfig};
use crate::link::retry::ExchangeError;
use crate::link::time::Instant;
use crate::link::timer::Timer;
use crate::transfer::areas::AreaList;
use crate::transfer::closer::{Closer, CloserMemory, ClosingAnswer};
use crate::transfer::integrity::{areas_checksum, mission_checksum};
use crate::transfer::mission::Mission;
use crate::transfer::receiver::{AreaReceiver, MissionReceiver, Received, TransferTimedOut};
use crate::transfer::sender::{Script, SenderEvent, TransferSender};
use crate::transfer::staged::{MissionId, StagedMissions};

/// Settings of mission data handling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FccConfig {
    /// Addresses and clocks.
    pub endpoint: EndpointConfig,
    /// How long a download message waits for the GCS's answer (ICD §1: 500 ms).
    pub ack_timeout: Duration,
    /// How long an upload waits for the GCS before it is abandoned (ICD §1: 3 s).
    pub transfer_timeout: Duration,
}

/// What the driver must know of: the lists to publish, failures to log, commands to forward.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FccEvent {
    /// A new waypoint list is active (publish it).
    MissionActivated {
        /// Its generation.
        generation: u64,
    },
    /// The waypoint list was cleared (publish the empty list).
    MissionCleared,
    /// A new area list is active (publish it).
    AreasActivated {
        /// Its generation.
        generation: u64,
    },
    /// The area list was cleared (publish the empty list).
    AreasCleared,
    /// An upload was abandoned: cancelled by the GCS or timed out. A refused closer is answered
    /// (and remembered, ICD §11) but raises no event of its own.
    UploadAbandoned {
        /// Mission or area upload.
        kind: DataKind,
        /// Why, where known.
        reason: Option<Reason>,
    },
    /// A download was complete and acknowledged.
    DownloadComplete {
        /// Mission or area download.
        kind: DataKind,
    },
    /// A download ended without its last answer: the GCS opened a new transfer of the same
    /// kind after it ([`MissionDataHandling`]'s `end_download_before`).
    DownloadEnded {
        /// Mission or area download.
        kind: DataKind,
    },
    /// A download message failed twice.
    DownloadFailed {
        /// Mission or area download.
        kind: DataKind,
        /// The failure.
        error: ExchangeError,
    },
    /// #50000 accepted: system automation carries it out.
    Execute(ExecuteCommand),
    /// A mission upload is open: record it (with the lists) before any answer goes out, so a
    /// restarted partition knows the upload was cut (see the module documentation).
    MissionUploadOpened,
    /// No mission upload is open any more: remove the record.
    MissionUploadClosed,
    /// A list was stored under a staged Mission ID (ICD §8: #13000 mode 8 or #2011 mode 7): record
    /// it ([`MissionDataHandling::staged`]) so a restart keeps it. The active lists did not
    /// change.
    StagedStored {
        /// The staged mission.
        id: MissionId,
        /// Which list: [`DataKind::Mission`] or [`DataKind::Areas`].
        kind: DataKind,
    },
    /// A staged mission was deleted (ICD §8: #13000 mode 6): remove its record.
    StagedDeleted {
        /// The staged mission.
        id: MissionId,
    },
    /// A staged mission replaced both active lists in one step (ICD §8: #50000 command 4):
    /// publish both, which carry the same activation (see the module documentation). Raised
    /// instead of [`FccEvent::MissionActivated`] and [`FccEvent::AreasActivated`]; the staged
    /// copy stays staged.
    StagedActivated {
        /// The staged mission now active.
        id: MissionId,
        /// The new generation of the waypoint list.
        mission_generation: u64,
        /// The new generation of the area list.
        area_generation: u64,
    },
}

/// Mission (waypoints), areas, or the report of both.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataKind {
    /// Waypoint list.
    Mission,
    /// Area list.
    Areas,
    /// The mission report (ICD §8, #50001): sent, never uploaded.
    Report,
}

/// Events the queue holds; the driver drains it after every call.
pub const EVENT_CAPACITY: usize = 8;

/// The timers of mission data handling, one per transfer: each names the deadline of the
/// sender or receiver that runs the transfer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FccTimer {
    /// The ack timeout of the mission download message in flight (ICD §1: 500 ms).
    MissionDownload = 0,
    /// The ack timeout of the area download message in flight.
    AreaDownload = 1,
    /// The transfer timeout of the mission upload (ICD §1: 3 s).
    MissionUpload = 2,
    /// The transfer timeout of the area upload.
    AreaUpload = 3,
    /// The end of a mission upload interrupted by a restart: the transfer timeout after the
    /// GCS was last heard in it.
    InterruptedUpload = 4,
    /// The ack timeout of the report message in flight (ICD §8).
    Report = 5,
}

impl Timer<6> for FccTimer {
    const ALL: [Self; 6] = [
        Self::MissionDownload,
        Self::AreaDownload,
        Self::MissionUpload,
        Self::AreaUpload,
        Self::InterruptedUpload,
        Self::Report,
    ];
    fn index(self) -> usize {
        self as usize
    }
}

/// Mission data handling of the FCC.
#[derive(Debug, Clone)]
pub struct MissionDataHandling {
    config: FccConfig,
    endpoint: Endpoint,
    mission_upload: MissionReceiver,
    area_upload: AreaReceiver,
    mission_download: Option<TransferSender>,
    area_download: Option<TransferSender>,
    /// The time stamps of the requests that opened the downloads in progress, `[mission,
    /// areas]`: a newer opener from the GCS ends its download ([`Self::end_transfers_before`]).
    download_requests: [Timestamp; 2],
    /// The newest time stamp of a message of each kind's upload, `[mission, areas]`: a newer
    /// opener from the GCS ends the upload still open ([`Self::end_transfers_before`]).
    upload_stamps: [Timestamp; 2],
    report: Option<TransferSender>,
    active_mission: Option<Mission>,
    mission_generation: u64,
    active_areas: Option<AreaList>,
    area_generation: u64,
    automation: AutomationStatePayload,
    /// Guidance's last progress: where the onboard geofence check starts from (ICD §7).
    navigation: GuidanceProgressPayload,
    events: Deque<FccEvent, EVENT_CAPACITY>,
    /// The lists as published, rebuilt only when they change.
    waypoint_list: WaypointListPayload,
    area_list: AreaListPayload,
    /// The active area list as the onboard geofence check takes it (ICD §7), rebuilt in place
    /// when the list changes.
    fence: Box<Fence>,
    /// The staged missions (ICD §8).
    staged: StagedMissions,
    /// A staged area list as the onboard geofence check takes it, rebuilt in place for each
    /// check of a staged mission (report, activation): allocated once.
    staged_fence: Box<Fence>,
    from_to_next: FromToNextReporter,
    /// The last closer answered (ICD §11).
    closers: CloserMemory,
    /// While a mission upload cut by a restart is refused: until when.
    interrupted_until: Option<Instant>,
    /// Whether the driver was last told that a mission upload is open.
    upload_recorded_open: bool,
}

/// A way lists become active; [`MissionDataHandling::activate`] carries out each.
#[derive(Debug)]
enum Activation {
    /// The closer of a mission upload (ICD §5.1): the assembled waypoint list, or none (the
    /// empty list that clears it).
    Mission(Option<Mission>),
    /// The closer of an area upload (ICD §5.3), or the clear of the areas (none).
    Areas(Option<AreaList>),
    /// A staged mission's waypoint and area list in one step (ICD §8).
    Staged {
        /// The staged mission.
        id: MissionId,
        /// Its waypoint list.
        mission: Mission,
        /// Its area list.
        areas: AreaList,
    },
    /// After a restart: the recorded lists (or none, after a clear) under their recorded
    /// generations, so guidance sees no change; no event.
    Resumed {
        /// The waypoint list.
        mission: Option<Mission>,
        /// Its generation.
        mission_generation: u64,
        /// The area list.
        areas: Option<AreaList>,
        /// Its generation.
        area_generation: u64,
    },
}

/// What mission data handling resumes with after a restart: what the driver recorded.
#[derive(Debug, Clone, Default)]
pub struct Resumed {
    /// The active mission, if any.
    pub mission: Option<Mission>,
    /// Its generation (counts clears too).
    pub mission_generation: u64,
    /// The active area list, if any.
    pub areas: Option<AreaList>,
    /// Its generation.
    pub area_generation: u64,
    /// A mission upload was open when the partition stopped.
    pub mission_upload_open: bool,
    /// The staged missions (ICD §8), kept across a restart like the active lists.
    pub staged: StagedMissions,
}

impl MissionDataHandling {
    /// Mission data handling with no active lists.
    pub fn new(config: FccConfig) -> Self {
        Self {
            config,
            endpoint: Endpoint::new(config.endpoint),
            mission_upload: MissionReceiver::new(config.transfer_timeout),
            area_upload: AreaReceiver::new(config.transfer_timeout),
            mission_download: None,
            area_download: None,
            download_requests: [Timestamp::default(); 2],
            upload_stamps: [Timestamp::default(); 2],
            report: None,
            active_mission: None,
            mission_generation: 0,
            active_areas: None,
            area_generation: 0,
            automation: AutomationStatePayload::ON_GROUND,
            navigation: GuidanceProgressPayload::IDLE,
            events: Deque::new(),
            waypoint_list: WaypointListPayload::EMPTY,
            area_list: AreaListPayload::EMPTY,
            fence: Box::new(Fence::empty()),
            staged: StagedMissions::new(),
            staged_fence: Box::new(Fence::empty()),
            from_to_next: FromToNextReporter::new(),
            closers: CloserMemory::new(),
            interrupted_until: None,
            upload_recorded_open: false,
        }
    }

    /// Resumes at `now` with what was recorded before a restart: the lists that were active
    /// (or none, after a clear) under their generations (and so under the same activation), so
    /// guidance sees no change and later lists get newer generations; the staged missions; and
    /// a mission upload that was open, which is now held interrupted (see the module
    /// documentation).
    pub fn resume(&mut self, now: Instant, resumed: Resumed) {
        let Resumed {
            mission,
            mission_generation,
            areas,
            area_generation,
            mission_upload_open,
            staged,
        } = resumed;
        self.activate(Activation::Resumed {
            mission,
            mission_generation,
            areas,
            area_generation,
        });
        self.mission_upload.abandon(self.active_mission.as_ref());
        self.staged = staged;
        if mission_upload_open {
            tracing::warn!(
                "a mission upload was open when the partition stopped: its remaining messages \
                 are refused until the GCS opens a new one, cancels, or falls silent"
            );
            self.interrupted_until = Some(now + self.config.transfer_timeout);
            self.upload_recorded_open = true;
        }
    }

    /// The generation of the active waypoint list and of the active area list.
    pub fn generations(&self) -> (u64, u64) {
        (self.mission_generation, self.area_generation)
    }

    /// The endpoint (counters, configuration).
    pub fn endpoint(&self) -> &Endpoint {
        &self.endpoint
    }

    /// The active mission.
    pub fn active_mission(&self) -> Option<&Mission> {
        self.active_mission.as_ref()
    }

    /// The active area list.
    pub fn active_areas(&self) -> Option<&AreaList> {
        self.active_areas.as_ref()
    }

    /// The active waypoint list as published to guidance (empty when none; the generation
    /// counts every change, clears included).
    pub fn waypoint_list(&self) -> &WaypointListPayload {
        &self.waypoint_list
    }

    /// The active area list as published to guidance.
    pub fn area_list(&self) -> &AreaListPayload {
        &self.area_list
    }

    /// The staged missions (ICD §8), to record after [`FccEvent::StagedStored`] and
    /// [`FccEvent::StagedDeleted`].
    pub fn staged(&self) -> &StagedMissions {
        &self.staged
    }

    /// Makes lists active, the one way every change of the active lists takes (module
    /// documentation, "Activation"): the new lists under their generations, the payloads
    /// published to guidance rebuilt, both carrying the activation of the pair they form now
    /// (the sum of the generations, which grows with every change of either), the onboard
    /// check's fence and FROM-TO-NEXT following, and the event that tells the driver to publish
    /// and record them.
    fn activate(&mut self, activation: Activation) {
        let next = (self.mission_generation + 1, self.area_generation + 1);
        let (mission, areas, (mission_generation, area_generation), event) = match activation {
            Activation::Mission(mission) => {
                let event = match mission {
                    Some(_) => FccEvent::MissionActivated { generation: next.0 },
                    None => FccEvent::MissionCleared,
                };
                (Some(mission), None, next, Some(event))
            }
            Activation::Areas(areas) => {
                let event = match areas {
                    Some(_) => FccEvent::AreasActivated { generation: next.1 },
                    None => FccEvent::AreasCleared,
                };
                (None, Some(areas), next, Some(event))
            }
            Activation::Staged { id, mission, areas } => {
                let event = FccEvent::StagedActivated {
                    id,
                    mission_generation: next.0,
                    area_generation: next.1,
                };
                (Some(Some(mission)), Some(Some(areas)), next, Some(event))
            }
            Activation::Resumed {
                mission,
                mission_generation,
                areas,
                area_generation,
            } => (
                Some(mission),
                Some(areas),
                (mission_generation, area_generation),
                None,
            ),
        };
        if let Some(mission) = mission {
            self.mission_generation = mission_generation;
            self.waypoint_list = match &mission {
                Some(m) => m.to_payload(mission_generation),
                None => WaypointListPayload {
                    generation: mission_generation,
                    ..WaypointListPayload::EMPTY
                },
            };
            self.active_mission = mission;
            self.from_to_next.reset();
        }
        if let Some(areas) = areas {
            self.area_generation = area_generation;
            self.area_list = match &areas {
                Some(a) => a.to_payload(area_generation),
                None => AreaListPayload {
                    generation: area_generation,
                    ..AreaListPayload::EMPTY
                },
            };
            self.active_areas = areas;
            self.fence.set_payload(&self.area_list);
        }
        let activation = self.mission_generation + self.area_generation;
        self.waypoint_list.activation = activation;
        self.area_list.activation = activation;
        if let Some(event) = event {
            self.event(event);
        }
    }

    /// Guidance reported its progress: #4001 goes out when FROM, TO or NEXT changed (paper
    /// §3.1.7, ICD §5.5).
    pub fn handle_progress(&mut self, now: Instant, progress: &GuidanceProgressPayload) {
        self.navigation = *progress;
        if let Some(ftn) =
            self.from_to_next
                .update(progress, &self.waypoint_list, Timestamp::default())
        {
            self.endpoint.send(now, ftn.into(), false);
        }
    }

    /// System automation published its state: the flight phase decides whether a #50000 is
    /// accepted, and a clear is refused while trajectory generation is active (ICD §5.1 step 1).
    pub fn set_automation_state(&mut self, state: &AutomationStatePayload) {
        self.automation = *state;
    }

    /// Handles one uplink message (wrapper to checksum) received at `now`. A frame error is
    /// returned for the driver to count and log; it is never answered (ICD §2).
    pub fn handle_frame(&mut self, now: Instant, bytes: &[u8]) -> Result<(), FrameError> {
        let result = self.receive_frame(now, bytes);
        self.record_upload_state();
        result
    }

    /// Whether a mission upload is open, cut by a restart included.
    fn mission_upload_open(&self) -> bool {
        self.mission_upload.in_transfer() || self.interrupted_until.is_some()
    }

    /// Tells the driver when a mission upload opened or closed, to record it before the answers
    /// go out.
    fn record_upload_state(&mut self) {
        let open = self.mission_upload_open();
        if open != self.upload_recorded_open {
            self.upload_recorded_open = open;
            self.event(if open {
                FccEvent::MissionUploadOpened
            } else {
                FccEvent::MissionUploadClosed
            });
        }
    }

    /// The mission upload cut by a restart heard from the GCS again: refused (it cannot be
    /// resumed), and held for another transfer timeout.
    fn refuse_interrupted(&mut self, now: Instant) -> Result<(), Reason> {
        self.interrupted_until = Some(now + self.config.transfer_timeout);
        Err(Reason::WrongState)
    }

    /// Answers `message` (an opener or a data message of a transfer) with `outcome`; an
    /// accepted one ends the memory of the last closer (ICD §11).
    fn answer_transfer(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        outcome: Result<(), Reason>,
    ) {
        if outcome.is_ok() {
            self.closers.forget();
        }
        self.endpoint.answer(now, message, ack, outcome);
    }

    /// A closer (ICD §10.2): the retry of the closer answered last gets the same answer and
    /// changes nothing (ICD §11); any other is carried out and remembered.
    fn closer(&mut self, now: Instant, message: &Message, ack: bool) {
        let answer = match Closer::of(message) {
            Some(closer) => match self.closers.repeat(&closer) {
                Some(answer) => answer,
                None => {
                    let answer = self.close(now, message);
                    self.closers.remember(closer, answer);
                    answer
                }
            },
            None => self.close(now, message),
        };
        self.answer_closer(now, message, ack, answer);
    }

    /// Carries out a closer: assembles the list and activates it (mode 2) or stages it (ICD §8:
    /// #13000 mode 8, #2011 mode 7), or says why not.
    fn close(&mut self, now: Instant, message: &Message) -> ClosingAnswer {
        match message {
            Message::AreaTransmissionCommand(_) => self.complete_area_upload(now, message),
            Message::MissionTransferCommand(c) if c.mode == MissionPlanMode::StageMission => {
                ClosingAnswer::Acknowledgement(self.stage_mission(now, message, c.mission_id))
            }
            _ => ClosingAnswer::Acknowledgement(self.mission_data(now, message)),
        }
    }

    /// Sends `answer` to the closer `message`: #17000 or #3012.
    fn answer_closer(&mut self, now: Instant, message: &Message, ack: bool, answer: ClosingAnswer) {
        match answer {
            ClosingAnswer::Acknowledgement(outcome) => {
                self.endpoint.answer(now, message, ack, outcome);
            }
            ClosingAnswer::AreaStatus {
                loop_count,
                outcome,
            } => {
                let alert = AreaStatusAlert {
                    time_stamp: Timestamp::default(),
                    loop_count,
                    status: if outcome.is_ok() {
                        AreaListStatus::Valid
                    } else {
                        AreaListStatus::Invalid
                    },
                    reason: Some(outcome.err().unwrap_or(Reason::None)),
                };
                self.endpoint.send(now, alert.into(), false);
            }
        }
    }

    fn event(&mut self, e: FccEvent) {
        if self.events.push_back(e).is_err() {
            tracing::error!("event queue full: the driver does not drain it");
        }
    }

    fn clear_mission(&mut self, now: Instant) -> Result<(), Reason> {
        if self.automation.trajectory_generation_active {
            return Err(Reason::GuidanceActive);
        }
        if self.mission_download.is_some() {
            return Err(Reason::Busy);
        }
        // The buffer empties now; the active list changes only with the transmit that closes
        // the transfer (see the module documentation).
        self.mission_upload.clear(now);
        Ok(())
    }

    fn clear_areas(&mut self) -> Result<(), Reason> {
        if self.automation.trajectory_generation_active {
            return Err(Reason::GuidanceActive);
        }
        if self.area_download.is_some() || self.area_upload.in_transfer() {
            return Err(Reason::Busy);
        }
        if self.active_areas.is_some() {
            self.activate(Activation::Areas(None));
            self.closers.forget();
        }
        Ok(())
    }

    /// One message of a mission upload to the waypoint buffer: a data message or a closer
    /// (#13000 mode 2 or 8), handed to the receiver.
    fn upload_step(&mut self, now: Instant, message: &Message) -> Result<Received, Reason> {
        if self.mission_download.is_some() {
            return Err(Reason::WrongState);
        }
        if self.interrupted_until.is_some() {
            self.refuse_interrupted(now)?;
        }
        if !self.mission_upload.in_transfer() {
            // An upload without clear (or mode 10) edits the active mission, as in edition 1.
            self.mission_upload.abandon(self.active_mission.as_ref());
        }
        self.mission_upload.handle(now, message)
    }

    /// Mission upload: store, or assemble and activate on #13000 mode 2.
    fn mission_data(&mut self, now: Instant, message: &Message) -> Result<(), Reason> {
        match self.upload_step(now, message)? {
            Received::Complete => {
                let Some(mission) = self.mission_upload.take() else {
                    return Err(Reason::WrongState);
                };
                if self.active_mission.as_ref() != Some(&mission) {
                    self.activate(Activation::Mission(Some(mission)));
                }
                Ok(())
            }
            Received::Emptied => {
                if self.active_mission.is_some() {
                    self.activate(Activation::Mission(None));
                }
                Ok(())
            }
            Received::Stored | Received::Abandoned(_) => Ok(()),
        }
    }

    /// #13000 mode 8 (ICD §8): assembles the waypoint buffer as mode 2 does and stores the list
    /// under the Mission ID; the active lists do not change. A ninth ID is refused (`Capacity`)
    /// before the assembly, so the upload stays as it was.
    fn stage_mission(
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
    /// upload, so an upload cut by a restart is over.
    fn load_buffer(&mut self, now: Instant, id: Option<Text<20>>) -> Result<(), Reason> {
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
        self.mission_upload.load(now, base);
        self.interrupted_until = None;
        Ok(())
    }

    /// #13000 mode 6 (ICD §8): deletes the staged mission (`WrongState` when there is none).
    fn delete_staged(&mut self, id: Option<Text<20>>) -> Result<(), Reason> {
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
    fn activate_staged(&mut self, id: Option<Text<20>>) -> Result<(), Reason> {
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
        // The last closer's "valid and active" is no longer true (see `CloserMemory`).
        self.closers.forget();
        Ok(())
    }

    /// #2011 mode 2 or 7 (ICD §5.3, §8): assembles the area list, then activates it or stores it
    /// under the Mission ID; answered by #3012 with the loop count of that list.
    fn complete_area_upload(&mut self, now: Instant, message: &Message) -> ClosingAnswer {
        let result = self.area_closer(now, message);
        ClosingAnswer::AreaStatus {
            loop_count: result.unwrap_or(0),
            outcome: result.map(|_| ()),
        }
    }

    /// The area closer `message`: the loop count of the list activated or staged, or why not.
    fn area_closer(&mut self, now: Instant, message: &Message) -> Result<u8, Reason> {
        let staged = match message {
            Message::AreaTransmissionCommand(c)
                if c.mode == AreaTransferMode::UploadCompleteStaged =>
            {
                Some(staged_id(c.mission_id)?)
            }
            _ => None,
        };
        if self.area_download.is_some() {
            return Err(Reason::WrongState);
        }
        if staged.is_some_and(|id| !self.staged.can_store(&id)) {
            return Err(Reason::Capacity);
        }
        match self.area_upload.handle(now, message)? {
            Received::Complete => {}
            Received::Stored | Received::Abandoned(_) | Received::Emptied => {
                return Err(Reason::WrongState);
            }
        }
        let list = self.area_upload.take().ok_or(Reason::WrongState)?;
        let loop_count = list.areas.len() as u8;
        match staged {
            Some(id) => {
                if self.staged.store_areas(id, list)? {
                    self.event(FccEvent::StagedStored {
                        id,
                        kind: DataKind::Areas,
                    });
                }
            }
            None => {
                if self.active_areas.as_ref() != Some(&list) {
                    self.activate(Activation::Areas(Some(list)));
                }
            }
        }
        Ok(loop_count)
    }

    /// #13000 mode 3 (the active mission, ICD §5.2) or mode 9 (a staged mission's, ICD §8):
    /// acknowledged, then the download. No such list: `WrongState`, nothing follows.
    /// Ends the transfers of `kind` still open when `opener`, a transfer's opener from the GCS,
    /// is stamped after them: a download stamped-after its request, an upload after its newest
    /// message.
    ///
    /// The GCS runs one transfer at a time (ICD §5) and opens the next only when it is done
    /// with the one before, so such a transfer has no peer left. Kept, it would refuse the
    /// GCS's new transfer `Busy`:
    /// - a download, for up to twice the ack timeout, while it waits for the answer to its last
    ///   message that the GCS sent and the link lost (the `bad` link of `src/link_emulator.rs`);
    /// - an upload, for the transfer timeout, when a data message resent before the GCS gave
    ///   up arrives late, after the cancel, and opens an edit of its own (ICD §5.1: an upload
    ///   without clear edits the active mission).
    ///
    /// Ending an upload abandons its buffer; the active lists never change by it (§7). An
    /// opener stamped before is an old one, delayed on the link: it meets the transfer as
    /// before. This project's choice: the ICD says nothing of transfers that outlive their GCS.
    fn end_transfers_before(&mut self, kind: DataKind, opener: &Message) {
        let stamp = opener.time_stamp();
        let (requested, uploaded, download) = match kind {
            DataKind::Mission => (
                self.download_requests[0],
                self.upload_stamps[0],
                &mut self.mission_download,
            ),
            DataKind::Areas => (
                self.download_requests[1],
                self.upload_stamps[1],
                &mut self.area_download,
            ),
            DataKind::Report => return,
        };
        if stamp > requested {
            if let Some(mut d) = download.take() {
                d.cancel();
                self.event(FccEvent::DownloadEnded { kind });
            }
        }
        if stamp <= uploaded {
            return;
        }
        let abandoned = match kind {
            DataKind::Mission if self.mission_upload.in_transfer() => {
                self.mission_upload.abandon(self.active_mission.as_ref());
                true
            }
            DataKind::Areas if self.area_upload.in_transfer() => {
                self.area_upload.abandon();
                true
            }
            _ => false,
        };
        if abandoned {
            self.event(FccEvent::UploadAbandoned { kind, reason: None });
        }
    }

    fn start_mission_download(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        request: &MissionTransferCommand,
    ) {
        let mission = if request.mode == MissionPlanMode::ReceiveStagedMission {
            staged_id(request.mission_id)
                .map(|id| self.staged.get(&id).and_then(|e| e.mission.clone()))
        } else {
            Ok(self.active_mission.clone())
        };
        let busy = self.mission_download.is_some() || self.mission_upload.in_transfer();
        let mission = match mission {
            Err(reason) => Err(reason),
            Ok(_) if busy => Err(Reason::Busy),
            Ok(None) => Err(Reason::WrongState),
            Ok(Some(mission)) => Ok(mission),
        };
        self.answer_transfer(
            now,
            message,
            ack,
            mission.as_ref().map(|_| ()).map_err(|r| *r),
        );
        if let Ok(mission) = mission {
            // Edition-2 fields only to an edition-2 request (ICD §10.2: it carries the window).
            let checksum = request
                .transfer_window
                .is_some()
                .then(|| mission_checksum(&mission));
            // ICD §10.2: the window the GCS put into its request, 1 when absent.
            let window = request.transfer_window.unwrap_or_default().get();
            self.download_requests[0] = message.time_stamp();
            self.mission_download = Some(TransferSender::start_windowed(
                Script::MissionDownload { mission, checksum },
                usize::from(window),
                self.config.ack_timeout,
                &mut self.endpoint,
                now,
            ));
        }
    }

    /// #2011 mode 3 (the active areas, ICD §5.4) or mode 8 (a staged mission's, ICD §8): opened
    /// by #3013. With mode 8, an invalid Mission ID or no such list is answered by #17000 type 3
    /// (`Malformed`, `WrongState`) and nothing follows (ICD §8); busy is answered as for mode 3.
    fn start_area_download(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        request: &AreaTransmissionCommand,
    ) {
        let list = if request.mode == AreaTransferMode::InitiateStagedDownload {
            let list = staged_id(request.mission_id).and_then(|id| {
                self.staged
                    .get(&id)
                    .and_then(|e| e.areas.clone())
                    .ok_or(Reason::WrongState)
            });
            match list {
                Ok(list) => Some(list),
                Err(reason) => {
                    self.endpoint.answer(now, message, ack, Err(reason));
                    return;
                }
            }
        } else {
            self.active_areas.clone()
        };
        // ICD §4 #2011 field 3: "mode 3: 0 = all areas, else that one" (mode 8 "as with mode
        // 3"). An Area ID the list does not hold leaves nothing to send: aborted, as an empty
        // list is.
        let area_id = request.area_id.unwrap_or(0);
        let list = match area_id {
            0 => list,
            id => list.and_then(|l| l.only(id)),
        };
        let busy = self.area_download.is_some() || self.area_upload.in_transfer();
        match (list, busy) {
            (Some(list), false) => {
                self.closers.forget();
                // Edition-2 fields only to an edition-2 request (ICD §10.2).
                let checksum = request
                    .transfer_window()
                    .is_some()
                    .then(|| areas_checksum(&list));
                let window = request.transfer_window().unwrap_or_default().get();
                self.download_requests[1] = message.time_stamp();
                self.area_download = Some(TransferSender::start_windowed(
                    Script::AreaDownload {
                        list,
                        area_id,
                        checksum,
                    },
                    usize::from(window),
                    self.config.ack_timeout,
                    &mut self.endpoint,
                    now,
                ));
            }
            // Nothing to send, or busy: the #3013 says aborted (ICD §4: status 2).
            _ => {
                let status = AreaTransmissionStatus {
                    time_stamp: Timestamp::default(),
                    area_id,
                    loop_count: 0,
                    safety_offset: SafetyOffset::default(),
                    status: AreaDownloadStatus::Aborted,
                };
                self.endpoint.send(now, status.into(), false);
            }
        }
    }

    /// The sender of the download (or the report) of `kind`, and the endpoint it sends on.
    fn outgoing(&mut self, kind: DataKind) -> (&mut Option<TransferSender>, &mut Endpoint) {
        let slot = match kind {
            DataKind::Mission => &mut self.mission_download,
            DataKind::Areas => &mut self.area_download,
            DataKind::Report => &mut self.report,
        };
        (slot, &mut self.endpoint)
    }

    /// #13000 mode 7 (ICD §8): acknowledged, then the report of the active lists (and, with
    /// staged missions, of each). A new request replaces a report still in progress: the GCS
    /// that asks again has given up the earlier one.
    fn start_report(&mut self, now: Instant, message: &Message, ack: bool) {
        self.endpoint.answer(now, message, ack, Ok(()));
        if let Some(mut old) = self.report.take() {
            old.cancel();
        }
        let (geofence_check, reason) = automation::report_check(
            &self.waypoint_list,
            &self.area_list,
            &self.fence,
            &self.navigation,
        );
        let count = (1 + self.staged.len()) as u8;
        let active = MissionReport {
            time_stamp: Timestamp::default(),
            report_index: 1,
            report_count: count,
            // Present and empty: the active lists (ICD §8).
            mission_id: Some(Text::default()),
            waypoint_count: self
                .active_mission
                .as_ref()
                .map_or(0, |m| m.waypoints.len() as u16),
            area_count: self
                .active_areas
                .as_ref()
                .map_or(0, |a| a.areas.len() as u8),
            geofence_check,
            reason,
            mission_checksum: self.active_mission.as_ref().map(mission_checksum),
            area_checksum: self.active_areas.as_ref().map(areas_checksum),
        };
        let mut entries = heapless::Vec::new();
        // At most MAX_REPORT_ENTRIES: the active lists and MAX_STAGED_MISSIONS.
        let _ = entries.push(active);
        // Then each staged mission in ascending byte order of its ID (ICD §8), with the check
        // execute would run after its activation, against a fence built for its areas.
        for (index, entry) in self.staged.iter().enumerate() {
            let waypoint_list = entry
                .mission
                .as_ref()
                .map_or(WaypointListPayload::EMPTY, |m| m.to_payload(1));
            let area_list = entry
                .areas
                .as_ref()
                .map_or(AreaListPayload::EMPTY, |a| a.to_payload(1));
            self.staged_fence.set_payload(&area_list);
            let (geofence_check, reason) = automation::report_check(
                &waypoint_list,
                &area_list,
                &self.staged_fence,
                &self.navigation,
            );
            let _ = entries.push(MissionReport {
                time_stamp: Timestamp::default(),
                report_index: (index + 2) as u8,
                report_count: count,
                mission_id: Some(entry.id.text()),
                waypoint_count: entry
                    .mission
                    .as_ref()
                    .map_or(0, |m| m.waypoints.len() as u16),
                area_count: entry.areas.as_ref().map_or(0, |a| a.areas.len() as u8),
                geofence_check,
                reason,
                mission_checksum: entry.mission.as_ref().map(mission_checksum),
                area_checksum: entry.areas.as_ref().map(areas_checksum),
            });
        }
        self.report = Some(TransferSender::start(
            Script::MissionReport { entries },
            self.config.ack_timeout,
            &mut self.endpoint,
            now,
        ));
    }

    fn download_answer(&mut self, now: Instant, message: &Message) {
        for kind in [DataKind::Mission, DataKind::Areas, DataKind::Report] {
            let (slot, endpoint) = self.outgoing(kind);
            let Some(sender) = slot.as_mut() else {
                continue;
            };
            if let Some(event) = sender.handle_answer(endpoint, now, message) {
                self.download_event(kind, event);
                return;
            }
        }
        tracing::debug!("acknowledgement that answers nothing outstanding");
    }

    fn download_event(&mut self, kind: DataKind, event: SenderEvent) {
        let (slot, _) = self.outgoing(kind);
        match event {
            SenderEvent::Progress { .. } => {}
            SenderEvent::Completed(_) => {
                *slot = None;
                self.event(FccEvent::DownloadComplete { kind });
            }
            SenderEvent::Failed(error) => {
                *slot = None;
                self.event(FccEvent::DownloadFailed { kind, error });
            }
        }
    }

    fn cancel(&mut self, kind: DataKind) {
        match kind {
            DataKind::Mission => {
                if let Some(mut d) = self.mission_download.take() {
                    d.cancel();
                }
                if self.mission_upload.in_transfer() {
                    self.mission_upload.abandon(self.active_mission.as_ref());
                    self.event(FccEvent::UploadAbandoned { kind, reason: None });
                }
                self.interrupted_until = None;
            }

            DataKind::Areas => {
                if let Some(mut d) = self.area_download.take() {
                    d.cancel();
                }
                if self.area_upload.in_transfer() {
                    self.area_upload.abandon();
                    self.event(FccEvent::UploadAbandoned { kind, reason: None });
                }
            }
            DataKind::Report => {
                if let Some(mut r) = self.report.take() {
                    r.cancel();
                }
            }
        }
    }

    /// #50000 (ICD §4): the rule of system automation ([`automation::check_command`]).
    fn check_execute(&self, command: ExecuteCommand) -> Result<(), Reason> {
        automation::check_command(
            &self.automation,
            &self.waypoint_list,
            &self.area_list,
            &self.fence,
            &self.navigation,
            command,
        )
    }

    /// When [`MissionDataHandling::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.earliest_deadline()
    }

    /// The timers due at `now` fire: download retries, upload transfer timeouts.
    pub fn handle_timeout(&mut self, now: Instant) {
        self.fire_expired(now);
        self.record_upload_state();
    }

    fn upload_timed_out(&mut self, kind: DataKind, timed_out: TransferTimedOut) {
        tracing::warn!(
            ?kind,
            last_heard = ?timed_out.last_heard,
            "upload abandoned: nothing heard for the transfer timeout"
        );
        self.event(FccEvent::UploadAbandoned { kind, reason: None });
    }

    /// Encodes the next message to send into `buf`; returns the frame length.
    pub fn poll_transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        self.endpoint.poll_transmit(buf)
    }

    /// The next event for the driver.
    pub fn poll_event(&mut self) -> Option<FccEvent> {
        self.events.pop_front()
    }
}

/// The staged mission a request names (ICD §8: #13000 modes 6, 8, 9, #2011 modes 7, 8, #50000
/// command 4): absent is `MissingField`; empty, or not printable ASCII, is `Malformed` (our
/// choice: the ICD names the rule of the ID, not the reason; an empty ID names the active lists
/// only with mode 10).
fn staged_id(id: Option<Text<20>>) -> Result<MissionId, Reason> {
    let id = id.ok_or(Reason::MissingField)?;
    MissionId::of_text(&id).map_err(|_| Reason::Malformed)
}

impl Composite<FccTimer, 6> for MissionDataHandling {
    fn endpoint(&mut self) -> &mut Endpoint {
        &mut self.endpoint
    }

    fn deadline(&self, timer: FccTimer) -> Option<Instant> {
        let download =
            |s: &Option<TransferSender>| s.as_ref().and_then(TransferSender::poll_timeout);
        match timer {
            FccTimer::MissionDownload => download(&self.mission_download),
            FccTimer::AreaDownload => download(&self.area_download),
            FccTimer::Report => download(&self.report),
            FccTimer::MissionUpload => self.mission_upload.poll_timeout(),
            FccTimer::AreaUpload => self.area_upload.poll_timeout(),
            FccTimer::InterruptedUpload => self.interrupted_until,
        }
    }

    fn fire(&mut self, timer: FccTimer, now: Instant) {
        match timer {
            FccTimer::MissionDownload | FccTimer::AreaDownload | FccTimer::Report => {
                let kind = match timer {
                    FccTimer::MissionDownload => DataKind::Mission,
                    FccTimer::AreaDownload => DataKind::Areas,
                    _ => DataKind::Report,
                };
                let (slot, endpoint) = self.outgoing(kind);
                if let Some(event) = slot.as_mut().and_then(|s| s.handle_timeout(endpoint, now)) {
                    self.download_event(kind, event);
                }
            }
            FccTimer::MissionUpload => {
                if let Some(t) = self.mission_upload.handle_timeout(now) {
                    self.upload_timed_out(DataKind::Mission, t);
                }
            }
            FccTimer::AreaUpload => {
                if let Some(t) = self.area_upload.handle_timeout(now) {
                    self.upload_timed_out(DataKind::Areas, t);
                }
            }
            FccTimer::InterruptedUpload => {
                tracing::info!("the mission upload cut by the restart is over");
                self.interrupted_until = None;
            }
        }
    }

    /// The moding of paper §3.1.2.
    fn route(&mut self, now: Instant, message: &Message, ack: bool) {
        if let Some(kind) = opens_transfer(message) {
            self.end_transfers_before(kind, message);
        }
        if let Some(kind) = uploads(message) {
            let newest = match kind {
                DataKind::Areas => &mut self.upload_stamps[1],
                _ => &mut self.upload_stamps[0],
            };
            *newest = (*newest).max(message.time_stamp());
        }
        match message {
            Message::MessageAcknowledgement(_) => self.download_answer(now, message),
            Message::MissionTransferCommand(c) => match c.mode {
                MissionPlanMode::ClearMission => {
                    let outcome = self.clear_mission(now);
                    if outcome.is_ok() {
                        // A new upload: the one cut by a restart is over.
                        self.interrupted_until = None;
                    }
                    self.answer_transfer(now, message, ack, outcome);
                }
                MissionPlanMode::TransmitMission => self.closer(now, message, ack),
                MissionPlanMode::ReceiveMission | MissionPlanMode::ReceiveStagedMission => {
                    self.start_mission_download(now, message, ack, c);
                }
                MissionPlanMode::CancelTransfer => {
                    // Every transfer of #13000: the mission upload or download, and the report
                    // the mode 7 request started.
                    self.cancel(DataKind::Mission);
                    self.cancel(DataKind::Report);
                    self.endpoint.answer(now, message, ack, Ok(()));
                }
                MissionPlanMode::ReportMissions => self.start_report(now, message, ack),
                MissionPlanMode::StageMission => self.closer(now, message, ack),
                MissionPlanMode::LoadWaypointBuffer => {
                    let outcome = self.load_buffer(now, c.mission_id);
                    self.answer_transfer(now, message, ack, outcome);
                }
                MissionPlanMode::DeleteStagedMission => {
                    let outcome = self.delete_staged(c.mission_id);
                    self.endpoint.answer(now, message, ack, outcome);
                }
            },
            Message::UaRoute(_)
            | Message::UaPositionWaypoint(_)
            | Message::VehicleSpecificWaypoint(_) => {
                let outcome = self.mission_data(now, message);
                self.answer_transfer(now, message, ack, outcome);
            }
            Message::AreaTransmissionCommand(c) => match c.mode {
                AreaTransferMode::InitiateUpload => {
                    let outcome = if self.area_download.is_some() {
                        Err(Reason::Busy)
                    } else {
                        self.area_upload.handle(now, message).map(|_| ())
                    };
                    self.answer_transfer(now, message, ack, outcome);
                }
                // Answered by #3012 instead of #17000 (ICD §5.3 step 3).
                AreaTransferMode::UploadComplete => self.closer(now, message, ack),
                // Answered by #3013 instead of #17000 (ICD §5.4 step 1).
                AreaTransferMode::InitiateDownload | AreaTransferMode::InitiateStagedDownload => {
                    self.start_area_download(now, message, ack, c);
                }
                AreaTransferMode::Cancel => {
                    self.cancel(DataKind::Areas);
                    self.endpoint.answer(now, message, ack, Ok(()));
                }
                AreaTransferMode::ClearAreas => {
                    let outcome = self.clear_areas();
                    self.endpoint.answer(now, message, ack, outcome);
                }
                AreaTransferMode::DownloadComplete => {
                    self.endpoint
                        .answer(now, message, ack, Err(Reason::WrongState));
                }
                AreaTransferMode::UploadCompleteStaged => self.closer(now, message, ack),
            },
            Message::AreaPolygonLoopSegment(_) => {
                let outcome = if self.area_download.is_some() {
                    Err(Reason::WrongState)
                } else {
                    self.area_upload.handle(now, message).map(|_| ())
                };
                self.answer_transfer(now, message, ack, outcome);
            }
            // Mission data handling activates a staged mission itself (ICD §8): it owns the
            // lists; system automation has nothing to carry out.
            Message::MissionExecuteCommand(c) if c.command == ExecuteCommand::ActivateStaged => {
                let outcome = self.activate_staged(c.mission_id);
                self.endpoint.answer(now, message, ack, outcome);
            }
            Message::MissionExecuteCommand(c) => {
                let outcome = self.check_execute(c.command);
                if outcome.is_ok() {
                    self.event(FccEvent::Execute(c.command));
                }
                self.endpoint.answer(now, message, ack, outcome);
            }
            // Messages the FCC sends, never receives.
            Message::FromToNext(_)
            | Message::MissionUploadDownloadStatus(_)
            | Message::AreaStatusAlert(_)
            | Message::AreaTransmissionStatus(_)
            | Message::MissionReport(_) => {
                self.endpoint
                    .answer(now, message, ack, Err(Reason::WrongState));
            }
        }
    }
}

/// Which data's upload `message` belongs to, when it does (ICD §5.1, §5.3, §8).
fn uploads(message: &Message) -> Option<DataKind> {
    match message {
        Message::UaRoute(_)
        | Message::UaPositionWaypoint(_)
        | Message::VehicleSpecificWaypoint(_) => Some(DataKind::Mission),
        Message::MissionTransferCommand(c) => matches!(
            c.mode,
            MissionPlanMode::ClearMission
                | MissionPlanMode::TransmitMission
                | MissionPlanMode::StageMission
                | MissionPlanMode::LoadWaypointBuffer
        )
        .then_some(DataKind::Mission),
        Message::AreaPolygonLoopSegment(_) => Some(DataKind::Areas),
        Message::AreaTransmissionCommand(c) => matches!(
            c.mode,
            AreaTransferMode::InitiateUpload
                | AreaTransferMode::UploadComplete
                | AreaTransferMode::UploadCompleteStaged
        )
        .then_some(DataKind::Areas),
        _ => None,
    }
}

/// Which data `message` opens a transfer of, when it is an opener from the GCS (ICD §10.2): a
/// clear, a download request or a buffer load of #13000; an upload or download opener, or the
/// clear, of #2011.
fn opens_transfer(message: &Message) -> Option<DataKind> {
    match message {
        Message::MissionTransferCommand(c) => matches!(
            c.mode,
            MissionPlanMode::ClearMission
                | MissionPlanMode::ReceiveMission
                | MissionPlanMode::ReceiveStagedMission
                | MissionPlanMode::LoadWaypointBuffer
        )
        .then_some(DataKind::Mission),
        Message::AreaTransmissionCommand(c) => matches!(
            c.mode,
            AreaTransferMode::InitiateUpload
                | AreaTransferMode::InitiateDownload
                | AreaTransferMode::InitiateStagedDownload
                | AreaTransferMode::ClearAreas
        )
        .then_some(DataKind::Areas),
        _ => None,
    }
}
