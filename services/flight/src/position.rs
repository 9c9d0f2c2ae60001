//! The position downlink (ICD §4 #101, §5.8): the FCC tells the GCS where the aircraft is and how
//! it moves, periodically (by default 2 Hz), from guidance's progress. Sans-IO: the reporter
//! keeps the latest progress and its own deadline in a one-slot timer table; mission data
//! handling names that deadline among its timers and, when it fires, sends the #101 the
//! reporter builds, without acknowledgement request (a periodic status: a lost one is superseded
//! by the next).
//!
//! Guidance's progress carries position, altitude and ground speed, not the direction of
//! flight: the course is the direction from the previous reported position to the latest one
//! (the direction of the last movement), and #101 carries both as its horizontal velocity (U
//! Speed north, V Speed east), as STANAG 4586 does.
//!
//! Guidance reports its own climb rate, heading, bank and pitch too (NaN when it does not know
//! one). The climb rate is its vertical speed in its own simulated time, so it holds whatever
//! the time scale, which a rate computed here from the progress' host time would not. #101
//! carries them as W Speed (downwards, so the climb rate negated), Phi (roll), Theta (pitch) and
//! Psi (heading, wrapped into the I2's -pi..pi: 350 deg is sent as -10 deg), each only when the
//! value is finite and fits the field (ICD §4 #101); otherwise the field is absent, as it is
//! for a value not known.

use core::time::Duration;

use geo::Point;
use missionlink_interfaces::contracts::{GuidanceProgressPayload, WaypointListPayload};
use missionlink_interfaces::wire::{
    Altitude, AltitudeType, GeoPoint, InertialStates, Timestamp, Velocity,
};

use missionlink_protocol::geofence::earth::{bearing_deg, distance_m};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::link::timer::TimerTable;

/// The default rate of the position downlink (ICD §5.8): 2 Hz.
pub const DEFAULT_PERIOD: Duration = Duration::from_millis(500);

/// Movements shorter than this leave the course as it was: below the wire's resolution of a
/// position (about 1 cm, ICD §3) a direction is noise.
const MIN_MOVEMENT_M: f64 = 0.05;

missionlink_protocol::timers! {
    /// The one timer of the reporter: the next #101 is due.
    pub enum PositionTimer {
        /// Send the next #101.
        Report,
    }
}

/// Decides when the FCC sends #101 and what it holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionReporter {
    /// Time between two reports; `None`: the downlink is off.
    period: Option<Duration>,
    /// Guidance's latest progress, once it reported any.
    latest: Option<GuidanceProgressPayload>,
    /// The last position the course was measured from, (latitude, longitude) in degrees.
    previous: Option<(f64, f64)>,
    /// The direction of the last movement, degrees clockwise from north.
    course_deg: Option<f64>,
    timers: TimerTable<PositionTimer, 1>,
}

impl PositionReporter {
    /// A reporter that sends every `period` once guidance reported, or never with `None` (or a
    /// zero period).
    pub fn new(period: Option<Duration>) -> Self {
        Self {
            period: period.filter(|p| !p.is_zero()),
            latest: None,
            previous: None,
            course_deg: None,
            timers: TimerTable::new(),
        }
    }

    /// Guidance reported `progress` at `now`: it is what the next #101 says. The first report
    /// of guidance makes the first #101 due at once.
    pub fn handle_progress(&mut self, now: Instant, progress: &GuidanceProgressPayload) {
        if progress.sequence == 0 {
            // The idle value before guidance reported anything: no position to tell.
            return;
        }
        let here = (progress.latitude_deg, progress.longitude_deg);
        match self.previous {
            Some(before) => {
                let (a, b) = (point(before), point(here));
                if distance_m(a, b) >= MIN_MOVEMENT_M {
                    self.course_deg = Some(bearing_deg(a, b));
                    self.previous = Some(here);
                }
            }
            None => self.previous = Some(here),
        }
        self.latest = Some(*progress);
        if self.timers.get(PositionTimer::Report).is_none() && self.period.is_some() {
            self.timers.set(PositionTimer::Report, now);
        }
    }

