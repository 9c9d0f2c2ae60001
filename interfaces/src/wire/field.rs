//! Field encodings of ICD §3 (STANAG 4586 Ed 3 §1.7).
//!
//! Every scaled quantity is a newtype that stores the exact wire value, so a message decoded and
//! encoded again gives the same bytes, and a mission downloaded equals the mission uploaded. The
//! API is in physical units: constructors take degrees, metres, m/s or UTC time and refuse values
//! the encoding cannot carry; accessors give the same units back (within one LSB).

use core::fmt;

#[cfg(feature = "ipc")]
use iceoryx2::prelude::ZeroCopySend;

use super::error::Cause;

/// A value given in physical units that its wire encoding cannot represent.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{quantity} {value} is outside {min}..={max}")]
pub struct OutOfRange {
    /// The quantity, e.g. "latitude".
    pub quantity: &'static str,
    /// The value that was given, in the unit of the constructor.
    pub value: f64,
    /// Smallest value the encoding carries.
    pub min: f64,
    /// Largest value the encoding carries.
    pub max: f64,
}

fn checked(quantity: &'static str, value: f64, min: f64, max: f64) -> Result<f64, OutOfRange> {
    if value.is_finite() && value >= min && value <= max {
        Ok(value)
    } else {
        Err(OutOfRange {
            quantity,
            value,
            min,
            max,
        })
    }
}

/// Reads a big-endian unsigned integer of 1 to 8 bytes.
pub(crate) fn read_be(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0u64, |acc, b| (acc << 8) | u64::from(*b))
}

/// Writes the low `out.len()` bytes of `value` big-endian.
pub(crate) fn write_be(value: u64, out: &mut [u8]) {
    let mut v = value;
    for byte in out.iter_mut().rev() {
        *byte = (v & 0xff) as u8;
        v >>= 8;
    }
}

/// A field type of ICD §3: how many bytes it takes and how it is read and written.
///
/// `decode` gets exactly `SIZE` bytes; it checks only what the encoding itself forbids (an
/// undefined enumeration value, text without terminator). Ranges that depend on the field are
/// checked by the message.
pub trait Codec: Sized {
    /// Bytes on the wire.
    const SIZE: usize;
    /// Reads the field from exactly `SIZE` bytes.
    fn decode(bytes: &[u8]) -> Result<Self, Cause>;
    /// Writes the field into exactly `SIZE` bytes.
    fn encode(&self, out: &mut [u8]);
}

impl Codec for u8 {
    const SIZE: usize = 1;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        Ok(read_be(bytes) as u8)
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(*self), out);
    }
}

impl Codec for u16 {
    const SIZE: usize = 2;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        Ok(read_be(bytes) as u16)
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(*self), out);
    }
}

impl Codec for u32 {
    const SIZE: usize = 4;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        Ok(read_be(bytes) as u32)
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(*self), out);
    }
}

/// The codec of a newtype over an unsigned integer sent big-endian in `$size` bytes (U2, U3,
/// U5 and the scaled fields stored as their raw wire value): every bit pattern is a value.
macro_rules! unsigned_codec {
    ($t:ty, $inner:ty, $size:expr) => {
        impl Codec for $t {
            const SIZE: usize = $size;
            fn decode(bytes: &[u8]) -> Result<Self, Cause> {
                Ok(Self(read_be(bytes) as $inner))
            }
            fn encode(&self, out: &mut [u8]) {
                write_be(u64::from(self.0), out);
            }
        }
    };
}

/// U3: a 24-bit unsigned integer (Activity ID fields).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "u32", into = "u32"))]
pub struct U3(u32);

impl U3 {
    /// Largest value of a U3.
    pub const MAX: u32 = (1 << 24) - 1;

    /// A U3 holding `value`, if it fits 24 bits.
    pub const fn new(value: u32) -> Option<Self> {
        if value <= Self::MAX {
            Some(Self(value))
        } else {
            None
        }
    }

    /// The value.
    pub const fn get(self) -> u32 {
        self.0
    }
}

