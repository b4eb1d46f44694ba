//! The hybrid parameterization, the method [CURVE12] improves on
//! (its reference [9]; section 3.1, eq. 3.1):
//!
//! ```text
//! u_0 = 0,  u_n = 1,  u_i = u_{i-1} + sqrt|B_i - B_{i-1}| / sum_j sqrt|B_j - B_{j-1}|
//! ```
//!
//! where `B_i = max N_{i,p}(u)` are the maxima of the basis functions (eq. 3.2).
//! The OCR of eq. 3.1 does not say on which knots the `B_i` are taken; Table 1
//! describes the method as combining "centripetal and chord length", so we take
//! the basis functions on the averaging knots (de Boor) of the chord-length
//! parameters. This reproduces the failure the paper reports (section 4.1.3,
//! Figs. 14-15): on symmetric data such as data set 3 two neighbouring maxima
//! are equal, so `u_3 = u_4 = 0.5` and the interpolation matrix is singular.
//!
//! It also blows up on dense, nearly evenly spaced data such as data set 6
//! (69 points; asserted in `tests/datasets.rs`): the interior basis maxima
//! are then almost equal, so the increments `sqrt|B_i - B_{i-1}|` give almost
//! all of `[0, 1]` to the few end intervals and the interior parameters
//! nearly coincide. The interpolant still passes through every point but
//! oscillates between them (measured: curve 7615 times the polygon's length,
//! 538 self-intersections, condition estimate 7.3e6). The paper (section
//! 4.1.6, Fig. 21(f)) reports only "a cusp near the corner" for hybrid on
//! data set 6: our reading of eq. 3.1 fails far worse than its figure. We
//! keep the formula as printed and document the gap rather than tune it.
//!
//! Maxima equal up to rounding (a relative difference below 64 machine
//! epsilons) count as equal: their difference is rounding noise, and its
//! square root would otherwise hide the coincidence as a spurious 1e-8 gap.

use super::{basis_maximum, exponential, knots::averaging};
use crate::bspline::{BasisWorkspace, KnotVector};
use crate::{Point3, Result};

/// Hybrid parameters; the knots returned are the averaging knots of the result
/// (computed only when the parameters are strictly increasing; otherwise the
/// chord-length averaging knots are returned and the caller's check reports the
/// coincident parameters).
pub fn params(points: &[Point3], p: usize) -> Result<(Vec<f64>, KnotVector)> {
    let chord = exponential::params(points, 1.0, false)?;
    super::check_increasing(&chord, "chord-length (hybrid's first step)")?;
    let kv = averaging(&chord, p)?;
    let mut ws = BasisWorkspace::new(p, 2);
    let b: Vec<f64> = (0..points.len())
        .map(|i| basis_maximum(&kv, i, &mut ws).1)
        .collect();
    let bmax = b.iter().cloned().fold(0.0f64, f64::max);
    let inc: Vec<f64> = b
        .windows(2)
        .map(|w| {
            let d = (w[1] - w[0]).abs();
            if d <= 64.0 * f64::EPSILON * bmax {
                0.0
            } else {
                d.sqrt()
            }
        })
        .collect();
    let total: f64 = inc.iter().sum();
    let mut u = Vec::with_capacity(points.len());
    let mut acc = 0.0;
    u.push(0.0);
    for d in &inc {
        acc += d;
        u.push(if total > 0.0 { acc / total } else { 0.0 });
    }
    if let Some(l) = u.last_mut() {
        *l = 1.0;
    }
    let knots = if u.windows(2).all(|w| w[1] > w[0]) {
        averaging(&u, p)?
    } else {
        kv
    };
    Ok((u, knots))
}
