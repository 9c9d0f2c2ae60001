//! The turn at a waypoint as guidance flies it and the geofence checks it (ICD §7 "the legs
//! as flown"): what joins the leg into a waypoint to the leg out of it. Guidance
//! (`missionlink_flight::guidance`) flies exactly these paths, the onboard check and the safety gateway
//! check exactly these paths: there is one construction, [`turn`].
//!
//! - **Fly-by** (ARINC 424 fly-by): the arc of radius `r` (`v²/(g·tan(bank))` in calm air, sized
//!   for the wind by [`super::flown_route::FlyBy`]) tangent to both
//!   legs, inside the corner; it leaves the inbound leg at its first tangent point (where
//!   FROM-TO-NEXT switches) and joins the outbound leg at the second. Between two track-to-fix
//!   legs turning `Δψ` the tangent points are `r·tan(Δψ/2)` from the waypoint along the legs; a
//!   radius-to-fix leg is met on its own circle (the tangent circle of the arc). A turn of less
//!   than [`STRAIGHT_DEG`] is no turn.
//! - **Legs too short for the arc**: a turn uses at most half of each leg next to it (so that
//!   the turns at both ends of a leg never overlap). A fly-by arc whose tangent point lies
//!   farther from the waypoint than that (a sharp turn between short legs, and always a U-turn,
//!   whose arc does not exist) is flown as a fly-over.
//! - **Fly-over**: over the waypoint, then the turn of radius `r` tangent to the inbound leg at
//!   the waypoint, through the course change and on to an intercept angle
//!   `χ = min(45°, acos(cos²(Δψ/2)))` towards the outbound leg (45° unless the turn is too
//!   small to come back at that angle), straight on that course, and the turn of radius `r`
//!   the other way onto the outbound leg (tangent to it): an intercept of the outbound leg
//!   itself, not a direct-to its waypoint. Where that intercept does not meet the outbound leg
//!   (a radius-to-fix leg curving away from it), the first turn goes straight into the reverse
//!   turn onto the leg: two arcs of radius `r`, the second tangent to the first and to the leg.
//! - **No room for the intercept** (its join farther along the outbound leg than half of it):
//!   the aircraft turns on the spot at the waypoint (the demo aircraft is a multicopter) and
//!   flies the outbound leg from there; the legs in full are checked anyway (see
//!   [`super::onboard`]).
//!
//! The construction is done in the azimuthal equidistant projection at the waypoint, where a
//! geodesic through the waypoint is exactly a straight line; every point it yields is put on
//! the ellipsoid along the geodesic from the waypoint (or, on a radius-to-fix leg, from the
//! leg's centre at the leg's own radius), and every path is a [`Path`] of the geofence: a
//! geodesic, or an arc around a centre (its radius going linearly with the angle, as all arcs
//! of the geofence). The construction's own error (a tangency off by micro-radians, an arc
//! radius off by micrometres at a kilometre from the waypoint) changes no path: guidance flies
//! the paths the construction gives, and the geofence checks those.

use geo::Coord;
use heapless::Vec;
use missionlink_interfaces::wire::TurnDirection;

use super::earth::Site;
use super::path::{ArcLeg, Path};

/// Paths of one turn at most (fly-over: turn, intercept, turn).
pub const MAX_TURN_PATHS: usize = 3;
/// A course change smaller than this is no turn, degrees.
pub const STRAIGHT_DEG: f64 = 0.01;
/// The intercept angle of a fly-over, degrees (smaller for small turns, see the module doc).
pub const INTERCEPT_DEG: f64 = 45.0;
/// Straight intercepts shorter than this are left out (the two turns meet), metres.
const MIN_STRAIGHT_M: f64 = 0.001;
/// Legs shorter than this have no direction: no turn at their end, metres.
const MIN_LEG_M: f64 = 0.01;

/// How a turn is flown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TurnKind {
    /// No turn (straight on, or a leg without direction): the legs meet at the waypoint.
    Straight,
    /// On the arc tangent to both legs.
    FlyBy,
    /// Over the waypoint, then turn, intercept, turn onto the outbound leg.
    FlyOver,
    /// Over the waypoint and round on the spot onto the outbound leg (no room to intercept).
    OnTheSpot,
}

