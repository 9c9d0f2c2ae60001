//! #14000 Mission Upload/Download Status (ICD §4): closes a mission download (ICD §5.2 step 5),
//! in edition 2 with the checksum of the mission sent (ICD §11).

use core::fmt;

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::{MissionPlanMode, TransferStatus};
use crate::wire::error::{EncodeError, MessageError, Reason};
use crate::wire::field::{Checksum, Text, Timestamp};
use crate::wire::presence::Writer;

/// #14000.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MissionUploadDownloadStatus {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1.
    pub mission_id: Option<Text<20>>,
    /// Bit 2, M.
    pub status: TransferStatus,
    /// Bit 3: 0..=100.
    pub percent_complete: Option<u8>,
    /// Bit 4.
    pub waypoint_request: Option<u16>,
    /// Bit 5.
    pub mode: Option<MissionPlanMode>,
    /// Bit 6 (icd): why the transfer aborted.
    pub reason: Option<Reason>,
    /// Bit 7 (ext, ICD §11): with status 1 of a download whose request was edition 2, the
    /// checksum of the mission sent.
    pub mission_checksum: Option<Checksum>,
}

impl MessageBody for MissionUploadDownloadStatus {
    const TYPE: MessageType = MessageType::MissionUploadDownloadStatus;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Mission ID",
        "Status",
        "Percent Complete",
        "Waypoint Request",
        "Mission Plan Mode",
        "Reason",
        "Mission Checksum",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let mission_id = r.optional(1)?;
        let status = r.mandatory(2)?;
        let percent: Option<u8> = r.optional(3)?;
        if let Some(p) = percent {
            r.in_range(3, p, p <= 100)?;
        }
        let m = Self {
            time_stamp,
            mission_id,
            status,
            percent_complete: percent,
            waypoint_request: r.optional(4)?,
            mode: r.optional(5)?,
            reason: r.optional(6)?,
            mission_checksum: r.optional(7)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.optional(1, self.mission_id.as_ref())?;
        w.field(2, &self.status)?;
        w.optional(3, self.percent_complete.as_ref())?;
        w.optional(4, self.waypoint_request.as_ref())?;
        w.optional(5, self.mode.as_ref())?;
        w.optional(6, self.reason.as_ref())?;
        w.optional(7, self.mission_checksum.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#14000 Mission Upload/Download Status: status 1 complete, 100 %, mode 3 receive mission`.
impl fmt::Display for MissionUploadDownloadStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: status {}", Self::TYPE, self.status.numbered())?;
        super::reason(f, self.reason)?;
        if let Some(p) = self.percent_complete {
            write!(f, ", {p} %")?;
        }
        if let Some(m) = self.mode {
            write!(f, ", mode {}", m.numbered())?;
        }
        super::optional(f, "mission", self.mission_id.as_ref().map(Text::as_str))?;
        super::optional(f, "waypoint request", self.waypoint_request)?;
        super::optional(f, "checksum", self.mission_checksum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #14000: download of mission 2 complete, every field present; FCC to GCS, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 52] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x20,                                     // message length: 32 bytes of message data
        0x0b, 0x00, 0x00, 0x01,                         // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,                         // destination ID: GCS 0x0A00_0001
        0x36, 0xb0,                                     // message type 14000 = 0x36B0
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x7f,                                           // presence vector 0x7F: bits 0..=6
        0xc5, 0x93, 0x2c, 0x6e, 0xc0,                   // time stamp 2026-11-21T12:02:00.000Z = 848_577_720_000 ms since 2000-01-01 = 0xC5_932C_6EC0
        b'M', b'E', b'D', b'E', b'V', b'A', b'C', b'-', // mission ID "MEDEVAC-2" (Char20)
        b'2',
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 11 bytes
        0x00, 0x00, 0x00,
        0x01,                                           // status 1: complete
        0x64,                                           // percent complete 100
        0x00, 0x03,                                     // waypoint request 3
        0x03,                                           // mission plan mode 3: receive mission
        0x00,                                           // reason 0: None
        // checksum
        0x00, 0x00, 0x0a, 0x33,                         // checksum: byte sum of header and data = 2611 = 0x0000_0A33
    ];

    /// FCC to GCS, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> MissionUploadDownloadStatus {
        MissionUploadDownloadStatus {
            time_stamp: Timestamp::from_millis(848_577_720_000).unwrap(),
            mission_id: Some(Text::new("MEDEVAC-2").unwrap()),
            status: TransferStatus::Complete,
            percent_complete: Some(100),
            waypoint_request: Some(3),
            mode: Some(MissionPlanMode::ReceiveMission),
            reason: Some(Reason::None),
            mission_checksum: None,
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:02:00.000Z");
        assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-2");
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#14000 Mission Upload/Download Status: status 1 complete, 100 %, mode 3 receive mission, mission MEDEVAC-2, waypoint request 3",
        );
    }

    #[test]
    fn display_aborted() {
        super::super::assert_display(
            MissionUploadDownloadStatus {
                mission_id: None,
                status: TransferStatus::Aborted,
                percent_complete: None,
                waypoint_request: None,
                mode: None,
                reason: Some(Reason::Busy),
                ..repr()
            },
            "#14000 Mission Upload/Download Status: status 2 aborted (Busy (13))",
        );
    }

    /// #14000: download complete, with the checksum of the mission sent (ext, ICD §11), the
    /// closer of an edition-2 download; FCC to GCS, ack.
    #[rustfmt::skip]
    static FRAME_CHECKSUM: [u8; 32] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0c,                   // message length: 12 bytes of message data
        0x0b, 0x00, 0x00, 0x01,       // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,       // destination ID: GCS 0x0A00_0001
        0x36, 0xb0,                   // message type 14000 = 0x36B0
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0xa5,                         // presence vector 0xA5: bits 0, 2, 5 and 7
        0xc5, 0x93, 0x2c, 0x72, 0xa8, // time stamp 2026-11-21T12:02:01.000Z = 848_577_721_000 ms since 2000-01-01 = 0xC5_932C_72A8
        0x01,                         // status 1: complete
        0x03,                         // mission plan mode 3: receive mission
        0x1a, 0x2b, 0x3c, 0x4d,       // mission checksum 0x1A2B3C4D (U4)
        // checksum
        0x00, 0x00, 0x08, 0x44,       // checksum: byte sum of header and data = 2116 = 0x0000_0844
    ];

    fn with_checksum() -> MissionUploadDownloadStatus {
        MissionUploadDownloadStatus {
            time_stamp: Timestamp::from_millis(848_577_721_000).unwrap(),
            mission_id: None,
            status: TransferStatus::Complete,
            percent_complete: None,
            waypoint_request: None,
            mode: Some(MissionPlanMode::ReceiveMission),
            reason: None,
            mission_checksum: Some(Checksum::new(0x1A2B_3C4D)),
        }
    }

    #[test]
    fn golden_checksum() {
        super::super::assert_golden(&FRAME_CHECKSUM, ENVELOPE, with_checksum().into());
    }

    #[test]
    fn display_checksum() {
        super::super::assert_display(
            with_checksum(),
            "#14000 Mission Upload/Download Status: status 1 complete, mode 3 receive mission, checksum 0x1A2B3C4D",
        );
    }
}
