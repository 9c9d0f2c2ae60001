//! The mission file of the `gcs` tool, one mission plan as TOML: the format is documented, with
//! a complete example, in `docs/mission-files.md`.

use core::fmt;
use std::path::Path;

use missionlink_interfaces::capacity::{MAX_AREAS, MAX_POLYGON_VERTICES, MAX_WAYPOINTS};
use missionlink_interfaces::wire::{
    AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, LegType, LocationType,
    PolygonVertices, RouteType, SafetyOffset, SpecificData, Speed, SpeedType, Text, Timestamp,
    TurnDirection, TurnType, U3, UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};
use missionlink_services::ground_station::{MissionPlan, ValidatedPlan};
use missionlink_services::transfer::areas::AreaBuffer;
use missionlink_services::transfer::mission::{MissionBuffer, WaypointRecord};
use serde::{Deserialize, Deserializer, Serialize};
use toml::value::Datetime;

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
    /// [`MissionBuffer`], every area in an [`AreaBuffer`]. Every value is checked against what
    /// the wire carries and the FCC's message decoding accepts; the plan as a whole is checked
    /// by the GCS validation.
    pub fn to_plan(&self) -> Result<MissionPlan, MissionFileError> {
        let mut mission = MissionBuffer::new();
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
        store(&mut mission, take_off.into(), "take_off_height_m")?;

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
            store(&mut mission, waypoint.into(), &format!("waypoints[{i}]"))?;
            if let Some(c) = rf_centre {
                store(&mut mission, c.into(), &format!("waypoints[{i}].rf_centre"))?;
            }
        }
        store(&mut mission, self.route.to_message()?.into(), "route")?;

        let mut areas = AreaBuffer::new();
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

        Ok(MissionPlan {
            mission,
            areas,
            safety_offset: SafetyOffset::from_metres(self.safety_offset_m)
                .map_err(|e| field_error("safety_offset_m", e.to_string()))?,
            mission_id: optional(self.mission_id.as_deref(), |s| text("mission_id", s))?,
            take_off_position: optional(self.take_off_position, |[lat, lon]| {
                point("take_off_position", lat, lon)
            })?,
        })
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

impl RouteEntry {
    fn to_message(&self) -> Result<UaRoute, MissionFileError> {
        Ok(UaRoute {
            time_stamp: Timestamp::default(),
            initial_waypoint: integer("route.initial_waypoint", self.initial_waypoint, 1, 65534)?,
            route_id: optional(self.route_id.as_deref(), |s| text("route.route_id", s))?,
            route_type: optional(self.route_type.as_deref(), |s| {
                from_word("route.route_type", s)
            })?,
            bidirectional: self.bidirectional,
        })
    }
}

impl WaypointEntry {
    fn to_messages(
        &self,
        i: usize,
    ) -> Result<(UaPositionWaypoint, Option<VehicleSpecificWaypoint>), MissionFileError> {
        let at = |key: &str| format!("waypoints[{i}].{key}");
        let waypoint_number = integer(&at("number"), self.number, 1, 65534)?;
        let speed = Speed::from_mps(self.speed_mps)
            .map_err(|e| field_error(at("speed_mps"), e.to_string()))?;
        if speed.raw() == 0 {
            return Err(field_error(
                at("speed_mps"),
                format!(
                    "{} m/s is 0 on the wire (steps of 0.5 m/s); the speed must be above 0",
                    self.speed_mps
                ),
            ));
        }
        let waypoint = UaPositionWaypoint {
            time_stamp: Timestamp::default(),
            waypoint_number,
            latitude: latitude(&at("latitude_deg"), self.latitude_deg)?,
            longitude: longitude(&at("longitude_deg"), self.longitude_deg)?,
            location_type: optional(self.location_type.as_deref(), |s| {
                from_word(&at("location_type"), s)
            })?,
            altitude: altitude(&at("altitude_m"), self.altitude_m)?,
            altitude_type: optional(self.altitude_type.as_deref(), |s| {
                from_word(&at("altitude_type"), s)
            })?,
            altitude_change_behaviour: optional(self.altitude_change_behaviour, |v| {
                integer(&at("altitude_change_behaviour"), v, 0, 255)
            })?,
            speed,
            speed_type: optional(self.speed_type.as_deref(), |s| {
                from_word(&at("speed_type"), s)
            })?,
            next_waypoint: integer(&at("next"), self.next, 0, 65534)?,
            turn_type: from_word(&at("turn_type"), &self.turn_type)?,
            optional_messages: optional(self.optional_messages, |v| {
                integer(&at("optional_messages"), v, 0, 255)
            })?,
            leg_type: from_word(&at("leg_type"), &self.leg_type)?,
            limit_type: optional(self.limit_type, |v| integer(&at("limit_type"), v, 0, 255))?,
            loop_limit: optional(self.loop_limit, |v| integer(&at("loop_limit"), v, 0, 65535))?,
            arrival_time: optional(self.arrival_time.as_ref(), |t| {
                timestamp(&at("arrival_time"), t)
            })?,
            activity_id: optional(self.activity_id, |v| activity_id(&at("activity_id"), v))?,
        };
        let rf_centre = optional(self.rf_centre.as_ref(), |c| {
            let at = |key: &str| format!("waypoints[{i}].rf_centre.{key}");
            Ok(VehicleSpecificWaypoint {
                time_stamp: Timestamp::default(),
                data: SpecificData::RfCentre {
                    waypoint_number,
                    latitude: latitude(&at("latitude_deg"), c.latitude_deg)?,
                    longitude: longitude(&at("longitude_deg"), c.longitude_deg)?,
                    turn_direction: from_word(&at("turn_direction"), &c.turn_direction)?,
                },
                activity_id: optional(c.activity_id, |v| activity_id(&at("activity_id"), v))?,
            })
        })?;
        Ok((waypoint, rf_centre))
    }

