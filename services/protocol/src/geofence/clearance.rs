//! How far a path stays from a zone's border, on which side (ICD §7): the signed margin with
//! the position of the closest approach, or of the deepest point on the forbidden side.
//!
//! - A circle: the path's closest approach to the centre, found in the path's planes and then
//!   measured exactly along the geodesic from the centre; margin = that distance − radius
//!   (inside a no-fly circle, the deepest point is the closest to the centre).
//! - A polygon: the closest approach between the path's chords and the border's pieces in the
//!   path's planes (see [`super::plane`] for how exact that is), whether any of them cross, and,
//!   when none does, on which side the path's first point lies (the parity of the border pieces
//!   a ray towards north crosses). When the path is on the forbidden side somewhere, the depth is
//!   the largest distance to the border of its points on that side: sampled along every chord
//!   ([`DEPTH_SAMPLES`] per piece of a geodesic) and refined by golden-section search about the
//!   deepest sample, to well under a centimetre where the depth function is smooth.
//!
//! Margins are before the safety offset: the caller compares them with it (a zone grown or
//! shrunk by the offset is the zone whose margin is the offset). Everything farther than the
//! horizon the caller gives is only known to be farther ([`Clearance::Beyond`]), which is what
//! keeps the onboard check fast: most of the border is culled by one ball test.

use geo::Coord;

use super::earth::Site;
use super::path::Track;
use super::plane::{Plane, point_segment, segment_segment};
use super::zone::{Ball, GROUP, Shape, Zone, ZoneKind};

/// Samples along each chord of a geodesic piece for the depth of a violation.
pub const DEPTH_SAMPLES: usize = 64;
/// Samples about each place a path meets a polygon's border, for the depth of a short cut.
const CROSSING_SAMPLES: usize = 64;
/// A path closer than this to a border meets it (a touch counts as a crossing: the safe side).
const CONTACT_M: f64 = 0.001;
/// Places a path meets a polygon's border kept for the depth search.
const MAX_CROSSINGS: usize = 32;

/// Where a path meets a polygon's border: the chord (in its patch's plane) and the parameter.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    patch: usize,
    p: Coord,
    q: Coord,
    t: f64,
}

type Crossings = heapless::Vec<Crossing, MAX_CROSSINGS>;

/// Golden-section steps refining the deepest sample (each shrinks the interval by 0.618).
const GOLDEN_STEPS: usize = 40;

/// How a path stands to a zone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clearance {
    /// On the allowed side everywhere and farther than the horizon from the border.
    Beyond,
    /// The signed margin in metres: positive, the path stays that far on the allowed side at
    /// its closest approach (`at`); negative, it goes that deep onto the forbidden side at its
    /// deepest point (`at`).
    Margin {
        /// Metres, signed.
        metres: f64,
        /// Where.
        at: Site,
    },
    /// On the forbidden side somewhere (the depth was not asked for).
    Forbidden,
}

impl Clearance {
    /// The margin, `+∞` for [`Clearance::Beyond`] and `-∞` for [`Clearance::Forbidden`].
    pub fn metres(&self) -> f64 {
        match self {
            Self::Beyond => f64::INFINITY,
            Self::Margin { metres, .. } => *metres,
            Self::Forbidden => f64::NEG_INFINITY,
        }
    }
}

/// The closest approach found so far: distance, patch and point in its plane.
#[derive(Debug, Clone, Copy)]
struct Closest {
    distance: f64,
    patch: usize,
    at: Coord,
}

/// How `track` stands to `zone`; `horizon_m` bounds how far the border is looked for on the
/// allowed side; `depth` asks for the depth of a violation (else [`Clearance::Forbidden`]).
pub fn clearance(track: &Track, zone: &Zone, horizon_m: f64, depth: bool) -> Clearance {
    match &zone.shape {
        Shape::Circle { centre, radius_m } => {
            circle(track, zone, centre, *radius_m, horizon_m, depth)
        }
        Shape::Polygon { .. } => polygon(track, zone, horizon_m, depth),
    }
}

