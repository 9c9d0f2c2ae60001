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
//!   terrain, AGL; 0 `GLOBAL` and 5 are AMSL, written as WGS-84 (type 3; the geoid separation is
//!   not applied). QGC's "calculated above terrain" mode (`AltitudeMode` 3) saves frame 0 with a
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
//! frame 3, WGS-84 in frame 0), a land at the last waypoint, the planned home (given, else the
//! take-off position, else the first waypoint, at 0 m AMSL), the geofence (the
//! fly-zone an inclusion polygon, no-fly polygons exclusion polygons, no-fly circles exclusion
//! circles whose radius is the geodesic distance centre -> border point, to the millimetre)
//! and no rally points. What QGC cannot hold is returned as notes: radius-to-fix legs
//! (written as track-to-fix), fly-over turns, true airspeed (written as airspeed), pressure,
//! baro or absent altitude types (written as AMSL), the bidirectional route, mission and route
//! IDs, route type, the safety offset and area altitude bounds. The other optional #13002
//! fields (arrival time, activity ID, limits) are not written. Area IDs are not kept: QGC
//! holds polygons and circles in two lists, and an import numbers them as above.

use missionlink_interfaces::capacity::{
    MAX_AREAS, MAX_NO_FLY_ZONES, MAX_POLYGON_VERTICES, MAX_WAYPOINTS,
};
use missionlink_interfaces::wire::{
    Altitude, AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, LegType,
    PolygonVertices, SafetyOffset, SpecificData, Speed, SpeedType, Timestamp, TurnType,
    UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};
use missionlink_services::ground_station::{MissionPlan, ValidatedPlan};
use missionlink_services::transfer::areas::AreaBuffer;
use missionlink_services::transfer::mission::MissionBuffer;
use serde_json::{Value, json};

use crate::mission_file::MissionFileError;
use crate::values::{
    altitude, border_due_north, degrees, field_error, latitude, longitude, metres, point, radius,
    radius_mm,
};

pub use crate::import::{Dropped, Unsupported};
use crate::import::{exact_or_dropped, note};
use crate::json_path::{At, parse_json};

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

/// A waypoint being imported.
struct Pending {
    position: GeoPoint,
    altitude: Altitude,
    altitude_type: AltitudeType,
    speed: Speed,
    speed_type: Option<SpeedType>,
    turn_type: TurnType,
}

/// MAV_TYPEs that QGC plans with `hoverSpeed` (`QGCMAVLink::isMultiRotor`).
const MULTI_ROTOR_TYPES: [u64; 8] = [2, 3, 4, 13, 14, 15, 29, 35];

/// The take-off, waypoints and route of the mission items, and the take-off item's position
/// (if it has one); what they hold that the ICD cannot carry goes to `dropped`.
fn import_items(
    mission: &At<'_>,
    home: Option<Home>,
    options: &ImportOptions,
    dropped: &mut Vec<Dropped>,
) -> Result<(MissionBuffer, Option<GeoPoint>), MissionFileError> {
    let vehicle_type = match mission.opt("vehicleType") {
        Some(v) => v.integer()?,
        None => 0,
    };
    let speed_key = if MULTI_ROTOR_TYPES.contains(&vehicle_type) {
        "hoverSpeed"
    } else {
        "cruiseSpeed"
    };
    let planning_speed = mission.field(speed_key)?;
    let mut speed = speed_value(&planning_speed)?;
    let mut speed_type: Option<SpeedType> = None;

    let items_at = mission.field("items")?;
    let items = items_at.items()?;
    let mut take_off: Option<(Altitude, usize, Option<GeoPoint>)> = None;
    let mut land: Option<usize> = None;
    let mut waypoints: Vec<Pending> = Vec::new();

    for (i, item) in items.iter().enumerate() {
        if let Some(j) = land {
            dropped.push(note(
                &item.path,
                format!("after the land (mission.items[{j}]): the route ends at the land"),
            ));
            continue;
        }
        let type_at = item.field("type")?;
        match type_at.string()? {
            "SimpleItem" => {}
            "ComplexItem" => {
                let kind = item
                    .opt("complexItemType")
                    .and_then(|k| k.value.as_str())
                    .unwrap_or("?");
                dropped.push(note(
                    &item.path,
                    format!(
                        "complex item {kind:?} is not supported (only take-off, waypoint, land \
                         and speed change)"
                    ),
                ));
                continue;
            }
            other => {
                return Err(type_at.error(format!(
                    "{other:?} is not \"SimpleItem\" or \"ComplexItem\""
                )));
            }
        }
        let command = item.field("command")?.integer()?;
        match command {
            22 | 84 => {
                if let Some((_, first, _)) = take_off {
                    dropped.push(note(
                        &item.path,
                        format!(
                            "command {command} ({}): a second take-off (the first is \
                             mission.items[{first}])",
                            command_name(command)
                        ),
                    ));
                    continue;
                }
                if !waypoints.is_empty() {
                    // Not droppable: without it the mission has no take-off at all.
                    return Err(item.error(format!(
                        "command {command} ({}): a take-off after waypoints is not supported \
                         (the ICD's take-off comes before the route)",
                        command_name(command)
                    )));
                }
                let params = Params::of(item)?;
                let Some((value, kind)) = item_altitude(item, &params, command, dropped)? else {
                    continue;
                };
                let height = match kind {
                    AltitudeType::Wgs84 => {
                        let Some(home) = home else {
                            return Err(params
                                .at(6)?
                                .error("an AMSL take-off altitude needs the plannedHomePosition"));
                        };
                        value - home.altitude_m
                    }
                    _ => value,
                };
                let altitude_at = params.at(6)?;
                let h = altitude(&altitude_at.path, height)?;
                if h.raw() < 0 {
                    return Err(altitude_at.error(format!(
                        "take-off height {height} m is below the ground at home"
                    )));
                }
                // Its position is the plan's take-off position (not sent, checked by the
                // safety gateway); none given (0, 0 or null): the planned home.
                take_off = Some((h, i, params.position()?));
            }
            16 => {
                let params = Params::of(item)?;
                let Some((value, kind)) = item_altitude(item, &params, command, dropped)? else {
                    continue;
                };
                let Some(position) = params.position()? else {
                    return Err(params
                        .at(4)?
                        .error("a waypoint needs latitude and longitude"));
                };
                let hold = params.at(0)?.opt_number()?.unwrap_or(0.0);
                let turn_type = if hold > 0.0 {
                    dropped.push(note(
                        &params.at(0)?.path,
                        format!(
                            "hold {hold} s is not supported (the ICD has no hold time); dropped, \
                             the waypoint is fly-over"
                        ),
                    ));
                    TurnType::FlyOver
                } else {
                    TurnType::FlyBy
                };
                waypoints.push(Pending {
                    position,
                    altitude: altitude(&params.at(6)?.path, value)?,
                    altitude_type: kind,
                    speed,
                    speed_type,
                    turn_type,
                });
            }
            21 | 85 => {
                let params = Params::of(item)?;
                let Some(position) = params.position()? else {
                    return Err(params.at(4)?.error("a land needs latitude and longitude"));
                };
                land = Some(i);
                let last = waypoints.last();
                if last.is_some_and(|w| w.position == position) {
                    continue;
                }
                let (altitude, altitude_type) = match last {
                    Some(w) => (w.altitude, w.altitude_type),
                    None => {
                        let Some((value, kind)) = item_altitude(item, &params, command, dropped)?
                        else {
                            continue;
                        };
                        (altitude(&params.at(6)?.path, value)?, kind)
                    }
                };
                waypoints.push(Pending {
                    position,
                    altitude,
                    altitude_type,
                    speed,
                    speed_type,
                    turn_type: TurnType::FlyOver,
                });
            }
            178 => {
                let params = Params::of(item)?;
                let kind_at = params.at(0)?;
                let kind = kind_at.number()?;
                let new_type = if kind == 0.0 {
                    SpeedType::IndicatedAirspeed
                } else if kind == 1.0 {
                    SpeedType::GroundSpeed
                } else {
                    dropped.push(note(
                        &kind_at.path,
                        format!(
                            "speed type {kind} (2 climb, 3 descent speed) is not supported: \
                             only airspeed (0) and ground speed (1)"
                        ),
                    ));
                    continue;
                };
                let value_at = params.at(1)?;
                if value_at.number()? < 0.0 {
                    // -1: no change of speed.
                    continue;
                }
                speed = speed_value(value_at)?;
                speed_type = Some(new_type);
            }
            _ => dropped.push(note(
                &item.path,
                format!(
                    "command {command} ({}) is not supported",
                    command_name(command)
                ),
            )),
        }
    }

    if waypoints.is_empty() {
        return Err(items_at.error(format!(
            "no waypoints: none of the {} mission items is a waypoint (command 16) or a land \
             (21); a file that holds only a geofence imports as areas",
            items.len()
        )));
    }
    if waypoints.len() > MAX_WAYPOINTS {
        return Err(items_at.error(format!(
            "{} waypoints, more than {MAX_WAYPOINTS} (the FCC's capacity)",
            waypoints.len()
        )));
    }

    let mut buffer = MissionBuffer::new();
    let stored = |r: Result<(), _>| {
        r.map_err(|_| {
            items_at.error(format!(
                "more than {MAX_WAYPOINTS} waypoints (the FCC's capacity)"
            ))
        })
    };
    // The ICD's mission has a take-off height (#13006 type 1); a mission file must give one
    // too, so a plan without a take-off is no mission.
    let Some((height, _, take_off_position)) = take_off else {
        return Err(items_at
            .error("no take-off (command 22 or 84): the ICD's mission needs its take-off height"));
    };
    stored(
        buffer.store(
            &VehicleSpecificWaypoint {
                time_stamp: Timestamp::default(),
                data: SpecificData::TakeOffHeight { height },
                activity_id: None,
            }
            .into(),
        ),
    )?;
    let count = waypoints.len();
    for (k, w) in waypoints.into_iter().enumerate() {
        // At most MAX_WAYPOINTS (checked above): the numbers fit a u16.
        let number = u16::try_from(k + 1).unwrap_or(u16::MAX);
        let next = if k + 1 == count {
            0
        } else {
            number.saturating_add(1)
        };
        stored(
            buffer.store(
                &UaPositionWaypoint {
                    time_stamp: Timestamp::default(),
                    waypoint_number: number,
                    latitude: w.position.latitude,
                    longitude: w.position.longitude,
                    location_type: None,
                    altitude: w.altitude,
                    altitude_type: Some(w.altitude_type),
                    altitude_change_behaviour: None,
                    speed: w.speed,
                    speed_type: w.speed_type,
                    next_waypoint: next,
                    turn_type: w.turn_type,
                    optional_messages: None,
                    leg_type: LegType::TrackToFix,
                    limit_type: None,
                    loop_limit: None,
                    arrival_time: None,
                    activity_id: None,
                }
                .into(),
            ),
        )?;
    }
    stored(
        buffer.store(
            &UaRoute {
                time_stamp: Timestamp::default(),
                initial_waypoint: 1,
                route_id: None,
                route_type: None,
                bidirectional: options.bidirectional,
            }
            .into(),
        ),
    )?;
    Ok((buffer, take_off_position))
}

