//! One surface per patch whose boundary is exactly the shared edge curves
//! (issue 15, item 4).
//!
//! * Sides ([`group_sides`]): a cycle of 3 or 4 edges gives a three- or
//!   four-sided patch; a longer cycle keeps its 4 sharpest corners (smallest
//!   angle between the edge tangents, Coons paper eq. 12) and the edges
//!   between two kept corners form one side. A three-sided patch starts at
//!   its sharpest corner, the apex where `P(0, v)` degenerates (PDE paper
//!   §5.2).
//! * Side curves ([`side_curve`]): the edge curves of a side, oriented along
//!   the side, joined into one C0 curve on `[0, 1]`, each edge on a
//!   sub-interval with dyadic ends (so the joined knots are exact).
//! * The surface ([`fit_face`]): the Coons patch of the side curves (PDE
//!   paper eq. 1), closest-point parameters on it (§4.4), then either the PDE
//!   deformation (§4.5, eqs. 4-14) or a least-squares B-spline. Its exported
//!   B-spline form has the knots of the side curves (plus uniform ones) and
//!   the side curves' refined control points as its boundary rows and columns,
//!   set, not computed: only the interior control points are fitted (to the
//!   PDE surface, which is exactly the Coons patch on the boundary, or to the
//!   points). Neighbouring patches therefore meet along the same curve, up to
//!   the rounding of knot insertion.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use rayon::prelude::*;

use crate::base::{coons_parameters, CoonsParamConfig, CoonsPatch, CoonsProjection, Sides};
use crate::bspline::ops::{missing_knots, refine_surface_to, reversed};
use crate::bspline::{basis_funs, Curve, KnotVector, Surface};
use crate::metrics::ErrorStats;
use crate::pde::{fit_pde, PdeConfig, PdeSurface};
use crate::project::{InversionConfig, SurfaceInverter};
use crate::{Error, Point3, Result, Vector3};

use super::junctions::NetUse;

/// How a patch's surface is fitted inside its fixed boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum FaceFit {
    /// The PDE deformation of the Coons patch with `M x N` sine terms (PDE
    /// paper eqs. 4-14; default 5 x 5).
    Pde(PdeConfig),
    /// A least-squares B-spline with at least `ctrl = (nu, nv)` control
    /// points per direction (more where the side curves bring knots), its
    /// boundary control rows fixed to the side curves.
    Bspline {
        /// Control points per direction (at least 4 each, degree 3).
        ctrl: (usize, usize),
    },
}

impl Default for FaceFit {
    fn default() -> Self {
        FaceFit::Pde(PdeConfig::default())
    }
}

/// Settings of [`fit_face`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceConfig {
    /// PDE (default) or least-squares B-spline.
    pub fit: FaceFit,
    /// The closest-point projection giving the parameters (PDE paper §4.4).
    pub inversion: InversionConfig,
    /// Largest allowed distance, in data units, between the PDE surface and
    /// its B-spline form (checked at every quarter of every knot span).
    pub tolerance: f64,
    /// Most uniform knot spans per direction of the B-spline form (default 256).
    pub max_spans: usize,
}

impl FaceConfig {
    /// Defaults with the conversion `tolerance` in data units (the pipeline
    /// takes `1e-4` x the model diagonal).
    pub fn new(tolerance: f64) -> Self {
        Self {
            fit: FaceFit::default(),
            inversion: InversionConfig::default(),
            tolerance,
            max_spans: 256,
        }
    }
}

/// Interior angle at every vertex of a cycle: the angle between the
/// directions back along the incoming edge and forward along the outgoing
/// one (Coons paper eq. 12 on the end legs of the control polygons).
fn vertex_angles(cycle: &[NetUse], curves: &[Curve]) -> Vec<f64> {
    let leg = |u: &NetUse, at_start: bool| -> Vector3 {
        let cp = curves[u.edge].control_points();
        let n = cp.len();
        // the use's start is the curve's end when reversed
        let curve_start = at_start != u.reversed;
        if curve_start {
            cp[1] - cp[0]
        } else {
            cp[n - 2] - cp[n - 1]
        }
    };
    let m = cycle.len();
    (0..m)
        .map(|k| {
            let back = leg(&cycle[(k + m - 1) % m], false);
            let fwd = leg(&cycle[k], true);
            let d = back.norm() * fwd.norm();
            if d > 0.0 {
                (back.dot(&fwd) / d).clamp(-1.0, 1.0).acos()
            } else {
                std::f64::consts::PI
            }
        })
        .collect()
}

