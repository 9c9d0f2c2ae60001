//! Fixed capacities of the FCC, shared by the wire layer, the services and the iceoryx2 payloads
//! (ICD §6 `Capacity`: more than these is refused, never truncated).

/// Waypoints in one assembled waypoint list.
pub const MAX_WAYPOINTS: usize = 256;
/// Areas in one assembled area list: one fly-zone and up to ten no-fly-zones (ICD §5.3: a
/// #2011 that announces more is refused).
pub const MAX_AREAS: usize = 11;
/// No-fly-zones in one area list.
pub const MAX_NO_FLY_ZONES: usize = MAX_AREAS - 1;
/// Vertices of one polygon (ICD §4, #2012: 3..=60).
pub const MAX_POLYGON_VERTICES: usize = 60;
/// Vertices of a polygon at least (ICD §4, #2012).
pub const MIN_POLYGON_VERTICES: usize = 3;
/// Staged missions the FCC holds beside the active lists (ICD §8).
pub const MAX_STAGED_MISSIONS: usize = 8;
/// Entries of a mission report (ICD §8, #50001): the active lists, then each staged mission.
pub const MAX_REPORT_ENTRIES: usize = 1 + MAX_STAGED_MISSIONS;
