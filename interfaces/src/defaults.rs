//! The defaults of ICD §1. Every one is configurable; these are what a node uses when nothing
//! else is configured, and what a third-party peer built from the ICD expects.

use core::time::Duration;

/// GCS (CUCS) ID.
pub const GCS_ID: u32 = 0x0A00_0001;
/// FCC (vehicle) ID.
pub const FCC_ID: u32 = 0x0B00_0001;
/// The FCC receives the direct link here.
pub const FCC_DIRECT: &str = "127.0.0.1:4586";
/// The GCS receives the direct link here.
pub const GCS_DIRECT: &str = "127.0.0.1:4587";
/// The FCC receives the LTE link here.
pub const FCC_LTE: &str = "127.0.0.1:4588";
/// The GCS receives the LTE link here.
pub const GCS_LTE: &str = "127.0.0.1:4589";
/// How long a sender waits for the answer to a message before its one retry (ICD §5).
pub const ACK_TIMEOUT: Duration = Duration::from_millis(500);
/// How long a receiver in a transfer waits for its peer before abandoning it (ICD §5).
pub const TRANSFER_TIMEOUT: Duration = Duration::from_secs(3);
