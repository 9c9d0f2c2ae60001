//! QGroundControl `.plan` files: import into a [`MissionPlan`] (waypoints and areas) and export of
//! a [`ValidatedPlan`]. A `.plan` file is JSON: `mission` (the items, the planned home position,
//! the planning speeds), `geoFence` (polygons and circles) and `rallyPoints`. What the ICD cannot
//! carry is never dropped silently: the import returns it as a list of [`Unsupported`] notes,
//! each with the JSON path of the item (e.g. `mission.items[4]`) and the reason; the caller (the
//! `gcs` tool) decides whether to refuse the file or to warn. A file that is not a `.plan` at all
//! or holds a value that cannot be read is an error ([`MissionFileError::Syntax`] with line and
//! column from the JSON parser, or [`MissionFileError::Field`] with the JSON path, e.g.
//! `mission.items[3].params[4]`).
//!
//! # Import: mission items
//!
//! Items are read in order; MAVLink command numbers (`MAV_CMD`) and frames (`MAV_FRAME`):
//!
//! - **Take-off** (22 `NAV_TAKEOFF`, 84 `NAV_VTOL_TAKEOFF`): its altitude gives the take-off
//!   height (#13006 type 1, above ground). In a relative or terrain frame the altitude is the
//!   height; in a global (AMSL) frame the height is the altitude less the planned home altitude.
//!   The ICD's take-off has a height only: a take-off position further than 1 m from the planned
//!   home is reported (the aircraft climbs where it stands). ArduPilot's minimum pitch (param 1)
//!   and the yaw are not carried. A second take-off, or one after a waypoint, is reported.
//! - **Waypoint** (16 `NAV_WAYPOINT`): a track-to-fix #13002. Waypoints are numbered 1..n in
//!   item order, each one's next is the following one and the last one's next is 0; the route
//!   (#13001) starts at waypoint 1 and is one-way unless [`ImportOptions::bidirectional`]. The
//!   turn is fly-by; a hold time above 0 (param 1) makes it fly-over, and the hold itself is
//!   reported (the ICD has no hold). The acceptance and pass radii and the yaw are not carried
//!   (PX4 and ArduPilot treat 0, the value QGC writes, as "the vehicle's default").
//! - **Land** (21 `NAV_LAND`, 85 `NAV_VTOL_LAND`): the land position is the last waypoint of the
//!   route, because the FCC lands at the last waypoint by itself (as demo mission 2 lands at
//!   ROLE2). When the waypoint before already lies at that position (the same wire value), it is
//!   the last waypoint and no waypoint is added; otherwise a fly-over waypoint is added at the
//!   land position, at the altitude (and altitude type) of the waypoint before: the approach
//!   altitude, the descent being the FCC's. The land altitude of the item is not used. Items
//!   after a land are reported (the route ends there).
//! - **Speed change** (178 `DO_CHANGE_SPEED`): applies to the waypoints that follow. Param 1
//!   is the speed type (0 airspeed -> indicated airspeed, 1 ground speed -> ground speed; 2 and 3,
//!   climb and descent speeds, are reported), param 2 the speed in m/s (-1: no change). The
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
//!   taken as AGL. Any other frame is reported and the item skipped.
//! - **Everything else** is reported with its index and skipped: other commands (loiters 17, 18,
//!   19, 31, return-to-launch 20, region of interest 195 and 201, camera, jumps, ...), complex
//!   items (surveys, corridor and structure scans, landing patterns) and rally points.
//!
//! A file without a waypoint or land item is an error ("no waypoints"); its geofence can still
//! be imported with [`import_areas`]. A file without a take-off is imported with a note: the
//! plan then has no take-off height and validation refuses it.
//!
//! The planned home position (`plannedHomePosition`, `[latitude, longitude, altitude AMSL]`) is
//! the reference of the take-off: the AMSL take-off altitudes are measured from it and the
//! take-off position is compared with it. It is not a waypoint (the ICD has no home position);
//! it is returned in [`QgcImport::home`] for an export to write back.
//!
//! # Import: geofence
//!
//! Inclusion polygons are the fly-zone (exactly one: a second one is reported and left out),
//! exclusion polygons and circles are no-fly-zones (a circle's border point is placed due north
//! of its centre at the radius, a geodesic on WGS-84). An inclusion circle is
//! not a fly-zone the ICD carries (a polygon): when there is no inclusion polygon it is
//! approximated by the inscribed polygon of 60 vertices (on the safe side: at most
//! `r (1 - cos 3°)`, 1.4 m per km of radius, inside the circle) and reported; otherwise it is
//! reported and left out. Area IDs are 1..n: the fly-zone first, then the exclusion polygons and
//! the exclusion circles in file order. QGC has no safety offset: it is
//! [`ImportOptions::safety_offset_m`] (0 by default). Polygons of more than 60 vertices and areas
//! beyond the eleven an area list holds are reported and left out. A file without a geofence
//! gives no areas (they may come from elsewhere, e.g. GeoJSON).
//!
//! # Export
//!
//! [`export_plan`] writes a `.plan` (`fileType` "Plan", version 1, `groundStation`
//! "missionlink") that QGC reads: a take-off at the home position with the take-off height
//! (frame 3), a `DO_CHANGE_SPEED` wherever the speed or its type changes (the first waypoint's
//! speed is also `cruiseSpeed` and `hoverSpeed`), every waypoint in flight-plan order (AGL in
//! frame 3, WGS-84 in frame 0), a land at the last waypoint, the planned home, the geofence (the
//! fly-zone an inclusion polygon, no-fly polygons exclusion polygons, no-fly circles exclusion
//! circles whose radius is the geodesic distance centre -> border point, to the millimetre)
//! and no rally points. What QGC cannot hold is returned as notes: radius-to-fix legs
//! (written as track-to-fix), fly-over turns, true airspeed (written as airspeed), pressure,
//! baro or absent altitude types (written as AMSL), the bidirectional route, mission and route
//! IDs, route type, the safety offset and area altitude bounds. The other optional #13002
//! fields (arrival time, activity ID, limits) are not written. Area IDs are not kept: QGC
//! holds polygons and circles in two lists, and an import numbers them as above.

