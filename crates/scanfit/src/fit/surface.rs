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
use crate::par::BlockSum;
use crate::wire::{read_pair_sums, write_pair_sums, Reader, Writer};
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
    check_net(cfg)?;
    let (p, q) = cfg.degree;
    let (nu, nv) = cfg.ctrl;
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

/// The degrees and net of `cfg` are usable: degrees 1 to 10, at least
/// `p + 1` (periodic: `2p + 1`) by `q + 1` control points, at most
/// [`MAX_SURFACE_CONTROL_POINTS`].
fn check_net(cfg: &SurfaceFitConfig) -> Result<()> {
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
    let bytes = memory_estimate(cfg);
    if bytes > MAX_FIT_BYTES {
        // the largest square net of these degrees under the limit
        let per = |k: usize| {
            memory_estimate(&SurfaceFitConfig {
                ctrl: (k, k),
                ..cfg.clone()
            })
        };
        let side = (p.max(q) + 1..=2048)
            .take_while(|&k| per(k) <= MAX_FIT_BYTES)
            .last();
        return Err(Error::InvalidSetting {
            setting: "ctrl",
            value: format!("{nu} x {nv}"),
            hint: format!(
                "a {nu} x {nv} net of degrees {p} x {q} needs about {:.1} GiB for its normal equations and their Cholesky factor (limit {} GiB); use at most {} control points",
                bytes as f64 / (1u64 << 30) as f64,
                MAX_FIT_BYTES >> 30,
                side.map_or("fewer".into(), |k| format!("{k} x {k}"))
            ),
        });
    }
    Ok(())
}

/// Most bytes a least-squares surface fit may plan for (4 GiB).
pub const MAX_FIT_BYTES: usize = 4 << 30;

/// Bytes a least-squares fit of `cfg`'s net takes, about: the band-block
/// normal equations and one partial sum (`nu nv ((2p+1)(2q+1) + 3)` values
/// each) plus a Cholesky factor of about `nu nv min(nu, nv) (p + 1)` values
/// (the fill of a banded ordering), whatever the number of points.
///
/// ```
/// use scanfit::fit::surface::{memory_estimate, SurfaceFitConfig};
/// let small = memory_estimate(&SurfaceFitConfig { ctrl: (100, 100), ..Default::default() });
/// let big = memory_estimate(&SurfaceFitConfig { ctrl: (1000, 1000), ..Default::default() });
/// assert!(small < 100 << 20 && big > 16 << 30);
/// ```
pub fn memory_estimate(cfg: &SurfaceFitConfig) -> usize {
    let ((p, q), (nu, nv)) = (cfg.degree, cfg.ctrl);
    let n = nu.saturating_mul(nv);
    let band = n.saturating_mul((2 * p + 1) * (2 * q + 1) + 3);
    let factor = n.saturating_mul(nu.min(nv)).saturating_mul(p.min(q) + 1);
    band.saturating_mul(2)
        .saturating_add(factor)
        .saturating_mul(8)
}

impl SurfaceFitConfig {
    /// Empty normal equations for this configuration with uniform knots
    /// (the knots of [`fit_surface`] with [`KnotPlacement::Uniform`]), for
    /// points that arrive in chunks. Errors for the distribution knots
    /// (NURBS Book eq. 9.69 needs all parameters sorted at once) and for
    /// weights (give them per chunk to [`NormalEquations::add`]).
    ///
    /// ```
    /// use scanfit::fit::surface::{KnotPlacement, SurfaceFitConfig};
    /// let cfg = SurfaceFitConfig { knots: KnotPlacement::Uniform, ctrl: (10, 8), ..Default::default() };
    /// let eq = cfg.uniform_equations()?;
    /// assert_eq!(eq.points(), 0);
    /// assert!(SurfaceFitConfig::default().uniform_equations().is_err());
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn uniform_equations(&self) -> Result<NormalEquations> {
        check_net(self)?;
        if self.knots != KnotPlacement::Uniform {
            return Err(Error::InvalidSetting {
                setting: "knots",
                value: "distribution".into(),
                hint: "knots from the parameter distribution (NURBS Book eq. 9.69) need all parameters sorted at once; use uniform knots for points read in chunks, or find the parameters' order statistics first (scanfit::fit::knot_ranks::KnotSearch)".into(),
            });
        }
        let ((p, q), (nu, nv)) = (self.degree, self.ctrl);
        let ku = if self.periodic_u {
            KnotVector::uniform_periodic(p, nu)?
        } else {
            KnotVector::uniform_clamped(p, nu)?
        };
        self.equations_with(ku, KnotVector::uniform_clamped(q, nv)?)
    }

