//! `fuzz_datagram`: see `missionlink_fuzz::datagram`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| missionlink_fuzz::datagram::datagram(data));
