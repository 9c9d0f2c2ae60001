//! #2011 Area Transmission Command (ICD §4, icd): opens, closes, cancels and clears area
//! transfers (ICD §5.3, §5.4); in edition 2 also stages and downloads the areas of a staged
//! mission (ICD §8), with the Transfer Window of a download request (ICD §10.2) or the Area
//! Checksum of a closer (ICD §11) in field 7.

use core::fmt;

use super::{MessageBody, MessageType, ext_field, reader, staged_mission_id};
use crate::wire::enums::AreaTransferMode;
use crate::wire::error::{Cause, EncodeError, MessageError};
use crate::wire::field::{Checksum, SafetyOffset, Text, Timestamp, TransferWindow, U3};
use crate::wire::presence::{Reader, Writer};

/// #2011 field 7 (ext): one U4 that is a Transfer Window or an Area Checksum by the mode (ICD §4,
/// rev. 2), so that the presence vector stays one byte and an edition-1 peer parses every #2011.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum WindowOrChecksum {
    /// With modes 3 and 8 (ICD §10.2): data messages the requester accepts in flight.
    TransferWindow(TransferWindow),
    /// With modes 2 and 7, the checksum of the area list the sender means; with mode 4, of the
    /// list sent (ICD §11).
    AreaChecksum(Checksum),
}

impl WindowOrChecksum {
    /// The U4 on the wire.
    pub fn wire_value(self) -> u32 {
        match self {
            Self::TransferWindow(w) => w.into(),
            Self::AreaChecksum(c) => c.value(),
        }
    }

    /// The U4 `value` of field 7 read as `mode` says: a window (1..=32, else `OutOfRange`) with
    /// modes 3 and 8, a checksum with modes 2, 4 and 7, and with any other mode a field its
    /// table does not name (`Inconsistent`, see `ext_field`).
    fn decode(r: &Reader<'_>, mode: AreaTransferMode, value: u32) -> Result<Self, MessageError> {
        use AreaTransferMode as Mode;
        match mode {
            Mode::InitiateDownload | Mode::InitiateStagedDownload => {
                TransferWindow::try_from(value)
                    .map(Self::TransferWindow)
                    .map_err(|_| {
                        r.error(
                            7,
                            Cause::OutOfRange {
                                value: i64::from(value),
                            },
                        )
                    })
            }
            Mode::UploadComplete | Mode::DownloadComplete | Mode::UploadCompleteStaged => {
                Ok(Self::AreaChecksum(Checksum::new(value)))
            }
            Mode::InitiateUpload | Mode::Cancel | Mode::ClearAreas => {
                Err(r.error(7, Cause::Inconsistent))
            }
        }
    }
}

/// `transfer window 8` or `checksum 0x1A2B3C4D`.
impl fmt::Display for WindowOrChecksum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TransferWindow(w) => write!(f, "transfer window {w}"),
            Self::AreaChecksum(c) => write!(f, "checksum {c}"),
        }
    }
}

/// #2011.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AreaTransmissionCommand {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M.
    pub mode: AreaTransferMode,
    /// Bit 2, M for modes 1, 2, 4 and 7: areas that will follow or followed.
    pub loop_count: Option<u8>,
    /// Bit 3: modes 3 and 8, 0 = all areas, else that one.
    pub area_id: Option<u16>,
    /// Bit 4: distance the geofence keeps from every area border.
    pub safety_offset: Option<SafetyOffset>,
    /// Bit 5.
    pub activity_id: Option<U3>,
    /// Bit 6 (ext, ICD §8), M for modes 7 and 8 (not empty), with no other mode: the staged
    /// mission.
    pub mission_id: Option<Text<20>>,
    /// Bit 7 (ext, ICD §10.2, §11): the Transfer Window with modes 3 and 8, the Area Checksum
    /// with modes 2, 4 and 7.
    pub window_or_checksum: Option<WindowOrChecksum>,
}

impl AreaTransmissionCommand {
    /// Field 7 as the checksum of an area list (modes 2, 4 and 7, ICD §11).
    pub fn area_checksum(&self) -> Option<Checksum> {
        match self.window_or_checksum {
            Some(WindowOrChecksum::AreaChecksum(c)) => Some(c),
            _ => None,
        }
    }

    /// Field 7 as the Transfer Window of a download request (modes 3 and 8, ICD §10.2).
    pub fn transfer_window(&self) -> Option<TransferWindow> {
        match self.window_or_checksum {
            Some(WindowOrChecksum::TransferWindow(w)) => Some(w),
            _ => None,
        }
    }
}

