//! The GCS logic (paper §3.2, Figure 11), sans-IO: standby; a validation request assembles the
//! waypoint and area lists with the FCC's own assembly code, applies the validity checks of ICD
//! §7, then the safety gateway; an upload request validates first, then uploads the waypoints,
//! then the areas, and ends in success or the error; a download fetches the mission, then the
//! areas. Any failure (a message failed twice, or the FCC fell silent for the transfer timeout)
//! returns the logic to standby: the timeout reset of Figure 11.
//!
//! Inverted use (paper §3.2; ICD §5.6): the GCS uploads with the FCC's download sender and
//! downloads with the FCC's upload receivers ([`TransferSender`], [`MissionReceiver`],
//! [`AreaReceiver`]).
//!
//! Their deadlines are the slots of one [`TimerTable`] ([`GcsTimer`]), kept in step with them as
//! on the FCC (`link::composite::Composite`). Commands are typed:
//! [`GroundStation::clear_areas`] and [`GroundStation::execute`] build #2011 mode 6 and #50000,
//! so no tool writes a message by hand.

use core::fmt;
use core::time::Duration;
use std::collections::VecDeque;

use missionlink_interfaces::wire::{
    AreaDownloadStatus, AreaTransferMode, EncodeError, ExecuteCommand, FrameError, FromToNext,
    GeoPoint, Message, MessageType, MissionExecuteCommand, MissionPlanMode, Reason, SafetyOffset,
    Text, Timestamp,
};

use crate::link::composite::Composite;
use crate::link::endpoint::{Endpoint, EndpointConfig};
use crate::link::retry::ExchangeError;
use crate::link::time::Instant;
use crate::link::timer::{Timer, TimerTable};
use crate::transfer::areas::{AreaBuffer, AreaList};
use crate::transfer::mission::{Mission, MissionBuffer};
use crate::transfer::receiver::{AreaReceiver, MissionReceiver, Received};
use crate::transfer::sender::{Script, SenderEvent, TransferSender, area_request, mission_command};

/// The safety gateway hook (paper §2.2): a mission is uploaded only if every check passes. The
/// gateway itself (geometry, energy, environment) plugs in here.
pub trait SafetyGateway {
    /// What the gateway reports against a mission.
    type Report: fmt::Debug + fmt::Display + Clone + PartialEq;
    /// Checks the lists the plan assembled into, flown from the plan's take-off position (ICD
    /// §7: on the GCS, the mission's planned take-off position). `areas` may be a list that
    /// failed the ICD §7 assembly ([`AreaBuffer::unchecked`]): a gateway reports its defects as
    /// violations that name the area.
    fn check(
        &self,
        mission: &Mission,
        areas: &AreaList,
        take_off: Option<GeoPoint>,
    ) -> Result<(), Self::Report>;
}

/// No gateway configured: the lists pass with the checks of ICD §7 alone.
#[derive(Debug, Clone, Copy, Default)]
pub struct WithoutGateway;

impl SafetyGateway for WithoutGateway {
    type Report = core::convert::Infallible;
    fn check(&self, _: &Mission, _: &AreaList, _: Option<GeoPoint>) -> Result<(), Self::Report> {
        Ok(())
    }
}

/// What the operator planned: the mission data in any order and the areas, as the GCS holds
/// them before assembly.
#[derive(Debug, Clone, Default)]
pub struct MissionPlan {
    /// Take-off height, waypoints, RF centres and route.
    pub mission: MissionBuffer,
    /// Fly-zone and no-fly-zones.
    pub areas: AreaBuffer,
    /// Safety offset of the areas.
    pub safety_offset: SafetyOffset,
    /// Mission ID sent with #13000 mode 2.
    pub mission_id: Option<Text<20>>,
    /// Where the aircraft stands before take-off (QGroundControl's planned home or take-off
    /// item). Not sent: the FCC takes off where navigation says it is (ICD §7); the safety
    /// gateway needs it to check the climb and the way to the initial waypoint.
    pub take_off_position: Option<GeoPoint>,
}

