//! #14000 Mission Upload/Download Status (ICD §4): closes a mission download (ICD §5.2 step 5).

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::{MissionPlanMode, TransferStatus};
use crate::wire::error::{EncodeError, MessageError, Reason};
use crate::wire::field::{Text, Timestamp};
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
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
