//! The upload requests of the GCS logic and the steps they take (ICD §5.1, §5.3, §8, §11).
//!
//! Every upload starts with the FCC's report (ICD §8, §10.1): the edition, what is active, which
//! missions are staged and their checksums; pipelining (ICD §10.3: toward edition 2 with a
//! window above 1), the report the GCS holds when it is fresh instead. Then the GCS plans its
//! steps and sends them one after the other, pipelining the area upload behind the mission
//! closer and the activation behind the area closer (`send_next_behind`):
//!
//! | request | toward edition 2 | toward edition 1 |
//! |---|---|---|
//! | [`Sequence::Atomic`] upload | mission staged under the staging ID (#13000 mode 10, data, mode 8), areas staged (#2011 mode 1, #2012, mode 7), #50000 command 4, #13000 mode 6 of the staged copy | the paper's sequence with the clear |
//! | [`Sequence::Paper`] upload | the paper's sequence (Figure 11): waypoints (mode 2), then areas (#2011 mode 2) | the same |
//! | stage | mission and areas under the given ID (modes 10, 8; #2011 mode 7) | refused: edition 1 holds no staged missions |
//! | edit | mode 10 (load the buffer from the target), what changed, the closer; areas only if changed | what changed, mode 2; areas only if changed |
//!
//! **The staging ID** of an atomic upload is the operator's Mission ID, the plan's: the activation
//! makes the staged mission's lists the active ones under its ID (ICD §8), so the FCC holds,
//! reports and hands back on a download the name the operator gave. When the plan has no Mission
//! ID, or the report lists a staged mission of that name (the operator's own, which the upload
//! must neither replace nor delete), the upload stages under a fresh ID instead and logs that the
//! active lists will carry it.
//!
//! **A fresh Mission ID** is `gcs-` and the new mission's checksum (ICD §11) in eight hex digits;
//! when the report lists that ID, `-1` to `-9` is appended, the first free one. The same rule
//! names the unused ID whose #13000 mode 10 empties the buffer before a full upload into a staged
//! mission that already holds a waypoint list (ICD §8: mode 10 empties the buffer when the ID has
//! no waypoint list).
//!
//! **An edit of the active mission toward edition 2** whose areas are unchanged closes with mode 2:
//! only the waypoint list changes, so it is atomic without staging. When the areas changed too, the
//! edited mission is staged under the staging ID from the active list (mode 10 with the empty ID), the
//! areas staged, and the whole activated in one step.
//!
//! **After a failure** the GCS asks what the FCC holds (the report; a download from edition 1)
//! and goes on where a lost answer hid a success: a staged closer whose list the report shows
//! under the ID, an activation whose lists are active. Before the activation is sent, the active
//! lists cannot have changed: when the FCC does not answer the question, the outcome says so by
//! construction ([`Confirmation::NotActivated`]). The staged copy of an atomic upload is deleted
//! whatever the outcome, when the FCC holds it; a failed delete is a warning
//! ([`UploadReport::warning`]), not a failed upload.

use missionlink_interfaces::capacity::MAX_STAGED_MISSIONS;
use missionlink_interfaces::wire::{Checksum, GeofenceCheck, MissionReport, Text};

use super::edit::{FullUpload, difference};
use super::outcome::{
    Before, Confirmation, Held, ListOutcome, Messages, UploadKind, UploadOutcome, UploadReport,
    Warning,
};
use super::{Edition, GcsError, GroundStation, MissionPlan, Phase, SafetyGateway, State, Then};
use missionlink_protocol::link::retry::ExchangeError;
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::sender::{
    Opener, Script, Target, activate_staged, delete_staged,
};
use missionlink_protocol::transfer::staged::MissionId;

/// How an upload of the active lists changes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sequence {
    /// Toward an edition-2 FCC: stage under the staging ID, activate (#50000 command 4),
    /// delete the staged copy: the waypoint list and the area list change in one step, and a
    /// failure before the activation leaves both as they were. Toward an edition-1 FCC: the
    /// paper's sequence with the clear (the lists change one after the other).
    Atomic,
    /// The paper's sequence (Figure 11; ICD §5.1, then §5.3) toward either edition: the waypoint
    /// list becomes active at its closer, the area list at its own. `clear`: start with #13000
    /// mode 1 (without it, the buffer's content stays and the file's waypoints overwrite it).
    Paper {
        /// Send #13000 mode 1 first.
        clear: bool,
    },
}

/// What the upload writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// The active lists by the paper's sequence.
    Paper { clear: bool },
    /// The active lists, staged and activated (edition 2).
    Atomic,
    /// The staged mission of this ID (edition 2).
    Stage(MissionId),
}

/// An edit request: what the GCS knows of the FCC's missions and what it found.
#[derive(Debug, Clone)]
pub(super) struct EditJob {
    /// Missions this GCS uploaded before (its cache): one whose checksum the report shows for
    /// the target is the base without a download.
    known: Vec<Mission>,
    /// The mission on the FCC the edit starts from, once known.
    base: Option<Mission>,
    /// The target's area checksum as downloaded (edition 1 gives no report).
    base_areas: Option<Option<Checksum>>,
    /// Downloading the base.
    pub(super) fetching: bool,
    /// Why the edit is a full upload, if it is.
    fallback: Option<FullUpload>,
}