    /// When [`Self::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.timers.next_timeout()
    }

    /// The report is due at `now`: the #101 to send (the caller stamps it, ICD §3), with the
    /// altitude type of `list` (the active waypoint list), and the next report set one period
    /// later (one period from now when the driver woke later than a whole period).
    pub fn handle_timeout(
        &mut self,
        now: Instant,
        list: &WaypointListPayload,
    ) -> Option<InertialStates> {
        let (Some(period), Some(due)) = (self.period, self.timers.get(PositionTimer::Report))
        else {
            return None;
        };
        if due > now {
            return None;
        }
        let next = due + period;
        self.timers.set(
            PositionTimer::Report,
            if next > now { next } else { now + period },
        );
        let progress = self.latest?;
        Some(self.inertial_states(&progress, list))
    }

    /// The #101 of `progress`: fields 1 to 7 and 11 to 13 as ICD §4 #101 says what the FCC
    /// fills in.
    fn inertial_states(
        &self,
        progress: &GuidanceProgressPayload,
        list: &WaypointListPayload,
    ) -> InertialStates {
        let position = GeoPoint::from_degrees(progress.latitude_deg, progress.longitude_deg).ok();
        let altitude = Altitude::from_metres(progress.altitude_m).ok();
        let altitude_type = list
            .waypoints()
            .iter()
            .find_map(|w| w.altitude_type())
            .unwrap_or(AltitudeType::Wgs84);
        let speed = progress.ground_speed_mps;
        let (u_speed, v_speed) = match self.course_deg {
            _ if speed == 0.0 => (Velocity::from_mps(0.0).ok(), Velocity::from_mps(0.0).ok()),
            Some(course) => {
                let c = course.to_radians();
                (
                    Velocity::from_mps(speed * c.cos()).ok(),
                    Velocity::from_mps(speed * c.sin()).ok(),
                )
            }
            // Moving, but not yet far enough to tell where to.
            None => (None, None),
        };
        let (u_speed, v_speed) = match (u_speed, v_speed) {
            (Some(u), Some(v)) => (Some(u), Some(v)),
            _ => (None, None),
        };
        // Written by another process: NaN is "not known", and so is anything else not finite.
        let known = |v: f32| Some(f64::from(v)).filter(|v| v.is_finite());
        // W Speed is positive downwards; a rate beyond VEL2's range (1638 m/s) is left out.
        let w_speed = known(progress.climb_rate_mps)
            .and_then(|climb| Velocity::from_mps(if climb == 0.0 { 0.0 } else { -climb }).ok());
        let angle = |deg: f32, to_raw: fn(f64) -> Option<i16>| {
            known(deg).and_then(|d| to_raw(d.to_radians()))
        };
        InertialStates {
            time_stamp: Timestamp::default(),
            latitude: position.map(|p| p.latitude),
            longitude: position.map(|p| p.longitude),
            altitude,
            altitude_type: altitude.map(|_| altitude_type),
            u_speed,
            v_speed,
            w_speed,
            phi: angle(progress.roll_deg, InertialStates::roll_from_rad),
            theta: angle(progress.pitch_deg, InertialStates::pitch_from_rad),
            psi: angle(progress.heading_deg, InertialStates::heading_from_rad),
            ..InertialStates::default()
        }
    }
}

