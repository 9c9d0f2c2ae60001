//! What an upload ended with (ICD §11, "The truth after a failure"). When a transfer fails
//! after its closer may have reached the FCC, the answers alone cannot say what the FCC holds:
//! the closer may have been carried out and its answer lost. The GCS then asks the FCC (the §8
//! report toward edition 2, a download toward edition 1) and compares the checksums of what is
//! active with the checksums of what it uploaded and of what was active before.

use core::fmt;

use missionlink_interfaces::wire::Checksum;

use crate::ground_station::Phase;
use crate::ground_station::edit::FullUpload;
use missionlink_protocol::link::retry::ExchangeError;
use missionlink_protocol::transfer::staged::MissionId;

/// What the FCC holds of one list, compared with the upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Held {
    /// The list uploaded: its checksum is the one the GCS computed.
    New,
    /// The list active before the upload (its checksum is the one the FCC reported before the
    /// upload began), or still none when there was none.
    Previous,
    /// Not the list uploaded; the GCS does not know what was active before (an edition-1 FCC
    /// gives no report): by ICD §7 the FCC still holds the list it held before.
    NotNew,
    /// Neither the list uploaded nor the one active before.
    Foreign,
    /// None: the upload began with the clear of the paper's sequence (ICD §5.1 step 1), which
    /// deletes the active waypoint list, and failed before its closer activated the new one.
    Cleared,
    /// The GCS could not find out: the FCC did not answer its question.
    Unknown,
}

/// One list after an upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ListOutcome {
    /// Compared with the upload.
    pub held: Held,
    /// The checksum of what the FCC holds (ICD §11); `None` when it holds no list, or when it
    /// is unknown.
    pub checksum: Option<Checksum>,
    /// The list uploaded is the one held before (an edit that left it alone): new and previous
    /// at once, so it alone never makes an upload half done.
    pub unchanged: bool,
}

impl ListOutcome {
    /// The list the FCC holds, found to have `held` against the upload and `before`.
    pub fn compare(held: Option<Checksum>, uploaded: Checksum, before: Option<Before>) -> Self {
        let verdict = if held == Some(uploaded) {
            Held::New
        } else {
            match before {
                Some(Before(b)) if b == held => Held::Previous,
                Some(_) => Held::Foreign,
                None => Held::NotNew,
            }
        };
        Self {
            held: verdict,
            checksum: held,
            unchanged: verdict == Held::New && before == Some(Before(Some(uploaded))),
        }
    }

    /// Known to be the list uploaded (the FCC answered its closer with success).
    pub fn new(uploaded: Checksum) -> Self {
        Self {
            held: Held::New,
            checksum: Some(uploaded),
            unchanged: false,
        }
    }

    /// Unknown (the FCC did not answer the question).
    pub const UNKNOWN: Self = Self {
        held: Held::Unknown,
        checksum: None,
        unchanged: false,
    };

    /// The list held before: `checksum` (by construction, not asked).
    pub const fn previous(checksum: Option<Checksum>) -> Self {
        Self {
            held: Held::Previous,
            checksum,
            unchanged: false,
        }
    }

    fn is_new(&self) -> bool {
        self.held == Held::New
    }
}

/// The checksum of a list active before an upload (`None` inside: there was none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Before(pub Option<Checksum>);

/// How the GCS knows what the FCC holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Confirmation {
    /// The FCC answered both closers with success.
    Answers,
    /// The FCC's report of its active lists (ICD §8, #50001) after the failure.
    Report,
    /// A download of the active lists (an edition-1 FCC) after the failure.
    Download,
    /// Neither: the FCC did not answer the question.
    None,
    /// By construction: an atomic upload failed before it sent the activation (#50000 command
    /// 4), the only message that changes the active lists, and the FCC did not answer the
    /// question.
    NotActivated,
}

/// How the upload changed the FCC's lists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UploadKind {
    /// Staged and activated in one step (ICD §8), or an edit of the waypoint list alone.
    Atomic,
    /// The paper's sequence: the waypoint list became active before the area list, one after
    /// the other; `edition_1`: because the FCC speaks only edition 1 (else it was asked for).
    Paper {
        /// The FCC speaks edition 1.
        edition_1: bool,
    },
    /// Into a staged mission (ICD §8): the lists compared are that mission's, the active lists
    /// are untouched.
    Staged(MissionId),
}

/// Messages the GCS sent for the upload (first attempts, the report request included) and what
/// a full upload of the same lists would have sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Messages {
    /// Sent.
    pub sent: usize,
    /// A full upload's.
    pub full: usize,
}

/// What went wrong beside the upload itself (the upload's outcome stands).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Warning {
    /// The temporary staged copy of an atomic upload may still be on the FCC: its delete failed
    /// (with the error), or the FCC did not say whether it holds it.
    StagedCopyLeft {
        /// Its Mission ID.
        id: MissionId,
        /// The failure of #13000 mode 6, if it was sent.
        error: Option<ExchangeError>,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::StagedCopyLeft { id, error } => {
                write!(
                    f,
                    "the temporary staged mission {id:?} may be left on the FCC"
                )?;
                if let Some(e) = error {
                    write!(f, " (its delete failed: {e})")?;
                }
                write!(f, "; delete it with `gcs delete {id}`")
            }
        }
    }
}

