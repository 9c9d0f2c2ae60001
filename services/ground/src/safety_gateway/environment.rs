//! Environment checks (`ENV-*`, see the [module documentation](super)): wind speed and
//! temperature against the profile's limits.

use super::*;

impl SafetyGateway {
    pub(super) fn check_environment(&self, c: &mut Collector) {
        let (p, env) = (&self.profile, &self.environment);
        if exceeds(env.wind_speed_mps, p.max_wind_mps) {
            c.push(
                ViolationCode::Wind,
                Element::Environment,
                format!(
                    "wind {} m/s above {} m/s",
                    env.wind_speed_mps, p.max_wind_mps
                ),
                Some((env.wind_speed_mps, p.max_wind_mps)),
            );
        }
        let t = env.temperature_c;
        if below(t, p.min_temperature_c) {
            c.push(
                ViolationCode::Temperature,
                Element::Environment,
                format!("temperature {t} °C below {} °C", p.min_temperature_c),
                Some((t, p.min_temperature_c)),
            );
        } else if exceeds(t, p.max_temperature_c) {
            c.push(
                ViolationCode::Temperature,
                Element::Environment,
                format!("temperature {t} °C above {} °C", p.max_temperature_c),
                Some((t, p.max_temperature_c)),
            );
        }
    }
}
