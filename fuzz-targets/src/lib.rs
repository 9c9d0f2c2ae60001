//! The fuzz targets of missionlink (docs/design.md, "Testing"), one entry point per target: a
//! function that takes the fuzzer's bytes and panics only when an invariant is broken.
//!
//! The entry points live here, in a crate of the workspace that builds on stable, so that one
//! piece of code serves both who calls them:
//! - the cargo-fuzz crate `fuzz/` (nightly, its own workspace, excluded from this one) wraps each
//!   in a `fuzz_target!` of one line, binary `fuzz_<name>`;
//! - the test `tests/corpus_replay.rs` (stable, part of `cargo test --workspace`) replays every
//!   file of every corpus in `fuzz/corpus/` and of `fuzz/artifacts/` through the same functions,
//!   so CI keeps every input that ever mattered.
//!
//! The targets ([`TARGETS`]):
//! - [`datagram::datagram`]: the datagram walker and the message decoders (`interfaces` wire);
//! - [`fcc::fcc`]: mission data handling fed sequences of frames: the active lists are unchanged
//!   or whole valid lists after every input;
//! - [`gcs::gcs`]: the GCS logic fed frames in the middle of uploads and downloads;
//! - [`voting::voting`]: voting across both links, each signing policy;
//! - [`signature::signature`]: the signature check of ICD §9 against a model;
//! - [`importers::qgc_plan`], [`importers::geojson`], [`importers::mission_toml`]: the
//!   QGroundControl `.plan`, GeoJSON and TOML mission importers.
//!
//! The targets that take sequences cut their input with [`input::records`]; the seed generator
//! (`examples/seed_corpora.rs`) writes seeds with [`input::record`].
//!
//! Assertions are what this crate is for: it may panic, unwrap and index where the product may
//! not (the workspace lints deny them in product code).
#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

pub mod datagram;
pub mod fcc;
pub mod gcs;
pub mod importers;
pub mod input;
pub mod session;
pub mod signature;
pub mod voting;

/// A target's entry point.
pub type EntryPoint = fn(&[u8]);

/// Every target: its name (the cargo-fuzz binary and the corpus directory `fuzz/corpus/<name>`)
/// and its entry point.
pub const TARGETS: [(&str, EntryPoint); 8] = [
    ("fuzz_datagram", datagram::datagram),
    ("fuzz_fcc", fcc::fcc),
    ("fuzz_gcs", gcs::gcs),
    ("fuzz_voting", voting::voting),
    ("fuzz_signature", signature::signature),
    ("fuzz_qgc_plan", importers::qgc_plan),
    ("fuzz_geojson", importers::geojson),
    ("fuzz_mission_toml", importers::mission_toml),
];

/// The entry point of the target `name`.
pub fn entry_point(name: &str) -> Option<EntryPoint> {
    TARGETS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
}
