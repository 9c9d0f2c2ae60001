//! What a `gcs` command asks of a vehicle's ground station and how it ended, in one form for
//! both ways a command runs: alone, over the links it binds itself, or through the ground service
//! that owns them ([`super::client`]). [`carry_out`] is the one place a request meets the GCS
//! logic, so a command prints the same and exits with the same status either way.
//!
//! A request carries what the command read from its files, not their paths: a mission as a
//! mission file's text (exact to the wire values, `mission_file`), the aircraft profile and the
//! environment as values. The service validates the plan again with them (the safety gateway
//! is never skipped on the way), and reads no file of the operator's.

use missionlink_ground::ground_station::outcome::{UploadOutcome, UploadReport};
use missionlink_ground::ground_station::{
    GcsError, GcsEvent, GroundStation, MissionPlan, SafetyGateway as Gateway, Sequence,
    ValidatedPlan, validate,
};
use missionlink_ground::safety_gateway::SafetyGateway;
use missionlink_interfaces::wire::{ExecuteCommand, GeoPoint, Message};
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::sender::Target;
use missionlink_protocol::transfer::staged::MissionId;
use serde::{Deserialize, Serialize};

use crate::gcs_link::{Finished, GcsLink};
use crate::mission_file::MissionFile;
use crate::profile::{EnvironmentFile, ProfileFile};

/// What a command asks of a vehicle's ground station.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Request {
    /// `gcs upload` and `gcs stage`.
    Upload(Box<Upload>),
    /// `gcs activate ID` (#50000 command 4, ICD §8).
    Activate {
        /// The Mission ID.
        id: String,
    },
    /// `gcs delete ID` (#13000 mode 6, ICD §8).
    Delete {
        /// The Mission ID.
        id: String,
    },
    /// `gcs download`: the active lists, or a staged mission's.
    Download {
        /// The staged mission's ID, if one.
        id: Option<String>,
    },
    /// `gcs missions`: the FCC's report (ICD §8).
    Report,
    /// `gcs clear`.
    ClearMission,
    /// `gcs clear-areas`.
    ClearAreas,
    /// `gcs execute`, `gcs rth`, `gcs land` (#50000).
    Execute {
        /// Which.
        command: ExecuteCommand,
    },
}

/// An upload or a staging, as the command read it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Upload {
    /// The mission file the command was given, as it names it in messages.
    pub file: String,
    /// The lists as the command validated them, with the take-off position: a mission file.
    pub mission: String,
    /// The staged mission's ID, or none for the active lists.
    pub stage: Option<String>,
    /// The paper's sequence instead of the atomic upload (toward the active lists).
    pub paper_sequence: bool,
    /// Only what changed from the FCC's mission.
    pub edit: bool,
    /// The missions this GCS uploaded last (mission files, from its state directory), for an
    /// edit to start from without a download.
    pub known: Vec<String>,
    /// The aircraft profile of the safety gateway.
    pub profile: ProfileFile,
    /// The environment of the safety gateway.
    pub environment: EnvironmentFile,
}

/// How a request ended well.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Answer {
    /// Accepted.
    Done,
    /// Uploaded (or staged): the report as the GCS words it.
    Uploaded {
        /// The report (`UploadReport`'s text).
        report: String,
        /// For an edit: messages sent, and those a full upload would have sent.
        edit: Option<(usize, usize)>,
    },
    /// The lists downloaded, as a mission file without take-off position.
    Downloaded {
        /// The mission file.
        mission: String,
    },
    /// The FCC's report (ICD §8), the active lists first: #50001 messages.
    Reported {
        /// The entries.
        entries: Vec<Message>,
    },
}

/// How a request failed: the exit status and what to print.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Failure {
    /// The command's exit status (see each command's help).
    pub status: u8,
    /// What to print after `gcs: `.
    pub message: String,
}

impl Failure {
    /// A failure of exit status 1.
    pub fn other(message: impl Into<String>) -> Self {
        Self {
            status: 1,
            message: message.into(),
        }
    }

