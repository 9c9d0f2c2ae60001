//! The `gcs` tool as its users run it: the real binary with arguments, files and stdin, against
//! an FCC that answers nothing (what the tool checks before it sends), the Wireshark dissector
//! on the tool's captures, and the checksums of ICD §11 against the golden file computed from the
//! ICD text alone. One test binary, a module per topic; [`support`] runs the binary.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

mod support;

mod dissector;
mod inspect;
mod integrity_golden;
mod safety;
mod staged;
