//! #13001 UA Route (ICD §4): route properties, the initial waypoint and whether the route is
//! bidirectional (ICD §5.1 step 4), and (edition 2) the wind the mission was checked in, which
//! sizes the turns the FCC flies and checks (ICD §7).

use core::fmt;

use super::{MessageBody, MessageType, is_waypoint_number, reader};
use crate::wire::enums::RouteType;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{Speed, Text, Timestamp, U3};
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
    /// Bit 5 (ext, ICD §7 "Turns in wind"): the wind speed the mission was planned and checked
    /// in; the FCC flies and checks every turn at the radius this wind forces. Absent: calm.
    pub planning_wind: Option<Speed>,
}

impl MessageBody for UaRoute {
    const TYPE: MessageType = MessageType::UaRoute;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Initial Waypoint Number",
        "Route ID",
        "Route Type",
        "Activity ID",
        "Planning Wind Speed",
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
            planning_wind: r.optional(5)?,
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
        w.optional(5, self.planning_wind.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#13001 UA Route: initial waypoint 1, bidirectional, flight, route TROL-CCP`.
impl fmt::Display for UaRoute {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: initial waypoint {}, {}",
            Self::TYPE,
            self.initial_waypoint,
            if self.bidirectional {
                "bidirectional"
            } else {
                "one-way"
            }
        )?;
        if let Some(t) = self.route_type {
            write!(f, ", {}", t.name())?;
        }
        if let Some(w) = self.planning_wind {
            write!(f, ", planned in wind {} m/s", w.mps())?;
        }
        super::optional(f, "route", self.route_id.as_ref().map(Text::as_str))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #13001 route of mission 1, every field present, bidirectional; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 65] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x2d,                                     // message length: 45 bytes of message data
        0x0a, 0x00, 0x00, 0x01,                         // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,                         // destination ID: FCC 0x0B00_0001
        0x32, 0xc9,                                     // message type 13001 = 0x32C9
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x1f,                                           // presence vector 0x1F: bits 0..=4
        0xc5, 0x93, 0x2b, 0x86, 0x54,                   // time stamp 2026-11-21T12:01:00.500Z = 848_577_660_500 ms since 2000-01-01 = 0xC5_932B_8654
        0x00, 0x01,                                     // initial waypoint number 1 (TROL)
        b'T', b'R', b'O', b'L', b'-', b'C', b'C', b'P', // route ID "TROL-CCP" (Char33)
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 25 bytes
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00,
        0x02,                                           // route type 2: flight
        0x00, 0x00, 0x01,                               // activity ID: bit 0 set = bidirectional
        // checksum
        0x00, 0x00, 0x09, 0x29,                         // checksum: byte sum of header and data = 2345 = 0x0000_0929
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> UaRoute {
        UaRoute {
            time_stamp: Timestamp::from_millis(848_577_660_500).unwrap(),
            initial_waypoint: 1,
            route_id: Some(Text::new("TROL-CCP").unwrap()),
            route_type: Some(RouteType::Flight),
            bidirectional: true,
            planning_wind: None,
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:01:00.500Z");
        assert_eq!(m.route_id.unwrap().as_str(), "TROL-CCP");
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#13001 UA Route: initial waypoint 1, bidirectional, flight, route TROL-CCP",
        );
    }

    #[test]
    fn display_one_way() {
        super::super::assert_display(
            UaRoute {
                route_id: None,
                route_type: None,
                bidirectional: false,
                planning_wind: None,
                ..repr()
            },
            "#13001 UA Route: initial waypoint 1, one-way",
        );
    }
}
