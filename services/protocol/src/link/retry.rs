//! Timeout and retry (paper §3.1.4; ICD §5): the one mechanism every sender uses. A message is
//! sent with "acknowledgement requested" and the sender waits for its answer. When none arrives
//! within the ack timeout, or the answer is a rejection, the message is sent once more with a new
//! time stamp; a second timeout or rejection fails the exchange with an error that names the
//! message and both causes. Worst case for one message: 2 x ack timeout.
//!
//! An [`Exchange`] keeps what identifies its message and its answers, not the message: a window
//! of 32 in flight (ICD §10) stays small. Its owner sends the message again when told to
//! ([`Outcome::Retry`], [`Exchange::resend`]).
//!
//! One rejection is final, not retried: an edition-1 FCC's `Unsupported` to the report request
//! (#13000 mode 7), which is how a GCS learns the FCC's edition (ICD §10.1).
//!
//! The answer is #17000 for most messages, #3012 for #2011 mode 2 (ICD §5.3) and #3013 for
//! #2011 mode 3 (ICD §5.4).

use core::fmt;
use core::time::Duration;

use missionlink_interfaces::wire::{
    AckType, AreaDownloadStatus, AreaListStatus, AreaTransferMode, Message, MessageType,
    MissionPlanMode, Reason, SpecificData, Timestamp,
};

use crate::link::endpoint::Endpoint;
use crate::link::time::Instant;
use crate::link::timer::TimerTable;

/// The kind of answer a message waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Expected {
    /// #17000 matching the message's type and time stamp.
    Acknowledgement,
    /// #3012, the answer to #2011 mode 2 upload complete (and mode 7, its staged twin, ICD §8).
    AreaStatusAlert,
    /// #3013, the answer to #2011 mode 3 initiate download (and mode 8, ICD §8, which an FCC
    /// without that staged mission refuses by #17000 type 3 instead).
    AreaTransmissionStatus,
}

impl Expected {
    /// What `message` waits for.
    pub fn of(message: &Message) -> Self {
        match message {
            Message::AreaTransmissionCommand(c)
                if matches!(
                    c.mode,
                    AreaTransferMode::UploadComplete | AreaTransferMode::UploadCompleteStaged
                ) =>
            {
                Self::AreaStatusAlert
            }
            Message::AreaTransmissionCommand(c)
                if matches!(
                    c.mode,
                    AreaTransferMode::InitiateDownload | AreaTransferMode::InitiateStagedDownload
                ) =>
            {
                Self::AreaTransmissionStatus
            }
            _ => Self::Acknowledgement,
        }
    }
}

/// Why one attempt failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttemptFailure {
    /// No answer within the ack timeout.
    Timeout,
    /// Rejected: #17000 type 3 or 4, #3012 status 0, with the reason given.
    Rejected(Reason),
    /// #3013 status 2: the peer aborted the download.
    Aborted,
}

impl fmt::Display for AttemptFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Timeout => write!(f, "no answer within the ack timeout"),
            Self::Rejected(reason) => {
                write!(f, "rejected with reason {reason}: {}", reason.meaning())
            }
            Self::Aborted => write!(f, "the peer aborted"),
        }
    }
}

/// The element a message carries, for error reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subject {
    /// A waypoint (#13002, #13006 RF centre).
    Waypoint(u16),
    /// An area (#2012).
    Area(u16),
}

impl Subject {
    fn of(message: &Message) -> Option<Self> {
        match message {
            Message::UaPositionWaypoint(w) => Some(Self::Waypoint(w.waypoint_number)),
            Message::VehicleSpecificWaypoint(v) => match v.data {
                SpecificData::RfCentre {
                    waypoint_number, ..
                } => Some(Self::Waypoint(waypoint_number)),
                SpecificData::TakeOffHeight { .. } => None,
            },
            Message::AreaPolygonLoopSegment(a) => Some(Self::Area(a.area_id)),
            _ => None,
        }
    }
}

/// An exchange that failed: which message, about what, and why each attempt failed (twice, or
/// once when the rejection is final).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExchangeError {
    /// The message that failed.
    pub message_type: MessageType,
    /// The waypoint or area it carried.
    pub subject: Option<Subject>,
    /// Why the first attempt failed.
    pub first: AttemptFailure,
    /// Why the retry failed; `None` when there was no retry: the rejection was final (ICD
    /// §10.1: an edition-1 FCC's `Unsupported` to the report request).
    pub second: Option<AttemptFailure>,
}

