//! Geographic checks (`GEO-*`, see the [module documentation](super)): waypoints, legs and the
//! take-off against the fly-zone and the no-fly-zones, with the safety offset.

use super::area::{Shape, Zone};
use super::*;

/// Signed closest approach of a path to a zone's forbidden side, before the safety offset:
/// positive = clear by that much. With the point where it is reached.
fn zone_margin(zone: &Zone, path: &[Coord]) -> (f64, Coord) {
    let ls = LineString::from(path.to_vec());
    let fallback = path.first().copied().unwrap_or(Coord { x: 0.0, y: 0.0 });
    match (&zone.shape, zone.fly_zone) {
        (Shape::Circle { centre, radius }, false) => {
            let c = Point::from(*centre);
            let (d, at) = if path.len() < 2 {
                (Euclidean.distance(&c, &Point::from(fallback)), fallback)
            } else {
                let at = match ls.closest_point(&c) {
                    Closest::Intersection(p) | Closest::SinglePoint(p) => p.0,
                    Closest::Indeterminate => fallback,
                };
                (Euclidean.distance(&c, &ls), at)
            };
            (d - radius, at)
        }
        (Shape::Polygon(poly), false) => {
            let inside = if path.len() < 2 {
                poly.intersects(&fallback)
            } else {
                poly.intersects(&ls)
            };
            let samples = sample(path);
            if inside {
                // Depth: the deepest sample inside, by its distance to the border.
                let ring = poly.exterior();
                let (depth, at) = samples
                    .iter()
                    .filter(|c| poly.contains(*c))
                    .map(|c| (Euclidean.distance(&Point::from(*c), ring), *c))
                    .fold(
                        (0.0, fallback),
                        |best, x| if x.0 > best.0 { x } else { best },
                    );
                (-depth, at)
            } else {
                let d = if path.len() < 2 {
                    Euclidean.distance(&Point::from(fallback), poly)
                } else {
                    Euclidean.distance(&ls, poly)
                };
                (
                    d,
                    argmin(&samples, |c| Euclidean.distance(&Point::from(*c), poly)),
                )
            }
        }
        (Shape::Polygon(poly), true) => {
            let ring = poly.exterior();
            let contained = if path.len() < 2 {
                poly.contains(&fallback)
            } else {
                poly.contains(&ls)
            };
            let samples = sample(path);
            let signed = |c: &Coord| {
                let d = Euclidean.distance(&Point::from(*c), ring);
                if poly.contains(c) { d } else { -d }
            };
            let at = argmin(&samples, signed);
            if contained {
                let d = if path.len() < 2 {
                    Euclidean.distance(&Point::from(fallback), ring)
                } else {
                    Euclidean.distance(&ls, ring)
                };
                (d, at)
            } else {
                (signed(&at).min(0.0), at)
            }
        }
        // A circular fly-zone is reported as an area violation and not used.
        (Shape::Circle { .. }, true) => (f64::INFINITY, fallback),
    }
}

fn argmin(samples: &[Coord], f: impl Fn(&Coord) -> f64) -> Coord {
    samples
        .iter()
        .map(|c| (f(c), *c))
        .fold(None, |best: Option<(f64, Coord)>, x| match best {
            Some(b) if b.0 <= x.0 => Some(b),
            _ => Some(x),
        })
        .map(|(_, c)| c)
        .unwrap_or(Coord { x: 0.0, y: 0.0 })
}

/// The path with extra points so that no two are more than [`SAMPLE_STEP_M`] apart.
fn sample(path: &[Coord]) -> Vec<Coord> {
    if path.len() < 2 {
        return path.to_vec();
    }
    let ls = LineString::from(path.to_vec());
    let length = Euclidean.length(&ls);
    // Very long paths are sampled more coarsely rather than without bound.
    let step = SAMPLE_STEP_M.max(length / 200_000.0);
    Euclidean.densify(&ls, step).0
}

