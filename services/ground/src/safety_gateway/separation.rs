//! Separation between the fleet's vehicles (docs/design.md, "Separation between the fleet's
//! vehicles"): before a mission is uploaded to one vehicle, every path it would fly is compared
//! with every path of the other vehicles' active missions, horizontally and in altitude.
//! [`conflicts`] is the check; [`Flown`] is one mission's paths made ready once, so that a fleet
//! checked vehicle by vehicle measures each mission's paths once ([`Flown::conflicts`]).
//!
//! # What is compared
//!
//! Each mission as the geographic checks fly it (the [module documentation](super); ICD §7
//! "Onboard geofence check" and "Turns in wind"), element by element, each element named as the
//! gateway's violations name it ([`RouteElement`]):
//!
//! - the climb at the take-off point and the leg from there to the initial waypoint, where the
//!   take-off point is given ([`Flight::take_off`]);
//! - every leg between the waypoints in full: track-to-fix legs as WGS-84 geodesics,
//!   radius-to-fix legs as their arcs about their centre;
//! - the turn at every waypoint as guidance flies it ([`missionlink_protocol::geofence::turn`]):
//!   at the profile's bank, sized for the wind the gateway checks the mission's turns in
//!   ([`SafetyGateway::turn_wind_mps`]: the larger of the mission's planning wind and the
//!   environment's), so that more wind makes wider turns; the paths of one turn (a fly-over's
//!   turn, intercept and turn back) are one element. The other vehicles' turns too: an active
//!   mission carries the planning wind it was uploaded with (#13001 field 5, set by the
//!   validation, `ground_station::plan_in_wind`), which its FCC flies its turns in; where the
//!   wind given is stronger, the check takes the wider turns that wind calls for (ICD §7 "Turns
//!   in wind" holds a turn only up to its planning wind);
//! - on a bidirectional route, the turns of a return to home (the way back from the last
//!   waypoint and the turn round at every waypoint); the reverse legs are the legs' own paths.
//!
//! Two elements of two vehicles **conflict** where their paths come closer than the horizontal
//! separation ([`Separation::horizontal_m`], `[fleet] separation_m`) while their altitude bands
//! are closer than the vertical separation ([`Separation::vertical_m`], `[fleet]
//! vertical_separation_m`). Each pair of elements in conflict is one [`Conflict`], whatever the
//! length over which they are close: it names both vehicles and both elements, says how much
//! closer than the separation the paths come (the margin) and where (on the checked vehicle's
//! path), and becomes one gateway [`Violation`] (`FLEET-SEP`, [`Conflict::violation`]).
//!
//! # Time-independent, and so conservative
//!
//! The check does not know when each vehicle will be where: a vehicle's mission may start at
//! any time, and its speed over the ground depends on the wind. So it compares paths, not
//! positions at a time: two routes that cross conflict even if the vehicles would pass the
//! crossing minutes apart. It can refuse missions that would have been flown safely; of the
//! paths it compares, it never passes two that come closer than the separation. The other
//! vehicles' missions are their *active* ones: once a vehicle has landed and its mission is no
//! longer active, it no longer counts.
//!
//! # Altitudes
//!
//! Altitudes are the mission's waypoint altitudes, heights above the take-off ground as
//! guidance takes them (the gateway's approximation, [module documentation](super)). Each
//! element has a *band*, the lowest and highest altitude the aircraft may be at on it, taken so
//! that it holds whatever the rate of climb:
//!
//! - a leg spans the altitudes of its two ends (guidance moves linearly from the one to the
//!   other; a slower climb stays between them too); the leg from the take-off point spans the
//!   take-off height and the initial waypoint's altitude;
//! - a turn at a waypoint spans that waypoint's altitude and those of the waypoints before and
//!   after it in the flight plan (and the take-off height at the initial waypoint), so that an
//!   aircraft still climbing on the leg into the turn or already on the way to the next
//!   waypoint's altitude is inside it;
//! - the climb at the take-off point spans the ground (0) to the take-off height.
//!
//! Two bands are as close as the gap between them (0 when they overlap).
//!
//! # Geometry
//!
//! The geofence's ([`missionlink_protocol::geofence`]), the one Earth model: each path is the
//! [`Track`] the geographic checks measure, its patches tangent planes with the path's corners
//! in them, each corner lifted back onto the ellipsoid exactly ([`Plane::lift`]). Two patches
//! are measured in the plane of the checked vehicle's patch (the other's corners projected
//! into it, as the geofence projects a zone's border), chord against chord with
//! [`segment_segment`]: exact on geodesics up to the plane's own error (millimetres for pieces
//! of 20 km, [`missionlink_protocol::geofence::plane`]). An arc is the geofence's polyline,
//! whose corners lie on it and whose chords stray at most [`ARC_SAG_M`] (5 cm) from it, towards
//! the other path or away: the distance found is lowered by that much for each arc of the pair,
//! so that it is never more than the true distance and at most twice [`ARC_SAG_M`] less for
//! each arc (a test bounds it against the exact distance to a circle).
//!
//! A fleet of sixteen 256-waypoint missions has some ten thousand elements: each element has an
//! axis-aligned box in Earth-centred coordinates (holding its paths, with room for the sag and
//! the geodesics' bulge), and only pairs whose boxes come within the separation are measured,
//! found by a sweep along the axis where the boxes spread most (so not every pair of elements
//! is looked at). Within a pair, a patch whose box is farther than the closest approach found
//! so far is skipped, as the geofence does, and the chords are taken in runs of eight with a
//! box each, the closest runs first: two turns of a hundred chords each compare a few runs,
//! not every chord with every chord.
//!
//! # Not compared
//!
//! - The landing's vertical descent: where an aircraft lands is where the land command finds it
//!   (the last waypoint when the route is complete), not part of the route.
//! - An aircraft's way from its take-off point to its initial waypoint when the take-off point
//!   is not given (an aircraft already on its route), and a return to home from wherever it is
//!   off its route.
//! - Altitude data: all altitudes are compared as heights above one ground; vehicles taking off
//!   from grounds of different elevation need their altitudes on one datum.

