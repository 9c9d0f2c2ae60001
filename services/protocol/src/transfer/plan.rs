//! What the operator planned ([`MissionPlan`]) and the lists it assembles into
//! ([`ValidatedPlan`]), each describing itself in one line as `gcs validate` prints it.

use core::fmt;

use missionlink_interfaces::capacity::MAX_WAYPOINTS;
use missionlink_interfaces::wire::{GeoPoint, Reason, SafetyOffset, Text};

use super::areas::{AreaBuffer, AreaList};
use super::mission::{Mission, MissionBuffer};

/// What the operator planned: the mission data in any order and the areas, as the GCS holds
/// them before assembly.
#[derive(Debug, Clone, Default)]
pub struct MissionPlan {
    /// Take-off height, waypoints, RF centres and route.
    pub mission: MissionBuffer,
    /// Fly-zone and no-fly-zones.
    pub areas: AreaBuffer,
    /// Safety offset of the areas.
    pub safety_offset: SafetyOffset,
    /// Mission ID sent with #13000 mode 2.
    pub mission_id: Option<Text<20>>,
    /// Where the aircraft stands before take-off (QGroundControl's planned home or take-off
    /// item). Not sent: the FCC takes off where navigation says it is (ICD §7); the safety
    /// gateway needs it to check the climb and the way to the initial waypoint.
    pub take_off_position: Option<GeoPoint>,
}

/// Why a plan does not assemble into the lists of ICD §7.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum InvalidPlan {
    /// The waypoint list, with the reason.
    #[error("the waypoint list is invalid (ICD §7): {0}")]
    Mission(Reason),
    /// The area list, with the reason.
    #[error("the area list is invalid (ICD §7): {0}")]
    Areas(Reason),
}

impl MissionPlan {
    /// The first step of a validation request: both lists assembled with the FCC's own
    /// assembly (ICD §7), the plan's counts as the announced counts.
    pub fn assemble(&self) -> Result<ValidatedPlan, InvalidPlan> {
        let announced = u16::try_from(self.mission.len())
            .map_err(|_| InvalidPlan::Mission(Reason::Capacity))?;
        let mission = self
            .mission
            .assemble(Some(announced), self.mission_id)
            .map_err(InvalidPlan::Mission)?;
        let areas = self
            .areas
            .assemble(self.areas.len() as u8, self.safety_offset)
            .map_err(InvalidPlan::Areas)?;
        Ok(ValidatedPlan { mission, areas })
    }
}

/// What the safety gateway checks of a plan: both lists as far as they assemble, and why they
/// fail ICD §7 if they do. A waypoint list whose only fault is a radius-to-fix leg's radii, and
/// an area list with any fault, are still checked (unchecked), so that the gateway names every
/// defect; the ICD reason is the answer when it names none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ListsToCheck {
    /// The waypoint list.
    pub mission: Mission,
    /// The area list, valid or not.
    pub areas: AreaList,
    /// Why the lists fail ICD §7, if they do.
    pub invalid: Option<InvalidPlan>,
}

impl MissionPlan {
    /// The lists to run the safety gateway on; `Err` only when the waypoint list does not
    /// even chain (count, initial waypoint, Next Waypoints, RF centres, take-off height).
    pub fn lists_to_check(&self) -> Result<ListsToCheck, InvalidPlan> {
        let announced = u16::try_from(self.mission.len())
            .map_err(|_| InvalidPlan::Mission(Reason::Capacity))?;
        let mission = self
            .mission
            .chain(Some(announced), self.mission_id)
            .map_err(InvalidPlan::Mission)?;
        // Each list assembled once; the first ICD §7 refusal is the answer, as `assemble`'s.
        let (areas, areas_invalid) = match self
            .areas
            .assemble(self.areas.len() as u8, self.safety_offset)
        {
            Ok(areas) => (areas, None),
            Err(r) => (self.areas.unchecked(self.safety_offset), Some(r)),
        };
        let invalid = match (mission.check_radii(), areas_invalid) {
            (Err(r), _) => Some(InvalidPlan::Mission(r)),
            (Ok(()), Some(r)) => Some(InvalidPlan::Areas(r)),
            (Ok(()), None) => None,
        };
        Ok(ListsToCheck {
            mission,
            areas,
            invalid,
        })
    }
}

/// The Mission ID as the one-line descriptions quote it (empty when none).
fn quoted_mission_id(f: &mut fmt::Formatter<'_>, id: Option<Text<20>>) -> fmt::Result {
    write!(f, "{:?}", id.as_ref().map_or("", |t| t.as_str()))
}

/// One line, before assembly: `plan "MEDEVAC-2": 3 waypoints, 3 areas, safety offset 25.0 m`.
impl fmt::Display for MissionPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("plan ")?;
        quoted_mission_id(f, self.mission_id)?;
        write!(
            f,
            ": {} waypoints, {} areas, safety offset {:.1} m",
            self.mission.len(),
            self.areas.len(),
            self.safety_offset.metres()
        )
    }
}