    /// Unreadable or unusable input: exit status 2.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            status: 2,
            message: message.into(),
        }
    }
}

/// Progress of a transfer, for a terminal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Progress {
    /// The phase, as the GCS logic names it.
    pub phase: String,
    /// Messages answered so far.
    pub sent: usize,
    /// Messages in the transfer.
    pub total: usize,
}

/// The link a request is carried out on.
pub type Link = GcsLink<SafetyGateway>;

/// An event of the GCS logic on that link.
pub type Event = GcsEvent<<SafetyGateway as Gateway>::Report>;

/// What hears a request while it runs.
pub trait Listener {
    /// A transfer's progress, for a terminal.
    fn progress(&mut self, _progress: Progress) {}
    /// Any other event of the GCS logic (the downlink's reports among them).
    fn event(&mut self, _event: &Event) {}
    /// The link was pumped once (every 20 ms at most): time for what must not wait for the
    /// request to end (the ground service's MAVLink heartbeat, its monitors, the staged copies
    /// it keeps on disk); `station` is the GCS logic as it runs the request.
    fn tick(&mut self, _station: &GroundStation<SafetyGateway>) {}
    /// An upload's lists passed the safety gateway (`gateway`, as the command gave it), before
    /// anything is sent: the ground service's own checks of them (the fleet's separation), and
    /// what they will be once uploaded (`target`). An error (why, its first line the summary)
    /// refuses the upload with nothing sent. The plan is read and validated once, here, for
    /// both.
    fn validated(
        &mut self,
        _lists: &ValidatedPlan,
        _take_off: Option<GeoPoint>,
        _target: Target,
        _gateway: &SafetyGateway,
    ) -> Result<(), String> {
        Ok(())
    }
}

/// A listener that hears nothing.
impl Listener for () {}

/// Carries `request` out on `link` until it ends, `listener` hearing it run.
pub fn carry_out(
    link: &mut Link,
    request: Request,
    listener: &mut dyn Listener,
) -> Result<Answer, Failure> {
    let now = link.now();
    let station = link.station();
    let started = match &request {
        Request::Upload(upload) => return carry_out_upload(link, upload, listener),
        Request::Activate { id } => station.activate(now, mission_id(id)?),
        Request::Delete { id } => station.delete(now, mission_id(id)?),
        Request::Download { id } => {
            let id = id.as_deref().map(mission_id).transpose()?;
            station.download_of(now, id)
        }
        Request::Report => station.report(now),
        Request::ClearMission => station.clear_mission(now),
        Request::ClearAreas => station.clear_areas(now),
        Request::Execute { command } => station.execute(now, *command),
    };
    started.map_err(|e| Failure::other(e.to_string()))?;
    match finish(link, listener)? {
        Finished::Downloaded(plan) => Ok(Answer::Downloaded {
            mission: MissionFile::from_plan(&plan, None).to_toml(),
        }),
        Finished::Reported(entries) => Ok(Answer::Reported {
            entries: entries.into_iter().map(Message::from).collect(),
        }),
        Finished::Uploaded(report) => Ok(uploaded(&report)),
        Finished::Done => match request {
            Request::Download { .. } => Err(Failure::other("the download ended without lists")),
            Request::Report => Err(Failure::other("the FCC sent no report")),
            _ => Ok(Answer::Done),
        },
    }
}

fn uploaded(report: &UploadReport) -> Answer {
    Answer::Uploaded {
        report: report.to_string(),
        edit: report
            .edit
            .map(|_| (report.messages.sent, report.messages.full)),
    }
}

/// A Mission ID as ICD §8 defines it; the command checked it already, so a bad one here came
/// from elsewhere and is unusable input.
fn mission_id(id: &str) -> Result<MissionId, Failure> {
    MissionId::new(id).map_err(|e| Failure::input(format!("Mission ID {id:?}: {e}")))
}

