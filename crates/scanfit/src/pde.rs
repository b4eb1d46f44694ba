//! PDE deformation surfaces on a Coons patch ([PDE23],
//! §4.5).
//!
//! The thin-plate equation `D (w_uuuu + 2 w_uuvv + w_vvvv) = q_w` (eq. 4,
//! `w = x, y, z`) with the lateral force a sine series
//! `q_w = sum_{m<=M, n<=N} q_wmn sin(m pi u) sin(n pi v)` (eq. 5) has the
//! particular solution (eqs. 6-11)
//!
//! ```text
//! w(u, v) = 1/(D pi^4) sum_{m=1}^{M} sum_{n=1}^{N} q_wmn / (m^2 + n^2)^2 sin(m pi u) sin(n pi v)
//! ```
//!
//! (the paper writes `m^4 + 2 m^2 n^2 + n^4` = `(m^2 + n^2)^2`). It vanishes on
//! the boundary of `[0, 1]^2`, so `S = S_c + S_PDE` (eq. 14) keeps the Coons
//! patch's boundary curves and patches that share boundaries join without gaps.
//! The `q_wmn` minimise `E_w = sum_i [wbar_i - w(u_i, v_i)]^2` (eq. 12) with
//! `wbar_i` the offset of point `i` from `S_c(u_i, v_i)`; the normal equations
//! are eq. 13. We solve them for `w_mn = q_wmn / (D pi^4 (m^2+n^2)^2)` (eq. 10)
//! — a column scaling that leaves the minimiser unchanged and keeps the system
//! as well conditioned as the sine basis itself — and report
//! `q_wmn = D pi^4 (m^2+n^2)^2 w_mn`. As the paper notes (§5.3), `D` then only
//! scales `q`: the surface does not depend on it.
//!
//! Errors are eq. 15: mean and maximum of `|P_i - S(u_i, v_i)|`.

use std::f64::consts::PI;

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use rayon::prelude::*;

use crate::base::CoonsPatch;
use crate::bspline::ops::{knot_union, refine_surface_to};
use crate::bspline::Surface;
use crate::fit::interpolate_with;
use crate::metrics::ErrorStats;
use crate::{Error, Point3, Result, Vector3};

/// Settings of [`fit_pde`] (the paper's defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PdeConfig {
    /// Terms in `u`, `M` (paper: 5; 10 in Table 2 and §5.4).
    pub m: usize,
    /// Terms in `v`, `N` (paper: 5).
    pub n: usize,
    /// Flexural rigidity `D` (eq. 3; the paper sets 1). Must be positive; it
    /// does not change the fitted surface.
    pub d: f64,
}

impl Default for PdeConfig {
    fn default() -> Self {
        Self { m: 5, n: 5, d: 1.0 }
    }
}

/// The deformation `S_PDE(u, v)` of eq. 11, one coefficient vector per term.
#[derive(Debug, Clone, PartialEq)]
pub struct PdeDeformation {
    m: usize,
    n: usize,
    d: f64,
    /// `w_mn` (eq. 10) at `(m - 1) * n + (n - 1)`, for x, y, z at once.
    w: Vec<Vector3>,
}

/// `sin(k pi t)`, exactly 0 at `t = 0` and `t = 1` (so the deformation is
/// exactly zero on the boundary, not `1e-16`).
fn sin_k_pi(k: usize, t: f64) -> f64 {
    if t <= 0.0 || t >= 1.0 {
        0.0
    } else {
        (k as f64 * PI * t).sin()
    }
}

/// `D pi^4 (m^2 + n^2)^2`, the factor between `q_wmn` and `w_mn` (eq. 10).
fn factor(d: f64, m: usize, n: usize) -> f64 {
    let s = (m * m + n * n) as f64;
    d * PI.powi(4) * s * s
}

impl PdeDeformation {
    /// `(M, N)`.
    pub fn terms(&self) -> (usize, usize) {
        (self.m, self.n)
    }

    /// The flexural rigidity `D`.
    pub fn rigidity(&self) -> f64 {
        self.d
    }