/// A turn at a waypoint.
#[derive(Debug, Clone, PartialEq)]
pub struct Turn {
    /// How it is flown.
    pub kind: TurnKind,
    /// Where the inbound leg is left: the fly-by arc's start, else the waypoint.
    pub leave: Site,
    /// Where the outbound leg is joined: the fly-by arc's end, the end of the fly-over's
    /// intercept, else the waypoint.
    pub join: Site,
    /// The paths flown from `leave` to `join`, in order.
    pub paths: Vec<Path, MAX_TURN_PATHS>,
}

/// Azimuth from `centre` to `at` growing (clockwise) or not, degrees to go from `from` to `to`.
pub fn angle_to_go(from_deg: f64, to_deg: f64, clockwise: bool) -> f64 {
    if clockwise {
        (to_deg - from_deg).rem_euclid(360.0)
    } else {
        (from_deg - to_deg).rem_euclid(360.0)
    }
}

/// Signed difference `b − a` of two courses, in `[-180, 180)` degrees.
pub fn course_change(a: f64, b: f64) -> f64 {
    (b - a + 180.0).rem_euclid(360.0) - 180.0
}

/// The geometry of an arc path: centre, radii and azimuths (from the centre) of its ends, its
/// direction and sweep (degrees, positive).
#[derive(Debug, Clone, Copy)]
pub struct ArcGeometry {
    /// The centre.
    pub centre: Site,
    /// Clockwise (azimuth from the centre growing).
    pub clockwise: bool,
    /// Radius and azimuth at the start.
    pub r0: f64,
    /// Azimuth of the start from the centre, degrees.
    pub az0: f64,
    /// Radius at the end.
    pub r1: f64,
    /// Azimuth of the end from the centre, degrees.
    pub az1: f64,
    /// Degrees turned from start to end.
    pub sweep: f64,
}

impl ArcGeometry {
    /// The geometry of `from -> to` around `centre` in `direction`.
    pub fn of(from: &Site, to: &Site, centre: &Site, direction: TurnDirection) -> Self {
        let clockwise = direction == TurnDirection::Clockwise;
        let (r0, az0) = centre.inverse(from);
        let (r1, az1) = centre.inverse(to);
        Self {
            centre: *centre,
            clockwise,
            r0,
            az0,
            r1,
            az1,
            sweep: angle_to_go(az0, az1, clockwise),
        }
    }

    /// The radius at azimuth `az` (degrees turned from the start, linearly), metres.
    pub fn radius_at(&self, az: f64) -> f64 {
        if self.sweep <= 0.0 {
            return self.r1;
        }
        let f = (angle_to_go(self.az0, az, self.clockwise) / self.sweep).min(1.0);
        self.r0 + (self.r1 - self.r0) * f
    }

    /// The point of the arc at azimuth `az` from the centre.
    pub fn at(&self, az: f64) -> Site {
        self.centre.direct(az, self.radius_at(az))
    }

    /// Length along the arc, metres.
    pub fn length_m(&self) -> f64 {
        self.sweep.to_radians() * (self.r0 + self.r1) / 2.0
    }

    /// Course of flight on the arc at `at` (a point of it), degrees.
    pub fn course_at(&self, at: &Site) -> f64 {
        let (_, _, radial) = self.centre.inverse_azimuths(at);
        if self.clockwise {
            radial + 90.0
        } else {
            radial - 90.0
        }
    }
}

/// Length of a path, metres (0 for a point).
pub fn length_m(path: &Path) -> f64 {
    match path {
        Path::Point(_) => 0.0,
        Path::Geodesic { from, to } => from.inverse(to).0,
        Path::Arc(leg) => leg.geometry().length_m(),
    }
}

/// The rest of `path` from `at`, a point of it.
pub fn rest_from(path: &Path, at: Site) -> Path {
    match *path {
        Path::Point(p) => Path::Point(p),
        Path::Geodesic { to, .. } => Path::Geodesic { from: at, to },
        Path::Arc(leg) => Path::Arc(ArcLeg { from: at, ..leg }),
    }
}