/// An upload request in progress.
#[derive(Debug, Clone)]
pub(super) struct UploadJob {
    pub(super) mission: Mission,
    pub(super) areas: AreaList,
    pub(super) kind: Kind,
    pub(super) edit: Option<EditJob>,
    /// ICD §11 checksums of both lists.
    pub(super) checksums: (Checksum, Checksum),
    /// The target's lists before (the active ones, or the staged mission's), from the report.
    pub(super) before: Option<(Before, Before)>,
    /// The report's entries before the upload.
    entries: Vec<MissionReport>,
    /// The fresh ID an atomic upload stages under.
    temp: Option<MissionId>,
    /// Whether the FCC holds the staged copy: `Some(false)` no, `Some(true)` yes, `None` it may.
    temp_staged: Option<bool>,
    /// Copies earlier uploads left that the report lists: deleted after the upload's own.
    leftovers: Vec<MissionId>,
    /// Whether the report gave copies to delete: the upload then does not bring the report
    /// up to date (ICD §10.3), as which of them went is not followed.
    had_leftovers: bool,
    /// Whether this attempt asked for the report (ICD §10.3: not when it held a fresh one).
    asked_report: bool,
    /// The staged copy whose delete is in progress.
    deleting: Option<MissionId>,
    /// The mission step: its opener and selection; `None`: the mission is not sent.
    mission_step: Option<(Opener, Option<Vec<u16>>)>,
    send_areas: bool,
    activation_sent: bool,
    /// The transfer's failure, once it failed.
    pub(super) failure: Option<(Phase, ExchangeError)>,
    /// The lists downloaded to find out what is active (edition 1): the mission, once known
    /// (`Some(None)`: there is none).
    pub(super) verified_mission: Option<Option<Checksum>>,
    /// When the GCS began to ask what is active.
    pub(super) asking_since: Option<Instant>,
    /// How the GCS knows, for an upload that ends after it went on from a lost answer.
    confirmation: Confirmation,
    /// Messages sent so far.
    pub(super) sent: usize,
    /// The report, held while the staged copy is deleted.
    ending: Option<Box<UploadReport>>,
    warning: Option<Warning>,
    /// Which attempt this is, from 1 (see [`GcsConfig::upload_attempts`](super::GcsConfig)).
    attempt: u8,
    /// What began the upload, to begin it again.
    request: Box<Request>,
}

impl UploadJob {
    /// Attempt `attempt` of `request`, `sent` messages sent by the attempts before it. Built
    /// apart from the steps that follow (not inlined into them): the job is 60 KB, and the
    /// frame that builds it is left before the first step goes deeper.
    #[inline(never)]
    fn attempt(request: Box<Request>, attempt: u8, sent: usize) -> Box<Self> {
        let super::ValidatedPlan { mission, areas } = request.plan.clone();
        let edit = request.known.clone().map(|known| EditJob {
            known,
            base: None,
            base_areas: None,
            fetching: false,
            fallback: None,
        });
        Box::new(UploadJob {
            checksums: (mission_checksum(&mission), areas_checksum(&areas)),
            mission,
            areas,
            kind: request.kind,
            edit,
            before: None,
            entries: Vec::new(),
            temp: None,
            temp_staged: Some(false),
            leftovers: Vec::new(),
            had_leftovers: false,
            asked_report: false,
            deleting: None,
            mission_step: None,
            send_areas: true,
            activation_sent: false,
            failure: None,
            verified_mission: None,
            asking_since: None,
            confirmation: Confirmation::Answers,
            sent,
            ending: None,
            warning: None,
            attempt,
            request,
        })
    }
}

/// An upload request as it was made: what another attempt begins with.
#[derive(Debug, Clone)]
pub(super) struct Request {
    plan: super::ValidatedPlan,
    kind: Kind,
    /// For an edit: the missions the GCS knew.
    known: Option<Vec<Mission>>,
}

/// The entry of the report for `target`: the active lists (empty Mission ID) or a staged mission.
pub(super) fn entry_of(entries: &[MissionReport], target: Target) -> Option<&MissionReport> {
    let wanted = target.mission_id_field();
    entries
        .iter()
        .find(|e| e.mission_id.unwrap_or_default().as_str() == wanted.as_str())
}

fn staged_count(entries: &[MissionReport]) -> usize {
    entries
        .iter()
        .filter(|e| e.mission_id.is_some_and(|id| !id.is_empty()))
        .count()
}

/// The fresh Mission ID for `checksum` (see the module's documentation): `gcs-XXXXXXXX`, or
/// with `-1` to `-9` appended, the first the report does not list.
pub fn fresh_mission_id(entries: &[MissionReport], checksum: Checksum) -> Option<MissionId> {
    let stem = format!("gcs-{:08X}", checksum.value());
    core::iter::once(stem.clone())
        .chain((1..=9).map(|n| format!("{stem}-{n}")))
        .filter_map(|s| MissionId::new(&s).ok())
        .find(|id| entry_of(entries, Target::Staged(*id)).is_none())
}

/// The Mission ID an atomic upload stages under (see the module's documentation): the plan's
/// own `mission_id` when it is a valid Mission ID that the report does not list, else a fresh
/// one.
pub fn staging_id(
    entries: &[MissionReport],
    mission_id: Option<Text<20>>,
    checksum: Checksum,
) -> Option<MissionId> {
    let own = mission_id.and_then(|text| MissionId::new(text.as_str()).ok());
    match own {
        Some(id) if entry_of(entries, Target::Staged(id)).is_none() => Some(id),
        _ => {
            let fresh = fresh_mission_id(entries, checksum);
            if let (Some(own), Some(fresh)) = (own, fresh) {
                tracing::warn!(
                    %own,
                    %fresh,
                    "the FCC holds a staged mission named like this plan: the upload stages under \
                     a fresh Mission ID, which the active lists will carry"
                );
            }
            fresh
        }
    }
}