fn circle(
    track: &Track,
    zone: &Zone,
    centre: &Site,
    radius_m: f64,
    horizon_m: f64,
    depth: bool,
) -> Clearance {
    let mut best: Option<Closest> = None;
    let mut farthest: f64 = 0.0;
    for (i, patch) in track.patches.iter().enumerate() {
        if zone.kind == ZoneKind::NoFlyZone && zone.ball.gap(&patch.ball) > horizon_m {
            continue;
        }
        let c = patch.plane.xy(centre);
        for (a, b) in chords(track.corners_of(patch)) {
            let (d, t) = point_segment(c, a, b);
            for end in [a, b] {
                farthest = farthest.max((end - c).x.hypot((end - c).y));
            }
            if best.is_none_or(|x| d < x.distance) {
                best = Some(Closest {
                    distance: d,
                    patch: i,
                    at: a + (b - a) * t,
                });
            }
        }
    }
    let Some(best) = best else {
        return Clearance::Beyond;
    };
    let Some(patch) = track.patches.get(best.patch) else {
        return Clearance::Beyond;
    };
    // The distance to the centre may be long: measure it along the geodesic.
    let at = Track::site_at(patch, best.at);
    let closest = centre.inverse(&at).0;
    let metres = match zone.kind {
        ZoneKind::NoFlyZone => closest - radius_m,
        // Not a zone ICD §7 allows; checked as what it says: stay within the radius.
        ZoneKind::FlyZone => radius_m - farthest,
    };
    if metres > horizon_m {
        Clearance::Beyond
    } else if metres < 0.0 && !depth {
        Clearance::Forbidden
    } else {
        Clearance::Margin { metres, at }
    }
}

/// Whether `track` crosses or touches the border of the polygon `zone` (false for a circle).
pub fn crosses(track: &Track, zone: &Zone) -> bool {
    matches!(zone.shape, Shape::Polygon { .. }) && !contact(track, zone, 0.0).1.is_empty()
}

fn polygon(track: &Track, zone: &Zone, horizon_m: f64, depth: bool) -> Clearance {
    let (best, crossings) = contact(track, zone, horizon_m);
    let allowed_inside = zone.kind == ZoneKind::FlyZone;
    // Which side the path is on, when it does not meet the border: the side of its first
    // point. A path that crosses comes within rounding (far below CONTACT_M) of a border piece
    // at some chord, and no ball or box test culls a distance of 0, so `crossings` has it.
    let start_forbidden = track.patches.first().is_some_and(|p| {
        let start = track
            .corners_of(p)
            .first()
            .copied()
            .unwrap_or(Coord { x: 0.0, y: 0.0 });
        // The path's start as given (no geodesic to solve per zone): outside the zone's ball,
        // it is outside the zone.
        let ball = Ball {
            centre: track.start().ecef,
            radius: 0.0,
        };
        let inside = zone.ball.gap(&ball) <= 0.0 && zone.polygon_contains(&p.plane, start);
        inside != allowed_inside
    });
    let forbidden = !crossings.is_empty() || start_forbidden;
    if !forbidden {
        return match best {
            // Not a number (a site that is not one) is not "beyond": the caller fails closed.
            Some(b) if b.distance <= horizon_m || b.distance.is_nan() => {
                match track.patches.get(b.patch) {
                    Some(patch) => Clearance::Margin {
                        metres: b.distance,
                        at: Track::site_at(patch, b.at),
                    },
                    None => Clearance::Beyond,
                }
            }
            _ => Clearance::Beyond,
        };
    }
    if !depth {
        return Clearance::Forbidden;
    }
    let (metres, at) = deepest(track, zone, allowed_inside, &crossings);
    // On the forbidden side is never a margin of 0 or more, however shallow (a grazing cut
    // deeper than nothing the samples saw): with a safety offset of 0 it must still violate.
    Clearance::Margin {
        metres: -metres.max(f64::MIN_POSITIVE),
        at,
    }
}

/// The chords between consecutive corners; a single corner (a point) as a chord of length 0.
fn chords(corners: &[Coord]) -> impl Iterator<Item = (Coord, Coord)> + '_ {
    let single = match corners {
        [p] => Some((*p, *p)),
        _ => None,
    };
    corners
        .windows(2)
        .filter_map(|w| match w {
            [p, q] => Some((*p, *q)),
            _ => None,
        })
        .chain(single)
}

