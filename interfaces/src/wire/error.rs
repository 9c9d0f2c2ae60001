//! Errors of the wire layer.
//!
//! Two levels, as ICD §2 and §3 separate them:
//! - [`FrameError`]: the wrapper is broken or not for us. The frame is rejected, never processed,
//!   never acknowledged (ICD §2).
//! - [`MessageError`]: the wrapper is sound but the message data breaks a rule of §3 or §4. The
//!   receiver answers with #17000 type 3 and the [`Reason`] of [`Cause::reason`]; the error names
//!   the message, the field and the rule, and carries the time stamp the rejection refers to.

use core::fmt;

use super::field::Timestamp;

wire_enum! {
    /// Reject reasons of ICD §6, carried in #17000 field 4, #14000 field 6 and #3012 field 3.
    pub enum Reason {
        /// Accepted.
        None = 0 => "none",
        /// Fields out of range or inconsistent.
        Malformed = 1 => "malformed",
        /// A mandatory field is absent.
        MissingField = 2 => "missing field",
        /// A presence-vector bit beyond the defined fields.
        UnknownField = 3 => "unknown field",
        /// A value this system does not implement (relative location, unknown mode).
        Unsupported = 4 => "unsupported",
        /// More waypoints, areas or vertices than the FCC holds.
        Capacity = 5 => "capacity",
        /// Message not expected now (e.g. #13002 during a download).
        WrongState = 6 => "wrong state",
        /// Clear refused while trajectory generation is active.
        GuidanceActive = 7 => "guidance active",
        /// Assembled count differs from the announced count.
        CountMismatch = 8 => "count mismatch",
        /// Next Waypoint refers to a missing waypoint, or the plan loops.
        BrokenChain = 9 => "broken chain",
        /// The initial waypoint is not in the list.
        MissingInitial = 10 => "missing initial",
        /// An RF waypoint has no #13006 centre.
        MissingRfCentre = 11 => "missing RF centre",
        /// Polygon with fewer than 3 vertices, circle without 2 points or zero radius, no or
        /// several fly-zones.
        BadGeometry = 12 => "bad geometry",
        /// Another transfer is in progress.
        Busy = 13 => "busy",
        /// (ext) The onboard geofence check of ICD §7 failed: a leg, the climb at the take-off
        /// or the route to the initial waypoint leaves the fly-zone or enters a no-fly-zone.
        GeofenceViolation = 14 => "geofence violation",
        /// (ext, ICD §11) The list the receiver assembled is not the one the sender's checksum
        /// describes.
        IntegrityMismatch = 15 => "integrity mismatch",
    }
}

impl Reason {
    /// What the reason means, as ICD §6 says it: for an operator reading a refusal.
    pub fn meaning(self) -> &'static str {
        match self {
            Self::None => "accepted",
            Self::Malformed => "fields out of range or inconsistent",
            Self::MissingField => "a mandatory field is absent",
            Self::UnknownField => "a presence-vector bit beyond the defined fields",
            Self::Unsupported => "a value this system does not implement",
            Self::Capacity => "more waypoints, areas or vertices than the FCC holds",
            Self::WrongState => "message not expected now",
            Self::GuidanceActive => "clear refused while trajectory generation is active",
            Self::CountMismatch => "assembled count differs from the announced count",
            Self::BrokenChain => "Next Waypoint refers to a missing waypoint, or the plan loops",
            Self::MissingInitial => "the initial waypoint is not in the list",
            Self::MissingRfCentre => "an RF waypoint has no #13006 centre",
            Self::BadGeometry => {
                "a polygon that is not simple or has fewer than 3 vertices, a circle of zero radius, no or several fly-zones"
            }
            Self::Busy => "another transfer is in progress",
            Self::GeofenceViolation => {
                "the onboard geofence check failed: from where the aircraft is, the climb, the way to the route or a leg would leave the fly-zone or enter a no-fly-zone (ICD §7)"
            }
            Self::IntegrityMismatch => {
                "the list the FCC assembled is not the one the sender's checksum describes (ICD §11): nothing was activated"
            }
        }
    }
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self:?} ({})", *self as u8)
    }
}

