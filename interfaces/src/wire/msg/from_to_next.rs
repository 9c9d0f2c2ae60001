//! #4001 FROM-TO-NEXT Waypoint States (ICD §4, std field order; paper §3.1.7): where the aircraft
//! comes from, flies to and goes next. Sent on every change of the triple, never acknowledged.

use core::fmt;

use super::{GeoPoint, MessageBody, MessageType, latitude, reader};
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

/// `<number> (<position>)`, the number alone without a position, `-` for none (0 or absent).
fn state(
    f: &mut fmt::Formatter<'_>,
    label: &str,
    number: Option<u16>,
    latitude: Option<Angle>,
    longitude: Option<Angle>,
) -> fmt::Result {
    match (number, latitude, longitude) {
        (Some(0) | None, _, _) => write!(f, "{label} -"),
        (Some(n), Some(latitude), Some(longitude)) => write!(
            f,
            "{label} {n} ({})",
            GeoPoint {
                latitude,
                longitude
            }
        ),
        (Some(n), _, _) => write!(f, "{label} {n}"),
    }
}

/// `#4001 FROM-TO-NEXT Waypoint States: FROM 1 (48.275000 N 11.645000 E), TO 2 (...), NEXT -`.
impl fmt::Display for FromToNext {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", Self::TYPE)?;
        let (from, to, next) = (&self.from, &self.to, &self.next);
        state(
            f,
            "FROM",
            from.waypoint_number,
            from.latitude,
            from.longitude,
        )?;
        state(f, ", TO", to.waypoint_number, to.latitude, to.longitude)?;
        state(
            f,
            ", NEXT",
            next.waypoint_number,
            next.latitude,
            next.longitude,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #4001 on mission 2: FROM CCP (1), TO W1 (2), NEXT ROLE2 (3), all 21 fields; FCC to GCS, no ack.
    #[rustfmt::skip]
    static FRAME: [u8; 89] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x45,                   // message length: 69 bytes of message data
        0x0b, 0x00, 0x00, 0x01,       // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,       // destination ID: GCS 0x0A00_0001
        0x0f, 0xa1,                   // message type 4001 = 0x0FA1
        0x28, 0x80,                   // properties: ack 0 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0x2880
        // message data
        0x1f, 0xff, 0xff,             // presence vector 0x1F_FFFF: bits 0..=20
        0xc5, 0x93, 0x2f, 0x2d, 0xe0, // time stamp 2026-11-21T12:05:00.000Z = 848_577_900_000 ms since 2000-01-01 = 0xC5_932F_2DE0
        0x03,                         // altitude type 3: WGS-84
        0x00,                         // speed type 0: indicated airspeed
        0x22, 0x54, 0x32, 0x10,       // from latitude 48.275 deg: 48.275 / 180 * 2^31 = 575_943_183.9 -> 575_943_184 = 0x2254_3210
        0x08, 0x47, 0xe8, 0x56,       // from longitude 11.645 deg: 11.645 / 180 * 2^31 = 138_930_261.6 -> 138_930_262 = 0x0847_E856
        0x00, 0x17, 0x70,             // from altitude 120 m: 120 / 0.02 = 6000 = 0x00_1770
        0xc5, 0x93, 0x2e, 0x6a, 0x90, // from time 2026-11-21T12:04:10.000Z = 848_577_850_000 ms since 2000-01-01 = 0xC5_932E_6A90
        0x00, 0x01,                   // from waypoint number 1 (CCP)
        0x22, 0x54, 0xbd, 0xdf,       // to latitude 48.278 deg: 48.278 / 180 * 2^31 = 575_978_975.3 -> 575_978_975 = 0x2254_BDDF
        0x08, 0x4a, 0x46, 0x2e,       // to longitude 11.658 deg: 11.658 / 180 * 2^31 = 139_085_357.6 -> 139_085_358 = 0x084A_462E
        0x00, 0x17, 0x70,             // to altitude 120 m: 120 / 0.02 = 6000 = 0x00_1770
        0x00, 0x32,                   // to speed 25 m/s: 25 / 0.5 = 50 = 0x0032
        0xc5, 0x93, 0x2f, 0x7c, 0x00, // to time 2026-11-21T12:05:20.000Z = 848_577_920_000 ms since 2000-01-01 = 0xC5_932F_7C00
        0x00, 0x02,                   // to waypoint number 2 (W1)
        0x22, 0x55, 0x1b, 0x14,       // next latitude 48.28 deg: 48.28 / 180 * 2^31 = 576_002_836.3 -> 576_002_836 = 0x2255_1B14
        0x08, 0x4e, 0x47, 0x74,       // next longitude 11.68 deg: 11.68 / 180 * 2^31 = 139_347_827.8 -> 139_347_828 = 0x084E_4774
        0x00, 0x17, 0x70,             // next altitude 120 m: 120 / 0.02 = 6000 = 0x00_1770
        0x00, 0x32,                   // next speed 25 m/s: 25 / 0.5 = 50 = 0x0032
        0xc5, 0x93, 0x30, 0x18, 0x40, // next time 2026-11-21T12:06:00.000Z = 848_577_960_000 ms since 2000-01-01 = 0xC5_9330_1840
        0x00, 0x03,                   // next waypoint number 3 (ROLE2)
        0x00,                         // loiter configuration report validity 0
        // checksum
        0x00, 0x00, 0x17, 0x9c,       // checksum: byte sum of header and data = 6044 = 0x0000_179C
    ];

