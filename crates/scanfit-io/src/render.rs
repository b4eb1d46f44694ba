//! Software rendering of surfaces to PNG: no GPU, no window, no system fonts.
//!
//! An orthographic camera looks at the object from an azimuth and elevation
//! (z up) and fits it into the image; triangles are rasterised with a depth
//! buffer, shaded (two-sided Lambert plus ambient) and coloured by height,
//! by a per-vertex scalar (viridis, with a colour bar) or by per-vertex RGB
//! colours (categories such as patches), with darker iso-parameter lines; input
//! points can be drawn on top where they are not hidden by the surface.

use scanfit::bspline::Mesh;
use scanfit::{Point3, Vector3};

use crate::{Error, Result};

/// What the surface colour shows.
#[derive(Debug, Clone, Copy)]
pub enum Colouring<'a> {
    /// The height (world z), low = dark blue, high = yellow.
    Height,
    /// One value per mesh vertex over `range` (e.g. deviation).
    Scalar {
        /// values per vertex
        values: &'a [f64],
        /// value range mapped onto the colour map
        range: (f64, f64),
    },
    /// One colour per mesh vertex (e.g. one per patch), interpolated across
    /// each triangle; no colour bar, since the colours are categories, not
    /// a scale.
    Rgb(&'a [[u8; 3]]),
}

/// Camera and image settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels (default 1200).
    pub width: u32,
    /// Image height in pixels (default 900).
    pub height: u32,
    /// Camera azimuth around z, degrees (default -60).
    pub azimuth: f64,
    /// Camera elevation above the xy plane, degrees (default 35).
    pub elevation: f64,
    /// Iso-parameter lines per direction (default 10; 0 = none).
    pub iso_lines: usize,
    /// Lines of text drawn at the top left (title, figures).
    pub legend: Vec<String>,
    /// Vertical exaggeration: z is multiplied by this before drawing (default 1;
    /// see [`auto_exaggeration`] for flat data such as terrain).
    pub z_scale: f64,
}

/// A vertical exaggeration that makes the relief of flat data visible: the
/// factor that brings the z range to 20% of the larger horizontal extent,
/// rounded to one significant digit; 1 when the data are not flat.
pub fn auto_exaggeration(points: &[Point3]) -> f64 {
    let (lo, hi) = points.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    let ext = hi - lo;
    let horizontal = ext.x.max(ext.y);
    if ext.z.is_nan() || ext.z <= 0.0 || ext.z >= 0.1 * horizontal {
        return 1.0;
    }
    let f = 0.2 * horizontal / ext.z;
    let mag = 10f64.powf(f.log10().floor());
    (f / mag).round() * mag
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 1200,
            height: 900,
            azimuth: -60.0,
            elevation: 35.0,
            iso_lines: 10,
            legend: Vec::new(),
            z_scale: 1.0,
        }
    }
}

/// Renders `mesh` (and `points` on top) and returns the PNG bytes.
pub fn render_png(
    mesh: &Mesh,
    points: Option<&[Point3]>,
    colouring: Colouring,
    opts: &RenderOptions,
) -> Result<Vec<u8>> {
    let img = render_rgb(mesh, points, colouring, opts);
    encode_png(&img, opts.width, opts.height)
}

/// Renders a point cloud (each point a small square, coloured by height,
/// nearer points on top) and returns the PNG bytes.
pub fn render_points_png(points: &[Point3], opts: &RenderOptions) -> Result<Vec<u8>> {
    render_scene_png(
        &PointScene {
            points,
            ..Default::default()
        },
        opts,
    )
}

/// A polyline drawn over a point picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    /// Vertices, in order.
    pub points: Vec<Point3>,
    /// Line colour.
    pub rgb: [u8; 3],
    /// Joins the last vertex to the first.
    pub closed: bool,
}

