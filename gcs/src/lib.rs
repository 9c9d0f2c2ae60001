//! The ground segment of missionlink: everything the GCS needs and the FCC never links.
//!
//! - [`gcs_link`]: the GCS link driver, the sans-IO GCS logic
//!   ([`missionlink_ground::ground_station`]) over the two UDP links.
//! - [`mission_file`]: the TOML mission file; [`qgc`]: QGroundControl `.plan` import and
//!   export; [`geojson`]: areas as GeoJSON; [`import`]: the error and the rules all three
//!   importers share (and `json_path`, the JSON walker of the two JSON formats).
//! - [`geoid`]: mean sea level against the WGS-84 ellipsoid, for MAVLink's and QGC's AMSL
//!   altitudes.
//! - [`mavlink`]: `gcs mavlink`, the vehicle for QGroundControl, MAVSDK and pymavlink.
//! - [`monitor`]: what `gcs monitor` prints, position and FROM-TO-NEXT together.
//! - [`map`]: the mission map as SVG; [`inspect`]: the frame inspector; [`profile`]: the
//!   aircraft profile and environment the safety gateway checks against; [`report_table`]: the
//!   FCC's mission report (ICD §8) as a table.

pub mod gcs_link;
pub mod geoid;
pub mod geojson;
pub mod import;
pub mod inspect;
mod json_path;
pub mod map;
pub mod mavlink;
pub mod mission_file;
pub mod monitor;
pub mod pcap;
pub mod profile;
pub mod qgc;
pub mod report_table;
pub mod service;
mod values;
