//! The Wireshark dissector (`tools/wireshark/missionlink.lua`) against the Rust wire layer, so the
//! two cannot drift: tshark runs the dissector over captures of every message type (edition-2
//! fields, signed frames with their trailer, several messages per datagram, every checksum
//! width) and over the committed capture of the demo, and every field it shows must equal what
//! `gcs inspect --json` says of the same datagram; frames that break a rule of ICD §2 must carry
//! the dissector's expert info. The dissector's field labels and value names are checked against
//! `MessageType::fields()` and the Rust enumerations.
//!
//! tshark must be installed (CI installs it: `.ci/run`); without it these tests fail, they do
//! not skip.

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::SystemTime;

use missionlink_gcs::inspect::encode_json;
use missionlink_gcs::pcap::PcapWriter;
use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::wire::{self, MessageType};
use missionlink_protocol::link::signing::{LinkKey, Signer};
use serde::Serialize;
use serde_json::Value;

fn dissector() -> PathBuf {
    crate::support::repo_dir().join("tools/wireshark/missionlink.lua")
}

/// The committed capture of the demo (`cargo run --release -- --pcap ...`).
fn demo_capture() -> PathBuf {
    crate::support::repo_dir().join("tools/wireshark/demo.pcap")
}

/// Fails the test with what to do: CI installs tshark, so its absence is a failure, not a skip.
fn missing_tshark(e: std::io::Error) -> ! {
    panic!(
        "cannot run tshark ({e}): the dissector test needs it. Install it with \
         `DEBIAN_FRONTEND=noninteractive apt-get install -y tshark` (.ci/run does)"
    )
}

/// Runs tshark with the dissector (its heuristic on, whatever the user's preferences say: the
/// demo's ports are the system's choice).
fn tshark(args: &[&str]) -> String {
    let lua = format!("lua_script:{}", dissector().display());
    let out = Command::new("tshark")
        .args(args)
        .args(["-X", &lua, "-o", "missionlink.heuristic:TRUE"])
        .output()
        .unwrap_or_else(|e| missing_tshark(e));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "tshark {args:?} failed: {stderr}");
    // A Lua error is printed, not fatal: treat it as a failure.
    assert!(
        !stderr.contains("Lua: Error") && !stderr.contains("lua_script"),
        "the dissector did not load: {stderr}"
    );
    String::from_utf8(out.stdout).unwrap()
}

/// `gcs inspect --json` of one datagram: the messages it prints and whether it accepted all.
fn inspect(datagram: &[u8]) -> (Vec<Value>, Output) {
    let out = crate::support::gcs_with_input(
        &["inspect", "--json"],
        &format!("{}\n", hex::encode(datagram)),
    );
    let messages = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (messages, out)
}

// ---------------------------------------------------------------------------------------------
// Captures