impl<G: SafetyGateway> GroundStation<G> {
    /// The upload request of the active lists by `sequence`: validation first (nothing is sent
    /// when it fails), then the report (ICD §8, §10.1: the edition and what is active before;
    /// skipped toward an edition-1 FCC heard within the transfer timeout), then the steps of
    /// the module's table. Ends in [`super::GcsEvent::Uploaded`], or in
    /// [`super::GcsEvent::Failed`] with what the FCC holds ([`GcsError::Upload`]).
    pub fn upload_with(
        &mut self,
        now: Instant,
        plan: &MissionPlan,
        sequence: Sequence,
    ) -> Result<(), GcsError<G::Report>> {
        let validated = self.validate(plan)?;
        self.upload_validated(now, validated, sequence)
    }

    /// [`GroundStation::upload_with`] of a plan validated already: `now` read after the
    /// validation, which takes up to a second for a large plan in a debug build. With `now` read
    /// before it, the first message's ack timer would have run during the validation and its one
    /// retry would be spent before the FCC could answer (`services/ground/tests/sans_io/retry_timing.rs`).
    pub fn upload_validated(
        &mut self,
        now: Instant,
        validated: super::ValidatedPlan,
        sequence: Sequence,
    ) -> Result<(), GcsError<G::Report>> {
        let kind = match sequence {
            Sequence::Atomic => Kind::Atomic,
            Sequence::Paper { clear } => Kind::Paper { clear },
        };
        self.begin_upload(now, validated, kind, None)
    }

    /// The stage request (ICD §8): the plan's mission and areas stored under `id`, the active
    /// lists untouched. Toward an edition-1 FCC it fails ([`GcsError::Edition1`]); when the FCC
    /// holds 8 other staged missions, before anything is staged ([`GcsError::Capacity`]).
    pub fn stage(
        &mut self,
        now: Instant,
        id: MissionId,
        plan: &MissionPlan,
    ) -> Result<(), GcsError<G::Report>> {
        let validated = self.validate(plan)?;
        self.stage_validated(now, id, validated)
    }

    /// [`GroundStation::stage`] of a plan validated already (`now` read after the validation,
    /// see [`GroundStation::upload_validated`]).
    pub fn stage_validated(
        &mut self,
        now: Instant,
        id: MissionId,
        validated: super::ValidatedPlan,
    ) -> Result<(), GcsError<G::Report>> {
        self.begin_upload(now, validated, Kind::Stage(id), None)
    }

    /// The edit request: the plan compared with the mission `target` holds on the FCC, and only
    /// what changed sent (module [`super::edit`]). The FCC's mission is one of `known` (missions
    /// this GCS uploaded, from its cache) when the report's checksum for the target confirms it,
    /// else it is downloaded. Toward the active lists `sequence` says how both lists change when
    /// the areas changed too; toward a staged mission it does not matter.
    pub fn edit(
        &mut self,
        now: Instant,
        plan: &MissionPlan,
        target: Target,
        sequence: Sequence,
        known: Vec<Mission>,
    ) -> Result<(), GcsError<G::Report>> {
        let validated = self.validate(plan)?;
        self.edit_validated(now, validated, target, sequence, known)
    }

    /// [`GroundStation::edit`] of a plan validated already (`now` read after the validation,
    /// see [`GroundStation::upload_validated`]).
    pub fn edit_validated(
        &mut self,
        now: Instant,
        validated: super::ValidatedPlan,
        target: Target,
        sequence: Sequence,
        known: Vec<Mission>,
    ) -> Result<(), GcsError<G::Report>> {
        let kind = match (target, sequence) {
            (Target::Staged(id), _) => Kind::Stage(id),
            (Target::Active, Sequence::Atomic) => Kind::Atomic,
            (Target::Active, Sequence::Paper { clear }) => Kind::Paper { clear },
        };
        self.begin_upload(now, validated, kind, Some(known))
    }

    fn begin_upload(
        &mut self,
        now: Instant,
        validated: super::ValidatedPlan,
        kind: Kind,
        known: Option<Vec<Mission>>,
    ) -> Result<(), GcsError<G::Report>> {
        self.ensure_standby()?;
        let request = Request {
            plan: validated,
            kind,
            known,
        };
        self.begin_attempt(now, Box::new(request), 1, 0);
        Ok(())
    }

    /// The staged copies of this GCS's atomic uploads the FCC may hold and nobody else will
    /// delete: those whose delete failed or went unanswered, and the copy of the upload in
    /// progress from the moment it is chosen until its delete is answered. A ground that keeps
    /// them across its own restart ([`GroundStation::set_copies_to_delete`]) leaves none
    /// behind when it dies in the middle of an upload.
    pub fn copies_to_delete(&self) -> Vec<MissionId> {
        let mut ids = self.copies_left.clone();
        if let Some(job) = &self.upload
            && let Some(id) = job.temp
            && job.temp_staged != Some(false)
            && !ids.contains(&id)
        {
            ids.push(id);
        }
        ids
    }

    /// The copies left to delete are `ids` (a previous run's, [`GroundStation::copies_to_delete`];
    /// or what remains once the caller deleted some): the next upload toward edition 2 deletes
    /// those its report still lists.
    pub fn set_copies_to_delete(&mut self, ids: &[MissionId]) {
        self.copies_left = ids.to_vec();
    }

