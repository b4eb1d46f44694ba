//! SVG pictures of fitted curves: one panel per curve with the data points
//! (squares), the curve, and its control polygon (circles, dashed), in the
//! style of the curve paper's figures 11-21.
//!
//! Points are drawn in the data's own plane: x/y when the data are flat in z
//! (the common case of planar sections), otherwise the best-fit plane's two
//! principal directions.

use std::fmt::Write;

use scanfit::bspline::Curve;
use scanfit::{Point3, Vector3};

/// One panel of a comparison figure.
#[derive(Debug, Clone)]
pub struct Panel<'a> {
    /// Title (the method name).
    pub title: String,
    /// One line under the title (figures, or the error).
    pub subtitle: String,
    /// The data points.
    pub points: &'a [Point3],
    /// The fitted curve, if the fit succeeded.
    pub curve: Option<&'a Curve>,
}

/// Orthographic projection onto a plane through the data.
#[derive(Debug, Clone, Copy)]
struct Projection {
    origin: Vector3,
    e1: Vector3,
    e2: Vector3,
}

impl Projection {
    fn fit(points: &[Point3]) -> Self {
        let n = points.len().max(1) as f64;
        let c = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
        let (lo, hi) = points.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
        );
        let ext = hi - lo;
        if ext.z <= 1e-9 * ext.x.max(ext.y) || points.len() < 3 {
            return Self {
                origin: c,
                e1: Vector3::x(),
                e2: Vector3::y(),
            };
        }
        let mut cov = nalgebra::Matrix3::zeros();
        for p in points {
            let d = p.coords - c;
            cov += d * d.transpose();
        }
        let eig = nalgebra::SymmetricEigen::new(cov);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        Self {
            origin: c,
            e1: eig.eigenvectors.column(idx[0]).into(),
            e2: eig.eigenvectors.column(idx[1]).into(),
        }
    }

    fn apply(&self, p: &Point3) -> (f64, f64) {
        let d = p.coords - self.origin;
        (d.dot(&self.e1), d.dot(&self.e2))
    }
}

const HEADER: f64 = 52.0;
const MARGIN: f64 = 14.0;

/// Size of one panel in pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelSize {
    /// width
    pub width: f64,
    /// height
    pub height: f64,
}

impl PanelSize {
    /// Small panels for a grid (360 x 310).
    pub const GRID: PanelSize = PanelSize {
        width: 360.0,
        height: 310.0,
    };
    /// One large picture (900 x 600).
    pub const SINGLE: PanelSize = PanelSize {
        width: 900.0,
        height: 600.0,
    };
}

/// An SVG document with the panels in a grid of `columns` columns.
pub fn curve_panels(panels: &[Panel], columns: usize, title: &str, size: PanelSize) -> String {
    let (panel_w, panel_h) = (size.width, size.height);
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns);
    let top = if title.is_empty() { 0.0 } else { 30.0 };
    let (w, h) = (panel_w * columns as f64, panel_h * rows as f64 + top);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    if !title.is_empty() {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="21" font-size="16" text-anchor="middle" font-weight="bold">{}</text>"#,
            w / 2.0,
            escape(title)
        );
    }
    for (k, panel) in panels.iter().enumerate() {
        let (col, row) = (k % columns, k / columns);
        let (x0, y0) = (col as f64 * panel_w, top + row as f64 * panel_h);
        draw_panel(&mut s, panel, x0, y0, k, size);
    }
    s.push_str("</svg>\n");
    s
}

