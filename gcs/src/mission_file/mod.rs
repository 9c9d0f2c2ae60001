//! The mission file of the `gcs` tool, one mission plan as TOML: the format is documented, with
//! a complete example, in `docs/mission-files.md`.

use core::fmt;
use std::path::Path;

use missionlink_ground::ground_station::{MissionPlan, ValidatedPlan};
use missionlink_interfaces::capacity::{MAX_AREAS, MAX_POLYGON_VERTICES, MAX_WAYPOINTS};
use missionlink_interfaces::wire::{
    AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, LegType, LocationType,
    PolygonVertices, RouteType, SafetyOffset, SpecificData, Speed, SpeedType, Text, Timestamp,
    TurnDirection, TurnType, U3, UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};
use missionlink_protocol::transfer::mission::{MissionBuffer, WaypointRecord};
use serde::{Deserialize, Deserializer, Serialize};
use toml::value::Datetime;

mod wire;

pub use self::wire::position;
use self::wire::*;

pub use crate::import::{Dropped, MissionFileError};
use crate::values::{
    altitude, altitude_bounds, border_due_north, degrees, field_error, latitude, longitude, metres,
    point, shortest,
};

/// A mission file: one mission plan in the format of `docs/mission-files.md`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionFile {
    /// #13000 Mission ID (Char20: at most 19 bytes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mission_id: Option<String>,
    /// #13006 type 1: take-off height above ground, metres, not below 0.
    pub take_off_height_m: f64,
    /// Activity ID (U3) of the take-off #13006.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub take_off_activity_id: Option<i64>,
    /// The planned take-off position, `[latitude_deg, longitude_deg]` (not sent; checked by the
    /// safety gateway). `None`: not known (a download), and validation refuses the plan.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub take_off_position: Option<[f64; 2]>,
    /// #2011 Safety Offset, metres (0 to 6553.5).
    pub safety_offset_m: f64,
    /// #13001.
    pub route: RouteEntry,
    /// #13002 (and #13006 type 2), in any order.
    #[serde(default)]
    pub waypoints: Vec<WaypointEntry>,
    /// #2012, in upload order.
    #[serde(default)]
    pub areas: Vec<AreaEntry>,
}

/// The `[route]` table: #13001 UA Route.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouteEntry {
    /// Initial Waypoint Number, 1..=65534.
    pub initial_waypoint: i64,
    /// Activity ID bit 0: return-to-home may fly the route backwards.
    pub bidirectional: bool,
    /// Route ID (Char33: at most 32 bytes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route_id: Option<String>,
    /// Route Type: launch, approach, flight, contingency-a, contingency-b.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route_type: Option<String>,
    /// Planning Wind Speed (#13001 bit 5, ICD §7 "Turns in wind"), m/s in steps of 0.5: the
    /// wind the mission was checked in, which sizes the turns the FCC flies. Absent: calm, or
    /// the wind of the check that uploads it (`--wind-mps`, the environment file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planning_wind_mps: Option<f64>,
}

/// One `[[waypoints]]` entry: a #13002 UA Position Waypoint and its #13006 RF centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaypointEntry {
    /// Waypoint Number, 1..=65534, unique in the file.
    pub number: i64,
    /// Next Waypoint, 0 (last) or 1..=65534.
    pub next: i64,
    /// Waypoint to Latitude, -90..=90 deg.
    pub latitude_deg: f64,
    /// Waypoint to Longitude, -180..=180 deg.
    pub longitude_deg: f64,
    /// Waypoint to Altitude, metres.
    pub altitude_m: f64,
    /// Waypoint Altitude Type: pressure, baro, agl, wgs84.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub altitude_type: Option<String>,
    /// Waypoint to Speed, m/s, above 0.
    pub speed_mps: f64,
    /// Waypoint Speed Type: indicated-airspeed, true-airspeed, ground-speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_type: Option<String>,
    /// Turn Type: fly-by, fly-over.
    pub turn_type: String,
    /// Waypoint Type, the leg that ends here: track-to-fix, radius-to-fix.
    pub leg_type: String,
    /// Location Type: absolute.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub location_type: Option<String>,
    /// Altitude Change Behaviour (U1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub altitude_change_behaviour: Option<i64>,
    /// Optional Messages for Waypoint (U1 bitmap; bit 0 = an RF centre follows).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optional_messages: Option<i64>,
    /// Limit Type (U1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit_type: Option<i64>,
    /// Loop Limit (U2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_limit: Option<i64>,
    /// Arrival Time, RFC 3339 with a UTC offset (a TOML date-time or a string), 2000 to 2034.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "date_time"
    )]
    pub arrival_time: Option<Datetime>,
    /// Activity ID (U3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub activity_id: Option<i64>,
    /// The #13006 type 2 radius-to-fix centre of this waypoint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rf_centre: Option<RfCentreEntry>,
}