/// The outcome of an upload in one word, each with its exit status of `gcs upload`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UploadOutcome {
    /// Both lists are active; every answer arrived (exit status 0).
    Complete,
    /// Both lists are active, although an answer was lost and the transfer reported a failure
    /// (exit status 0).
    CompleteAfterLostAnswer,
    /// Both lists are active, and were before the step the FCC refused (a refusal changes
    /// nothing, ICD §5): the upload of the lists already active, in flight say, where the FCC
    /// refuses the activation (`WrongState`). Nothing to do (exit status 0).
    AlreadyActive,
    /// Neither list changed: the FCC holds the lists it held before (exit status 3).
    PreviousActive,
    /// One list is the new one, the other is not (exit status 4).
    Mixed,
    /// What the FCC holds is unknown: it did not answer (exit status 5).
    Unknown,
    /// The FCC holds no mission: the paper's sequence cleared it, then failed (exit status 7).
    /// Only an upload by the paper's sequence ends so; the atomic upload never does (ICD §8).
    NoMission,
    /// The FCC holds a list that is neither the new one nor the one before (exit status 6).
    Foreign,
}

/// What an upload ended with.
#[derive(Debug, Clone, PartialEq)]
pub struct UploadReport {
    /// The waypoint list (with take-off height and route).
    pub mission: ListOutcome,
    /// The area list.
    pub areas: ListOutcome,
    /// The checksums of what was uploaded (ICD §11).
    pub uploaded: (Checksum, Checksum),
    /// Why the transfer failed, if it did: where, which message and why.
    pub failure: Option<(Phase, ExchangeError)>,
    /// How the GCS knows.
    pub confirmation: Confirmation,
    /// How the lists changed.
    pub kind: UploadKind,
    /// Messages sent, and a full upload's.
    pub messages: Messages,
    /// For an edit: `None` inside when only the difference was sent, else why it was a full
    /// upload. `None`: not an edit.
    pub edit: Option<Option<FullUpload>>,
    /// What went wrong beside the upload.
    pub warning: Option<Warning>,
    /// Attempts made (more than 1: the ones before failed with the lists as they were).
    pub attempts: u8,
}

impl UploadReport {
    /// The outcome in one word.
    pub fn outcome(&self) -> UploadOutcome {
        let lists = [self.mission.held, self.areas.held];
        if lists.contains(&Held::Unknown) {
            UploadOutcome::Unknown
        } else if lists.contains(&Held::Foreign) {
            UploadOutcome::Foreign
        } else if self.mission.held == Held::Cleared {
            UploadOutcome::NoMission
        } else if self.mission.is_new() && self.areas.is_new() {
            match &self.failure {
                None => UploadOutcome::Complete,
                // A refused step changed nothing: the lists were active before it.
                Some((_, e)) if e.reason().is_some() => UploadOutcome::AlreadyActive,
                Some(_) => UploadOutcome::CompleteAfterLostAnswer,
            }
        } else if [self.mission, self.areas]
            .iter()
            .any(|l| l.is_new() && !l.unchanged)
        {
            UploadOutcome::Mixed
        } else {
            UploadOutcome::PreviousActive
        }
    }

    /// What the reason of the failure means where it is about staged missions (ICD §8): the
    /// activation's refusal, a staging closer's `Capacity`, and `IntegrityMismatch` anywhere.
    fn hint(&self) -> Option<&'static str> {
        use missionlink_interfaces::wire::{MessageType, Reason};
        let (phase, e) = self.failure.as_ref()?;
        let reason = e.reason()?;
        let staging_closer = !matches!(self.kind, UploadKind::Paper { .. })
            && matches!(
                e.message_type,
                MessageType::MissionTransferCommand | MessageType::AreaTransmissionCommand
            );
        let about_staging = *phase == Phase::Activation
            || (staging_closer && reason == Reason::Capacity)
            || reason == Reason::IntegrityMismatch;
        about_staging.then(|| super::reason_hint(reason)).flatten()
    }

    /// Whether both lists uploaded are active.
    pub fn is_complete(&self) -> bool {
        matches!(
            self.outcome(),
            UploadOutcome::Complete
                | UploadOutcome::CompleteAfterLostAnswer
                | UploadOutcome::AlreadyActive
        )
    }
}

fn checksum(f: &mut fmt::Formatter<'_>, c: Option<Checksum>) -> fmt::Result {
    match c {
        Some(c) => write!(f, "{c}"),
        None => f.write_str("none"),
    }
}

