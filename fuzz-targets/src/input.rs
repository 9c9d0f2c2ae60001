//! How the targets that take sequences cut their input into steps, and how they build frames
//! from the fuzzer's bytes.
//!
//! **Records.** An input is a sequence of records, each one *tag* byte, a two-byte big-endian
//! length and that many bytes of *body* (the last record takes what is left when the input ends
//! early). A plain length prefix instead of the `arbitrary` crate: the corpus files stay
//! readable with `xxd`, the seed generator writes them with [`record`] in a line, and a mutation
//! of one byte changes one step, not the way every later byte is read.
//!
//! **Frames from message data.** Random bytes almost never carry a valid checksum, so a target
//! that only took raw frames would spend its time in the wrapper rules of ICD §2. The targets
//! therefore also take a message's type and data and put the wrapper around them
//! ([`wrap`]: any data, correct checksum, so the decoders see it), or decode the data and let an
//! [`Endpoint`] send it with a fresh time stamp ([`MessageBody`]: a valid message that sampling
//! takes as new, so the frame handlers see it).

use missionlink_interfaces::wire::{self, ChecksumWidth, Message, MessageProperties, Reason};
use missionlink_protocol::testkit::RawFrame;

/// Bytes of a record's header: the tag and the length.
pub const RECORD_HEADER_LEN: usize = 3;

/// The records of an input, in order.
#[derive(Debug, Clone)]
pub struct Records<'a> {
    rest: &'a [u8],
}

/// Cuts `input` into records (see the module documentation).
pub fn records(input: &[u8]) -> Records<'_> {
    Records { rest: input }
}

impl<'a> Iterator for Records<'a> {
    /// The tag and the body.
    type Item = (u8, &'a [u8]);

    fn next(&mut self) -> Option<Self::Item> {
        let (&tag, rest) = self.rest.split_first()?;
        let (len, body) = match rest {
            [hi, lo, body @ ..] => (usize::from(u16::from_be_bytes([*hi, *lo])), body),
            _ => (0, &[][..]),
        };
        let (body, rest) = body.split_at(len.min(body.len()));
        self.rest = rest;
        Some((tag, body))
    }
}

/// One record: `tag`, the length of `body`, `body` (the seed generator's writer).
pub fn record(tag: u8, body: &[u8]) -> Vec<u8> {
    let len = u16::try_from(body.len()).unwrap_or(u16::MAX);
    let mut out = vec![tag];
    out.extend_from_slice(&len.to_be_bytes());
    out.extend_from_slice(body.get(..usize::from(len)).unwrap_or(body));
    out
}

/// A body that names a message: its type, one byte of flags, its data.
#[derive(Debug, Clone, Copy)]
pub struct MessageBody<'a> {
    /// The Message Type.
    pub message_type: u16,
    /// Bit 0: acknowledgement requested; bits 1-2: checksum width (0 none, 1 two, 2 four
    /// bytes, 3 the invalid width); bit 3: broadcast destination; bit 4: marked signed (ICD
    /// §9; [`wrap`] appends no trailer). Targets may read the other bits as they need.
    pub flags: u8,
    /// The message data (presence vector and fields).
    pub data: &'a [u8],
}

impl<'a> MessageBody<'a> {
    /// Reads `[type (2), flags (1), data ...]`; `None` when the body is shorter than 3 bytes.
    pub fn parse(body: &'a [u8]) -> Option<Self> {
        match body {
            [hi, lo, flags, data @ ..] => Some(Self {
                message_type: u16::from_be_bytes([*hi, *lo]),
                flags: *flags,
                data,
            }),
            _ => None,
        }
    }

    /// The body that names `message` with `flags` (the seed generator's writer).
    pub fn of(message: &Message, flags: u8) -> Vec<u8> {
        let mut data = [0u8; wire::MAX_FRAME_LEN];
        let len = message.encode(&mut data).unwrap_or(0);
        let mut out = (message.message_type() as u16).to_be_bytes().to_vec();
        out.push(flags);
        out.extend_from_slice(data.get(..len).unwrap_or_default());
        out
    }

