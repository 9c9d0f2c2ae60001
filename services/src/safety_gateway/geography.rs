//! Geographic checks (`GEO-*`, see the [module documentation](super)): the take-off point,
//! every waypoint and every leg, forward and on the reverse route, against the fly-zone and the
//! no-fly-zones with the safety offset, on the geofence.

use super::*;
use crate::geofence::clearance::{Clearance, clearance};
use crate::geofence::zone::{Zone, ZoneKind};

/// The signed margin beyond the safety offset and where, if the path violates `zone`.
fn violation(track: &Track, zone: &Zone, offset: f64) -> Option<(f64, Site)> {
    match clearance(track, zone, offset, true) {
        Clearance::Margin { metres, at } if metres < offset => Some((metres - offset, at)),
        _ => None,
    }
}

fn describe(z: &Zone) -> String {
    match z.kind {
        ZoneKind::FlyZone => format!("fly-zone {}", z.id),
        ZoneKind::NoFlyZone => format!("no-fly-zone {}", z.id),
    }
}

fn what(z: &Zone) -> &'static str {
    match z.kind {
        ZoneKind::FlyZone => "outside the fly-zone shrunk by",
        ZoneKind::NoFlyZone => "inside no-fly-zone grown by",
    }
}

fn code(z: &Zone, fly_zone: ViolationCode, no_fly_zone: ViolationCode) -> ViolationCode {
    match z.kind {
        ZoneKind::FlyZone => fly_zone,
        ZoneKind::NoFlyZone => no_fly_zone,
    }
}

impl SafetyGateway {
    pub(super) fn check_geography(
        &self,
        mission: &Mission,
        take_off: Option<GeoPoint>,
        fence: &Fence,
        valid: &[bool],
        legs: &[Leg],
        c: &mut Collector,
    ) {
        let offset = fence.safety_offset_m;
        let zones: Vec<&Zone> = fence
            .zones
            .iter()
            .zip(valid)
            .filter(|(_, v)| **v)
            .map(|(z, _)| z)
            .collect();
        // margins[waypoint index][zone index], beyond the offset (+∞: clear).
        let mut margins: Vec<Vec<f64>> = Vec::with_capacity(mission.waypoints.len());
        for record in &mission.waypoints {
            let n = record.waypoint.waypoint_number;
            let track = Track::new(Path::Point(Site::of(position(record))));
            let mut row = Vec::with_capacity(zones.len());
            for z in &zones {
                let found = violation(&track, z, offset);
                row.push(found.map_or(f64::INFINITY, |f| f.0));
                if let Some((m, at)) = found {
                    let code = code(
                        z,
                        ViolationCode::FlyZoneWaypoint,
                        ViolationCode::NoFlyZoneWaypoint,
                    );
                    let detail = format!(
                        "waypoint {n} {} the safety offset {offset} m ({})",
                        what(z),
                        describe(z)
                    );
                    geo_violation(c, code, Element::Waypoint(n), m, at, detail);
                }
            }
            margins.push(row);
        }
        // The take-off point's margins, for the leg from there (index None).
        let mut take_off_margins = vec![f64::INFINITY; zones.len()];
        if let Some(t) = take_off {
            let track = Track::new(Path::Point(Site::of(t)));
            for (zi, z) in zones.iter().enumerate() {
                if let Some((m, at)) = violation(&track, z, offset) {
                    if let Some(slot) = take_off_margins.get_mut(zi) {
                        *slot = m;
                    }
                    let code = code(
                        z,
                        ViolationCode::FlyZoneTakeOff,
                        ViolationCode::NoFlyZoneTakeOff,
                    );
                    let detail = format!(
                        "the take-off point (the climb to the take-off height) {} the safety offset {offset} m ({})",
                        what(z),
                        describe(z)
                    );
                    geo_violation(c, code, Element::TakeOff, m, at, detail);
                }
            }
        }
        for leg in legs {
            let track = Track::new(leg.path);
            let reverse = leg.reversible.then(|| Track::new(leg.path.reversed()));
            for (zi, z) in zones.iter().enumerate() {
                let from_margin = match leg.from_index {
                    Some(i) => margins.get(i).and_then(|row| row.get(zi)),
                    None => take_off_margins.get(zi),
                };
                let to_margin = margins.get(leg.to_index).and_then(|row| row.get(zi));
                let endpoint_margin = [from_margin, to_margin]
                    .into_iter()
                    .flatten()
                    .fold(f64::INFINITY, |a, b| a.min(*b));
                let code = code(z, ViolationCode::FlyZoneLeg, ViolationCode::NoFlyZoneLeg);
                let subsumed = |m: f64| endpoint_margin < 0.0 && m >= endpoint_margin - SUBSUMED_M;
                let forward = violation(&track, z, offset).filter(|(m, _)| !subsumed(*m));
                let backward = reverse
                    .as_ref()
                    .and_then(|r| violation(r, z, offset))
                    .filter(|(m, _)| !subsumed(*m));
                let mut reverse_detail = "";
                if let Some((rm, rat)) = backward {
                    if forward.is_some_and(|(m, _)| (rm - m).abs() <= SAME_MARGIN_M) {
                        reverse_detail = " (also on the reverse route)";
                    } else {
                        let detail = format!(
                            "reverse leg {}->{} {} the safety offset {offset} m ({})",
                            leg.to,
                            leg.from,
                            what(z),
                            describe(z)
                        );
                        let element = Element::ReverseLeg {
                            from: leg.to,
                            to: leg.from,
                        };
                        geo_violation(c, code, element, rm, rat, detail);
                    }
                }
                if let Some((m, at)) = forward {
                    let start = if leg.from == 0 {
                        "the leg from the take-off point to waypoint".to_string()
                    } else {
                        format!("leg {}->", leg.from)
                    };
                    let detail = format!(
                        "{start}{} {} the safety offset {offset} m ({}){reverse_detail}",
                        if leg.from == 0 {
                            format!(" {}", leg.to)
                        } else {
                            leg.to.to_string()
                        },
                        what(z),
                        describe(z)
                    );
                    let element = Element::Leg {
                        from: leg.from,
                        to: leg.to,
                    };
                    geo_violation(c, code, element, m, at, detail);
                }
            }
        }
    }
}

fn geo_violation(
    c: &mut Collector,
    code: ViolationCode,
    element: Element,
    margin: f64,
    at: Site,
    detail: String,
) {
    c.push(code, element, detail, None);
    if let Some(v) = c.out.last_mut() {
        v.margin_m = Some(margin);
    }
    c.at(at);
}
