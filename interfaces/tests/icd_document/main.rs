//! Keeps `docs/icd.md`, the interface control document, true to the code:
//!
//! - every message type the code defines has its section and field table in §4, with every field
//!   the code names, at its presence-vector bit, the presence vector's width, and offsets that
//!   add up from the byte counts;
//! - every value of every enumerated field appears in its message's table;
//! - every reject reason (§6) and every frame reject cause (§2) appears;
//! - every section the code cites as "ICD §N" exists;
//! - every example frame decodes, with the project's decoder, to exactly the table printed under
//!   it; its byte counts agree with the field tables; the signed example verifies with the key
//!   the document gives; every message type has an example;
//! - every canonical byte string of Appendix B has the CRC-32 printed under it.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

mod describe;

use std::path::{Path, PathBuf};

use hmac::{Hmac, Mac};
use missionlink_interfaces::wire::{
    self, AckType, AltitudeType, AreaDownloadStatus, AreaListStatus, AreaTransferMode, AreaType,
    ExecuteCommand, FrameError, GeofenceCheck, LegType, LocationType, MessageType, MissionPlanMode,
    Numbered, Reason, RouteType, SpeedType, TransferStatus, TurnDirection, TurnType,
};
use sha2::Sha256;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn document() -> String {
    let path = repo().join("docs/icd.md");
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{} cannot be read: {e}", path.display()))
}

/// The lines of the section that starts at the heading line `heading` (exactly), up to the
/// next heading of the same or a higher level.
fn section<'a>(doc: &'a str, heading: &str) -> Vec<&'a str> {
    let level = heading.chars().take_while(|c| *c == '#').count();
    let mut lines = doc.lines().skip_while(|l| l.trim_end() != heading);
    assert!(
        lines.next().is_some(),
        "docs/icd.md has no heading `{heading}`"
    );
    lines
        .take_while(|l| {
            let hashes = l.chars().take_while(|c| *c == '#').count();
            !(hashes > 0 && hashes <= level && l.chars().nth(hashes) == Some(' '))
        })
        .collect()
}

/// The cells of a table row `| a | b |`, trimmed.
fn cells(line: &str) -> Vec<String> {
    let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
    inner.split('|').map(|c| c.trim().to_string()).collect()
}

/// The width of the presence vector of `t` (ICD §4), from the code.
fn pv_bytes(t: MessageType) -> usize {
    use wire::*;
    match t {
        MessageType::MessageAcknowledgement => MessageAcknowledgement::PV_BYTES,
        MessageType::MissionTransferCommand => MissionTransferCommand::PV_BYTES,
        MessageType::UaRoute => UaRoute::PV_BYTES,
        MessageType::UaPositionWaypoint => UaPositionWaypoint::PV_BYTES,
        MessageType::VehicleSpecificWaypoint => VehicleSpecificWaypoint::PV_BYTES,
        MessageType::MissionUploadDownloadStatus => MissionUploadDownloadStatus::PV_BYTES,
        MessageType::FromToNext => FromToNext::PV_BYTES,
        MessageType::InertialStates => InertialStates::PV_BYTES,
        MessageType::AreaTransmissionCommand => AreaTransmissionCommand::PV_BYTES,
        MessageType::AreaPolygonLoopSegment => AreaPolygonLoopSegment::PV_BYTES,
        MessageType::AreaStatusAlert => AreaStatusAlert::PV_BYTES,
        MessageType::AreaTransmissionStatus => AreaTransmissionStatus::PV_BYTES,
        MessageType::MissionExecuteCommand => MissionExecuteCommand::PV_BYTES,
        MessageType::MissionReport => MissionReport::PV_BYTES,
    }
}

fn heading(t: MessageType) -> String {
    format!("### #{} {}", t as u16, t.name())
}

/// One row of a field table of §4.
struct FieldRow {
    bit: usize,
    name: String,
    /// Bytes on the wire; `None` for the vertices of #2012 (8 per vertex).
    bytes: Option<usize>,
    offset: usize,
}

