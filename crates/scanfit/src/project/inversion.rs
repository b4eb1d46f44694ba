//! Point inversion: the orthogonal projection of points onto a parametric
//! surface ([NURBS97] section 6.1, eqs. 6.5-6.8): any
//! [`ParametricSurface`] (a B-spline, a Coons patch, a PDE surface), with no
//! conversion; the code is generic, so the B-spline path is compiled for the
//! B-spline and runs as fast as before.
//!
//! Start: the nearest vertex of a parameter grid sampled on the surface, found
//! with the library's KD-tree ([`crate::spatial::KdTree`]), moved by one Gauss-Newton step on the tangent plane
//! stored with the vertex (no surface evaluation; the start error drops from
//! O(h) to O(h^2)). Iteration: Newton on `f = r.S_u = 0`, `g = r.S_v = 0`
//! (`r = S - P`) with the full Jacobian; when it is not positive definite (far
//! from a minimum) a Gauss-Newton step is taken instead, and a step that does
//! not reduce the distance is halved. Parameters are clamped to the domain, or
//! wrapped in a periodic direction. If the iteration does not converge, it is
//! restarted from the next nearest grid vertices and the closest result wins.
//! Convergence (eq. 6.8): the point is on the surface, or `r` is orthogonal to
//! both tangents, or the parameter step is negligible (also at the boundary,
//! where the constrained minimum is not orthogonal).

use rayon::prelude::*;

use crate::bspline::Surface;
use crate::spatial::KdTree;
use crate::surface::ParametricSurface;
use crate::{Point3, Result, Vector3};

/// Settings of [`SurfaceInverter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InversionConfig {
    /// Grid samples per knot span in each direction for the initial guess
    /// (default 4; at least 16 and at most 1024 per direction).
    pub samples_per_span: usize,
    /// Newton iterations per start (default 30).
    pub max_iterations: usize,
    /// Zero-cosine and point-coincidence tolerance, relative (default 1e-12).
    pub tolerance: f64,
    /// Grid vertices to start from when an iteration does not converge (default 3).
    pub starts: usize,
}

impl Default for InversionConfig {
    fn default() -> Self {
        Self {
            samples_per_span: 4,
            max_iterations: 30,
            tolerance: 1e-12,
            starts: 3,
        }
    }
}

/// The projection of one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inversion {
    /// Parameters of the foot point.
    pub uv: [f64; 2],
    /// The foot point `S(u, v)`.
    pub point: Point3,
    /// Distance from the input point to the foot point.
    pub distance: f64,
    /// Newton iterations used (summed over restarts).
    pub iterations: usize,
    /// Whether a convergence criterion was met.
    pub converged: bool,
}

/// What [`SurfaceInverter::invert_near`] returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearInversion {
    /// `S(uv0) - P`: the residual at the parameters given.
    pub at_start: Vector3,
    /// Distance from the point to its foot point.
    pub distance: f64,
    /// Whether a convergence criterion was met.
    pub converged: bool,
}

/// Reusable evaluation memory for one thread (the surface's derivative
/// workspace, up to second order).
#[derive(Debug, Clone)]
pub struct InversionWorkspace<W = crate::surface::SurfaceWorkspace> {
    ws: W,
}

impl<W> InversionWorkspace<W> {
    /// Workspace for `surface`.
    ///
    /// ```
    /// use scanfit::bspline::{KnotVector, Surface};
    /// use scanfit::project::{InversionConfig, InversionWorkspace, SurfaceInverter};
    /// use scanfit::Point3;
    /// let k = KnotVector::uniform_clamped(1, 2).unwrap();
    /// let ctrl = vec![Point3::new(0., 0., 0.), Point3::new(0., 1., 0.), Point3::new(1., 0., 0.), Point3::new(1., 1., 0.)];
    /// let s = Surface::new(k.clone(), k, ctrl).unwrap();
    /// let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
    /// let mut ws = InversionWorkspace::new(&s);
    /// let r = inv.invert(&Point3::new(0.25, 0.75, 2.0), &mut ws);
    /// assert!((r.uv[0] - 0.25).abs() < 1e-12 && (r.uv[1] - 0.75).abs() < 1e-12);
    /// assert!((r.distance - 2.0).abs() < 1e-12);
    /// ```
    pub fn new<S: ParametricSurface<Workspace = W> + ?Sized>(surface: &S) -> Self {
        Self {
            ws: surface.workspace(2),
        }
    }
}

