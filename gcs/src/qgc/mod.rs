//! QGroundControl `.plan` files: import into a [`MissionPlan`] (waypoints, areas and the planned
//! take-off position) and export of a [`ValidatedPlan`]. A `.plan` file is JSON: `mission` (the
//! items, the planned home position, the planning speeds), `geoFence` (polygons and circles) and
//! `rallyPoints`. A file that is not a `.plan` at all or holds a value that cannot be read is an
//! error ([`MissionFileError::Syntax`] with line and column from the JSON parser, or
//! [`MissionFileError::Field`] with the JSON path, e.g. `mission.items[3].params[4]`).
//!
//! # Exact or refused
//!
//! The import gives the plan the file describes, or none: an element that the ICD cannot carry
//! or the FCC cannot hold (each marked *not supported* below) makes it fail with
//! [`MissionFileError::Unsupported`], which names every such element with its JSON path (e.g.
//! `mission.items[3]`, `geoFence.polygons[1]`, `geoFence.circles[10]`) and the reason. An
//! operator who wants the rest anyway says so ([`ImportOptions::unsupported`],
//! [`Unsupported::Drop`]; `gcs --drop unsupported`): the elements are then left out and listed in
//! [`QgcImport::dropped`], so that validation judges what will be uploaded. Nothing is
//! approximated. What only QGC uses and changes nothing the FCC flies is not an element of this
//! kind: the planned home position, the take-off item once its position and height are taken,
//! the acceptance radius and yaw of a waypoint (0, "the vehicle's default").
//!
//! # Import: mission items
//!
//! Items are read in order; MAVLink command numbers (`MAV_CMD`) and frames (`MAV_FRAME`):
//!
//! - **Take-off** (22 `NAV_TAKEOFF`, 84 `NAV_VTOL_TAKEOFF`): its altitude gives the take-off
//!   height (#13006 type 1, above ground). In a relative or terrain frame the altitude is the
//!   height; in a global (AMSL) frame the height is the altitude less the planned home altitude.
//!   Its latitude and longitude (params 5 and 6), when not 0 or null, are the planned take-off
//!   position ([`MissionPlan::take_off_position`]: not sent, checked by the safety gateway);
//!   otherwise the planned home is. ArduPilot's minimum pitch (param 1) and the yaw are not
//!   carried. A second take-off is not supported; a take-off after a waypoint is an error (the
//!   ICD's take-off comes first), and so is a file without a take-off (the ICD's mission needs
//!   its height).
//! - **Waypoint** (16 `NAV_WAYPOINT`): a track-to-fix #13002. Waypoints are numbered 1..n in
//!   item order, each one's next is the following one and the last one's next is 0; the route
//!   (#13001) starts at waypoint 1 and is one-way unless [`ImportOptions::bidirectional`]. The
//!   turn is fly-by. A hold time above 0 (param 1) is not supported (the ICD has no hold);
//!   dropped, the waypoint is fly-over. The acceptance and pass radii and the yaw are not
//!   carried (PX4 and ArduPilot treat 0, the value QGC writes, as "the vehicle's default").
//! - **Land** (21 `NAV_LAND`, 85 `NAV_VTOL_LAND`): the land position is the last waypoint of the
//!   route, because the FCC lands at the last waypoint by itself (as demo mission 2 lands at
//!   ROLE2). When the waypoint before already lies at that position (the same wire value), it is
//!   the last waypoint and no waypoint is added; otherwise a fly-over waypoint is added at the
//!   land position, at the altitude (and altitude type) of the waypoint before: the approach
//!   altitude, the descent being the FCC's. The land altitude of the item is not used. Items
//!   after a land are not supported (the route ends there).
//! - **Speed change** (178 `DO_CHANGE_SPEED`): applies to the waypoints that follow. Param 1
//!   is the speed type (0 airspeed -> indicated airspeed, 1 ground speed -> ground speed; 2 and 3,
//!   climb and descent speeds, are not supported), param 2 the speed in m/s (-1: no change). The
//!   waypoints before any speed change fly the file's planning speed as QGC does: `hoverSpeed`
//!   for a multi-rotor `vehicleType` (MAV_TYPE 2, 3, 4, 13, 14, 15, 29, 35, QGC's
//!   `isMultiRotor`), `cruiseSpeed` for every other (fixed-wing, VTOL, rover), with no speed
//!   type (absent: the FCC's default). `firmwareType` does not change the mapping.
//! - **Altitude frames** of waypoints and take-off: 3 `GLOBAL_RELATIVE_ALT` and 6 (its `_INT`)
//!   are heights above home, written as AGL (#13002 altitude type 2: exact at home, the
//!   terrain elsewhere is not known to the file); 10 `GLOBAL_TERRAIN_ALT` and 11 are above
//!   terrain, AGL; 0 `GLOBAL` and 5 are AMSL: a waypoint's altitude becomes its WGS-84 height
//!   (type 3) at its position by the geoid ([`crate::geoid`], EGM96), so the FCC flies at the
//!   height above mean sea level the operator planned. QGC's "calculated above terrain" mode (`AltitudeMode` 3) saves frame 0 with a
//!   null altitude when it had no terrain data: the item's `Altitude` (above terrain) is then
//!   taken as AGL. Any other frame is not supported (the item, path `.frame`).
//! - **Everything else** is not supported: other commands (loiters 17, 18, 19, 31,
//!   return-to-launch 20, region of interest 195 and 201, camera, jumps, ...), complex items
//!   (surveys, corridor and structure scans, landing patterns) and rally points.
//!
//! A file without a waypoint or land item is an error ("no waypoints"); its geofence can still
//! be imported with [`import_areas`].
//!
//! The planned home position (`plannedHomePosition`, `[latitude, longitude, altitude AMSL]`) is
//! the reference of AMSL take-off altitudes and the take-off position when the take-off item
//! has none (QGC's "not set", (0, 0), is none). It is not a waypoint (the ICD has no home
//! position); it is returned in [`QgcImport::home`] for an export to write back.
//!
//! # Import: geofence
//!
//! The inclusion polygon is the fly-zone; a second one is not supported (the ICD has one
//! fly-zone). Exclusion polygons and circles are no-fly-zones (a circle's border point is placed
//! due north of its centre at the radius, a geodesic on WGS-84). An inclusion circle is not
//! supported: the ICD's fly-zone is a polygon (draw it as one). The FCC holds eleven areas, one
//! of them the fly-zone: the no-fly-zones after the tenth (exclusion polygons first, then
//! circles, in file order) are not supported, and neither are polygons of more than 60
//! vertices. Area IDs are 1..n: the fly-zone first, then the exclusion polygons and the
//! exclusion circles in file order. QGC has no safety offset: it is
//! [`ImportOptions::safety_offset_m`] (0 by default). A file without a geofence gives no areas
//! (they may come from elsewhere, e.g. GeoJSON).
//!
//! # Export
//!
//! [`export_plan`] writes a `.plan` (`fileType` "Plan", version 1, `groundStation`
//! "missionlink") that QGC reads: a take-off at the planned take-off position
//! ([`ExportOptions::take_off_position`], else the home position) with the take-off height
//! (frame 3), a `DO_CHANGE_SPEED` wherever the speed or its type changes (the first waypoint's
//! speed is also `cruiseSpeed` and `hoverSpeed`), every waypoint in flight-plan order (AGL in
//! frame 3, WGS-84 in frame 0 as its height above mean sea level by the geoid), a land at the last waypoint, the planned home (given, else the
//! take-off position, else the first waypoint, at 0 m AMSL), the geofence (the
//! fly-zone an inclusion polygon, no-fly polygons exclusion polygons, no-fly circles exclusion
//! circles whose radius is the geodesic distance centre -> border point, to the millimetre)
//! and no rally points. What QGC cannot hold is returned as notes: radius-to-fix legs
//! (written as track-to-fix), fly-over turns, true airspeed (written as airspeed), pressure,
//! baro or absent altitude types (written as AMSL), the bidirectional route, mission and route
//! IDs, route type, the safety offset and area altitude bounds. The other optional #13002
//! fields (arrival time, activity ID, limits) are not written. Area IDs are not kept: QGC
//! holds polygons and circles in two lists, and an import numbers them as above.

