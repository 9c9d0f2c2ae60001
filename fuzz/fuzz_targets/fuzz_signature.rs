//! `fuzz_signature`: see `missionlink_fuzz::signature`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::signature::signature(data));
