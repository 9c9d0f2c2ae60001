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
//! **Editions and the truth (ICD §10.1, §11).** Before it uploads or downloads, the GCS asks the
//! FCC for its report (#13000 mode 7) once per session: an edition-2 FCC answers with the active
//! lists' checksums (what is active *before*), an edition-1 FCC refuses (`Unsupported`, final).
//! Toward edition 2 an upload asks again, unless the GCS holds a fresh report (ICD §10.3).
//!
//! **Fewer round trips (ICD §10.3, §10.4).** Toward an edition-2 FCC with a window above 1 the
//! GCS sends the data behind their opener and the next step of an upload behind the closer of the
//! one before ([`Pacing`]), and sizes the window to the link ([`Window`]: one for the link,
//! carried from transfer to transfer, the rate set by [`GroundStation::set_link_rate`]).
//! Toward edition 2 the closers carry the checksums of the lists meant and download requests ask
//! for them back. When an upload fails, the GCS asks again what is active (the report, or a
//! download from an edition-1 FCC) and says for each list whether it is the new one or the
//! previous one ([`outcome::UploadReport`]): a lost answer is not a failure, and a half-done
//! upload is named as such.
//!
//! **Staged missions (ICD §8).** [`GroundStation::stage`], [`GroundStation::activate`],
//! [`GroundStation::delete`], [`GroundStation::download_of`] and the report reach the staged
//! missions of an edition-2 FCC; [`GroundStation::upload_with`] uploads atomically through them
//! ([`Sequence::Atomic`]) and [`GroundStation::edit`] sends only what changed ([`edit`]); the
//! steps each upload takes are in [`upload`].
//!
//! Their deadlines are their own; [`GcsTimer`] names them, one per transfer, as on the FCC
//! (`link::composite::Composite`). Commands are typed:
//! [`GroundStation::clear_areas`] and [`GroundStation::execute`] build #2011 mode 6 and #50000,
//! so no tool writes a message by hand.

use core::fmt;
use core::time::Duration;
use std::collections::VecDeque;

use missionlink_interfaces::capacity::MAX_REPORT_ENTRIES;
use missionlink_interfaces::wire::{
    AreaDownloadStatus, AreaTransferMode, EncodeError, ExecuteCommand, FrameError, FromToNext,
    GeoPoint, InertialStates, Message, MessageType, MissionExecuteCommand, MissionPlanMode,
    MissionReport, Reason, Speed, Timestamp, TransferWindow,
};

use missionlink_protocol::link::composite::Composite;
use missionlink_protocol::link::endpoint::{Endpoint, EndpointConfig};
use missionlink_protocol::link::retry::{AttemptFailure, ExchangeError};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::receiver::{
    AreaReceiver, MissionReceiver, Received, ReportReceiver,
};
use missionlink_protocol::transfer::sender::{
    Pacing, Script, SenderEvent, Target, TransferSender, activate_staged, area_download_request,
    area_request, delete_staged, mission_command, mission_download_request,
};
use missionlink_protocol::transfer::staged::MissionId;
use missionlink_protocol::transfer::window::Window;

pub mod edit;
mod error;
pub mod outcome;

pub mod upload;

pub use error::{GcsError, StagedRequest, reason_hint};
pub use missionlink_protocol::transfer::plan::{
    InvalidPlan, ListsToCheck, MissionPlan, ValidatedPlan,
};
use outcome::{Confirmation, UploadReport};
use upload::UploadJob;
pub use upload::{Sequence, fresh_mission_id, staging_id};

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

    /// The wind the gateway sizes turns for (ICD §7 "Turns in wind"), `None` for calm. The
    /// validation sends the larger of this and the plan's own planning wind (#13001 field 5),
    /// so that the FCC flies and checks every turn as the gateway checked it, and a wind the
    /// plan was made for is never lost.
    fn planning_wind(&self) -> Option<Speed> {
        None
    }
}

/// Sets the planning wind `mission` is sent with (#13001 field 5, ICD §7 "Turns in wind"): the
/// larger of its own and the one `gateway` checks turns in, none in calm air. The one place the
/// ground decides it: the validation before every upload, `gcs validate` (whose checksums are
/// then the ones the FCC will report) and the map.
pub fn plan_in_wind<G: SafetyGateway>(gateway: &G, mission: &mut Mission) {
    let route = &mut mission.route;
    route.planning_wind = route
        .planning_wind
        .max(gateway.planning_wind())
        .filter(|w| w.raw() != 0);
}

