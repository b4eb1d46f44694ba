//! Corners of a closed boundary loop, and the loop's split into the sides a
//! Coons patch is built on.
//!
//! Two corner measures from the papers, both evaluated at loop point `n`
//! with the neighbours `m` positions before and after it (`m` = the
//! neighbour offset; the papers use the adjacent points, `m = 1`, which on
//! scanned data measures the noise rather than the shape):
//!
//! * [`CornerCriterion::TurningAngle`], Coons base-surface paper
//!   (§III, eqs. 10–12):
//!   `d1 = P[n-m] - P[n]` (eq. 10), `d2 = P[n+m] - P[n]` (eq. 11),
//!   `theta_n = acos(d1 . d2 / (|d1| |d2|))` (eq. 12; the OCR text splits
//!   the fraction over two lines and prints the dot as `d1.d2`). A straight
//!   run gives `theta = pi`, a sharp turn a small angle; "four points where
//!   this angle comes out to be least are selected".
//! * [`CornerCriterion::ThreePointCurvature`], PDE/Coons reconstruction
//!   paper (§4.1, the unnumbered
//!   equation after ref. 30, Belyaev's three-point curvature):
//!   `k = 4 S / (a b c)`, `S` the area of the triangle `A = P[n-m]`,
//!   `B = P[n]`, `C = P[n+m]`, `a = |AB|`, `b = |BC|`, `c = |AC|` (the
//!   inverse circumradius); "the top four or three curvature points will be
//!   treated as the corner points".
//!
//! Both measures are unsigned: a reflex (concave) corner scores like a
//! convex one of the same angle. The best `count` points pairwise at least
//! `min_separation` (a fraction of the loop's length, measured along the
//! loop) apart are the corners, returned in loop order; side `k` runs from
//! corner `k` to corner `k + 1` along the loop's direction (reverse the loop
//! to reverse the sides).

use crate::{validate_points, Error, Point3, Result};

/// The corner measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CornerCriterion {
    /// Smallest angle between the vectors to the neighbours ([COONS19]
    /// eqs. 10–12). Values in radians, `[0, pi]`.
    #[default]
    TurningAngle,
    /// Largest three-point curvature `k = 4 S / (a b c)` ([PDE23] §4.1).
    /// Values in 1 / (units of the points).
    ThreePointCurvature,
}

/// Parameters of [`find_corners`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerConfig {
    /// The corner measure. Default [`CornerCriterion::TurningAngle`].
    pub criterion: CornerCriterion,
    /// Number of corners (and sides): 4 for a four-sided Coons patch, 3 for
    /// a three-sided one ([PDE23] §4.1, §5). Default 4; at least 2.
    pub count: usize,
    /// Neighbour offset `m` (in loop positions; must satisfy `2 m < n`).
    /// `None` (default): the neighbours of each point are the first loop
    /// points at least [`ARC_NEIGHBOUR`] (2.5%) of the loop's length away
    /// along it, before and after ([`arc_neighbour_values`]). Measured by
    /// length, not by count, the scale does not change with the uneven
    /// spacing of an alpha-shape boundary of sparse points, and it is wide
    /// enough to smooth over the small notches such a boundary bites into
    /// the outline (which a 1%-of-the-points offset picked as corners on
    /// 2000 scattered points, missing a true corner by a whole side), while
    /// staying inside the sides of a patch with aspect ratio up to ~15:1.
    pub offset: Option<usize>,
    /// Smallest distance between two corners along the loop, as a fraction
    /// of the loop's length. Default `0.03`: the best points around one
    /// corner (its neighbours score almost as well) are suppressed, while
    /// sides down to 3% of the perimeter (a 15:1 rectangle) are still found.
    pub min_separation: f64,
}

impl Default for CornerConfig {
    fn default() -> Self {
        Self {
            criterion: CornerCriterion::TurningAngle,
            count: 4,
            offset: None,
            min_separation: 0.03,
        }
    }
}

/// The default neighbour distance of the corner measures: 2.5% of the
/// loop's length (see [`CornerConfig::offset`]).
pub const ARC_NEIGHBOUR: f64 = 0.025;