/// The closest approach of `track` to the polygon's border within `horizon_m`, and whether
/// they cross or touch.
fn contact(track: &Track, zone: &Zone, horizon_m: f64) -> (Option<Closest>, Crossings) {
    let (border, balls, groups) = zone.border();
    let mut best: Option<Closest> = None;
    let mut crossings = Crossings::new();
    // Only what can come closer than the horizon, or than the closest approach found, counts;
    // the balls of the zone, of groups of pieces and of each piece cull the rest in one test.
    let reach = |best: &Option<Closest>| best.map_or(horizon_m, |b| b.distance.min(horizon_m));
    for (i, patch) in track.patches.iter().enumerate() {
        if zone.ball.gap(&patch.ball) > reach(&best) {
            continue;
        }
        let corners = track.corners_of(patch);
        for (g, group) in groups.iter().enumerate() {
            if group.gap(&patch.ball) > reach(&best) {
                continue;
            }
            for k in g * GROUP..((g + 1) * GROUP).min(border.len()) {
                let (Some(ball), Some(a), Some(b)) = (
                    balls.get(k),
                    border.get(k),
                    border.get((k + 1) % border.len()),
                ) else {
                    continue;
                };
                if ball.gap(&patch.ball) > reach(&best) {
                    continue;
                }
                let (pa, pb) = (patch.plane.xy(a), patch.plane.xy(b));
                for (p, q) in chords(corners) {
                    // A chord whose box is farther from the piece's box than the reach cannot
                    // come closer (the many chords of an arc, mostly).
                    let r = reach(&best);
                    if p.x.min(q.x) > pa.x.max(pb.x) + r
                        || p.x.max(q.x) < pa.x.min(pb.x) - r
                        || p.y.min(q.y) > pa.y.max(pb.y) + r
                        || p.y.max(q.y) < pa.y.min(pb.y) - r
                    {
                        continue;
                    }
                    let meet = segment_segment(p, q, pa, pb);
                    if meet.distance <= CONTACT_M {
                        // Where the path meets the border: the depth is looked for about here
                        // too. Beyond the capacity the first ones are enough to know it meets.
                        let _ = crossings.push(Crossing {
                            patch: i,
                            p,
                            q,
                            t: meet.t,
                        });
                    }
                    if best.is_none_or(|x| meet.distance < x.distance) {
                        best = Some(Closest {
                            distance: meet.distance,
                            patch: i,
                            at: p + (q - p) * meet.t,
                        });
                    }
                }
            }
        }
    }
    (best, crossings)
}

/// Distance from `p` (in `plane`) to the polygon's border, or 0 when `p` is on the allowed side.
fn depth_at(zone: &Zone, plane: &Plane, p: Coord, allowed_inside: bool) -> f64 {
    if zone.polygon_contains(plane, p) == allowed_inside {
        return 0.0;
    }
    zone.pieces()
        .map(|(a, b)| point_segment(p, plane.xy(a), plane.xy(b)).0)
        .fold(f64::INFINITY, f64::min)
}

/// The deepest point of the path on the polygon's forbidden side: its depth and site.
fn deepest(track: &Track, zone: &Zone, allowed_inside: bool, crossings: &Crossings) -> (f64, Site) {
    // The chords of the path in order, each with its patch and its sampling step.
    let all_chords = || {
        track.patches.iter().flat_map(move |patch| {
            let corners = track.corners_of(patch);
            chords(corners).map(move |(p, q)| (patch, p, q, chord_samples(track, patch)))
        })
    };
    // The deepest sample: (depth, chord index, parameter).
    let mut best: Option<(f64, usize, f64)> = None;
    for (c, (patch, p, q, samples)) in all_chords().enumerate() {
        for k in 0..=samples {
            let t = k as f64 / samples as f64;
            let d = depth_at(zone, &patch.plane, p + (q - p) * t, allowed_inside);
            if best.is_none_or(|b| d > b.0) {
                best = Some((d, c, t));
            }
        }
    }
    // A short cut into the zone may fall between two samples: sample densely about every
    // place the path meets the border too (two sampling steps either side).
    let mut near_crossing: Option<(f64, &Crossing, f64)> = None;
    for x in crossings {
        let Some(patch) = track.patches.get(x.patch) else {
            continue;
        };
        let step = 1.0 / chord_samples(track, patch) as f64;
        let (lo, hi) = ((x.t - 2.0 * step).max(0.0), (x.t + 2.0 * step).min(1.0));
        for k in 0..=CROSSING_SAMPLES {
            let t = lo + (hi - lo) * k as f64 / CROSSING_SAMPLES as f64;
            let d = depth_at(zone, &patch.plane, x.p + (x.q - x.p) * t, allowed_inside);
            if near_crossing.is_none_or(|b| d > b.0) {
                near_crossing = Some((d, x, t));
            }
        }
    }
    let Some((d, c, t)) = best else {
        return (0.0, Site::new(0.0, 0.0));
    };
    if let Some((dx, x, tx)) = near_crossing
        && dx > d
        && let Some(patch) = track.patches.get(x.patch)
    {
        let step = 4.0 / (chord_samples(track, patch) * CROSSING_SAMPLES) as f64;
        let f = |t: f64| depth_at(zone, &patch.plane, x.p + (x.q - x.p) * t, allowed_inside);
        let (xt, fx) = golden_maximum(f, (tx - step).max(0.0), (tx + step).min(1.0));
        let (d, t) = if fx > dx { (fx, xt) } else { (dx, tx) };
        return (d, Track::site_at(patch, x.p + (x.q - x.p) * t));
    }
    // The deepest point lies within a sampling step of the deepest sample: on its chord, or,
    // when that sample ends its chord, on the neighbouring chord (pieces meet there).
    let mut deepest = (
        d,
        all_chords()
            .nth(c)
            .map(|(patch, p, q, _)| (patch, p + (q - p) * t)),
    );
    let mut brackets: [Option<(usize, f64, f64)>; 3] = [None; 3];
    if let Some((_, _, _, samples)) = all_chords().nth(c) {
        let step = 1.0 / samples as f64;
        brackets[0] = Some((c, (t - step).max(0.0), (t + step).min(1.0)));
    }
    if t <= 0.0 && c > 0 {
        if let Some((_, _, _, samples)) = all_chords().nth(c - 1) {
            brackets[1] = Some((c - 1, 1.0 - 1.0 / samples as f64, 1.0));
        }
    }
    if t >= 1.0 {
        if let Some((_, _, _, samples)) = all_chords().nth(c + 1) {
            brackets[2] = Some((c + 1, 0.0, 1.0 / samples as f64));
        }
    }
    for (c, lo, hi) in brackets.into_iter().flatten() {
        let Some((patch, p, q, _)) = all_chords().nth(c) else {
            continue;
        };
        let f = |t: f64| depth_at(zone, &patch.plane, p + (q - p) * t, allowed_inside);
        let (x, fx) = golden_maximum(f, lo, hi);
        if fx > deepest.0 {
            deepest = (fx, Some((patch, p + (q - p) * x)));
        }
    }
    match deepest {
        (d, Some((patch, at))) => (d, Track::site_at(patch, at)),
        (d, None) => (d, Site::new(0.0, 0.0)),
    }
}