/// Every message type of ICD §4 with every field it can carry present (edition-2 fields where
/// the mode allows them), as `gcs encode` reads them.
const MESSAGES: &[&str] = &[
    r#"{"message_type":17000,"source_id":"0x0b000001","destination_id":"0x0a000001","fields":{"time_stamp":"2026-11-21T12:01:00.650Z","original_time_stamp":"2026-11-21T12:01:00.600Z","original_message_type":13000,"ack_type":"rejected","reject_reason":"broken_chain"}}"#,
    r#"{"message_type":13000,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:01:01.000Z","mission_id":"MEDEVAC-2","mode":"stage_mission","waypoint_number":3,"route_id":"TROL-CCP","activity_id":5,"transfer_window":null,"mission_checksum":439041101}}"#,
    r#"{"message_type":13000,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:01:01.001Z","mission_id":"MEDEVAC-2","mode":"receive_staged_mission","waypoint_number":null,"route_id":null,"activity_id":null,"transfer_window":8,"mission_checksum":null}}"#,
    r#"{"message_type":13001,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:01:02.000Z","initial_waypoint":1,"route_id":"ROUTE-ÄÖ","route_type":"contingency_b","bidirectional":true}}"#,
    r#"{"message_type":13002,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:01:00.300Z","waypoint_number":3,"latitude":48.28,"longitude":11.68,"location_type":"absolute","altitude":120.0,"altitude_type":"wgs84","altitude_change_behaviour":1,"speed":25.0,"speed_type":"true_airspeed","next_waypoint":0,"turn_type":"fly_over","optional_messages":1,"leg_type":"radius_to_fix","limit_type":2,"loop_limit":5,"arrival_time":"2026-11-21T12:06:00.000Z","activity_id":42}}"#,
    r#"{"message_type":13002,"checksum":"two","fields":{"time_stamp":"2026-11-21T12:01:00.301Z","waypoint_number":65534,"latitude":-33.865143,"longitude":-151.2099,"location_type":null,"altitude":-12.5,"altitude_type":"agl","altitude_change_behaviour":null,"speed":0.5,"speed_type":null,"next_waypoint":2,"turn_type":"fly_by","optional_messages":null,"leg_type":"track_to_fix","limit_type":null,"loop_limit":null,"arrival_time":null,"activity_id":null}}"#,
    r#"{"message_type":13002,"checksum":"none","fields":{"time_stamp":"2026-11-21T12:01:00.302Z","waypoint_number":2,"latitude":90.0,"longitude":-180.0,"altitude":0.0,"speed":1.0,"next_waypoint":3,"turn_type":"fly_by","leg_type":"track_to_fix"}}"#,
    r#"{"message_type":13006,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:01:00.000Z","data":{"take_off_height":{"height":30.0}},"activity_id":7}}"#,
    r#"{"message_type":13006,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:01:00.400Z","data":{"rf_centre":{"waypoint_number":3,"latitude":48.2745,"longitude":11.6699,"turn_direction":"counter_clockwise"}},"activity_id":null}}"#,
    r#"{"message_type":14000,"source_id":"0x0b000001","destination_id":"0x0a000001","ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:02:01.000Z","mission_id":"MEDEVAC-2","status":"complete","percent_complete":100,"waypoint_request":3,"mode":"receive_staged_mission","reason":"none","mission_checksum":439041101}}"#,
    r#"{"message_type":14000,"source_id":"0x0b000001","destination_id":"0x0a000001","ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:02:02.000Z","mission_id":null,"status":"aborted","percent_complete":40,"waypoint_request":null,"mode":"receive_mission","reason":"integrity_mismatch","mission_checksum":null}}"#,
    r#"{"message_type":4001,"source_id":"0x0b000001","destination_id":"0x0a000001","fields":{"time_stamp":"2026-11-21T12:05:00.000Z","altitude_type":"wgs84","speed_type":"ground_speed","from":{"latitude":48.275,"longitude":11.645,"altitude":120.0,"time":"2026-11-21T12:04:10.000Z","waypoint_number":1},"to":{"latitude":48.278,"longitude":11.658,"altitude":120.0,"speed":25.0,"time":"2026-11-21T12:05:20.000Z","waypoint_number":2},"next":{"latitude":48.28,"longitude":11.68,"altitude":130.0,"speed":30.0,"time":"2026-11-21T12:06:00.000Z","waypoint_number":3},"loiter_configuration_report_validity":0}}"#,
    r#"{"message_type":4001,"source_id":"0x0b000001","destination_id":"0xffffffff","fields":{"time_stamp":"2026-11-21T12:05:01.000Z","altitude_type":null,"speed_type":null,"from":{"latitude":null,"longitude":null,"altitude":null,"time":null,"waypoint_number":null},"to":{"latitude":48.278,"longitude":11.658,"altitude":120.0,"speed":25.0,"time":null,"waypoint_number":1},"next":{"latitude":null,"longitude":null,"altitude":null,"speed":null,"time":null,"waypoint_number":0},"loiter_configuration_report_validity":null}}"#,
    r#"{"message_type":101,"source_id":"0x0b000001","destination_id":"0x0a000001","fields":{"time_stamp":"2026-11-21T12:05:00.500Z","latitude":48.2725,"longitude":11.6425,"altitude":120.0,"altitude_type":"wgs84","u_speed":17.7,"v_speed":-17.7,"w_speed":null,"u_accel":null,"v_accel":null,"w_accel":null,"phi":null,"theta":null,"psi":null,"phi_dot":null,"theta_dot":null,"psi_dot":null,"magnetic_variation":null}}"#,
    r#"{"message_type":101,"source_id":"0x0b000001","destination_id":"0x0a000001","fields":{"time_stamp":"2026-11-21T12:05:01.000Z","latitude":-33.8688,"longitude":-151.2093,"altitude":-12.5,"altitude_type":"agl","u_speed":-0.05,"v_speed":0.0,"w_speed":1.5,"u_accel":-3,"v_accel":4,"w_accel":-32768,"phi":32767,"theta":-1,"psi":16384,"phi_dot":7,"theta_dot":-7,"psi_dot":0,"magnetic_variation":-100}}"#,
    r#"{"message_type":2011,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:00:00.000Z","mode":"initiate_upload","loop_count":3,"area_id":0,"safety_offset":25.0,"activity_id":0,"mission_id":null,"window_or_checksum":null}}"#,
    r#"{"message_type":2011,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:00:30.000Z","mode":"upload_complete_staged","loop_count":3,"area_id":null,"safety_offset":null,"activity_id":null,"mission_id":"MEDEVAC-2","window_or_checksum":{"area_checksum":439041101}}}"#,
    r#"{"message_type":2011,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:00:31.000Z","mode":"initiate_staged_download","loop_count":null,"area_id":2,"safety_offset":null,"activity_id":null,"mission_id":"MEDEVAC-2","window_or_checksum":{"transfer_window":32}}}"#,
    r#"{"message_type":2012,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:00:00.100Z","area_id":1,"area_type":"fly_zone","lower_altitude":0.0,"upper_altitude":300.0,"altitude_type":"wgs84","shape":{"polygon":[{"latitude":48.255,"longitude":11.635},{"latitude":48.255,"longitude":11.69},{"latitude":48.285,"longitude":11.69},{"latitude":48.285,"longitude":11.635}]}}}"#,
    r#"{"message_type":2012,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:00:00.200Z","area_id":2,"area_type":"no_fly_zone","lower_altitude":null,"upper_altitude":150.0,"altitude_type":"baro","shape":{"circle":{"centre":{"latitude":48.268,"longitude":11.675},"border":{"latitude":48.268,"longitude":11.679}}}}}"#,
    r#"{"message_type":3012,"source_id":"0x0b000001","destination_id":"0x0a000001","fields":{"time_stamp":"2026-11-21T12:00:00.350Z","loop_count":3,"status":"invalid","reason":"bad_geometry"}}"#,
    r#"{"message_type":3013,"source_id":"0x0b000001","destination_id":"0x0a000001","ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:00:05.000Z","area_id":0,"loop_count":3,"safety_offset":25.5,"status":"ready"}}"#,
    r#"{"message_type":50000,"ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:03:00.000Z","command":"activate_staged","mission_id":"MEDEVAC-2"}}"#,
    r#"{"message_type":50000,"ack_requested":true,"idd_version":30,"fields":{"time_stamp":"2026-11-21T12:03:01.000Z","command":"return_to_home","mission_id":null}}"#,
    r#"{"message_type":50001,"source_id":"0x0b000001","destination_id":"0x0a000001","ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:04:00.000Z","report_index":2,"report_count":3,"mission_id":"MEDEVAC-2","waypoint_count":3,"area_count":3,"geofence_check":"failed","reason":"geofence_violation","mission_checksum":439041101,"area_checksum":3421780262}}"#,
    r#"{"message_type":50001,"source_id":"0x0b000001","destination_id":"0x0a000001","ack_requested":true,"fields":{"time_stamp":"2026-11-21T12:04:00.001Z","report_index":1,"report_count":3,"mission_id":"","waypoint_count":0,"area_count":0,"geofence_check":"not_run","reason":null,"mission_checksum":null,"area_checksum":null}}"#,
];

