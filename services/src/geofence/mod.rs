//! The geometry of missions and areas on the Earth: the one Earth model every check and every
//! drawing uses (ICD §4 "Geometry", §7).
//!
//! - [`earth`]: the WGS-84 ellipsoid and its geodesics (distance, bearing, destination), for
//!   guidance, the mission files and every circle's radius.
//! - [`local_frame`]: the local metric projection on that ellipsoid in which the safety gateway
//!   checks and the map draws, and the radius-to-fix arc in it.

pub mod earth;
pub mod local_frame;
