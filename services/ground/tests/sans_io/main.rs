//! The sans-IO machines of both ends of the link in one process, in simulated time
//! (docs/design.md, "The sans-IO core"): the ground station against the FCC's own mission data
//! handling, frame by frame or over two simulated links with loss, duplication and reordering,
//! where every ICD sequence, timeout and retry takes microseconds; and guidance flying what the
//! geofence checks. One test binary, a module per topic; [`support`] is the pair they share.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

#[global_allocator]
static ALLOCATOR: missionlink_protocol::testkit::CountingAllocator =
    missionlink_protocol::testkit::CountingAllocator;

mod support;

mod faults;
mod flown_path;
mod integrity;
mod mission_pair;
mod no_allocation;
mod pipelined;
mod reject_reasons;
mod retry_timing;
mod round_trips;
mod signing;
mod staged;
mod staged_gcs;
mod upload_attempts;
mod windowed;
