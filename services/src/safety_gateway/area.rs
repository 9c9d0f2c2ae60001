//! Area geometry (`AREA-*`, see the [module documentation](super)): the areas in the local frame
//! and their checks.

use super::*;

/// An area's outline in the local frame (metres).
#[derive(Debug, Clone)]
pub(super) enum Shape {
    Polygon(Polygon),
    Circle { centre: Coord, radius: f64 },
}

/// An area in the local frame, as the geographic checks take it.
#[derive(Debug, Clone)]
pub(super) struct Zone {
    pub(super) id: u16,
    pub(super) fly_zone: bool,
    pub(super) shape: Shape,
    /// Geometry passed the area checks; geographic checks use only valid zones.
    pub(super) valid: bool,
}

impl SafetyGateway {
    /// The areas in `frame`, each checked for its geometry (violations into `c`).
    pub(super) fn zones(
        &self,
        areas: &AreaList,
        frame: &LocalFrame,
        c: &mut Collector<'_>,
    ) -> Vec<Zone> {
        let mut zones = Vec::new();
        let fly_zones: Vec<&AreaPolygonLoopSegment> = areas
            .areas
            .iter()
            .filter(|a| a.area_type == AreaType::FlyZone)
            .collect();
        match fly_zones.as_slice() {
            [] => c.push(
                ViolationCode::FlyZoneCount,
                Element::Mission,
                "no fly-zone".into(),
                Some((0.0, 1.0)),
            ),
            [_] => {}
            [_, rest @ ..] => {
                for extra in rest {
                    c.push(
                        ViolationCode::FlyZoneCount,
                        Element::Area(extra.area_id),
                        format!("a second fly-zone (area {})", extra.area_id),
                        Some((fly_zones.len() as f64, 1.0)),
                    );
                }
            }
        }
        for (n, area) in areas.areas.iter().enumerate() {
            let id = area.area_id;
            let fly_zone = area.area_type == AreaType::FlyZone;
            if let (Some(lo), Some(hi)) = (area.lower_altitude, area.upper_altitude)
                && lo.metres() > hi.metres()
            {
                c.push(
                    ViolationCode::AltitudeBounds,
                    Element::Area(id),
                    format!(
                        "lower altitude {} m above upper altitude {} m",
                        lo.metres(),
                        hi.metres()
                    ),
                    Some((lo.metres(), hi.metres())),
                );
            }
            // Only the first fly-zone is used; further ones are reported above.
            let first_fly_zone = fly_zone
                && !areas
                    .areas
                    .iter()
                    .take(n)
                    .any(|a| a.area_type == AreaType::FlyZone);
            let (shape, valid) = match &area.shape {
                AreaShape::Circle { centre, border } => {
                    let centre_xy = frame.point(centre);
                    // The radius every module gives a circle: the geodesic centre -> border.
                    let radius = earth::distance_m(*centre, *border);
                    let mut valid = true;
                    if below(radius, MIN_CIRCLE_RADIUS_M) {
                        c.push(
                            ViolationCode::CircleRadius,
                            Element::Area(id),
                            format!("circle radius {radius:.2} m"),
                            Some((radius, MIN_CIRCLE_RADIUS_M)),
                        );
                        c.at(centre_xy);
                        valid = false;
                    }
                    if fly_zone {
                        c.push(
                            ViolationCode::FlyZoneShape,
                            Element::Area(id),
                            "the fly-zone is a circle; it must be a polygon".into(),
                            None,
                        );
                        valid = false;
                    }
                    (
                        Shape::Circle {
                            centre: centre_xy,
                            radius,
                        },
                        valid,
                    )
                }
                AreaShape::Polygon(vertices) => {
                    let coords: Vec<Coord> = vertices.iter().map(|p| frame.point(p)).collect();
                    let poly = Polygon::new(LineString::from(coords.clone()), vec![]);
                    // A figure-eight has zero signed area too; its hull has not.
                    let hull_area = poly.convex_hull().unsigned_area();
                    let repeated = vertices
                        .iter()
                        .enumerate()
                        .find(|(i, p)| vertices.iter().skip(i + 1).any(|q| q == *p));
                    let valid = if let Some((i, p)) = repeated {
                        c.push(
                            ViolationCode::RepeatedVertex,
                            Element::Area(id),
                            format!("vertex {} repeated", i + 1),
                            None,
                        );
                        c.at(frame.point(p));
                        false
                    } else if !poly.is_valid() && !below(hull_area, MIN_POLYGON_AREA_M2) {
                        c.push(
                            ViolationCode::SelfIntersection,
                            Element::Area(id),
                            "the polygon's border crosses itself".into(),
                            None,
                        );
                        false
                    } else if below(hull_area, MIN_POLYGON_AREA_M2)
                        || below(poly.unsigned_area(), MIN_POLYGON_AREA_M2)
                    {
                        let area = poly.unsigned_area();
                        c.push(
                            ViolationCode::DegeneratePolygon,
                            Element::Area(id),
                            format!("polygon area {area:.2} m² (collinear vertices)"),
                            Some((area, MIN_POLYGON_AREA_M2)),
                        );
                        false
                    } else {
                        true
                    };
                    (Shape::Polygon(poly), valid)
                }
            };
            if fly_zone && !first_fly_zone {
                continue;
            }
            zones.push(Zone {
                id,
                fly_zone,
                shape,
                valid,
            });
        }
        // No-fly-zones at least partly inside the fly-zone.
        let fz = zones
            .iter()
            .find_map(|z| match (&z.shape, z.fly_zone, z.valid) {
                (Shape::Polygon(p), true, true) => Some(p.clone()),
                _ => None,
            });
        if let Some(fz) = fz {
            for z in zones.iter().filter(|z| !z.fly_zone && z.valid) {
                let (inside, gap, at) = match &z.shape {
                    Shape::Circle { centre, radius } => {
                        let d = Euclidean.distance(&Point::from(*centre), &fz);
                        (d < *radius, d - radius, *centre)
                    }
                    Shape::Polygon(p) => {
                        let at = p
                            .exterior()
                            .0
                            .first()
                            .copied()
                            .unwrap_or(Coord { x: 0.0, y: 0.0 });
                        (fz.intersects(p), Euclidean.distance(p, &fz), at)
                    }
                };
                if !inside {
                    c.push(
                        ViolationCode::NoFlyZoneOutside,
                        Element::Area(z.id),
                        format!("no-fly-zone {} lies entirely outside the fly-zone", z.id),
                        None,
                    );
                    if let Some(v) = c.out.last_mut() {
                        v.margin_m = Some(gap);
                    }
                    c.at(at);
                }
            }
        }
        zones
    }
}
