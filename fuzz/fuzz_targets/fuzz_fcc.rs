//! `fuzz_fcc`: see `missionlink_fuzz::fcc`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::fcc::fcc(data));
