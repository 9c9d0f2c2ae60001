//! #101 Inertial States (ICD §4, std field order; ICD §5.8): where the aircraft is and how it
//! moves, the position downlink. The FCC sends it periodically from guidance's progress, never
//! acknowledged: a lost one is superseded by the next.
//!
//! Ground speed and course are not fields of their own: they are the horizontal part of the
//! north and east velocity (U Speed, V Speed), as STANAG 4586 carries them
//! ([`InertialStates::ground_speed_mps`], [`InertialStates::course_deg`]).
//!
//! Phi, Theta and Psi (roll, pitch, heading) stay the raw I2 of the wire, pi / 2^15 rad per
//! unit (ICD §4 #101); [`InertialStates::roll_rad`] and its siblings read them, and
//! [`InertialStates::roll_from_rad`] and its siblings make them from radians: an angle wrapped
//! into the field's -pi..pi, a pitch clamped to -pi/2..=pi/2.

use core::f64::consts::{FRAC_PI_2, PI, TAU};
use core::fmt;

use super::{GeoPoint, MessageBody, MessageType, latitude, reader};
use crate::wire::enums::AltitudeType;
use crate::wire::error::{Cause, EncodeError, MessageError};
use crate::wire::field::{Altitude, Angle, Timestamp, Velocity};
use crate::wire::presence::Writer;

/// #101.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct InertialStates {
    /// Bit 0, M: when the state was valid (the time it was sent, ICD §5.8).
    pub time_stamp: Timestamp,
    /// Bit 1; present with Longitude.
    pub latitude: Option<Angle>,
    /// Bit 2; present with Latitude.
    pub longitude: Option<Angle>,
    /// Bit 3; present with Altitude Type.
    pub altitude: Option<Altitude>,
    /// Bit 4.
    pub altitude_type: Option<AltitudeType>,
    /// Bit 5: the velocity towards north.
    pub u_speed: Option<Velocity>,
    /// Bit 6: the velocity towards east.
    pub v_speed: Option<Velocity>,
    /// Bit 7: the velocity downwards; the FCC sends guidance's climb rate, negated, when
    /// guidance knows it ([`Self::climb_rate_mps`]).
    pub w_speed: Option<Velocity>,
    /// Bit 8: north acceleration, 0.01 m/s² per unit; raw I2, never filled by this project.
    pub u_accel: Option<i16>,
    /// Bit 9: east acceleration, 0.01 m/s² per unit; raw I2, never filled by this project.
    pub v_accel: Option<i16>,
    /// Bit 10: downward acceleration, 0.01 m/s² per unit; raw I2, never filled by this project.
    pub w_accel: Option<i16>,
    /// Bit 11: roll, pi / 2^15 rad per unit, positive right wing down; raw I2. The FCC sends
    /// guidance's bank when guidance knows it ([`Self::roll_rad`], [`Self::roll_from_rad`]).
    pub phi: Option<i16>,
    /// Bit 12: pitch, pi / 2^15 rad per unit, positive nose up; raw I2. The FCC sends guidance's
    /// pitch when guidance knows it ([`Self::pitch_rad`], [`Self::pitch_from_rad`]).
    pub theta: Option<i16>,
    /// Bit 13: true heading, where the nose points, pi / 2^15 rad per unit clockwise from true
    /// north, in -pi..pi; raw I2. The FCC sends guidance's heading when guidance knows it
    /// ([`Self::heading_rad`], [`Self::heading_from_rad`]).
    pub psi: Option<i16>,
    /// Bit 14: roll rate, 0.001 rad/s per unit; raw I2, never filled by this project.
    pub phi_dot: Option<i16>,
    /// Bit 15: pitch rate, 0.001 rad/s per unit; raw I2, never filled by this project.
    pub theta_dot: Option<i16>,
    /// Bit 16: yaw rate, 0.001 rad/s per unit; raw I2, never filled by this project.
    pub psi_dot: Option<i16>,
    /// Bit 17: magnetic variation, pi / 2^15 rad per unit; raw I2, never filled by this project.
    pub magnetic_variation: Option<i16>,
}