/// Why a plan does not assemble into the lists of ICD §7.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InvalidPlan {
    /// The waypoint list, with the reason.
    Mission(Reason),
    /// The area list, with the reason.
    Areas(Reason),
}

impl fmt::Display for InvalidPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Mission(r) => write!(f, "the waypoint list is invalid (ICD §7): {r}"),
            Self::Areas(r) => write!(f, "the area list is invalid (ICD §7): {r}"),
        }
    }
}

impl std::error::Error for InvalidPlan {}

impl MissionPlan {
    /// The first step of a validation request: both lists assembled with the FCC's own
    /// assembly (ICD §7), the plan's counts as the announced counts.
    pub fn assemble(&self) -> Result<ValidatedPlan, InvalidPlan> {
        let announced = u16::try_from(self.mission.len())
            .map_err(|_| InvalidPlan::Mission(Reason::Capacity))?;
        let mission = self
            .mission
            .assemble(Some(announced), self.mission_id)
            .map_err(InvalidPlan::Mission)?;
        let areas = self
            .areas
            .assemble(self.areas.len() as u8, self.safety_offset)
            .map_err(InvalidPlan::Areas)?;
        Ok(ValidatedPlan { mission, areas })
    }
}

/// What the safety gateway checks of a plan: both lists as far as they assemble, and why they
/// fail ICD §7 if they do. A waypoint list whose only fault is a radius-to-fix leg's radii, and
/// an area list with any fault, are still checked (unchecked), so that the gateway names every
/// defect; the ICD reason is the answer when it names none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ListsToCheck {
    /// The waypoint list.
    pub mission: Mission,
    /// The area list, valid or not.
    pub areas: AreaList,
    /// Why the lists fail ICD §7, if they do.
    pub invalid: Option<InvalidPlan>,
}

impl MissionPlan {
    /// The lists to run the safety gateway on; `Err` only when the waypoint list does not
    /// even chain (count, initial waypoint, Next Waypoints, RF centres, take-off height).
    pub fn lists_to_check(&self) -> Result<ListsToCheck, InvalidPlan> {
        let announced = u16::try_from(self.mission.len())
            .map_err(|_| InvalidPlan::Mission(Reason::Capacity))?;
        let mission = self
            .mission
            .chain(Some(announced), self.mission_id)
            .map_err(InvalidPlan::Mission)?;
        // Each list assembled once; the first ICD §7 refusal is the answer, as `assemble`'s.
        let (areas, areas_invalid) = match self
            .areas
            .assemble(self.areas.len() as u8, self.safety_offset)
        {
            Ok(areas) => (areas, None),
            Err(r) => (self.areas.unchecked(self.safety_offset), Some(r)),
        };
        let invalid = match (mission.check_radii(), areas_invalid) {
            (Err(r), _) => Some(InvalidPlan::Mission(r)),
            (Ok(()), Some(r)) => Some(InvalidPlan::Areas(r)),
            (Ok(()), None) => None,
        };
        Ok(ListsToCheck {
            mission,
            areas,
            invalid,
        })
    }
}

/// The Mission ID as the one-line descriptions quote it (empty when none).
fn quoted_mission_id(f: &mut fmt::Formatter<'_>, id: Option<Text<20>>) -> fmt::Result {
    write!(f, "{:?}", id.as_ref().map_or("", |t| t.as_str()))
}

/// One line, before assembly: `plan "MEDEVAC-2": 3 waypoints, 3 areas, safety offset 25.0 m`.
impl fmt::Display for MissionPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("plan ")?;
        quoted_mission_id(f, self.mission_id)?;
        write!(
            f,
            ": {} waypoints, {} areas, safety offset {:.1} m",
            self.mission.len(),
            self.areas.len(),
            self.safety_offset.metres()
        )
    }
}

