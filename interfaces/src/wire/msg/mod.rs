//! The messages of ICD §4, one module each, named as the ICD names them. Each is a typed value in
//! physical units with `decode` (message data to value, every rule of §3 and §4 checked) and
//! `encode` (value to message data, every field it has marked present).
//!
//! Encode does not validate: it writes what the value holds, so tests and tools can produce the
//! invalid messages a peer might send. Decode is where the rules live.
//!
//! Every message is `Display`ed on one line (after smoltcp's `Repr`s), so that no tool writes its
//! own description: `#<type> <ICD name>: <what it says>`, values in physical units, enumerated
//! values as the ICD's table names them, the discriminating one with its number (`mode 2
//! transmit mission`), optional fields only where present, time stamps left out (a log line
//! carries its own time). For example `#13002 UA Position Waypoint: waypoint 2: 48.275000 N
//! 11.645000 E, 120.0 m WGS-84, 25.0 m/s indicated airspeed, fly-by, track-to-fix, next 3`.

mod area_polygon_loop_segment;
mod area_status_alert;
mod area_transmission_command;
mod area_transmission_status;
mod from_to_next;
mod inertial_states;
mod message_acknowledgement;
mod mission_execute_command;
mod mission_report;
mod mission_transfer_command;
mod mission_upload_download_status;
mod ua_position_waypoint;
mod ua_route;
mod vehicle_specific_waypoint;

pub use area_polygon_loop_segment::{AreaPolygonLoopSegment, AreaShape, PolygonVertices};
pub use area_status_alert::AreaStatusAlert;
pub use area_transmission_command::{AreaTransmissionCommand, WindowOrChecksum};
pub use area_transmission_status::AreaTransmissionStatus;
pub use from_to_next::{FromToNext, FromWaypointState, WaypointState};
pub use inertial_states::InertialStates;
pub use message_acknowledgement::MessageAcknowledgement;
pub use mission_execute_command::MissionExecuteCommand;
pub use mission_report::MissionReport;
pub use mission_transfer_command::MissionTransferCommand;
pub use mission_upload_download_status::MissionUploadDownloadStatus;
pub use ua_position_waypoint::UaPositionWaypoint;
pub use ua_route::UaRoute;
pub use vehicle_specific_waypoint::{SpecificData, VehicleSpecificWaypoint};

use core::fmt;

#[cfg(feature = "ipc")]
use iceoryx2::prelude::ZeroCopySend;

use super::error::{Cause, EncodeError, MessageError};
use super::field::{Angle, OutOfRange, Text, Timestamp};
use super::presence::Reader;

/// One message type of ICD §4.
pub trait MessageBody: Sized {
    /// The STANAG message type.
    const TYPE: MessageType;
    /// Field names as in the ICD table; index = presence-vector bit.
    const FIELDS: &'static [&'static str];
    /// Width of the presence vector in bytes (U1, U2 or U3).
    const PV_BYTES: usize;
    /// Decodes message data (presence vector and fields).
    fn decode(data: &[u8]) -> Result<Self, MessageError>;
    /// Encodes message data into `out`; returns its length.
    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError>;
    /// Field 0, the time stamp that identifies the message.
    fn time_stamp(&self) -> Timestamp;
}

fn reader<M: MessageBody>(data: &[u8]) -> Result<Reader<'_>, MessageError> {
    Reader::new(M::TYPE as u16, M::FIELDS, M::PV_BYTES, data)
}

/// A waypoint number of #13002, #13001 and #13006: 1..=65534 (0 means none, 65535 is reserved).
fn is_waypoint_number(n: u16) -> bool {
    (1..=65534).contains(&n)
}

/// A latitude and longitude on WGS-84.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    zerocopy::TryFromBytes,
    zerocopy::IntoBytes,
    zerocopy::KnownLayout,
    zerocopy::Immutable,
)]
#[cfg_attr(feature = "ipc", derive(ZeroCopySend))]
#[repr(C)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GeoPoint {
    /// Latitude, -90..=90 deg.
    pub latitude: Angle,
    /// Longitude, -180..180 deg.
    pub longitude: Angle,
}

