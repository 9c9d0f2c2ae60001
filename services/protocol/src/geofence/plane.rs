//! The tangent plane of the ellipsoid at a site, and the planar geometry the geofence does in
//! it.
//!
//! Every distance and crossing the geofence computes is computed in the tangent plane at a site
//! close to where it happens (the start of a path piece of at most [`super::PIECE_M`], or the
//! centre of a radius-to-fix arc), between points that lie exactly on the geodesics, projected
//! orthographically along the ellipsoid normal. Two errors remain and both are small there:
//! - a projected geodesic piece of length `l` passing at distance `D` from the tangent point
//!   bows away from its chord by about `l²·D/(8R²)`: 3 mm for `l` = `D` = 20 km;
//! - lengths at distance `D` from the tangent point shrink by about `D²/(2R²)`: 5 ppm at 20 km,
//!   5 mm on a 1 km margin.

/// A point of a plane: x east, y north, metres.
pub use geo::Coord;

use super::earth::{Site, WGS84_A_M, WGS84_E2};

/// The tangent plane at a site: x east, y north, metres.
#[derive(Debug, Clone, Copy)]
pub struct Plane {
    origin: [f64; 3],
    east: [f64; 3],
    north: [f64; 3],
    /// The ellipsoid's normal at the origin (east × north), along which sites are projected.
    up: [f64; 3],
}

impl Plane {
    /// The tangent plane at `site`.
    pub fn at(site: &Site) -> Self {
        let (phi, lambda) = (site.lat.to_radians(), site.lon.to_radians());
        let (sp, cp, sl, cl) = (phi.sin(), phi.cos(), lambda.sin(), lambda.cos());
        Self {
            origin: site.ecef,
            east: [-sl, cl, 0.0],
            north: [-sp * cl, -sp * sl, cp],
            up: [cp * cl, cp * sl, sp],
        }
    }

    /// The site of the ellipsoid that lands at `c` ([`Plane::xy`]'s inverse): where the line
    /// through `c` along the normal at the origin meets the ellipsoid, the meeting nearer the
    /// plane. Exact (a quadratic, no iteration), so a point measured in one plane can be
    /// measured in another: what the fleet separation check of the safety gateway does with
    /// the corners of two vehicles' paths. `None` where that line misses the ellipsoid (`c`
    /// farther than the Earth's radius from the origin) or `c` is not finite.
    pub fn lift(&self, c: Coord) -> Option<Site> {
        let p = self.lift_ecef(c)?;
        // On the surface the geodetic latitude is exactly atan(z / ((1 − e²)·√(x² + y²))).
        let lat = p[2].atan2((1.0 - WGS84_E2) * p[0].hypot(p[1])).to_degrees();
        let lon = p[1].atan2(p[0]).to_degrees();
        (lat.is_finite() && lon.is_finite()).then_some(Site { lat, lon, ecef: p })
    }

    /// [`Plane::lift`]'s site as its Earth-centred, Earth-fixed coordinates alone, metres.
    pub fn lift_ecef(&self, c: Coord) -> Option<[f64; 3]> {
        let q = [
            self.origin[0] + c.x * self.east[0] + c.y * self.north[0],
            self.origin[1] + c.x * self.east[1] + c.y * self.north[1],
            self.origin[2] + c.x * self.east[2] + c.y * self.north[2],
        ];
        let u = self.up;
        // The ellipsoid is x² + y² + w·z² = a² with w = 1/(1 − e²); the line q + t·u meets it
        // where A·t² + B·t + C = 0.
        let w = 1.0 / (1.0 - WGS84_E2);
        let a = u[0] * u[0] + u[1] * u[1] + w * u[2] * u[2];
        let b = 2.0 * (q[0] * u[0] + q[1] * u[1] + w * q[2] * u[2]);
        let cc = q[0] * q[0] + q[1] * q[1] + w * q[2] * q[2] - WGS84_A_M * WGS84_A_M;
        let disc = b * b - 4.0 * a * cc;
        if !disc.is_finite() || disc < 0.0 {
            return None;
        }
        // The root nearer 0 without cancellation: C/q with q = −(B + sign(B)·√disc)/2.
        let half = -0.5 * (b + b.signum() * disc.sqrt());
        let t = if half == 0.0 { 0.0 } else { cc / half };
        let p = [q[0] + t * u[0], q[1] + t * u[1], q[2] + t * u[2]];
        p.iter().all(|x| x.is_finite()).then_some(p)
    }

    /// Where `site` lands in the plane.
    pub fn xy(&self, site: &Site) -> Coord {
        self.project(&site.ecef)
    }

    /// Where the ECEF point `p` lands in the plane.
    pub fn project(&self, p: &[f64; 3]) -> Coord {
        let d = [
            p[0] - self.origin[0],
            p[1] - self.origin[1],
            p[2] - self.origin[2],
        ];
        Coord {
            x: self.east[0] * d[0] + self.east[1] * d[1] + self.east[2] * d[2],
            y: self.north[0] * d[0] + self.north[1] * d[1] + self.north[2] * d[2],
        }
    }
}

fn dot(a: Coord, b: Coord) -> f64 {
    a.x * b.x + a.y * b.y
}

fn cross(a: Coord, b: Coord) -> f64 {
    a.x * b.y - a.y * b.x
}

fn length(a: Coord) -> f64 {
    a.x.hypot(a.y)
}