/// A labelled marker drawn over a point picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Where.
    pub at: Point3,
    /// Fill colour.
    pub rgb: [u8; 3],
    /// Text written beside it (may be empty).
    pub label: String,
}

/// What [`render_scene_png`] draws: points (by height or in given colours),
/// then polylines and markers on top of everything.
#[derive(Debug, Clone, Default)]
pub struct PointScene<'a> {
    /// The points.
    pub points: &'a [Point3],
    /// One colour per point; `None` colours by height (viridis).
    pub colours: Option<&'a [[u8; 3]]>,
    /// Lines over the points (boundaries, curves).
    pub polylines: Vec<Polyline>,
    /// Markers over the lines (corners, viewpoints).
    pub markers: Vec<Marker>,
}

/// Renders a [`PointScene`] with an orthographic camera that fits points,
/// lines and markers into the frame; returns the PNG bytes.
pub fn render_scene_png(scene: &PointScene, opts: &RenderOptions) -> Result<Vec<u8>> {
    let (w, h) = (opts.width.max(16) as usize, opts.height.max(16) as usize);
    if let Some(c) = scene.colours {
        if c.len() != scene.points.len() {
            return Err(Error::Invalid {
                path: "<png>".into(),
                message: format!(
                    "{} colours for {} points; give one colour per point",
                    c.len(),
                    scene.points.len()
                ),
            });
        }
    }
    let (az, el) = (opts.azimuth.to_radians(), opts.elevation.to_radians());
    let d = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let right = Vector3::new(-az.sin(), az.cos(), 0.0);
    let up = d.cross(&right);
    let zs = if opts.z_scale > 0.0 && opts.z_scale.is_finite() {
        opts.z_scale
    } else {
        1.0
    };
    let view = |p: &Point3| {
        let c = Vector3::new(p.x, p.y, p.z * zs);
        (c.dot(&right), c.dot(&up), c.dot(&d))
    };
    let sp: Vec<(f64, f64, f64)> = scene.points.iter().map(view).collect();
    let mut img = vec![255u8; w * h * 3];
    let extra = scene
        .polylines
        .iter()
        .flat_map(|l| l.points.iter())
        .chain(scene.markers.iter().map(|m| &m.at))
        .map(view);
    let all: Vec<(f64, f64, f64)> = sp.iter().copied().chain(extra).collect();
    if all.is_empty() {
        return encode_png(&img, w as u32, h as u32);
    }
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y, _) in &all {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let (z0, z1) = scene
        .points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.z), b.max(p.z))
        });
    let top = 14.0 * opts.legend.len() as f64;
    let usable_h = h as f64 - top;
    let scale =
        (w as f64 * 0.9 / (x1 - x0).max(1e-300)).min(usable_h * 0.9 / (y1 - y0).max(1e-300));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let pixel = |x: f64, y: f64| {
        (
            (w as f64 / 2.0 + (x - cx) * scale) as isize,
            (top + usable_h / 2.0 - (y - cy) * scale) as isize,
        )
    };
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    // splat size: points cover the picture of a surface (about half of the
    // projected box, twice over for the front of a closed body), so nearer
    // points hide farther ones
    let area = (x1 - x0) * (y1 - y0) * scale * scale;
    let spacing_px = (2.0 * area / sp.len().max(1) as f64).sqrt();
    let r = (0.5 * spacing_px).round().clamp(0.0, 4.0) as isize;
    // visibility in two passes: the depth of the front surface with wider
    // splats (so it has no holes), then the colours of the points within a
    // few point spacings of that front (the back of a closed body stays hidden)
    let wide = (2 * r + 2).min(10);
    let tolerance = (2.0 * (wide as f64 + 1.0) + 3.0 * spacing_px.max(1.0)) / scale;
    let footprint = |px: isize, py: isize, r: isize| {
        (-r..=r).flat_map(move |dy| (-r..=r).map(move |dx| (px + dx, py + dy)))
    };
    let inside = |qx: isize, qy: isize| qx >= 0 && qy >= 0 && qx < w as isize && qy < h as isize;
    for &(x, y, z) in &sp {
        let (px, py) = pixel(x, y);
        for (qx, qy) in footprint(px, py, wide) {
            if inside(qx, qy) {
                let k = qy as usize * w + qx as usize;
                depth[k] = depth[k].max(z);
            }
        }
    }
    let mut drawn = vec![f64::NEG_INFINITY; w * h];
    for (i, &(x, y, z)) in sp.iter().enumerate() {
        let (px, py) = pixel(x, y);
        let col = match scene.colours {
            Some(c) => c[i],
            None => viridis(((scene.points[i].z - z0) / (z1 - z0).max(1e-300)).clamp(0.0, 1.0))
                .map(|c| (c * 255.0).round() as u8),
        };
        for (qx, qy) in footprint(px, py, r) {
            if !inside(qx, qy) {
                continue;
            }
            let k = qy as usize * w + qx as usize;
            if z >= depth[k] - tolerance && z > drawn[k] {
                drawn[k] = z;
                img[k * 3..k * 3 + 3].copy_from_slice(&col);
            }
        }
    }
    draw_overlay(&mut img, w, h, &scene.polylines, &scene.markers, |p| {
        let (x, y, _) = view(p);
        let (px, py) = pixel(x, y);
        (px as f64, py as f64)
    });
    let mut canvas = Canvas {
        rgb: &mut img,
        width: w,
        height: h,
    };
    for (k, line) in opts.legend.iter().enumerate() {
        draw_text(&mut canvas, 8, 6 + 14 * k, line, 1, [20, 20, 20]);
    }
    encode_png(&img, w as u32, h as u32)
}