use std::collections::HashMap;
use std::fmt;

use missionlink_protocol::geofence::earth::WGS84_MIN_RADIUS_M;
use missionlink_protocol::geofence::path::ARC_SAG_M;
use missionlink_protocol::geofence::plane::{Coord, Plane, segment_segment};

use super::*;

/// The separation the fleet's vehicles keep (`[fleet] separation_m` and
/// `vertical_separation_m`): two paths conflict where they are closer than `horizontal_m`
/// while their altitudes are closer than `vertical_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Separation {
    /// Horizontal distance, metres (geodesic, on WGS-84).
    pub horizontal_m: f64,
    /// Vertical distance, metres.
    pub vertical_m: f64,
}

/// Why the separation check cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SeparationError {
    /// The horizontal separation is not a finite distance above 0.
    #[error("the horizontal separation {0} m is not a distance above 0")]
    Horizontal(f64),
    /// The vertical separation is not a finite distance above 0.
    #[error("the vertical separation {0} m is not a distance above 0")]
    Vertical(f64),
    /// A vehicle is named twice: the checked vehicle among the others, or one of the others
    /// twice. Its mission would be compared with itself (or counted twice), and a path is
    /// always in conflict with itself.
    #[error("vehicle {0:?} is named twice: a vehicle's mission is not compared with itself")]
    DuplicateVehicle(String),
}

impl Separation {
    fn validate(&self) -> Result<(), SeparationError> {
        let usable = |m: f64| m.is_finite() && m > 0.0;
        if !usable(self.horizontal_m) {
            return Err(SeparationError::Horizontal(self.horizontal_m));
        }
        if !usable(self.vertical_m) {
            return Err(SeparationError::Vertical(self.vertical_m));
        }
        Ok(())
    }
}

/// One vehicle and its mission, as the check takes them.
#[derive(Debug, Clone, Copy)]
pub struct Flight<'a> {
    /// The vehicle's name in the fleet.
    pub vehicle: &'a str,
    /// Its mission: the one to be uploaded, or another vehicle's active one.
    pub mission: &'a Mission,
    /// Where it takes off (the plan's take-off position), when known: then the climb there and
    /// the leg to the initial waypoint are compared too. `None` for an aircraft on its route.
    pub take_off: Option<GeoPoint>,
}

/// A vehicle and one element of its mission, as a [`Conflict`] names them.
#[derive(Debug, Clone, PartialEq)]
pub struct Side {
    /// The vehicle's name.
    pub vehicle: String,
    /// The element, in the gateway's words (`leg 1->2`, `fly-by turn at waypoint 3 onto the
    /// leg to 4`, ...).
    pub element: RouteElement,
    /// Its altitude band: the lowest and the highest altitude on it, metres.
    pub altitudes_m: (f64, f64),
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (lo, hi) = self.altitudes_m;
        write!(
            f,
            "{} of {} ({lo:.0} to {hi:.0} m)",
            self.element, self.vehicle
        )
    }
}

