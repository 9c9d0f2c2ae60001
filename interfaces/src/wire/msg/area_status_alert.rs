//! #3012 Area Status Alert (ICD §4, icd use): the FCC's answer to #2011 mode 2 upload complete,
//! instead of a #17000 (ICD §5.3).

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