/// The validation: assembles both lists with the FCC's assembly (ICD §7) and runs `gateway`,
/// the route planned in its wind ([`plan_in_wind`]). The ground service validates with the
/// gateway of each request, so this is not only the GCS logic's.
///
/// An area list that fails the ICD §7 assembly still goes through the gateway, unchecked, so
/// that its defects come back as violations naming the area; the ICD reason is the answer
/// only when the gateway finds nothing.
pub fn validate<G: SafetyGateway>(
    gateway: &G,
    plan: &MissionPlan,
) -> Result<ValidatedPlan, GcsError<G::Report>> {
    let mut lists = plan.lists_to_check().map_err(|e| match e {
        InvalidPlan::Mission(r) => GcsError::InvalidMission(r),
        InvalidPlan::Areas(r) => GcsError::InvalidAreas(r),
    })?;
    plan_in_wind(gateway, &mut lists.mission);
    gateway
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

/// No gateway configured: the lists pass with the checks of ICD §7 alone.
#[derive(Debug, Clone, Copy, Default)]
pub struct WithoutGateway;

impl SafetyGateway for WithoutGateway {
    type Report = core::convert::Infallible;
    fn check(&self, _: &Mission, _: &AreaList, _: Option<GeoPoint>) -> Result<(), Self::Report> {
        Ok(())
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
    /// Data messages in flight toward an edition-2 FCC (ICD §10.2), 1 to
    /// [`MAX_WINDOW`](missionlink_protocol::transfer::window::MAX_WINDOW): the uploads' window,
    /// and the one download requests ask for up to the 32 their field holds. Toward edition 1
    /// it is always 1. The uploads keep at or below it by the window sized to the link (ICD
    /// §10.4); above 1 the GCS sends what ICD §10.3 allows without waiting.
    pub transfer_window: u8,
    /// How often an upload is attempted in all, at least 1: a failed attempt that left the
    /// lists as they were, for a cause that may pass (no answer, `Busy`, `WrongState`), is
    /// begun again (the upload module, `attempt_again`).
    pub upload_attempts: u8,
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
    /// The FCC's report of its lists (ICD §8, #13000 mode 7 and #50001).
    Report,
    /// The activation of an atomic upload's staged copy (#50000 command 4, ICD §8).
    Activation,
    /// The delete of an atomic upload's staged copy (#13000 mode 6, ICD §8).
    Deletion,
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::MissionUpload => "mission upload",
            Self::AreaUpload => "area upload",
            Self::MissionDownload => "mission download",
            Self::AreaDownload => "area download",
            Self::Command => "command",
            Self::Report => "mission report",
            Self::Activation => "activation",
            Self::Deletion => "delete of the staged copy",
        })
    }
}

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
    /// An upload completed: both lists are active on the FCC (confirmed after a lost answer,
    /// perhaps: the report says). An upload that did not complete ends in
    /// [`GcsEvent::Failed`] with [`GcsError::Upload`].
    Uploaded(Box<UploadReport>),
    /// The FCC's report of its lists (ICD §8): the active lists first.
    Reported(heapless::Vec<MissionReport, MAX_REPORT_ENTRIES>),
    /// Mission and areas are downloaded.
    DownloadComplete(Box<ValidatedPlan>),
    /// The FCC accepted a command (the message type).
    CommandAccepted(MessageType),
    /// The request failed; the logic is in standby again.
    Failed(GcsError<R>),
    /// The FCC reported FROM-TO-NEXT (#4001).
    FromToNext(FromToNext),
    /// The FCC's position downlink (#101, ICD §5.8).
    Position(InertialStates),
}

missionlink_protocol::timers! {
    /// The timers of the GCS logic: the sender's and each download receiver's deadline.
    pub enum GcsTimer {
        /// The ack timeout of the message in flight (ICD §1: 500 ms).
        Sender,
        /// The ack timeouts of the step sent behind the one in progress (ICD §10.3).
        Behind,
        /// The transfer timeout of the mission download (ICD §1: 3 s).
        MissionDownload,
        /// The transfer timeout of the area download.
        AreaDownload,
        /// The transfer timeout of the mission report.
        Report,
    }
}

/// Which edition of the ICD the FCC speaks (ICD §10.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edition {
    /// Edition 1: §5 only; it refuses the report request with `Unsupported`.
    One,
    /// Edition 2: §8-§11.
    Two,
}

/// Why the GCS asks for the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Purpose {
    /// Edition discovery before a transfer (ICD §10.1); the report gives what is active before.
    Discovery(Then),
    /// After a failed upload: what is active now (ICD §11).
    Truth,
    /// The operator asked.
    Query,
}

/// What follows the discovery.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Then {
    Upload,
    Download,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Standby,
    /// Waiting for the answer to the report request, or receiving the report.
    Reporting(Purpose),
    Uploading(Phase),
    /// Waiting for the answer to a download request of `Phase`, or receiving it (the truth
    /// after a failed upload to an edition-1 FCC when an upload is in progress).
    Downloading(Phase),
    Commanding,
}

/// The GCS's senders keep their script boxed: a sender moves as a few kilobytes, not the
/// mission's 27 (see [`TransferSender`]).
type Sender = TransferSender<Box<Script>>;

/// The script of a single request and its answer, boxed. Not inlined: a [`Script`] is as large
/// as its largest kind (a mission, 27 KB), and a caller that built one would carry that much
/// frame into everything it calls next.
#[inline(never)]
fn request_script(message: Message) -> Box<Script> {
    Box::new(Script::Request(message))
}

/// A step of an upload sent behind the one in progress, whose last message is unanswered
/// (ICD §10.3): the area upload beside the mission upload's data, the activation behind the area
/// closer.
#[derive(Debug)]
struct Behind {
    phase: Phase,
    sender: Sender,
    /// How it ended, when it ended before the step it was sent behind.
    ended: Option<SenderEvent>,
}

