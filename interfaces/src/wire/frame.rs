//! The wrapper of ICD §2 (STANAG 4586 Ed 3 §3.3.1): a 16-byte header, the message data, and a
//! 0, 2 or 4-byte byte-sum checksum; and the walker over a datagram that holds several messages.
//!
//! [`Frame::new_checked`] and [`Frames`] apply every structural reject rule of §2, so no accessor
//! of a [`Frame`] can fail afterwards. The addressing rules (destination, source) need the node's
//! configuration and live in [`Frame::check_addressing`].
//!
//! A frame whose Message Properties bit 5 is set is *signed* (ICD §9): a 16-byte
//! [`SignatureTrailer`] follows its checksum in the same datagram. The walker hands the trailer
//! over with the frame ([`Frame::trailer`]) and goes on after it; whether it verifies is the
//! receiver's business (`missionlink_protocol::link::signing`), since it needs keys.

use zerocopy::byteorder::big_endian::{U16, U32};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

use super::error::{DecodeError, EncodeError, FrameError, MessageError};
use super::field::{Timestamp, write_be};
use super::msg::Message;

/// Bytes of the wrapper header.
pub const HEADER_LEN: usize = 16;
/// Largest Message Length (message data only).
pub const MAX_DATA_LEN: usize = 528;
/// Largest frame: header, data and a 4-byte checksum.
pub const MAX_FRAME_LEN: usize = HEADER_LEN + MAX_DATA_LEN + 4;
/// Destination ID that addresses every node.
pub const BROADCAST_ID: u32 = 0xFFFF_FFFF;
/// The IDD version this project sends.
pub const IDD_VERSION: u8 = 40;
/// The IDD versions a receiver accepts.
pub const ACCEPTED_IDD_VERSIONS: core::ops::RangeInclusive<u8> = 30..=40;
/// The Reserved (sequence) field as sent; ignored on receive.
pub const RESERVED: u16 = 0xFFFF;
/// Bytes of the signature trailer of ICD §9.
pub const TRAILER_LEN: usize = 16;
/// Largest signed frame with its trailer (ICD §1: 564 bytes).
pub const MAX_SIGNED_FRAME_LEN: usize = MAX_FRAME_LEN + TRAILER_LEN;
/// Message Properties bit 5: the frame is signed (ICD §9; edition 1 sends 0).
const SIGNED_BIT: u16 = 1 << 5;

/// The wrapper header, field by field, big-endian (ICD §2 table).
#[derive(Debug, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct WrapperHeader {
    /// Reserved (sequence): 0xFFFF on send, ignored on receive.
    pub reserved: U16,
    /// Bytes of message data, 1..=528.
    pub message_length: U16,
    /// Sender's ID.
    pub source_id: U32,
    /// Receiver's ID or [`BROADCAST_ID`].
    pub destination_id: U32,
    /// STANAG message type.
    pub message_type: U16,
    /// Message Properties, see [`MessageProperties`].
    pub message_properties: U16,
}

/// Width of the checksum, set by bits 7..6 of Message Properties.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum ChecksumWidth {
    /// Code 00: no checksum.
    None,
    /// Code 01: two bytes.
    Two,
    /// Code 10: four bytes (what this project sends).
    Four,
}

impl ChecksumWidth {
    /// Bytes the checksum takes.
    pub const fn len(self) -> usize {
        match self {
            Self::None => 0,
            Self::Two => 2,
            Self::Four => 4,
        }
    }

    /// Whether there is no checksum.
    pub const fn is_empty(self) -> bool {
        matches!(self, Self::None)
    }

    const fn code(self) -> u16 {
        match self {
            Self::None => 0b00,
            Self::Two => 0b01,
            Self::Four => 0b10,
        }
    }
}

/// The Message Properties field: bit 15 acknowledgement requested, bits 14..8 IDD version,
/// bits 7..6 checksum length, bit 5 signed (ICD §9), bits 4..0 zero (sent as 0, ignored on
/// receive).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MessageProperties(pub u16);

impl MessageProperties {
    /// Properties with these fields.
    pub const fn new(ack_requested: bool, idd_version: u8, checksum: ChecksumWidth) -> Self {
        Self(
            ((ack_requested as u16) << 15)
                | (((idd_version & 0x7f) as u16) << 8)
                | (checksum.code() << 6),
        )
    }