/// The part of `path` up to `at`, a point of it.
pub fn up_to(path: &Path, at: Site) -> Path {
    match *path {
        Path::Point(p) => Path::Point(p),
        Path::Geodesic { from, .. } => Path::Geodesic { from, to: at },
        Path::Arc(leg) => Path::Arc(ArcLeg { to: at, ..leg }),
    }
}

/// Where `path` starts.
pub fn start(path: &Path) -> Site {
    match path {
        Path::Point(p) => *p,
        Path::Geodesic { from, .. } | Path::Arc(ArcLeg { from, .. }) => *from,
    }
}

/// Where `path` ends.
pub fn end(path: &Path) -> Site {
    match path {
        Path::Point(p) => *p,
        Path::Geodesic { to, .. } | Path::Arc(ArcLeg { to, .. }) => *to,
    }
}

/// The azimuthal equidistant projection at a site: x east, y north, metres.
#[derive(Debug, Clone, Copy)]
struct Aeqd {
    origin: Site,
}

impl Aeqd {
    fn xy(&self, s: &Site) -> Coord {
        let (d, az) = self.origin.inverse(s);
        let a = az.to_radians();
        Coord {
            x: d * a.sin(),
            y: d * a.cos(),
        }
    }

    fn site(&self, c: Coord) -> Site {
        let d = c.x.hypot(c.y);
        if d == 0.0 {
            return self.origin;
        }
        self.origin.direct(c.x.atan2(c.y).to_degrees(), d)
    }
}

fn unit(course_deg: f64) -> Coord {
    let a = course_deg.to_radians();
    Coord {
        x: a.sin(),
        y: a.cos(),
    }
}

fn dot(a: Coord, b: Coord) -> f64 {
    a.x * b.x + a.y * b.y
}

fn norm(a: Coord) -> f64 {
    a.x.hypot(a.y)
}

/// A leg near the waypoint in the projection: a line through `p` in direction `u` (unit), or a
/// circle around `c` of radius `r` flown clockwise or not.
#[derive(Debug, Clone, Copy)]
enum Local {
    Line { p: Coord, u: Coord },
    Circle { c: Coord, r: f64, clockwise: bool },
}

/// The curve at distance `d` on side `side` (+1 right of the direction of flight, −1 left):
/// a line `n·x = k` (n the unit normal to the right) or a circle.
#[derive(Debug, Clone, Copy)]
enum Offset {
    Line { n: Coord, k: f64 },
    Circle { c: Coord, r: f64 },
}

impl Local {
    fn offset(&self, side: f64, d: f64) -> Offset {
        match *self {
            Self::Line { p, u } => {
                let n = Coord { x: u.y, y: -u.x };
                Offset::Line {
                    n,
                    k: dot(n, p) + side * d,
                }
            }
            Self::Circle { c, r, clockwise } => {
                // Right of a clockwise circle is towards its centre.
                let towards = if clockwise { 1.0 } else { -1.0 };
                Offset::Circle {
                    c,
                    r: r - side * towards * d,
                }
            }
        }
    }

    /// The point of the curve closest to `f`.
    fn foot(&self, f: Coord) -> Option<Coord> {
        match *self {
            Self::Line { p, u } => Some(p + u * dot(u, f - p)),
            Self::Circle { c, r, .. } => {
                let d = norm(f - c);
                (d > 0.0).then(|| c + (f - c) * (r / d))
            }
        }
    }
}

