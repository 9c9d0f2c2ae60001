//! Edits that send only what changed (paper §3.1.5: the waypoint buffer exists so that "only
//! changes in the flight plan need to be transmitted"; ICD §8 "The waypoint buffer").
//!
//! The FCC's buffer, once loaded with the mission to edit (#13000 mode 10 toward edition 2; the
//! content it kept after the last closer toward edition 1), needs only the messages that differ:
//! a waypoint number sent again overwrites, a new one is added (ICD §5.1 step 3), and the
//! closer assembles the whole list from the buffer again. What a difference cannot express is
//! a removal: the buffer has no message that takes a waypoint or a radius-to-fix centre out, so
//! the assembly would still count a removed waypoint (`CountMismatch`, ICD §7) or keep a
//! removed centre. Such an edit is a full upload, and the GCS says why ([`FullUpload`]).

use core::fmt;

use missionlink_protocol::transfer::mission::Mission;

/// Why an edit is sent as a full upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FullUpload {
    /// The target holds no waypoint list: there is nothing to edit.
    NoMission,
    /// Waypoints of the FCC's mission are not in the file: the buffer cannot forget them.
    WaypointsRemoved {
        /// The first such waypoint number (in flight-plan order of the FCC's mission).
        first: u16,
        /// How many.
        count: usize,
    },
    /// A waypoint lost its radius-to-fix centre (#13006 type 2): the buffer keeps a centre once
    /// stored.
    RfCentreRemoved(u16),
}

impl fmt::Display for FullUpload {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoMission => f.write_str("the FCC holds no mission there to edit"),
            Self::WaypointsRemoved { first, count } => write!(
                f,
                "{count} waypoint(s) removed (first: {first}); the waypoint buffer has no \
                 message that removes one"
            ),
            Self::RfCentreRemoved(n) => write!(
                f,
                "waypoint {n} lost its radius-to-fix centre; the waypoint buffer keeps a centre \
                 once stored"
            ),
        }
    }
}

/// The messages of `new` (indices into [`Mission::messages`], ascending) that turn a buffer
/// holding `base` into one that assembles to `new`: the take-off height if it changed, each
/// waypoint (#13002) that changed or is new, each radius-to-fix centre that changed or is new,
/// the route (#13001) if it changed. Empty when the missions are equal (the Mission ID aside,
/// which only the closer carries).
pub fn difference(base: &Mission, new: &Mission) -> Result<Vec<u16>, FullUpload> {
    let find = |number: u16| {
        new.waypoints
            .iter()
            .find(|r| r.waypoint.waypoint_number == number)
    };
    let removed: Vec<u16> = base
        .waypoints
        .iter()
        .map(|r| r.waypoint.waypoint_number)
        .filter(|n| find(*n).is_none())
        .collect();
    if let Some(&first) = removed.first() {
        return Err(FullUpload::WaypointsRemoved {
            first,
            count: removed.len(),
        });
    }
    let mut selection = Vec::new();
    let mut index: u16 = 0;
    if base.take_off != new.take_off {
        selection.push(index);
    }
    for record in &new.waypoints {
        let number = record.waypoint.waypoint_number;
        let old = base
            .waypoints
            .iter()
            .find(|r| r.waypoint.waypoint_number == number);
        index += 1;
        if old.is_none_or(|o| o.waypoint != record.waypoint) {
            selection.push(index);
        }
        match (old.and_then(|o| o.rf_centre), record.rf_centre) {
            (Some(_), None) => return Err(FullUpload::RfCentreRemoved(number)),
            (old_centre, Some(centre)) => {
                index += 1;
                if old_centre != Some(centre) {
                    selection.push(index);
                }
            }
            (None, None) => {}
        }
    }
    index += 1;
    if base.route != new.route {
        selection.push(index);
    }
    Ok(selection)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{generated_plan, mission_2};
    use missionlink_interfaces::wire::{Altitude, Message};
    use missionlink_protocol::transfer::mission::MissionBuffer;

    fn mission(plan: &crate::ground_station::MissionPlan) -> Mission {
        plan.assemble()
            .map(|v| v.mission)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// The selection applied to a buffer holding the base assembles to the new mission.
    fn applied(base: &Mission, new: &Mission, selection: &[u16]) -> Mission {
        let mut buffer = MissionBuffer::from_mission(base);
        let messages: Vec<Message> = new.messages().collect();
        for i in selection {
            buffer
                .store(&messages[usize::from(*i)])
                .unwrap_or_else(|r| panic!("{r}"));
        }
        buffer
            .assemble(Some(new.waypoints.len() as u16), new.mission_id)
            .unwrap_or_else(|r| panic!("{r}"))
    }

    #[test]
    fn one_changed_waypoint_is_one_message() {
        let base = mission(&generated_plan(256));
        let mut new = base.clone();
        new.waypoints[100].waypoint.altitude = Altitude::from_metres(321.0).unwrap();
        let selection = difference(&base, &new).unwrap();
        assert_eq!(selection, [101]);
        assert_eq!(applied(&base, &new, &selection), new);
        assert_eq!(difference(&base, &base), Ok(vec![]));
    }

    #[test]
    fn take_off_route_and_rf_centres_are_sent_only_when_changed() {
        let base = mission(&mission_2());
        let mut new = base.clone();
        new.take_off = crate::testkit::take_off(55.0);
        new.route.bidirectional = !base.route.bidirectional;
        let selection = difference(&base, &new).unwrap();
        assert_eq!(
            selection,
            [0, new.message_count() as u16 - 1],
            "take-off first, route last"
        );
        assert_eq!(applied(&base, &new, &selection), new);
    }

    #[test]
    fn a_removal_is_a_full_upload() {
        let base = mission(&generated_plan(5));
        let shorter = mission(&generated_plan(4));
        assert_eq!(
            difference(&base, &shorter),
            Err(FullUpload::WaypointsRemoved { first: 5, count: 1 })
        );
        // Added waypoints are a difference: the longer mission from the shorter one.
        let selection = difference(&shorter, &base).unwrap();
        assert_eq!(applied(&shorter, &base, &selection), base);
    }
}