    /// `w_mn = q_wmn / (D pi^4 (m^2 + n^2)^2)` (eq. 10), `1 <= m <= M`, `1 <= n <= N`.
    pub fn w_coefficient(&self, m: usize, n: usize) -> Option<Vector3> {
        (1..=self.m)
            .contains(&m)
            .then_some(())
            .filter(|_| (1..=self.n).contains(&n))
            .map(|_| self.w[(m - 1) * self.n + (n - 1)])
    }

    /// The lateral force coefficient `q_wmn` (eq. 5) of term `(m, n)`.
    pub fn q_coefficient(&self, m: usize, n: usize) -> Option<Vector3> {
        self.w_coefficient(m, n).map(|w| w * factor(self.d, m, n))
    }

    /// The partial derivative `d^(k+l) S_PDE / du^k dv^l` at `(u, v)` in
    /// `[0, 1]^2` (eq. 11 differentiated term by term:
    /// `d^k/du^k sin(m pi u) = (m pi)^k sin(m pi u + k pi / 2)`).
    ///
    /// ```
    /// # use scanfit::base::CoonsPatch;
    /// # use scanfit::bspline::{Curve, KnotVector};
    /// # use scanfit::pde::{fit_pde, PdeConfig};
    /// # use scanfit::Point3;
    /// # let line = |a: [f64; 3], b: [f64; 3]| Curve::new(KnotVector::uniform_clamped(1, 2).unwrap(), vec![Point3::from(a), Point3::from(b)]).unwrap();
    /// # let c = CoonsPatch::new(&line([0., 0., 0.], [1., 0., 0.]), &line([0., 1., 0.], [1., 1., 0.]), &line([0., 0., 0.], [0., 1., 0.]), &line([1., 0., 0.], [1., 1., 0.])).unwrap();
    /// // points on z = 0.1 sin(pi u) sin(pi v) over the unit square
    /// let uv: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64 / 9.0, (i / 10) as f64 / 9.0]).collect();
    /// let pts: Vec<Point3> = uv.iter().map(|t| {
    ///     let s = |x: f64| (std::f64::consts::PI * x).sin();
    ///     Point3::new(t[0], t[1], 0.1 * s(t[0]) * s(t[1]))
    /// }).collect();
    /// let fit = fit_pde(&c, &pts, &uv, &PdeConfig::default()).unwrap();
    /// // d/du at the centre vanishes, d/du at u = 0 is 0.1 pi sin(pi v)
    /// let d = &fit.surface.deformation;
    /// assert!(d.derivative(0.5, 0.5, 1, 0).z.abs() < 1e-9);
    /// assert!((d.derivative(0.0, 0.5, 1, 0).z - 0.1 * std::f64::consts::PI).abs() < 1e-9);
    /// ```
    pub fn derivative(&self, u: f64, v: f64, k: usize, l: usize) -> Vector3 {
        let der = |j: usize, order: usize, t: f64| {
            let w = j as f64 * PI;
            let f = match order % 4 {
                0 => sin_k_pi(j, t),
                1 => (w * t).cos(),
                2 => -sin_k_pi(j, t),
                _ => -(w * t).cos(),
            };
            w.powi(order as i32) * f
        };
        let su: Vec<f64> = (1..=self.m).map(|m| der(m, k, u)).collect();
        let sv: Vec<f64> = (1..=self.n).map(|n| der(n, l, v)).collect();
        let mut out = Vector3::zeros();
        for (a, &x) in su.iter().enumerate() {
            for (b, &y) in sv.iter().enumerate() {
                out += self.w[a * self.n + b] * (x * y);
            }
        }
        out
    }

    /// `S_PDE(u, v)` (eq. 11), zero on the boundary of `[0, 1]^2`.
    pub fn displacement(&self, u: f64, v: f64) -> Vector3 {
        let su: Vec<f64> = (1..=self.m).map(|m| sin_k_pi(m, u)).collect();
        let sv: Vec<f64> = (1..=self.n).map(|n| sin_k_pi(n, v)).collect();
        let mut out = Vector3::zeros();
        for (a, &x) in su.iter().enumerate() {
            for (b, &y) in sv.iter().enumerate() {
                out += self.w[a * self.n + b] * (x * y);
            }
        }
        out
    }
}

/// `S(u, v) = S_c(u, v) + S_PDE(u, v)` (eq. 14).
#[derive(Debug, Clone, PartialEq)]
pub struct PdeSurface {
    /// The Coons patch `S_c`.
    pub coons: CoonsPatch,
    /// The deformation `S_PDE`.
    pub deformation: PdeDeformation,
}

