//! Presence vector rules of ICD §3: the reader and writer every message is built on.
//!
//! The presence vector (PV) is field 0 of every message, U1, U2 or U3. Bit k set says the field of
//! bit k is present; absent fields take no bytes; fields follow in bit order. A receiver rejects a
//! message that lacks a mandatory field (`MissingField`) or sets a bit beyond the last defined
//! field (`UnknownField`), and (this project's reading of "Message Length ... disagrees") one whose
//! data ends inside a field or goes on after the last one (`Malformed`).

use super::error::{Cause, EncodeError, FieldRef, MessageError};
use super::field::{Codec, Timestamp, read_be, write_be};
use super::frame::MAX_DATA_LEN;

/// Walks the data of one message field by field, in bit order.
pub(crate) struct Reader<'a> {
    message_type: u16,
    fields: &'static [&'static str],
    pv: u32,
    rest: &'a [u8],
    time_stamp: Option<Timestamp>,
}

impl<'a> Reader<'a> {
    /// Reads the presence vector of `pv_bytes` bytes and rejects unknown bits. `fields` names the
    /// defined fields, index = PV bit.
    pub(crate) fn new(
        message_type: u16,
        fields: &'static [&'static str],
        pv_bytes: usize,
        data: &'a [u8],
    ) -> Result<Self, MessageError> {
        let Some((pv, rest)) = data.split_at_checked(pv_bytes) else {
            return Err(MessageError {
                message_type,
                field: None,
                cause: Cause::ShortPresenceVector,
                time_stamp: None,
            });
        };
        let mut reader = Self {
            message_type,
            fields,
            pv: read_be(pv) as u32,
            rest,
            time_stamp: None,
        };
        // Peek the time stamp first so that even a rejection for an unknown bit can be
        // acknowledged with the original time stamp.
        if reader.present(0) {
            reader.time_stamp = rest
                .get(..Timestamp::SIZE)
                .and_then(|b| Timestamp::decode(b).ok());
        }
        let unknown = reader.pv >> fields.len().min(31);
        if unknown != 0 {
            let bit = fields.len() as u8 + unknown.trailing_zeros() as u8;
            return Err(reader.error_without_field(Cause::UnknownField { bit }));
        }
        Ok(reader)
    }

    /// The time stamp as [`Reader::new`] peeked it (`None`: absent, or it does not decode).
    pub(crate) fn peeked_time_stamp(&self) -> Option<Timestamp> {
        self.time_stamp
    }

    fn present(&self, bit: u8) -> bool {
        self.pv & (1 << bit) != 0
    }

    /// The error `cause` on the field of `bit`.
    pub(crate) fn error(&self, bit: u8, cause: Cause) -> MessageError {
        MessageError {
            message_type: self.message_type,
            field: Some(FieldRef {
                bit,
                name: self.fields.get(usize::from(bit)).copied().unwrap_or("?"),
            }),
            cause,
            time_stamp: self.time_stamp,
        }
    }

    fn error_without_field(&self, cause: Cause) -> MessageError {
        MessageError {
            message_type: self.message_type,
            field: None,
            cause,
            time_stamp: self.time_stamp,
        }
    }

    /// The `len` bytes of the field of `bit`, or `None` when the field is absent.
    pub(crate) fn bytes(&mut self, bit: u8, len: usize) -> Result<Option<&'a [u8]>, MessageError> {
        if !self.present(bit) {
            return Ok(None);
        }
        let Some((field, rest)) = self.rest.split_at_checked(len) else {
            return Err(self.error(bit, Cause::Truncated));
        };
        self.rest = rest;
        Ok(Some(field))
    }

    /// The field of `bit` if present.
    pub(crate) fn optional<T: Codec>(&mut self, bit: u8) -> Result<Option<T>, MessageError> {
        match self.bytes(bit, T::SIZE)? {
            None => Ok(None),
            Some(b) => T::decode(b).map(Some).map_err(|c| self.error(bit, c)),
        }
    }

    /// The field of `bit`, which must be present (M).
    pub(crate) fn mandatory<T: Codec>(&mut self, bit: u8) -> Result<T, MessageError> {
        let v = self.optional(bit)?;
        self.require(bit, v)
    }

    /// The field of `bit`, which is mandatory here (a field marked "M for mode 2" and the like).
    pub(crate) fn require<T>(&self, bit: u8, value: Option<T>) -> Result<T, MessageError> {
        value.ok_or_else(|| self.error(bit, Cause::MissingField))
    }

    /// Field 0, the time stamp, mandatory in every message.
    pub(crate) fn time_stamp(&mut self) -> Result<Timestamp, MessageError> {
        let ts = self.mandatory(0)?;
        self.time_stamp = Some(ts);
        Ok(ts)
    }

    /// `Ok(value)` when `ok`, else [`Cause::OutOfRange`] on the field of `bit`.
    pub(crate) fn in_range<T: Copy + Into<i64>>(
        &self,
        bit: u8,
        value: T,
        ok: bool,
    ) -> Result<T, MessageError> {
        if ok {
            Ok(value)
        } else {
            Err(self.error(
                bit,
                Cause::OutOfRange {
                    value: value.into(),
                },
            ))
        }
    }

    /// Ends the message: no bytes may follow the last present field.
    pub(crate) fn finish(self) -> Result<(), MessageError> {
        if self.rest.is_empty() {
            Ok(())
        } else {
            Err(self.error_without_field(Cause::TrailingBytes {
                count: self.rest.len(),
            }))
        }
    }
}