fn draw_panel(s: &mut String, panel: &Panel, x0: f64, y0: f64, id: usize, size: PanelSize) {
    let (panel_w, panel_h) = (size.width, size.height);
    let proj = Projection::fit(panel.points);
    let data: Vec<(f64, f64)> = panel.points.iter().map(|p| proj.apply(p)).collect();
    let samples: Vec<(f64, f64)> = panel
        .curve
        .map(|c| {
            let (a, b) = c.domain();
            let n = 60 * c.knots().breakpoints().len().max(2);
            (0..=n)
                .map(|k| proj.apply(&c.point(a + (b - a) * k as f64 / n as f64)))
                .collect()
        })
        .unwrap_or_default();
    let ctrl: Vec<(f64, f64)> = panel
        .curve
        .map(|c| c.control_points().iter().map(|p| proj.apply(p)).collect())
        .unwrap_or_default();
    // view: the data and the curve, but at most the data box grown by 60% on
    // each side, so that a wild curve does not shrink the data to a dot
    let bbox = |pts: &[(f64, f64)]| {
        pts.iter().fold(
            (
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ),
            |b, p| (b.0.min(p.0), b.1.min(p.1), b.2.max(p.0), b.3.max(p.1)),
        )
    };
    let d = bbox(&data);
    let size = (d.2 - d.0).max(d.3 - d.1).max(1e-12);
    let c = bbox(&samples);
    let grow = 0.6 * size;
    let view = if samples.is_empty() {
        d
    } else {
        (
            c.0.max(d.0 - grow).min(d.0),
            c.1.max(d.1 - grow).min(d.1),
            c.2.min(d.2 + grow).max(d.2),
            c.3.min(d.3 + grow).max(d.3),
        )
    };
    let (vw, vh) = ((view.2 - view.0).max(1e-12), (view.3 - view.1).max(1e-12));
    let (aw, ah) = (panel_w - 2.0 * MARGIN, panel_h - HEADER - 2.0 * MARGIN);
    let scale = (aw / vw).min(ah / vh);
    let (ox, oy) = (
        x0 + MARGIN + (aw - vw * scale) / 2.0,
        y0 + HEADER + MARGIN + (ah - vh * scale) / 2.0,
    );
    let map = |p: &(f64, f64)| (ox + (p.0 - view.0) * scale, oy + (view.3 - p.1) * scale);

    let _ = writeln!(
        s,
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#ccc"/>"##,
        x0 + 2.0,
        y0 + 2.0,
        panel_w - 4.0,
        panel_h - 4.0
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" font-size="14" font-weight="bold">{}</text>"#,
        x0 + 10.0,
        y0 + 18.0,
        escape(&panel.title)
    );
    let colour = if panel.curve.is_some() {
        "#333"
    } else {
        "#b00"
    };
    // about 6 px per character at 10.5 px
    let per_line = ((panel_w - 20.0) / 6.0) as usize;
    for (k, line) in wrap(&panel.subtitle, per_line, 2).iter().enumerate() {
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="10.5" fill="{colour}">{}</text>"#,
            x0 + 10.0,
            y0 + 32.0 + 13.0 * k as f64,
            escape(line)
        );
    }
    let _ = writeln!(
        s,
        r#"<clipPath id="clip{id}"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}"/></clipPath><g clip-path="url(#clip{id})">"#,
        x0 + 3.0,
        y0 + HEADER,
        panel_w - 6.0,
        panel_h - HEADER - 3.0
    );
    if !ctrl.is_empty() {
        let _ = writeln!(
            s,
            r##"<polyline fill="none" stroke="#8a8a8a" stroke-width="0.8" stroke-dasharray="4 3" points="{}"/>"##,
            path(&ctrl, &map)
        );
        for p in &ctrl {
            let (x, y) = map(p);
            let _ = writeln!(
                s,
                r##"<circle cx="{x:.2}" cy="{y:.2}" r="3" fill="white" stroke="#8a8a8a"/>"##
            );
        }
    }
    if !samples.is_empty() {
        let _ = writeln!(
            s,
            r##"<polyline fill="none" stroke="#1f5fbf" stroke-width="1.6" points="{}"/>"##,
            path(&samples, &map)
        );
    }
    // markers shrink when the data are dense, so the curve stays visible
    let side = (6.0 * (20.0 / data.len().max(1) as f64).sqrt()).clamp(2.0, 6.0);
    for p in &data {
        let (x, y) = map(p);
        let _ = writeln!(
            s,
            r##"<rect x="{:.2}" y="{:.2}" width="{side:.1}" height="{side:.1}" fill="#d1372b"/>"##,
            x - side / 2.0,
            y - side / 2.0
        );
    }
    s.push_str("</g>\n");
}

fn path(pts: &[(f64, f64)], map: &impl Fn(&(f64, f64)) -> (f64, f64)) -> String {
    let mut out = String::with_capacity(pts.len() * 16);
    for p in pts {
        let (x, y) = map(p);
        let _ = write!(out, "{x:.2},{y:.2} ");
    }
    out
}

/// Splits `s` at spaces into at most `max_lines` lines of about `width`
/// characters; the last line ends in an ellipsis when text is left over.
fn wrap(s: &str, width: usize, max_lines: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut cur = String::new();
    for word in s.split_whitespace() {
        if !cur.is_empty() && cur.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut cur));
        }
        if !cur.is_empty() {
            cur.push(' ');
        }
        cur.push_str(word);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    if lines.len() > max_lines {
        lines.truncate(max_lines);
        let last = &mut lines[max_lines - 1];
        let keep: String = last.chars().take(width.saturating_sub(1)).collect();
        *last = keep + "…";
    }
    lines
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use scanfit::bspline::KnotVector;

    #[test]
    fn panels_contain_every_element() {
        let pts = vec![
            Point3::new(0., 0., 0.),
            Point3::new(1., 1., 0.),
            Point3::new(2., 0., 0.),
        ];
        let kv = KnotVector::uniform_clamped(2, 3).unwrap();
        let c = Curve::new(kv, pts.clone()).unwrap();
        let panels = vec![
            Panel {
                title: "a<b".into(),
                subtitle: "ok".into(),
                points: &pts,
                curve: Some(&c),
            },
            Panel {
                title: "b".into(),
                subtitle: "error".into(),
                points: &pts,
                curve: None,
            },
        ];
        let svg = curve_panels(&panels, 2, "t", PanelSize::GRID);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("a&lt;b"));
        assert_eq!(svg.matches("<polyline").count(), 2); // one curve, one polygon
        assert_eq!(svg.matches("<circle").count(), 3);
        assert_eq!(svg.matches(r##"fill="#d1372b""##).count(), 6);
        // every coordinate lies inside the document
        for cap in svg.split("cx=\"").skip(1) {
            let x: f64 = cap.split('"').next().unwrap().parse().unwrap();
            assert!((0.0..=720.0).contains(&x));
        }
    }

    #[test]
    fn wrapping() {
        assert_eq!(wrap("aa bb cc", 5, 2), vec!["aa bb", "cc"]);
        assert_eq!(wrap("aa bb cc dd ee", 5, 2), vec!["aa bb", "cc d…"]);
    }
}
