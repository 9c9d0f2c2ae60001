//! #50000 Mission Execute Command (ICD §4, private range): execute, return to home, land; in
//! edition 2 also activate a staged mission (ICD §8).

use core::fmt;

use super::{MessageBody, MessageType, ext_field, reader, staged_mission_id};
use crate::wire::enums::ExecuteCommand;
use crate::wire::error::{EncodeError, MessageError};
use crate::wire::field::{Text, Timestamp};
use crate::wire::presence::Writer;

/// #50000. Acknowledged with #17000 type 2 when system automation accepts it, type 3 with
/// `WrongState` or `Unsupported` when not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MissionExecuteCommand {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M.
    pub command: ExecuteCommand,
    /// Bit 2 (ext, ICD §8), M for command 4 (not empty), with no other command: the staged
    /// mission to activate.
    pub mission_id: Option<Text<20>>,
}

impl MessageBody for MissionExecuteCommand {
    const TYPE: MessageType = MessageType::MissionExecuteCommand;
    const FIELDS: &'static [&'static str] = &["Time Stamp", "Command", "Mission ID"];
    const PV_BYTES: usize = 1;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let command = r.mandatory(1)?;
        // Mission ID (ICD §8): command 4 names the staged mission; the field is an extension
        // that no other command's table names (see `ext_field`).
        let mission_id = r.optional(2)?;
        let mission_id = match command {
            ExecuteCommand::ActivateStaged => Some(staged_mission_id(&r, 2, mission_id)?),
            _ => ext_field(&r, 2, mission_id, false)?,
        };
        r.finish()?;
        Ok(Self {
            time_stamp,
            command,
            mission_id,
        })
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.command)?;
        w.optional(2, self.mission_id.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#50000 Mission Execute Command: command 1 execute`.
impl fmt::Display for MissionExecuteCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: command {}", Self::TYPE, self.command.numbered())?;
        super::optional(f, "mission", self.mission_id.as_ref().map(Text::as_str))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #50000 command 1 execute; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME: [u8; 27] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x07,                   // message length: 7 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0xc3, 0x50,                   // message type 50000 = 0xC350
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x03,                         // presence vector 0x03: bits 0, 1
        0xc5, 0x93, 0x2d, 0x59, 0x20, // time stamp 2026-11-21T12:03:00.000Z = 848_577_780_000 ms since 2000-01-01 = 0xC5_932D_5920
        0x01,                         // command 1: execute
        // checksum
        0x00, 0x00, 0x06, 0x59,       // checksum: byte sum of header and data = 1625 = 0x0000_0659
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> MissionExecuteCommand {
        MissionExecuteCommand {
            time_stamp: Timestamp::from_millis(848_577_780_000).unwrap(),
            command: ExecuteCommand::Execute,
            mission_id: None,
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        assert_eq!(repr().time_stamp.to_string(), "2026-11-21T12:03:00.000Z");
    }

    #[test]
    fn display() {
        super::super::assert_display(repr(), "#50000 Mission Execute Command: command 1 execute");
    }

    /// #50000 command 4: activate the staged mission MEDEVAC-1 (ext, ICD §8); GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_ACTIVATE: [u8; 47] = [
        // wrapper
        0xff, 0xff,                                     // reserved (sequence): 0xFFFF
        0x00, 0x1b,                                     // message length: 27 bytes of message data
        0x0a, 0x00, 0x00, 0x01,                         // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,                         // destination ID: FCC 0x0B00_0001
        0xc3, 0x50,                                     // message type 50000 = 0xC350
        0xa8, 0x80,                                     // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x07,                                           // presence vector 0x07: bits 0..=2
        0xc5, 0x93, 0x2d, 0x5d, 0x08,                   // time stamp 2026-11-21T12:03:01.000Z = 848_577_781_000 ms since 2000-01-01 = 0xC5_932D_5D08
        0x04,                                           // command 4: activate the staged mission
        b'M', b'E', b'D', b'E', b'V', b'A', b'C', b'-', // mission ID "MEDEVAC-1" (Char20)
        b'1',
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // NUL padding, 11 bytes
        0x00, 0x00, 0x00,
        // checksum
        0x00, 0x00, 0x08, 0xb3,                         // checksum: byte sum of header and data = 2227 = 0x0000_08B3
    ];

    fn activate() -> MissionExecuteCommand {
        MissionExecuteCommand {
            time_stamp: Timestamp::from_millis(848_577_781_000).unwrap(),
            command: ExecuteCommand::ActivateStaged,
            mission_id: Some(Text::new("MEDEVAC-1").unwrap()),
        }
    }

    #[test]
    fn golden_activate() {
        super::super::assert_golden(&FRAME_ACTIVATE, ENVELOPE, activate().into());
    }

    #[test]
    fn display_activate() {
        super::super::assert_display(
            activate(),
            "#50000 Mission Execute Command: command 4 activate the staged mission, mission MEDEVAC-1",
        );
    }
}
