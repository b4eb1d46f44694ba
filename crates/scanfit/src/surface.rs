//! Capability traits: what a parametric surface or curve can do, whatever its
//! representation.
//!
//! [`ParametricSurface`] is implemented by the tensor-product B-spline
//! ([`crate::bspline::Surface`]), the bilinearly blended Coons patch
//! ([`crate::base::CoonsPatch`], [Coons67] / [PDE23] eq. 1) and the PDE
//! surface ([`crate::pde::PdeSurface`], [PDE23] eq. 14). Algorithms that only
//! evaluate a surface take `S: ParametricSurface` and so work on each of them
//! without a conversion: point inversion ([`crate::project::SurfaceInverter`])
//! and [COONS19]'s grid iteration ([`crate::project::grid_iteration`]).
//! [`ParametricCurve`] is the curve counterpart, implemented by
//! [`crate::bspline::Curve`].
//!
//! Derivatives are written to a caller's buffer with scratch memory the
//! caller keeps (one [`ParametricSurface::Workspace`] per thread), so hot
//! loops do not allocate.
//!
//! Keys in brackets are those of `docs/references.md`.

use crate::base::CoonsPatch;
use crate::bspline::{BasisWorkspace, Curve, Surface};
use crate::pde::PdeSurface;
use crate::{Point3, Vector3};

/// A surface `S(u, v)` over a rectangular parameter domain.
///
/// ```
/// use scanfit::surface::ParametricSurface;
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::Point3;
/// // the bilinear patch z = u v on [0, 1]^2
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let ctrl = vec![Point3::new(0., 0., 0.), Point3::new(0., 1., 0.), Point3::new(1., 0., 0.), Point3::new(1., 1., 1.)];
/// let s = Surface::new(k.clone(), k, ctrl).unwrap();
/// let mut ws = s.workspace(2);
/// let mut d = [scanfit::Vector3::zeros(); 9];
/// ParametricSurface::derivatives(&s, 0.5, 0.25, 2, &mut ws, &mut d);
/// // d[k * 3 + l] = S_{u^k v^l}: S_u = (1, 0, v), S_v = (0, 1, u), S_uv = (0, 0, 1)
/// assert!((d[3] - scanfit::Vector3::new(1.0, 0.0, 0.25)).norm() < 1e-15);
/// assert!((d[1] - scanfit::Vector3::new(0.0, 1.0, 0.5)).norm() < 1e-15);
/// assert!((d[4].z - 1.0).abs() < 1e-15);
/// assert_eq!(ParametricSurface::domain(&s), ((0.0, 1.0), (0.0, 1.0)));
/// ```
pub trait ParametricSurface: Sync {
    /// Scratch memory for [`ParametricSurface::derivatives`] (one per thread).
    type Workspace: Send;

    /// A workspace for derivatives up to `max_order` (orders above it come
    /// out zero).
    fn workspace(&self, max_order: usize) -> Self::Workspace;

    /// The point `S(u, v)`; parameters outside the domain are clamped to it
    /// (wrapped in a periodic direction).
    fn point(&self, u: f64, v: f64) -> Point3;

    /// The partial derivatives `S_{u^k v^l}` for `k + l <= order`, written to
    /// `out[k * (order + 1) + l]` (`out[0]` is the point as a vector; `out`
    /// holds at least `(order + 1)^2` vectors; entries with `k + l > order`
    /// are zero).
    fn derivatives(
        &self,
        u: f64,
        v: f64,
        order: usize,
        ws: &mut Self::Workspace,
        out: &mut [Vector3],
    );

    /// The parameter domain `((u0, u1), (v0, v1))`.
    fn domain(&self) -> ((f64, f64), (f64, f64));

    /// Whether the surface is periodic (closed) in `u` and in `v`.
    fn periodic(&self) -> (bool, bool) {
        (false, false)
    }

    /// Pieces per direction on which the surface is smooth and simple (knot
    /// spans for a B-spline): sampling densities scale with them. The
    /// default is 4 x 4.
    fn spans(&self) -> (usize, usize) {
        (4, 4)
    }