/// The criterion's value at every position of the closed loop `points`, the
/// neighbours of each point being the first loop points at least `fraction`
/// of the loop's length away along the loop on either side ([COONS19] eqs.
/// 10-12 or [PDE23]'s `k = 4S/(abc)` on those three points), and the median
/// of the neighbours' offsets in positions.
///
/// ```
/// use scanfit::cloud::corners::{arc_neighbour_values, CornerCriterion};
/// use scanfit::Point3;
/// // a unit square with 10 points a side: 90 degrees at the corners
/// let mut sq = Vec::new();
/// for k in 0..40 {
///     let (s, t) = (k / 10, (k % 10) as f64 / 10.0);
///     sq.push(match s {
///         0 => Point3::new(t, 0.0, 0.0),
///         1 => Point3::new(1.0, t, 0.0),
///         2 => Point3::new(1.0 - t, 1.0, 0.0),
///         _ => Point3::new(0.0, 1.0 - t, 0.0),
///     });
/// }
/// let (v, m) = arc_neighbour_values(&sq, CornerCriterion::TurningAngle, 0.05)?;
/// // 5% of the length is 2 steps of 0.1; the arc sum may round past it
/// assert!((2..=3).contains(&m));
/// assert!((v[10].to_degrees() - 90.0).abs() < 1e-9);
/// assert!((v[5].to_degrees() - 180.0).abs() < 1e-9);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn arc_neighbour_values(
    points: &[Point3],
    criterion: CornerCriterion,
    fraction: f64,
) -> Result<(Vec<f64>, usize)> {
    validate_points(points)?;
    let n = points.len();
    if n < 3 || !(fraction.is_finite() && fraction > 0.0 && fraction < 0.5) {
        return Err(Error::InvalidInput(format!(
            "arc neighbours at {fraction} of the length of a {n}-point loop: need 3 or more points and a fraction in (0, 0.5)"
        )));
    }
    let step: Vec<f64> = (0..n)
        .map(|i| (points[(i + 1) % n] - points[i]).norm())
        .collect();
    if let Some(i) = step.iter().position(|&s| s == 0.0) {
        let j = (i + 1) % n;
        return Err(Error::DuplicatePoints {
            first: i.min(j),
            second: i.max(j),
            distance: 0.0,
        });
    }
    let length: f64 = step.iter().sum();
    let reach = fraction * length;
    // how many positions forward (backward) the neighbour of each point is
    let walk = |i: usize, forward: bool| {
        let (mut d, mut k) = (0.0, 0usize);
        while d < reach && k < n / 2 {
            let j = if forward {
                (i + k) % n
            } else {
                (i + n - k - 1) % n
            };
            d += step[j];
            k += 1;
        }
        k.max(1)
    };
    let mut offsets = Vec::with_capacity(n);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (kb, kf) = (walk(i, false), walk(i, true));
        offsets.push(kb.max(kf));
        let (ia, ic) = ((i + n - kb) % n, (i + kf) % n);
        out.push(measure(points, criterion, ia, i, ic)?);
    }
    let mid = offsets.len() / 2;
    let median = *offsets.select_nth_unstable(mid).1;
    Ok((out, median))
}

/// The criterion at `b` with neighbours `a` and `c` (eqs. 10-12 or `4S/(abc)`).
fn measure(
    points: &[Point3],
    criterion: CornerCriterion,
    ia: usize,
    i: usize,
    ic: usize,
) -> Result<f64> {
    let (a, b, c) = (points[ia], points[i], points[ic]);
    let d1 = a - b; // eq. 10
    let d2 = c - b; // eq. 11
    let (l1, l2) = (d1.norm(), d2.norm());
    for (j, l) in [(ia, l1), (ic, l2)] {
        if l == 0.0 {
            return Err(Error::DuplicatePoints {
                first: j.min(i),
                second: j.max(i),
                distance: 0.0,
            });
        }
    }
    Ok(match criterion {
        // eq. 12
        CornerCriterion::TurningAngle => (d1.dot(&d2) / (l1 * l2)).clamp(-1.0, 1.0).acos(),
        CornerCriterion::ThreePointCurvature => {
            let s = 0.5 * d1.cross(&d2).norm();
            let ac = (c - a).norm();
            if ac == 0.0 {
                return Err(Error::DuplicatePoints {
                    first: ia.min(ic),
                    second: ia.max(ic),
                    distance: 0.0,
                });
            }
            4.0 * s / (l1 * l2 * ac)
        }
    })
}

