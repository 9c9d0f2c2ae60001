//! The mission: the waypoint buffer a mission upload fills (paper §3.1.5; ICD §5.1), its
//! assembly into the waypoint list in flight-plan order with the validity checks of ICD §7, and
//! the list as a whole, which a mission download sends back (paper §3.1.6; ICD §5.2) and the
//! FCC publishes to guidance.
//!
//! The buffer and the list keep every message as received, time stamp aside, so that a download
//! of an uploaded mission gives back every field equal (ICD §5.2).

use crate::geofence::earth;
use crate::geofence::flown_route::RouteWaypoint;
use heapless::Vec;
use heapless::index_map::FnvIndexMap;
use missionlink_interfaces::capacity::MAX_WAYPOINTS;
use missionlink_interfaces::contracts::{WaypointEntry, WaypointListPayload};
use missionlink_interfaces::wire::{
    Altitude, GeoPoint, LegType, Message, Reason, SpecificData, Text, Timestamp,
    UaPositionWaypoint, UaRoute, VehicleSpecificWaypoint,
};

/// One waypoint of the flight plan with its radius-to-fix centre, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WaypointRecord {
    /// The #13002, time stamp zero.
    pub waypoint: UaPositionWaypoint,
    /// The #13006 type 2, time stamp zero; present for radius-to-fix waypoints (and kept if a
    /// track-to-fix waypoint has one, so a download gives back what was uploaded).
    pub rf_centre: Option<VehicleSpecificWaypoint>,
}

/// An assembled, valid mission: take-off height, route and the waypoints in flight-plan order,
/// from the initial waypoint to the one whose Next Waypoint is 0.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mission {
    /// The #13006 type 1, time stamp zero.
    pub take_off: VehicleSpecificWaypoint,
    /// The #13001, time stamp zero.
    pub route: UaRoute,
    /// The waypoints in flight-plan order.
    pub waypoints: Vec<WaypointRecord, MAX_WAYPOINTS>,
    /// Mission ID of the #13000 that activated the mission, sent back in #14000.
    pub mission_id: Option<Text<20>>,
}

fn unstamped(mut m: Message) -> Message {
    m.set_time_stamp(Timestamp::default());
    m
}

impl Mission {
    /// The take-off height above ground.
    pub fn take_off_height(&self) -> Altitude {
        match self.take_off.data {
            SpecificData::TakeOffHeight { height } => height,
            SpecificData::RfCentre { .. } => Altitude::ZERO,
        }
    }

    /// ICD §7 rev. 2: every radius-to-fix leg starts and ends on one circle about its centre
    /// (within 1 % or 5 m, whichever is larger), else `Malformed`.
    pub fn check_radii(&self) -> Result<(), Reason> {
        if self
            .waypoints
            .windows(2)
            .any(|w| matches!(w, [from, to] if !rf_radii_agree(from, to)))
        {
            return Err(Reason::Malformed);
        }
        Ok(())
    }

    /// Messages of the mission in the order of ICD §5.1 steps 2 to 4 and §5.2 steps 2 to 4:
    /// take-off height, each waypoint in flight-plan order followed by its RF centre, route.
    pub fn messages(&self) -> impl Iterator<Item = Message> + '_ {
        let waypoints = self.waypoints.iter().flat_map(|r| {
            core::iter::once(Message::from(r.waypoint)).chain(r.rf_centre.map(Message::from))
        });
        core::iter::once(Message::from(self.take_off))
            .chain(waypoints)
            .chain(core::iter::once(Message::from(self.route)))
    }

    /// How many messages [`Mission::messages`] yields.
    pub fn message_count(&self) -> usize {
        2 + self.waypoints.len()
            + self
                .waypoints
                .iter()
                .filter(|r| r.rf_centre.is_some())
                .count()
    }

    /// The mission as guidance receives it (`fcc/mission/waypoint-list`).
    pub fn to_payload(&self, generation: u64) -> WaypointListPayload {
        let mut p = WaypointListPayload::EMPTY;
        p.generation = generation;
        p.take_off_height = self.take_off_height();
        p.initial_waypoint = self.route.initial_waypoint;
        p.bidirectional = self.route.bidirectional;
        p.planning_wind = self.route.planning_wind.unwrap_or_default();
        p.count = self.waypoints.len() as u16;
        for (entry, record) in p.waypoints.iter_mut().zip(&self.waypoints) {
            let w = &record.waypoint;
            // Position and RF centre as the geofence reads the plan (one conversion of each).
            *entry = WaypointEntry {
                number: w.waypoint_number,
                next: w.next_waypoint,
                position: RouteWaypoint::position(record),
                altitude: w.altitude,
                speed: w.speed,
                turn_type: w.turn_type as u8,
                leg_type: w.leg_type as u8,
                ..WaypointEntry::EMPTY
            };
            entry.set_altitude_type(w.altitude_type);
            entry.set_speed_type(w.speed_type);
            entry.set_rf_centre(RouteWaypoint::rf_centre(record));
        }
        p
    }
}