fn frames() -> Vec<Vec<u8>> {
    MESSAGES
        .iter()
        .map(|json| encode_json(json).unwrap_or_else(|e| panic!("{json}: {e}")))
        .collect()
}

/// `frame` signed for `link` with key 3 (ICD §9: the frame, then its 16-byte trailer).
fn signed(frame: &[u8], link: Link) -> Vec<u8> {
    let signer = Signer::new(LinkKey::new(3, &[0x5a; 32]));
    let mut out = [0u8; wire::MAX_SIGNED_FRAME_LEN];
    let len = signer.sign(link, frame, &mut out).unwrap();
    out[..len].to_vec()
}

/// The datagrams of the test capture: each message alone; each message signed; several
/// messages back to back, unsigned and signed.
fn good_datagrams() -> Vec<Vec<u8>> {
    let frames = frames();
    let mut datagrams = frames.clone();
    datagrams.extend(frames.iter().map(|f| signed(f, Link::Lte)));
    datagrams.push(frames[..4].concat());
    datagrams.push(frames.iter().rev().take(5).flatten().copied().collect());
    datagrams.push(
        frames[4..8]
            .iter()
            .flat_map(|f| signed(f, Link::Direct))
            .collect(),
    );
    datagrams
}

/// Writes `datagrams` as a pcap on the ICD §1 default ports (GCS direct to FCC direct).
fn capture(dir: &Path, datagrams: &[Vec<u8>]) -> PathBuf {
    let path = dir.join("capture.pcap");
    let w = PcapWriter::create(&path).unwrap();
    let from: SocketAddr = "127.0.0.1:4587".parse().unwrap();
    let to: SocketAddr = "127.0.0.1:4586".parse().unwrap();
    for d in datagrams {
        w.write(SystemTime::now(), from, to, d).unwrap();
    }
    path
}

