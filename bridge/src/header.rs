//! The header every sample carries across Zenoh, as the sample's attachment (ICD §14,
//! docs/icd.md): which contract the raw bytes are (type name, size, contract version), which
//! bridge sent them and its sequence number for the service. Sans-IO: bytes in, a value or a
//! reason out; the receiver refuses a sample whose header does not match its own contract.
//!
//! Layout, little-endian:
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `MLBR` |
//! | 4..6 | header layout version, 1 |
//! | 6..8 | length N of the type name |
//! | 8..12 | contract version (`contracts::CONTRACT_VERSION`) |
//! | 12..16 | payload size, bytes |
//! | 16..24 | the sending bridge's ID |
//! | 24..32 | sequence number, per service and sending bridge, from 1 |
//! | 32..32+N | the payload's iceoryx2 type name, UTF-8 |

use core::fmt;

/// The first four bytes.
pub const MAGIC: [u8; 4] = *b"MLBR";
/// The layout version of this header.
pub const LAYOUT_VERSION: u16 = 1;
/// Bytes before the type name.
pub const FIXED_LEN: usize = 32;
/// The longest type name a header carries.
pub const MAX_TYPE_NAME: usize = 256;

/// A header, borrowed from the bytes it was read from (or from the contract it describes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header<'a> {
    /// The contract version of the payload types.
    pub contract_version: u32,
    /// The payload's size in bytes.
    pub payload_size: u32,
    /// The sending bridge.
    pub bridge_id: u64,
    /// Counts the samples of this service the sending bridge sent, from 1.
    pub sequence: u64,
    /// The payload's iceoryx2 type name.
    pub type_name: &'a str,
}

/// Why a header (or the sample it describes) is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// The sample had no attachment.
    Missing,
    /// Fewer bytes than the fixed part, or than the type name it announces.
    Truncated,
    /// The first four bytes are not [`MAGIC`].
    Magic,
    /// A header layout this bridge does not read.
    Layout(u16),
    /// The type name is not UTF-8 or longer than [`MAX_TYPE_NAME`].
    TypeNameEncoding,
    /// Another contract version than this bridge's.
    ContractVersion(u32),
    /// Another type than the service's.
    TypeName,
    /// Another payload size than the service's type, or a payload of another length than the
    /// header says.
    Size(u32),
    /// The bytes are not a valid value of the type (a `bool` that is neither 0 nor 1, say).
    Invalid,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Missing => f.write_str("no header"),
            Self::Truncated => f.write_str("header truncated"),
            Self::Magic => f.write_str("not a bridge header"),
            Self::Layout(v) => write!(f, "header layout {v}"),
            Self::TypeNameEncoding => f.write_str("type name not UTF-8 or too long"),
            Self::ContractVersion(v) => write!(f, "contract version {v}"),
            Self::TypeName => f.write_str("another type name"),
            Self::Size(s) => write!(f, "payload size {s}"),
            Self::Invalid => f.write_str("not a valid value of the type"),
        }
    }
}

fn le_u16(b: &[u8], at: usize) -> Option<u16> {
    b.get(at..at + 2)?.try_into().ok().map(u16::from_le_bytes)
}

fn le_u32(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)?.try_into().ok().map(u32::from_le_bytes)
}

fn le_u64(b: &[u8], at: usize) -> Option<u64> {
    b.get(at..at + 8)?.try_into().ok().map(u64::from_le_bytes)
}