impl MessageBody for AreaTransmissionCommand {
    const TYPE: MessageType = MessageType::AreaTransmissionCommand;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Area Transfer Mode",
        "Area Loop Count",
        "Area ID",
        "Safety Offset",
        "Activity ID",
        "Mission ID",
        "Transfer Window or Area Checksum",
    ];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        use AreaTransferMode as Mode;
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let mode = r.mandatory(1)?;
        let loop_count = r.optional(2)?;
        if matches!(
            mode,
            Mode::InitiateUpload
                | Mode::UploadComplete
                | Mode::DownloadComplete
                | Mode::UploadCompleteStaged
        ) {
            r.require(2, loop_count)?;
        }
        let area_id = r.optional(3)?;
        let safety_offset = r.optional(4)?;
        let activity_id = r.optional(5)?;
        // Mission ID (ICD §8): modes 7 and 8 name a staged mission; the field is an extension
        // that no other mode's table names (see `ext_field`).
        let mission_id = r.optional(6)?;
        let mission_id = match mode {
            Mode::UploadCompleteStaged | Mode::InitiateStagedDownload => {
                Some(staged_mission_id(&r, 6, mission_id)?)
            }
            _ => ext_field(&r, 6, mission_id, false)?,
        };
        let window_or_checksum = match r.optional::<u32>(7)? {
            Some(v) => Some(WindowOrChecksum::decode(&r, mode, v)?),
            None => None,
        };
        r.finish()?;
        Ok(Self {
            time_stamp,
            mode,
            loop_count,
            area_id,
            safety_offset,
            activity_id,
            mission_id,
            window_or_checksum,
        })
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.mode)?;
        w.optional(2, self.loop_count.as_ref())?;
        w.optional(3, self.area_id.as_ref())?;
        w.optional(4, self.safety_offset.as_ref())?;
        w.optional(5, self.activity_id.as_ref())?;
        w.optional(6, self.mission_id.as_ref())?;
        w.optional(
            7,
            self.window_or_checksum
                .map(WindowOrChecksum::wire_value)
                .as_ref(),
        )?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#2011 Area Transmission Command: mode 1 initiate upload, 3 areas, safety offset 25.0 m`.
