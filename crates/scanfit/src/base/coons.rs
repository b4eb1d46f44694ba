//! Bilinearly blended Coons patches from four (or three) boundary curves.
//!
//! * Boundary curves ([`fit_boundary_curve`]): [PDE23]
//!   (§4.2) fits each side's points by a
//!   least-squares B-spline that passes through the side's two end points,
//!   with chord-length parameters and a clamped knot vector whose interior
//!   knots are uniform; [COONS19] (`coons-base-surface-parameterization`,
//!   §II eqs. 3-6 and §III) uses the same end-pinned least squares (NURBS Book
//!   eq. 9.63-9.67). [`BoundaryFit::Interpolation`] interpolates every side
//!   point instead (chord length, averaging knots; a cubic is C2, more than the
//!   C1 a base surface needs).
//! * The patch ([`CoonsPatch`]): [COONS19] eq. 16 = [PDE23] eq. 1,
//!
//!   ```text
//!   S_c(u, v) = [1-u  u  1] | -P00  -P01  P(0,v) | [1-v]
//!                           | -P10  -P11  P(1,v) | [ v ]
//!                           | P(u,0) P(u,1)  0   | [ 1 ]
//!   ```
//!
//!   (both OCR texts print the matrix legibly; [COONS19] names the second
//!   parameter `w`). `P00` is where `P(u,0)` meets `P(0,v)`, and so on.
//! * Three sides ([PDE23] §5.2, Fig. 10): the side `P(0, v)` degenerates to
//!   the corner shared by the first and last curve.
//! * Exact B-spline form ([`CoonsPatch::to_bspline`]): the opposite curves are
//!   refined to common knots; a function linear in one parameter is a B-spline
//!   of any degree on any clamped knot vector with control values at the
//!   Greville abscissae (linear precision, `sum_i xi_i N_i(u) = u`: de Boor, *A
//!   Practical Guide to Splines*, ch. IX), so
//!   every term of eq. 16 is a tensor-product B-spline on the same knots and
//!   their sum is exact to rounding.

/// Moved to [`crate::bspline::ops`]; re-exported here for existing callers.
pub use crate::bspline::ops::{greville, missing_knots, reversed};
use crate::bspline::ops::{make_compatible, to_unit_domain};
use crate::bspline::{Curve, KnotVector, Surface};
use crate::fit::{interpolate, least_squares_with, InterpolationConfig, LeastSquaresOptions};
use crate::param::{self, Method};
use crate::{Error, Point3, Result, Vector3};

/// How a side's points become a boundary curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundaryFit {
    /// End-pinned least squares, chord-length parameters, clamped knots with
    /// uniform interior knots ([PDE23] §4.2; [COONS19] eqs. 3-6).
    /// `ctrl_count: None` picks `round(sqrt(n))` control points for a side of
    /// `n` points, clamped to `[degree + 1, 30]` (the papers do not say).
    LeastSquares {
        /// Control points per curve (`None`: automatic).
        ctrl_count: Option<usize>,
    },
    /// Interpolation of every side point (chord length, averaging knots).
    Interpolation,
}

/// Settings of [`fit_boundary_curve`] and [`fit_boundary_curves`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryCurveConfig {
    /// Degree of every boundary curve (default 3).
    pub degree: usize,
    /// Least squares (default, automatic control-point count) or interpolation.
    pub fit: BoundaryFit,
}

impl Default for BoundaryCurveConfig {
    fn default() -> Self {
        Self {
            degree: 3,
            fit: BoundaryFit::LeastSquares { ctrl_count: None },
        }
    }
}

/// A side's fitted curve with the parameters its points received.
#[derive(Debug, Clone)]
pub struct BoundaryCurve {
    /// The curve, on `[0, 1]`, from the side's first point to its last.
    pub curve: Curve,
    /// Chord-length parameter of each side point.
    pub params: Vec<f64>,
    /// Largest `|Q_k - C(t_k)|` over the side's points.
    pub max_error: f64,
}

