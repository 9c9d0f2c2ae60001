//! `fuzz_voting`: see `missionlink_fuzz::voting`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::voting::voting(data));