/// One entry of the waypoint buffer: what a message of a mission upload stores, and a later one
/// of the same entry overwrites (ICD §5.1 step 3, §10.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Entry {
    /// The take-off height (#13006 type 1).
    TakeOff,
    /// The route (#13001).
    Route,
    /// A waypoint (#13002), by Waypoint Number.
    Waypoint(u16),
    /// A radius-to-fix centre (#13006 type 2), by the number of its waypoint.
    RfCentre(u16),
}

impl Entry {
    /// The entry `message` stores, if it is mission data.
    pub fn of(message: &Message) -> Option<Self> {
        match message {
            Message::UaPositionWaypoint(w) => Some(Self::Waypoint(w.waypoint_number)),
            Message::VehicleSpecificWaypoint(v) => match v.data {
                SpecificData::TakeOffHeight { .. } => Some(Self::TakeOff),
                SpecificData::RfCentre {
                    waypoint_number, ..
                } => Some(Self::RfCentre(waypoint_number)),
            },
            Message::UaRoute(_) => Some(Self::Route),
            _ => None,
        }
    }
}

/// The waypoint buffer: what a mission upload has stored so far, in any order (ICD §5.1 step
/// 3). A waypoint number sent again overwrites (an edit). Capacity: [`MAX_WAYPOINTS`] waypoints
/// (a power of two, as the index maps need).
#[derive(Debug, Clone, Default)]
pub struct MissionBuffer {
    take_off: Option<VehicleSpecificWaypoint>,
    route: Option<UaRoute>,
    waypoints: FnvIndexMap<u16, UaPositionWaypoint, MAX_WAYPOINTS>,
    rf_centres: FnvIndexMap<u16, VehicleSpecificWaypoint, MAX_WAYPOINTS>,
}

impl MissionBuffer {
    /// An empty buffer.
    pub fn new() -> Self {
        Self::default()
    }

    /// A buffer holding `mission`, the starting point of an edit.
    pub fn from_mission(mission: &Mission) -> Self {
        let mut b = Self::new();
        for m in mission.messages() {
            // A mission never holds more than the buffer does.
            let _ = b.store(&m);
        }
        b
    }

    /// Empties the buffer (#13000 mode 1).
    pub fn clear(&mut self) {
        *self = Self::new();
    }

    /// Waypoints stored.
    pub fn len(&self) -> usize {
        self.waypoints.len()
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.waypoints.is_empty()
            && self.take_off.is_none()
            && self.route.is_none()
            && self.rf_centres.is_empty()
    }

    /// The message stored at `entry`, time stamp zero.
    pub fn entry(&self, entry: Entry) -> Option<Message> {
        match entry {
            Entry::TakeOff => self.take_off.map(Message::from),
            Entry::Route => self.route.map(Message::from),
            Entry::Waypoint(n) => self.waypoints.get(&n).copied().map(Message::from),
            Entry::RfCentre(n) => self.rf_centres.get(&n).copied().map(Message::from),
        }
    }

