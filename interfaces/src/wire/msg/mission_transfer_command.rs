//! #13000 Mission Transfer Command (ICD §4): clear, transmit (assemble and activate), receive
//! (download) and cancel (ICD §5.1, §5.2).

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::MissionPlanMode;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{Text, Timestamp, U3};
use crate::wire::presence::Writer;

/// #13000.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MissionTransferCommand {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1.
    pub mission_id: Option<Text<20>>,
    /// Bit 2, M.
    pub mode: MissionPlanMode,
    /// Bit 3, M for mode 2: the number of waypoints the flight plan must have.
    pub waypoint_number: Option<u16>,
    /// Bit 4.
    pub route_id: Option<Text<33>>,
    /// Bit 5.
    pub activity_id: Option<U3>,
}

impl MessageBody for MissionTransferCommand {
    const TYPE: MessageType = MessageType::MissionTransferCommand;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Mission ID",
        "Mission Plan Mode",
        "Waypoint Number",
        "Route ID",
        "Activity ID",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let mission_id = r.optional(1)?;
        let mode = r.mandatory(2)?;
        let waypoint_number = r.optional(3)?;
        if mode == MissionPlanMode::TransmitMission {
            r.require(3, waypoint_number)?;
        }
        let m = Self {
            time_stamp,
            mission_id,
            mode,
            waypoint_number,
            route_id: r.optional(4)?,
            activity_id: r.optional(5)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.optional(1, self.mission_id.as_ref())?;
        w.field(2, &self.mode)?;
        w.optional(3, self.waypoint_number.as_ref())?;
        w.optional(4, self.route_id.as_ref())?;
        w.optional(5, self.activity_id.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