/// The 7 params of a simple item.
struct Params<'a> {
    at: At<'a>,
    values: Vec<At<'a>>,
}

impl<'a> Params<'a> {
    fn of(item: &At<'a>) -> Result<Self, MissionFileError> {
        let at = item.field("params")?;
        let values = at.items()?;
        if values.len() != 7 {
            return Err(at.error(format!("{} values, expected 7", values.len())));
        }
        Ok(Self { at, values })
    }

    fn at(&self, k: usize) -> Result<&At<'a>, MissionFileError> {
        self.values
            .get(k)
            .ok_or_else(|| self.at.error(format!("no value {k}")))
    }

    /// Params 5 and 6 (indices 4, 5); `None` when both are null or 0 (no position).
    fn position(&self) -> Result<Option<GeoPoint>, MissionFileError> {
        let (lat_at, lon_at) = (self.at(4)?, self.at(5)?);
        let (lat, lon) = (lat_at.opt_number()?, lon_at.opt_number()?);
        match (lat, lon) {
            (None, None) | (Some(0.0), Some(0.0)) => Ok(None),
            (Some(lat), Some(lon)) => Ok(Some(GeoPoint {
                latitude: latitude(&lat_at.path, lat)?,
                longitude: longitude(&lon_at.path, lon)?,
            })),
            (None, _) => Err(lat_at.error("expected a number, found null")),
            (_, None) => Err(lon_at.error("expected a number, found null")),
        }
    }
}

/// The altitude of a take-off, waypoint or land and its type by the item's frame; `None` (and
/// the item in `dropped`) for a frame that is not supported.
fn item_altitude(
    item: &At<'_>,
    params: &Params<'_>,
    command: u64,
    dropped: &mut Vec<Dropped>,
) -> Result<Option<(f64, AltitudeType)>, MissionFileError> {
    let frame_at = item.field("frame")?;
    let frame = frame_at.integer()?;
    let alt_at = params.at(6)?;
    let value = match frame {
        3 | 6 | 10 | 11 => (alt_at.number()?, AltitudeType::Agl),
        0 | 5 => match alt_at.opt_number()? {
            Some(v) => (v, AltitudeType::Wgs84),
            None => {
                let mode = match item.opt("AltitudeMode") {
                    Some(m) => Some(m.integer()?),
                    None => None,
                };
                if mode != Some(3) {
                    return Err(alt_at.error("expected a number, found null"));
                }
                // QGC's "calculated above terrain" without terrain data.
                (item.field("Altitude")?.number()?, AltitudeType::Agl)
            }
        },
        _ => {
            dropped.push(note(
                &frame_at.path,
                format!(
                    "command {command} ({}) in frame {frame} ({}) is not supported: only \
                     global (0, 5), relative (3, 6) and terrain (10, 11) frames",
                    command_name(command),
                    frame_name(frame)
                ),
            ));
            return Ok(None);
        }
    };
    Ok(Some(value))
}

fn speed_value(at: &At<'_>) -> Result<Speed, MissionFileError> {
    let mps = at.number()?;
    let speed = Speed::from_mps(mps).map_err(|e| at.error(e.to_string()))?;
    if speed.raw() == 0 {
        return Err(at.error(format!(
            "{mps} m/s is 0 on the wire (steps of 0.5 m/s); the speed must be above 0"
        )));
    }
    Ok(speed)
}