/// Settings of [`PdeSurface::to_bspline`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsplineConversionConfig {
    /// Largest allowed distance between `S` and its B-spline form, in data
    /// units, checked on a grid twice as fine as the interpolation grid.
    pub tolerance: f64,
    /// Most knot spans per direction before giving up (default 512).
    pub max_spans: usize,
    /// Most control points of the result (default `None`: no cap). When the
    /// next refinement would exceed it, the conversion stops at the last
    /// one within the cap, whatever its deviation, and says so
    /// ([`PdeBspline::capped`]); the pipelines cap at the number of input
    /// points, so the exported net never holds more control points than
    /// there are data.
    pub max_control_points: Option<usize>,
}

impl BsplineConversionConfig {
    /// A conversion to within `tolerance` data units.
    pub fn new(tolerance: f64) -> Self {
        Self {
            tolerance,
            max_spans: 512,
            max_control_points: None,
        }
    }
}

/// The B-spline form of a PDE surface.
#[derive(Debug, Clone)]
pub struct PdeBspline {
    /// The surface: the exact Coons B-spline plus an interpolant of `S_PDE`.
    pub surface: Surface,
    /// Largest `|S_B - S|` on the check grid (data units).
    pub max_deviation: f64,
    /// Uniform interpolation spans per direction used for `S_PDE`.
    pub spans: usize,
    /// The control-point cap stopped the refinement before the tolerance
    /// was met (`max_deviation` is then above it).
    pub capped: bool,
}

impl PdeSurface {
    /// `S(u, v)` (eq. 14).
    pub fn point(&self, u: f64, v: f64) -> Point3 {
        self.coons.point(u, v) + self.deformation.displacement(u, v)
    }

    /// A B-spline surface within `cfg.tolerance` of `S`: the Coons patch is
    /// converted exactly ([`CoonsPatch::to_bspline`]); `S_PDE` is interpolated
    /// on a uniform `(k+1) x (k+1)` grid (tensor-product interpolation, NURBS
    /// Book A9.4, degrees of the Coons B-spline, averaging knots), `k` doubling
    /// from `max(8, 2 max(M, N))` until the deviation sampled at every quarter
    /// of every cell, with a 20% margin, is within tolerance. The interpolant is exactly zero on the boundary,
    /// so the boundary curves stay those of the Coons patch. Both parts are
    /// refined to common knots and added.
    pub fn to_bspline(&self, cfg: &BsplineConversionConfig) -> Result<PdeBspline> {
        if !(cfg.tolerance.is_finite() && cfg.tolerance > 0.0) {
            return Err(Error::InvalidInput(format!(
                "B-spline conversion tolerance {} must be a positive number of data units",
                cfg.tolerance
            )));
        }
        let base = self.coons.to_bspline()?;
        let (p, q) = base.degrees();
        let (m, n) = self.deformation.terms();
        let mut k = (2 * m.max(n)).max(8).max(p.max(q) + 1);
        let cap = cfg.max_control_points.unwrap_or(usize::MAX);
        let mut best: Option<PdeBspline> = None;
        loop {
            if k > cfg.max_spans {
                return Err(Error::InvalidInput(format!(
                    "the B-spline form of the PDE surface would need more than {} x {} spans for {m} x {n} terms; allow more spans or use fewer PDE terms",
                    cfg.max_spans, cfg.max_spans
                )));
            }
            let w = self.interpolate_deformation(k, p, q)?;
            // check every quarter of every cell (nodes, quarter points and
            // midpoints, boundary cells included), and keep a margin of 20%
            // for the maximum between the samples
            let check = 4 * k;
            let dev = (0..=check)
                .into_par_iter()
                .map(|i| {
                    let u = i as f64 / check as f64;
                    (0..=check)
                        .map(|j| {
                            let v = j as f64 / check as f64;
                            (w.point(u, v).coords - self.deformation.displacement(u, v)).norm()
                        })
                        .fold(0.0, f64::max)
                })
                .reduce(|| 0.0, f64::max);
            let (ku, kv) = (
                knot_union(base.knots_u(), w.knots_u())?,
                knot_union(base.knots_v(), w.knots_v())?,
            );
            let count = ku.basis_count() * kv.basis_count();
            if count > cap {
                return match best {
                    Some(mut b) => {
                        b.capped = true;
                        Ok(b)
                    }
                    None => Err(Error::InvalidInput(format!(
                        "the B-spline form of the PDE surface needs {count} control points with the fewest spans ({k}), more than the cap of {cap}; use fewer PDE terms or boundary-curve control points"
                    ))),
                };
            }
            let (a, b) = (
                refine_surface_to(&base, &ku, &kv)?,
                refine_surface_to(&w, &ku, &kv)?,
            );
            let ctrl = a
                .control_points()
                .iter()
                .zip(b.control_points())
                .map(|(x, y)| x + y.coords)
                .collect();
            let result = PdeBspline {
                surface: Surface::new(ku, kv, ctrl)?,
                max_deviation: dev,
                spans: k,
                capped: false,
            };
            if dev * 1.2 <= cfg.tolerance {
                return Ok(result);
            }
            best = Some(result);
            if 2 * k > cfg.max_spans {
                return Err(Error::InvalidInput(format!(
                    "the B-spline form of the PDE surface deviates by {dev:e} with {k} x {k} spans, more than the tolerance {:e}; allow a larger tolerance or fewer PDE terms",
                    cfg.tolerance
                )));
            }
            k *= 2;
        }
    }

