//! #50001 Mission Report (ICD §4, ext, §8): the FCC's answer to #13000 mode 7, one message per
//! entry: the active lists first, then each staged mission, with their counts, the onboard
//! geofence check of ICD §7 and the checksums of ICD §11.

use core::fmt;

use super::{MessageBody, MessageType, reader};
use crate::wire::enums::GeofenceCheck;
use crate::wire::error::{EncodeError, MessageError, Reason};
use crate::wire::field::{Checksum, Text, Timestamp};
use crate::wire::presence::Writer;

/// #50001. Acknowledged by the GCS as a download message is (ICD §8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MissionReport {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: 1..=Report Count.
    pub report_index: u8,
    /// Bit 2, M: entries in this report, the active lists first, then each staged mission.
    pub report_count: u8,
    /// Bit 3: empty for the active lists, else the staged mission.
    pub mission_id: Option<Text<20>>,
    /// Bit 4, M: waypoints of the entry's valid waypoint list; 0 = none.
    pub waypoint_count: u16,
    /// Bit 5, M: areas of the entry's valid area list; 0 = none.
    pub area_count: u8,
    /// Bit 6, M: the onboard geofence check of ICD §7 for the entry's lists.
    pub geofence_check: GeofenceCheck,
    /// Bit 7: why the check failed.
    pub reason: Option<Reason>,
    /// Bit 8 (ICD §11): the checksum of the waypoint list (with take-off height and route);
    /// absent when there is none.
    pub mission_checksum: Option<Checksum>,
    /// Bit 9 (ICD §11): the checksum of the area list; absent when there is none.
    pub area_checksum: Option<Checksum>,
}

impl MessageBody for MissionReport {
    const TYPE: MessageType = MessageType::MissionReport;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Report Index",
        "Report Count",
        "Mission ID",
        "Waypoint Count",
        "Area Count",
        "Geofence Check",
        "Reason",
        "Mission Checksum",
        "Area Checksum",
    ];
    const PV_BYTES: usize = 2;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let report_index: u8 = r.mandatory(1)?;
        let report_count: u8 = r.mandatory(2)?;
        // An index names one of the entries: 1..=Report Count (so a count of 0 has none).
        r.in_range(1, report_index, (1..=report_count).contains(&report_index))?;
        let m = Self {
            time_stamp,
            report_index,
            report_count,
            mission_id: r.optional(3)?,
            waypoint_count: r.mandatory(4)?,
            area_count: r.mandatory(5)?,
            geofence_check: r.mandatory(6)?,
            reason: r.optional(7)?,
            mission_checksum: r.optional(8)?,
            area_checksum: r.optional(9)?,
        };
        r.finish()?;
        Ok(m)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.report_index)?;
        w.field(2, &self.report_count)?;
        w.optional(3, self.mission_id.as_ref())?;
        w.field(4, &self.waypoint_count)?;
        w.field(5, &self.area_count)?;
        w.field(6, &self.geofence_check)?;
        w.optional(7, self.reason.as_ref())?;
        w.optional(8, self.mission_checksum.as_ref())?;
        w.optional(9, self.area_checksum.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#50001 Mission Report: 1 of 3, active lists, 12 waypoints, 3 areas, geofence check passed,
/// mission checksum 0x1A2B3C4D, area checksum 0xCBF43926`.
impl fmt::Display for MissionReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} of {}",
            Self::TYPE,
            self.report_index,
            self.report_count
        )?;
        match self.mission_id {
            Some(id) if id.is_empty() => f.write_str(", active lists")?,
            Some(id) => write!(f, ", mission {}", id.as_str())?,
            None => {}
        }
        super::count(f, self.waypoint_count, "waypoint")?;
        super::count(f, self.area_count.into(), "area")?;
        write!(f, ", geofence check {}", self.geofence_check.name())?;
        super::reason(f, self.reason)?;
        super::optional(f, "mission checksum", self.mission_checksum)?;
        super::optional(f, "area checksum", self.area_checksum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #50001 entry 2 of 3: the staged mission MEDEVAC-1, 12 waypoints and 3 areas that fail
    /// the geofence check, every field present; FCC to GCS, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 62] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x2a,                                     // message length: 42 bytes of message data
        0x0b, 0x00, 0x00, 0x01,                         // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,                         // destination ID: GCS 0x0A00_0001
        0xc3, 0x51,                                     // message type 50001 = 0xC351
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x03, 0xff,                                     // presence vector 0x03FF (U2): bits 0..=9
        0xc5, 0x93, 0x2e, 0x43, 0x80,                   // time stamp 2026-11-21T12:04:00.000Z = 848_577_840_000 ms since 2000-01-01 = 0xC5_932E_4380
        0x02,                                           // report index 2
        0x03,                                           // report count 3
        b'M', b'E', b'D', b'E', b'V', b'A', b'C', b'-', // mission ID "MEDEVAC-1" (Char20)
        b'1',
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 11 bytes
        0x00, 0x00, 0x00,
        0x00, 0x0c,                                     // waypoint count 12
        0x03,                                           // area count 3
        0x02,                                           // geofence check 2: failed
        0x0e,                                           // reason 14: GeofenceViolation
        0x1a, 0x2b, 0x3c, 0x4d,                         // mission checksum 0x1A2B3C4D (U4)
        0xcb, 0xf4, 0x39, 0x26,                         // area checksum 0xCBF43926 (U4)
        // checksum
        0x00, 0x00, 0x0d, 0x29,                         // checksum: byte sum of header and data = 3369 = 0x0000_0D29
    ];

    /// FCC to GCS, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> MissionReport {
        MissionReport {
            time_stamp: Timestamp::from_millis(848_577_840_000).unwrap(),
            report_index: 2,
            report_count: 3,
            mission_id: Some(Text::new("MEDEVAC-1").unwrap()),
            waypoint_count: 12,
            area_count: 3,
            geofence_check: GeofenceCheck::Failed,
            reason: Some(Reason::GeofenceViolation),
            mission_checksum: Some(Checksum::new(0x1A2B_3C4D)),
            area_checksum: Some(Checksum::new(0xCBF4_3926)),
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:04:00.000Z");
        assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-1");
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#50001 Mission Report: 2 of 3, mission MEDEVAC-1, 12 waypoints, 3 areas, geofence check failed (GeofenceViolation (14)), mission checksum 0x1A2B3C4D, area checksum 0xCBF43926",
        );
    }

    #[test]
    fn display_active_lists() {
        super::super::assert_display(
            MissionReport {
                report_index: 1,
                mission_id: Some(Text::default()),
                geofence_check: GeofenceCheck::Passed,
                reason: None,
                ..repr()
            },
            "#50001 Mission Report: 1 of 3, active lists, 12 waypoints, 3 areas, geofence check passed, mission checksum 0x1A2B3C4D, area checksum 0xCBF43926",
        );
    }

    #[test]
    fn display_empty_lists() {
        super::super::assert_display(
            MissionReport {
                report_index: 1,
                report_count: 1,
                mission_id: Some(Text::default()),
                waypoint_count: 0,
                area_count: 0,
                geofence_check: GeofenceCheck::NotRun,
                reason: None,
                mission_checksum: None,
                area_checksum: None,
                ..repr()
            },
            "#50001 Mission Report: 1 of 1, active lists, 0 waypoints, 0 areas, geofence check not run",
        );
    }
}
