//! Least-squares B-spline surface fitting to scattered points with given
//! parameters ([NURBS97] section 9.4.3 generalised to scattered data):
//!
//! ```text
//! minimise  sum_k w_k |P_k - S(u_k, v_k)|^2
//!         + lambda ∫∫ |S_uu|^2 + 2 |S_uv|^2 + |S_vv|^2 du dv      (thin-plate energy)
//! ```
//!
//! The normal equations are assembled point by point, in parallel (one
//! accumulator per thread, summed at the end, so the result does not depend on
//! the thread count beyond rounding), in a band-block layout: control point
//! `(i, j)` couples only with `(i + di, j + dj)`, `|di| <= p`, `|dj| <= q`. The
//! lower triangle goes to faer's sparse Cholesky (AMD ordering, supernodal).
//! The thin-plate energy uses exact Gram matrices ([`super::gram`]).
//! In a periodic `u` direction the control rows wrap (`i mod count_u`).

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use super::gram;
use crate::bspline::{BasisWorkspace, KnotVector, Surface};
use crate::{Error, Point3, Result};

/// How the knots of a least-squares surface are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnotPlacement {
    /// Equally spaced interior knots.
    Uniform,
    /// Interior knots at quantiles of the parameter distribution (NURBS Book
    /// eq. 9.69 applied to the sorted parameters), so every span holds data.
    Distribution,
}

/// Configuration of [`fit_surface`].
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceFitConfig {
    /// Degrees `(p, q)` (default bicubic).
    pub degree: (usize, usize),
    /// Control-net size `(count_u, count_v)`; `count_u` counts distinct rows when
    /// periodic in `u` (default 16 x 16).
    pub ctrl: (usize, usize),
    /// Periodic (closed) in `u`, for cylinder-like clouds (default false).
    pub periodic_u: bool,
    /// Knot placement (default: from the parameter distribution).
    pub knots: KnotPlacement,
    /// Thin-plate smoothing weight `lambda` (default 0).
    pub smoothing: f64,
    /// Optional non-negative weight per point.
    pub weights: Option<Vec<f64>>,
}

impl Default for SurfaceFitConfig {
    fn default() -> Self {
        Self {
            degree: (3, 3),
            ctrl: (16, 16),
            periodic_u: false,
            knots: KnotPlacement::Distribution,
            smoothing: 0.0,
            weights: None,
        }
    }
}

/// Options of [`least_squares_surface_with`].
#[derive(Debug, Clone, Copy, Default)]
pub struct SurfaceLsqOptions<'a> {
    /// Thin-plate smoothing weight `lambda`.
    pub smoothing: f64,
    /// Optional non-negative weight per point.
    pub weights: Option<&'a [f64]>,
    /// The `u` knot vector is periodic (its last `p` control rows repeat the first).
    pub periodic_u: bool,
}

/// Most control points of a fitted surface (2^22, a 2048 x 2048 net).
pub const MAX_SURFACE_CONTROL_POINTS: usize = 1 << 22;

/// Fits a surface to `points` with parameters `uv` in `[0, 1]^2`.
pub fn fit_surface(points: &[Point3], uv: &[[f64; 2]], cfg: &SurfaceFitConfig) -> Result<Surface> {
    let (p, q) = cfg.degree;
    let (nu, nv) = cfg.ctrl;
    if p == 0 || q == 0 {
        return Err(Error::InvalidInput("degrees must be at least 1".into()));
    }
    if nv < q + 1 || (!cfg.periodic_u && nu < p + 1) || (cfg.periodic_u && nu < 2 * p + 1) {
        return Err(Error::InvalidInput(format!(
            "a {nu} x {nv} control net is too small for degrees {p} x {q} (need at least {} x {})",
            if cfg.periodic_u { 2 * p + 1 } else { p + 1 },
            q + 1
        )));
    }
    // the normal equations hold nu nv unknowns; degrees above 10 and nets
    // beyond 2^22 (a 2048 x 2048 net) are not what a CAD surface needs, and
    // would exhaust memory before any error could be reported
    let unknowns = nu
        .checked_mul(nv)
        .filter(|&n| n <= MAX_SURFACE_CONTROL_POINTS);
    if unknowns.is_none() || p > 10 || q > 10 {
        return Err(Error::InvalidInput(format!(
            "a {nu} x {nv} control net of degrees {p} x {q} is beyond the limits ({MAX_SURFACE_CONTROL_POINTS} control points, degree 10); choose a smaller net"
        )));
    }
    let ku = if cfg.periodic_u {
        KnotVector::uniform_periodic(p, nu)?
    } else {
        match cfg.knots {
            KnotPlacement::Uniform => KnotVector::uniform_clamped(p, nu)?,
            KnotPlacement::Distribution => distribution_knots(uv.iter().map(|t| t[0]), p, nu)?,
        }
    };
    let kv = match cfg.knots {
        KnotPlacement::Uniform => KnotVector::uniform_clamped(q, nv)?,
        KnotPlacement::Distribution => distribution_knots(uv.iter().map(|t| t[1]), q, nv)?,
    };
    let opts = SurfaceLsqOptions {
        smoothing: cfg.smoothing,
        weights: cfg.weights.as_deref(),
        periodic_u: cfg.periodic_u,
    };
    least_squares_surface_with(points, uv, ku, kv, opts)
}