    /// Empty normal equations for this configuration's net and periodicity
    /// with the given knot vectors (e.g. from
    /// [`KnotSearch`](super::knot_ranks::KnotSearch)); the checks of
    /// [`uniform_equations`](Self::uniform_equations).
    pub fn equations_with(&self, ku: KnotVector, kv: KnotVector) -> Result<NormalEquations> {
        check_net(self)?;
        if self.weights.is_some() {
            return Err(Error::InvalidSetting {
                setting: "weights",
                value: "given".into(),
                hint: "give the weights of points read in chunks with each chunk (NormalEquations::add)".into(),
            });
        }
        NormalEquations::new(ku, kv, self.periodic_u)
    }
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
    if !distribution_applies(s.len(), p, count) {
        return KnotVector::uniform_clamped(p, count);
    }
    knots_from_interior(crate::param::knots::eq_9_69_interior(&s, p, count), p)
}

/// Whether [`distribution_knots`] follows `len` parameters for `count`
/// control points of degree `p` (otherwise its knots are uniform: fewer
/// parameters than control points, or no interior knot).
pub fn distribution_applies(len: usize, p: usize, count: usize) -> bool {
    len >= count && count > p + 1
}

/// The clamped knot vector on `[0, 1]` with the interior knots of eq. 9.69,
/// kept strictly inside `(0, 1)` and strictly increasing (the last step of
/// [`distribution_knots`]); the uniform clamped knots when the distribution
/// cannot place them ([`knots_degenerate`]).
pub fn knots_from_interior(mut interior: Vec<f64>, p: usize) -> Result<KnotVector> {
    if knots_degenerate(&interior) {
        return KnotVector::uniform_clamped(p, interior.len() + p + 1);
    }
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

/// Whether eq. 9.69's interior knots leave a knot span
/// shorter than a millionth of the uniform one (between consecutive knots,
/// the ends 0 and 1 included): the parameters repeat (the rows of a grid,
/// 30 distinct values for 40 control points) or cluster, so spans hold no
/// parameter, and the basis functions over them are pinned down neither
/// by the data nor by a smoothing term of any weight (the normal equations
/// are singular). The distribution cannot place such knots, and
/// [`knots_from_interior`] uses the uniform ones, as [`distribution_knots`]
/// does for fewer parameters than control points.
///
/// ```
/// use scanfit::fit::surface::knots_degenerate;
/// assert!(!knots_degenerate(&[0.25, 0.5, 0.75]));
/// assert!(knots_degenerate(&[0.25, 0.25, 0.75]));
/// ```
pub fn knots_degenerate(interior: &[f64]) -> bool {
    let shortest = 1e-6 / (interior.len() + 1) as f64;
    let ends = std::iter::once(0.0)
        .chain(interior.iter().copied())
        .chain(std::iter::once(1.0));
    let mut before = None;
    for t in ends {
        if let Some(b) = before {
            if t - b < shortest {
                return true;
            }
        }
        before = Some(t);
    }
    false
}

/// Least-squares surface with given knot vectors (clamped, or periodic in `u`).
pub fn least_squares_surface_with(
    points: &[Point3],
    uv: &[[f64; 2]],
    ku: KnotVector,
    kv: KnotVector,
    opts: SurfaceLsqOptions,
) -> Result<Surface> {
    let p = ku.degree();
    let nu = if opts.periodic_u {
        ku.basis_count().saturating_sub(p)
    } else {
        ku.basis_count()
    };
    validate(points, uv, &ku, &kv, &opts, nu * kv.basis_count())?;
    let mut eq = NormalEquations::new(ku, kv, opts.periodic_u)?;
    eq.add_checked(points, uv, opts.weights);
    eq.finish(opts.smoothing)
}

/// The normal equations of the least-squares surface (see the module
/// documentation) as a sum over points that can be built in pieces: create
/// it from the knot vectors, [`add`](Self::add) chunks of points with their
/// parameters (and weights), [`merge`](Self::merge) the equations of other
/// chunks, and [`finish`](Self::finish) with the smoothing weight to solve
/// for the surface. Memory is that of the band-block matrix, `nu nv
/// (2p+1)(2q+1)` values, whatever the number of points.
///
/// Points are summed in blocks of 16384 counted from the first point added
/// (a constant, so the order of the floating-point operations depends on
/// neither the thread count nor the chunks): adding the points of a file in
/// chunks of any size, in file order, gives the same surface, bit for bit,
/// as [`least_squares_surface_with`] on all of them at once (which goes
/// through this type). Merging equations summed separately (other machines)
/// equals the one-pass sum up to the rounding of the additions.
///
/// ```
/// use scanfit::bspline::KnotVector;
/// use scanfit::fit::surface::{least_squares_surface_with, NormalEquations, SurfaceLsqOptions};
/// use scanfit::Point3;
///
/// let (mut pts, mut uv) = (Vec::new(), Vec::new());
/// for k in 0..2000 {
///     let (u, v) = ((k % 50) as f64 / 49.0, (k / 50) as f64 / 39.0);
///     pts.push(Point3::new(u, v, (3.0 * u).sin() * v));
///     uv.push([u, v]);
/// }
/// let k = KnotVector::uniform_clamped(3, 8)?;
/// let once = least_squares_surface_with(&pts, &uv, k.clone(), k.clone(), SurfaceLsqOptions::default())?;
/// // two halves summed separately, then merged
/// let mut a = NormalEquations::new(k.clone(), k.clone(), false)?;
/// let mut b = NormalEquations::new(k.clone(), k, false)?;
/// a.add(&pts[..700], &uv[..700], None)?;
/// b.add(&pts[700..], &uv[700..], None)?;
/// a.merge(b)?;
/// assert_eq!(a.points(), 2000);
/// let merged = a.finish(0.0)?;
/// for (x, y) in once.control_points().iter().zip(merged.control_points()) {
///     assert!((x - y).norm() < 1e-12);
/// }
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct NormalEquations {
    ku: KnotVector,
    kv: KnotVector,
    layout: Layout,
    sums: BlockSum<(Vec<f64>, Vec<f64>)>,
}

impl NormalEquations {
    /// Empty equations for the clamped knot vectors `ku`, `kv` (periodic in
    /// `u` when `periodic_u`: the last `p` control rows repeat the first).
    /// Errors for nets beyond [`MAX_SURFACE_CONTROL_POINTS`] or degree 10, or
    /// a periodic net with fewer than `2p + 1` rows.
    pub fn new(ku: KnotVector, kv: KnotVector, periodic_u: bool) -> Result<Self> {
        let (p, q) = (ku.degree(), kv.degree());
        let nu_total = ku.basis_count();
        let nu = if periodic_u {
            nu_total.saturating_sub(p)
        } else {
            nu_total
        };
        let nv = kv.basis_count();
        if nu
            .checked_mul(nv)
            .is_none_or(|n| n > MAX_SURFACE_CONTROL_POINTS)
            || p > 10
            || q > 10
        {
            return Err(Error::InvalidInput(format!(
                "a {nu} x {nv} control net of degrees {p} x {q} is beyond the limits ({MAX_SURFACE_CONTROL_POINTS} control points, degree 10); choose a smaller net"
            )));
        }
        if periodic_u && nu < 2 * p + 1 {
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
            periodic: periodic_u,
        };
        let block = ASSEMBLY_CHUNK;
        Ok(Self {
            ku,
            kv,
            sums: BlockSum::new(layout.zeros(), block),
            layout,
        })
    }

    /// Points added so far (over all merged equations).
    pub fn points(&self) -> u64 {
        self.sums.items()
    }

    /// Bytes the equations hold (the matrix band and the right-hand sides),
    /// for a memory estimate before any point is read.
    pub fn bytes(&self) -> usize {
        self.layout.values() * std::mem::size_of::<f64>()
    }

    /// Adds the points `points` with parameters `uv` (inside the knot
    /// vectors' domains) and optional non-negative `weights` (default 1).
    /// Errors name the index of the offending point within the chunk.
    pub fn add(
        &mut self,
        points: &[Point3],
        uv: &[[f64; 2]],
        weights: Option<&[f64]>,
    ) -> Result<()> {
        check_chunk(points, uv, &self.ku, &self.kv, weights)?;
        self.add_checked(points, uv, weights);
        Ok(())
    }

    /// Adds the equations of another set of points (the same knot vectors
    /// and periodicity).
    pub fn merge(&mut self, other: Self) -> Result<()> {
        if self.ku != other.ku
            || self.kv != other.kv
            || self.layout.periodic != other.layout.periodic
        {
            return Err(Error::InvalidInput(
                "cannot merge normal equations of different knot vectors or periodicity; every chunk must be summed with the same knots".into(),
            ));
        }
        self.sums.merge(other.sums, merge_sums);
        Ok(())
    }

    /// Solves for the surface, with `smoothing` times the thin-plate energy
    /// (exact Gram matrices, [`super::gram`]). Errors when the points do not
    /// determine the net: fewer points than control points without
    /// smoothing, a control point no point influences, or a singular matrix.
    pub fn finish(self, smoothing: f64) -> Result<Surface> {
        super::validate_weights_and_smoothing(None, 0, smoothing)?;
        let l = self.layout;
        let (ku, kv) = (self.ku, self.kv);
        let points = self.sums.items();
        let n = l.nu * l.nv;
        if smoothing == 0.0 && points < n as u64 {
            return Err(Error::TooFewPoints {
                got: usize::try_from(points).unwrap_or(usize::MAX),
                needed: n,
                what: format!(
                    "a least-squares surface with {n} control points (without smoothing)"
                ),
            });
        }
        let (mut acc, rhs) = self.sums.finish(merge_sums);
        let (p, q, nv) = (l.p, l.q, l.nv);
        let centre = l.slot(p, q);
        if smoothing > 0.0 {
            add_thin_plate(&mut acc, &ku, &kv, smoothing, &l);
        } else if let Some((i, j)) = (0..n)
            .position(|r| acc[r * l.slots() + centre] <= 0.0)
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
        let sol = solve(acc, rhs, &l, smoothing)?;
        // unfold into the control net (repeating the first p rows when periodic)
        let nu_total = ku.basis_count();
        let mut ctrl = Vec::with_capacity(nu_total * nv);
        for i in 0..nu_total {
            let fi = i % l.nu;
            for j in 0..nv {
                let r = fi * nv + j;
                ctrl.push(Point3::new(sol[(r, 0)], sol[(r, 1)], sol[(r, 2)]));
            }
        }
        Surface::with_options(ku, kv, ctrl, None, l.periodic, false)
    }

    /// The equations as bytes ([`crate::wire`]), exact: equations read back
    /// with [`from_bytes`](Self::from_bytes) continue, merge and solve bit
    /// for bit as these.
    ///
    /// ```
    /// use scanfit::bspline::KnotVector;
    /// use scanfit::fit::surface::NormalEquations;
    /// use scanfit::Point3;
    /// let k = KnotVector::uniform_clamped(3, 5)?;
    /// let mut a = NormalEquations::new(k.clone(), k, false)?;
    /// let uv: Vec<[f64; 2]> = (0..400).map(|i| [(i % 20) as f64 / 19.0, (i / 20) as f64 / 19.0]).collect();
    /// let p: Vec<Point3> = uv.iter().map(|t| Point3::new(t[0], t[1], t[0] * t[1])).collect();
    /// a.add(&p, &uv, None)?;
    /// let b = NormalEquations::from_bytes(&a.to_bytes())?;
    /// assert_eq!(b.finish(0.0)?, a.finish(0.0)?);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(NORMAL_TAG);
        w.u64(u64::from(self.layout.periodic));
        for k in [&self.ku, &self.kv] {
            w.usize(k.degree());
            w.f64s(k.as_slice());
        }
        write_pair_sums(&mut w, &self.sums);
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote; errors for bytes of
    /// another type, cut short or inconsistent.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, NORMAL_TAG, "least-squares normal equations")?;
        let periodic = match r.u64()? {
            0 => false,
            1 => true,
            x => return Err(r.corrupt(&format!("periodicity flag {x}"))),
        };
        let mut knots = || -> Result<KnotVector> {
            let degree = r.usize()?;
            KnotVector::new(r.f64s()?, degree)
        };
        let (ku, kv) = (knots()?, knots()?);
        let mut eq = Self::new(ku, kv, periodic)?;
        let rows = eq.layout.nu * eq.layout.nv;
        eq.sums = read_pair_sums(&mut r, (rows * eq.layout.slots(), rows * 3), ASSEMBLY_CHUNK)?;
        r.end()?;
        Ok(eq)
    }

    /// [`add`](Self::add) without the checks (the caller made them).
    fn add_checked(&mut self, points: &[Point3], uv: &[[f64; 2]], weights: Option<&[f64]>) {
        let l = &self.layout;
        let partials = (PARTIAL_BUDGET / self.bytes().max(1)).clamp(1, 16);
        let (ku, kv) = (&self.ku, &self.kv);
        self.sums.add(
            points.len(),
            partials,
            || l.zeros(),
            |sums, range| assemble_range(sums, points, uv, ku, kv, weights, l, range),
            merge_sums,
        );
    }
}