/// The UDP payloads of a pcap of link type RAW (IPv4), as `gcs::pcap` writes them.
fn read_pcap(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[0..4].try_into().unwrap()),
        0xa1b2_c3d4
    );
    assert_eq!(u32::from_le_bytes(bytes[20..24].try_into().unwrap()), 101);
    let mut at = 24;
    let mut out = Vec::new();
    while at < bytes.len() {
        let len = u32::from_le_bytes(bytes[at + 8..at + 12].try_into().unwrap()) as usize;
        let packet = &bytes[at + 16..at + 16 + len];
        out.push(packet[28..].to_vec());
        at += 16 + len;
    }
    out
}

// ---------------------------------------------------------------------------------------------
// What tshark shows (PDML: one element per line)

#[derive(Debug, Clone)]
struct Shown {
    name: String,
    show: String,
    showname: String,
    value: String,
}

impl Shown {
    /// The name of an enumerated value: `Mission Plan Mode: stage_mission (8)` -> `stage_mission`.
    fn value_name(&self) -> &str {
        let text = self.showname.rsplit_once(": ").map_or("", |(_, v)| v);
        text.rsplit_once(" (").map_or(text, |(name, _)| name)
    }
}

/// One message the dissector found: its heading and its fields in order.
#[derive(Debug, Default)]
struct Dissected {
    heading: String,
    fields: Vec<Shown>,
}

impl Dissected {
    fn has(&self, name: &str) -> bool {
        self.fields.iter().any(|f| f.name == name)
    }
}

fn attr(line: &str, name: &str) -> String {
    let key = format!(" {name}=\"");
    let Some(start) = line.find(&key) else {
        return String::new();
    };
    let rest = &line[start + key.len()..];
    let raw = &rest[..rest.find('"').unwrap()];
    raw.replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

/// Per packet, the missionlink messages in order.
fn dissect(pcap: &Path) -> Vec<Vec<Dissected>> {
    let pdml = tshark(&["-r", pcap.to_str().unwrap(), "-T", "pdml"]);
    let mut packets = Vec::new();
    let mut current: Option<Dissected> = None;
    for line in pdml.lines() {
        let line = line.trim_start();
        if line.starts_with("<packet>") {
            packets.push(Vec::new());
        } else if line.starts_with("<proto name=\"missionlink\"") {
            current = Some(Dissected {
                heading: attr(line, "showname"),
                fields: Vec::new(),
            });
        } else if line.starts_with("</proto>") {
            if let Some(m) = current.take() {
                packets.last_mut().unwrap().push(m);
            }
        } else if line.starts_with("<field") {
            if let Some(m) = current.as_mut() {
                m.fields.push(Shown {
                    name: attr(line, "name"),
                    show: attr(line, "show"),
                    showname: attr(line, "showname"),
                    value: attr(line, "value"),
                });
            }
        }
    }
    packets
}

// ---------------------------------------------------------------------------------------------
// The comparison

/// `gcs inspect --json` of one message as the dissector names its fields: the wrapper by its
/// own names, message fields as `m<type>.<path>` (nested objects joined by dots). The few
/// places where the Rust value is shaped unlike the wire are flattened to the wire's fields:
/// #13006's `data`, #2012's `shape`, #2011's window or checksum. Absent fields are `Null`.
fn expected(json: &Value) -> Vec<(String, Value)> {
    let t = json["message_type"].as_u64().unwrap();
    let mut out = vec![
        ("message_type".to_owned(), json["message_type"].clone()),
        ("source_id".to_owned(), json["source_id"].clone()),
        ("destination_id".to_owned(), json["destination_id"].clone()),
        ("ack_requested".to_owned(), json["ack_requested"].clone()),
        ("idd_version".to_owned(), json["idd_version"].clone()),
        ("checksum_width".to_owned(), json["checksum"].clone()),
        ("frame_length".to_owned(), json["length"].clone()),
    ];
    if let Some(s) = json.get("signature") {
        for k in ["key_id", "link_id", "reserved", "signature"] {
            out.push((format!("signature.{k}"), s[k].clone()));
        }
    }
    let mut fields = json["fields"].as_object().unwrap().clone();
    match t {
        13006 => {
            let data = fields.remove("data").unwrap();
            let (kind, inner) = data.as_object().unwrap().iter().next().unwrap();
            fields.insert("specific_data_type".into(), Value::from(kind.as_str()));
            match kind.as_str() {
                "take_off_height" => {
                    fields.insert("take_off_height".into(), inner["height"].clone());
                }
                _ => {
                    for (from, to) in [
                        ("waypoint_number", "waypoint_number"),
                        ("latitude", "rf_centre_latitude"),
                        ("longitude", "rf_centre_longitude"),
                        ("turn_direction", "turn_direction"),
                    ] {
                        fields.insert(to.into(), inner[from].clone());
                    }
                }
            }
        }
        2012 => {
            let shape = fields.remove("shape").unwrap();
            let (kind, inner) = shape.as_object().unwrap().iter().next().unwrap();
            let vertices = match kind.as_str() {
                "polygon" => inner.as_array().unwrap().clone(),
                _ => vec![inner["centre"].clone(), inner["border"].clone()],
            };
            fields.insert("shape".into(), Value::from(kind.as_str()));
            fields.insert("vertex_count".into(), Value::from(vertices.len()));
            fields.insert("vertices".into(), Value::Array(vertices));
        }
        2011 => {
            if let Some(Value::Object(w)) = fields.remove("window_or_checksum") {
                let (k, v) = w.iter().next().unwrap();
                fields.insert(k.clone(), v.clone());
            }
        }
        _ => {}
    }
    flatten(&format!("m{t}"), &Value::Object(fields), &mut out);
    out
}

fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, Value)>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                flatten(&format!("{prefix}.{k}"), v, out);
            }
        }
        // Arrays (the vertices) repeat their elements' fields in order.
        Value::Array(items) => {
            for v in items {
                flatten(prefix, v, out);
            }
        }
        other => out.push((prefix.to_owned(), other.clone())),
    }
}

