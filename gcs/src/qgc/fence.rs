//! Import of the `geoFence` of a `.plan`: the fly-zone and the no-fly-zones, as the
//! [module documentation](super) says.

use super::*;

/// The areas of the `geoFence`: the inclusion polygon as the fly-zone, then the exclusion
/// polygons and circles as no-fly-zones; what the ICD cannot carry or the FCC cannot hold goes to
/// `dropped`.
pub(super) fn import_fence(
    root: &At<'_>,
    dropped: &mut Vec<Dropped>,
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
