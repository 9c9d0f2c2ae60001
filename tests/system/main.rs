//! The cross-process tests: the real binaries (the fcc launcher and its partitions, the gcs tool,
//! the Python guidance, the Zenoh bridge, ground stations nobody here wrote) as processes over
//! UDP and iceoryx2, through the link emulator where links must fail, with `kill -9` and
//! SIGSTOP (docs/design.md, "Testing"). One test binary, a module per topic, on the harness of
//! the root package (`missionlink::harness`): each test has its own prefix, ports and state
//! directory, so they run in parallel.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

mod atomic_activation;
mod atomic_upload;
mod c_partition;
mod demo;
mod emulated_links;
mod end_to_end;
mod ground_service;
mod health;
mod isolation;
mod link_faults;
mod mavlink_clients;
mod position_downlink;
mod python_guidance;
mod restart_safety;
mod signed_links;
mod supervision;
mod two_hosts;