/// Projects points onto one surface; build once, query many times. Generic
/// over the surface ([`ParametricSurface`]); the default is the B-spline.
pub struct SurfaceInverter<'s, S: ParametricSurface + ?Sized = Surface> {
    surface: &'s S,
    tree: KdTree,
    grid: Vec<[f64; 2]>,
    /// Point and tangents `S, S_u, S_v` at each grid vertex.
    frames: Vec<[Vector3; 3]>,
    cfg: InversionConfig,
    scale: f64,
}

impl<'s, S: ParametricSurface + ?Sized> SurfaceInverter<'s, S> {
    /// Samples `surface` on a parameter grid and builds the KD-tree: per
    /// direction `samples_per_span` x the knot spans of a B-spline (the
    /// surface's [`ParametricSurface::spans`]), clamped to 16..=1024.
    ///
    /// ```
    /// use scanfit::base::CoonsPatch;
    /// use scanfit::bspline::{Curve, KnotVector};
    /// use scanfit::project::{InversionConfig, SurfaceInverter};
    /// use scanfit::Point3;
    /// let line = |a: [f64; 3], b: [f64; 3]| {
    ///     let k = KnotVector::uniform_clamped(1, 2).unwrap();
    ///     Curve::new(k, vec![Point3::from(a), Point3::from(b)]).unwrap()
    /// };
    /// // a Coons patch inverts directly, without its B-spline form
    /// let c = CoonsPatch::new(
    ///     &line([0., 0., 0.], [2., 0., 0.]),
    ///     &line([0., 1., 0.], [2., 1., 0.]),
    ///     &line([0., 0., 0.], [0., 1., 0.]),
    ///     &line([2., 0., 0.], [2., 1., 0.]),
    /// )
    /// .unwrap();
    /// let inv = SurfaceInverter::new(&c, InversionConfig::default()).unwrap();
    /// let r = inv.invert_all(&[Point3::new(0.5, 0.25, -1.0)]);
    /// assert!((r[0].uv[0] - 0.25).abs() < 1e-12 && (r[0].uv[1] - 0.25).abs() < 1e-12);
    /// ```
    pub fn new(surface: &'s S, cfg: InversionConfig) -> Result<Self> {
        let ((u0, u1), (v0, v1)) = surface.domain();
        let (su, sv) = surface.spans();
        let count = |spans: usize| (spans * cfg.samples_per_span.max(1)).clamp(16, 1024);
        let (nu, nv) = (count(su), count(sv));
        let mut grid = Vec::with_capacity((nu + 1) * (nv + 1));
        for i in 0..=nu {
            for j in 0..=nv {
                grid.push([
                    u0 + (u1 - u0) * i as f64 / nu as f64,
                    v0 + (v1 - v0) * j as f64 / nv as f64,
                ]);
            }
        }
        let frames: Vec<[Vector3; 3]> = grid
            .par_iter()
            .map_init(
                || InversionWorkspace::new(surface),
                |ws, t| {
                    let mut d = [Vector3::zeros(); 4];
                    surface.derivatives(t[0], t[1], 1, &mut ws.ws, &mut d);
                    [d[0], d[2], d[1]]
                },
            )
            .collect();
        let pts: Vec<Point3> = frames.iter().map(|f| Point3::from(f[0])).collect();
        let scale = surface.extent().max(f64::MIN_POSITIVE);
        let tree = KdTree::new(&pts, "the surface samples")?;
        Ok(Self {
            surface,
            tree,
            grid,
            frames,
            cfg,
            scale,
        })
    }

    /// The surface.
    pub fn surface(&self) -> &S {
        self.surface
    }