/// Tag of the byte record of [`NormalEquations`] ([`crate::wire`]).
const NORMAL_TAG: &[u8; 8] = b"SFNORMQ1";

/// Bytes of partial sums that may exist at a time during an assembly.
const PARTIAL_BUDGET: usize = 256 << 20;

/// Adds a partial (matrix band, right-hand sides) to a total.
fn merge_sums(total: &mut (Vec<f64>, Vec<f64>), part: (Vec<f64>, Vec<f64>)) {
    total.0.iter_mut().zip(&part.0).for_each(|(x, y)| *x += y);
    total.1.iter_mut().zip(&part.1).for_each(|(x, y)| *x += y);
}

/// Checks a chunk for [`NormalEquations::add`]: equal lengths, finite
/// points, parameters inside the domains, valid weights.
fn check_chunk(
    points: &[Point3],
    uv: &[[f64; 2]],
    ku: &KnotVector,
    kv: &KnotVector,
    weights: Option<&[f64]>,
) -> Result<()> {
    if points.len() != uv.len() {
        return Err(Error::LengthMismatch {
            what: "parameter pairs",
            expected: points.len(),
            got: uv.len(),
        });
    }
    crate::validate_points(points)?;
    check_domain(uv, ku, kv)?;
    super::validate_weights_and_smoothing(weights, points.len(), 0.0)
}