/// The intersections of two offset curves (at most two).
fn intersect(a: Offset, b: Offset) -> Vec<Coord, 2> {
    let mut out = Vec::new();
    match (a, b) {
        (Offset::Line { n: n1, k: k1 }, Offset::Line { n: n2, k: k2 }) => {
            let det = n1.x * n2.y - n1.y * n2.x;
            if det.abs() > 1e-12 {
                let _ = out.push(Coord {
                    x: (k1 * n2.y - k2 * n1.y) / det,
                    y: (n1.x * k2 - n2.x * k1) / det,
                });
            }
        }
        (Offset::Line { n, k }, Offset::Circle { c, r })
        | (Offset::Circle { c, r }, Offset::Line { n, k }) => {
            // The foot of the centre on the line, then ± along it.
            let foot = c + n * (k - dot(n, c));
            let h = norm(foot - c);
            if r > 0.0 && h <= r {
                let t = (r * r - h * h).sqrt();
                let along = Coord { x: -n.y, y: n.x };
                let _ = out.push(foot + along * t);
                let _ = out.push(foot - along * t);
            }
        }
        (Offset::Circle { c: c1, r: r1 }, Offset::Circle { c: c2, r: r2 }) => {
            let d = norm(c2 - c1);
            if r1 > 0.0 && r2 > 0.0 && d > 0.0 && d <= r1 + r2 && d >= (r1 - r2).abs() {
                let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
                let h = (r1 * r1 - a * a).max(0.0).sqrt();
                let e = (c2 - c1) / d;
                let m = c1 + e * a;
                let perp = Coord { x: -e.y, y: e.x };
                let _ = out.push(m + perp * h);
                let _ = out.push(m - perp * h);
            }
        }
    }
    out
}

/// A leg as the turn sees it: its path (ending or starting at the waypoint) and how much of it
/// the turn may use.
struct LegNear {
    path: Path,
    local: Local,
    /// Course of flight at the waypoint, degrees.
    course: f64,
    /// Metres of the leg the turn may use (half of it).
    room: f64,
}

impl LegNear {
    fn of(path: &Path, at: &Site, proj: &Aeqd, inbound: bool) -> Option<Self> {
        let (local, course, length) = match *path {
            Path::Point(_) => return None,
            Path::Geodesic { from, to } => {
                let (length, start, end) = from.inverse_azimuths(&to);
                let course = if inbound { end } else { start };
                (
                    Local::Line {
                        p: Coord { x: 0.0, y: 0.0 },
                        u: unit(course),
                    },
                    course,
                    length,
                )
            }
            Path::Arc(leg) => {
                let arc = leg.geometry();
                let r = leg.centre.inverse(at).0;
                (
                    Local::Circle {
                        c: proj.xy(&leg.centre),
                        r,
                        clockwise: arc.clockwise,
                    },
                    arc.course_at(at),
                    arc.length_m(),
                )
            }
        };
        if length < MIN_LEG_M || length.is_nan() {
            return None;
        }
        Some(Self {
            path: *path,
            local,
            course,
            room: length / 2.0,
        })
    }

    /// The site of the tangent point `t` (projected) on the leg, if within the turn's room
    /// before (`inbound`) or after the waypoint.
    fn site_of(&self, t: Coord, proj: &Aeqd, inbound: bool) -> Option<Site> {
        match (self.local, self.path) {
            (Local::Line { u, .. }, _) => {
                let along = dot(u, t);
                let distance = if inbound { -along } else { along };
                (distance >= 0.0 && distance <= self.room).then(|| {
                    let course = if inbound {
                        self.course + 180.0
                    } else {
                        self.course
                    };
                    proj.origin.direct(course, distance)
                })
            }
            (Local::Circle { .. }, Path::Arc(leg)) => {
                let arc = leg.geometry();
                let az = arc.centre.inverse(&proj.site(t)).1;
                let az_w = arc.centre.inverse(&proj.origin).1;
                let turned = if inbound {
                    angle_to_go(az, az_w, arc.clockwise)
                } else {
                    angle_to_go(az_w, az, arc.clockwise)
                };
                let r = arc.radius_at(az);
                (turned <= 180.0 && turned.to_radians() * r <= self.room).then(|| arc.at(az))
            }
            _ => None,
        }
    }
}

fn direction(clockwise: bool) -> TurnDirection {
    if clockwise {
        TurnDirection::Clockwise
    } else {
        TurnDirection::CounterClockwise
    }
}