/// Two elements of two vehicles closer than the separation, horizontally and vertically.
#[derive(Debug, Clone, PartialEq)]
pub struct Conflict {
    /// The vehicle whose mission is checked, and its element.
    pub own: Side,
    /// The other vehicle, and the element of its active mission.
    pub other: Side,
    /// The closest horizontal approach of the two elements' paths, metres: exact on geodesics
    /// (to the plane's millimetres); never more than the true one and at most 10 cm less for
    /// each arc (see "Geometry" in the module documentation).
    pub distance_m: f64,
    /// How much closer than the horizontal separation the paths come, metres (above 0):
    /// `separation − distance`.
    pub margin_m: f64,
    /// The gap between the two altitude bands, metres (0 where they overlap): below the
    /// vertical separation.
    pub vertical_gap_m: f64,
    /// Latitude and longitude (degrees) of the closest approach on the checked vehicle's path.
    pub position: (f64, f64),
    /// The separation checked.
    pub separation: Separation,
}

impl Conflict {
    /// The conflict as the gateway reports a violation: `FLEET-SEP` on the checked vehicle's
    /// element, the margin signed as the gateway signs margins (negative: that far inside the
    /// separation), the distance against the separation, the position of the closest
    /// approach.
    pub fn violation(&self) -> Violation {
        Violation {
            code: ViolationCode::Separation,
            element: Element::Route(self.own.element),
            detail: self.to_string(),
            margin_m: Some(-self.margin_m),
            value: Some(self.distance_m),
            limit: Some(self.separation.horizontal_m),
            position: Some(self.position),
        }
    }
}

impl fmt::Display for Conflict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} comes within {:.1} m of {}, {:.1} m inside the separation of {} m, {:.0} m apart in altitude (vertical separation {} m)",
            self.own,
            self.distance_m,
            self.other,
            self.margin_m,
            self.separation.horizontal_m,
            self.vertical_gap_m,
            self.separation.vertical_m,
        )
    }
}

/// Compares the mission `own` would fly with the active missions of `others`, as the gateway
/// in `gateway` (its aircraft profile and environment) flies them: every conflict, in the order
/// of the others, then of `own`'s elements as flown, then of the other's (empty: the mission
/// keeps its separation from the fleet).
pub fn conflicts(
    gateway: &SafetyGateway,
    own: Flight<'_>,
    others: &[Flight<'_>],
    separation: Separation,
) -> Result<Vec<Conflict>, SeparationError> {
    separation.validate()?;
    distinct(core::iter::once(own.vehicle).chain(others.iter().map(|f| f.vehicle)))?;
    let own = Flown::new(gateway, own);
    let others: Vec<Flown> = others.iter().map(|f| Flown::new(gateway, *f)).collect();
    own.conflicts(&others, separation)
}

/// `Err` naming the first vehicle named twice.
fn distinct<'a>(names: impl Iterator<Item = &'a str>) -> Result<(), SeparationError> {
    let mut seen = std::collections::HashSet::new();
    for name in names {
        if !seen.insert(name) {
            return Err(SeparationError::DuplicateVehicle(name.to_owned()));
        }
    }
    Ok(())
}

/// One vehicle's mission as the check compares it: its elements with their paths, altitude
/// bands and boxes, built once ([`Flown::new`]) and compared with any others
/// ([`Flown::conflicts`]).
#[derive(Debug, Clone)]
pub struct Flown {
    vehicle: String,
    elements: Vec<FlownElement>,
}

/// One element: what it is, its altitude band and its paths' patches.
#[derive(Debug, Clone)]
struct FlownElement {
    part: RouteElement,
    band: (f64, f64),
    patches: Vec<Patch>,
    bounds: Bounds,
}

/// One patch of a path ([`Track::planes`]): its plane, the path's corners in it and the same
/// corners on the ellipsoid.
#[derive(Debug, Clone)]
struct Patch {
    plane: Plane,
    corners: Vec<Coord>,
    ecef: Vec<[f64; 3]>,
    /// The first corner: where a closest approach is placed should its lift fail.
    first: Site,
    /// How far the chords between the corners may lie from the path, metres.
    sag_m: f64,
    bounds: Bounds,
    /// The chords in runs, with their boxes in the plane.
    runs: Vec<Run>,
}