    /// Projects `p` (KD-tree start, restarts if needed).
    pub fn invert(&self, p: &Point3, ws: &mut InversionWorkspace<S::Workspace>) -> Inversion {
        let first = self.tree.nearest(p);
        let mut best = self.invert_from(p, self.refined_start(p, first.index), ws);
        if best.converged || self.cfg.starts <= 1 {
            return best;
        }
        let n = std::num::NonZeroUsize::new(self.cfg.starts.max(2))
            .unwrap_or(std::num::NonZeroUsize::MIN);
        let more = self.tree.nearest_n(p, n);
        let mut iterations = best.iterations;
        for item in more.iter().skip(1) {
            let r = self.invert_from(p, self.refined_start(p, item.index), ws);
            iterations += r.iterations;
            if (r.converged && !best.converged) || r.distance < best.distance {
                best = r;
            }
        }
        best.iterations = iterations;
        best
    }

    /// Projects `p`, a point near its own parameters `uv0` (a point the
    /// surface was fitted to, whose foot point is close to `S(uv0)`), and
    /// returns the residual at `uv0` too, from the same evaluation.
    ///
    /// The fast path costs two evaluations: one Newton step (eq. 6.6) from
    /// `uv0` with the derivatives up to second order there, a second one
    /// with those at the new parameters, and the distance at its end by the
    /// second-order Taylor model there. That distance is taken when the
    /// iteration contracts (the second step at most half the first) and its
    /// estimated error (the third-order remainder, with the third
    /// derivatives estimated by the change of the second ones over the
    /// first step, plus the second-order effect of the offset left from the
    /// foot point) is at most `tolerance` x the distance (plus
    /// `tolerance^2` x the surface's extent): the distance of the foot
    /// point to a relative `tolerance` (1e-12 by default) beyond the
    /// rounding of the surface's evaluation, tighter than
    /// [`SurfaceInverter::invert_from`]'s stopping rule. Otherwise (a step
    /// leaves the domain's interior, a Hessian is not positive definite,
    /// the steps do not contract), [`SurfaceInverter::invert_from`]
    /// from `uv0`, and where that does not converge
    /// [`SurfaceInverter::invert`] with its restarts; the better result
    /// counts.
    ///
    /// ```
    /// use scanfit::bspline::{KnotVector, Surface};
    /// use scanfit::project::{InversionConfig, InversionWorkspace, SurfaceInverter};
    /// use scanfit::Point3;
    /// let k = KnotVector::uniform_clamped(2, 3).unwrap();
    /// // the bowl z = x^2 + y^2 over [-1, 1]^2, a biquadratic Bezier patch
    /// let z = [1.0, -1.0, 1.0];
    /// let c: Vec<Point3> = (0..3)
    ///     .flat_map(|i| (0..3).map(move |j| (i, j)))
    ///     .map(|(i, j)| Point3::new(i as f64 - 1.0, j as f64 - 1.0, z[i] + z[j]))
    ///     .collect();
    /// let s = Surface::new(k.clone(), k, c).unwrap();
    /// let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
    /// let mut ws = InversionWorkspace::new(&s);
    /// let p = Point3::new(0.1, -0.2, 0.3);
    /// let near = inv.invert_near(&p, [0.55, 0.4], &mut ws);
    /// let full = inv.invert(&p, &mut ws);
    /// assert!(near.converged && (near.distance - full.distance).abs() < 1e-12);
    /// assert!((near.at_start - (s.point(0.55, 0.4) - p)).norm() < 1e-15);
    /// ```
    pub fn invert_near(
        &self,
        p: &Point3,
        uv0: [f64; 2],
        ws: &mut InversionWorkspace<S::Workspace>,
    ) -> NearInversion {
        let surface = self.surface;
        self.invert_near_with(p, uv0, ws, |u, v, order, out, ws| {
            surface.derivatives(u, v, order, &mut ws.ws, out)
        })
    }

