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
//! turn, intercept and turn onto the next leg; `missionlink_protocol::geofence::turn`, at the gateway's
//! bank and in its wind, forward from the take-off position; in wind also the same turn in calm
//! air, dashed, and the band between the two shaded: what the wind adds to the turn, ICD §7
//! "Turns in wind"); the RF centres as small crosses with
//! dotted radii to the arc's ends; the take-off point; the waypoints as numbered circles; every [`Marker`] as a
//! red ring with its code. Beside the map: a legend, the projection, and a red box listing the
//! markers (those without a position are drawn nowhere else). Above: the title, the mission ID
//! and the waypoint and area counts. A scale bar (metres) and a north arrow sit on the map.
//!
//! The map draws what the safety gateway checks: the areas are the geofence's zones
//! ([`Fence::of_list`]) and the legs the geofence's paths ([`flown_route::legs`], as the gateway and
//! the FCC walk them), each drawn through the sites along it ([`Track::sites`]): geodesic edges
//! and track-to-fix legs at most [`DRAW_STEP_M`] apart along the geodesic (a 35 km leg along
//! 71° N bows about 70 m north of the line between its ends, and is drawn so), radius-to-fix
//! arcs at the geofence's corners, circles as the points at their geodesic radius (centre to
//! border point) around the centre. Nothing is decided on the map.
//!
//! Drawing projection (for the screen only): `local_frame`, equirectangular
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
//! [`flown_route::execute_route`]); without one it marks the initial waypoint. The leg type of the
//! initial waypoint (the leg that would end there) is not drawn: it is flown direct.

use std::fmt::Write as _;

use local_frame::LocalFrame;
use missionlink_ground::ground_station::ValidatedPlan;
use missionlink_ground::safety_gateway::SafetyGateway;
use missionlink_interfaces::wire::{AreaShape, GeoPoint, SpecificData, TurnDirection};
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::flown_route::{self, RouteElement, RouteView, RouteWaypoint};
use missionlink_protocol::geofence::path::{Path, Track};
use missionlink_protocol::geofence::turn::TurnKind;
use missionlink_protocol::geofence::zone::{Fence, Zone, ZoneKind};

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

// Before the modules that write SVG: a macro is in scope after its definition.
/// Appends a formatted line to the document (writing to a `String` cannot fail).
macro_rules! w {
    ($svg:expr, $($arg:tt)*) => {{
        let _ = writeln!($svg, $($arg)*);
    }};
}

mod geometry;
mod local_frame;
mod panel;
mod svg;

use self::geometry::*;
use self::panel::*;
use self::svg::*;

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
    gateway: &SafetyGateway,
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
    let route: Vec<flown_route::RouteLeg> = match take_off {
        Some(t) => flown_route::execute_route(list, Site::of(t), None).collect(),
        None => flown_route::legs(list).collect(),
    };
    // The turns at the waypoints as flown and checked (the gateway's bank), from the take-off
    // position or, without one, from the initial waypoint.
    let fly_by = flown_route::FlyBy {
        bank_deg: gateway.profile.max_bank_deg,
    };
    let in_wind = RouteView {
        wind_mps: gateway.turn_wind_mps(mission),
        ..list
    };
    let start = take_off.or(list.waypoints.first().map(|w| w.position()));
    let turns_in = |route: RouteView<'_, _>| -> Vec<Turn> {
        start
            .into_iter()
            .flat_map(|s| flown_route::execute_route(route, Site::of(s), Some(fly_by)))
            .filter_map(|leg| match leg.element {
                RouteElement::Turn { at, to, kind } => Some(Turn {
                    at,
                    to,
                    kind,
                    points: drawn(leg.path, &proj),
                }),
                _ => None,
            })
            .collect()
    };
    let turns = turns_in(in_wind);
    // In wind, the same turns in calm air too: the band between them is what the wind adds
    // (ICD §7 "Turns in wind"), where a turn refused in wind but not in calm air goes wrong.
    let calm_turns = if in_wind.wind_mps > 0.0 {
        turns_in(RouteView {
            wind_mps: 0.0,
            ..list
        })
    } else {
        Vec::new()
    };
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
            Path::Arc(arc) => {
                let c = view.screen(proj.site(&arc.centre));
                for end in [arc.from, arc.to] {
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
                    match arc.direction {
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

    // The turns as flown, over the corners of the legs; in wind, first the band each turn
    // sweeps from calm air to the wind checked (the turn's paths, then the calm turn's back:
    // both start on the leg in, or at the waypoint, and end on the leg out) and the calm turn
    // dashed.
    w!(svg, r#"<g class="turns">"#);
    let key = |t: &Turn| (t.at, t.to);
    let mut seen: Vec<(u16, u16)> = Vec::new();
    for turn in turns.iter().chain(&calm_turns) {
        if calm_turns.is_empty() || seen.contains(&key(turn)) {
            continue;
        }
        seen.push(key(turn));
        let points_of = |list: &[Turn]| -> Vec<P> {
            list.iter()
                .filter(|t| key(t) == key(turn))
                .flat_map(|t| t.points.iter().map(|p| view.screen(*p)))
                .collect()
        };
        let mut band = points_of(&turns);
        let calm = points_of(&calm_turns);
        band.extend(calm.iter().rev());
        w!(
            svg,
            r#"<path class="turn-band" data-turn-at="{}" data-turn-to="{}" d="{} Z" fill="{TURN}" fill-opacity="0.18" stroke="none"/>"#,
            turn.at,
            turn.to,
            path_d(&band)
        );
        w!(
            svg,
            r#"<path class="turn calm" data-turn-at="{}" data-turn-to="{}" d="{}" fill="none" stroke="{TURN}" stroke-width="1" stroke-dasharray="4 3"/>"#,
            turn.at,
            turn.to,
            path_d(&calm)
        );
    }
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

    legend(&mut svg, &proj, !calm_turns.is_empty());
    violations(&mut svg, markers);
    svg.push_str("</svg>\n");
    svg
}

#[cfg(test)]
mod tests;