    /// A length of the order of the surface's size (an upper bound of its
    /// bounding-box diagonal where one is cheap): relative tolerances are
    /// scaled by it. The default samples a 17 x 17 grid.
    fn extent(&self) -> f64 {
        let ((u0, u1), (v0, v1)) = self.domain();
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for i in 0..=16 {
            for j in 0..=16 {
                let p = self.point(
                    u0 + (u1 - u0) * i as f64 / 16.0,
                    v0 + (v1 - v0) * j as f64 / 16.0,
                );
                lo = lo.inf(&p.coords);
                hi = hi.sup(&p.coords);
            }
        }
        (hi - lo).norm()
    }
}

/// A curve `C(t)` over a parameter interval: the counterpart of
/// [`ParametricSurface`].
///
/// ```
/// use scanfit::surface::ParametricCurve;
/// use scanfit::bspline::{Curve, KnotVector};
/// use scanfit::{Point3, Vector3};
/// let c = Curve::new(KnotVector::uniform_clamped(1, 2).unwrap(),
///     vec![Point3::origin(), Point3::new(2.0, 0.0, 0.0)]).unwrap();
/// let mut ws = ParametricCurve::workspace(&c, 1);
/// let mut d = [Vector3::zeros(); 2];
/// ParametricCurve::derivatives(&c, 0.5, 1, &mut ws, &mut d);
/// assert_eq!(d[1], Vector3::new(2.0, 0.0, 0.0));
/// assert_eq!(ParametricCurve::domain(&c), (0.0, 1.0));
/// ```
pub trait ParametricCurve: Sync {
    /// Scratch memory for [`ParametricCurve::derivatives`] (one per thread).
    type Workspace: Send;

    /// A workspace for derivatives up to `max_order`.
    fn workspace(&self, max_order: usize) -> Self::Workspace;

    /// The point `C(t)`.
    fn point(&self, t: f64) -> Point3;

    /// `C^(k)(t)` for `k = 0..=order` in `out[k]` (`out[0]` the point as a
    /// vector; `out` holds at least `order + 1` vectors).
    fn derivatives(&self, t: f64, order: usize, ws: &mut Self::Workspace, out: &mut [Vector3]);

    /// The parameter interval `(t0, t1)`.
    fn domain(&self) -> (f64, f64);

    /// Whether the curve is closed and periodic.
    fn periodic(&self) -> bool {
        false
    }
}

/// Scratch memory of a B-spline surface's derivatives: one basis workspace
/// per direction.
#[derive(Debug, Clone)]
pub struct SurfaceWorkspace {
    /// Basis functions in `u`.
    pub u: BasisWorkspace,
    /// Basis functions in `v`.
    pub v: BasisWorkspace,
}

impl ParametricSurface for Surface {
    type Workspace = SurfaceWorkspace;

    fn workspace(&self, max_order: usize) -> SurfaceWorkspace {
        let (p, q) = self.degrees();
        SurfaceWorkspace {
            u: BasisWorkspace::new(p, max_order),
            v: BasisWorkspace::new(q, max_order),
        }
    }

    #[inline]
    fn point(&self, u: f64, v: f64) -> Point3 {
        Surface::point(self, u, v)
    }

    #[inline]
    fn derivatives(
        &self,
        u: f64,
        v: f64,
        order: usize,
        ws: &mut SurfaceWorkspace,
        out: &mut [Vector3],
    ) {
        self.derivatives_into(u, v, &mut ws.u, &mut ws.v, order, out);
    }

    fn domain(&self) -> ((f64, f64), (f64, f64)) {
        Surface::domain(self)
    }

    fn periodic(&self) -> (bool, bool) {
        Surface::periodic(self)
    }

    fn spans(&self) -> (usize, usize) {
        (
            self.knots_u().breakpoints().len() - 1,
            self.knots_v().breakpoints().len() - 1,
        )
    }

    /// The diagonal of the control points' bounding box (the surface lies in
    /// their convex hull).
    fn extent(&self) -> f64 {
        crate::geom::bbox_diagonal(self.control_points())
    }
}

impl ParametricCurve for Curve {
    type Workspace = BasisWorkspace;

    fn workspace(&self, max_order: usize) -> BasisWorkspace {
        BasisWorkspace::new(self.degree(), max_order)
    }

