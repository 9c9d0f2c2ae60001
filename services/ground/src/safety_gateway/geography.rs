//! Geographic checks (`GEO-*`, see the [module documentation](super)): the take-off point,
//! every waypoint and every leg, forward and on the reverse route, against the fly-zone and the
//! no-fly-zones with the safety offset, on the geofence.

use super::*;
use missionlink_protocol::geofence::clearance::{Clearance, clearance};
use missionlink_protocol::geofence::zone::{Zone, ZoneKind};

/// The signed margin beyond the safety offset and where, if the path violates `zone`.
fn violation(track: &Track, zone: &Zone, offset: f64) -> Option<(f64, Site)> {
    match clearance(track, zone, offset, true) {
        // A margin that is not a number is no clearance (fail closed).
        Clearance::Margin { metres, at } if metres.is_nan() || metres < offset => {
            Some((metres - offset, at))
        }
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

/// A point the aircraft passes (a waypoint) or climbs at (the take-off point), with what its
/// violations are reported on.
struct Point {
    track: Track,
    element: Element,
    /// Codes outside the fly-zone and inside a no-fly-zone.
    codes: (ViolationCode, ViolationCode),
}

impl Point {
    fn new(at: GeoPoint, element: Element, codes: (ViolationCode, ViolationCode)) -> Self {
        Self {
            track: Track::new(Path::Point(Site::of(at))),
            element,
            codes,
        }
    }

    /// The point's margin beyond the offset against every zone (+∞: clear), each violation
    /// reported as `name`'s.
    fn margins(&self, zones: &[&Zone], offset: f64, name: &str, c: &mut Collector) -> Vec<f64> {
        zones
            .iter()
            .map(|z| {
                let Some((m, at)) = violation(&self.track, z, offset) else {
                    return f64::INFINITY;
                };
                let code = code(z, self.codes.0, self.codes.1);
                let detail = format!(
                    "{name} {} the safety offset {offset} m ({})",
                    what(z),
                    describe(z)
                );
                geo_violation(c, code, self.element, m, at, detail);
                m
            })
            .collect()
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
        let margins: Vec<Vec<f64>> = mission
            .waypoints
            .iter()
            .map(|record| {
                let n = record.waypoint.waypoint_number;
                let codes = (
                    ViolationCode::FlyZoneWaypoint,
                    ViolationCode::NoFlyZoneWaypoint,
                );
                let point = Point::new(position(record), Element::Waypoint(n), codes);
                point.margins(&zones, offset, &format!("waypoint {n}"), c)
            })
            .collect();
        // The take-off point's margins, for the leg from there (index None).
        let take_off_margins = match take_off {
            Some(t) => {
                let codes = (
                    ViolationCode::FlyZoneTakeOff,
                    ViolationCode::NoFlyZoneTakeOff,
                );
                Point::new(t, Element::TakeOff, codes).margins(
                    &zones,
                    offset,
                    "the take-off point (the climb to the take-off height)",
                    c,
                )
            }
            None => vec![f64::INFINITY; zones.len()],
        };
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
                let report = |c: &mut Collector, leg: RouteElement, (m, at), also: &str| {
                    let detail = format!(
                        "{leg} {} the safety offset {offset} m ({}){also}",
                        what(z),
                        describe(z)
                    );
                    geo_violation(c, code, Element::Route(leg), m, at, detail);
                };
                let mut also = "";
                if let Some(found) = backward {
                    if forward.is_some_and(|(m, _)| (found.0 - m).abs() <= SAME_MARGIN_M) {
                        also = " (also on the reverse route)";
                    } else {
                        let reverse = RouteElement::ReverseLeg {
                            from: leg.to,
                            to: leg.from,
                        };
                        report(c, reverse, found, "");
                    }
                }
                if let Some(found) = forward {
                    report(c, leg.element, found, also);
                }
            }
        }
    }
}

/// Reports `element` violating a zone by `margin` at `at`. The paths of one turn (a fly-over's
/// turn, intercept and turn back) are one element: the turn violating a zone is one defect,
/// reported once with the worst margin of its paths and where that is.
fn geo_violation(
    c: &mut Collector,
    code: ViolationCode,
    element: Element,
    margin: f64,
    at: Site,
    detail: String,
) {
    if let Some(v) = c
        .out
        .iter_mut()
        .find(|v| v.code == code && v.element == element && v.detail == detail)
    {
        if v.margin_m.is_some_and(|m| margin < m) {
            v.margin_m = Some(margin);
            v.position = Some(earth::Position::lat_lon_deg(at));
        }
        return;
    }
    c.push(code, element, detail, None);
    if let Some(v) = c.out.last_mut() {
        v.margin_m = Some(margin);
    }
    c.at(at);
}