/// The `rf_centre` table of a waypoint: #13006 type 2.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RfCentreEntry {
    /// RF Centre Latitude, -90..=90 deg.
    pub latitude_deg: f64,
    /// RF Centre Longitude, -180..=180 deg.
    pub longitude_deg: f64,
    /// Turn Direction: clockwise, counter-clockwise.
    pub turn_direction: String,
    /// Activity ID (U3) of the #13006.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub activity_id: Option<i64>,
}

/// One `[[areas]]` entry: a #2012 Area Polygon Loop Segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaEntry {
    /// Area ID, 1..=65534, unique in the file.
    pub area_id: i64,
    /// Area Type: fly-zone, no-fly-zone.
    pub area_type: String,
    /// Lower Altitude, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_altitude_m: Option<f64>,
    /// Upper Altitude, metres, not below the lower.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_altitude_m: Option<f64>,
    /// Altitude Type: pressure, baro, agl, wgs84.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub altitude_type: Option<String>,
    /// A polygon: `[latitude_deg, longitude_deg]` vertices in order, not closed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// A circle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circle: Option<CircleEntry>,
}

/// The `circle` of an area: the centre and either a border point or a radius.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleEntry {
    /// The centre, `[latitude_deg, longitude_deg]`.
    pub centre: [f64; 2],
    /// A point on the border, `[latitude_deg, longitude_deg]` (exact; what export writes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub border: Option<[f64; 2]>,
    /// The radius in metres (input only): the border point goes due north of the centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
}

impl MissionFile {
    /// Reads a mission file from TOML text. Checks syntax, types, required and unknown keys;
    /// the values are checked by [`MissionFile::to_plan`].
    pub fn parse(text: &str) -> Result<Self, MissionFileError> {
        toml::from_str(text).map_err(|e| {
            let (line, column) =
                missionlink_platform::config::line_column(text, e.span().map_or(0, |s| s.start));
            MissionFileError::Syntax {
                line,
                column,
                message: e.message().trim_end().to_owned(),
            }
        })
    }