    #[inline]
    fn point(&self, t: f64) -> Point3 {
        Curve::point(self, t)
    }

    #[inline]
    fn derivatives(&self, t: f64, order: usize, ws: &mut BasisWorkspace, out: &mut [Vector3]) {
        self.derivatives_into(t, ws, &mut out[..=order]);
    }

    fn domain(&self) -> (f64, f64) {
        Curve::domain(self)
    }

    fn periodic(&self) -> bool {
        self.is_periodic()
    }
}

/// Scratch memory of a Coons patch's derivatives: one basis workspace per
/// boundary curve and their derivatives.
#[derive(Debug, Clone)]
pub struct CoonsWorkspace {
    /// Workspaces of `P(u,0)`, `P(u,1)`, `P(0,v)`, `P(1,v)`.
    curves: [BasisWorkspace; 4],
    /// `C^(k)` of the four curves, `k = 0..=order`.
    ders: [Vec<Vector3>; 4],
}

/// `d^k/dt^k` of the blending weight `1 - t` (`lin = false`) or `t` (`true`).
fn blend(k: usize, t: f64, lin: bool) -> f64 {
    match (k, lin) {
        (0, false) => 1.0 - t,
        (0, true) => t,
        (1, false) => -1.0,
        (1, true) => 1.0,
        _ => 0.0,
    }
}

impl ParametricSurface for CoonsPatch {
    type Workspace = CoonsWorkspace;

    fn workspace(&self, max_order: usize) -> CoonsWorkspace {
        let c = [self.bottom(), self.top(), self.left(), self.right()];
        CoonsWorkspace {
            curves: c.map(|c| BasisWorkspace::new(c.degree(), max_order)),
            ders: std::array::from_fn(|_| vec![Vector3::zeros(); max_order + 1]),
        }
    }

    fn point(&self, u: f64, v: f64) -> Point3 {
        CoonsPatch::point(self, u, v)
    }

    /// Eq. 16 / [PDE23] eq. 1 differentiated term by term: with
    /// `S = (1-v) B(u) + v T(u) + (1-u) L(v) + u R(v) - bilinear(u, v)`,
    /// `S_{u^k v^l} = b_l(v) B^(k) + t_l(v) T^(k) + b_k(u) L^(l) + t_k(u) R^(l) - ...`
    /// where `b_j, t_j` are the j-th derivatives of `1 - x` and `x`.
    fn derivatives(
        &self,
        u: f64,
        v: f64,
        order: usize,
        ws: &mut CoonsWorkspace,
        out: &mut [Vector3],
    ) {
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let d1 = order + 1;
        out[..d1 * d1]
            .iter_mut()
            .for_each(|o| *o = Vector3::zeros());
        let curves = [self.bottom(), self.top(), self.left(), self.right()];
        for (i, (c, (cw, cd))) in curves
            .iter()
            .zip(ws.curves.iter_mut().zip(ws.ders.iter_mut()))
            .enumerate()
        {
            // P(u,0), P(u,1) run in u; P(0,v), P(1,v) in v
            let t = if i < 2 { u } else { v };
            cd.resize(d1, Vector3::zeros());
            c.derivatives_into(t, cw, &mut cd[..d1]);
        }
        let [b, t, l, r] = &ws.ders;
        let [p00, p10, p11, p01] = self.corners().map(|p| p.coords);
        for k in 0..=order {
            for m in 0..=order - k {
                let mut s = b[k] * blend(m, v, false)
                    + t[k] * blend(m, v, true)
                    + l[m] * blend(k, u, false)
                    + r[m] * blend(k, u, true);
                if k <= 1 && m <= 1 {
                    s -= p00 * (blend(k, u, false) * blend(m, v, false))
                        + p10 * (blend(k, u, true) * blend(m, v, false))
                        + p01 * (blend(k, u, false) * blend(m, v, true))
                        + p11 * (blend(k, u, true) * blend(m, v, true));
                }
                out[k * d1 + m] = s;
            }
        }
        // the point itself by eq. 16 as [`CoonsPatch::point`] computes it
        out[0] = CoonsPatch::point(self, u, v).coords;
    }

    fn domain(&self) -> ((f64, f64), (f64, f64)) {
        ((0.0, 1.0), (0.0, 1.0))
    }

