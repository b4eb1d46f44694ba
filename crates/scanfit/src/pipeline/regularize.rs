//! Safe defaults of the least-squares surface fits (`fit` and the Coons
//! paper's route of `coons`): the control net from the point density and a
//! thin-plate weight scaled to the data, so a default run on a real scan
//! (uneven density, sparse regions, a rounded outline whose parameter
//! rectangle has empty corners) does not fly off.
//!
//! **The weight.** The fit minimises `sum_k |P_k - S(u_k, v_k)|^2 + lambda
//! E(S)` with the thin-plate energy `E = ∫∫ |S_uu|^2 + 2|S_uv|^2 + |S_vv|^2`
//! over the parameter square (NURBS Book eq. 9.63 plus the energy term of
//! [`crate::fit::surface`]). Both terms are squared lengths, so `lambda` has
//! no unit and a cloud scaled by 1000 gives the same surface scaled by 1000.
//! What it must follow is the point count and the net: a control point of an
//! `nu x nv` net holds about `N / (nu nv)` points, whose data term on its
//! diagonal is of that order, while the energy's diagonal entry grows as
//! `nu^3 / nv + nv^3 / nu` (second derivatives of basis functions of width
//! `1 / nu`). [`scaled_smoothing`] takes
//!
//! ```text
//! lambda = c * N / (nu nv)^2   (for a square net: the energy's diagonal is
//!                               about c times the data term of an average span)
//! ```
//!
//! with `c` = [`DEFAULT_RELATIVE_SMOOTHING`]: negligible where a span holds
//! its share of points, dominant where it holds a small fraction of it, so
//! sparsely covered spans follow the thin-plate continuation of their
//! neighbours instead of the few points (or none) in them. The bare fit of
//! the paper is `lambda = 0` (`--smooth 0`).
//!
//! **The net.** [`density_ctrl`]: `n = round(sqrt(N / 16))` control points
//! per direction (16 points per control point on average, the old default
//! 16 x 16 at 4096 points), at least `degree + 2` and at most
//! [`MAX_DENSITY_CTRL`].

/// The default relative thin-plate weight `c` of [`scaled_smoothing`].
/// Measured (README, `scanfit fit`, "Safe defaults") on
/// `examples/data/make_nasty.py`'s face: the default 19 x 19 fit stays within
/// 10% of the diagonal of the points' box (the continuation of the face's
/// slope into the empty corners of its parameter rectangle), where the bare
/// 16 x 16 fit reaches 1.4 x 10^5 units (450 diagonals); on the shipped
/// `patch_20k.ply` the bare 16 x 16 fit overshoots a corner by 30.6 units
/// (105 point spacings) and the default by 0.32; the RMSE of the clean
/// samples rises by 0.1% (patch) to 0.5% (terrain) over the bare fit on the
/// same net. Ten times the weight costs the terrain 5-8% of its RMSE.
pub const DEFAULT_RELATIVE_SMOOTHING: f64 = 0.001;

/// Average points per control point of [`density_ctrl`].
pub const POINTS_PER_CONTROL_POINT: usize = 16;

/// Most control points per direction [`density_ctrl`] chooses.
pub const MAX_DENSITY_CTRL: usize = 32;

/// The thin-plate weight `lambda = relative * points / (nu nv)^2` (see the
/// module documentation).
///
/// ```
/// use scanfit::pipeline::regularize::scaled_smoothing;
/// // 4096 points on a 16 x 16 net: 4096 / 65536 = 1/16 of the relative weight
/// assert_eq!(scaled_smoothing(0.001, 4096, (16, 16)), 0.001 / 16.0);
/// ```
pub fn scaled_smoothing(relative: f64, points: usize, ctrl: (usize, usize)) -> f64 {
    let cells = (ctrl.0.max(1) * ctrl.1.max(1)) as f64;
    relative * points as f64 / (cells * cells)
}

/// The control net from the point density: `round(sqrt(points / 16))` per
/// direction, clamped to `[degree + 2, 32]` (see the module documentation).
///
/// ```
/// use scanfit::pipeline::regularize::density_ctrl;
/// assert_eq!(density_ctrl(4096, (3, 3)), (16, 16));
/// assert_eq!(density_ctrl(100, (3, 3)), (5, 5));
/// assert_eq!(density_ctrl(1_000_000, (3, 3)), (32, 32));
/// ```
pub fn density_ctrl(points: usize, degree: (usize, usize)) -> (usize, usize) {
    let n = (points as f64 / POINTS_PER_CONTROL_POINT as f64)
        .sqrt()
        .round() as usize;
    let each = |p: usize| n.clamp(p + 2, MAX_DENSITY_CTRL.max(p + 2));
    (each(degree.0), each(degree.1))
}
