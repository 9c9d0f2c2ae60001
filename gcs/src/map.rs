//! The mission map: a validated plan drawn as an SVG document, written by hand as text (no
//! plotting crate), for `gcs map` and the documents
//! (`docs/mission-2.svg`).
//!
//! What is drawn, bottom to top: the fly-zone (light green) and, dashed, the fly-zone shrunk by
//! the safety offset; every no-fly-zone (polygon or circle, light red) and, dashed, the
//! no-fly-zone grown by the safety offset; the area IDs; the legs in flight-plan order
//! (track-to-fix as geodesics, radius-to-fix as arcs around their RF centre in their turn
//! direction, each with a direction arrow); the turns at the waypoints as guidance flies them
//! and the gateway checks them (orange: the fly-by arc tangent to both legs, the fly-over's
//! turn, intercept and turn onto the next leg; `services::geofence::turn`, at the default
//! profile's bank, forward from the take-off position); the RF centres as small crosses with
//! dotted radii to the arc's ends; the take-off point; the waypoints as numbered circles; every [`Marker`] as a
//! red ring with its code. Beside the map: a legend, the projection, and a red box listing the
//! markers (those without a position are drawn nowhere else). Above: the title, the mission ID
//! and the waypoint and area counts. A scale bar (metres) and a north arrow sit on the map.
//!
//! The map draws what the safety gateway checks: the areas are the geofence's zones
//! ([`Fence::of_list`]) and the legs the geofence's paths ([`onboard::legs`], as the gateway and
//! the FCC walk them), each drawn through the sites along it ([`Track::sites`]): geodesic edges
//! and track-to-fix legs at most [`DRAW_STEP_M`] apart along the geodesic (a 35 km leg along
//! 71° N bows about 70 m north of the line between its ends, and is drawn so), radius-to-fix
//! arcs at the geofence's corners, circles as the points at their geodesic radius (centre to
//! border point) around the centre. Nothing is decided on the map.
//!
//! Drawing projection (for the screen only): `services::geofence::local_frame`, equirectangular
//! about the centre of the fly-zone's bounding box with the WGS-84 radii of curvature there
//! (`x = N(φ0)·cos φ0·Δλ`, `y = M(φ0)·Δφ`), north up. The map fits the fly-zone (and anything
//! lying outside it, say a violating waypoint) with a margin into the map frame.
//!
//! One approximation, for the picture only: the safety-offset outlines of polygons offset each
//! drawn border point along its angle bisector in the drawing projection (the miter offset of
//! the edges, with very sharp corners clamped); it does not round the corners as the true zone
//! grown or shrunk by the offset does, nor repair a concave outline that the offset folds over.
//! The offset outlines of circles are the points at the geodesic radius ± the offset.
//!
//! The take-off: given the plan's take-off position, the map marks it "take-off" with the
//! take-off height (#13006 type 1) and draws the leg from there to the initial waypoint (flown
//! direct, `data-leg="0-<initial>"`), both as the safety gateway checks them (the geofence's
//! [`onboard::execute_route`]); without one it marks the initial waypoint. The leg type of the
//! initial waypoint (the leg that would end there) is not drawn: it is flown direct.

use std::fmt::Write as _;

use missionlink_interfaces::wire::{AreaShape, GeoPoint, SpecificData, TurnDirection};
use missionlink_services::geofence::earth::Site;
use missionlink_services::geofence::local_frame::LocalFrame;
use missionlink_services::geofence::onboard::{self, RouteElement, RouteView, RouteWaypoint};
use missionlink_services::geofence::path::{Path, Track};
use missionlink_services::geofence::turn::TurnKind;
use missionlink_services::geofence::zone::{Fence, Zone, ZoneKind};
use missionlink_services::ground_station::ValidatedPlan;
use missionlink_services::safety_gateway::AircraftProfile;

/// A mark the map draws in red: a violation the safety gateway reported (its code, a label, and
/// where).
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// The violation code, drawn next to the red symbol and listed in the violation box.
    pub code: String,
    /// What it concerns (element, margin), listed in the violation box.
    pub label: String,
    /// Where, latitude and longitude in degrees; `None` for violations without a place (energy,
    /// environment, ...): those are only listed in the violation box.
    pub position: Option<(f64, f64)>,
}

/// Longest distance between the drawn sites along a geodesic, metres: the chords between them
/// stay within `l²/(8R)` (5 mm) of it, far below a pixel.
pub const DRAW_STEP_M: f64 = 500.0;
/// Largest distance of a circle's drawn chords from the circle (a quarter metre is far below a
/// pixel at map scales).
const CIRCLE_SAG_DRAWN_M: f64 = 0.25;
/// Points of a drawn circle, at least and at most.
const CIRCLE_POINTS: (f64, f64) = (16.0, 3600.0);
const WIDTH: f64 = 1000.0;
const HEIGHT: f64 = 800.0;
/// The map frame: left, top, right, bottom.
const MAP: (f64, f64, f64, f64) = (10.0, 62.0, 760.0, 790.0);
/// Left edge of the side panel (legend, violations).
const PANEL_X: f64 = 772.0;
/// Margin around the content, as a share of its larger extent.
const MARGIN: f64 = 0.07;
/// Smallest extent fitted, metres (a map of a single point still has a scale).
const MIN_EXTENT_M: f64 = 200.0;

const FZ_FILL: &str = "#e2f3da";
const FZ_STROKE: &str = "#2e7d32";
const NFZ_FILL: &str = "#f8d2d2";
const NFZ_STROKE: &str = "#c62828";
const LEG: &str = "#1f4e9c";
const RF_CENTRE: &str = "#6a1b9a";
/// The turns at the waypoints as flown.
const TURN: &str = "#e07b00";
const TAKE_OFF: &str = "#e65100";
const VIOLATION: &str = "#d50000";
const FONT: &str = "DejaVu Sans, Arial, Helvetica, sans-serif";

/// A point in the local metric plane (x east, y north, metres) or on the screen (pixels).
type P = (f64, f64);

fn sub(a: P, b: P) -> P {
    (a.0 - b.0, a.1 - b.1)
}

fn add(a: P, b: P) -> P {
    (a.0 + b.0, a.1 + b.1)
}

fn mul(a: P, k: f64) -> P {
    (a.0 * k, a.1 * k)
}

fn len(a: P) -> f64 {
    a.0.hypot(a.1)
}

fn unit(a: P) -> Option<P> {
    let l = len(a);
    (l > 1e-9).then(|| mul(a, 1.0 / l))
}

/// The drawing projection (`services::geofence::local_frame`), with the map's point type.
#[derive(Debug, Clone, Copy)]
struct Projection(LocalFrame);

