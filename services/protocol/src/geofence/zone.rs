//! Zones as the geofence holds them (ICD §4 "Geometry", §7): a polygon's border as the sites
//! along its geodesic edges, at most [`PIECE_M`] apart, or a circle's centre and geodesic
//! radius; each with a ball that holds all of it, so that what is far away costs one test.
//!
//! A [`Fence`] is the area list: the fly-zone and the no-fly-zones, in fixed capacity. It is
//! built from the wire's list (the GCS) or from the published list (the FCC) alike.

use heapless::Vec;
use missionlink_interfaces::capacity::{MAX_AREAS, MAX_POLYGON_VERTICES};
use missionlink_interfaces::contracts::AreaListPayload;
use missionlink_interfaces::wire::{AreaShape, AreaType, GeoPoint};

use super::PIECE_M;
use super::earth::{Site, WGS84_MIN_RADIUS_M, chord};
use super::plane::{Plane, SegmentPair, point_segment, segment_segment};
use crate::transfer::areas::AreaList;

/// Sites along one polygon's border at most: its vertices and the points that split edges
/// longer than [`PIECE_M`]. Past it, the longest edges get longer pieces (see
/// [`Zone::polygon`]).
pub const MAX_BORDER_SITES: usize = 4 * MAX_POLYGON_VERTICES;
/// Border pieces under one ball of the coarse level: a path far from all of them costs one
/// test for the group.
pub(crate) const GROUP: usize = 8;
const MAX_GROUPS: usize = MAX_BORDER_SITES.div_ceil(GROUP);

/// Which side of a zone is allowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZoneKind {
    /// Stay inside (fly-zone).
    FlyZone,
    /// Stay outside (no-fly-zone).
    NoFlyZone,
}

/// A ball in ECEF that holds a piece of geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ball {
    pub(crate) centre: [f64; 3],
    pub(crate) radius: f64,
}

impl Ball {
    /// A ball holding the geodesic between `a` and `b`: about their chord's midpoint, with
    /// room for the geodesic's bulge away from the chord (`l²/(8R)`, taken twice).
    pub(crate) fn of_piece(a: &Site, b: &Site) -> Self {
        let c = a.chord_m(b);
        Self {
            centre: [
                (a.ecef[0] + b.ecef[0]) / 2.0,
                (a.ecef[1] + b.ecef[1]) / 2.0,
                (a.ecef[2] + b.ecef[2]) / 2.0,
            ],
            radius: c / 2.0 * 1.001 + c * c / (4.0 * WGS84_MIN_RADIUS_M) + 0.01,
        }
    }

    /// A ball holding every one of `balls`.
    pub(crate) fn around(balls: &[Ball]) -> Self {
        let n = balls.len().max(1) as f64;
        let mut centre = [0.0; 3];
        for b in balls {
            for (c, x) in centre.iter_mut().zip(b.centre) {
                *c += x / n;
            }
        }
        let radius = balls
            .iter()
            .map(|b| chord(&centre, &b.centre) + b.radius)
            .fold(0.0, f64::max);
        Self { centre, radius }
    }

    /// A lower bound of the geodesic distance between anything in `self` and anything in
    /// `other` (a chord is never longer than the geodesic).
    pub(crate) fn gap(&self, other: &Ball) -> f64 {
        chord(&self.centre, &other.centre) - self.radius - other.radius
    }
}

/// A zone's shape.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Shape {
    /// The border: every site in order around the polygon, the edges split into pieces; the
    /// last connects to the first.
    Polygon {
        border: Vec<Site, MAX_BORDER_SITES>,
        /// Index in `border` of each vertex.
        vertices: Vec<u16, MAX_POLYGON_VERTICES>,
        /// The ball of each border piece (from `border[i]` to the next).
        balls: Vec<Ball, MAX_BORDER_SITES>,
        /// The ball of each [`GROUP`] of consecutive pieces.
        groups: Vec<Ball, MAX_GROUPS>,
    },
    /// The points within `radius_m` (geodesic) of `centre`.
    Circle { centre: Site, radius_m: f64 },
}

/// What is wrong with a zone's geometry (ICD §7 "BadGeometry").
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ZoneDefect {
    /// A polygon with fewer than 3 vertices.
    TooFewVertices(usize),
    /// A vertex is the same point as an earlier one (consecutive: a zero-length edge; else
    /// the border touches itself there): the index of the later one.
    RepeatedVertex(usize),
    /// Two edges that are not neighbours cross or touch: the indices of their first vertices,
    /// and where.
    SelfIntersection {
        /// First edge (from this vertex to the next).
        first: usize,
        /// Second edge.
        second: usize,
        /// Latitude and longitude, degrees.
        at: (f64, f64),
    },
    /// A circle whose border point is its centre.
    ZeroRadius,
}