/// Samples along each chord of `patch` for the depth: many along a geodesic piece, the ends
/// along an arc's short chords.
fn chord_samples(track: &Track, patch: &super::path::Patch) -> usize {
    if track.corners_of(patch).len() > 2 {
        2
    } else {
        DEPTH_SAMPLES
    }
}

/// Golden-section search for the largest value of `f` on `[lo, hi]` (unimodal there): the
/// best of the two last probes.
fn golden_maximum(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_STEPS {
        if f1 > f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 > f2 { (x1, f1) } else { (x2, f2) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geofence::path::Path;
    use missionlink_interfaces::wire::{Angle, GeoPoint};

    fn wire(s: Site) -> GeoPoint {
        GeoPoint {
            latitude: Angle::from_degrees(s.lat).unwrap(),
            longitude: Angle::from_degrees(s.lon).unwrap(),
        }
    }

    /// A no-fly triangle whose tip cuts a 19 km leg between two depth samples (found in
    /// review: the depth came out 0, and with a safety offset of 0 the leg passed). The depth
    /// must be the one dense sampling finds, and the margin negative.
    #[test]
    fn a_short_cut_between_samples_is_found_and_is_negative() {
        let a = Site::new(48.0, 11.0);
        let length = 19_000.0;
        let b = a.direct(90.0, length);
        let (_, azimuth) = a.inverse(&b);
        let at = a.direct(azimuth, length * (0.5 + 0.5 / 64.0));
        let tip = at.direct(180.0, 100.0);
        let base = at.direct(0.0, 150.0);
        let zone = Zone::polygon(
            7,
            ZoneKind::NoFlyZone,
            &[
                wire(tip),
                wire(base.direct(90.0, 250.0)),
                wire(base.direct(270.0, 250.0)),
            ],
        );
        let track = Track::new(Path::Geodesic { from: a, to: b });
        let Clearance::Margin { metres, .. } = clearance(&track, &zone, 0.0, true) else {
            panic!("the leg enters the zone");
        };
        // Dense sampling, a point every metre along the leg.
        let dense = (0..=length as usize)
            .map(|s| {
                let p = Track::new(Path::Point(a.direct(azimuth, s as f64)));
                clearance(&p, &zone, f64::INFINITY, true).metres()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(dense < -50.0, "{dense}");
        assert!((metres - dense).abs() < 0.5, "{metres} against {dense}");
        assert_eq!(clearance(&track, &zone, 0.0, false), Clearance::Forbidden);
    }
}
