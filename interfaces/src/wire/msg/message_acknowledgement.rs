//! #17000 Message Acknowledgement (ICD §4, std structure, field 4 icd): the answer to every
//! message sent with "acknowledgement requested" (ICD §5).

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::AckType;
use crate::wire::error::{EncodeError, MessageError, Reason};
use crate::wire::field::Timestamp;
use crate::wire::presence::Writer;

/// #17000. Matches its original by (peer ID, Original Message Type, Original Time Stamp).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MessageAcknowledgement {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: time stamp of the message acknowledged.
    pub original_time_stamp: Timestamp,
    /// Bit 2, M: type of the message acknowledged (any U2, so that a message of an unknown type
    /// can be answered too).
    pub original_message_type: u16,
    /// Bit 3, M.
    pub ack_type: AckType,
    /// Bit 4: why a message was rejected; `None` (0) when accepted.
    pub reject_reason: Option<Reason>,
}

impl MessageBody for MessageAcknowledgement {
    const TYPE: MessageType = MessageType::MessageAcknowledgement;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Original Message Time Stamp",
        "Original Message Type",
        "Acknowledgement Type",
        "Reject Reason",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let m = Self {
            time_stamp: r.time_stamp()?,
            original_time_stamp: r.mandatory(1)?,
            original_message_type: r.mandatory(2)?,
            ack_type: r.mandatory(3)?,
            reject_reason: r.optional(4)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.original_time_stamp)?;
        w.field(2, &self.original_message_type)?;
        w.field(3, &self.ack_type)?;
        w.optional(4, self.reject_reason.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
