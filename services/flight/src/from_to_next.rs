//! FROM-TO-NEXT (paper §3.1.7; ICD §4 #4001, §5.5): the FCC tells the GCS where the aircraft
//! comes from, flies to and goes next. Guidance reports its progress as the triple of waypoint
//! numbers (FROM, TO, NEXT); whenever the triple changes, the FCC sends one #4001, without
//! acknowledgement request (a lost report is superseded by the next change anyway).
//!
//! The reporter only decides *when* to report and *what* the #4001 holds: positions, altitudes
//! and speeds are copied from the active waypoint list, so the GCS sees exactly the values it
//! uploaded. The caller stamps the message (ICD §3) and sends it on both links.

use missionlink_interfaces::contracts::{
    GuidanceProgressPayload, WaypointEntry, WaypointListPayload,
};
use missionlink_interfaces::wire::{FromToNext, FromWaypointState, Timestamp, WaypointState};

/// Waypoint numbers (FROM, TO, NEXT); 0 = none.
type Triple = (u16, u16, u16);

/// Nothing flown: no FROM, no TO, no NEXT.
const NOTHING: Triple = (0, 0, 0);

/// Decides when the FCC sends #4001 and fills it from the active waypoint list.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FromToNextReporter {
    /// The triple last reported; `None` after [`Self::reset`], so that any triple is reported.
    last: Option<Triple>,
}

impl Default for FromToNextReporter {
    fn default() -> Self {
        Self::new()
    }
}

impl FromToNextReporter {
    /// A reporter that has reported "nothing" (0, 0, 0): the GCS assumes no waypoint is flown
    /// until told otherwise, so an idle guidance is not reported.
    pub const fn new() -> Self {
        Self {
            last: Some(NOTHING),
        }
    }

    /// Guidance reported progress. Returns the #4001 to send when the (from, to, next) triple
    /// differs from the last one reported, else `None`.
    ///
    /// `list` is the active waypoint list guidance flies (`progress.waypoint_list ==
    /// list.generation`). Each of FROM, TO and NEXT with a waypoint number other than 0 is
    /// filled from the list entry with that number: latitude, longitude, altitude, speed (TO and
    /// NEXT only: #4001 has no FROM speed) and the number. Number 0 means none: that block
    /// carries only Waypoint Number 0. A number not in the list keeps its number, every other
    /// field absent: the report still says which waypoint guidance names, without inventing a
    /// position. Altitude Type and Speed Type come from the TO entry where it exists and gives
    /// them. The Time fields stay absent: no arrival time is predicted. `time_stamp` is the
    /// #4001's time stamp; the caller stamps it (ICD §3).
    pub fn update(
        &mut self,
        progress: &GuidanceProgressPayload,
        list: &WaypointListPayload,
        time_stamp: Timestamp,
    ) -> Option<FromToNext> {
        let triple = progress.from_to_next();
        if self.last == Some(triple) {
            return None;
        }
        self.last = Some(triple);
        let (from, to, next) = triple;
        let to_entry = entry(list, to);
        Some(FromToNext {
            time_stamp,
            altitude_type: to_entry.and_then(WaypointEntry::altitude_type),
            speed_type: to_entry.and_then(WaypointEntry::speed_type),
            from: from_state(from, entry(list, from)),
            to: state(to, to_entry),
            next: state(next, entry(list, next)),
            loiter_configuration_report_validity: None,
        })
    }

    /// Forget the last triple (after a new mission is activated, so the next progress is
    /// reported even if the numbers are equal; "nothing" (0, 0, 0) included, so the GCS learns
    /// that no waypoint of the new mission is flown yet).
    pub fn reset(&mut self) {
        self.last = None;
    }
}

/// The entry of waypoint `number` in `list`; `None` for 0 (none) or a number not in the list.
fn entry(list: &WaypointListPayload, number: u16) -> Option<&WaypointEntry> {
    if number == 0 {
        return None;
    }
    list.waypoints().iter().find(|e| e.number == number)
}

/// The FROM block of #4001 (bits 3 to 7).
fn from_state(number: u16, entry: Option<&WaypointEntry>) -> FromWaypointState {
    FromWaypointState {
        latitude: entry.map(|e| e.position.latitude),
        longitude: entry.map(|e| e.position.longitude),
        altitude: entry.map(|e| e.altitude),
        time: None,
        waypoint_number: Some(number),
    }
}