impl core::fmt::Display for ZoneDefect {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooFewVertices(n) => write!(f, "a polygon of {n} vertices (at least 3)"),
            Self::RepeatedVertex(i) => write!(f, "vertex {i} repeats an earlier vertex"),
            Self::SelfIntersection { first, second, .. } => write!(
                f,
                "the border crosses itself: the edge from vertex {first} meets the edge from vertex {second}"
            ),
            Self::ZeroRadius => f.write_str("a circle of zero radius"),
        }
    }
}

/// One area as the geofence holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct Zone {
    /// Area ID.
    pub id: u16,
    /// Fly-zone or no-fly-zone.
    pub kind: ZoneKind,
    pub(crate) shape: Shape,
    pub(crate) ball: Ball,
}

impl Zone {
    /// A polygon through `vertices` (in order, not closed), its edges geodesics. Edges longer
    /// than [`PIECE_M`] are split by the sites along them; when [`MAX_BORDER_SITES`] are not
    /// enough, every edge gets its share, so a border of 60 edges of 80 km or more is held with
    /// pieces longer than [`PIECE_M`] (and proportionally less exactly, see
    /// [`super::plane`]).
    pub fn polygon(id: u16, kind: ZoneKind, vertices: &[GeoPoint]) -> Self {
        let sites: Vec<Site, MAX_POLYGON_VERTICES> =
            vertices.iter().map(|p| Site::of(*p)).collect();
        let n = sites.len();
        let mut edges: Vec<(f64, f64, usize), MAX_POLYGON_VERTICES> = Vec::new();
        for (i, a) in sites.iter().enumerate() {
            let Some(b) = sites.get((i + 1) % n) else {
                continue;
            };
            let (length, azimuth) = a.inverse(b);
            let pieces = (length / PIECE_M).ceil().max(1.0) as usize;
            let _ = edges.push((length, azimuth, pieces));
        }
        let wanted: usize = edges.iter().map(|e| e.2 - 1).sum();
        let room = MAX_BORDER_SITES - n;
        let mut border = Vec::new();
        let mut indices = Vec::new();
        for (a, (length, azimuth, pieces)) in sites.iter().zip(&edges) {
            let pieces = if wanted > room {
                1 + (pieces - 1) * room / wanted
            } else {
                *pieces
            };
            let _ = indices.push(border.len() as u16);
            let _ = border.push(*a);
            for k in 1..pieces {
                let _ = border.push(a.direct(*azimuth, length * k as f64 / pieces as f64));
            }
        }
        let ball = enclosing(&border);
        let balls: Vec<Ball, MAX_BORDER_SITES> = border
            .iter()
            .zip(border.iter().cycle().skip(1))
            .map(|(a, b)| Ball::of_piece(a, b))
            .collect();
        let groups = balls.chunks(GROUP).map(Ball::around).collect();
        Self {
            id,
            kind,
            shape: Shape::Polygon {
                border,
                vertices: indices,
                balls,
                groups,
            },
            ball,
        }
    }

    /// A circle about `centre` through `border` (ICD §4: radius = their geodesic distance).
    pub fn circle(id: u16, kind: ZoneKind, centre: GeoPoint, border: GeoPoint) -> Self {
        let centre = Site::of(centre);
        let (radius_m, _) = centre.inverse(&Site::of(border));
        Self {
            id,
            kind,
            shape: Shape::Circle { centre, radius_m },
            ball: Ball {
                centre: centre.ecef,
                radius: radius_m + 0.01,
            },
        }
    }

    /// The circle's radius, metres (`None` for a polygon).
    pub fn radius_m(&self) -> Option<f64> {
        match self.shape {
            Shape::Circle { radius_m, .. } => Some(radius_m),
            Shape::Polygon { .. } => None,
        }
    }