/// The lists a validation request produced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValidatedPlan {
    /// The waypoint list.
    pub mission: Mission,
    /// The area list.
    pub areas: AreaList,
}

/// One line, the route in flight-plan order: `mission "MEDEVAC-2": take-off 30.0 m, 3 waypoints
/// (1 -> 2 -> 3), route bidirectional; 3 areas, safety offset 25.0 m`.
impl fmt::Display for ValidatedPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.mission;
        f.write_str("mission ")?;
        quoted_mission_id(f, m.mission_id)?;
        write!(
            f,
            ": take-off {:.1} m, {} waypoints (",
            m.take_off_height().metres(),
            m.waypoints.len()
        )?;
        for (i, record) in m.waypoints.iter().enumerate() {
            if i > 0 {
                f.write_str(" -> ")?;
            }
            write!(f, "{}", record.waypoint.waypoint_number)?;
        }
        write!(
            f,
            "), route {}; {} areas, safety offset {:.1} m",
            if m.route.bidirectional {
                "bidirectional"
            } else {
                "one-way"
            },
            self.areas.areas.len(),
            self.areas.safety_offset.metres()
        )
    }
}

/// Settings of the GCS logic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GcsConfig {
    /// Addresses and clocks.
    pub endpoint: EndpointConfig,
    /// How long a message waits for the FCC's answer (ICD §1: 500 ms).
    pub ack_timeout: Duration,
    /// How long a download waits for the FCC before it is abandoned (ICD §1: 3 s).
    pub transfer_timeout: Duration,
}

/// The steps of Figure 11 that talk to the FCC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Waypoint upload.
    MissionUpload,
    /// Area upload.
    AreaUpload,
    /// Mission download.
    MissionDownload,
    /// Area download.
    AreaDownload,
    /// A single command (clear, clear areas, execute).
    Command,
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::MissionUpload => "mission upload",
            Self::AreaUpload => "area upload",
            Self::MissionDownload => "mission download",
            Self::AreaDownload => "area download",
            Self::Command => "command",
        })
    }
}

/// Why a request failed.
#[derive(Debug, Clone, PartialEq)]
pub enum GcsError<R> {
    /// Another request is in progress.
    Busy,
    /// The waypoint list does not assemble (ICD §7), with the reason.
    InvalidMission(Reason),
    /// The area list does not assemble (ICD §7), with the reason.
    InvalidAreas(Reason),
    /// The safety gateway refused the mission.
    Gateway(R),
    /// A message failed twice (rejected or unanswered).
    Transfer {
        /// Where.
        phase: Phase,
        /// Which message and why.
        error: ExchangeError,
    },
    /// The FCC aborted its download (#14000 status 2 or #2011 mode 5).
    Aborted {
        /// Where.
        phase: Phase,
        /// The FCC's reason, where it gave one.
        reason: Option<Reason>,
    },
    /// The FCC fell silent for the transfer timeout during a download.
    Timeout {
        /// Where.
        phase: Phase,
    },
    /// What the FCC sent does not assemble into a valid list.
    InvalidDownload {
        /// Where.
        phase: Phase,
        /// Why.
        reason: Reason,
    },
}

impl<R: fmt::Display> fmt::Display for GcsError<R> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Busy => write!(f, "another request is in progress"),
            Self::InvalidMission(r) => write!(f, "the waypoint list is invalid: {r}"),
            Self::InvalidAreas(r) => write!(f, "the area list is invalid: {r}"),
            Self::Gateway(report) => write!(f, "the safety gateway refused the mission: {report}"),
            Self::Transfer { phase, error } => write!(f, "{phase} failed: {error}"),
            Self::Aborted { phase, reason } => match reason {
                Some(r) => write!(f, "{phase} aborted by the FCC: {r}"),
                None => write!(f, "{phase} aborted by the FCC"),
            },
            Self::Timeout { phase } => {
                write!(
                    f,
                    "{phase} abandoned: nothing heard from the FCC for the transfer timeout"
                )
            }
            Self::InvalidDownload { phase, reason } => {
                write!(f, "{phase}: what the FCC sent is invalid: {reason}")
            }
        }
    }
}