impl TryFrom<u32> for U3 {
    type Error = OutOfRange;
    fn try_from(value: u32) -> Result<Self, Self::Error> {
        Self::new(value).ok_or(OutOfRange {
            quantity: "U3",
            value: f64::from(value),
            min: 0.0,
            max: f64::from(Self::MAX),
        })
    }
}

impl From<U3> for u32 {
    fn from(v: U3) -> u32 {
        v.0
    }
}

unsigned_codec!(U3, u32, 3);

/// BAM4 angle (ICD §3): a signed 32-bit binary angle, LSB = pi / 2^31 rad. Latitude and
/// longitude on WGS-84. One LSB is about 9.3 mm of latitude.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
pub struct Angle(i32);

impl Angle {
    /// Degrees per LSB: 180 / 2^31.
    pub const LSB_DEGREES: f64 = 180.0 / 2_147_483_648.0;

    /// The angle with this raw BAM4 value.
    pub const fn from_raw(raw: i32) -> Self {
        Self(raw)
    }

    /// The raw BAM4 value.
    pub const fn raw(self) -> i32 {
        self.0
    }

    /// The angle nearest to `degrees`, which must lie in -180..=180 (180 and -180 are the same
    /// BAM4 value).
    pub fn from_degrees(degrees: f64) -> Result<Self, OutOfRange> {
        let d = checked("angle (deg)", degrees, -180.0, 180.0)?;
        let raw = (d / Self::LSB_DEGREES).round() as i64;
        // +180 deg is 2^31, one past i32::MAX: on the circle it is -180 deg.
        Ok(Self(if raw >= 1 << 31 { i32::MIN } else { raw as i32 }))
    }

    /// The angle nearest to `radians`, in -pi..=pi.
    pub fn from_radians(radians: f64) -> Result<Self, OutOfRange> {
        Self::from_degrees(radians.to_degrees())
    }

    /// The angle in degrees, -180..180.
    pub fn degrees(self) -> f64 {
        f64::from(self.0) * Self::LSB_DEGREES
    }

    /// The angle in radians, -pi..pi.
    pub fn radians(self) -> f64 {
        self.degrees().to_radians()
    }

    /// Whether the angle is a latitude, -90..=90 deg (ICD §7).
    pub fn is_latitude(self) -> bool {
        self.0.unsigned_abs() <= 1 << 30
    }
}

impl fmt::Debug for Angle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.7}°", self.degrees())
    }
}

impl Codec for Angle {
    const SIZE: usize = 4;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        Ok(Self(read_be(bytes) as u32 as i32))
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(self.0 as u32), out);
    }
}

/// ALT3 altitude or height (ICD §3): a signed 24-bit integer, LSB 0.02 m.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
pub struct Altitude(i32);

impl Altitude {
    /// Metres per LSB.
    pub const LSB_METRES: f64 = 0.02;
    /// Zero metres.
    pub const ZERO: Self = Self(0);
    const MIN_RAW: i32 = -(1 << 23);
    const MAX_RAW: i32 = (1 << 23) - 1;

    /// The altitude with this raw ALT3 value, if it fits 24 bits.
    pub const fn from_raw(raw: i32) -> Option<Self> {
        if raw >= Self::MIN_RAW && raw <= Self::MAX_RAW {
            Some(Self(raw))
        } else {
            None
        }
    }

    /// The raw ALT3 value.
    pub const fn raw(self) -> i32 {
        self.0
    }

    /// The altitude nearest to `metres` (about -167772 m to +167772 m).
    pub fn from_metres(metres: f64) -> Result<Self, OutOfRange> {
        let m = checked(
            "altitude (m)",
            metres,
            f64::from(Self::MIN_RAW) * Self::LSB_METRES,
            f64::from(Self::MAX_RAW) * Self::LSB_METRES,
        )?;
        Ok(Self((m * 50.0).round() as i32))
    }

    /// The altitude in metres.
    pub fn metres(self) -> f64 {
        f64::from(self.0) / 50.0
    }
}