/// The fillets of radius `r` on side `side` between `a` (flown first) and `b`: their centre
/// and their tangent points on `a` and on `b` (projected), nearest the origin first.
fn fillets(a: &Local, b: &Local, side: f64, r: f64) -> Vec<(Coord, Coord, Coord), 2> {
    let mut centres = intersect(a.offset(side, r), b.offset(side, r));
    if let [p, q] = centres.as_mut_slice()
        && norm(*q) < norm(*p)
    {
        core::mem::swap(p, q);
    }
    centres
        .into_iter()
        .filter_map(|f| Some((f, a.foot(f)?, b.foot(f)?)))
        .collect()
}

/// The turn at `at` from `inbound` (a leg ending there) to `outbound` (a leg starting there),
/// at turn radius `radius_m`, fly-over or fly-by (see the module documentation).
pub fn turn(inbound: &Path, outbound: &Path, fly_over: bool, radius_m: f64) -> Turn {
    let at = end(inbound);
    let straight = Turn {
        kind: TurnKind::Straight,
        leave: at,
        join: at,
        paths: Vec::new(),
    };
    let proj = Aeqd { origin: at };
    let (Some(a), Some(b)) = (
        LegNear::of(inbound, &at, &proj, true),
        LegNear::of(outbound, &at, &proj, false),
    ) else {
        return straight;
    };
    let delta = course_change(a.course, b.course);
    let usable_radius = radius_m > 0.0;
    if delta.abs() < STRAIGHT_DEG || !usable_radius || start(outbound) != at {
        return straight;
    }
    let side = if delta > 0.0 { 1.0 } else { -1.0 };
    if !fly_over && let Some(t) = fly_by(&a, &b, &proj, side, radius_m) {
        return t;
    }
    over(&a, &b, &proj, delta, side, radius_m).unwrap_or(Turn {
        kind: TurnKind::OnTheSpot,
        ..straight
    })
}

fn fly_by(a: &LegNear, b: &LegNear, proj: &Aeqd, side: f64, r: f64) -> Option<Turn> {
    fillets(&a.local, &b.local, side, r)
        .into_iter()
        .find_map(|(f, t1, t2)| {
            let leave = a.site_of(t1, proj, true)?;
            let join = b.site_of(t2, proj, false)?;
            let mut paths = Vec::new();
            let _ = paths.push(Path::Arc(ArcLeg {
                from: leave,
                to: join,
                centre: proj.site(f),
                direction: direction(side > 0.0),
            }));
            Some(Turn {
                kind: TurnKind::FlyBy,
                leave,
                join,
                paths,
            })
        })
}

fn over(a: &LegNear, b: &LegNear, proj: &Aeqd, delta: f64, side: f64, r: f64) -> Option<Turn> {
    let at = proj.origin;
    let half = (delta.abs() / 2.0).to_radians().cos();
    let chi = INTERCEPT_DEG.min((half * half).clamp(-1.0, 1.0).acos().to_degrees());
    // The first turn: tangent to the inbound course at the waypoint, through Δψ + χ.
    let centre = at.direct(a.course + side * 90.0, r);
    let az_w = centre.inverse(&at).1;
    let az_p = az_w + side * (delta.abs() + chi);
    let p1 = centre.direct(az_p, r);
    let course = a.course + side * (delta.abs() + chi);
    let (p, u) = (proj.xy(&p1), unit(course));
    let line = Local::Line { p, u };
    let intercept = fillets(&line, &b.local, -side, r)
        .into_iter()
        .find_map(|(f, t1, t2)| {
            let straight = dot(u, t1 - p);
            if straight < -MIN_STRAIGHT_M {
                return None;
            }
            let join = b.site_of(t2, proj, false)?;
            let mut paths = Vec::new();
            let _ = paths.push(Path::Arc(ArcLeg {
                from: at,
                to: p1,
                centre,
                direction: direction(side > 0.0),
            }));
            let intercept_end = if straight > MIN_STRAIGHT_M {
                let e = proj.site(t1);
                let _ = paths.push(Path::Geodesic { from: p1, to: e });
                e
            } else {
                p1
            };
            let _ = paths.push(Path::Arc(ArcLeg {
                from: intercept_end,
                to: join,
                centre: proj.site(f),
                direction: direction(side < 0.0),
            }));
            Some(Turn {
                kind: TurnKind::FlyOver,
                leave: at,
                join,
                paths,
            })
        });
    intercept.or_else(|| s_turn(b, proj, &centre, side, r))
}