/// Inserts chord midpoints into a short polyline until it has `needed` points
/// (a two-point side becomes a straight curve of any degree).
fn densify(points: &[Point3], needed: usize) -> Vec<Point3> {
    let mut pts = points.to_vec();
    while pts.len() < needed && pts.len() >= 2 {
        // split the longest chord
        let k = (0..pts.len() - 1)
            .max_by(|&a, &b| {
                (pts[a + 1] - pts[a])
                    .norm()
                    .total_cmp(&(pts[b + 1] - pts[b]).norm())
            })
            .unwrap_or(0);
        let mid = Point3::from((pts[k].coords + pts[k + 1].coords) * 0.5);
        pts.insert(k + 1, mid);
    }
    pts
}

/// Fits one side's points (in order, first and last = the corners) by a
/// B-spline through the two end points: [PDE23] §4.2 / [COONS19] §III.
/// The curve's first and last control points are the side's end points
/// exactly. A side with fewer than `degree + 1` points is densified by chord
/// midpoints first.
pub fn fit_boundary_curve(points: &[Point3], cfg: &BoundaryCurveConfig) -> Result<BoundaryCurve> {
    let p = cfg.degree;
    if p == 0 {
        return Err(Error::InvalidInput(
            "boundary curve degree must be at least 1".into(),
        ));
    }
    crate::validate_points(points)?;
    if points.len() < 2 {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: 2,
            what: "a boundary curve (a side needs its two corners)".into(),
        });
    }
    let pts = densify(points, p + 1);
    let (mut curve, params) = match cfg.fit {
        BoundaryFit::LeastSquares { ctrl_count } => {
            let n = pts.len();
            let count = ctrl_count
                .unwrap_or_else(|| ((n as f64).sqrt().round() as usize).clamp(p + 1, 30))
                .min(n);
            if count < p + 1 {
                return Err(Error::InvalidInput(format!(
                    "{count} control points are too few for a boundary curve of degree {p}; use at least {}",
                    p + 1
                )));
            }
            let par = param::parameterize(&pts, Method::ChordLength, p, false)?;
            let kv = KnotVector::uniform_clamped(p, count)?;
            let opts = LeastSquaresOptions {
                fix_ends: true,
                ..Default::default()
            };
            let (c, _) = least_squares_with(&pts, &par.params, kv, opts)?;
            (c, par.params)
        }
        BoundaryFit::Interpolation => {
            let fit = interpolate(
                &pts,
                &InterpolationConfig {
                    degree: p,
                    method: Method::ChordLength,
                    ..Default::default()
                },
            )?;
            (fit.curve, fit.params)
        }
    };
    // the corners exactly (interpolation hits them to rounding only)
    curve = with_ends(&curve, pts[0], pts[pts.len() - 1])?;
    let max_error = pts
        .iter()
        .zip(&params)
        .map(|(q, &t)| (q - curve.point(t)).norm())
        .fold(0.0, f64::max);
    // report the parameters of the given points (densified ones dropped)
    let params = if pts.len() == points.len() {
        params
    } else {
        points
            .iter()
            .map(|q| {
                pts.iter()
                    .position(|x| x == q)
                    .map(|k| params[k])
                    .unwrap_or(0.0)
            })
            .collect()
    };
    Ok(BoundaryCurve {
        curve,
        params,
        max_error,
    })
}

/// Fits every side (see [`fit_boundary_curve`]).
pub fn fit_boundary_curves(
    sides: &[Vec<Point3>],
    cfg: &BoundaryCurveConfig,
) -> Result<Vec<BoundaryCurve>> {
    sides
        .iter()
        .enumerate()
        .map(|(k, s)| {
            fit_boundary_curve(s, cfg).map_err(|e| match e {
                Error::InvalidInput(m) => Error::InvalidInput(format!("side {k}: {m}")),
                other => other,
            })
        })
        .collect()
}

/// A copy of the clamped, non-rational `curve` with its end control points
/// (= its end points) set to `a` and `b`.
fn with_ends(curve: &Curve, a: Point3, b: Point3) -> Result<Curve> {
    let mut ctrl = curve.control_points().to_vec();
    let n = ctrl.len();
    ctrl[0] = a;
    ctrl[n - 1] = b;
    Curve::new(curve.knots().clone(), ctrl)
}

