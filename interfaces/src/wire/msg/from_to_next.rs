//! #4001 FROM-TO-NEXT Waypoint States (ICD §4, std field order; paper §3.1.7): where the aircraft
//! comes from, flies to and goes next. Sent on every change of the triple, never acknowledged.

use super::{MessageBody, MessageType, latitude, reader};
use crate::wire::enums::{AltitudeType, SpeedType};
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{Altitude, Angle, Speed, Timestamp};
use crate::wire::presence::{Reader, Writer};

/// The FROM waypoint of #4001 (bits 3 to 7). Waypoint Number 0 = none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FromWaypointState {
    /// Latitude.
    pub latitude: Option<Angle>,
    /// Longitude.
    pub longitude: Option<Angle>,
    /// Altitude.
    pub altitude: Option<Altitude>,
    /// Time.
    pub time: Option<Timestamp>,
    /// Waypoint Number; 0 = none (before the first waypoint).
    pub waypoint_number: Option<u16>,
}

/// The TO waypoint (bits 8 to 13) or the NEXT waypoint (bits 14 to 19) of #4001.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct WaypointState {
    /// Latitude.
    pub latitude: Option<Angle>,
    /// Longitude.
    pub longitude: Option<Angle>,
    /// Altitude.
    pub altitude: Option<Altitude>,
    /// Speed.
    pub speed: Option<Speed>,
    /// Time.
    pub time: Option<Timestamp>,
    /// Waypoint Number; 0 = none (no NEXT on the last leg).
    pub waypoint_number: Option<u16>,
}

/// #4001.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FromToNext {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1.
    pub altitude_type: Option<AltitudeType>,
    /// Bit 2.
    pub speed_type: Option<SpeedType>,
    /// Bits 3 to 7.
    pub from: FromWaypointState,
    /// Bits 8 to 13.
    pub to: WaypointState,
    /// Bits 14 to 19.
    pub next: WaypointState,
    /// Bit 20.
    pub loiter_configuration_report_validity: Option<u8>,
}

const FROM: u8 = 3;
const TO: u8 = 8;
const NEXT: u8 = 14;

fn optional_latitude(r: &mut Reader<'_>, bit: u8) -> Result<Option<Angle>, MessageError> {
    match r.optional(bit)? {
        Some(a) => latitude(r, bit, a).map(Some),
        None => Ok(None),
    }
}

fn read_state(r: &mut Reader<'_>, first: u8) -> Result<WaypointState, MessageError> {
    Ok(WaypointState {
        latitude: optional_latitude(r, first)?,
        longitude: r.optional(first + 1)?,
        altitude: r.optional(first + 2)?,
        speed: r.optional(first + 3)?,
        time: r.optional(first + 4)?,
        waypoint_number: r.optional(first + 5)?,
    })
}

fn write_state(w: &mut Writer<'_>, first: u8, s: &WaypointState) -> Result<(), EncodeError> {
    w.optional(first, s.latitude.as_ref())?;
    w.optional(first + 1, s.longitude.as_ref())?;
    w.optional(first + 2, s.altitude.as_ref())?;
    w.optional(first + 3, s.speed.as_ref())?;
    w.optional(first + 4, s.time.as_ref())?;
    w.optional(first + 5, s.waypoint_number.as_ref())
}

impl MessageBody for FromToNext {
    const TYPE: MessageType = MessageType::FromToNext;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Altitude Type",
        "Speed Type",
        "From Latitude",
        "From Longitude",
        "From Altitude",
        "From Time",
        "From Waypoint Number",
        "To Latitude",
        "To Longitude",
        "To Altitude",
        "To Speed",
        "To Time",
        "To Waypoint Number",
        "Next Latitude",
        "Next Longitude",
        "Next Altitude",
        "Next Speed",
        "Next Time",
        "Next Waypoint Number",
        "Loiter Configuration Report Validity",
    ];
    const PV_BYTES: usize = 3;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let m = Self {
            time_stamp: r.time_stamp()?,
            altitude_type: r.optional(1)?,
            speed_type: r.optional(2)?,
            from: FromWaypointState {
                latitude: optional_latitude(&mut r, FROM)?,
                longitude: r.optional(FROM + 1)?,
                altitude: r.optional(FROM + 2)?,
                time: r.optional(FROM + 3)?,
                waypoint_number: r.optional(FROM + 4)?,
            },
            to: read_state(&mut r, TO)?,
            next: read_state(&mut r, NEXT)?,
            loiter_configuration_report_validity: r.optional(20)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.optional(1, self.altitude_type.as_ref())?;
        w.optional(2, self.speed_type.as_ref())?;
        let f = &self.from;
        w.optional(FROM, f.latitude.as_ref())?;
        w.optional(FROM + 1, f.longitude.as_ref())?;
        w.optional(FROM + 2, f.altitude.as_ref())?;
        w.optional(FROM + 3, f.time.as_ref())?;
        w.optional(FROM + 4, f.waypoint_number.as_ref())?;
        write_state(&mut w, TO, &self.to)?;
        write_state(&mut w, NEXT, &self.next)?;
        w.optional(20, self.loiter_configuration_report_validity.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}