/// Fields the dissector shows that `gcs inspect --json` has no key for: #13001's Activity ID
/// (the JSON gives its meaning, `bidirectional`), #13006's Waypoint Number of a take-off height
/// (0 on the wire) and #2012's vertex list heading.
const WIRE_ONLY: &[&str] = &[
    "m13001.activity_id",
    "m13006.waypoint_number",
    "m2012.vertices",
];

fn same(expected: &Value, shown: &Shown) -> bool {
    match expected {
        Value::Bool(b) => {
            matches!(
                (b, shown.show.as_str()),
                (true, "1" | "True" | "true") | (false, "0" | "False" | "false")
            )
        }
        Value::Number(n) => {
            let (want, got) = (n.as_f64().unwrap(), shown.show.parse::<f64>());
            // tshark prints doubles with 15 significant digits: far below one LSB (BAM4 is
            // 8.4e-8 degrees).
            got.is_ok_and(|got| (want - got).abs() <= 1e-9 * want.abs().max(1.0))
        }
        Value::String(s) if shown.name.ends_with("signature.signature") => *s == shown.value,
        Value::String(s) => *s == shown.show || *s == shown.value_name(),
        _ => false,
    }
}

/// Compares one message; returns what differs.
fn compare(json: &Value, d: &Dissected) -> Vec<String> {
    let mut errors = Vec::new();
    let t = json["message_type"].as_u64().unwrap();
    let name = json["name"].as_str().unwrap();
    if d.heading != format!("STANAG 4586 #{t} {name}") {
        errors.push(format!("heading {:?}", d.heading));
    }
    let expected = expected(json);
    let mut shown: BTreeMap<&str, Vec<&Shown>> = BTreeMap::new();
    for f in &d.fields {
        if let Some(n) = f.name.strip_prefix("missionlink.") {
            shown.entry(n).or_default().push(f);
        }
    }
    let mut wanted: BTreeMap<&str, Vec<&Value>> = BTreeMap::new();
    for (k, v) in &expected {
        wanted.entry(k.as_str()).or_default().push(v);
    }
    for (key, values) in &wanted {
        let present: Vec<&&Value> = values.iter().filter(|v| !v.is_null()).collect();
        let got = shown.get(key).cloned().unwrap_or_default();
        if present.len() != got.len() {
            errors.push(format!(
                "{key}: inspect has {present:?}, the dissector shows {:?}",
                got.iter().map(|s| &s.showname).collect::<Vec<_>>()
            ));
            continue;
        }
        for (want, s) in present.iter().zip(&got) {
            if !same(want, s) {
                errors.push(format!("{key}: inspect {want}, dissector {:?}", s.showname));
            }
        }
    }
    let prefix = format!("m{t}.");
    for key in shown.keys() {
        if key.starts_with(&prefix) && !wanted.contains_key(key) && !WIRE_ONLY.contains(key) {
            errors.push(format!("{key}: shown by the dissector, not by inspect"));
        }
    }
    errors
}

