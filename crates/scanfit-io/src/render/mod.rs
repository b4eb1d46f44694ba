//! Software rendering of surfaces to PNG: no GPU, no window, no system fonts.
//!
//! An orthographic camera ([`Camera`]) looks at the object from an azimuth
//! and elevation around the up axis ([`Up`]: x, y or z; named views in
//! [`ViewPreset`]) and fits it into the image; triangles are rasterised with
//! a depth buffer, shaded (two-sided Lambert plus ambient) and coloured by
//! height, by a per-vertex scalar (viridis, on a [`ColourScale`] clipped at
//! a percentile) or by per-vertex RGB colours (categories such as patches),
//! with darker iso-parameter lines; input points can be drawn on top where
//! they are not hidden by the surface.
//!
//! The [`Layout`] reserves the caption's rows (wrapped to the width, never
//! cut off) and the colour bar's column before the drawing is fitted into
//! what is left, so neither is drawn over the object.

mod camera;
mod legend;

pub use camera::{Camera, Up, ViewPreset};
pub use legend::{
    format_value, text_width, wrap_text, BarLabels, BarLayout, Clip, ColourScale, Fit, Layout,
    DEVIATION_PERCENTILE, GLYPH, LINE,
};

use scanfit::bspline::Mesh;
use scanfit::{Point3, Vector3};

use crate::{Error, Result};

/// What the surface colour shows.
#[derive(Debug, Clone, Copy)]
pub enum Colouring<'a> {
    /// The height (along the up axis), low = dark blue, high = yellow, with a
    /// colour bar in [`RenderOptions::units`].
    Height,
    /// One value per mesh vertex on `scale` (e.g. deviation), with a colour bar.
    Scalar {
        /// values per vertex
        values: &'a [f64],
        /// what the colours mean: range, clipping, name with units
        scale: &'a ColourScale,
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
    /// Camera azimuth around the up axis, degrees (default -60).
    pub azimuth: f64,
    /// Camera elevation above the plane across the up axis, degrees (default 35).
    pub elevation: f64,
    /// The world axis that is up (default z).
    pub up: Up,
    /// Length unit of the data for the height bar, e.g. "m" (default "data units").
    pub units: String,
    /// Iso-parameter lines per direction (default 10; 0 = none).
    pub iso_lines: usize,
    /// Lines of text drawn at the top left (title, figures); wrapped to the
    /// width. A picture with a vertical exaggeration gets a line saying so.
    pub legend: Vec<String>,
    /// Vertical exaggeration: the up axis is multiplied by this before
    /// drawing (default 1; see [`auto_exaggeration`] for flat data such as
    /// terrain).
    pub z_scale: f64,
}

impl RenderOptions {
    /// The caption: [`Self::legend`] and, when the picture is exaggerated,
    /// a line with the factor and the axis.
    pub fn caption(&self) -> Vec<String> {
        let mut c = self.legend.clone();
        if self.z_scale != 1.0 && self.z_scale > 0.0 && self.z_scale.is_finite() {
            c.push(format!(
                "vertical exaggeration {}x along {} (up)",
                self.z_scale,
                self.up.name()
            ));
        }
        c
    }
}

