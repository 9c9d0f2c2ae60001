//! #13002 UA Position Waypoint (ICD §4, std field order, Ed 4): one waypoint of the flight plan.
//! Waypoint Number and Next Waypoint define the plan; the order of upload is free.

use core::fmt;

use super::{GeoPoint, MessageBody, MessageType, is_waypoint_number, latitude, reader};
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

/// `#13002 UA Position Waypoint: waypoint 2: 48.275000 N 11.645000 E, 120.0 m WGS-84, 25.0 m/s
/// indicated airspeed, fly-by, track-to-fix, next 3` (`last` for Next Waypoint 0).
impl fmt::Display for UaPositionWaypoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = GeoPoint {
            latitude: self.latitude,
            longitude: self.longitude,
        };
        write!(
            f,
            "{}: waypoint {}: {at}, {:.1} m",
            Self::TYPE,
            self.waypoint_number,
            self.altitude.metres()
        )?;
        if let Some(t) = self.altitude_type {
            write!(f, " {}", t.name())?;
        }
        write!(f, ", {:.1} m/s", self.speed.mps())?;
        if let Some(t) = self.speed_type {
            write!(f, " {}", t.name())?;
        }
        write!(f, ", {}, {}", self.turn_type.name(), self.leg_type.name())?;
        super::optional(f, "arrival", self.arrival_time)?;
        match self.next_waypoint {
            0 => f.write_str(", last"),
            next => write!(f, ", next {next}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #13002 ROLE2, waypoint 3 of mission 2 (radius-to-fix, last), all 18 fields; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 63] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x2b,                   // message length: 43 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x32, 0xca,                   // message type 13002 = 0x32CA
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x03, 0xff, 0xff,             // presence vector 0x03_FFFF: bits 0..=17
        0xc5, 0x93, 0x2b, 0x85, 0x8c, // time stamp 2026-11-21T12:01:00.300Z = 848_577_660_300 ms since 2000-01-01 = 0xC5_932B_858C
        0x00, 0x03,                   // waypoint number 3 (ROLE2)
        0x22, 0x55, 0x1b, 0x14,       // waypoint to latitude 48.28 deg: 48.28 / 180 * 2^31 = 576_002_836.3 -> 576_002_836 = 0x2255_1B14
        0x08, 0x4e, 0x47, 0x74,       // waypoint to longitude 11.68 deg: 11.68 / 180 * 2^31 = 139_347_827.8 -> 139_347_828 = 0x084E_4774
        0x00,                         // location type 0: absolute
        0x00, 0x17, 0x70,             // waypoint to altitude 120 m: 120 / 0.02 = 6000 = 0x00_1770
        0x03,                         // waypoint altitude type 3: WGS-84
        0x01,                         // altitude change behaviour 1
        0x00, 0x32,                   // waypoint to speed 25 m/s: 25 / 0.5 = 50 = 0x0032
        0x00,                         // waypoint speed type 0: indicated airspeed
        0x00, 0x00,                   // next waypoint 0: last waypoint
        0x00,                         // turn type 0: fly-by
        0x01,                         // optional messages: bit 0 = a #13006 RF centre follows
        0x01,                         // waypoint type 1: radius-to-fix
        0x02,                         // limit type 2
        0x00, 0x05,                   // loop limit 5
        0xc5, 0x93, 0x30, 0x18, 0x40, // arrival time 2026-11-21T12:06:00.000Z = 848_577_960_000 ms since 2000-01-01 = 0xC5_9330_1840
        0x00, 0x00, 0x2a,             // activity ID 42 = 0x00_002A
        // checksum
        0x00, 0x00, 0x0d, 0x83,       // checksum: byte sum of header and data = 3459 = 0x0000_0D83
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> UaPositionWaypoint {
        UaPositionWaypoint {
            time_stamp: Timestamp::from_millis(848_577_660_300).unwrap(),
            waypoint_number: 3,
            latitude: Angle::from_raw(576_002_836),
            longitude: Angle::from_raw(139_347_828),
            location_type: Some(LocationType::Absolute),
            altitude: Altitude::from_metres(120.0).unwrap(),
            altitude_type: Some(AltitudeType::Wgs84),
            altitude_change_behaviour: Some(1),
            speed: Speed::from_mps(25.0).unwrap(),
            speed_type: Some(SpeedType::IndicatedAirspeed),
            next_waypoint: 0,
            turn_type: TurnType::FlyBy,
            optional_messages: Some(1),
            leg_type: LegType::RadiusToFix,
            limit_type: Some(2),
            loop_limit: Some(5),
            arrival_time: Some(Timestamp::from_millis(848_577_960_000).unwrap()),
            activity_id: U3::new(42),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:01:00.300Z");
        assert!((m.latitude.degrees() - 48.28).abs() < Angle::LSB_DEGREES);
        assert!((m.longitude.degrees() - 11.68).abs() < Angle::LSB_DEGREES);
        assert_eq!(Angle::from_degrees(48.28).unwrap(), m.latitude);
        assert_eq!(Angle::from_degrees(11.68).unwrap(), m.longitude);
        assert_eq!(m.altitude.raw(), 6000);
        assert_eq!(m.altitude.metres(), 120.0);
        assert_eq!(m.speed.raw(), 50);
        assert_eq!(m.speed.mps(), 25.0);
        assert_eq!(
            m.arrival_time.unwrap().to_string(),
            "2026-11-21T12:06:00.000Z"
        );
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#13002 UA Position Waypoint: waypoint 3: 48.280000 N 11.680000 E, 120.0 m WGS-84, 25.0 m/s indicated airspeed, fly-by, radius-to-fix, arrival 2026-11-21T12:06:00.000Z, last",
        );
    }

    #[test]
    fn display_without_the_optional_fields() {
        let mut m = repr();
        (m.altitude_type, m.speed_type, m.arrival_time) = (None, None, None);
        (m.next_waypoint, m.leg_type) = (4, LegType::TrackToFix);
        super::super::assert_display(
            m,
            "#13002 UA Position Waypoint: waypoint 3: 48.280000 N 11.680000 E, 120.0 m, 25.0 m/s, fly-by, track-to-fix, next 4",
        );
    }
}