    /// [`SurfaceInverter::invert_near`] whose fast path evaluates the
    /// surface's derivatives (of order 1 or 2, in the layout of
    /// [`ParametricSurface::derivatives`]) by `eval`: the B-spline's power
    /// form in the assessment.
    pub(crate) fn invert_near_with(
        &self,
        p: &Point3,
        uv0: [f64; 2],
        ws: &mut InversionWorkspace<S::Workspace>,
        mut eval: impl FnMut(f64, f64, usize, &mut [Vector3], &mut InversionWorkspace<S::Workspace>),
    ) -> NearInversion {
        let mut d = [Vector3::zeros(); 9];
        eval(uv0[0], uv0[1], 2, &mut d, ws);
        let at_start = d[0] - p.coords;
        let second_order = |u: f64, v: f64| {
            let mut e = [Vector3::zeros(); 9];
            eval(u, v, 2, &mut e, ws);
            e
        };
        if let Some(distance) = self.one_step(p, uv0, &d, second_order) {
            return NearInversion {
                at_start,
                distance,
                converged: true,
            };
        }
        let mut r = self.invert_from(p, uv0, ws);
        if !r.converged {
            let again = self.invert(p, ws);
            if again.converged || again.distance < r.distance {
                r = again;
            }
        }
        NearInversion {
            at_start,
            distance: r.distance,
            converged: r.converged,
        }
    }

    /// The fast path of [`SurfaceInverter::invert_near`] from the
    /// derivatives `d` at `uv0` (layout of [`ParametricSurface::derivatives`]
    /// of order 2), with `first_order` the point and tangents elsewhere: the
    /// distance, or `None` where the general iteration must decide.
    fn one_step(
        &self,
        p: &Point3,
        uv0: [f64; 2],
        d: &[Vector3; 9],
        mut second_order: impl FnMut(f64, f64) -> [Vector3; 9],
    ) -> Option<f64> {
        let ((ua, ub), (va, vb)) = self.surface.domain();
        let inside = |u: f64, v: f64| u > ua && u < ub && v > va && v < vb;
        // Newton (eq. 6.6) from uv0
        let r = d[0] - p.coords;
        let (su, sv, suu, suv, svv) = (d[3], d[1], d[6], d[4], d[2]);
        let (f, g) = (r.dot(&su), r.dot(&sv));
        let a = su.norm_squared() + r.dot(&suu);
        let b = su.dot(&sv) + r.dot(&suv);
        let c = sv.norm_squared() + r.dot(&svv);
        let det = a * c - b * b;
        if !(a > 0.0 && det > 0.0) {
            return None;
        }
        let (du, dv) = (-(c * f - b * g) / det, -(a * g - b * f) / det);
        let (u, v) = (uv0[0] + du, uv0[1] + dv);
        if !inside(u, v) {
            return None;
        }
        // a second Newton step, with the derivatives at the new parameters
        let e = second_order(u, v);
        let r1 = e[0] - p.coords;
        let (tu, tv, tuu, tuv, tvv) = (e[3], e[1], e[6], e[4], e[2]);
        let (f1, g1) = (r1.dot(&tu), r1.dot(&tv));
        let a1 = tu.norm_squared() + r1.dot(&tuu);
        let b1 = tu.dot(&tv) + r1.dot(&tuv);
        let c1 = tv.norm_squared() + r1.dot(&tvv);
        let det1 = a1 * c1 - b1 * b1;
        if !(a1 > 0.0 && det1 > 0.0) {
            return None;
        }
        let (eu, ev) = (-(c1 * f1 - b1 * g1) / det1, -(a1 * g1 - b1 * f1) / det1);
        if !inside(u + eu, v + ev) {
            return None;
        }
        // the distance at the second step's end by the second-order Taylor
        // model at (u, v)
        let bend = |uu: Vector3, uv: Vector3, vv: Vector3| {
            uu * (eu * eu) + uv * (2.0 * eu * ev) + vv * (ev * ev)
        };
        let (q1, q0) = (bend(tuu, tuv, tvv), bend(suu, suv, svv));
        let second = tu * eu + tv * ev;
        let distance = (r1 + second + q1 * 0.5).norm();
        let first = (su * du + sv * dv).norm();
        let tol = self.cfg.tolerance;
        // its errors: the third-order remainder (the third derivatives
        // estimated by the change of the second ones over the first step)
        // and the second order of the offset left from the foot point
        // (about the bend over the step)
        let moved = du.hypot(dv);
        let third = if moved > 0.0 {
            (q1 - q0).norm() * eu.hypot(ev) / moved
        } else {
            0.0
        };
        let offset = q1.norm();
        let error = third + offset * offset / (2.0 * distance).max(f64::MIN_POSITIVE);
        let contracts = second.norm() <= 0.5 * first || second.norm() <= tol * self.scale;
        (contracts && error <= tol * (distance + tol * self.scale) && distance.is_finite())
            .then_some(distance)
    }

