//! The map's drawing projection: an equirectangular projection about a reference point with the
//! radii of curvature there of the WGS-84 ellipsoid of the one Earth model
//! (`missionlink_protocol::geofence::earth`; east-west scale error about tan(lat0) x |dlat|: under
//! 0.03 % over the demo area), north up.
//!
//! It only puts on the screen what the geofence computed: the map draws the sites along the
//! geofence's geodesics, arcs and circles (`Track::sites`) through it, and no check, distance or
//! crossing is decided in it; so it lives with the map, not with the geofence.

use missionlink_protocol::geofence::earth::{WGS84_A_M, WGS84_E2};

/// A point of the frame: metres east (x) and north (y) of the reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coord {
    /// Metres east.
    pub x: f64,
    /// Metres north.
    pub y: f64,
}

/// Equirectangular projection about a reference point, WGS-84 radii of curvature there: for
/// drawing only.
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

    /// Latitude and longitude (degrees) of a point of the frame (the map's tests read what
    /// was drawn back).
    #[cfg(test)]
    pub fn deg(&self, c: Coord) -> (f64, f64) {
        (
            self.lat0 + c.y / self.m_per_deg_lat,
            self.lon0 + c.x / self.m_per_deg_lon,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_protocol::geofence::earth::Site;

    /// On the same ellipsoid as the geofence, the frame scales latitude as the meridian arc.
    #[test]
    fn latitude_scales_as_the_meridian_arc() {
        let frame = LocalFrame::new(48.0, 11.0);
        let y = frame.xy(48.0005, 11.0).y - frame.xy(47.9995, 11.0).y;
        let (arc, _) = Site::new(47.9995, 11.0).inverse(&Site::new(48.0005, 11.0));
        assert!((y - arc).abs() < 1e-6, "{y} {arc}");
    }
}