/// The constant curve `C(t) = a` of degree `p` (a degenerate side).
fn point_curve(a: Point3, p: usize) -> Result<Curve> {
    Curve::new(KnotVector::uniform_clamped(p, p + 1)?, vec![a; p + 1])
}

/// Four sides, or three with one degenerate side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sides {
    /// Four boundary curves.
    Four,
    /// Three boundary curves; `P(0, v)` is a single point.
    Three,
}

/// A bilinearly blended Coons patch on `[0, 1]^2` ([COONS19] eq. 16, PDE
/// paper eq. 1). The four curves are `P(u, 0)`, `P(u, 1)`, `P(0, v)` and
/// `P(1, v)`; their ends meet exactly at the corners.
#[derive(Debug, Clone, PartialEq)]
pub struct CoonsPatch {
    bottom: Curve,
    top: Curve,
    left: Curve,
    right: Curve,
    sides: Sides,
}

impl CoonsPatch {
    /// A patch from `P(u,0)` (`bottom`), `P(u,1)` (`top`), `P(0,v)` (`left`) and
    /// `P(1,v)` (`right`). Domains are mapped to `[0, 1]`. Corners closer than
    /// `1e-9` x the patch size are made identical (the average); farther
    /// apart is an error naming the two curves.
    pub fn new(bottom: &Curve, top: &Curve, left: &Curve, right: &Curve) -> Result<Self> {
        let b = to_unit_domain(bottom, "P(u,0)")?;
        let t = to_unit_domain(top, "P(u,1)")?;
        let l = to_unit_domain(left, "P(0,v)")?;
        let r = to_unit_domain(right, "P(1,v)")?;
        let ends = |c: &Curve| {
            let cp = c.control_points();
            (cp[0], cp[cp.len() - 1])
        };
        let ((b0, b1), (t0, t1), (l0, l1), (r0, r1)) = (ends(&b), ends(&t), ends(&l), ends(&r));
        let size = [b0, b1, t0, t1]
            .iter()
            .flat_map(|p| [b0, b1, t0, t1].map(|q| (p - q).norm()))
            .fold(0.0, f64::max);
        let tol = 1e-9 * size.max(f64::MIN_POSITIVE);
        let meet = |x: Point3, y: Point3, name: &str| -> Result<Point3> {
            let gap = (x - y).norm();
            if gap > tol {
                return Err(Error::InvalidInput(format!(
                    "the boundary curves do not meet at corner {name}: ({:.6}, {:.6}, {:.6}) and ({:.6}, {:.6}, {:.6}) are {gap:e} apart; give curves that share their end points",
                    x.x, x.y, x.z, y.x, y.y, y.z
                )));
            }
            Ok(Point3::from((x.coords + y.coords) * 0.5))
        };
        let p00 = meet(b0, l0, "P00 = P(0,0)")?;
        let p10 = meet(b1, r0, "P10 = P(1,0)")?;
        let p01 = meet(t0, l1, "P01 = P(0,1)")?;
        let p11 = meet(t1, r1, "P11 = P(1,1)")?;
        let degenerate = (l.control_points().iter().all(|c| *c == l0)) && p00 == p01;
        Ok(Self {
            bottom: with_ends(&b, p00, p10)?,
            top: with_ends(&t, p01, p11)?,
            left: with_ends(&l, p00, p01)?,
            right: with_ends(&r, p10, p11)?,
            sides: if degenerate {
                Sides::Three
            } else {
                Sides::Four
            },
        })
    }