/// A vertical exaggeration that makes the relief of flat data visible: the
/// factor that brings the range along `up` to 20% of the larger extent
/// across it, rounded to one significant digit; 1 when the data are not flat.
pub fn auto_exaggeration(points: &[Point3], up: Up) -> f64 {
    let (lo, hi) = points.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| {
            let c = up.to_frame(&p.coords);
            (lo.inf(&c), hi.sup(&c))
        },
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
            up: Up::Z,
            units: "data units".into(),
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
/// lines and markers into the frame; returns the PNG bytes. Points coloured
/// by height get a colour bar clipped at their 1st and 99th percentiles.
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
    let camera = Camera::new(opts);
    let view = |p: &Point3| camera.project(p);
    let sp: Vec<(f64, f64, f64)> = scene.points.iter().map(view).collect();
    let mut img = vec![255u8; w * h * 3];
    let extra = scene
        .polylines
        .iter()
        .flat_map(|l| l.points.iter())
        .chain(scene.markers.iter().map(|m| &m.at))
        .map(view);
    let all: Vec<(f64, f64, f64)> = sp.iter().copied().chain(extra).collect();
    let heights: Vec<f64> = scene.points.iter().map(|p| camera.height(p)).collect();
    let scale = scene.colours.is_none().then(|| {
        ColourScale::two_sided(
            format!("height ({}) [{}]", opts.up.name(), opts.units),
            &heights,
            DEVIATION_PERCENTILE,
        )
    });
    let layout = Layout::new(w, h, &opts.caption(), scale.as_ref());
    if all.is_empty() {
        layout.draw(&mut img);
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
    let fit = layout.fit(x0, x1, y0, y1);
    let pixel = |x: f64, y: f64| {
        let (px, py) = fit.pixel(x, y);
        (px as isize, py as isize)
    };
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    // splat size: points cover the picture of a surface (about half of the
    // projected box, twice over for the front of a closed body), so nearer
    // points hide farther ones
    let area = (x1 - x0) * (y1 - y0) * fit.scale * fit.scale;
    let spacing_px = (2.0 * area / sp.len().max(1) as f64).sqrt();
    let r = (0.5 * spacing_px).round().clamp(0.0, 4.0) as isize;
    // visibility in two passes: the depth of the front surface with wider
    // splats (so it has no holes), then the colours of the points within a
    // few point spacings of that front (the back of a closed body stays hidden)
    let wide = (2 * r + 2).min(10);
    let tolerance = (2.0 * (wide as f64 + 1.0) + 3.0 * spacing_px.max(1.0)) / fit.scale;
    let footprint = |px: isize, py: isize, r: isize| {
        (-r..=r).flat_map(move |dy| (-r..=r).map(move |dx| (px + dx, py + dy)))
    };
    // splats stay inside the drawing's area (off the caption and the bar)
    let (ax0, ay0, ax1, ay1) = layout.area;
    let inside = |qx: isize, qy: isize| {
        qx >= ax0 as isize && qy >= ay0 as isize && qx < ax1 as isize && qy < ay1 as isize
    };
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
        let col = match (scene.colours, &scale) {
            (Some(c), _) => c[i],
            (None, Some(s)) => viridis(s.position(heights[i])).map(|c| (c * 255.0).round() as u8),
            (None, None) => [0, 0, 0],
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
    draw_overlay(&mut img, &layout, &scene.polylines, &scene.markers, |p| {
        let (x, y, _) = view(p);
        fit.pixel(x, y)
    });
    layout.draw(&mut img);
    encode_png(&img, w as u32, h as u32)
}

/// Draws `lines` (2-pixel wide) and labelled `markers` over an image, with
/// `to_pixel` mapping a world point to pixel coordinates; a label that would
/// run out of the layout's drawing area is written on the marker's left.
fn draw_overlay(
    img: &mut [u8],
    layout: &Layout,
    lines: &[Polyline],
    markers: &[Marker],
    to_pixel: impl Fn(&Point3) -> (f64, f64),
) {
    let (w, h) = (layout.width, layout.height);
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
            let lw = text_width(&m.label, 2) as isize;
            let right = layout.area.2 as isize;
            let lx = if px + 10 + lw > right {
                px - 10 - lw
            } else {
                px + 10
            };
            let mut canvas = Canvas {
                rgb: img,
                width: w,
                height: h,
            };
            draw_text(
                &mut canvas,
                lx.max(0) as usize,
                (py - 16).max(layout.area.1 as isize) as usize,
                &m.label,
                2,
                [0, 0, 0],
            );
        }
    }
}

/// Camera angles `(azimuth, elevation)` in degrees that look along `-n`,
/// i.e. from the side `n` points to (with `up` the up axis): a top view of
/// a patch with normal `n`.
pub fn angles_facing(n: &Vector3, up: Up) -> (f64, f64) {
    let len = n.norm();
    if !(len > 0.0 && len.is_finite()) {
        return (-60.0, 35.0);
    }
    let n = up.to_frame(&(n / len));
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
    let (img, _, _) = render_rgb_with(mesh, points, colouring, lines, markers, opts);
    encode_png(&img, opts.width, opts.height)
}

