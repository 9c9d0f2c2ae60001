//! Route checks (`ROUTE-*`, see the [module documentation](super)): radius-to-fix radii, the
//! speed envelope, altitudes and the take-off height.

use super::*;

impl SafetyGateway {
    pub(super) fn check_route(
        &self,
        mission: &Mission,
        areas: &AreaList,
        legs: &[Leg],
        c: &mut Collector,
    ) {
        let p = &self.profile;
        let toh = mission.take_off_height().metres();
        if below(toh, p.min_take_off_height_m) {
            c.push(
                ViolationCode::TakeOffHeightLow,
                Element::TakeOff,
                format!(
                    "take-off height {toh} m below {} m",
                    p.min_take_off_height_m
                ),
                Some((toh, p.min_take_off_height_m)),
            );
        }
        if exceeds(toh, p.max_take_off_height_m) {
            c.push(
                ViolationCode::TakeOffHeightHigh,
                Element::TakeOff,
                format!(
                    "take-off height {toh} m above {} m",
                    p.max_take_off_height_m
                ),
                Some((toh, p.max_take_off_height_m)),
            );
        }
        let fz = areas.fly_zone();
        for record in &mission.waypoints {
            let w = &record.waypoint;
            let n = w.waypoint_number;
            let here = position(record);
            let (v, alt) = (w.speed.mps(), w.altitude.metres());
            if below(v, p.min_speed_mps) {
                c.push(
                    ViolationCode::SpeedLow,
                    Element::Waypoint(n),
                    format!("speed {v} m/s below {} m/s", p.min_speed_mps),
                    Some((v, p.min_speed_mps)),
                );
                c.at(here);
            }
            if exceeds(v, p.max_speed_mps) {
                c.push(
                    ViolationCode::SpeedHigh,
                    Element::Waypoint(n),
                    format!("speed {v} m/s above {} m/s", p.max_speed_mps),
                    Some((v, p.max_speed_mps)),
                );
                c.at(here);
            }
            if exceeds(alt, p.max_altitude_m) {
                c.push(
                    ViolationCode::AltitudeHigh,
                    Element::Waypoint(n),
                    format!("altitude {alt} m above {} m", p.max_altitude_m),
                    Some((alt, p.max_altitude_m)),
                );
                c.at(here);
            }
            if let Some(lo) = fz.and_then(|a| a.lower_altitude).map(|a| a.metres())
                && below(alt, lo)
            {
                c.push(
                    ViolationCode::AreaAltitude,
                    Element::Waypoint(n),
                    format!("altitude {alt} m below the fly-zone's lower bound {lo} m"),
                    Some((alt, lo)),
                );
                c.at(here);
            }
            if let Some(hi) = fz.and_then(|a| a.upper_altitude).map(|a| a.metres())
                && exceeds(alt, hi)
            {
                c.push(
                    ViolationCode::AreaAltitude,
                    Element::Waypoint(n),
                    format!("altitude {alt} m above the fly-zone's upper bound {hi} m"),
                    Some((alt, hi)),
                );
                c.at(here);
            }
        }
        // Radius-to-fix legs.
        for leg in legs {
            let (Some(from_index), Some(to)) =
                (leg.from_index, mission.waypoints.get(leg.to_index))
            else {
                continue;
            };
            let (Some(from), Some(centre)) = (mission.waypoints.get(from_index), rf_centre(to))
            else {
                continue;
            };
            if to.waypoint.leg_type != LegType::RadiusToFix {
                continue;
            }
            let rs = earth::distance_m(centre, position(from));
            let re = earth::distance_m(centre, position(to));
            let element = Element::Route(RouteElement::Leg {
                from: leg.from,
                to: leg.to,
            });
            let diff = (rs - re).abs();
            if exceeds(diff, p.rf_radius_tolerance_m) {
                c.push(
                    ViolationCode::RfRadiusMismatch,
                    element,
                    format!(
                        "start radius {rs:.1} m and end radius {re:.1} m differ by {diff:.1} m"
                    ),
                    Some((diff, p.rf_radius_tolerance_m)),
                );
                c.at(centre);
            }
            // The ground speed of a tailwind (ICD §7 "Turns in wind"): the wind the turns are
            // checked in, from whatever direction.
            let ground = leg.speed_mps + self.turn_wind_mps(mission);
            let min_r = p.min_turn_radius_m(ground);
            let r = rs.min(re);
            if below(r, min_r) {
                c.push(
                    ViolationCode::TurnRadius,
                    element,
                    format!(
                        "arc radius {r:.1} m below the minimum turn radius {min_r:.1} m at {ground:.1} m/s and {} deg bank",
                        p.max_bank_deg
                    ),
                    Some((r, min_r)),
                );
                c.at(centre);
            }
        }
    }
}