/// The field table of `t`'s section: the rows whose first cell is a bit number.
fn field_table(doc: &str, t: MessageType) -> (Vec<&str>, Vec<FieldRow>) {
    let lines = section(doc, &heading(t));
    let header = lines
        .iter()
        .find(|l| l.starts_with("| Bit |"))
        .unwrap_or_else(|| panic!("{}: no field table (`| Bit | ...`)", heading(t)));
    let columns = cells(header);
    let col = |name: &str| {
        columns
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("{}: the field table has no column {name}", heading(t)))
    };
    let (bit, field, bytes, offset) = (col("Bit"), col("Field"), col("Bytes"), col("Offset"));
    let rows = lines
        .iter()
        .filter(|l| l.starts_with('|'))
        .map(|l| cells(l))
        .filter(|c| c[0].parse::<usize>().is_ok())
        .map(|c| FieldRow {
            bit: c[bit].parse().unwrap(),
            name: c[field].clone(),
            bytes: c[bytes].parse().ok(),
            offset: c[offset].parse().unwrap_or_else(|_| {
                panic!(
                    "{}, {}: Offset {:?} is no number",
                    heading(t),
                    c[field],
                    c[offset]
                )
            }),
        })
        .collect();
    (lines, rows)
}

#[test]
fn every_message_type_has_its_field_table() {
    let doc = document();
    for &t in MessageType::ALL {
        let (lines, rows) = field_table(&doc, t);
        let fields = t.fields();
        for (bit, name) in fields.iter().enumerate() {
            let row = rows.iter().find(|r| r.name == *name).unwrap_or_else(|| {
                panic!(
                    "{}: field {name:?} (PV bit {bit}) is missing from its table",
                    heading(t)
                )
            });
            assert_eq!(
                row.bit,
                bit,
                "{}: field {name:?} is at PV bit {bit} in the code, {} in the document",
                heading(t),
                row.bit
            );
        }
        assert_eq!(
            rows.len(),
            fields.len(),
            "{}: the table has {} field rows, the code defines {} fields",
            heading(t),
            rows.len(),
            fields.len()
        );
        let pv = pv_bytes(t);
        let said = format!("Presence vector: U{pv}.");
        let prose = lines.join(" ");
        let prose: Vec<&str> = prose.split_whitespace().collect();
        assert!(
            prose.join(" ").contains(&said),
            "{}: the section must say `{said}`",
            heading(t)
        );
        // Offsets when every earlier field is present: the presence vector, then each field's
        // bytes in bit order.
        let mut expected = pv;
        for row in &rows {
            assert_eq!(
                row.offset,
                expected,
                "{}, {}: Offset {} does not follow from the Bytes column ({expected})",
                heading(t),
                row.name,
                row.offset
            );
            expected += row.bytes.unwrap_or(0);
        }
    }
}

/// Every value of an enumerated field, `number name`, in the section of the message that
/// carries it.
#[test]
fn every_enumerated_value_appears_in_its_table() {
    let doc = document();
    let check = |t: MessageType, values: &mut dyn Iterator<Item = Numbered>| {
        let text = section(&doc, &heading(t)).join("\n");
        for v in values {
            assert!(
                text.contains(&v.to_string()),
                "{}: the value `{v}` of the code is not in its table",
                heading(t)
            );
        }
    };
    use MessageType as T;
    check(
        T::MessageAcknowledgement,
        &mut AckType::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::MissionTransferCommand,
        &mut MissionPlanMode::ALL.iter().map(|v| v.numbered()),
    );
    check(T::UaRoute, &mut RouteType::ALL.iter().map(|v| v.numbered()));
    for values in [
        LocationType::ALL
            .iter()
            .map(|v| v.numbered())
            .collect::<Vec<_>>(),
        AltitudeType::ALL.iter().map(|v| v.numbered()).collect(),
        SpeedType::ALL.iter().map(|v| v.numbered()).collect(),
        TurnType::ALL.iter().map(|v| v.numbered()).collect(),
        LegType::ALL.iter().map(|v| v.numbered()).collect(),
    ] {
        check(T::UaPositionWaypoint, &mut values.into_iter());
    }
    check(
        T::VehicleSpecificWaypoint,
        &mut TurnDirection::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::MissionUploadDownloadStatus,
        &mut TransferStatus::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::AreaTransmissionCommand,
        &mut AreaTransferMode::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::AreaPolygonLoopSegment,
        &mut AreaType::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::AreaStatusAlert,
        &mut AreaListStatus::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::AreaTransmissionStatus,
        &mut AreaDownloadStatus::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::MissionExecuteCommand,
        &mut ExecuteCommand::ALL.iter().map(|v| v.numbered()),
    );
    check(
        T::MissionReport,
        &mut GeofenceCheck::ALL.iter().map(|v| v.numbered()),
    );
}