    /// Projects every point, in parallel (results in input order).
    pub fn invert_all(&self, points: &[Point3]) -> Vec<Inversion> {
        points
            .par_iter()
            .map_init(
                || InversionWorkspace::new(self.surface),
                |ws, p| self.invert(p, ws),
            )
            .collect()
    }

    /// Projects every point starting from its given parameters (no KD-tree: for
    /// re-projection after a small change of the surface, as in parameter
    /// correction), in parallel.
    pub fn invert_all_from(&self, points: &[Point3], start: &[[f64; 2]]) -> Vec<Inversion> {
        points
            .par_iter()
            .zip(start.par_iter())
            .map_init(
                || InversionWorkspace::new(self.surface),
                |ws, (p, uv)| {
                    let r = self.invert_from(p, *uv, ws);
                    if r.converged {
                        r
                    } else {
                        self.invert(p, ws)
                    }
                },
            )
            .collect()
    }

    /// The grid vertex `k` moved by one Gauss-Newton step on its stored tangent
    /// plane: the start's error drops from O(h) to O(h^2) without evaluating
    /// the surface.
    fn refined_start(&self, p: &Point3, k: usize) -> [f64; 2] {
        let [s, su, sv] = self.frames[k];
        let r = s - p.coords;
        let (a, b, c) = (su.norm_squared(), su.dot(&sv), sv.norm_squared());
        let det = a * c - b * b;
        let [u, v] = self.grid[k];
        if det.is_nan() || det <= 1e-300 {
            return [u, v];
        }
        let (f, g) = (r.dot(&su), r.dot(&sv));
        let ((u0, u1), (v0, v1)) = self.surface.domain();
        let (pu, pv) = self.surface.periodic();
        let wrap = |x: f64, lo: f64, hi: f64, periodic: bool| {
            if periodic {
                lo + (x - lo).rem_euclid(hi - lo)
            } else {
                x.clamp(lo, hi)
            }
        };
        [
            wrap(u - (c * f - b * g) / det, u0, u1, pu),
            wrap(v - (a * g - b * f) / det, v0, v1, pv),
        ]
    }