    /// Begins attempt `attempt` of `request`, `sent` messages sent by the attempts before.
    fn begin_attempt(&mut self, now: Instant, request: Box<Request>, attempt: u8, sent: usize) {
        self.upload = Some(UploadJob::attempt(request, attempt, sent));
        // Toward edition 2 the report goes first: it is what is held before, for the plan and
        // for the truth after a failure (ICD §11); pipelining, a fresh one the GCS holds will
        // do (ICD §10.3). The upload changes the lists: the one held is used up.
        let fresh = self.pipelining().then(|| self.fresh_report(now)).flatten();
        self.held_report = None;
        if self.edition_known(now) && self.edition == Some(Edition::One) {
            self.plan_upload(now);
        } else if let Some(entries) = fresh {
            tracing::info!("the report held is fresh: the upload goes without asking for it");
            self.upload_discovered(&entries);
            self.plan_upload(now);
        } else {
            if let Some(job) = self.upload.as_mut() {
                job.asked_report = true;
            }
            self.start_report(now, super::Purpose::Discovery(Then::Upload));
        }
    }

    /// After a failed attempt that left the lists the upload targets as they were, or without a
    /// mission only because the attempt's own clear deleted it (`clean`):
    /// begins the next attempt when the failure may pass (`may_pass`: the FCC did not answer,
    /// was busy, or lost the transfer in a restart, see [`ExchangeError::may_pass`]) and
    /// attempts are left. `true` when it did; `failure` says what failed, for the log.
    ///
    /// ICD §5 allows each message one resend; on a link that loses a burst, a message and its
    /// resend are lost together more often than the loss rate says. An operator would press
    /// upload again; the GCS does it for them, only when nothing was changed and nothing was
    /// refused for what the lists are, so the outcome is the one upload would have had.
    pub(super) fn attempt_again(
        &mut self,
        now: Instant,
        failure: &dyn core::fmt::Display,
        may_pass: bool,
        clean: bool,
    ) -> bool {
        let attempts = self.config.upload_attempts;
        let Some(job) = self.upload.as_ref() else {
            return false;
        };
        if !may_pass || !clean || job.attempt >= attempts {
            return false;
        }
        let (attempt, sent, request) = (job.attempt, job.sent, job.request.clone());
        tracing::warn!(
            attempt,
            attempts,
            "upload attempt failed ({failure}) with the lists as they were: attempting it again"
        );
        self.reset();
        self.begin_attempt(now, request, attempt + 1, sent);
        true
    }

    /// The discovery's report arrived (edition 2): what the target holds before.
    pub(super) fn upload_discovered(&mut self, entries: &[MissionReport]) {
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        let target = match job.kind {
            Kind::Stage(id) => Target::Staged(id),
            _ => Target::Active,
        };
        let held = entry_of(entries, target);
        job.before = Some((
            Before(held.and_then(|e| e.mission_checksum)),
            Before(held.and_then(|e| e.area_checksum)),
        ));
        job.entries = entries.to_vec();
        // Copies the FCC no longer lists are gone (deleted, or the FCC lost them).
        self.copies_left
            .retain(|id| entry_of(entries, Target::Staged(*id)).is_some());
        job.leftovers = self.copies_left.clone();
        job.had_leftovers = !job.leftovers.is_empty();
    }