    fn from_record(record: &WaypointRecord) -> Self {
        let w = &record.waypoint;
        let rf_centre = record.rf_centre.and_then(|c| match c.data {
            SpecificData::RfCentre {
                latitude,
                longitude,
                turn_direction,
                ..
            } => Some(RfCentreEntry {
                latitude_deg: degrees(latitude),
                longitude_deg: degrees(longitude),
                turn_direction: word(turn_direction),
                activity_id: c.activity_id.map(u3),
            }),
            SpecificData::TakeOffHeight { .. } => None,
        });
        Self {
            number: i64::from(w.waypoint_number),
            next: i64::from(w.next_waypoint),
            latitude_deg: degrees(w.latitude),
            longitude_deg: degrees(w.longitude),
            altitude_m: metres(w.altitude),
            altitude_type: w.altitude_type.map(word),
            speed_mps: w.speed.mps(),
            speed_type: w.speed_type.map(word),
            turn_type: word(w.turn_type),
            leg_type: word(w.leg_type),
            location_type: w.location_type.map(word),
            altitude_change_behaviour: w.altitude_change_behaviour.map(i64::from),
            optional_messages: w.optional_messages.map(i64::from),
            limit_type: w.limit_type.map(i64::from),
            loop_limit: w.loop_limit.map(i64::from),
            arrival_time: w.arrival_time.map(date_time_of),
            activity_id: w.activity_id.map(u3),
            rf_centre,
        }
    }
}

impl AreaEntry {
    fn to_message(&self, i: usize) -> Result<AreaPolygonLoopSegment, MissionFileError> {
        let at = |key: &str| format!("areas[{i}].{key}");
        let lower_altitude = optional(self.lower_altitude_m, |m| {
            altitude(&at("lower_altitude_m"), m)
        })?;
        let upper_altitude = optional(self.upper_altitude_m, |m| {
            altitude(&at("upper_altitude_m"), m)
        })?;
        altitude_bounds(&at("upper_altitude_m"), lower_altitude, upper_altitude)?;
        let shape = match (&self.polygon, &self.circle) {
            (Some(vertices), None) => {
                if vertices.len() > MAX_POLYGON_VERTICES {
                    return Err(field_error(
                        at("polygon"),
                        format!(
                            "{} vertices, at most {MAX_POLYGON_VERTICES} fit a #2012",
                            vertices.len()
                        ),
                    ));
                }
                let mut points = PolygonVertices::new();
                for (k, v) in vertices.iter().enumerate() {
                    let [lat, lon] = *v;
                    let p = point(&at(&format!("polygon[{k}]")), lat, lon)?;
                    // The length was checked above.
                    let _ = points.push(p);
                }
                AreaShape::Polygon(points)
            }
            (None, Some(circle)) => {
                let [lat, lon] = circle.centre;
                let centre = point(&at("circle.centre"), lat, lon)?;
                let border = match (circle.border, circle.radius_m) {
                    (Some([lat, lon]), None) => point(&at("circle.border"), lat, lon)?,
                    (None, Some(r)) => border_due_north(&at("circle.radius_m"), centre, r)?,
                    (Some(_), Some(_)) => {
                        return Err(field_error(
                            at("circle"),
                            "give either border or radius_m, not both",
                        ));
                    }
                    (None, None) => {
                        return Err(field_error(at("circle"), "give border or radius_m"));
                    }
                };
                AreaShape::Circle { centre, border }
            }
            (Some(_), Some(_)) => {
                return Err(field_error(
                    format!("areas[{i}]"),
                    "give either polygon or circle, not both",
                ));
            }
            (None, None) => {
                return Err(field_error(format!("areas[{i}]"), "give polygon or circle"));
            }
        };
        Ok(AreaPolygonLoopSegment {
            time_stamp: Timestamp::default(),
            area_id: integer(&at("area_id"), self.area_id, 1, 65534)?,
            area_type: from_word(&at("area_type"), &self.area_type)?,
            lower_altitude,
            upper_altitude,
            altitude_type: optional(self.altitude_type.as_deref(), |s| {
                from_word(&at("altitude_type"), s)
            })?,
            shape,
        })
    }

    fn from_area(area: &AreaPolygonLoopSegment) -> Self {
        let pair = |p: &GeoPoint| position(*p);
        let (polygon, circle) = match &area.shape {
            AreaShape::Polygon(vertices) => (Some(vertices.iter().map(pair).collect()), None),
            AreaShape::Circle { centre, border } => (
                None,
                Some(CircleEntry {
                    centre: pair(centre),
                    border: Some(pair(border)),
                    radius_m: None,
                }),
            ),
        };
        Self {
            area_id: i64::from(area.area_id),
            area_type: word(area.area_type),
            lower_altitude_m: area.lower_altitude.map(metres),
            upper_altitude_m: area.upper_altitude.map(metres),
            altitude_type: area.altitude_type.map(word),
            polygon,
            circle,
        }
    }
}

// ---- Values ----

/// A position as the file writes it, `[latitude_deg, longitude_deg]`: the shortest decimals
/// that give the wire values back (for reports too, e.g. `gcs validate`).
pub fn position(p: GeoPoint) -> [f64; 2] {
    [degrees(p.latitude), degrees(p.longitude)]
}

/// `f` applied to the value, if there is one.
fn optional<T, U>(
    value: Option<T>,
    f: impl FnOnce(T) -> Result<U, MissionFileError>,
) -> Result<Option<U>, MissionFileError> {
    value.map(f).transpose()
}

/// The integer `value` as a `T`, if it lies in `min..=max`.
fn integer<T: TryFrom<i64>>(
    path: &str,
    value: i64,
    min: i64,
    max: i64,
) -> Result<T, MissionFileError> {
    T::try_from(value)
        .ok()
        .filter(|_| (min..=max).contains(&value))
        .ok_or_else(|| field_error(path, format!("{value} is outside {min}..={max}")))
}

fn activity_id(path: &str, value: i64) -> Result<U3, MissionFileError> {
    let v: u32 = integer(path, value, 0, i64::from(U3::MAX))?;
    U3::new(v).ok_or_else(|| field_error(path, format!("{value} does not fit a U3")))
}

fn u3(v: U3) -> i64 {
    i64::from(v.get())
}