use missionlink_interfaces::capacity::{MAX_AREAS, MAX_POLYGON_VERTICES, MAX_WAYPOINTS};
use missionlink_interfaces::wire::{
    Altitude, AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, LegType,
    PolygonVertices, SafetyOffset, SpecificData, Speed, SpeedType, Timestamp, TurnType,
    UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};
use missionlink_services::ground_station::{MissionPlan, ValidatedPlan};
use missionlink_services::transfer::areas::AreaBuffer;
use missionlink_services::transfer::mission::MissionBuffer;
use serde_json::{Map, Value, json};

use crate::mission_file::MissionFileError;
use crate::values::{
    altitude, border_due_north, degrees, field_error, latitude, longitude, metres, point, radius,
    radius_mm,
};
use missionlink_services::geofence::earth;

/// Something in a file that the ICD cannot carry, or carries only approximately: where (the
/// JSON path, e.g. `mission.items[4]`) and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unsupported {
    /// The JSON path of the item, e.g. `geoFence.circles[0]`.
    pub path: String,
    /// What is not carried, and what was done instead.
    pub reason: String,
}

impl core::fmt::Display for Unsupported {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {}", self.path, self.reason)
    }
}

/// Choices the `.plan` file cannot express.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImportOptions {
    /// The #2011 safety offset, metres (QGC has none).
    pub safety_offset_m: f64,
    /// Whether return-to-home may fly the route backwards (QGC has no such notion).
    pub bidirectional: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            safety_offset_m: 0.0,
            bidirectional: false,
        }
    }
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
    /// The mission plan: take-off height, waypoints, route and areas.
    pub plan: MissionPlan,
    /// The planned home position, if the file has one.
    pub home: Option<Home>,
    /// What the plan does not carry, in file order.
    pub notes: Vec<Unsupported>,
}

/// How [`export_plan`] fills what a [`ValidatedPlan`] does not hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExportOptions {
    /// The planned home position; `None`: the first waypoint's position at 0 m AMSL.
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
    let mut notes = Vec::new();
    let mission_buffer = import_items(&mission, home, options, &mut notes)?;
    let areas = import_fence(&at, &mut notes)?;
    if let Some(rally) = at.opt("rallyPoints") {
        if let Some(points) = rally.opt("points") {
            for p in points.items()? {
                notes.push(note(
                    &p.path,
                    "rally points are not supported (the ICD has none)",
                ));
            }
        }
    }
    let safety_offset = SafetyOffset::from_metres(options.safety_offset_m)
        .map_err(|e| field_error("safety_offset_m", e.to_string()))?;
    Ok(QgcImport {
        plan: MissionPlan {
            mission: mission_buffer,
            areas,
            safety_offset,
            mission_id: None,
            take_off_position: None,
        },
        home,
        notes,
    })
}