    /// The larger knot-span count of each pair of opposite curves.
    fn spans(&self) -> (usize, usize) {
        let n = |c: &Curve| c.knots().breakpoints().len().saturating_sub(1).max(1);
        (
            n(self.bottom()).max(n(self.top())),
            n(self.left()).max(n(self.right())),
        )
    }

    /// The diagonal of the boundary curves' control points' bounding box.
    fn extent(&self) -> f64 {
        let pts: Vec<Point3> = [self.bottom(), self.top(), self.left(), self.right()]
            .iter()
            .flat_map(|c| c.control_points().iter().copied())
            .collect();
        crate::geom::bbox_diagonal(&pts)
    }
}

impl ParametricSurface for PdeSurface {
    type Workspace = CoonsWorkspace;

    fn workspace(&self, max_order: usize) -> CoonsWorkspace {
        self.coons.workspace(max_order)
    }

    fn point(&self, u: f64, v: f64) -> Point3 {
        PdeSurface::point(self, u, v)
    }

    /// `S_c`'s derivatives plus those of the sine series ([PDE23] eq. 11):
    /// `d^k/du^k sin(m pi u) = (m pi)^k sin(m pi u + k pi / 2)`.
    fn derivatives(
        &self,
        u: f64,
        v: f64,
        order: usize,
        ws: &mut CoonsWorkspace,
        out: &mut [Vector3],
    ) {
        ParametricSurface::derivatives(&self.coons, u, v, order, ws, out);
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let d1 = order + 1;
        for k in 0..=order {
            for l in 0..=order - k {
                out[k * d1 + l] += self.deformation.derivative(u, v, k, l);
            }
        }
        out[0] = PdeSurface::point(self, u, v).coords;
    }

    fn domain(&self) -> ((f64, f64), (f64, f64)) {
        ((0.0, 1.0), (0.0, 1.0))
    }