/// Groups a patch's cycle of edge uses into 3 or 4 sides (see the module
/// docs). Angle `k` is at the vertex where use `k` starts.
pub fn group_sides(cycle: &[NetUse], curves: &[Curve], id: i64) -> Result<Vec<Vec<NetUse>>> {
    let m = cycle.len();
    if m < 3 {
        return Err(Error::InvalidInput(format!(
            "patch {id} has {m} corner(s); a patch needs at least 3"
        )));
    }
    let angles = vertex_angles(cycle, curves);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| angles[a].total_cmp(&angles[b]).then(a.cmp(&b)));
    let mut corners: Vec<usize> = if m == 3 {
        vec![order[0], (order[0] + 1) % 3, (order[0] + 2) % 3]
    } else {
        let mut c = order[..4].to_vec();
        c.sort_unstable();
        c
    };
    if m == 3 {
        corners.sort_by_key(|&c| (c + 3 - order[0]) % 3);
    }
    let n = corners.len();
    Ok((0..n)
        .map(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % n]);
            let len = (b + m - a) % m;
            let len = if len == 0 { m } else { len };
            (0..len).map(|j| cycle[(a + j) % m]).collect()
        })
        .collect())
}

/// The curve of an edge use, oriented along the use (on `[0, 1]`).
pub fn oriented(u: &NetUse, curves: &[Curve]) -> Result<Curve> {
    let c = &curves[u.edge];
    if u.reversed {
        reversed(c)
    } else {
        Ok(c.clone())
    }
}

/// Parameter resolution of the joints of a side (`1 / 64`).
const JOINT_STEP: f64 = 1.0 / 64.0;

/// The sub-interval of the side's `[0, 1]` each use occupies: proportional
/// to the curves' lengths, rounded to multiples of 1/64.
pub fn side_ranges(uses: &[NetUse], curves: &[Curve]) -> Vec<(f64, f64)> {
    let k = uses.len();
    if k == 1 {
        return vec![(0.0, 1.0)];
    }
    let lens: Vec<f64> = uses
        .iter()
        .map(|u| curves[u.edge].length(8).max(f64::MIN_POSITIVE))
        .collect();
    let total: f64 = lens.iter().sum();
    let mut cuts = vec![0.0];
    let mut acc = 0.0;
    for (j, l) in lens.iter().enumerate().take(k - 1) {
        acc += l;
        let lo = cuts[j] + JOINT_STEP;
        let hi = 1.0 - (k - 1 - j) as f64 * JOINT_STEP;
        let x = ((acc / total / JOINT_STEP).round() * JOINT_STEP).clamp(lo, hi);
        cuts.push(x);
    }
    cuts.push(1.0);
    (0..k).map(|j| (cuts[j], cuts[j + 1])).collect()
}