#[test]
fn every_reject_reason_is_in_section_6() {
    let doc = document();
    let rows: Vec<Vec<String>> = section(&doc, "## 6. Reasons")
        .iter()
        .filter(|l| l.starts_with('|'))
        .map(|l| cells(l))
        .filter(|c| c[0].parse::<u8>().is_ok())
        .collect();
    for &r in Reason::ALL {
        let name = format!("{r:?}");
        assert!(
            rows.iter()
                .any(|c| c[0] == (r as u8).to_string() && c[1] == name),
            "§6: the reason `| {} | {name} |` of the code is not in the table",
            r as u8
        );
    }
    assert_eq!(
        rows.len(),
        Reason::ALL.len(),
        "§6 lists {} reasons, the code defines {}",
        rows.len(),
        Reason::ALL.len()
    );
}

/// The name of a frame reject cause as §2 writes it. Exhaustive: a cause added to the code
/// does not compile here until it is named (and then must be in the document).
fn frame_cause(e: &FrameError) -> &'static str {
    match e {
        FrameError::TooShort { .. } => "TooShort",
        FrameError::LengthOutOfRange { .. } => "LengthOutOfRange",
        FrameError::LengthMismatch { .. } => "LengthMismatch",
        FrameError::InvalidChecksumLength => "InvalidChecksumLength",
        FrameError::ChecksumMismatch { .. } => "ChecksumMismatch",
        FrameError::UnsupportedVersion { .. } => "UnsupportedVersion",
        FrameError::WrongDestination { .. } => "WrongDestination",
        FrameError::UnknownSource { .. } => "UnknownSource",
    }
}

#[test]
fn every_frame_reject_cause_is_in_section_2() {
    let doc = document();
    let rows: Vec<String> = section(&doc, "## 2. Wrapper")
        .iter()
        .filter(|l| l.starts_with('|'))
        .map(|l| cells(l)[0].clone())
        .collect();
    let causes = [
        FrameError::TooShort { len: 0 },
        FrameError::LengthOutOfRange { length: 0 },
        FrameError::LengthMismatch {
            expected: 0,
            actual: 0,
        },
        FrameError::InvalidChecksumLength,
        FrameError::ChecksumMismatch {
            computed: 0,
            received: 0,
        },
        FrameError::UnsupportedVersion { version: 0 },
        FrameError::WrongDestination { destination: 0 },
        FrameError::UnknownSource { source: 0 },
    ];
    for e in &causes {
        let name = frame_cause(e);
        assert!(
            rows.iter().any(|r| r == name),
            "§2: the frame reject cause {name} ({e}) is not in the table"
        );
    }
}

/// Every section the code cites as `ICD §N` or `ICD §N.M` has its heading.
#[test]
fn every_section_the_code_cites_exists() {
    let doc = document();
    let headings: Vec<String> = doc
        .lines()
        .filter(|l| l.starts_with("## ") || l.starts_with("### "))
        .filter_map(|l| l.split_whitespace().nth(1))
        .map(|n| n.trim_end_matches('.').to_string())
        .collect();
    let mut files = Vec::new();
    let mut dirs = vec![repo()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                if !name.starts_with('.') && name != "target" {
                    dirs.push(path);
                }
            } else if name.ends_with(".rs") {
                files.push(path);
            }
        }
    }
    let mut cited = 0;
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for (i, _) in text.match_indices("ICD §") {
            let number: String = text[i + "ICD §".len()..]
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '.')
                .collect();
            let number = number.trim_end_matches('.');
            if number.is_empty() {
                continue;
            }
            cited += 1;
            assert!(
                headings.iter().any(|h| h == number),
                "{} cites ICD §{number}, which docs/icd.md has no heading for",
                file.display()
            );
        }
    }
    assert!(
        cited > 0,
        "no citation found: the walk of the repository is wrong"
    );
}