    /// Bit 15: the sender asks for a #17000.
    pub const fn ack_requested(self) -> bool {
        self.0 & 0x8000 != 0
    }

    /// Bits 14..8.
    pub const fn idd_version(self) -> u8 {
        ((self.0 >> 8) & 0x7f) as u8
    }

    /// Bit 5: a [`SignatureTrailer`] follows the checksum (ICD §9).
    pub const fn signed(self) -> bool {
        self.0 & SIGNED_BIT != 0
    }

    /// The same properties with bit 5 set.
    pub const fn with_signed(self) -> Self {
        Self(self.0 | SIGNED_BIT)
    }

    /// Bits 7..6; code 11 is invalid.
    pub const fn checksum_width(self) -> Result<ChecksumWidth, FrameError> {
        match (self.0 >> 6) & 0b11 {
            0b00 => Ok(ChecksumWidth::None),
            0b01 => Ok(ChecksumWidth::Two),
            0b10 => Ok(ChecksumWidth::Four),
            _ => Err(FrameError::InvalidChecksumLength),
        }
    }
}

/// The byte-sum checksum of ICD §2: unsigned addition of every byte, truncated to the width.
pub fn checksum(bytes: &[u8], width: ChecksumWidth) -> u32 {
    let sum = bytes
        .iter()
        .fold(0u32, |acc, b| acc.wrapping_add(u32::from(*b)));
    match width {
        ChecksumWidth::None => 0,
        ChecksumWidth::Two => sum & 0xffff,
        ChecksumWidth::Four => sum,
    }
}

/// The signature trailer of ICD §9, right after a signed frame's checksum.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct SignatureTrailer {
    /// Which configured key signed the frame.
    pub key_id: u8,
    /// The link the frame was sent on: 0 direct, 1 LTE.
    pub link_id: u8,
    /// Reserved, 0.
    pub reserved: U16,
    /// The first 12 bytes of HMAC-SHA-256 over the frame and the first
    /// [`SignatureTrailer::SIGNED_PREFIX`] bytes of this trailer.
    pub signature: [u8; 12],
}

impl SignatureTrailer {
    /// Bytes of the trailer the signature covers: Key ID, Link ID, Reserved.
    pub const SIGNED_PREFIX: usize = 4;

    /// The bytes the signature covers after the frame.
    pub fn signed_prefix(&self) -> &[u8] {
        self.as_bytes()
            .get(..Self::SIGNED_PREFIX)
            .unwrap_or_default()
    }
}

/// A frame that passed the structural rules of ICD §2: a typed view over its bytes.
#[derive(Debug, Clone, Copy)]
pub struct Frame<'a> {
    header: &'a WrapperHeader,
    bytes: &'a [u8],
    data: &'a [u8],
    trailer: Option<&'a SignatureTrailer>,
}

impl<'a> Frame<'a> {
    /// Checks `bytes`, which must hold exactly one message (one datagram, one message), with
    /// its signature trailer when it is signed.
    pub fn new_checked(bytes: &'a [u8]) -> Result<Self, FrameError> {
        let (frame, rest) = Self::split_first(bytes)?;
        if !rest.is_empty() {
            return Err(FrameError::LengthMismatch {
                expected: frame.bytes.len(),
                actual: bytes.len(),
            });
        }
        Ok(frame)
    }

