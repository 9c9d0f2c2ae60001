//! The mission file's entries to and from the wire's messages (#13001, #13002, #13006, #2011,
//! #2012): every value checked by the wire types, errors with the entry's path.

use super::*;

impl RouteEntry {
    pub(super) fn to_message(&self) -> Result<UaRoute, MissionFileError> {
        Ok(UaRoute {
            time_stamp: Timestamp::default(),
            initial_waypoint: integer("route.initial_waypoint", self.initial_waypoint, 1, 65534)?,
            route_id: optional(self.route_id.as_deref(), |s| text("route.route_id", s))?,
            route_type: optional(self.route_type.as_deref(), |s| {
                from_word("route.route_type", s)
            })?,
            bidirectional: self.bidirectional,
            planning_wind: optional(self.planning_wind_mps, |mps| {
                Speed::from_mps(mps)
                    .map_err(|e| field_error("route.planning_wind_mps", e.to_string()))
            })?,
        })
    }
}

impl WaypointEntry {
    pub(super) fn to_messages(
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

    pub(super) fn from_record(record: &WaypointRecord) -> Self {
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
    pub(super) fn to_message(&self, i: usize) -> Result<AreaPolygonLoopSegment, MissionFileError> {
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

    pub(super) fn from_area(area: &AreaPolygonLoopSegment) -> Self {
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
pub(super) fn optional<T, U>(
    value: Option<T>,
    f: impl FnOnce(T) -> Result<U, MissionFileError>,
) -> Result<Option<U>, MissionFileError> {
    value.map(f).transpose()
}

/// The integer `value` as a `T`, if it lies in `min..=max`.
pub(super) fn integer<T: TryFrom<i64>>(
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

pub(super) fn activity_id(path: &str, value: i64) -> Result<U3, MissionFileError> {
    let v: u32 = integer(path, value, 0, i64::from(U3::MAX))?;
    U3::new(v).ok_or_else(|| field_error(path, format!("{value} does not fit a U3")))
}

pub(super) fn u3(v: U3) -> i64 {
    i64::from(v.get())
}

pub(super) fn text<const N: usize>(path: &str, s: &str) -> Result<Text<N>, MissionFileError> {
    Text::new(s).map_err(|e| field_error(path, format!("{s:?}: {e}")))
}

/// A TOML date-time with offset (RFC 3339) as a time stamp.
pub(super) fn timestamp(path: &str, t: &Datetime) -> Result<Timestamp, MissionFileError> {
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
pub(super) fn date_time_of(t: Timestamp) -> Datetime {
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
pub(super) fn date_time<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Datetime>, D::Error> {
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

pub(super) fn store(
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
pub(super) trait Word: Copy + PartialEq + 'static {
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

pub(super) fn word<T: Word>(value: T) -> String {
    T::WORDS
        .iter()
        .find(|(_, v)| *v == value)
        .map_or("?", |(w, _)| w)
        .to_owned()
}

pub(super) fn from_word<T: Word>(path: &str, s: &str) -> Result<T, MissionFileError> {
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
pub(super) fn one_vertex_per_line(toml: &str) -> String {
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