impl fmt::Display for AreaTransmissionCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: mode {}", Self::TYPE, self.mode.numbered())?;
        if let Some(n) = self.loop_count {
            super::count(f, n.into(), "area")?;
        }
        // Area ID only means something to a download request (modes 3 and 8).
        if let (
            AreaTransferMode::InitiateDownload | AreaTransferMode::InitiateStagedDownload,
            Some(id),
        ) = (self.mode, self.area_id)
        {
            f.write_str(", ")?;
            super::areas(f, id)?;
        }
        super::optional(f, "mission", self.mission_id.as_ref().map(Text::as_str))?;
        if let Some(offset) = self.safety_offset {
            write!(f, ", safety offset {:.1} m", offset.metres())?;
        }
        if let Some(w) = self.window_or_checksum {
            write!(f, ", {w}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #2011 mode 1: initiate upload of 3 areas, every field present; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 35] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0f,                   // message length: 15 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x07, 0xdb,                   // message type 2011 = 0x07DB
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x3f,                         // presence vector 0x3F: bits 0..=5
        0xc5, 0x93, 0x2a, 0x9a, 0x00, // time stamp 2026-11-21T12:00:00.000Z = 848_577_600_000 ms since 2000-01-01 = 0xC5_932A_9A00
        0x01,                         // area transfer mode 1: initiate upload
        0x03,                         // area loop count 3
        0x00, 0x00,                   // area ID 0
        0x00, 0xfa,                   // safety offset 25 m: 25 / 0.1 = 250 = 0x00FA
        0x00, 0x00, 0x00,             // activity ID 0
        // checksum
        0x00, 0x00, 0x07, 0x87,       // checksum: byte sum of header and data = 1927 = 0x0000_0787
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> AreaTransmissionCommand {
        AreaTransmissionCommand {
            time_stamp: Timestamp::from_millis(848_577_600_000).unwrap(),
            mode: AreaTransferMode::InitiateUpload,
            loop_count: Some(3),
            area_id: Some(0),
            safety_offset: Some(SafetyOffset::from_metres(25.0).unwrap()),
            activity_id: U3::new(0),
            mission_id: None,
            window_or_checksum: None,
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:00:00.000Z");
        let offset = m.safety_offset.unwrap();
        assert_eq!(offset.raw(), 250);
        assert_eq!(offset.metres(), 25.0);
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#2011 Area Transmission Command: mode 1 initiate upload, 3 areas, safety offset 25.0 m",
        );
    }

    #[test]
    fn display_download() {
        super::super::assert_display(
            AreaTransmissionCommand {
                mode: AreaTransferMode::InitiateDownload,
                loop_count: None,
                area_id: Some(2),
                safety_offset: None,
                ..repr()
            },
            "#2011 Area Transmission Command: mode 3 initiate download, area 2",
        );
    }

    /// #2011 mode 2 upload complete of 3 areas with the Area Checksum of ICD §11 (ext), the
    /// closer of an edition-2 upload; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_CHECKSUM: [u8; 32] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x0c,                   // message length: 12 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x07, 0xdb,                   // message type 2011 = 0x07DB
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x87,                         // presence vector 0x87: bits 0..=2 and 7
        0xc5, 0x93, 0x2b, 0x0f, 0x30, // time stamp 2026-11-21T12:00:30.000Z = 848_577_630_000 ms since 2000-01-01 = 0xC5_932B_0F30
        0x02,                         // area transfer mode 2: upload complete
        0x03,                         // area loop count 3
        0x1a, 0x2b, 0x3c, 0x4d,       // area checksum 0x1A2B3C4D (U4, mode 2)
        // checksum
        0x00, 0x00, 0x07, 0x47,       // checksum: byte sum of header and data = 1863 = 0x0000_0747
    ];

    fn with_checksum() -> AreaTransmissionCommand {
        AreaTransmissionCommand {
            time_stamp: Timestamp::from_millis(848_577_630_000).unwrap(),
            mode: AreaTransferMode::UploadComplete,
            loop_count: Some(3),
            area_id: None,
            safety_offset: None,
            activity_id: None,
            mission_id: None,
            window_or_checksum: Some(WindowOrChecksum::AreaChecksum(Checksum::new(0x1A2B_3C4D))),
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
            "#2011 Area Transmission Command: mode 2 upload complete, 3 areas, checksum 0x1A2B3C4D",
        );
    }

    /// #2011 mode 8: download all areas of the staged mission MEDEVAC-1 with a Transfer Window
    /// of 8 (ext, ICD §8, §10.2); GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_STAGED_DOWNLOAD: [u8; 53] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x21,                                     // message length: 33 bytes of message data
        0x0a, 0x00, 0x00, 0x01,                         // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,                         // destination ID: FCC 0x0B00_0001
        0x07, 0xdb,                                     // message type 2011 = 0x07DB
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0xcb,                                           // presence vector 0xCB: bits 0, 1, 3, 6 and 7
        0xc5, 0x93, 0x2b, 0x13, 0x18,                   // time stamp 2026-11-21T12:00:31.000Z = 848_577_631_000 ms since 2000-01-01 = 0xC5_932B_1318
        0x08,                                           // area transfer mode 8: initiate download of a staged mission's areas
        0x00, 0x00,                                     // area ID 0: all areas
        b'M', b'E', b'D', b'E', b'V', b'A', b'C', b'-', // mission ID "MEDEVAC-1" (Char20)
        b'1',
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 11 bytes
        0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x08,                         // transfer window 8 (U4, mode 8)
        // checksum
        0x00, 0x00, 0x09, 0x1c,                         // checksum: byte sum of header and data = 2332 = 0x0000_091C
    ];

    fn staged_download() -> AreaTransmissionCommand {
        AreaTransmissionCommand {
            time_stamp: Timestamp::from_millis(848_577_631_000).unwrap(),
            mode: AreaTransferMode::InitiateStagedDownload,
            loop_count: None,
            area_id: Some(0),
            safety_offset: None,
            activity_id: None,
            mission_id: Some(Text::new("MEDEVAC-1").unwrap()),
            window_or_checksum: TransferWindow::new(8).map(WindowOrChecksum::TransferWindow),
        }
    }

    #[test]
    fn golden_staged_download() {
        super::super::assert_golden(&FRAME_STAGED_DOWNLOAD, ENVELOPE, staged_download().into());
    }

    #[test]
    fn display_staged_download() {
        super::super::assert_display(
            staged_download(),
            "#2011 Area Transmission Command: mode 8 initiate download of a staged mission's areas, all areas, mission MEDEVAC-1, transfer window 8",
        );
    }
}