    /// The Coons patch's spans, at least `M x N` (the sine terms' half waves).
    fn spans(&self) -> (usize, usize) {
        let (su, sv) = self.coons.spans();
        let (m, n) = self.deformation.terms();
        (su.max(m), sv.max(n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::KnotVector;

    fn curve(pts: &[[f64; 3]]) -> Curve {
        let ctrl: Vec<Point3> = pts.iter().map(|p| Point3::new(p[0], p[1], p[2])).collect();
        Curve::new(KnotVector::uniform_clamped(3, ctrl.len()).unwrap(), ctrl).unwrap()
    }

    fn patch() -> CoonsPatch {
        let bottom = curve(&[
            [0., 0., 0.],
            [0.3, -0.2, 0.4],
            [0.7, 0.1, -0.2],
            [1., 0., 0.],
        ]);
        let right = curve(&[
            [1., 0., 0.],
            [1.2, 0.3, 0.5],
            [0.9, 0.5, 0.0],
            [1.1, 0.8, 0.2],
            [1., 1., 0.3],
        ]);
        let top = curve(&[
            [0., 1., 0.5],
            [0.5, 1.3, 0.0],
            [0.8, 1.1, 0.2],
            [1., 1., 0.3],
        ]);
        let left = curve(&[
            [0., 0., 0.],
            [-0.2, 0.4, 0.1],
            [0.1, 0.7, 0.3],
            [0., 1., 0.5],
        ]);
        CoonsPatch::new(&bottom, &top, &left, &right).unwrap()
    }

    /// Derivatives up to order 2 against central differences of the order
    /// below, and against the exact B-spline form for the Coons patch.
    fn check_by_differences<S: ParametricSurface>(s: &S, tol: f64) {
        let mut ws = s.workspace(2);
        let h = 1e-5;
        // off the knots (0.5 is one): the differences need C3 around the point
        for &(u, v) in &[(0.3, 0.6), (0.71, 0.2), (0.55, 0.45)] {
            let mut d = [Vector3::zeros(); 9];
            s.derivatives(u, v, 2, &mut ws, &mut d);
            assert!((d[0] - s.point(u, v).coords).norm() < 1e-15);
            let mut du = [[Vector3::zeros(); 9]; 2];
            let mut dv = [[Vector3::zeros(); 9]; 2];
            s.derivatives(u + h, v, 2, &mut ws, &mut du[0]);
            s.derivatives(u - h, v, 2, &mut ws, &mut du[1]);
            s.derivatives(u, v + h, 2, &mut ws, &mut dv[0]);
            s.derivatives(u, v - h, 2, &mut ws, &mut dv[1]);
            let fd = |a: &[Vector3; 9], b: &[Vector3; 9], i: usize| (a[i] - b[i]) / (2.0 * h);
            // S_u, S_v from points; S_uu, S_uv from S_u; S_vv from S_v
            assert!((d[3] - fd(&du[0], &du[1], 0)).norm() < tol, "S_u");
            assert!((d[1] - fd(&dv[0], &dv[1], 0)).norm() < tol, "S_v");
            assert!((d[6] - fd(&du[0], &du[1], 3)).norm() < tol, "S_uu");
            assert!((d[4] - fd(&dv[0], &dv[1], 3)).norm() < tol, "S_uv");
            assert!((d[2] - fd(&dv[0], &dv[1], 1)).norm() < tol, "S_vv");
        }
    }

    #[test]
    fn coons_derivatives_match_its_bspline_form() {
        let c = patch();
        check_by_differences(&c, 1e-6);
        let b = c.to_bspline().unwrap();
        let (mut wc, mut wb) = (c.workspace(2), ParametricSurface::workspace(&b, 2));
        for &(u, v) in &[(0.1, 0.9), (0.45, 0.33), (1.0, 0.0)] {
            let (mut dc, mut db) = ([Vector3::zeros(); 9], [Vector3::zeros(); 9]);
            ParametricSurface::derivatives(&c, u, v, 2, &mut wc, &mut dc);
            ParametricSurface::derivatives(&b, u, v, 2, &mut wb, &mut db);
            for i in [0, 1, 2, 3, 4, 6] {
                assert!((dc[i] - db[i]).norm() < 1e-12, "({u}, {v}) entry {i}");
            }
        }
        // the tuple form of the inherent method is the same derivatives
        let (p, su, sv) = c.derivatives(0.45, 0.33);
        let mut d = [Vector3::zeros(); 4];
        ParametricSurface::derivatives(&c, 0.45, 0.33, 1, &mut wc, &mut d);
        assert_eq!((p.coords, su, sv), (d[0], d[2], d[1]));
        assert!((c.extent() - ParametricSurface::extent(&b)).abs() < 0.5);
    }

    #[test]
    fn pde_surface_derivatives_include_the_sine_series() {
        let c = patch();
        let pts: Vec<Point3> = (0..400)
            .map(|i| {
                let (u, v) = ((i % 20) as f64 / 19.0, (i / 20) as f64 / 19.0);
                c.point(u, v)
                    + Vector3::z()
                        * (0.2
                            * (std::f64::consts::PI * u).sin()
                            * (2.0 * std::f64::consts::PI * v).sin())
            })
            .collect();
        let uv: Vec<[f64; 2]> = (0..400)
            .map(|i| [(i % 20) as f64 / 19.0, (i / 20) as f64 / 19.0])
            .collect();
        let fit = crate::pde::fit_pde(&c, &pts, &uv, &crate::pde::PdeConfig::default()).unwrap();
        check_by_differences(&fit.surface, 1e-5);
        // the deformation moves S_uv away from the Coons patch's
        let (mut wc, mut wp) = (c.workspace(2), fit.surface.workspace(2));
        let (mut dc, mut dp) = ([Vector3::zeros(); 9], [Vector3::zeros(); 9]);
        ParametricSurface::derivatives(&c, 0.3, 0.2, 2, &mut wc, &mut dc);
        fit.surface.derivatives(0.3, 0.2, 2, &mut wp, &mut dp);
        // d2/du dv of 0.2 sin(pi u) sin(2 pi v) = 0.4 pi^2 cos(pi u) cos(2 pi v)
        let pi = std::f64::consts::PI;
        let exact = 0.4 * pi * pi * (0.3 * pi).cos() * (0.4 * pi).cos();
        let got = dp[4] - dc[4];
        assert!((got.z - exact).abs() < 1e-3 * exact, "{got} vs {exact}");
    }
}
