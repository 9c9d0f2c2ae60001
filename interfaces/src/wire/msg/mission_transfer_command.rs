//! #13000 Mission Transfer Command (ICD §4): clear, transmit (assemble and activate), receive
//! (download) and cancel (ICD §5.1, §5.2); in edition 2 also delete, report, stage, download and
//! load staged missions (ICD §8), with the Transfer Window of a download request (ICD §10.2) and
//! the Mission Checksum of a closer (ICD §11).

use core::fmt;

use super::{MessageBody, MessageType, ext_field, reader, staged_mission_id};
use crate::wire::enums::MissionPlanMode;
use crate::wire::error::{Cause, EncodeError, MessageError};
use crate::wire::field::{Checksum, Text, Timestamp, TransferWindow, U3};
use crate::wire::presence::Writer;

/// #13000.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MissionTransferCommand {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M for modes 6, 8, 9 (not empty) and 10: the staged mission (ICD §8); with modes
    /// 1, 2, 3 and 5 the mission's name, informational; with mode 7 absent or empty.
    pub mission_id: Option<Text<20>>,
    /// Bit 2, M.
    pub mode: MissionPlanMode,
    /// Bit 3, M for modes 2 and 8: the number of waypoints the flight plan must have.
    pub waypoint_number: Option<u16>,
    /// Bit 4.
    pub route_id: Option<Text<33>>,
    /// Bit 5.
    pub activity_id: Option<U3>,
    /// Bit 6 (ext, ICD §10.2), with modes 3 and 9 only: data messages the requester accepts in
    /// flight; absent = 1. Its presence makes the request an edition-2 request.
    pub transfer_window: Option<TransferWindow>,
    /// Bit 7 (ext, ICD §11), with modes 2 and 8 only: the checksum of the mission the sender
    /// means.
    pub mission_checksum: Option<Checksum>,
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
        "Transfer Window",
        "Mission Checksum",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        use MissionPlanMode as Mode;
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let mission_id: Option<Text<20>> = r.optional(1)?;
        let mode = r.mandatory(2)?;
        // Mission ID (ICD §8): modes 6, 8 and 9 name a staged mission, so it must be there and
        // not empty; mode 10 needs it too, empty meaning the active list; mode 7 reports every
        // mission, so a Mission ID that names one contradicts it.
        match mode {
            Mode::DeleteStagedMission | Mode::StageMission | Mode::ReceiveStagedMission => {
                staged_mission_id(&r, 1, mission_id)?;
            }
            Mode::LoadWaypointBuffer => {
                r.require(1, mission_id)?;
            }
            Mode::ReportMissions if mission_id.is_some_and(|id| !id.is_empty()) => {
                return Err(r.error(1, Cause::Inconsistent));
            }
            _ => {}
        }
        let waypoint_number = r.optional(3)?;
        if matches!(mode, Mode::TransmitMission | Mode::StageMission) {
            r.require(3, waypoint_number)?;
        }
        let route_id = r.optional(4)?;
        let activity_id = r.optional(5)?;
        // The extension fields only with the modes their table names (ICD §3); any other mode
        // is refused, not ignored (see `ext_field`). The window's range 1..=32 is its codec's.
        let transfer_window = r.optional(6)?;
        let transfer_window = ext_field(
            &r,
            6,
            transfer_window,
            matches!(mode, Mode::ReceiveMission | Mode::ReceiveStagedMission),
        )?;
        let mission_checksum = r.optional(7)?;
        let mission_checksum = ext_field(
            &r,
            7,
            mission_checksum,
            matches!(mode, Mode::TransmitMission | Mode::StageMission),
        )?;
        r.finish()?;
        Ok(Self {
            time_stamp,
            mission_id,
            mode,
            waypoint_number,
            route_id,
            activity_id,
            transfer_window,
            mission_checksum,
        })
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.optional(1, self.mission_id.as_ref())?;
        w.field(2, &self.mode)?;
        w.optional(3, self.waypoint_number.as_ref())?;
        w.optional(4, self.route_id.as_ref())?;
        w.optional(5, self.activity_id.as_ref())?;
        w.optional(6, self.transfer_window.as_ref())?;
        w.optional(7, self.mission_checksum.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#13000 Mission Transfer Command: mode 2 transmit mission, 2 waypoints, mission MEDEVAC-1,
/// checksum 0x1A2B3C4D`.
impl fmt::Display for MissionTransferCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: mode {}", Self::TYPE, self.mode.numbered())?;
        if let Some(n) = self.waypoint_number {
            super::count(f, n, "waypoint")?;
        }
        super::optional(f, "mission", self.mission_id.as_ref().map(Text::as_str))?;
        super::optional(f, "route", self.route_id.as_ref().map(Text::as_str))?;
        super::optional(f, "transfer window", self.transfer_window)?;
        super::optional(f, "checksum", self.mission_checksum)
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
            transfer_window: None,
            mission_checksum: None,
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

    /// #13000 mode 2 transmit mission with the Mission Checksum of ICD §11 (ext), the closer of
    /// an edition-2 upload; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_CHECKSUM: [u8; 53] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x21,                                     // message length: 33 bytes of message data
        0x0a, 0x00, 0x00, 0x01,                         // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,                         // destination ID: FCC 0x0B00_0001
        0x32, 0xc8,                                     // message type 13000 = 0x32C8
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x8f,                                           // presence vector 0x8F: bits 0..=3 and 7
        0xc5, 0x93, 0x2b, 0x86, 0xb8,                   // time stamp 2026-11-21T12:01:00.600Z = 848_577_660_600 ms since 2000-01-01 = 0xC5_932B_86B8
        b'M', b'E', b'D', b'E', b'V', b'A', b'C', b'-', // mission ID "MEDEVAC-1" (Char20)
        b'1',
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 11 bytes
        0x00, 0x00, 0x00,
        0x02,                                           // mission plan mode 2: transmit mission
        0x00, 0x02,                                     // waypoint number: 2 waypoints
        0x1a, 0x2b, 0x3c, 0x4d,                         // mission checksum 0x1A2B3C4D (U4)
        // checksum
        0x00, 0x00, 0x0a, 0xcd,                         // checksum: byte sum of header and data = 2765 = 0x0000_0ACD
    ];

    fn with_checksum() -> MissionTransferCommand {
        MissionTransferCommand {
            route_id: None,
            activity_id: None,
            mission_checksum: Some(Checksum::new(0x1A2B_3C4D)),
            ..repr()
        }
    }

    #[test]
    fn golden_checksum() {
        super::super::assert_golden(&FRAME_CHECKSUM, ENVELOPE, with_checksum().into());
    }

    #[test]
    fn display_checksum() {
        super::super::assert_display(
            with_checksum(),
            "#13000 Mission Transfer Command: mode 2 transmit mission, 2 waypoints, mission MEDEVAC-1, checksum 0x1A2B3C4D",
        );
    }

    /// #13000 mode 3 receive mission with a Transfer Window of 8 (ext, ICD §10.2): an edition-2
    /// download request; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_WINDOW: [u8; 28] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x08,                   // message length: 8 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x32, 0xc8,                   // message type 13000 = 0x32C8
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x45,                         // presence vector 0x45: bits 0, 2 and 6
        0xc5, 0x93, 0x2b, 0x88, 0x48, // time stamp 2026-11-21T12:01:01.000Z = 848_577_661_000 ms since 2000-01-01 = 0xC5_932B_8848
        0x03,                         // mission plan mode 3: receive mission
        0x08,                         // transfer window: 8 data messages in flight (U1)
        // checksum
        0x00, 0x00, 0x06, 0xe2,       // checksum: byte sum of header and data = 1762 = 0x0000_06E2
    ];

    fn with_window() -> MissionTransferCommand {
        MissionTransferCommand {
            time_stamp: Timestamp::from_millis(848_577_661_000).unwrap(),
            mission_id: None,
            mode: MissionPlanMode::ReceiveMission,
            waypoint_number: None,
            route_id: None,
            activity_id: None,
            transfer_window: TransferWindow::new(8),
            mission_checksum: None,
        }
    }

    #[test]
    fn golden_window() {
        super::super::assert_golden(&FRAME_WINDOW, ENVELOPE, with_window().into());
    }

    #[test]
    fn display_window() {
        super::super::assert_display(
            with_window(),
            "#13000 Mission Transfer Command: mode 3 receive mission, transfer window 8",
        );
    }

    #[test]
    fn display_stage() {
        super::super::assert_display(
            MissionTransferCommand {
                mode: MissionPlanMode::StageMission,
                route_id: None,
                ..with_checksum()
            },
            "#13000 Mission Transfer Command: mode 8 stage mission, 2 waypoints, mission MEDEVAC-1, checksum 0x1A2B3C4D",
        );
    }
}