    /// Whether the sender asks for an acknowledgement.
    pub fn ack_requested(&self) -> bool {
        self.flags & 1 != 0
    }

    /// The message the data decodes to.
    pub fn message(&self) -> Option<Message> {
        Message::decode(self.message_type, self.data).ok()
    }
}

/// A frame around `body`'s data from `source` to `destination` (or broadcast, flags bit 3),
/// with the checksum width of its flags and a correct checksum: what a sender would put on the
/// wire with this data, valid or not. `None` when the data is empty or longer than a frame
/// holds (a length the wrapper cannot express).
pub fn wrap(body: &MessageBody<'_>, source: u32, destination: u32) -> Option<Vec<u8>> {
    let length = u16::try_from(body.data.len())
        .ok()
        .filter(|l| (1..=wire::MAX_DATA_LEN as u16).contains(l))?;
    let width = match (body.flags >> 1) & 3 {
        0 => ChecksumWidth::None,
        1 => ChecksumWidth::Two,
        _ => ChecksumWidth::Four,
    };
    let destination = if body.flags & 8 != 0 {
        wire::BROADCAST_ID
    } else {
        destination
    };
    let mut properties = MessageProperties::new(body.ack_requested(), wire::IDD_VERSION, width).0;
    if (body.flags >> 1) & 3 == 3 {
        // The width ICD §2 leaves undefined (bits 7..6 = 11).
        properties |= 0b11 << 6;
    }
    if body.flags & 16 != 0 {
        properties = MessageProperties(properties).with_signed().0;
    }
    let raw = RawFrame {
        length: Some(length),
        source,
        destination,
        message_type: body.message_type,
        properties,
        checksum_len: width.len(),
        ..RawFrame::uplink(body.message_type)
    };
    Some(raw.build(body.data))
}

/// The outcome an answer record's body asks for: its first byte 0 accepts, any other is a
/// rejection with that reason (an undefined one as `Malformed`).
pub fn answer_outcome(body: &[u8]) -> Result<(), Reason> {
    match body.first().copied().unwrap_or(0) {
        0 => Ok(()),
        r => Err(Reason::try_from(r).unwrap_or(Reason::Malformed)),
    }
}

/// Two bytes of `body` from `at` as a big-endian number, missing bytes as 0.
pub fn u16_at(body: &[u8], at: usize) -> u16 {
    let byte = |i: usize| body.get(i).copied().unwrap_or(0);
    u16::from_be_bytes([byte(at), byte(at + 1)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_round_trip_and_cut_short() {
        let mut input = record(7, b"abc");
        input.extend(record(9, b""));
        input.extend([1, 0, 5, b'x']);
        let got: Vec<_> = records(&input).collect();
        assert_eq!(
            got,
            vec![(7, &b"abc"[..]), (9, &b""[..]), (1, &b"x"[..])],
            "the last record takes what is left"
        );
        assert_eq!(records(&[4]).collect::<Vec<_>>(), vec![(4, &b""[..])]);
    }

    #[test]
    fn wrapped_frames_pass_the_wrapper_rules() {
        let data = [0u8, 0, 1, 2, 3];
        for flags in [0, 1, 2, 4, 8, 5] {
            let body = MessageBody {
                message_type: 13002,
                flags,
                data: &data,
            };
            let frame = wrap(&body, 1, 2).unwrap();
            let checked = wire::Frame::new_checked(&frame).unwrap();
            assert_eq!(checked.data(), &data);
            assert_eq!(checked.properties().ack_requested(), flags & 1 != 0);
        }
        let bad_width = MessageBody {
            message_type: 13002,
            flags: 6,
            data: &data,
        };
        assert!(wire::Frame::new_checked(&wrap(&bad_width, 1, 2).unwrap()).is_err());
    }
}