    /// Checks the first message of `bytes` and returns it with the bytes after it.
    fn split_first(bytes: &'a [u8]) -> Result<(Self, &'a [u8]), FrameError> {
        let (header, _) = WrapperHeader::ref_from_prefix(bytes)
            .map_err(|_| FrameError::TooShort { len: bytes.len() })?;
        let length = header.message_length.get();
        if length == 0 || usize::from(length) > MAX_DATA_LEN {
            return Err(FrameError::LengthOutOfRange { length });
        }
        let properties = MessageProperties(header.message_properties.get());
        let width = properties.checksum_width()?;
        let data_end = HEADER_LEN + usize::from(length);
        let total = data_end + width.len();
        let (Some((frame, rest)), Some(data), Some(received)) = (
            bytes.split_at_checked(total),
            bytes.get(HEADER_LEN..data_end),
            bytes.get(data_end..total),
        ) else {
            return Err(FrameError::LengthMismatch {
                expected: total,
                actual: bytes.len(),
            });
        };
        let covered = frame.get(..data_end).unwrap_or_default();
        let computed = checksum(covered, width);
        let received = super::field::read_be(received) as u32;
        if computed != received {
            return Err(FrameError::ChecksumMismatch { computed, received });
        }
        let version = properties.idd_version();
        if !ACCEPTED_IDD_VERSIONS.contains(&version) {
            return Err(FrameError::UnsupportedVersion { version });
        }
        // A signed frame without the room for its trailer keeps what follows as the next
        // message (which then fails as too short): the receiver's policy decides what a
        // signed frame without a trailer is worth.
        let (trailer, rest) = match properties.signed() {
            true => match SignatureTrailer::ref_from_prefix(rest) {
                Ok((trailer, after)) => (Some(trailer), after),
                Err(_) => (None, rest),
            },
            false => (None, rest),
        };
        Ok((
            Self {
                header,
                bytes: frame,
                data,
                trailer,
            },
            rest,
        ))
    }

    /// The rules of ICD §2 that need the node's configuration: the destination is this node or
    /// broadcast, the source is the configured peer.
    pub fn check_addressing(&self, local_id: u32, peer_id: u32) -> Result<(), FrameError> {
        let destination = self.destination_id();
        if destination != local_id && destination != BROADCAST_ID {
            return Err(FrameError::WrongDestination { destination });
        }
        let source = self.source_id();
        if source != peer_id {
            return Err(FrameError::UnknownSource { source });
        }
        Ok(())
    }

    /// The whole frame: header, data, checksum (not the trailer).
    pub fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// The signature trailer of a signed frame (ICD §9), when the datagram holds one.
    pub fn trailer(&self) -> Option<&'a SignatureTrailer> {
        self.trailer
    }

    /// The message data (presence vector and fields).
    pub fn data(&self) -> &'a [u8] {
        self.data
    }

    /// The header.
    pub fn header(&self) -> &'a WrapperHeader {
        self.header
    }

    /// Source ID.
    pub fn source_id(&self) -> u32 {
        self.header.source_id.get()
    }

    /// Destination ID.
    pub fn destination_id(&self) -> u32 {
        self.header.destination_id.get()
    }

    /// Message Type.
    pub fn message_type(&self) -> u16 {
        self.header.message_type.get()
    }

    /// Message Properties.
    pub fn properties(&self) -> MessageProperties {
        MessageProperties(self.header.message_properties.get())
    }

    /// The wrapper fields a sender chooses.
    pub fn envelope(&self) -> Envelope {
        let p = self.properties();
        Envelope {
            source_id: self.source_id(),
            destination_id: self.destination_id(),
            ack_requested: p.ack_requested(),
            idd_version: p.idd_version(),
            // Checked in `split_first`.
            checksum: p.checksum_width().unwrap_or(ChecksumWidth::None),
        }
    }

    /// Decodes the message data.
    pub fn message(&self) -> Result<Message, MessageError> {
        Message::decode(self.message_type(), self.data)
    }

    /// The message's time stamp without decoding the rest ([`Message::peek_time_stamp`]).
    pub fn time_stamp(&self) -> Option<Timestamp> {
        Message::peek_time_stamp(self.message_type(), self.data)
    }
}

/// The walker over a datagram that holds messages back to back (ICD §1): each message's length
/// and checksum width say where it ends. It stops at the first broken frame, since nothing after
/// it can be located.
#[derive(Debug, Clone)]
pub struct Frames<'a> {
    rest: &'a [u8],
}

/// The messages of a datagram.
pub fn frames(datagram: &[u8]) -> Frames<'_> {
    Frames { rest: datagram }
}

impl<'a> Iterator for Frames<'a> {
    type Item = Result<Frame<'a>, FrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.rest.is_empty() {
            return None;
        }
        match Frame::split_first(self.rest) {
            Ok((frame, rest)) => {
                self.rest = rest;
                Some(Ok(frame))
            }
            Err(e) => {
                self.rest = &[];
                Some(Err(e))
            }
        }
    }
}