/// The areas of the `geoFence`: the inclusion polygon as the fly-zone, then the exclusion
/// polygons and circles as no-fly-zones; what the ICD cannot carry or the FCC cannot hold goes to
/// `dropped`.
fn import_fence(root: &At<'_>, dropped: &mut Vec<Dropped>) -> Result<AreaBuffer, MissionFileError> {
    let mut fly_zone: Option<(AreaShape, String)> = None;
    let mut no_fly: Vec<(AreaShape, String)> = Vec::new();
    let Some(fence) = root.opt("geoFence") else {
        return Ok(AreaBuffer::new());
    };
    let polygons = match fence.opt("polygons") {
        Some(p) => p.items()?,
        None => Vec::new(),
    };
    for p in &polygons {
        let inclusion = p.field("inclusion")?.boolean()?;
        let vertices_at = p.field("polygon")?;
        let mut vertices = Vec::new();
        for v in vertices_at.items()? {
            let values = v.items()?;
            let [lat, lon] = values.as_slice() else {
                return Err(v.error(format!(
                    "{} values, expected [latitude, longitude]",
                    values.len()
                )));
            };
            vertices.push(GeoPoint {
                latitude: latitude(&lat.path, lat.number()?)?,
                longitude: longitude(&lon.path, lon.number()?)?,
            });
        }
        if vertices.len() > 1 && vertices.first() == vertices.last() {
            vertices.pop();
        }
        let Ok(vertices) = PolygonVertices::from_slice(&vertices) else {
            dropped.push(note(
                &p.path,
                format!(
                    "{} vertices, at most {MAX_POLYGON_VERTICES} fit a #2012",
                    vertices.len()
                ),
            ));
            continue;
        };
        let shape = AreaShape::Polygon(vertices);
        if !inclusion {
            no_fly.push((shape, p.path.clone()));
        } else if let Some((_, first)) = &fly_zone {
            dropped.push(note(
                &p.path,
                format!("a second inclusion polygon: the ICD has one fly-zone ({first})"),
            ));
        } else {
            fly_zone = Some((shape, p.path.clone()));
        }
    }
    let circles = match fence.opt("circles") {
        Some(c) => c.items()?,
        None => Vec::new(),
    };
    for c in &circles {
        let inclusion = c.field("inclusion")?.boolean()?;
        let circle = c.field("circle")?;
        let center_at = circle.field("center")?;
        let values = center_at.items()?;
        let [lat, lon] = values.as_slice() else {
            return Err(center_at.error(format!(
                "{} values, expected [latitude, longitude]",
                values.len()
            )));
        };
        let centre = GeoPoint {
            latitude: latitude(&lat.path, lat.number()?)?,
            longitude: longitude(&lon.path, lon.number()?)?,
        };
        let radius_at = circle.field("radius")?;
        let radius = radius(&radius_at.path, radius_at.number()?)?;
        if inclusion {
            // Not approximated: the import is exact or refused.
            dropped.push(note(
                &c.path,
                match &fly_zone {
                    Some((_, first)) => format!(
                        "an inclusion circle: the ICD has one fly-zone ({first}), and it is a \
                         polygon"
                    ),
                    None => "an inclusion circle: the ICD's fly-zone is a polygon (draw it as \
                             an inclusion polygon)"
                        .to_owned(),
                },
            ));
            continue;
        }
        let border = border_due_north(&radius_at.path, centre, radius)?;
        no_fly.push((AreaShape::Circle { centre, border }, c.path.clone()));
    }

    // The FCC holds MAX_AREAS areas, one of them the fly-zone: the no-fly-zones beyond
    // MAX_NO_FLY_ZONES (polygons first, then circles, as numbered) do not fit.
    for (_, path) in no_fly.get(MAX_NO_FLY_ZONES..).unwrap_or_default() {
        dropped.push(note(
            path,
            format!(
                "more than {MAX_NO_FLY_ZONES} no-fly-zones (polygons and circles): the FCC holds \
                 {MAX_AREAS} areas, one of them the fly-zone"
            ),
        ));
    }
    no_fly.truncate(MAX_NO_FLY_ZONES);

    let mut buffer = AreaBuffer::new();
    let zones = fly_zone
        .into_iter()
        .map(|z| (AreaType::FlyZone, z))
        .chain(no_fly.into_iter().map(|z| (AreaType::NoFlyZone, z)));
    for (k, (area_type, (shape, path))) in zones.enumerate() {
        let area = AreaPolygonLoopSegment {
            time_stamp: Timestamp::default(),
            area_id: u16::try_from(k + 1).unwrap_or(u16::MAX),
            area_type,
            lower_altitude: None,
            upper_altitude: None,
            altitude_type: None,
            shape,
        };
        // At most one fly-zone and MAX_NO_FLY_ZONES no-fly-zones: the buffer holds them.
        buffer.store(&area).map_err(|_| {
            field_error(
                path,
                format!("more than {MAX_AREAS} areas (the FCC's capacity)"),
            )
        })?;
    }
    Ok(buffer)
}

// ---- Export ----

