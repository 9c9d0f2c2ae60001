//! missionlink: the mission data-handling system of an automatic flight guidance system, after
//! Heimsch et al., Aerospace 2024, 11, 115. This root package owns the cross-process tests in
//! `tests/` and the benchmarks in `benches/`; the code lives in the workspace crates, re-exported
//! here for them, and the [`link_emulator`] they run the real GCS and FCC through.

pub mod link_emulator;

pub use missionlink_interfaces as interfaces;