impl<R: fmt::Debug + fmt::Display> std::error::Error for GcsError<R> {}

/// What the driver shows the operator.
#[derive(Debug, Clone, PartialEq)]
pub enum GcsEvent<R> {
    /// Message `sent` of `total` of a transfer was answered.
    Progress {
        /// Where.
        phase: Phase,
        /// Answered so far.
        sent: usize,
        /// In the transfer.
        total: usize,
    },
    /// Waypoints and areas are uploaded; the FCC activated both.
    UploadComplete,
    /// Mission and areas are downloaded.
    DownloadComplete(Box<ValidatedPlan>),
    /// The FCC accepted a command (the message type).
    CommandAccepted(MessageType),
    /// The request failed; the logic is in standby again.
    Failed(GcsError<R>),
    /// The FCC reported FROM-TO-NEXT (#4001).
    FromToNext(FromToNext),
}

/// The timers of the GCS logic: the sender's and each download receiver's deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GcsTimer {
    /// The ack timeout of the message in flight (ICD §1: 500 ms).
    Sender = 0,
    /// The transfer timeout of the mission download (ICD §1: 3 s).
    MissionDownload = 1,
    /// The transfer timeout of the area download.
    AreaDownload = 2,
}

impl Timer<3> for GcsTimer {
    const ALL: [Self; 3] = [Self::Sender, Self::MissionDownload, Self::AreaDownload];
    fn index(self) -> usize {
        self as usize
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Standby,
    Uploading(Phase),
    /// Waiting for the answer to a download request of `Phase`, or receiving it.
    Downloading(Phase),
    Commanding,
}

/// The GCS logic.
#[derive(Debug)]
pub struct GroundStation<G: SafetyGateway> {
    config: GcsConfig,
    endpoint: Endpoint,
    gateway: G,
    state: State,
    sender: Option<TransferSender>,
    areas_to_upload: Option<AreaList>,
    mission_download: MissionReceiver,
    area_download: AreaReceiver,
    downloaded_mission: Option<Mission>,
    events: VecDeque<GcsEvent<G::Report>>,
    timers: TimerTable<GcsTimer, 3>,
}

impl<G: SafetyGateway> GroundStation<G> {
    /// The GCS logic in standby.
    pub fn new(config: GcsConfig, gateway: G) -> Self {
        Self {
            config,
            endpoint: Endpoint::new(config.endpoint),
            gateway,
            state: State::Standby,
            sender: None,
            areas_to_upload: None,
            mission_download: MissionReceiver::new(config.transfer_timeout),
            area_download: AreaReceiver::new(config.transfer_timeout),
            downloaded_mission: None,
            events: VecDeque::new(),
            timers: TimerTable::new(),
        }
    }

    /// The endpoint (counters).
    pub fn endpoint(&self) -> &Endpoint {
        &self.endpoint
    }

    /// Whether the logic is in standby (no request in progress).
    pub fn is_standby(&self) -> bool {
        self.state == State::Standby
    }

    fn ensure_standby(&self) -> Result<(), GcsError<G::Report>> {
        if self.is_standby() {
            Ok(())
        } else {
            Err(GcsError::Busy)
        }
    }

