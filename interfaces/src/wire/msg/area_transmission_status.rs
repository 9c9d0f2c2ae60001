//! #3013 Area Transmission Status (ICD §4, icd): the FCC's answer to #2011 mode 3 initiate
//! download, instead of a #17000 (ICD §5.4).

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