    /// A patch from the curves around a boundary loop, in loop order, each in
    /// either direction (orientation is made consistent automatically): four
    /// curves `C0 -> C1 -> C2 -> C3 -> C0` give `P(u,0) = C0->C1`,
    /// `P(1,v) = C1->C2`, `P(u,1) = C3->C2`, `P(0,v) = C0->C3`; three curves
    /// `A -> B -> C -> A` give `P(u,0) = A->B`, `P(1,v) = B->C`, `P(u,1) = A->C`
    /// and the degenerate `P(0,v) = A` ([PDE23] §5.2). Ends closer than
    /// `1e-9` x the loop size are snapped together.
    pub fn from_loop(curves: &[Curve]) -> Result<Self> {
        if !(3..=4).contains(&curves.len()) {
            return Err(Error::InvalidInput(format!(
                "{} boundary curves given; a Coons patch needs 4 (or 3, one side degenerate)",
                curves.len()
            )));
        }
        let fwd: Vec<Curve> = curves
            .iter()
            .enumerate()
            .map(|(k, c)| to_unit_domain(c, &format!("boundary curve {k}")))
            .collect::<Result<_>>()?;
        let rev: Vec<Curve> = fwd.iter().map(reversed).collect::<Result<_>>()?;
        let start = |c: &Curve| c.control_points()[0];
        let end = |c: &Curve| c.control_points()[c.control_points().len() - 1];
        // chain greedily from either direction of the first curve; keep the
        // chain with the smaller total gap
        let chain = |first_reversed: bool| {
            let mut out: Vec<Curve> = vec![if first_reversed {
                rev[0].clone()
            } else {
                fwd[0].clone()
            }];
            let mut gaps = Vec::new();
            for k in 1..fwd.len() {
                let prev = end(&out[k - 1]);
                let (gf, gr) = (
                    (start(&fwd[k]) - prev).norm(),
                    (start(&rev[k]) - prev).norm(),
                );
                if gf <= gr {
                    out.push(fwd[k].clone());
                    gaps.push(gf);
                } else {
                    out.push(rev[k].clone());
                    gaps.push(gr);
                }
            }
            gaps.push((start(&out[0]) - end(&out[out.len() - 1])).norm());
            (out, gaps)
        };
        let (a, ga) = chain(false);
        let (b, gb) = chain(true);
        let (mut loop_curves, gaps) = if ga.iter().sum::<f64>() <= gb.iter().sum::<f64>() {
            (a, ga)
        } else {
            (b, gb)
        };
        let size = loop_curves
            .iter()
            .flat_map(|c| [start(c), end(c)])
            .flat_map(|p| loop_curves.iter().map(move |c| (start(c) - p).norm()))
            .fold(0.0, f64::max);
        let tol = 1e-9 * size.max(f64::MIN_POSITIVE);
        let n = loop_curves.len();
        for (k, &g) in gaps.iter().enumerate() {
            if g > tol {
                return Err(Error::InvalidInput(format!(
                    "boundary curve {k} ends {g:e} away from where curve {} starts (in either direction); the curves do not form a closed loop",
                    (k + 1) % n
                )));
            }
        }
        // snap: corner k = start of curve k = end of curve k - 1
        let corners: Vec<Point3> = (0..n)
            .map(|k| {
                Point3::from(
                    (start(&loop_curves[k]).coords + end(&loop_curves[(k + n - 1) % n]).coords)
                        * 0.5,
                )
            })
            .collect();
        for k in 0..n {
            loop_curves[k] = with_ends(&loop_curves[k], corners[k], corners[(k + 1) % n])?;
        }
        if n == 4 {
            Self::new(
                &loop_curves[0],
                &reversed(&loop_curves[2])?,
                &reversed(&loop_curves[3])?,
                &loop_curves[1],
            )
        } else {
            let apex = point_curve(corners[0], loop_curves[2].degree())?;
            Self::new(
                &loop_curves[0],
                &reversed(&loop_curves[2])?,
                &apex,
                &loop_curves[1],
            )
        }
    }

    /// `P(u, 0)`.
    pub fn bottom(&self) -> &Curve {
        &self.bottom
    }
    /// `P(u, 1)`.
    pub fn top(&self) -> &Curve {
        &self.top
    }
    /// `P(0, v)` (a single point for a three-sided patch).
    pub fn left(&self) -> &Curve {
        &self.left
    }
    /// `P(1, v)`.
    pub fn right(&self) -> &Curve {
        &self.right
    }
    /// Four sides, or three with `P(0, v)` degenerate.
    pub fn sides(&self) -> Sides {
        self.sides
    }

