//! The edge curves and control nets of a grid layout (issue 16: "more detail
//! per control point").
//!
//! A grid's patches meet along cut lines that run through the middle of the
//! data. Fitting each cut's curve to the border points of its two patches
//! alone (as for hand labels, [`super::super::curves`]) mixes points up to a
//! contact radius on either side of the cut, so wherever the sheet slopes
//! across a cut the curve is off by the slope times that offset, and every
//! patch inherits that error along its boundary. Here the cuts come from
//! one least-squares surface of the whole sheet instead, the *frame*, fitted
//! to every point at its `(u, v)` on the sheet's Coons base (the Coons
//! paper's parameters, [COONS19] §III): the vertices are the frame at the
//! crossings of the cuts and each edge curve is the frame's iso-parameter
//! curve between two crossings, exactly (the cuts are knots of the frame, so
//! the piece between two cuts is a B-spline of its own, cut out by knot
//! insertion, The NURBS Book §5.3). Each patch is then fitted inside those
//! curves with its boundary fixed, as every reconstruction patch is.
//!
//! **Control points where the detail is** (least-squares route). A
//! patch's control-point density (control points per unit length along
//! each direction) is made proportional to the RMS distance of its points
//! from one least-squares surface of the whole sheet at the grid's average
//! resolution (the one-patch residual: large over a badge or a nose, the
//! noise over a smooth panel), the way adaptive knot placement spaces knots
//! by the local error; the densities are scaled so that the model has at
//! most the control points of the uniform grid asked for (every patch
//! `N x M`), counted once
//! ([`crate::topology::PatchComplex::control_point_count`]). A uniform
//! tensor-product patch cannot do this: refining it about a badge refines
//! whole rows and columns of the sheet.
//!
//! **Knots.** A row of patches shares its cut curves along `u`, so the frame
//! gives row `r` a power-of-two count `m_r` of uniform `u` spans (dyadic knots
//! are exact under the reversal of an edge, as the network's own curves),
//! the largest power of two not above the least any of its patches wants;
//! a patch takes `k m_r` spans (`k >= 1` its own), whose knots contain its
//! edges' exactly, so the knot union of [`super::super::face`] adds none.
//! Columns likewise along `v`.
//!
//! Measured (BENCHMARKS.md, "Grid layout"): on a panel with a badge the
//! grid 3x3 beats the best single patch with as many control points by
//! 16-23%; on a face-like sheet (detail across the middle) and on terrain
//! (detail everywhere) it does not (within -1% to +26%).

use crate::bspline::{basis_funs, Curve, KnotVector, Surface};
use crate::fit::surface::{least_squares_surface_with, SurfaceLsqOptions};
use crate::{Error, Point3, Result};

use super::super::Network;
use super::grid::GridLayout;

/// The power of a patch's mean squared one-patch residual that its
/// control-point density is proportional to: 0.5, the RMS (measured on the
/// panel and the face sheet, BENCHMARKS.md: 0.25 gives 0.0661 instead of
/// 0.0614 on the panel, 0.0816 instead of 0.0802 on the face).
pub const DETAIL_POWER: f64 = 0.5;

/// How a grid layout's edge curves and control nets are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct GridOptions {
    /// Vertices and edge curves from the frame surface (default true)
    /// rather than from the border points of the two patches along each cut.
    pub frame: bool,
    /// Least-squares route with a frame: control nets by the detail of each
    /// patch within the uniform grid's total (default true), rather than one
    /// control-point density per unit length for all.
    pub detail_ctrl: bool,
}

impl Default for GridOptions {
    fn default() -> Self {
        Self {
            frame: true,
            detail_ctrl: true,
        }
    }
}

impl GridOptions {
    /// The grid as first built: edge curves from the border points, one net
    /// for every patch.
    pub fn plain() -> Self {
        Self {
            frame: false,
            detail_ctrl: false,
        }
    }

