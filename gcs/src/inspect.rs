//! The frame inspector engineers use on captured link traffic: hex datagrams in, every message
//! with every field in readable units out (text or one JSON object per message); and the reverse,
//! a message given as JSON encoded into a hex frame.
//!
//! The JSON of a message is the same in both directions, so `gcs inspect --json | gcs encode`
//! gives back the frames it was fed:
//!
//! ```json
//! {"message_type":13002,"name":"UA Position Waypoint","source_id":"0x0a000001",
//!  "destination_id":"0x0b000001","ack_requested":true,"idd_version":40,"checksum":"four",
//!  "length":64,"fields":{"time_stamp":"2026-11-21T12:00:00.000Z","waypoint_number":1,...}}
//! ```
//!
//! Units in `fields`: angles in degrees, altitudes, heights and distances in metres, speeds in
//! m/s, time stamps as RFC 3339 UTC (milliseconds since 2000-01-01 are accepted on input); an
//! absent optional field is `null`.
//!
//! A signed frame (ICD §9) has `"signature"`: the trailer's Key ID, Link ID and signature, and
//! whether it verifies with the keys given (`--key`): `"verified"`, `"bad signature"`,
//! `"unknown key"`, `"no trailer"`, or `"not checked"` without keys. The Link ID is the one the
//! trailer names (a capture does not say which link a datagram came by). `gcs encode` ignores
//! it: it writes unsigned frames.

use std::fmt::Write as _;

use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{
    self, ChecksumWidth, DecodeError, Envelope, Frame, IDD_VERSION, MAX_FRAME_LEN, Message,
    MessageType,
};
use missionlink_protocol::link::signing::{self, Keyring, SignatureCause};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// A frame the inspector could not read, or a JSON message it could not encode.
#[derive(Debug, thiserror::Error)]
pub enum InspectError {
    /// The text is not hex.
    #[error("not a hex datagram: {0}")]
    Hex(hex::FromHexError),
    /// The frame is rejected (ICD §2) or the message is (ICD §3, §4).
    #[error("{0}")]
    Decode(DecodeError),
    /// The JSON does not describe a message.
    #[error("not a message in JSON: {0}")]
    Json(serde_json::Error),
    /// `message_type` names no message of the ICD.
    #[error("message type {0} is not in the ICD")]
    UnknownMessageType(u16),
    /// The message does not encode.
    #[error("cannot encode: {0}")]
    Encode(wire::EncodeError),
}

/// Parses one datagram written as hex; spaces, colons, underscores and a leading `0x` are
/// ignored so that captures pasted from tools read as they are.
pub fn parse_hex(text: &str) -> Result<Vec<u8>, InspectError> {
    let text = text.trim();
    let text = text
        .strip_prefix("0x")
        .or_else(|| text.strip_prefix("0X"))
        .unwrap_or(text);
    let digits: String = text
        .chars()
        .filter(|c| !c.is_whitespace() && !matches!(c, ':' | '_' | '-'))
        .collect();
    hex::decode(digits).map_err(InspectError::Hex)
}

/// An ID in JSON: a number or a hex string such as `"0x0A000001"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeId(pub u32);

impl Serialize for NodeId {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&format!("{:#010x}", self.0))
    }
}

impl<'de> Deserialize<'de> for NodeId {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Number(u32),
            Text(String),
        }
        match Raw::deserialize(d)? {
            Raw::Number(n) => Ok(Self(n)),
            Raw::Text(s) => missionlink_platform::config::parse_id(&s)
                .map(Self)
                .map_err(serde::de::Error::custom),
        }
    }
}

fn default_source() -> NodeId {
    NodeId(defaults::GCS_ID)
}
fn default_destination() -> NodeId {
    NodeId(defaults::FCC_ID)
}
fn default_idd_version() -> u8 {
    IDD_VERSION
}
fn default_checksum() -> ChecksumWidth {
    ChecksumWidth::Four
}

