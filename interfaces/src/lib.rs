//! The contracts of missionlink, and nothing else: no I/O, no clocks.
//!
//! - [`wire`]: the STANAG 4586 wire layer of `docs/icd.md` (wrapper, field encodings, presence
//!   vector, the messages), typed values in physical units with encode and decode.
//! - [`contracts`]: the iceoryx2 payloads and service names between the FCC partitions
//!   (`docs/design.md`, "Contracts between partitions").
//! - [`capacity`]: the fixed capacities both share; [`defaults`]: the defaults of ICD §1.

pub mod capacity;
pub mod contracts;
pub mod defaults;
pub mod wire;
