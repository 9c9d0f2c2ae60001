//! What the aircraft flies, as the geofence checks it (ICD §4 "Geometry"): a point (the climb
//! at the take-off point, a waypoint), a track-to-fix leg (the geodesic between its ends) or a
//! radius-to-fix leg (the arc around its centre from the previous waypoint to its own, in its
//! turn direction).
//!
//! A [`Track`] holds a path as *patches*: a tangent plane (at a site on or near the path) and
//! the path in it as a polyline whose corners lie exactly on the path. A geodesic is split into
//! pieces of at most [`PIECE_M`], each a patch at its start; an arc is one patch at its centre,
//! its corners at most [`ARC_SAG_M`] from the arc between them. Fixed capacity, no allocation.

use geo::Coord;
use heapless::Vec;
use missionlink_interfaces::wire::TurnDirection;

use super::PIECE_M;
use super::earth::Site;
use super::plane::Plane;
use super::turn::ArcGeometry;
use super::zone::Ball;

/// Largest distance between a radius-to-fix arc and the chords between its corners, metres.
pub const ARC_SAG_M: f64 = 0.05;
/// Pieces of a geodesic at most; a geodesic longer than `MAX_PIECES` × [`PIECE_M`] (1280 km)
/// gets longer pieces.
pub const MAX_PIECES: usize = 64;
/// Corners of all patches of one track at most (an arc of 300 m radius turning 270° needs 130).
/// An arc that would need more (a radius above about 25 km turning far) gets longer chords: its
/// sagitta grows past [`ARC_SAG_M`] (0.14 m at 30 km, 0.47 m at 100 km for 359°), and its
/// corners, laid out at the true distance from the centre in the centre's plane, stand about
/// `r³/(6R²)` farther out than the plane shows the borders (0.5 m at 50 km).
pub const MAX_CORNERS: usize = 1024;

/// One path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Path {
    /// A point: the vertical climb at the take-off point, a waypoint.
    Point(Site),
    /// A track-to-fix leg: the geodesic from `from` to `to`.
    Geodesic {
        /// Start.
        from: Site,
        /// End.
        to: Site,
    },
    /// A radius-to-fix leg.
    Arc(ArcLeg),
}

impl Path {
    /// The same path flown the other way (the reverse route of ICD §4 #13001).
    pub fn reversed(self) -> Self {
        match self {
            Self::Point(p) => Self::Point(p),
            Self::Geodesic { from, to } => Self::Geodesic { from: to, to: from },
            Self::Arc(leg) => Self::Arc(leg.reversed()),
        }
    }
}

/// A radius-to-fix leg: from `from` to `to` around `centre` in `direction` (clockwise =
/// azimuth from the centre growing), the radius going linearly with the angle turned from the
/// start's to the end's distance from the centre (equal on a valid leg, ICD §7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcLeg {
    /// Start (the previous waypoint).
    pub from: Site,
    /// End (the leg's own waypoint).
    pub to: Site,
    /// Centre (#13006).
    pub centre: Site,
    /// Turn direction.
    pub direction: TurnDirection,
}

impl ArcLeg {
    /// Its centre, radii, azimuths and sweep.
    pub fn geometry(&self) -> ArcGeometry {
        ArcGeometry::of(&self.from, &self.to, &self.centre, self.direction)
    }

    /// The same leg flown the other way.
    pub fn reversed(self) -> Self {
        Self {
            from: self.to,
            to: self.from,
            centre: self.centre,
            direction: match self.direction {
                TurnDirection::Clockwise => TurnDirection::CounterClockwise,
                TurnDirection::CounterClockwise => TurnDirection::Clockwise,
            },
        }
    }
}

/// One tangent plane and the corners of the path in it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Patch {
    pub(crate) origin: Site,
    pub(crate) plane: Plane,
    /// Range of the track's corners.
    pub(crate) start: usize,
    pub(crate) end: usize,
    pub(crate) ball: Ball,
}

