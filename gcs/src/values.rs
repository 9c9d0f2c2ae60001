//! The values of mission files, one way for every format (TOML mission file, QGroundControl
//! `.plan`, GeoJSON): numbers read into wire fields with the file path of each error, numbers
//! written back as the shortest decimal that gives the same wire value, and a circle given by
//! its radius placed on the one Earth model ([`missionlink_protocol::geofence::earth`]).

use missionlink_interfaces::wire::{Altitude, Angle, GeoPoint};
use missionlink_protocol::geofence::earth;

use crate::geoid;
use crate::mission_file::MissionFileError;

/// A [`MissionFileError::Field`]: `reason` at `path`.
pub(crate) fn field_error(path: impl Into<String>, reason: impl Into<String>) -> MissionFileError {
    MissionFileError::Field {
        path: path.into(),
        reason: reason.into(),
    }
}

/// A latitude in degrees, -90..=90.
pub(crate) fn latitude(path: &str, degrees: f64) -> Result<Angle, MissionFileError> {
    Angle::from_degrees(degrees)
        .ok()
        .filter(|a| a.is_latitude())
        .ok_or_else(|| field_error(path, format!("latitude {degrees} deg is outside -90..=90")))
}

/// A longitude in degrees, -180..=180.
pub(crate) fn longitude(path: &str, degrees: f64) -> Result<Angle, MissionFileError> {
    Angle::from_degrees(degrees).map_err(|_| {
        field_error(
            path,
            format!("longitude {degrees} deg is outside -180..=180"),
        )
    })
}

/// A position from latitude and longitude in degrees.
pub(crate) fn point(path: &str, lat: f64, lon: f64) -> Result<GeoPoint, MissionFileError> {
    Ok(GeoPoint {
        latitude: latitude(path, lat)?,
        longitude: longitude(path, lon)?,
    })
}

/// An altitude in metres.
pub(crate) fn altitude(path: &str, metres: f64) -> Result<Altitude, MissionFileError> {
    Altitude::from_metres(metres).map_err(|e| field_error(path, e.to_string()))
}

/// An area's altitude bounds: the upper (at `upper_path`) not below the lower.
pub(crate) fn altitude_bounds(
    upper_path: &str,
    lower: Option<Altitude>,
    upper: Option<Altitude>,
) -> Result<(), MissionFileError> {
    match (lower, upper) {
        (Some(lo), Some(up)) if lo > up => Err(field_error(
            upper_path,
            format!(
                "{} m is below lower_altitude_m ({} m)",
                up.metres(),
                lo.metres()
            ),
        )),
        _ => Ok(()),
    }
}

/// A circle's radius in metres: finite and above 0.
pub(crate) fn radius(path: &str, metres: f64) -> Result<f64, MissionFileError> {
    if metres.is_finite() && metres > 0.0 {
        Ok(metres)
    } else {
        Err(field_error(
            path,
            format!("{metres} m: the radius must be above 0"),
        ))
    }
}

/// The border point of a circle given by its `radius` (at `path`): `radius` metres due north of
/// `centre` along its meridian, on WGS-84 ([`earth::due_north`]).
pub(crate) fn border_due_north(
    path: &str,
    centre: GeoPoint,
    radius_m: f64,
) -> Result<GeoPoint, MissionFileError> {
    let radius = radius(path, radius_m)?;
    earth::due_north(centre, radius).ok_or_else(|| {
        field_error(
            path,
            format!("{radius} m north of the centre is beyond the pole"),
        )
    })
}

/// A circle's radius as a file writes it: the geodesic distance centre -> border point
/// ([`earth::distance_m`]), to the millimetre.
pub(crate) fn radius_mm(centre: GeoPoint, border: GeoPoint) -> f64 {
    (earth::distance_m(centre, border) * 1000.0).round() / 1000.0
}

/// The shortest decimal (fewest fraction digits) of `exact` that `same` accepts as the same
/// wire value; `exact` itself when none is shorter.
pub(crate) fn shortest(exact: f64, same: impl Fn(f64) -> bool) -> f64 {
    (0..=17)
        .filter_map(|digits| format!("{exact:.digits$}").parse::<f64>().ok())
        .find(|v| same(*v))
        .unwrap_or(exact)
}

/// The angle in degrees, the shortest decimal that gives it back.
pub(crate) fn degrees(a: Angle) -> f64 {
    shortest(a.degrees(), |d| Angle::from_degrees(d) == Ok(a))
}

/// The altitude in metres, the shortest decimal that gives it back.
pub(crate) fn metres(a: Altitude) -> f64 {
    shortest(a.metres(), |m| Altitude::from_metres(m) == Ok(a))
}

/// A WGS-84 altitude as its height above mean sea level at a position, metres, the shortest
/// decimal that gives the altitude back through [`crate::geoid`].
pub(crate) fn amsl_metres(a: Altitude, latitude_deg: f64, longitude_deg: f64) -> f64 {
    let amsl = geoid::amsl_from_wgs84(a.metres(), latitude_deg, longitude_deg);
    shortest(amsl, |m| {
        Altitude::from_metres(geoid::wgs84_from_amsl(m, latitude_deg, longitude_deg)) == Ok(a)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_radius_places_the_border_due_north_and_reads_back_to_the_millimetre() {
        let centre = point("c", 48.268, 11.675).unwrap();
        let border = border_due_north("r", centre, 296.07).unwrap();
        assert_eq!(border.longitude, centre.longitude);
        // One BAM4 step of latitude is about 9.3 mm (ICD §4).
        assert!((radius_mm(centre, border) - 296.07).abs() < 0.01);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = border_due_north("r", centre, bad).unwrap_err();
            assert!(e.to_string().contains("must be above 0"), "{e}");
        }
        let e = border_due_north("r", centre, 5e6).unwrap_err();
        assert_eq!(
            e.to_string(),
            "r: 5000000 m north of the centre is beyond the pole"
        );
    }

    #[test]
    fn values_read_with_their_path_and_write_back_shortest() {
        assert_eq!(
            latitude("w.lat", 91.0).unwrap_err().to_string(),
            "w.lat: latitude 91 deg is outside -90..=90"
        );
        assert!(longitude("w.lon", 181.0).is_err());
        let a = Angle::from_degrees(48.275).unwrap();
        assert_eq!(degrees(a), 48.275);
        let h = Altitude::from_metres(120.0).unwrap();
        assert_eq!(metres(h), 120.0);
        assert!(altitude_bounds("u", Some(h), Some(h)).is_ok());
        let low = Altitude::from_metres(100.0).unwrap();
        assert_eq!(
            altitude_bounds("u", Some(h), Some(low))
                .unwrap_err()
                .to_string(),
            "u: 100 m is below lower_altitude_m (120 m)"
        );
    }
}
