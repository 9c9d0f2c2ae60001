//! The STANAG 4586 wire layer of ICD §1 to §4: wrapper, field encodings, presence vector and the
//! thirteen messages (edition 2, with the extension fields of §8, §10 and §11), each with encode
//! and decode. Decoding untrusted bytes never panics and never
//! allocates; errors say which message, which field and which rule (see [`error`]).

/// Defines an enumeration field of ICD §4 (a U1 on the wire): its values, `TryFrom<u8>` and its
/// [`field::Codec`], which rejects an undefined value as `Unsupported`.
macro_rules! wire_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident = $value:literal => $word:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[cfg_attr(
            feature = "serde",
            derive(serde::Serialize, serde::Deserialize),
            serde(rename_all = "snake_case")
        )]
        #[repr(u8)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $value ),+
        }

        impl $name {
            /// Every value, in wire order.
            pub const ALL: &'static [Self] = &[$(Self::$variant),+];

            /// The value's name in the ICD's table, as the messages' `Display` writes it.
            pub const fn name(self) -> &'static str {
                match self {
                    $( Self::$variant => $word, )+
                }
            }

            /// The value with its number, `2 transmit mission`, as the messages' `Display`
            /// writes the field their meaning hangs on (mode, type, status, command).
            pub const fn numbered(self) -> $crate::wire::Numbered {
                $crate::wire::Numbered {
                    number: self as u8,
                    name: self.name(),
                }
            }
        }

        impl TryFrom<u8> for $name {
            type Error = u8;
            fn try_from(v: u8) -> Result<Self, u8> {
                match v {
                    $( $value => Ok(Self::$variant), )+
                    other => Err(other),
                }
            }
        }

        impl $crate::wire::field::Codec for $name {
            const SIZE: usize = 1;
            fn decode(bytes: &[u8]) -> Result<Self, $crate::wire::error::Cause> {
                let v = $crate::wire::field::read_be(bytes) as u8;
                Self::try_from(v)
                    .map_err(|v| $crate::wire::error::Cause::Unsupported { value: u32::from(v) })
            }
            fn encode(&self, out: &mut [u8]) {
                $crate::wire::field::write_be(*self as u64, out);
            }
        }
    };
}

/// An enumerated value with its number and its name in the ICD, displayed `2 transmit mission`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Numbered {
    /// The value on the wire.
    pub number: u8,
    /// The value's name in the ICD's table.
    pub name: &'static str,
}

impl core::fmt::Display for Numbered {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} {}", self.number, self.name)
    }
}

pub mod enums;
pub mod error;
pub mod field;
pub mod frame;
pub mod msg;
mod presence;

pub use enums::*;
pub use error::{Cause, DecodeError, EncodeError, FieldRef, FrameError, MessageError, Reason};
pub use field::{
    Altitude, Angle, Checksum, OutOfRange, SafetyOffset, Speed, Text, TextError, Timestamp,
    TransferWindow, U3, Velocity,
};
pub use frame::{
    BROADCAST_ID, ChecksumWidth, Envelope, Frame, Frames, HEADER_LEN, IDD_VERSION, MAX_DATA_LEN,
    MAX_FRAME_LEN, MAX_SIGNED_FRAME_LEN, MessageProperties, SignatureTrailer, TRAILER_LEN, decode,
    encode, frames, mark_signed,
};
pub use msg::*;