impl InertialStates {
    /// Radians per unit of Phi, Theta, Psi and Magnetic Variation: pi / 2^15.
    pub const ANGLE_LSB_RAD: f64 = PI / 32_768.0;

    /// The position, when both latitude and longitude are present.
    pub fn position(&self) -> Option<GeoPoint> {
        Some(GeoPoint {
            latitude: self.latitude?,
            longitude: self.longitude?,
        })
    }

    /// Ground speed in m/s: the length of the horizontal velocity (U Speed, V Speed).
    pub fn ground_speed_mps(&self) -> Option<f64> {
        Some(self.u_speed?.mps().hypot(self.v_speed?.mps()))
    }

    /// Course over ground, degrees clockwise from true north in 0..360: the direction of the
    /// horizontal velocity; `None` without it or when it is zero.
    pub fn course_deg(&self) -> Option<f64> {
        let (u, v) = (self.u_speed?.raw(), self.v_speed?.raw());
        if u == 0 && v == 0 {
            return None;
        }
        Some(
            f64::from(v)
                .atan2(f64::from(u))
                .to_degrees()
                .rem_euclid(360.0),
        )
    }

    /// Vertical speed in m/s, positive up: W Speed (positive down) negated.
    pub fn climb_rate_mps(&self) -> Option<f64> {
        let down = self.w_speed?.mps();
        // Level is 0, not -0 (which prints as "-0.0").
        Some(if down == 0.0 { 0.0 } else { -down })
    }

    /// Roll (Phi) in radians, positive right wing down, in -pi..pi.
    pub fn roll_rad(&self) -> Option<f64> {
        self.phi.map(angle_rad)
    }

    /// Pitch (Theta) in radians, positive nose up.
    pub fn pitch_rad(&self) -> Option<f64> {
        self.theta.map(angle_rad)
    }

    /// True heading (Psi) in radians clockwise from true north, in -pi..pi.
    pub fn heading_rad(&self) -> Option<f64> {
        self.psi.map(angle_rad)
    }

    /// True heading (Psi) in degrees clockwise from true north, in 0..360, as
    /// [`Self::course_deg`] gives the course.
    pub fn heading_deg(&self) -> Option<f64> {
        Some(self.heading_rad()?.to_degrees().rem_euclid(360.0))
    }

    /// Phi of a roll of `rad` radians: wrapped into -pi..pi (a roll of 190 deg is one of -170),
    /// to the nearest unit; `None` when `rad` is not finite (not known).
    pub fn roll_from_rad(rad: f64) -> Option<i16> {
        wrapped_angle(rad)
    }

    /// Theta of a pitch of `rad` radians: clamped to -pi/2..=pi/2 (the nose points no higher
    /// than straight up), to the nearest unit; `None` when `rad` is not finite (not known).
    pub fn pitch_from_rad(rad: f64) -> Option<i16> {
        if !rad.is_finite() {
            return None;
        }
        // Within -16384..=16384 units: the cast cannot saturate.
        Some((rad.clamp(-FRAC_PI_2, FRAC_PI_2) / Self::ANGLE_LSB_RAD).round() as i16)
    }

    /// Psi of a heading of `rad` radians clockwise from true north: wrapped into -pi..pi, as
    /// the I2 field holds it (a heading of 350 deg is one of -10 deg), to the nearest unit;
    /// `None` when `rad` is not finite (not known).
    pub fn heading_from_rad(rad: f64) -> Option<i16> {
        wrapped_angle(rad)
    }
}

/// An I2 angle (pi / 2^15 rad per unit) in radians.
fn angle_rad(raw: i16) -> f64 {
    f64::from(raw) * InertialStates::ANGLE_LSB_RAD
}