impl Projection {
    fn new(lat0: f64, lon0: f64) -> Self {
        Self(LocalFrame::new(lat0, lon0))
    }

    /// Metres east and north of the centre.
    fn local(&self, lat: f64, lon: f64) -> P {
        let c = self.0.xy(lat, lon);
        (c.x, c.y)
    }

    fn site(&self, s: &Site) -> P {
        self.local(s.lat, s.lon)
    }
}

/// The sites along `path` as the geofence holds it, at most [`DRAW_STEP_M`] apart along a
/// geodesic.
fn drawn_sites(path: Path) -> Vec<Site> {
    Track::new(path).sites(DRAW_STEP_M).collect()
}

/// [`drawn_sites`] in the drawing projection.
fn drawn(path: Path, proj: &Projection) -> Vec<P> {
    drawn_sites(path).iter().map(|s| proj.site(s)).collect()
}

/// The points at geodesic distance `radius` (metres) around `centre`, clockwise from north,
/// close enough that no chord lies more than [`CIRCLE_SAG_DRAWN_M`] inside the circle.
fn ring(proj: &Projection, centre: &Site, radius: f64) -> Vec<P> {
    let step = 2.0 * (1.0 - CIRCLE_SAG_DRAWN_M / radius.max(CIRCLE_SAG_DRAWN_M)).acos();
    let n = (core::f64::consts::TAU / step)
        .ceil()
        .clamp(CIRCLE_POINTS.0, CIRCLE_POINTS.1) as usize;
    (0..n)
        .map(|k| proj.site(&centre.direct(360.0 * k as f64 / n as f64, radius)))
        .collect()
}

/// Local metres to screen pixels: uniform scale, north up.
#[derive(Debug, Clone, Copy)]
struct View {
    /// Pixels per metre.
    scale: f64,
    /// Screen position of the local origin.
    origin: P,
}

impl View {
    /// The view that fits the box `lo`..`hi` (local metres) with a margin into the map frame.
    fn fit(lo: P, hi: P) -> Self {
        let (left, top, right, bottom) = MAP;
        let w = (hi.0 - lo.0).max(MIN_EXTENT_M);
        let h = (hi.1 - lo.1).max(MIN_EXTENT_M);
        let margin = MARGIN * w.max(h);
        let scale = ((right - left) / (w + 2.0 * margin)).min((bottom - top) / (h + 2.0 * margin));
        let centre = ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0);
        let screen_centre = ((left + right) / 2.0, (top + bottom) / 2.0);
        Self {
            scale,
            origin: (
                screen_centre.0 - scale * centre.0,
                screen_centre.1 + scale * centre.1,
            ),
        }
    }

    fn screen(&self, p: P) -> P {
        (
            self.origin.0 + self.scale * p.0,
            self.origin.1 - self.scale * p.1,
        )
    }
}

/// An area as drawn, in local metres.
#[derive(Debug, Clone)]
enum Shape {
    /// The sites along the geodesic edges, in order around the polygon.
    Polygon(Vec<P>),
    /// A geodesic circle: its centre and radius (metres), and the points drawn around it.
    Circle {
        centre: Site,
        radius: f64,
        outline: Vec<P>,
    },
}

#[derive(Debug, Clone)]
struct Area {
    id: u16,
    kind: ZoneKind,
    shape: Shape,
}

impl Shape {
    /// The zone as drawn: a polygon through the sites along its edges (each edge's last site is
    /// the next edge's first), a circle through the points at its radius.
    fn of_zone(zone: &Zone, proj: &Projection) -> Self {
        match (zone.radius_m(), zone.vertices().next()) {
            (Some(radius), Some(centre)) => Shape::Circle {
                centre,
                radius,
                outline: ring(proj, &centre, radius),
            },
            _ => Shape::Polygon(
                zone.edges()
                    .flat_map(|edge| {
                        let mut points = drawn(edge, proj);
                        points.pop();
                        points
                    })
                    .collect(),
            ),
        }
    }

    /// The shape offset by `d` metres: outward for `d > 0`, inward for `d < 0` (see the module
    /// documentation for the approximation).
    fn offset(&self, d: f64, proj: &Projection) -> Shape {
        match self {
            Shape::Polygon(points) => Shape::Polygon(offset_polygon(points, d)),
            Shape::Circle { centre, radius, .. } => {
                let radius = (radius + d).max(0.0);
                Shape::Circle {
                    centre: *centre,
                    radius,
                    outline: ring(proj, centre, radius),
                }
            }
        }
    }

    /// The points drawn.
    fn outline(&self) -> &[P] {
        match self {
            Shape::Polygon(points)
            | Shape::Circle {
                outline: points, ..
            } => points,
        }
    }

    /// Where the area's label goes: above the shape's top, horizontally at its middle (local
    /// metres), with the given clearance in metres.
    fn label_anchor(&self, clearance: f64) -> P {
        let (lo, hi) = bounds(self.outline().iter().copied()).unwrap_or(((0.0, 0.0), (0.0, 0.0)));
        ((lo.0 + hi.0) / 2.0, hi.1 + clearance)
    }
}

/// Twice the signed area (shoelace): positive for counter-clockwise (x east, y north).
fn signed_area2(points: &[P]) -> f64 {
    points
        .iter()
        .zip(points.iter().cycle().skip(1))
        .map(|(a, b)| a.0 * b.1 - b.0 * a.1)
        .sum()
}

/// Offsets a closed polygon by `d` metres (outward for `d > 0`): each vertex moves along its
/// angle bisector so that both adjacent edges move by `d` (the miter offset). An approximation of
/// the true buffer: corners stay sharp, very sharp corners are clamped, and an inward offset of a
/// concave or thin polygon may fold over.
fn offset_polygon(points: &[P], d: f64) -> Vec<P> {
    let n = points.len();
    if n < 3 {
        return points.to_vec();
    }
    // Left normals point inward for a counter-clockwise polygon.
    let outward = if signed_area2(points) >= 0.0 { -d } else { d };
    let mut out = Vec::with_capacity(n);
    for (i, v) in points.iter().enumerate() {
        let (Some(prev), Some(next)) = (points.get((i + n - 1) % n), points.get((i + 1) % n))
        else {
            continue;
        };
        let normal = |a: P, b: P| unit(sub(b, a)).map(|u| (-u.1, u.0));
        let shift = match (normal(*prev, *v), normal(*v, *next)) {
            (Some(n1), Some(n2)) => {
                // Miter: n·shift = 1 for both normals; clamp corners sharper than ~150 deg.
                let denom = (1.0 + n1.0 * n2.0 + n1.1 * n2.1).max(0.07);
                mul(add(n1, n2), 1.0 / denom)
            }
            (Some(n1), None) | (None, Some(n1)) => n1,
            (None, None) => (0.0, 0.0),
        };
        out.push(add(*v, mul(shift, outward)));
    }
    out
}

