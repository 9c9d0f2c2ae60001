//! Export of a validated plan as a `.plan` that QGroundControl reads, as the
//! [module documentation](super) says.

use super::*;

/// The `.plan` file of a validated plan and what it cannot hold (see the
/// [module documentation](crate::qgc)).
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
        // Frame 0 is above mean sea level: a WGS-84 height less the geoid's undulation there.
        let alt = match w.altitude_type {
            Some(AltitudeType::Wgs84) => {
                amsl_metres(w.altitude, w.latitude.degrees(), w.longitude.degrees())
            }
            _ => metres(w.altitude),
        };
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