/// Draws `lines` (2-pixel wide) and labelled `markers` over an image, with
/// `to_pixel` mapping a world point to pixel coordinates.
fn draw_overlay(
    img: &mut [u8],
    w: usize,
    h: usize,
    lines: &[Polyline],
    markers: &[Marker],
    to_pixel: impl Fn(&Point3) -> (f64, f64),
) {
    let put = |x: isize, y: isize, rgb: [u8; 3], img: &mut [u8]| {
        if x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h {
            let k = (y as usize * w + x as usize) * 3;
            img[k..k + 3].copy_from_slice(&rgb);
        }
    };
    for line in lines {
        let n = line.points.len();
        let segments = if line.closed { n } else { n.saturating_sub(1) };
        for s in 0..segments {
            let (pa, pb) = (
                to_pixel(&line.points[s]),
                to_pixel(&line.points[(s + 1) % n]),
            );
            let steps = ((pb.0 - pa.0).abs().max((pb.1 - pa.1).abs()).ceil() as usize).max(1);
            for t in 0..=steps {
                let f = t as f64 / steps as f64;
                let x = (pa.0 + f * (pb.0 - pa.0)).round() as isize;
                let y = (pa.1 + f * (pb.1 - pa.1)).round() as isize;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    put(x + dx, y + dy, line.rgb, img);
                }
            }
        }
    }
    for m in markers {
        let (x, y) = to_pixel(&m.at);
        let (px, py) = (x as isize, y as isize);
        for dy in -6..=6isize {
            for dx in -6..=6isize {
                let edge = dx.abs() == 6 || dy.abs() == 6;
                put(px + dx, py + dy, if edge { [0, 0, 0] } else { m.rgb }, img);
            }
        }
        if !m.label.is_empty() {
            let mut canvas = Canvas {
                rgb: img,
                width: w,
                height: h,
            };
            draw_text(
                &mut canvas,
                (px + 10).max(0) as usize,
                (py - 16).max(0) as usize,
                &m.label,
                2,
                [0, 0, 0],
            );
        }
    }
}

