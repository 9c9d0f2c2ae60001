//! `fuzz_gcs`: see `missionlink_fuzz::gcs`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::gcs::gcs(data));
