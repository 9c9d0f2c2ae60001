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
//! **The clear** (#13000 mode 1, ICD §5.1 step 1) deletes the waypoint buffer and the active
//! waypoint list, as paper §3.1 says: a peer built from the paper that clears a mission is told
//! the truth. It is refused while trajectory generation is active. The guarantee that a failed
//! upload leaves the previous mission active belongs to the atomic upload (ICD §8): an upload by
//! the paper's sequence that fails after its clear leaves the FCC without a mission, and the GCS
//! says so. The clear of the areas (#2011 mode 6) deletes the active area list alike.
//!
//! **A newer opener ends what is left open.** A transfer opener from the GCS ends the download of
//! the same kind whose request it is stamped after, and the upload of the same kind whose newest
//! message it is stamped after: the GCS is done with them (this project's choice where the ICD
//! is silent; see `end_transfers_before`). One stamped before a message of the upload was
//! overtaken on the link and does not end it (ICD §10.3).
//!
//! **Closers are idempotent (ICD §11).** The last closer answered of each kind of list and its
//! answer are remembered ([`CloserMemory`]): its retry, until an opener or a data message of its
//! kind is accepted, gets the same answer and changes nothing, so a lost "valid and active" never
//! turns into a reported failure, also when the GCS sent the area opener behind the mission
//! closer (ICD §10.3).
//!
//! **Uploads in stamp order (ICD §10.3).** The receivers apply an upload's messages in the order
//! of their time stamps ([`MissionReceiver`]): an opener overtaken on the link by the data sent
//! behind it leaves what they stored, and a late copy of an opener changes nothing.
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
use crate::position::PositionReporter;
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::link::composite::Composite;
use missionlink_protocol::link::endpoint::{Endpoint, EndpointConfig};
use missionlink_protocol::link::retry::ExchangeError;
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::closer::{Closer, CloserMemory, ClosingAnswer};
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::receiver::{
    AreaReceiver, MissionReceiver, Received, TransferTimedOut,
};
use missionlink_protocol::transfer::sender::{Script, SenderEvent, TransferSender};
use missionlink_protocol::transfer::staged::{MissionId, StagedMissions};

mod download;
mod staged;
mod upload;

use staged::staged_id;

/// Settings of mission data handling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FccConfig {
    /// Addresses and clocks.
    pub endpoint: EndpointConfig,
    /// How long a download message waits for the GCS's answer (ICD §1: 500 ms).
    pub ack_timeout: Duration,
    /// How long an upload waits for the GCS before it is abandoned (ICD §1: 3 s).
    pub transfer_timeout: Duration,
    /// The period of the position downlink (ICD §5.8: #101, by default every 500 ms); `None`
    /// sends none.
    pub position_period: Option<Duration>,
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

missionlink_protocol::timers! {
    /// The timers of mission data handling, one per transfer: each names the deadline of the
    /// sender or receiver that runs the transfer.
    pub enum FccTimer {
        /// The ack timeout of the mission download message in flight (ICD §1: 500 ms).
        MissionDownload,
        /// The ack timeout of the area download message in flight.
        AreaDownload,
        /// The transfer timeout of the mission upload (ICD §1: 3 s).
        MissionUpload,
        /// The transfer timeout of the area upload.
        AreaUpload,
        /// The end of a mission upload interrupted by a restart: the transfer timeout after the
        /// GCS was last heard in it.
        InterruptedUpload,
        /// The ack timeout of the report message in flight (ICD §8).
        Report,
        /// The next #101 of the position downlink (ICD §5.8), owned by the [`PositionReporter`].
        Position,
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
    /// Whether system automation, which carries out a #50000, is alive: its driver watches its
    /// heartbeat ([`MissionDataHandling::set_automation_alive`]); taken as alive until told.
    automation_alive: bool,
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
    /// The position downlink (ICD §5.8).
    position: PositionReporter,
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
            automation_alive: true,
            navigation: GuidanceProgressPayload::IDLE,
            events: Deque::new(),
            waypoint_list: WaypointListPayload::EMPTY,
            area_list: AreaListPayload::EMPTY,
            fence: Box::new(Fence::empty()),
            staged: StagedMissions::new(),
            staged_fence: Box::new(Fence::empty()),
            from_to_next: FromToNextReporter::new(),
            position: PositionReporter::new(config.position_period),
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
    /// §3.1.7, ICD §5.5); the next #101 of the position downlink tells it (ICD §5.8).
    pub fn handle_progress(&mut self, now: Instant, progress: &GuidanceProgressPayload) {
        self.navigation = *progress;
        self.position.handle_progress(now, progress);
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

    /// Whether system automation is alive (its heartbeat, docs/design.md "Health"). While it is
    /// not (hung, dead, or given up by the launcher: the FCC is degraded), its last published
    /// state says nothing, and execute, return to home and land are refused (`WrongState`), as
    /// while guidance is not alive: nothing would carry them out.
    pub fn set_automation_alive(&mut self, alive: bool) {
        self.automation_alive = alive;
    }

    /// Handles one uplink message (wrapper to checksum) received at `now`. A frame error is
    /// returned for the driver to count and log; it is never answered (ICD §2).
    pub fn handle_frame(&mut self, now: Instant, bytes: &[u8]) -> Result<(), FrameError> {
        let result = self.receive_frame(now, bytes);
        self.record_upload_state();
        result
    }

    fn event(&mut self, e: FccEvent) {
        if self.events.push_back(e).is_err() {
            tracing::error!("event queue full: the driver does not drain it");
        }
    }

    /// #50000 (ICD §4): the rule of system automation ([`automation::check_command`]).
    fn check_execute(&self, command: ExecuteCommand) -> Result<(), Reason> {
        let flies = matches!(
            command,
            ExecuteCommand::Execute | ExecuteCommand::ReturnToHome | ExecuteCommand::Land
        );
        if flies && !self.automation_alive {
            return Err(Reason::WrongState);
        }
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

    /// The timers due at `now` fire: download retries, upload transfer timeouts, the position
    /// downlink.
    pub fn handle_timeout(&mut self, now: Instant) {
        self.fire_expired(now);
        self.record_upload_state();
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

impl Composite<FccTimer, 7> for MissionDataHandling {
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
            FccTimer::Position => self.position.poll_timeout(),
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
            // A periodic status, never acknowledged (ICD §5.8).
            FccTimer::Position => {
                if let Some(states) = self.position.handle_timeout(now, &self.waypoint_list) {
                    self.endpoint.send(now, states.into(), false);
                }
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
                    let outcome = self.clear_mission(now, message.time_stamp());
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
                    let outcome = self.load_buffer(now, c.mission_id, message.time_stamp());
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
            | Message::InertialStates(_)
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