fn text<const N: usize>(path: &str, s: &str) -> Result<Text<N>, MissionFileError> {
    Text::new(s).map_err(|e| field_error(path, format!("{s:?}: {e}")))
}

/// A TOML date-time with offset (RFC 3339) as a time stamp.
fn timestamp(path: &str, t: &Datetime) -> Result<Timestamp, MissionFileError> {
    let (Some(date), Some(time), Some(offset)) = (t.date, t.time, t.offset) else {
        return Err(field_error(
            path,
            format!("{t}: give date, time and UTC offset (RFC 3339), e.g. 2026-11-21T12:06:00Z"),
        ));
    };
    let bad = |e: &dyn fmt::Display| field_error(path, format!("{t}: {e}"));
    let month = time::Month::try_from(date.month).map_err(|e| bad(&e))?;
    let day = time::Date::from_calendar_date(i32::from(date.year), month, date.day)
        .map_err(|e| bad(&e))?;
    let clock = time::Time::from_hms_nano(
        time.hour,
        time.minute,
        time.second.unwrap_or(0),
        time.nanosecond.unwrap_or(0),
    )
    .map_err(|e| bad(&e))?;
    let offset = match offset {
        toml::value::Offset::Z => time::UtcOffset::UTC,
        toml::value::Offset::Custom { minutes } => {
            time::UtcOffset::from_whole_seconds(i32::from(minutes) * 60).map_err(|e| bad(&e))?
        }
    };
    let utc = time::PrimitiveDateTime::new(day, clock).assume_offset(offset);
    Timestamp::from_utc(utc).ok_or_else(|| {
        field_error(
            path,
            format!("{t} is outside what a TS holds (2000-01-01 to 2034-11-01)"),
        )
    })
}

/// The time stamp as a TOML date-time in UTC, milliseconds only where there are any.
fn date_time_of(t: Timestamp) -> Datetime {
    let utc = t.to_utc();
    let millis = u32::from(utc.millisecond());
    Datetime {
        date: Some(toml::value::Date {
            // A TS lies in 2000..2035.
            year: u16::try_from(utc.year()).unwrap_or(2000),
            month: u8::from(utc.month()),
            day: utc.day(),
        }),
        time: Some(toml::value::Time {
            hour: utc.hour(),
            minute: utc.minute(),
            second: Some(utc.second()),
            nanosecond: (millis != 0).then_some(millis * 1_000_000),
        }),
        offset: Some(toml::value::Offset::Z),
    }
}

/// `arrival_time`: a TOML date-time, or a string holding one.
fn date_time<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Datetime>, D::Error> {
    use serde::de::Error as _;
    match toml::Value::deserialize(d)? {
        toml::Value::Datetime(t) => Ok(Some(t)),
        toml::Value::String(s) => s
            .parse()
            .map(Some)
            .map_err(|e| D::Error::custom(format_args!("{s:?} is not an RFC 3339 date-time: {e}"))),
        other => Err(D::Error::custom(format_args!(
            "expected an RFC 3339 date-time, found {}",
            other.type_str()
        ))),
    }
}

fn store(
    buffer: &mut MissionBuffer,
    message: missionlink_interfaces::wire::Message,
    path: &str,
) -> Result<(), MissionFileError> {
    buffer.store(&message).map_err(|_| {
        field_error(
            path,
            format!("more than {MAX_WAYPOINTS} waypoints (the FCC's capacity)"),
        )
    })
}

// ---- Enumeration words ----

/// An enumeration of the wire and its words in the file.
trait Word: Copy + PartialEq + 'static {
    const WORDS: &'static [(&'static str, Self)];
}

macro_rules! words {
    ($ty:ty { $($word:literal => $variant:ident),+ $(,)? }) => {
        impl Word for $ty {
            const WORDS: &'static [(&'static str, Self)] = &[$(($word, <$ty>::$variant)),+];
        }
    };
}

words!(AltitudeType { "pressure" => Pressure, "baro" => Baro, "agl" => Agl, "wgs84" => Wgs84 });
words!(SpeedType {
    "indicated-airspeed" => IndicatedAirspeed,
    "true-airspeed" => TrueAirspeed,
    "ground-speed" => GroundSpeed,
});
words!(TurnType { "fly-by" => FlyBy, "fly-over" => FlyOver });
words!(LegType { "track-to-fix" => TrackToFix, "radius-to-fix" => RadiusToFix });
words!(TurnDirection { "clockwise" => Clockwise, "counter-clockwise" => CounterClockwise });
words!(LocationType { "absolute" => Absolute });
words!(RouteType {
    "launch" => Launch,
    "approach" => Approach,
    "flight" => Flight,
    "contingency-a" => ContingencyA,
    "contingency-b" => ContingencyB,
});
words!(AreaType { "fly-zone" => FlyZone, "no-fly-zone" => NoFlyZone });

fn word<T: Word>(value: T) -> String {
    T::WORDS
        .iter()
        .find(|(_, v)| *v == value)
        .map_or("?", |(w, _)| w)
        .to_owned()
}

fn from_word<T: Word>(path: &str, s: &str) -> Result<T, MissionFileError> {
    T::WORDS
        .iter()
        .find(|(w, _)| *w == s)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            let known: Vec<String> = T::WORDS.iter().map(|(w, _)| format!("{w:?}")).collect();
            field_error(path, format!("{s:?} is not one of {}", known.join(", ")))
        })
}

