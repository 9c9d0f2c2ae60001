//! #13002 UA Position Waypoint (ICD §4, std field order, Ed 4): one waypoint of the flight plan.
//! Waypoint Number and Next Waypoint define the plan; the order of upload is free.

use super::{MessageBody, MessageType, is_waypoint_number, latitude, reader};
use crate::wire::enums::{AltitudeType, LegType, LocationType, SpeedType, TurnType};
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{Altitude, Angle, Speed, Timestamp, U3};
use crate::wire::presence::Writer;

/// #13002.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct UaPositionWaypoint {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: 1..=65534.
    pub waypoint_number: u16,
    /// Bit 2, M: within +-90 deg.
    pub latitude: Angle,
    /// Bit 3, M.
    pub longitude: Angle,
    /// Bit 4: only absolute (relative is `Unsupported`).
    pub location_type: Option<LocationType>,
    /// Bit 5, M.
    pub altitude: Altitude,
    /// Bit 6.
    pub altitude_type: Option<AltitudeType>,
    /// Bit 7.
    pub altitude_change_behaviour: Option<u8>,
    /// Bit 8, M: above 0 (ICD §7).
    pub speed: Speed,
    /// Bit 9.
    pub speed_type: Option<SpeedType>,
    /// Bit 10, M: the waypoint that follows; 0 = last waypoint.
    pub next_waypoint: u16,
    /// Bit 11, M.
    pub turn_type: TurnType,
    /// Bit 12: bitmap, bit 0 = a #13006 radius-to-fix centre follows.
    pub optional_messages: Option<u8>,
    /// Bit 13 (Waypoint Type), M: ARINC 424 type of the leg that ends here.
    pub leg_type: LegType,
    /// Bit 14.
    pub limit_type: Option<u8>,
    /// Bit 15.
    pub loop_limit: Option<u16>,
    /// Bit 16.
    pub arrival_time: Option<Timestamp>,
    /// Bit 17.
    pub activity_id: Option<U3>,
}

impl MessageBody for UaPositionWaypoint {
    const TYPE: MessageType = MessageType::UaPositionWaypoint;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Waypoint Number",
        "Waypoint to Latitude",
        "Waypoint to Longitude",
        "Location Type",
        "Waypoint to Altitude",
        "Waypoint Altitude Type",
        "Altitude Change Behaviour",
        "Waypoint to Speed",
        "Waypoint Speed Type",
        "Next Waypoint",
        "Turn Type",
        "Optional Messages for Waypoint",
        "Waypoint Type",
        "Limit Type",
        "Loop Limit",
        "Arrival Time",
        "Activity ID",
    ];
    const PV_BYTES: usize = 3;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let number: u16 = r.mandatory(1)?;
        let waypoint_number = r.in_range(1, number, is_waypoint_number(number))?;
        let lat = r.mandatory(2)?;
        let lat = latitude(&r, 2, lat)?;
        let longitude = r.mandatory(3)?;
        let location_type = r.optional(4)?;
        let altitude = r.mandatory(5)?;
        let altitude_type = r.optional(6)?;
        let altitude_change_behaviour = r.optional(7)?;
        let speed: Speed = r.mandatory(8)?;
        r.in_range(8, speed.raw(), speed.raw() > 0)?;
        let speed_type = r.optional(9)?;
        let next: u16 = r.mandatory(10)?;
        let next_waypoint = r.in_range(10, next, next != u16::MAX)?;
        let m = Self {
            time_stamp,
            waypoint_number,
            latitude: lat,
            longitude,
            location_type,
            altitude,
            altitude_type,
            altitude_change_behaviour,
            speed,
            speed_type,
            next_waypoint,
            turn_type: r.mandatory(11)?,
            optional_messages: r.optional(12)?,
            leg_type: r.mandatory(13)?,
            limit_type: r.optional(14)?,
            loop_limit: r.optional(15)?,
            arrival_time: r.optional(16)?,
            activity_id: r.optional(17)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.waypoint_number)?;
        w.field(2, &self.latitude)?;
        w.field(3, &self.longitude)?;
        w.optional(4, self.location_type.as_ref())?;
        w.field(5, &self.altitude)?;
        w.optional(6, self.altitude_type.as_ref())?;
        w.optional(7, self.altitude_change_behaviour.as_ref())?;
        w.field(8, &self.speed)?;
        w.optional(9, self.speed_type.as_ref())?;
        w.field(10, &self.next_waypoint)?;
        w.field(11, &self.turn_type)?;
        w.optional(12, self.optional_messages.as_ref())?;
        w.field(13, &self.leg_type)?;
        w.optional(14, self.limit_type.as_ref())?;
        w.optional(15, self.loop_limit.as_ref())?;
        w.optional(16, self.arrival_time.as_ref())?;
        w.optional(17, self.activity_id.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