    /// The frame's edges, one control-point density for every patch.
    pub fn frame_only() -> Self {
        Self {
            frame: true,
            detail_ctrl: false,
        }
    }
}

/// The frame of a grid: the whole-sheet surface its edges come from, and the
/// knot spans of every row, column and patch.
#[derive(Debug, Clone)]
pub struct GridFrame {
    /// The frame surface on the base's `(u, v)`; the cuts are among its knots.
    pub surface: Surface,
    /// Per row, the `u` spans of its cut curves (a power of two).
    pub row_spans: Vec<usize>,
    /// Per column, the `v` spans of its cut curves (a power of two).
    pub col_spans: Vec<usize>,
    /// Per patch (`row C + column`), its control points along the base's
    /// `u` and `v` (`k m + 3` for its multiple `k` of the row's or column's spans).
    pub ctrl: Vec<(usize, usize)>,
    /// Per patch its relative control-point density (1 without detail).
    pub density: Vec<f64>,
}

/// The grid's rows and columns, from the layout's cuts.
fn shape(g: &GridLayout) -> (usize, usize) {
    (g.row_cuts.len() - 1, g.col_cuts.len() - 1)
}

/// Interior knots of `spans[k]` uniform spans inside each `[cuts[k], cuts[k+1]]`.
fn piecewise_knots(cuts: &[f64], spans: &[usize], p: usize) -> Result<KnotVector> {
    let mut inner = Vec::new();
    for (k, &m) in spans.iter().enumerate() {
        let (a, b) = (cuts[k], cuts[k + 1]);
        inner.extend((1..m).map(|j| a + (b - a) * j as f64 / m as f64));
        if k + 1 < spans.len() {
            inner.push(b);
        }
    }
    KnotVector::clamped(p, 0.0, 1.0, &inner)
}

/// The control points the model of a grid with these spans has, each
/// counted once (vertices, inner control points of the edges and of the
/// patches, [`crate::topology::PatchComplex::control_point_count`]).
pub fn grid_count(row: &[usize], col: &[usize], patch: &[(usize, usize)]) -> usize {
    let (r, c) = (row.len(), col.len());
    let vertices = (r + 1) * (c + 1);
    let along_u: usize = row.iter().map(|m| m + 1).sum::<usize>() * (c + 1);
    let along_v: usize = col.iter().map(|m| m + 1).sum::<usize>() * (r + 1);
    let inner: usize = patch.iter().map(|&(a, b)| (a - 2) * (b - 2)).sum();
    vertices + along_u + along_v + inner
}

/// Largest power of two not above `x` (at least 1).
fn pow2_floor(x: f64) -> usize {
    let mut m = 1usize;
    while (2 * m) as f64 <= x && m < 1 << 20 {
        m *= 2;
    }
    m
}

/// Spans of every row, column and patch for densities `rho` (per patch, row
/// major) scaled by `lambda`: the patch wants `lambda rho L` spans along a
/// side of length `L`, its row (column) takes the largest power of two not
/// above the least any of its patches wants, the patch a whole multiple of it.
fn allocate(
    lambda: f64,
    rho: &[f64],
    len: &[(f64, f64)],
    rows: usize,
    cols: usize,
) -> (Vec<usize>, Vec<usize>, Vec<(usize, usize)>) {
    let want = |k: usize| (lambda * rho[k] * len[k].0, lambda * rho[k] * len[k].1);
    // the largest power of two not above the least any patch of a row (column) wants
    let least = |w: &mut dyn Iterator<Item = f64>| pow2_floor(w.fold(f64::INFINITY, f64::min));
    let row: Vec<usize> = (0..rows)
        .map(|r| least(&mut (0..cols).map(|c| want(r * cols + c).0)))
        .collect();
    let col: Vec<usize> = (0..cols)
        .map(|c| least(&mut (0..rows).map(|r| want(r * cols + c).1)))
        .collect();
    let patch = (0..rows * cols)
        .map(|k| {
            let (mu, mv) = (row[k / cols], col[k % cols]);
            let (wu, wv) = want(k);
            let ku = ((wu / mu as f64).round() as usize).clamp(1, 1 << 12);
            let kv = ((wv / mv as f64).round() as usize).clamp(1, 1 << 12);
            (ku * mu + 3, kv * mv + 3)
        })
        .collect();
    (row, col, patch)
}

