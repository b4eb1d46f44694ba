//! The virtual turntable ([TURN17] sections 3.2-3.3): the cloud turned
//! by `2 pi k / V` about the axis (eq. 17), hidden point removal from `+z`
//! ([Katz07]) for each turn, a multilevel B-spline surface
//! `z' = f_k(x', y')` on each visible set, grid points on layers of constant
//! height, intersection pairs between neighbouring views and the grid points
//! beyond them discarded.
//!
//! View `k` has the unit viewing direction `w_k = cos(a_k) e2 + sin(a_k) e1`
//! and `u_k = cos(a_k) e1 - sin(a_k) e2`; the turned coordinates of eq. 17
//! are `x' = (p - c0).u_k`, `y' = (p - c0).a`, `z' = (p - c0).w_k` (`M` the
//! rotation by `a_k` about `y` in the paper's frame) and eq. 18 maps back,
//! `p = c0 + x' u_k + y' a + z' w_k`. Along a layer, growing `x'` turns
//! towards view `k + 1`.
//!
//! Intersection pairs (section 3.3): on every layer, the closest pair of grid
//! points between view `k`'s row and view `k + 1`'s row, searched in the
//! angular sector between the two viewing directions, where the two surfaces
//! cross. View `k` keeps its grid points from its pair with view `k - 1`
//! (included) to its pair with view `k + 1` (excluded): the rest lies beyond
//! the neighbour's better view, towards the silhouette where a height field
//! is steep and the MBA surface no longer follows the cloud. The kept pieces,
//! in view order, form one closed polygon per layer around the axis.

use std::f64::consts::PI;

use rayon::prelude::*;

use crate::cloud::hpr::{hidden_point_removal, HprConfig};
use crate::mba::{mba, Mba, MbaConfig, Start};
use crate::{Error, Point3, Result, Vector3};

use super::axis::CylinderFrame;

/// Settings of the virtual turntable and its MBA surfaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewConfig {
    /// Number of turns `V` (paper: 4, at 0/90/180/270 degrees; at least 3).
    pub views: usize,
    /// Distance of the viewpoint from the axis, in bounding-cylinder radii
    /// (default 4; the paper looks "from +z" without a distance).
    pub view_distance: f64,
    /// Hidden point removal (default `gamma = 2`, see [`HprConfig`]).
    pub hpr: HprConfig,
    /// Multilevel B-splines on each view (default: 6 levels from the
    /// aspect-ratio base lattice, eq. 4 of [LWS97], from the mean height).
    pub mba: MbaConfig,
    /// Grid points per layer and view (`u` count; default 32). The base
    /// surface gets about `0.7 V` times as many samples around the axis;
    /// when their spacing falls below the cloud's, interpolating the
    /// projected (noisy) samples makes a wavy base surface whose orthogonal
    /// projection folds (on the blob sample: 0 fold-overs inside the layers
    /// with 32, 10 with 40, 377 with 128).
    pub grid_u: usize,
}

impl Default for ViewConfig {
    fn default() -> Self {
        Self {
            views: 4,
            view_distance: 4.0,
            hpr: HprConfig::default(),
            // the views' settings (grid, fold-overs) were measured with the
            // mean start; the fitted start (MBA's default since issue 18) is
            // not measured on the turntable yet
            mba: MbaConfig {
                start: Start::Mean,
                ..MbaConfig::default()
            },
            grid_u: 32,
        }
    }
}

/// One turn of the virtual turntable.
#[derive(Debug, Clone)]
pub struct View {
    /// Turn angle `a_k` (radians).
    pub angle: f64,
    /// Indices of the cloud points visible from `+z` after the turn.
    pub visible: Vec<usize>,
    /// The MBA surface `z' = f(x', y')` over the visible points (turned coordinates).
    pub mba: Mba,
}

impl View {
    /// `(u_k, w_k)`: the turned `x'` and `z'` directions in world space.
    pub fn directions(&self, frame: &CylinderFrame) -> (Vector3, Vector3) {
        turn_directions(frame, self.angle)
    }

    /// Eq. 17: turned coordinates `(x', y', z')` of `p`.
    pub fn turn(&self, frame: &CylinderFrame, p: &Point3) -> Point3 {
        let (u, w) = self.directions(frame);
        let d = p - frame.centre;
        Point3::new(d.dot(&u), d.dot(&frame.axis), d.dot(&w))
    }

    /// Eq. 18: the world point of turned coordinates.
    pub fn unturn(&self, frame: &CylinderFrame, q: &Point3) -> Point3 {
        let (u, w) = self.directions(frame);
        frame.centre + q.x * u + q.y * frame.axis + q.z * w
    }

    /// The grid row of this view's MBA surface at height `h`: `n` points
    /// equally spaced in `x'` over the surface's frame, in world space.
    pub fn grid_row(&self, frame: &CylinderFrame, h: f64, n: usize) -> Vec<Point3> {
        let f = &self.mba.frame;
        (0..n)
            .map(|i| {
                let x = f.x0 + f.width * i as f64 / (n - 1) as f64;
                self.unturn(frame, &Point3::new(x, h, self.mba.eval(x, h)))
            })
            .collect()
    }
}