/// One message as JSON: the wrapper fields, then the message fields.
#[derive(Debug, Serialize, Deserialize)]
pub struct MessageJson {
    /// STANAG message type.
    pub message_type: u16,
    /// Name in the ICD (output only; ignored on input).
    #[serde(default, skip_deserializing)]
    pub name: String,
    /// Source ID; the GCS default on input when absent.
    #[serde(default = "default_source")]
    pub source_id: NodeId,
    /// Destination ID; the FCC default on input when absent.
    #[serde(default = "default_destination")]
    pub destination_id: NodeId,
    /// Acknowledgement requested.
    #[serde(default)]
    pub ack_requested: bool,
    /// IDD version.
    #[serde(default = "default_idd_version")]
    pub idd_version: u8,
    /// Checksum width.
    #[serde(default = "default_checksum")]
    pub checksum: ChecksumWidth,
    /// Frame length in bytes (output only; ignored on input).
    #[serde(default, skip_deserializing)]
    pub length: usize,
    /// The message fields.
    pub fields: Value,
    /// The signature trailer of a signed frame (output only; ignored on input).
    #[serde(default, skip_deserializing, skip_serializing_if = "Option::is_none")]
    pub signature: Option<SignatureJson>,
}

/// The signature trailer of ICD §9 as the inspector shows it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SignatureJson {
    /// Key ID.
    pub key_id: u8,
    /// Link ID: 0 direct, 1 LTE.
    pub link_id: u8,
    /// Reserved (0).
    pub reserved: u16,
    /// The 12 bytes of the signature, hex.
    pub signature: String,
    /// `verified`, `bad signature`, `unknown key`, `no trailer` (bit 5 set, the datagram ends
    /// before the 16 bytes), or `not checked` (no key given).
    pub verification: String,
}

impl SignatureJson {
    /// The trailer of `frame` and what `keys` make of it; `None` for an unsigned frame.
    fn of(frame: &Frame<'_>, keys: Option<&Keyring>) -> Option<Self> {
        if !frame.properties().signed() {
            return None;
        }
        let verification = match keys.map(|k| signing::check_signature(k, frame)) {
            None if frame.trailer().is_some() => "not checked",
            None | Some(Err(SignatureCause::NoTrailer)) => "no trailer",
            Some(Ok(_)) => "verified",
            Some(Err(SignatureCause::UnknownKey)) => "unknown key",
            Some(Err(SignatureCause::BadSignature | SignatureCause::Replay)) => "bad signature",
        };
        let trailer = frame.trailer();
        Some(Self {
            key_id: trailer.map_or(0, |t| t.key_id),
            link_id: trailer.map_or(0, |t| t.link_id),
            reserved: trailer.map_or(0, |t| t.reserved.get()),
            signature: trailer.map_or_else(String::new, |t| hex::encode(t.signature)),
            verification: verification.to_owned(),
        })
    }
}

impl MessageJson {
    /// The JSON of a decoded frame.
    pub fn new(
        envelope: &Envelope,
        message: &Message,
        length: usize,
    ) -> Result<Self, InspectError> {
        let t = message.message_type();
        // `Message` serializes as {"<Variant>": {fields}}: keep the fields.
        let fields = match serde_json::to_value(message).map_err(InspectError::Json)? {
            Value::Object(map) => map
                .into_iter()
                .next()
                .map(|(_, v)| v)
                .unwrap_or(Value::Null),
            other => other,
        };
        Ok(Self {
            message_type: t as u16,
            name: t.name().to_owned(),
            source_id: NodeId(envelope.source_id),
            destination_id: NodeId(envelope.destination_id),
            ack_requested: envelope.ack_requested,
            idd_version: envelope.idd_version,
            checksum: envelope.checksum,
            length,
            fields,
            signature: None,
        })
    }

    /// The envelope and message this JSON describes.
    pub fn to_message(&self) -> Result<(Envelope, Message), InspectError> {
        let t =
            MessageType::try_from(self.message_type).map_err(InspectError::UnknownMessageType)?;
        // The Rust variant name of the type is its Debug name.
        let mut tagged = serde_json::Map::new();
        tagged.insert(format!("{t:?}"), self.fields.clone());
        let message: Message =
            serde_json::from_value(Value::Object(tagged)).map_err(InspectError::Json)?;
        let envelope = Envelope {
            source_id: self.source_id.0,
            destination_id: self.destination_id.0,
            ack_requested: self.ack_requested,
            idd_version: self.idd_version,
            checksum: self.checksum,
        };
        Ok((envelope, message))
    }
}