/// An axis-aligned box in Earth-centred, Earth-fixed coordinates, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounds {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Bounds {
    const EMPTY: Self = Self {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    /// The box grown to hold `p` with `pad` metres around it.
    fn with(self, p: &[f64; 3], pad: f64) -> Self {
        let mut b = self;
        for ((lo, hi), x) in b.lo.iter_mut().zip(b.hi.iter_mut()).zip(p) {
            *lo = lo.min(x - pad);
            *hi = hi.max(x + pad);
        }
        b
    }

    fn union(self, other: &Self) -> Self {
        self.with(&other.lo, 0.0).with(&other.hi, 0.0)
    }

    /// The largest gap between the boxes along an axis: no point of the one is closer than
    /// this to a point of the other, along a straight line and so along the surface.
    fn gap(&self, other: &Self) -> f64 {
        (0..3)
            .map(|axis| {
                let (a, b) = (self.span(axis), other.span(axis));
                (b.0 - a.1).max(a.0 - b.1).max(0.0)
            })
            .fold(0.0, f64::max)
    }

    /// Lower and upper end along `axis`.
    fn span(&self, axis: usize) -> (f64, f64) {
        match (self.lo.get(axis), self.hi.get(axis)) {
            (Some(lo), Some(hi)) => (*lo, *hi),
            _ => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
}

impl FlownElement {
    fn new(part: RouteElement, band: (f64, f64), path: &Path) -> Self {
        let mut element = Self {
            part,
            band,
            patches: Vec::new(),
            bounds: Bounds::EMPTY,
        };
        element.extend(path);
        element
    }

    /// Adds the patches of `path`, another path of the element.
    fn extend(&mut self, path: &Path) {
        for patch in patches(path) {
            self.bounds = self.bounds.union(&patch.bounds);
            self.patches.push(patch);
        }
    }
}

/// The band from the lowest to the highest of `altitudes`, metres.
fn band(altitudes: impl IntoIterator<Item = f64>) -> (f64, f64) {
    altitudes
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
            (lo.min(a), hi.max(a))
        })
}

/// The gap between two altitude bands (0 where they overlap), metres.
fn vertical_gap(a: (f64, f64), b: (f64, f64)) -> f64 {
    (b.0 - a.1).max(a.0 - b.1).max(0.0)
}

/// The patches of `path`'s track, each corner lifted onto the ellipsoid.
fn patches(path: &Path) -> Vec<Patch> {
    let track = Track::new(*path);
    let sag_m = match path {
        Path::Arc(_) => ARC_SAG_M,
        Path::Point(_) | Path::Geodesic { .. } => 0.0,
    };
    track
        .planes()
        .enumerate()
        .filter_map(|(i, (plane, corners))| {
            // The lift is exact; the geodesic from the plane's origin is the fallback for a
            // corner it cannot lift (none closer than the Earth's radius to the origin).
            let ecef: Vec<[f64; 3]> = corners
                .iter()
                .filter_map(|c| {
                    plane
                        .lift_ecef(*c)
                        .or_else(|| track.site(i, *c).map(|s| s.ecef))
                })
                .collect();
            if ecef.len() != corners.len() {
                return None;
            }
            let first = match corners.first() {
                Some(c) => plane.lift(*c).or_else(|| track.site(i, *c))?,
                None => return None,
            };
            // The path between two corners leaves their chord by the sag (arcs) and by the
            // geodesic's bulge over the chord (`l²/(8R)`, taken twice as the geofence's balls
            // take it).
            let longest = ecef
                .windows(2)
                .filter_map(|w| match w {
                    [a, b] => Some(earth::chord(a, b)),
                    _ => None,
                })
                .fold(0.0, f64::max);
            let pad = sag_m + longest * longest / (4.0 * WGS84_MIN_RADIUS_M) + 0.01;
            let bounds = ecef.iter().fold(Bounds::EMPTY, |b, p| b.with(p, pad));
            let mut chord_runs = Vec::new();
            runs(corners, &mut chord_runs);
            Some(Patch {
                plane: *plane,
                corners: corners.to_vec(),
                ecef,
                first,
                sag_m,
                bounds,
                runs: chord_runs,
            })
        })
        .collect()
}