    /// The vertices of a polygon, or the centre of a circle.
    pub fn vertices(&self) -> impl Iterator<Item = Site> + '_ {
        let (border, indices, centre): (&[Site], &[u16], Option<Site>) = match &self.shape {
            Shape::Polygon {
                border, vertices, ..
            } => (border, vertices, None),
            Shape::Circle { centre, .. } => (&[], &[], Some(*centre)),
        };
        indices
            .iter()
            .filter_map(|&i| border.get(usize::from(i)).copied())
            .chain(centre)
    }

    /// The edges of a polygon as paths (none for a circle).
    pub fn edges(&self) -> impl Iterator<Item = super::path::Path> + '_ {
        let vertices: Vec<Site, MAX_POLYGON_VERTICES> = match &self.shape {
            Shape::Polygon { .. } => self.vertices().collect(),
            Shape::Circle { .. } => Vec::new(),
        };
        let n = vertices.len();
        (0..n).filter_map(move |i| {
            Some(super::path::Path::Geodesic {
                from: *vertices.get(i)?,
                to: *vertices.get((i + 1) % n)?,
            })
        })
    }

    /// Twice the largest triangle a polygon's vertices span with its first vertex and the vertex
    /// farthest from it, square metres: 0 when all vertices lie on one line, whatever the
    /// border's crossings (a figure-eight encloses no net area but spans a real one).
    pub fn spread_m2(&self) -> f64 {
        let mut vertices = self.vertices();
        let Some(first) = vertices.next() else {
            return 0.0;
        };
        let plane = Plane::at(&first);
        let points: Vec<geo::Coord, MAX_POLYGON_VERTICES> =
            self.vertices().map(|v| plane.xy(&v)).collect();
        let far = points
            .iter()
            .copied()
            .fold(geo::Coord { x: 0.0f64, y: 0.0 }, |f, p| {
                if p.x.hypot(p.y) > f.x.hypot(f.y) {
                    p
                } else {
                    f
                }
            });
        points
            .iter()
            .map(|p| (p.x * far.y - far.x * p.y).abs())
            .fold(0.0, f64::max)
    }

    /// The area a polygon encloses, square metres, in the tangent plane at its first vertex
    /// (for telling a degenerate polygon from a real one; 0 for a circle).
    pub fn area_m2(&self) -> f64 {
        let Some(first) = self.pieces().next().map(|(a, _)| *a) else {
            return 0.0;
        };
        let plane = Plane::at(&first);
        let twice: f64 = self
            .pieces()
            .map(|(a, b)| {
                let (p, q) = (plane.xy(a), plane.xy(b));
                p.x * q.y - q.x * p.y
            })
            .sum();
        twice.abs() / 2.0
    }

    /// The polygon's border sites, the ball of each piece and the ball of each [`GROUP`] of
    /// pieces (empty for a circle).
    pub(crate) fn border(&self) -> (&[Site], &[Ball], &[Ball]) {
        match &self.shape {
            Shape::Polygon {
                border,
                balls,
                groups,
                ..
            } => (border, balls, groups),
            Shape::Circle { .. } => (&[], &[], &[]),
        }
    }

    /// The border pieces, each from a site to the next (the last back to the first).
    pub(crate) fn pieces(&self) -> impl Iterator<Item = (&Site, &Site)> {
        let border: &[Site] = match &self.shape {
            Shape::Polygon { border, .. } => border,
            Shape::Circle { .. } => &[],
        };
        border
            .iter()
            .zip(border.iter().cycle().skip(1))
            .take(border.len())
    }

    /// Whether `p` (a point in `plane`) is inside this polygon, by the parity of the border
    /// pieces a ray from it towards north crosses; always false for a circle.
    pub(crate) fn polygon_contains(&self, plane: &Plane, p: geo::Coord) -> bool {
        let mut inside = false;
        for (a, b) in self.pieces() {
            if super::plane::ray_crosses(p, plane.xy(a), plane.xy(b)) {
                inside = !inside;
            }
        }
        inside
    }

    /// The first defect of this zone's geometry (ICD §7), if any. Self-intersection is tested
    /// between every two border pieces of edges that are not neighbours, in the tangent plane
    /// at the first piece's start; neighbours may only meet at their shared vertex.
    pub fn defect(&self) -> Option<ZoneDefect> {
        let (border, vertices) = match &self.shape {
            Shape::Circle { radius_m, .. } => {
                return (*radius_m <= 0.0).then_some(ZoneDefect::ZeroRadius);
            }
            Shape::Polygon {
                border, vertices, ..
            } => (border, vertices),
        };
        let n = vertices.len();
        if n < 3 {
            return Some(ZoneDefect::TooFewVertices(n));
        }
        for i in 1..n {
            for j in 0..i {
                if let (Some(a), Some(b)) =
                    (vertex(border, vertices, i), vertex(border, vertices, j))
                    && a.lat == b.lat
                    && (a.lon == b.lon || (a.lon.abs() == 180.0 && b.lon.abs() == 180.0))
                {
                    return Some(ZoneDefect::RepeatedVertex(i));
                }
            }
        }
        let edge_of = |site: usize| vertices.iter().rposition(|&v| usize::from(v) <= site);
        let m = border.len();
        for i in 0..m {
            let (Some(a), Some(b)) = (border.get(i), border.get((i + 1) % m)) else {
                continue;
            };
            let piece = Ball::of_piece(a, b);
            let plane = Plane::at(a);
            let (pa, pb) = (plane.xy(a), plane.xy(b));
            for j in i + 1..m {
                let (Some(c), Some(d)) = (border.get(j), border.get((j + 1) % m)) else {
                    continue;
                };
                let (pc, pd) = (plane.xy(c), plane.xy(d));
                let meet = if j == i + 1 || (i == 0 && j == m - 1) {
                    // Pieces in sequence share a site; they must not fold back onto each
                    // other (a spike), so neither far end may lie on the other piece.
                    let (far_i, far_j) = if j == i + 1 { (pa, pd) } else { (pb, pc) };
                    let folded = point_segment(far_j, pa, pb)
                        .0
                        .min(point_segment(far_i, pc, pd).0);
                    SegmentPair {
                        distance: folded,
                        t: if j == i + 1 { 1.0 } else { 0.0 },
                    }
                } else if piece.gap(&Ball::of_piece(c, d)) > 0.0 {
                    continue;
                } else {
                    segment_segment(pa, pb, pc, pd)
                };
                if meet.distance <= 1e-3 {
                    let (length, azimuth) = a.inverse(b);
                    let at = a.direct(azimuth, length * meet.t);
                    return Some(ZoneDefect::SelfIntersection {
                        first: edge_of(i).unwrap_or(0),
                        second: edge_of(j).unwrap_or(0),
                        at: (at.lat, at.lon),
                    });
                }
            }
        }
        None
    }

    /// Whether `site` is in this zone: within the geodesic radius of a circle's centre, or
    /// inside a polygon by the parity of the border pieces a ray towards north from it crosses
    /// in the tangent plane at `site` (as [`super::clearance`] decides the side of a path's
    /// start). No allocation; a site outside the zone's ball costs one test.
    pub fn contains(&self, site: &Site) -> bool {
        match &self.shape {
            Shape::Circle { centre, radius_m } => centre.inverse(site).0 <= *radius_m,
            Shape::Polygon { .. } => {
                let at = Ball {
                    centre: site.ecef,
                    radius: 0.0,
                };
                self.ball.gap(&at) <= 0.0
                    && self.polygon_contains(&Plane::at(site), geo::Coord { x: 0.0, y: 0.0 })
            }
        }
    }
}