    /// The validation request: assembles both lists with the FCC's assembly (ICD §7) and runs
    /// the safety gateway.
    ///
    /// An area list that fails the ICD §7 assembly still goes through the gateway, unchecked, so
    /// that its defects come back as violations naming the area; the ICD reason is the answer
    /// only when the gateway finds nothing.
    pub fn validate(&self, plan: &MissionPlan) -> Result<ValidatedPlan, GcsError<G::Report>> {
        let lists = plan.lists_to_check().map_err(|e| match e {
            InvalidPlan::Mission(r) => GcsError::InvalidMission(r),
            InvalidPlan::Areas(r) => GcsError::InvalidAreas(r),
        })?;
        self.gateway
            .check(&lists.mission, &lists.areas, plan.take_off_position)
            .map_err(GcsError::Gateway)?;
        match lists.invalid {
            Some(InvalidPlan::Mission(r)) => Err(GcsError::InvalidMission(r)),
            Some(InvalidPlan::Areas(r)) => Err(GcsError::InvalidAreas(r)),
            None => Ok(ValidatedPlan {
                mission: lists.mission,
                areas: lists.areas,
            }),
        }
    }

    /// The upload request: validation first, then the waypoints (after a clear when `clear`,
    /// else as an edit), then the areas. Nothing is sent when validation fails.
    pub fn upload(
        &mut self,
        now: Instant,
        plan: &MissionPlan,
        clear: bool,
    ) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        let ValidatedPlan { mission, areas } = self.validate(plan)?;
        self.areas_to_upload = Some(areas);
        self.start(
            now,
            State::Uploading(Phase::MissionUpload),
            Script::MissionUpload {
                mission,
                clear,
                checksum: None,
            },
        );
        Ok(())
    }

    /// The download request: the mission (#13000 mode 3), then the areas (#2011 mode 3).
    pub fn download(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        self.downloaded_mission = None;
        self.mission_download.abandon(None);
        self.area_download.abandon();
        let request = mission_command(MissionPlanMode::ReceiveMission, None, None);
        self.start(
            now,
            State::Downloading(Phase::MissionDownload),
            Script::Request(request),
        );
        Ok(())
    }

    /// Clears the active mission: #13000 mode 1, then mode 2 with 0 waypoints (see
    /// [`crate::mission_data_handling`]).
    pub fn clear_mission(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        self.start(now, State::Commanding, Script::MissionClear);
        Ok(())
    }

    /// Clears the active area list: #2011 mode 6 (ICD §4). The FCC refuses it while
    /// trajectory generation is active or an area transfer is in progress.
    pub fn clear_areas(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.command(now, area_request(AreaTransferMode::ClearAreas, None))
    }

    /// #50000 Mission Execute Command (ICD §4): execute the active mission, return to home or
    /// land. The FCC accepts it by the rule of [`crate::automation::check_command`].
    pub fn execute(
        &mut self,
        now: Instant,
        command: ExecuteCommand,
    ) -> Result<(), GcsError<G::Report>> {
        let execute = MissionExecuteCommand {
            time_stamp: Timestamp::default(),
            command,
            mission_id: None,
        };
        self.command(now, execute.into())
    }