/// The criterion's values by the rule of `config` (its index offset, or the
/// arc neighbours when it has none) and the (median) offset used.
pub fn values_for(points: &[Point3], config: &CornerConfig) -> Result<(Vec<f64>, usize)> {
    match config.offset {
        Some(m) => Ok((corner_values(points, config.criterion, m)?, m)),
        None => arc_neighbour_values(points, config.criterion, ARC_NEIGHBOUR),
    }
}

/// Corners of a loop and its sides. All indices are positions in the loop.
#[derive(Debug, Clone, PartialEq)]
pub struct Corners {
    /// Loop positions of the corners, in loop order (ascending).
    pub corners: Vec<usize>,
    /// Side `k`: loop positions from `corners[k]` to `corners[k + 1]`
    /// (cyclically), both included; consecutive sides share their corner.
    pub sides: Vec<Vec<usize>>,
    /// The criterion's value at every loop position (angle in radians or
    /// curvature).
    pub values: Vec<f64>,
    /// The neighbour offset used (the median one with arc neighbours).
    pub offset: usize,
}

/// The criterion's value at every position of the closed loop `points`
/// (first point not repeated at the end), with neighbour offset `offset`:
/// [COONS19] eqs. 10–12 or [PDE23]'s `k = 4S/(abc)` (§4.1).
///
/// Errors: `offset >= n / 2` (rounded up), `offset == 0`, coincident points at a
/// position and its neighbour (remove duplicates), non-finite points.
pub fn corner_values(
    points: &[Point3],
    criterion: CornerCriterion,
    offset: usize,
) -> Result<Vec<f64>> {
    validate_points(points)?;
    let n = points.len();
    if offset == 0 || offset >= n.div_ceil(2) {
        return Err(Error::InvalidInput(format!(
            "neighbour offset {offset} does not fit a loop of {n} points; it needs 1 <= offset < n / 2"
        )));
    }
    (0..n)
        .map(|i| measure(points, criterion, (i + n - offset) % n, i, (i + offset) % n))
        .collect()
}

/// Finds `config.count` corners on the closed loop `points` (first point not
/// repeated at the end) and splits the loop into sides between them. See the
/// module documentation for the two criteria ([COONS19] eqs. 10–12, PDE
/// paper §4.1).
///
/// For a [`Boundary`](super::boundary::Boundary) loop `lp` of a cloud, pass
/// the points `lp.iter().map(|&i| cloud.points()[i])`, and map the returned
/// positions back through `lp`.
///
/// Errors: fewer than `max(3, count)` points; `count < 2`; a bad offset or
/// separation; coincident neighbours; fewer than `count` points pairwise
/// `min_separation` apart (lower it or the count).
pub fn find_corners(points: &[Point3], config: &CornerConfig) -> Result<Corners> {
    let n = points.len();
    if config.count < 2 {
        return Err(Error::InvalidInput(format!(
            "{} corners asked for; a loop splits into sides at 2 or more (3 or 4 for Coons patches)",
            config.count
        )));
    }
    let needed = config.count.max(3);
    if n < needed {
        return Err(Error::TooFewPoints {
            got: n,
            needed,
            what: format!("{} corners on a closed loop", config.count),
        });
    }
    let sep = config.min_separation;
    if !(sep.is_finite() && (0.0..0.5).contains(&sep)) {
        return Err(Error::InvalidInput(format!(
            "min_separation = {sep} must be a fraction of the loop length in [0, 0.5) (default 0.03)"
        )));
    }
    let (values, offset) = values_for(points, config)?;
    // arc length along the loop
    let mut s = Vec::with_capacity(n);
    let mut acc = 0.0;
    for i in 0..n {
        s.push(acc);
        acc += (points[(i + 1) % n] - points[i]).norm();
    }
    let length = acc;
    let min_gap = sep * length;
    let mut order: Vec<usize> = (0..n).collect();
    match config.criterion {
        CornerCriterion::TurningAngle => {
            order.sort_by(|&a, &b| values[a].total_cmp(&values[b]).then(a.cmp(&b)))
        }
        CornerCriterion::ThreePointCurvature => {
            order.sort_by(|&a, &b| values[b].total_cmp(&values[a]).then(a.cmp(&b)))
        }
    }
    let mut picked: Vec<usize> = Vec::with_capacity(config.count);
    for &i in &order {
        let far_enough = picked.iter().all(|&j| {
            let d = (s[i] - s[j]).abs();
            d.min(length - d) >= min_gap && i != j
        });
        if far_enough {
            picked.push(i);
            if picked.len() == config.count {
                break;
            }
        }
    }
    if picked.len() < config.count {
        return Err(Error::InvalidInput(format!(
            "only {} points of the {n}-point loop are pairwise {sep} of its length apart, {} corners asked for; lower min_separation or count",
            picked.len(),
            config.count
        )));
    }
    if config.offset.is_none() {
        // at the wide arc scale the angle is nearly as small a few points
        // either side of a corner: move each pick to the apex of its
        // neighbourhood, the point farthest from the chord between its
        // neighbours
        for c in picked.iter_mut() {
            *c = apex(points, *c, offset);
        }
        picked.dedup();
        if picked.len() < config.count {
            return Err(Error::InvalidInput(format!(
                "two of the {} corners of the {n}-point loop fall on one point; lower the count",
                config.count
            )));
        }
    }
    picked.sort_unstable();
    picked.dedup();
    if picked.len() < config.count {
        return Err(Error::InvalidInput(format!(
            "two of the {} corners of the {n}-point loop fall on one point; lower the count",
            config.count
        )));
    }
    let sides = split_at_corners(n, &picked)?;
    Ok(Corners {
        corners: picked,
        sides,
        values,
        offset,
    })
}