    /// Newton iteration from `uv0`.
    pub fn invert_from(
        &self,
        p: &Point3,
        uv0: [f64; 2],
        ws: &mut InversionWorkspace<S::Workspace>,
    ) -> Inversion {
        let s = self.surface;
        let ((u0, u1), (v0, v1)) = s.domain();
        let (pu, pv) = s.periodic();
        let wrap = |x: f64, lo: f64, hi: f64, periodic: bool| {
            if periodic {
                lo + (x - lo).rem_euclid(hi - lo)
            } else {
                x.clamp(lo, hi)
            }
        };
        let eps1 = self.cfg.tolerance * self.scale;
        let eps2 = self.cfg.tolerance; // zero-cosine tolerance (eq. 6.8)
        let mut d = [Vector3::zeros(); 9];
        let (mut u, mut v) = (uv0[0], uv0[1]);
        s.derivatives(u, v, 2, &mut ws.ws, &mut d);
        let mut r = d[0] - p.coords;
        let mut dist = r.norm();
        let mut converged = false;
        let mut it = 0;
        while it < self.cfg.max_iterations {
            it += 1;
            let (su, sv) = (d[3], d[1]);
            let (suu, suv, svv) = (d[6], d[4], d[2]);
            if dist <= eps1 {
                converged = true;
                break;
            }
            let f = r.dot(&su);
            let g = r.dot(&sv);
            let (nsu, nsv) = (su.norm(), sv.norm());
            let interior_u = pu || (u > u0 && u < u1);
            let interior_v = pv || (v > v0 && v < v1);
            let cos_u = f.abs() / (nsu * dist).max(f64::MIN_POSITIVE);
            let cos_v = g.abs() / (nsv * dist).max(f64::MIN_POSITIVE);
            if (cos_u <= eps2 || !interior_u && f * if u <= u0 { 1.0 } else { -1.0 } >= 0.0)
                && (cos_v <= eps2 || !interior_v && g * if v <= v0 { 1.0 } else { -1.0 } >= 0.0)
            {
                converged = true;
                break;
            }
            // Newton (eq. 6.6) or, if J is not positive definite, Gauss-Newton
            let (mut a, mut b, mut c) = (
                nsu * nsu + r.dot(&suu),
                su.dot(&sv) + r.dot(&suv),
                nsv * nsv + r.dot(&svv),
            );
            if !(a > 0.0 && a * c - b * b > 0.0) {
                a = nsu * nsu;
                b = su.dot(&sv);
                c = nsv * nsv;
            }
            let det = a * c - b * b;
            if det.is_nan() || det.abs() <= f64::MIN_POSITIVE {
                break;
            }
            let mut du = -(c * f - b * g) / det;
            let mut dv = -(a * g - b * f) / det;
            // active set: a parameter on its bound whose step points outward stays
            // there, and the other one takes the one-dimensional Newton step
            let out_u = !pu && ((u <= u0 && du < 0.0) || (u >= u1 && du > 0.0));
            let out_v = !pv && ((v <= v0 && dv < 0.0) || (v >= v1 && dv > 0.0));
            if out_u && out_v {
                converged = true;
                break;
            } else if out_u {
                du = 0.0;
                dv = if c > 0.0 { -g / c } else { -g / (nsv * nsv) };
            } else if out_v {
                dv = 0.0;
                du = if a > 0.0 { -f / a } else { -f / (nsu * nsu) };
            }
            // halve the step until the distance decreases (judged on the point
            // alone; derivatives are evaluated only where the iteration goes on)
            let mut t = 1.0;
            let mut accepted = false;
            let (mut nu_, mut nv_) = (u, v);
            let mut np = Point3::origin();
            for _ in 0..30 {
                nu_ = wrap(u + t * du, u0, u1, pu);
                nv_ = wrap(v + t * dv, v0, v1, pv);
                np = s.point(nu_, nv_);
                let nr = np - p;
                let nd = nr.norm();
                // accept unless the distance grows beyond rounding: near the
                // minimum it is flat to rounding while the parameters still improve
                if nd <= dist + 4.0 * f64::EPSILON * (dist + p.coords.amax()) {
                    r = nr;
                    dist = nd;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            let step = ((nu_ - u) * nsu).hypot((nv_ - v) * nsv);
            if !accepted {
                // no decrease along the step: at a (constrained) minimum up to rounding
                converged = step <= 1e3 * eps1.max(dist * 1e-12);
                break;
            }
            let dparam = ((nu_ - u) / (u1 - u0))
                .abs()
                .max(((nv_ - v) / (v1 - v0)).abs());
            u = nu_;
            v = nv_;
            // Newton converges quadratically: after a relative parameter step
            // below 1e-7 the remaining error is of order 1e-14, so the iteration
            // stops here without evaluating derivatives again
            if step <= eps1 || (dparam <= 1e-7 && t == 1.0) {
                d[0] = np.coords;
                converged = true;
                break;
            }
            s.derivatives(u, v, 2, &mut ws.ws, &mut d);
        }
        Inversion {
            uv: [u, v],
            point: Point3::from(d[0]),
            distance: dist,
            iterations: it,
            converged,
        }
    }
}