impl fmt::Debug for Altitude {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.2} m", self.metres())
    }
}

impl Codec for Altitude {
    const SIZE: usize = 3;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        // Sign-extend 24 to 32 bits.
        let raw = ((read_be(bytes) as u32) << 8) as i32 >> 8;
        Ok(Self(raw))
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(self.0 as u32 & 0x00ff_ffff), out);
    }
}

/// SPD2 speed (ICD §3): an unsigned 16-bit integer, LSB 0.5 m/s.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
pub struct Speed(u16);

impl Speed {
    /// Metres per second per LSB.
    pub const LSB_MPS: f64 = 0.5;

    /// The speed with this raw SPD2 value.
    pub const fn from_raw(raw: u16) -> Self {
        Self(raw)
    }

    /// The raw SPD2 value.
    pub const fn raw(self) -> u16 {
        self.0
    }

    /// The speed nearest to `mps` (0 to 32767.5 m/s).
    pub fn from_mps(mps: f64) -> Result<Self, OutOfRange> {
        let v = checked("speed (m/s)", mps, 0.0, f64::from(u16::MAX) * Self::LSB_MPS)?;
        Ok(Self((v * 2.0).round() as u16))
    }

    /// The speed in metres per second.
    pub fn mps(self) -> f64 {
        f64::from(self.0) * Self::LSB_MPS
    }
}

impl fmt::Debug for Speed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.1} m/s", self.mps())
    }
}

unsigned_codec!(Speed, u16, 2);

/// VEL2 velocity (ICD §3): a signed 16-bit integer, LSB 0.05 m/s (about -1638 to +1638 m/s);
/// the north, east and down speeds of #101.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
pub struct Velocity(i16);

impl Velocity {
    /// Metres per second per LSB.
    pub const LSB_MPS: f64 = 0.05;

    /// The velocity with this raw VEL2 value.
    pub const fn from_raw(raw: i16) -> Self {
        Self(raw)
    }

    /// The raw VEL2 value.
    pub const fn raw(self) -> i16 {
        self.0
    }

    /// The velocity nearest to `mps`.
    pub fn from_mps(mps: f64) -> Result<Self, OutOfRange> {
        let v = checked(
            "velocity (m/s)",
            mps,
            f64::from(i16::MIN) * Self::LSB_MPS,
            f64::from(i16::MAX) * Self::LSB_MPS,
        )?;
        Ok(Self((v / Self::LSB_MPS).round() as i16))
    }

    /// The velocity in metres per second.
    pub fn mps(self) -> f64 {
        f64::from(self.0) * Self::LSB_MPS
    }
}

impl fmt::Debug for Velocity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.2} m/s", self.mps())
    }
}

impl Codec for Velocity {
    const SIZE: usize = 2;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        Ok(Self(read_be(bytes) as u16 as i16))
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(self.0 as u16), out);
    }
}

/// I2: a signed 16-bit integer (the fields of #101 this project carries but never fills, kept
/// as their raw wire value).
impl Codec for i16 {
    const SIZE: usize = 2;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        Ok(read_be(bytes) as u16 as i16)
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(*self as u16), out);
    }
}

/// Safety offset of #2011 and #3013 (ICD §4): an unsigned 16-bit distance, LSB 0.1 m.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
pub struct SafetyOffset(u16);

impl SafetyOffset {
    /// Metres per LSB.
    pub const LSB_METRES: f64 = 0.1;

    /// The offset with this raw value.
    pub const fn from_raw(raw: u16) -> Self {
        Self(raw)
    }

    /// The raw value.
    pub const fn raw(self) -> u16 {
        self.0
    }

    /// The offset nearest to `metres` (0 to 6553.5 m).
    pub fn from_metres(metres: f64) -> Result<Self, OutOfRange> {
        let m = checked(
            "safety offset (m)",
            metres,
            0.0,
            f64::from(u16::MAX) * Self::LSB_METRES,
        )?;
        Ok(Self((m * 10.0).round() as u16))
    }

