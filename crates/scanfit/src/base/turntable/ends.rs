//! Open or closed ends of a cylinder-like cloud, decided from the data.
//!
//! The layers of the virtual turntable ([`super::layers`]) leave a margin at
//! each end because a *closed* end (a bottle's bottom, the top of a head)
//! has no section around the axis there. An *open* end (the rim of a tube)
//! has one up to its last point, and a margin only leaves its points
//! outside the surface (6% of a tube's points with the default 3% at each
//! end). [`end_shapes`] tells them apart by where the points near the end
//! lie across the axis:
//!
//! * the *end band*: points within the margin of the end (`margin x` the
//!   height; at least 1% of it);
//! * the *reference radius*: the median distance from the axis of the
//!   points in the next band inwards (two margins wide);
//! * the end is **closed** when more than [`CLOSED_SHARE`] of the end band
//!   lies within [`INNER_RADIUS`] x the reference radius of the axis (a cap
//!   or bottom disk crosses the axis; a rim stays on the wall), **open**
//!   otherwise.
//!
//! Both tests are ratios of the data's own lengths: the decision does not
//! change with the units.

use crate::Point3;

use super::axis::CylinderFrame;

/// Share of the end band near the axis above which an end is closed (0.1;
/// a flat bottom puts about a quarter of its disk there, a tube none).
pub const CLOSED_SHARE: f64 = 0.1;

/// "Near the axis": within this fraction of the reference radius (0.5).
pub const INNER_RADIUS: f64 = 0.5;

/// What [`end_shapes`] found at one end.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EndShape {
    /// The end is open (a rim): fit the surface to it, no margin.
    pub open: bool,
    /// Share of the end band's points within [`INNER_RADIUS`] x the
    /// reference radius of the axis.
    pub inner_share: f64,
    /// Points in the end band.
    pub points: usize,
}

/// The shapes of the low (`h_min`) and high (`h_max`) ends of `points` in
/// `frame`, with end bands `margin` x the height wide (see the module
/// documentation).
///
/// ```
/// use scanfit::base::turntable::{end_shapes, AxisChoice, CylinderFrame};
/// use scanfit::{Point3, Vector3};
///
/// // a tube of radius 1 along y (open at both ends) with a bottom disk at y = 0
/// let mut pts = Vec::new();
/// for i in 0..60 {
///     for k in 0..40 {
///         let (t, y) = (k as f64 * 0.157, i as f64 * 0.05);
///         pts.push(Point3::new(t.cos(), y, t.sin()));
///         let r = (k as f64 + 0.5) / 40.0;
///         pts.push(Point3::new(r * (i as f64).cos(), 0.0, r * (i as f64).sin()));
///     }
/// }
/// let frame = CylinderFrame::of(&pts, AxisChoice::Given(Vector3::y()))?;
/// let [low, high] = end_shapes(&pts, &frame, 0.03);
/// assert!(!low.open && high.open);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn end_shapes(points: &[Point3], frame: &CylinderFrame, margin: f64) -> [EndShape; 2] {
    let (lo, hi) = frame.height;
    let span = hi - lo;
    let band = margin.max(0.01) * span;
    let local: Vec<(f64, f64)> = points
        .iter()
        .map(|p| {
            let l = frame.to_local(p);
            (l.y, l.x.hypot(l.z))
        })
        .collect();
    let shape = |depth: &dyn Fn(f64) -> f64| {
        let end: Vec<f64> = local
            .iter()
            .filter(|(h, _)| depth(*h) <= band)
            .map(|&(_, r)| r)
            .collect();
        let mut next: Vec<f64> = local
            .iter()
            .filter(|(h, _)| depth(*h) > band && depth(*h) <= 3.0 * band)
            .map(|&(_, r)| r)
            .collect();
        let reference = if next.is_empty() {
            0.0
        } else {
            let mid = next.len() / 2;
            *next.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let inner = end
            .iter()
            .filter(|&&r| r < INNER_RADIUS * reference)
            .count();
        let inner_share = inner as f64 / end.len().max(1) as f64;
        EndShape {
            open: !end.is_empty() && reference > 0.0 && inner_share <= CLOSED_SHARE,
            inner_share,
            points: end.len(),
        }
    };
    [shape(&|h| h - lo), shape(&|h| hi - h)]
}