/// A message read from a datagram, ready to print.
#[derive(Debug)]
pub struct Inspected {
    /// The wrapper fields.
    pub envelope: Envelope,
    /// The message.
    pub message: Message,
    /// Bytes of the frame.
    pub length: usize,
    /// The signature trailer of a signed frame.
    pub signature: Option<SignatureJson>,
}

/// Every message of a datagram, each decoded or with the error that stopped it. The walker stops
/// at a broken frame (nothing after it can be located); a rejected message does not stop it.
/// With `addressing = Some((local, peer))` the addressing rules of ICD §2 apply too; with `keys`
/// the signature of a signed frame is checked (ICD §9).
pub fn inspect_datagram(
    datagram: &[u8],
    addressing: Option<(u32, u32)>,
    keys: Option<&Keyring>,
) -> Vec<Result<Inspected, InspectError>> {
    wire::frames(datagram)
        .map(|frame| {
            let frame = frame.map_err(|e| InspectError::Decode(e.into()))?;
            if let Some((local, peer)) = addressing {
                frame
                    .check_addressing(local, peer)
                    .map_err(|e| InspectError::Decode(e.into()))?;
            }
            let message = frame
                .message()
                .map_err(|e| InspectError::Decode(e.into()))?;
            Ok(Inspected {
                envelope: frame.envelope(),
                message,
                length: frame.as_bytes().len(),
                signature: SignatureJson::of(&frame, keys),
            })
        })
        .collect()
}

/// Encodes the message a JSON object describes into a frame.
pub fn encode_json(json: &str) -> Result<Vec<u8>, InspectError> {
    let m: MessageJson = serde_json::from_str(json).map_err(InspectError::Json)?;
    let (envelope, message) = m.to_message()?;
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(&envelope, &message, &mut buf).map_err(InspectError::Encode)?;
    Ok(buf.get(..len).unwrap_or_default().to_vec())
}

/// The unit a field is printed with, by its name.
fn unit(key: &str) -> Option<(&'static str, usize)> {
    match key {
        "latitude" | "longitude" => Some(("°", 7)),
        "altitude" | "lower_altitude" | "upper_altitude" | "height" => Some(("m", 2)),
        "speed" => Some(("m/s", 1)),
        "safety_offset" => Some(("m", 1)),
        _ => None,
    }
}

fn render_value(out: &mut String, key: &str, value: &Value, depth: usize) {
    let pad = "  ".repeat(depth);
    match value {
        Value::Null => {
            let _ = writeln!(out, "{pad}{key}: (absent)");
        }
        Value::Object(map) => {
            let _ = writeln!(out, "{pad}{key}:");
            for (k, v) in map {
                render_value(out, k, v, depth + 1);
            }
        }
        Value::Array(items) => {
            let _ = writeln!(out, "{pad}{key}: {} items", items.len());
            for (i, v) in items.iter().enumerate() {
                render_value(out, &format!("[{i}]"), v, depth + 1);
            }
        }
        Value::Number(n) => match (unit(key), n.as_f64()) {
            (Some((u, decimals)), Some(x)) => {
                let _ = writeln!(out, "{pad}{key}: {x:.decimals$} {u}");
            }
            _ => {
                let _ = writeln!(out, "{pad}{key}: {n}");
            }
        },
        Value::String(s) => {
            let _ = writeln!(out, "{pad}{key}: {s}");
        }
        Value::Bool(b) => {
            let _ = writeln!(out, "{pad}{key}: {b}");
        }
    }
}