    /// The offset in metres.
    pub fn metres(self) -> f64 {
        f64::from(self.0) / 10.0
    }
}

impl fmt::Debug for SafetyOffset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.1} m", self.metres())
    }
}

unsigned_codec!(SafetyOffset, u16, 2);

/// U4 checksum of ICD §11 (ext): the CRC-32/ISO-HDLC of a list's canonical form, carried by
/// #13000 field 7, #2011 field 7, #14000 field 7 and #50001 fields 8 and 9. Every bit pattern is
/// a checksum; what it covers is §11's business, not the wire's.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(from = "u32", into = "u32"))]
pub struct Checksum(u32);

impl Checksum {
    /// The checksum with this value.
    pub const fn new(value: u32) -> Self {
        Self(value)
    }

    /// The value.
    pub const fn value(self) -> u32 {
        self.0
    }
}

impl From<u32> for Checksum {
    fn from(value: u32) -> Self {
        Self(value)
    }
}

impl From<Checksum> for u32 {
    fn from(c: Checksum) -> u32 {
        c.0
    }
}

/// `0x` and eight upper-case hex digits, `0xCBF43926`: a checksum is compared by eye.
impl fmt::Display for Checksum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:08X}", self.0)
    }
}

impl fmt::Debug for Checksum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

unsigned_codec!(Checksum, u32, 4);

/// Transfer Window of ICD §10.2 (ext): how many data messages the requester of a download
/// accepts in flight, 1..=32 (absent = 1). A U1 in #13000 field 6; in #2011 field 7 the same
/// value in a U4 (see `WindowOrChecksum`). A value outside 1..=32 does not decode (`OutOfRange`,
/// reason `Malformed`), so a window held is always one a receiver of edition 2 accepts.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "u32", into = "u32"))]
pub struct TransferWindow(u8);

impl TransferWindow {
    /// Smallest window: stop-and-wait, exactly edition 1 (ICD §10.2).
    pub const MIN: u8 = 1;
    /// Largest window: the data messages a receiver of edition 2 accepts in flight.
    pub const MAX: u8 = 32;
    /// The window of a request without the field (ICD §10.2: absent = 1).
    pub const ONE: Self = Self(1);

    /// The window of `messages` data messages, if it lies in 1..=32.
    pub const fn new(messages: u8) -> Option<Self> {
        if messages >= Self::MIN && messages <= Self::MAX {
            Some(Self(messages))
        } else {
            None
        }
    }

    /// Data messages in flight.
    pub const fn get(self) -> u8 {
        self.0
    }
}

impl Default for TransferWindow {
    fn default() -> Self {
        Self::ONE
    }
}

impl TryFrom<u32> for TransferWindow {
    type Error = OutOfRange;
    fn try_from(value: u32) -> Result<Self, Self::Error> {
        u8::try_from(value)
            .ok()
            .and_then(Self::new)
            .ok_or(OutOfRange {
                quantity: "transfer window",
                value: f64::from(value),
                min: f64::from(Self::MIN),
                max: f64::from(Self::MAX),
            })
    }
}

impl From<TransferWindow> for u32 {
    fn from(w: TransferWindow) -> u32 {
        u32::from(w.0)
    }
}

impl fmt::Display for TransferWindow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

impl fmt::Debug for TransferWindow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

/// The U1 of #13000 field 6; its range is the field's definition in every message, so it is
/// checked here rather than by the message.
impl Codec for TransferWindow {
    const SIZE: usize = 1;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        let v = read_be(bytes) as u8;
        Self::new(v).ok_or(Cause::OutOfRange {
            value: i64::from(v),
        })
    }
    fn encode(&self, out: &mut [u8]) {
        write_be(u64::from(self.0), out);
    }
}

/// TS time stamp (ICD §3): milliseconds since 2000-01-01T00:00:00Z (UTC) in a U5.
///
/// A time stamp is an identity (ICD §3): together with Source ID and Message Type it names one
/// message. The U5 runs out in 2034-11-01.
#[derive(
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    PartialOrd,
    Ord,
    zerocopy::TryFromBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
