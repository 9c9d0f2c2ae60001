//! #13006 Vehicle Specific Waypoint (ICD §4, icd): the take-off height (type 1) and the centre
//! and turn direction of a radius-to-fix leg (type 2).

use core::fmt;

use super::{GeoPoint, MessageBody, MessageType, is_waypoint_number, latitude, reader};
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

/// `#13006 Vehicle Specific Waypoint: take-off height 30.0 m`, or `RF centre of waypoint 3:
/// 48.274550 N 11.669910 E, clockwise`.
impl fmt::Display for VehicleSpecificWaypoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", Self::TYPE)?;
        match self.data {
            SpecificData::TakeOffHeight { height } => {
                write!(f, "take-off height {:.1} m", height.metres())
            }
            SpecificData::RfCentre {
                waypoint_number,
                latitude,
                longitude,
                turn_direction,
            } => write!(
                f,
                "RF centre of waypoint {waypoint_number}: {}, {}",
                GeoPoint {
                    latitude,
                    longitude
                },
                turn_direction.name()
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #13006 type 1: take-off height 30 m, no activity ID; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_TAKE_OFF: [u8; 32] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0c,                   // message length: 12 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x32, 0xce,                   // message type 13006 = 0x32CE
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x0f,                         // presence vector 0x0F: bits 0..=3
        0xc5, 0x93, 0x2b, 0x84, 0x60, // time stamp 2026-11-21T12:01:00.000Z = 848_577_660_000 ms since 2000-01-01 = 0xC5_932B_8460
        0x00, 0x00,                   // waypoint number 0: take-off height
        0x01,                         // specific data type 1: take-off height
        0x00, 0x05, 0xdc,             // take-off height 30 m: 30 / 0.02 = 1500 = 0x00_05DC
        // checksum
        0x00, 0x00, 0x07, 0xa1,       // checksum: byte sum of header and data = 1953 = 0x0000_07A1
    ];

    /// #13006 type 2: the RF centre of ROLE2 (waypoint 3), clockwise, with activity ID; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_RF_CENTRE: [u8; 41] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x15,                   // message length: 21 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x32, 0xce,                   // message type 13006 = 0x32CE
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0xf7,                         // presence vector 0xF7: bits 0..=2, 4..=7
        0xc5, 0x93, 0x2b, 0x85, 0xf0, // time stamp 2026-11-21T12:01:00.400Z = 848_577_660_400 ms since 2000-01-01 = 0xC5_932B_85F0
        0x00, 0x03,                   // waypoint number 3 (ROLE2)
        0x02,                         // specific data type 2: radius-to-fix centre
        0x22, 0x54, 0x1d, 0x17,       // RF centre latitude 48.27455 deg: 48.27455 / 180 * 2^31 = 575_937_815.2 -> 575_937_815 = 0x2254_1D17
        0x08, 0x4c, 0x71, 0x39,       // RF centre longitude 11.66991 deg: 11.66991 / 180 * 2^31 = 139_227_449.4 -> 139_227_449 = 0x084C_7139
        0x00,                         // turn direction 0: clockwise
        0x00, 0x00, 0x07,             // activity ID 7
        // checksum
        0x00, 0x00, 0x09, 0xf5,       // checksum: byte sum of header and data = 2549 = 0x0000_09F5
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr_take_off() -> VehicleSpecificWaypoint {
        VehicleSpecificWaypoint {
            time_stamp: Timestamp::from_millis(848_577_660_000).unwrap(),
            data: SpecificData::TakeOffHeight {
                height: Altitude::from_metres(30.0).unwrap(),
            },
            activity_id: None,
        }
    }

    fn repr_rf_centre() -> VehicleSpecificWaypoint {
        VehicleSpecificWaypoint {
            time_stamp: Timestamp::from_millis(848_577_660_400).unwrap(),
            data: SpecificData::RfCentre {
                waypoint_number: 3,
                latitude: Angle::from_raw(575_937_815),
                longitude: Angle::from_raw(139_227_449),
                turn_direction: TurnDirection::Clockwise,
            },
            activity_id: U3::new(7),
        }
    }

    #[test]
    fn golden_take_off_height() {
        super::super::assert_golden(&FRAME_TAKE_OFF, ENVELOPE, repr_take_off().into());
    }

    #[test]
    fn physical_take_off_height() {
        let m = repr_take_off();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:01:00.000Z");
        let SpecificData::TakeOffHeight { height } = m.data else {
            panic!("not a take-off height");
        };
        assert_eq!(height.raw(), 1500);
        assert_eq!(height.metres(), 30.0);
    }

    #[test]
    fn golden_rf_centre() {
        super::super::assert_golden(&FRAME_RF_CENTRE, ENVELOPE, repr_rf_centre().into());
    }

    #[test]
    fn physical_rf_centre() {
        let m = repr_rf_centre();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:01:00.400Z");
        let SpecificData::RfCentre {
            latitude,
            longitude,
            ..
        } = m.data
        else {
            panic!("not an RF centre");
        };
        assert!((latitude.degrees() - 48.27455).abs() < Angle::LSB_DEGREES);
        assert!((longitude.degrees() - 11.66991).abs() < Angle::LSB_DEGREES);
        assert_eq!(Angle::from_degrees(48.27455).unwrap(), latitude);
        assert_eq!(Angle::from_degrees(11.66991).unwrap(), longitude);
    }

    #[test]
    fn display_take_off_height() {
        super::super::assert_display(
            repr_take_off(),
            "#13006 Vehicle Specific Waypoint: take-off height 30.0 m",
        );
    }

    #[test]
    fn display_rf_centre() {
        super::super::assert_display(
            repr_rf_centre(),
            "#13006 Vehicle Specific Waypoint: RF centre of waypoint 3: 48.274550 N 11.669910 E, clockwise",
        );
    }
}
