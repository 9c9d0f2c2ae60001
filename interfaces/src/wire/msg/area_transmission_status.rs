//! #3013 Area Transmission Status (ICD §4, icd): the FCC's answer to #2011 mode 3 initiate
//! download, instead of a #17000 (ICD §5.4).

use core::fmt;

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::AreaDownloadStatus;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{SafetyOffset, Timestamp};
use crate::wire::presence::Writer;

/// #3013.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AreaTransmissionStatus {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: as requested (0 = all).
    pub area_id: u16,
    /// Bit 2, M: areas about to be sent.
    pub loop_count: u8,
    /// Bit 3, M.
    pub safety_offset: SafetyOffset,
    /// Bit 4, M.
    pub status: AreaDownloadStatus,
}

impl MessageBody for AreaTransmissionStatus {
    const TYPE: MessageType = MessageType::AreaTransmissionStatus;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Area ID",
        "Area Loop Count",
        "Safety Offset",
        "Status",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let m = Self {
            time_stamp: r.time_stamp()?,
            area_id: r.mandatory(1)?,
            loop_count: r.mandatory(2)?,
            safety_offset: r.mandatory(3)?,
            status: r.mandatory(4)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.area_id)?;
        w.field(2, &self.loop_count)?;
        w.field(3, &self.safety_offset)?;
        w.field(4, &self.status)?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#3013 Area Transmission Status: status 0 ready, 3 areas (all areas), safety offset 25.0 m`.
impl fmt::Display for AreaTransmissionStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: status {}", Self::TYPE, self.status.numbered())?;
        super::count(f, self.loop_count.into(), "area")?;
        f.write_str(" (")?;
        super::areas(f, self.area_id)?;
        write!(f, "), safety offset {:.1} m", self.safety_offset.metres())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #3013: ready to send all 3 areas; FCC to GCS, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 32] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0c,                   // message length: 12 bytes of message data
        0x0b, 0x00, 0x00, 0x01,       // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,       // destination ID: GCS 0x0A00_0001
        0x0b, 0xc5,                   // message type 3013 = 0x0BC5
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x1f,                         // presence vector 0x1F: bits 0..=4
        0xc5, 0x93, 0x2a, 0xad, 0x88, // time stamp 2026-11-21T12:00:05.000Z = 848_577_605_000 ms since 2000-01-01 = 0xC5_932A_AD88
        0x00, 0x00,                   // area ID 0: all areas
        0x03,                         // area loop count 3
        0x00, 0xfa,                   // safety offset 25 m: 25 / 0.1 = 250 = 0x00FA
        0x00,                         // status 0: ready
        // checksum
        0x00, 0x00, 0x07, 0xec,       // checksum: byte sum of header and data = 2028 = 0x0000_07EC
    ];

    /// FCC to GCS, acknowledgement requested (ICD §5.4: the GCS acknowledges the #3013).
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> AreaTransmissionStatus {
        AreaTransmissionStatus {
            time_stamp: Timestamp::from_millis(848_577_605_000).unwrap(),
            area_id: 0,
            loop_count: 3,
            safety_offset: SafetyOffset::from_metres(25.0).unwrap(),
            status: AreaDownloadStatus::Ready,
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:00:05.000Z");
        assert_eq!(m.safety_offset.raw(), 250);
        assert_eq!(m.safety_offset.metres(), 25.0);
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#3013 Area Transmission Status: status 0 ready, 3 areas (all areas), safety offset 25.0 m",
        );
    }
}