pub struct Timestamp(u64);

impl Timestamp {
    /// Largest value of a U5.
    pub const MAX_MILLIS: u64 = (1 << 40) - 1;
    /// 2000-01-01T00:00:00Z in milliseconds since the Unix epoch.
    pub const EPOCH_UNIX_MILLIS: u64 = 946_684_800_000;

    /// The time stamp `millis` milliseconds after 2000-01-01T00:00:00Z, if it fits a U5.
    pub const fn from_millis(millis: u64) -> Option<Self> {
        if millis <= Self::MAX_MILLIS {
            Some(Self(millis))
        } else {
            None
        }
    }

    /// Milliseconds since 2000-01-01T00:00:00Z.
    pub const fn millis(self) -> u64 {
        self.0
    }

    /// The time stamp of a Unix time in milliseconds, if it lies between 2000 and 2034.
    pub const fn from_unix_millis(unix_millis: u64) -> Option<Self> {
        match unix_millis.checked_sub(Self::EPOCH_UNIX_MILLIS) {
            Some(m) => Self::from_millis(m),
            None => None,
        }
    }

    /// Milliseconds since the Unix epoch.
    pub const fn unix_millis(self) -> u64 {
        self.0 + Self::EPOCH_UNIX_MILLIS
    }

    /// The time stamp as a UTC date and time.
    pub fn to_utc(self) -> time::OffsetDateTime {
        // Both bounds are far inside what OffsetDateTime holds, so the fallback never applies.
        time::OffsetDateTime::from_unix_timestamp_nanos(i128::from(self.unix_millis()) * 1_000_000)
            .unwrap_or(time::OffsetDateTime::UNIX_EPOCH)
    }

    /// The time stamp of a UTC date and time (truncated to the millisecond), if it fits a U5.
    pub fn from_utc(t: time::OffsetDateTime) -> Option<Self> {
        let ms = t.unix_timestamp_nanos().div_euclid(1_000_000);
        u64::try_from(ms).ok().and_then(Self::from_unix_millis)
    }

    /// The time stamp one millisecond later, if it still fits a U5.
    pub const fn next(self) -> Option<Self> {
        Self::from_millis(self.0 + 1)
    }
}

/// RFC 3339 in UTC with milliseconds, e.g. `2026-11-21T16:46:11.123Z`.
impl fmt::Display for Timestamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = self.to_utc();
        write!(
            f,
            "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z",
            t.year(),
            u8::from(t.month()),
            t.day(),
            t.hour(),
            t.minute(),
            t.second(),
            t.millisecond()
        )
    }
}

impl fmt::Debug for Timestamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

unsigned_codec!(Timestamp, u64, 5);

/// CharN text (ICD §3): `N` bytes, NUL padded, the width including the terminator, so at most
/// `N - 1` characters. This project carries UTF-8.
// Ordered by its bytes: NUL padding sorts a text before every longer text it begins.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Text<const N: usize>([u8; N]);

/// Why a string cannot be a [`Text`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum TextError {
    /// Longer than `N - 1` bytes.
    #[error("text of {len} bytes, at most {max} fit")]
    TooLong {
        /// Bytes given.
        len: usize,
        /// Most bytes the field holds.
        max: usize,
    },
    /// Holds a NUL character, which would end the text early.
    #[error("text contains a NUL character")]
    ContainsNul,
}

impl<const N: usize> Text<N> {
    /// The text `s`, if it has at most `N - 1` bytes and no NUL.
    pub fn new(s: &str) -> Result<Self, TextError> {
        let bytes = s.as_bytes();
        if bytes.contains(&0) {
            return Err(TextError::ContainsNul);
        }
        let max = N.saturating_sub(1);
        if bytes.len() > max {
            return Err(TextError::TooLong {
                len: bytes.len(),
                max,
            });
        }
        let mut out = [0u8; N];
        for (o, b) in out.iter_mut().zip(bytes) {
            *o = *b;
        }
        Ok(Self(out))
    }

