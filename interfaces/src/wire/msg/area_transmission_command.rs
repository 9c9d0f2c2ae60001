//! #2011 Area Transmission Command (ICD §4, icd): opens, closes, cancels and clears area
//! transfers (ICD §5.3, §5.4).

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