/// Every parameter pair finite and inside the knot vectors' domains.
fn check_domain(uv: &[[f64; 2]], ku: &KnotVector, kv: &KnotVector) -> Result<()> {
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
    Ok(())
}

/// Index bookkeeping of the band-block normal matrix.
#[derive(Debug, Clone, Copy)]
struct Layout {
    p: usize,
    q: usize,
    nu: usize,
    nv: usize,
    periodic: bool,
}

impl Layout {
    /// Values of the matrix band and the three right-hand sides.
    fn values(&self) -> usize {
        self.nu * self.nv * (self.slots() + 3)
    }
    /// A zero matrix band and right-hand sides.
    fn zeros(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.nu * self.nv;
        (vec![0.0; n * self.slots()], vec![0.0; n * 3])
    }
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
    check_domain(uv, ku, kv)?;
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

/// Points per block of the assembly ([`BlockSum`]): a constant, so the
/// summation order depends on neither the thread count nor the chunks.
const ASSEMBLY_CHUNK: usize = 16_384;

/// Adds the points `range` to the matrix band and right-hand sides `sums`.
#[allow(clippy::too_many_arguments)]
fn assemble_range(
    sums: &mut (Vec<f64>, Vec<f64>),
    points: &[Point3],
    uv: &[[f64; 2]],
    ku: &KnotVector,
    kv: &KnotVector,
    weights: Option<&[f64]>,
    l: &Layout,
    range: std::ops::Range<usize>,
) {
    let (acc, rhs) = sums;
    let s = l.slots();
    let (p, q) = (l.p, l.q);
    let tu = ku.as_slice();
    let tv = kv.as_slice();
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
fn solve(acc: Vec<f64>, rhs: Vec<f64>, l: &Layout, smoothing: f64) -> Result<Mat<f64>> {
    let remedy = if smoothing > 0.0 {
        "use fewer control points or a larger smoothing weight"
    } else {
        "add smoothing or use fewer control points"
    };
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
        singular(format!(
            "the normal equations are not positive definite: the parameters do not spread over the control net (e.g. too few distinct u or v values); {remedy}"
        ))
    })?;
    let mut x = Mat::<f64>::from_fn(n, 3, |i, c| rhs[i * 3 + c]);
    llt.solve_in_place(&mut x);
    if x.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(singular(format!("the solution is not finite; {remedy}")));
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy sheet with scattered parameters, weights and a far offset.
    fn data(n: usize) -> (Vec<Point3>, Vec<[f64; 2]>, Vec<f64>) {
        let mut rng = crate::testdata::Lcg::new(3);
        let (mut p, mut uv, mut w) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..n {
            let (u, v) = (rng.next_f64(), rng.next_f64());
            p.push(Point3::new(
                1e5 + 50.0 * u,
                -2e5 + 30.0 * v,
                4.0 * (5.0 * u).sin() * (3.0 * v).cos(),
            ));
            uv.push([u, v]);
            w.push(0.5 + rng.next_f64());
        }
        (p, uv, w)
    }