/// The `.plan` file of a validated plan and what it cannot hold (see the
/// [module documentation](self)).
pub fn export_plan(plan: &ValidatedPlan, options: &ExportOptions) -> (String, Vec<Dropped>) {
    let mission = &plan.mission;
    let mut notes = Vec::new();
    let first = mission.waypoints.first().map(|r| GeoPoint {
        latitude: r.waypoint.latitude,
        longitude: r.waypoint.longitude,
    });
    let home = options.home.unwrap_or_else(|| {
        let at = options.take_off_position.or(first);
        Home {
            latitude_deg: at.map_or(0.0, |p| degrees(p.latitude)),
            longitude_deg: at.map_or(0.0, |p| degrees(p.longitude)),
            altitude_m: 0.0,
        }
    });
    let (take_off_lat, take_off_lon) = match options.take_off_position {
        Some(p) => (degrees(p.latitude), degrees(p.longitude)),
        None => (home.latitude_deg, home.longitude_deg),
    };
    let planning_speed = mission
        .waypoints
        .first()
        .map_or(0.0, |r| r.waypoint.speed.mps());

    if mission.route.bidirectional {
        notes.push(note(
            "route.bidirectional",
            "QGC has no bidirectional route (return-to-home flying it backwards): not written",
        ));
    }
    if let Some(id) = mission.mission_id {
        notes.push(note(
            "mission_id",
            format!("{:?}: QGC has no mission ID: not written", id.as_str()),
        ));
    }
    if let Some(id) = mission.route.route_id {
        notes.push(note(
            "route.route_id",
            format!("{:?}: QGC has no route ID: not written", id.as_str()),
        ));
    }
    if mission.route.route_type.is_some() {
        notes.push(note(
            "route.route_type",
            "QGC has no route type: not written",
        ));
    }

    let mut items: Vec<Value> = Vec::new();
    let mut jump_id = 0u32;
    let mut next_id = || {
        jump_id += 1;
        jump_id
    };
    let height = metres(mission.take_off_height());
    items.push(json!({
        "AMSLAltAboveTerrain": null,
        "Altitude": height,
        "AltitudeMode": 1,
        "autoContinue": true,
        "command": 22,
        "doJumpId": next_id(),
        "frame": 3,
        "params": [0, 0, 0, null, take_off_lat, take_off_lon, height],
        "type": "SimpleItem",
    }));
    let mut current = (planning_speed, None);
    for (k, record) in mission.waypoints.iter().enumerate() {
        let w = &record.waypoint;
        let path = format!("waypoints[{k}] (number {})", w.waypoint_number);
        let speed = (w.speed.mps(), w.speed_type);
        if speed != current {
            let kind = match w.speed_type {
                Some(SpeedType::GroundSpeed) => 1,
                Some(SpeedType::IndicatedAirspeed) => 0,
                Some(SpeedType::TrueAirspeed) => {
                    notes.push(note(
                        &path,
                        "true airspeed written as airspeed (DO_CHANGE_SPEED type 0), which \
                         reads back as indicated airspeed",
                    ));
                    0
                }
                None => {
                    notes.push(note(
                        &path,
                        "no speed type after a typed speed: written as airspeed",
                    ));
                    0
                }
            };
            items.push(json!({
                "autoContinue": true,
                "command": 178,
                "doJumpId": next_id(),
                "frame": 2,
                "params": [kind, w.speed.mps(), -1, 0, 0, 0, 0],
                "type": "SimpleItem",
            }));
            current = speed;
        }
        let (frame, mode) = match w.altitude_type {
            Some(AltitudeType::Agl) => (3, 1),
            Some(AltitudeType::Wgs84) => (0, 2),
            other => {
                notes.push(note(
                    &path,
                    format!(
                        "altitude type {}: written as AMSL (frame 0)",
                        match other {
                            Some(AltitudeType::Pressure) => "pressure",
                            Some(AltitudeType::Baro) => "baro",
                            _ => "absent",
                        }
                    ),
                ));
                (0, 2)
            }
        };
        if w.leg_type == LegType::RadiusToFix {
            notes.push(note(
                &path,
                "radius-to-fix leg: QGC has none, written as a track-to-fix waypoint (the RF \
                 centre is not written)",
            ));
        }
        if w.turn_type == TurnType::FlyOver {
            notes.push(note(
                &path,
                "fly-over: QGC has no fly-over turn without a hold time: written as fly-by",
            ));
        }
        let alt = metres(w.altitude);
        items.push(json!({
            "AMSLAltAboveTerrain": null,
            "Altitude": alt,
            "AltitudeMode": mode,
            "autoContinue": true,
            "command": 16,
            "doJumpId": next_id(),
            "frame": frame,
            "params": [0, 0, 0, null, degrees(w.latitude), degrees(w.longitude), alt],
            "type": "SimpleItem",
        }));
    }
    if let Some(last) = mission.waypoints.last() {
        let w = &last.waypoint;
        items.push(json!({
            "AMSLAltAboveTerrain": null,
            "Altitude": 0,
            "AltitudeMode": 1,
            "autoContinue": true,
            "command": 21,
            "doJumpId": next_id(),
            "frame": 3,
            "params": [0, 0, 0, null, degrees(w.latitude), degrees(w.longitude), 0],
            "type": "SimpleItem",
        }));
    }

    let safety_offset = plan.areas.safety_offset.metres();
    if safety_offset > 0.0 {
        notes.push(note(
            "safety_offset_m",
            format!("{safety_offset} m: QGC has no safety offset: not written"),
        ));
    }
    let mut polygons = Vec::new();
    let mut circles = Vec::new();
    for (k, area) in plan.areas.areas.iter().enumerate() {
        if area.lower_altitude.is_some()
            || area.upper_altitude.is_some()
            || area.altitude_type.is_some()
        {
            notes.push(note(
                format!("areas[{k}] (area ID {})", area.area_id),
                "QGC's geofence has no altitude bounds: not written",
            ));
        }
        let inclusion = area.area_type == AreaType::FlyZone;
        match &area.shape {
            AreaShape::Polygon(vertices) => {
                let vertices: Vec<Value> = vertices
                    .iter()
                    .map(|p| json!([degrees(p.latitude), degrees(p.longitude)]))
                    .collect();
                polygons.push(json!({
                    "inclusion": inclusion,
                    "polygon": vertices,
                    "version": 1,
                }));
            }
            AreaShape::Circle { centre, border } => circles.push(json!({
                "circle": {
                    "center": [degrees(centre.latitude), degrees(centre.longitude)],
                    "radius": radius_mm(*centre, *border),
                },
                "inclusion": inclusion,
                "version": 1,
            })),
        }
    }

    let document = json!({
        "fileType": "Plan",
        "geoFence": {
            "circles": circles,
            "polygons": polygons,
            "version": 2,
        },
        "groundStation": "missionlink",
        "mission": {
            "cruiseSpeed": planning_speed,
            "firmwareType": options.firmware_type,
            "globalPlanAltitudeMode": 1,
            "hoverSpeed": planning_speed,
            "items": items,
            "plannedHomePosition": [home.latitude_deg, home.longitude_deg, home.altitude_m],
            "vehicleType": options.vehicle_type,
            "version": 2,
        },
        "rallyPoints": {
            "points": [],
            "version": 2,
        },
        "version": 1,
    });
    (pretty(&document), notes)
}

/// JSON indented by four spaces, as QGC writes it, with a final newline.
pub(crate) fn pretty(value: &Value) -> String {
    let mut out = Vec::new();
    let formatter = serde_json::ser::PrettyFormatter::with_indent(b"    ");
    let mut serializer = serde_json::Serializer::with_formatter(&mut out, formatter);
    // Writing a Value into a Vec cannot fail.
    let _ = serde::Serialize::serialize(value, &mut serializer);
    let mut text = String::from_utf8(out).unwrap_or_default();
    text.push('\n');
    text
}

// ---- Names ----

fn command_name(command: u64) -> &'static str {
    match command {
        16 => "NAV_WAYPOINT",
        17 => "NAV_LOITER_UNLIM",
        18 => "NAV_LOITER_TURNS",
        19 => "NAV_LOITER_TIME",
        20 => "NAV_RETURN_TO_LAUNCH",
        21 => "NAV_LAND",
        22 => "NAV_TAKEOFF",
        30 => "NAV_CONTINUE_AND_CHANGE_ALT",
        31 => "NAV_LOITER_TO_ALT",
        82 => "NAV_SPLINE_WAYPOINT",
        84 => "NAV_VTOL_TAKEOFF",
        85 => "NAV_VTOL_LAND",
        93 => "NAV_DELAY",
        112 => "CONDITION_DELAY",
        114 => "CONDITION_DISTANCE",
        115 => "CONDITION_YAW",
        177 => "DO_JUMP",
        178 => "DO_CHANGE_SPEED",
        179 => "DO_SET_HOME",
        183 => "DO_SET_SERVO",
        189 => "DO_LAND_START",
        195 => "DO_SET_ROI_LOCATION",
        197 => "DO_SET_ROI_NONE",
        201 => "DO_SET_ROI",
        203 => "DO_DIGICAM_CONTROL",
        205 => "DO_MOUNT_CONTROL",
        206 => "DO_SET_CAM_TRIGG_DIST",
        530 => "SET_CAMERA_MODE",
        2000 => "IMAGE_START_CAPTURE",
        2001 => "IMAGE_STOP_CAPTURE",
        2500 => "VIDEO_START_CAPTURE",
        2501 => "VIDEO_STOP_CAPTURE",
        3000 => "DO_VTOL_TRANSITION",
        _ => "unknown command",
    }
}

