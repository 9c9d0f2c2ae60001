//! The route as it is flown: its waypoints read through a [`RouteView`] and walked leg by leg
//! and turn by turn, in the direction flown, as guidance flies them ([`super::turn`] at each
//! waypoint, sized for the plan's wind by [`FlyBy`]): for execute from the take-off point, for
//! return to home from wherever the aircraft is, and the turns round. The onboard check
//! ([`super::onboard`]), the safety gateway and the map walk these same paths, so what is checked
//! is what is flown.
//!
//! The route is read through a [`RouteView`]: the waypoints in flight-plan order (anything that
//! is a [`RouteWaypoint`]), the route properties and the take-off height, borrowed. The FCC's
//! published list (`WaypointListPayload`) and the ground's validated plan
//! ([`crate::transfer::mission::Mission`]) both give one without copying. No allocation; at most
//! 2 + 256 legs and 3 paths per turn.

use missionlink_interfaces::contracts::{WaypointEntry, WaypointListPayload};
use missionlink_interfaces::wire::{
    Altitude, GeoPoint, LegType, SpecificData, Speed, TurnDirection, TurnType,
};

use crate::transfer::mission::{Mission, WaypointRecord};

use super::earth::Site;
use super::path::{ArcLeg, Path};
use super::turn::{Turn, TurnKind, turn};

/// What a path of the route is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RouteElement {
    /// The vertical climb at the take-off point.
    Climb,
    /// A leg flown from `from` to `to` (`from` 0: from the take-off point or the aircraft).
    Leg {
        /// FROM Waypoint Number (0: from where the aircraft is).
        from: u16,
        /// TO Waypoint Number.
        to: u16,
    },
    /// A leg of the reverse route (return to home), flown from `from` to `to`.
    ReverseLeg {
        /// FROM Waypoint Number.
        from: u16,
        /// TO Waypoint Number.
        to: u16,
    },
    /// A path of the turn at waypoint `at` onto the leg to `to` ([`super::turn`]).
    Turn {
        /// The waypoint turned at.
        at: u16,
        /// The TO waypoint of the leg turned onto.
        to: u16,
        /// How the turn is flown.
        kind: TurnKind,
    },
}

impl core::fmt::Display for RouteElement {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Climb => f.write_str("climb at the take-off point"),
            Self::Leg { from: 0, to } => write!(f, "leg to waypoint {to} from the take-off point"),
            Self::Leg { from, to } => write!(f, "leg {from}->{to}"),
            Self::ReverseLeg { from, to } => write!(f, "reverse leg {from}->{to}"),
            Self::Turn {
                at,
                to,
                kind: TurnKind::FlyBy,
            } => write!(f, "fly-by turn at waypoint {at} onto the leg to {to}"),
            Self::Turn {
                at,
                to,
                kind: TurnKind::FlyOver,
            } => write!(
                f,
                "fly-over turn at waypoint {at} intercepting the leg to {to}"
            ),
            Self::Turn { at, to, .. } => write!(f, "turn at waypoint {at} onto the leg to {to}"),
        }
    }
}

/// What the route's paths need of a waypoint: the FCC's [`WaypointEntry`] and the ground's
/// [`WaypointRecord`] answer from the fields they hold.
pub trait RouteWaypoint {
    /// Waypoint Number.
    fn number(&self) -> u16;
    /// Where it is.
    fn position(&self) -> GeoPoint;
    /// The commanded altitude.
    fn altitude(&self) -> Altitude;
    /// The commanded speed towards it.
    fn speed(&self) -> Speed;
    /// Turn Type (`None` only for a corrupted byte of a payload).
    fn turn_type(&self) -> Option<TurnType>;
    /// Leg type of the leg that ends here (`None` only for a corrupted byte of a payload).
    fn leg_type(&self) -> Option<LegType>;
    /// Centre and turn direction of a radius-to-fix leg ending here.
    fn rf_centre(&self) -> Option<(GeoPoint, TurnDirection)>;
}