/// The TO (bits 8 to 13) or NEXT (bits 14 to 19) block of #4001.
fn state(number: u16, entry: Option<&WaypointEntry>) -> WaypointState {
    WaypointState {
        latitude: entry.map(|e| e.position.latitude),
        longitude: entry.map(|e| e.position.longitude),
        altitude: entry.map(|e| e.altitude),
        speed: entry.map(|e| e.speed),
        time: None,
        waypoint_number: Some(number),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_interfaces::wire::{
        self, Altitude, AltitudeType, Angle, Envelope, GeoPoint, MAX_FRAME_LEN, Message, Speed,
        SpeedType,
    };

    fn ts(ms: u64) -> Timestamp {
        Timestamp::from_millis(ms).unwrap()
    }

    /// Waypoint `number` at (`lat`, `lon`) deg, `alt` m, `spd` m/s, followed by `next`.
    fn wp(number: u16, next: u16, lat: f64, lon: f64, alt: f64, spd: f64) -> WaypointEntry {
        let mut e = WaypointEntry::EMPTY;
        e.number = number;
        e.next = next;
        e.position = GeoPoint::from_degrees(lat, lon).unwrap();
        e.altitude = Altitude::from_metres(alt).unwrap();
        e.speed = Speed::from_mps(spd).unwrap();
        e
    }

    /// Mission of three waypoints, 1 -> 2 -> 3; waypoint 2 flies at ground speed on WGS-84.
    fn list() -> WaypointListPayload {
        let mut l = WaypointListPayload::EMPTY;
        l.generation = 1;
        l.count = 3;
        l.initial_waypoint = 1;
        l.waypoints[0] = wp(1, 2, 48.275, 11.645, 120.0, 25.0);
        l.waypoints[1] = wp(2, 3, 48.278, 11.658, 150.0, 30.0);
        l.waypoints[1].set_altitude_type(Some(AltitudeType::Wgs84));
        l.waypoints[1].set_speed_type(Some(SpeedType::GroundSpeed));
        l.waypoints[2] = wp(3, 0, 48.28, 11.68, 100.5, 20.5);
        l.waypoints[2].set_altitude_type(Some(AltitudeType::Agl));
        l
    }

    fn progress(from: u16, to: u16, next: u16) -> GuidanceProgressPayload {
        GuidanceProgressPayload {
            waypoint_list: 1,
            from,
            to,
            next,
            ..GuidanceProgressPayload::IDLE
        }
    }

    fn triple(m: &FromToNext) -> (Option<u16>, Option<u16>, Option<u16>) {
        (
            m.from.waypoint_number,
            m.to.waypoint_number,
            m.next.waypoint_number,
        )
    }

    const NONE: WaypointState = WaypointState {
        latitude: None,
        longitude: None,
        altitude: None,
        speed: None,
        time: None,
        waypoint_number: Some(0),
    };

    #[test]
    fn idle_guidance_is_not_reported() {
        let mut r = FromToNextReporter::new();
        assert_eq!(r.update(&progress(0, 0, 0), &list(), ts(1)), None);
    }

    #[test]
    fn reports_each_change_and_only_changes() {
        let mut r = FromToNextReporter::new();
        let l = list();
        let steps = [
            ((0, 1, 2), 10, true),
            ((0, 1, 2), 11, false),
            ((1, 2, 3), 12, true),
            ((1, 2, 3), 13, false),
            ((1, 2, 3), 14, false),
            ((2, 3, 0), 15, true),
            ((2, 3, 0), 16, false),
        ];
        for ((f, t, n), stamp, reported) in steps {
            let m = r.update(&progress(f, t, n), &l, ts(stamp));
            assert_eq!(m.is_some(), reported, "({f}, {t}, {n}) at {stamp}");
            if let Some(m) = m {
                assert_eq!(triple(&m), (Some(f), Some(t), Some(n)));
                assert_eq!(m.time_stamp, ts(stamp));
            }
        }
    }

    #[test]
    fn fields_are_the_list_entries() {
        let mut r = FromToNextReporter::new();
        let l = list();
        let m = r.update(&progress(1, 2, 3), &l, ts(42)).unwrap();
        assert_eq!(
            m,
            FromToNext {
                time_stamp: ts(42),
                altitude_type: Some(AltitudeType::Wgs84),
                speed_type: Some(SpeedType::GroundSpeed),
                from: FromWaypointState {
                    latitude: Some(Angle::from_degrees(48.275).unwrap()),
                    longitude: Some(Angle::from_degrees(11.645).unwrap()),
                    altitude: Some(Altitude::from_raw(6000).unwrap()),
                    time: None,
                    waypoint_number: Some(1),
                },
                to: WaypointState {
                    latitude: Some(Angle::from_degrees(48.278).unwrap()),
                    longitude: Some(Angle::from_degrees(11.658).unwrap()),
                    altitude: Some(Altitude::from_raw(7500).unwrap()),
                    speed: Some(Speed::from_raw(60)),
                    time: None,
                    waypoint_number: Some(2),
                },
                next: WaypointState {
                    latitude: Some(Angle::from_degrees(48.28).unwrap()),
                    longitude: Some(Angle::from_degrees(11.68).unwrap()),
                    altitude: Some(Altitude::from_raw(5025).unwrap()),
                    speed: Some(Speed::from_raw(41)),
                    time: None,
                    waypoint_number: Some(3),
                },
                loiter_configuration_report_validity: None,
            }
        );
        // Exactly the list's wire values, not a round trip through degrees.
        assert_eq!(m.to.latitude, Some(l.waypoints[1].position.latitude));
        assert_eq!(m.next.longitude, Some(l.waypoints[2].position.longitude));
    }

    #[test]
    fn number_zero_carries_only_the_number() {
        let mut r = FromToNextReporter::new();
        let l = list();
        let first = r.update(&progress(0, 1, 2), &l, ts(1)).unwrap();
        assert_eq!(
            first.from,
            FromWaypointState {
                waypoint_number: Some(0),
                ..FromWaypointState::default()
            }
        );
        // TO = 1 gives neither type: the entry carries none.
        assert_eq!((first.altitude_type, first.speed_type), (None, None));
        let last = r.update(&progress(2, 3, 0), &l, ts(2)).unwrap();
        assert_eq!(last.next, NONE);
        // TO = 3 gives its altitude type, and no speed type.
        assert_eq!(last.altitude_type, Some(AltitudeType::Agl));
        assert_eq!(last.speed_type, None);
        let done = r.update(&progress(3, 0, 0), &l, ts(3)).unwrap();
        assert_eq!((done.to, done.next), (NONE, NONE));
        assert_eq!(done.from.waypoint_number, Some(3));
        assert!(done.from.latitude.is_some());
        assert_eq!(done.altitude_type, None);
    }

    #[test]
    fn unknown_number_keeps_the_number_only() {
        let mut r = FromToNextReporter::new();
        let m = r.update(&progress(0, 7, 1), &list(), ts(1)).unwrap();
        assert_eq!(
            m.to,
            WaypointState {
                waypoint_number: Some(7),
                ..WaypointState::default()
            }
        );
        assert_eq!((m.altitude_type, m.speed_type), (None, None));
        assert_eq!(m.next.waypoint_number, Some(1));
        assert!(m.next.latitude.is_some());
    }

    #[test]
    fn reset_causes_a_re_report() {
        let mut r = FromToNextReporter::new();
        let l = list();
        assert!(r.update(&progress(0, 1, 2), &l, ts(1)).is_some());
        assert!(r.update(&progress(0, 1, 2), &l, ts(2)).is_none());
        r.reset();
        let m = r.update(&progress(0, 1, 2), &l, ts(3)).unwrap();
        assert_eq!(triple(&m), (Some(0), Some(1), Some(2)));
        assert!(r.update(&progress(0, 1, 2), &l, ts(4)).is_none());
        assert!(r.update(&progress(1, 2, 3), &l, ts(5)).is_some());
        // After a reset even "nothing" is news: the new mission is not flown yet.
        r.reset();
        let idle = r.update(&progress(0, 0, 0), &l, ts(6)).unwrap();
        assert_eq!((idle.to, idle.next), (NONE, NONE));
    }

    #[test]
    fn report_round_trips_through_the_wire() {
        let mut r = FromToNextReporter::new();
        let m = r.update(&progress(1, 2, 3), &list(), ts(848_577_900_000));
        let message = Message::from(m.unwrap());
        let envelope = Envelope::new(FCC_ID, GCS_ID);
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = wire::encode(&envelope, &message, &mut buf).unwrap();
        assert_eq!(wire::decode(&buf[..len]).unwrap(), (envelope, message));
        // Not acknowledged (ICD §5.5).
        assert!(
            !wire::Frame::new_checked(&buf[..len])
                .unwrap()
                .properties()
                .ack_requested()
        );
    }
}