/// The text form: a header line with the wrapper, then every field, indented, in its unit.
pub fn render_text(m: &MessageJson) -> String {
    let mut out = format!(
        "#{} {}  {} -> {}  {}  IDD {}  checksum {} B  {} B\n",
        m.message_type,
        m.name,
        serde_json::to_value(m.source_id)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default(),
        serde_json::to_value(m.destination_id)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default(),
        if m.ack_requested {
            "ack requested"
        } else {
            "no ack"
        },
        m.idd_version,
        m.checksum.len(),
        m.length,
    );
    if let Some(s) = &m.signature {
        let link = match s.link_id {
            0 => "direct",
            1 => "LTE",
            _ => "unknown link",
        };
        let _ = writeln!(
            out,
            "  signed (ICD §9): key {}, link {} ({link}), signature {}: {}",
            s.key_id, s.link_id, s.signature, s.verification
        );
    }
    match &m.fields {
        Value::Object(map) => {
            for (k, v) in map {
                render_value(&mut out, k, v, 1);
            }
        }
        other => render_value(&mut out, "fields", other, 1),
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A #13002 of the demo mission 1 (CCP), as in docs/gcs.md ("The frame inspector").
    pub(crate) const DOCUMENTED_13002: &str = "ffff001d0a0000010b00000132caa880\
        002f6fc5932a9a000001225432100847e856001770030032000000000000000a12";

    #[test]
    fn hex_accepts_capture_spellings() {
        assert_eq!(parse_hex("0x01 02:03_04").unwrap(), [1, 2, 3, 4]);
        assert!(matches!(parse_hex("0g"), Err(InspectError::Hex(_))));
    }

    #[test]
    fn json_round_trip_of_every_frame_field() {
        let ts = wire::Timestamp::from_millis(848_577_600_000).unwrap();
        let message = Message::MissionExecuteCommand(wire::MissionExecuteCommand {
            time_stamp: ts,
            command: wire::ExecuteCommand::Execute,
            mission_id: None,
        });
        let envelope = Envelope::new(0x0A00_0001, 0x0B00_0001).with_ack(true);
        let json = MessageJson::new(&envelope, &message, 0).unwrap();
        let text = serde_json::to_string(&json).unwrap();
        let frame = encode_json(&text).unwrap();
        let (e, m) = wire::decode(&frame).unwrap();
        assert_eq!((e, m), (envelope, message));
    }

    #[test]
    fn unknown_type_is_refused_by_encode() {
        let err = encode_json(r#"{"message_type":9999,"fields":{}}"#).unwrap_err();
        assert!(matches!(err, InspectError::UnknownMessageType(9999)));
    }

    #[test]
    fn a_signed_frame_shows_its_trailer_and_whether_it_verifies() {
        use missionlink_interfaces::contracts::Link;
        use missionlink_protocol::link::signing::{LinkKey, Signer};
        let frame = parse_hex(DOCUMENTED_13002).unwrap();
        let key = LinkKey::new(3, &[9; 32]);
        let mut signed = [0u8; wire::MAX_SIGNED_FRAME_LEN];
        let len = Signer::new(key.clone())
            .sign(Link::Lte, &frame, &mut signed)
            .unwrap();
        let signed = &signed[..len];
        let mut right = Keyring::new();
        right.insert(key).unwrap();
        let mut wrong = Keyring::new();
        wrong.insert(LinkKey::new(3, &[8; 32])).unwrap();
        let mut other = Keyring::new();
        other.insert(LinkKey::new(4, &[9; 32])).unwrap();
        for (keys, expected) in [
            (None, "not checked"),
            (Some(&right), "verified"),
            (Some(&wrong), "bad signature"),
            (Some(&other), "unknown key"),
        ] {
            let all = inspect_datagram(signed, None, keys);
            let inspected = all[0].as_ref().unwrap();
            let s = inspected.signature.as_ref().unwrap();
            assert_eq!((s.key_id, s.link_id, s.reserved), (3, 1, 0));
            assert_eq!(s.signature, hex::encode(&signed[len - 12..]));
            assert_eq!(s.verification, expected);
            assert_eq!(inspected.length, frame.len());
        }
        // Marked signed, the trailer cut off.
        let all = inspect_datagram(&signed[..frame.len()], None, Some(&right));
        let s = all[0].as_ref().unwrap().signature.clone().unwrap();
        assert_eq!(s.verification, "no trailer");
        // An unsigned frame has none.
        let all = inspect_datagram(&frame, None, Some(&right));
        assert!(all[0].as_ref().unwrap().signature.is_none());
    }

    #[test]
    fn documented_frame_decodes() {
        let bytes = parse_hex(DOCUMENTED_13002).unwrap();
        let all = inspect_datagram(&bytes, None, None);
        assert_eq!(all.len(), 1);
        assert!(all[0].is_ok(), "{:?}", all[0]);
    }
}
