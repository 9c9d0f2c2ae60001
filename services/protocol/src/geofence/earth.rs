//! The one Earth model (docs/design.md, "Module map": `geofence/`): the WGS-84 ellipsoid and its
//! geodesics. Every distance, bearing and destination on the Earth in missionlink comes from
//! here: guidance flies track-to-fix legs as geodesics, a circle's radius is the geodesic
//! distance centre -> border point wherever a circle is read, written, flown or checked, the
//! geofence's [`Site`]s sit on this ellipsoid, and the map's drawing projection
//! (`gcs/src/map/local_frame.rs`) takes its radii of curvature from the same constants.
//!
//! The geodesic problems are solved with `geographiclib-rs`, a port of Karney's algorithms
//! (C. F. F. Karney, "Algorithms for geodesics", J. Geodesy 87, 2013): accurate to about 15 nm
//! on the ellipsoid, every call in bounded time (the inverse problem iterates at most a fixed
//! number of times) and without allocating.
//!
//! Positions are latitude and longitude in degrees on WGS-84 (the ICD's positions, ICD §4), as
//! a [`GeoPoint`] of the wire or a [`geo::Point`] (x = longitude, y = latitude), whichever the
//! caller holds ([`Position`]).

use std::sync::LazyLock;

use geo::Point;
use geographiclib_rs::{DirectGeodesic, Geodesic, InverseGeodesic};
use missionlink_interfaces::wire::{Angle, GeoPoint};

/// WGS-84 semi-major axis (equatorial radius), metres.
pub const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS-84 first eccentricity squared, `e² = f·(2 − f)`.
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

/// The geodesic solver on the ellipsoid above (its series coefficients computed once).
static WGS84: LazyLock<Geodesic> = LazyLock::new(|| Geodesic::new(WGS84_A_M, WGS84_F));

/// A position on WGS-84 as latitude and longitude in degrees.
pub trait Position: Copy {
    /// (latitude, longitude), degrees.
    fn lat_lon_deg(self) -> (f64, f64);
}

impl Position for GeoPoint {
    fn lat_lon_deg(self) -> (f64, f64) {
        (self.latitude.degrees(), self.longitude.degrees())
    }
}

impl Position for Point<f64> {
    fn lat_lon_deg(self) -> (f64, f64) {
        (self.y(), self.x())
    }
}

/// The smallest radius of curvature of the ellipsoid (the meridian's at the equator,
/// `a(1 − e²)`), metres: the bound the geofence takes for how far a geodesic bulges away from
/// its chord.
pub const WGS84_MIN_RADIUS_M: f64 = WGS84_A_M * (1.0 - WGS84_E2);

/// A position on the ellipsoid with its Earth-centred, Earth-fixed coordinates, computed once:
/// what the geofence keeps of every vertex, waypoint and point along a geodesic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// Latitude, degrees.
    pub lat: f64,
    /// Longitude, degrees.
    pub lon: f64,
    /// Earth-centred, Earth-fixed x, y, z on the ellipsoid's surface, metres.
    pub ecef: [f64; 3],
}

impl Site {
    /// The site at latitude `lat`, longitude `lon` (degrees), on the ellipsoid's surface.
    pub fn new(lat: f64, lon: f64) -> Self {
        let (phi, lambda) = (lat.to_radians(), lon.to_radians());
        let n = WGS84_A_M / (1.0 - WGS84_E2 * phi.sin().powi(2)).sqrt();
        Self {
            lat,
            lon,
            ecef: [
                n * phi.cos() * lambda.cos(),
                n * phi.cos() * lambda.sin(),
                n * (1.0 - WGS84_E2) * phi.sin(),
            ],
        }
    }

    /// The site of any position.
    pub fn of(p: impl Position) -> Self {
        let (lat, lon) = p.lat_lon_deg();
        Self::new(lat, lon)
    }

    /// The site `distance_m` along the geodesic leaving this one at `azimuth_deg`.
    pub fn direct(&self, azimuth_deg: f64, distance_m: f64) -> Self {
        let (lat, lon): (f64, f64) = WGS84.direct(self.lat, self.lon, azimuth_deg, distance_m);
        Self::new(lat, lon)
    }

    /// Length (metres) and initial azimuth (degrees) of the geodesic from here to `to`.
    pub fn inverse(&self, to: &Site) -> (f64, f64) {
        let (s12, azi1, _azi2, _a12): (f64, f64, f64, f64) =
            WGS84.inverse(self.lat, self.lon, to.lat, to.lon);
        (s12, azi1)
    }

    /// Length (metres), initial azimuth and final azimuth (degrees) of the geodesic from here
    /// to `to`.
    pub fn inverse_azimuths(&self, to: &Site) -> (f64, f64, f64) {
        let (s12, azi1, azi2, _a12): (f64, f64, f64, f64) =
            WGS84.inverse(self.lat, self.lon, to.lat, to.lon);
        (s12, azi1, azi2)
    }

    /// Straight-line (chord) distance to `other` through the Earth, metres: never more than
    /// the geodesic distance.
    pub fn chord_m(&self, other: &Site) -> f64 {
        chord(&self.ecef, &other.ecef)
    }
}

impl Position for Site {
    fn lat_lon_deg(self) -> (f64, f64) {
        (self.lat, self.lon)
    }
}

