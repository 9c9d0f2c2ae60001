//! Area geometry (`AREA-*`, see the [module documentation](super)): the rules of ICD §7 and a
//! few more, on the list as the plan holds it, each defect naming its area.

use super::*;
use missionlink_protocol::geofence::clearance::{Clearance, clearance, crosses};
use missionlink_protocol::geofence::zone::Zone;
use missionlink_protocol::geofence::zone::{ZoneDefect, ZoneKind};

impl SafetyGateway {
    /// Checks the areas' geometry (violations into `c`); returns, for each zone of `fence`,
    /// whether the geographic checks may use it.
    pub(super) fn check_areas(
        &self,
        areas: &AreaList,
        fence: &Fence,
        c: &mut Collector,
    ) -> Vec<bool> {
        let fly_zones: Vec<u16> = areas
            .areas
            .iter()
            .filter(|a| a.area_type == AreaType::FlyZone)
            .map(|a| a.area_id)
            .collect();
        let no_fly_zones: Vec<u16> = areas
            .areas
            .iter()
            .filter(|a| a.area_type == AreaType::NoFlyZone)
            .map(|a| a.area_id)
            .collect();
        if fly_zones.is_empty() {
            c.push(
                ViolationCode::FlyZoneCount,
                Element::AreaList,
                if no_fly_zones.is_empty() {
                    "no fly-zone: the list has no area to stay in".to_string()
                } else {
                    format!(
                        "no fly-zone: the list has no-fly-zones {no_fly_zones:?} and no area to stay in"
                    )
                },
                Some((0.0, 1.0)),
            );
        }
        for extra in fly_zones.iter().skip(1) {
            c.push(
                ViolationCode::FlyZoneCount,
                Element::Area(*extra),
                format!("a second fly-zone (area {extra}); a list has exactly one"),
                Some((fly_zones.len() as f64, 1.0)),
            );
        }
        if no_fly_zones.len() > MAX_NO_FLY_ZONES {
            c.push(
                ViolationCode::NoFlyZoneCount,
                Element::AreaList,
                format!(
                    "{} no-fly-zones; the FCC holds at most {MAX_NO_FLY_ZONES}",
                    no_fly_zones.len()
                ),
                Some((no_fly_zones.len() as f64, MAX_NO_FLY_ZONES as f64)),
            );
        }
        let mut valid = Vec::with_capacity(fence.zones.len());
        for (area, zone) in areas.areas.iter().zip(&fence.zones) {
            let id = area.area_id;
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
            let used = area.area_type == AreaType::NoFlyZone || fly_zones.first() == Some(&id);
            let mut ok = used;
            if let AreaShape::Circle { centre, .. } = &area.shape {
                let radius = zone.radius_m().unwrap_or(0.0);
                if below(radius, MIN_CIRCLE_RADIUS_M) {
                    c.push(
                        ViolationCode::CircleRadius,
                        Element::Area(id),
                        format!("circle radius {radius:.2} m"),
                        Some((radius, MIN_CIRCLE_RADIUS_M)),
                    );
                    c.at(*centre);
                    ok = false;
                }
                if area.area_type == AreaType::FlyZone {
                    c.push(
                        ViolationCode::FlyZoneShape,
                        Element::Area(id),
                        "the fly-zone is a circle; it must be a polygon".into(),
                        None,
                    );
                    ok = false;
                }
            }
            if let AreaShape::Polygon(vertices) = &area.shape {
                ok &= self.check_polygon(id, zone, vertices, c);
            }
            valid.push(ok);
        }
        self.check_no_fly_zones_inside(fence, &valid, c);
        valid
    }

