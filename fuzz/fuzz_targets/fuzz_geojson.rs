//! `fuzz_geojson`: see `missionlink_fuzz::importers`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::importers::geojson(data));