/// One side's curve: its edge curves, oriented along it, joined (C0) on the
/// ranges of [`side_ranges`].
pub fn side_curve(uses: &[NetUse], curves: &[Curve]) -> Result<Curve> {
    let mut segs: Vec<Curve> = uses
        .iter()
        .map(|u| oriented(u, curves))
        .collect::<Result<_>>()?;
    if segs.len() == 1 {
        return Ok(segs.swap_remove(0));
    }
    if segs.is_empty() {
        return Err(Error::InvalidInput("a side without edges".into()));
    }
    let ranges = side_ranges(uses, curves);
    let p = segs[0].degree();
    let mut knots: Vec<f64> = vec![0.0; p + 1];
    let mut ctrl: Vec<Point3> = Vec::new();
    for (j, (c, &(a, b))) in segs.iter().zip(&ranges).enumerate() {
        if c.degree() != p {
            return Err(Error::InvalidInput(
                "the edge curves of one side have different degrees".into(),
            ));
        }
        let t = c.knots().as_slice();
        let inner = &t[p + 1..t.len() - p - 1];
        knots.extend(inner.iter().map(|&x| a + (b - a) * x));
        if j + 1 < segs.len() {
            knots.extend(std::iter::repeat_n(b, p));
        }
        let cp = c.control_points();
        if j == 0 {
            ctrl.extend_from_slice(cp);
        } else {
            ctrl.extend_from_slice(&cp[1..]);
        }
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    Curve::new(KnotVector::new(knots, p)?, ctrl)
}

/// A patch's fitted surface.
#[derive(Debug, Clone)]
pub struct FaceSurface {
    /// The Coons patch of the side curves.
    pub coons: CoonsPatch,
    /// The PDE surface `S_c + S_PDE` (PDE fit only).
    pub pde: Option<PdeSurface>,
    /// The exported B-spline surface on `[0, 1]^2`, boundary = side curves.
    pub surface: Surface,
    /// Parameters of the patch's points (closest points on the Coons patch).
    pub uv: Vec<[f64; 2]>,
    /// Eq. 15 errors of the Coons patch, `|P_i - S_c(u_i, v_i)|`.
    pub coons_errors: ErrorStats,
    /// Eq. 15 errors of the fitted surface, `|P_i - S(u_i, v_i)|`.
    pub errors: ErrorStats,
    /// Orthogonal distances of the points to the exported surface.
    pub orthogonal: ErrorStats,
    /// The orthogonal distance of each point (in the order given).
    pub distances: Vec<f64>,
    /// Largest distance between the PDE surface and its B-spline form (0 for
    /// the B-spline fit).
    pub conversion_deviation: f64,
}

/// The knot union of clamped knot vectors of one degree on `[0, 1]`.
fn union(vs: &[&KnotVector]) -> Result<KnotVector> {
    let mut k = vs[0].as_slice().to_vec();
    let p = vs[0].degree();
    for v in &vs[1..] {
        let cur = KnotVector::new(k.clone(), p)?;
        k.extend(missing_knots(&cur, v));
        k.sort_by(f64::total_cmp);
    }
    KnotVector::new(k, p)
}

/// The Coons patch's knots (opposite sides' knots) with `spans` uniform
/// spans added per direction.
fn face_knots(coons: &CoonsPatch, spans: (usize, usize)) -> Result<(KnotVector, KnotVector)> {
    let p = coons.bottom().degree();
    let q = coons.left().degree();
    let uu = KnotVector::uniform_clamped(p, spans.0 + p)?;
    let uv = KnotVector::uniform_clamped(q, spans.1 + q)?;
    Ok((
        union(&[coons.bottom().knots(), coons.top().knots(), &uu])?,
        union(&[coons.left().knots(), coons.right().knots(), &uv])?,
    ))
}

/// The Coons patch on knots `ku x kv` with its boundary rows and columns set
/// to the refined side curves (not computed from the blend), so that they
/// are the side curves' control points themselves.
fn coons_on(coons: &CoonsPatch, ku: &KnotVector, kv: &KnotVector) -> Result<Vec<Point3>> {
    let s = refine_surface_to(&coons.to_bspline()?, ku, kv)?;
    let (nu, nv) = s.counts();
    let mut ctrl = s.control_points().to_vec();
    let on = |c: &Curve, k: &KnotVector| -> Result<Vec<Point3>> {
        Ok(c.refine(&missing_knots(c.knots(), k))?
            .control_points()
            .to_vec())
    };
    let (b, t) = (on(coons.bottom(), ku)?, on(coons.top(), ku)?);
    let r = on(coons.right(), kv)?;
    for i in 0..nu {
        ctrl[i * nv] = b[i];
        ctrl[i * nv + nv - 1] = t[i];
    }
    for j in 0..nv {
        ctrl[(nu - 1) * nv + j] = r[j];
    }
    if coons.sides() == Sides::Three {
        let apex = coons.corners()[0];
        for c in ctrl.iter_mut().take(nv) {
            *c = apex;
        }
    } else {
        let l = on(coons.left(), kv)?;
        ctrl[..nv].copy_from_slice(&l);
    }
    Ok(ctrl)
}

/// Values of the interior basis functions `N_1 .. N_{n-2}` of `kv` at `ts`
/// (a `ts.len() x (n - 2)` matrix).
fn interior_basis(kv: &KnotVector, ts: &[f64]) -> Mat<f64> {
    let p = kv.degree();
    let n = kv.basis_count();
    let mut a = Mat::<f64>::zeros(ts.len(), n.saturating_sub(2));
    let (mut out, mut l, mut r) = (vec![0.0; p + 1], vec![0.0; p + 1], vec![0.0; p + 1]);
    for (s, &t) in ts.iter().enumerate() {
        let span = kv.find_span(t);
        basis_funs(kv.as_slice(), p, span, t, &mut out, &mut l, &mut r);
        for (k, &v) in out.iter().enumerate() {
            let i = span - p + k;
            if i >= 1 && i + 1 < n {
                a[(s, i - 1)] = v;
            }
        }
    }
    a
}

/// Least squares `min |A X B^T - D|` by the normal equations of each factor
/// (the tensor-product problem separates).
fn separable(a: &Mat<f64>, b: &Mat<f64>, d: &Mat<f64>) -> Result<Mat<f64>> {
    let solve = |m: &Mat<f64>, rhs: Mat<f64>| -> Result<Mat<f64>> {
        let g = m.transpose() * m;
        let llt = g.llt(Side::Lower).map_err(|_| Error::Singular {
            what: "fixed-boundary B-spline form of a PDE patch".into(),
            condition: f64::INFINITY,
            hint: "allow fewer knot spans".into(),
        })?;
        Ok(llt.solve(&rhs))
    };
    // X = (A^T A)^-1 A^T D B (B^T B)^-1
    let left = solve(a, a.transpose() * d)?; // (na x gv)
    let right = solve(b, b.transpose() * left.transpose())?; // (nb x na)
    Ok(right.transpose().to_owned())
}

/// The B-spline form of `pde` with its boundary fixed to the Coons patch's
/// side curves and its interior control points fitted, by separable least
/// squares on a grid of `S_PDE` samples, with `spans` uniform spans added per
/// direction. Returns the surface and its largest deviation from `pde` at
/// every quarter of every span.
fn pde_form(pde: &PdeSurface, spans: usize) -> Result<(Surface, f64)> {
    let coons = &pde.coons;
    let (ku, kv) = face_knots(coons, (spans, spans))?;
    let mut ctrl = coons_on(coons, &ku, &kv)?;
    let (nu, nv) = (ku.basis_count(), kv.basis_count());
    let grid = |n: usize| -> Vec<f64> {
        let g = 3 * n;
        (1..g).map(|k| k as f64 / g as f64).collect()
    };
    let (gu, gv) = (grid(nu), grid(nv));
    let (a, b) = (interior_basis(&ku, &gu), interior_basis(&kv, &gv));
    let disp: Vec<Vector3> = gu
        .par_iter()
        .flat_map_iter(|&u| gv.iter().map(move |&v| pde.deformation.displacement(u, v)))
        .collect();
    for c in 0..3 {
        let d = Mat::<f64>::from_fn(gu.len(), gv.len(), |i, j| disp[i * gv.len() + j][c]);
        let x = separable(&a, &b, &d)?;
        for i in 1..nu - 1 {
            for j in 1..nv - 1 {
                ctrl[i * nv + j][c] += x[(i - 1, j - 1)];
            }
        }
    }
    let s = Surface::new(ku, kv, ctrl)?;
    let check = 4 * (nu.max(nv));
    let dev = (0..=check)
        .into_par_iter()
        .map(|i| {
            let u = i as f64 / check as f64;
            (0..=check)
                .map(|j| {
                    let v = j as f64 / check as f64;
                    (s.point(u, v) - pde.point(u, v)).norm()
                })
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max);
    Ok((s, dev))
}

/// The least-squares B-spline of `points` at `uv` with the boundary fixed
/// to the Coons patch's side curves: only the interior control points are
/// unknown (normal equations, dense Cholesky).
fn bspline_fit(
    coons: &CoonsPatch,
    points: &[Point3],
    uv: &[[f64; 2]],
    ctrl_count: (usize, usize),
    id: i64,
) -> Result<Surface> {
    let p = coons.bottom().degree();
    let q = coons.left().degree();
    if ctrl_count.0 < p + 1 || ctrl_count.1 < q + 1 || ctrl_count.0 > 200 || ctrl_count.1 > 200 {
        return Err(Error::InvalidInput(format!(
            "control net {} x {} is out of range: give 4 to 200 control points per direction (--ctrl NxM)",
            ctrl_count.0, ctrl_count.1
        )));
    }
    let (ku, kv) = face_knots(coons, (ctrl_count.0 - p, ctrl_count.1 - q))?;
    let mut ctrl = coons_on(coons, &ku, &kv)?;
    let (nu, nv) = (ku.basis_count(), kv.basis_count());
    let (mu, mv) = (nu - 2, nv - 2);
    let unknowns = mu * mv;
    if points.len() < unknowns {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: unknowns,
            what: format!("patch {id}: a least-squares B-spline with {mu} x {mv} free (interior) control points (lower --ctrl)"),
        });
    }
    let fixed = ctrl.clone();
    let chunk = 4096;
    let parts: Vec<(Mat<f64>, Mat<f64>)> = points
        .par_chunks(chunk)
        .zip(uv.par_chunks(chunk))
        .map(|(pts, ts)| {
            let mut g = Mat::<f64>::zeros(unknowns, unknowns);
            let mut r = Mat::<f64>::zeros(unknowns, 3);
            let (mut bu, mut l, mut rr) = (vec![0.0; p + 1], vec![0.0; p + 1], vec![0.0; p + 1]);
            let (mut bv, mut l2, mut r2) = (vec![0.0; q + 1], vec![0.0; q + 1], vec![0.0; q + 1]);
            let mut idx: Vec<(usize, f64)> = Vec::with_capacity((p + 1) * (q + 1));
            for (pt, t) in pts.iter().zip(ts) {
                let (su, sv) = (ku.find_span(t[0]), kv.find_span(t[1]));
                basis_funs(ku.as_slice(), p, su, t[0], &mut bu, &mut l, &mut rr);
                basis_funs(kv.as_slice(), q, sv, t[1], &mut bv, &mut l2, &mut r2);
                let mut rhs = pt.coords;
                idx.clear();
                for (a, &x) in bu.iter().enumerate() {
                    let i = su - p + a;
                    for (b, &y) in bv.iter().enumerate() {
                        let j = sv - q + b;
                        let w = x * y;
                        if i == 0 || j == 0 || i == nu - 1 || j == nv - 1 {
                            rhs -= fixed[i * nv + j].coords * w;
                        } else {
                            idx.push(((i - 1) * mv + (j - 1), w));
                        }
                    }
                }
                for &(a, wa) in &idx {
                    for &(b, wb) in &idx {
                        g[(a, b)] += wa * wb;
                    }
                    for c in 0..3 {
                        r[(a, c)] += wa * rhs[c];
                    }
                }
            }
            (g, r)
        })
        .collect();
    let mut g = Mat::<f64>::zeros(unknowns, unknowns);
    let mut r = Mat::<f64>::zeros(unknowns, 3);
    for (pg, pr) in &parts {
        g += pg;
        r += pr;
    }
    let singular = || Error::Singular {
        what: format!(
            "patch {id}: fixed-boundary least-squares B-spline ({nu} x {nv} control points)"
        ),
        condition: f64::INFINITY,
        hint: "some interior control points have no points under them; lower --ctrl".into(),
    };
    let llt = g.llt(Side::Lower).map_err(|_| singular())?;
    let diag: Vec<f64> = (0..unknowns).map(|k| llt.L()[(k, k)].abs()).collect();
    let (lo, hi) = diag
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    let condition = (hi / lo).powi(2);
    if condition.is_nan() || condition > crate::fit::CONDITION_LIMIT {
        return Err(singular());
    }
    let x = llt.solve(&r);
    for i in 0..mu {
        for j in 0..mv {
            let v = Vector3::new(x[(i * mv + j, 0)], x[(i * mv + j, 1)], x[(i * mv + j, 2)]);
            if !v.iter().all(|c| c.is_finite()) {
                return Err(singular());
            }
            ctrl[(i + 1) * nv + (j + 1)] = Point3::from(v);
        }
    }
    Surface::new(ku, kv, ctrl)
}

