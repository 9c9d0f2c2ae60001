//! #13006 Vehicle Specific Waypoint (ICD §4, icd): the take-off height (type 1) and the centre
//! and turn direction of a radius-to-fix leg (type 2).

use super::{MessageBody, MessageType, is_waypoint_number, latitude, reader};
use crate::wire::enums::TurnDirection;
use crate::wire::error::{Cause, EncodeError, MessageError};
use crate::wire::field::{Altitude, Angle, Timestamp, U3};
use crate::wire::presence::Writer;

/// What a #13006 carries, by Specific Data Type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum SpecificData {
    /// Type 1, Waypoint Number 0.
    TakeOffHeight {
        /// Bit 3: height above ground level, not below 0.
        height: Altitude,
    },
    /// Type 2.
    RfCentre {
        /// Bit 1: the radius-to-fix waypoint the centre belongs to.
        waypoint_number: u16,
        /// Bit 4.
        latitude: Angle,
        /// Bit 5.
        longitude: Angle,
        /// Bit 6.
        turn_direction: TurnDirection,
    },
}

/// #13006.
///
/// Fields that belong to the other Specific Data Type (say an RF centre in a type 1 message) are
/// read and ignored on receive, and never sent: a peer that fills every field it knows still
/// interoperates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct VehicleSpecificWaypoint {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bits 1 to 6.
    pub data: SpecificData,
    /// Bit 7.
    pub activity_id: Option<U3>,
}

const TAKE_OFF_HEIGHT: u8 = 1;
const RF_CENTRE: u8 = 2;

impl MessageBody for VehicleSpecificWaypoint {
    const TYPE: MessageType = MessageType::VehicleSpecificWaypoint;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Waypoint Number",
        "Specific Data Type",
        "Take-off Height",
        "RF Centre Latitude",
        "RF Centre Longitude",
        "Turn Direction",
        "Activity ID",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let number: u16 = r.mandatory(1)?;
        let kind: u8 = r.mandatory(2)?;
        let height: Option<Altitude> = r.optional(3)?;
        let lat = r.optional(4)?;
        let lon = r.optional(5)?;
        let direction = r.optional(6)?;
        let activity_id = r.optional(7)?;
        let data = match kind {
            TAKE_OFF_HEIGHT => {
                if number != 0 {
                    return Err(r.error(1, Cause::Inconsistent));
                }
                let height = r.require(3, height)?;
                r.in_range(3, height.raw(), height.raw() >= 0)?;
                SpecificData::TakeOffHeight { height }
            }
            RF_CENTRE => {
                let waypoint_number = r.in_range(1, number, is_waypoint_number(number))?;
                let lat = r.require(4, lat)?;
                SpecificData::RfCentre {
                    waypoint_number,
                    latitude: latitude(&r, 4, lat)?,
                    longitude: r.require(5, lon)?,
                    turn_direction: r.require(6, direction)?,
                }
            }
            other => {
                return Err(r.error(
                    2,
                    Cause::Unsupported {
                        value: u32::from(other),
                    },
                ));
            }
        };
        r.finish()?;
        Ok(Self {
            time_stamp,
            data,
            activity_id,
        })
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        match &self.data {
            SpecificData::TakeOffHeight { height } => {
                w.field(1, &0u16)?;
                w.field(2, &TAKE_OFF_HEIGHT)?;
                w.field(3, height)?;
            }
            SpecificData::RfCentre {
                waypoint_number,
                latitude,
                longitude,
                turn_direction,
            } => {
                w.field(1, waypoint_number)?;
                w.field(2, &RF_CENTRE)?;
                w.field(4, latitude)?;
                w.field(5, longitude)?;
                w.field(6, turn_direction)?;
            }
        }
        w.optional(7, self.activity_id.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