fn bounds(points: impl IntoIterator<Item = P>) -> Option<(P, P)> {
    points
        .into_iter()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .fold(None, |acc, p| {
            Some(match acc {
                None => (p, p),
                Some((lo, hi)) => (
                    (lo.0.min(p.0), lo.1.min(p.1)),
                    (hi.0.max(p.0), hi.1.max(p.1)),
                ),
            })
        })
}

/// The point halfway along the polyline `points` and the direction of the chord there.
fn midway(points: &[P]) -> Option<(P, P)> {
    let chords = || {
        points.windows(2).filter_map(|w| match w {
            [a, b] => Some((*a, sub(*b, *a))),
            _ => None,
        })
    };
    let mut left = chords().map(|(_, d)| len(d)).sum::<f64>() / 2.0;
    for (a, d) in chords() {
        let l = len(d);
        if l > 0.0 && left <= l {
            return Some((add(a, mul(d, left / l)), d));
        }
        left -= l;
    }
    None
}

/// XML-escapes text for element content and attribute values.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if c.is_control() => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Appends a formatted line to the document (writing to a `String` cannot fail).
macro_rules! w {
    ($svg:expr, $($arg:tt)*) => {{
        let _ = writeln!($svg, $($arg)*);
    }};
}

fn points_attr(points: &[P]) -> String {
    let mut s = String::new();
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{:.1},{:.1}", p.0, p.1);
    }
    s
}

fn path_d(points: &[P]) -> String {
    let mut s = String::new();
    for (i, p) in points.iter().enumerate() {
        let _ = write!(
            s,
            "{}{:.1} {:.1}",
            if i == 0 { "M " } else { " L " },
            p.0,
            p.1
        );
    }
    s
}

/// Draws `shape` (screen conversion included) with the given attributes.
fn shape_element(svg: &mut String, view: &View, shape: &Shape, attrs: &str) {
    let screen: Vec<P> = shape.outline().iter().map(|p| view.screen(*p)).collect();
    w!(
        svg,
        r#"<polygon class="area" data-shape="{}" points="{}" {attrs}/>"#,
        match shape {
            Shape::Polygon(_) => "polygon",
            Shape::Circle { .. } => "circle",
        },
        points_attr(&screen)
    );
}

/// A filled arrowhead centred on `at` (screen), pointing along `direction` (screen).
fn arrowhead(svg: &mut String, at: P, direction: P, colour: &str) {
    let Some(u) = unit(direction) else {
        return;
    };
    let n = (-u.1, u.0);
    let tip = add(at, mul(u, 7.0));
    let back = sub(at, mul(u, 6.0));
    let left = add(back, mul(n, 6.0));
    let right = sub(back, mul(n, 6.0));
    w!(
        svg,
        r#"<polygon class="arrow" points="{}" fill="{colour}"/>"#,
        points_attr(&[tip, left, right])
    );
}

/// Text with a white halo, readable over lines and fills.
fn label(svg: &mut String, at: P, text: &str, attrs: &str) {
    w!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" stroke="white" stroke-width="3.5" stroke-linejoin="round" paint-order="stroke" {attrs}>{}</text>"#,
        at.0,
        at.1,
        esc(text)
    );
}

/// A "nice" scale bar length (1, 2 or 5 times a power of ten) not above `max_m`.
fn nice_length(max_m: f64) -> f64 {
    if !(max_m.is_finite() && max_m > 0.0) {
        return 1.0;
    }
    let power = 10f64.powf(max_m.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|k| k * power)
        .find(|l| *l <= max_m)
        .unwrap_or(power)
}

fn metres_text(m: f64) -> String {
    if m >= 1000.0 {
        format!("{} km", m / 1000.0)
    } else {
        format!("{m} m")
    }
}

/// Word-wraps `text` to lines of at most `width` characters (longer words are cut).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let word: String = word.chars().take(width).collect();
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// One waypoint of the flight plan in local metres, with the RF centre of the leg ending there.
struct Waypoint {
    number: u16,
    at: P,
    rf: Option<P>,
}

/// One leg of the route as drawn: FROM and TO waypoint numbers, the path, its points.
struct Leg {
    from: u16,
    to: u16,
    path: Path,
    points: Vec<P>,
}

/// A path of the turn at waypoint `at` onto the leg to `to`, as drawn.
struct Turn {
    at: u16,
    to: u16,
    kind: TurnKind,
    points: Vec<P>,
}