fn frame_name(frame: u64) -> &'static str {
    match frame {
        0 => "GLOBAL",
        1 => "LOCAL_NED",
        2 => "MISSION",
        3 => "GLOBAL_RELATIVE_ALT",
        4 => "LOCAL_ENU",
        5 => "GLOBAL_INT",
        6 => "GLOBAL_RELATIVE_ALT_INT",
        7 => "LOCAL_OFFSET_NED",
        10 => "GLOBAL_TERRAIN_ALT",
        11 => "GLOBAL_TERRAIN_ALT_INT",
        _ => "unknown frame",
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use missionlink_services::geofence::earth;
    use missionlink_services::transfer::mission::Mission;

    use crate::mission_file::tests::{MISSION_2, validated};

    /// A real file saved by QGroundControl, kept in the repository (`missions/qgc/`, copied
    /// from the shared mission documents).
    fn real(name: &str) -> String {
        let path = format!("{}/../missions/qgc/{name}", env!("CARGO_MANIFEST_DIR"));
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
    }

    fn assembled(plan: &MissionPlan) -> Mission {
        plan.mission
            .assemble(Some(plan.mission.len() as u16), None)
            .unwrap()
    }

    fn lines(dropped: &[Dropped]) -> Vec<String> {
        dropped.iter().map(ToString::to_string).collect()
    }

    /// The options that drop what the ICD cannot carry.
    fn dropping() -> ImportOptions {
        ImportOptions {
            unsupported: Unsupported::Drop,
            ..ImportOptions::default()
        }
    }

    /// The elements a refused import names.
    fn refused(result: Result<QgcImport, MissionFileError>) -> Vec<String> {
        match result {
            Err(MissionFileError::Unsupported { elements }) => lines(&elements),
            Err(other) => panic!("refused for another reason: {other}"),
            Ok(i) => panic!("imported, dropping {:?}", i.dropped),
        }
    }

    fn pos(lat: f64, lon: f64) -> GeoPoint {
        GeoPoint::from_degrees(lat, lon).unwrap()
    }

    /// (latitude, longitude, altitude, altitude type, speed, speed type, turn type) of each
    /// waypoint in flight order.
    type Row = (
        GeoPoint,
        f64,
        AltitudeType,
        f64,
        Option<SpeedType>,
        TurnType,
    );

    fn rows(m: &Mission) -> Vec<Row> {
        m.waypoints
            .iter()
            .map(|r| {
                let w = r.waypoint;
                (
                    GeoPoint {
                        latitude: w.latitude,
                        longitude: w.longitude,
                    },
                    w.altitude.metres(),
                    w.altitude_type.unwrap(),
                    w.speed.mps(),
                    w.speed_type,
                    w.turn_type,
                )
            })
            .collect()
    }

    /// `m`'s waypoints are `expected`, altitudes within [`close`].
    fn assert_rows(m: &Mission, expected: &[Row]) {
        let got = rows(m);
        assert_eq!(got.len(), expected.len());
        for (g, e) in got.iter().zip(expected) {
            assert!(close(g.1, e.1), "{g:?} {e:?}");
            assert_eq!((g.0, g.2, g.3, g.4, g.5), (e.0, e.2, e.3, e.4, e.5));
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 0.011
    }

    #[test]
    fn ardu_plane_is_refused_for_its_loiters_or_imported_without_them() {
        let text = real("PX4SITL-ArduPlane.plan");
        let expected = [
            "mission.items[3]: command 18 (NAV_LOITER_TURNS) is not supported",
            "mission.items[5]: command 31 (NAV_LOITER_TO_ALT) is not supported",
        ];
        assert_eq!(
            refused(import_plan(&text, &ImportOptions::default())),
            expected
        );
        let import = import_plan(&text, &dropping()).unwrap();
        assert_eq!(lines(&import.dropped), expected);
        assert_eq!(
            import.home,
            Some(Home {
                latitude_deg: 47.397,
                longitude_deg: 8.5455,
                altitude_m: 488.056
            })
        );
        // The take-off item's own position (300 m south of the planned home) is the take-off
        // position: it is carried, not dropped.
        assert_eq!(import.plan.take_off_position, Some(pos(47.3996949, 8.5455)));
        assert!(import.plan.areas.is_empty());
        assert_eq!(import.plan.safety_offset, SafetyOffset::default());

        let m = assembled(&import.plan);
        assert_eq!(m.take_off_height().metres(), 50.0);
        assert!(!m.route.bidirectional);
        assert_eq!(m.route.initial_waypoint, 1);
        let numbers: Vec<(u16, u16)> = m
            .waypoints
            .iter()
            .map(|r| (r.waypoint.waypoint_number, r.waypoint.next_waypoint))
            .collect();
        assert_eq!(numbers, [(1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 0)]);
        use AltitudeType::{Agl, Wgs84};
        use TurnType::{FlyBy, FlyOver};
        let ground = Some(SpeedType::GroundSpeed);
        let expected: Vec<Row> = vec![
            (pos(47.4104747, 8.565406), 120.0, Agl, 15.0, None, FlyBy),
            (pos(47.397, 8.585312), 688.06, Wgs84, 15.0, None, FlyBy),
            // Frame 10, above terrain.
            (pos(47.3700507, 8.5455), 100.0, Agl, 15.0, None, FlyBy),
            // After DO_CHANGE_SPEED (items[6]): 18 m/s ground speed.
            (pos(47.397, 8.505688), 60.0, Agl, 18.0, ground, FlyBy),
            (pos(47.4194578, 8.5189587), 40.0, Agl, 18.0, ground, FlyBy),
            // The land (items[9]) at the altitude of the waypoint before.
            (pos(47.3943051, 8.5455), 40.0, Agl, 18.0, ground, FlyOver),
        ];
        assert_rows(&m, &expected);
        assert!(
            m.waypoints
                .iter()
                .all(|r| r.waypoint.leg_type == LegType::TrackToFix)
        );
    }

    #[test]
    fn multi_rotor_imports_with_hover_speed_and_terrain_altitudes() {
        let import = import_plan(
            &real("PX4SITL-PX4-MultiRotor.plan"),
            &ImportOptions {
                safety_offset_m: 20.0,
                bidirectional: true,
                unsupported: Unsupported::Drop,
            },
        )
        .unwrap();
        assert_eq!(
            lines(&import.dropped),
            [
                "mission.items[4]: command 195 (DO_SET_ROI_LOCATION) is not supported",
                "mission.items[6]: command 19 (NAV_LOITER_TIME) is not supported",
            ]
        );
        assert_eq!(import.plan.take_off_position, Some(pos(47.3996949, 8.5455)));
        assert_eq!(import.plan.safety_offset.metres(), 20.0);
        let m = assembled(&import.plan);
        assert!(m.route.bidirectional);
        assert_eq!(m.take_off_height().metres(), 30.0);
        use AltitudeType::{Agl, Wgs84};
        use TurnType::{FlyBy, FlyOver};
        let ground = Some(SpeedType::GroundSpeed);
        let expected: Vec<Row> = vec![
            // Multi-rotor (vehicleType 2): hoverSpeed 5 m/s until the speed change.
            (pos(47.4104747, 8.565406), 60.0, Agl, 5.0, None, FlyBy),
            (pos(47.397, 8.585312), 638.06, Wgs84, 10.0, ground, FlyBy),
            // AltitudeMode 3 without terrain data: Altitude above terrain.
            (pos(47.3700507, 8.585312), 80.0, Agl, 10.0, ground, FlyBy),
            (pos(47.3700507, 8.505688), 40.0, Agl, 10.0, ground, FlyBy),
            (pos(47.397, 8.505688), 70.0, Agl, 10.0, ground, FlyBy),
            (pos(47.4194578, 8.5189587), 15.0, Agl, 10.0, ground, FlyBy),
            (pos(47.3996949, 8.5455), 15.0, Agl, 10.0, ground, FlyOver),
        ];
        assert_rows(&m, &expected);
    }

    #[test]
    fn a_geofence_file_imports_as_areas_but_is_no_mission() {
        let text = real("ce_geofence_home_base.plan");
        let err = import_plan(&text, &ImportOptions::default()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "mission.items: no waypoints: none of the 0 mission items is a waypoint (command 16) \
             or a land (21); a file that holds only a geofence imports as areas"
        );
        let (areas, dropped) = import_areas(&text, Unsupported::Refuse).unwrap();
        assert!(dropped.is_empty(), "{dropped:?}");
        let list = areas.assemble(2, SafetyOffset::default()).unwrap();
        let [fly, no_fly] = list.areas.as_slice() else {
            panic!("{list:?}")
        };
        assert_eq!((fly.area_id, fly.area_type), (1, AreaType::FlyZone));
        assert_eq!((no_fly.area_id, no_fly.area_type), (2, AreaType::NoFlyZone));
        let (AreaShape::Polygon(f), AreaShape::Polygon(n)) = (&fly.shape, &no_fly.shape) else {
            panic!("{list:?}")
        };
        assert_eq!((f.len(), n.len()), (4, 4));
        assert_eq!(f[0], pos(38.7507608625056, -77.49735908548331));
        assert_eq!(f[3], pos(38.750551952470936, -77.49713235890398));
        assert_eq!(n[2], pos(38.7508358, -77.496979));
    }

    #[test]
    fn export_then_import_gives_back_waypoints_and_areas() {
        let original = validated(MISSION_2);
        let home = Home {
            latitude_deg: 48.2748,
            longitude_deg: 11.6449,
            altitude_m: 510.5,
        };
        let take_off = pos(48.275, 11.645);
        let options = ExportOptions {
            take_off_position: Some(take_off),
            home: Some(home),
            ..ExportOptions::default()
        };
        let (text, notes) = export_plan(&original, &options);
        assert!(
            text.starts_with("{\n    \"fileType\": \"Plan\",\n"),
            "{text}"
        );
        assert!(text.contains("\"groundStation\": \"missionlink\""));
        let lost: Vec<String> = notes.iter().map(ToString::to_string).collect();
        assert_eq!(
            lost,
            [
                "route.bidirectional: QGC has no bidirectional route (return-to-home flying it \
                 backwards): not written",
                "mission_id: \"MEDEVAC-2\": QGC has no mission ID: not written",
                "route.route_type: QGC has no route type: not written",
                "waypoints[2] (number 3): radius-to-fix leg: QGC has none, written as a \
                 track-to-fix waypoint (the RF centre is not written)",
                "safety_offset_m: 25 m: QGC has no safety offset: not written",
            ]
        );

        let import = import_plan(
            &text,
            &ImportOptions {
                safety_offset_m: 25.0,
                bidirectional: true,
                unsupported: Unsupported::Refuse,
            },
        )
        .unwrap();
        assert!(import.dropped.is_empty(), "{:#?}", import.dropped);
        assert_eq!(import.home, Some(home));
        // The take-off item is at the take-off position, the planned home apart from it.
        assert_eq!(import.plan.take_off_position, Some(take_off));
        let m = assembled(&import.plan);
        assert_eq!(m.take_off_height(), original.mission.take_off_height());
        assert_eq!(m.waypoints.len(), original.mission.waypoints.len());
        for (a, b) in m.waypoints.iter().zip(&original.mission.waypoints) {
            let (a, b) = (a.waypoint, b.waypoint);
            assert_eq!(
                (a.waypoint_number, a.next_waypoint, a.latitude, a.longitude),
                (b.waypoint_number, b.next_waypoint, b.latitude, b.longitude)
            );
            assert_eq!((a.altitude, a.altitude_type), (b.altitude, b.altitude_type));
            assert_eq!(
                (a.speed, a.speed_type, a.turn_type),
                (b.speed, b.speed_type, b.turn_type)
            );
        }
        let areas = import
            .plan
            .areas
            .assemble(import.plan.areas.len() as u8, import.plan.safety_offset)
            .unwrap();
        assert_eq!(areas.safety_offset, original.areas.safety_offset);
        // QGC keeps polygons and circles apart: the import numbers the fly-zone, then the
        // exclusion polygons, then the circles (demo mission 2 has the circle before the
        // polygon).
        let mut expected = original.areas.areas.clone();
        expected.sort_by_key(|a| {
            (
                a.area_type != AreaType::FlyZone,
                matches!(a.shape, AreaShape::Circle { .. }),
            )
        });
        for (k, a) in expected.iter_mut().enumerate() {
            a.area_id = k as u16 + 1;
        }
        assert_same_areas(&areas.areas, &expected);

        // Exported twice, the same text: the export is a function of the plan.
        assert_eq!(export_plan(&original, &options).0, text);
    }

    /// Same IDs, types and polygons; circles with the same centre and radius (the border point
    /// is placed due north again).
    pub(crate) fn assert_same_areas(a: &[AreaPolygonLoopSegment], b: &[AreaPolygonLoopSegment]) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert_eq!((x.area_id, x.area_type), (y.area_id, y.area_type));
            match (&x.shape, &y.shape) {
                (AreaShape::Polygon(p), AreaShape::Polygon(q)) => assert_eq!(p, q),
                (
                    AreaShape::Circle { centre, border },
                    AreaShape::Circle {
                        centre: c,
                        border: b,
                    },
                ) => {
                    assert_eq!(centre, c);
                    let (r1, r2) = (
                        earth::distance_m(*centre, *border),
                        earth::distance_m(*c, *b),
                    );
                    assert!((r1 - r2).abs() < 0.02, "{r1} {r2}");
                }
                other => panic!("{other:?}"),
            }
        }
    }

    /// A small `.plan` with the given items and fence.
    fn plan_with(items: &str, fence: &str) -> String {
        format!(
            r#"{{"fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
  "geoFence": {{ {fence} }},
  "mission": {{"cruiseSpeed": 15, "hoverSpeed": 5, "vehicleType": 1, "firmwareType": 12,
    "plannedHomePosition": [47.397, 8.5455, 488],
    "items": [
{items}
    ]}},
  "rallyPoints": {{"points": [[47.39, 8.54, 500]], "version": 2}}}}"#
        )
    }

    const WAYPOINT: &str = r#"{"type": "SimpleItem", "command": 16, "frame": 3,
        "params": [0, 0, 0, null, 47.41, 8.56, 100]}"#;

    const TAKE_OFF: &str = r#"{"type": "SimpleItem", "command": 22, "frame": 3,
        "params": [0, 0, 0, null, 0, 0, 30]}"#;

    /// A fence of `polygons` and `circles` (JSON objects).
    fn fence(polygons: &[String], circles: &[String]) -> String {
        format!(
            r#""version": 2, "polygons": [{}], "circles": [{}]"#,
            polygons.join(", "),
            circles.join(", ")
        )
    }

    fn polygon(inclusion: bool, vertices: &[(f64, f64)]) -> String {
        let v: Vec<String> = vertices
            .iter()
            .map(|(lat, lon)| format!("[{lat}, {lon}]"))
            .collect();
        format!(
            r#"{{"inclusion": {inclusion}, "polygon": [{}], "version": 1}}"#,
            v.join(", ")
        )
    }

    fn circle(inclusion: bool, (lat, lon): (f64, f64), radius: f64) -> String {
        format!(
            r#"{{"inclusion": {inclusion}, "circle": {{"center": [{lat}, {lon}], "radius": {radius}}}, "version": 1}}"#
        )
    }

    /// A small square with its south-west corner at (`lat`, `lon`).
    fn square(lat: f64, lon: f64) -> Vec<(f64, f64)> {
        vec![
            (lat, lon),
            (lat, lon + 0.001),
            (lat + 0.001, lon + 0.001),
            (lat + 0.001, lon),
        ]
    }

    #[test]
    fn everything_the_icd_cannot_carry_refuses_the_file_or_is_dropped() {
        let items = format!(
            r#"{TAKE_OFF},
        {WAYPOINT},
        {{"type": "ComplexItem", "complexItemType": "survey"}},
        {{"type": "SimpleItem", "command": 16, "frame": 3, "params": [5, 0, 0, null, 47.42, 8.56, 100]}},
        {{"type": "SimpleItem", "command": 20, "frame": 2, "params": [0, 0, 0, 0, 0, 0, 0]}},
        {{"type": "SimpleItem", "command": 16, "frame": 1, "params": [0, 0, 0, null, 47.43, 8.56, 100]}},
        {{"type": "SimpleItem", "command": 178, "frame": 2, "params": [2, 3, -1, 0, 0, 0, 0]}},
        {{"type": "SimpleItem", "command": 21, "frame": 3, "params": [0, 0, 0, null, 47.42, 8.56, 0]}},
        {WAYPOINT}"#
        );
        let fence = fence(
            &[polygon(
                false,
                &[(47.41, 8.56), (47.41, 8.57), (47.42, 8.57)],
            )],
            &[
                circle(true, (47.40, 8.55), 5000.0),
                circle(false, (47.41, 8.55), 200.0),
            ],
        );
        let text = plan_with(&items, &fence);
        let expected = [
            "mission.items[2]: complex item \"survey\" is not supported (only take-off, \
             waypoint, land and speed change)",
            "mission.items[3].params[0]: hold 5 s is not supported (the ICD has no hold \
             time); dropped, the waypoint is fly-over",
            "mission.items[4]: command 20 (NAV_RETURN_TO_LAUNCH) is not supported",
            "mission.items[5].frame: command 16 (NAV_WAYPOINT) in frame 1 (LOCAL_NED) is \
             not supported: only global (0, 5), relative (3, 6) and terrain (10, 11) frames",
            "mission.items[6].params[0]: speed type 2 (2 climb, 3 descent speed) is not \
             supported: only airspeed (0) and ground speed (1)",
            "mission.items[8]: after the land (mission.items[7]): the route ends at the land",
            "geoFence.circles[0]: an inclusion circle: the ICD's fly-zone is a polygon (draw \
             it as an inclusion polygon)",
            "rallyPoints.points[0]: a rally point is not supported (the ICD has none)",
        ];
        // Refused by default, every element named; the error says how many.
        let err = import_plan(&text, &ImportOptions::default()).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("not imported: 8 elements the ICD cannot carry"),
            "{err}"
        );
        assert_eq!(refused(Err(err)), expected);

        // Dropped on request: the plan is what remains.
        let import = import_plan(&text, &dropping()).unwrap();
        assert_eq!(lines(&import.dropped), expected);
        // Two waypoints: the land is at the second one, fly-over by its hold.
        let m = assembled(&import.plan);
        assert_eq!(m.take_off_height().metres(), 30.0);
        assert_eq!(
            rows(&m).iter().map(|r| (r.0, r.5)).collect::<Vec<_>>(),
            [
                (pos(47.41, 8.56), TurnType::FlyBy),
                (pos(47.42, 8.56), TurnType::FlyOver)
            ]
        );
        // The take-off item has no position (0, 0): the planned home is the take-off position.
        assert_eq!(import.plan.take_off_position, Some(pos(47.397, 8.5455)));
        // The inclusion circle is not approximated: no fly-zone is left, which validation
        // names.
        let list = import.plan.areas.unchecked(SafetyOffset::default());
        let kinds: Vec<(u16, AreaType, bool)> = list
            .areas
            .iter()
            .map(|a| {
                (
                    a.area_id,
                    a.area_type,
                    matches!(a.shape, AreaShape::Circle { .. }),
                )
            })
            .collect();
        assert_eq!(
            kinds,
            [
                (1, AreaType::NoFlyZone, false),
                (2, AreaType::NoFlyZone, true)
            ]
        );
        let AreaShape::Circle { border, .. } = list.areas[1].shape else {
            panic!()
        };
        assert!((earth::distance_m(pos(47.41, 8.55), border) - 200.0).abs() < 0.01);
    }

    #[test]
    fn a_second_fly_zone_is_refused_or_dropped() {
        let big = [(47.3, 8.4), (47.3, 8.7), (47.5, 8.7), (47.5, 8.4)];
        let text = plan_with(
            WAYPOINT,
            &fence(
                &[
                    polygon(true, &big),
                    polygon(true, &[(47.3, 8.4), (47.3, 8.5), (47.4, 8.5)]),
                ],
                &[circle(true, (47.4, 8.5), 100.0)],
            ),
        );
        let expected = [
            "geoFence.polygons[1]: a second inclusion polygon: the ICD has one fly-zone \
             (geoFence.polygons[0])",
            "geoFence.circles[0]: an inclusion circle: the ICD has one fly-zone \
             (geoFence.polygons[0]), and it is a polygon",
        ];
        match import_areas(&text, Unsupported::Refuse) {
            Err(MissionFileError::Unsupported { elements }) => {
                assert_eq!(lines(&elements), expected);
            }
            other => panic!("{other:?}"),
        }
        let (areas, dropped) = import_areas(&text, Unsupported::Drop).unwrap();
        assert_eq!(lines(&dropped), expected, "rally points are no areas");
        assert_eq!(areas.len(), 1);
    }

    #[test]
    fn an_eleventh_no_fly_zone_is_refused_or_dropped() {
        let fly = [(47.3, 8.4), (47.3, 8.7), (47.5, 8.7), (47.5, 8.4)];
        let mut polygons = vec![polygon(true, &fly)];
        // Ten exclusion polygons fill the FCC's area list with the fly-zone; the circle is
        // the eleventh no-fly-zone.
        for k in 0..10 {
            polygons.push(polygon(false, &square(47.35, 8.45 + 0.01 * f64::from(k))));
        }
        let text = plan_with(
            &format!("{TAKE_OFF},\n{WAYPOINT}"),
            &fence(&polygons, &[circle(false, (47.45, 8.6), 100.0)]),
        );
        let text = text.replace(r#""points": [[47.39, 8.54, 500]]"#, r#""points": []"#);
        let expected = [
            "geoFence.circles[0]: more than 10 no-fly-zones (polygons and circles): the FCC \
             holds 11 areas, one of them the fly-zone",
        ];
        assert_eq!(
            refused(import_plan(&text, &ImportOptions::default())),
            expected
        );
        let import = import_plan(&text, &dropping()).unwrap();
        assert_eq!(lines(&import.dropped), expected);
        let list = import
            .plan
            .areas
            .assemble(11, SafetyOffset::default())
            .unwrap();
        assert_eq!(list.areas.len(), 11);
        assert!(
            list.areas
                .iter()
                .all(|a| matches!(a.shape, AreaShape::Polygon(_)))
        );

        // Ten no-fly-zones fit exactly.
        let ten = text.replace(&circle(false, (47.45, 8.6), 100.0), "");
        let import = import_plan(&ten, &ImportOptions::default()).unwrap();
        assert_eq!(import.plan.areas.len(), 11);
    }

    #[test]
    fn a_polygon_of_more_than_60_vertices_is_refused_or_dropped() {
        let ring: Vec<(f64, f64)> = (0..61)
            .map(|k| {
                let a = f64::from(k) * core::f64::consts::TAU / 61.0;
                (47.4 + 0.01 * a.cos(), 8.5 + 0.01 * a.sin())
            })
            .collect();
        let text = plan_with(WAYPOINT, &fence(&[polygon(false, &ring)], &[]));
        let expected = ["geoFence.polygons[0]: 61 vertices, at most 60 fit a #2012"];
        match import_areas(&text, Unsupported::Refuse) {
            Err(MissionFileError::Unsupported { elements }) => {
                assert_eq!(lines(&elements), expected);
            }
            other => panic!("{other:?}"),
        }
        let (areas, dropped) = import_areas(&text, Unsupported::Drop).unwrap();
        assert_eq!(lines(&dropped), expected);
        assert!(areas.is_empty());
    }

    #[test]
    fn the_take_off_position_is_the_take_off_items_else_the_planned_home() {
        let take_off = |lat: &str, lon: &str| {
            format!(
                r#"{{"type": "SimpleItem", "command": 84, "frame": 3,
                "params": [0, 0, 0, null, {lat}, {lon}, 25]}},
                {WAYPOINT}"#
            )
        };
        let import = |text: &str| {
            let text = text.replace(r#""points": [[47.39, 8.54, 500]]"#, r#""points": []"#);
            import_plan(&text, &ImportOptions::default()).unwrap()
        };
        // VTOL take-off with its own position.
        let own = import(&plan_with(&take_off("47.398", "8.546"), ""));
        assert_eq!(own.plan.take_off_position, Some(pos(47.398, 8.546)));
        assert_eq!(assembled(&own.plan).take_off_height().metres(), 25.0);
        // No position (0, 0 or null): the planned home.
        for (lat, lon) in [("0", "0"), ("null", "null")] {
            let home = import(&plan_with(&take_off(lat, lon), ""));
            assert_eq!(home.plan.take_off_position, Some(pos(47.397, 8.5455)));
        }
        // Neither: none, which validation refuses.
        let none = import(
            &plan_with(&take_off("0", "0"), "")
                .replace(r#""plannedHomePosition": [47.397, 8.5455, 488],"#, ""),
        );
        assert_eq!(none.plan.take_off_position, None);
        assert_eq!(none.home, None);
        // A planned home of (0, 0) is QGC's "not set".
        let unset = import(
            &plan_with(&take_off("0", "0"), "").replace("[47.397, 8.5455, 488]", "[0, 0, 0]"),
        );
        assert_eq!(unset.plan.take_off_position, None);
    }

    /// Found by fuzz_qgc_plan and fuzz_geojson: an empty file was "line 1, column 0".
    #[test]
    fn an_early_end_is_at_column_1() {
        for (text, line) in [("", 1), ("{\"fileType\": \"Plan\",\n", 2)] {
            match import_plan(text, &ImportOptions::default()).unwrap_err() {
                MissionFileError::Syntax {
                    line: l, column, ..
                } => assert_eq!((l, column), (line, 1), "{text:?}"),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn bad_files_name_the_position() {
        let err = import_plan(
            "{\"fileType\": \"Plan\",\n  \"mission\": [1,}",
            &ImportOptions::default(),
        )
        .unwrap_err();
        match err {
            MissionFileError::Syntax {
                line,
                column,
                message,
            } => {
                assert_eq!((line, column), (2, 17));
                assert_eq!(message, "expected value");
            }
            other => panic!("{other:?}"),
        }

        let with = |item: &str| {
            plan_with(&format!("{TAKE_OFF},\n{WAYPOINT},\n{item}"), "")
                .replace(r#""points": [[47.39, 8.54, 500]]"#, r#""points": []"#)
        };
        let cases: &[(&str, &str)] = &[
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 95, 8.5, 10]}"#,
                "mission.items[2].params[4]: latitude 95 deg is outside -90..=90",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 47.4, null, 10]}"#,
                "mission.items[2].params[5]: expected a number, found null",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 47.4, 8.5, "high"]}"#,
                "mission.items[2].params[6]: expected a number, found the string \"high\"",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 0, "params": [0, 0, 0, null, 47.4, 8.5, null]}"#,
                "mission.items[2].params[6]: expected a number, found null",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 47.4, 8.5, 10]}"#,
                "mission.items[2].params: 5 values, expected 7",
            ),
            (
                r#"{"type": "Simple", "command": 16}"#,
                "mission.items[2].type: \"Simple\" is not \"SimpleItem\" or \"ComplexItem\"",
            ),
            (
                r#"{"type": "SimpleItem", "frame": 3, "params": []}"#,
                "mission.items[2].command: missing",
            ),
            (
                r#"{"type": "SimpleItem", "command": 178, "frame": 2, "params": [1, 0.2, -1, 0, 0, 0, 0]}"#,
                "mission.items[2].params[1]: 0.2 m/s is 0 on the wire (steps of 0.5 m/s); the \
                 speed must be above 0",
            ),
            (
                r#"{"type": "SimpleItem", "command": 22, "frame": 0, "params": [0, 0, 0, null, 0, 0, 400]}"#,
                "not imported: 1 element the ICD cannot carry or the FCC cannot hold; \
                 mission.items[2]: command 22 (NAV_TAKEOFF): a second take-off (the first is \
                 mission.items[0])",
            ),
            (
                r#"{"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 47.4, 181, 40]}"#,
                "not imported: 1 element the ICD cannot carry or the FCC cannot hold; \
                 mission.items[2]: command 22 (NAV_TAKEOFF): a second take-off (the first is \
                 mission.items[0])",
            ),
        ];
        for (item, expected) in cases {
            let got = import_plan(&with(item), &ImportOptions::default())
                .map(|i| i.dropped)
                .unwrap_err();
            assert_eq!(&got.to_string(), expected);
        }

        // A take-off after the waypoints: no take-off before the route, which is no mission.
        let late = plan_with(
            &format!(
                r#"{WAYPOINT},
{{"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 0, 0, 40]}}"#
            ),
            "",
        );
        assert_eq!(
            import_plan(&late, &dropping()).unwrap_err().to_string(),
            "mission.items[1]: command 22 (NAV_TAKEOFF): a take-off after waypoints is not \
             supported (the ICD's take-off comes before the route)"
        );
        // No take-off at all.
        assert_eq!(
            import_plan(&plan_with(WAYPOINT, ""), &dropping())
                .unwrap_err()
                .to_string(),
            "mission.items: no take-off (command 22 or 84): the ICD's mission needs its \
             take-off height"
        );
        // A take-off position outside the world.
        let far = plan_with(
            r#"{"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 47.4, 181, 40]}"#,
            "",
        );
        assert_eq!(
            import_plan(&far, &dropping()).unwrap_err().to_string(),
            "mission.items[0].params[5]: longitude 181 deg is outside -180..=180"
        );

        // A take-off below home, in AMSL.
        let below = plan_with(
            &format!(
                r#"{{"type": "SimpleItem", "command": 22, "frame": 0, "params": [0, 0, 0, null, 0, 0, 400]}},
{WAYPOINT}"#
            ),
            "",
        );
        assert_eq!(
            import_plan(&below, &ImportOptions::default())
                .unwrap_err()
                .to_string(),
            "mission.items[0].params[6]: take-off height -88 m is below the ground at home"
        );
        let fence = plan_with(
            WAYPOINT,
            r#""polygons": [{"inclusion": false, "polygon": [[47.3, 8.4], [47.3], [47.5, 8.7]]}]"#,
        );
        assert_eq!(
            import_areas(&fence, Unsupported::Drop)
                .unwrap_err()
                .to_string(),
            "geoFence.polygons[0].polygon[1]: 1 values, expected [latitude, longitude]"
        );
        assert_eq!(
            import_areas("{\"fileType\": \"Mission\"}", Unsupported::Refuse)
                .unwrap_err()
                .to_string(),
            "fileType: \"Mission\": not a QGroundControl plan (\"Plan\")"
        );
        assert_eq!(
            import_areas("[]", Unsupported::Refuse)
                .unwrap_err()
                .to_string(),
            "(top level): expected an object, found an array"
        );
    }
}
