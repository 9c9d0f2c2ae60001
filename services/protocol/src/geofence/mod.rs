//! The geofence: the one Earth model and the one geometry of missions and areas (ICD §4
//! "Geometry", §7). The safety gateway, the onboard check, guidance's zone monitoring and the
//! map all use it.
//!
//! - [`earth`]: the WGS-84 ellipsoid and its geodesics (`geographiclib-rs`), sites with their
//!   Earth-centred coordinates.
//! - [`plane`]: the tangent plane at a site and the planar geometry done in it.
//! - [`zone`]: the fly-zone and the no-fly-zones (geodesic polygons, geodesic circles) and their
//!   defects; [`zone::Fence`], the area list.
//! - [`path`]: what is flown (a point, a geodesic leg, a radius-to-fix arc) as a
//!   [`path::Track`].
//! - [`turn`]: the turn at a waypoint as flown (fly-by arc, fly-over and intercept), the one
//!   construction guidance flies and the checks check.
//! - [`clearance`]: the signed margin of a track against a zone, with the position of the
//!   closest approach or of the deepest violation.
//! - [`flown_route`]: the route as flown, leg by leg and turn by turn (execute, return to home,
//!   the turns round), which the onboard check, the safety gateway and the map walk.
//!
//! The onboard check of ICD §7 (ext) that measures the route as flown against the fence is the
//! FCC's (`missionlink_flight::onboard`).
//!
//! Everything the FCC runs is allocation-free (fixed capacities) and bounded in time: at most
//! [`path::MAX_PIECES`] pieces per geodesic, [`path::MAX_CORNERS`] corners per arc,
//! [`zone::MAX_BORDER_SITES`] per polygon.

pub mod clearance;
pub mod earth;
pub mod flown_route;
pub mod path;
pub mod plane;
pub mod turn;
pub mod zone;

/// Longest piece a geodesic is split into, metres. Each piece is handled in the tangent plane
/// at its start, where a piece of this length is straight to about 3 mm (see [`plane`]).
pub const PIECE_M: f64 = 20_000.0;