/// `(u, w)` of the turn by `angle`: `u = cos(a) e1 - sin(a) e2`, `w = cos(a) e2 + sin(a) e1`.
fn turn_directions(frame: &CylinderFrame, angle: f64) -> (Vector3, Vector3) {
    let (s, c) = angle.sin_cos();
    (c * frame.e1 - s * frame.e2, c * frame.e2 + s * frame.e1)
}

/// Section 3.2-3.3 up to the MBA surfaces: the `V` turns, their visible
/// sets and MBA surfaces.
pub fn turntable_views(
    points: &[Point3],
    frame: &CylinderFrame,
    cfg: &ViewConfig,
) -> Result<Vec<View>> {
    if !(3..=64).contains(&cfg.views) {
        return Err(Error::InvalidInput(format!(
            "{} turntable views: use between 3 (to surround the cloud) and 64 (the paper uses 4)",
            cfg.views
        )));
    }
    if !(8..=4096).contains(&cfg.grid_u) {
        return Err(Error::InvalidInput(format!(
            "{} grid points per view and layer: use between 8 and 4096",
            cfg.grid_u
        )));
    }
    // each view's sector must hold grid points of its MBA surface: the first
    // grid point off the centre is at about asin(2 / grid) from it
    let sector = std::f64::consts::PI / cfg.views as f64;
    let step = (2.0 / cfg.grid_u as f64).min(1.0).asin();
    if sector < 2.0 * step {
        return Err(Error::InvalidInput(format!(
            "{} views of {} grid points: a view's half-sector ({:.2} degrees) holds no grid points (their angular step is {:.2} degrees); use fewer --views or a larger --grid",
            cfg.views,
            cfg.grid_u,
            sector.to_degrees(),
            step.to_degrees()
        )));
    }
    if !(cfg.view_distance.is_finite() && cfg.view_distance > 1.0) {
        return Err(Error::InvalidInput(format!(
            "view distance {} must be more than 1 bounding radius (the viewpoint must lie outside the cloud)",
            cfg.view_distance
        )));
    }
    // the views are independent: their hulls (serial each) run side by side;
    // collected in view order, the first failing view's error is returned
    let views: Vec<Result<View>> = (0..cfg.views)
        .into_par_iter()
        .map(|k| {
            let angle = 2.0 * PI * k as f64 / cfg.views as f64;
            let (u, w) = turn_directions(frame, angle);
            let eye = frame.centre + cfg.view_distance * frame.radius * w;
            let visible = hidden_point_removal(points, &eye, &cfg.hpr)?;
            // eq. 17: turned coordinates of the visible points
            let turned: Vec<Point3> = visible
                .iter()
                .map(|&i| {
                    let d = points[i] - frame.centre;
                    Point3::new(d.dot(&u), d.dot(&frame.axis), d.dot(&w))
                })
                .collect();
            let surface = mba(&turned, &cfg.mba).map_err(|e| {
                Error::InvalidInput(format!(
                    "turntable view {k} ({:.0} degrees, {} visible points): {e}",
                    angle.to_degrees(),
                    turned.len()
                ))
            })?;
            let view = View {
                angle,
                visible,
                mba: surface,
            };
            Ok(view)
        })
        .collect();
    views.into_iter().collect()
}

/// Wraps an angle into `(-pi, pi]`.
pub(crate) fn wrap_angle(a: f64) -> f64 {
    let mut x = a % (2.0 * PI);
    if x > PI {
        x -= 2.0 * PI
    } else if x <= -PI {
        x += 2.0 * PI
    }
    x
}

/// Mean distance between consecutive points of a grid row.
fn row_spacing(row: &[Point3]) -> f64 {
    row.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>() / (row.len() - 1) as f64
}