impl SafetyGateway {
    pub(super) fn check_geography(
        &self,
        mission: &Mission,
        offset: f64,
        zones: &[Zone],
        legs: &[Leg],
        c: &mut Collector<'_>,
    ) {
        let zones: Vec<&Zone> = zones.iter().filter(|z| z.valid).collect();
        let describe = |z: &Zone| {
            if z.fly_zone {
                format!("fly-zone {}", z.id)
            } else {
                format!("no-fly-zone {}", z.id)
            }
        };
        let what = |z: &Zone| {
            if z.fly_zone {
                "outside the fly-zone shrunk by"
            } else {
                "inside no-fly-zone grown by"
            }
        };
        // margins[waypoint index][zone index]
        let mut margins: Vec<Vec<f64>> = Vec::with_capacity(mission.waypoints.len());
        for record in &mission.waypoints {
            let n = record.waypoint.waypoint_number;
            let here = c.frame.point(&position(record));
            let mut row = Vec::with_capacity(zones.len());
            for z in &zones {
                let (m, at) = zone_margin(z, &[here]);
                let m = m - offset;
                row.push(m);
                if m < 0.0 {
                    let code = if z.fly_zone {
                        ViolationCode::FlyZoneWaypoint
                    } else {
                        ViolationCode::NoFlyZoneWaypoint
                    };
                    self.geo_violation(
                        c,
                        code,
                        Element::Waypoint(n),
                        m,
                        at,
                        format!(
                            "waypoint {n} {} the safety offset {offset} m ({})",
                            what(z),
                            describe(z)
                        ),
                    );
                }
            }
            margins.push(row);
        }
        if let Some((lat, lon)) = self.take_off_position_deg {
            let here = c.frame.xy(lat, lon);
            for z in &zones {
                let (m, at) = zone_margin(z, &[here]);
                let m = m - offset;
                if m < 0.0 {
                    let code = if z.fly_zone {
                        ViolationCode::FlyZoneTakeOff
                    } else {
                        ViolationCode::NoFlyZoneTakeOff
                    };
                    self.geo_violation(
                        c,
                        code,
                        Element::TakeOff,
                        m,
                        at,
                        format!(
                            "take-off point {} the safety offset {offset} m ({})",
                            what(z),
                            describe(z)
                        ),
                    );
                }
            }
        }
        for leg in legs {
            for (zi, z) in zones.iter().enumerate() {
                let endpoint_margin = [leg.from_index, Some(leg.to_index)]
                    .iter()
                    .flatten()
                    .filter_map(|i| margins.get(*i).and_then(|row| row.get(zi)))
                    .fold(f64::INFINITY, |a, b| a.min(*b));
                let code = if z.fly_zone {
                    ViolationCode::FlyZoneLeg
                } else {
                    ViolationCode::NoFlyZoneLeg
                };
                let subsumed = |m: f64| endpoint_margin < 0.0 && m >= endpoint_margin - SUBSUMED_M;
                let (m, at) = zone_margin(z, &leg.path);
                let m = m - offset;
                let forward = m < 0.0 && !subsumed(m);
                let reverse = leg.reverse_path.as_ref().map(|p| {
                    let (rm, rat) = zone_margin(z, p);
                    (rm - offset, rat)
                });
                let mut reverse_detail = "";
                if let Some((rm, rat)) = reverse
                    && rm < 0.0
                    && !subsumed(rm)
                {
                    if forward && (rm - m).abs() <= SAME_MARGIN_M {
                        reverse_detail = " (also on the reverse route)";
                    } else {
                        self.geo_violation(
                            c,
                            code,
                            Element::ReverseLeg {
                                from: leg.to,
                                to: leg.from,
                            },
                            rm,
                            rat,
                            format!(
                                "reverse leg {}->{} {} the safety offset {offset} m ({})",
                                leg.to,
                                leg.from,
                                what(z),
                                describe(z)
                            ),
                        );
                    }
                }
                if forward {
                    self.geo_violation(
                        c,
                        code,
                        Element::Leg {
                            from: leg.from,
                            to: leg.to,
                        },
                        m,
                        at,
                        format!(
                            "leg {}->{} {} the safety offset {offset} m ({}){reverse_detail}",
                            leg.from,
                            leg.to,
                            what(z),
                            describe(z)
                        ),
                    );
                }
            }
        }
    }

    pub(super) fn geo_violation(
        &self,
        c: &mut Collector<'_>,
        code: ViolationCode,
        element: Element,
        margin: f64,
        at: Coord,
        detail: String,
    ) {
        c.push(code, element, detail, None);
        if let Some(v) = c.out.last_mut() {
            v.margin_m = Some(margin);
        }
        c.at(at);
    }
}