impl GeoPoint {
    /// The point at `latitude` and `longitude` in degrees.
    pub fn from_degrees(latitude: f64, longitude: f64) -> Result<Self, OutOfRange> {
        let latitude = Angle::from_degrees(latitude)?;
        if !latitude.is_latitude() {
            return Err(OutOfRange {
                quantity: "latitude (deg)",
                value: latitude.degrees(),
                min: -90.0,
                max: 90.0,
            });
        }
        Ok(Self {
            latitude,
            longitude: Angle::from_degrees(longitude)?,
        })
    }
}

/// Degrees with six decimals (about 0.1 m) and the hemisphere: `48.275000 N 11.645000 E`.
impl fmt::Display for GeoPoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (lat, lon) = (self.latitude.degrees(), self.longitude.degrees());
        let ns = if lat < 0.0 { 'S' } else { 'N' };
        let ew = if lon < 0.0 { 'W' } else { 'E' };
        write!(f, "{:.6} {ns} {:.6} {ew}", lat.abs(), lon.abs())
    }
}

/// `#13002 UA Position Waypoint`: the number and the name of the ICD.
impl fmt::Display for MessageType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{} {}", *self as u16, self.name())
    }
}

/// Writes `, <label> <value>` where an optional field is present (the messages' `Display`).
fn optional<T: fmt::Display>(
    f: &mut fmt::Formatter<'_>,
    label: &str,
    value: Option<T>,
) -> fmt::Result {
    match value {
        Some(v) => write!(f, ", {label} {v}"),
        None => Ok(()),
    }
}

/// ` (<reason>)` where a reject reason other than `None` is given.
fn reason(f: &mut fmt::Formatter<'_>, reason: Option<super::error::Reason>) -> fmt::Result {
    match reason {
        Some(r) if r != super::error::Reason::None => write!(f, " ({r})"),
        _ => Ok(()),
    }
}

/// `, 1 <thing>` or `, <n> <thing>s`: a count of waypoints or areas.
fn count(f: &mut fmt::Formatter<'_>, n: u16, thing: &str) -> fmt::Result {
    let s = if n == 1 { "" } else { "s" };
    write!(f, ", {n} {thing}{s}")
}

/// `all areas` for Area ID 0 (#2011 mode 3, #3013), else `area <id>`.
fn areas(f: &mut fmt::Formatter<'_>, area_id: u16) -> fmt::Result {
    match area_id {
        0 => f.write_str("all areas"),
        id => write!(f, "area {id}"),
    }
}

/// A Mission ID that names a staged mission (ICD §8: #13000 modes 6, 8, 9, #2011 modes 7, 8,
/// #50000 command 4): present (`MissingField`) and not empty, since an empty Mission ID names the
/// active lists, never a staged mission (`Inconsistent`, reason `Malformed`).
fn staged_mission_id(
    r: &Reader<'_>,
    bit: u8,
    id: Option<Text<20>>,
) -> Result<Text<20>, MessageError> {
    let id = r.require(bit, id)?;
    if id.is_empty() {
        Err(r.error(bit, Cause::Inconsistent))
    } else {
        Ok(id)
    }
}

/// An extension field (ext) of the field of `bit`, where `named` says whether its table names it
/// for the message's mode or command. ICD §3 has senders send extension fields only with the
/// modes their table names; what a receiver does with one sent otherwise is this project's
/// choice: it rejects the message (`Inconsistent`, reason `Malformed`) rather than ignore the
/// field, so that a sender who believes its checksum was compared or its window used learns that
/// it was not.
fn ext_field<T>(
    r: &Reader<'_>,
    bit: u8,
    value: Option<T>,
    named: bool,
) -> Result<Option<T>, MessageError> {
    if value.is_some() && !named {
        Err(r.error(bit, Cause::Inconsistent))
    } else {
        Ok(value)
    }
}