/// An example of Appendix A: its heading, its bytes, the table printed under it.
struct Example {
    title: String,
    bytes: Vec<u8>,
    table: Vec<(String, String)>,
}

fn parse_hex(title: &str, text: &str) -> Vec<u8> {
    text.split_whitespace()
        .map(|h| {
            u8::from_str_radix(h, 16).unwrap_or_else(|_| panic!("{title}: {h:?} is not a hex byte"))
        })
        .collect()
}

/// The fenced blocks of `kind` (```frame, ```canonical) with the heading above each and the
/// lines after each up to the next blank line that follows content.
fn blocks<'a>(doc: &'a str, kind: &str) -> Vec<(String, String, Vec<&'a str>)> {
    let lines: Vec<&str> = doc.lines().collect();
    let mut out = Vec::new();
    let mut title = String::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].starts_with('#') {
            title = lines[i].trim_start_matches('#').trim().to_string();
        }
        if lines[i].trim() == format!("```{kind}") {
            let start = i + 1;
            let end = start
                + lines[start..]
                    .iter()
                    .position(|l| l.trim() == "```")
                    .unwrap_or_else(|| panic!("{title}: the ```{kind} block is not closed"));
            let body = lines[start..end].join("\n");
            let after: Vec<&str> = lines[end + 1..]
                .iter()
                .skip_while(|l| l.trim().is_empty())
                .take_while(|l| !l.trim().is_empty())
                .copied()
                .collect();
            out.push((title.clone(), body, after));
            i = end;
        }
        i += 1;
    }
    out
}

fn examples(doc: &str) -> Vec<Example> {
    blocks(doc, "frame")
        .into_iter()
        .map(|(title, body, after)| {
            let table = after
                .iter()
                .filter(|l| l.starts_with('|'))
                .map(|l| cells(l))
                .filter(|c| c[0] != "Field" && !c[0].starts_with("---"))
                .map(|c| (c[0].clone(), c[1..].join("|")))
                .collect();
            Example {
                bytes: parse_hex(&title, &body),
                title,
                table,
            }
        })
        .collect()
}