/// The points' parameters: their closest points on the Coons patch (PDE
/// paper §4.4, by point inversion), clamped to `[0, 1]^2`.
pub fn coons_uv(
    coons: &CoonsPatch,
    points: &[Point3],
    inversion: InversionConfig,
) -> Result<Vec<[f64; 2]>> {
    let par = coons_parameters(
        &coons.to_bspline()?,
        points,
        &CoonsParamConfig {
            projection: CoonsProjection::Inversion(inversion),
            outside_tolerance: None,
        },
    )?;
    Ok(par
        .uv
        .iter()
        .map(|t| [t[0].clamp(0.0, 1.0), t[1].clamp(0.0, 1.0)])
        .collect())
}

/// Fits one patch inside its side curves (3 or 4, counter-clockwise: `P(u,0)`,
/// `P(1,v)`, `P(u,1)` run backwards, `P(0,v)` run backwards; a three-sided
/// patch's apex where the first curve starts). See the module docs.
pub fn fit_face(
    points: &[Point3],
    sides: &[Curve],
    cfg: &FaceConfig,
    id: i64,
) -> Result<FaceSurface> {
    let ctx = |e: Error| match e {
        Error::InvalidInput(m) => Error::InvalidInput(format!("patch {id}: {m}")),
        other => other,
    };
    let coons = CoonsPatch::from_loop(sides).map_err(ctx)?;
    let uv = coons_uv(&coons, points, cfg.inversion).map_err(ctx)?;
    let (pde, surface, errors, coons_errors, deviation) = match cfg.fit {
        FaceFit::Pde(pc) => {
            let fit = fit_pde(&coons, points, &uv, &pc).map_err(ctx)?;
            let (m, n) = fit.surface.deformation.terms();
            let mut spans = (2 * m.max(n)).next_power_of_two().max(8);
            let (s, dev) = loop {
                let (s, dev) = pde_form(&fit.surface, spans).map_err(ctx)?;
                if dev <= cfg.tolerance {
                    break (s, dev);
                }
                if 2 * spans > cfg.max_spans {
                    return Err(Error::InvalidInput(format!(
                        "patch {id}: the B-spline form of its PDE surface deviates by {dev:e} with {spans} spans, more than the tolerance {:e}; allow a larger tolerance or use fewer PDE terms",
                        cfg.tolerance
                    )));
                }
                spans *= 2;
            };
            (Some(fit.surface), s, fit.errors, fit.coons_errors, dev)
        }
        FaceFit::Bspline { ctrl } => {
            let s = bspline_fit(&coons, points, &uv, ctrl, id)?;
            let d: Vec<f64> = points
                .par_iter()
                .zip(&uv)
                .map(|(p, t)| (s.point(t[0], t[1]) - p).norm())
                .collect();
            let dc: Vec<f64> = points
                .par_iter()
                .zip(&uv)
                .map(|(p, t)| (coons.point(t[0], t[1]) - p).norm())
                .collect();
            (None, s, ErrorStats::of(&d), ErrorStats::of(&dc), 0.0)
        }
    };
    let inverter = SurfaceInverter::new(&surface, cfg.inversion).map_err(ctx)?;
    let orth: Vec<f64> = inverter
        .invert_all_from(points, &uv)
        .iter()
        .map(|r| r.distance)
        .collect();
    Ok(FaceSurface {
        coons,
        pde,
        surface,
        uv,
        coons_errors,
        errors,
        orthogonal: ErrorStats::of(&orth),
        distances: orth,
        conversion_deviation: deviation,
    })
}