/// Camera angles `(azimuth, elevation)` in degrees that look along `-n`,
/// i.e. from the side `n` points to (z up): a top view of a patch with
/// normal `n`.
pub fn angles_facing(n: &Vector3) -> (f64, f64) {
    let len = n.norm();
    if !(len > 0.0 && len.is_finite()) {
        return (-60.0, 35.0);
    }
    let n = n / len;
    let el = n.z.clamp(-1.0, 1.0).asin().to_degrees();
    let az = if n.x.abs() + n.y.abs() < 1e-12 {
        -90.0
    } else {
        n.y.atan2(n.x).to_degrees()
    };
    (az, el)
}

/// Encodes an RGB8 image.
pub fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    let err = |e: png::EncodingError| Error::Invalid {
        path: "<png>".into(),
        message: format!("PNG encoding failed: {e}"),
    };
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(err)?;
        w.write_image_data(rgb).map_err(err)?;
    }
    Ok(out)
}

/// Renders `mesh` coloured by `colouring`, `points` (red dots where not
/// hidden), then `lines` and `markers` on top (boundary curves, corners), and
/// returns the PNG bytes.
pub fn render_surface_scene_png(
    mesh: &Mesh,
    points: Option<&[Point3]>,
    colouring: Colouring,
    lines: &[Polyline],
    markers: &[Marker],
    opts: &RenderOptions,
) -> Result<Vec<u8>> {
    let img = render_rgb_with(mesh, points, colouring, lines, markers, opts);
    encode_png(&img, opts.width, opts.height)
}

/// Renders into an RGB8 buffer of `width x height` (row-major, top row first).
pub fn render_rgb(
    mesh: &Mesh,
    points: Option<&[Point3]>,
    colouring: Colouring,
    opts: &RenderOptions,
) -> Vec<u8> {
    render_rgb_with(mesh, points, colouring, &[], &[], opts)
}