    /// The corners `[P00, P10, P11, P01]` (counter-clockwise in `(u, v)`).
    pub fn corners(&self) -> [Point3; 4] {
        let e = |c: &Curve, last: bool| {
            let cp = c.control_points();
            if last {
                cp[cp.len() - 1]
            } else {
                cp[0]
            }
        };
        [
            e(&self.bottom, false),
            e(&self.bottom, true),
            e(&self.top, true),
            e(&self.top, false),
        ]
    }

    /// `S_c(u, v)` by eq. 16 / eq. 1, `(u, v)` clamped to `[0, 1]^2`.
    pub fn point(&self, u: f64, v: f64) -> Point3 {
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let [p00, p10, p11, p01] = self.corners();
        let (pu0, pu1) = (self.bottom.point(u).coords, self.top.point(u).coords);
        let (p0v, p1v) = (self.left.point(v).coords, self.right.point(v).coords);
        // [1-u u 1] M [1-v v 1]^T, row by row of M
        let row0 = -p00.coords * (1.0 - v) - p01.coords * v + p0v;
        let row1 = -p10.coords * (1.0 - v) - p11.coords * v + p1v;
        let row2 = pu0 * (1.0 - v) + pu1 * v;
        Point3::from(row0 * (1.0 - u) + row1 * u + row2)
    }

    /// `(S_c, dS_c/du, dS_c/dv)` at `(u, v)` (eq. 16 differentiated; the
    /// general derivatives are [`crate::surface::ParametricSurface::derivatives`]).
    ///
    /// ```
    /// use scanfit::base::CoonsPatch;
    /// use scanfit::bspline::{Curve, KnotVector};
    /// use scanfit::Point3;
    /// let line = |a: [f64; 3], b: [f64; 3]| {
    ///     let k = KnotVector::uniform_clamped(1, 2).unwrap();
    ///     Curve::new(k, vec![Point3::from(a), Point3::from(b)]).unwrap()
    /// };
    /// // the unit square
    /// let c = CoonsPatch::new(
    ///     &line([0., 0., 0.], [1., 0., 0.]),
    ///     &line([0., 1., 0.], [1., 1., 0.]),
    ///     &line([0., 0., 0.], [0., 1., 0.]),
    ///     &line([1., 0., 0.], [1., 1., 0.]),
    /// )
    /// .unwrap();
    /// let (p, su, sv) = c.derivatives(0.25, 0.5);
    /// assert!((p - Point3::new(0.25, 0.5, 0.0)).norm() < 1e-15);
    /// assert!((su.x - 1.0).abs() < 1e-15 && (sv.y - 1.0).abs() < 1e-15);
    /// ```
    pub fn derivatives(&self, u: f64, v: f64) -> (Point3, Vector3, Vector3) {
        use crate::surface::ParametricSurface;
        let mut ws = self.workspace(1);
        let mut d = [Vector3::zeros(); 4];
        ParametricSurface::derivatives(self, u, v, 1, &mut ws, &mut d);
        (Point3::from(d[0]), d[2], d[1])
    }