impl RouteWaypoint for WaypointEntry {
    fn number(&self) -> u16 {
        self.number
    }
    fn position(&self) -> GeoPoint {
        self.position
    }
    fn altitude(&self) -> Altitude {
        self.altitude
    }
    fn speed(&self) -> Speed {
        self.speed
    }
    fn turn_type(&self) -> Option<TurnType> {
        WaypointEntry::turn_type(self)
    }
    fn leg_type(&self) -> Option<LegType> {
        WaypointEntry::leg_type(self)
    }
    fn rf_centre(&self) -> Option<(GeoPoint, TurnDirection)> {
        WaypointEntry::rf_centre(self)
    }
}

impl RouteWaypoint for WaypointRecord {
    fn number(&self) -> u16 {
        self.waypoint.waypoint_number
    }
    fn position(&self) -> GeoPoint {
        GeoPoint {
            latitude: self.waypoint.latitude,
            longitude: self.waypoint.longitude,
        }
    }
    fn altitude(&self) -> Altitude {
        self.waypoint.altitude
    }
    fn speed(&self) -> Speed {
        self.waypoint.speed
    }
    fn turn_type(&self) -> Option<TurnType> {
        Some(self.waypoint.turn_type)
    }
    fn leg_type(&self) -> Option<LegType> {
        Some(self.waypoint.leg_type)
    }
    fn rf_centre(&self) -> Option<(GeoPoint, TurnDirection)> {
        match self.rf_centre.map(|c| c.data) {
            Some(SpecificData::RfCentre {
                latitude,
                longitude,
                turn_direction,
                ..
            }) => Some((
                GeoPoint {
                    latitude,
                    longitude,
                },
                turn_direction,
            )),
            _ => None,
        }
    }
}

/// A route as the geofence reads it, borrowed: the waypoints in flight-plan order, the route
/// properties and the take-off height. `From` the FCC's published list and the ground's
/// validated plan; copying it copies three words.
#[derive(Debug)]
pub struct RouteView<'a, W> {
    /// The waypoints in flight-plan order, from the initial waypoint.
    pub waypoints: &'a [W],
    /// The route may be flown back (return to home).
    pub bidirectional: bool,
    /// The take-off height above ground.
    pub take_off_height: Altitude,
    /// The wind speed every turn is sized for (the plan's #13001 field 5, m/s; 0 calm): see
    /// [`FlyBy`].
    pub wind_mps: f64,
}

// Copy whatever the waypoint type: the view holds a reference (a derive would ask `W: Copy`).
impl<W> Clone for RouteView<'_, W> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<W> Copy for RouteView<'_, W> {}

impl<'a> From<&'a WaypointListPayload> for RouteView<'a, WaypointEntry> {
    fn from(list: &'a WaypointListPayload) -> Self {
        Self {
            waypoints: list.waypoints(),
            bidirectional: list.bidirectional,
            take_off_height: list.take_off_height,
            wind_mps: list.planning_wind.mps(),
        }
    }
}

impl<'a> From<&'a Mission> for RouteView<'a, WaypointRecord> {
    fn from(mission: &'a Mission) -> Self {
        Self {
            waypoints: &mission.waypoints,
            bidirectional: mission.route.bidirectional,
            take_off_height: mission.take_off_height(),
            wind_mps: mission.route.planning_wind.map_or(0.0, |w| w.mps()),
        }
    }
}

/// One path of the route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteLeg {
    /// What it is.
    pub element: RouteElement,
    /// Where it goes.
    pub path: Path,
}

fn site(w: &impl RouteWaypoint) -> Site {
    Site::of(w.position())
}

/// The leg flown from `from` to `to` by `to`'s leg type (a radius-to-fix leg as its arc).
pub fn leg<W: RouteWaypoint>(from: &W, to: &W) -> Path {
    match (to.leg_type(), to.rf_centre()) {
        (Some(LegType::RadiusToFix), Some((centre, direction))) => Path::Arc(ArcLeg {
            from: site(from),
            to: site(to),
            centre: Site::of(centre),
            direction,
        }),
        _ => Path::Geodesic {
            from: site(from),
            to: site(to),
        },
    }
}