/// `rad` as an I2 angle: wrapped into -pi..pi, where +pi, one unit beyond the field's largest
/// value, is the same angle as -pi, its smallest; `None` when `rad` is not finite.
fn wrapped_angle(rad: f64) -> Option<i16> {
    if !rad.is_finite() {
        return None;
    }
    let units = ((rad + PI).rem_euclid(TAU) - PI) / InertialStates::ANGLE_LSB_RAD;
    // -32768.0..=32768.0 after rounding; 32768 units is +pi, which the field writes as -pi.
    let units = units.round();
    Some(if units >= 32_768.0 {
        i16::MIN
    } else {
        units as i16
    })
}

impl MessageBody for InertialStates {
    const TYPE: MessageType = MessageType::InertialStates;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Latitude",
        "Longitude",
        "Altitude",
        "Altitude Type",
        "U Speed",
        "V Speed",
        "W Speed",
        "U Accel",
        "V Accel",
        "W Accel",
        "Phi",
        "Theta",
        "Psi",
        "Phi Dot",
        "Theta Dot",
        "Psi Dot",
        "Magnetic Variation",
    ];
    const PV_BYTES: usize = 3;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let latitude = match r.optional(1)? {
            Some(a) => Some(latitude(&r, 1, a)?),
            None => None,
        };
        let longitude: Option<Angle> = r.optional(2)?;
        let altitude: Option<Altitude> = r.optional(3)?;
        let altitude_type: Option<AltitudeType> = r.optional(4)?;
        // A position is a pair, and an altitude means nothing without its reference.
        match (latitude, longitude) {
            (Some(_), None) => return Err(r.error(2, Cause::MissingField)),
            (None, Some(_)) => return Err(r.error(1, Cause::MissingField)),
            _ => {}
        }
        if altitude.is_some() && altitude_type.is_none() {
            return Err(r.error(4, Cause::MissingField));
        }
        let u_speed = r.optional(5)?;
        let v_speed = r.optional(6)?;
        let w_speed = r.optional(7)?;
        let u_accel = r.optional(8)?;
        let v_accel = r.optional(9)?;
        let w_accel = r.optional(10)?;
        let phi = r.optional(11)?;
        let theta = r.optional(12)?;
        let psi = r.optional(13)?;
        let phi_dot = r.optional(14)?;
        let theta_dot = r.optional(15)?;
        let psi_dot = r.optional(16)?;
        let magnetic_variation = r.optional(17)?;
        r.finish()?;
        Ok(Self {
            time_stamp,
            latitude,
            longitude,
            altitude,
            altitude_type,
            u_speed,
            v_speed,
            w_speed,
            u_accel,
            v_accel,
            w_accel,
            phi,
            theta,
            psi,
            phi_dot,
            theta_dot,
            psi_dot,
            magnetic_variation,
        })
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.optional(1, self.latitude.as_ref())?;
        w.optional(2, self.longitude.as_ref())?;
        w.optional(3, self.altitude.as_ref())?;
        w.optional(4, self.altitude_type.as_ref())?;
        w.optional(5, self.u_speed.as_ref())?;
        w.optional(6, self.v_speed.as_ref())?;
        w.optional(7, self.w_speed.as_ref())?;
        w.optional(8, self.u_accel.as_ref())?;
        w.optional(9, self.v_accel.as_ref())?;
        w.optional(10, self.w_accel.as_ref())?;
        w.optional(11, self.phi.as_ref())?;
        w.optional(12, self.theta.as_ref())?;
        w.optional(13, self.psi.as_ref())?;
        w.optional(14, self.phi_dot.as_ref())?;
        w.optional(15, self.theta_dot.as_ref())?;
        w.optional(16, self.psi_dot.as_ref())?;
        w.optional(17, self.magnetic_variation.as_ref())?;
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#101 Inertial States: 48.272500 N 11.642500 E, 120.0 m WGS-84, ground speed 25.0 m/s,
/// course 45.0 deg, climb 1.2 m/s, heading 350.0 deg, roll -25.0 deg, pitch 2.7 deg`, each
/// part only when its fields are present; `position unknown` without latitude and longitude.
impl fmt::Display for InertialStates {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", Self::TYPE)?;
        match self.position() {
            Some(p) => write!(f, "{p}")?,
            None => f.write_str("position unknown")?,
        }
        if let Some(a) = self.altitude {
            write!(f, ", {:.1} m", a.metres())?;
            if let Some(t) = self.altitude_type {
                write!(f, " {}", t.name())?;
            }
        }
        if let Some(gs) = self.ground_speed_mps() {
            write!(f, ", ground speed {gs:.1} m/s")?;
        }
        if let Some(course) = self.course_deg() {
            write!(f, ", course {course:.1} deg")?;
        }
        if let Some(climb) = self.climb_rate_mps() {
            write!(f, ", climb {climb:.1} m/s")?;
        }
        if let Some(heading) = self.heading_deg() {
            write!(f, ", heading {heading:.1} deg")?;
        }
        if let Some(roll) = self.roll_rad() {
            write!(f, ", roll {:.1} deg", roll.to_degrees())?;
        }
        if let Some(pitch) = self.pitch_rad() {
            write!(f, ", pitch {:.1} deg", pitch.to_degrees())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #101 as the FCC sends it: position, altitude, velocity (25 m/s towards north-east);
    /// FCC to GCS, no ack.
    #[rustfmt::skip]
    static FRAME: [u8; 46] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x1a,                   // message length: 26 bytes of message data
        0x0b, 0x00, 0x00, 0x01,       // source ID: FCC 0x0B00_0001
        0x0a, 0x00, 0x00, 0x01,       // destination ID: GCS 0x0A00_0001
        0x00, 0x65,                   // message type 101 = 0x0065
        0x28, 0x80,                   // properties: ack 0 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0x2880
        // message data
        0x00, 0x00, 0xff,             // presence vector 0x00_00FF: bits 0..=7
        0xc5, 0xa7, 0x56, 0x2f, 0xbc, // time stamp 2026-11-25T10:00:00.700Z = 848_916_000_700 ms since 2000-01-01 = 0xC5_A756_2FBC
        0x22, 0x53, 0xbd, 0x8e,       // latitude 48.2725 deg: 48.2725 / 180 * 2^31 = 575_913_357.9 -> 575_913_358 = 0x2253_BD8E
        0x08, 0x47, 0x73, 0xd3,       // longitude 11.6425 deg: 11.6425 / 180 * 2^31 = 138_900_435.3 -> 138_900_435 = 0x0847_73D3
        0x00, 0x17, 0x70,             // altitude 120 m: 120 / 0.02 = 6000 = 0x00_1770
        0x03,                         // altitude type 3: WGS-84
        0x01, 0x62,                   // U speed (north) 17.7 m/s: 17.7 / 0.05 = 354 = 0x0162
        0x01, 0x62,                   // V speed (east) 17.7 m/s: 354 = 0x0162
        0x00, 0x00,                   // W speed (down) 0 m/s
        // checksum
        0x00, 0x00, 0x0b, 0x8d,       // checksum: byte sum of header and data = 2957 = 0x0000_0B8D
    ];

    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0B00_0001,
        destination_id: 0x0A00_0001,
        ack_requested: false,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn repr() -> InertialStates {
        InertialStates {
            time_stamp: Timestamp::from_millis(848_916_000_700).unwrap(),
            latitude: Some(Angle::from_raw(575_913_358)),
            longitude: Some(Angle::from_raw(138_900_435)),
            altitude: Some(Altitude::from_metres(120.0).unwrap()),
            altitude_type: Some(AltitudeType::Wgs84),
            u_speed: Some(Velocity::from_raw(354)),
            v_speed: Some(Velocity::from_raw(354)),
            w_speed: Some(Velocity::from_raw(0)),
            ..InertialStates::default()
        }
    }