    /// A single command and its answer.
    fn command(&mut self, now: Instant, message: Message) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        self.start(now, State::Commanding, Script::Request(message));
        Ok(())
    }

    fn start(&mut self, now: Instant, state: State, script: Script) {
        self.state = state;
        self.sender = Some(TransferSender::start(
            script,
            self.config.ack_timeout,
            &mut self.endpoint,
            now,
        ));
        self.update_timers();
    }

    fn finish(&mut self, event: GcsEvent<G::Report>) {
        self.state = State::Standby;
        self.sender = None;
        self.areas_to_upload = None;
        self.mission_download.abandon(None);
        self.area_download.abandon();
        self.events.push_back(event);
    }

    fn fail(&mut self, error: GcsError<G::Report>) {
        tracing::warn!(%error, "request failed");
        self.finish(GcsEvent::Failed(error));
    }

    fn phase(&self) -> Phase {
        match self.state {
            State::Uploading(p) | State::Downloading(p) => p,
            State::Standby | State::Commanding => Phase::Command,
        }
    }

    /// Handles one downlink message (wrapper to checksum) received at `now`.
    pub fn handle_frame(&mut self, now: Instant, bytes: &[u8]) -> Result<(), FrameError> {
        self.receive_frame(now, bytes)
    }

    /// Answers one message of the download of `phase` with its receiver's `outcome`, and fails
    /// the request when the FCC abandoned the download or the receiver refused the message that
    /// closes it (`closing`); a refused message in between is only answered, the FCC resends
    /// it. `true` when the download is complete, for the caller to take the list.
    fn downloaded(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        phase: Phase,
        outcome: Result<Received, Reason>,
        closing: bool,
    ) -> bool {
        self.endpoint.answer(now, message, ack, outcome.map(|_| ()));
        match outcome {
            Ok(Received::Complete) => return true,
            Ok(Received::Abandoned(reason)) => self.fail(GcsError::Aborted { phase, reason }),
            Ok(Received::Stored | Received::Emptied) => {}
            Err(reason) if closing => self.fail(GcsError::InvalidDownload { phase, reason }),
            Err(_) => {}
        }
        false
    }

    fn request_areas(&mut self, now: Instant, mission: Mission) {
        self.downloaded_mission = Some(mission);
        let request = area_request(AreaTransferMode::InitiateDownload, Some(0));
        self.start(
            now,
            State::Downloading(Phase::AreaDownload),
            Script::Request(request),
        );
    }

    fn sender_event(&mut self, now: Instant, event: SenderEvent) {
        let phase = self.phase();
        match event {
            SenderEvent::Progress { sent, total } => {
                self.events
                    .push_back(GcsEvent::Progress { phase, sent, total });
            }
            SenderEvent::Failed(error) => self.fail(GcsError::Transfer { phase, error }),
            SenderEvent::Completed(answer) => match self.state {
                State::Uploading(Phase::MissionUpload) => {
                    self.events.push_back(GcsEvent::Progress {
                        phase,
                        sent: self.sender.as_ref().map_or(0, |s| s.script().len()),
                        total: self.sender.as_ref().map_or(0, |s| s.script().len()),
                    });
                    match self.areas_to_upload.take() {
                        Some(list) => self.start(
                            now,
                            State::Uploading(Phase::AreaUpload),
                            Script::AreaUpload {
                                list,
                                checksum: None,
                            },
                        ),
                        None => self.finish(GcsEvent::UploadComplete),
                    }
                }
                State::Uploading(_) => self.finish(GcsEvent::UploadComplete),
                State::Downloading(Phase::MissionDownload) => {
                    // The FCC accepted the request; its messages follow.
                    self.sender = None;
                    if !self.mission_download.in_transfer() {
                        self.mission_download.begin(now);
                    }
                }
                State::Downloading(_) => {
                    // The #3013 that accepted the request opens the area download (handled
                    // by the caller).
                    self.sender = None;
                }
                State::Commanding => {
                    self.finish(GcsEvent::CommandAccepted(answer_type(&answer)));
                }
                State::Standby => {}
            },
        }
    }

    /// When [`GroundStation::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.mirrored_timeout(&self.timers)
    }

    /// The timers due at `now` fire: retries, and the download's transfer timeout.
    pub fn handle_timeout(&mut self, now: Instant) {
        self.fire_expired(now);
    }

    /// Encodes the next message to send into `buf`; returns the frame length.
    pub fn poll_transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        self.endpoint.poll_transmit(buf)
    }

    /// The next event for the operator.
    pub fn poll_event(&mut self) -> Option<GcsEvent<G::Report>> {
        self.events.pop_front()
    }
}

impl<G: SafetyGateway> Composite<GcsTimer, 3> for GroundStation<G> {
    fn timers(&mut self) -> &mut TimerTable<GcsTimer, 3> {
        &mut self.timers
    }

    fn endpoint(&mut self) -> &mut Endpoint {
        &mut self.endpoint
    }

    fn deadline(&self, timer: GcsTimer) -> Option<Instant> {
        match timer {
            GcsTimer::Sender => self.sender.as_ref().and_then(TransferSender::poll_timeout),
            GcsTimer::MissionDownload => self.mission_download.poll_timeout(),
            GcsTimer::AreaDownload => self.area_download.poll_timeout(),
        }
    }

