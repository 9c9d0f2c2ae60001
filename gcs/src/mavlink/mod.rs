//! `gcs mavlink`: the GCS presents the vehicle to MAVLink 2 clients (QGroundControl, MAVSDK,
//! pymavlink) over UDP.
//!
//! - [`vehicle`]: the vehicle's MAVLink logic, sans-IO (time injected, its timer table); its
//!   module documentation says how QGroundControl's mission, fence and rally uploads become one
//!   atomic upload to the FCC.
//! - [`driver`]: the UDP socket and the GCS link; it only moves bytes and carries out the
//!   vehicle's commits and executes.
//! - [`home`]: the vehicle's home and altitudes above mean sea level.
//! - [`memory`]: what the vehicle remembers across its restarts (the items the client
//!   uploaded, the home), so a download returns what was uploaded.
//! - [`plan`]: MAVLink mission and fence items to the GCS's plan through the one `.plan`
//!   importer ([`crate::qgc`]), so a client's mission is taken or refused, with the index of the
//!   item, by the same rules as a `.plan` file; and the FCC's lists back to items.
//!
//! docs/qgroundcontrol.md tells how to connect QGroundControl.
//!
//! The MAVLink 2 framing and the `common` message set are the `mavlink` crate's.

pub mod driver;
pub mod home;
pub mod memory;
pub mod plan;
pub mod vehicle;