/// Renders `plan` as an SVG document (1000 x 800 px) with `markers` in red and `title` on top.
/// See the module documentation for what is drawn and the approximations.
pub fn render(
    plan: &ValidatedPlan,
    take_off: Option<GeoPoint>,
    markers: &[Marker],
    title: &str,
) -> String {
    let mission = &plan.mission;
    let offset = plan.areas.safety_offset.metres();

    // Projection centre: the middle of the fly-zone's bounding box (degrees); without a
    // fly-zone, of the waypoints.
    let fly_zone_points: Vec<(f64, f64)> = match plan.areas.fly_zone().map(|a| &a.shape) {
        Some(AreaShape::Polygon(vertices)) => vertices
            .iter()
            .map(|v| (v.latitude.degrees(), v.longitude.degrees()))
            .collect(),
        Some(AreaShape::Circle { centre, .. }) => {
            vec![(centre.latitude.degrees(), centre.longitude.degrees())]
        }
        None => mission
            .waypoints
            .iter()
            .map(|r| {
                (
                    r.waypoint.latitude.degrees(),
                    r.waypoint.longitude.degrees(),
                )
            })
            .collect(),
    };
    let (lat0, lon0) = bounds(fly_zone_points.iter().copied()).map_or((0.0, 0.0), |(lo, hi)| {
        ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0)
    });
    let proj = Projection::new(lat0, lon0);

    // The zones the safety gateway checks.
    let areas: Vec<Area> = Fence::of_list(&plan.areas)
        .zones
        .iter()
        .map(|zone| Area {
            id: zone.id,
            kind: zone.kind,
            shape: Shape::of_zone(zone, &proj),
        })
        .collect();

    let waypoints: Vec<Waypoint> = mission
        .waypoints
        .iter()
        .map(|r| {
            let w = &r.waypoint;
            let rf = match r.rf_centre.map(|c| c.data) {
                Some(SpecificData::RfCentre {
                    latitude,
                    longitude,
                    ..
                }) => Some(proj.local(latitude.degrees(), longitude.degrees())),
                _ => None,
            };
            Waypoint {
                number: w.waypoint_number,
                at: proj.local(w.latitude.degrees(), w.longitude.degrees()),
                rf,
            }
        })
        .collect();

    // The legs the safety gateway checks, in the order flown: from the take-off position when
    // the plan has one.
    let list = RouteView::from(mission);
    let route: Vec<onboard::RouteLeg> = match take_off {
        Some(t) => onboard::execute_route(list, Site::of(t), None).collect(),
        None => onboard::legs(list).collect(),
    };
    // The turns at the waypoints as flown and checked (the gateway's bank), from the take-off
    // position or, without one, from the initial waypoint.
    let fly_by = onboard::FlyBy {
        bank_deg: AircraftProfile::default().max_bank_deg,
    };
    let start = take_off.or(list.waypoints.first().map(|w| w.position()));
    let turns: Vec<Turn> = start
        .into_iter()
        .flat_map(|s| onboard::execute_route(list, Site::of(s), Some(fly_by)))
        .filter_map(|leg| match leg.element {
            RouteElement::Turn { at, to, kind } => Some(Turn {
                at,
                to,
                kind,
                points: drawn(leg.path, &proj),
            }),
            _ => None,
        })
        .collect();
    let take_off_at = take_off.map(|t| proj.site(&Site::of(t)));
    let legs: Vec<Leg> = route
        .into_iter()
        .filter_map(|leg| match leg.element {
            RouteElement::Leg { from, to } => Some(Leg {
                from,
                to,
                path: leg.path,
                points: drawn(leg.path, &proj),
            }),
            RouteElement::Climb | RouteElement::ReverseLeg { .. } | RouteElement::Turn { .. } => {
                None
            }
        })
        .collect();

    let marker_points: Vec<Option<P>> = markers
        .iter()
        .map(|m| m.position.map(|(lat, lon)| proj.local(lat, lon)))
        .collect();

    // Fit the fly-zone; and whatever lies outside it (a violating waypoint, a marker).
    let mut all: Vec<P> = Vec::new();
    for area in &areas {
        all.extend_from_slice(area.shape.outline());
        if area.kind == ZoneKind::NoFlyZone {
            all.extend_from_slice(area.shape.offset(offset, &proj).outline());
        }
    }
    for w in &waypoints {
        all.push(w.at);
        all.extend(w.rf);
    }
    all.extend(take_off_at);
    for leg in &legs {
        all.extend_from_slice(&leg.points);
    }
    for turn in &turns {
        all.extend_from_slice(&turn.points);
    }
    all.extend(marker_points.iter().flatten().copied());
    let (lo, hi) = bounds(all).unwrap_or(((0.0, 0.0), (0.0, 0.0)));
    let view = View::fit(lo, hi);

    let mut svg = String::with_capacity(16 * 1024);
    w!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="{FONT}">"#
    );
    w!(svg, "<title>{}</title>", esc(title));
    w!(
        svg,
        r##"<rect x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="#ffffff"/>"##
    );
    let (left, top, right, bottom) = MAP;
    w!(
        svg,
        r##"<rect x="{left}" y="{top}" width="{}" height="{}" fill="#f6f8fa" stroke="#b0b8c0"/>"##,
        right - left,
        bottom - top
    );
    w!(
        svg,
        r#"<clipPath id="map-frame"><rect x="{left}" y="{top}" width="{}" height="{}"/></clipPath>"#,
        right - left,
        bottom - top
    );
    w!(svg, r#"<g clip-path="url(#map-frame)">"#);

    // Areas: fills first, then the offset outlines, then the labels.
    let fly_zones = areas.iter().filter(|a| a.kind == ZoneKind::FlyZone);
    let no_fly_zones = areas.iter().filter(|a| a.kind == ZoneKind::NoFlyZone);
    w!(svg, r#"<g class="fly-zones">"#);
    for area in fly_zones.clone() {
        shape_element(
            &mut svg,
            &view,
            &area.shape,
            &format!(r#"fill="{FZ_FILL}" stroke="{FZ_STROKE}" stroke-width="2""#),
        );
        shape_element(
            &mut svg,
            &view,
            &area.shape.offset(-offset, &proj),
            &format!(
                r#"fill="none" stroke="{FZ_STROKE}" stroke-width="1.3" stroke-dasharray="8 5""#
            ),
        );
    }
    w!(svg, "</g>");
    w!(svg, r#"<g class="no-fly-zones">"#);
    for area in no_fly_zones.clone() {
        shape_element(
            &mut svg,
            &view,
            &area.shape.offset(offset, &proj),
            &format!(
                r#"fill="none" stroke="{NFZ_STROKE}" stroke-width="1.3" stroke-dasharray="8 5""#
            ),
        );
        shape_element(
            &mut svg,
            &view,
            &area.shape,
            &format!(
                r#"fill="{NFZ_FILL}" fill-opacity="0.85" stroke="{NFZ_STROKE}" stroke-width="2""#
            ),
        );
    }
    w!(svg, "</g>");

    // Legs, each ending at its waypoint, with the arrow at the middle.
    w!(svg, r#"<g class="legs">"#);
    for leg in &legs {
        let name = format!("{}-{}", leg.from, leg.to);
        let screen: Vec<P> = leg.points.iter().map(|p| view.screen(*p)).collect();
        let kind = match leg.path {
            Path::Arc {
                from,
                to,
                centre,
                direction,
            } => {
                let c = view.screen(proj.site(&centre));
                for end in [from, to] {
                    let e = view.screen(proj.site(&end));
                    w!(
                        svg,
                        r#"<line class="rf-radius" x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{RF_CENTRE}" stroke-width="1" stroke-dasharray="2 4"/>"#,
                        c.0,
                        c.1,
                        e.0,
                        e.1
                    );
                }
                format!(
                    r#"rf" data-leg="{name}" data-turn="{}"#,
                    match direction {
                        TurnDirection::Clockwise => "clockwise",
                        TurnDirection::CounterClockwise => "counter-clockwise",
                    }
                )
            }
            Path::Geodesic { .. } | Path::Point(_) => format!(r#"tf" data-leg="{name}"#),
        };
        w!(
            svg,
            r#"<path class="leg {kind}" d="{}" fill="none" stroke="{LEG}" stroke-width="2.5" stroke-linejoin="round"/>"#,
            path_d(&screen)
        );
        if let Some((at, direction)) = midway(&screen) {
            arrowhead(&mut svg, at, direction, LEG);
        }
    }
    w!(svg, "</g>");

    // The turns as flown, over the corners of the legs.
    w!(svg, r#"<g class="turns">"#);
    for turn in &turns {
        let screen: Vec<P> = turn.points.iter().map(|p| view.screen(*p)).collect();
        let kind = match turn.kind {
            TurnKind::FlyBy => "fly-by",
            TurnKind::FlyOver => "fly-over",
            TurnKind::Straight | TurnKind::OnTheSpot => "on-the-spot",
        };
        w!(
            svg,
            r#"<path class="turn {kind}" data-turn-at="{}" data-turn-to="{}" d="{}" fill="none" stroke="{TURN}" stroke-width="2" stroke-linejoin="round"/>"#,
            turn.at,
            turn.to,
            path_d(&screen)
        );
    }
    w!(svg, "</g>");

    // RF centres: small crosses.
    w!(svg, r#"<g class="rf-centres">"#);
    for w in &waypoints {
        if let Some(centre) = w.rf {
            let c = view.screen(centre);
            w!(
                svg,
                r#"<path class="rf-centre" data-waypoint="{}" d="M {:.1} {:.1} l 12 12 M {:.1} {:.1} l 12 -12" stroke="{RF_CENTRE}" stroke-width="2"/>"#,
                w.number,
                c.0 - 6.0,
                c.1 - 6.0,
                c.0 - 6.0,
                c.1 + 6.0
            );
            label(
                &mut svg,
                add(c, (9.0, 16.0)),
                &format!("RF centre {}", w.number),
                &format!(r#"font-size="11" fill="{RF_CENTRE}""#),
            );
        }
    }
    w!(svg, "</g>");

    // Area labels above their (grown) outline.
    w!(svg, r#"<g class="area-labels">"#);
    for area in fly_zones {
        let at = match &area.shape {
            Shape::Polygon(points) => bounds(points.iter().copied())
                .map(|(lo, hi)| view.screen((lo.0, hi.1)))
                .map(|p| add(p, (0.0, -8.0))),
            Shape::Circle { .. } => None,
        }
        .unwrap_or_else(|| add(view.screen(area.shape.label_anchor(0.0)), (0.0, -8.0)));
        label(
            &mut svg,
            at,
            &format!("fly-zone {}", area.id),
            &format!(r#"font-size="13" font-weight="bold" fill="{FZ_STROKE}""#),
        );
    }
    for area in no_fly_zones {
        let at = add(view.screen(area.shape.label_anchor(offset)), (0.0, -6.0));
        label(
            &mut svg,
            at,
            &format!("NFZ {}", area.id),
            &format!(
                r#"font-size="13" font-weight="bold" fill="{NFZ_STROKE}" text-anchor="middle""#
            ),
        );
    }
    w!(svg, "</g>");

    // Take-off at the plan's take-off position, else at the initial waypoint.
    if let Some(at) = take_off_at.or(waypoints.first().map(|w| w.at)) {
        let c = view.screen(at);
        w!(
            svg,
            r#"<polygon class="take-off" points="{}" fill="{TAKE_OFF}" fill-opacity="0.9"/>"#,
            points_attr(&[
                add(c, (0.0, -24.0)),
                add(c, (20.0, 12.0)),
                add(c, (-20.0, 12.0))
            ])
        );
        label(
            &mut svg,
            add(c, (0.0, 30.0)),
            &format!("take-off, {:.0} m AGL", mission.take_off_height().metres()),
            &format!(r#"font-size="12" font-weight="bold" fill="{TAKE_OFF}" text-anchor="middle""#),
        );
    }

    // Waypoints: numbered circles.
    w!(svg, r#"<g class="waypoints">"#);
    for w in &waypoints {
        let c = view.screen(w.at);
        let number = w.number.to_string();
        let size = match number.len() {
            0..=2 => 12,
            3 => 10,
            _ => 8,
        };
        w!(
            svg,
            r#"<circle class="waypoint" data-waypoint="{number}" cx="{:.1}" cy="{:.1}" r="11" fill="white" stroke="{LEG}" stroke-width="2.5"/>"#,
            c.0,
            c.1
        );
        w!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="{size}" font-weight="bold" fill="{LEG}" text-anchor="middle">{number}</text>"#,
            c.0,
            c.1 + 0.36 * f64::from(size)
        );
    }
    w!(svg, "</g>");

    // Markers: red rings with their code.
    w!(svg, r#"<g class="markers">"#);
    for (marker, at) in markers.iter().zip(&marker_points) {
        if let Some(at) = at {
            let c = view.screen(*at);
            w!(
                svg,
                r#"<circle class="marker" cx="{:.1}" cy="{:.1}" r="17" fill="none" stroke="{VIOLATION}" stroke-width="3"/>"#,
                c.0,
                c.1
            );
            // A reticle: the ring and four ticks outward (north, east, south, west).
            w!(
                svg,
                r#"<path d="M {:.1} {:.1} v -8 M {:.1} {:.1} h 8 M {:.1} {:.1} v 8 M {:.1} {:.1} h -8" stroke="{VIOLATION}" stroke-width="3"/>"#,
                c.0,
                c.1 - 17.0,
                c.0 + 17.0,
                c.1,
                c.0,
                c.1 + 17.0,
                c.0 - 17.0,
                c.1
            );
            label(
                &mut svg,
                add(c, (20.0, -18.0)),
                &marker.code,
                &format!(r#"font-size="13" font-weight="bold" fill="{VIOLATION}""#),
            );
        }
    }
    w!(svg, "</g>");
    w!(svg, "</g>");

    // Scale bar, bottom left of the map.
    let bar_m = nice_length((right - left) * 0.25 / view.scale);
    let bar_px = bar_m * view.scale;
    let (bx, by) = (left + 20.0, bottom - 22.0);
    w!(
        svg,
        r#"<g class="scale-bar"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="6" fill="black"/><rect x="{:.1}" y="{:.1}" width="{:.1}" height="6" fill="white" stroke="black"/>"#,
        bx,
        by,
        bar_px / 2.0,
        bx + bar_px / 2.0,
        by,
        bar_px / 2.0
    );
    label(
        &mut svg,
        (bx, by - 6.0),
        "0",
        r#"font-size="11" text-anchor="middle""#,
    );
    label(
        &mut svg,
        (bx + bar_px, by - 6.0),
        &metres_text(bar_m),
        r#"font-size="11" text-anchor="middle""#,
    );
    w!(svg, "</g>");

    // North arrow, top right of the map.
    let (nx, ny) = (right - 30.0, top + 22.0);
    w!(
        svg,
        r#"<g class="north-arrow"><polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="black"/>"#,
        nx,
        ny + 8.0,
        nx + 9.0,
        ny + 40.0,
        nx,
        ny + 33.0,
        nx - 9.0,
        ny + 40.0
    );
    w!(
        svg,
        r#"<text x="{nx:.1}" y="{:.1}" font-size="15" font-weight="bold" text-anchor="middle">N</text></g>"#,
        ny + 3.0
    );

    // Title and counts.
    let fz_count = areas.iter().filter(|a| a.kind == ZoneKind::FlyZone).count();
    let nfz_count = areas.len() - fz_count;
    let mission_id = mission.mission_id.map(|t| t.as_str().to_owned());
    w!(
        svg,
        r#"<text x="{left}" y="26" font-size="19" font-weight="bold">{}</text>"#,
        esc(title)
    );
    w!(
        svg,
        r##"<text x="{left}" y="50" font-size="13" fill="#333">{}</text>"##,
        esc(&format!(
            "mission {} · {} waypoint{} · {} area{} ({} fly-zone, {} no-fly-zone{}) · safety offset {:.0} m · {} route",
            mission_id.as_deref().unwrap_or("(no ID)"),
            waypoints.len(),
            if waypoints.len() == 1 { "" } else { "s" },
            areas.len(),
            if areas.len() == 1 { "" } else { "s" },
            fz_count,
            nfz_count,
            if nfz_count == 1 { "" } else { "s" },
            offset,
            if mission.route.bidirectional {
                "bidirectional"
            } else {
                "one-way"
            },
        ))
    );

    legend(&mut svg, &proj);
    violations(&mut svg, markers);
    svg.push_str("</svg>\n");
    svg
}

/// The legend in the side panel.
fn legend(svg: &mut String, proj: &Projection) {
    let x = PANEL_X;
    let mut y = 70.0;
    w!(svg, r#"<g class="legend">"#);
    w!(
        svg,
        r##"<rect x="{x}" y="{y}" width="{}" height="372" fill="white" stroke="#b0b8c0"/>"##,
        WIDTH - x - 10.0
    );
    y += 20.0;
    w!(
        svg,
        r#"<text x="{:.1}" y="{y:.1}" font-size="13" font-weight="bold">Legend</text>"#,
        x + 10.0
    );
    let (sx, tx) = (x + 12.0, x + 52.0);
    let mut entry = |svg: &mut String, symbol: &dyn Fn(&mut String, f64), text: &str| {
        y += 24.0;
        symbol(svg, y);
        w!(
            svg,
            r#"<text x="{tx:.1}" y="{:.1}" font-size="12">{}</text>"#,
            y + 4.0,
            esc(text)
        );
    };
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<rect x="{sx:.1}" y="{:.1}" width="30" height="14" fill="{FZ_FILL}" stroke="{FZ_STROKE}" stroke-width="2"/>"#,
                y - 7.0
            )
        },
        "fly-zone",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<line x1="{sx:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{FZ_STROKE}" stroke-width="1.3" stroke-dasharray="8 5"/>"#,
                sx + 30.0
            )
        },
        "fly-zone − safety offset",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<rect x="{sx:.1}" y="{:.1}" width="30" height="14" fill="{NFZ_FILL}" stroke="{NFZ_STROKE}" stroke-width="2"/>"#,
                y - 7.0
            )
        },
        "no-fly-zone",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<line x1="{sx:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{NFZ_STROKE}" stroke-width="1.3" stroke-dasharray="8 5"/>"#,
                sx + 30.0
            )
        },
        "no-fly-zone + safety offset",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<circle class="legend" cx="{:.1}" cy="{y:.1}" r="9" fill="white" stroke="{LEG}" stroke-width="2.5"/><text x="{:.1}" y="{:.1}" font-size="10" font-weight="bold" fill="{LEG}" text-anchor="middle">n</text>"#,
                sx + 15.0,
                sx + 15.0,
                y + 3.6
            )
        },
        "waypoint n",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<line x1="{sx:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{LEG}" stroke-width="2.5"/>"#,
                sx + 30.0
            );
            arrowhead(s, (sx + 15.0, y), (1.0, 0.0), LEG);
        },
        "track-to-fix leg",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<path d="M {sx:.1} {:.1} Q {:.1} {:.1} {:.1} {:.1}" fill="none" stroke="{LEG}" stroke-width="2.5"/>"#,
                y + 5.0,
                sx + 15.0,
                y - 12.0,
                sx + 30.0,
                y + 5.0
            );
        },
        "radius-to-fix arc",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<path d="M {sx:.1} {:.1} Q {:.1} {:.1} {:.1} {:.1}" fill="none" stroke="{TURN}" stroke-width="2"/>"#,
                y + 6.0,
                sx + 24.0,
                y + 6.0,
                sx + 24.0,
                y - 8.0
            );
        },
        "turn as flown (fly-by arc, fly-over)",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<path d="M {:.1} {:.1} l 12 12 M {:.1} {:.1} l 12 -12" stroke="{RF_CENTRE}" stroke-width="2"/>"#,
                sx + 9.0,
                y - 6.0,
                sx + 9.0,
                y + 6.0
            )
        },
        "RF centre (dotted: radius)",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<polygon points="{}" fill="{TAKE_OFF}"/>"#,
                points_attr(&[
                    (sx + 15.0, y - 10.0),
                    (sx + 26.0, y + 8.0),
                    (sx + 4.0, y + 8.0)
                ])
            )
        },
        "take-off (initial waypoint)",
    );
    entry(
        svg,
        &|s, y| {
            w!(
                s,
                r#"<circle cx="{:.1}" cy="{y:.1}" r="9" fill="none" stroke="{VIOLATION}" stroke-width="3"/>"#,
                sx + 15.0
            )
        },
        "violation (code)",
    );
    y += 30.0;
    for line in [
        "Local equirectangular projection".to_owned(),
        format!(
            "about {:.5}°, {:.5}°,",
            proj.0.origin().0,
            proj.0.origin().1
        ),
        "north up".to_owned(),
        "Dashed offsets: miter approximation".to_owned(),
    ] {
        w!(
            svg,
            r##"<text x="{:.1}" y="{y:.1}" font-size="11" fill="#555">{}</text>"##,
            x + 10.0,
            esc(&line)
        );
        y += 15.0;
    }
    w!(svg, "</g>");
}