/// `polygon = [[a, b], [c, d]]` as one vertex per line, as a person writes it.
fn one_vertex_per_line(toml: &str) -> String {
    let mut out = String::with_capacity(toml.len() + toml.len() / 4);
    for line in toml.lines() {
        match line
            .strip_prefix("polygon = [[")
            .and_then(|rest| rest.strip_suffix("]]"))
        {
            Some(vertices) => {
                out.push_str("polygon = [\n");
                for v in vertices.split("], [") {
                    out.push_str("    [");
                    out.push_str(v);
                    out.push_str("],\n");
                }
                out.push_str("]\n");
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    out
}

/// The demo missions and their validated plans, for the tests of every module of the crate.
#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use missionlink_interfaces::wire::{Angle, Reason};
    use missionlink_services::geofence::earth;
    use missionlink_services::ground_station::InvalidPlan;

    pub(crate) const MISSION_1: &str = include_str!("../../missions/mission-1.toml");
    pub(crate) const MISSION_2: &str = include_str!("../../missions/mission-2.toml");

    /// The plan of `text`, assembled as the GCS validation request does (ICD §7).
    pub(crate) fn validated(text: &str) -> ValidatedPlan {
        let file = MissionFile::parse(text).unwrap();
        file.to_plan().unwrap().assemble().unwrap()
    }

    /// `text` with each `(from, to)` replaced once; every `from` must occur.
    fn edit(text: &str, edits: &[(&str, &str)]) -> String {
        let mut t = text.to_owned();
        for (from, to) in edits {
            assert!(t.contains(from), "{from:?} not in the text");
            t = t.replacen(from, to, 1);
        }
        t
    }

    fn field_err(text: &str) -> (String, String) {
        let file = MissionFile::parse(text).unwrap();
        match file.to_plan() {
            Err(MissionFileError::Field { path, reason }) => (path, reason),
            other => panic!("expected a field error, got {other:?}"),
        }
    }

    fn syntax_err(text: &str) -> (usize, usize, String) {
        match MissionFile::parse(text) {
            Err(MissionFileError::Syntax {
                line,
                column,
                message,
            }) => (line, column, message),
            other => panic!("expected a syntax error, got {other:?}"),
        }
    }

    fn point(lat: f64, lon: f64) -> GeoPoint {
        GeoPoint::from_degrees(lat, lon).unwrap()
    }

    #[test]
    fn demo_mission_1_validates() {
        let v = validated(MISSION_1);
        let m = &v.mission;
        assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-1");
        assert_eq!(m.take_off_height().metres(), 30.0);
        assert_eq!(m.route.initial_waypoint, 1);
        assert!(!m.route.bidirectional);
        assert_eq!(m.waypoints.len(), 1);
        let ccp = &m.waypoints[0].waypoint;
        assert_eq!((ccp.waypoint_number, ccp.next_waypoint), (1, 0));
        assert_eq!(ccp.latitude, Angle::from_degrees(48.275).unwrap());
        assert_eq!(ccp.longitude, Angle::from_degrees(11.645).unwrap());
        assert_eq!(ccp.altitude.metres(), 120.0);
        assert_eq!(ccp.altitude_type, Some(AltitudeType::Wgs84));
        assert_eq!(ccp.speed.mps(), 25.0);
        assert_eq!(ccp.speed_type, Some(SpeedType::IndicatedAirspeed));
        assert_eq!(ccp.turn_type, TurnType::FlyBy);
        assert_eq!(ccp.leg_type, LegType::TrackToFix);
        assert_eq!(v.areas.safety_offset.metres(), 25.0);
        assert_eq!(v.areas.areas.len(), 1);
        let fz = &v.areas.areas[0];
        assert_eq!((fz.area_id, fz.area_type), (1, AreaType::FlyZone));
        let corners = [
            point(48.255, 11.635),
            point(48.255, 11.690),
            point(48.285, 11.690),
            point(48.285, 11.635),
        ];
        assert_eq!(
            fz.shape,
            AreaShape::Polygon(PolygonVertices::from_slice(&corners).unwrap())
        );
    }

    #[test]
    fn demo_mission_2_validates() {
        let v = validated(MISSION_2);
        let m = &v.mission;
        assert_eq!(m.mission_id.unwrap().as_str(), "MEDEVAC-2");
        assert_eq!(m.take_off_height().metres(), 30.0);
        assert!(m.route.bidirectional);
        assert_eq!(m.route.route_type, Some(RouteType::Flight));
        let order: Vec<u16> = m
            .waypoints
            .iter()
            .map(|r| r.waypoint.waypoint_number)
            .collect();
        assert_eq!(order, [1, 2, 3], "CCP, W1, ROLE2");
        let role2 = &m.waypoints[2];
        assert_eq!(role2.waypoint.leg_type, LegType::RadiusToFix);
        assert_eq!(role2.waypoint.latitude, Angle::from_degrees(48.28).unwrap());
        assert_eq!(role2.waypoint.optional_messages, Some(1));
        assert_eq!(
            role2.rf_centre.map(|c| c.data),
            Some(SpecificData::RfCentre {
                waypoint_number: 3,
                latitude: Angle::from_degrees(48.27455).unwrap(),
                longitude: Angle::from_degrees(11.66991).unwrap(),
                turn_direction: TurnDirection::Clockwise,
            })
        );
        assert!(m.waypoints[..2].iter().all(|r| r.rf_centre.is_none()));
        let areas: Vec<(u16, AreaType)> = v
            .areas
            .areas
            .iter()
            .map(|a| (a.area_id, a.area_type))
            .collect();
        assert_eq!(
            areas,
            [
                (1, AreaType::FlyZone),
                (2, AreaType::NoFlyZone),
                (3, AreaType::NoFlyZone)
            ]
        );
        assert_eq!(
            v.areas.areas[1].shape,
            AreaShape::Circle {
                centre: point(48.268, 11.675),
                border: point(48.268, 11.679),
            }
        );
        assert!(matches!(&v.areas.areas[2].shape, AreaShape::Polygon(p) if p.len() == 4));
    }

    #[test]
    fn read_reads_a_file_and_names_one_it_cannot() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../missions");
        let file = MissionFile::read(&dir.join("mission-2.toml")).unwrap();
        assert_eq!(file, MissionFile::parse(MISSION_2).unwrap());
        let missing = dir.join("no-such-mission.toml");
        let err = MissionFile::read(&missing).unwrap_err();
        assert!(matches!(&err, MissionFileError::Io { path, .. } if *path == missing));
        assert!(err.to_string().starts_with(&missing.display().to_string()));
    }

    /// The plan of the file `text` (before assembly).
    fn plan_of(text: &str) -> MissionPlan {
        MissionFile::parse(text).unwrap().to_plan().unwrap()
    }

    /// The file of `text` as an export writes it (the plan validated, with its take-off).
    fn exported(text: &str) -> MissionFile {
        let plan = plan_of(text);
        MissionFile::from_plan(&plan.assemble().unwrap(), plan.take_off_position)
    }

    /// Export, parse, plan, validate: the same plan and take-off position, and the same file
    /// again.
    fn assert_round_trip(plan: &MissionPlan) {
        let v = plan.assemble().unwrap();
        let file = MissionFile::from_plan(&v, plan.take_off_position);
        let text = file.to_toml();
        let parsed = MissionFile::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(parsed, file, "{text}");
        let again = parsed.to_plan().unwrap();
        assert_eq!(again.take_off_position, plan.take_off_position, "{text}");
        let again_valid = again.assemble().unwrap();
        assert_eq!(again_valid, v, "{text}");
        assert_eq!(
            MissionFile::from_plan(&again_valid, again.take_off_position).to_toml(),
            text
        );
    }

    #[test]
    fn export_round_trip_gives_back_the_plan() {
        for text in [MISSION_1, MISSION_2] {
            assert_round_trip(&plan_of(text));
        }
        // The export of a demo mission writes the same numbers as the file: the shortest
        // decimals of the wire values.
        let exported = exported(MISSION_2);
        let mut original = MissionFile::parse(MISSION_2).unwrap();
        assert_eq!(exported, original);
        original.waypoints[2].latitude_deg = 48.280_000_001;
        assert_ne!(exported, original);
        let text = exported.to_toml();
        assert!(text.starts_with("# missionlink mission file"), "{text}");
        assert!(
            text.contains(
                "polygon = [\n    [48.255, 11.635],\n    [48.255, 11.69],\n    \
                 [48.285, 11.69],\n    [48.285, 11.635],\n]\n"
            ),
            "{text}"
        );
    }

    #[test]
    fn round_trip_variations() {
        let all_optional = edit(
            MISSION_2,
            &[
                (
                    "safety_offset_m = 25.0",
                    "safety_offset_m = 0.3\ntake_off_activity_id = 16777215",
                ),
                (
                    "route_type = \"flight\"",
                    "route_type = \"contingency-b\"\nroute_id = \"CCP-ROLE2 über W1\"",
                ),
                (
                    "leg_type = \"track-to-fix\"",
                    "leg_type = \"track-to-fix\"\n\
                     location_type = \"absolute\"\n\
                     altitude_change_behaviour = 255\n\
                     limit_type = 2\n\
                     loop_limit = 65535\n\
                     arrival_time = 2026-11-21T12:06:00.300Z\n\
                     activity_id = 42\n\
                     optional_messages = 0",
                ),
                (
                    "turn_direction = \"clockwise\"",
                    "turn_direction = \"counter-clockwise\"\nactivity_id = 7",
                ),
                (
                    "area_type = \"fly-zone\"",
                    "area_type = \"fly-zone\"\n\
                     lower_altitude_m = -12.34\n\
                     upper_altitude_m = 300\n\
                     altitude_type = \"agl\"",
                ),
            ],
        );
        let cases: [(&str, String); 7] = [
            ("every optional field", all_optional),
            (
                "circle given by radius_m",
                edit(
                    MISSION_2,
                    &[("border = [48.268, 11.679]", "radius_m = 296.07")],
                ),
            ),
            (
                "off-grid values, extremes, other enumeration words",
                edit(
                    MISSION_2,
                    &[
                        ("latitude_deg = 48.275", "latitude_deg = 48.123456789"),
                        ("longitude_deg = 11.645", "longitude_deg = -180"),
                        ("altitude_m = 120.0", "altitude_m = -123.457"),
                        ("speed_mps = 25.0", "speed_mps = 0.3"),
                        ("altitude_type = \"wgs84\"", "altitude_type = \"pressure\""),
                        (
                            "speed_type = \"indicated-airspeed\"",
                            "speed_type = \"ground-speed\"",
                        ),
                        ("turn_type = \"fly-by\"", "turn_type = \"fly-over\""),
                        ("[48.255, 11.635]", "[-90, 179.99999999]"),
                        ("take_off_height_m = 30.0", "take_off_height_m = 0.01"),
                    ],
                ),
            ),
            (
                "optional fields absent",
                edit(
                    MISSION_2,
                    &[
                        ("mission_id = \"MEDEVAC-2\"", ""),
                        ("route_type = \"flight\"", ""),
                        ("optional_messages = 1", ""),
                        ("altitude_type = \"wgs84\"", ""),
                        ("speed_type = \"indicated-airspeed\"", ""),
                    ],
                ),
            ),
            (
                "empty texts are kept, not dropped",
                edit(
                    MISSION_2,
                    &[
                        ("mission_id = \"MEDEVAC-2\"", "mission_id = \"\""),
                        (
                            "route_type = \"flight\"",
                            "route_type = \"flight\"\nroute_id = \"\"",
                        ),
                    ],
                ),
            ),
            (
                "arrival time as a string with an offset, without milliseconds",
                edit(
                    MISSION_1,
                    &[(
                        "leg_type = \"track-to-fix\"",
                        "leg_type = \"track-to-fix\"\narrival_time = \"2026-11-21T13:06:00+01:00\"",
                    )],
                ),
            ),
            (
                "file order is free; the export lists the flight plan",
                edit(
                    MISSION_2,
                    &[
                        // CCP becomes waypoint 40 and starts the route; ROLE2 is listed first.
                        ("initial_waypoint = 1", "initial_waypoint = 40"),
                        ("number = 1\n", "number = 40\n"),
                        ("number = 3\n", "number = 7\n"),
                        ("next = 3 ", "next = 7 "),
                    ],
                ),
            ),
        ];
        for (name, text) in &cases {
            let file = MissionFile::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
            let plan = file.to_plan().unwrap_or_else(|e| panic!("{name}: {e}"));
            plan.assemble().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_round_trip(&plan);
        }

        // Spot checks of what the cases hold.
        let v = validated(&cases[0].1);
        let w1 = &v.mission.waypoints[0].waypoint;
        assert_eq!(
            w1.arrival_time.unwrap().to_string(),
            "2026-11-21T12:06:00.300Z"
        );
        assert_eq!(w1.activity_id, U3::new(42));
        assert_eq!(w1.loop_limit, Some(65535));
        assert_eq!(
            v.mission.route.route_id.unwrap().as_str(),
            "CCP-ROLE2 über W1"
        );
        assert_eq!(v.mission.take_off.activity_id, U3::new(16_777_215));
        assert_eq!(v.areas.safety_offset.raw(), 3);
        assert_eq!(v.areas.areas[0].lower_altitude.unwrap().raw(), -617);
        let text = MissionFile::from_plan(&v, None).to_toml();
        assert!(
            text.contains("arrival_time = 2026-11-21T12:06:00.3Z\n"),
            "{text}"
        );
        assert!(text.contains("lower_altitude_m = -12.34\n"), "{text}");

        let v = validated(&cases[2].1);
        let text = MissionFile::from_plan(&v, None).to_toml();
        // BAM4 keeps about 7 decimals; the export writes the shortest decimal of the wire value.
        assert!(text.contains("latitude_deg = 48.1234568\n"), "{text}");
        assert!(text.contains("longitude_deg = -180.0\n"), "{text}");
        assert!(text.contains("altitude_m = -123.46\n"), "{text}");
        assert!(text.contains("speed_mps = 0.5\n"), "{text}");
        assert!(text.contains("take_off_height_m = 0.02\n"), "{text}");

        let v = validated(&cases[4].1);
        assert_eq!(v.mission.mission_id.map(|t| t.as_str().len()), Some(0));
        assert_eq!(v.mission.route.route_id.map(|t| t.as_str().len()), Some(0));

        let v = validated(&cases[5].1);
        let t = v.mission.waypoints[0].waypoint.arrival_time.unwrap();
        assert_eq!(t.to_string(), "2026-11-21T12:06:00.000Z");
        let text = MissionFile::from_plan(&v, None).to_toml();
        assert!(
            text.contains("arrival_time = 2026-11-21T12:06:00Z\n"),
            "{text}"
        );

        let v = validated(&cases[6].1);
        let order: Vec<u16> = v
            .mission
            .waypoints
            .iter()
            .map(|r| r.waypoint.waypoint_number)
            .collect();
        assert_eq!(order, [40, 2, 7]);
    }

    #[test]
    fn radius_m_places_the_border_due_north() {
        let text = edit(
            MISSION_2,
            &[("border = [48.268, 11.679]", "radius_m = 296.07")],
        );
        let v = validated(&text);
        let AreaShape::Circle { centre, border } = v.areas.areas[1].shape else {
            panic!("not a circle");
        };
        assert_eq!(centre, point(48.268, 11.675));
        assert_eq!(border.longitude, centre.longitude);
        let metres = earth::distance_m(centre, border);
        // One BAM4 step of latitude is about 9.3 mm.
        assert!((metres - 296.07).abs() < 0.01, "{metres}");
        // Exported, the circle has its exact border point and no radius.
        let file = MissionFile::from_plan(&v, None);
        let circle = file.areas[1].circle.as_ref().unwrap();
        assert_eq!(circle.radius_m, None);
        assert_eq!(
            point(circle.border.unwrap()[0], circle.border.unwrap()[1]),
            border
        );
    }

    #[test]
    fn syntax_and_type_errors_give_line_and_column() {
        /// 1-based number of the first line of `text` that starts with `start`.
        fn line_of(text: &str, start: &str) -> usize {
            text.lines().position(|l| l.starts_with(start)).unwrap() + 1
        }
        let broken = edit(
            MISSION_2,
            &[("latitude_deg = 48.275", "latitude_deg = 48.275 deg")],
        );
        let (line, column, message) = syntax_err(&broken);
        let expected = line_of(MISSION_2, "latitude_deg = 48.275");
        // The value `48.275 deg` starts after `latitude_deg = `, 15 characters.
        assert_eq!((line, column), (expected, 16), "{message}");
        assert!(
            message.contains("string values must be quoted"),
            "{message}"
        );

        let typed = edit(MISSION_2, &[("speed_mps = 25.0", "speed_mps = \"fast\"")]);
        let (line, column, message) = syntax_err(&typed);
        assert_eq!(
            (line, column),
            (line_of(MISSION_2, "speed_mps"), 13),
            "{message}"
        );
        assert!(message.contains("invalid type"), "{message}");

        let unknown = edit(MISSION_2, &[("altitude_m = 120.0", "altitud_m = 120.0")]);
        let (line, column, message) = syntax_err(&unknown);
        assert_eq!(
            (line, column),
            (line_of(MISSION_2, "altitude_m"), 1),
            "{message}"
        );
        assert!(message.contains("unknown field `altitud_m`"), "{message}");

        let missing = edit(MISSION_2, &[("turn_type = \"fly-by\"\n", "")]);
        let (line, _, message) = syntax_err(&missing);
        assert_eq!(
            line,
            line_of(MISSION_2, "[[waypoints]]"),
            "the table of CCP: {message}"
        );
        assert!(message.contains("missing field `turn_type`"), "{message}");

        // Columns count characters, not bytes.
        let (line, column, _) = syntax_err("mission_id = \"ü\" x\n");
        assert_eq!((line, column), (1, 18));

        let e = MissionFileError::Syntax {
            line: 12,
            column: 5,
            message: "expected `=`".into(),
        };
        assert_eq!(e.to_string(), "line 12, column 5: expected `=`");
    }

    #[test]
    fn bad_values_name_their_path() {
        let lat = edit(MISSION_2, &[("latitude_deg = 48.275", "latitude_deg = 95")]);
        let (path, reason) = field_err(&lat);
        assert_eq!(path, "waypoints[0].latitude_deg");
        assert_eq!(reason, "latitude 95 deg is outside -90..=90");
        assert_eq!(
            MissionFile::parse(&lat)
                .unwrap()
                .to_plan()
                .unwrap_err()
                .to_string(),
            "waypoints[0].latitude_deg: latitude 95 deg is outside -90..=90"
        );

        /// Edits of mission 2, the path named, the end of the reason.
        type Case<'a> = (&'a [(&'a str, &'a str)], &'a str, &'a str);
        let cases: &[Case] = &[
            (
                &[("turn_type = \"fly-by\"", "turn_type = \"fly_by\"")],
                "waypoints[0].turn_type",
                "\"fly_by\" is not one of \"fly-by\", \"fly-over\"",
            ),
            (
                &[("number = 3\n", "number = 1\n")],
                "waypoints[2].number",
                "waypoint number 1 is also waypoints[0].number",
            ),
            (
                &[("area_id = 3", "area_id = 2")],
                "areas[2].area_id",
                "area ID 2 is also areas[1].area_id",
            ),
            (
                &[(
                    "mission_id = \"MEDEVAC-2\"",
                    "mission_id = \"MEDEVAC-2-CCP-TO-ROLE2\"",
                )],
                "mission_id",
                "\"MEDEVAC-2-CCP-TO-ROLE2\": text of 22 bytes, at most 19 fit",
            ),
            (
                &[(
                    "route_type = \"flight\"",
                    "route_id = \"CCP-W1-ROLE2-CCP-W1-ROLE2-CCP-W1X\"",
                )],
                "route.route_id",
                "text of 33 bytes, at most 32 fit",
            ),
            (
                &[("speed_mps = 25.0", "speed_mps = -25.0")],
                "waypoints[0].speed_mps",
                "speed (m/s) -25 is outside 0..=32767.5",
            ),
            (
                &[("speed_mps = 25.0", "speed_mps = 0.2")],
                "waypoints[0].speed_mps",
                "the speed must be above 0",
            ),
            (
                &[("longitude_deg = 11.66991", "longitude_deg = 181")],
                "waypoints[2].rf_centre.longitude_deg",
                "longitude 181 deg is outside -180..=180",
            ),
            (
                &[(
                    "turn_direction = \"clockwise\"",
                    "turn_direction = \"right\"",
                )],
                "waypoints[2].rf_centre.turn_direction",
                "\"right\" is not one of \"clockwise\", \"counter-clockwise\"",
            ),
            (
                &[("take_off_height_m = 30.0", "take_off_height_m = -1")],
                "take_off_height_m",
                "-1 m is below ground (0)",
            ),
            (
                &[(
                    "take_off_position = [48.275, 11.645]",
                    "take_off_position = [95, 11.645]",
                )],
                "take_off_position",
                "latitude 95 deg is outside -90..=90",
            ),
            (
                &[(
                    "take_off_position = [48.275, 11.645]",
                    "take_off_position = [48.275, -180.5]",
                )],
                "take_off_position",
                "longitude -180.5 deg is outside -180..=180",
            ),
            (
                &[("safety_offset_m = 25.0", "safety_offset_m = 7000")],
                "safety_offset_m",
                "safety offset (m) 7000 is outside 0..=6553.5",
            ),
            (
                &[("initial_waypoint = 1", "initial_waypoint = 0")],
                "route.initial_waypoint",
                "0 is outside 1..=65534",
            ),
            (
                &[("next = 0 ", "next = 65535 ")],
                "waypoints[2].next",
                "65535 is outside 0..=65534",
            ),
            (
                &[("leg_type = \"radius-to-fix\"", "leg_type = \"arc\"")],
                "waypoints[2].leg_type",
                "\"arc\" is not one of \"track-to-fix\", \"radius-to-fix\"",
            ),
            (
                &[("optional_messages = 1", "optional_messages = 256")],
                "waypoints[2].optional_messages",
                "256 is outside 0..=255",
            ),
            (
                &[("optional_messages = 1", "activity_id = 16777216")],
                "waypoints[2].activity_id",
                "16777216 is outside 0..=16777215",
            ),
            (
                &[("optional_messages = 1", "location_type = \"relative\"")],
                "waypoints[2].location_type",
                "\"relative\" is not one of \"absolute\"",
            ),
            (
                &[(
                    "optional_messages = 1",
                    "arrival_time = 2026-11-21T12:06:00",
                )],
                "waypoints[2].arrival_time",
                "2026-11-21T12:06:00: give date, time and UTC offset (RFC 3339), e.g. 2026-11-21T12:06:00Z",
            ),
            (
                &[(
                    "optional_messages = 1",
                    "arrival_time = 2040-01-01T00:00:00Z",
                )],
                "waypoints[2].arrival_time",
                "2040-01-01T00:00:00Z is outside what a TS holds (2000-01-01 to 2034-11-01)",
            ),
            (
                &[("area_type = \"fly-zone\"", "area_type = \"stay-in\"")],
                "areas[0].area_type",
                "\"stay-in\" is not one of \"fly-zone\", \"no-fly-zone\"",
            ),
            (
                &[("[48.262, 11.646],", "[95, 11.646],")],
                "areas[2].polygon[1]",
                "latitude 95 deg is outside -90..=90",
            ),
            (
                &[(
                    "area_type = \"fly-zone\"",
                    "area_type = \"fly-zone\"\nlower_altitude_m = 300\nupper_altitude_m = 0",
                )],
                "areas[0].upper_altitude_m",
                "0 m is below lower_altitude_m (300 m)",
            ),
            (
                &[(
                    "border = [48.268, 11.679]",
                    "border = [48.268, 11.679], radius_m = 300",
                )],
                "areas[1].circle",
                "give either border or radius_m, not both",
            ),
            (
                &[("border = [48.268, 11.679]", "radius_m = 0")],
                "areas[1].circle.radius_m",
                "0 m: the radius must be above 0",
            ),
            (
                &[(
                    "centre = [48.268, 11.675], border = [48.268, 11.679]",
                    "centre = [89.99, 0], radius_m = 2000",
                )],
                "areas[1].circle.radius_m",
                "2000 m north of the centre is beyond the pole",
            ),
            (
                &[(
                    "area_type = \"no-fly-zone\"\ncircle",
                    "area_type = \"no-fly-zone\"\npolygon = []\ncircle",
                )],
                "areas[1]",
                "give either polygon or circle, not both",
            ),
            (
                &[(
                    "circle = { centre = [48.268, 11.675], border = [48.268, 11.679] }",
                    "",
                )],
                "areas[1]",
                "give polygon or circle",
            ),
        ];
        for (edits, path, reason) in cases {
            let (p, r) = field_err(&edit(MISSION_2, edits));
            assert_eq!(&p, path, "{edits:?}: {r}");
            assert!(
                r.ends_with(reason),
                "{edits:?}: {r:?} does not end with {reason:?}"
            );
        }

        // More than a #2012 holds.
        let many: Vec<String> = (0..61)
            .map(|k| format!("[48.26, {}]", 11.64 + f64::from(k) * 1e-4))
            .collect();
        let text = edit(
            MISSION_2,
            &[("[48.262, 11.640],", &format!("{},", many.join(", ")))],
        );
        let (path, reason) = field_err(&text);
        assert_eq!(path, "areas[2].polygon");
        assert_eq!(reason, "64 vertices, at most 60 fit a #2012");
    }

    #[test]
    fn the_take_off_position_is_read_written_and_may_be_absent() {
        let point_of = |text: &str| plan_of(text).take_off_position;
        assert_eq!(point_of(MISSION_1), Some(point(48.26, 11.66)), "TROL");
        assert_eq!(point_of(MISSION_2), Some(point(48.275, 11.645)), "CCP");
        let text = exported(MISSION_1).to_toml();
        assert!(
            text.contains("take_off_height_m = 30.0\ntake_off_position = [48.26, 11.66]\n"),
            "{text}"
        );
        assert!(!text.contains("No take_off_position"), "{text}");
        // Not a pair of numbers: a syntax error at the key.
        let (line, _, message) = syntax_err(&edit(
            MISSION_1,
            &[(
                "take_off_position = [48.26, 11.66]",
                "take_off_position = [48.26]",
            )],
        ));
        assert_eq!(line, 10, "{message}");
        // Absent (a download): read, and written with a comment that says why it is missing.
        let without = edit(MISSION_1, &[("take_off_position = [48.26, 11.66]", "")]);
        assert_eq!(point_of(&without), None);
        let downloaded = MissionFile::from_plan(&validated(MISSION_1), None);
        assert_eq!(downloaded.take_off_position, None);
        let text = downloaded.to_toml();
        assert!(
            text.contains("# No take_off_position: the FCC does not hold it"),
            "{text}"
        );
        assert!(!text.contains("\ntake_off_position"), "{text}");
        assert_round_trip(&plan_of(&without));
    }

    #[test]
    fn a_two_vertex_polygon_is_a_file_but_not_a_valid_plan() {
        let text = edit(
            MISSION_2,
            &[("    [48.266, 11.646],\n    [48.266, 11.640],\n", "")],
        );
        let plan = MissionFile::parse(&text).unwrap().to_plan().unwrap();
        assert_eq!(
            plan.assemble().unwrap_err(),
            InvalidPlan::Areas(Reason::BadGeometry)
        );
    }

    #[test]
    fn plan_level_faults_are_left_to_validation() {
        // A broken chain and a circular fly-zone are well-formed files.
        let broken = edit(MISSION_2, &[("next = 3 ", "next = 9 ")]);
        let plan = MissionFile::parse(&broken).unwrap().to_plan().unwrap();
        assert_eq!(
            plan.assemble().unwrap_err(),
            InvalidPlan::Mission(Reason::BrokenChain)
        );
        let no_centre = edit(
            MISSION_2,
            &[(
                "[waypoints.rf_centre]\nlatitude_deg = 48.27455\nlongitude_deg = 11.66991\n\
                 turn_direction = \"clockwise\"\n",
                "",
            )],
        );
        let plan = MissionFile::parse(&no_centre).unwrap().to_plan().unwrap();
        assert_eq!(
            plan.assemble().unwrap_err(),
            InvalidPlan::Mission(Reason::MissingRfCentre)
        );
        let round_fz = edit(
            MISSION_2,
            &[
                ("area_type = \"fly-zone\"", "area_type = \"no-fly-zone\""),
                (
                    "area_type = \"no-fly-zone\"\ncircle",
                    "area_type = \"fly-zone\"\ncircle",
                ),
            ],
        );
        let plan = MissionFile::parse(&round_fz).unwrap().to_plan().unwrap();
        assert_eq!(
            plan.assemble().unwrap_err(),
            InvalidPlan::Areas(Reason::BadGeometry)
        );
    }

    #[test]
    fn the_documented_example_validates() {
        // The first `toml` block of the format's document is its complete example.
        let source = include_str!("../../docs/mission-files.md");
        let example: String = source
            .lines()
            .skip_while(|l| *l != "```toml")
            .skip(1)
            .take_while(|l| *l != "```")
            .map(|l| format!("{l}\n"))
            .collect();
        assert!(example.contains("[[areas]]"));
        let v = validated(&example);
        assert_round_trip(&plan_of(&example));
        // The example is demo mission 2 plus optional fields.
        let demo = validated(MISSION_2);
        assert_eq!(v.mission.waypoints.len(), demo.mission.waypoints.len());
        assert_eq!(v.areas.areas.len(), demo.areas.areas.len());
        for (a, b) in v.areas.areas.iter().zip(&demo.areas.areas) {
            assert_eq!(a.shape, b.shape);
        }
    }

    fn check_words<T: Word + core::fmt::Debug>(all: &[T]) {
        assert_eq!(T::WORDS.len(), all.len());
        for v in all {
            let w = word(*v);
            assert!(
                w.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
                "{w}"
            );
            assert_eq!(from_word::<T>("x", &w).unwrap(), *v);
        }
    }

    #[test]
    fn every_wire_value_has_a_kebab_case_word() {
        check_words(AltitudeType::ALL);
        check_words(SpeedType::ALL);
        check_words(TurnType::ALL);
        check_words(LegType::ALL);
        check_words(TurnDirection::ALL);
        check_words(LocationType::ALL);
        check_words(RouteType::ALL);
        check_words(AreaType::ALL);
    }
}