/// Imports only the geofence of a `.plan` file as areas (a file that holds only a fence, or the
/// areas of a mission planned elsewhere). The mission items are not looked at.
pub fn import_areas(text: &str) -> Result<(AreaBuffer, Vec<Unsupported>), MissionFileError> {
    let root = parse_json(text)?;
    let at = At::root(&root);
    check_file_type(&at)?;
    let mut notes = Vec::new();
    let areas = import_fence(&at, &mut notes)?;
    Ok((areas, notes))
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

fn import_items(
    mission: &At<'_>,
    home: Option<Home>,
    options: &ImportOptions,
    notes: &mut Vec<Unsupported>,
) -> Result<MissionBuffer, MissionFileError> {
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
    let mut take_off: Option<(Altitude, usize)> = None;
    let mut land: Option<usize> = None;
    let mut waypoints: Vec<Pending> = Vec::new();

    for (i, item) in items.iter().enumerate() {
        if let Some(j) = land {
            notes.push(note(
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
                notes.push(note(
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
                if let Some((_, first)) = take_off {
                    notes.push(note(
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
                    notes.push(note(
                        &item.path,
                        format!(
                            "command {command} ({}): a take-off after waypoints is not \
                             supported",
                            command_name(command)
                        ),
                    ));
                    continue;
                }
                let params = Params::of(item)?;
                let Some((value, kind)) = item_altitude(item, &params, command, notes)? else {
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
                if let (Some(home), Some(position)) = (home, params.position()?) {
                    let home_point = point(
                        "mission.plannedHomePosition",
                        home.latitude_deg,
                        home.longitude_deg,
                    )?;
                    let d = earth::distance_m(home_point, position);
                    if d > 1.0 {
                        notes.push(note(
                            &item.path,
                            format!(
                                "the take-off position ({}, {}) is {d:.0} m from the planned \
                                 home: the ICD's take-off has a height only, the aircraft \
                                 climbs where it stands",
                                degrees(position.latitude),
                                degrees(position.longitude)
                            ),
                        ));
                    }
                }
                take_off = Some((h, i));
            }
            16 => {
                let params = Params::of(item)?;
                let Some((value, kind)) = item_altitude(item, &params, command, notes)? else {
                    continue;
                };
                let Some(position) = params.position()? else {
                    return Err(params
                        .at(4)?
                        .error("a waypoint needs latitude and longitude"));
                };
                let hold = params.at(0)?.opt_number()?.unwrap_or(0.0);
                let turn_type = if hold > 0.0 {
                    notes.push(note(
                        &params.at(0)?.path,
                        format!(
                            "hold {hold} s is not carried (the ICD has no hold time): the \
                             waypoint is fly-over"
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
                        let Some((value, kind)) = item_altitude(item, &params, command, notes)?
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
                    notes.push(note(
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
            _ => notes.push(note(
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
    match take_off {
        Some((height, _)) => stored(
            buffer.store(
                &VehicleSpecificWaypoint {
                    time_stamp: Timestamp::default(),
                    data: SpecificData::TakeOffHeight { height },
                    activity_id: None,
                }
                .into(),
            ),
        )?,
        None => notes.push(note(
            &items_at.path,
            "no take-off (command 22 or 84): the plan has no take-off height, which \
             validation requires",
        )),
    }
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
    Ok(buffer)
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

/// The altitude of a take-off, waypoint or land and its type by the item's frame; `None` (and a
/// note) for a frame that is not supported.
fn item_altitude(
    item: &At<'_>,
    params: &Params<'_>,
    command: u64,
    notes: &mut Vec<Unsupported>,
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
            notes.push(note(
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

fn import_fence(
    root: &At<'_>,
    notes: &mut Vec<Unsupported>,
) -> Result<AreaBuffer, MissionFileError> {
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
            notes.push(note(
                &p.path,
                format!(
                    "{} vertices, at most {MAX_POLYGON_VERTICES} fit a #2012: left out",
                    vertices.len()
                ),
            ));
            continue;
        };
        let shape = AreaShape::Polygon(vertices);
        if !inclusion {
            no_fly.push((shape, p.path.clone()));
        } else if let Some((_, first)) = &fly_zone {
            notes.push(note(
                &p.path,
                format!("a second inclusion polygon: the ICD has one fly-zone ({first}): left out"),
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
        if !inclusion {
            let border = border_due_north(&radius_at.path, centre, radius)?;
            no_fly.push((AreaShape::Circle { centre, border }, c.path.clone()));
        } else if let Some((_, first)) = &fly_zone {
            notes.push(note(
                &c.path,
                format!(
                    "an inclusion circle: the ICD has one fly-zone ({first}) and it is a \
                     polygon: left out"
                ),
            ));
        } else {
            let polygon = inscribed_polygon(centre, radius)
                .ok_or_else(|| radius_at.error(format!("{radius} m: the circle is too large")))?;
            notes.push(note(
                &c.path,
                format!(
                    "an inclusion circle: the ICD's fly-zone is a polygon: approximated by the \
                     inscribed polygon of {MAX_POLYGON_VERTICES} vertices (at most {:.1} m \
                     inside the circle)",
                    radius * (1.0 - (core::f64::consts::PI / MAX_POLYGON_VERTICES as f64).cos())
                ),
            ));
            fly_zone = Some((AreaShape::Polygon(polygon), c.path.clone()));
        }
    }

    let mut buffer = AreaBuffer::new();
    let zones = fly_zone
        .into_iter()
        .map(|z| (AreaType::FlyZone, z))
        .chain(no_fly.into_iter().map(|z| (AreaType::NoFlyZone, z)));
    for (k, (area_type, (shape, path))) in zones.enumerate() {
        if k >= MAX_AREAS {
            notes.push(note(
                &path,
                format!("more than {MAX_AREAS} areas (the FCC's capacity): left out"),
            ));
            continue;
        }
        let area = AreaPolygonLoopSegment {
            time_stamp: Timestamp::default(),
            area_id: u16::try_from(k + 1).unwrap_or(u16::MAX),
            area_type,
            lower_altitude: None,
            upper_altitude: None,
            altitude_type: None,
            shape,
        };
        if buffer.store(&area).is_err() {
            notes.push(note(
                &path,
                format!("more than {MAX_AREAS} areas (the FCC's capacity): left out"),
            ));
        }
    }
    Ok(buffer)
}

/// The polygon of [`MAX_POLYGON_VERTICES`] vertices on the circle, from due north clockwise.
fn inscribed_polygon(centre: GeoPoint, radius: f64) -> Option<PolygonVertices> {
    let mut v = PolygonVertices::new();
    for k in 0..MAX_POLYGON_VERTICES {
        let bearing = 360.0 * k as f64 / MAX_POLYGON_VERTICES as f64;
        v.push(earth::geo_point(earth::destination(
            centre, bearing, radius,
        ))?)
        .ok()?;
    }
    Some(v)
}

// ---- Export ----

/// The `.plan` file of a validated plan and what it cannot hold (see the
/// [module documentation](self)).
pub fn export_plan(plan: &ValidatedPlan, options: &ExportOptions) -> (String, Vec<Unsupported>) {
    let mission = &plan.mission;
    let mut notes = Vec::new();
    let first = mission.waypoints.first().map(|r| r.waypoint);
    let home = options.home.unwrap_or_else(|| Home {
        latitude_deg: first.map_or(0.0, |w| degrees(w.latitude)),
        longitude_deg: first.map_or(0.0, |w| degrees(w.longitude)),
        altitude_m: 0.0,
    });
    let planning_speed = first.map_or(0.0, |w| w.speed.mps());

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
        "params": [0, 0, 0, null, home.latitude_deg, home.longitude_deg, height],
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

// ---- JSON with paths (shared with the GeoJSON module) ----

/// Parses JSON text; a syntax error carries the parser's line and column.
pub(crate) fn parse_json(text: &str) -> Result<Value, MissionFileError> {
    serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let message = match message.rfind(" at line ") {
            Some(k) => message.get(..k).unwrap_or(&message).to_owned(),
            None => message,
        };
        MissionFileError::Syntax {
            line: e.line(),
            column: e.column(),
            message,
        }
    })
}

/// A JSON value and its path from the top, e.g. `mission.items[3].params[4]`.
#[derive(Debug, Clone)]
pub(crate) struct At<'a> {
    pub(crate) value: &'a Value,
    pub(crate) path: String,
}

impl<'a> At<'a> {
    pub(crate) fn root(value: &'a Value) -> Self {
        Self {
            value,
            path: String::new(),
        }
    }

    fn child(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_owned()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The error `reason` at this value.
    pub(crate) fn error(&self, reason: impl Into<String>) -> MissionFileError {
        let path = if self.path.is_empty() {
            "(top level)".to_owned()
        } else {
            self.path.clone()
        };
        field_error(path, reason)
    }

    pub(crate) fn object(&self) -> Result<&'a Map<String, Value>, MissionFileError> {
        self.value
            .as_object()
            .ok_or_else(|| self.error(format!("expected an object, found {}", kind(self.value))))
    }

    /// The member `key`, which must be there.
    pub(crate) fn field(&self, key: &str) -> Result<At<'a>, MissionFileError> {
        match self.object()?.get(key) {
            Some(value) => Ok(At {
                value,
                path: self.child(key),
            }),
            None => Err(field_error(self.child(key), "missing")),
        }
    }

    /// The member `key`, if this is an object that has it.
    pub(crate) fn opt(&self, key: &str) -> Option<At<'a>> {
        self.value.as_object()?.get(key).map(|value| At {
            value,
            path: self.child(key),
        })
    }

    /// The elements of an array.
    pub(crate) fn items(&self) -> Result<Vec<At<'a>>, MissionFileError> {
        let array = self
            .value
            .as_array()
            .ok_or_else(|| self.error(format!("expected an array, found {}", kind(self.value))))?;
        Ok(array
            .iter()
            .enumerate()
            .map(|(i, value)| At {
                value,
                path: format!("{}[{i}]", self.path),
            })
            .collect())
    }

    pub(crate) fn number(&self) -> Result<f64, MissionFileError> {
        self.value
            .as_f64()
            .ok_or_else(|| self.error(format!("expected a number, found {}", kind(self.value))))
    }

    /// A number, or `None` for null (QGC writes NaN as null).
    pub(crate) fn opt_number(&self) -> Result<Option<f64>, MissionFileError> {
        if self.value.is_null() {
            Ok(None)
        } else {
            self.number().map(Some)
        }
    }

    pub(crate) fn integer(&self) -> Result<u64, MissionFileError> {
        self.value.as_u64().ok_or_else(|| {
            self.error(format!(
                "expected an integer of at least 0, found {}",
                kind(self.value)
            ))
        })
    }

    pub(crate) fn boolean(&self) -> Result<bool, MissionFileError> {
        self.value.as_bool().ok_or_else(|| {
            self.error(format!(
                "expected true or false, found {}",
                kind(self.value)
            ))
        })
    }

    /// The string field `key`, which must be `expected`.
    pub(crate) fn expect_string(&self, key: &str, expected: &str) -> Result<(), MissionFileError> {
        let at = self.field(key)?;
        match at.string()? {
            s if s == expected => Ok(()),
            other => Err(at.error(format!("{other:?}: expected {expected:?}"))),
        }
    }

    pub(crate) fn string(&self) -> Result<&'a str, MissionFileError> {
        self.value
            .as_str()
            .ok_or_else(|| self.error(format!("expected a string, found {}", kind(self.value))))
    }
}

fn kind(value: &Value) -> String {
    match value {
        Value::Null => "null".to_owned(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => format!("the string {s:?}"),
        Value::Array(_) => "an array".to_owned(),
        Value::Object(_) => "an object".to_owned(),
    }
}

pub(crate) fn note(path: impl Into<String>, reason: impl Into<String>) -> Unsupported {
    Unsupported {
        path: path.into(),
        reason: reason.into(),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use missionlink_interfaces::wire::Reason;
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

    fn paths(notes: &[Unsupported]) -> Vec<&str> {
        notes.iter().map(|n| n.path.as_str()).collect()
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
    fn ardu_plane_imports_with_its_loiters_reported() {
        let import =
            import_plan(&real("PX4SITL-ArduPlane.plan"), &ImportOptions::default()).unwrap();
        assert_eq!(
            import.home,
            Some(Home {
                latitude_deg: 47.397,
                longitude_deg: 8.5455,
                altitude_m: 488.056
            })
        );
        assert_eq!(
            paths(&import.notes),
            ["mission.items[0]", "mission.items[3]", "mission.items[5]"],
            "{:#?}",
            import.notes
        );
        assert!(
            import.notes[0]
                .reason
                .contains("take-off position (47.3996949, 8.5455)")
        );
        assert!(
            import.notes[0]
                .reason
                .contains("300 m from the planned home")
        );
        assert_eq!(
            import.notes[1].reason,
            "command 18 (NAV_LOITER_TURNS) is not supported"
        );
        assert_eq!(
            import.notes[2].reason,
            "command 31 (NAV_LOITER_TO_ALT) is not supported"
        );
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
            },
        )
        .unwrap();
        assert_eq!(
            paths(&import.notes),
            ["mission.items[0]", "mission.items[4]", "mission.items[6]"],
            "{:#?}",
            import.notes
        );
        assert_eq!(
            import.notes[1].to_string(),
            "mission.items[4]: command 195 (DO_SET_ROI_LOCATION) is not supported"
        );
        assert_eq!(
            import.notes[2].to_string(),
            "mission.items[6]: command 19 (NAV_LOITER_TIME) is not supported"
        );
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
        let (areas, notes) = import_areas(&text).unwrap();
        assert!(notes.is_empty(), "{notes:?}");
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
        let options = ExportOptions {
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
            },
        )
        .unwrap();
        assert!(import.notes.is_empty(), "{:#?}", import.notes);
        assert_eq!(import.home, Some(home));
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

    #[test]
    fn fences_complex_items_and_rally_points() {
        let items = format!(
            r#"{WAYPOINT},
        {{"type": "ComplexItem", "complexItemType": "survey"}},
        {{"type": "SimpleItem", "command": 16, "frame": 3, "params": [5, 0, 0, null, 47.42, 8.56, 100]}},
        {{"type": "SimpleItem", "command": 20, "frame": 2, "params": [0, 0, 0, 0, 0, 0, 0]}},
        {{"type": "SimpleItem", "command": 16, "frame": 1, "params": [0, 0, 0, null, 47.43, 8.56, 100]}},
        {{"type": "SimpleItem", "command": 178, "frame": 2, "params": [2, 3, -1, 0, 0, 0, 0]}},
        {{"type": "SimpleItem", "command": 21, "frame": 3, "params": [0, 0, 0, null, 47.42, 8.56, 0]}},
        {WAYPOINT}"#
        );
        let fence = r#""version": 2,
            "circles": [
              {"inclusion": true, "circle": {"center": [47.40, 8.55], "radius": 5000}, "version": 1},
              {"inclusion": false, "circle": {"center": [47.41, 8.55], "radius": 200}, "version": 1}],
            "polygons": [
              {"inclusion": false, "polygon": [[47.41, 8.56], [47.41, 8.57], [47.42, 8.57]], "version": 1}]"#;
        let import = import_plan(&plan_with(&items, fence), &ImportOptions::default()).unwrap();
        let notes: Vec<String> = import.notes.iter().map(ToString::to_string).collect();
        assert_eq!(
            notes,
            [
                "mission.items[1]: complex item \"survey\" is not supported (only take-off, \
                 waypoint, land and speed change)",
                "mission.items[2].params[0]: hold 5 s is not carried (the ICD has no hold \
                 time): the waypoint is fly-over",
                "mission.items[3]: command 20 (NAV_RETURN_TO_LAUNCH) is not supported",
                "mission.items[4].frame: command 16 (NAV_WAYPOINT) in frame 1 (LOCAL_NED) is \
                 not supported: only global (0, 5), relative (3, 6) and terrain (10, 11) frames",
                "mission.items[5].params[0]: speed type 2 (2 climb, 3 descent speed) is not \
                 supported: only airspeed (0) and ground speed (1)",
                "mission.items[7]: after the land (mission.items[6]): the route ends at the land",
                "mission.items: no take-off (command 22 or 84): the plan has no take-off \
                 height, which validation requires",
                "geoFence.circles[0]: an inclusion circle: the ICD's fly-zone is a polygon: \
                 approximated by the inscribed polygon of 60 vertices (at most 6.9 m inside \
                 the circle)",
                "rallyPoints.points[0]: rally points are not supported (the ICD has none)",
            ]
        );
        // Two waypoints: the land is at the second one, fly-over by its hold.
        assert_eq!(import.plan.mission.len(), 2);
        assert_eq!(
            import.plan.mission.assemble(Some(2), None).unwrap_err(),
            Reason::MissingField
        );
        let list = import
            .plan
            .areas
            .assemble(3, SafetyOffset::default())
            .unwrap();
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
                (1, AreaType::FlyZone, false),
                (2, AreaType::NoFlyZone, false),
                (3, AreaType::NoFlyZone, true),
            ]
        );
        let AreaShape::Polygon(ring) = &list.areas[0].shape else {
            panic!()
        };
        let centre = pos(47.40, 8.55);
        assert_eq!(ring.len(), 60);
        assert!(
            ring.iter()
                .all(|p| (earth::distance_m(centre, *p) - 5000.0).abs() < 0.01)
        );
        let AreaShape::Circle { border, .. } = list.areas[2].shape else {
            panic!()
        };
        assert!((earth::distance_m(pos(47.41, 8.55), border) - 200.0).abs() < 0.01);
    }

    #[test]
    fn a_second_inclusion_polygon_is_reported() {
        let fence = r#""polygons": [
              {"inclusion": true, "polygon": [[47.3, 8.4], [47.3, 8.7], [47.5, 8.7], [47.5, 8.4]]},
              {"inclusion": true, "polygon": [[47.3, 8.4], [47.3, 8.5], [47.4, 8.5]]}]"#;
        let (areas, notes) = import_areas(&plan_with(WAYPOINT, fence)).unwrap();
        assert_eq!(areas.len(), 1);
        assert_eq!(
            paths(&notes),
            ["geoFence.polygons[1]"],
            "rally points are no areas"
        );
        assert!(notes[0].reason.contains("(geoFence.polygons[0])"));
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

        let with = |item: &str| plan_with(&format!("{WAYPOINT},\n{item}"), "");
        let cases: &[(&str, &str)] = &[
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 95, 8.5, 10]}"#,
                "mission.items[1].params[4]: latitude 95 deg is outside -90..=90",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 47.4, null, 10]}"#,
                "mission.items[1].params[5]: expected a number, found null",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 47.4, 8.5, "high"]}"#,
                "mission.items[1].params[6]: expected a number, found the string \"high\"",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 0, "params": [0, 0, 0, null, 47.4, 8.5, null]}"#,
                "mission.items[1].params[6]: expected a number, found null",
            ),
            (
                r#"{"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 47.4, 8.5, 10]}"#,
                "mission.items[1].params: 5 values, expected 7",
            ),
            (
                r#"{"type": "Simple", "command": 16}"#,
                "mission.items[1].type: \"Simple\" is not \"SimpleItem\" or \"ComplexItem\"",
            ),
            (
                r#"{"type": "SimpleItem", "frame": 3, "params": []}"#,
                "mission.items[1].command: missing",
            ),
            (
                r#"{"type": "SimpleItem", "command": 178, "frame": 2, "params": [1, 0.2, -1, 0, 0, 0, 0]}"#,
                "mission.items[1].params[1]: 0.2 m/s is 0 on the wire (steps of 0.5 m/s); the \
                 speed must be above 0",
            ),
            (
                r#"{"type": "SimpleItem", "command": 22, "frame": 0, "params": [0, 0, 0, null, 0, 0, 400]}"#,
                "mission.items[1]: command 22 (NAV_TAKEOFF): a take-off after waypoints is not \
                 supported",
            ),
        ];
        for (item, expected) in cases {
            let got = match import_plan(&with(item), &ImportOptions::default()) {
                Err(e) => e.to_string(),
                Ok(i) => i.notes.first().map(ToString::to_string).unwrap_or_default(),
            };
            assert_eq!(&got, expected);
        }

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
            import_areas(&fence).unwrap_err().to_string(),
            "geoFence.polygons[0].polygon[1]: 1 values, expected [latitude, longitude]"
        );
        assert_eq!(
            import_areas("{\"fileType\": \"Mission\"}")
                .unwrap_err()
                .to_string(),
            "fileType: \"Mission\": not a QGroundControl plan (\"Plan\")"
        );
        assert_eq!(
            import_areas("[]").unwrap_err().to_string(),
            "(top level): expected an object, found an array"
        );
    }
}