fn list(f: &mut fmt::Formatter<'_>, name: &str, list: &ListOutcome) -> fmt::Result {
    let what = match list.held {
        Held::New => "new",
        Held::Previous => "previous",
        Held::NotNew => "not the uploaded one",
        Held::Foreign => "neither the uploaded one nor the previous one",
        Held::Cleared => "cleared",
        Held::Unknown => return write!(f, "{name} unknown"),
    };
    write!(f, "{name} {what} (")?;
    checksum(f, list.checksum)?;
    f.write_str(")")
}

/// One line for the operator: `upload complete (confirmed after a lost answer: ...): mission
/// 0x1A2B3C4D, areas 0x5E6F7A8B active`, `nothing to do: the uploaded lists were active already
/// (...)`, `upload failed (...): the previous mission and areas are active: ...`, `upload failed
/// (...): the FCC holds no mission (...)`.
impl fmt::Display for UploadReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let outcome = self.outcome();
        let request = match self.kind {
            UploadKind::Staged(_) => "stage",
            _ => "upload",
        };
        match (outcome, &self.failure) {
            (UploadOutcome::Complete, _) => write!(f, "{request} complete")?,
            (UploadOutcome::CompleteAfterLostAnswer, Some((phase, e))) => {
                write!(
                    f,
                    "{request} complete (confirmed after a lost answer: {phase}: {e})"
                )?;
            }
            (UploadOutcome::AlreadyActive, Some((phase, e))) => {
                write!(
                    f,
                    "nothing to do: the uploaded lists were active already (the FCC refused the \
                     {phase}, which changed nothing: {e})"
                )?;
            }
            (_, Some((phase, e))) => {
                write!(f, "{request} failed ({phase}: {e}")?;
                if let Some(hint) = self.hint() {
                    write!(f, "; {hint}")?;
                }
                f.write_str(")")?;
            }
            (_, None) => write!(f, "{request} ended")?,
        }
        let (m, a) = (&self.mission, &self.areas);
        match outcome {
            UploadOutcome::Complete
            | UploadOutcome::CompleteAfterLostAnswer
            | UploadOutcome::AlreadyActive => {
                f.write_str(": mission ")?;
                checksum(f, m.checksum)?;
                f.write_str(" and areas ")?;
                checksum(f, a.checksum)?;
                match self.kind {
                    UploadKind::Staged(id) => write!(f, " staged as {id:?} on the FCC"),
                    _ => f.write_str(" active on the FCC"),
                }
            }
            UploadOutcome::PreviousActive => {
                match self.kind {
                    UploadKind::Staged(id) => {
                        write!(f, ": staged mission {id:?} is as it was: mission ")?
                    }
                    _ => f.write_str(
                        ": the previous mission and areas are active, unchanged: mission ",
                    )?,
                }
                checksum(f, m.checksum)?;
                f.write_str(", areas ")?;
                checksum(f, a.checksum)
            }
            UploadOutcome::Mixed => {
                f.write_str(": only one list changed: ")?;
                list(f, "mission", m)?;
                f.write_str(", ")?;
                list(f, "areas", a)
            }
            UploadOutcome::Unknown => {
                f.write_str(": what the FCC holds is unknown (it did not answer): ")?;
                list(f, "mission", m)?;
                f.write_str(", ")?;
                list(f, "areas", a)
            }
            UploadOutcome::NoMission => {
                f.write_str(
                    ": the FCC holds no mission (the paper's sequence cleared it before the \
                     upload failed): ",
                )?;
                list(f, "areas", a)
            }
            UploadOutcome::Foreign => {
                f.write_str(": the FCC holds lists it was not sent: ")?;
                list(f, "mission", m)?;
                f.write_str(", ")?;
                list(f, "areas", a)
            }
        }?;
        if self.confirmation != Confirmation::Answers {
            write!(
                f,
                " (uploaded: mission {}, areas {}; {})",
                self.uploaded.0,
                self.uploaded.1,
                match self.confirmation {
                    Confirmation::Report => "as the FCC reports",
                    Confirmation::Download => "as downloaded from the FCC",
                    Confirmation::NotActivated => {
                        "the FCC did not answer, but the activation was never sent"
                    }
                    Confirmation::Answers | Confirmation::None => "the FCC did not answer",
                }
            )?;
        }
        match self.kind {
            UploadKind::Atomic => {}
            UploadKind::Paper { edition_1: true } => f.write_str(
                " [edition-1 FCC: the paper's sequence, the waypoint list and the area list \
                 changed one after the other]",
            )?,
            UploadKind::Paper { edition_1: false } => f.write_str(
                " [the paper's sequence, as asked: the waypoint list and the area list changed \
                 one after the other]",
            )?,
            UploadKind::Staged(_) => f.write_str(" [the active lists are untouched]")?,
        }
        if let Some(edit) = self.edit {
            match edit {
                None => f.write_str("; edit: only what changed was sent")?,
                Some(why) => write!(f, "; edit sent as a full upload: {why}")?,
            }
        }
        if let Some(w) = self.warning {
            write!(f, "; warning: {w}")?;
        }
        if self.attempts > 1 {
            write!(f, "; attempt {}", self.attempts)?;
        }
        Ok(())
    }
}