impl Flown {
    /// The elements of `flight`'s mission as `gateway` flies them (see the module
    /// documentation): the climb and the leg from the take-off point where it is given, the
    /// legs, the turns.
    pub fn new(gateway: &SafetyGateway, flight: Flight<'_>) -> Self {
        let Flight {
            vehicle,
            mission,
            take_off,
        } = flight;
        let toh = mission.take_off_height().metres();
        let altitude = |i: usize| {
            mission
                .waypoints
                .get(i)
                .map(|r| r.waypoint.altitude.metres())
        };
        let mut elements: Vec<FlownElement> = Vec::new();
        if let Some(t) = take_off {
            elements.push(FlownElement::new(
                RouteElement::Climb,
                (0.0, toh),
                &Path::Point(Site::of(t)),
            ));
        }
        for leg in SafetyGateway::legs(mission, take_off) {
            let from = match leg.from_index {
                Some(i) => altitude(i),
                None => Some(toh),
            };
            let band = band(from.into_iter().chain(altitude(leg.to_index)));
            elements.push(FlownElement::new(leg.element, band, &leg.path));
        }
        // The paths of one turn come one after the other with the same name; a turn of the
        // way back and the turn round at a waypoint may share a name too (both onto the leg
        // back): one element each name.
        let mut turns: HashMap<RouteElement, usize> = HashMap::new();
        for turn in gateway.turns(mission, take_off) {
            let Some(at) = turn.from_index else { continue };
            if let Some(existing) = turns.get(&turn.element).and_then(|k| elements.get_mut(*k)) {
                existing.extend(&turn.path);
                continue;
            }
            let neighbours = [
                at.checked_sub(1),
                Some(at),
                Some(at + 1),
                Some(turn.to_index),
            ]
            .into_iter()
            .flatten()
            .filter_map(altitude);
            let climbing = (at == 0 && take_off.is_some()).then_some(toh);
            turns.insert(turn.element, elements.len());
            let band = band(neighbours.chain(climbing));
            elements.push(FlownElement::new(turn.element, band, &turn.path));
        }
        Self {
            vehicle: vehicle.to_owned(),
            elements,
        }
    }

    /// The vehicle's name.
    pub fn vehicle(&self) -> &str {
        &self.vehicle
    }

    /// The elements in the order flown, each with its altitude band (lowest, highest, metres).
    pub fn elements(&self) -> impl Iterator<Item = (RouteElement, (f64, f64))> + '_ {
        self.elements.iter().map(|e| (e.part, e.band))
    }

    /// Every conflict of this mission with the missions of `others` (see [`conflicts`] for the
    /// order).
    pub fn conflicts<'a>(
        &self,
        others: impl IntoIterator<Item = &'a Flown>,
        separation: Separation,
    ) -> Result<Vec<Conflict>, SeparationError> {
        separation.validate()?;
        let others: Vec<&Flown> = others.into_iter().collect();
        distinct(core::iter::once(self.vehicle()).chain(others.iter().map(|f| f.vehicle())))?;
        // Every other vehicle's elements in one list, each with its vehicle's index.
        let their_elements: Vec<(usize, usize, &FlownElement)> = others
            .iter()
            .enumerate()
            .flat_map(|(v, f)| f.elements.iter().enumerate().map(move |(k, e)| (v, k, e)))
            .collect();
        let own_bounds: Vec<Bounds> = self.elements.iter().map(|e| e.bounds).collect();
        let their_bounds: Vec<Bounds> = their_elements.iter().map(|(_, _, e)| e.bounds).collect();
        let reach = separation.horizontal_m;
        let mut scratch = Scratch::default();
        let mut found: Vec<((usize, usize, usize), Conflict)> = Vec::new();
        for (i, j) in overlapping(&own_bounds, &their_bounds, reach) {
            let (Some(mine), Some(&(v, k, theirs)), Some(other)) = (
                self.elements.get(i),
                their_elements.get(j),
                their_elements.get(j).and_then(|(v, _, _)| others.get(*v)),
            ) else {
                continue;
            };
            let gap = vertical_gap(mine.band, theirs.band);
            if gap >= separation.vertical_m {
                continue;
            }
            let Some((distance_m, at)) = approach(mine, theirs, reach, &mut scratch) else {
                continue;
            };
            let side = |vehicle: &str, e: &FlownElement| Side {
                vehicle: vehicle.to_owned(),
                element: e.part,
                altitudes_m: e.band,
            };
            found.push((
                (v, i, k),
                Conflict {
                    own: side(&self.vehicle, mine),
                    other: side(&other.vehicle, theirs),
                    distance_m,
                    margin_m: separation.horizontal_m - distance_m,
                    vertical_gap_m: gap,
                    position: earth::Position::lat_lon_deg(at),
                    separation,
                },
            ));
        }
        found.sort_by_key(|(order, _)| *order);
        Ok(found.into_iter().map(|(_, c)| c).collect())
    }
}