    /// Stores a #13006, #13002 or #13001. A new waypoint beyond the capacity is refused
    /// (`Capacity`); any other message is not mission data (`WrongState`).
    pub fn store(&mut self, message: &Message) -> Result<(), Reason> {
        match unstamped(message.clone()) {
            Message::UaPositionWaypoint(w) => self
                .waypoints
                .insert(w.waypoint_number, w)
                .map(|_| ())
                .map_err(|_| Reason::Capacity),
            Message::VehicleSpecificWaypoint(v) => match v.data {
                SpecificData::TakeOffHeight { .. } => {
                    self.take_off = Some(v);
                    Ok(())
                }
                SpecificData::RfCentre {
                    waypoint_number, ..
                } => self
                    .rf_centres
                    .insert(waypoint_number, v)
                    .map(|_| ())
                    .map_err(|_| Reason::Capacity),
            },
            Message::UaRoute(r) => {
                self.route = Some(r);
                Ok(())
            }
            _ => Err(Reason::WrongState),
        }
    }

    /// Assembles the waypoint list (#13000 mode 2, ICD §5.1 step 5) and checks it (ICD §7):
    /// - `CountMismatch`: the buffer does not hold `announced` waypoints, or the flight plan
    ///   does not visit every waypoint stored;
    /// - `MissingInitial`: no route, or its initial waypoint is not stored;
    /// - `BrokenChain`: a Next Waypoint refers to a waypoint not stored, or the plan loops;
    /// - `MissingRfCentre`: a radius-to-fix waypoint has no #13006 centre;
    /// - `Malformed`: a radius-to-fix leg whose start (the previous waypoint) and end are not at
    ///   the same geodesic distance from its centre within 1 % or 5 m, whichever is larger (ICD
    ///   §7 rev. 2);
    /// - `MissingField`: no take-off height (#13006 type 1) was sent (this project's choice: the
    ///   height is part of every mission, ICD §5.1 step 2).
    ///
    /// Latitude, longitude and speed ranges are checked per message at decode. With
    /// `announced = None` (a download, closed by #14000) the count is what the plan visits.
    pub fn assemble(
        &self,
        announced: Option<u16>,
        mission_id: Option<Text<20>>,
    ) -> Result<Mission, Reason> {
        let mission = self.chain(announced, mission_id)?;
        mission.check_radii()?;
        Ok(mission)
    }

    /// [`MissionBuffer::assemble`] without the radius rule of radius-to-fix legs: the list as
    /// the chain of Next Waypoints gives it, for the safety gateway to name a leg whose radii
    /// differ (`ROUTE-RF-RADIUS`) where the FCC would only say `Malformed`.
    pub fn chain(
        &self,
        announced: Option<u16>,
        mission_id: Option<Text<20>>,
    ) -> Result<Mission, Reason> {
        let stored = self.waypoints.len();
        if announced.is_some_and(|n| usize::from(n) != stored) {
            return Err(Reason::CountMismatch);
        }
        let route = self.route.ok_or(Reason::MissingInitial)?;
        if !self.waypoints.contains_key(&route.initial_waypoint) {
            return Err(Reason::MissingInitial);
        }
        let mut waypoints = Vec::new();
        let mut number = route.initial_waypoint;
        loop {
            let waypoint = *self.waypoints.get(&number).ok_or(Reason::BrokenChain)?;
            // More steps than waypoints stored: the plan went round in a loop.
            waypoints
                .push(WaypointRecord {
                    waypoint,
                    rf_centre: self.rf_centres.get(&number).copied(),
                })
                .map_err(|_| Reason::BrokenChain)?;
            if waypoints.len() > stored {
                return Err(Reason::BrokenChain);
            }
            if waypoint.next_waypoint == 0 {
                break;
            }
            number = waypoint.next_waypoint;
        }
        if waypoints.len() != stored {
            return Err(Reason::CountMismatch);
        }
        if waypoints
            .iter()
            .any(|r| r.waypoint.leg_type == LegType::RadiusToFix && r.rf_centre.is_none())
        {
            return Err(Reason::MissingRfCentre);
        }
        let take_off = self.take_off.ok_or(Reason::MissingField)?;
        Ok(Mission {
            take_off,
            route,
            waypoints,
            mission_id,
        })
    }
}