/// Clamped knots on `[0, 1]` whose interior knots follow the distribution of the
/// given parameters (eq. 9.69 on the sorted values).
pub fn distribution_knots(
    params: impl Iterator<Item = f64>,
    p: usize,
    count: usize,
) -> Result<KnotVector> {
    let mut s: Vec<f64> = params.filter(|u| u.is_finite()).collect();
    s.sort_by(f64::total_cmp);
    if s.len() < count || count <= p + 1 {
        return KnotVector::uniform_clamped(p, count);
    }
    let mut interior = crate::param::knots::eq_9_69_interior(&s, p, count);
    // keep interior knots strictly inside (0, 1) and below multiplicity p
    let eps = 1e-9;
    for t in interior.iter_mut() {
        *t = t.clamp(eps, 1.0 - eps);
    }
    for k in 1..interior.len() {
        if interior[k] <= interior[k - 1] {
            interior[k] = (interior[k - 1] + eps).min(1.0 - eps);
        }
    }
    KnotVector::clamped(p, 0.0, 1.0, &interior)
}

/// Least-squares surface with given knot vectors (clamped, or periodic in `u`).
pub fn least_squares_surface_with(
    points: &[Point3],
    uv: &[[f64; 2]],
    ku: KnotVector,
    kv: KnotVector,
    opts: SurfaceLsqOptions,
) -> Result<Surface> {
    let (p, q) = (ku.degree(), kv.degree());
    let nu_total = ku.basis_count();
    let nu = if opts.periodic_u {
        nu_total - p
    } else {
        nu_total
    };
    let nv = kv.basis_count();
    let n = nu * nv;
    validate(points, uv, &ku, &kv, &opts, n)?;
    if opts.periodic_u && nu < 2 * p + 1 {
        return Err(Error::InvalidInput(format!(
            "periodic in u with degree {p} needs at least {} distinct control rows, got {nu}",
            2 * p + 1
        )));
    }
    let layout = Layout {
        p,
        q,
        nu,
        nv,
        periodic: opts.periodic_u,
    };
    let (mut acc, rhs, diag_data) = assemble(points, uv, &ku, &kv, opts.weights, &layout);
    if opts.smoothing > 0.0 {
        add_thin_plate(&mut acc, &ku, &kv, opts.smoothing, &layout);
    } else if let Some((i, j)) = diag_data
        .iter()
        .position(|&d| d <= 0.0)
        .map(|k| (k / nv, k % nv))
    {
        let tu = ku.as_slice();
        let tv = kv.as_slice();
        return Err(Error::Singular {
            what: "least-squares surface".into(),
            condition: f64::INFINITY,
            hint: format!(
                "no data point influences control point ({i}, {j}): the region u in [{:.4}, {:.4}], v in [{:.4}, {:.4}] is empty; add smoothing (--smooth) or use fewer control points",
                tu[i].max(ku.domain().0),
                tu[i + p + 1].min(ku.domain().1),
                tv[j].max(kv.domain().0),
                tv[j + q + 1].min(kv.domain().1)
            ),
        });
    }
    let sol = solve(acc, rhs, &layout)?;
    // unfold into the control net (repeating the first p rows when periodic)
    let mut ctrl = Vec::with_capacity(nu_total * nv);
    for i in 0..nu_total {
        let fi = i % nu;
        for j in 0..nv {
            let r = fi * nv + j;
            ctrl.push(Point3::new(sol[(r, 0)], sol[(r, 1)], sol[(r, 2)]));
        }
    }
    Surface::with_options(ku, kv, ctrl, None, opts.periodic_u, false)
}

/// Index bookkeeping of the band-block normal matrix.
struct Layout {
    p: usize,
    q: usize,
    nu: usize,
    nv: usize,
    periodic: bool,
}