    fn max_diff(a: &Surface, b: &Surface) -> f64 {
        a.control_points()
            .iter()
            .zip(b.control_points())
            .fold(0.0f64, |m, (x, y)| m.max((x - y).norm()))
    }

    /// A 30 x 30 grid has 30 distinct values of `u` and of `v`: eq. 9.69
    /// for 40 control points puts knots on repeated values, and those spans
    /// made the smoothed normal equations singular (`fit --ctrl 40x40
    /// --smooth 0.001` on 900 points failed). The knots are now uniform
    /// and the fit follows the sheet.
    #[test]
    fn repeated_parameters_take_uniform_knots_and_fit() -> Result<()> {
        let (mut pts, mut uv) = (Vec::new(), Vec::new());
        for i in 0..30 {
            for j in 0..30 {
                let (u, v) = (f64::from(i) / 29.0, f64::from(j) / 29.0);
                pts.push(Point3::new(u, v, 0.2 * (3.0 * u).sin() * v));
                uv.push([u, v]);
            }
        }
        let k = distribution_knots(uv.iter().map(|t| t[0]), 3, 40)?;
        assert_eq!(k, KnotVector::uniform_clamped(3, 40)?);
        // 30 control points: eq. 9.69 finds 26 distinct interior knots
        let k30 = distribution_knots(uv.iter().map(|t| t[0]), 3, 30)?;
        assert_ne!(k30, KnotVector::uniform_clamped(3, 30)?);
        let cfg = SurfaceFitConfig {
            ctrl: (40, 40),
            smoothing: 1e-3,
            ..SurfaceFitConfig::default()
        };
        let s = fit_surface(&pts, &uv, &cfg)?;
        let worst = pts
            .iter()
            .zip(&uv)
            .fold(0.0f64, |m, (p, t)| m.max((s.point(t[0], t[1]) - p).norm()));
        // relief 0.2: the smoothed fit stays within 1% of it
        assert!(worst < 2e-3, "max error {worst}");
        Ok(())
    }