fn render_rgb_with(
    mesh: &Mesh,
    points: Option<&[Point3]>,
    colouring: Colouring,
    lines: &[Polyline],
    markers: &[Marker],
    opts: &RenderOptions,
) -> Vec<u8> {
    let (w, h) = (opts.width.max(16) as usize, opts.height.max(16) as usize);
    let (az, el) = (opts.azimuth.to_radians(), opts.elevation.to_radians());
    // towards the camera, right, up
    let d = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let right = Vector3::new(-az.sin(), az.cos(), 0.0);
    let up = d.cross(&right);
    let light = (d + 0.4 * up - 0.3 * right).normalize();
    let zs = if opts.z_scale > 0.0 && opts.z_scale.is_finite() {
        opts.z_scale
    } else {
        1.0
    };
    let proj = |p: &Point3| {
        let c = Vector3::new(p.x, p.y, p.z * zs);
        (c.dot(&right), c.dot(&up), c.dot(&d))
    };
    let sv: Vec<(f64, f64, f64)> = mesh.vertices.iter().map(proj).collect();
    let sp: Vec<(f64, f64, f64)> = points.unwrap_or(&[]).iter().map(proj).collect();
    let overlay: Vec<(f64, f64, f64)> = lines
        .iter()
        .flat_map(|l| l.points.iter())
        .chain(markers.iter().map(|m| &m.at))
        .map(proj)
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let (mut z0, mut z1) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y, z) in sv.iter().chain(&sp).chain(&overlay) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
        z0 = z0.min(z);
        z1 = z1.max(z);
    }
    let mut img = vec![255u8; w * h * 3];
    if !(x1 > x0 || y1 > y0) {
        return img;
    }
    let margin = 0.05;
    let scale = ((w as f64) * (1.0 - 2.0 * margin) / (x1 - x0).max(1e-300))
        .min((h as f64) * (1.0 - 2.0 * margin) / (y1 - y0).max(1e-300));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let to_px = |x: f64, y: f64| {
        (
            w as f64 / 2.0 + (x - cx) * scale,
            h as f64 / 2.0 - (y - cy) * scale,
        )
    };
    let heights: Vec<f64> = mesh.vertices.iter().map(|p| p.z).collect();
    let (vals, (lo, hi)) = match colouring {
        Colouring::Height => {
            let lo = heights.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            (heights.as_slice(), (lo, hi))
        }
        Colouring::Scalar { values, range } => (values, range),
        Colouring::Rgb(_) => (heights.as_slice(), (0.0, 1.0)),
    };
    let rgb_of = |k: usize| match colouring {
        Colouring::Rgb(c) => c.get(k).map(|c| c.map(|x| x as f64 / 255.0)),
        _ => None,
    };
    let span = if hi > lo { hi - lo } else { 1.0 };
    let ((u0, u1), (v0, v1)) = mesh.uv.iter().fold(
        (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        ),
        |((a, b), (c, e)), t| ((a.min(t[0]), b.max(t[0])), (c.min(t[1]), e.max(t[1]))),
    );
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|k| k as usize);
        let (pa, pb, pc) = (
            to_px(sv[a].0, sv[a].1),
            to_px(sv[b].0, sv[b].1),
            to_px(sv[c].0, sv[c].1),
        );
        let area = (pb.0 - pa.0) * (pc.1 - pa.1) - (pc.0 - pa.0) * (pb.1 - pa.1);
        if area.abs() < 1e-12 {
            continue;
        }
        let xmin = pa.0.min(pb.0).min(pc.0).floor().max(0.0) as usize;
        let xmax = (pa.0.max(pb.0).max(pc.0).ceil() as usize).min(w - 1);
        let ymin = pa.1.min(pb.1).min(pc.1).floor().max(0.0) as usize;
        let ymax = (pa.1.max(pb.1).max(pc.1).ceil() as usize).min(h - 1);
        for py in ymin..=ymax {
            for px in xmin..=xmax {
                let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
                let w0 = ((pb.0 - x) * (pc.1 - y) - (pc.0 - x) * (pb.1 - y)) / area;
                let w1 = ((pc.0 - x) * (pa.1 - y) - (pa.0 - x) * (pc.1 - y)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9 {
                    continue;
                }
                let z = w0 * sv[a].2 + w1 * sv[b].2 + w2 * sv[c].2;
                let k = py * w + px;
                if z <= depth[k] {
                    continue;
                }
                depth[k] = z;
                let mut n = mesh.normals[a] * w0 + mesh.normals[b] * w1 + mesh.normals[c] * w2;
                n.z /= zs; // normals transform with the inverse transpose of the scaling
                let nn = n.norm();
                let lambert = if nn > 0.0 {
                    (n.dot(&light) / nn).abs()
                } else {
                    0.5
                };
                let shade = 0.3 + 0.7 * lambert;
                let value = w0 * vals[a] + w1 * vals[b] + w2 * vals[c];
                let mut col = match (rgb_of(a), rgb_of(b), rgb_of(c)) {
                    (Some(ca), Some(cb), Some(cc)) => {
                        [0, 1, 2].map(|ch| w0 * ca[ch] + w1 * cb[ch] + w2 * cc[ch])
                    }
                    _ => viridis(((value - lo) / span).clamp(0.0, 1.0)),
                };
                if opts.iso_lines > 0 {
                    let u = w0 * mesh.uv[a][0] + w1 * mesh.uv[b][0] + w2 * mesh.uv[c][0];
                    let v = w0 * mesh.uv[a][1] + w1 * mesh.uv[b][1] + w2 * mesh.uv[c][1];
                    let fu = (u - u0) / (u1 - u0).max(1e-300) * opts.iso_lines as f64;
                    let fv = (v - v0) / (v1 - v0).max(1e-300) * opts.iso_lines as f64;
                    let near =
                        |f: f64| (f - f.round()).abs() < 0.012 * opts.iso_lines as f64 / 10.0;
                    if near(fu) || near(fv) {
                        col = col.map(|c| c * 0.45);
                    }
                }
                for ch in 0..3 {
                    img[k * 3 + ch] = (col[ch] * shade * 255.0).round().clamp(0.0, 255.0) as u8;
                }
            }
        }
    }
    // points: small red dots where not hidden (1% of the depth range of tolerance)
    let tol = 0.01 * (z1 - z0).max(1e-300);
    let dot: &[(isize, isize)] = if sp.len() > 2000 {
        &[(0, 0)]
    } else {
        &[(0, 0), (1, 0), (0, 1), (1, 1)]
    };
    for &(x, y, z) in &sp {
        let (px, py) = to_px(x, y);
        let (px, py) = (px as isize, py as isize);
        for &(dx, dy) in dot {
            let (qx, qy) = (px + dx, py + dy);
            if qx < 0 || qy < 0 || qx >= w as isize || qy >= h as isize {
                continue;
            }
            let k = qy as usize * w + qx as usize;
            if z + tol >= depth[k] {
                img[k * 3..k * 3 + 3].copy_from_slice(&[200, 30, 30]);
            }
        }
    }
    draw_overlay(&mut img, w, h, lines, markers, |p| {
        let (x, y, _) = proj(p);
        to_px(x, y)
    });
    if let Colouring::Scalar { range, .. } = colouring {
        colour_bar(&mut img, w, h, range);
    }
    let mut canvas = Canvas {
        rgb: &mut img,
        width: w,
        height: h,
    };
    for (k, line) in opts.legend.iter().enumerate() {
        draw_text(&mut canvas, 8, 6 + 14 * k, line, 1, [20, 20, 20]);
    }
    img
}