/// Checks that a decoded angle is a latitude (ICD §7: within +-90 deg).
fn latitude(r: &Reader<'_>, bit: u8, a: Angle) -> Result<Angle, MessageError> {
    if a.is_latitude() {
        Ok(a)
    } else {
        Err(r.error(
            bit,
            Cause::OutOfRange {
                value: i64::from(a.raw()),
            },
        ))
    }
}

macro_rules! messages {
    ($( $variant:ident = $code:literal, $name:literal; )+) => {
        /// The message types of ICD §4.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[repr(u16)]
        pub enum MessageType {
            $(
                #[doc = concat!("#", stringify!($code), " ", $name)]
                $variant = $code,
            )+
        }

        impl MessageType {
            /// Every message type.
            pub const ALL: &'static [Self] = &[$(Self::$variant),+];

            /// The name of the message in the ICD.
            pub const fn name(self) -> &'static str {
                match self {
                    $( Self::$variant => $name, )+
                }
            }

            /// Field names, index = presence-vector bit.
            pub const fn fields(self) -> &'static [&'static str] {
                match self {
                    $( Self::$variant => <$variant as MessageBody>::FIELDS, )+
                }
            }
        }

        impl TryFrom<u16> for MessageType {
            type Error = u16;
            fn try_from(v: u16) -> Result<Self, u16> {
                match v {
                    $( $code => Ok(Self::$variant), )+
                    other => Err(other),
                }
            }
        }

        /// Any message of ICD §4.
        #[derive(Debug, Clone, PartialEq, Eq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[allow(
            clippy::large_enum_variant,
            reason = "decoding allocates nothing: a #2012 (about 500 B) lives inline"
        )]
        pub enum Message {
            $(
                #[doc = concat!("#", stringify!($code), " ", $name)]
                $variant($variant),
            )+
        }

        impl Message {
            /// Decodes the message data of a message of type `message_type`.
            pub fn decode(message_type: u16, data: &[u8]) -> Result<Self, MessageError> {
                match MessageType::try_from(message_type) {
                    $( Ok(MessageType::$variant) => $variant::decode(data).map(Self::$variant), )+
                    Err(_) => Err(MessageError {
                        message_type,
                        field: None,
                        cause: Cause::UnknownMessageType,
                        time_stamp: None,
                    }),
                }
            }

            /// The time stamp of message data of type `message_type`, read as
            /// [`Message::decode`] reads it but without the other fields: what message sampling
            /// needs, which identifies a message by it (ICD §3). `None` for a type the ICD does
            /// not define, a presence vector cut short, an absent time stamp or one that does not
            /// decode: the cases where a rejection could not be acknowledged either.
            pub fn peek_time_stamp(message_type: u16, data: &[u8]) -> Option<Timestamp> {
                let read = match MessageType::try_from(message_type) {
                    $( Ok(MessageType::$variant) => reader::<$variant>(data), )+
                    Err(_) => return None,
                };
                match read {
                    Ok(reader) => reader.peeked_time_stamp(),
                    Err(error) => error.time_stamp,
                }
            }

            /// Encodes the message data into `out`; returns its length.
            pub fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
                match self {
                    $( Self::$variant(m) => m.encode(out), )+
                }
            }

            /// The message type.
            pub const fn message_type(&self) -> MessageType {
                match self {
                    $( Self::$variant(_) => MessageType::$variant, )+
                }
            }

            /// Field 0, the time stamp.
            pub fn time_stamp(&self) -> Timestamp {
                match self {
                    $( Self::$variant(m) => m.time_stamp(), )+
                }
            }

            /// Sets field 0, the time stamp: every message a sender originates, and every retry,
            /// gets a new one (ICD §3).
            pub fn set_time_stamp(&mut self, time_stamp: Timestamp) {
                match self {
                    $( Self::$variant(m) => m.time_stamp = time_stamp, )+
                }
            }
        }

        /// One line: the message's own `Display`.
        impl fmt::Display for Message {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                match self {
                    $( Self::$variant(m) => fmt::Display::fmt(m, f), )+
                }
            }
        }

        $(
            impl From<$variant> for Message {
                fn from(m: $variant) -> Self {
                    Self::$variant(m)
                }
            }
        )+
    };
}