/// Every pair (index into `a`, index into `b`) of boxes no farther apart than `reach` along
/// any axis: a sweep along the axis where the boxes' centres spread most. Both lists are
/// sorted by the boxes' lower ends there; a box stays active while the others' lower ends
/// are within `reach` of its upper end, and each box is tested against the other list's
/// active ones, so every pair that overlaps along that axis is tested once and no other is.
fn overlapping(a: &[Bounds], b: &[Bounds], reach: f64) -> Vec<(usize, usize)> {
    let axis = (0..3)
        .map(|axis| {
            let centres = a.iter().chain(b).map(|x| {
                let (lo, hi) = x.span(axis);
                (lo + hi) / 2.0
            });
            let (lo, hi) = band(centres);
            (hi - lo, axis)
        })
        .fold(
            (f64::NEG_INFINITY, 0),
            |best, x| if x.0 > best.0 { x } else { best },
        )
        .1;
    let sorted = |list: &[Bounds]| {
        let mut s: Vec<(f64, f64, usize)> = list
            .iter()
            .enumerate()
            .map(|(i, x)| {
                let (lo, hi) = x.span(axis);
                (lo, hi, i)
            })
            .collect();
        s.sort_by(|x, y| x.0.total_cmp(&y.0));
        s
    };
    let (mut next_a, mut next_b) = (
        sorted(a).into_iter().peekable(),
        sorted(b).into_iter().peekable(),
    );
    // The boxes still active on each side: their upper end and index.
    let mut active_a: Vec<(f64, usize)> = Vec::new();
    let mut active_b: Vec<(f64, usize)> = Vec::new();
    let near = |i: usize, j: usize| match (a.get(i), b.get(j)) {
        (Some(x), Some(y)) => x.gap(y) <= reach,
        _ => false,
    };
    let mut pairs = Vec::new();
    loop {
        let from_a = match (next_a.peek(), next_b.peek()) {
            (Some(x), Some(y)) => x.0 <= y.0,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => break,
        };
        if from_a {
            let Some((lo, hi, i)) = next_a.next() else {
                break;
            };
            active_b.retain(|(end, _)| *end + reach >= lo);
            pairs.extend(
                active_b
                    .iter()
                    .filter(|(_, j)| near(i, *j))
                    .map(|(_, j)| (i, *j)),
            );
            active_a.push((hi, i));
        } else {
            let Some((lo, hi, j)) = next_b.next() else {
                break;
            };
            active_a.retain(|(end, _)| *end + reach >= lo);
            pairs.extend(
                active_a
                    .iter()
                    .filter(|(_, i)| near(*i, j))
                    .map(|(_, i)| (*i, j)),
            );
            active_b.push((hi, j));
        }
    }
    pairs
}

/// Chords per run: a patch's chords are measured against another patch's only where the
/// boxes of their runs come within reach, closest runs first.
const RUN: usize = 8;

/// A run of consecutive chords of a patch (`first..last`) and the box of their corners in a
/// plane.
#[derive(Debug, Clone, Copy)]
struct Run {
    first: usize,
    last: usize,
    lo: Coord,
    hi: Coord,
}

impl Run {
    /// The distance between the boxes of two runs: no chord of the one comes closer to a chord
    /// of the other.
    fn gap(&self, other: &Run) -> f64 {
        let dx = (self.lo.x - other.hi.x)
            .max(other.lo.x - self.hi.x)
            .max(0.0);
        let dy = (self.lo.y - other.hi.y)
            .max(other.lo.y - self.hi.y)
            .max(0.0);
        // Not `hypot`: libm's exact rounding costs more than the rest of the test, and
        // these are metres, far from overflow.
        (dx * dx + dy * dy).sqrt()
    }
}

