//! #13000 Mission Transfer Command (ICD §4): clear, transmit (assemble and activate), receive
//! (download) and cancel (ICD §5.1, §5.2).

use core::fmt;

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

/// `#13000 Mission Transfer Command: mode 2 transmit mission, 2 waypoints, mission MEDEVAC-1`.
impl fmt::Display for MissionTransferCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: mode {}", Self::TYPE, self.mode.numbered())?;
        if let Some(n) = self.waypoint_number {
            super::count(f, n, "waypoint")?;
        }
        super::optional(f, "mission", self.mission_id.as_ref().map(Text::as_str))?;
        super::optional(f, "route", self.route_id.as_ref().map(Text::as_str))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #13000 mode 2 transmit mission 1 (TROL, CCP), every field present; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 85] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x41,                                     // message length: 65 bytes of message data
        0x0a, 0x00, 0x00, 0x01,                         // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,                         // destination ID: FCC 0x0B00_0001
        0x32, 0xc8,                                     // message type 13000 = 0x32C8
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x3f,                                           // presence vector 0x3F: bits 0..=5
        0xc5, 0x93, 0x2b, 0x86, 0xb8,                   // time stamp 2026-11-21T12:01:00.600Z = 848_577_660_600 ms since 2000-01-01 = 0xC5_932B_86B8
        b'M', b'E', b'D', b'E', b'V', b'A', b'C', b'-', // mission ID "MEDEVAC-1" (Char20)
        b'1',
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 11 bytes
        0x00, 0x00, 0x00,
        0x02,                                           // mission plan mode 2: transmit mission
        0x00, 0x02,                                     // waypoint number: 2 waypoints (TROL, CCP)
        b'T', b'R', b'O', b'L', b'-', b'C', b'C', b'P', // route ID "TROL-CCP" (Char33)
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 25 bytes
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00,
        0x00, 0x00, 0x00,                               // activity ID 0
        // checksum
        0x00, 0x00, 0x0c, 0x13,                         // checksum: byte sum of header and data = 3091 = 0x0000_0C13
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> MissionTransferCommand {
        MissionTransferCommand {
            time_stamp: Timestamp::from_millis(848_577_660_600).unwrap(),
            mission_id: Some(Text::new("MEDEVAC-1").unwrap()),
            mode: MissionPlanMode::TransmitMission,
            waypoint_number: Some(2),
            route_id: Some(Text::new("TROL-CCP").unwrap()),
            activity_id: U3::new(0),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:01:00.600Z");
        assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-1");
        assert_eq!(m.route_id.unwrap().as_str(), "TROL-CCP");
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#13000 Mission Transfer Command: mode 2 transmit mission, 2 waypoints, mission MEDEVAC-1, route TROL-CCP",
        );
    }

    #[test]
    fn display_clear() {
        super::super::assert_display(
            MissionTransferCommand {
                mission_id: None,
                mode: MissionPlanMode::ClearMission,
                waypoint_number: None,
                route_id: None,
                ..repr()
            },
            "#13000 Mission Transfer Command: mode 1 clear mission",
        );
    }
}