impl Layout {
    /// Slots per row: `(2p+1)(2q+1)`.
    fn slots(&self) -> usize {
        (2 * self.p + 1) * (2 * self.q + 1)
    }
    /// Slot of the coupling with offsets `(di, dj)` (each shifted by `p`, `q`).
    #[inline]
    fn slot(&self, di_p: usize, dj_q: usize) -> usize {
        di_p * (2 * self.q + 1) + dj_q
    }
    /// Folded row index of the unfolded `u` index `i`.
    #[inline]
    fn fold(&self, i: usize) -> usize {
        if self.periodic {
            i % self.nu
        } else {
            i
        }
    }
    /// Column of slot `s` in row `r`, or `None` outside the net.
    fn column(&self, r: usize, s: usize) -> Option<usize> {
        let (i, j) = (r / self.nv, r % self.nv);
        let w = 2 * self.q + 1;
        let (di, dj) = (
            (s / w) as isize - self.p as isize,
            (s % w) as isize - self.q as isize,
        );
        let jj = j as isize + dj;
        if jj < 0 || jj >= self.nv as isize {
            return None;
        }
        let mut ii = i as isize + di;
        if self.periodic {
            ii = ii.rem_euclid(self.nu as isize);
        } else if ii < 0 || ii >= self.nu as isize {
            return None;
        }
        Some(ii as usize * self.nv + jj as usize)
    }
}

fn validate(
    points: &[Point3],
    uv: &[[f64; 2]],
    ku: &KnotVector,
    kv: &KnotVector,
    opts: &SurfaceLsqOptions,
    unknowns: usize,
) -> Result<()> {
    if points.len() != uv.len() {
        return Err(Error::LengthMismatch {
            what: "parameter pairs",
            expected: points.len(),
            got: uv.len(),
        });
    }
    crate::validate_points(points)?;
    let ((u0, u1), (v0, v1)) = (ku.domain(), kv.domain());
    let tol = 1e-12;
    for (k, t) in uv.iter().enumerate() {
        let inside = t[0] >= u0 - tol && t[0] <= u1 + tol && t[1] >= v0 - tol && t[1] <= v1 + tol;
        if !inside || !t[0].is_finite() || !t[1].is_finite() {
            return Err(Error::ParametersOutsideDomain {
                index: k,
                u: t[0],
                v: t[1],
                u_range: (u0, u1),
                v_range: (v0, v1),
            });
        }
    }
    super::validate_weights_and_smoothing(opts.weights, points.len(), opts.smoothing)?;
    if opts.smoothing == 0.0 {
        if points.len() < unknowns {
            return Err(Error::TooFewPoints {
                got: points.len(),
                needed: unknowns,
                what: format!(
                    "a least-squares surface with {unknowns} control points (without smoothing)"
                ),
            });
        }
        for (dir, name, count) in [(0usize, "u", ku.basis_count()), (1, "v", kv.basis_count())] {
            let mut vals: Vec<f64> = uv.iter().map(|t| t[dir]).collect();
            vals.sort_by(f64::total_cmp);
            vals.dedup();
            let need = if dir == 0 && opts.periodic_u {
                count - ku.degree()
            } else {
                count
            };
            if vals.len() < need {
                return Err(Error::InvalidInput(format!(
                    "the points have only {} distinct {name} parameters, but {need} control points in {name} need at least {need}; add smoothing or use fewer control points",
                    vals.len()
                )));
            }
        }
    }
    Ok(())
}

/// Points per chunk of the parallel assembly ([`crate::par::accumulate`]): a
/// constant, so the summation order does not depend on the thread count.
const ASSEMBLY_CHUNK: usize = 16_384;