/// The runs of the chords between `corners` into `out` (a single corner, a point: one run of
/// its one chord of length 0).
fn runs(corners: &[Coord], out: &mut Vec<Run>) {
    out.clear();
    let chords = match corners.len() {
        0 => 0,
        1 => 1,
        n => n - 1,
    };
    let mut first = 0;
    while first < chords {
        let last = (first + RUN).min(chords);
        let span = corners
            .get(first..=last.min(corners.len().saturating_sub(1)))
            .unwrap_or_default();
        let (lo, hi) = span.iter().fold(
            (
                Coord {
                    x: f64::INFINITY,
                    y: f64::INFINITY,
                },
                Coord {
                    x: f64::NEG_INFINITY,
                    y: f64::NEG_INFINITY,
                },
            ),
            |(lo, hi), c| {
                (
                    Coord {
                        x: lo.x.min(c.x),
                        y: lo.y.min(c.y),
                    },
                    Coord {
                        x: hi.x.max(c.x),
                        y: hi.y.max(c.y),
                    },
                )
            },
        );
        out.push(Run {
            first,
            last,
            lo,
            hi,
        });
        first = last;
    }
}

/// Chord `k` of `corners`: from corner `k` to `k + 1`; of a single corner, the corner twice.
fn chord(corners: &[Coord], k: usize) -> Option<(Coord, Coord)> {
    match corners {
        [p] if k == 0 => Some((*p, *p)),
        _ => Some((*corners.get(k)?, *corners.get(k + 1)?)),
    }
}

/// What [`approach`] reuses from one call to the next: the other patch's corners projected,
/// their runs, the pairs of runs within reach.
#[derive(Debug, Default)]
struct Scratch {
    corners: Vec<Coord>,
    runs: Vec<Run>,
    pairs: Vec<(f64, usize, usize)>,
}

/// The closest approach of `a`'s paths to `b`'s if closer than `horizon_m`: the distance
/// (never more than the true one: less the sag of each arc) and where it is on `a`. Each pair
/// of patches is measured in `a`'s patch's plane, `b`'s corners projected into it.
fn approach(
    a: &FlownElement,
    b: &FlownElement,
    horizon_m: f64,
    scratch: &mut Scratch,
) -> Option<(f64, Site)> {
    // (distance, patch of `a`, point in its plane).
    let mut best: Option<(f64, &Patch, Coord)> = None;
    for pa in &a.patches {
        for pb in &b.patches {
            let sags = pa.sag_m + pb.sag_m;
            let reach = |best: &Option<(f64, &Patch, Coord)>| {
                best.map_or(horizon_m, |b| b.0.min(horizon_m)) + sags
            };
            if pa.bounds.gap(&pb.bounds) > reach(&best) {
                continue;
            }
            scratch.corners.clear();
            scratch
                .corners
                .extend(pb.ecef.iter().map(|p| pa.plane.project(p)));
            runs(&scratch.corners, &mut scratch.runs);
            scratch.pairs.clear();
            let within = reach(&best);
            for (i, ra) in pa.runs.iter().enumerate() {
                for (j, rb) in scratch.runs.iter().enumerate() {
                    let gap = ra.gap(rb);
                    if gap <= within {
                        scratch.pairs.push((gap, i, j));
                    }
                }
            }
            scratch.pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
            for &(gap, i, j) in &scratch.pairs {
                if gap > reach(&best) {
                    break;
                }
                let (Some(ra), Some(rb)) = (pa.runs.get(i), scratch.runs.get(j)) else {
                    continue;
                };
                for (p, q) in (ra.first..ra.last).filter_map(|k| chord(&pa.corners, k)) {
                    for (r, s) in (rb.first..rb.last).filter_map(|l| chord(&scratch.corners, l)) {
                        // A chord whose box is farther from the other's box than the reach
                        // cannot come closer.
                        let d = reach(&best);
                        if p.x.min(q.x) > r.x.max(s.x) + d
                            || p.x.max(q.x) < r.x.min(s.x) - d
                            || p.y.min(q.y) > r.y.max(s.y) + d
                            || p.y.max(q.y) < r.y.min(s.y) - d
                        {
                            continue;
                        }
                        let meet = segment_segment(p, q, r, s);
                        let distance = (meet.distance - sags).max(0.0);
                        if distance < horizon_m && best.is_none_or(|b| distance < b.0) {
                            best = Some((distance, pa, p + (q - p) * meet.t));
                        }
                    }
                }
            }
        }
    }
    let (distance, patch, at) = best?;
    Some((distance, patch.plane.lift(at).unwrap_or(patch.first)))
}

#[cfg(test)]
mod tests;