    fn fire(&mut self, timer: GcsTimer, now: Instant) {
        let timed_out = match timer {
            GcsTimer::Sender => {
                if let Some(event) = self
                    .sender
                    .as_mut()
                    .and_then(|s| s.handle_timeout(&mut self.endpoint, now))
                {
                    self.sender_event(now, event);
                }
                None
            }
            GcsTimer::MissionDownload => self.mission_download.handle_timeout(now),
            GcsTimer::AreaDownload => self.area_download.handle_timeout(now),
        };
        if timed_out.is_some() {
            let phase = self.phase();
            self.fail(GcsError::Timeout { phase });
        }
    }

    fn route(&mut self, now: Instant, message: &Message, ack: bool) {
        // An answer to what the GCS sent?
        if let Some(event) = self
            .sender
            .as_mut()
            .and_then(|s| s.handle_answer(&mut self.endpoint, now, message))
        {
            self.sender_event(now, event);
            // A ready #3013 answers the area download request and opens the download: it goes
            // on to the receiver below.
            if !matches!(message, Message::AreaTransmissionStatus(s) if s.status == AreaDownloadStatus::Ready)
            {
                return;
            }
        }
        match message {
            Message::FromToNext(ftn) => {
                self.events.push_back(GcsEvent::FromToNext(*ftn));
            }
            Message::MessageAcknowledgement(_) | Message::AreaStatusAlert(_) => {
                tracing::debug!("answer to nothing outstanding (late or duplicate)");
            }
            Message::VehicleSpecificWaypoint(_)
            | Message::UaPositionWaypoint(_)
            | Message::UaRoute(_)
            | Message::MissionUploadDownloadStatus(_)
                if self.state == State::Downloading(Phase::MissionDownload) =>
            {
                // The FCC may start before its acceptance of the request arrives (the links
                // reorder): the first mission message opens the download as well.
                if !self.mission_download.in_transfer() {
                    self.sender = None;
                    self.mission_download.begin(now);
                }
                let outcome = self.mission_download.handle(now, message);
                let closing = matches!(message, Message::MissionUploadDownloadStatus(_));
                if self.downloaded(now, message, ack, Phase::MissionDownload, outcome, closing) {
                    match self.mission_download.take() {
                        Some(mission) => self.request_areas(now, mission),
                        None => self.fail(GcsError::InvalidDownload {
                            phase: Phase::MissionDownload,
                            reason: Reason::WrongState,
                        }),
                    }
                }
            }
            Message::AreaTransmissionStatus(_)
            | Message::AreaPolygonLoopSegment(_)
            | Message::AreaTransmissionCommand(_)
                if self.state == State::Downloading(Phase::AreaDownload) =>
            {
                let outcome = self.area_download.handle(now, message);
                let closing = matches!(message, Message::AreaTransmissionCommand(c) if c.mode == AreaTransferMode::DownloadComplete);
                if self.downloaded(now, message, ack, Phase::AreaDownload, outcome, closing) {
                    match (self.downloaded_mission.take(), self.area_download.take()) {
                        (Some(mission), Some(areas)) => {
                            self.finish(GcsEvent::DownloadComplete(Box::new(ValidatedPlan {
                                mission,
                                areas,
                            })))
                        }
                        _ => self.fail(GcsError::InvalidDownload {
                            phase: Phase::AreaDownload,
                            reason: Reason::WrongState,
                        }),
                    }
                }
            }
            _ => self
                .endpoint
                .answer(now, message, ack, Err(Reason::WrongState)),
        }
    }
}

/// The message type a command answer acknowledged.
fn answer_type(answer: &Message) -> MessageType {
    match answer {
        Message::MessageAcknowledgement(a) => MessageType::try_from(a.original_message_type)
            .unwrap_or(MessageType::MessageAcknowledgement),
        other => other.message_type(),
    }
}