/// Whether a radius-to-fix leg from `from` to `to` starts and ends on one circle about its
/// centre (ICD §7: within 1 % or 5 m, whichever is larger); true for any other leg.
fn rf_radii_agree(from: &WaypointRecord, to: &WaypointRecord) -> bool {
    let centre = match to.rf_centre.map(|c| c.data) {
        Some(SpecificData::RfCentre {
            latitude,
            longitude,
            ..
        }) if to.waypoint.leg_type == LegType::RadiusToFix => GeoPoint {
            latitude,
            longitude,
        },
        _ => return true,
    };
    let at = |w: &UaPositionWaypoint| GeoPoint {
        latitude: w.latitude,
        longitude: w.longitude,
    };
    let r0 = earth::distance_m(centre, at(&from.waypoint));
    let r1 = earth::distance_m(centre, at(&to.waypoint));
    (r0 - r1).abs() <= (0.01 * r0.max(r1)).max(5.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{self, mission_buffer as buffer};
    use missionlink_interfaces::wire::TurnDirection;

    /// Waypoint `number` (stamped `number` ms, so that a test sees time stamps dropped), on the
    /// circle of 1 km about [`rf_centre`]'s centre, 10° further round than the one before: any
    /// radius-to-fix leg between them passes ICD §7's radius rule.
    fn waypoint(number: u16, next: u16, leg: LegType) -> Message {
        let p = earth::destination(
            GeoPoint {
                latitude: missionlink_interfaces::wire::Angle::from_degrees(48.27455).unwrap(),
                longitude: missionlink_interfaces::wire::Angle::from_degrees(11.66991).unwrap(),
            },
            f64::from(number) * 10.0,
            1000.0,
        );
        let at = (p.y(), p.x());
        UaPositionWaypoint {
            time_stamp: Timestamp::from_millis(u64::from(number)).unwrap(),
            ..testkit::waypoint(number, next, at, leg)
        }
        .into()
    }

    fn take_off() -> Message {
        testkit::take_off(30.0).into()
    }

    fn rf_centre(number: u16) -> Message {
        testkit::rf_centre(number, (48.27455, 11.66991), TurnDirection::Clockwise).into()
    }

    fn route(initial: u16) -> Message {
        testkit::route(initial, true).into()
    }

    fn numbers(m: &Mission) -> std::vec::Vec<u16> {
        m.waypoints
            .iter()
            .map(|r| r.waypoint.waypoint_number)
            .collect()
    }

    #[test]
    fn assembles_in_flight_plan_order_from_any_upload_order() {
        let b = buffer(&[
            route(5),
            waypoint(9, 0, LegType::TrackToFix),
            waypoint(5, 7, LegType::TrackToFix),
            rf_centre(7),
            take_off(),
            waypoint(7, 9, LegType::RadiusToFix),
        ]);
        let m = b.assemble(Some(3), None).unwrap();
        assert_eq!(numbers(&m), [5, 7, 9]);
        assert!(m.waypoints[1].rf_centre.is_some());
        assert_eq!(m.take_off_height().metres(), 30.0);
        // Time stamps are not part of the mission.
        assert_eq!(m.waypoints[0].waypoint.time_stamp, Timestamp::default());
        let p = m.to_payload(4);
        assert_eq!(p.generation, 4);
        assert_eq!(p.waypoints().len(), 3);
        assert_eq!(
            p.waypoints()[1].rf_centre().unwrap().1,
            TurnDirection::Clockwise
        );
        assert!(p.bidirectional);
    }

    #[test]
    fn every_validity_check_of_icd_7() {
        let tf = LegType::TrackToFix;
        let cases: [(&[Message], Option<u16>, Reason); 8] = [
            (
                &[take_off(), route(1), waypoint(1, 0, tf)],
                Some(2),
                Reason::CountMismatch,
            ),
            (
                &[take_off(), waypoint(1, 0, tf)],
                Some(1),
                Reason::MissingInitial,
            ),
            (
                &[take_off(), route(2), waypoint(1, 0, tf)],
                Some(1),
                Reason::MissingInitial,
            ),
            (
                &[take_off(), route(1), waypoint(1, 3, tf), waypoint(2, 0, tf)],
                Some(2),
                Reason::BrokenChain,
            ),
            (
                &[take_off(), route(1), waypoint(1, 2, tf), waypoint(2, 1, tf)],
                Some(2),
                Reason::BrokenChain,
            ),
            (
                &[take_off(), route(1), waypoint(1, 1, tf)],
                Some(1),
                Reason::BrokenChain,
            ),
            (
                &[take_off(), route(1), waypoint(1, 0, tf), waypoint(2, 0, tf)],
                Some(2),
                Reason::CountMismatch,
            ),
            (
                &[take_off(), route(1), waypoint(1, 0, LegType::RadiusToFix)],
                Some(1),
                Reason::MissingRfCentre,
            ),
        ];
        for (messages, announced, reason) in cases {
            assert_eq!(
                buffer(messages).assemble(announced, None),
                Err(reason),
                "{messages:?}"
            );
        }
        assert_eq!(
            buffer(&[route(1), waypoint(1, 0, tf)]).assemble(Some(1), None),
            Err(Reason::MissingField)
        );
    }

    #[test]
    fn an_edit_overwrites_one_waypoint_and_keeps_the_rest() {
        let tf = LegType::TrackToFix;
        let b = buffer(&[take_off(), route(1), waypoint(1, 2, tf), waypoint(2, 0, tf)]);
        let m = b.assemble(Some(2), None).unwrap();
        let mut edit = MissionBuffer::from_mission(&m);
        let Message::UaPositionWaypoint(mut w2) = waypoint(2, 0, tf) else {
            unreachable!()
        };
        w2.altitude = Altitude::from_metres(150.0).unwrap();
        edit.store(&w2.into()).unwrap();
        let edited = edit.assemble(Some(2), None).unwrap();
        assert_eq!(edited.waypoints[0], m.waypoints[0]);
        assert_eq!(edited.waypoints[1].waypoint.altitude.metres(), 150.0);
    }

    #[test]
    fn capacity_is_refused_not_truncated() {
        let mut b = MissionBuffer::new();
        for n in 1..=MAX_WAYPOINTS as u16 {
            b.store(&waypoint(n, n + 1, LegType::TrackToFix)).unwrap();
        }
        assert_eq!(
            b.store(&waypoint(999, 0, LegType::TrackToFix)),
            Err(Reason::Capacity)
        );
        // Overwriting a stored number is still possible.
        assert_eq!(b.store(&waypoint(1, 2, LegType::TrackToFix)), Ok(()));
    }

    #[test]
    fn messages_follow_icd_order() {
        let b = buffer(&[
            take_off(),
            route(1),
            waypoint(1, 2, LegType::TrackToFix),
            waypoint(2, 0, LegType::RadiusToFix),
            rf_centre(2),
        ]);
        let m = b.assemble(Some(2), None).unwrap();
        let types: std::vec::Vec<u16> = m.messages().map(|m| m.message_type() as u16).collect();
        assert_eq!(types, [13006, 13002, 13002, 13006, 13001]);
        assert_eq!(m.message_count(), types.len());
    }

    /// ICD §7 rev. 2: a radius-to-fix leg whose end is 30 m farther from the centre than its
    /// start (1 km: beyond 1 % and 5 m) is `Malformed`; 8 m (within 1 %) is accepted.
    #[test]
    fn a_radius_to_fix_leg_starts_and_ends_on_one_circle() {
        let centre = (48.27455, 11.66991);
        let on = |bearing: f64, r: f64| {
            let c = GeoPoint {
                latitude: missionlink_interfaces::wire::Angle::from_degrees(centre.0).unwrap(),
                longitude: missionlink_interfaces::wire::Angle::from_degrees(centre.1).unwrap(),
            };
            let p = earth::destination(c, bearing, r);
            (p.y(), p.x())
        };
        for (end_radius, expected) in [(1030.0, Err(Reason::Malformed)), (1008.0, Ok(()))] {
            let b = buffer(&[
                take_off(),
                route(1),
                testkit::waypoint(1, 2, on(0.0, 1000.0), LegType::TrackToFix).into(),
                testkit::waypoint(2, 0, on(90.0, end_radius), LegType::RadiusToFix).into(),
                rf_centre(2),
            ]);
            assert_eq!(
                b.assemble(Some(2), None).map(|_| ()),
                expected,
                "{end_radius}"
            );
        }
    }
}