    /// Plans the steps once the edition (and toward edition 2 the report) is known, and starts
    /// the first; or first downloads the base of an edit.
    pub(super) fn plan_upload(&mut self, now: Instant) {
        let edition_2 = self.edition == Some(Edition::Two);
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        match (job.kind, edition_2) {
            (Kind::Stage(_), false) => {
                return self.fail(GcsError::Edition1 {
                    request: "staging a mission (ICD §8)",
                });
            }
            // An edition-1 FCC cannot be told the wind its turns were checked in: it would fly
            // and check them for calm air, tighter than the gateway checked (ICD §7 "Turns in
            // wind"). Refused before anything is sent rather than sent without it.
            (_, false) if job.mission.route.planning_wind.is_some() => {
                return self.fail(GcsError::Edition1 {
                    request: "a mission planned in wind (#13001 field 5, ICD §7 \"Turns in wind\")",
                });
            }
            (Kind::Atomic, false) => job.kind = Kind::Paper { clear: true },
            _ => {}
        }
        let target = match job.kind {
            Kind::Stage(id) => Target::Staged(id),
            _ => Target::Active,
        };
        let held = entry_of(&job.entries, target).copied();
        // The edit's base: confirmed by the report's checksum from the cache, else downloaded
        // (toward edition 1 always, with the areas: there is no report).
        if let Some(edit) = job.edit.as_mut()
            && edit.base.is_none()
            && edit.fallback.is_none()
        {
            let cached = held
                .and_then(|e| e.mission_checksum)
                .and_then(|c| edit.known.iter().find(|m| mission_checksum(m) == c));
            match (edition_2, held.and_then(|e| e.mission_checksum), cached) {
                (true, None, _) => edit.fallback = Some(FullUpload::NoMission),
                (true, Some(_), Some(m)) => edit.base = Some(m.clone()),
                _ => {
                    edit.fetching = true;
                    tracing::info!(%target, "downloading the mission to edit");
                    self.download_target = target;
                    self.request_mission(now);
                    return;
                }
            }
        }
        let areas_held = match (&job.edit, edition_2) {
            (Some(edit), false) => edit.base_areas.flatten(),
            _ => held.and_then(|e| e.area_checksum),
        };
        let areas_changed = job.edit.is_none() || areas_held != Some(job.checksums.1);
        let selection = match job.edit.as_mut() {
            Some(edit) => match edit.base.as_ref().map(|b| difference(b, &job.mission)) {
                Some(Ok(selection)) => Some(selection),
                Some(Err(why)) => {
                    edit.fallback = Some(why);
                    None
                }
                None => None,
            },
            None => None,
        };
        if let Some(why) = job.edit.as_ref().and_then(|e| e.fallback) {
            tracing::info!(%why, "the edit is sent as a full upload");
        }
        let staged = staged_count(&job.entries);
        let fresh = fresh_mission_id(&job.entries, job.checksums.0);
        // A full upload through the buffer starts from an empty one: toward edition 2 mode 10
        // with an ID that holds no waypoint list empties it without touching any list.
        let emptied = |id: Option<MissionId>| id.map(|i| Opener::LoadBuffer(Target::Staged(i)));
        match job.kind {
            Kind::Paper { clear } => {
                job.mission_step = match selection {
                    Some(s) if s.is_empty() => None,
                    Some(s) if edition_2 => Some((Opener::LoadBuffer(Target::Active), Some(s))),
                    Some(s) => Some((Opener::None, Some(s))),
                    None if job.edit.is_some() && edition_2 => {
                        Some((emptied(fresh).unwrap_or(Opener::Clear), None))
                    }
                    None if job.edit.is_some() || clear => Some((Opener::Clear, None)),
                    None => Some((Opener::None, None)),
                };
                job.send_areas = areas_changed;
            }
            Kind::Atomic if selection.is_some() && !areas_changed => {
                // Only the waypoint list changes: mode 2 is atomic by itself.
                job.mission_step = selection
                    .filter(|s| !s.is_empty())
                    .map(|s| (Opener::LoadBuffer(Target::Active), Some(s)));
                job.send_areas = false;
            }
            Kind::Atomic => {
                if staged >= MAX_STAGED_MISSIONS {
                    return self.fail(GcsError::Capacity { staged });
                }
                let Some(temp) = staging_id(&job.entries, job.mission.mission_id, job.checksums.0)
                else {
                    return self.fail(GcsError::Capacity { staged });
                };
                job.temp = Some(temp);
                job.mission_step = Some(match selection {
                    Some(s) => (Opener::LoadBuffer(Target::Active), Some(s)),
                    None => (Opener::LoadBuffer(Target::Staged(temp)), None),
                });
                job.send_areas = true;
            }
            Kind::Stage(_) => {
                if held.is_none() && staged >= MAX_STAGED_MISSIONS {
                    return self.fail(GcsError::Capacity { staged });
                }
                let has_waypoints = held.is_some_and(|e| e.waypoint_count > 0);
                job.mission_step = match selection {
                    Some(s) if s.is_empty() => None,
                    Some(s) => Some((Opener::LoadBuffer(target), Some(s))),
                    None if !has_waypoints => Some((Opener::LoadBuffer(target), None)),
                    None => match emptied(fresh) {
                        Some(opener) => Some((opener, None)),
                        None => return self.fail(GcsError::Capacity { staged }),
                    },
                };
                job.send_areas = areas_changed;
            }
        }
        self.next_step(now, None);
    }

    /// Where the closers of the upload go.
    fn closer_target(job: &UploadJob) -> Target {
        match (job.kind, job.temp) {
            (Kind::Stage(id), _) | (Kind::Atomic, Some(id)) => Target::Staged(id),
            _ => Target::Active,
        }
    }

    /// The first step after `after` that the plan holds, and its script (boxed, see
    /// [`super::Sender`]).
    fn following(
        job: &UploadJob,
        after: Option<Phase>,
        edition_2: bool,
    ) -> Option<(Phase, Box<Script>)> {
        let order = [
            Phase::MissionUpload,
            Phase::AreaUpload,
            Phase::Activation,
            Phase::Deletion,
        ];
        let start = after
            .and_then(|p| order.iter().position(|o| *o == p))
            .map_or(0, |i| i + 1);
        let target = Self::closer_target(job);
        order.into_iter().skip(start).find_map(|phase| {
            let script = match phase {
                Phase::MissionUpload => {
                    job.mission_step
                        .clone()
                        .map(|(opener, selection)| Script::MissionUpload {
                            mission: job.mission.clone(),
                            opener,
                            selection,
                            target,
                            checksum: edition_2.then_some(job.checksums.0),
                        })
                }
                Phase::AreaUpload => job.send_areas.then(|| Script::AreaUpload {
                    list: job.areas.clone(),
                    target,
                    checksum: edition_2.then_some(job.checksums.1),
                }),
                Phase::Activation => job.temp.map(|id| Script::Request(activate_staged(id))),
                Phase::Deletion => job
                    .temp
                    .filter(|_| job.temp_staged != Some(false))
                    .map(|id| Script::Request(delete_staged(id))),
                _ => None,
            };
            script.map(|s| (phase, Box::new(s)))
        })
    }

    /// What starting `phase` means for the job.
    fn starting(job: &mut UploadJob, phase: Phase) {
        match phase {
            Phase::MissionUpload | Phase::AreaUpload if job.temp.is_some() => {
                job.temp_staged = job.temp_staged.filter(|s| *s);
            }
            Phase::Activation => job.activation_sent = true,
            Phase::Deletion => {
                job.deleting = job.temp.filter(|_| job.temp_staged != Some(false));
            }
            _ => {}
        }
    }