/// The legs between consecutive waypoints, in flight-plan order.
pub fn legs<W: RouteWaypoint>(route: RouteView<'_, W>) -> impl Iterator<Item = RouteLeg> + '_ {
    route.waypoints.windows(2).filter_map(|w| match w {
        [a, b] => Some(RouteLeg {
            element: RouteElement::Leg {
                from: a.number(),
                to: b.number(),
            },
            path: leg(a, b),
        }),
        _ => None,
    })
}

/// The legs of the reverse route back from the last of `waypoints` to the first.
fn back_over<W: RouteWaypoint>(waypoints: &[W]) -> impl Iterator<Item = RouteLeg> + '_ {
    waypoints.windows(2).rev().filter_map(|w| match w {
        [a, b] => Some(RouteLeg {
            element: RouteElement::ReverseLeg {
                from: b.number(),
                to: a.number(),
            },
            path: leg(a, b).reversed(),
        }),
        _ => None,
    })
}

/// The paths of `turn` at `at` onto the leg to `to`.
fn turn_legs(at: u16, to: u16, turn: Turn) -> impl Iterator<Item = RouteLeg> {
    let kind = turn.kind;
    turn.paths.into_iter().map(move |path| RouteLeg {
        element: RouteElement::Turn { at, to, kind },
        path,
    })
}

/// The way from `start` to the initial waypoint: the geodesic.
fn first_leg<W: RouteWaypoint>(route: RouteView<'_, W>, start: Site) -> Option<(&W, Path)> {
    route.waypoints.first().map(|w| {
        (
            w,
            Path::Geodesic {
                from: start,
                to: site(w),
            },
        )
    })
}

/// What execute flies from `take_off`: the climb there, the way to the initial waypoint, every
/// leg, and with `fly_by` every turn at a waypoint as flown.
pub fn execute_route<W: RouteWaypoint>(
    route: RouteView<'_, W>,
    take_off: Site,
    fly_by: Option<FlyBy>,
) -> impl Iterator<Item = RouteLeg> + '_ {
    let first = first_leg(route, take_off);
    let climb = RouteLeg {
        element: RouteElement::Climb,
        path: Path::Point(take_off),
    };
    let (waypoints, wind) = (route.waypoints, route.wind_mps);
    let turns = fly_by.into_iter().flat_map(move |f| {
        waypoints.iter().enumerate().flat_map(move |(k, w)| {
            let next = waypoints.get(k + 1);
            let inbound = match k.checked_sub(1).and_then(|i| waypoints.get(i)) {
                Some(before) => Some(leg(before, w)),
                None => first.map(|(_, p)| p),
            };
            let t = match (inbound, next) {
                (Some(inbound), Some(next)) => Some((
                    next.number(),
                    f.turn(w, next, &inbound, &leg(w, next), wind),
                )),
                _ => None,
            };
            t.into_iter()
                .flat_map(move |(to, t)| turn_legs(w.number(), to, t))
        })
    });
    core::iter::once(climb)
        .chain(first.map(|(w, path)| RouteLeg {
            element: RouteElement::Leg {
                from: 0,
                to: w.number(),
            },
            path,
        }))
        .chain(legs(route))
        .chain(turns)
}

/// The way from `position` to the waypoint at `index` as guidance flies it on: on its leg
/// (`on_leg`, the waypoint is the TO waypoint) the rest of a radius-to-fix arc, else the
/// geodesic.
fn direct<W: RouteWaypoint>(
    waypoints: &[W],
    index: usize,
    position: Site,
    on_leg: bool,
) -> Option<Path> {
    let w = waypoints.get(index)?;
    let before = index
        .checked_sub(1)
        .and_then(|i| waypoints.get(i))
        .filter(|_| on_leg);
    Some(match before.map(|b| leg(b, w)) {
        Some(Path::Arc(ArcLeg {
            to,
            centre,
            direction,
            ..
        })) => Path::Arc(ArcLeg {
            from: position,
            to,
            centre,
            direction,
        }),
        _ => Path::Geodesic {
            from: position,
            to: site(w),
        },
    })
}

