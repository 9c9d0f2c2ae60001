//! `gcs mavlink`: the GCS presents the vehicle to MAVLink 2 clients (QGroundControl, MAVSDK,
//! pymavlink) over UDP.
//!
//! Built so far: [`bridge`], the sans-IO MAVLink vehicle (its module documentation says how
//! the mission and fence uploads commit as one); [`plan`], the conversion of MAVLink mission and fence items into the GCS's plan
//! through the one `.plan` importer ([`crate::qgc`]), so that a client's mission is taken or
//! refused, with the index of the item, by the same rules as a `.plan` file.
//!
//! The MAVLink 2 framing and the `common` message set are the `mavlink` crate's.

pub mod bridge;
pub mod driver;
pub mod plan;