/// An RGB8 image being drawn on (row-major, top row first).
pub struct Canvas<'a> {
    /// The pixels, 3 bytes each.
    pub rgb: &'a mut [u8],
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
}

/// Draws `text` with the 8x8 bitmap font (font8x8, public domain) at pixel
/// `(x, y)`, each font pixel `scale x scale` image pixels.
pub fn draw_text(canvas: &mut Canvas, x: usize, y: usize, text: &str, scale: usize, rgb: [u8; 3]) {
    use font8x8::UnicodeFonts;
    for (k, ch) in text.chars().enumerate() {
        let Some(glyph) = font8x8::BASIC_FONTS.get(ch) else {
            continue;
        };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let (px, py) = (x + (k * 8 + col) * scale + dx, y + row * scale + dy);
                        if px < canvas.width && py < canvas.height {
                            let o = (py * canvas.width + px) * 3;
                            canvas.rgb[o..o + 3].copy_from_slice(&rgb);
                        }
                    }
                }
            }
        }
    }
}

/// A vertical viridis bar at the right edge with its range written beside it.
fn colour_bar(img: &mut [u8], w: usize, h: usize, range: (f64, f64)) {
    let (x0, x1) = (w.saturating_sub(110), w.saturating_sub(90));
    let (y0, y1) = (h / 6, h - h / 6);
    for y in y0..y1 {
        let t = 1.0 - (y - y0) as f64 / (y1 - y0).max(1) as f64;
        let c = viridis(t).map(|v| (v * 255.0).round() as u8);
        for x in x0..x1 {
            img[(y * w + x) * 3..(y * w + x) * 3 + 3].copy_from_slice(&c);
        }
    }
    let label = |v: f64| {
        if v != 0.0 && !(1e-3..1e5).contains(&v.abs()) {
            format!("{v:.2e}")
        } else {
            format!("{v:.4}")
        }
    };
    let (lo, hi) = range;
    let mut c = Canvas {
        rgb: img,
        width: w,
        height: h,
    };
    draw_text(
        &mut c,
        x1 + 6,
        y0.saturating_sub(4),
        &label(hi),
        1,
        [20, 20, 20],
    );
    draw_text(
        &mut c,
        x1 + 6,
        (y0 + y1) / 2 - 4,
        &label(0.5 * (lo + hi)),
        1,
        [20, 20, 20],
    );
    draw_text(
        &mut c,
        x1 + 6,
        y1.saturating_sub(4),
        &label(lo),
        1,
        [20, 20, 20],
    );
}