#[test]
fn every_example_frame_decodes_to_its_table() {
    let doc = document();
    let examples = examples(&doc);
    assert!(!examples.is_empty(), "docs/icd.md holds no ```frame block");
    let mut types = std::collections::BTreeSet::new();
    for ex in &examples {
        let frames: Vec<_> = wire::frames(&ex.bytes).collect();
        assert_eq!(
            frames.len(),
            1,
            "{}: the bytes hold {} frames, not one",
            ex.title,
            frames.len()
        );
        let frame = frames[0]
            .as_ref()
            .unwrap_or_else(|e| panic!("{}: the frame is rejected: {e}", ex.title));
        let message = frame
            .message()
            .unwrap_or_else(|e| panic!("{}: the message is rejected: {e}", ex.title));
        let decoded = describe::describe(frame);
        for (i, (key, value)) in decoded.iter().enumerate() {
            let said = ex.table.iter().find(|(k, _)| k == key);
            match said {
                None => panic!(
                    "{}: the frame holds `{key} = {value}`, the table has no row {key}",
                    ex.title
                ),
                Some((_, v)) => assert_eq!(
                    v, value,
                    "{}: row {key}: the document says {v:?}, the frame decodes to {value:?}",
                    ex.title
                ),
            }
            assert_eq!(
                ex.table.get(i).map(|(k, _)| k),
                Some(key),
                "{}: the rows are not in the order the frame holds them (row {key})",
                ex.title
            );
        }
        assert_eq!(
            ex.table.len(),
            decoded.len(),
            "{}: the table has rows the frame does not hold: {:?}",
            ex.title,
            ex.table
                .iter()
                .filter(|(k, _)| !decoded.iter().any(|(d, _)| d == k))
                .collect::<Vec<_>>()
        );
        // The field table of §4 sizes this message: presence vector plus the bytes of each
        // present field (a #2012's vertices 8 each) is its Message Length.
        let t = message.message_type();
        types.insert(t);
        let (_, rows) = field_table(&doc, t);
        let pv = pv_bytes(t);
        let bits = frame.data()[..pv]
            .iter()
            .fold(0u32, |acc, b| (acc << 8) | u32::from(*b));
        let vertices = match &message {
            wire::Message::AreaPolygonLoopSegment(a) => match &a.shape {
                wire::AreaShape::Polygon(v) => v.len(),
                wire::AreaShape::Circle { .. } => 2,
            },
            _ => 0,
        };
        let sized: usize = pv
            + rows
                .iter()
                .filter(|r| bits & (1 << r.bit) != 0)
                .map(|r| r.bytes.unwrap_or(8 * vertices))
                .sum::<usize>();
        assert_eq!(
            sized,
            frame.data().len(),
            "{}: the Bytes column of §4 sizes the present fields to {sized} bytes, the frame \
             holds {}",
            ex.title,
            frame.data().len()
        );
    }
    for &t in MessageType::ALL {
        assert!(
            types.contains(&t),
            "Appendix A has no example of {}",
            heading(t)
        );
    }
}

/// The example key of §9 and Appendix A.25: 0x00, 0x01, ..., 0x1F.
fn example_key() -> [u8; 32] {
    core::array::from_fn(|i| i as u8)
}

#[test]
fn the_signed_example_verifies() {
    let doc = document();
    assert!(
        doc.contains("example key 0x00, 0x01, ..., 0x1F (32 bytes)"),
        "Appendix A must name the example key"
    );
    let mut signed = 0;
    for ex in examples(&doc) {
        let frame = wire::frames(&ex.bytes)
            .next()
            .unwrap()
            .unwrap_or_else(|e| panic!("{}: the frame is rejected: {e}", ex.title));
        let Some(trailer) = frame.trailer() else {
            continue;
        };
        assert!(
            frame.properties().signed(),
            "{}: bit 5 is not set",
            ex.title
        );
        let mut mac = <Hmac<Sha256> as Mac>::new_from_slice(&example_key()).unwrap();
        mac.update(frame.as_bytes());
        mac.update(&ex.bytes[frame.as_bytes().len()..][..4]);
        let tag = mac.finalize().into_bytes();
        assert_eq!(
            &tag[..12],
            &trailer.signature,
            "{}: the signature does not verify with the example key",
            ex.title
        );
        signed += 1;
    }
    assert!(signed > 0, "Appendix A has no signed frame");
}

/// CRC-32/ISO-HDLC (ICD §11), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for b in bytes {
        crc ^= u32::from(*b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn every_canonical_example_has_its_checksum() {
    let doc = document();
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert!(
        doc.contains("0xCBF43926"),
        "§11 must give the check value of the CRC"
    );
    let canonical = blocks(&doc, "canonical");
    assert!(
        !canonical.is_empty(),
        "Appendix B holds no ```canonical block"
    );
    for (title, body, after) in canonical {
        let bytes = parse_hex(&title, &body);
        let said = after
            .iter()
            .find_map(|l| l.strip_prefix("checksum = 0x"))
            .unwrap_or_else(|| panic!("{title}: no `checksum = 0x...` line under the block"));
        let said = u32::from_str_radix(said.trim(), 16).unwrap();
        assert_eq!(
            crc32(&bytes),
            said,
            "{title}: the CRC-32 of the canonical bytes is 0x{:08X}, the document says 0x{said:08X}",
            crc32(&bytes)
        );
    }
}