messages! {
    MessageAcknowledgement = 17000, "Message Acknowledgement";
    MissionTransferCommand = 13000, "Mission Transfer Command";
    UaRoute = 13001, "UA Route";
    UaPositionWaypoint = 13002, "UA Position Waypoint";
    VehicleSpecificWaypoint = 13006, "Vehicle Specific Waypoint";
    MissionUploadDownloadStatus = 14000, "Mission Upload/Download Status";
    FromToNext = 4001, "FROM-TO-NEXT Waypoint States";
    InertialStates = 101, "Inertial States";
    AreaTransmissionCommand = 2011, "Area Transmission Command";
    AreaPolygonLoopSegment = 2012, "Area Polygon Loop Segment";
    AreaStatusAlert = 3012, "Area Status Alert";
    AreaTransmissionStatus = 3013, "Area Transmission Status";
    MissionExecuteCommand = 50000, "Mission Execute Command";
    MissionReport = 50001, "Mission Report";
}

/// Display check shared by the message modules: `message` and the [`Message`] holding it both
/// read `expected`.
#[cfg(test)]
pub(crate) fn assert_display(message: impl fmt::Display + Into<Message>, expected: &str) {
    assert_eq!(message.to_string(), expected);
    assert_eq!(message.into().to_string(), expected, "as a Message");
}

/// Golden-frame check shared by the message modules: `frame` decodes to `envelope` and
/// `message`, and encoding them into a buffer pre-filled with 0xa5 writes exactly `frame` and
/// nothing past it. With `MISSIONLINK_GOLDEN_DIR` set, writes `frame` there too (the seeds of
/// the fuzz targets, `fuzz-targets/examples/seed_corpora.rs`).
#[cfg(test)]
pub(crate) fn assert_golden(frame: &[u8], envelope: super::frame::Envelope, message: Message) {
    assert_eq!(
        super::frame::decode(frame).unwrap(),
        (envelope, message.clone()),
        "decode"
    );
    let mut buf = [0xa5; super::frame::MAX_FRAME_LEN + 4];
    let len = super::frame::encode(&envelope, &message, &mut buf).unwrap();
    assert_eq!(&buf[..len], frame, "emit");
    assert!(
        buf[len..].iter().all(|&b| b == 0xa5),
        "emit wrote past the frame"
    );
    // The golden frames seed the fuzzers (docs/fuzzing.md): with MISSIONLINK_GOLDEN_DIR set,
    // each is also written there, named by its type and its byte sum.
    if let Some(dir) = std::env::var_os("MISSIONLINK_GOLDEN_DIR") {
        let sum = super::frame::checksum(frame, super::frame::ChecksumWidth::Four);
        let name = format!("golden-{}-{sum:08x}", message.message_type() as u16);
        std::fs::write(std::path::Path::new(&dir).join(name), frame).unwrap();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_name_their_hemisphere() {
        let p = |lat, lon| GeoPoint::from_degrees(lat, lon).unwrap().to_string();
        assert_eq!(p(48.275, 11.645), "48.275000 N 11.645000 E");
        assert_eq!(p(-33.8688, -151.2093), "33.868800 S 151.209300 W");
        assert_eq!(p(0.0, 0.0), "0.000000 N 0.000000 E");
    }

    #[test]
    fn message_types_show_number_and_icd_name() {
        assert_eq!(
            MessageType::MissionUploadDownloadStatus.to_string(),
            "#14000 Mission Upload/Download Status"
        );
        for t in MessageType::ALL {
            assert!(t.to_string().ends_with(t.name()), "{t}");
        }
    }
}
