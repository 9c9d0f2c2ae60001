//! #17000 Message Acknowledgement (ICD §4, std structure, field 4 icd): the answer to every
//! message sent with "acknowledgement requested" (ICD §5).

use core::fmt;

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

/// `#17000 Message Acknowledgement: type 3 rejected (BrokenChain (9)), of #13000`.
impl fmt::Display for MessageAcknowledgement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: type {}", Self::TYPE, self.ack_type.numbered())?;
        super::reason(f, self.reject_reason)?;
        write!(f, ", of #{}", self.original_message_type)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #17000: the FCC rejects the #13000 of 12:01:00.600Z (BrokenChain); FCC to GCS, no ack.
    #[rustfmt::skip]
    static FRAME: [u8; 35] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0f,                   // message length: 15 bytes of message data
        0x0b, 0x00, 0x00, 0x01,       // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,       // destination ID: GCS 0x0A00_0001
        0x42, 0x68,                   // message type 17000 = 0x4268
        0x28, 0x80,                   // properties: ack 0 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0x2880
        // message data
        0x1f,                         // presence vector 0x1F: bits 0..=4
        0xc5, 0x93, 0x2b, 0x86, 0xea, // time stamp 2026-11-21T12:01:00.650Z = 848_577_660_650 ms since 2000-01-01 = 0xC5_932B_86EA
        0xc5, 0x93, 0x2b, 0x86, 0xb8, // original message time stamp 2026-11-21T12:01:00.600Z = 848_577_660_600 ms since 2000-01-01 = 0xC5_932B_86B8
        0x32, 0xc8,                   // original message type 13000 = 0x32C8
        0x03,                         // acknowledgement type 3: rejected
        0x09,                         // reject reason 9: BrokenChain
        // checksum
        0x00, 0x00, 0x0a, 0x4f,       // checksum: byte sum of header and data = 2639 = 0x0000_0A4F
    ];

    /// FCC to GCS; an acknowledgement is never acknowledged.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: false,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> MessageAcknowledgement {
        MessageAcknowledgement {
            time_stamp: Timestamp::from_millis(848_577_660_650).unwrap(),
            original_time_stamp: Timestamp::from_millis(848_577_660_600).unwrap(),
            original_message_type: 13000,
            ack_type: AckType::Rejected,
            reject_reason: Some(Reason::BrokenChain),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:01:00.650Z");
        assert_eq!(
            m.original_time_stamp.to_string(),
            "2026-11-21T12:01:00.600Z"
        );
        assert_eq!(
            m.original_message_type,
            MessageType::MissionTransferCommand as u16
        );
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#17000 Message Acknowledgement: type 3 rejected (BrokenChain (9)), of #13000",
        );
    }

    #[test]
    fn display_completed() {
        super::super::assert_display(
            MessageAcknowledgement {
                ack_type: AckType::Completed,
                reject_reason: None,
                original_message_type: 13002,
                ..repr()
            },
            "#17000 Message Acknowledgement: type 2 completed, of #13002",
        );
    }
}