    /// Starts the first step after `after` that the plan holds; ends the upload after the last.
    /// A step sent behind `after` already (ICD §10.3) goes on instead.
    pub(super) fn next_step(&mut self, now: Instant, after: Option<Phase>) {
        let edition_2 = self.edition == Some(Edition::Two);
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        let next = Self::following(job, after, edition_2);
        if let Some(behind) = self.behind.take() {
            if next
                .as_ref()
                .is_some_and(|(phase, _)| *phase == behind.phase)
            {
                return self.promote_behind(now, behind);
            }
            // Not the step that follows (it cannot be: only the next step is sent behind).
            self.behind = Some(behind);
            self.drop_behind(now);
        }
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        match next {
            Some((phase, script)) => {
                Self::starting(job, phase);
                self.start(now, State::Uploading(phase), script);
                // A mission upload whose data all went with its opener: the areas go beside.
                self.send_next_behind(now);
            }
            None => {
                let (m, a) = job.checksums;
                let confirmation = job.confirmation;
                self.end_upload(now, ListOutcome::new(m), ListOutcome::new(a), confirmation);
            }
        }
    }

    /// ICD §10.3: the area upload goes beside the mission upload once every mission data
    /// message was sent (their window shared, ICD §10.4), the activation behind the area closer
    /// once only that is unanswered. The area closer waits for the mission upload to be
    /// accepted, and the activation goes only after both closers were sent, the mission's
    /// accepted. The delete of the staged copy never goes behind the activation: arriving
    /// first, it would make the activation fail.
    pub(super) fn send_next_behind(&mut self, now: Instant) {
        if !self.pipelining() || self.behind.is_some() {
            return;
        }
        let State::Uploading(phase) = self.state else {
            return;
        };
        let Some(sender) = self.sender.as_ref() else {
            return;
        };
        // The step that may go now, if the plan's next step is that one.
        let may_follow = match phase {
            Phase::MissionUpload if sender.sent_all_data() || sender.awaits_only_its_last() => {
                Phase::AreaUpload
            }
            Phase::AreaUpload if sender.awaits_only_its_last() => Phase::Activation,
            _ => return,
        };
        let edition_2 = self.edition == Some(Edition::Two);
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        let Some((next, script)) = Self::following(job, Some(phase), edition_2) else {
            return;
        };
        if next != may_follow {
            return;
        }
        Self::starting(job, next);
        self.start_behind(now, next, script);
    }

    /// A step's script was answered to its end.
    pub(super) fn step_completed(&mut self, now: Instant, phase: Phase) {
        if let Some(job) = self.upload.as_mut() {
            match phase {
                Phase::MissionUpload | Phase::AreaUpload if job.temp.is_some() => {
                    job.temp_staged = Some(true);
                }
                Phase::Deletion => {
                    let deleted = job.deleting.take();
                    if deleted.is_some() && deleted == job.temp {
                        job.temp_staged = Some(false);
                    }
                    self.copies_left.retain(|id| Some(*id) != deleted);
                    if self.delete_leftover(now) {
                        return;
                    }
                    if let Some(report) = self.upload.as_mut().and_then(|j| j.ending.take()) {
                        return self.emit_upload(now, report);
                    }
                }
                _ => {}
            }
        }
        self.next_step(now, Some(phase));
    }

    /// A step failed. The delete of the staged copy only warns; any other step makes the GCS
    /// ask what the FCC holds (ICD §11).
    pub(super) fn step_failed(&mut self, now: Instant, phase: Phase, error: ExchangeError) {
        if self.upload.is_none() {
            return;
        }
        // ICD §10.3: what was sent behind the step that failed is dropped (an area upload is
        // cancelled); the FCC is then asked what it holds.
        self.drop_behind(now);
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        if phase == Phase::Deletion {
            let failed = job.deleting.take();
            tracing::warn!(%error, copy = ?failed.map(|id| id.to_string()), "the staged copy was not deleted");
            if failed.is_some() && failed == job.temp {
                job.warning = job.temp.map(|id| Warning::StagedCopyLeft {
                    id,
                    error: Some(error),
                });
            }
            // A copy an earlier upload left stays remembered; the next upload tries again.
            match job.ending.take() {
                Some(report) => self.emit_upload(now, report),
                None => {
                    let (m, a) = job.checksums;
                    let confirmation = job.confirmation;
                    self.end_upload(now, ListOutcome::new(m), ListOutcome::new(a), confirmation);
                }
            }
            return;
        }
        job.failure = Some((phase, error));
        self.find_out(now);
    }