    /// FCC to GCS; #4001 is never acknowledged.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: false,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn ts(millis: u64) -> Option<Timestamp> {
        Timestamp::from_millis(millis)
    }

    fn repr() -> FromToNext {
        let altitude = Some(Altitude::from_metres(120.0).unwrap());
        let speed = Some(Speed::from_mps(25.0).unwrap());
        FromToNext {
            time_stamp: ts(848_577_900_000).unwrap(),
            altitude_type: Some(AltitudeType::Wgs84),
            speed_type: Some(SpeedType::IndicatedAirspeed),
            from: FromWaypointState {
                latitude: Some(Angle::from_raw(575_943_184)),
                longitude: Some(Angle::from_raw(138_930_262)),
                altitude,
                time: ts(848_577_850_000),
                waypoint_number: Some(1),
            },
            to: WaypointState {
                latitude: Some(Angle::from_raw(575_978_975)),
                longitude: Some(Angle::from_raw(139_085_358)),
                altitude,
                speed,
                time: ts(848_577_920_000),
                waypoint_number: Some(2),
            },
            next: WaypointState {
                latitude: Some(Angle::from_raw(576_002_836)),
                longitude: Some(Angle::from_raw(139_347_828)),
                altitude,
                speed,
                time: ts(848_577_960_000),
                waypoint_number: Some(3),
            },
            loiter_configuration_report_validity: Some(0),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:05:00.000Z");
        let points = [
            (m.from.latitude, m.from.longitude, 48.275, 11.645),
            (m.to.latitude, m.to.longitude, 48.278, 11.658),
            (m.next.latitude, m.next.longitude, 48.28, 11.68),
        ];
        for (lat, lon, lat_deg, lon_deg) in points {
            let (lat, lon) = (lat.unwrap(), lon.unwrap());
            assert!((lat.degrees() - lat_deg).abs() < Angle::LSB_DEGREES);
            assert!((lon.degrees() - lon_deg).abs() < Angle::LSB_DEGREES);
            assert_eq!(Angle::from_degrees(lat_deg).unwrap(), lat);
            assert_eq!(Angle::from_degrees(lon_deg).unwrap(), lon);
        }
        for altitude in [m.from.altitude, m.to.altitude, m.next.altitude] {
            assert_eq!(altitude.unwrap().raw(), 6000);
        }
        for speed in [m.to.speed, m.next.speed] {
            assert_eq!(speed.unwrap().mps(), 25.0);
        }
        let times = [m.from.time, m.to.time, m.next.time].map(|t| t.unwrap().to_string());
        assert_eq!(
            times,
            [
                "2026-11-21T12:04:10.000Z",
                "2026-11-21T12:05:20.000Z",
                "2026-11-21T12:06:00.000Z"
            ]
        );
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#4001 FROM-TO-NEXT Waypoint States: FROM 1 (48.275000 N 11.645000 E), TO 2 (48.278000 N 11.658000 E), NEXT 3 (48.280000 N 11.680000 E)",
        );
    }

    #[test]
    fn display_last_leg() {
        super::super::assert_display(
            {
                let mut m = repr();
                m.from = FromWaypointState::default();
                m.next.waypoint_number = Some(0);
                m.to.latitude = None;
                m
            },
            "#4001 FROM-TO-NEXT Waypoint States: FROM -, TO 2, NEXT -",
        );
    }
}