    /// The patch as a tensor-product B-spline surface, exact to rounding:
    /// degree `p` in `u` (the degree of `P(u,0)` and `P(u,1)`, which must
    /// agree), `q` in `v`; knots the union of the opposite curves' knots.
    /// With Greville abscissae `xi_i`, `eta_j` and the refined control points
    /// `B_i, T_i` (of `P(u,0), P(u,1)`) and `L_j, R_j`:
    /// `P_ij = (1-eta_j) B_i + eta_j T_i + (1-xi_i) L_j + xi_i R_j - bilinear(xi_i, eta_j)`.
    pub fn to_bspline(&self) -> Result<Surface> {
        let (bottom, top) = make_compatible(&self.bottom, &self.top, "P(u,0) and P(u,1)")?;
        let (left, right) = make_compatible(&self.left, &self.right, "P(0,v) and P(1,v)")?;
        let ku = bottom.knots().clone();
        let kv = left.knots().clone();
        let (xi, eta) = (greville(&ku), greville(&kv));
        let [p00, p10, p11, p01] = self.corners().map(|p| p.coords);
        let (bc, tc) = (bottom.control_points(), top.control_points());
        let (lc, rc) = (left.control_points(), right.control_points());
        let mut ctrl = Vec::with_capacity(xi.len() * eta.len());
        for (i, &x) in xi.iter().enumerate() {
            for (j, &y) in eta.iter().enumerate() {
                let bilinear = p00 * ((1.0 - x) * (1.0 - y))
                    + p10 * (x * (1.0 - y))
                    + p01 * ((1.0 - x) * y)
                    + p11 * (x * y);
                let c = bc[i].coords * (1.0 - y)
                    + tc[i].coords * y
                    + lc[j].coords * (1.0 - x)
                    + rc[j].coords * x
                    - bilinear;
                ctrl.push(Point3::from(c));
            }
        }
        if self.sides() == Sides::Three {
            // the collapsed side P(0, v) is the apex exactly, not up to rounding
            let apex = Point3::from(p00);
            for c in ctrl.iter_mut().take(eta.len()) {
                *c = apex;
            }
        }
        Surface::new(ku, kv, ctrl)
    }
}

