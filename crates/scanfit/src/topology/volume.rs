//! Enclosed volume of a closed set of parametric faces by the divergence
//! theorem: with `div x = 3`,
//!
//! ```text
//! V = 1/3 ∮ x · n dA = 1/3 Σ_faces ∫∫ S(u,v) · (S_u × S_v) du dv
//! ```
//!
//! integrated by Gauss-Legendre quadrature on every knot span of every face.
//! For a polynomial surface of degrees `(p, q)` the integrand has degree
//! `3p - 1` in `u` and `3q - 1` in `v`, so `ceil(3p / 2)` (resp. `3q`) nodes per
//! span integrate it exactly; rational faces get 4 extra nodes (their
//! integrand is not polynomial). The sign is positive when every face's normal
//! `S_u × S_v` points outwards.

use crate::bspline::{BasisWorkspace, Surface};
use crate::Vector3;

/// Gauss-Legendre nodes and weights on `[-1, 1]` (Newton's iteration on the
/// Legendre polynomial from the Chebyshev guess; `n >= 1`).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let n = n.max(1);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            // p1 = P_n, p0 = P_{n-1}
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// `∫∫ S · (S_u × S_v) du dv` over one face (3 x its contribution to the volume).
fn face_flux(s: &Surface) -> f64 {
    let (p, q) = s.degrees();
    let extra = if s.weights().is_some() { 4 } else { 0 };
    let gu = gauss_legendre((3 * p).div_ceil(2) + 1 + extra);
    let gv = gauss_legendre((3 * q).div_ceil(2) + 1 + extra);
    let bu = s.knots_u().breakpoints();
    let bv = s.knots_v().breakpoints();
    let mut wu = BasisWorkspace::new(p, 1);
    let mut wv = BasisWorkspace::new(q, 1);
    let mut d = [Vector3::zeros(); 4];
    let mut total = 0.0;
    for su in bu.windows(2) {
        let (ha, hb) = ((su[1] - su[0]) / 2.0, (su[1] + su[0]) / 2.0);
        for sv in bv.windows(2) {
            let (ka, kb) = ((sv[1] - sv[0]) / 2.0, (sv[1] + sv[0]) / 2.0);
            for &(xu, au) in &gu {
                for &(xv, av) in &gv {
                    s.derivatives_into(hb + ha * xu, kb + ka * xv, &mut wu, &mut wv, 1, &mut d);
                    // d[0] = S, d[1] = S_v, d[2] = S_u
                    total += au * av * ha * ka * d[0].dot(&d[2].cross(&d[1]));
                }
            }
        }
    }
    total
}

/// Signed volume enclosed by the faces (see the module doc); positive when
/// the normals `S_u × S_v` point outwards.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::topology::volume::signed_volume;
/// use scanfit::Point3;
/// // the unit square z = 0 with normal +z contributes nothing (x . n = 0 there);
/// // lifted to z = 1 it contributes 1/3 of the unit cube
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let top = Surface::new(k.clone(), k.clone(), vec![
///     Point3::new(0.0, 0.0, 1.0), Point3::new(0.0, 1.0, 1.0),
///     Point3::new(1.0, 0.0, 1.0), Point3::new(1.0, 1.0, 1.0)]).unwrap();
/// assert!((signed_volume([&top]) - 1.0 / 3.0).abs() < 1e-14);
/// ```
pub fn signed_volume<'a>(faces: impl IntoIterator<Item = &'a Surface>) -> f64 {
    faces.into_iter().map(face_flux).sum::<f64>() / 3.0
}