fn vertex<'a>(border: &'a [Site], vertices: &[u16], i: usize) -> Option<&'a Site> {
    border.get(usize::from(*vertices.get(i)?))
}

/// A ball about the mean of `sites` holding every piece between consecutive ones.
fn enclosing(sites: &[Site]) -> Ball {
    let n = sites.len().max(1) as f64;
    let mut centre = [0.0; 3];
    for s in sites {
        for (c, x) in centre.iter_mut().zip(s.ecef) {
            *c += x / n;
        }
    }
    let radius = sites
        .iter()
        .zip(sites.iter().cycle().skip(1))
        .map(|(a, b)| {
            let piece = Ball::of_piece(a, b);
            chord(&centre, &piece.centre) + piece.radius
        })
        .fold(0.0, f64::max);
    Ball { centre, radius }
}

/// The area list as the geofence holds it, with the safety offset.
#[derive(Debug, Clone, PartialEq)]
pub struct Fence {
    /// The fly-zone and the no-fly-zones, in the order of the list.
    pub zones: Vec<Zone, MAX_AREAS>,
    /// Distance kept from every border, metres (ICD §4 #2011 field 4).
    pub safety_offset_m: f64,
}

impl Fence {
    /// The fence of an assembled (or unchecked) area list, boxed: built in place (a fence is
    /// about 200 kB; see [`Fence::set_payload`]).
    pub fn of_list(list: &AreaList) -> Box<Self> {
        let mut fence = Box::new(Self::empty());
        fence.set_list(list);
        fence
    }

