//! The map's plane: points in local metres and on the screen, the projection, paths and zones
//! drawn as polylines, the view that fits the mission, and polygons grown by an offset.

use super::*;

/// A point in the local metric plane (x east, y north, metres) or on the screen (pixels).
pub(super) type P = (f64, f64);

pub(super) fn sub(a: P, b: P) -> P {
    (a.0 - b.0, a.1 - b.1)
}

pub(super) fn add(a: P, b: P) -> P {
    (a.0 + b.0, a.1 + b.1)
}

pub(super) fn mul(a: P, k: f64) -> P {
    (a.0 * k, a.1 * k)
}

pub(super) fn len(a: P) -> f64 {
    a.0.hypot(a.1)
}

pub(super) fn unit(a: P) -> Option<P> {
    let l = len(a);
    (l > 1e-9).then(|| mul(a, 1.0 / l))
}

/// The drawing projection (`local_frame`), with the map's point type.
#[derive(Debug, Clone, Copy)]
pub(super) struct Projection(pub(super) LocalFrame);

impl Projection {
    pub(super) fn new(lat0: f64, lon0: f64) -> Self {
        Self(LocalFrame::new(lat0, lon0))
    }

    /// Metres east and north of the centre.
    pub(super) fn local(&self, lat: f64, lon: f64) -> P {
        let c = self.0.xy(lat, lon);
        (c.x, c.y)
    }

    pub(super) fn site(&self, s: &Site) -> P {
        self.local(s.lat, s.lon)
    }
}

/// The sites along `path` as the geofence holds it, at most [`DRAW_STEP_M`] apart along a
/// geodesic.
pub(super) fn drawn_sites(path: Path) -> Vec<Site> {
    Track::new(path).sites(DRAW_STEP_M).collect()
}

/// [`drawn_sites`] in the drawing projection.
pub(super) fn drawn(path: Path, proj: &Projection) -> Vec<P> {
    drawn_sites(path).iter().map(|s| proj.site(s)).collect()
}

/// The points at geodesic distance `radius` (metres) around `centre`, clockwise from north,
/// close enough that no chord lies more than [`CIRCLE_SAG_DRAWN_M`] inside the circle.
pub(super) fn ring(proj: &Projection, centre: &Site, radius: f64) -> Vec<P> {
    let step = 2.0 * (1.0 - CIRCLE_SAG_DRAWN_M / radius.max(CIRCLE_SAG_DRAWN_M)).acos();
    let n = (core::f64::consts::TAU / step)
        .ceil()
        .clamp(CIRCLE_POINTS.0, CIRCLE_POINTS.1) as usize;
    (0..n)
        .map(|k| proj.site(&centre.direct(360.0 * k as f64 / n as f64, radius)))
        .collect()
}

/// Local metres to screen pixels: uniform scale, north up.
#[derive(Debug, Clone, Copy)]
pub(super) struct View {
    /// Pixels per metre.
    pub(super) scale: f64,
    /// Screen position of the local origin.
    pub(super) origin: P,
}

impl View {
    /// The view that fits the box `lo`..`hi` (local metres) with a margin into the map frame.
    pub(super) fn fit(lo: P, hi: P) -> Self {
        let (left, top, right, bottom) = MAP;
        let w = (hi.0 - lo.0).max(MIN_EXTENT_M);
        let h = (hi.1 - lo.1).max(MIN_EXTENT_M);
        let margin = MARGIN * w.max(h);
        let scale = ((right - left) / (w + 2.0 * margin)).min((bottom - top) / (h + 2.0 * margin));
        let centre = ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0);
        let screen_centre = ((left + right) / 2.0, (top + bottom) / 2.0);
        Self {
            scale,
            origin: (
                screen_centre.0 - scale * centre.0,
                screen_centre.1 + scale * centre.1,
            ),
        }
    }

    pub(super) fn screen(&self, p: P) -> P {
        (
            self.origin.0 + self.scale * p.0,
            self.origin.1 - self.scale * p.1,
        )
    }
}

/// An area as drawn, in local metres.
#[derive(Debug, Clone)]
pub(super) enum Shape {
    /// The sites along the geodesic edges, in order around the polygon.
    Polygon(Vec<P>),
    /// A geodesic circle: its centre and radius (metres), and the points drawn around it.
    Circle {
        centre: Site,
        radius: f64,
        outline: Vec<P>,
    },
}

#[derive(Debug, Clone)]
pub(super) struct Area {
    pub(super) id: u16,
    pub(super) kind: ZoneKind,
    pub(super) shape: Shape,
}

