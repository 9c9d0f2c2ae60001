//! `fuzz_qgc_plan`: see `missionlink_fuzz::importers`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::importers::qgc_plan(data));