/// What return to home flies from `position` with `to` the TO waypoint (0: the route is
/// complete, the way back starts at the last waypoint): on to that waypoint, then the reverse
/// route from there to the initial waypoint (guidance's return to home), with `fly_by` every
/// turn as flown: the turn onto the leg to the TO waypoint (the aircraft may still be on it,
/// and flies the rest), the turn round at the TO waypoint and the turns on the way back.
pub fn return_route<W: RouteWaypoint>(
    route: RouteView<'_, W>,
    position: Site,
    to: u16,
    fly_by: Option<FlyBy>,
) -> impl Iterator<Item = RouteLeg> + '_ {
    let (waypoints, wind) = (route.waypoints, route.wind_mps);
    let index = waypoints
        .iter()
        .position(|w| w.number() == to)
        .unwrap_or(waypoints.len().saturating_sub(1));
    let direct = direct(waypoints, index, position, to != 0);
    let first = waypoints.get(index).zip(direct).map(|(w, path)| RouteLeg {
        element: RouteElement::Leg {
            from: 0,
            to: w.number(),
        },
        path,
    });
    let back = waypoints.get(..=index).unwrap_or_default();
    let turns = fly_by.into_iter().flat_map(move |f| {
        (1..=index).rev().flat_map(move |i| {
            let (Some(w), Some(next)) = (back.get(i), back.get(i - 1)) else {
                return None.into_iter().flatten();
            };
            // The turn round at the TO waypoint: from the leg the aircraft is on (guidance turns
            // from the leg it flies, whatever the way from here to its end).
            let inbound = if i == index {
                match (to != 0, back.get(i - 1)) {
                    (true, Some(before)) => Some(leg(before, w)),
                    _ => direct,
                }
            } else {
                back.get(i + 1).map(|after| leg(w, after).reversed())
            };
            let t = inbound.map(|inbound| {
                turn_legs(
                    w.number(),
                    next.number(),
                    f.turn(w, next, &inbound, &leg(next, w).reversed(), wind),
                )
            });
            t.into_iter().flatten()
        })
    });
    // The turn onto the leg the aircraft is on (from a leg between waypoints: the turn at the
    // initial waypoint depends on where the aircraft took off, and was checked from there).
    let current = fly_by
        .filter(|_| to != 0 && index >= 2)
        .and_then(|f| {
            let (before, at, w) = (back.get(index - 2)?, back.get(index - 1)?, back.get(index)?);
            Some(turn_legs(
                at.number(),
                w.number(),
                f.turn(at, w, &leg(before, at), &leg(at, w), wind),
            ))
        })
        .into_iter()
        .flatten();
    first
        .into_iter()
        .chain(current)
        .chain(back_over(back))
        .chain(turns)
}

/// The turns round of a return to home commanded on any leg of a bidirectional route: at
/// each waypoint but the initial one, from the leg into it onto the same leg backwards.
pub fn turns_round<W: RouteWaypoint>(
    route: RouteView<'_, W>,
    fly_by: FlyBy,
) -> impl Iterator<Item = RouteLeg> + '_ {
    route.waypoints.windows(2).flat_map(move |w| {
        let t = match w {
            [a, b] => {
                let inbound = leg(a, b);
                Some((
                    b.number(),
                    a.number(),
                    fly_by.turn(b, a, &inbound, &inbound.reversed(), route.wind_mps),
                ))
            }
            _ => None,
        };
        t.into_iter().flat_map(|(at, to, t)| turn_legs(at, to, t))
    })
}