/// Renders into an RGB8 buffer of `width x height` (row-major, top row first).
pub fn render_rgb(
    mesh: &Mesh,
    points: Option<&[Point3]>,
    colouring: Colouring,
    opts: &RenderOptions,
) -> Vec<u8> {
    render_rgb_with(mesh, points, colouring, &[], &[], opts).0
}

/// The scale of the colours of `mesh` under `colouring`: a height scale
/// over the mesh's heights (its own range: a surface has no stray points),
/// the given scale, or none for category colours.
fn surface_scale(mesh: &Mesh, colouring: &Colouring, opts: &RenderOptions) -> Option<ColourScale> {
    match colouring {
        Colouring::Height => {
            let (lo, hi) = mesh
                .vertices
                .iter()
                .map(|p| opts.up.height(p))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
                    (a.min(z), b.max(z))
                });
            let range = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
            Some(ColourScale::new(
                format!("height ({}) [{}]", opts.up.name(), opts.units),
                range,
            ))
        }
        Colouring::Scalar { scale, .. } => Some((*scale).clone()),
        Colouring::Rgb(_) => None,
    }
}

/// The picture and its layout; pixels of the surface have a finite depth in
/// the returned buffer.
fn render_rgb_with(
    mesh: &Mesh,
    points: Option<&[Point3]>,
    colouring: Colouring,
    lines: &[Polyline],
    markers: &[Marker],
    opts: &RenderOptions,
) -> (Vec<u8>, Layout, Vec<f64>) {
    let (w, h) = (opts.width.max(16) as usize, opts.height.max(16) as usize);
    let camera = Camera::new(opts);
    let (d, right, up) = (camera.toward, camera.right, camera.up);
    let light = (d + 0.4 * up - 0.3 * right).normalize();
    let proj = |p: &Point3| camera.project(p);
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
    let scale = surface_scale(mesh, &colouring, opts);
    let layout = Layout::new(w, h, &opts.caption(), scale.as_ref());
    let mut img = vec![255u8; w * h * 3];
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    if !(x1 > x0 || y1 > y0) {
        layout.draw(&mut img);
        return (img, layout, depth);
    }
    let fit = layout.fit(x0, x1, y0, y1);
    let to_px = |x: f64, y: f64| fit.pixel(x, y);
    let heights: Vec<f64> = mesh.vertices.iter().map(|p| camera.height(p)).collect();
    let vals = match colouring {
        Colouring::Scalar { values, .. } => values,
        _ => heights.as_slice(),
    };
    let rgb_of = |k: usize| match colouring {
        Colouring::Rgb(c) => c.get(k).map(|c| c.map(|x| x as f64 / 255.0)),
        _ => None,
    };
    let position = |v: f64| scale.as_ref().map_or(0.0, |s| s.position(v));
    let ((u0, u1), (v0, v1)) = mesh.uv.iter().fold(
        (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        ),
        |((a, b), (c, e)), t| ((a.min(t[0]), b.max(t[0])), (c.min(t[1]), e.max(t[1]))),
    );
    let normals: Vec<Vector3> = mesh.normals.iter().map(|n| camera.normal(n)).collect();
    let (ax0, ay0, ax1, ay1) = layout.area;
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
        // pixels inside the drawing's area only (off the caption and the bar)
        let xmin = pa.0.min(pb.0).min(pc.0).floor().max(ax0 as f64) as usize;
        let xmax = (pa.0.max(pb.0).max(pc.0).ceil().max(0.0) as usize).min(ax1 - 1);
        let ymin = pa.1.min(pb.1).min(pc.1).floor().max(ay0 as f64) as usize;
        let ymax = (pa.1.max(pb.1).max(pc.1).ceil().max(0.0) as usize).min(ay1 - 1);
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
                let n = normals[a] * w0 + normals[b] * w1 + normals[c] * w2;
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
                    _ => viridis(position(value)),
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
            if qx < ax0 as isize || qy < ay0 as isize || qx >= ax1 as isize || qy >= ay1 as isize {
                continue;
            }
            let k = qy as usize * w + qx as usize;
            if z + tol >= depth[k] {
                img[k * 3..k * 3 + 3].copy_from_slice(&[200, 30, 30]);
            }
        }
    }
    draw_overlay(&mut img, &layout, lines, markers, |p| {
        let (x, y, _) = proj(p);
        to_px(x, y)
    });
    layout.draw(&mut img);
    (img, layout, depth)
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

    /// A bumpy 5 x 5 patch over `[0, 4] x [0, sy]`, tessellated 40 x 40.
    fn bumpy(sy: f64) -> Mesh {
        let ku = KnotVector::uniform_clamped(3, 5).unwrap();
        let kv = KnotVector::uniform_clamped(3, 5).unwrap();
        let mut c = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                c.push(Point3::new(
                    i as f64,
                    j as f64 * sy / 4.0,
                    ((i + j) as f64 * 0.8).sin(),
                ));
            }
        }
        tessellate(&Surface::new(ku, kv, c).unwrap(), 40, 40)
    }

    #[test]
    fn the_colour_bar_and_caption_are_never_drawn_over_the_surface() {
        // a wide patch (it would fill the width) with a corner marker at the
        // right end, coloured by a clipped scale with a long name
        let mesh = bumpy(1.0);
        let values: Vec<f64> = mesh.vertices.iter().map(|p| p.x * 0.01).collect();
        let scale = ColourScale::deviation(
            "orthogonal distance of the nearest input point [data units]",
            &values,
            99.0,
        );
        let right_end =
            mesh.vertices
                .iter()
                .copied()
                .fold(Point3::new(f64::MIN, 0.0, 0.0), |a, p| {
                    if p.x > a.x {
                        p
                    } else {
                        a
                    }
                });
        let marker = Marker {
            at: right_end,
            rgb: [255, 255, 255],
            label: "C3".into(),
        };
        for (w, h) in [(1200u32, 900u32), (400, 300)] {
            let opts = RenderOptions {
                width: w,
                height: h,
                azimuth: -90.0,
                elevation: 60.0,
                legend: vec!["a caption ".repeat(30)],
                ..Default::default()
            };
            let colouring = Colouring::Scalar {
                values: &values,
                scale: &scale,
            };
            let (img, layout, depth) = render_rgb_with(
                &mesh,
                None,
                colouring,
                &[],
                std::slice::from_ref(&marker),
                &opts,
            );
            let bar = layout.bar.as_ref().unwrap();
            let (bx0, bx1) = bar.columns;
            let w = w as usize;
            let surface: Vec<(usize, usize)> = (0..depth.len())
                .filter(|&k| depth[k].is_finite())
                .map(|k| (k % w, k / w))
                .collect();
            assert!(surface.len() > depth.len() / 20, "{}", surface.len());
            let (sx0, sx1) = surface
                .iter()
                .fold((usize::MAX, 0), |(a, b), &(x, _)| (a.min(x), b.max(x)));
            let sy0 = surface.iter().map(|&(_, y)| y).min().unwrap();
            // the surface's columns end before the bar's begin, and it starts
            // below the caption's last line
            assert!(sx1 < bx0, "surface columns {sx0}..={sx1}, bar {bx0}..{bx1}");
            assert!(
                sy0 >= layout.area.1,
                "surface from row {sy0}, caption to {}",
                layout.area.1
            );
            assert!(layout.caption.len() > 1);
            // the bar is drawn: its middle row holds viridis(0.5)
            let (cx, cy) = (
                (bar.bar_columns.0 + bar.bar_columns.1) / 2,
                (bar.rows.0 + bar.rows.1) / 2,
            );
            let px = &img[(cy * w + cx) * 3..(cy * w + cx) * 3 + 3];
            let mid = viridis(0.5).map(|c| (c * 255.0).round() as u8);
            assert!(
                px.iter().zip(&mid).all(|(a, b)| a.abs_diff(*b) <= 3),
                "{px:?}"
            );
            // nothing black (marker labels, outlines) inside the bar's strip
            // left of its labels
            for y in 0..h as usize {
                for x in bx0..bar.bar_columns.1 {
                    let px = &img[(y * w + x) * 3..(y * w + x) * 3 + 3];
                    if y < bar.rows.0.saturating_sub(LINE) || y > bar.rows.1 + LINE {
                        continue;
                    }
                    assert_ne!(px, [0, 0, 0], "ink at ({x}, {y}) in the bar");
                }
            }
        }
    }

    #[test]
    fn y_up_data_with_up_y_is_the_same_picture_as_the_z_up_data() {
        let mesh = bumpy(3.0);
        let points: Vec<Point3> = mesh
            .vertices
            .iter()
            .step_by(7)
            .map(|p| p + Vector3::new(0.0, 0.0, 0.01))
            .collect();
        // the same object stored y-up: (x, y, z) -> (x, z, -y)
        let turn = |p: &Point3| Point3::new(p.x, p.z, -p.y);
        let turned = Mesh {
            vertices: mesh.vertices.iter().map(turn).collect(),
            normals: mesh
                .normals
                .iter()
                .map(|n| Vector3::new(n.x, n.z, -n.y))
                .collect(),
            uv: mesh.uv.clone(),
            triangles: mesh.triangles.clone(),
        };
        let turned_points: Vec<Point3> = points.iter().map(turn).collect();
        let z_up = RenderOptions {
            width: 300,
            height: 200,
            z_scale: 3.0,
            legend: vec!["caption".into()],
            ..Default::default()
        };
        let y_up = RenderOptions {
            up: Up::Y,
            ..z_up.clone()
        };
        let (a, la, _) = render_rgb_with(&mesh, Some(&points), Colouring::Height, &[], &[], &z_up);
        let (b, lb, _) = render_rgb_with(
            &turned,
            Some(&turned_points),
            Colouring::Height,
            &[],
            &[],
            &y_up,
        );
        assert_eq!(la.area, lb.area);
        // pixel-equal in the drawing (caption and bar title name the axis)
        let (x0, y0, x1, y1) = la.area;
        let drawing = |img: &[u8]| -> Vec<u8> {
            (y0..y1)
                .flat_map(|y| img[(y * 300 + x0) * 3..(y * 300 + x1) * 3].to_vec())
                .collect()
        };
        assert_eq!(drawing(&a), drawing(&b));
        assert!(drawing(&a).iter().filter(|&&c| c != 255).count() > 10_000);
        assert_eq!(z_up.caption()[1], "vertical exaggeration 3x along z (up)");
        assert_eq!(y_up.caption()[1], "vertical exaggeration 3x along y (up)");
        // seen unturned (z up), the y-up data are another picture
        let c = render_rgb(&turned, Some(&turned_points), Colouring::Height, &z_up);
        assert!(a.iter().zip(&c).filter(|(x, y)| x != y).count() > a.len() / 20);
        // point pictures too
        let decode = |png: Vec<u8>| {
            let mut r = png::Decoder::new(std::io::Cursor::new(png))
                .read_info()
                .unwrap();
            let mut buf = vec![0; r.output_buffer_size().unwrap()];
            r.next_frame(&mut buf).unwrap();
            buf
        };
        let scene = |p| PointScene {
            points: p,
            ..Default::default()
        };
        let pa = decode(render_scene_png(&scene(&points), &z_up).unwrap());
        let pb = decode(render_scene_png(&scene(&turned_points), &y_up).unwrap());
        assert_eq!(drawing(&pa), drawing(&pb));
        assert!(drawing(&pa).iter().filter(|&&c| c != 255).count() > 1000);
    }

    #[test]
    fn a_rendered_surface_fills_the_frame_and_is_not_blank() {
        let mesh = bumpy(4.0);
        let opts = RenderOptions {
            width: 200,
            height: 150,
            ..Default::default()
        };
        let (img, layout, depth) = render_rgb_with(&mesh, None, Colouring::Height, &[], &[], &opts);
        // the surface covers more than a sixth of the drawing's area (wide
        // object, width-bound)
        let (x0, y0, x1, y1) = layout.area;
        let covered = depth.iter().filter(|d| d.is_finite()).count();
        assert!(covered > (x1 - x0) * (y1 - y0) / 6, "{covered}");
        // nothing drawn in the top row (object inside the frame)
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