    /// Tensor-product interpolant of `S_PDE` on the uniform `(k+1)^2` grid.
    fn interpolate_deformation(&self, k: usize, p: usize, q: usize) -> Result<Surface> {
        let t: Vec<f64> = (0..=k).map(|i| i as f64 / k as f64).collect();
        let ku = crate::param::knots::averaging(&t, p)?;
        let kv = crate::param::knots::averaging(&t, q)?;
        // along u for every column v_j, then along v through the results
        let cols: Vec<Vec<Point3>> = t
            .par_iter()
            .map(|&v| {
                let pts: Vec<Point3> = t
                    .iter()
                    .map(|&u| Point3::from(self.deformation.displacement(u, v)))
                    .collect();
                interpolate_with(&pts, &t, ku.clone(), None)
                    .map(|(c, _)| c.control_points().to_vec())
            })
            .collect::<Result<_>>()?;
        let rows: Vec<Vec<Point3>> = (0..=k)
            .into_par_iter()
            .map(|i| {
                let pts: Vec<Point3> = cols.iter().map(|c| c[i]).collect();
                interpolate_with(&pts, &t, kv.clone(), None)
                    .map(|(c, _)| c.control_points().to_vec())
            })
            .collect::<Result<_>>()?;
        Surface::new(ku, kv, rows.concat())
    }
}

/// A fitted PDE surface with its errors.
#[derive(Debug, Clone)]
pub struct PdeFit {
    /// `S = S_c + S_PDE`.
    pub surface: PdeSurface,
    /// Eq. 15 errors of the Coons patch alone, `|P_i - S_c(u_i, v_i)|`.
    pub coons_errors: ErrorStats,
    /// Eq. 15 errors of `S`, `|P_i - S(u_i, v_i)|`.
    pub errors: ErrorStats,
    /// `|P_i - S(u_i, v_i)|` per point.
    pub residuals: Vec<f64>,
}

/// Points per block of the normal-equation assembly.
const BLOCK: usize = 1024;

/// Most sine terms `M x N` of a PDE deformation: the normal equations hold
/// `(M N)^2` doubles (4096 terms: 134 MB).
pub const MAX_PDE_TERMS: usize = 4096;