    /// A polygon's defects (ICD §7), then its area; whether it is usable.
    fn check_polygon(
        &self,
        id: u16,
        zone: &Zone,
        vertices: &[GeoPoint],
        c: &mut Collector,
    ) -> bool {
        let vertex = |i: usize| vertices.get(i).copied();
        let area = zone.area_m2();
        // Collinear vertices fold the border onto itself; that is said as what it is.
        let defect = match zone.defect() {
            Some(ZoneDefect::SelfIntersection { .. })
                if below(zone.spread_m2(), 2.0 * MIN_POLYGON_AREA_M2) =>
            {
                None
            }
            defect => defect,
        };
        match defect {
            Some(ZoneDefect::TooFewVertices(n)) => {
                c.push(
                    ViolationCode::VertexCount,
                    Element::Area(id),
                    format!("a polygon of {n} vertices; at least 3"),
                    Some((n as f64, 3.0)),
                );
                if let Some(p) = vertex(0) {
                    c.at(p);
                }
                false
            }
            Some(ZoneDefect::RepeatedVertex(i)) => {
                c.push(
                    ViolationCode::RepeatedVertex,
                    Element::Area(id),
                    format!("vertex {} repeats an earlier vertex", i + 1),
                    None,
                );
                if let Some(p) = vertex(i) {
                    c.at(p);
                }
                false
            }
            Some(ZoneDefect::SelfIntersection { first, second, at }) => {
                c.push(
                    ViolationCode::SelfIntersection,
                    Element::Area(id),
                    format!(
                        "the border crosses itself: the edge from vertex {} meets the edge from vertex {}",
                        first + 1,
                        second + 1
                    ),
                    None,
                );
                c.at(Site::new(at.0, at.1));
                false
            }
            Some(ZoneDefect::ZeroRadius) => false,
            None => {
                if below(area, MIN_POLYGON_AREA_M2) {
                    c.push(
                        ViolationCode::DegeneratePolygon,
                        Element::Area(id),
                        format!("polygon area {area:.2} m² (collinear vertices)"),
                        Some((area, MIN_POLYGON_AREA_M2)),
                    );
                    false
                } else {
                    true
                }
            }
        }
    }

    /// Each usable no-fly-zone at least partly inside the usable fly-zone.
    fn check_no_fly_zones_inside(&self, fence: &Fence, valid: &[bool], c: &mut Collector) {
        let usable = || {
            fence
                .zones
                .iter()
                .zip(valid)
                .filter(|(_, v)| **v)
                .map(|(z, _)| z)
        };
        let Some(fz) = usable().find(|z| z.kind == ZoneKind::FlyZone) else {
            return;
        };
        for z in usable().filter(|z| z.kind == ZoneKind::NoFlyZone) {
            // A no-fly-zone overlaps the fly-zone when a vertex of either lies inside the
            // other, their borders cross, or (a circle) its centre is within its radius of the
            // fly-zone.
            let inside = |p: Site, zone: &Zone| {
                clearance(&Track::new(Path::Point(p)), zone, f64::INFINITY, true).metres()
            };
            let overlaps = match z.radius_m() {
                Some(r) => z.vertices().any(|centre| inside(centre, fz) > -r),
                None => {
                    z.vertices().any(|v| inside(v, fz) > 0.0)
                        || fz.vertices().any(|v| inside(v, z) < 0.0)
                        || z.edges().any(|e| crosses(&Track::new(e), fz))
                }
            };
            if !overlaps {
                // How far outside: the closest vertex (or the circle's border).
                let (gap, at) = z
                    .vertices()
                    .map(|v| {
                        let m =
                            match clearance(&Track::new(Path::Point(v)), fz, f64::INFINITY, true) {
                                Clearance::Margin { metres, .. } => -metres,
                                _ => f64::INFINITY,
                            };
                        (m - z.radius_m().unwrap_or(0.0), Some(v))
                    })
                    .fold(
                        (f64::INFINITY, None),
                        |best, x| if x.0 < best.0 { x } else { best },
                    );
                c.push(
                    ViolationCode::NoFlyZoneOutside,
                    Element::Area(z.id),
                    format!("no-fly-zone {} lies entirely outside the fly-zone", z.id),
                    None,
                );
                if let Some(v) = c.out.last_mut() {
                    v.margin_m = Some(gap);
                }
                if let Some(at) = at {
                    c.at(at);
                }
            }
        }
    }
}