/// The fly-over's turn at the waypoint (around `centre`) straight into the reverse turn onto
/// the outbound leg: the arc of radius `r` tangent to both, the first of the candidates
/// reached soonest on the first turn.
fn s_turn(b: &LegNear, proj: &Aeqd, centre: &Site, side: f64, r: f64) -> Option<Turn> {
    let at = proj.origin;
    let first = Local::Circle {
        c: proj.xy(centre),
        r,
        clockwise: side > 0.0,
    };
    let az_w = centre.inverse(&at).1;
    let mut best: Option<(f64, Turn)> = None;
    for (f, t1, t2) in fillets(&first, &b.local, -side, r) {
        let Some(join) = b.site_of(t2, proj, false) else {
            continue;
        };
        let t1 = proj.site(t1);
        let turned = angle_to_go(az_w, centre.inverse(&t1).1, side > 0.0);
        if best.as_ref().is_some_and(|(b, _)| *b <= turned) {
            continue;
        }
        let mut paths = Vec::new();
        let _ = paths.push(Path::Arc(ArcLeg {
            from: at,
            to: t1,
            centre: *centre,
            direction: direction(side > 0.0),
        }));
        let _ = paths.push(Path::Arc(ArcLeg {
            from: t1,
            to: join,
            centre: proj.site(f),
            direction: direction(side < 0.0),
        }));
        best = Some((
            turned,
            Turn {
                kind: TurnKind::FlyOver,
                leave: at,
                join,
                paths,
            },
        ));
    }
    best.map(|(_, t)| t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leg(from: Site, to: Site) -> Path {
        Path::Geodesic { from, to }
    }

    /// A 90° fly-by between two track-to-fix legs: tangent points `r·tan(45°) = r` from the
    /// waypoint, the centre `r·√2` from it, the arc's radius `r` at both ends.
    #[test]
    fn a_right_angle_fly_by_is_tangent_at_r_from_the_corner() {
        let w = Site::new(48.27, 11.66);
        let a = w.direct(180.0, 2000.0);
        let (_, _, course_in) = a.inverse_azimuths(&w);
        let b = w.direct(course_in + 90.0, 2000.0);
        let r = 136.7;
        let t = turn(&leg(a, w), &leg(w, b), false, r);
        assert_eq!(t.kind, TurnKind::FlyBy);
        assert!((w.inverse(&t.leave).0 - r).abs() < 1e-6);
        assert!((w.inverse(&t.join).0 - r).abs() < 1e-6);
        let Some(Path::Arc(ArcLeg { centre, .. })) = t.paths.first() else {
            panic!("{t:?}");
        };
        assert!((centre.inverse(&t.leave).0 - r).abs() < 1e-5);
        assert!((centre.inverse(&t.join).0 - r).abs() < 1e-5);
        assert!((centre.inverse(&w).0 - r * 2f64.sqrt()).abs() < 1e-5);
    }

    /// A U-turn has no fly-by arc: it is flown over, out by the turn and back at 45°.
    #[test]
    fn a_u_turn_is_flown_over_and_intercepts_the_leg_back() {
        let w = Site::new(48.27, 11.66);
        let a = w.direct(180.0, 2000.0);
        let t = turn(&leg(a, w), &leg(w, a), false, 136.7);
        assert_eq!(t.kind, TurnKind::FlyOver);
        assert_eq!(t.leave, w);
        assert_eq!(t.paths.len(), 3);
        // The join is on the way back.
        let (_, course_back) = w.inverse(&a);
        let (d, az) = w.inverse(&t.join);
        assert!(course_change(az, course_back).abs() < 1e-6, "{az}");
        assert!(d > 0.0 && d < 1000.0, "{d}");
    }
}