/// Writes the data of one message: presence vector, then the present fields in bit order.
pub(crate) struct Writer<'a> {
    out: &'a mut [u8],
    pv_bytes: usize,
    pv: u32,
    pos: usize,
}

impl<'a> Writer<'a> {
    /// A writer into `out`, the message data region (after the wrapper header).
    pub(crate) fn new(out: &'a mut [u8], pv_bytes: usize) -> Result<Self, EncodeError> {
        let mut w = Self {
            out,
            pv_bytes,
            pv: 0,
            pos: 0,
        };
        w.reserve(pv_bytes)?;
        Ok(w)
    }

    fn reserve(&mut self, len: usize) -> Result<core::ops::Range<usize>, EncodeError> {
        let end = self.pos + len;
        if end > MAX_DATA_LEN {
            return Err(EncodeError::TooLong);
        }
        if end > self.out.len() {
            return Err(EncodeError::BufferTooSmall {
                needed: end,
                available: self.out.len(),
            });
        }
        let range = self.pos..end;
        self.pos = end;
        Ok(range)
    }

    /// `len` bytes for the field of `bit`, marked present.
    pub(crate) fn bytes(&mut self, bit: u8, len: usize) -> Result<&mut [u8], EncodeError> {
        let range = self.reserve(len)?;
        self.pv |= 1 << bit;
        // `reserve` checked the range against the buffer.
        self.out.get_mut(range).ok_or(EncodeError::TooLong)
    }

    /// Writes the field of `bit`.
    pub(crate) fn field<T: Codec>(&mut self, bit: u8, value: &T) -> Result<(), EncodeError> {
        value.encode(self.bytes(bit, T::SIZE)?);
        Ok(())
    }

    /// Writes the field of `bit` when it has a value; an absent field takes no bytes.
    pub(crate) fn optional<T: Codec>(
        &mut self,
        bit: u8,
        value: Option<&T>,
    ) -> Result<(), EncodeError> {
        match value {
            Some(v) => self.field(bit, v),
            None => Ok(()),
        }
    }

    /// Writes the presence vector and returns the length of the message data.
    pub(crate) fn finish(self) -> usize {
        if let Some(pv) = self.out.get_mut(..self.pv_bytes) {
            write_be(u64::from(self.pv), pv);
        }
        self.pos
    }
}