    /// Whether the text has no characters (the field is all NUL).
    pub fn is_empty(&self) -> bool {
        self.0.first().is_none_or(|b| *b == 0)
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        let end = self.0.iter().position(|b| *b == 0).unwrap_or(N);
        // Construction and decoding guarantee UTF-8 up to the terminator.
        self.0
            .get(..end)
            .and_then(|b| core::str::from_utf8(b).ok())
            .unwrap_or("")
    }
}

impl<const N: usize> Default for Text<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

impl<const N: usize> fmt::Debug for Text<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl<const N: usize> Codec for Text<N> {
    const SIZE: usize = N;
    fn decode(bytes: &[u8]) -> Result<Self, Cause> {
        let raw: [u8; N] = bytes.try_into().map_err(|_| Cause::Truncated)?;
        // The terminator is part of the width: a full field without NUL is malformed, and so
        // is padding that is not NUL, or text that is not UTF-8.
        let end = raw.iter().position(|b| *b == 0).ok_or(Cause::BadText)?;
        let (text, padding) = raw.split_at(end);
        if padding.iter().any(|b| *b != 0) || core::str::from_utf8(text).is_err() {
            return Err(Cause::BadText);
        }
        Ok(Self(raw))
    }
    fn encode(&self, out: &mut [u8]) {
        for (o, b) in out.iter_mut().zip(self.0.iter()) {
            *o = *b;
        }
    }
}