    #[test]
    fn golden() {
        super::super::assert_golden(&FRAME, ENVELOPE, repr().into());
    }

    #[test]
    fn physical() {
        let m = repr();
        assert_eq!(m.time_stamp.to_string(), "2026-11-25T10:00:00.700Z");
        assert_eq!(Angle::from_degrees(48.2725).unwrap(), m.latitude.unwrap());
        assert_eq!(Angle::from_degrees(11.6425).unwrap(), m.longitude.unwrap());
        assert_eq!(Velocity::from_mps(17.7).unwrap(), m.u_speed.unwrap());
        assert_eq!(Velocity::from_mps(-17.7).unwrap().raw(), -354);
        assert!((m.ground_speed_mps().unwrap() - 25.0316).abs() < 1e-3);
        assert!((m.course_deg().unwrap() - 45.0).abs() < 1e-9);
    }

    #[test]
    fn course_runs_clockwise_from_north() {
        let course = |u: i16, v: i16| {
            InertialStates {
                u_speed: Some(Velocity::from_raw(u)),
                v_speed: Some(Velocity::from_raw(v)),
                ..repr()
            }
            .course_deg()
        };
        assert_eq!(course(100, 0), Some(0.0));
        assert_eq!(course(0, 100), Some(90.0));
        assert_eq!(course(-100, 0), Some(180.0));
        assert_eq!(course(0, -100), Some(270.0));
        assert_eq!(course(0, 0), None);
    }