impl ExchangeError {
    /// Whether the cause may pass, so that the same request may succeed when made again: the
    /// peer did not answer (a lossy link, a restart), was busy with another transfer
    /// (`Busy`), or did not expect the message (`WrongState`: it lost the transfer, say in a
    /// restart). Any other rejection is about the content and comes again.
    pub fn may_pass(&self) -> bool {
        match self.second.unwrap_or(self.first) {
            AttemptFailure::Timeout => true,
            AttemptFailure::Rejected(reason) => matches!(reason, Reason::Busy | Reason::WrongState),
            AttemptFailure::Aborted => false,
        }
    }

    /// The reason of the last rejection, if the peer gave one.
    pub fn reason(&self) -> Option<Reason> {
        match (self.second, self.first) {
            (Some(AttemptFailure::Rejected(r)), _) | (_, AttemptFailure::Rejected(r)) => Some(r),
            _ => None,
        }
    }
}

// Written out, not derived with thiserror: the subject and the retry are printed only where
// there is one, which one format string cannot say without a helper as long as this.
impl fmt::Display for ExchangeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "#{} {}",
            self.message_type as u16,
            self.message_type.name()
        )?;
        match self.subject {
            Some(Subject::Waypoint(n)) => write!(f, " (waypoint {n})")?,
            Some(Subject::Area(n)) => write!(f, " (area {n})")?,
            None => {}
        }
        match self.second {
            Some(second) => write!(f, ": {}; retried: {second}", self.first),
            None => write!(f, ": {} (final, not retried)", self.first),
        }
    }
}

impl core::error::Error for ExchangeError {}

#[derive(Debug, Clone, Copy)]
struct Pending {
    message_type: MessageType,
    subject: Option<Subject>,
    /// The report request, whose `Unsupported` is final (ICD §10.1).
    report_request: bool,
    expected: Expected,
    /// Time stamps of the first attempt and, after a retry, of the second.
    stamps: [Option<Timestamp>; 2],
    first_failure: Option<AttemptFailure>,
}

/// What became of the outstanding message after an answer or a timeout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// The peer accepted it; the answer.
    Accepted(Message),
    /// The first attempt failed: the owner sends the message again ([`Exchange::resend`]).
    Retry(AttemptFailure),
    /// Both attempts failed.
    Failed(ExchangeError),
}

crate::timers! {
    /// The timer of an [`Exchange`].
    pub enum ExchangeTimer {
        /// The ack timeout of the attempt in flight (ICD §1: 500 ms).
        Ack,
    }
}

/// One message in flight and its timer.
#[derive(Debug, Clone, Copy)]
pub struct Exchange {
    ack_timeout: Duration,
    pending: Option<Pending>,
    /// Set while a message waits for its answer.
    timers: TimerTable<ExchangeTimer, 1>,
}

impl Exchange {
    /// An idle exchange whose messages wait `ack_timeout` for an answer.
    pub const fn new(ack_timeout: Duration) -> Self {
        Self {
            ack_timeout,
            pending: None,
            timers: TimerTable::new(),
        }
    }

    /// Whether no message waits for an answer.
    pub fn is_idle(&self) -> bool {
        self.pending.is_none()
    }

    /// Sends `message` through `endpoint` with "acknowledgement requested" and waits for its
    /// answer. A message still outstanding is given up.
    pub fn send(&mut self, endpoint: &mut Endpoint, now: Instant, message: Message) {
        let pending = Pending {
            message_type: message.message_type(),
            subject: Subject::of(&message),
            report_request: matches!(&message, Message::MissionTransferCommand(c) if c.mode == MissionPlanMode::ReportMissions),
            expected: Expected::of(&message),
            stamps: [Some(endpoint.send(now, message, true)), None],
            first_failure: None,
        };
        self.pending = Some(pending);
        self.timers.set(ExchangeTimer::Ack, now + self.ack_timeout);
    }

    /// Sends `message`, the one of this exchange, once more with a new time stamp (ICD §3):
    /// the retry after [`Outcome::Retry`].
    pub fn resend(&mut self, endpoint: &mut Endpoint, now: Instant, message: Message) {
        let Some(pending) = self.pending.as_mut() else {
            return;
        };
        pending.stamps[1] = Some(endpoint.send(now, message, true));
        self.timers.set(ExchangeTimer::Ack, now + self.ack_timeout);
        tracing::info!(
            message = pending.message_type as u16,
            failure = ?pending.first_failure,
            "resending once"
        );
    }

