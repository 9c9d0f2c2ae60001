//! `fuzz_mission_toml`: see `missionlink_fuzz::importers`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::importers::mission_toml(data));
