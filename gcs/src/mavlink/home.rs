//! The vehicle's home (MAVLink's HOME_POSITION, the reference of `relative_alt`) and altitudes
//! above mean sea level: what the vehicle reports and its memory keeps.

use missionlink_interfaces::wire::AltitudeType;

/// The vehicle's home as MAVLink means it: where the flight starts and the reference of
/// `relative_alt`. It is where the aircraft is while no mission flies, and it stays where the
/// mission started while the mission flies (PX4 sets it at arming; the FCC's arming is
/// execute).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Home {
    /// Latitude, degrees.
    pub latitude_deg: f64,
    /// Longitude, degrees.
    pub longitude_deg: f64,
    /// The altitude as the FCC reports it (#101 field 4), metres.
    pub altitude_m: f64,
    /// Its type (#101 field 5).
    pub altitude_type: Option<AltitudeType>,
}

impl Home {
    /// The home's altitude above mean sea level, when its type says where that is.
    pub fn amsl_m(&self) -> Option<f64> {
        amsl_m(
            self.altitude_m,
            self.altitude_type,
            self.latitude_deg,
            self.longitude_deg,
        )
    }
}

/// An altitude of the FCC above mean sea level: a WGS-84 height less the geoid's undulation
/// ([`crate::geoid`]); a barometric altitude is one already (set to the local QNH, ICD §4
/// #13002 type 1); pressure altitude (standard atmosphere), height above ground and no type do
/// not say where sea level is.
pub(super) fn amsl_m(
    altitude_m: f64,
    kind: Option<AltitudeType>,
    lat: f64,
    lon: f64,
) -> Option<f64> {
    match kind {
        Some(AltitudeType::Wgs84) => Some(crate::geoid::amsl_from_wgs84(altitude_m, lat, lon)),
        Some(AltitudeType::Baro) => Some(altitude_m),
        _ => None,
    }
}
