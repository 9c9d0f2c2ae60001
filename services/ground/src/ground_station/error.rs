//! Why a request of the GCS logic failed ([`GcsError`]), with the hints the operator reads.

use super::*;

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
    /// The upload did not complete: what the FCC holds now, list by list (ICD §11).
    Upload(Box<UploadReport>),
    /// What the FCC sent does not assemble into a valid list.
    InvalidDownload {
        /// Where.
        phase: Phase,
        /// Why.
        reason: Reason,
    },
    /// The FCC holds as many staged missions as it can (ICD §8: 8) and the request needs one
    /// more; nothing was staged and the active lists are untouched.
    Capacity {
        /// Staged missions the report listed.
        staged: usize,
    },
    /// The FCC speaks edition 1 (it refused the report request, ICD §10.1): it holds no staged
    /// missions. Nothing was sent but the report request.
    Edition1 {
        /// What needed edition 2.
        request: &'static str,
    },
    /// [`GroundStation::execute`] was asked for #50000 command 4, which must name the staged
    /// mission (ICD §8): [`GroundStation::activate`] sends it. Nothing was sent.
    ActivateWithoutId,
    /// A download of the active lists found no mission: the FCC refused the mission download
    /// request with `WrongState`, its answer when it holds none (ICD §5.2), after a clear say.
    NoMission,
    /// A request about a staged mission failed (activate, delete, download).
    Staged {
        /// Which request.
        request: StagedRequest,
        /// The staged mission.
        id: MissionId,
        /// Which message and why.
        error: ExchangeError,
    },
}

/// A request about one staged mission (ICD §8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StagedRequest {
    /// #50000 command 4.
    Activate,
    /// #13000 mode 6.
    Delete,
    /// #13000 mode 9, #2011 mode 8.
    Download,
}

impl fmt::Display for StagedRequest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Activate => "activation",
            Self::Delete => "delete",
            Self::Download => "download",
        })
    }
}

/// What a reason of ICD §6 means for a request about staged missions (ICD §8), in words for the
/// operator; `None` where the reason's own meaning says it.
pub fn reason_hint(reason: Reason) -> Option<&'static str> {
    match reason {
        Reason::Capacity => Some("the FCC holds 8 staged missions: delete one"),
        Reason::WrongState => Some(
            "no such staged mission, or it lacks a list (activation needs both), or the \
             aircraft is airborne, or another transfer is open",
        ),
        Reason::GeofenceViolation => {
            Some("the onboard geofence check of the mission against its areas failed")
        }
        Reason::Unsupported | Reason::UnknownField => {
            Some("the FCC speaks ICD edition 1: it holds no staged missions")
        }
        Reason::IntegrityMismatch => {
            Some("the FCC assembled another list than the one sent (ICD §11)")
        }
        _ => None,
    }
}

impl<R> GcsError<R> {
    /// Whether the request failed in the FCC's report (ICD §8, §10.1): unanswered, silent or
    /// aborted. Before an upload that means it never began: nothing that changes a list was
    /// sent.
    pub fn in_report(&self) -> bool {
        matches!(
            self,
            Self::Transfer {
                phase: Phase::Report,
                ..
            } | Self::Timeout {
                phase: Phase::Report
            } | Self::Aborted {
                phase: Phase::Report,
                ..
            }
        )
    }
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
            Self::Upload(report) => write!(f, "{report}"),
            Self::InvalidDownload { phase, reason } => {
                write!(f, "{phase}: what the FCC sent is invalid: {reason}")
            }
            Self::Capacity { staged } => write!(
                f,
                "the FCC holds {staged} staged missions, the most it can (ICD §8): delete one \
                 first; nothing was staged and the active lists are unchanged"
            ),
            Self::Edition1 { request } => write!(
                f,
                "the FCC speaks ICD edition 1 (it refused the report request): {request} needs \
                 edition 2; nothing was sent but the report request"
            ),
            Self::NoMission => write!(
                f,
                "the FCC holds no mission: it refused the mission download with WrongState, its \
                 answer when no mission is active (ICD §5.2)"
            ),
            Self::ActivateWithoutId => write!(
                f,
                "#50000 command 4 activates a staged mission and must name it (ICD §8): \
                 nothing was sent"
            ),
            Self::Staged { request, id, error } => {
                write!(f, "{request} of staged mission {id:?} failed: {error}")?;
                if let Some(hint) = error.reason().and_then(reason_hint) {
                    write!(f, " ({hint})")?;
                }
                Ok(())
            }
        }
    }
}

impl<R: fmt::Debug + fmt::Display> std::error::Error for GcsError<R> {}