/// The viridis colour map (matplotlib), linear between 9 stops.
pub fn viridis(t: f64) -> [f64; 3] {
    const STOPS: [[f64; 3]; 9] = [
        [0.267, 0.005, 0.329],
        [0.283, 0.141, 0.458],
        [0.254, 0.265, 0.530],
        [0.207, 0.372, 0.553],
        [0.164, 0.471, 0.558],
        [0.128, 0.567, 0.551],
        [0.135, 0.659, 0.518],
        [0.478, 0.821, 0.319],
        [0.993, 0.906, 0.144],
    ];
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x.floor() as usize).min(7);
    let f = x - i as f64;
    [0, 1, 2].map(|c| STOPS[i][c] * (1.0 - f) + STOPS[i + 1][c] * f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use scanfit::bspline::{tessellate, KnotVector, Surface};

    #[test]
    fn a_rendered_surface_fills_the_frame_and_is_not_blank() {
        let ku = KnotVector::uniform_clamped(3, 5).unwrap();
        let kv = KnotVector::uniform_clamped(3, 5).unwrap();
        let mut c = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                c.push(Point3::new(
                    i as f64,
                    j as f64,
                    ((i + j) as f64 * 0.8).sin(),
                ));
            }
        }
        let s = Surface::new(ku, kv, c).unwrap();
        let mesh = tessellate(&s, 40, 40);
        let opts = RenderOptions {
            width: 200,
            height: 150,
            ..Default::default()
        };
        let img = render_rgb(&mesh, None, Colouring::Height, &opts);
        let painted = img.chunks(3).filter(|p| p != &[255, 255, 255]).count();
        assert!(painted > 200 * 150 / 4, "{painted}");
        // nothing drawn in the 2-pixel border (object inside the frame)
        for x in 0..200 {
            assert_eq!(&img[x * 3..x * 3 + 3], &[255, 255, 255]);
        }
        let png = encode_png(&img, 200, 150).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }

    #[test]
    fn rgb_colouring_paints_the_given_colours_and_no_colour_bar() {
        let k = KnotVector::uniform_clamped(1, 2).unwrap();
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let s = Surface::new(
            k.clone(),
            k,
            vec![p(0., 0.), p(0., 1.), p(1., 0.), p(1., 1.)],
        )
        .unwrap();
        let mesh = tessellate(&s, 8, 8);
        // left half (u < 0.5) pure red, the rest pure blue
        let colours: Vec<[u8; 3]> = mesh
            .uv
            .iter()
            .map(|t| if t[0] < 0.5 { [255, 0, 0] } else { [0, 0, 255] })
            .collect();
        let opts = RenderOptions {
            width: 300,
            height: 300,
            azimuth: -90.0,
            elevation: 90.0,
            iso_lines: 0,
            ..Default::default()
        };
        let img = render_rgb(&mesh, None, Colouring::Rgb(&colours), &opts);
        let px: Vec<&[u8]> = img.chunks(3).collect();
        // every painted pixel is a shade of red, blue or their blend: no green,
        // so neither viridis nor its colour bar
        let painted: Vec<&&[u8]> = px.iter().filter(|c| c != &&[255, 255, 255]).collect();
        assert!(painted.len() > 300 * 300 / 2, "{}", painted.len());
        assert!(painted.iter().all(|c| c[1] == 0), "a green (viridis) pixel");
        let red = painted.iter().filter(|c| c[0] > 0 && c[2] == 0).count();
        let blue = painted.iter().filter(|c| c[2] > 0 && c[0] == 0).count();
        assert!(
            red > painted.len() / 3 && blue > painted.len() / 3,
            "{red} {blue}"
        );
    }
}