    /// What the FCC holds after a failure: the target's lists and, for an atomic upload, the
    /// staged copy's (`None` when the FCC was not asked about it: edition 1). Goes on where a
    /// lost answer hid a success, else ends the upload.
    pub(super) fn resolve(
        &mut self,
        now: Instant,
        target: (Option<Checksum>, Option<Checksum>),
        temp: Option<(Option<Checksum>, Option<Checksum>)>,
        confirmation: Confirmation,
    ) {
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        let new = job.checksums;
        let phase = job.failure.map(|(p, _)| p);
        let staged_under_temp = job.temp.is_some();
        let go_on = match (phase, staged_under_temp) {
            (Some(Phase::MissionUpload), true) => temp.is_some_and(|t| t.0 == Some(new.0)),
            (Some(Phase::AreaUpload), true) => temp.is_some_and(|t| t.1 == Some(new.1)),
            (Some(Phase::MissionUpload), false) => target.0 == Some(new.0),
            (Some(Phase::AreaUpload), false) => false,
            (Some(Phase::Activation), _) => target == (Some(new.0), Some(new.1)),
            _ => false,
        };
        if let Some(t) = temp.filter(|_| staged_under_temp) {
            job.temp_staged = Some(t != (None, None));
        }
        // ICD §10.3: the activation sent behind the area closer was carried out when the new
        // lists are active; the upload goes on after it, not with it again.
        let phase = match phase {
            Some(Phase::AreaUpload)
                if go_on && job.activation_sent && target == (Some(new.0), Some(new.1)) =>
            {
                Some(Phase::Activation)
            }
            other => other,
        };
        if let Some(p) = phase.filter(|_| go_on) {
            let refused = job.failure.as_ref().and_then(|(_, e)| e.reason());
            match refused {
                // A refusal changes nothing (ICD §5): what it was to make so was so before.
                Some(reason) => tracing::info!(
                    %p,
                    ?reason,
                    "the FCC refused it and holds what it was to achieve already: the upload goes on"
                ),
                None => tracing::info!(
                    %p,
                    "its answer was lost but the FCC carried it out: the upload goes on"
                ),
            }
            job.confirmation = confirmation;
            return self.next_step(now, Some(p));
        }
        let (before_m, before_a) = job.before.unzip();
        let mut m = ListOutcome::compare(target.0, new.0, before_m);
        let cleared = job
            .mission_step
            .as_ref()
            .is_some_and(|(opener, _)| *opener == Opener::Clear);
        if cleared && target.0.is_none() && m.held != Held::Previous {
            m.held = Held::Cleared;
        }
        let a = ListOutcome::compare(target.1, new.1, before_a);
        self.end_upload(now, m, a, confirmation);
    }

    /// The truth report arrived (edition 2).
    pub(super) fn truth_reported(&mut self, now: Instant, entries: &[MissionReport]) {
        let Some(job) = self.upload.as_ref() else {
            return;
        };
        let lists = |t: Target| {
            entry_of(entries, t).map_or((None, None), |e| (e.mission_checksum, e.area_checksum))
        };
        let target = match job.kind {
            Kind::Stage(id) => lists(Target::Staged(id)),
            _ => lists(Target::Active),
        };
        let temp = job.temp.map(|id| lists(Target::Staged(id)));
        self.resolve(now, target, temp, Confirmation::Report);
    }

    /// The FCC did not answer the question. Before the activation was sent an atomic upload
    /// knows anyway: the active lists are the previous ones.
    pub(super) fn end_upload_unknown(&mut self, now: Instant) {
        let by_construction = self
            .upload
            .as_ref()
            .filter(|j| j.kind == Kind::Atomic && j.temp.is_some() && !j.activation_sent)
            .and_then(|j| j.before);
        match by_construction {
            Some((Before(m), Before(a))) => self.end_upload(
                now,
                ListOutcome::previous(m),
                ListOutcome::previous(a),
                Confirmation::NotActivated,
            ),
            None => self.end_upload(
                now,
                ListOutcome::UNKNOWN,
                ListOutcome::UNKNOWN,
                Confirmation::None,
            ),
        }
    }

    /// Ends the upload with what the FCC holds; an atomic upload's staged copy is deleted
    /// first when the FCC holds it (or may).
    pub(super) fn end_upload(
        &mut self,
        now: Instant,
        mission: ListOutcome,
        areas: ListOutcome,
        confirmation: Confirmation,
    ) {
        self.account_sender();
        let edition_2 = self.edition == Some(Edition::Two);
        let Some(job) = self.upload.as_mut() else {
            return;
        };
        let kind = match job.kind {
            Kind::Paper { .. } => UploadKind::Paper {
                edition_1: !edition_2,
            },
            Kind::Atomic => UploadKind::Atomic,
            Kind::Stage(id) => UploadKind::Staged(id),
        };
        let report = UploadReport {
            mission,
            areas,
            uploaded: job.checksums,
            failure: job.failure,
            confirmation,
            kind,
            messages: Messages {
                sent: job.sent,
                full: full_upload_messages(job, edition_2),
            },
            edit: job.edit.as_ref().map(|e| e.fallback),
            warning: None,
            attempts: job.attempt,
        };
        // The staged copy goes when the FCC holds it and no delete was tried yet; when the FCC
        // may hold it (it did not answer), the operator is told.
        let cleanup = job
            .temp
            .filter(|_| job.temp_staged != Some(false) && job.warning.is_none());
        if let Some(id) = cleanup {
            if job.temp_staged == Some(true) && self.state != State::Uploading(Phase::Deletion) {
                job.ending = Some(Box::new(report));
                job.deleting = Some(id);
                self.start(
                    now,
                    State::Uploading(Phase::Deletion),
                    super::request_script(delete_staged(id)),
                );
                return;
            }
            job.warning = Some(Warning::StagedCopyLeft { id, error: None });
        }
        if self.state != State::Uploading(Phase::Deletion) {
            job.ending = Some(Box::new(report));
            if self.delete_leftover(now) {
                return;
            }
            if let Some(report) = self.upload.as_mut().and_then(|j| j.ending.take()) {
                self.emit_upload(now, report);
            }
            return;
        }
        self.emit_upload(now, Box::new(report));
    }

    /// Starts the delete of the next copy an earlier upload left (`true`), if any is left.
    fn delete_leftover(&mut self, now: Instant) -> bool {
        let Some(job) = self.upload.as_mut() else {
            return false;
        };
        let Some(id) = job.leftovers.pop() else {
            return false;
        };
        job.deleting = Some(id);
        self.start(
            now,
            State::Uploading(Phase::Deletion),
            super::request_script(delete_staged(id)),
        );
        true
    }