/// A mission file's text as the plan it holds; `what` names it in errors.
fn plan_of(text: &str, what: &str) -> Result<Box<MissionPlan>, Failure> {
    MissionFile::parse(text)
        .and_then(|f| f.to_plan())
        .map_err(|e| Failure::input(format!("{what}: {e}")))
}

fn carry_out_upload(
    link: &mut Link,
    upload: &Upload,
    listener: &mut dyn Listener,
) -> Result<Answer, Failure> {
    let plan = plan_of(&upload.mission, &upload.file)?;
    let gateway = SafetyGateway::new(upload.profile.into(), upload.environment.into());
    let nothing_sent = |e: &dyn std::fmt::Display| {
        Failure::other(format!("{}: {e}; nothing was sent", upload.file))
    };
    let validated = validate(&gateway, &plan).map_err(|e| nothing_sent(&e))?;
    let target = match &upload.stage {
        Some(id) => Target::Staged(mission_id(id)?),
        None => Target::Active,
    };
    listener
        .validated(&validated, plan.take_off_position, target, &gateway)
        .map_err(|why| {
            // "nothing was sent" ends the summary; the details (one per line) follow it.
            let (first, rest) = why.split_once('\n').unwrap_or((&why, ""));
            let rest = if rest.is_empty() {
                String::new()
            } else {
                format!("\n{rest}")
            };
            Failure::other(format!("{}: {first}; nothing was sent{rest}", upload.file))
        })?;
    let sequence = if upload.paper_sequence {
        Sequence::Paper { clear: true }
    } else {
        Sequence::Atomic
    };
    let known: Vec<Mission> = upload
        .known
        .iter()
        .filter_map(|text| plan_of(text, "a known mission").ok()?.assemble().ok())
        .map(|v: ValidatedPlan| v.mission)
        .collect();
    // Read after the validation: the first message's ack timer starts when it is sent.
    let now = link.now();
    let station = link.station();
    let requested = match (upload.edit, target) {
        (true, _) => station.edit_validated(now, validated, target, sequence, known),
        (false, Target::Active) => station.upload_validated(now, validated, sequence),
        (false, Target::Staged(id)) => station.stage_validated(now, id, validated),
    };
    requested.map_err(|e| nothing_sent(&e))?;
    match finish(link, listener)? {
        Finished::Uploaded(report) => Ok(uploaded(&report)),
        _ => Ok(Answer::Done),
    }
}

/// Runs the link until the request ends; a failure with the exit status of its command.
fn finish(link: &mut Link, listener: &mut dyn Listener) -> Result<Finished, Failure> {
    let outcome = link.finish_ticking(|event, station| match event {
        Some(GcsEvent::Progress { phase, sent, total }) => listener.progress(Progress {
            phase: phase.to_string(),
            sent: *sent,
            total: *total,
        }),
        Some(other_event) => listener.event(other_event),
        None => listener.tick(station),
    });
    let unheard = link.unheard();
    outcome.map_err(|e| {
        let mut failure = match e {
            GcsError::Upload(report) => Failure {
                status: upload_status(report.outcome()),
                message: report.to_string(),
            },
            // Nothing was staged: the lists are as they were.
            capacity @ GcsError::Capacity { .. } => Failure {
                status: upload_status(UploadOutcome::PreviousActive),
                message: capacity.to_string(),
            },
            other => Failure::other(other.to_string()),
        };
        if let Some(why) = unheard {
            failure.message = format!("{}\n{why}", failure.message);
        }
        failure
    })
}

/// The exit status of `gcs upload` for each outcome (see the command's help).
pub fn upload_status(outcome: UploadOutcome) -> u8 {
    match outcome {
        UploadOutcome::Complete
        | UploadOutcome::CompleteAfterLostAnswer
        | UploadOutcome::AlreadyActive => 0,
        UploadOutcome::PreviousActive => 3,
        UploadOutcome::Mixed => 4,
        UploadOutcome::Unknown => 5,
        UploadOutcome::Foreign => 6,
        UploadOutcome::NoMission => 7,
    }
}