    #[test]
    fn chunks_in_order_give_the_one_call_surface_bit_for_bit_and_trees_to_1e12() {
        let (p, uv, w) = data(50_000);
        for periodic in [false, true] {
            let ku = if periodic {
                KnotVector::uniform_periodic(3, 12).unwrap()
            } else {
                KnotVector::uniform_clamped(3, 12).unwrap()
            };
            let kv = KnotVector::uniform_clamped(2, 9).unwrap();
            let opts = SurfaceLsqOptions {
                smoothing: 1e-7,
                weights: Some(&w),
                periodic_u: periodic,
            };
            let once = least_squares_surface_with(&p, &uv, ku.clone(), kv.clone(), opts).unwrap();
            let scale = once
                .control_points()
                .iter()
                .fold(0.0f64, |m, c| m.max(c.coords.norm()));
            for chunk in [1000, 16_384, 20_001, 50_000] {
                // one accumulator fed chunk by chunk: bit-identical
                let mut eq = NormalEquations::new(ku.clone(), kv.clone(), periodic).unwrap();
                for s in (0..p.len()).step_by(chunk) {
                    let e = (s + chunk).min(p.len());
                    eq.add(&p[s..e], &uv[s..e], Some(&w[s..e])).unwrap();
                }
                assert_eq!(eq.points(), 50_000);
                assert_eq!(eq.finish(1e-7).unwrap(), once, "chunk {chunk}");
                // one accumulator per chunk, merged right to left: rounding only
                let mut parts: Vec<NormalEquations> = (0..p.len())
                    .step_by(chunk)
                    .map(|s| {
                        let e = (s + chunk).min(p.len());
                        let mut eq =
                            NormalEquations::new(ku.clone(), kv.clone(), periodic).unwrap();
                        eq.add(&p[s..e], &uv[s..e], Some(&w[s..e])).unwrap();
                        eq
                    })
                    .collect();
                let mut acc = parts.pop().unwrap();
                while let Some(mut next) = parts.pop() {
                    next.merge(acc).unwrap();
                    acc = next;
                }
                let merged = acc.finish(1e-7).unwrap();
                let d = max_diff(&merged, &once);
                assert!(
                    d <= 1e-12 * scale,
                    "chunk {chunk} periodic {periodic}: {d:e}"
                );
            }
        }
    }

    #[test]
    fn bad_chunks_and_merges_are_errors() {
        let k = KnotVector::uniform_clamped(3, 6).unwrap();
        let mut eq = NormalEquations::new(k.clone(), k.clone(), false).unwrap();
        let p = [Point3::new(0.0, 0.0, 0.0)];
        let e = eq.add(&p, &[[1.5, 0.5]], None).unwrap_err();
        assert!(
            matches!(e, Error::ParametersOutsideDomain { index: 0, .. }),
            "{e}"
        );
        assert!(eq.add(&p, &[], None).is_err());
        assert!(eq.add(&p, &[[0.5, 0.5]], Some(&[-1.0])).is_err());
        let other =
            NormalEquations::new(KnotVector::uniform_clamped(3, 7).unwrap(), k.clone(), false)
                .unwrap();
        assert!(eq.merge(other).is_err());
        // 1 point for 36 control points: refused at finish, not singular
        eq.add(&p, &[[0.5, 0.5]], None).unwrap();
        let e = eq.finish(0.0).unwrap_err();
        assert!(
            matches!(
                e,
                Error::TooFewPoints {
                    got: 1,
                    needed: 36,
                    ..
                }
            ),
            "{e}"
        );
    }
}