/// The FCC's report as the GCS holds it (ICD §10.3).
#[derive(Debug, Clone)]
struct HeldReport {
    entries: Vec<MissionReport>,
    /// When it was received or brought up to date.
    at: Instant,
}

/// The GCS logic.
#[derive(Debug)]
pub struct GroundStation<G: SafetyGateway> {
    config: GcsConfig,
    endpoint: Endpoint,
    gateway: G,
    state: State,
    sender: Option<Sender>,
    /// The step of an upload sent behind the one in progress (ICD §10.3).
    behind: Option<Behind>,
    /// The window of the link (ICD §10.4): what the senders measured, carried from one
    /// transfer to the next.
    window: Window,
    /// The FCC's report as the GCS knows it now (ICD §10.3): received, or brought up to date
    /// by an upload that completed since.
    held_report: Option<HeldReport>,
    upload: Option<Box<UploadJob>>,
    edition: Option<Edition>,
    /// When the FCC was last heard (a frame that passed preprocessing).
    last_heard: Option<Instant>,
    report: ReportReceiver,
    mission_download: MissionReceiver,
    area_download: AreaReceiver,
    downloaded_mission: Option<Mission>,
    events: VecDeque<GcsEvent<G::Report>>,
    /// Which lists the download in progress reads.
    download_target: Target,
    /// The staged mission the command in progress is about.
    staged_command: Option<(StagedRequest, MissionId)>,
    /// Staged copies of this GCS's atomic uploads whose delete failed or went unanswered: the
    /// next upload toward edition 2 deletes those its report still lists, after its own, so
    /// that copies left on a bad link neither pile up to the FCC's capacity nor take a name an
    /// operator's upload needs.
    copies_left: Vec<MissionId>,
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
            behind: None,
            window: Window::adaptive(usize::from(config.transfer_window), None),
            held_report: None,
            upload: None,
            edition: None,
            last_heard: None,
            report: ReportReceiver::new(config.transfer_timeout),
            mission_download: MissionReceiver::new(config.transfer_timeout),
            area_download: AreaReceiver::new(config.transfer_timeout),
            downloaded_mission: None,
            events: VecDeque::new(),
            download_target: Target::Active,
            staged_command: None,
            copies_left: Vec::new(),
        }
    }

    /// The endpoint (counters, the last time stamp issued).
    pub fn endpoint(&self) -> &Endpoint {
        &self.endpoint
    }

    /// How often the uploads requested from now on are attempted in all (at least 1; see
    /// [`GcsConfig::upload_attempts`]).
    pub fn set_upload_attempts(&mut self, attempts: u8) {
        self.config.upload_attempts = attempts.max(1);
    }

    /// The window of the transfers started from now on (ICD §10.2; toward an edition-2 FCC):
    /// the most the window sized to the link may reach (ICD §10.4); 0 counts as 1, above
    /// [`MAX_WINDOW`](missionlink_protocol::transfer::window::MAX_WINDOW) as that.
    pub fn set_transfer_window(&mut self, window: u8) {
        self.config.transfer_window = window;
    }

    /// The link's rate toward the FCC in bit/s, when known (`None`: not known): the window
    /// then keeps in flight at most what the link carries in a round trip (ICD §10.4).
    pub fn set_link_rate(&mut self, rate_bps: Option<u64>) {
        self.window.set_rate(rate_bps);
    }

    /// The window of the link as the senders measured it (ICD §10.4).
    pub fn link_window(&self) -> &Window {
        &self.window
    }

    /// Whether the GCS sends without waiting where ICD §10.3 allows it: toward an edition-2
    /// FCC with a window above 1 (a window of 1 keeps every message stop-and-wait, and every
    /// upload starting with the report).
    fn pipelining(&self) -> bool {
        self.edition == Some(Edition::Two) && self.config.transfer_window > 1
    }

    /// The FCC's report the GCS holds, if it is fresh (ICD §10.3): received or brought up to
    /// date within the transfer timeout, with the FCC heard within it.
    fn fresh_report(&self, now: Instant) -> Option<Vec<MissionReport>> {
        self.held_report
            .as_ref()
            .filter(|h| now.saturating_since(h.at) < self.config.transfer_timeout)
            .filter(|_| self.edition_known(now))
            .map(|h| h.entries.clone())
    }

    /// Time stamps from now on are strictly greater than `floor`
    /// ([`Endpoint::resume_stamps_after`]).
    pub fn resume_stamps_after(&mut self, floor: Timestamp) {
        self.endpoint.resume_stamps_after(floor);
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

    /// The validation request: [`validate`] with this GCS's gateway.
    pub fn validate(&self, plan: &MissionPlan) -> Result<ValidatedPlan, GcsError<G::Report>> {
        validate(&self.gateway, plan)
    }

    /// The upload request by the paper's sequence ([`Sequence::Paper`], after a clear when
    /// `clear`, else as an edition-1 edit); see [`GroundStation::upload_with`].
    pub fn upload(
        &mut self,
        now: Instant,
        plan: &MissionPlan,
        clear: bool,
    ) -> Result<(), GcsError<G::Report>> {
        self.upload_with(now, plan, Sequence::Paper { clear })
    }

    /// The download request: the mission (#13000 mode 3), then the areas (#2011 mode 3), after
    /// the edition discovery when needed; toward edition 2 the requests ask for the checksums,
    /// which the receivers compare with what arrived (ICD §11).
    pub fn download(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.download_of(now, None)
    }

    /// The download request of the active lists (`None`) or of the staged mission `id` (ICD §8:
    /// #13000 mode 9, then #2011 mode 8; refused toward an edition-1 FCC with
    /// [`GcsError::Edition1`]).
    pub fn download_of(
        &mut self,
        now: Instant,
        id: Option<MissionId>,
    ) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        self.download_target = id.map_or(Target::Active, Target::Staged);
        if self.edition_known(now) && !(id.is_some() && self.edition == Some(Edition::One)) {
            self.request_mission(now);
        } else {
            self.start_report(now, Purpose::Discovery(Then::Download));
        }
        Ok(())
    }

    /// The report request (ICD §8, #13000 mode 7): ends in [`GcsEvent::Reported`], or fails
    /// with `Unsupported` from an edition-1 FCC.
    pub fn report(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        self.start_report(now, Purpose::Query);
        Ok(())
    }

    /// The edition the FCC speaks, if the GCS found out in this session.
    pub fn edition(&self) -> Option<Edition> {
        self.edition
    }

    /// Whether the edition is known and the FCC was heard within the transfer timeout (ICD
    /// §10.1: after a silence that long, the GCS asks again).
    fn edition_known(&self, now: Instant) -> bool {
        self.edition.is_some()
            && self
                .last_heard
                .is_some_and(|t| now.saturating_since(t) < self.config.transfer_timeout)
    }

    fn start_report(&mut self, now: Instant, purpose: Purpose) {
        if matches!(purpose, Purpose::Discovery(_)) && !self.edition_known(now) {
            // Silent for the transfer timeout, or never heard: the path may have changed, and
            // the window measures it afresh (ICD §10.4).
            self.window.forget_path();
        }
        self.report.abandon();
        let request = mission_command(MissionPlanMode::ReportMissions, None, None);
        self.start(now, State::Reporting(purpose), request_script(request));
    }

    /// The transfer window of a download request: the configured one toward edition 2, at
    /// most the 32 its field holds (the field makes it an edition-2 request, ICD §10.2),
    /// absent toward edition 1.
    fn window(&self) -> Option<TransferWindow> {
        let window = self
            .config
            .transfer_window
            .clamp(TransferWindow::MIN, TransferWindow::MAX);
        (self.edition == Some(Edition::Two))
            .then(|| TransferWindow::new(window).unwrap_or_default())
    }

    fn request_mission(&mut self, now: Instant) {
        self.downloaded_mission = None;
        self.mission_download.abandon(None);
        self.area_download.abandon();
        let request = mission_download_request(self.download_target, self.window());
        self.start(
            now,
            State::Downloading(Phase::MissionDownload),
            request_script(request),
        );
    }

    fn request_areas(&mut self, now: Instant) {
        let request = area_download_request(self.download_target, self.window());
        self.start(
            now,
            State::Downloading(Phase::AreaDownload),
            request_script(request),
        );
    }

    /// Clears the active mission: #13000 mode 1 deletes the waypoint buffer and the active
    /// waypoint list (ICD §5.1 step 1). The FCC refuses it while trajectory generation is active.
    pub fn clear_mission(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        // The lists change: the report held is no longer what the FCC holds.
        self.held_report = None;
        self.start(
            now,
            State::Commanding,
            request_script(mission_command(MissionPlanMode::ClearMission, None, None)),
        );
        Ok(())
    }

    /// Clears the active area list: #2011 mode 6 (ICD §4). The FCC refuses it while
    /// trajectory generation is active or an area transfer is in progress.
    pub fn clear_areas(&mut self, now: Instant) -> Result<(), GcsError<G::Report>> {
        self.command(now, area_request(AreaTransferMode::ClearAreas, None))
    }

    /// #50000 Mission Execute Command (ICD §4): execute the active mission, return to home or
    /// land. The FCC accepts it by the rule of `missionlink_flight::automation::check_command`. Command 4
    /// names a staged mission and goes through [`GroundStation::activate`]: here it is refused
    /// ([`GcsError::ActivateWithoutId`]) and nothing is sent.
    pub fn execute(
        &mut self,
        now: Instant,
        command: ExecuteCommand,
    ) -> Result<(), GcsError<G::Report>> {
        if command == ExecuteCommand::ActivateStaged {
            // Without its Mission ID, command 4 is a message the FCC must refuse as
            // `MissingField` (ICD §8 #50000 field 2): never put it on the wire.
            return Err(GcsError::ActivateWithoutId);
        }
        let execute = MissionExecuteCommand {
            time_stamp: Timestamp::default(),
            command,
            mission_id: None,
        };
        self.command(now, execute.into())
    }

    /// Activates the staged mission `id` (ICD §8, #50000 command 4): the FCC replaces the active
    /// waypoint list and area list by it in one step, or refuses (see [`reason_hint`]); its
    /// failure is [`GcsError::Staged`].
    pub fn activate(&mut self, now: Instant, id: MissionId) -> Result<(), GcsError<G::Report>> {
        self.command(now, activate_staged(id))?;
        self.staged_command = Some((StagedRequest::Activate, id));
        Ok(())
    }

    /// Deletes the staged mission `id` (ICD §8, #13000 mode 6); its failure is
    /// [`GcsError::Staged`].
    pub fn delete(&mut self, now: Instant, id: MissionId) -> Result<(), GcsError<G::Report>> {
        self.command(now, delete_staged(id))?;
        self.staged_command = Some((StagedRequest::Delete, id));
        Ok(())
    }

    /// A single command and its answer.
    fn command(&mut self, now: Instant, message: Message) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        // A command may change the lists (a clear, an activation, a delete): the report held
        // is no longer known to be what the FCC holds.
        self.held_report = None;
        self.start(now, State::Commanding, request_script(message));
        Ok(())
    }

    /// The sender's messages count toward the upload in progress; what its window measured is
    /// kept for the next transfer (ICD §10.4); the sender goes.
    fn account_sender(&mut self) {
        if let Some(sender) = self.sender.take() {
            self.keep_window(&sender);
            if let Some(job) = self.upload.as_mut() {
                job.sent += sender.sent();
            }
        }
    }

    /// Keeps what `sender`'s window measured of the link (ICD §10.4).
    fn keep_window(&mut self, sender: &Sender) {
        let mut window = *sender.window();
        window.absorb(&self.window);
        self.window = window;
    }

    /// Drops the step sent behind the one in progress (ICD §10.3), telling the FCC where it is a
    /// transfer (an area upload: #2011 mode 5); its messages count toward the upload.
    fn drop_behind(&mut self, now: Instant) {
        let Some(mut behind) = self.behind.take() else {
            return;
        };
        if behind.ended.is_none() {
            behind.sender.abandon(&mut self.endpoint, now, Reason::None);
        }
        self.keep_window(&behind.sender);
        if let Some(job) = self.upload.as_mut() {
            job.sent += behind.sender.sent();
        }
    }

    /// An event of the step sent behind (ICD §10.3): progress is shown; its end waits for the
    /// end of the step it was sent behind.
    fn behind_event(&mut self, event: SenderEvent) {
        let Some(behind) = self.behind.as_mut() else {
            return;
        };
        match event {
            SenderEvent::Progress { sent, total } => self.events.push_back(GcsEvent::Progress {
                phase: behind.phase,
                sent,
                total,
            }),
            ended => behind.ended = Some(ended),
        }
    }

    fn start(&mut self, now: Instant, state: State, script: Box<Script>) {
        self.account_sender();
        self.state = state;
        let pacing = Pacing {
            pipelined: self.pipelining(),
            behind: false,
        };
        let window = self.sender_window();
        self.sender = Some(TransferSender::start_with(
            script,
            window,
            pacing,
            self.config.ack_timeout,
            &mut self.endpoint,
            now,
        ));
    }

    /// The window a sender starts with (ICD §10.2, §10.4): the link's, agreed at the configured
    /// window toward an edition-2 FCC, at 1 toward edition 1; the scripts without data messages
    /// send one at a time whatever the window.
    fn sender_window(&mut self) -> Window {
        let agreed = match self.edition {
            Some(Edition::Two) => self.config.transfer_window,
            _ => TransferWindow::MIN,
        };
        self.window.set_max(usize::from(agreed));
        self.window
    }

    /// Starts `script`, the upload step `phase`, behind the step in progress, whose last message
    /// is unanswered (ICD §10.3).
    fn start_behind(&mut self, now: Instant, phase: Phase, script: Box<Script>) {
        // It starts from what the step in progress measured of the link (ICD §10.4).
        if let Some(sender) = self.sender.take() {
            self.keep_window(&sender);
            self.sender = Some(sender);
        }
        let pacing = Pacing {
            pipelined: true,
            behind: true,
        };
        let window = self.sender_window();
        // Beside the data of the step in progress still in flight (ICD §10.4).
        let beside = self
            .sender
            .as_ref()
            .map_or((0, 0), TransferSender::data_in_flight);
        let sender = TransferSender::start_beside(
            script,
            window,
            pacing,
            self.config.ack_timeout,
            beside,
            &mut self.endpoint,
            now,
        );
        self.behind = Some(Behind {
            phase,
            sender,
            ended: None,
        });
    }

    /// The step in progress answered or timed out: the step sent beside its data (ICD §10.3)
    /// may send what the window now allows beside them (ICD §10.4).
    fn pace_behind(&mut self, now: Instant) {
        if let (Some(sender), Some(behind)) = (self.sender.as_ref(), self.behind.as_mut()) {
            behind
                .sender
                .pace_beside(&mut self.endpoint, now, sender.data_in_flight());
        }
    }

    /// The step sent behind becomes the step in progress: the one before it was accepted to its
    /// end (ICD §10.3). Its closer may go; its end, if it came already, is handled now.
    fn promote_behind(&mut self, now: Instant, behind: Behind) {
        let Behind {
            phase,
            mut sender,
            ended,
        } = behind;
        self.account_sender();
        self.state = State::Uploading(phase);
        sender.release(&mut self.endpoint, now);
        self.sender = Some(sender);
        match ended {
            Some(event) => self.sender_event(now, event),
            // Released, its closer may have gone at once: the next step may go behind it.
            None => self.send_next_behind(now),
        }
    }

    fn finish(&mut self, event: GcsEvent<G::Report>) {
        self.reset();
        self.events.push_back(event);
    }

    /// Back to standby, every request's state dropped.
    fn reset(&mut self) {
        self.state = State::Standby;
        if let Some(sender) = self.sender.take() {
            self.keep_window(&sender);
        }
        self.behind = None;
        self.upload = None;
        self.download_target = Target::Active;
        self.staged_command = None;
        self.report.abandon();
        self.mission_download.abandon(None);
        self.area_download.abandon();
    }

    fn fail(&mut self, error: GcsError<G::Report>) {
        tracing::warn!(%error, "request failed");
        self.finish(GcsEvent::Failed(error));
    }

    fn phase(&self) -> Phase {
        match self.state {
            State::Uploading(p) | State::Downloading(p) => p,
            State::Reporting(_) => Phase::Report,
            State::Standby | State::Commanding => Phase::Command,
        }
    }

    /// Handles one downlink message (wrapper to checksum) received at `now`.
    pub fn handle_frame(&mut self, now: Instant, bytes: &[u8]) -> Result<(), FrameError> {
        self.receive_frame(now, bytes)?;
        self.last_heard = Some(now);
        Ok(())
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
            Ok(Received::Abandoned(reason)) => {
                self.download_failed(now, GcsError::Aborted { phase, reason })
            }
            Ok(Received::Stored | Received::Emptied) => {}
            Err(reason) if closing => {
                self.download_failed(now, GcsError::InvalidDownload { phase, reason })
            }
            Err(_) => {}
        }
        false
    }

    /// A download failed: the request fails, or, when the download was to find out what an
    /// edition-1 FCC holds after a failed upload, the upload ends with that unknown. The
    /// download of an edit's base fails the edit (nothing but requests was sent).
    fn download_failed(&mut self, now: Instant, error: GcsError<G::Report>) {
        // The report before an upload (ICD §8, §10.1) broke off: nothing that changes a list
        // was sent, so the upload may begin again, or fails as the report did.
        if self.state == State::Reporting(Purpose::Discovery(Then::Upload)) {
            let may_pass = matches!(error, GcsError::Timeout { .. } | GcsError::Aborted { .. });
            if !self.attempt_again(now, &error, may_pass, true) {
                self.fail(error);
            }
            return;
        }
        if self.upload.is_some() && !self.fetching_edit_base() {
            tracing::warn!(%error, "cannot find out what the FCC holds");
            self.end_upload_unknown(now);
        } else {
            self.fail(error);
        }
    }

    /// A request about the staged mission of the download (or command) failed.
    fn staged_error(&self, phase: Phase, error: ExchangeError) -> GcsError<G::Report> {
        match (self.staged_command, self.download_target) {
            (Some((request, id)), _) => GcsError::Staged { request, id, error },
            (None, Target::Staged(id)) => GcsError::Staged {
                request: StagedRequest::Download,
                id,
                error,
            },
            (None, Target::Active) => GcsError::Transfer { phase, error },
        }
    }

    /// A download request failed twice. After a failed upload to an edition-1 FCC, a refusal
    /// (`WrongState`) of the mission request or an aborted #3013 means there is no such list;
    /// anything else leaves it unknown. For an edit's base the same refusal means there is
    /// nothing to edit.
    fn download_request_failed(&mut self, now: Instant, phase: Phase, error: ExchangeError) {
        let none_held = match phase {
            Phase::MissionDownload => error.reason() == Some(Reason::WrongState),
            _ => error.first == AttemptFailure::Aborted,
        };
        if self.fetching_edit_base() {
            if !none_held {
                let error = self.staged_error(phase, error);
                return self.fail(error);
            }
            let _ = match phase {
                Phase::MissionDownload => self.edit_base_downloaded(now, None),
                _ => self.edit_areas_downloaded(now, None),
            };
            return;
        }
        let Some(job) = self.upload.as_mut() else {
            let error = match (phase, self.download_target) {
                (Phase::MissionDownload, Target::Active) if none_held => GcsError::NoMission,
                _ => self.staged_error(phase, error),
            };
            self.fail(error);
            return;
        };
        if !none_held {
            self.end_upload_unknown(now);
            return;
        }
        match phase {
            Phase::MissionDownload => {
                job.verified_mission = Some(None);
                self.request_areas(now);
            }
            _ => {
                let mission = job.verified_mission.flatten();
                self.resolve(now, (mission, None), None, Confirmation::Download);
            }
        }
    }

    fn sender_event(&mut self, now: Instant, event: SenderEvent) {
        let phase = self.phase();
        match event {
            SenderEvent::Progress { sent, total } => {
                self.events
                    .push_back(GcsEvent::Progress { phase, sent, total });
                self.send_next_behind(now);
            }
            SenderEvent::Failed(error) => match self.state {
                // The FCC may have carried out what it did not answer: ask (ICD §11).
                State::Uploading(phase) => self.step_failed(now, phase, error),
                State::Reporting(purpose) => self.report_refused(now, purpose, error),
                State::Downloading(phase) => self.download_request_failed(now, phase, error),
                _ => {
                    let error = self.staged_error(phase, error);
                    self.fail(error)
                }
            },
            SenderEvent::Completed(answer) => match self.state {
                State::Uploading(phase) => {
                    let total = self.sender.as_ref().map_or(0, |s| s.script().len());
                    self.events.push_back(GcsEvent::Progress {
                        phase,
                        sent: total,
                        total,
                    });
                    self.step_completed(now, phase);
                }
                State::Reporting(_) => {
                    // The FCC accepted the request: an edition-2 FCC (ICD §10.1); its entries
                    // follow.
                    self.edition = Some(Edition::Two);
                    self.account_sender();
                    if !self.report.in_transfer() {
                        self.report.begin(now);
                    }
                }
                State::Downloading(Phase::MissionDownload) => {
                    // The FCC accepted the request; its messages follow.
                    self.account_sender();
                    if !self.mission_download.in_transfer() {
                        self.mission_download.begin(now);
                    }
                }
                State::Downloading(_) => {
                    // The #3013 that accepted the request opens the area download (handled
                    // by the caller).
                    self.account_sender();
                }
                State::Commanding => {
                    self.finish(GcsEvent::CommandAccepted(answer_type(&answer)));
                }
                State::Standby => {}
            },
        }
    }

    /// After a failed upload: the report toward edition 2, a download toward edition 1.
    fn find_out(&mut self, now: Instant) {
        if let Some(job) = self.upload.as_mut() {
            job.asking_since = Some(now);
        }
        self.download_target = Target::Active;
        if self.edition == Some(Edition::Two) {
            self.start_report(now, Purpose::Truth);
        } else {
            self.request_mission(now);
        }
    }

    /// The report request failed twice, or was refused once for good (edition 1).
    fn report_refused(&mut self, now: Instant, purpose: Purpose, error: ExchangeError) {
        let edition_1 = error.second.is_none() && error.reason() == Some(Reason::Unsupported);
        if edition_1 {
            self.edition = Some(Edition::One);
        }
        match (purpose, edition_1) {
            (Purpose::Discovery(Then::Upload), true) => self.plan_upload(now),
            (Purpose::Discovery(Then::Download), true) => match self.download_target {
                Target::Active => self.request_mission(now),
                Target::Staged(_) => self.fail(GcsError::Edition1 {
                    request: "downloading a staged mission (ICD §8)",
                }),
            },
            (Purpose::Truth, true) => self.request_mission(now),
            (Purpose::Truth, false) => self.ask_again_or_give_up(now),
            // Nothing was sent that changes a list: an upload may be attempted again.
            (Purpose::Discovery(Then::Upload), false)
                if self.attempt_again(
                    now,
                    &format_args!("{}: {error}", Phase::Report),
                    error.may_pass(),
                    true,
                ) => {}
            (Purpose::Discovery(_) | Purpose::Query, _) => self.fail(GcsError::Transfer {
                phase: Phase::Report,
                error,
            }),
        }
    }

    /// The report is complete.
    fn reported(&mut self, now: Instant, purpose: Purpose) {
        let Some(entries) = self.report.take() else {
            return;
        };
        self.held_report = Some(HeldReport {
            entries: entries.to_vec(),
            at: now,
        });
        match purpose {
            Purpose::Discovery(Then::Upload) => {
                self.upload_discovered(&entries);
                self.plan_upload(now);
            }
            Purpose::Discovery(Then::Download) => self.request_mission(now),
            Purpose::Truth => self.truth_reported(now, &entries),
            Purpose::Query => self.finish(GcsEvent::Reported(entries)),
        }
    }

    /// The FCC did not answer the question what is active: it may be restarting (the failure
    /// may have been its restart). The GCS asks again for the transfer timeout, then gives up.
    fn ask_again_or_give_up(&mut self, now: Instant) {
        let since = self.upload.as_ref().and_then(|j| j.asking_since);
        if since.is_some_and(|t| now.saturating_since(t) < self.config.transfer_timeout) {
            self.start_report(now, Purpose::Truth);
        } else {
            self.end_upload_unknown(now);
        }
    }

    /// The mission download is complete: the areas follow.
    fn mission_downloaded(&mut self, now: Instant, mission: Mission) {
        if self.fetching_edit_base() {
            self.edit_base_downloaded(now, Some(mission));
            return;
        }
        if let Some(job) = self.upload.as_mut() {
            job.verified_mission = Some(Some(mission_checksum(&mission)));
        } else {
            self.downloaded_mission = Some(mission);
        }
        self.request_areas(now);
    }

    /// The area download is complete.
    fn areas_downloaded(&mut self, now: Instant, areas: AreaList) {
        if self.fetching_edit_base() {
            self.edit_areas_downloaded(now, Some(&areas));
            return;
        }
        if let Some(job) = self.upload.as_ref() {
            let mission = job.verified_mission.flatten();
            self.resolve(
                now,
                (mission, Some(areas_checksum(&areas))),
                None,
                Confirmation::Download,
            );
            return;
        }
        match self.downloaded_mission.take() {
            Some(mission) => self.finish(GcsEvent::DownloadComplete(Box::new(ValidatedPlan {
                mission,
                areas,
            }))),
            None => self.fail(GcsError::InvalidDownload {
                phase: Phase::AreaDownload,
                reason: Reason::WrongState,
            }),
        }
    }

    /// When [`GroundStation::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.earliest_deadline()
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