#[cfg(feature = "serde")]
mod serde_impls {
    //! JSON in physical units: angles in degrees, altitudes and distances in metres, speeds in
    //! m/s, time stamps as RFC 3339 UTC (or milliseconds since 2000 on input), text as strings.
    use super::*;
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    macro_rules! physical {
        ($ty:ty, $to:ident, $from:ident) => {
            impl Serialize for $ty {
                fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                    s.serialize_f64(self.$to())
                }
            }
            impl<'de> Deserialize<'de> for $ty {
                fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                    <$ty>::$from(f64::deserialize(d)?).map_err(D::Error::custom)
                }
            }
        };
    }
    physical!(Angle, degrees, from_degrees);
    physical!(Altitude, metres, from_metres);
    physical!(Speed, mps, from_mps);
    physical!(Velocity, mps, from_mps);
    physical!(SafetyOffset, metres, from_metres);

    impl Serialize for Timestamp {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            s.collect_str(self)
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum TimestampInput {
        Millis(u64),
        Utc(String),
    }

    impl<'de> Deserialize<'de> for Timestamp {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            match TimestampInput::deserialize(d)? {
                TimestampInput::Millis(ms) => Timestamp::from_millis(ms).ok_or_else(|| {
                    D::Error::custom(format_args!("time stamp {ms} ms does not fit a U5"))
                }),
                TimestampInput::Utc(s) => {
                    let t = time::OffsetDateTime::parse(
                        &s,
                        &time::format_description::well_known::Rfc3339,
                    )
                    .map_err(|e| D::Error::custom(format_args!("time stamp {s:?}: {e}")))?;
                    Timestamp::from_utc(t).ok_or_else(|| {
                        D::Error::custom(format_args!("time stamp {s} is outside 2000..2034"))
                    })
                }
            }
        }
    }

    impl<const N: usize> Serialize for Text<N> {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            s.serialize_str(self.as_str())
        }
    }

    impl<'de, const N: usize> Deserialize<'de> for Text<N> {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            let s = String::deserialize(d)?;
            Text::new(&s).map_err(D::Error::custom)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bam4_scale_and_wrap() {
        // 90 deg = 2^30 LSB; 180 deg wraps to i32::MIN (= -180 deg).
        assert_eq!(Angle::from_degrees(90.0).unwrap().raw(), 1 << 30);
        assert_eq!(Angle::from_degrees(-90.0).unwrap().raw(), -(1 << 30));
        assert_eq!(Angle::from_degrees(180.0).unwrap().raw(), i32::MIN);
        assert_eq!(Angle::from_degrees(-180.0).unwrap().raw(), i32::MIN);
        assert!(Angle::from_degrees(180.1).is_err());
        assert!(Angle::from_degrees(f64::NAN).is_err());
        assert!(Angle::from_raw(1 << 30).is_latitude());
        assert!(!Angle::from_raw((1 << 30) + 1).is_latitude());
    }

    #[test]
    fn alt3_sign_extension() {
        let mut b = [0u8; 3];
        Altitude::from_metres(-0.02).unwrap().encode(&mut b);
        assert_eq!(b, [0xff, 0xff, 0xff]);
        assert_eq!(Altitude::decode(&b).unwrap().raw(), -1);
        assert_eq!(Altitude::decode(&[0x80, 0, 0]).unwrap().raw(), -(1 << 23));
        assert!(Altitude::from_metres(167_800.0).is_err());
    }

    #[test]
    fn text_rules() {
        assert_eq!(Text::<4>::new("abc").unwrap().as_str(), "abc");
        assert!(matches!(
            Text::<4>::new("abcd"),
            Err(TextError::TooLong { len: 4, max: 3 })
        ));
        assert!(matches!(Text::<4>::new("a\0"), Err(TextError::ContainsNul)));
        assert_eq!(Text::<4>::decode(b"abcd"), Err(Cause::BadText));
        assert_eq!(Text::<4>::decode(b"a\0b\0"), Err(Cause::BadText));
        assert_eq!(Text::<4>::decode(b"\xff\0\0\0"), Err(Cause::BadText));
    }

    #[test]
    fn checksum_shows_eight_upper_case_hex_digits() {
        assert_eq!(Checksum::new(0xCBF4_3926).to_string(), "0xCBF43926");
        assert_eq!(Checksum::new(0x1A).to_string(), "0x0000001A");
        let mut b = [0u8; 4];
        Checksum::new(0x1A2B_3C4D).encode(&mut b);
        assert_eq!(b, [0x1a, 0x2b, 0x3c, 0x4d]);
        assert_eq!(Checksum::decode(&b), Ok(Checksum::new(0x1A2B_3C4D)));
        assert_eq!(Checksum::new(7).value(), 7);
    }

    #[test]
    fn transfer_window_is_1_to_32() {
        assert_eq!(TransferWindow::new(0), None);
        assert_eq!(TransferWindow::new(1), Some(TransferWindow::ONE));
        assert_eq!(TransferWindow::new(32).map(TransferWindow::get), Some(32));
        assert_eq!(TransferWindow::new(33), None);
        assert_eq!(TransferWindow::default(), TransferWindow::ONE);
        assert!(
            TransferWindow::try_from(256 + 4).is_err(),
            "no truncation to a U1"
        );
        assert_eq!(TransferWindow::try_from(4).map(TransferWindow::get), Ok(4));
        assert_eq!(
            TransferWindow::decode(&[32]).map(TransferWindow::get),
            Ok(32)
        );
        assert_eq!(
            TransferWindow::decode(&[0]),
            Err(Cause::OutOfRange { value: 0 })
        );
        assert_eq!(
            TransferWindow::decode(&[33]),
            Err(Cause::OutOfRange { value: 33 })
        );
    }

    #[test]
    fn empty_text() {
        assert!(Text::<20>::default().is_empty());
        assert!(Text::<20>::new("").unwrap().is_empty());
        assert!(!Text::<20>::new("M").unwrap().is_empty());
    }

    #[test]
    fn timestamp_utc() {
        let t = Timestamp::from_millis(0).unwrap();
        assert_eq!(t.to_string(), "2000-01-01T00:00:00.000Z");
        // 2026-11-21T16:46:11.123Z is 1795279571123 ms Unix.
        let t = Timestamp::from_unix_millis(1_795_279_571_123).unwrap();
        assert_eq!(t.to_string(), "2026-11-21T16:46:11.123Z");
        assert_eq!(Timestamp::from_utc(t.to_utc()), Some(t));
        assert!(Timestamp::from_millis(1 << 40).is_none());
    }
}
