//! #13001 UA Route (ICD §4): route properties, the initial waypoint and whether the route is
//! bidirectional (ICD §5.1 step 4).

use super::{MessageBody, MessageType, is_waypoint_number, reader};
use crate::wire::enums::RouteType;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{Text, Timestamp, U3};
use crate::wire::presence::Writer;

/// #13001.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct UaRoute {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: where the flight plan starts, 1..=65534.
    pub initial_waypoint: u16,
    /// Bit 2.
    pub route_id: Option<Text<33>>,
    /// Bit 3.
    pub route_type: Option<RouteType>,
    /// Bit 4 (Activity ID, M), bit 0 of the U3: return-to-home may fly the route backwards.
    /// The other 23 bits have no meaning in this ICD: sent as 0, ignored on receive.
    pub bidirectional: bool,
}

impl MessageBody for UaRoute {
    const TYPE: MessageType = MessageType::UaRoute;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Initial Waypoint Number",
        "Route ID",
        "Route Type",
        "Activity ID",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let initial: u16 = r.mandatory(1)?;
        let m = Self {
            time_stamp,
            initial_waypoint: r.in_range(1, initial, is_waypoint_number(initial))?,
            route_id: r.optional(2)?,
            route_type: r.optional(3)?,
            bidirectional: r.mandatory::<U3>(4)?.get() & 1 != 0,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.initial_waypoint)?;
        w.optional(2, self.route_id.as_ref())?;
        w.optional(3, self.route_type.as_ref())?;
        w.field(
            4,
            &U3::new(u32::from(self.bidirectional)).unwrap_or_default(),
        )?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
