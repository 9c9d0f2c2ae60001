//! #3012 Area Status Alert (ICD §4, icd use): the FCC's answer to #2011 mode 2 upload complete,
//! instead of a #17000 (ICD §5.3).

use core::fmt;

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::AreaListStatus;
use crate::wire::error::{EncodeError, MessageError, Reason};
use crate::wire::field::Timestamp;
use crate::wire::presence::Writer;

/// #3012.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AreaStatusAlert {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: areas in the assembled list.
    pub loop_count: u8,
    /// Bit 2, M.
    pub status: AreaListStatus,
    /// Bit 3: why the list is invalid.
    pub reason: Option<Reason>,
}

impl MessageBody for AreaStatusAlert {
    const TYPE: MessageType = MessageType::AreaStatusAlert;
    const FIELDS: &'static [&'static str] = &["Time Stamp", "Area Loop Count", "Status", "Reason"];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let m = Self {
            time_stamp: r.time_stamp()?,
            loop_count: r.mandatory(1)?,
            status: r.mandatory(2)?,
            reason: r.optional(3)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.loop_count)?;
        w.field(2, &self.status)?;
        w.optional(3, self.reason.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#3012 Area Status Alert: status 0 invalid (BadGeometry (12)), 3 areas`.
impl fmt::Display for AreaStatusAlert {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: status {}", Self::TYPE, self.status.numbered())?;
        super::reason(f, self.reason)?;
        super::count(f, self.loop_count.into(), "area")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #3012: the area list of 3 areas is valid, every field present; FCC to GCS, no ack.
    #[rustfmt::skip]
    static FRAME: [u8; 29] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x09,                   // message length: 9 bytes of message data
        0x0b, 0x00, 0x00, 0x01,       // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,       // destination ID: GCS 0x0A00_0001
        0x0b, 0xc4,                   // message type 3012 = 0x0BC4
        0x28, 0x80,                   // properties: ack 0 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0x2880
        // message data
        0x0f,                         // presence vector 0x0F: bits 0..=3
        0xc5, 0x93, 0x2a, 0x9b, 0x5e, // time stamp 2026-11-21T12:00:00.350Z = 848_577_600_350 ms since 2000-01-01 = 0xC5_932A_9B5E
        0x03,                         // area loop count 3
        0x01,                         // status 1: area list valid
        0x00,                         // reason 0: None
        // checksum
        0x00, 0x00, 0x06, 0x23,       // checksum: byte sum of header and data = 1571 = 0x0000_0623
    ];

    /// FCC to GCS, no acknowledgement requested: it is itself the answer to #2011 mode 2
    /// (ICD §5.3).
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: false,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> AreaStatusAlert {
        AreaStatusAlert {
            time_stamp: Timestamp::from_millis(848_577_600_350).unwrap(),
            loop_count: 3,
            status: AreaListStatus::Valid,
            reason: Some(Reason::None),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        assert_eq!(repr().time_stamp.to_string(), "2026-11-21T12:00:00.350Z");
    }

    #[test]
    fn display() {
        super::super::assert_display(repr(), "#3012 Area Status Alert: status 1 valid, 3 areas");
    }

    #[test]
    fn display_invalid() {
        super::super::assert_display(
            AreaStatusAlert {
                status: AreaListStatus::Invalid,
                reason: Some(Reason::BadGeometry),
                ..repr()
            },
            "#3012 Area Status Alert: status 0 invalid (BadGeometry (12)), 3 areas",
        );
    }

    #[test]
    fn display_one_area() {
        let m = AreaStatusAlert {
            loop_count: 1,
            ..repr()
        };
        super::super::assert_display(m, "#3012 Area Status Alert: status 1 valid, 1 area");
    }
}
