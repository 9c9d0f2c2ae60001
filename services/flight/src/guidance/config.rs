//! The guidance model's settings: start position, climb and descent rates, bank limit, the
//! steady wind it flies in, time scale, each replaced by its default where unusable.

use missionlink_protocol::geofence::flown_route::FlyBy;

/// Settings of the guidance model, as the FCC's configuration file's `[guidance]` table gives
/// them (every field optional, unknown names refused).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct GuidanceConfig {
    /// Start latitude on the ground (degrees); default: TROL 48.26 from the demo missions.
    pub start_latitude_deg: f64,
    /// Start longitude on the ground (degrees); default: TROL 11.66 from the demo missions.
    pub start_longitude_deg: f64,
    /// Climb rate of the take-off (m/s), default 3.0.
    pub climb_rate_mps: f64,
    /// Descent rate of the landing (m/s), default 2.0.
    pub descent_rate_mps: f64,
    /// Bank angle of the turns at waypoints (deg; their radius is `(v + W)²/(g·tan(bank))`, `W`
    /// the plan's wind),
    /// default 25.
    pub max_bank_deg: f64,
    /// Simulated seconds per real second (demo time scale), default 1.0; 0 pauses.
    pub time_scale: f64,
    /// Speed of the steady wind the simulated aircraft flies in (m/s), default 0 (calm). The
    /// turns' radius is the plan's ([`missionlink_protocol::geofence::flown_route::FlyBy`]); this wind sets the
    /// ground speed along each path, and so the bank the path takes.
    pub wind_speed_mps: f64,
    /// Direction the wind blows from, degrees clockwise from true north, default 0.
    pub wind_from_deg: f64,
    /// How often the guidance partition steps the model and publishes its progress (ms),
    /// default 50; the model itself takes any step (it sub-steps long ones).
    pub update_interval_ms: u64,
}

impl Default for GuidanceConfig {
    fn default() -> Self {
        Self {
            start_latitude_deg: 48.26,
            start_longitude_deg: 11.66,
            climb_rate_mps: 3.0,
            descent_rate_mps: 2.0,
            max_bank_deg: 25.0,
            time_scale: 1.0,
            wind_speed_mps: 0.0,
            wind_from_deg: 0.0,
            update_interval_ms: 50,
        }
    }
}

impl GuidanceConfig {
    /// How this guidance turns at waypoints, for the geofence ([`missionlink_protocol::geofence::turn`] at
    /// its bank: the construction [`Guidance`] flies, sized for the wind of the plan flown).
    pub fn fly_by(&self) -> FlyBy {
        FlyBy {
            bank_deg: self.sanitized().max_bank_deg,
        }
    }

    /// Ground speed flying at airspeed `v` along a ground course of `course_deg` in the
    /// configured wind: the along-track wind plus what is left of `v` after the crab angle
    /// cancels the crosswind, m/s. Where the wind leaves no forward speed on this course (the
    /// safety gateway refuses such a leg, `ENERGY-TRACK`), a twentieth of `v`, so that the
    /// model keeps moving along the path it was given.
    pub fn ground_speed_mps(&self, v: f64, course_deg: f64) -> f64 {
        let c = self.sanitized();
        let w = c.wind_speed_mps;
        // Angle between the course and where the wind blows to.
        let delta = (course_deg - (c.wind_from_deg + 180.0)).to_radians();
        let (along, cross) = (w * delta.cos(), w * delta.sin());
        let ground = along + (v * v - cross * cross).max(0.0).sqrt();
        if ground.is_finite() && ground > v / 20.0 {
            ground
        } else {
            v / 20.0
        }
    }

    /// The crab angle flying at airspeed `v` along a ground course of `course_deg` in the
    /// configured wind: how far the nose is turned into the crosswind to cancel it,
    /// `asin(crosswind / v)`, degrees, positive clockwise (the same crosswind as
    /// [`Self::ground_speed_mps`]). Where the crosswind is stronger than `v` (the model then
    /// moves at a twentieth of `v`), the nose points square to the course, into the wind.
    pub fn crab_deg(&self, v: f64, course_deg: f64) -> f64 {
        let c = self.sanitized();
        // Angle between the course and where the wind blows to: a wind blowing to the right of
        // the course (sin < 0 here) is met with the nose turned left.
        let delta = (course_deg - (c.wind_from_deg + 180.0)).to_radians();
        let cross = c.wind_speed_mps * delta.sin();
        if v > 0.0 {
            (cross / v).clamp(-1.0, 1.0).asin().to_degrees()
        } else {
            0.0
        }
    }

    /// The true heading flying at airspeed `v` along a ground course of `course_deg` in the
    /// configured wind: the course turned by [`Self::crab_deg`], degrees clockwise from north
    /// in 0..360. Equal to the course in calm air.
    pub fn heading_deg(&self, v: f64, course_deg: f64) -> f64 {
        let heading = (course_deg + self.crab_deg(v, course_deg)).rem_euclid(360.0);
        // rem_euclid rounds a tiny negative angle up to 360 itself.
        if heading < 360.0 { heading } else { 0.0 }
    }

    /// The configuration with every unusable value replaced by its default: non-finite or
    /// non-positive rates, a bank outside 0..90 deg, a negative or non-finite time scale, a
    /// start position off the globe, a wind speed that is negative or not a number, a wind
    /// direction that is not a number.
    pub(super) fn sanitized(self) -> Self {
        let d = Self::default();
        let positive = |v: f64, default: f64| {
            if v.is_finite() && v > 0.0 { v } else { default }
        };
        Self {
            start_latitude_deg: if (-90.0..=90.0).contains(&self.start_latitude_deg) {
                self.start_latitude_deg
            } else {
                d.start_latitude_deg
            },
            start_longitude_deg: if (-180.0..=180.0).contains(&self.start_longitude_deg) {
                self.start_longitude_deg
            } else {
                d.start_longitude_deg
            },
            climb_rate_mps: positive(self.climb_rate_mps, d.climb_rate_mps),
            descent_rate_mps: positive(self.descent_rate_mps, d.descent_rate_mps),
            max_bank_deg: if self.max_bank_deg > 0.0 && self.max_bank_deg < 90.0 {
                self.max_bank_deg
            } else {
                d.max_bank_deg
            },
            time_scale: if self.time_scale.is_finite() && self.time_scale >= 0.0 {
                self.time_scale
            } else {
                d.time_scale
            },
            wind_speed_mps: if self.wind_speed_mps.is_finite() && self.wind_speed_mps >= 0.0 {
                self.wind_speed_mps
            } else {
                d.wind_speed_mps
            },
            wind_from_deg: if self.wind_from_deg.is_finite() {
                self.wind_from_deg.rem_euclid(360.0)
            } else {
                d.wind_from_deg
            },
            update_interval_ms: if self.update_interval_ms > 0 {
                self.update_interval_ms
            } else {
                d.update_interval_ms
            },
        }
    }
}