/// Why a frame is rejected at the wrapper (ICD §2). Rejected frames are never processed and
/// never acknowledged; the receiver counts and logs them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    /// Fewer bytes than the 16-byte wrapper header.
    TooShort {
        /// Bytes available.
        len: usize,
    },
    /// Message Length is 0 or above 528.
    LengthOutOfRange {
        /// Message Length as received.
        length: u16,
    },
    /// Header, Message Length and checksum do not add up to the bytes of the datagram.
    LengthMismatch {
        /// Bytes the wrapper says the message takes.
        expected: usize,
        /// Bytes the datagram has for it.
        actual: usize,
    },
    /// Checksum length code 11 in Message Properties.
    InvalidChecksumLength,
    /// The byte-sum checksum does not match.
    ChecksumMismatch {
        /// Checksum computed over header and data.
        computed: u32,
        /// Checksum received.
        received: u32,
    },
    /// IDD version outside 30..=40 (this choice: a frame of another IDD version is not ours to
    /// interpret, so it is rejected at the wrapper like a foreign frame).
    UnsupportedVersion {
        /// Version received.
        version: u8,
    },
    /// Destination is neither this node nor broadcast.
    WrongDestination {
        /// Destination ID received.
        destination: u32,
    },
    /// Source is not the configured peer.
    UnknownSource {
        /// Source ID received.
        source: u32,
    },
}

// Written out, not derived with thiserror: it takes a field named `source` (the Source ID of
// `UnknownSource`) for the error's cause, and a u32 is no error.
impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooShort { len } => {
                write!(
                    f,
                    "frame of {len} bytes is shorter than the 16-byte wrapper"
                )
            }
            Self::LengthOutOfRange { length } => {
                write!(f, "Message Length {length} is outside 1..=528")
            }
            Self::LengthMismatch { expected, actual } => write!(
                f,
                "wrapper says the message takes {expected} bytes, the datagram has {actual}"
            ),
            Self::InvalidChecksumLength => write!(f, "checksum length code 11 is invalid"),
            Self::ChecksumMismatch { computed, received } => {
                write!(f, "checksum {received:#x} received, {computed:#x} computed")
            }
            Self::UnsupportedVersion { version } => {
                write!(f, "IDD version {version} is outside 30..=40")
            }
            Self::WrongDestination { destination } => {
                write!(
                    f,
                    "destination {destination:#010x} is neither this node nor broadcast"
                )
            }
            Self::UnknownSource { source } => {
                write!(f, "source {source:#010x} is not the configured peer")
            }
        }
    }
}

impl core::error::Error for FrameError {}

/// The rule of ICD §3 or §4 a message breaks. Each maps onto one [`Reason`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cause {
    /// A field marked M (or mandatory for this mode or type) is absent. `MissingField`.
    MissingField,
    /// A presence-vector bit beyond the last defined field is set. `UnknownField`.
    UnknownField {
        /// The bit.
        bit: u8,
    },
    /// The message data is shorter than the presence vector. `Malformed`.
    ShortPresenceVector,
    /// The message data ends inside a present field. `Malformed`.
    Truncated,
    /// Bytes follow the last present field. `Malformed`.
    TrailingBytes {
        /// How many.
        count: usize,
    },
    /// A value outside the range of its field. `Malformed`.
    OutOfRange {
        /// The value received.
        value: i64,
    },
    /// CharN text without NUL terminator, with non-NUL padding, or not UTF-8. `Malformed`.
    BadText,
    /// Fields that contradict each other. `Malformed`.
    Inconsistent,
    /// An enumeration value the ICD does not define or this system does not implement (relative
    /// location, unknown mode). `Unsupported`.
    Unsupported {
        /// The value received.
        value: u32,
    },
    /// A message type this ICD does not define. `Unsupported`.
    UnknownMessageType,
    /// More vertices than the system holds. `Capacity`.
    Capacity {
        /// Count received.
        count: usize,
        /// Most the system holds.
        max: usize,
    },
    /// A vertex count that does not make the shape (polygon under 3, circle not 2). `BadGeometry`.
    BadGeometry {
        /// Count received.
        count: usize,
    },
}

