//! The energy estimate and its checks (`ENERGY-*`, see the [module documentation](super)).

use super::*;

impl SafetyGateway {
    /// The energy estimate (see the module documentation), with the legs whose track cannot be
    /// held against the wind (left out of the sum).
    pub(super) fn energy(
        &self,
        mission: &Mission,
        from_take_off_point: bool,
        legs: &[Leg],
    ) -> (EnergyEstimate, Vec<(u16, u16, Option<Site>)>) {
        let p = &self.profile;
        let env = &self.environment;
        let toh = mission.take_off_height().metres().max(0.0);
        let climb = |dh: f64| p.climb_power_w * dh.max(0.0) / p.climb_rate_mps / 3600.0;
        let descend = |dh: f64| p.descent_power_w * dh.max(0.0) / p.descent_rate_mps / 3600.0;
        let mut take_off_wh = climb(toh);
        // Without a take-off point the route starts at the initial waypoint: climb (or descend)
        // there to its altitude.
        if !from_take_off_point && let Some(first) = mission.waypoints.first() {
            let dh = first.waypoint.altitude.metres() - toh;
            take_off_wh += if dh >= 0.0 { climb(dh) } else { descend(-dh) };
        }
        // Wind vector (east, north) the air moves with.
        let from = env.wind_from_deg.to_radians();
        let wind = (
            -env.wind_speed_mps * from.sin(),
            -env.wind_speed_mps * from.cos(),
        );
        let mut cruise_wh = 0.0;
        let mut not_held = Vec::new();
        for leg in legs {
            let v = leg.speed_mps;
            let mut seconds = 0.0;
            let mut held = true;
            let track = Track::new(leg.path);
            for (patch, start, direction, length) in track.chords() {
                let t = (direction.to_radians().sin(), direction.to_radians().cos());
                let along = wind.0 * t.0 + wind.1 * t.1;
                let cross = wind.0 * t.1 - wind.1 * t.0;
                let disc = v * v - cross * cross;
                let ground = along + disc.max(0.0).sqrt();
                if disc <= 0.0 || ground <= 0.1 {
                    held = false;
                    not_held.push((leg.from, leg.to, track.site(patch, start)));
                    break;
                }
                seconds += length / ground;
            }
            if held {
                cruise_wh += p.cruise_power_w(v) * seconds / 3600.0 + climb(leg.climb_m);
            }
        }
        let landing_wh = mission
            .waypoints
            .last()
            .map(|w| descend(w.waypoint.altitude.metres()))
            .unwrap_or(0.0);
        let total_wh = take_off_wh + cruise_wh + landing_wh;
        (
            EnergyEstimate {
                take_off_wh,
                cruise_wh,
                landing_wh,
                total_wh,
                limit_wh: p.energy_limit_wh(),
            },
            not_held,
        )
    }

    /// The energy checks: every leg whose track cannot be held, and the estimate against the
    /// usable energy less the reserve.
    pub(super) fn check_energy(
        &self,
        mission: &Mission,
        from_take_off_point: bool,
        legs: &[Leg],
        c: &mut Collector,
    ) {
        let (p, env) = (&self.profile, &self.environment);
        let (estimate, not_held) = self.energy(mission, from_take_off_point, legs);
        for (from, to, at) in not_held {
            c.push(
                ViolationCode::TrackNotHeld,
                Element::Route(RouteElement::Leg { from, to }),
                format!(
                    "the track cannot be held against {} m/s wind from {} deg",
                    env.wind_speed_mps, env.wind_from_deg
                ),
                None,
            );
            if let Some(at) = at {
                c.at(at);
            }
        }
        if exceeds(estimate.total_wh, estimate.limit_wh) {
            c.push(
                ViolationCode::EnergyBudget,
                Element::Mission,
                format!(
                    "estimated energy {:.0} Wh (take-off {:.0}, cruise {:.0}, landing {:.0}) above usable {:.0} Wh minus {:.0} % reserve",
                    estimate.total_wh,
                    estimate.take_off_wh,
                    estimate.cruise_wh,
                    estimate.landing_wh,
                    p.usable_energy_wh,
                    p.reserve_fraction * 100.0
                ),
                Some((estimate.total_wh, estimate.limit_wh)),
            );
        }
    }
}
