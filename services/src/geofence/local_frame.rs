//! A local metric frame for the geometry of a mission: an equirectangular projection about a
//! reference point with the radii of curvature there of the WGS-84 ellipsoid of
//! [`super::earth`] (east-west error about tan(lat0) x |dlat|: under 0.03 % over the demo area),
//! and the radius-to-fix arc in it.
//!
//! The safety gateway checks, and the map draws, in this one frame, so the map shows the
//! geometry that was checked.

pub use geo::Coord;
use missionlink_interfaces::wire::{GeoPoint, TurnDirection};

use super::earth::{WGS84_A_M, WGS84_E2};
/// Samples of one arc at most, whatever the sagitta asked.
const MAX_ARC_SAMPLES: usize = 100_000;

/// Equirectangular projection about a reference point, WGS-84 radii of curvature there.
#[derive(Debug, Clone, Copy)]
pub struct LocalFrame {
    lat0: f64,
    lon0: f64,
    m_per_deg_lat: f64,
    m_per_deg_lon: f64,
}

impl LocalFrame {
    /// The frame about (`lat0`, `lon0`) degrees.
    pub fn new(lat0: f64, lon0: f64) -> Self {
        let phi = lat0.to_radians();
        let w = (1.0 - WGS84_E2 * phi.sin().powi(2)).sqrt();
        let meridional = WGS84_A_M * (1.0 - WGS84_E2) / (w * w * w);
        let prime_vertical = WGS84_A_M / w;
        Self {
            lat0,
            lon0,
            m_per_deg_lat: meridional.to_radians(),
            m_per_deg_lon: (prime_vertical * phi.cos()).to_radians(),
        }
    }

    /// The reference point, latitude and longitude in degrees.
    pub fn origin(&self) -> (f64, f64) {
        (self.lat0, self.lon0)
    }

    /// Metres east (x) and north (y) of the reference point.
    pub fn xy(&self, lat: f64, lon: f64) -> Coord {
        let mut dlon = lon - self.lon0;
        if dlon > 180.0 {
            dlon -= 360.0;
        } else if dlon < -180.0 {
            dlon += 360.0;
        }
        Coord {
            x: dlon * self.m_per_deg_lon,
            y: (lat - self.lat0) * self.m_per_deg_lat,
        }
    }

    /// [`LocalFrame::xy`] of a wire position.
    pub fn point(&self, p: &GeoPoint) -> Coord {
        self.xy(p.latitude.degrees(), p.longitude.degrees())
    }

    /// Latitude and longitude (degrees) of a point of the frame.
    pub fn deg(&self, c: Coord) -> (f64, f64) {
        (
            self.lat0 + c.y / self.m_per_deg_lat,
            self.lon0 + c.x / self.m_per_deg_lon,
        )
    }
}

/// The radius-to-fix arc from `start` to `end` around `centre` in `direction` (clockwise =
/// right turn, seen from above), the radius going linearly from the start radius to the end
/// radius (equal on a valid leg), sampled so that no chord lies more than `max_sag_m` from the
/// arc; both ends exact.
pub fn arc(
    start: Coord,
    end: Coord,
    centre: Coord,
    direction: TurnDirection,
    max_sag_m: f64,
) -> Vec<Coord> {
    let (s, e) = (start - centre, end - centre);
    let (rs, re) = (s.x.hypot(s.y), e.x.hypot(e.y));
    let (ts, te) = (s.y.atan2(s.x), e.y.atan2(e.x));
    let tau = core::f64::consts::TAU;
    // Swept angle in the turn direction, in [0, 2π); angles grow counter-clockwise.
    let sweep = match direction {
        TurnDirection::Clockwise => (ts - te).rem_euclid(tau),
        TurnDirection::CounterClockwise => (te - ts).rem_euclid(tau),
    };
    let r = rs.max(re);
    if r < max_sag_m || sweep <= 0.0 {
        return vec![start, end];
    }
    let step = 2.0 * (1.0 - max_sag_m / r).clamp(-1.0, 1.0).acos();
    let n = ((sweep / step).ceil() as usize).clamp(1, MAX_ARC_SAMPLES);
    let sign = match direction {
        TurnDirection::Clockwise => -1.0,
        TurnDirection::CounterClockwise => 1.0,
    };
    let mut points = Vec::with_capacity(n + 1);
    points.push(start);
    for i in 1..n {
        let t = i as f64 / n as f64;
        let theta = ts + sign * sweep * t;
        let radius = rs + (re - rs) * t;
        points.push(Coord {
            x: centre.x + radius * theta.cos(),
            y: centre.y + radius * theta.sin(),
        });
    }
    points.push(end);
    points
}