use missionlink_ground::ground_station::{MissionPlan, ValidatedPlan};
use missionlink_interfaces::capacity::{
    MAX_AREAS, MAX_NO_FLY_ZONES, MAX_POLYGON_VERTICES, MAX_WAYPOINTS,
};
use missionlink_interfaces::wire::{
    Altitude, AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, LegType,
    PolygonVertices, SafetyOffset, SpecificData, Speed, SpeedType, Timestamp, TurnType,
    UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};
use missionlink_protocol::transfer::areas::AreaBuffer;
use missionlink_protocol::transfer::mission::MissionBuffer;
use serde_json::{Value, json};

use crate::mission_file::MissionFileError;
use crate::values::{
    altitude, amsl_metres, border_due_north, degrees, field_error, latitude, longitude, metres,
    point, radius, radius_mm,
};

pub use crate::import::{Dropped, Unsupported};
use crate::import::{exact_or_dropped, note};
use crate::json_path::{At, parse_json};

mod commands;
mod export;
mod fence;
mod items;

use self::commands::*;
pub use self::export::export_plan;
pub(crate) use self::export::pretty;
use self::fence::*;
use self::items::*;

/// Choices the `.plan` file cannot express.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImportOptions {
    /// The #2011 safety offset, metres (QGC has none; default 0).
    pub safety_offset_m: f64,
    /// Whether return-to-home may fly the route backwards (QGC has no such notion).
    pub bidirectional: bool,
    /// Refuse the file (the default) or drop what it holds that the ICD cannot carry.
    pub unsupported: Unsupported,
}

/// The planned home position of a `.plan`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Home {
    /// Latitude, degrees.
    pub latitude_deg: f64,
    /// Longitude, degrees.
    pub longitude_deg: f64,
    /// Altitude above mean sea level, metres.
    pub altitude_m: f64,
}

