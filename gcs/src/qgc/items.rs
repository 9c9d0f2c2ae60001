//! Import of the mission items of a `.plan`: take-off, waypoints, land, speed changes and their
//! altitude frames, as the [module documentation](super) says.

use super::*;

/// A waypoint being imported.
pub(super) struct Pending {
    pub(super) position: GeoPoint,
    pub(super) altitude: Altitude,
    pub(super) altitude_type: AltitudeType,
    pub(super) speed: Speed,
    pub(super) speed_type: Option<SpeedType>,
    pub(super) turn_type: TurnType,
}

/// MAV_TYPEs that QGC plans with `hoverSpeed` (`QGCMAVLink::isMultiRotor`).
pub(super) const MULTI_ROTOR_TYPES: [u64; 8] = [2, 3, 4, 13, 14, 15, 29, 35];

/// The take-off, waypoints and route of the mission items, and the take-off item's position
/// (if it has one); what they hold that the ICD cannot carry goes to `dropped`.
pub(super) fn import_items(
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
                let value = wgs84_of_global(value, kind, position);
                let hold = params.at(0)?.opt_number()?.unwrap_or(0.0);
                let turn_type = if hold > 0.0 {
                    dropped.push(note(
                        &params.at(0)?.path,
                        format!(
                            "hold {hold} s is not supported: the FCC flies through its \
                             waypoints and stops at none (the ICD has no hold time; without \
                             the hold the waypoint is fly-over)"
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
                        let value = wgs84_of_global(value, kind, position);
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
                planning_wind: None,
            }
            .into(),
        ),
    )?;
    Ok((buffer, take_off_position))
}

/// The 7 params of a simple item.
pub(super) struct Params<'a> {
    pub(super) at: At<'a>,
    pub(super) values: Vec<At<'a>>,
}

impl<'a> Params<'a> {
    pub(super) fn of(item: &At<'a>) -> Result<Self, MissionFileError> {
        let at = item.field("params")?;
        let values = at.items()?;
        if values.len() != 7 {
            return Err(at.error(format!("{} values, expected 7", values.len())));
        }
        Ok(Self { at, values })
    }

    pub(super) fn at(&self, k: usize) -> Result<&At<'a>, MissionFileError> {
        self.values
            .get(k)
            .ok_or_else(|| self.at.error(format!("no value {k}")))
    }

    /// Params 5 and 6 (indices 4, 5); `None` when both are null or 0 (no position).
    pub(super) fn position(&self) -> Result<Option<GeoPoint>, MissionFileError> {
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

/// A waypoint's altitude of a global frame, above mean sea level, as the WGS-84 height the
/// FCC flies at its position ([`crate::geoid`]); other altitudes as they are.
fn wgs84_of_global(value: f64, kind: AltitudeType, position: GeoPoint) -> f64 {
    match kind {
        AltitudeType::Wgs84 => crate::geoid::wgs84_from_amsl(
            value,
            position.latitude.degrees(),
            position.longitude.degrees(),
        ),
        _ => value,
    }
}

/// The altitude of a take-off, waypoint or land and its type by the item's frame; `None` (and
/// the item in `dropped`) for a frame that is not supported. A global frame's altitude is above
/// mean sea level, typed [`AltitudeType::Wgs84`]: a waypoint's becomes its WGS-84 height by
/// [`wgs84_of_global`]; a take-off's is compared with the home's, also above mean sea level.
pub(super) fn item_altitude(
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

pub(super) fn speed_value(at: &At<'_>) -> Result<Speed, MissionFileError> {
    let mps = at.number()?;
    let speed = Speed::from_mps(mps).map_err(|e| at.error(e.to_string()))?;
    if speed.raw() == 0 {
        return Err(at.error(format!(
            "{mps} m/s is 0 on the wire (steps of 0.5 m/s); the speed must be above 0"
        )));
    }
    Ok(speed)
}
