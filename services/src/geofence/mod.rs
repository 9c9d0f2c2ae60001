//! The geometry of missions and areas on the Earth: the one Earth model every check and every
//! drawing uses (ICD §4 "Geometry", §7).

pub mod local_frame;
