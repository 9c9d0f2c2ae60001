//! missionlink: the mission data-handling system of an automatic flight guidance system, after
//! Heimsch et al., Aerospace 2024, 11, 115. This root package is the harness around the
//! workspace's crates, linked by no flight or ground binary: the demo (`src/bin/demo.rs`), the
//! [`link_emulator`] the demo, tests and benches run the real GCS and FCC through, and the
//! [`harness`] of the cross-process tests in `tests/` and the benchmarks in `benches/`.

pub mod harness;
pub mod link_emulator;
