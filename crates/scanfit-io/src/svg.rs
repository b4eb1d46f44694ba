//! Pictures of fitted curves, as SVG and as PNG ([`curve_panels_png`]): one panel per curve with the data points
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
    /// The text under the title (figures, or the error), wrapped onto as
    /// many lines as it needs: the header of every panel grows to the
    /// longest subtitle's lines, and no text is cut.
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

/// Height of a panel's header (title and a two-line subtitle); longer
/// subtitles grow it by a line height per line ([`Header`]).
const HEADER: f64 = 52.0;
const MARGIN: f64 = 14.0;

/// The header shared by the panels of a figure: every subtitle wrapped at
/// `per_line` characters, and the header's height, grown from [`HEADER`]
/// (two subtitle lines) by `line` pixels per line of the longest subtitle
/// beyond two. The panels grow by the same amount, so the plot area keeps
/// its size.
struct Header {
    lines: Vec<Vec<String>>,
    height: f64,
}

impl Header {
    fn of(panels: &[Panel], per_line: usize, line: f64) -> Self {
        let lines: Vec<Vec<String>> = panels.iter().map(|p| wrap(&p.subtitle, per_line)).collect();
        let most = lines.iter().map(Vec::len).max().unwrap_or(0);
        Self {
            lines,
            height: HEADER + line * most.saturating_sub(2) as f64,
        }
    }

    /// A panel's size with the header's growth added.
    fn panel(&self, size: PanelSize) -> PanelSize {
        PanelSize {
            width: size.width,
            height: size.height + self.height - HEADER,
        }
    }
}

/// Characters per subtitle line in the SVG (about 6 px per character at
/// 10.5 px) and in the PNG (the 8 px bitmap font).
fn per_line(size: PanelSize, char_width: f64) -> usize {
    (((size.width - 20.0) / char_width) as usize).max(8)
}

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
    let header = Header::of(panels, per_line(size, 6.0), 13.0);
    let size = header.panel(size);
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
        draw_panel(&mut s, panel, (x0, y0), k, size, &header);
    }
    s.push_str("</svg>\n");
    s
}

/// Pixel coordinates of a panel's data points, curve samples and control
/// points: projected into the data's plane, and the view fitted to the data
/// and the curve (at most the data box grown by 60% on each side, so that a
/// wild curve does not shrink the data to a dot). Shared by SVG and PNG.
pub(crate) struct PanelLayout {
    pub(crate) data: Vec<(f64, f64)>,
    pub(crate) samples: Vec<(f64, f64)>,
    pub(crate) ctrl: Vec<(f64, f64)>,
}

pub(crate) fn panel_layout(
    panel: &Panel,
    (x0, y0): (f64, f64),
    size: PanelSize,
    header: f64,
) -> PanelLayout {
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
    let (aw, ah) = (panel_w - 2.0 * MARGIN, panel_h - header - 2.0 * MARGIN);
    let scale = (aw / vw).min(ah / vh);
    let (ox, oy) = (
        x0 + MARGIN + (aw - vw * scale) / 2.0,
        y0 + header + MARGIN + (ah - vh * scale) / 2.0,
    );
    let map = |p: &(f64, f64)| (ox + (p.0 - view.0) * scale, oy + (view.3 - p.1) * scale);
    PanelLayout {
        data: data.iter().map(map).collect(),
        samples: samples.iter().map(map).collect(),
        ctrl: ctrl.iter().map(map).collect(),
    }
}