/// Euclidean distance of two ECEF points, metres.
pub fn chord(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// A wire position as a [`geo::Point`] (x = longitude, y = latitude, degrees).
pub fn point(p: GeoPoint) -> Point<f64> {
    Point::new(p.longitude.degrees(), p.latitude.degrees())
}

/// A [`geo::Point`] as a wire position (rounded to the wire's resolution, ICD §4); `None` when
/// the latitude or the longitude is out of range.
pub fn geo_point(p: Point<f64>) -> Option<GeoPoint> {
    Some(GeoPoint {
        latitude: Angle::from_degrees(p.y())
            .ok()
            .filter(|a| a.is_latitude())?,
        longitude: Angle::from_degrees(p.x()).ok()?,
    })
}

/// Length of the geodesic from `a` to `b`, metres.
pub fn distance_m(a: impl Position, b: impl Position) -> f64 {
    let ((lat1, lon1), (lat2, lon2)) = (a.lat_lon_deg(), b.lat_lon_deg());
    InverseGeodesic::<f64>::inverse(&*WGS84, lat1, lon1, lat2, lon2)
}

/// Initial bearing (azimuth) of the geodesic from `from` to `to`: degrees clockwise from north,
/// in `[0, 360)`.
pub fn bearing_deg(from: impl Position, to: impl Position) -> f64 {
    let ((lat1, lon1), (lat2, lon2)) = (from.lat_lon_deg(), to.lat_lon_deg());
    let (azi1, _azi2, _a12): (f64, f64, f64) = WGS84.inverse(lat1, lon1, lat2, lon2);
    azi1.rem_euclid(360.0)
}

/// The point `distance_m` metres from `start` along the geodesic leaving it at `bearing_deg`
/// (degrees clockwise from north); longitude in `[-180, 180]`.
pub fn destination(start: impl Position, bearing_deg: f64, distance_m: f64) -> Point<f64> {
    let (lat1, lon1) = start.lat_lon_deg();
    let (lat2, lon2): (f64, f64) = WGS84.direct(lat1, lon1, bearing_deg, distance_m);
    Point::new(lon2, lat2)
}

/// The point `distance_m` metres due north of `centre` along its meridian (a geodesic), with
/// `centre`'s longitude exactly: where a circle given by its radius gets its border point.
/// `None` when that is beyond the pole or the distance is not finite.
pub fn due_north(centre: GeoPoint, distance_m: f64) -> Option<GeoPoint> {
    let (lat1, lon1) = centre.lat_lon_deg();
    let (lat2, _lon2, azi2): (f64, f64, f64) = WGS84.direct(lat1, lon1, 0.0, distance_m);
    // Past the pole the meridian comes down the other side: the azimuth there points south.
    if !lat2.is_finite() || azi2.abs() > 90.0 {
        return None;
    }
    Some(GeoPoint {
        latitude: Angle::from_degrees(lat2).ok().filter(|a| a.is_latitude())?,
        longitude: centre.longitude,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(lat: f64, lon: f64) -> Point<f64> {
        Point::new(lon, lat)
    }

    #[test]
    fn the_ellipsoid_is_geographiclibs_wgs84() {
        let g = Geodesic::wgs84();
        assert_eq!(g.equatorial_radius(), WGS84_A_M);
        assert!((g.flattening() - WGS84_F).abs() < 1e-18);
        assert!((WGS84_E2 - 0.006_694_379_990_14).abs() < 1e-14);
    }

    /// The examples of geographiclib-rs's documentation: JFK to the point 10,000 km north-east,
    /// and the inverse back.
    #[test]
    fn direct_and_inverse_agree_with_geographiclib_reference_values() {
        let jfk = p(40.64, -73.78);
        let there = destination(jfk, 45.0, 10e6);
        assert!(
            (there.y() - 32.621_100_463_725_796).abs() < 1e-9,
            "{there:?}"
        );
        assert!(
            (there.x() - 49.052_487_092_959_82).abs() < 1e-9,
            "{there:?}"
        );
        assert!((distance_m(jfk, there) - 10e6).abs() < 1e-6);
        assert!((bearing_deg(jfk, there) - 45.0).abs() < 1e-9);
        // Los Angeles to Tallinn (geographiclib-rs's example).
        let d = distance_m(p(34.095925, -118.2884237), p(59.4323439, 24.7341649));
        assert!((d - 9_094_718.727_511_38).abs() < 1e-6, "{d}");
    }

    #[test]
    fn bearings_are_in_0_to_360_clockwise_from_north() {
        let o = p(48.27, 11.66);
        assert!(bearing_deg(o, p(48.28, 11.66)).abs() < 1e-9);
        assert!((bearing_deg(o, p(48.27, 11.67)) - 90.0).abs() < 0.01);
        assert!((bearing_deg(o, p(48.26, 11.66)) - 180.0).abs() < 1e-9);
        assert!((bearing_deg(o, p(48.27, 11.65)) - 270.0).abs() < 0.01);
    }

    /// One degree of latitude about 48° N is the meridian arc there, `M(φ)·π/180` with
    /// `M = a(1 − e²)/(1 − e² sin²φ)^(3/2)`: 111,190.3 m (the sphere of the mean radius would
    /// say 111,195.1 m).
    #[test]
    fn a_degree_of_latitude_is_the_meridian_arc() {
        let d = distance_m(p(47.5, 11.0), p(48.5, 11.0));
        assert!((d - 111_190.3).abs() < 0.1, "{d}");
    }

    #[test]
    fn due_north_keeps_the_meridian_and_stops_at_the_pole() {
        let centre = geo_point(p(48.268, 11.675)).unwrap();
        let border = due_north(centre, 296.07).unwrap();
        assert_eq!(border.longitude, centre.longitude);
        // One BAM4 step of latitude is about 9.3 mm (ICD §4).
        assert!((distance_m(centre, border) - 296.07).abs() < 0.01);
        let near_pole = geo_point(p(89.99, 0.0)).unwrap();
        assert_eq!(due_north(near_pole, 5_000.0), None);
        assert_eq!(due_north(centre, f64::NAN), None);
    }
}
