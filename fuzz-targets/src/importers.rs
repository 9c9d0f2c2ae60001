//! Targets `fuzz_qgc_plan`, `fuzz_geojson` and `fuzz_mission_toml`: the mission files that
//! come from other tools and from operators (`gcs/src/qgc/`, `gcs/src/geojson.rs`,
//! `gcs/src/mission_file/`), taken the way `gcs validate` takes them.
//!
//! The input is the file's bytes (invalid UTF-8 replaced, as an editor would show it). Each
//! import runs as it refuses what the ICD cannot carry and as it drops it. Checked:
//! - nothing panics, on the import and on what follows it: the ICD §7 assembly, the safety
//!   gateway with the default profile (paper §2.2), the energy estimate, the one-line summaries;
//! - an error names a position: a syntax error its line and column (from 1, within the file),
//!   a value its field path, a refusal every element it refuses with its path; an import never
//!   reports an I/O error (it reads no file);
//! - a TOML plan whose lists assemble writes a file (`MissionFile::from_plan`, as `gcs convert`
//!   and `gcs download -o` do) that reads back to the same lists (docs/mission-files.md: a
//!   download followed by an upload is a round trip).

use core::fmt::Write;

use missionlink_gcs::geojson;
use missionlink_gcs::mission_file::{MissionFile, MissionFileError};
use missionlink_gcs::qgc::{self, ImportOptions, Unsupported};
use missionlink_ground::ground_station::{MissionPlan, ValidatedPlan};
use missionlink_ground::safety_gateway::SafetyGateway;

/// Entry point of `fuzz_qgc_plan`: a QGroundControl `.plan` file, whole and as a geofence only.
pub fn qgc_plan(input: &[u8]) {
    let text = String::from_utf8_lossy(input);
    for unsupported in [Unsupported::Refuse, Unsupported::Drop] {
        let options = ImportOptions {
            safety_offset_m: 25.0,
            bidirectional: false,
            unsupported,
        };
        match qgc::import_plan(&text, &options) {
            Ok(import) => {
                dropped(&import.dropped, unsupported);
                checked(&import.plan);
            }
            Err(error) => positioned(&text, &error),
        }
        match qgc::import_areas(&text, unsupported) {
            Ok((_, d)) => dropped(&d, unsupported),
            Err(error) => positioned(&text, &error),
        }
    }
}

/// Entry point of `fuzz_geojson`: a GeoJSON `FeatureCollection` of areas, checked against the
/// waypoint list of demo mission 2 as `gcs validate --areas` does.
pub fn geojson(input: &[u8]) {
    let text = String::from_utf8_lossy(input);
    for unsupported in [Unsupported::Refuse, Unsupported::Drop] {
        match geojson::import_areas(&text, unsupported) {
            Ok((areas, d)) => {
                dropped(&d, unsupported);
                let mut plan = missionlink_protocol::testkit::mission_2();
                plan.areas = areas;
                checked(&plan);
            }
            Err(error) => positioned(&text, &error),
        }
    }
}

/// Entry point of `fuzz_mission_toml`: a missionlink TOML mission file.
pub fn mission_toml(input: &[u8]) {
    let text = String::from_utf8_lossy(input);
    let plan = match MissionFile::parse(&text).and_then(|file| file.to_plan()) {
        Ok(plan) => plan,
        Err(error) => return positioned(&text, &error),
    };
    let Some(valid) = checked(&plan) else {
        return;
    };
    let written = MissionFile::from_plan(&valid, plan.take_off_position).to_toml();
    let again = MissionFile::parse(&written)
        .and_then(|file| file.to_plan())
        .unwrap_or_else(|e| panic!("a written mission file does not read back: {e}\n{written}"));
    assert_eq!(
        again.take_off_position, plan.take_off_position,
        "the take-off position changed in a round trip"
    );
    let lists = again
        .assemble()
        .unwrap_or_else(|e| panic!("a written mission file does not assemble: {e}\n{written}"));
    assert_eq!(lists, valid, "the lists changed in a round trip\n{written}");
}

/// What `gcs validate` does with an imported plan; the lists when they pass ICD §7.
fn checked(plan: &MissionPlan) -> Option<ValidatedPlan> {
    shown(plan);
    let lists = plan.lists_to_check().ok()?;
    let gateway = SafetyGateway::default();
    for violation in gateway.violations(&lists.mission, &lists.areas, plan.take_off_position) {
        shown(&violation);
    }
    let _ = gateway.estimate_energy(&lists.mission, plan.take_off_position);
    let valid = ValidatedPlan {
        mission: lists.mission,
        areas: lists.areas,
    };
    shown(&valid);
    lists.invalid.is_none().then_some(valid)
}

/// Elements left out are named by their path, and only when the import may drop them.
fn dropped(elements: &[qgc::Dropped], unsupported: Unsupported) {
    assert!(
        unsupported == Unsupported::Drop || elements.is_empty(),
        "an import that refuses what it cannot carry dropped elements"
    );
    for e in elements {
        assert!(
            !e.path.is_empty() && !e.reason.is_empty(),
            "a dropped element without path or reason"
        );
    }
}

/// An error names a position in `text`.
fn positioned(text: &str, error: &MissionFileError) {
    match error {
        MissionFileError::Syntax {
            line,
            column,
            message,
        } => {
            let lines = text.split('\n').count();
            assert!(
                (1..=lines).contains(line) && *column >= 1,
                "a syntax error at line {line}, column {column} of a file of {lines} lines"
            );
            assert!(!message.is_empty(), "a syntax error without a message");
        }
        MissionFileError::Field { path, reason } => {
            assert!(
                !path.is_empty() && !reason.is_empty(),
                "a field error without path or reason: {error:?}"
            );
        }
        MissionFileError::Unsupported { elements } => {
            assert!(!elements.is_empty(), "a refusal that names no element");
            dropped(elements, Unsupported::Drop);
        }
        MissionFileError::Io { .. } => panic!("an import from text reports I/O: {error}"),
    }
    shown(error);
}

/// `Display` writes something and never fails.
fn shown(value: &dyn core::fmt::Display) {
    let mut text = String::new();
    assert!(write!(text, "{value}").is_ok(), "Display failed");
    assert!(!text.is_empty(), "Display wrote nothing");
}