/// Normal equations in band-block layout, right-hand sides, and the diagonal
/// data term per unknown (zero where no point influences a control point).
fn assemble(
    points: &[Point3],
    uv: &[[f64; 2]],
    ku: &KnotVector,
    kv: &KnotVector,
    weights: Option<&[f64]>,
    l: &Layout,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = l.nu * l.nv;
    let s = l.slots();
    let (p, q) = (l.p, l.q);
    let tu = ku.as_slice();
    let tv = kv.as_slice();
    // fixed chunks merged in order (crate::par): the sums, and so the
    // surface, are bit-identical for every thread count
    let (acc, rhs) = crate::par::accumulate(
        points.len(),
        ASSEMBLY_CHUNK,
        || (vec![0.0; n * s], vec![0.0; n * 3]),
        |(acc, rhs), range| {
            let mut wu = BasisWorkspace::new(p, 0);
            let mut wv = BasisWorkspace::new(q, 0);
            let mut b = vec![0.0; (p + 1) * (q + 1)];
            let mut rows = vec![0usize; (p + 1) * (q + 1)];
            for idx in range {
                let pt = &points[idx];
                let [u, v] = uv[idx];
                let w = weights.map_or(1.0, |w| w[idx]);
                let (su, sv) = (ku.find_span(u), kv.find_span(v));
                let nu_ = wu.values(tu, su, u);
                let nv_ = wv.values(tv, sv, v);
                for a in 0..=p {
                    for bb in 0..=q {
                        b[a * (q + 1) + bb] = nu_[a] * nv_[bb];
                        rows[a * (q + 1) + bb] = l.fold(su - p + a) * l.nv + sv - q + bb;
                    }
                }
                for a in 0..=p {
                    for bb in 0..=q {
                        let x = w * b[a * (q + 1) + bb];
                        if x == 0.0 {
                            continue;
                        }
                        let r = rows[a * (q + 1) + bb];
                        let base = r * s;
                        for c2 in 0..=p {
                            let srow = l.slot(c2 + p - a, 0);
                            for d in 0..=q {
                                acc[base + srow + d + q - bb] += x * b[c2 * (q + 1) + d];
                            }
                        }
                        rhs[r * 3] += x * pt.x;
                        rhs[r * 3 + 1] += x * pt.y;
                        rhs[r * 3 + 2] += x * pt.z;
                    }
                }
            }
        },
        |(a1, r1), (a2, r2)| {
            a1.iter_mut().zip(&a2).for_each(|(x, y)| *x += y);
            r1.iter_mut().zip(&r2).for_each(|(x, y)| *x += y);
        },
    );
    let centre = l.slot(p, q);
    let diag = (0..n).map(|r| acc[r * s + centre]).collect();
    (acc, rhs, diag)
}

/// Adds `lambda` times the thin-plate energy matrix
/// `G2u ⊗ G0v + 2 G1u ⊗ G1v + G0u ⊗ G2v`.
fn add_thin_plate(acc: &mut [f64], ku: &KnotVector, kv: &KnotVector, lambda: f64, l: &Layout) {
    let (p, q) = (l.p, l.q);
    let gu: Vec<Vec<f64>> = (0..3).map(|k| gram::band(ku, k)).collect();
    let gv: Vec<Vec<f64>> = (0..3).map(|k| gram::band(kv, k)).collect();
    let (wu, wv) = (2 * p + 1, 2 * q + 1);
    let s = l.slots();
    for i in 0..ku.basis_count() {
        let fi = l.fold(i);
        for dip in 0..wu {
            let (a2, a1, a0) = (
                gu[2][i * wu + dip],
                gu[1][i * wu + dip],
                gu[0][i * wu + dip],
            );
            if a2 == 0.0 && a1 == 0.0 && a0 == 0.0 {
                continue;
            }
            for j in 0..l.nv {
                for djq in 0..wv {
                    let g = a2 * gv[0][j * wv + djq]
                        + 2.0 * a1 * gv[1][j * wv + djq]
                        + a0 * gv[2][j * wv + djq];
                    if g != 0.0 {
                        acc[(fi * l.nv + j) * s + l.slot(dip, djq)] += lambda * g;
                    }
                }
            }
        }
    }
}

/// Sparse Cholesky of the lower triangle, three right-hand sides.
fn solve(acc: Vec<f64>, rhs: Vec<f64>, l: &Layout) -> Result<Mat<f64>> {
    let n = l.nu * l.nv;
    let s = l.slots();
    let mut trip = Vec::with_capacity(n * (s / 2 + 1));
    for r in 0..n {
        for sl in 0..s {
            let v = acc[r * s + sl];
            if v == 0.0 {
                continue;
            }
            if let Some(c) = l.column(r, sl) {
                if c <= r {
                    trip.push(Triplet::new(r, c, v));
                }
            }
        }
    }
    let singular = |hint: String| Error::Singular {
        what: "least-squares surface".into(),
        condition: f64::INFINITY,
        hint,
    };
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip)
        .map_err(|e| singular(format!("could not build the sparse matrix: {e:?}")))?;
    let llt = a.sp_cholesky(Side::Lower).map_err(|_| {
        singular(
            "the normal equations are not positive definite: the parameters do not spread over the control net (e.g. too few distinct u or v values); add smoothing or use fewer control points".into(),
        )
    })?;
    let mut x = Mat::<f64>::from_fn(n, 3, |i, c| rhs[i * 3 + c]);
    llt.solve_in_place(&mut x);
    if x.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(singular("the solution is not finite; add smoothing".into()));
    }
    Ok(x)
}