/// Every datagram: inspect accepts it, and the dissector shows the same messages, field by field.
fn compare_all(datagrams: &[Vec<u8>], packets: &[Vec<Dissected>]) -> usize {
    assert_eq!(datagrams.len(), packets.len());
    let mut compared = 0;
    let mut errors = Vec::new();
    for (i, (datagram, dissected)) in datagrams.iter().zip(packets).enumerate() {
        let (messages, out) = inspect(datagram);
        assert!(
            out.status.success(),
            "inspect refused datagram {i} ({}): {}",
            hex::encode(datagram),
            String::from_utf8_lossy(&out.stderr)
        );
        if messages.len() != dissected.len() {
            errors.push(format!(
                "datagram {i}: inspect finds {} messages, the dissector {}",
                messages.len(),
                dissected.len()
            ));
            continue;
        }
        for (j, (json, d)) in messages.iter().zip(dissected).enumerate() {
            for e in compare(json, d) {
                errors.push(format!(
                    "datagram {i} message {j} (#{}): {e}",
                    json["message_type"]
                ));
            }
            if d.fields.iter().any(|f| f.name == "_ws.expert") {
                errors.push(format!(
                    "datagram {i} message {j}: expert info on a good frame"
                ));
            }
            compared += 1;
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    compared
}

#[test]
fn every_message_type_shows_every_field_as_inspect_does() {
    let dir = tempfile::tempdir().unwrap();
    let datagrams = good_datagrams();
    let packets = dissect(&capture(dir.path(), &datagrams));
    let compared = compare_all(&datagrams, &packets);
    // Every message type is in the capture, and signed frames show their trailer.
    let types: Vec<u64> = MESSAGES
        .iter()
        .map(|m| {
            serde_json::from_str::<Value>(m).unwrap()["message_type"]
                .as_u64()
                .unwrap()
        })
        .collect();
    for t in MessageType::ALL {
        assert!(
            types.contains(&u64::from(*t as u16)),
            "{t} is not in the capture"
        );
    }
    assert!(compared > 2 * MESSAGES.len());
    assert!(
        packets
            .iter()
            .flatten()
            .any(|d| d.has("missionlink.signature.signature"))
    );
}

#[test]
fn the_committed_demo_capture_shows_what_inspect_shows() {
    let path = demo_capture();
    let datagrams = read_pcap(&path);
    assert!(!datagrams.is_empty());
    let packets = dissect(&path);
    let compared = compare_all(&datagrams, &packets);
    assert!(compared >= datagrams.len());
}

/// The frames of ICD §2 a receiver rejects, and messages that break §3, each with the expert
/// info the dissector gives it and the words `gcs inspect` uses.
#[test]
fn frames_that_break_the_icd_rules_carry_expert_info() {
    let good = frames()[0].clone();
    let mut bad_checksum = good.clone();
    *bad_checksum.last_mut().unwrap() ^= 1;
    let mut too_long = good.clone();
    too_long[3] += 1; // Message Length one byte more than the datagram holds
    let mut too_short_length = good.clone();
    too_short_length[3] -= 1; // the checksum lands one byte early: wrong checksum, then junk
    let mut zero = good.clone();
    zero[2..4].copy_from_slice(&[0, 0]);
    let mut above = good.clone();
    above[2..4].copy_from_slice(&529u16.to_be_bytes());
    let mut code_11 = good.clone();
    code_11[15] |= 0xc0;
    let mut version = encode_json(
        r#"{"message_type":50000,"idd_version":41,"fields":{"time_stamp":"2026-11-21T12:03:00.000Z","command":"land"}}"#,
    )
    .unwrap();
    let short = good[..10].to_vec();
    // A good message, then a broken one: the first still decodes.
    let mut second_broken = good.clone();
    second_broken.extend_from_slice(&bad_checksum);
    // Keep the version frame's checksum right: only the version is wrong.
    let n = version.len();
    let sum: u32 = version[..n - 4].iter().map(|b| u32::from(*b)).sum();
    version[n - 4..].copy_from_slice(&sum.to_be_bytes());
    // ICD §3 in a #50000 (PV U1, fields 0..=2): bit 7 set; bit 2 (Mission ID) set without
    // its 20 bytes. The checksum is made right again, so only the message is at fault.
    let execute = encode_json(
        r#"{"message_type":50000,"fields":{"time_stamp":"2026-11-21T12:03:00.000Z","command":"land"}}"#,
    )
    .unwrap();
    let with_checksum = |mut f: Vec<u8>| {
        let n = f.len();
        let sum: u32 = f[..n - 4].iter().map(|b| u32::from(*b)).sum();
        f[n - 4..].copy_from_slice(&sum.to_be_bytes());
        f
    };
    let mut unknown_bit = execute.clone();
    unknown_bit[16] |= 0x80;
    let unknown_bit = with_checksum(unknown_bit);
    let mut truncated = execute;
    truncated[16] |= 0x04;
    let truncated = with_checksum(truncated);
    let cases: Vec<(&str, Vec<u8>, &str, &str)> = vec![
        (
            "presence bit beyond the fields",
            unknown_bit,
            "missionlink.unknown_field",
            "beyond the defined fields",
        ),
        (
            "field cut off",
            truncated,
            "missionlink.truncated",
            "ends inside the field",
        ),
        (
            "bad checksum",
            bad_checksum,
            "missionlink.bad_checksum",
            "checksum",
        ),
        (
            "length above the datagram",
            too_long,
            "missionlink.length_mismatch",
            "takes",
        ),
        (
            "length below the datagram",
            too_short_length,
            "missionlink.bad_checksum",
            "checksum",
        ),
        ("length 0", zero, "missionlink.bad_length", "length"),
        ("length 529", above, "missionlink.bad_length", "length"),
        (
            "checksum code 11",
            code_11,
            "missionlink.bad_checksum_code",
            "checksum",
        ),
        (
            "IDD version 41",
            version,
            "missionlink.bad_version",
            "version",
        ),
        (
            "shorter than the header",
            short,
            "missionlink.too_short",
            "short",
        ),
        (
            "good then bad",
            second_broken,
            "missionlink.bad_checksum",
            "checksum",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    let datagrams: Vec<Vec<u8>> = cases.iter().map(|c| c.1.clone()).collect();
    let packets = dissect(&capture(dir.path(), &datagrams));
    for ((what, datagram, expert, words), dissected) in cases.iter().zip(&packets) {
        let (_, out) = inspect(datagram);
        let stderr = String::from_utf8_lossy(&out.stderr).to_lowercase();
        assert!(!out.status.success(), "{what}: inspect accepted it");
        assert!(stderr.contains(words), "{what}: inspect says {stderr}");
        let flagged = dissected.iter().any(|d| d.has(expert));
        assert!(flagged, "{what}: no {expert} in {dissected:#?}");
    }
    // The good message before the broken one is shown as inspect shows it.
    let last = cases.len() - 1;
    let (messages, _) = inspect(&cases[last].1);
    assert_eq!(messages.len(), 1);
    assert!(compare(&messages[0], &packets[last][0]).is_empty());
}

// ---------------------------------------------------------------------------------------------
// The dissector's definitions against the Rust wire layer

/// `tshark -G fields`: (label, abbrev, description) of every field of the dissector.
fn registered_fields() -> Vec<(String, String, String)> {
    let lua = format!("lua_script:{}", dissector().display());
    let out = tshark_g("fields", &lua);
    out.lines()
        .filter_map(|l| {
            let cols: Vec<&str> = l.split('\t').collect();
            (cols.first() == Some(&"F") && cols[2].starts_with("missionlink.")).then(|| {
                (
                    cols[1].to_owned(),
                    cols[2].to_owned(),
                    (*cols.last().unwrap()).to_owned(),
                )
            })
        })
        .collect()
}

/// `tshark -G <what>` (-G must come first, so not through `tshark()`).
fn tshark_g(what: &str, lua: &str) -> String {
    let out: Output = Command::new("tshark")
        .args(["-G", what, "-X", lua])
        .output()
        .unwrap_or_else(|e| missing_tshark(e));
    assert!(out.status.success());
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn field_labels_and_message_names_are_the_wire_layers() {
    let fields = registered_fields();
    for t in MessageType::ALL {
        let code = *t as u16;
        let names = t.fields();
        for (bit, name) in names.iter().enumerate() {
            let blurb = format!("#{code} bit {bit}");
            let at: Vec<_> = fields.iter().filter(|f| f.2 == blurb).collect();
            assert!(
                !at.is_empty(),
                "{t}: the dissector has no field for bit {bit} ({name})"
            );
            for f in at {
                assert_eq!(f.0, *name, "{t} bit {bit}: {}", f.1);
            }
        }
        let beyond = format!("#{code} bit {}", names.len());
        assert!(
            !fields.iter().any(|f| f.2 == beyond),
            "{t}: bits beyond the ICD's"
        );
    }
    let values = tshark_g("values", &format!("lua_script:{}", dissector().display()));
    let mut message_types = Vec::new();
    for l in values.lines() {
        let cols: Vec<&str> = l.split('\t').collect();
        if cols.len() == 4 && cols[1] == "missionlink.message_type" {
            message_types.push((cols[2].parse::<u16>().unwrap(), cols[3].to_owned()));
        }
    }
    message_types.sort();
    let mut expected: Vec<(u16, String)> = MessageType::ALL
        .iter()
        .map(|t| (*t as u16, t.name().to_owned()))
        .collect();
    expected.sort();
    assert_eq!(message_types, expected);
}

/// (value, JSON name) of every value of a Rust enumeration.
fn json_names<T: Serialize + Copy>(all: &[T], number: impl Fn(T) -> u8) -> Vec<(u8, String)> {
    let mut v: Vec<(u8, String)> = all
        .iter()
        .map(|e| {
            let name = serde_json::to_value(e)
                .unwrap()
                .as_str()
                .unwrap()
                .to_owned();
            (number(*e), name)
        })
        .collect();
    v.sort();
    v
}

#[test]
fn value_names_are_the_enumerations_of_the_wire_layer() {
    use wire::*;
    let values = tshark_g("values", &format!("lua_script:{}", dissector().display()));
    let mut shown: BTreeMap<String, Vec<(u8, String)>> = BTreeMap::new();
    for l in values.lines() {
        let cols: Vec<&str> = l.split('\t').collect();
        // Message fields only (`missionlink.m<type>.<key>`): the Message Type's own names
        // (`missionlink.message_type`) include #101, whose number fits a u8 too.
        let message_field = cols.get(1).is_some_and(|c| {
            c.strip_prefix("missionlink.m")
                .is_some_and(|rest| rest.starts_with(|ch: char| ch.is_ascii_digit()))
        });
        if cols.len() == 4 && message_field {
            if let Ok(n) = cols[2].parse::<u8>() {
                shown
                    .entry(cols[1].trim_start_matches("missionlink.").to_owned())
                    .or_default()
                    .push((n, cols[3].to_owned()));
            }
        }
    }
    for v in shown.values_mut() {
        v.sort();
    }
    let ack = json_names(AckType::ALL, |v| v as u8);
    let mode = json_names(MissionPlanMode::ALL, |v| v as u8);
    let reason = json_names(Reason::ALL, |v| v as u8);
    let altitude = json_names(AltitudeType::ALL, |v| v as u8);
    let speed = json_names(SpeedType::ALL, |v| v as u8);
    let expected: Vec<(&str, Vec<(u8, String)>)> = vec![
        ("m17000.ack_type", ack),
        ("m17000.reject_reason", reason.clone()),
        ("m13000.mode", mode.clone()),
        ("m13001.route_type", json_names(RouteType::ALL, |v| v as u8)),
        (
            "m13002.location_type",
            json_names(LocationType::ALL, |v| v as u8),
        ),
        ("m13002.altitude_type", altitude.clone()),
        ("m13002.speed_type", speed.clone()),
        ("m13002.turn_type", json_names(TurnType::ALL, |v| v as u8)),
        ("m13002.leg_type", json_names(LegType::ALL, |v| v as u8)),
        (
            "m13006.turn_direction",
            json_names(TurnDirection::ALL, |v| v as u8),
        ),
        (
            "m14000.status",
            json_names(TransferStatus::ALL, |v| v as u8),
        ),
        ("m14000.mode", mode),
        ("m14000.reason", reason.clone()),
        ("m4001.altitude_type", altitude.clone()),
        ("m4001.speed_type", speed),
        ("m101.altitude_type", altitude.clone()),
        ("m2011.mode", json_names(AreaTransferMode::ALL, |v| v as u8)),
        ("m2012.area_type", json_names(AreaType::ALL, |v| v as u8)),
        ("m2012.altitude_type", altitude),
        ("m3012.status", json_names(AreaListStatus::ALL, |v| v as u8)),
        ("m3012.reason", reason.clone()),
        (
            "m3013.status",
            json_names(AreaDownloadStatus::ALL, |v| v as u8),
        ),
        (
            "m50000.command",
            json_names(ExecuteCommand::ALL, |v| v as u8),
        ),
        (
            "m50001.geofence_check",
            json_names(GeofenceCheck::ALL, |v| v as u8),
        ),
        ("m50001.reason", reason),
    ];
    for (field, want) in &expected {
        assert_eq!(shown.get(*field), Some(want), "{field}");
    }
    // #13006's type and #2012's shape are not Rust enumerations; the comparison of captures
    // covers them. Every other enumerated field is listed above.
    let listed: Vec<&str> = expected.iter().map(|e| e.0).collect();
    for field in shown.keys() {
        assert!(
            listed.contains(&field.as_str())
                || ["m13006.specific_data_type", "m2012.shape"].contains(&field.as_str()),
            "{field}: value names not checked against the wire layer"
        );
    }
}