/// The loop position within `m` of `i` farthest from the chord between
/// positions `i - m` and `i + m` (the apex of the turn).
fn apex(points: &[Point3], i: usize, m: usize) -> usize {
    let n = points.len();
    let (a, c) = (points[(i + n - m) % n], points[(i + m) % n]);
    let chord = c - a;
    let len2 = chord.norm_squared();
    let dist = |p: &Point3| {
        let d = p - a;
        if len2 > 0.0 {
            (d - chord * (d.dot(&chord) / len2)).norm()
        } else {
            d.norm()
        }
    };
    (0..=2 * m)
        .map(|k| (i + n - m + k) % n)
        .max_by(|&x, &y| {
            dist(&points[x])
                .total_cmp(&dist(&points[y]))
                .then(y.cmp(&x))
        })
        .unwrap_or(i)
}

/// Splits a closed loop of `n` points at the given corner positions into
/// sides: side `k` runs from `corners[k]` to `corners[k + 1]` (the last one
/// back to `corners[0]`) along the loop, both ends included.
///
/// The corners must be distinct positions below `n`, at least 2, and follow
/// the loop's direction starting from `corners[0]` (`[5, 9, 1]` is fine on a
/// 12-point loop, `[5, 1, 9]` is not).
pub fn split_at_corners(n: usize, corners: &[usize]) -> Result<Vec<Vec<usize>>> {
    if corners.len() < 2 {
        return Err(Error::InvalidInput(format!(
            "{} corner(s) given; splitting a loop needs at least 2",
            corners.len()
        )));
    }
    if let Some(&bad) = corners.iter().find(|&&c| c >= n) {
        return Err(Error::InvalidInput(format!(
            "corner position {bad} is out of range for a loop of {n} points"
        )));
    }
    let first = corners[0];
    let rel: Vec<usize> = corners.iter().map(|&c| (c + n - first) % n).collect();
    for k in 1..rel.len() {
        if rel[k] <= rel[k - 1] {
            return Err(Error::InvalidInput(format!(
                "corner {k} (position {}) {} corner {} (position {}) along the loop from corner 0 (position {first}); give distinct corners in loop order",
                corners[k],
                if rel[k] == rel[k - 1] { "repeats" } else { "comes before" },
                k - 1,
                corners[k - 1]
            )));
        }
    }
    let m = corners.len();
    Ok((0..m)
        .map(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % m]);
            let len = (b + n - a) % n;
            (0..=len).map(|j| (a + j) % n).collect()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::boundary::{boundary_loops, BoundaryConfig};
    use crate::cloud::testutil::Rng;

    /// A closed polygon through `vertices`, sampled every `h`, starting at
    /// vertex 0; returns the points and the positions of the vertices.
    fn polygon(vertices: &[[f64; 2]], h: f64) -> (Vec<Point3>, Vec<usize>) {
        let mut p = Vec::new();
        let mut at = Vec::new();
        for k in 0..vertices.len() {
            let (a, b) = (vertices[k], vertices[(k + 1) % vertices.len()]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let steps = (len / h).round() as usize;
            at.push(p.len());
            for j in 0..steps {
                let t = j as f64 / steps as f64;
                let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                p.push(Point3::new(x, y, 0.3 * (0.5 * x).sin() + 0.2 * y));
            }
        }
        (p, at)
    }

    fn noisy(p: &mut [Point3], sigma: f64, seed: u64) {
        let mut rng = Rng::new(seed);
        for q in p {
            q.x += sigma * rng.normal();
            q.y += sigma * rng.normal();
            q.z += sigma * rng.normal();
        }
    }

    fn cyclic_dist(a: usize, b: usize, n: usize) -> usize {
        let d = a.abs_diff(b);
        d.min(n - d)
    }

    /// Every true corner has a found corner within `tol` positions (a
    /// cyclic set comparison: a corner near position 0 may be found at n - 1).
    fn assert_near_each(found: &[usize], truth: &[usize], n: usize, tol: usize) {
        assert_eq!(found.len(), truth.len(), "{found:?} vs {truth:?}");
        for &t in truth {
            let best = found.iter().map(|&f| cyclic_dist(f, t, n)).min().unwrap();
            assert!(best <= tol, "{found:?} vs {truth:?}");
        }
    }

    fn check_sides(c: &Corners, n: usize) {
        assert_eq!(c.sides.len(), c.corners.len());
        let mut count = vec![0usize; n];
        for (k, side) in c.sides.iter().enumerate() {
            assert_eq!(side[0], c.corners[k]);
            assert_eq!(*side.last().unwrap(), c.corners[(k + 1) % c.corners.len()]);
            for w in side.windows(2) {
                assert_eq!(w[1], (w[0] + 1) % n);
            }
            for &i in side {
                count[i] += 1;
            }
        }
        for i in 0..n {
            let expected = if c.corners.contains(&i) { 2 } else { 1 };
            assert_eq!(count[i], expected, "position {i}");
        }
        assert_eq!(
            c.sides.iter().map(Vec::len).sum::<usize>(),
            n + c.corners.len()
        );
    }

    #[test]
    fn noisy_rectangle_corners_by_both_criteria() {
        let (mut p, truth) = polygon(&[[0., 0.], [4., 0.], [4., 2.], [0., 2.]], 0.02);
        assert_eq!(p.len(), 600);
        // noise of a quarter of the point spacing, in all three coordinates
        noisy(&mut p, 0.005, 1);
        // start the loop mid-side so no corner sits at position 0
        p.rotate_left(50);
        let truth: Vec<usize> = truth.iter().map(|&t| (t + 600 - 50) % 600).collect();
        for criterion in [
            CornerCriterion::TurningAngle,
            CornerCriterion::ThreePointCurvature,
        ] {
            let cfg = CornerConfig {
                criterion,
                ..Default::default()
            };
            let c = find_corners(&p, &cfg).unwrap();
            // neighbours 2.5% of the perimeter (0.3) away: 15 spacings
            assert!((14..=17).contains(&c.offset), "{}", c.offset);
            assert_eq!(c.corners.len(), 4);
            assert_near_each(&c.corners, &truth, 600, 2);
            check_sides(&c, 600);
        }
        // with half a spacing of noise the paper's adjacent points (m = 1)
        // see the noise, not the corners; the default offset still finds them
        let (mut p, truth) = polygon(&[[0., 0.], [4., 0.], [4., 2.], [0., 2.]], 0.02);
        noisy(&mut p, 0.01, 2);
        let c = find_corners(&p, &CornerConfig::default()).unwrap();
        assert_near_each(&c.corners, &truth, 600, 3);
        let cfg = CornerConfig {
            offset: Some(1),
            ..Default::default()
        };
        let c = find_corners(&p, &cfg).unwrap();
        let hits = c
            .corners
            .iter()
            .filter(|&&g| truth.iter().any(|&t| cyclic_dist(g, t, 600) <= 1))
            .count();
        assert!(hits < 4, "offset 1 found all corners despite the noise");
    }

    #[test]
    fn triangle_has_three_sides() {
        let (p, truth) = polygon(&[[0., 0.], [3., 0.], [1., 2.]], 0.01);
        let n = p.len();
        for criterion in [
            CornerCriterion::TurningAngle,
            CornerCriterion::ThreePointCurvature,
        ] {
            let cfg = CornerConfig {
                criterion,
                count: 3,
                ..Default::default()
            };
            let c = find_corners(&p, &cfg).unwrap();
            // 4S/(abc) with neighbours m apart peaks next to an acute corner
            // (moving B off the corner along a side opens the angle at B and
            // shrinks the circumradius |AC| / (2 sin B)); the apex step moves
            // every pick onto the corner, for both criteria
            assert_eq!(c.corners, truth);
            check_sides(&c, n);
        }
        // the turning angle at a corner is the triangle's interior angle
        let c = find_corners(
            &p,
            &CornerConfig {
                count: 3,
                ..Default::default()
            },
        )
        .unwrap();
        let apex = c.values[truth[1]];
        let expected = (Point3::new(0., 0., 0.) - Point3::new(3., 0., 0.))
            .xy()
            .angle(&(Point3::new(1., 2., 0.) - Point3::new(3., 0., 0.)).xy());
        // the z bump makes the 3D angle differ slightly from the planar one
        assert!((apex - expected).abs() < 0.05, "{apex} vs {expected}");
    }

    #[test]
    fn rounded_rectangle_corners_are_the_arc_middles() {
        // 6 x 3 rectangle with corner radius 0.5, 1200 points
        let (w, h, r) = (6.0f64, 3.0f64, 0.5f64);
        let mut p = Vec::new();
        let mut mids = Vec::new();
        let centres = [[w - r, r], [w - r, h - r], [r, h - r], [r, r]];
        let starts = [[r, 0.0], [w, r], [w - r, h], [0.0, h - r]];
        let dirs = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let step = 0.015f64;
        for k in 0..4 {
            let len = if k % 2 == 0 { w - 2.0 * r } else { h - 2.0 * r };
            let m = (len / step).round() as usize;
            for j in 0..m {
                let t = len * j as f64 / m as f64;
                p.push(Point3::new(
                    starts[k][0] + t * dirs[k][0],
                    starts[k][1] + t * dirs[k][1],
                    0.0,
                ));
            }
            let m = (0.5 * std::f64::consts::PI * r / step).round() as usize;
            let a0 = -std::f64::consts::FRAC_PI_2 + k as f64 * std::f64::consts::FRAC_PI_2;
            for j in 0..m {
                let a = a0 + std::f64::consts::FRAC_PI_2 * j as f64 / m as f64;
                if j == m / 2 {
                    mids.push(p.len());
                }
                p.push(Point3::new(
                    centres[k][0] + r * a.cos(),
                    centres[k][1] + r * a.sin(),
                    0.0,
                ));
            }
        }
        let n = p.len();
        for criterion in [
            CornerCriterion::TurningAngle,
            CornerCriterion::ThreePointCurvature,
        ] {
            let cfg = CornerConfig {
                criterion,
                ..Default::default()
            };
            // the default neighbours (2.5% of the loop, 29 points) reach
            // past half an arc (26 points): the apex is the arc middle
            let c = find_corners(&p, &cfg).unwrap();
            assert_eq!((n, c.offset), (1140, 29));
            assert_near_each(&c.corners, &mids, n, 2);
            check_sides(&c, n);
            // an offset reaching past the arc's ends peaks at the arc middle
            let cfg = CornerConfig {
                offset: Some(40),
                ..cfg
            };
            let c = find_corners(&p, &cfg).unwrap();
            assert_near_each(&c.corners, &mids, n, 1);
        }
    }

    #[test]
    fn l_shape_scores_reflex_and_convex_corners_alike() {
        // L with six right-angle corners; position 3 of `truth` is the reflex one
        let v = [
            [0., 0.],
            [4., 0.],
            [4., 1.5],
            [1.5, 1.5],
            [1.5, 3.],
            [0., 3.],
        ];
        let (p, truth) = polygon(&v, 0.02);
        for criterion in [
            CornerCriterion::TurningAngle,
            CornerCriterion::ThreePointCurvature,
        ] {
            let cfg = CornerConfig {
                criterion,
                ..Default::default()
            };
            let c = find_corners(&p, &cfg).unwrap();
            // all six corners score the same up to the z bump: the unsigned
            // criteria cannot prefer convex ones
            let at: Vec<f64> = truth.iter().map(|&t| c.values[t]).collect();
            let spread = at.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - at.iter().copied().fold(f64::INFINITY, f64::min);
            let scale = at[0].abs();
            assert!(spread < 0.25 * scale, "{criterion:?}: {at:?}");
            // the four picked are true corners; which four follows the z bump
            assert!(
                c.corners.iter().all(|g| truth.contains(g)),
                "{criterion:?}: {:?} vs {truth:?}",
                c.corners
            );
            check_sides(&c, p.len());
        }
        let angle = find_corners(&p, &CornerConfig::default()).unwrap();
        let curv = find_corners(
            &p,
            &CornerConfig {
                criterion: CornerCriterion::ThreePointCurvature,
                ..Default::default()
            },
        )
        .unwrap();
        // the reflex corner (truth[3]) is among the picks of both criteria
        assert!(angle.corners.contains(&truth[3]) && curv.corners.contains(&truth[3]));
    }

    #[test]
    fn boundary_of_a_grid_patch_splits_at_its_four_corners() {
        let mut pts = Vec::new();
        for j in 0..30 {
            for i in 0..50 {
                let (x, y) = (i as f64, j as f64);
                pts.push(Point3::new(x, y, 2.0 * (0.1 * x).sin() * (0.1 * y).cos()));
            }
        }
        let b = boundary_loops(&pts, &BoundaryConfig::default()).unwrap();
        let lp = b.outer_loop();
        let loop_pts: Vec<Point3> = lp.iter().map(|&i| pts[i]).collect();
        let grid_corners = [0, 49, 50 * 29, 50 * 30 - 1];
        for criterion in [
            CornerCriterion::TurningAngle,
            CornerCriterion::ThreePointCurvature,
        ] {
            let cfg = CornerConfig {
                criterion,
                ..Default::default()
            };
            let c = find_corners(&loop_pts, &cfg).unwrap();
            let mut found: Vec<usize> = c.corners.iter().map(|&k| lp[k]).collect();
            found.sort_unstable();
            assert_eq!(found, grid_corners, "{criterion:?}");
            // sides: two of 50 points, two of 30, counting both corners
            let mut lens: Vec<usize> = c.sides.iter().map(Vec::len).collect();
            lens.sort_unstable();
            assert_eq!(lens, [30, 30, 50, 50]);
        }
    }

    #[test]
    fn user_corners_are_validated() {
        let sides = split_at_corners(12, &[5, 9, 1]).unwrap();
        assert_eq!(
            sides,
            vec![
                vec![5, 6, 7, 8, 9],
                vec![9, 10, 11, 0, 1],
                vec![1, 2, 3, 4, 5]
            ]
        );
        assert!(
            format!("{}", split_at_corners(12, &[5, 1, 9]).unwrap_err()).contains("comes before")
        );
        assert!(format!("{}", split_at_corners(12, &[5, 5, 9]).unwrap_err()).contains("repeats"));
        assert!(format!("{}", split_at_corners(12, &[5, 12]).unwrap_err()).contains("out of range"));
        assert!(split_at_corners(12, &[5]).is_err());
    }

    #[test]
    fn bad_loops_are_errors() {
        let (p, _) = polygon(&[[0., 0.], [1., 0.], [1., 1.], [0., 1.]], 0.1);
        let cfg = CornerConfig::default();
        assert!(matches!(
            find_corners(&p[..3], &cfg),
            Err(Error::TooFewPoints {
                got: 3,
                needed: 4,
                ..
            })
        ));
        assert!(find_corners(&p, &CornerConfig { count: 1, ..cfg }).is_err());
        assert!(find_corners(
            &p,
            &CornerConfig {
                offset: Some(20),
                ..cfg
            }
        )
        .is_err());
        assert!(find_corners(
            &p,
            &CornerConfig {
                offset: Some(0),
                ..cfg
            }
        )
        .is_err());
        assert!(find_corners(
            &p,
            &CornerConfig {
                min_separation: 0.6,
                ..cfg
            }
        )
        .is_err());
        let err = find_corners(
            &p,
            &CornerConfig {
                min_separation: 0.3,
                ..cfg
            },
        )
        .unwrap_err();
        assert!(format!("{err}").contains("lower min_separation"), "{err}");
        // the first point repeated at the end
        let mut closed = p.clone();
        closed.push(p[0]);
        assert!(matches!(
            find_corners(&closed, &cfg),
            Err(Error::DuplicatePoints { .. })
        ));
    }
}