impl Shape {
    /// The zone as drawn: a polygon through the sites along its edges (each edge's last site is
    /// the next edge's first), a circle through the points at its radius.
    pub(super) fn of_zone(zone: &Zone, proj: &Projection) -> Self {
        match (zone.radius_m(), zone.vertices().next()) {
            (Some(radius), Some(centre)) => Shape::Circle {
                centre,
                radius,
                outline: ring(proj, &centre, radius),
            },
            _ => Shape::Polygon(
                zone.edges()
                    .flat_map(|edge| {
                        let mut points = drawn(edge, proj);
                        points.pop();
                        points
                    })
                    .collect(),
            ),
        }
    }

    /// The shape offset by `d` metres: outward for `d > 0`, inward for `d < 0` (see the module
    /// documentation for the approximation).
    pub(super) fn offset(&self, d: f64, proj: &Projection) -> Shape {
        match self {
            Shape::Polygon(points) => Shape::Polygon(offset_polygon(points, d)),
            Shape::Circle { centre, radius, .. } => {
                let radius = (radius + d).max(0.0);
                Shape::Circle {
                    centre: *centre,
                    radius,
                    outline: ring(proj, centre, radius),
                }
            }
        }
    }

    /// The points drawn.
    pub(super) fn outline(&self) -> &[P] {
        match self {
            Shape::Polygon(points)
            | Shape::Circle {
                outline: points, ..
            } => points,
        }
    }

    /// Where the area's label goes: above the shape's top, horizontally at its middle (local
    /// metres), with the given clearance in metres.
    pub(super) fn label_anchor(&self, clearance: f64) -> P {
        let (lo, hi) = bounds(self.outline().iter().copied()).unwrap_or(((0.0, 0.0), (0.0, 0.0)));
        ((lo.0 + hi.0) / 2.0, hi.1 + clearance)
    }
}

/// Twice the signed area (shoelace): positive for counter-clockwise (x east, y north).
pub(super) fn signed_area2(points: &[P]) -> f64 {
    points
        .iter()
        .zip(points.iter().cycle().skip(1))
        .map(|(a, b)| a.0 * b.1 - b.0 * a.1)
        .sum()
}

/// Offsets a closed polygon by `d` metres (outward for `d > 0`): each vertex moves along its
/// angle bisector so that both adjacent edges move by `d` (the miter offset). An approximation of
/// the true buffer: corners stay sharp, very sharp corners are clamped, and an inward offset of a
/// concave or thin polygon may fold over.
pub(super) fn offset_polygon(points: &[P], d: f64) -> Vec<P> {
    let n = points.len();
    if n < 3 {
        return points.to_vec();
    }
    // Left normals point inward for a counter-clockwise polygon.
    let outward = if signed_area2(points) >= 0.0 { -d } else { d };
    let mut out = Vec::with_capacity(n);
    for (i, v) in points.iter().enumerate() {
        let (Some(prev), Some(next)) = (points.get((i + n - 1) % n), points.get((i + 1) % n))
        else {
            continue;
        };
        let normal = |a: P, b: P| unit(sub(b, a)).map(|u| (-u.1, u.0));
        let shift = match (normal(*prev, *v), normal(*v, *next)) {
            (Some(n1), Some(n2)) => {
                // Miter: n·shift = 1 for both normals; clamp corners sharper than ~150 deg.
                let denom = (1.0 + n1.0 * n2.0 + n1.1 * n2.1).max(0.07);
                mul(add(n1, n2), 1.0 / denom)
            }
            (Some(n1), None) | (None, Some(n1)) => n1,
            (None, None) => (0.0, 0.0),
        };
        out.push(add(*v, mul(shift, outward)));
    }
    out
}

pub(super) fn bounds(points: impl IntoIterator<Item = P>) -> Option<(P, P)> {
    points
        .into_iter()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .fold(None, |acc, p| {
            Some(match acc {
                None => (p, p),
                Some((lo, hi)) => (
                    (lo.0.min(p.0), lo.1.min(p.1)),
                    (hi.0.max(p.0), hi.1.max(p.1)),
                ),
            })
        })
}

/// The point halfway along the polyline `points` and the direction of the chord there.
pub(super) fn midway(points: &[P]) -> Option<(P, P)> {
    let chords = || {
        points.windows(2).filter_map(|w| match w {
            [a, b] => Some((*a, sub(*b, *a))),
            _ => None,
        })
    };
    let mut left = chords().map(|(_, d)| len(d)).sum::<f64>() / 2.0;
    for (a, d) in chords() {
        let l = len(d);
        if l > 0.0 && left <= l {
            return Some((add(a, mul(d, left / l)), d));
        }
        left -= l;
    }
    None
}