/// The red box listing every marker; those without a position appear only here.
fn violations(svg: &mut String, markers: &[Marker]) {
    if markers.is_empty() {
        return;
    }
    let x = PANEL_X;
    let top = 454.0;
    let bottom = MAP.3;
    let line_height = 15.0;
    let mut lines: Vec<(String, bool)> = Vec::new();
    for m in markers {
        let head = match m.position {
            Some(_) => m.code.clone(),
            None => format!("{} (no position)", m.code),
        };
        lines.extend(wrap(&head, 34).into_iter().map(|line| (line, true)));
        lines.extend(wrap(&m.label, 32).into_iter().map(|line| (line, false)));
    }
    let room = ((bottom - top - 40.0) / line_height).floor().max(1.0) as usize;
    let hidden = lines.len().saturating_sub(room);
    let shown = lines.len() - hidden;
    let height = 36.0 + line_height * (shown + usize::from(hidden > 0)) as f64;
    w!(svg, r#"<g class="violations">"#);
    w!(
        svg,
        r##"<rect x="{x}" y="{top}" width="{}" height="{height:.1}" fill="#fff3f3" stroke="{VIOLATION}" stroke-width="2"/>"##,
        WIDTH - x - 10.0
    );
    w!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" font-size="13" font-weight="bold" fill="{VIOLATION}">Violations ({})</text>"#,
        x + 10.0,
        top + 20.0,
        markers.len()
    );
    let mut y = top + 38.0;
    for (line, head) in lines.iter().take(shown) {
        w!(
            svg,
            r#"<text x="{:.1}" y="{y:.1}" font-size="11" fill="{VIOLATION}"{}>{}</text>"#,
            x + if *head { 10.0 } else { 20.0 },
            if *head { r#" font-weight="bold""# } else { "" },
            esc(line)
        );
        y += line_height;
    }
    if hidden > 0 {
        w!(
            svg,
            r#"<text x="{:.1}" y="{y:.1}" font-size="11" fill="{VIOLATION}">… {hidden} more lines</text>"#,
            x + 10.0
        );
    }
    w!(svg, "</g>");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission_file::MissionFile;
    use crate::mission_file::tests::{MISSION_1, MISSION_2, validated};
    use missionlink_services::geofence::earth;
    use missionlink_services::geofence::local_frame::Coord;

    fn example_markers() -> Vec<Marker> {
        vec![
            Marker {
                code: "LEG_IN_NFZ".into(),
                label: "leg 1-2 <cuts> NFZ 3 by 12.5 m".into(),
                position: Some((48.278, 11.658)),
            },
            Marker {
                code: "NFZ_CENTRE".into(),
                label: "area 2".into(),
                position: Some((48.268, 11.675)),
            },
            Marker {
                code: "ENERGY".into(),
                label: "needs 1.9 kWh of 1.6 kWh usable with 20 % reserve".into(),
                position: None,
            },
        ]
    }

    /// Every number in the document is finite, and the tags balance.
    fn assert_well_formed(svg: &str) {
        assert!(svg.starts_with("<svg "), "{svg}");
        assert!(svg.trim_end().ends_with("</svg>"));
        for bad in ["NaN", "inf"] {
            assert!(!svg.contains(bad), "{bad} in {svg}");
        }
        for tag in ["g", "text", "svg", "clipPath", "title"] {
            let open =
                svg.matches(&format!("<{tag} ")).count() + svg.matches(&format!("<{tag}>")).count();
            let close = svg.matches(&format!("</{tag}>")).count();
            assert_eq!(open, close, "<{tag}> opened {open}, closed {close}");
        }
        // Every attribute value is closed: quotes come in pairs on each line.
        for line in svg.lines() {
            assert_eq!(line.matches('"').count() % 2, 0, "{line}");
        }
    }

    #[test]
    fn mission_2_draws_every_element() {
        let plan = validated(MISSION_2);
        let svg = render(&plan, None, &[], "Demo mission 2");
        assert_well_formed(&svg);
        assert_eq!(
            svg.matches(r#"<circle class="waypoint""#).count(),
            plan.mission.waypoints.len()
        );
        for n in 1..=3 {
            assert!(svg.contains(&format!(r#"data-waypoint="{n}""#)));
            assert!(svg.contains(&format!(">{n}</text>")), "waypoint number {n}");
        }
        for label in ["fly-zone 1", "NFZ 2", "NFZ 3"] {
            assert!(svg.contains(label), "{label}");
        }
        // The TF leg CCP-W1 and the RF arc W1-ROLE2 (a sampled path), clockwise.
        assert!(svg.contains(r#"class="leg tf" data-leg="1-2""#));
        assert!(svg.contains(r#"class="leg rf" data-leg="2-3" data-turn="clockwise" d="M "#));
        assert_eq!(svg.matches(r#"class="rf-centre""#).count(), 1);
        assert_eq!(svg.matches(r#"class="arrow""#).count(), 2 + 1); // two legs + legend
        assert!(svg.contains("take-off, 30 m AGL"));
        assert!(svg.contains("MEDEVAC-2"));
        assert!(svg.contains("3 waypoints"));
        assert!(svg.contains("3 areas (1 fly-zone, 2 no-fly-zones)"));
        // Circle NFZ and its grown outline; polygon NFZ, its grown outline, fly-zone and its
        // shrunk outline.
        assert_eq!(
            svg.matches(r#"<polygon class="area" data-shape="circle""#)
                .count(),
            2
        );
        assert_eq!(
            svg.matches(r#"<polygon class="area" data-shape="polygon""#)
                .count(),
            4
        );
        assert!(svg.contains("scale-bar") && svg.contains("north-arrow"));
        assert!(!svg.contains("Violations"));
    }

    #[test]
    fn mission_1_draws_its_single_waypoint() {
        let plan = validated(MISSION_1);
        let svg = render(&plan, None, &[], "Demo mission 1");
        assert_well_formed(&svg);
        assert_eq!(svg.matches(r#"<circle class="waypoint""#).count(), 1);
        assert!(svg.contains(">1</text>"));
        assert!(svg.contains("fly-zone 1"));
        assert!(svg.contains("MEDEVAC-1"));
        assert!(svg.contains("1 waypoint ·"));
        assert!(svg.contains("take-off, 30 m AGL"));
        assert!(!svg.contains("class=\"leg "));
        // From its take-off position (TROL) the way to CCP is drawn, as the gateway checks it.
        let trol = MissionFile::parse(MISSION_1).unwrap().to_plan().unwrap();
        let svg = render(&plan, trol.take_off_position, &[], "Demo mission 1");
        assert_well_formed(&svg);
        assert_eq!(svg.matches(r#"class="leg tf" data-leg="0-1""#).count(), 1);
    }

    #[test]
    fn markers_are_drawn_and_listed() {
        let plan = validated(MISSION_2);
        let svg = render(&plan, None, &example_markers(), "Mission 2 <& markers>");
        assert_well_formed(&svg);
        assert!(svg.contains("Mission 2 &lt;&amp; markers&gt;"));
        // Two on the map, all three in the box.
        assert_eq!(svg.matches(r#"<circle class="marker""#).count(), 2);
        assert!(svg.contains("Violations (3)"));
        for code in ["LEG_IN_NFZ", "NFZ_CENTRE", "ENERGY"] {
            assert!(svg.matches(code).count() >= 1, "{code}");
        }
        assert_eq!(svg.matches(">LEG_IN_NFZ</text>").count(), 2); // map and box
        assert!(svg.contains("&lt;cuts&gt;"));
        assert!(svg.contains("(no position)"));
    }

    #[test]
    fn rf_arc_turns_the_right_way_and_ends_at_the_waypoints() {
        let (centre, w1, role2) = (
            Site::new(48.27455, 11.66991),
            Site::new(48.278, 11.658),
            Site::new(48.28, 11.68),
        );
        let arc = |direction| {
            drawn_sites(Path::Arc {
                from: w1,
                to: role2,
                centre,
                direction,
            })
        };
        let cw = arc(TurnDirection::Clockwise);
        let close = |a: &Site, b: &Site| a.inverse(b).0 < 1e-6;
        assert!(close(&cw[0], &w1) && close(cw.last().unwrap(), &role2));
        // Clockwise from W1 (north-west of the centre) to ROLE2 (north-east): over the top, at
        // the geodesic radius all along.
        let r = centre.inverse(&w1).0;
        let top = cw.iter().map(|s| s.lat).fold(f64::MIN, f64::max);
        let north = centre.direct(0.0, r);
        // (1e-5° of latitude is 1.1 m; the radius goes from W1's distance to ROLE2's.)
        assert!((top - north.lat).abs() < 1e-5, "{top} vs {}", north.lat);
        for s in &cw {
            assert!((centre.inverse(s).0 - r).abs() < 1.0);
        }
        // Counter-clockwise: the long way round, under the centre.
        let ccw = arc(TurnDirection::CounterClockwise);
        let low = ccw.iter().map(|s| s.lat).fold(f64::MAX, f64::min);
        assert!((low - centre.direct(180.0, r).lat).abs() < 1e-5);
        assert!(ccw.len() > cw.len());
    }

    /// A 35 km track-to-fix leg along 71° N is drawn as the geodesic the gateway checks: its
    /// middle about 70 m north of the parallel (and of the straight line between its ends in
    /// the drawing projection), where the geodesic's midpoint is, within a metre.
    #[test]
    fn a_long_east_west_leg_at_71_north_bows_north() {
        let (from, to) = (Site::new(71.0, 25.0), Site::new(71.0, 25.0 + 0.97));
        let (length, azimuth) = from.inverse(&to);
        assert!((length - 35_000.0).abs() < 300.0, "{length}");
        let sites = drawn_sites(Path::Geodesic { from, to });
        assert!(sites.len() >= 71, "{}", sites.len());
        for w in sites.windows(2) {
            assert!(w[0].inverse(&w[1]).0 <= DRAW_STEP_M + 1e-6);
        }
        let mid = earth::destination(from, azimuth, length / 2.0);
        let bow = earth::distance_m(mid, Site::new(71.0, mid.x()));
        assert!((60.0..80.0).contains(&bow), "{bow} m");

        // The drawn line halfway along is the geodesic's midpoint, latitude within a metre
        // (1e-5° is 1.1 m), and lies that far above the chord between the ends on the screen.
        let proj = Projection::new(71.0, 25.5);
        let points = drawn(Path::Geodesic { from, to }, &proj);
        let (m, _) = midway(&points).unwrap();
        let (lat, lon) = proj.0.deg(Coord { x: m.0, y: m.1 });
        assert!((lat - mid.y()).abs() < 0.9e-5, "{lat} vs {}", mid.y());
        assert!((lon - mid.x()).abs() < 1e-4, "{lon} vs {}", mid.x());
        let (a, b) = (points[0], *points.last().unwrap());
        let chord_y = a.1 + (b.1 - a.1) * (m.0 - a.0) / (b.0 - a.0);
        assert!(
            (m.1 - chord_y - bow).abs() < 1.0,
            "{} vs {bow}",
            m.1 - chord_y
        );
    }

    #[test]
    fn polygon_offsets_move_every_edge_by_the_offset() {
        let ccw = vec![(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)];
        let cw: Vec<P> = ccw.iter().rev().copied().collect();
        for square in [&ccw, &cw] {
            let grown = offset_polygon(square, 10.0);
            let (lo, hi) = bounds(grown).unwrap();
            assert!((lo.0 + 10.0).abs() < 1e-9 && (hi.1 - 110.0).abs() < 1e-9);
            let shrunk = offset_polygon(square, -10.0);
            let (lo, hi) = bounds(shrunk).unwrap();
            assert!((lo.0 - 10.0).abs() < 1e-9 && (hi.1 - 90.0).abs() < 1e-9);
        }
        // A circle shrunk past its centre is the centre.
        let proj = Projection::new(48.0, 11.0);
        let centre = Site::new(48.0, 11.0);
        let circle = Shape::Circle {
            centre,
            radius: 5.0,
            outline: ring(&proj, &centre, 5.0),
        };
        assert!(
            circle
                .offset(-10.0, &proj)
                .outline()
                .iter()
                .all(|p| len(*p) < 1e-6)
        );
    }

    #[test]
    fn scale_bar_lengths_are_round() {
        assert_eq!(nice_length(1234.0), 1000.0);
        assert_eq!(nice_length(2600.0), 2000.0);
        assert_eq!(nice_length(730.0), 500.0);
        assert_eq!(metres_text(1000.0), "1 km");
        assert_eq!(metres_text(500.0), "500 m");
    }

    const DOCS_MAP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/mission-2.svg");

    fn docs_map() -> String {
        let file = MissionFile::parse(MISSION_2).unwrap();
        render(
            &validated(MISSION_2),
            file.to_plan().unwrap().take_off_position,
            &[],
            "missionlink demo mission 2: CCP to ROLE2",
        )
    }

    /// Writes docs/mission-2.svg, and an example with markers to the temporary directory:
    /// `cargo test -p missionlink-gcs map::tests::write_maps -- --ignored`.
    #[test]
    #[ignore = "generator: writes docs/mission-2.svg"]
    fn write_maps() {
        std::fs::write(DOCS_MAP, docs_map()).unwrap();
        let markers = render(
            &validated(MISSION_2),
            None,
            &example_markers(),
            "missionlink demo mission 2 with example markers",
        );
        std::fs::write(std::env::temp_dir().join("mission-2-markers.svg"), markers).unwrap();
    }

    /// The committed map is what the renderer draws today.
    #[test]
    fn docs_map_is_current() {
        let committed = std::fs::read_to_string(DOCS_MAP).unwrap();
        assert!(
            committed == docs_map(),
            "docs/mission-2.svg is stale: cargo test -p missionlink-gcs map::tests::write_maps -- --ignored"
        );
    }
}