/// The frame of grid `g` over `points` (see the module docs): `ctrl` the
/// control points per patch of the uniform grid whose total the model keeps
/// (counted once); `detail` whether the patches' densities follow their
/// detail or are all the same.
///
/// Errors: a control net under 4 x 4; a frame the points do not determine
/// (a span without points).
pub fn grid_frame(
    points: &[Point3],
    g: &GridLayout,
    ctrl: (usize, usize),
    detail: bool,
) -> Result<GridFrame> {
    const P: usize = 3;
    if ctrl.0 < P + 1 || ctrl.1 < P + 1 || ctrl.0 > 200 || ctrl.1 > 200 {
        return Err(Error::InvalidInput(format!(
            "control net {} x {} is out of range: give 4 to 200 control points per direction (--ctrl NxM)",
            ctrl.0, ctrl.1
        )));
    }
    let (rows, cols) = shape(g);
    let n = rows * cols;
    // the budget: the uniform grid of `ctrl` nets, counted once
    let (su, sv) = (ctrl.0 - P, ctrl.1 - P);
    let budget = grid_count(&vec![su; rows], &vec![sv; cols], &vec![ctrl; n]);
    let rho = if detail {
        patch_detail(points, g, (rows * su + P, cols * sv + P))?
    } else {
        vec![1.0; n]
    };
    let (lu, lv) = g.side_lengths;
    let len: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let (r, c) = (k / cols, k % cols);
            (
                (g.row_cuts[r + 1] - g.row_cuts[r]) * lu,
                (g.col_cuts[c + 1] - g.col_cuts[c]) * lv,
            )
        })
        .collect();
    // the largest scale whose count stays within the budget (the count grows
    // with lambda; 64 halvings of a bracket)
    let count_at = |l: f64| {
        let (r, c, p) = allocate(l, &rho, &len, rows, cols);
        grid_count(&r, &c, &p)
    };
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    while count_at(hi) <= budget && hi < 1e300 {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if count_at(mid) <= budget {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (row_spans, col_spans, ctrl) = allocate(lo, &rho, &len, rows, cols);
    let ku = piecewise_knots(&g.row_cuts, &row_spans, P)?;
    let kv = piecewise_knots(&g.col_cuts, &col_spans, P)?;
    let surface = least_squares_surface_with(points, &g.uv, ku, kv, SurfaceLsqOptions::default())
        .map_err(|e| {
        Error::InvalidInput(format!(
            "the grid's frame surface ({} x {} spans over the whole sheet): {e}",
            row_spans.iter().sum::<usize>(),
            col_spans.iter().sum::<usize>()
        ))
    })?;
    Ok(GridFrame {
        surface,
        row_spans,
        col_spans,
        ctrl,
        density: rho,
    })
}

/// Per patch its control-point density from the detail: the mean squared
/// distance of its points from one least-squares surface of the whole sheet
/// with `ctrl` uniform control points (the resolution the grid has on
/// average), to the power [`DETAIL_POWER`].
fn patch_detail(points: &[Point3], g: &GridLayout, ctrl: (usize, usize)) -> Result<Vec<f64>> {
    let one = crate::fit::surface::fit_surface(
        points,
        &g.uv,
        &crate::fit::surface::SurfaceFitConfig {
            ctrl,
            knots: crate::fit::surface::KnotPlacement::Uniform,
            ..Default::default()
        },
    )?;
    let r2: Vec<f64> = points
        .iter()
        .zip(&g.uv)
        .map(|(p, t)| (one.point(t[0], t[1]) - p).norm_squared())
        .collect();
    let mut sorted = r2.clone();
    sorted.sort_by(f64::total_cmp);
    let n = g.labels.iter().max().map_or(0, |&m| m as usize + 1);
    let (mut sum, mut count) = (vec![0.0; n], vec![0usize; n]);
    for (&l, &e) in g.labels.iter().zip(&r2) {
        sum[l as usize] += e;
        count[l as usize] += 1;
    }
    // a floor keeps a patch the fit happens to pass through exactly finite
    let floor = 0.01 * sorted[sorted.len() / 2].max(f64::MIN_POSITIVE);
    Ok(sum
        .iter()
        .zip(&count)
        .map(|(s, &c)| (s / c.max(1) as f64).max(floor).powf(DETAIL_POWER))
        .collect())
}

/// The control points of the curve `t -> S(t, at)` (`along_u`) or
/// `t -> S(at, t)`, on the surface's knots in that direction.
fn iso_curve(s: &Surface, along_u: bool, at: f64) -> Vec<Point3> {
    let (p, q) = s.degrees();
    let (nu, nv) = s.counts();
    let cp = s.control_points();
    let (kv, deg) = if along_u {
        (s.knots_v(), q)
    } else {
        (s.knots_u(), p)
    };
    let span = kv.find_span(at);
    let (mut b, mut l, mut r) = (vec![0.0; deg + 1], vec![0.0; deg + 1], vec![0.0; deg + 1]);
    basis_funs(kv.as_slice(), deg, span, at, &mut b, &mut l, &mut r);
    let first = span - deg;
    if along_u {
        (0..nu)
            .map(|i| {
                let v = b
                    .iter()
                    .enumerate()
                    .fold(crate::Vector3::zeros(), |acc, (k, &w)| {
                        acc + cp[i * nv + first + k].coords * w
                    });
                Point3::from(v)
            })
            .collect()
    } else {
        (0..nv)
            .map(|j| {
                let v = b
                    .iter()
                    .enumerate()
                    .fold(crate::Vector3::zeros(), |acc, (k, &w)| {
                        acc + cp[(first + k) * nv + j].coords * w
                    });
                Point3::from(v)
            })
            .collect()
    }
}

/// The piece of a curve on `kv` with control points `ctrl` between the
/// knots `a < b`, on `[0, 1]` with `spans` uniform spans (the knots the piece
/// has between `a` and `b`), its ends replaced by `ends` (the vertices,
/// which they equal up to rounding).
fn piece(
    kv: &KnotVector,
    ctrl: Vec<Point3>,
    (a, b): (f64, f64),
    spans: usize,
    ends: (Point3, Point3),
) -> Result<Curve> {
    let p = kv.degree();
    let c = Curve::new(kv.clone(), ctrl)?;
    let mult = |x: f64| kv.as_slice().iter().filter(|&&t| t == x).count();
    let mut add = Vec::new();
    add.extend(std::iter::repeat_n(a, p.saturating_sub(mult(a))));
    add.extend(std::iter::repeat_n(b, p.saturating_sub(mult(b))));
    let c = c.refine(&add)?;
    let t = c.knots().as_slice();
    let last_a = t.iter().rposition(|&x| x == a).unwrap_or(p);
    let first = last_a - p;
    let cp = &c.control_points()[first..first + spans + p];
    let mut cp = cp.to_vec();
    cp[0] = ends.0;
    cp[spans + p - 1] = ends.1;
    Curve::new(KnotVector::uniform_clamped(p, spans + p)?, cp)
}

impl GridFrame {
    /// Replaces the vertices and edge curves of `net` (built from the grid's
    /// labels) by the frame's: every vertex the frame at the cut crossing
    /// nearest to it, every edge the frame's iso-curve between its two
    /// crossings. Returns, per edge, whether it runs along the base's `u`.
    ///
    /// Errors: vertices that are not the `(R + 1) x (C + 1)` crossings one to
    /// one, an edge that does not join two neighbouring crossings.
    pub fn apply(&self, g: &GridLayout, net: &mut Network) -> Result<Vec<bool>> {
        let (rows, cols) = shape(g);
        let s = &self.surface;
        let node = |i: usize, j: usize| s.point(g.row_cuts[i], g.col_cuts[j]);
        let mut at: Vec<(usize, usize)> = Vec::with_capacity(net.vertices.len());
        let mut seen = vec![false; (rows + 1) * (cols + 1)];
        for v in &net.vertices {
            let (mut best, mut d) = ((0, 0), f64::INFINITY);
            for i in 0..=rows {
                for j in 0..=cols {
                    let e = (node(i, j) - v).norm();
                    if e < d {
                        (best, d) = ((i, j), e);
                    }
                }
            }
            let k = best.0 * (cols + 1) + best.1;
            if seen[k] {
                return Err(Error::InvalidInput(format!(
                    "the grid's patch network has two corners at the crossing of cuts {} and {}; the grid's patches do not meet as a grid (use fewer rows or columns)",
                    best.0, best.1
                )));
            }
            seen[k] = true;
            at.push(best);
        }
        if at.len() != seen.len() {
            return Err(Error::InvalidInput(format!(
                "the grid's patch network has {} corners where a {rows}x{cols} grid has {}; its patches do not meet as a grid (use fewer rows or columns)",
                at.len(),
                seen.len()
            )));
        }
        let mut along = Vec::with_capacity(net.edges.len());
        for e in &mut net.edges {
            let ((i1, j1), (i2, j2)) = (at[e.start], at[e.end]);
            let ends = (node(i1, j1), node(i2, j2));
            // which cut the edge runs along, and its two crossings on it
            let (along_u, (a, b)) = if i1 == i2 && j1.abs_diff(j2) == 1 {
                (false, (j1, j2))
            } else if j1 == j2 && i1.abs_diff(i2) == 1 {
                (true, (i1, i2))
            } else {
                return Err(Error::InvalidInput(format!(
                    "the grid's patch network has an edge from the crossing ({i1}, {j1}) to ({i2}, {j2}), not along one cut between neighbouring crossings; its patches do not meet as a grid"
                )));
            };
            let (cuts, at_cut, knots, spans) = if along_u {
                (&g.row_cuts, g.col_cuts[j1], s.knots_u(), &self.row_spans)
            } else {
                (&g.col_cuts, g.row_cuts[i1], s.knots_v(), &self.col_spans)
            };
            let k = a.min(b);
            let ctrl = iso_curve(s, along_u, at_cut);
            let (lo, hi) = if a < b { ends } else { (ends.1, ends.0) };
            let c = piece(knots, ctrl, (cuts[k], cuts[k + 1]), spans[k], (lo, hi))?;
            e.curve = if a > b {
                crate::bspline::ops::reversed(&c)?
            } else {
                c
            };
            along.push(along_u);
        }
        for (v, &(i, j)) in net.vertices.iter_mut().zip(&at) {
            *v = node(i, j);
        }
        Ok(along)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::layout::grid::grid_labels;
    use crate::network::{build_network, NetworkConfig};
    use crate::progress::NoProgress;
    use crate::PointCloud;

    /// A 2 x 1 sheet, gently curved, with a bump near (1.6, 0.8).
    fn sheet() -> Vec<Point3> {
        let mut pts = Vec::new();
        for i in 0..=120 {
            for j in 0..=60 {
                let (x, y) = (i as f64 / 60.0, j as f64 / 60.0);
                let r2 = (x - 1.6).powi(2) + (y - 0.8).powi(2);
                pts.push(Point3::new(
                    x,
                    y,
                    0.1 * (x * y).sin() + 0.05 * (-r2 / 0.004).exp(),
                ));
            }
        }
        pts
    }

    #[test]
    fn frame_edges_are_its_iso_curves_and_nets_follow_the_bump() {
        let pts = sheet();
        let cloud = PointCloud::new(pts.clone()).unwrap();
        let g = grid_labels(&cloud, 3, 3, 1.0 / 60.0).unwrap();
        let f = grid_frame(&pts, &g, (8, 8), true).unwrap();
        // within the uniform grid's count, and the spans are whole multiples
        let budget = grid_count(&[5; 3], &[5; 3], &[(8, 8); 9]);
        let used = grid_count(&f.row_spans, &f.col_spans, &f.ctrl);
        assert!(used <= budget && used > budget / 2, "{used} of {budget}");
        for (k, &(a, b)) in f.ctrl.iter().enumerate() {
            assert_eq!((a - 3) % f.row_spans[k / 3], 0);
            assert_eq!((b - 3) % f.col_spans[k % 3], 0);
        }
        // the bump's patch has the densest net of all
        let bump = (0..pts.len())
            .min_by(|&x, &y| {
                let d = |p: &Point3| (p.x - 1.6).hypot(p.y - 0.8);
                d(&pts[x]).total_cmp(&d(&pts[y]))
            })
            .unwrap();
        let k = g.labels[bump] as usize;
        let size = |k: usize| f.ctrl[k].0 * f.ctrl[k].1;
        assert!((0..9).all(|j| j == k || size(j) < size(k)), "{:?}", f.ctrl);
        // the network's vertices and edges become the frame's crossings and
        // iso-curves (the edge curve at t is the frame at the linear
        // interpolation of its ends' parameters)
        let labelled = cloud
            .with_attribute("label", g.labels.iter().map(|&l| l as f64).collect())
            .unwrap();
        let mut net = build_network(&labelled, &NetworkConfig::default(), &NoProgress).unwrap();
        let along = f.apply(&g, &mut net).unwrap();
        assert_eq!(along.iter().filter(|&&a| a).count(), 12);
        let node = |p: Point3| {
            (0..=3)
                .flat_map(|i| (0..=3).map(move |j| (i, j)))
                .find(|&(i, j)| f.surface.point(g.row_cuts[i], g.col_cuts[j]) == p)
                .unwrap()
        };
        for e in &net.edges {
            let (a, b) = (node(net.vertices[e.start]), node(net.vertices[e.end]));
            assert_eq!(e.curve.point(0.0), net.vertices[e.start]);
            assert_eq!(e.curve.point(1.0), net.vertices[e.end]);
            for s in 0..=16 {
                let t = s as f64 / 16.0;
                let u = g.row_cuts[a.0] + t * (g.row_cuts[b.0] - g.row_cuts[a.0]);
                let v = g.col_cuts[a.1] + t * (g.col_cuts[b.1] - g.col_cuts[a.1]);
                let d = (e.curve.point(t) - f.surface.point(u, v)).norm();
                assert!(d < 1e-12, "edge {}-{} at {t}: {d}", e.start, e.end);
            }
        }
    }

    #[test]
    fn without_detail_equal_patches_get_nets_within_one_multiple() {
        let pts = sheet();
        let g = grid_labels(&PointCloud::new(pts.clone()).unwrap(), 3, 3, 1.0 / 60.0).unwrap();
        // one density per unit length: equal patches get nets within one
        // multiple of each other (the largest scale within the budget may
        // lift some of them, e.g. one column, and not the rest)
        let f = grid_frame(&pts, &g, (12, 12), false).unwrap();
        let spans: Vec<(usize, usize)> = f.ctrl.iter().map(|&(a, b)| (a - 3, b - 3)).collect();
        let (lo, hi) = spans.iter().fold((usize::MAX, 0), |(l, h), &(a, b)| {
            (l.min(a * b), h.max(a * b))
        });
        assert!(hi <= 2 * lo, "{:?}", f.ctrl);
        let budget = grid_count(&[9; 3], &[9; 3], &[(12, 12); 9]);
        assert!(grid_count(&f.row_spans, &f.col_spans, &f.ctrl) <= budget);
        let e = grid_frame(&pts, &g, (3, 12), false).unwrap_err();
        assert!(e.to_string().contains("4 to 200"), "{e}");
    }
}