impl Cause {
    /// The reject reason of ICD §6 the receiver acknowledges this with.
    pub const fn reason(&self) -> Reason {
        match self {
            Self::MissingField => Reason::MissingField,
            Self::UnknownField { .. } => Reason::UnknownField,
            Self::ShortPresenceVector
            | Self::Truncated
            | Self::TrailingBytes { .. }
            | Self::OutOfRange { .. }
            | Self::BadText
            | Self::Inconsistent => Reason::Malformed,
            Self::Unsupported { .. } | Self::UnknownMessageType => Reason::Unsupported,
            Self::Capacity { .. } => Reason::Capacity,
            Self::BadGeometry { .. } => Reason::BadGeometry,
        }
    }
}

impl fmt::Display for Cause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingField => write!(f, "mandatory field is absent"),
            Self::UnknownField { bit } => {
                write!(f, "presence vector bit {bit} is beyond the defined fields")
            }
            Self::ShortPresenceVector => {
                write!(f, "message data is shorter than the presence vector")
            }
            Self::Truncated => write!(f, "message data ends inside the field"),
            Self::TrailingBytes { count } => {
                write!(f, "{count} bytes follow the last present field")
            }
            Self::OutOfRange { value } => write!(f, "value {value} is out of range"),
            Self::BadText => write!(
                f,
                "text is not NUL terminated, not NUL padded, or not UTF-8"
            ),
            Self::Inconsistent => write!(f, "field contradicts another field"),
            Self::Unsupported { value } => write!(f, "value {value} is not supported"),
            Self::UnknownMessageType => write!(f, "message type is not in the ICD"),
            Self::Capacity { count, max } => write!(f, "{count} exceeds the capacity of {max}"),
            Self::BadGeometry { count } => {
                write!(f, "vertex count {count} does not make the shape")
            }
        }
    }
}

/// A field of a message, for error reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldRef {
    /// Presence-vector bit of the field.
    pub bit: u8,
    /// Field name as in the ICD table.
    pub name: &'static str,
}

/// A message that breaks a rule of ICD §3 or §4: which message, which field, which rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MessageError {
    /// Message Type of the wrapper.
    pub message_type: u16,
    /// The field concerned, where there is one (not for a trailing byte or an unknown type).
    pub field: Option<FieldRef>,
    /// The rule broken.
    pub cause: Cause,
    /// The message's own time stamp when it could be read, so the rejection can be
    /// acknowledged (#17000 Original Message Time Stamp).
    pub time_stamp: Option<Timestamp>,
}

impl MessageError {
    /// The reject reason of ICD §6.
    pub const fn reason(&self) -> Reason {
        self.cause.reason()
    }
}

// Written out, not derived with thiserror: the message name and the field are printed only where
// known, which one format string cannot say without a helper as long as this.
impl fmt::Display for MessageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match super::msg::MessageType::try_from(self.message_type) {
            Ok(t) => write!(f, "#{} {}", self.message_type, t.name())?,
            Err(_) => write!(f, "#{}", self.message_type)?,
        }
        if let Some(field) = self.field {
            write!(f, ", {} (PV bit {})", field.name, field.bit)?;
        }
        write!(f, ": {} [reason {}]", self.cause, self.reason())
    }
}

impl core::error::Error for MessageError {}

/// Why bytes did not decode into a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    /// The wrapper is rejected (ICD §2): drop, count, log, never acknowledge.
    #[error("frame rejected: {0}")]
    Frame(#[from] FrameError),
    /// The message is rejected (ICD §3, §4): acknowledge with type 3 and the reason.
    #[error("message rejected: {0}")]
    Message(#[from] MessageError),
}

impl DecodeError {
    /// The reason to acknowledge with, or `None` for a frame that is never acknowledged.
    pub const fn reason(&self) -> Option<Reason> {
        match self {
            Self::Frame(_) => None,
            Self::Message(m) => Some(m.reason()),
        }
    }
}

/// Why a message could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum EncodeError {
    /// The output buffer is too small.
    #[error("buffer of {available} bytes, at least {needed} needed")]
    BufferTooSmall {
        /// Bytes the frame needs at least.
        needed: usize,
        /// Bytes available.
        available: usize,
    },
    /// The message data would exceed 528 bytes.
    #[error("message data exceeds 528 bytes")]
    TooLong,
}