/// (latitude, longitude) in degrees as a [`geo::Point`] (x = longitude).
fn point((latitude, longitude): (f64, f64)) -> Point<f64> {
    Point::new(longitude, latitude)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    fn progress(sequence: u64, latitude_deg: f64, longitude_deg: f64) -> GuidanceProgressPayload {
        GuidanceProgressPayload {
            sequence,
            latitude_deg,
            longitude_deg,
            altitude_m: 120.0,
            ground_speed_mps: 25.0,
            on_ground: false,
            ..GuidanceProgressPayload::IDLE
        }
    }

    /// Scripted time: nothing before guidance reports; then a report at once and one every
    /// 500 ms, nothing at t - 1 ms, the report at t.
    #[test]
    fn reports_at_the_configured_rate() {
        let list = WaypointListPayload::EMPTY;
        let mut r = PositionReporter::new(Some(DEFAULT_PERIOD));
        assert_eq!(r.poll_timeout(), None);
        r.handle_progress(at(1_000), &GuidanceProgressPayload::IDLE);
        assert_eq!(r.poll_timeout(), None, "the idle value is no report");
        r.handle_progress(at(1_000), &progress(1, 48.0, 11.0));
        assert_eq!(r.poll_timeout(), Some(at(1_000)));
        assert!(r.handle_timeout(at(1_000), &list).is_some());
        let mut sent = 1;
        for ms in 1_001..=11_000 {
            if let Some(m) = r.handle_timeout(at(ms), &list) {
                assert_eq!((ms - 1_000) % 500, 0, "a report at {ms} ms");
                assert!(m.position().is_some());
                sent += 1;
            }
        }
        // 1000, 1500, ..., 11000 ms: 21 reports in 10 s, 2 Hz.
        assert_eq!(sent, 21);
        assert_eq!(r.poll_timeout(), Some(at(11_500)));
        assert_eq!(r.handle_timeout(at(11_499), &list), None);
        assert!(r.handle_timeout(at(11_500), &list).is_some());
    }

    /// A driver that wakes late sends once and keeps the rate from then on, without a burst.
    #[test]
    fn a_late_wake_sends_once() {
        let list = WaypointListPayload::EMPTY;
        let mut r = PositionReporter::new(Some(DEFAULT_PERIOD));
        r.handle_progress(at(0), &progress(1, 48.0, 11.0));
        assert!(r.handle_timeout(at(0), &list).is_some());
        assert!(r.handle_timeout(at(2_300), &list).is_some());
        assert_eq!(r.handle_timeout(at(2_300), &list), None);
        assert_eq!(r.poll_timeout(), Some(at(2_800)));
    }

    #[test]
    fn off_sends_nothing() {
        for period in [None, Some(Duration::ZERO)] {
            let mut r = PositionReporter::new(period);
            r.handle_progress(at(0), &progress(1, 48.0, 11.0));
            assert_eq!(r.poll_timeout(), None);
            assert_eq!(
                r.handle_timeout(at(10_000), &WaypointListPayload::EMPTY),
                None
            );
        }
    }

    /// The course is the direction of the last movement; with the ground speed it makes U and
    /// V Speed (ICD §4 #101).
    #[test]
    fn velocity_follows_the_last_movement() {
        let list = WaypointListPayload::EMPTY;
        let mut r = PositionReporter::new(Some(DEFAULT_PERIOD));
        r.handle_progress(at(0), &progress(1, 48.0, 11.0));
        let first = r.handle_timeout(at(0), &list).unwrap();
        assert_eq!(
            (first.u_speed, first.v_speed),
            (None, None),
            "no course yet"
        );
        assert_eq!(first.altitude.unwrap().metres(), 120.0);
        assert_eq!(first.altitude_type, Some(AltitudeType::Wgs84));
        // Due east, then due north.
        r.handle_progress(at(100), &progress(2, 48.0, 11.001));
        let east = r.handle_timeout(at(500), &list).unwrap();
        assert!((east.course_deg().unwrap() - 90.0).abs() < 0.5, "{east}");
        assert!(
            (east.ground_speed_mps().unwrap() - 25.0).abs() < 0.05,
            "{east}"
        );
        r.handle_progress(at(600), &progress(3, 48.001, 11.001));
        let north = r.handle_timeout(at(1_000), &list).unwrap();
        let course = north.course_deg().unwrap();
        assert!(!(0.5..=359.5).contains(&course), "{north}");
        assert_eq!(
            north.position(),
            Some(GeoPoint::from_degrees(48.001, 11.001).unwrap())
        );
        // Standing still: zero velocity.
        r.handle_progress(
            at(1_100),
            &GuidanceProgressPayload {
                ground_speed_mps: 0.0,
                ..progress(4, 48.001, 11.001)
            },
        );
        let still = r.handle_timeout(at(1_500), &list).unwrap();
        assert_eq!(still.ground_speed_mps(), Some(0.0));
        assert_eq!(still.course_deg(), None);
    }

    /// The #101 of one progress, sent at once.
    fn report(progress: &GuidanceProgressPayload) -> InertialStates {
        let mut r = PositionReporter::new(Some(DEFAULT_PERIOD));
        r.handle_progress(at(0), progress);
        r.handle_timeout(at(0), &WaypointListPayload::EMPTY)
            .unwrap()
    }

    /// What guidance knows of its attitude and vertical speed goes into W Speed, Phi, Theta and
    /// Psi (ICD §4 #101): W Speed downwards, so a climb is negative; a heading of 350 deg is
    /// -10 deg in the I2; a bank to the left is negative.
    #[test]
    fn attitude_and_vertical_speed_are_sent_when_known() {
        let m = report(&GuidanceProgressPayload {
            heading_deg: 350.0,
            roll_deg: -25.0,
            pitch_deg: 2.5,
            climb_rate_mps: 1.5,
            ..progress(1, 48.0, 11.0)
        });
        assert_eq!(m.w_speed, Some(Velocity::from_mps(-1.5).unwrap()));
        assert_eq!(m.climb_rate_mps(), Some(1.5));
        let unit_deg = InertialStates::ANGLE_LSB_RAD.to_degrees();
        let deg = |rad: Option<f64>| rad.unwrap().to_degrees();
        assert!((deg(m.heading_rad()) + 10.0).abs() <= unit_deg, "{m:?}");
        assert!(m.psi.unwrap() < 0, "{m:?}");
        assert!((m.heading_deg().unwrap() - 350.0).abs() <= unit_deg);
        assert!((deg(m.roll_rad()) + 25.0).abs() <= unit_deg, "{m:?}");
        assert!((deg(m.pitch_rad()) - 2.5).abs() <= unit_deg, "{m:?}");
        // The fields' own encodings: pi / 2^15 rad per unit.
        assert_eq!(
            (m.phi, m.theta, m.psi),
            (Some(-4551), Some(455), Some(-1820))
        );

        // Descending: W Speed positive.
        let down = report(&GuidanceProgressPayload {
            climb_rate_mps: -2.0,
            ..progress(1, 48.0, 11.0)
        });
        assert_eq!(down.w_speed, Some(Velocity::from_mps(2.0).unwrap()));
        // Level, wings level, north: all present and 0.
        let level = report(&GuidanceProgressPayload {
            heading_deg: 0.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            climb_rate_mps: 0.0,
            ..progress(1, 48.0, 11.0)
        });
        assert_eq!(level.w_speed, Some(Velocity::from_raw(0)));
        assert_eq!(
            (level.phi, level.theta, level.psi),
            (Some(0), Some(0), Some(0))
        );
    }

    /// NaN is guidance's "not known": the field is absent, and so is one for a value that is not
    /// finite or does not fit the field; what is known is sent beside it.
    #[test]
    fn attitude_and_vertical_speed_not_known_are_absent() {
        let unknown = report(&progress(1, 48.0, 11.0));
        assert!(GuidanceProgressPayload::IDLE.heading_deg.is_nan());
        assert_eq!(
            (unknown.w_speed, unknown.phi, unknown.theta, unknown.psi),
            (None, None, None, None)
        );
        let odd = report(&GuidanceProgressPayload {
            heading_deg: f32::INFINITY,
            roll_deg: f32::NEG_INFINITY,
            pitch_deg: 3.0,
            climb_rate_mps: 5_000.0,
            ..progress(1, 48.0, 11.0)
        });
        assert_eq!((odd.w_speed, odd.phi, odd.psi), (None, None, None));
        assert!(odd.theta.is_some());
        // The frame carries exactly what is present: it decodes to the same.
        use missionlink_interfaces::wire::MessageBody;
        let mut buf = [0u8; 64];
        let len = odd.encode(&mut buf).unwrap();
        assert_eq!(InertialStates::decode(&buf[..len]).unwrap(), odd);
    }
}
