//! The frame inspector as an engineer runs it: the real `gcs` binary, arguments and stdin, exit
//! status and output.

use std::process::Output;

use crate::support::gcs_with_input;

/// The #13002 of docs/gcs.md ("The frame inspector"): waypoint 1 of demo mission 1 (CCP), written
/// by hand from the ICD.
const DOCUMENTED_13002: &str = "ffff001d0a0000010b00000132caa880002f6fc5932a9a000001225432100847e856001770030032000000000000000a12";

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8")
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("UTF-8")
}

#[test]
fn documented_frame_prints_every_field_in_units() {
    let o = gcs_with_input(&["inspect", DOCUMENTED_13002], "");
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for line in [
        "#13002 UA Position Waypoint  0x0a000001 -> 0x0b000001  ack requested  IDD 40  checksum 4 B  49 B",
        "  time_stamp: 2026-11-21T12:00:00.000Z",
        "  waypoint_number: 1",
        "  latitude: 48.2750000 °",
        "  longitude: 11.6450000 °",
        "  altitude: 120.00 m",
        "  altitude_type: wgs84",
        "  speed: 25.0 m/s",
        "  next_waypoint: 0",
        "  turn_type: fly_by",
        "  leg_type: track_to_fix",
        "  arrival_time: (absent)",
    ] {
        assert!(
            text.lines().any(|l| l == line),
            "missing {line:?} in\n{text}"
        );
    }
    // Every one of the 18 fields is listed.
    assert_eq!(text.lines().count(), 1 + 18, "{text}");
}

#[test]
fn json_then_encode_gives_the_frame_back() {
    let o = gcs_with_input(&["inspect", "--json", DOCUMENTED_13002], "");
    assert!(o.status.success());
    let json = stdout(&o);
    let v: serde_json::Value = serde_json::from_str(json.trim()).expect("one JSON object");
    assert_eq!(v["message_type"], 13002);
    assert_eq!(v["fields"]["speed"], 25.0);
    let o = gcs_with_input(&["encode"], &json);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).trim(), DOCUMENTED_13002);
}

#[test]
fn stdin_datagrams_with_several_messages_and_comments() {
    let two = format!("{DOCUMENTED_13002}{DOCUMENTED_13002}");
    let input = format!("# capture of the direct link\n\n{two}\n{DOCUMENTED_13002}\n");
    let o = gcs_with_input(&["inspect", "--json"], &input);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).lines().count(), 3);
}

#[test]
fn bad_checksum_names_the_rule_and_fails() {
    let broken = format!("{}13", &DOCUMENTED_13002[..DOCUMENTED_13002.len() - 2]);
    let o = gcs_with_input(&["inspect", &broken], "");
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stderr(&o).trim(),
        "datagram 1, message 1: frame rejected: checksum 0xa13 received, 0xa12 computed"
    );
    assert!(stdout(&o).is_empty());
}

#[test]
fn rejected_message_names_message_field_and_reason() {
    // The documented frame with waypoint number 0 (data byte 9 of the frame is 0x01 -> 0x00) and
    // the checksum lowered by one to match.
    let mut bytes = hex::decode(DOCUMENTED_13002).expect("hex");
    bytes[25] = 0;
    let n = bytes.len();
    bytes[n - 1] -= 1;
    let o = gcs_with_input(&["inspect", &hex::encode(&bytes)], "");
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stderr(&o).trim(),
        "datagram 1, message 1: message rejected: #13002 UA Position Waypoint, Waypoint Number \
         (PV bit 1): value 0 is out of range [reason Malformed (1)]"
    );
}

#[test]
fn addressing_rules_apply_when_asked() {
    // The frame is for the FCC 0x0B000001: the GCS rejects it as not addressed to it.
    let o = gcs_with_input(
        &[
            "inspect",
            "--local-id",
            "0x0A000001",
            "--peer-id",
            "0x0B000001",
            DOCUMENTED_13002,
        ],
        "",
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("destination 0x0b000001 is neither this node nor broadcast"));
    let o = gcs_with_input(
        &[
            "inspect",
            "--local-id",
            "0x0B000001",
            "--peer-id",
            "0x0A000001",
            DOCUMENTED_13002,
        ],
        "",
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn not_hex_and_not_json_fail_clearly() {
    let o = gcs_with_input(&["inspect", "zz"], "");
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("not a hex datagram"), "{}", stderr(&o));
    let o = gcs_with_input(&["encode", r#"{"message_type":13002,"fields":{}}"#], "");
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("message 1: not a message in JSON"),
        "{}",
        stderr(&o)
    );
    let o = gcs_with_input(&["encode", r#"{"message_type":1,"fields":{}}"#], "");
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("message type 1 is not in the ICD"));
}