    fn emit_upload(&mut self, now: Instant, mut report: Box<UploadReport>) {
        self.account_sender();
        let Some(job) = self.upload.as_ref() else {
            return;
        };
        // The paper's sequence's own clear deleted the mission: attempting again (clear, then
        // transmit) cannot leave less than the failure left.
        let clean = matches!(
            report.outcome(),
            UploadOutcome::PreviousActive | UploadOutcome::NoMission
        ) && job.warning.is_none();
        if let Some((phase, error)) = report.failure.filter(|_| !report.is_complete()) {
            let failure = format_args!("{phase}: {error}");
            if self.attempt_again(now, &failure, error.may_pass(), clean) {
                return;
            }
        }
        let Some(job) = self.upload.take() else {
            return;
        };
        if let Some(Warning::StagedCopyLeft { id, .. }) = &job.warning {
            if !self.copies_left.contains(id) {
                self.copies_left.push(*id);
            }
        }
        report.messages.sent = job.sent;
        report.warning = job.warning;
        report.attempts = job.attempt;
        self.held_report =
            report_after(&job, &report).map(|entries| super::HeldReport { entries, at: now });
        if report.is_complete() {
            tracing::info!(%report, "upload ended");
            self.finish(super::GcsEvent::Uploaded(report));
        } else {
            self.fail(GcsError::Upload(report));
        }
    }

    /// The base of the edit was downloaded: the mission (then, toward edition 1, the areas).
    /// `true` when the download was the edit's.
    pub(super) fn edit_base_downloaded(&mut self, now: Instant, mission: Option<Mission>) -> bool {
        let edition_2 = self.edition == Some(Edition::Two);
        let Some(edit) = self
            .upload
            .as_mut()
            .and_then(|j| j.edit.as_mut())
            .filter(|e| e.fetching)
        else {
            return false;
        };
        match mission {
            Some(m) => edit.base = Some(m),
            None => edit.fallback = Some(FullUpload::NoMission),
        }
        if edition_2 {
            edit.fetching = false;
            self.download_target = Target::Active;
            self.plan_upload(now);
        } else {
            self.request_areas(now);
        }
        true
    }

    /// The areas of the edit's base were downloaded (edition 1). `true` when the download was
    /// the edit's.
    pub(super) fn edit_areas_downloaded(&mut self, now: Instant, areas: Option<&AreaList>) -> bool {
        let Some(edit) = self
            .upload
            .as_mut()
            .and_then(|j| j.edit.as_mut())
            .filter(|e| e.fetching)
        else {
            return false;
        };
        edit.fetching = false;
        edit.base_areas = Some(areas.map(areas_checksum));
        self.plan_upload(now);
        true
    }

    /// Whether the download in progress fetches the base of an edit.
    pub(super) fn fetching_edit_base(&self) -> bool {
        self.upload
            .as_ref()
            .and_then(|j| j.edit.as_ref())
            .is_some_and(|e| e.fetching)
    }
}

/// The report as the FCC gives it after `job` ended with `report` (ICD §10.3), for the next
/// upload: the report this upload began with, the target's entry (the active lists, or the
/// staged mission) holding the lists uploaded. Only after an upload that completed toward
/// edition 2 with nothing left unknown (no staged copy left behind, no earlier copies deleted);
/// otherwise `None`, and the next upload asks. The geofence check of the entry is not known
/// ("not run"): the GCS plans with the counts, checksums and Mission IDs only.
fn report_after(job: &UploadJob, report: &UploadReport) -> Option<Vec<MissionReport>> {
    if !report.is_complete()
        || report.warning.is_some()
        || job.had_leftovers
        || job.before.is_none()
    {
        return None;
    }
    let target = match job.kind {
        Kind::Stage(id) => Target::Staged(id),
        _ => Target::Active,
    };
    let id = target.mission_id_field();
    let entry = MissionReport {
        time_stamp: Default::default(),
        report_index: 0,
        report_count: 0,
        mission_id: Some(id),
        waypoint_count: job.mission.waypoints.len() as u16,
        area_count: job.areas.areas.len() as u8,
        geofence_check: GeofenceCheck::NotRun,
        reason: None,
        mission_checksum: Some(job.checksums.0),
        area_checksum: Some(job.checksums.1),
    };
    let mut entries = job.entries.clone();
    let name = |e: &MissionReport| e.mission_id.unwrap_or_default();
    match entries.iter_mut().find(|e| name(e).as_str() == id.as_str()) {
        Some(held) => *held = entry,
        None => {
            // The active lists first, then the staged missions in ascending byte order (ICD §8).
            let at = entries.partition_point(|e| name(e).as_str() < id.as_str());
            entries.insert(at, entry);
        }
    }
    let count = u8::try_from(entries.len()).ok()?;
    for (index, e) in (1..).zip(entries.iter_mut()) {
        e.report_index = index;
        e.report_count = count;
    }
    Some(entries)
}

/// The messages a full upload of the job's lists by its kind would have sent: the report
/// request, the opener, the mission's messages and closer, the areas with their opener and
/// closer, and for an atomic upload toward edition 2 the activation and the delete.
fn full_upload_messages(job: &UploadJob, edition_2: bool) -> usize {
    let report = usize::from(edition_2 && job.asked_report);
    let atomic = match job.kind {
        Kind::Atomic if edition_2 => 2,
        _ => 0,
    };
    report + 1 + job.mission.message_count() + 1 + job.areas.areas.len() + 2 + atomic
}