/// The wrapper fields a sender chooses (ICD §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Envelope {
    /// Sender's ID.
    pub source_id: u32,
    /// Receiver's ID or [`BROADCAST_ID`].
    pub destination_id: u32,
    /// Ask the receiver for a #17000.
    pub ack_requested: bool,
    /// IDD version, [`IDD_VERSION`] when sent by this project.
    pub idd_version: u8,
    /// Checksum width, four bytes when sent by this project.
    pub checksum: ChecksumWidth,
}

impl Envelope {
    /// An envelope as this project sends: IDD 40, 4-byte checksum, no acknowledgement request.
    pub const fn new(source_id: u32, destination_id: u32) -> Self {
        Self {
            source_id,
            destination_id,
            ack_requested: false,
            idd_version: IDD_VERSION,
            checksum: ChecksumWidth::Four,
        }
    }

    /// The same envelope with the acknowledgement request set or cleared.
    pub const fn with_ack(mut self, ack_requested: bool) -> Self {
        self.ack_requested = ack_requested;
        self
    }
}

/// Encodes `message` in a frame into `buf`; returns the frame length. Allocates nothing; bytes of
/// `buf` past the frame are left untouched.
pub fn encode(
    envelope: &Envelope,
    message: &Message,
    buf: &mut [u8],
) -> Result<usize, EncodeError> {
    let available = buf.len();
    let too_small = |needed| EncodeError::BufferTooSmall { needed, available };
    let (_, body) = buf
        .split_at_mut_checked(HEADER_LEN)
        .ok_or(too_small(HEADER_LEN))?;
    // The writer counts from the start of the data: report frame sizes, header and checksum
    // included.
    let data_len = message.encode(body).map_err(|e| match e {
        EncodeError::BufferTooSmall { needed, .. } => {
            too_small(HEADER_LEN + needed + envelope.checksum.len())
        }
        other => other,
    })?;
    let data_end = HEADER_LEN + data_len;
    let total = data_end + envelope.checksum.len();
    let frame = buf.get_mut(..total).ok_or(too_small(total))?;
    let (header, _) = WrapperHeader::mut_from_prefix(frame).map_err(|_| too_small(total))?;
    header.reserved.set(RESERVED);
    // data_len <= MAX_DATA_LEN, checked by the writer.
    header.message_length.set(data_len as u16);
    header.source_id.set(envelope.source_id);
    header.destination_id.set(envelope.destination_id);
    header.message_type.set(message.message_type() as u16);
    header.message_properties.set(
        MessageProperties::new(
            envelope.ack_requested,
            envelope.idd_version,
            envelope.checksum,
        )
        .0,
    );
    let (covered, sum) = frame.split_at_mut(data_end);
    write_be(u64::from(checksum(covered, envelope.checksum)), sum);
    Ok(total)
}

/// Marks the one frame in `frame` (wrapper to checksum, as [`encode`] wrote it) as signed: sets
/// Message Properties bit 5 and writes the checksum again, which covers it (ICD §9). The
/// trailer is the signer's to append.
pub fn mark_signed(frame: &mut [u8]) -> Result<(), FrameError> {
    let checked = Frame::new_checked(frame)?;
    let width = checked.properties().checksum_width()?;
    let data_end = checked.bytes.len() - width.len();
    if checked.bytes.len() != frame.len() {
        // A trailer was already there: the frame is signed.
        return Ok(());
    }
    let (header, _) = WrapperHeader::mut_from_prefix(&mut *frame)
        .map_err(|_| FrameError::TooShort { len: HEADER_LEN })?;
    let properties = MessageProperties(header.message_properties.get()).with_signed();
    header.message_properties.set(properties.0);
    let (covered, sum) = frame.split_at_mut(data_end);
    write_be(u64::from(checksum(covered, width)), sum);
    Ok(())
}

/// Decodes a datagram that holds exactly one message: the wrapper rules of ICD §2 (but for
/// addressing, see [`Frame::check_addressing`]), then the message rules of §3 and §4.
pub fn decode(bytes: &[u8]) -> Result<(Envelope, Message), DecodeError> {
    let frame = Frame::new_checked(bytes)?;
    Ok((frame.envelope(), frame.message()?))
}