/// Fits the deformation of `coons` to `points` with parameters `uv` (eqs.
/// 12-13, see the module docs) and returns `S` with its eq. 15 errors.
///
/// Errors: fewer points than `M x N`, or more than [`MAX_PDE_TERMS`] terms;
/// `M` or `N` zero; `D` not positive; parameters outside `[0, 1]^2`; a
/// singular system (the points do not determine `M x N` terms: lower `M`, `N`).
pub fn fit_pde(
    coons: &CoonsPatch,
    points: &[Point3],
    uv: &[[f64; 2]],
    cfg: &PdeConfig,
) -> Result<PdeFit> {
    let (mm, nn) = (cfg.m, cfg.n);
    if mm == 0 || nn == 0 {
        return Err(Error::InvalidInput(format!(
            "PDE terms M x N = {mm} x {nn}; both must be at least 1 (paper: 5 x 5)"
        )));
    }
    if !(cfg.d.is_finite() && cfg.d > 0.0) {
        return Err(Error::InvalidInput(format!(
            "flexural rigidity D = {} must be positive (paper: 1)",
            cfg.d
        )));
    }
    crate::validate_points(points)?;
    if uv.len() != points.len() {
        return Err(Error::InvalidInput(format!(
            "{} parameter pairs for {} points",
            uv.len(),
            points.len()
        )));
    }
    if let Some(i) = uv
        .iter()
        .position(|t| !t.iter().all(|x| (0.0..=1.0).contains(x)))
    {
        return Err(Error::ParametersOutsideDomain {
            index: i,
            u: uv[i][0],
            v: uv[i][1],
            u_range: (0.0, 1.0),
            v_range: (0.0, 1.0),
        });
    }
    let kk = mm
        .checked_mul(nn)
        .filter(|&k| k <= MAX_PDE_TERMS)
        .ok_or_else(|| {
            Error::InvalidInput(format!(
                "PDE terms M x N = {mm} x {nn} exceed the limit of {MAX_PDE_TERMS} terms (the normal equations would need (M N)^2 doubles); the paper uses 5 x 5 to 10 x 10"
            ))
        })?;
    if points.len() < kk {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: kk,
            what: format!("a PDE deformation with M x N = {mm} x {nn} terms (lower M, N)"),
        });
    }
    // offsets wbar_i = P_i - S_c(u_i, v_i) (eq. 12)
    let base: Vec<Point3> = uv.par_iter().map(|t| coons.point(t[0], t[1])).collect();
    // normal equations (eq. 13) for w_mn, assembled block by block (blocks in
    // parallel, merged in block order by crate::par: bit-identical for every
    // thread count)
    // The Gram matrix of the sine basis from cosine sums: with
    // sin(a) sin(b) = (cos(a - b) - cos(a + b)) / 2 in u and in v,
    // G[(m,n),(m',n')] = sum_i s_m(u_i) s_m'(u_i) s_n(v_i) s_n'(v_i)
    //   = (C(|m-m'|,|n-n'|) - C(|m-m'|,n+n') - C(m+m',|n-n'|) + C(m+m',n+n')) / 4
    // with C(p, q) = sum_i cos(p pi u_i) cos(q pi v_i): (2M+1)(2N+1) sums per
    // point instead of (MN)^2 / 2 products.
    let (pu, pv) = (2 * mm + 1, 2 * nn + 1);
    let block = |b: usize| {
        let r = b * BLOCK..((b + 1) * BLOCK).min(points.len());
        let mut c = vec![0.0; pu * pv];
        let mut rhs = Mat::<f64>::zeros(kk, 3);
        let (mut cu, mut cv) = (vec![0.0; pu], vec![0.0; pv]);
        let (mut su, mut sv) = (vec![0.0; mm], vec![0.0; nn]);
        for i in r {
            let [u, v] = uv[i];
            for (p, x) in cu.iter_mut().enumerate() {
                *x = (p as f64 * PI * u).cos();
            }
            for (q, x) in cv.iter_mut().enumerate() {
                *x = (q as f64 * PI * v).cos();
            }
            for (p, &a) in cu.iter().enumerate() {
                for (q, &b) in cv.iter().enumerate() {
                    c[p * pv + q] += a * b;
                }
            }
            for (m0, x) in su.iter_mut().enumerate() {
                *x = sin_k_pi(m0 + 1, u);
            }
            for (n0, x) in sv.iter_mut().enumerate() {
                *x = sin_k_pi(n0 + 1, v);
            }
            let off = points[i] - base[i];
            for (m0, &a) in su.iter().enumerate() {
                for (n0, &b) in sv.iter().enumerate() {
                    let w = a * b;
                    for k in 0..3 {
                        rhs[(m0 * nn + n0, k)] += w * off[k];
                    }
                }
            }
        }
        (c, rhs)
    };
    let nblocks = points.len().div_ceil(BLOCK);
    // one partial per block of BLOCK points (cosine sums and right-hand
    // side, both small), merged in block order
    let (csum, rhs) = crate::par::accumulate(
        nblocks,
        1,
        || (vec![0.0; pu * pv], Mat::<f64>::zeros(kk, 3)),
        |acc: &mut (Vec<f64>, Mat<f64>), blocks| {
            for b in blocks {
                let (bc, br) = block(b);
                for (x, y) in acc.0.iter_mut().zip(&bc) {
                    *x += y;
                }
                acc.1 += &br;
            }
        },
        |total, (bc, br)| {
            for (x, y) in total.0.iter_mut().zip(&bc) {
                *x += y;
            }
            total.1 += &br;
        },
    );
    let cs = |p: usize, q: usize| csum[p * pv + q];
    let g = Mat::<f64>::from_fn(kk, kk, |a, b| {
        let (m, n) = (a / nn + 1, a % nn + 1);
        let (m2, n2) = (b / nn + 1, b % nn + 1);
        let (dm, sm) = (m.abs_diff(m2), m + m2);
        let (dn, sn) = (n.abs_diff(n2), n + n2);
        0.25 * (cs(dm, dn) - cs(dm, sn) - cs(sm, dn) + cs(sm, sn))
    });
    let llt = g.llt(Side::Lower).map_err(|_| Error::Singular {
        what: format!("PDE deformation least squares (eq. 13, {mm} x {nn} terms)"),
        condition: f64::INFINITY,
        hint: format!(
            "the {} points' parameters do not determine {mm} x {nn} sine terms; lower M and N",
            points.len()
        ),
    })?;
    // cond(G) >= (max L_ii / min L_ii)^2: a cheap lower bound that catches
    // the rank deficiency Cholesky lets through as tiny positive pivots
    let diag: Vec<f64> = (0..kk).map(|k| llt.L()[(k, k)].abs()).collect();
    let (lo, hi) = diag
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    let condition = (hi / lo).powi(2);
    if condition.is_nan() || condition > crate::fit::CONDITION_LIMIT {
        return Err(Error::Singular {
            what: format!("PDE deformation least squares (eq. 13, {mm} x {nn} terms)"),
            condition,
            hint: format!(
                "the {} points' parameters do not determine {mm} x {nn} sine terms; lower M and N",
                points.len()
            ),
        });
    }
    let sol = llt.solve(&rhs);
    let w: Vec<Vector3> = (0..kk)
        .map(|k| Vector3::new(sol[(k, 0)], sol[(k, 1)], sol[(k, 2)]))
        .collect();
    if let Some(k) = w.iter().position(|x| !x.iter().all(|c| c.is_finite())) {
        return Err(Error::Singular {
            what: format!("PDE deformation least squares (eq. 13, {mm} x {nn} terms)"),
            condition: f64::INFINITY,
            hint: format!(
                "coefficient of term ({}, {}) is not finite; lower M and N",
                k / nn + 1,
                k % nn + 1
            ),
        });
    }
    let surface = PdeSurface {
        coons: coons.clone(),
        deformation: PdeDeformation {
            m: mm,
            n: nn,
            d: cfg.d,
            w,
        },
    };
    let coons_d: Vec<f64> = points
        .par_iter()
        .zip(&base)
        .map(|(p, b)| (p - b).norm())
        .collect();
    let residuals: Vec<f64> = points
        .par_iter()
        .zip(uv)
        .zip(&base)
        .map(|((p, t), b)| (p - (b + surface.deformation.displacement(t[0], t[1]))).norm())
        .collect();
    Ok(PdeFit {
        surface,
        coons_errors: ErrorStats::of(&coons_d),
        errors: ErrorStats::of(&residuals),
        residuals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::{Curve, KnotVector};

    fn flat_square() -> CoonsPatch {
        let c = |a: [f64; 2], b: [f64; 2]| {
            let ctrl = (0..4)
                .map(|k| {
                    let t = k as f64 / 3.0;
                    Point3::new(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), 0.0)
                })
                .collect();
            Curve::new(KnotVector::uniform_clamped(3, 4).unwrap(), ctrl).unwrap()
        };
        CoonsPatch::from_loop(&[
            c([0., 0.], [1., 0.]),
            c([1., 0.], [1., 1.]),
            c([1., 1.], [0., 1.]),
            c([0., 1.], [0., 0.]),
        ])
        .unwrap()
    }

    #[test]
    fn recovers_a_sine_bump_and_converts_to_bspline() {
        let coons = flat_square();
        let f = |u: f64, v: f64| {
            0.3 * (PI * u).sin() * (PI * v).sin()
                - 0.05 * (2.0 * PI * u).sin() * (3.0 * PI * v).sin()
        };
        let mut pts = Vec::new();
        let mut uv = Vec::new();
        for i in 0..=20 {
            for j in 0..=20 {
                let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
                pts.push(Point3::new(u, v, f(u, v)));
                uv.push([u, v]);
            }
        }
        let fit = fit_pde(&coons, &pts, &uv, &PdeConfig::default()).unwrap();
        assert!(fit.errors.max < 1e-13, "{:?}", fit.errors);
        assert!((fit.coons_errors.max - 0.3).abs() < 0.05);
        let d = &fit.surface.deformation;
        // w_11 = 0.3, w_23 = -0.05 (eq. 10), q = D pi^4 (m^2+n^2)^2 w
        assert!((d.w_coefficient(1, 1).unwrap().z - 0.3).abs() < 1e-13);
        assert!((d.w_coefficient(2, 3).unwrap().z + 0.05).abs() < 1e-13);
        assert!((d.q_coefficient(1, 1).unwrap().z - 0.3 * 4.0 * PI.powi(4)).abs() < 1e-10);
        assert!(d.w_coefficient(6, 1).is_none());
        let b = fit
            .surface
            .to_bspline(&BsplineConversionConfig::new(1e-5))
            .unwrap();
        assert!(b.max_deviation * 1.2 <= 1e-5);
        // the promise holds on a dense independent grid (1/397 steps, all cells)
        let mut worst: f64 = 0.0;
        for i in 0..=397 {
            for j in 0..=397 {
                let (u, v) = (i as f64 / 397.0, j as f64 / 397.0);
                worst = worst.max((b.surface.point(u, v) - fit.surface.point(u, v)).norm());
            }
        }
        assert!(worst <= 1e-5, "{worst}");
        // the boundary is the Coons patch's, exactly
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            assert!(b.surface.point(t, 0.0).z.abs() < 1e-15);
            assert!(b.surface.point(1.0, t).z.abs() < 1e-15);
        }
        // a tolerance out of reach under a cap: the refinement stops at the
        // last net within the cap and says so, with the deviation it reached
        let first = fit
            .surface
            .to_bspline(&BsplineConversionConfig::new(1.0))
            .unwrap();
        let (cu, cv) = first.surface.counts();
        assert!(!first.capped);
        let capped = fit
            .surface
            .to_bspline(&BsplineConversionConfig {
                max_control_points: Some(cu * cv + 1),
                ..BsplineConversionConfig::new(1e-14)
            })
            .unwrap();
        assert!(capped.capped);
        assert_eq!(capped.surface.counts(), (cu, cv));
        assert_eq!(capped.max_deviation, first.max_deviation);
        assert!(capped.max_deviation > 1e-14);
        // and a cap below the coarsest net is an error naming it
        let e = fit.surface.to_bspline(&BsplineConversionConfig {
            max_control_points: Some(cu * cv - 1),
            ..BsplineConversionConfig::new(1e-14)
        });
        assert!(format!("{}", e.unwrap_err()).contains("more than the cap"));
    }

    #[test]
    fn refuses_bad_input() {
        let coons = flat_square();
        let pts = vec![Point3::new(0.5, 0.5, 0.1); 10];
        let uv = vec![[0.5, 0.5]; 10];
        let e = fit_pde(&coons, &pts, &uv, &PdeConfig::default()).unwrap_err();
        assert!(e.to_string().contains("lower M, N"), "{e}");
        let cfg = PdeConfig { m: 2, n: 2, d: 1.0 };
        let e = fit_pde(&coons, &pts, &uv, &cfg).unwrap_err();
        assert!(e.to_string().contains("lower M and N"), "{e}");
        let e = fit_pde(&coons, &pts, &uv, &PdeConfig { d: 0.0, ..cfg }).unwrap_err();
        assert!(e.to_string().contains("D = 0"), "{e}");
    }
}