/// A Coons patch translates with its four boundary curves (eq. 16 is affine
/// in them).
impl crate::centring::Translate for CoonsPatch {
    fn translate(&mut self, by: &Vector3) {
        for c in [
            &mut self.bottom,
            &mut self.top,
            &mut self.left,
            &mut self.right,
        ] {
            crate::centring::Translate::translate(c, by);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_curve(pts: &[[f64; 3]]) -> Curve {
        let ctrl: Vec<Point3> = pts.iter().map(|p| Point3::new(p[0], p[1], p[2])).collect();
        Curve::new(KnotVector::uniform_clamped(3, ctrl.len()).unwrap(), ctrl).unwrap()
    }

    fn patch() -> CoonsPatch {
        // a saddle-like frame with curved sides
        let bottom = line_curve(&[
            [0., 0., 0.],
            [0.3, -0.2, 0.4],
            [0.7, 0.1, -0.2],
            [1., 0., 0.],
        ]);
        let right = line_curve(&[
            [1., 0., 0.],
            [1.2, 0.3, 0.5],
            [0.9, 0.5, 0.0],
            [1.1, 0.8, 0.2],
            [1., 1., 0.3],
        ]);
        let top = line_curve(&[
            [0., 1., 0.5],
            [0.5, 1.3, 0.0],
            [0.8, 1.1, 0.2],
            [1., 1., 0.3],
        ]);
        let left = line_curve(&[
            [0., 0., 0.],
            [-0.2, 0.4, 0.1],
            [0.1, 0.7, 0.3],
            [0., 1., 0.5],
        ]);
        CoonsPatch::new(&bottom, &top, &left, &right).unwrap()
    }

    #[test]
    fn interpolates_the_four_boundaries() {
        let s = patch();
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            assert!((s.point(t, 0.0) - s.bottom().point(t)).norm() < 1e-14);
            assert!((s.point(t, 1.0) - s.top().point(t)).norm() < 1e-14);
            assert!((s.point(0.0, t) - s.left().point(t)).norm() < 1e-14);
            assert!((s.point(1.0, t) - s.right().point(t)).norm() < 1e-14);
        }
        // straight, uniformly parameterized sides: the patch is the bilinear map
        let third = 1.0 / 3.0;
        let sq = CoonsPatch::from_loop(&[
            line_curve(&[
                [0., 0., 0.],
                [third, 0., 0.],
                [2. * third, 0., 0.],
                [1., 0., 0.],
            ]),
            line_curve(&[
                [1., 0., 0.],
                [1., 2. * third, 0.],
                [1., 4. * third, 0.],
                [1., 2., 0.],
            ]),
            line_curve(&[
                [1., 2., 0.],
                [2. * third, 2., 0.],
                [third, 2., 0.],
                [0., 2., 0.],
            ]),
            line_curve(&[
                [0., 2., 0.],
                [0., 4. * third, 0.],
                [0., 2. * third, 0.],
                [0., 0., 0.],
            ]),
        ])
        .unwrap();
        assert!((sq.point(0.3, 0.6) - Point3::new(0.3, 1.2, 0.0)).norm() < 1e-14);
    }

    #[test]
    fn bspline_form_is_exact() {
        let s = patch();
        let b = s.to_bspline().unwrap();
        assert_eq!(b.degrees(), (3, 3));
        for i in 0..=12 {
            for j in 0..=12 {
                let (u, v) = (i as f64 / 12.0, j as f64 / 12.0);
                assert!((b.point(u, v) - s.point(u, v)).norm() < 1e-13, "{u} {v}");
            }
        }
    }

    #[test]
    fn derivatives_match_differences() {
        let s = patch();
        let (u, v, h) = (0.37, 0.61, 1e-6);
        let (_, su, sv) = s.derivatives(u, v);
        let fu = (s.point(u + h, v) - s.point(u - h, v)) / (2.0 * h);
        let fv = (s.point(u, v + h) - s.point(u, v - h)) / (2.0 * h);
        assert!((su - fu).norm() < 1e-7, "{su} {fu}");
        assert!((sv - fv).norm() < 1e-7, "{sv} {fv}");
    }

    #[test]
    fn loop_orientation_is_fixed_and_three_sides_degenerate() {
        let a = line_curve(&[[0., 0., 0.], [0.3, -0.1, 0.], [0.6, -0.1, 0.], [1., 0., 0.]]);
        let b = line_curve(&[
            [1., 0., 0.],
            [0.9, 0.3, 0.1],
            [0.7, 0.7, 0.1],
            [0.5, 1., 0.],
        ]);
        // the third curve given backwards (A <- C)
        let c = line_curve(&[
            [0., 0., 0.],
            [0.1, 0.3, 0.2],
            [0.3, 0.7, 0.2],
            [0.5, 1., 0.],
        ]);
        let s = CoonsPatch::from_loop(&[a, b, c]).unwrap();
        assert_eq!(s.sides(), Sides::Three);
        for k in 0..=10 {
            assert!((s.point(0.0, k as f64 / 10.0) - Point3::origin()).norm() < 1e-15);
        }
        assert!((s.point(1.0, 1.0) - Point3::new(0.5, 1.0, 0.0)).norm() < 1e-15);
        let bs = s.to_bspline().unwrap();
        assert!((bs.point(0.3, 0.8) - s.point(0.3, 0.8)).norm() < 1e-14);
        // a gap is an error that names the curves
        let far = line_curve(&[[5., 5., 5.], [6., 6., 6.], [7., 7., 7.], [8., 9., 9.]]);
        let e = CoonsPatch::from_loop(&[far.clone(), far.clone(), far]).unwrap_err();
        assert!(e.to_string().contains("closed loop"), "{e}");
    }

    #[test]
    fn boundary_curves_pass_through_the_corners() {
        let pts: Vec<Point3> = (0..40)
            .map(|k| {
                let t = k as f64 / 39.0;
                Point3::new(t, 0.1 * (6.0 * t).sin() + 0.003 * ((k * 7) % 5) as f64, 0.0)
            })
            .collect();
        for fit in [
            BoundaryFit::LeastSquares { ctrl_count: None },
            BoundaryFit::Interpolation,
        ] {
            let c = fit_boundary_curve(&pts, &BoundaryCurveConfig { degree: 3, fit }).unwrap();
            assert_eq!(c.curve.point(0.0), pts[0]);
            assert_eq!(c.curve.point(1.0), pts[39]);
            assert!(c.max_error < 0.02, "{}", c.max_error);
        }
        // two points: a straight cubic
        let two = [Point3::origin(), Point3::new(2.0, 0.0, 0.0)];
        let c = fit_boundary_curve(&two, &BoundaryCurveConfig::default()).unwrap();
        assert!((c.curve.point(0.25) - Point3::new(0.5, 0.0, 0.0)).norm() < 1e-12);
    }
}
