//! #2011 Area Transmission Command (ICD §4, icd): opens, closes, cancels and clears area
//! transfers (ICD §5.3, §5.4).

use core::fmt;

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::AreaTransferMode;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{SafetyOffset, Timestamp, U3};
use crate::wire::presence::Writer;

/// #2011.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AreaTransmissionCommand {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M.
    pub mode: AreaTransferMode,
    /// Bit 2, M for modes 1, 2 and 4: areas that will follow or followed.
    pub loop_count: Option<u8>,
    /// Bit 3: mode 3, 0 = all areas, else that one.
    pub area_id: Option<u16>,
    /// Bit 4: distance the geofence keeps from every area border.
    pub safety_offset: Option<SafetyOffset>,
    /// Bit 5.
    pub activity_id: Option<U3>,
}

impl MessageBody for AreaTransmissionCommand {
    const TYPE: MessageType = MessageType::AreaTransmissionCommand;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Area Transfer Mode",
        "Area Loop Count",
        "Area ID",
        "Safety Offset",
        "Activity ID",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let mode = r.mandatory(1)?;
        let loop_count = r.optional(2)?;
        if matches!(
            mode,
            AreaTransferMode::InitiateUpload
                | AreaTransferMode::UploadComplete
                | AreaTransferMode::DownloadComplete
        ) {
            r.require(2, loop_count)?;
        }
        let m = Self {
            time_stamp,
            mode,
            loop_count,
            area_id: r.optional(3)?,
            safety_offset: r.optional(4)?,
            activity_id: r.optional(5)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.mode)?;
        w.optional(2, self.loop_count.as_ref())?;
        w.optional(3, self.area_id.as_ref())?;
        w.optional(4, self.safety_offset.as_ref())?;
        w.optional(5, self.activity_id.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#2011 Area Transmission Command: mode 1 initiate upload, 3 areas, safety offset 25.0 m`.
impl fmt::Display for AreaTransmissionCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: mode {}", Self::TYPE, self.mode.numbered())?;
        if let Some(n) = self.loop_count {
            super::count(f, n.into(), "area")?;
        }
        // Area ID only means something to a download request (mode 3).
        if let (AreaTransferMode::InitiateDownload, Some(id)) = (self.mode, self.area_id) {
            f.write_str(", ")?;
            super::areas(f, id)?;
        }
        if let Some(offset) = self.safety_offset {
            write!(f, ", safety offset {:.1} m", offset.metres())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #2011 mode 1: initiate upload of 3 areas, every field present; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 35] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0f,                   // message length: 15 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x07, 0xdb,                   // message type 2011 = 0x07DB
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x3f,                         // presence vector 0x3F: bits 0..=5
        0xc5, 0x93, 0x2a, 0x9a, 0x00, // time stamp 2026-11-21T12:00:00.000Z = 848_577_600_000 ms since 2000-01-01 = 0xC5_932A_9A00
        0x01,                         // area transfer mode 1: initiate upload
        0x03,                         // area loop count 3
        0x00, 0x00,                   // area ID 0
        0x00, 0xfa,                   // safety offset 25 m: 25 / 0.1 = 250 = 0x00FA
        0x00, 0x00, 0x00,             // activity ID 0
        // checksum
        0x00, 0x00, 0x07, 0x87,       // checksum: byte sum of header and data = 1927 = 0x0000_0787
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> AreaTransmissionCommand {
        AreaTransmissionCommand {
            time_stamp: Timestamp::from_millis(848_577_600_000).unwrap(),
            mode: AreaTransferMode::InitiateUpload,
            loop_count: Some(3),
            area_id: Some(0),
            safety_offset: Some(SafetyOffset::from_metres(25.0).unwrap()),
            activity_id: U3::new(0),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:00:00.000Z");
        let offset = m.safety_offset.unwrap();
        assert_eq!(offset.raw(), 250);
        assert_eq!(offset.metres(), 25.0);
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#2011 Area Transmission Command: mode 1 initiate upload, 3 areas, safety offset 25.0 m",
        );
    }

    #[test]
    fn display_download() {
        super::super::assert_display(
            AreaTransmissionCommand {
                mode: AreaTransferMode::InitiateDownload,
                loop_count: None,
                area_id: Some(2),
                safety_offset: None,
                ..repr()
            },
            "#2011 Area Transmission Command: mode 3 initiate download, area 2",
        );
    }
}