    /// Gives up the outstanding message without error (the transfer was cancelled).
    pub fn cancel(&mut self) {
        self.settle();
    }

    /// No message waits any more: nothing to time out.
    fn settle(&mut self) {
        self.pending = None;
        self.timers.stop(ExchangeTimer::Ack);
    }

    /// When [`Exchange::handle_timeout`] must be called.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.timers.next_timeout()
    }

    /// The ack timeout has passed at `now`: retry, or fail after the retry. `None` before the
    /// deadline.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<Outcome> {
        if !self.timers.is_expired(ExchangeTimer::Ack, now) {
            return None;
        }
        Some(self.fail_attempt(AttemptFailure::Timeout))
    }

    /// Offers `answer` to the exchange. `None` when it is not an answer to the outstanding
    /// message (the caller routes it elsewhere) or says nothing final (#17000 type 1).
    pub fn handle_answer(&mut self, answer: &Message) -> Option<Outcome> {
        let pending = self.pending.as_ref()?;
        let current = pending.stamps[1].or(pending.stamps[0]);
        let verdict = match (pending.expected, answer) {
            (Expected::Acknowledgement, Message::MessageAcknowledgement(ack))
                if ack.original_message_type == pending.message_type as u16 =>
            {
                let of_current = Some(ack.original_time_stamp) == current;
                let of_any = pending.stamps.contains(&Some(ack.original_time_stamp));
                match ack.ack_type {
                    // An acceptance of either attempt is an acceptance: the receiver handles
                    // a retried message the same way as the first.
                    AckType::Completed | AckType::Received if of_any => Ok(()),
                    // A late rejection of the first attempt says nothing about the retry.
                    AckType::Rejected | AckType::ReceiveFailed if of_current => Err(
                        AttemptFailure::Rejected(ack.reject_reason.unwrap_or(Reason::Malformed)),
                    ),
                    _ => return None,
                }
            }
            (Expected::AreaStatusAlert, Message::AreaStatusAlert(alert)) => match alert.status {
                AreaListStatus::Valid => Ok(()),
                AreaListStatus::Invalid => Err(AttemptFailure::Rejected(
                    alert.reason.unwrap_or(Reason::Malformed),
                )),
            },
            // ICD §8: a staged mission's area download request is refused by #17000 type 3
            // (`WrongState`) when there is no such list, not by #3013.
            (Expected::AreaTransmissionStatus, Message::MessageAcknowledgement(ack))
                if ack.original_message_type == pending.message_type as u16
                    && matches!(ack.ack_type, AckType::Rejected | AckType::ReceiveFailed)
                    && Some(ack.original_time_stamp) == current =>
            {
                Err(AttemptFailure::Rejected(
                    ack.reject_reason.unwrap_or(Reason::Malformed),
                ))
            }
            (Expected::AreaTransmissionStatus, Message::AreaTransmissionStatus(status)) => {
                match status.status {
                    AreaDownloadStatus::Ready => Ok(()),
                    AreaDownloadStatus::Aborted => Err(AttemptFailure::Aborted),
                }
            }
            _ => return None,
        };
        Some(match verdict {
            Ok(()) => {
                self.settle();
                Outcome::Accepted(answer.clone())
            }
            Err(failure) => self.fail_attempt(failure),
        })
    }

    fn fail_attempt(&mut self, failure: AttemptFailure) -> Outcome {
        let Some(pending) = self.pending.as_mut() else {
            self.timers.stop(ExchangeTimer::Ack);
            return Outcome::Retry(failure);
        };
        // ICD §10.1: an edition-1 FCC's refusal of the report request says which edition it
        // speaks; a retry would only be refused again.
        let is_final =
            failure == AttemptFailure::Rejected(Reason::Unsupported) && pending.report_request;
        match pending.first_failure {
            None if is_final => {
                let error = ExchangeError {
                    message_type: pending.message_type,
                    subject: None,
                    first: failure,
                    second: None,
                };
                self.settle();
                Outcome::Failed(error)
            }
            None => {
                // The owner resends (a new time stamp, ICD §3); until then no timer runs.
                pending.first_failure = Some(failure);
                self.timers.stop(ExchangeTimer::Ack);
                Outcome::Retry(failure)
            }
            Some(first) => {
                let error = ExchangeError {
                    message_type: pending.message_type,
                    subject: pending.subject,
                    first,
                    second: Some(failure),
                };
                self.settle();
                tracing::warn!(%error, "exchange failed");
                Outcome::Failed(error)
            }
        }
    }
}