    /// Becomes the fence of the assembled area list `list`, in place (as
    /// [`Fence::set_payload`] for a published one).
    pub fn set_list(&mut self, list: &AreaList) {
        self.zones.clear();
        self.safety_offset_m = list.safety_offset.metres();
        for area in &list.areas {
            let kind = match area.area_type {
                AreaType::FlyZone => ZoneKind::FlyZone,
                AreaType::NoFlyZone => ZoneKind::NoFlyZone,
            };
            let zone = match &area.shape {
                AreaShape::Polygon(v) => Zone::polygon(area.area_id, kind, v),
                AreaShape::Circle { centre, border } => {
                    Zone::circle(area.area_id, kind, *centre, *border)
                }
            };
            let _ = self.zones.push(zone);
        }
    }

    /// No zones, no offset: what the FCC holds before an area list is active.
    pub fn empty() -> Self {
        Self {
            zones: Vec::new(),
            safety_offset_m: 0.0,
        }
    }

    /// The fence of the area list mission data handling published.
    pub fn of_payload(list: &AreaListPayload) -> Self {
        let mut fence = Self::empty();
        fence.set_payload(list);
        fence
    }

    /// Becomes the fence of `list`, in place: the FCC keeps one fence (about 110 kB) in a box it
    /// allocated at start and rebuilds it when the active area list changes, so that neither a
    /// check nor a rebuild allocates or puts the whole fence on a stack.
    pub fn set_payload(&mut self, list: &AreaListPayload) {
        self.zones.clear();
        self.safety_offset_m = list.safety_offset.metres();
        if list.fly_zone.vertex_count > 0 {
            let _ = self.zones.push(Zone::polygon(
                list.fly_zone.area_id,
                ZoneKind::FlyZone,
                list.fly_zone.vertices(),
            ));
        }
        for p in list.no_fly_polygons() {
            let _ = self
                .zones
                .push(Zone::polygon(p.area_id, ZoneKind::NoFlyZone, p.vertices()));
        }
        for c in list.no_fly_circles() {
            let _ = self.zones.push(Zone::circle(
                c.area_id,
                ZoneKind::NoFlyZone,
                c.centre,
                c.border,
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_interfaces::wire::Angle;

    fn g(lat: f64, lon: f64) -> GeoPoint {
        GeoPoint {
            latitude: Angle::from_degrees(lat).unwrap(),
            longitude: Angle::from_degrees(lon).unwrap(),
        }
    }

    #[test]
    fn long_edges_are_split_and_short_ones_are_not() {
        let z = Zone::polygon(
            1,
            ZoneKind::FlyZone,
            &[g(48.0, 11.0), g(48.0, 12.0), g(48.01, 12.0)],
        );
        let Shape::Polygon {
            border, vertices, ..
        } = &z.shape
        else {
            panic!()
        };
        // Two edges of about 74.6 km: 4 pieces of at most 20 km each; the 1.1 km edge one.
        assert_eq!(vertices.as_slice(), &[0, 4, 5]);
        assert_eq!(border.len(), 9);
        for (a, b) in z.pieces() {
            assert!(a.inverse(b).0 <= PIECE_M + 1e-6);
        }
    }

    #[test]
    fn defects_of_icd_7() {
        let bow_tie = Zone::polygon(
            3,
            ZoneKind::NoFlyZone,
            &[
                g(48.0, 11.0),
                g(48.01, 11.01),
                g(48.0, 11.01),
                g(48.01, 11.0),
            ],
        );
        assert!(matches!(
            bow_tie.defect(),
            Some(ZoneDefect::SelfIntersection {
                first: 0,
                second: 2,
                ..
            })
        ));
        let two = Zone::polygon(3, ZoneKind::NoFlyZone, &[g(48.0, 11.0), g(48.01, 11.01)]);
        assert_eq!(two.defect(), Some(ZoneDefect::TooFewVertices(2)));
        let repeated = Zone::polygon(
            3,
            ZoneKind::NoFlyZone,
            &[
                g(48.0, 11.0),
                g(48.01, 11.01),
                g(48.0, 11.02),
                g(48.0, 11.0),
            ],
        );
        assert_eq!(repeated.defect(), Some(ZoneDefect::RepeatedVertex(3)));
        let square = Zone::polygon(
            3,
            ZoneKind::NoFlyZone,
            &[
                g(48.0, 11.0),
                g(48.0, 11.01),
                g(48.01, 11.01),
                g(48.01, 11.0),
            ],
        );
        assert_eq!(square.defect(), None);
        let dot = Zone::circle(4, ZoneKind::NoFlyZone, g(48.0, 11.0), g(48.0, 11.0));
        assert_eq!(dot.defect(), Some(ZoneDefect::ZeroRadius));
    }
}