    #[test]
    fn display() {
        super::super::assert_display(
            repr(),
            "#101 Inertial States: 48.272500 N 11.642500 E, 120.0 m WGS-84, ground speed 25.0 m/s, course 45.0 deg, climb 0.0 m/s",
        );
        let deg = |d: f64| d.to_radians();
        super::super::assert_display(
            InertialStates {
                w_speed: Some(Velocity::from_mps(-1.2).unwrap()),
                phi: InertialStates::roll_from_rad(deg(-25.0)),
                theta: InertialStates::pitch_from_rad(deg(2.7)),
                psi: InertialStates::heading_from_rad(deg(350.0)),
                ..repr()
            },
            "#101 Inertial States: 48.272500 N 11.642500 E, 120.0 m WGS-84, ground speed 25.0 m/s, course 45.0 deg, climb 1.2 m/s, heading 350.0 deg, roll -25.0 deg, pitch 2.7 deg",
        );
    }

    /// Phi and Psi wrap into the I2's -pi..pi (ICD §4 #101: pi / 2^15 rad per unit), +pi
    /// becoming -pi; Theta clamps to straight up or down; what is not finite is not sent.
    #[test]
    fn angles_from_radians_wrap_and_clamp() {
        let deg = |d: f64| d.to_radians();
        let heading = |d: f64| InertialStates::heading_from_rad(deg(d));
        // 350 deg is -10 deg: -10 / 180 * 32768 = -1820.4 -> -1820.
        assert_eq!(heading(350.0), Some(-1820));
        assert_eq!(heading(-10.0), Some(-1820));
        assert_eq!(heading(10.0), Some(1820));
        assert_eq!(heading(0.0), Some(0));
        assert_eq!(heading(360.0), Some(0));
        assert_eq!(heading(720.0 + 90.0), Some(16_384));
        // +pi is the same angle as -pi, the field's smallest value; its largest is just below.
        assert_eq!(heading(180.0), Some(i16::MIN));
        assert_eq!(heading(-180.0), Some(i16::MIN));
        assert_eq!(heading(179.995), Some(i16::MAX));
        // Within half a unit of +pi: rounded to it, so to -pi.
        assert_eq!(heading(179.999), Some(i16::MIN));
        assert_eq!(heading(180.0 - 180.0 / 32_768.0), Some(i16::MAX));
        assert_eq!(InertialStates::roll_from_rad(deg(190.0)), Some(-30_948));
        assert_eq!(InertialStates::roll_from_rad(deg(-25.0)), Some(-4551));
        let pitch = |d: f64| InertialStates::pitch_from_rad(deg(d));
        assert_eq!(pitch(90.0), Some(16_384));
        assert_eq!(pitch(120.0), Some(16_384));
        assert_eq!(pitch(-95.0), Some(-16_384));
        assert_eq!(pitch(2.7), Some(492));
        for nothing in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(InertialStates::roll_from_rad(nothing), None);
            assert_eq!(InertialStates::pitch_from_rad(nothing), None);
            assert_eq!(InertialStates::heading_from_rad(nothing), None);
        }
    }

    /// The accessors read back what the constructors made, within half a unit; the heading in
    /// radians is signed as the field is, in degrees it runs 0..360 as the course does.
    #[test]
    fn angles_read_back() {
        let unit = InertialStates::ANGLE_LSB_RAD;
        let m = InertialStates {
            phi: InertialStates::roll_from_rad(0.3),
            theta: InertialStates::pitch_from_rad(-0.2),
            psi: InertialStates::heading_from_rad(350f64.to_radians()),
            w_speed: Some(Velocity::from_mps(-2.0).unwrap()),
            ..repr()
        };
        assert!((m.roll_rad().unwrap() - 0.3).abs() <= unit / 2.0);
        assert!((m.pitch_rad().unwrap() + 0.2).abs() <= unit / 2.0);
        assert!((m.heading_rad().unwrap() + 10f64.to_radians()).abs() <= unit / 2.0);
        assert!((m.heading_deg().unwrap() - 350.0).abs() < 0.01);
        assert_eq!(m.climb_rate_mps(), Some(2.0));
        let south = InertialStates {
            psi: InertialStates::heading_from_rad(core::f64::consts::PI),
            ..repr()
        };
        assert_eq!(south.heading_rad(), Some(-core::f64::consts::PI));
        assert_eq!(south.heading_deg(), Some(180.0));
        let none = InertialStates {
            w_speed: None,
            ..repr()
        };
        assert_eq!(
            (none.roll_rad(), none.pitch_rad(), none.heading_rad()),
            (None, None, None)
        );
        assert_eq!((none.heading_deg(), none.climb_rate_mps()), (None, None));
    }

    /// A latitude without its longitude, and an altitude without its type, are refused as
    /// missing the other field (ICD §4).
    #[test]
    fn pairs_are_required() {
        let refuse = |m: InertialStates, bit: u8| {
            let mut buf = [0; 64];
            let len = m.encode(&mut buf).unwrap();
            let e = InertialStates::decode(&buf[..len]).unwrap_err();
            assert_eq!(e.cause, Cause::MissingField, "{e:?}");
            assert_eq!(e.field.unwrap().bit, bit);
        };
        refuse(
            InertialStates {
                longitude: None,
                ..repr()
            },
            2,
        );
        refuse(
            InertialStates {
                latitude: None,
                ..repr()
            },
            1,
        );
        refuse(
            InertialStates {
                altitude_type: None,
                ..repr()
            },
            4,
        );
    }

    #[test]
    fn latitude_beyond_the_pole_is_refused() {
        let mut frame = FRAME;
        // Latitude 0x4000_0001: one unit beyond +90 deg.
        frame[24..28].copy_from_slice(&[0x40, 0x00, 0x00, 0x01]);
        let e = InertialStates::decode(&frame[16..42]).unwrap_err();
        assert!(matches!(e.cause, Cause::OutOfRange { .. }), "{e:?}");
        assert_eq!(e.field.unwrap().bit, 1);
    }

    #[test]
    fn every_field_round_trips() {
        let m = InertialStates {
            u_accel: Some(1),
            v_accel: Some(-2),
            w_accel: Some(3),
            phi: Some(-4),
            theta: Some(5),
            psi: Some(i16::MIN),
            phi_dot: Some(i16::MAX),
            theta_dot: Some(0),
            psi_dot: Some(-1),
            magnetic_variation: Some(9),
            w_speed: Some(Velocity::from_raw(-20)),
            ..repr()
        };
        let mut buf = [0xa5; 64];
        let len = m.encode(&mut buf).unwrap();
        assert_eq!(len, 46);
        assert_eq!(InertialStates::decode(&buf[..len]).unwrap(), m);
    }
}
