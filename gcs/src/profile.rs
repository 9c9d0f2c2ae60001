//! The aircraft profile and the environment of the safety gateway as TOML files: every key
//! optional, the demo eVTOL's values (`missionlink_ground::safety_gateway::AircraftProfile::default`) where
//! a key is absent. Units are in the key names.
//!
//! ```toml
//! # aircraft.toml: the demo eVTOL
//! min_speed_mps = 5.0
//! max_speed_mps = 40.0
//! max_bank_deg = 25.0
//! min_take_off_height_m = 10.0
//! max_take_off_height_m = 100.0
//! max_altitude_m = 150.0
//! usable_energy_wh = 6000.0
//! reserve_fraction = 0.3
//! climb_rate_mps = 3.0
//! climb_power_w = 22000.0
//! descent_rate_mps = 2.0
//! descent_power_w = 12000.0
//! cruise_min_power_w = 8000.0
//! best_speed_mps = 25.0
//! cruise_power_k_w_per_mps2 = 20.0
//! max_wind_mps = 12.0
//! min_temperature_c = -20.0
//! max_temperature_c = 45.0
//! rf_radius_tolerance_m = 5.0
//! ```
//!
//! ```toml
//! # environment.toml
//! wind_speed_mps = 6.0
//! wind_from_deg = 270.0
//! temperature_c = 12.0
//! ```

use std::path::Path;

use missionlink_ground::safety_gateway::{AircraftProfile, Environment};
use serde::{Deserialize, Serialize};

use missionlink_platform::config::line_column;

macro_rules! toml_mirror {
    ($file:ident => $target:ident { $($field:ident),+ $(,)? }) => {
        /// The TOML form of the services type of the same fields.
        #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $file {
            $(
                #[allow(missing_docs)]
                pub $field: f64,
            )+
        }

        impl Default for $file {
            fn default() -> Self {
                Self::from($target::default())
            }
        }

        impl From<$target> for $file {
            fn from(v: $target) -> Self {
                Self { $($field: v.$field),+ }
            }
        }

        impl From<$file> for $target {
            fn from(v: $file) -> Self {
                Self { $($field: v.$field),+ }
            }
        }
    };
}

toml_mirror!(ProfileFile => AircraftProfile {
    min_speed_mps,
    max_speed_mps,
    max_bank_deg,
    min_take_off_height_m,
    max_take_off_height_m,
    max_altitude_m,
    usable_energy_wh,
    reserve_fraction,
    climb_rate_mps,
    climb_power_w,
    descent_rate_mps,
    descent_power_w,
    cruise_min_power_w,
    best_speed_mps,
    cruise_power_k_w_per_mps2,
    max_wind_mps,
    min_temperature_c,
    max_temperature_c,
    rf_radius_tolerance_m,
});

toml_mirror!(EnvironmentFile => Environment {
    wind_speed_mps,
    wind_from_deg,
    temperature_c,
});

fn read<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    toml::from_str(&text).map_err(|e| {
        let (line, column) = e
            .span()
            .map_or((0, 0), |span| line_column(&text, span.start));
        format!("{}:{line}:{column}: {}", path.display(), e.message())
    })
}

/// The aircraft profile of `path`, or the demo eVTOL's.
pub fn aircraft(path: Option<&Path>) -> Result<AircraftProfile, String> {
    match path {
        Some(p) => read::<ProfileFile>(p).map(AircraftProfile::from),
        None => Ok(AircraftProfile::default()),
    }
}

/// The environment of `path`, or calm air at 15 °C.
pub fn environment(path: Option<&Path>) -> Result<Environment, String> {
    match path {
        Some(p) => read::<EnvironmentFile>(p).map(Environment::from),
        None => Ok(Environment::default()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_defaults_are_the_demo_evtol() {
        let doc = ProfileFile::default();
        let text = toml::to_string(&doc).unwrap();
        let back: ProfileFile = toml::from_str(&text).unwrap();
        assert_eq!(back, doc);
        assert_eq!(AircraftProfile::from(doc), AircraftProfile::default());
    }

    #[test]
    fn a_file_overrides_what_it_names_and_errors_name_line_and_column() {
        let dir = tempfile::Builder::new()
            .prefix("profile-test-")
            .tempdir()
            .unwrap();
        let p = dir.path().join("a.toml");
        std::fs::write(&p, "max_wind_mps = 20.0\n").unwrap();
        let a = aircraft(Some(&p)).unwrap();
        assert_eq!(a.max_wind_mps, 20.0);
        assert_eq!(a.max_speed_mps, AircraftProfile::default().max_speed_mps);
        std::fs::write(&p, "max_wind = 20.0\n").unwrap();
        let e = aircraft(Some(&p)).unwrap_err();
        assert!(
            e.contains("a.toml:1:1") && e.contains("unknown field"),
            "{e}"
        );
        std::fs::write(&p, "wind_speed_mps = \"x\"\n").unwrap();
        let e = environment(Some(&p)).unwrap_err();
        assert!(e.contains("a.toml:1:18"), "{e}");
    }
}
