//! The side panel of the map: the legend and the list of violations.

use super::*;

/// The legend in the side panel; `in_wind`: the turns are drawn in wind and in calm air.
pub(super) fn legend(svg: &mut String, proj: &Projection, in_wind: bool) {
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
        if in_wind {
            "turn in wind (dashed: calm)"
        } else {
            "turn as flown (fly-by arc, fly-over)"
        },
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
pub(super) fn violations(svg: &mut String, markers: &[Marker]) {
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