/// The lists a validation request produced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValidatedPlan {
    /// The waypoint list.
    pub mission: Mission,
    /// The area list.
    pub areas: AreaList,
}

/// One line, the route in flight-plan order: `mission "MEDEVAC-2": take-off 30.0 m, 3 waypoints
/// (1 -> 2 -> 3), route bidirectional; 3 areas, safety offset 25.0 m`.
impl fmt::Display for ValidatedPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.mission;
        f.write_str("mission ")?;
        quoted_mission_id(f, m.mission_id)?;
        write!(
            f,
            ": take-off {:.1} m, {} waypoints (",
            m.take_off_height().metres(),
            m.waypoints.len()
        )?;
        write_chain(f, m.waypoints.iter().map(|r| r.waypoint.waypoint_number))?;
        write!(
            f,
            "), route {}; {} areas, safety offset {:.1} m",
            if m.route.bidirectional {
                "bidirectional"
            } else {
                "one-way"
            },
            self.areas.areas.len(),
            self.areas.safety_offset.metres()
        )
    }
}

/// A run of consecutive waypoint numbers this long or longer prints as its first two numbers,
/// `...` and its last.
const CHAIN_RUN: usize = 4;
/// A chain with more parts than this (after runs are shortened) prints its first and last
/// parts and how many it left out.
const CHAIN_PARTS: usize = 12;

/// Writes waypoint numbers in flight-plan order, compactly: `1 -> 2 -> ... -> 256` for a run of
/// consecutive numbers, and `... (40 more) ...` in the middle of a long chain without runs, so a
/// 256-waypoint mission stays one readable line.
fn write_chain(f: &mut fmt::Formatter<'_>, numbers: impl Iterator<Item = u16>) -> fmt::Result {
    // Runs (first, last) of numbers each one above the one before.
    let mut runs: heapless::Vec<(u16, u16), MAX_WAYPOINTS> = heapless::Vec::new();
    for n in numbers {
        match runs.last_mut() {
            Some((_, last)) if last.checked_add(1) == Some(n) => *last = n,
            _ => {
                if runs.push((n, n)).is_err() {
                    break;
                }
            }
        }
    }
    // Parts: a run of CHAIN_RUN numbers or more, or a single number.
    let parts = runs.iter().flat_map(|&(first, last)| {
        let short = usize::from(last - first) + 1 < CHAIN_RUN;
        let singles = (first..=last).filter(move |_| short).map(|n| (n, None));
        let run = (!short).then_some((first, Some(last)));
        singles.chain(run)
    });
    let total = parts.clone().count();
    let (head, tail) = if total > CHAIN_PARTS {
        (CHAIN_PARTS - 3, 3)
    } else {
        (total, 0)
    };
    for (i, (first, last)) in parts.enumerate() {
        if i >= head && i + tail < total {
            if i == head {
                write!(f, " -> ... ({} more) ...", total - head - tail)?;
            }
            continue;
        }
        if i > 0 {
            f.write_str(" -> ")?;
        }
        match last {
            Some(last) => write!(f, "{first} -> {} -> ... -> {last}", first.saturating_add(1))?,
            None => write!(f, "{first}")?,
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain printed by `write_chain`.
    fn chain(numbers: &[u16]) -> String {
        struct Chain<'a>(&'a [u16]);
        impl fmt::Display for Chain<'_> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write_chain(f, self.0.iter().copied())
            }
        }
        Chain(numbers).to_string()
    }

    #[test]
    fn short_chains_print_every_number() {
        assert_eq!(chain(&[1]), "1");
        assert_eq!(chain(&[1, 2, 3]), "1 -> 2 -> 3");
        assert_eq!(chain(&[5, 3, 9, 10]), "5 -> 3 -> 9 -> 10");
    }

    #[test]
    fn runs_of_consecutive_numbers_print_their_ends() {
        let all: Vec<u16> = (1..=256).collect();
        assert_eq!(chain(&all), "1 -> 2 -> ... -> 256");
        assert_eq!(
            chain(&[9, 1, 2, 3, 4, 5, 7]),
            "9 -> 1 -> 2 -> ... -> 5 -> 7"
        );
        assert_eq!(
            chain(&[u16::MAX - 3, u16::MAX - 2, u16::MAX - 1, u16::MAX]),
            "65532 -> 65533 -> ... -> 65535"
        );
    }

    #[test]
    fn long_chains_without_runs_print_their_ends_and_the_count_between() {
        let odd: Vec<u16> = (0..100).map(|i| 2 * i + 1).collect();
        assert_eq!(
            chain(&odd),
            "1 -> 3 -> 5 -> 7 -> 9 -> 11 -> 13 -> 15 -> 17 -> ... (88 more) ... -> 195 -> 197 -> 199"
        );
        let twelve: Vec<u16> = (0..12).map(|i| 2 * i).collect();
        assert_eq!(chain(&twelve).matches("->").count(), 11);
    }
}