/// A path made ready for the geofence.
#[derive(Debug, Clone)]
pub struct Track {
    pub(crate) path: Path,
    pub(crate) patches: Vec<Patch, MAX_PIECES>,
    pub(crate) corners: Vec<Coord, MAX_CORNERS>,
    length_m: f64,
}

impl Track {
    /// The track of `path`.
    pub fn new(path: Path) -> Self {
        let mut track = Self {
            path,
            patches: Vec::new(),
            corners: Vec::new(),
            length_m: 0.0,
        };
        match path {
            Path::Point(p) => track.push_patch(p, &[Coord { x: 0.0, y: 0.0 }]),
            Path::Geodesic { from, to } => {
                let (length, azimuth) = from.inverse(&to);
                track.length_m = length;
                let n = ((length / PIECE_M).ceil() as usize).clamp(1, MAX_PIECES);
                let mut a = from;
                for k in 1..=n {
                    let b = if k == n {
                        to
                    } else {
                        from.direct(azimuth, length * k as f64 / n as f64)
                    };
                    let plane = Plane::at(&a);
                    track.push_patch(a, &[Coord { x: 0.0, y: 0.0 }, plane.xy(&b)]);
                    a = b;
                }
            }
            Path::Arc(leg) => track.arc(&leg.geometry()),
        }
        track
    }

    fn arc(&mut self, arc: &ArcGeometry) {
        let ArcGeometry { r0, az0, r1, .. } = *arc;
        // Signed: the azimuth from the centre falls on a counter-clockwise arc.
        let sweep = if arc.clockwise { arc.sweep } else { -arc.sweep };
        let r = r0.max(r1);
        // Chords of sagitta ARC_SAG_M: a step of 2·acos(1 − s/r).
        let step = 2.0
            * (1.0 - ARC_SAG_M / r.max(ARC_SAG_M))
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
        let n = if step > 0.0 {
            ((sweep.abs() / step).ceil() as usize).clamp(1, MAX_CORNERS - 1)
        } else {
            1
        };
        let mut corners: Vec<Coord, MAX_CORNERS> = Vec::new();
        for k in 0..=n {
            let f = k as f64 / n as f64;
            let (theta, radius) = ((az0 + sweep * f).to_radians(), r0 + (r1 - r0) * f);
            let _ = corners.push(Coord {
                x: radius * theta.sin(),
                y: radius * theta.cos(),
            });
        }
        self.length_m = arc.length_m();
        self.push_patch(arc.centre, &corners);
    }

    fn push_patch(&mut self, origin: Site, corners: &[Coord]) {
        let start = self.corners.len();
        for c in corners {
            let _ = self.corners.push(*c);
        }
        let kept = self.corners.get(start..).unwrap_or_default();
        // The ball about the site at the middle of the corners' box: every point of the path
        // is within `reach` of it along the surface (a geodesic piece's points are within half
        // its length of its middle; an arc leaves its chords by at most ARC_SAG_M), up to the
        // plane's scale (1 + d²/R², well under the 0.1 % allowed), and a chord is never longer
        // than the geodesic.
        let (lo, hi) = kept.iter().fold(
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
        let middle = (lo + hi) * 0.5;
        let reach = kept
            .iter()
            .map(|c| (*c - middle).x.hypot((*c - middle).y))
            .fold(0.0, f64::max);
        let centre = if kept.len() > 1 {
            Self::site_at_origin(&origin, middle).ecef
        } else {
            origin.ecef
        };
        let ball = Ball {
            centre,
            radius: reach * 1.001 + ARC_SAG_M + 0.01,
        };
        let _ = self.patches.push(Patch {
            origin,
            plane: Plane::at(&origin),
            start,
            end: self.corners.len(),
            ball,
        });
    }

    fn site_at_origin(origin: &Site, c: Coord) -> Site {
        origin.direct(c.x.atan2(c.y).to_degrees(), c.x.hypot(c.y))
    }

    /// The path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Where the path starts.
    pub fn start(&self) -> Site {
        match self.path {
            Path::Point(p) => p,
            Path::Geodesic { from, .. } | Path::Arc(ArcLeg { from, .. }) => from,
        }
    }

    /// Length along the path, metres (0 for a point).
    pub fn length_m(&self) -> f64 {
        self.length_m
    }

    /// The corners of a patch.
    pub(crate) fn corners_of(&self, patch: &Patch) -> &[Coord] {
        self.corners.get(patch.start..patch.end).unwrap_or_default()
    }

    /// The site at `c`, a point of `patch`'s plane (near the patch): along the geodesic from
    /// the plane's origin in the direction of `c` for its distance.
    pub(crate) fn site_at(patch: &Patch, c: Coord) -> Site {
        patch
            .origin
            .direct(c.x.atan2(c.y).to_degrees(), c.x.hypot(c.y))
    }

    /// The patches in the order flown, each as its tangent plane and the path's corners in it
    /// (a geodesic piece: its two ends; an arc: its corners, the chords between them within
    /// [`ARC_SAG_M`] of it; a point: the origin), for measuring the track against another
    /// one outside the geofence (the fleet separation check of the safety gateway): a corner
    /// goes back onto the ellipsoid with [`Plane::lift`].
    pub fn planes(&self) -> impl Iterator<Item = (&Plane, &[Coord])> + '_ {
        self.patches
            .iter()
            .map(|patch| (&patch.plane, self.corners_of(patch)))
    }

