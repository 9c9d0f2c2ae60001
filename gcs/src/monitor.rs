//! What `gcs monitor` prints: the aircraft's position (#101, ICD §5.8) and the waypoints it
//! flies (#4001 FROM-TO-NEXT, ICD §5.5) together, one line per report, so the operator reads
//! where the aircraft is and where it goes in one place.

use missionlink_interfaces::wire::{FromToNext, InertialStates};

/// The monitor's state: the last FROM-TO-NEXT, shown beside each position.
#[derive(Debug, Clone, Default)]
pub struct Monitor {
    from_to_next: Option<(u16, u16, u16)>,
}

impl Monitor {
    /// A monitor that has heard nothing yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// A FROM-TO-NEXT report: the line to print (the message's own line, ICD §4 `Display`).
    pub fn from_to_next(&mut self, ftn: &FromToNext) -> String {
        let number = |n: Option<u16>| n.unwrap_or(0);
        self.from_to_next = Some((
            number(ftn.from.waypoint_number),
            number(ftn.to.waypoint_number),
            number(ftn.next.waypoint_number),
        ));
        ftn.to_string()
    }

    /// A position report: `position 48.272500 N 11.642500 E, 120.0 m WGS-84, ground speed 25.0
    /// m/s, course 45.0 deg | FROM 1 TO 2 NEXT 3` (`-` for none; `FROM-TO-NEXT not yet
    /// reported` before the first #4001).
    pub fn position(&self, states: &InertialStates) -> String {
        let full = states.to_string();
        let what = full
            .split_once(": ")
            .map_or(full.as_str(), |(_, rest)| rest);
        let waypoint = |n: u16| match n {
            0 => "-".to_owned(),
            n => n.to_string(),
        };
        match self.from_to_next {
            Some((from, to, next)) => format!(
                "position {what} | FROM {} TO {} NEXT {}",
                waypoint(from),
                waypoint(to),
                waypoint(next)
            ),
            None => format!("position {what} | FROM-TO-NEXT not yet reported"),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use missionlink_interfaces::wire::{
        Altitude, AltitudeType, GeoPoint, Timestamp, Velocity, WaypointState,
    };

    use super::*;

    /// At 48.2725 N 11.6425 E, 120 m WGS-84, 25 m/s towards north-east (the example of ICD
    /// A.26): the bridge's tests take it too.
    pub(crate) fn states() -> InertialStates {
        let p = GeoPoint::from_degrees(48.2725, 11.6425).unwrap();
        InertialStates {
            time_stamp: Timestamp::default(),
            latitude: Some(p.latitude),
            longitude: Some(p.longitude),
            altitude: Some(Altitude::from_metres(120.0).unwrap()),
            altitude_type: Some(AltitudeType::Wgs84),
            u_speed: Some(Velocity::from_raw(354)),
            v_speed: Some(Velocity::from_raw(354)),
            w_speed: None,
            ..InertialStates::default()
        }
    }

    #[test]
    fn position_and_from_to_next_on_one_line() {
        let mut m = Monitor::new();
        assert_eq!(
            m.position(&states()),
            "position 48.272500 N 11.642500 E, 120.0 m WGS-84, ground speed 25.0 m/s, course \
             45.0 deg | FROM-TO-NEXT not yet reported"
        );
        let ftn = FromToNext {
            time_stamp: Timestamp::default(),
            altitude_type: None,
            speed_type: None,
            from: Default::default(),
            to: WaypointState {
                waypoint_number: Some(2),
                ..Default::default()
            },
            next: WaypointState {
                waypoint_number: Some(3),
                ..Default::default()
            },
            loiter_configuration_report_validity: None,
        };
        assert_eq!(
            m.from_to_next(&ftn),
            "#4001 FROM-TO-NEXT Waypoint States: FROM -, TO 2, NEXT 3"
        );
        assert_eq!(
            m.position(&states()),
            "position 48.272500 N 11.642500 E, 120.0 m WGS-84, ground speed 25.0 m/s, course \
             45.0 deg | FROM - TO 2 NEXT 3"
        );
    }
}
