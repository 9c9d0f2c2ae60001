//! #50000 Mission Execute Command (ICD §4, private range): execute, return to home, land.

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::ExecuteCommand;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::Timestamp;
use crate::wire::presence::Writer;

/// #50000. Acknowledged with #17000 type 2 when system automation accepts it, type 3 with
/// `WrongState` or `Unsupported` when not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MissionExecuteCommand {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M.
    pub command: ExecuteCommand,
}

impl MessageBody for MissionExecuteCommand {
    const TYPE: MessageType = MessageType::MissionExecuteCommand;
    const FIELDS: &'static [&'static str] = &["Time Stamp", "Command"];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let m = Self {
            time_stamp: r.time_stamp()?,
            command: r.mandatory(1)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.command)?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