/// Distance from `p` to the segment `a`-`b`, with the parameter (0 at `a`, 1 at `b`) of the
/// closest point.
pub fn point_segment(p: Coord, a: Coord, b: Coord) -> (f64, f64) {
    let ab = b - a;
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(p - a, ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (length(p - (a + ab * t)), t)
}

/// How two segments `a`-`b` and `c`-`d` meet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentPair {
    /// Smallest distance between them (0 when they touch or cross).
    pub distance: f64,
    /// Parameter on `a`-`b` (0 at `a`, 1 at `b`) where it is reached.
    pub t: f64,
}

/// The closest approach of the segments `a`-`b` and `c`-`d` (either may be a single point).
pub fn segment_segment(a: Coord, b: Coord, c: Coord, d: Coord) -> SegmentPair {
    let (r, s) = (b - a, d - c);
    let denominator = cross(r, s);
    if denominator != 0.0 {
        let t = cross(c - a, s) / denominator;
        let u = cross(c - a, r) / denominator;
        if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
            return SegmentPair { distance: 0.0, t };
        }
    }
    // Apart (or parallel): the closest approach involves an end point of one of them.
    let (da, _) = point_segment(a, c, d);
    let mut best = SegmentPair {
        distance: da,
        t: 0.0,
    };
    let (db, _) = point_segment(b, c, d);
    if db < best.distance {
        best = SegmentPair {
            distance: db,
            t: 1.0,
        };
    }
    for q in [c, d] {
        let (dq, t) = point_segment(q, a, b);
        if dq < best.distance {
            best = SegmentPair { distance: dq, t };
        }
    }
    best
}

/// Whether the ray from `p` towards +y crosses the segment `a`-`b` (half-open in x, so that a
/// ray through a vertex counts it once).
pub fn ray_crosses(p: Coord, a: Coord, b: Coord) -> bool {
    if (a.x > p.x) == (b.x > p.x) {
        return false;
    }
    let y = a.y + (p.x - a.x) * (b.y - a.y) / (b.x - a.x);
    y > p.y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(x: f64, y: f64) -> Coord {
        Coord { x, y }
    }

    #[test]
    fn segments_that_cross_touch_or_stay_apart() {
        let crossing = segment_segment(c(0.0, 0.0), c(2.0, 0.0), c(1.0, -1.0), c(1.0, 1.0));
        assert_eq!(crossing.distance, 0.0);
        assert!((crossing.t - 0.5).abs() < 1e-12);
        let apart = segment_segment(c(0.0, 0.0), c(2.0, 0.0), c(1.0, 3.0), c(1.0, 7.0));
        assert!((apart.distance - 3.0).abs() < 1e-12);
        assert!((apart.t - 0.5).abs() < 1e-12);
        let parallel = segment_segment(c(0.0, 0.0), c(2.0, 0.0), c(3.0, 4.0), c(5.0, 4.0));
        assert!((parallel.distance - 17f64.sqrt()).abs() < 1e-12);
        let point = segment_segment(c(0.0, 0.0), c(0.0, 0.0), c(3.0, -1.0), c(3.0, 1.0));
        assert!((point.distance - 3.0).abs() < 1e-12);
    }

    #[test]
    fn the_tangent_plane_is_east_north_and_metric_near_its_site() {
        let o = Site::new(48.27, 11.66);
        let plane = Plane::at(&o);
        let north = plane.xy(&o.direct(0.0, 1000.0));
        assert!(
            north.x.abs() < 1e-6 && (north.y - 1000.0).abs() < 1e-4,
            "{north:?}"
        );
        let east = plane.xy(&o.direct(90.0, 1000.0));
        assert!(
            (east.x - 1000.0).abs() < 1e-4 && east.y.abs() < 0.1,
            "{east:?}"
        );
        let p = o.direct(37.0, 20_000.0);
        let q = p.direct(120.0, 500.0);
        let planar = length(plane.xy(&q) - plane.xy(&p));
        assert!((planar - 500.0).abs() < 0.01, "{planar}");
    }

    /// Lifting is the exact inverse of projecting: a site 1 km, 20 km and 300 km from the
    /// origin in any direction comes back to within a micrometre, its latitude and longitude
    /// to 1e-11 degrees (about a micrometre).
    #[test]
    fn lift_undoes_xy_exactly() {
        for origin in [
            Site::new(48.27, 11.66),
            Site::new(-33.9, 151.2),
            Site::new(0.0, -179.99),
        ] {
            let plane = Plane::at(&origin);
            assert!(plane.lift(c(0.0, 0.0)).unwrap().chord_m(&origin) < 1e-9);
            for distance in [1_000.0, 20_000.0, 300_000.0] {
                for azimuth in [0.0, 37.0, 90.0, 181.0, 300.0] {
                    let site = origin.direct(azimuth, distance);
                    let back = plane.lift(plane.xy(&site)).unwrap();
                    assert!(back.chord_m(&site) < 1e-6, "{distance} m at {azimuth}");
                    assert!((back.lat - site.lat).abs() < 1e-11, "{back:?} {site:?}");
                    let dlon = (back.lon - site.lon + 180.0).rem_euclid(360.0) - 180.0;
                    assert!(dlon.abs() < 1e-11, "{back:?} {site:?}");
                }
            }
        }
        let plane = Plane::at(&Site::new(48.27, 11.66));
        assert_eq!(plane.lift(c(1e8, 0.0)), None);
        assert_eq!(plane.lift(c(f64::NAN, 0.0)), None);
    }

    #[test]
    fn the_ray_counts_a_vertex_once() {
        let p = c(0.0, 0.0);
        assert!(
            ray_crosses(p, c(-1.0, 1.0), c(0.0, 1.0)) ^ ray_crosses(p, c(0.0, 1.0), c(1.0, 1.0))
        );
        assert!(!ray_crosses(p, c(-1.0, -1.0), c(1.0, -1.0)));
    }
}
