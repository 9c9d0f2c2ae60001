//! What the checks are checked against: the aircraft's limits and power model
//! ([`AircraftProfile`]) and the conditions of the flight ([`Environment`]).

use missionlink_interfaces::wire::Speed;

use super::GRAVITY_MPS2;

/// The aircraft's limits and its power model.
///
/// The [`Default`] is the demo eVTOL of the medical evacuation (the paper gives no figures;
/// these are this project's plausible choice for a ~150 kg multicopter-type cargo eVTOL):
///
/// | field | default |
/// |---|---|
/// | speed envelope | 5 to 40 m/s |
/// | bank limit | 25° (minimum turn radius 137 m at 25 m/s; the guidance stub's bank, so that the fly-by turns checked are the ones flown) |
/// | take-off height | 10 to 100 m above ground |
/// | maximum altitude | 150 m |
/// | usable battery energy, reserve | 6000 Wh, 30 % |
/// | climb rate, climb power | 3 m/s, 22 kW |
/// | descent rate, descent power | 2 m/s, 12 kW |
/// | cruise power | `P(v) = 8 kW + 20 W/(m/s)²·(v − 25 m/s)²` |
/// | wind limit | 12 m/s |
/// | temperature | −20 to 45 °C |
/// | RF radius tolerance | 5 m |
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AircraftProfile {
    /// Lowest commanded speed on a leg, m/s.
    pub min_speed_mps: f64,
    /// Highest commanded speed on a leg, m/s.
    pub max_speed_mps: f64,
    /// Bank angle limit, degrees (0 < bank < 90).
    pub max_bank_deg: f64,
    /// Lowest take-off height, metres above ground.
    pub min_take_off_height_m: f64,
    /// Highest take-off height, metres above ground.
    pub max_take_off_height_m: f64,
    /// Highest waypoint altitude, metres.
    pub max_altitude_m: f64,
    /// Usable battery energy, Wh.
    pub usable_energy_wh: f64,
    /// Fraction of the usable energy kept as reserve (0..1).
    pub reserve_fraction: f64,
    /// Vertical climb rate, m/s.
    pub climb_rate_mps: f64,
    /// Power in hover and vertical climb, W.
    pub climb_power_w: f64,
    /// Vertical descent rate, m/s.
    pub descent_rate_mps: f64,
    /// Power in vertical descent, W.
    pub descent_power_w: f64,
    /// Cruise power at the best-endurance speed, W.
    pub cruise_min_power_w: f64,
    /// Speed of least cruise power, m/s.
    pub best_speed_mps: f64,
    /// Cruise power growth away from the best speed, W/(m/s)².
    pub cruise_power_k_w_per_mps2: f64,
    /// Highest wind speed, m/s.
    pub max_wind_mps: f64,
    /// Lowest operating temperature, °C.
    pub min_temperature_c: f64,
    /// Highest operating temperature, °C.
    pub max_temperature_c: f64,
    /// Largest difference of a radius-to-fix leg's start and end radius, metres.
    pub rf_radius_tolerance_m: f64,
}

impl Default for AircraftProfile {
    fn default() -> Self {
        Self {
            min_speed_mps: 5.0,
            max_speed_mps: 40.0,
            max_bank_deg: 25.0,
            min_take_off_height_m: 10.0,
            max_take_off_height_m: 100.0,
            max_altitude_m: 150.0,
            usable_energy_wh: 6000.0,
            reserve_fraction: 0.3,
            climb_rate_mps: 3.0,
            climb_power_w: 22_000.0,
            descent_rate_mps: 2.0,
            descent_power_w: 12_000.0,
            cruise_min_power_w: 8_000.0,
            best_speed_mps: 25.0,
            cruise_power_k_w_per_mps2: 20.0,
            max_wind_mps: 12.0,
            min_temperature_c: -20.0,
            max_temperature_c: 45.0,
            rf_radius_tolerance_m: 5.0,
        }
    }
}

impl AircraftProfile {
    /// Cruise power at airspeed `v`: `P_min + k·(v − v_best)²`, W.
    pub fn cruise_power_w(&self, airspeed_mps: f64) -> f64 {
        let dv = airspeed_mps - self.best_speed_mps;
        self.cruise_min_power_w + self.cruise_power_k_w_per_mps2 * dv * dv
    }

    /// Minimum turn radius at ground speed `v` and the bank limit: `v²/(g·tan(bank))`, metres.
    pub fn min_turn_radius_m(&self, speed_mps: f64) -> f64 {
        speed_mps * speed_mps / (GRAVITY_MPS2 * self.max_bank_deg.to_radians().tan())
    }

    /// Energy the mission may use: usable energy minus the reserve, Wh.
    pub fn energy_limit_wh(&self) -> f64 {
        self.usable_energy_wh * (1.0 - self.reserve_fraction)
    }
}

/// The conditions at the time of the flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Environment {
    /// Wind speed, m/s.
    pub wind_speed_mps: f64,
    /// Direction the wind blows from, degrees clockwise from true north.
    pub wind_from_deg: f64,
    /// Outside air temperature, °C.
    pub temperature_c: f64,
}

impl Environment {
    /// The wind speed as the plan carries it (#13001 field 5, ICD §7 "Turns in wind"): rounded
    /// up to the wire's 0.5 m/s, so that the turns flown are never sized for less wind than
    /// the environment gives; `None` in calm air (and for a speed that is not a number or not
    /// above 0, which the environment check reports where it is out of limits).
    pub fn planning_wind(&self) -> Option<Speed> {
        let steps = (self.wind_speed_mps / Speed::LSB_MPS).ceil();
        (steps.is_finite() && steps >= 1.0)
            .then(|| Speed::from_raw(steps.min(f64::from(u16::MAX)) as u16))
    }
}

impl Default for Environment {
    /// Calm, 15 °C (ISA sea level).
    fn default() -> Self {
        Self {
            wind_speed_mps: 0.0,
            wind_from_deg: 0.0,
            temperature_c: 15.0,
        }
    }
}