/// What [`import_plan`] gives.
#[derive(Debug, Clone)]
pub struct QgcImport {
    /// The mission plan: take-off height and position, waypoints, route and areas.
    pub plan: MissionPlan,
    /// The planned home position, if the file has one.
    pub home: Option<Home>,
    /// What was left out ([`Unsupported::Drop`]), in file order; empty for an exact import.
    pub dropped: Vec<Dropped>,
}

/// How [`export_plan`] fills what a [`ValidatedPlan`] does not hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExportOptions {
    /// The planned take-off position (the plan's, [`MissionPlan::take_off_position`]): the
    /// position of the take-off item, and the planned home when `home` is not given.
    pub take_off_position: Option<GeoPoint>,
    /// The planned home position; `None`: the take-off position, else the first waypoint's
    /// position, at 0 m AMSL.
    pub home: Option<Home>,
    /// MAV_TYPE of `vehicleType`; default 22 (VTOL with separate lift and cruise rotors, the
    /// demo eVTOL), for which QGC plans with `cruiseSpeed`.
    pub vehicle_type: u32,
    /// MAV_AUTOPILOT of `firmwareType`; default 12 (PX4).
    pub firmware_type: u32,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            take_off_position: None,
            home: None,
            vehicle_type: 22,
            firmware_type: 12,
        }
    }
}

// ---- Import ----

/// Imports the mission and the geofence of a `.plan` file (see the [module documentation](self)).
pub fn import_plan(text: &str, options: &ImportOptions) -> Result<QgcImport, MissionFileError> {
    let root = parse_json(text)?;
    let at = At::root(&root);
    check_file_type(&at)?;
    let mission = at.field("mission")?;
    let home = planned_home(&mission)?;
    let mut dropped = Vec::new();
    let (mission_buffer, take_off_item) = import_items(&mission, home, options, &mut dropped)?;
    let areas = import_fence(&at, &mut dropped)?;
    if let Some(rally) = at.opt("rallyPoints") {
        if let Some(points) = rally.opt("points") {
            for p in points.items()? {
                dropped.push(note(
                    &p.path,
                    "a rally point is not supported (the ICD has none)",
                ));
            }
        }
    }
    let safety_offset = SafetyOffset::from_metres(options.safety_offset_m)
        .map_err(|e| field_error("safety_offset_m", e.to_string()))?;
    // The take-off item's own position, else the planned home: where QGC shows the take-off.
    let take_off_position = match (take_off_item, home) {
        (Some(p), _) => Some(p),
        (None, Some(h)) => home_point(h)?,
        (None, None) => None,
    };
    Ok(QgcImport {
        plan: MissionPlan {
            mission: mission_buffer,
            areas,
            safety_offset,
            mission_id: None,
            take_off_position,
        },
        home,
        dropped: exact_or_dropped(dropped, options.unsupported)?,
    })
}

/// The planned home as a position; `None` for QGC's "not set" (0, 0).
fn home_point(home: Home) -> Result<Option<GeoPoint>, MissionFileError> {
    if home.latitude_deg == 0.0 && home.longitude_deg == 0.0 {
        return Ok(None);
    }
    point(
        "mission.plannedHomePosition",
        home.latitude_deg,
        home.longitude_deg,
    )
    .map(Some)
}

/// Imports only the geofence of a `.plan` file as areas (a file that holds only a fence, or the
/// areas of a mission planned elsewhere), with what was dropped ([`Unsupported::Drop`]). The
/// mission items and rally points are not looked at.
pub fn import_areas(
    text: &str,
    unsupported: Unsupported,
) -> Result<(AreaBuffer, Vec<Dropped>), MissionFileError> {
    let root = parse_json(text)?;
    let at = At::root(&root);
    check_file_type(&at)?;
    let mut dropped = Vec::new();
    let areas = import_fence(&at, &mut dropped)?;
    Ok((areas, exact_or_dropped(dropped, unsupported)?))
}

fn check_file_type(at: &At<'_>) -> Result<(), MissionFileError> {
    let file_type = at.field("fileType")?;
    match file_type.string()? {
        "Plan" => Ok(()),
        other => Err(file_type.error(format!("{other:?}: not a QGroundControl plan (\"Plan\")"))),
    }
}

fn planned_home(mission: &At<'_>) -> Result<Option<Home>, MissionFileError> {
    let Some(home) = mission.opt("plannedHomePosition") else {
        return Ok(None);
    };
    let values = home.items()?;
    let [lat, lon, alt] = values.as_slice() else {
        return Err(home.error(format!(
            "{} values, expected [latitude, longitude, altitude]",
            values.len()
        )));
    };
    let latitude_deg = lat.number()?;
    latitude(&lat.path, latitude_deg)?;
    let longitude_deg = lon.number()?;
    longitude(&lon.path, longitude_deg)?;
    Ok(Some(Home {
        latitude_deg,
        longitude_deg,
        altitude_m: alt.number()?,
    }))
}

#[cfg(test)]
pub(crate) mod tests;