/// How guidance turns at a waypoint ([`super::turn`]): at the radius the wind forces on a
/// bank-limited aircraft, fly-by or fly-over by the waypoint's turn type.
///
/// # Turns in wind (ICD §7 "Turns in wind")
///
/// Guidance flies every turn as a path over the ground (ARINC 424 fly-by and RF legs are
/// ground paths too): the arc, the intercept and the arc of [`super::turn`], at the radius
///
/// `r = (v + W)² / (g·tan(bank))`
///
/// with `v` the airspeed flown in the turn (the next waypoint's speed: guidance flies towards it
/// from the turn's start) and `W` the wind speed the plan was checked in ([`RouteView::wind_mps`],
/// #13001 field 5). This is the radius PANS-OPS (ICAO Doc 8168) protects a turn with: true
/// airspeed plus the wind speed, at the bank limit. It is the smallest ground radius a
/// bank-limited aircraft can hold **whatever the wind's direction**: holding a ground circle of
/// radius `R` at airspeed `v` in a steady wind `w` (|w| = W < v) takes a horizontal
/// acceleration `a = V_g² / (R·cos β)` perpendicular to the air velocity (`V_g` the ground speed,
/// `β` the drift angle), and with `c` the cosine of the angle between air velocity and wind,
/// `V_g² / cos β = (v² + W² + 2vWc)^{3/2} / (v + Wc)`, which grows with `c` over all of
/// `[−1, 1]` (its logarithmic derivative is positive iff `2v² + vWc − W² > 0`, true for
/// `W < v`): its largest value, at a tailwind, is `(v + W)²`. So `g·tan(bank) ≥ a` everywhere on
/// the circle, in every direction of the wind up to `W`; the bank needed peaks at the limit only
/// where the wind is straight behind. The direction is not needed, and is not assumed: a
/// forecast's direction is the least certain part of it.
///
/// Because guidance holds this path over the ground, the path flown is the one path checked, not
/// a band of drifted paths: a constant-bank turn would drift onto a trochoid that never meets
/// the next leg tangentially, and where it rejoins the leg would depend on the controller's
/// recovery, which no check could bound without modelling it. In calm air (`W = 0`) the radius is
/// `v²/(g·tan(bank))`, the turn of ICD edition 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlyBy {
    /// Guidance's bank angle limit in the turn, degrees (0 < bank < 90).
    pub bank_deg: f64,
}

/// Standard gravity, m/s².
const GRAVITY_MPS2: f64 = 9.806_65;
/// The speed guidance flies towards a waypoint whose speed is 0, m/s.
pub const FALLBACK_SPEED_MPS: f64 = 10.0;

impl FlyBy {
    /// The speed guidance flies towards `w`: its commanded speed, or [`FALLBACK_SPEED_MPS`].
    pub fn speed_mps(w: &impl RouteWaypoint) -> f64 {
        match w.speed().mps() {
            v if v > 0.0 => v,
            _ => FALLBACK_SPEED_MPS,
        }
    }

    /// Radius of a turn at ground speed `v` and the bank: `v²/(g·tan(bank))`, metres.
    pub fn turn_radius_m(&self, v: f64) -> f64 {
        v * v / (GRAVITY_MPS2 * self.bank_deg.to_radians().tan())
    }

    /// The bank that holds a ground path curving at radius `radius_m` at ground speed
    /// `ground_mps` with the drift angle `drift_deg` between the air velocity and the ground
    /// track: `atan(V_g² / (g·R·cos β))` (the relation of the type's documentation; in calm air
    /// `atan(v²/(g·R))`, the inverse of [`Self::turn_radius_m`]), degrees in 0..=90. 0 for a
    /// radius that is not above 0 (turning on the spot is no banked turn).
    pub fn bank_on_radius_deg(ground_mps: f64, radius_m: f64, drift_deg: f64) -> f64 {
        if radius_m.is_nan() || radius_m <= 0.0 {
            return 0.0;
        }
        let acceleration = ground_mps * ground_mps / (radius_m * drift_deg.to_radians().cos());
        // A drift of 90 deg (a crosswind stronger than the airspeed) divides by 0: infinite,
        // which atan takes to 90 deg; NaN (a speed that is not a number) reads as no bank.
        let bank = (acceleration.abs() / GRAVITY_MPS2).atan().to_degrees();
        if bank.is_nan() { 0.0 } else { bank }
    }

    /// Radius of the turn flown at airspeed `v` in a wind of `wind_mps` from any direction:
    /// `(v + W)²/(g·tan(bank))`, metres (see the type's documentation).
    pub fn radius_in_wind_m(&self, v: f64, wind_mps: f64) -> f64 {
        let wind = if wind_mps.is_finite() {
            wind_mps.max(0.0)
        } else {
            0.0
        };
        self.turn_radius_m(v + wind)
    }

    /// The turn at `w` from `inbound` (ending at `w`) onto `outbound` (starting there, to
    /// `next`), sized for a wind of `wind_mps`.
    pub fn turn<W: RouteWaypoint>(
        &self,
        w: &W,
        next: &W,
        inbound: &Path,
        outbound: &Path,
        wind_mps: f64,
    ) -> Turn {
        turn(
            inbound,
            outbound,
            w.turn_type() == Some(TurnType::FlyOver),
            self.radius_in_wind_m(Self::speed_mps(next), wind_mps),
        )
    }
}