/// The closed polygon of one layer at height `h` (section 3.3): grid rows of
/// every view, trimmed at the intersection pairs, in view order (growing
/// angle). Returns the polygon and, per view, how many of its grid points it
/// kept.
pub fn layer_polygon(
    frame: &CylinderFrame,
    views: &[View],
    h: f64,
    grid_u: usize,
) -> Result<(Vec<Point3>, Vec<usize>)> {
    let v = views.len();
    let rows: Vec<Vec<Point3>> = views
        .iter()
        .map(|view| view.grid_row(frame, h, grid_u))
        .collect();
    let sector = 2.0 * PI / v as f64;
    // pair[k] = (index in view k, index in view k+1) of the closest pair
    let mut pairs = Vec::with_capacity(v);
    for k in 0..v {
        let k1 = (k + 1) % v;
        let rel = |view: &View, p: &Point3| wrap_angle(frame.angle(p) - view.angle);
        let a: Vec<usize> = (0..grid_u)
            .filter(|&i| {
                let b = rel(&views[k], &rows[k][i]);
                (0.0..=sector).contains(&b)
            })
            .collect();
        let b: Vec<usize> = (0..grid_u)
            .filter(|&j| {
                let b = rel(&views[k1], &rows[k1][j]);
                (-sector..=0.0).contains(&b)
            })
            .collect();
        // the closest pair; where the two rows run together (a round
        // section seen from both sides) every nearby pair is as close, and the
        // pair nearest the bisector of the two viewing directions is taken
        let spacing = row_spacing(&rows[k]).min(row_spacing(&rows[k1]));
        let mut cands = Vec::new();
        let mut min_d = f64::INFINITY;
        for &i in &a {
            for &j in &b {
                let d = (rows[k][i] - rows[k1][j]).norm();
                min_d = min_d.min(d);
                cands.push((d, i, j));
            }
        }
        let bisector = views[k].angle + 0.5 * sector;
        let best = cands
            .into_iter()
            .filter(|c| c.0 <= min_d + 0.25 * spacing)
            .map(|(_, i, j)| {
                let mid = Point3::from(0.5 * (rows[k][i].coords + rows[k1][j].coords));
                (wrap_angle(frame.angle(&mid) - bisector).abs(), i, j)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, i, j)| (i, j));
        let pair = best.ok_or_else(|| {
            Error::InvalidInput(format!(
                "layer at height {h:.4}: the MBA surfaces of views {k} and {k1} do not reach the sector between them; the cloud may not surround the axis there (check the axis, add views, or narrow the layer range)"
            ))
        })?;
        pairs.push(pair);
    }
    let mut polygon = Vec::new();
    let mut kept = Vec::with_capacity(v);
    for k in 0..v {
        let start = pairs[(k + v - 1) % v].1;
        let end = pairs[k].0;
        let before = polygon.len();
        if start < end {
            polygon.extend_from_slice(&rows[k][start..end]);
        }
        kept.push(polygon.len() - before);
    }
    Ok((polygon, kept))
}

#[cfg(test)]
mod tests {
    use super::super::axis::AxisChoice;
    use super::*;

    /// A cylinder of radius 1 and height 4 around y, on a jittered lattice.
    fn cylinder(n_around: usize, n_up: usize) -> Vec<Point3> {
        let mut pts = Vec::new();
        for j in 0..n_up {
            for i in 0..n_around {
                let t = 2.0 * PI * (i as f64 + 0.5 * (j % 2) as f64) / n_around as f64;
                let y = -2.0 + 4.0 * j as f64 / (n_up - 1) as f64;
                pts.push(Point3::new(t.sin(), y, t.cos()));
            }
        }
        pts
    }

    #[test]
    fn four_views_see_the_front_halves_and_make_a_round_polygon() {
        let pts = cylinder(120, 40);
        let frame = CylinderFrame::of(&pts, AxisChoice::Given(Vector3::y())).unwrap();
        let views = turntable_views(&pts, &frame, &ViewConfig::default()).unwrap();
        assert_eq!(views.len(), 4);
        for v in &views {
            // each view sees about half the cylinder (the facing side, from 4 radii)
            let frac = v.visible.len() as f64 / pts.len() as f64;
            assert!((0.40..0.52).contains(&frac), "visible fraction {frac}");
            // and every visible point faces the viewer
            let (_, w) = v.directions(&frame);
            for &i in &v.visible {
                assert!((pts[i] - frame.centre).dot(&w) > -0.05);
            }
        }
        let (poly, kept) = layer_polygon(&frame, &views, 0.0, 64).unwrap();
        // each view keeps its quarter, |x'| <= sin 45 deg of the width 2:
        // 63 * 0.707 = 44.5 grid points
        assert_eq!(kept.len(), 4);
        for &k in &kept {
            assert!((43..=47).contains(&k), "kept {kept:?}");
        }
        // the polygon lies on the circle and goes round once, angle growing
        let mut turn = 0.0;
        for (i, p) in poly.iter().enumerate() {
            let r = (p.x * p.x + p.z * p.z).sqrt();
            assert!((r - 1.0).abs() < 0.02, "radius {r} at {i}");
            let q = poly[(i + 1) % poly.len()];
            let d = wrap_angle(frame.angle(&q) - frame.angle(p));
            assert!(d > 0.0 && d < 0.3, "step {d} at {i}");
            turn += d;
        }
        assert!((turn - 2.0 * PI).abs() < 1e-9);
    }

    #[test]
    fn two_views_are_refused() {
        let pts = cylinder(30, 5);
        let frame = CylinderFrame::of(&pts, AxisChoice::Given(Vector3::y())).unwrap();
        let cfg = ViewConfig {
            views: 2,
            ..Default::default()
        };
        let e = turntable_views(&pts, &frame, &cfg).unwrap_err();
        assert!(e.to_string().contains("between 3"), "{e}");
        // and too many views, too fine or too coarse a grid for them
        for (views, grid_u, needle) in [
            (1_000_000, 32, "and 64"),
            (4, 1 << 40, "and 4096"),
            (60, 16, "holds no grid points"),
        ] {
            let cfg = ViewConfig {
                views,
                grid_u,
                ..Default::default()
            };
            let e = turntable_views(&pts, &frame, &cfg).unwrap_err();
            assert!(e.to_string().contains(needle), "{e}");
        }
    }
}