fn draw_panel(
    s: &mut String,
    panel: &Panel,
    (x0, y0): (f64, f64),
    id: usize,
    size: PanelSize,
    header: &Header,
) {
    let (panel_w, panel_h) = (size.width, size.height);
    let PanelLayout {
        data,
        samples,
        ctrl,
    } = panel_layout(panel, (x0, y0), size, header.height);
    let map = |p: &(f64, f64)| *p;

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
    for (k, line) in header.lines[id].iter().enumerate() {
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
        y0 + header.height,
        panel_w - 6.0,
        panel_h - header.height - 3.0
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

/// Splits `s` at spaces into lines of at most `width` characters (a word
/// longer than that is broken into pieces of `width`); every word is kept.
fn wrap(s: &str, width: usize) -> Vec<String> {
    let width = width.max(1);
    let mut lines: Vec<String> = Vec::new();
    let mut cur = String::new();
    for word in s.split_whitespace() {
        let chars: Vec<char> = word.chars().collect();
        for piece in chars.chunks(width) {
            let n = cur.chars().count();
            if n > 0 && n + 1 + piece.len() > width {
                lines.push(std::mem::take(&mut cur));
            }
            if !cur.is_empty() {
                cur.push(' ');
            }
            cur.extend(piece);
        }
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The same panels as [`curve_panels`], rasterised to a PNG (bitmap font, no
/// system fonts): data points as red squares, the curve in blue, the control
/// polygon dashed grey with hollow circles.
pub fn curve_panels_png(
    panels: &[Panel],
    columns: usize,
    title: &str,
    size: PanelSize,
) -> crate::Result<Vec<u8>> {
    use crate::render::{draw_text, encode_png, Canvas};
    // 11 px per line of the bitmap font; its two lines fit in HEADER
    let header = Header::of(panels, per_line(size, 8.0), 11.0);
    let size = header.panel(size);
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    let top = if title.is_empty() { 0.0 } else { 30.0 };
    let (w, h) = (
        (size.width * columns as f64) as usize,
        (size.height * rows as f64 + top) as usize,
    );
    let mut img = vec![255u8; w * h * 3];
    let put = |img: &mut [u8], x: f64, y: f64, c: [u8; 3]| {
        let (xi, yi) = (x.round() as isize, y.round() as isize);
        if xi >= 0 && yi >= 0 && (xi as usize) < w && (yi as usize) < h {
            let o = (yi as usize * w + xi as usize) * 3;
            img[o..o + 3].copy_from_slice(&c);
        }
    };
    // a line of the given width; `dash` > 0 leaves gaps of that length
    let line = |img: &mut [u8], a: (f64, f64), b: (f64, f64), c: [u8; 3], width: f64, dash: f64| {
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let steps = (len * 2.0).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            if dash > 0.0 && ((t * len) / dash) as usize % 2 == 1 {
                continue;
            }
            let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            let r = (width / 2.0).floor() as isize;
            for dx in -r..=r {
                for dy in -r..=r {
                    put(img, x + dx as f64, y + dy as f64, c);
                }
            }
        }
    };
    for (k, panel) in panels.iter().enumerate() {
        let (x0, y0) = (
            (k % columns) as f64 * size.width,
            top + (k / columns) as f64 * size.height,
        );
        // clip to the panel: draw into a panel-sized view of the layout
        let l = panel_layout(panel, (x0, y0), size, header.height);
        let inside = |p: &(f64, f64)| {
            p.0 >= x0 + 3.0
                && p.0 <= x0 + size.width - 3.0
                && p.1 >= y0 + header.height
                && p.1 <= y0 + size.height - 3.0
        };
        let grey = [140, 140, 140];
        for s in l.ctrl.windows(2) {
            if inside(&s[0]) && inside(&s[1]) {
                line(&mut img, s[0], s[1], grey, 1.0, 4.0);
            }
        }
        for c in l.ctrl.iter().filter(|p| inside(p)) {
            for a in 0..24 {
                let t = a as f64 / 24.0 * std::f64::consts::TAU;
                put(&mut img, c.0 + 3.0 * t.cos(), c.1 + 3.0 * t.sin(), grey);
            }
        }
        for s in l.samples.windows(2) {
            if inside(&s[0]) && inside(&s[1]) {
                line(&mut img, s[0], s[1], [31, 95, 191], 2.0, 0.0);
            }
        }
        let side = (6.0 * (20.0 / l.data.len().max(1) as f64).sqrt()).clamp(2.0, 6.0);
        for p in &l.data {
            for dx in 0..side as usize {
                for dy in 0..side as usize {
                    put(
                        &mut img,
                        p.0 - side / 2.0 + dx as f64,
                        p.1 - side / 2.0 + dy as f64,
                        [209, 55, 43],
                    );
                }
            }
        }
        // frame, title, caption
        for t in 0..(size.width as usize - 4) {
            put(&mut img, x0 + 2.0 + t as f64, y0 + 2.0, [204, 204, 204]);
            put(
                &mut img,
                x0 + 2.0 + t as f64,
                y0 + size.height - 2.0,
                [204, 204, 204],
            );
        }
        for t in 0..(size.height as usize - 4) {
            put(&mut img, x0 + 2.0, y0 + 2.0 + t as f64, [204, 204, 204]);
            put(
                &mut img,
                x0 + size.width - 2.0,
                y0 + 2.0 + t as f64,
                [204, 204, 204],
            );
        }
        let mut canvas = Canvas {
            rgb: &mut img,
            width: w,
            height: h,
        };
        let (tx, ty) = (x0 as usize + 10, y0 as usize + 8);
        draw_text(&mut canvas, tx, ty, &panel.title, 1, [0, 0, 0]);
        draw_text(&mut canvas, tx + 1, ty, &panel.title, 1, [0, 0, 0]); // bold
        let colour = if panel.curve.is_some() {
            [50, 50, 50]
        } else {
            [180, 0, 0]
        };
        for (i, s) in header.lines[k].iter().enumerate() {
            draw_text(&mut canvas, tx, ty + 14 + 11 * i, s, 1, colour);
        }
    }
    if !title.is_empty() {
        let mut canvas = Canvas {
            rgb: &mut img,
            width: w,
            height: h,
        };
        let x = (w / 2).saturating_sub(title.chars().count() * 8 / 2);
        draw_text(&mut canvas, x, 10, title, 1, [0, 0, 0]);
        draw_text(&mut canvas, x + 1, 10, title, 1, [0, 0, 0]);
    }
    encode_png(&img, w as u32, h as u32)
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
    fn wrapping_keeps_every_word() {
        assert_eq!(wrap("aa bb cc", 5), vec!["aa bb", "cc"]);
        assert_eq!(wrap("aa bb cc dd ee", 5), vec!["aa bb", "cc dd", "ee"]);
        // a word longer than a line is broken, not cut
        assert_eq!(wrap("x abcdefgh y", 4), vec!["x", "abcd", "efgh", "y"]);
        assert!(wrap("", 5).is_empty());
    }

    /// The text of every subtitle `<text>` element of an SVG, in order.
    fn subtitle_text(svg: &str) -> String {
        svg.lines()
            .filter(|l| l.contains(r#"font-size="10.5""#))
            .map(|l| l.split('>').nth(1).unwrap().split('<').next().unwrap())
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn long_subtitles_are_wrapped_whole_and_the_header_grows() {
        let pts = vec![Point3::new(0., 0., 0.), Point3::new(1., 1., 0.)];
        let long = "error: exponential parameterization gives coincident parameters at points 3 and 4 (u = 0.49999999999999994 then 0.5); the interpolation matrix would be singular, choose another method (e.g. centripetal)";
        let panels = vec![
            Panel {
                title: "exponential".into(),
                subtitle: long.into(),
                points: &pts,
                curve: None,
            },
            Panel {
                title: "uniform".into(),
                subtitle: "loops 0".into(),
                points: &pts,
                curve: None,
            },
        ];
        let svg = curve_panels(&panels, 2, "", PanelSize::GRID);
        // every character of both subtitles is in the picture, nothing cut
        assert_eq!(subtitle_text(&svg), format!("{long} loops 0"));
        assert!(!svg.contains('…'));
        // 56 characters a line: the long one needs 4 lines, so the panels
        // grow by two 13 px lines and the plot area keeps its height
        let lines = wrap(long, per_line(PanelSize::GRID, 6.0));
        assert_eq!(lines.len(), 4);
        assert!(lines.iter().all(|l| l.chars().count() <= 56));
        assert!(svg.contains(r#"height="336""#), "{}", &svg[..200]);
        // the last subtitle line sits above the clipped plot area
        let last_y = 32.0 + 13.0 * 3.0;
        assert!(svg.contains(&format!(r#"y="{last_y:.1}" font-size="10.5""#)));
        assert!(svg.contains(r#"<rect x="3.0" y="78.0""#));
        // a short one keeps the two-line header of 52 px
        let svg = curve_panels(&panels[1..], 1, "", PanelSize::GRID);
        assert!(svg.contains(r#"height="310""#));
        // the PNG grows the same way (8 px characters, 11 px lines: 42 a
        // line, 5 lines, 3 more than two) and draws all of it
        let png = curve_panels_png(&panels, 2, "", PanelSize::GRID).unwrap();
        let r = png::Decoder::new(std::io::Cursor::new(png))
            .read_info()
            .unwrap();
        assert_eq!(wrap(long, per_line(PanelSize::GRID, 8.0)).len(), 5);
        assert_eq!((r.info().width, r.info().height), (720, 310 + 33));
    }
}