impl<G: SafetyGateway> Composite<GcsTimer, 5> for GroundStation<G> {
    fn endpoint(&mut self) -> &mut Endpoint {
        &mut self.endpoint
    }

    fn deadline(&self, timer: GcsTimer) -> Option<Instant> {
        match timer {
            GcsTimer::Sender => self.sender.as_ref().and_then(TransferSender::poll_timeout),
            GcsTimer::Behind => self.behind.as_ref().and_then(|b| b.sender.poll_timeout()),
            GcsTimer::MissionDownload => self.mission_download.poll_timeout(),
            GcsTimer::AreaDownload => self.area_download.poll_timeout(),
            GcsTimer::Report => self.report.poll_timeout(),
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
                self.pace_behind(now);
                None
            }
            GcsTimer::Behind => {
                if let Some(event) = self
                    .behind
                    .as_mut()
                    .and_then(|b| b.sender.handle_timeout(&mut self.endpoint, now))
                {
                    self.behind_event(event);
                }
                None
            }
            GcsTimer::MissionDownload => self.mission_download.handle_timeout(now),
            GcsTimer::AreaDownload => self.area_download.handle_timeout(now),
            GcsTimer::Report => self.report.handle_timeout(now),
        };
        if timed_out.is_some() {
            let phase = self.phase();
            match self.state {
                State::Reporting(Purpose::Truth) => self.ask_again_or_give_up(now),
                _ => self.download_failed(now, GcsError::Timeout { phase }),
            }
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
            self.pace_behind(now);
            // A ready #3013 answers the area download request and opens the download: it goes
            // on to the receiver below.
            if !matches!(message, Message::AreaTransmissionStatus(s) if s.status == AreaDownloadStatus::Ready)
            {
                return;
            }
        }
        // An answer to the step sent behind (ICD §10.3)?
        if let Some(event) = self
            .behind
            .as_mut()
            .and_then(|b| b.sender.handle_answer(&mut self.endpoint, now, message))
        {
            self.behind_event(event);
            return;
        }
        match message {
            Message::FromToNext(ftn) => {
                self.events.push_back(GcsEvent::FromToNext(*ftn));
            }
            // A periodic status, never acknowledged (ICD §5.8).
            Message::InertialStates(states) => {
                self.events.push_back(GcsEvent::Position(*states));
            }
            Message::MessageAcknowledgement(_) | Message::AreaStatusAlert(_) => {
                tracing::debug!("answer to nothing outstanding (late or duplicate)");
            }
            Message::MissionReport(entry) => match self.state {
                State::Reporting(purpose) => {
                    // The FCC may start before its acceptance of the request arrives.
                    if !self.report.in_transfer() {
                        self.account_sender();
                        self.edition = Some(Edition::Two);
                        self.report.begin(now);
                    }
                    let outcome = self.report.handle(now, entry);
                    self.endpoint.answer(now, message, ack, outcome.map(|_| ()));
                    if outcome == Ok(Received::Complete) {
                        self.reported(now, purpose);
                    }
                }
                _ => self
                    .endpoint
                    .answer(now, message, ack, Err(Reason::WrongState)),
            },
            Message::VehicleSpecificWaypoint(_)
            | Message::UaPositionWaypoint(_)
            | Message::UaRoute(_)
            | Message::MissionUploadDownloadStatus(_)
                if self.state == State::Downloading(Phase::MissionDownload) =>
            {
                // The FCC may start before its acceptance of the request arrives (the links
                // reorder): the first mission message opens the download as well.
                if !self.mission_download.in_transfer() {
                    self.account_sender();
                    self.mission_download.begin(now);
                }
                let outcome = self.mission_download.handle(now, message);
                let closing = matches!(message, Message::MissionUploadDownloadStatus(_));
                if self.downloaded(now, message, ack, Phase::MissionDownload, outcome, closing) {
                    match self.mission_download.take() {
                        Some(mission) => self.mission_downloaded(now, mission),
                        None => self.download_failed(
                            now,
                            GcsError::InvalidDownload {
                                phase: Phase::MissionDownload,
                                reason: Reason::WrongState,
                            },
                        ),
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
                    match self.area_download.take() {
                        Some(areas) => self.areas_downloaded(now, areas),
                        None => self.download_failed(
                            now,
                            GcsError::InvalidDownload {
                                phase: Phase::AreaDownload,
                                reason: Reason::WrongState,
                            },
                        ),
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