impl<'a> Header<'a> {
    /// Appends the header's bytes to `out` (cleared first).
    pub fn emit(&self, out: &mut Vec<u8>) {
        let name = self.type_name.as_bytes();
        let name = name.get(..MAX_TYPE_NAME).unwrap_or(name);
        out.clear();
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&LAYOUT_VERSION.to_le_bytes());
        out.extend_from_slice(&(name.len() as u16).to_le_bytes());
        out.extend_from_slice(&self.contract_version.to_le_bytes());
        out.extend_from_slice(&self.payload_size.to_le_bytes());
        out.extend_from_slice(&self.bridge_id.to_le_bytes());
        out.extend_from_slice(&self.sequence.to_le_bytes());
        out.extend_from_slice(name);
    }

    /// Reads a header from untrusted bytes.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, Refusal> {
        if bytes.len() < FIXED_LEN {
            return Err(Refusal::Truncated);
        }
        if bytes.get(..4) != Some(&MAGIC[..]) {
            return Err(Refusal::Magic);
        }
        let layout = le_u16(bytes, 4).ok_or(Refusal::Truncated)?;
        if layout != LAYOUT_VERSION {
            return Err(Refusal::Layout(layout));
        }
        let name_len = usize::from(le_u16(bytes, 6).ok_or(Refusal::Truncated)?);
        if name_len > MAX_TYPE_NAME {
            return Err(Refusal::TypeNameEncoding);
        }
        let name = bytes
            .get(FIXED_LEN..FIXED_LEN + name_len)
            .ok_or(Refusal::Truncated)?;
        Ok(Self {
            contract_version: le_u32(bytes, 8).ok_or(Refusal::Truncated)?,
            payload_size: le_u32(bytes, 12).ok_or(Refusal::Truncated)?,
            bridge_id: le_u64(bytes, 16).ok_or(Refusal::Truncated)?,
            sequence: le_u64(bytes, 24).ok_or(Refusal::Truncated)?,
            type_name: core::str::from_utf8(name).map_err(|_| Refusal::TypeNameEncoding)?,
        })
    }

    /// Checks the header against the receiver's contract (`version`, `type_name`, `size`) and
    /// the payload's length.
    pub fn check(
        &self,
        version: u32,
        type_name: &str,
        size: usize,
        payload_len: usize,
    ) -> Result<(), Refusal> {
        if self.contract_version != version {
            return Err(Refusal::ContractVersion(self.contract_version));
        }
        if self.type_name != type_name {
            return Err(Refusal::TypeName);
        }
        if usize::try_from(self.payload_size).ok() != Some(size) || payload_len != size {
            return Err(Refusal::Size(self.payload_size));
        }
        Ok(())
    }
}

impl fmt::Display for Header<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({} B, contract v{}) from bridge {:#x} #{}",
            self.type_name, self.payload_size, self.contract_version, self.bridge_id, self.sequence
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOLDEN: [u8; 35] = [
        b'M', b'L', b'B', b'R', 1, 0, 3, 0, // magic, layout 1, name length 3
        3, 0, 0, 0, 0x24, 0x02, 0, 0, // contract 3, 548 bytes
        0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, // bridge id
        9, 0, 0, 0, 0, 0, 0, 0, // sequence 9
        b'a', b'/', b'b',
    ];

    fn golden() -> Header<'static> {
        Header {
            contract_version: 3,
            payload_size: 548,
            bridge_id: 0x0102_0304_0506_0708,
            sequence: 9,
            type_name: "a/b",
        }
    }

    #[test]
    fn emits_and_parses_the_golden_bytes() {
        let mut out = vec![0xa5; 3];
        golden().emit(&mut out);
        assert_eq!(out, GOLDEN);
        assert_eq!(Header::parse(&GOLDEN).unwrap(), golden());
    }

    #[test]
    fn refuses_what_is_not_a_header_of_this_contract() {
        assert_eq!(Header::parse(&GOLDEN[..31]), Err(Refusal::Truncated));
        assert_eq!(Header::parse(&GOLDEN[..34]), Err(Refusal::Truncated));
        let mut bad = GOLDEN;
        bad[0] = b'X';
        assert_eq!(Header::parse(&bad), Err(Refusal::Magic));
        let mut bad = GOLDEN;
        bad[4] = 2;
        assert_eq!(Header::parse(&bad), Err(Refusal::Layout(2)));
        let mut bad = GOLDEN;
        bad[32] = 0xff;
        assert_eq!(Header::parse(&bad), Err(Refusal::TypeNameEncoding));
        let h = golden();
        assert_eq!(h.check(3, "a/b", 548, 548), Ok(()));
        assert_eq!(
            h.check(4, "a/b", 548, 548),
            Err(Refusal::ContractVersion(3))
        );
        assert_eq!(h.check(3, "a/c", 548, 548), Err(Refusal::TypeName));
        assert_eq!(h.check(3, "a/b", 584, 548), Err(Refusal::Size(548)));
        assert_eq!(h.check(3, "a/b", 548, 547), Err(Refusal::Size(548)));
    }

    #[test]
    fn parse_never_panics_on_any_prefix_or_byte() {
        for n in 0..GOLDEN.len() {
            let _ = Header::parse(&GOLDEN[..n]);
        }
        for i in 0..GOLDEN.len() {
            for v in [0u8, 0x7f, 0xff] {
                let mut b = GOLDEN;
                b[i] = v;
                let _ = Header::parse(&b);
            }
        }
    }
}