    /// Reads the mission file at `path` (see [`MissionFile::parse`]).
    pub fn read(path: &Path) -> Result<Self, MissionFileError> {
        let text = std::fs::read_to_string(path).map_err(|e| MissionFileError::Io {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        Self::parse(&text)
    }

    /// The mission plan: the take-off height, every waypoint, RF centre and the route in a
    /// [`MissionBuffer`], every area in an
    /// [`AreaBuffer`](missionlink_protocol::transfer::areas::AreaBuffer). Every value is checked
    /// against what the wire carries and the FCC's message decoding accepts; the plan as a whole
    /// is checked by the GCS validation.
    ///
    /// Boxed, and filled in place: a plan is 38 KB, and every frame it passed through by value
    /// would be that much larger (the ground service runs each request on a fresh thread, whose
    /// stack pages each cost a fault).
    pub fn to_plan(&self) -> Result<Box<MissionPlan>, MissionFileError> {
        let mut plan = Box::<MissionPlan>::default();
        let mission = &mut plan.mission;
        let height = altitude("take_off_height_m", self.take_off_height_m)?;
        if height.raw() < 0 {
            return Err(field_error(
                "take_off_height_m",
                format!("{} m is below ground (0)", self.take_off_height_m),
            ));
        }
        let take_off = VehicleSpecificWaypoint {
            time_stamp: Timestamp::default(),
            data: SpecificData::TakeOffHeight { height },
            activity_id: optional(self.take_off_activity_id, |v| {
                activity_id("take_off_activity_id", v)
            })?,
        };
        store(mission, take_off.into(), "take_off_height_m")?;

        let mut numbers: Vec<(u16, usize)> = Vec::with_capacity(self.waypoints.len());
        for (i, entry) in self.waypoints.iter().enumerate() {
            let (waypoint, rf_centre) = entry.to_messages(i)?;
            if let Some((_, first)) = numbers.iter().find(|(n, _)| *n == waypoint.waypoint_number) {
                return Err(field_error(
                    format!("waypoints[{i}].number"),
                    format!(
                        "waypoint number {} is also waypoints[{first}].number",
                        waypoint.waypoint_number
                    ),
                ));
            }
            numbers.push((waypoint.waypoint_number, i));
            if numbers.len() > MAX_WAYPOINTS {
                return Err(field_error(
                    format!("waypoints[{i}]"),
                    format!("more than {MAX_WAYPOINTS} waypoints (the FCC's capacity)"),
                ));
            }
            store(mission, waypoint.into(), &format!("waypoints[{i}]"))?;
            if let Some(c) = rf_centre {
                store(mission, c.into(), &format!("waypoints[{i}].rf_centre"))?;
            }
        }
        store(mission, self.route.to_message()?.into(), "route")?;

        let areas = &mut plan.areas;
        let mut ids: Vec<(u16, usize)> = Vec::with_capacity(self.areas.len());
        for (i, entry) in self.areas.iter().enumerate() {
            let area = entry.to_message(i)?;
            if let Some((_, first)) = ids.iter().find(|(id, _)| *id == area.area_id) {
                return Err(field_error(
                    format!("areas[{i}].area_id"),
                    format!("area ID {} is also areas[{first}].area_id", area.area_id),
                ));
            }
            ids.push((area.area_id, i));
            areas.store(&area).map_err(|_| {
                field_error(
                    format!("areas[{i}]"),
                    format!("more than {MAX_AREAS} areas (the FCC's capacity)"),
                )
            })?;
        }

        plan.safety_offset = SafetyOffset::from_metres(self.safety_offset_m)
            .map_err(|e| field_error("safety_offset_m", e.to_string()))?;
        plan.mission_id = optional(self.mission_id.as_deref(), |s| text("mission_id", s))?;
        plan.take_off_position = optional(self.take_off_position, |[lat, lon]| {
            point("take_off_position", lat, lon)
        })?;
        Ok(plan)
    }

    /// The file of a validated plan and its planned take-off position (`gcs convert`; `gcs
    /// download -o` has none, the FCC does not hold it): the waypoints in flight-plan order, the
    /// areas in list order, every value exact.
    pub fn from_plan(plan: &ValidatedPlan, take_off_position: Option<GeoPoint>) -> Self {
        let mission = &plan.mission;
        let route = &mission.route;
        Self {
            mission_id: mission.mission_id.map(|t| t.as_str().to_owned()),
            take_off_height_m: metres(mission.take_off_height()),
            take_off_activity_id: mission.take_off.activity_id.map(u3),
            take_off_position: take_off_position.map(position),
            safety_offset_m: shortest(plan.areas.safety_offset.metres(), |m| {
                SafetyOffset::from_metres(m) == Ok(plan.areas.safety_offset)
            }),
            route: RouteEntry {
                initial_waypoint: i64::from(route.initial_waypoint),
                bidirectional: route.bidirectional,
                route_id: route.route_id.map(|t| t.as_str().to_owned()),
                route_type: route.route_type.map(word),
                planning_wind_mps: route.planning_wind.map(|w| w.mps()),
            },
            waypoints: mission
                .waypoints
                .iter()
                .map(WaypointEntry::from_record)
                .collect(),
            areas: plan.areas.areas.iter().map(AreaEntry::from_area).collect(),
        }
    }

    /// The file as TOML text: a comment that names the format, then the keys in a fixed order
    /// (optional ones only when present), one polygon vertex per line.
    pub fn to_toml(&self) -> String {
        // Serialization fails only for values TOML cannot hold (a top-level non-table, a map
        // with non-string keys); a MissionFile has none.
        let body = toml::to_string(self).unwrap_or_else(|e| format!("# not writable: {e}\n"));
        // The layout is cosmetic; it is kept only if it reads back the same.
        let laid_out = one_vertex_per_line(&body);
        let body = if Self::parse(&laid_out).as_ref() == Ok(self) {
            laid_out
        } else {
            body
        };
        let take_off = if self.take_off_position.is_none() {
            "# No take_off_position: the FCC does not hold it, so a download has none. Add it\n\
             # (take_off_position = [latitude_deg, longitude_deg]) before uploading this file:\n\
             # validation refuses a plan without one.\n"
        } else {
            ""
        };
        format!(
            "# missionlink mission file (format: docs/mission-files.md in missionlink).\n\
             # Positions are [latitude_deg, longitude_deg] on WGS-84.\n{take_off}\n{body}"
        )
    }
}

/// The demo missions and their validated plans, for the tests of every module of the crate.
#[cfg(test)]
pub(crate) mod tests;