    /// The site at `c`, a point in the plane of the `patch`-th patch.
    pub fn site(&self, patch: usize, c: Coord) -> Option<Site> {
        self.patches.get(patch).map(|p| Self::site_at(p, c))
    }

    /// The chords of the path in the order flown, each as its patch, its start in that patch's
    /// plane ([`Track::site`]), its direction of flight (degrees from true north) and its
    /// length in metres: what the energy estimate integrates the wind along.
    pub fn chords(&self) -> impl Iterator<Item = (usize, Coord, f64, f64)> + '_ {
        self.patches.iter().enumerate().flat_map(move |(i, patch)| {
            self.corners_of(patch).windows(2).filter_map(move |w| {
                let [a, b] = w else { return None };
                let d = *b - *a;
                let length = d.x.hypot(d.y);
                // A direction in the plane is the direction on the ellipsoid near the origin.
                (length > 0.0)
                    .then(|| (i, *a, d.x.atan2(d.y).to_degrees().rem_euclid(360.0), length))
            })
        })
    }
    /// The sites along the path in the order flown, for drawing it (the map): a geodesic at
    /// `step_m` or less apart along it (at most [`MAX_DRAWN_SITES`], both ends exact), an arc
    /// at its corners (the chords between them within [`ARC_SAG_M`] of it), a point once.
    pub fn sites(&self, step_m: f64) -> impl Iterator<Item = Site> + '_ {
        let geodesic = match self.path {
            Path::Geodesic { from, to } => {
                let (length, azimuth) = from.inverse(&to);
                let n = (length / step_m.max(1.0))
                    .ceil()
                    .clamp(1.0, MAX_DRAWN_SITES as f64);
                Some((from, to, length, azimuth, n as usize))
            }
            Path::Point(_) | Path::Arc(ArcLeg { .. }) => None,
        };
        let along = geodesic
            .into_iter()
            .flat_map(|(from, to, length, azimuth, n)| {
                (0..=n).map(move |k| match k {
                    0 => from,
                    k if k == n => to,
                    k => from.direct(azimuth, length * k as f64 / n as f64),
                })
            });
        let corners = geodesic
            .is_none()
            .then_some(())
            .into_iter()
            .flat_map(move |()| {
                self.patches.iter().flat_map(move |patch| {
                    self.corners_of(patch)
                        .iter()
                        .map(move |c| Self::site_at(patch, *c))
                })
            });
        along.chain(corners)
    }
}

/// Sites of one geodesic drawn at most ([`Track::sites`]).
pub const MAX_DRAWN_SITES: usize = 100_000;
