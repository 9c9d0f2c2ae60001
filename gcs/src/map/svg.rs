//! Writing SVG: escaping, point lists and paths, shapes, arrowheads, labels, scale lengths and
//! wrapped text.

use super::*;

/// XML-escapes text for element content and attribute values.
pub(super) fn esc(text: &str) -> String {
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

pub(super) fn points_attr(points: &[P]) -> String {
    let mut s = String::new();
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{:.1},{:.1}", p.0, p.1);
    }
    s
}

pub(super) fn path_d(points: &[P]) -> String {
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
pub(super) fn shape_element(svg: &mut String, view: &View, shape: &Shape, attrs: &str) {
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
pub(super) fn arrowhead(svg: &mut String, at: P, direction: P, colour: &str) {
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
pub(super) fn label(svg: &mut String, at: P, text: &str, attrs: &str) {
    w!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" stroke="white" stroke-width="3.5" stroke-linejoin="round" paint-order="stroke" {attrs}>{}</text>"#,
        at.0,
        at.1,
        esc(text)
    );
}

/// A "nice" scale bar length (1, 2 or 5 times a power of ten) not above `max_m`.
pub(super) fn nice_length(max_m: f64) -> f64 {
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

pub(super) fn metres_text(m: f64) -> String {
    if m >= 1000.0 {
        format!("{} km", m / 1000.0)
    } else {
        format!("{m} m")
    }
}

/// Word-wraps `text` to lines of at most `width` characters (longer words are cut).
pub(super) fn wrap(text: &str, width: usize) -> Vec<String> {
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
