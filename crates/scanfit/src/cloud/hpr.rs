//! Hidden point removal: which points of a cloud are visible from a
//! viewpoint, without a surface or normals ([Katz07], "Direct
//! visibility of point sets", ACM TOG 26(3)).
//!
//! The operator has two steps (Katz et al. §2):
//!
//! 1. *Spherical flipping*: with the viewpoint `C` moved to the origin, every
//!    point `p` is reflected along its ray about a sphere of radius `R`
//!    centred at `C` that contains all points,
//!    `p' = p + 2 (R - |p|) p / |p|` (Katz et al. eq. 1).
//! 2. *Convex hull*: a point is marked visible when its flipped image is a
//!    vertex of the convex hull of the flipped points together with `C`.
//!    From 50 000 points on, the flipped points certainly inside the hull of
//!    a sample are dropped first (exact predicates, `hpr_filter`): the hull
//!    of the rest has the same vertices, at a fraction of the cost.
//!
//! The radius follows the authors' reference implementation,
//! `R = max|p - C| * 10^gamma`: the larger `gamma`, the more points near
//! grazing angles (and in shallow concavities) count as visible. Too large a
//! radius turns against a sampled surface: the hull facet between two
//! neighbouring flipped points, an angle `delta` apart seen from `C`, bulges
//! out by about `R delta^2 / 4`, and a hidden point less deep than that behind
//! the visible surface shows through. (On 20 000 points of a unit sphere seen
//! from distance 3, `gamma` from 0.5 to 2 gives exactly the geometric cap,
//! `gamma = 3` lets the first far-side points through, `gamma = 8` shows
//! nearly all.)
//!
//! The turntable parameterization paper (Kim et al.,
//! `cylindrical-turntable-parameterization`, §3.2, eqs. 17–18) applies this
//! operator to each of four 90° turns of the cloud, looking along `-z`, to
//! turn the cloud into 2.5D data for multilevel B-splines; it gives no value
//! for `R`. [`HprConfig::default`] uses `gamma = 2` (`R` a hundred times the
//! farthest point's distance): large, as Katz et al. advise, yet below the
//! range where sampling gaps let hidden points through at scan densities;
//! the tests of this module show what it gives on spheres, boxes and
//! occluded sheets. Sparse clouds want a smaller `gamma`.

use std::collections::HashSet;

use super::hpr_filter::{hull_candidates, MIN_POINTS};
use super::hull::hull_of_coordinates;
use crate::{validate_points, Error, Point3, Result};

/// Parameters of [`hidden_point_removal`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HprConfig {
    /// `gamma` of the flipping radius `R = max|p - C| * 10^gamma` (Katz et
    /// al. 2007, §2; their reference code calls it `param`). Must be in
    /// `(0, 12]` so that `R` exceeds every distance and the flipped points
    /// still resolve the distances in f64. Default `2.0` ([TURN17]
    /// §3.2 uses the operator without giving `R`).
    pub gamma: f64,
}

impl Default for HprConfig {
    fn default() -> Self {
        Self { gamma: 2.0 }
    }
}

/// Relative distance (to the farthest point) under which a point counts as
/// coinciding with the viewpoint; such a point has no direction to flip
/// along.
pub const VIEWPOINT_TOLERANCE: f64 = 1e-12;

/// Indices (sorted ascending) of the `points` visible from `viewpoint`, by
/// the hidden point removal operator of [Katz07] (spherical
/// flipping, eq. 1, then the convex hull of the flipped points and the
/// viewpoint). Exact duplicates of a visible point are visible too.
///
/// For a [`PointCloud`](crate::PointCloud) pass `cloud.points()`.
///
/// Errors: fewer than 4 points; a non-finite viewpoint or point; a point
/// coinciding with the viewpoint (within [`VIEWPOINT_TOLERANCE`] of the
/// farthest distance; move the viewpoint or remove the point); `gamma`
/// outside `(0, 12]`; points that all lie on one plane through the viewpoint
/// (the flipped set spans no volume; such a view sees every point edge-on).
pub fn hidden_point_removal(
    points: &[Point3],
    viewpoint: &Point3,
    config: &HprConfig,
) -> Result<Vec<usize>> {
    hpr_filtered_above(points, viewpoint, config, MIN_POINTS)
}

/// [`hidden_point_removal`] with the interior filter
/// ([`super::hpr_filter`]) applied from `min_filtered` points on
/// (`usize::MAX`: never, the plain hull of all flipped points).
pub(crate) fn hpr_filtered_above(
    points: &[Point3],
    viewpoint: &Point3,
    config: &HprConfig,
    min_filtered: usize,
) -> Result<Vec<usize>> {
    validate_points(points)?;
    validate_points(std::slice::from_ref(viewpoint)).map_err(|e| {
        Error::InvalidInput(format!("hidden point removal: invalid viewpoint: {e}"))
    })?;
    if points.len() < 4 {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: 4,
            what: "hidden point removal".into(),
        });
    }
    let gamma = config.gamma;
    if !(gamma > 0.0 && gamma <= 12.0) {
        return Err(Error::InvalidInput(format!(
            "hidden point removal: gamma = {gamma} is outside (0, 12]; the flipping radius R = max|p - C| * 10^gamma must exceed every distance (the default is 2)"
        )));
    }
    let norms: Vec<f64> = points.iter().map(|p| (p - viewpoint).norm()).collect();
    let max_norm = norms.iter().copied().fold(0.0, f64::max);
    if let Some(i) = norms
        .iter()
        .position(|&d| d <= VIEWPOINT_TOLERANCE * max_norm)
    {
        return Err(Error::InvalidInput(format!(
            "hidden point removal: point {i} coincides with the viewpoint {viewpoint} (distance {:e}); move the viewpoint off the points or remove that point",
            norms[i]
        )));
    }
    let radius = max_norm * 10f64.powf(gamma);
    // Katz et al. eq. 1: p' = p + 2 (R - |p|) p / |p| = p (2R / |p| - 1)
    let mut flipped: Vec<[f64; 3]> = Vec::with_capacity(points.len() + 1);
    flipped.extend(points.iter().zip(&norms).map(|(p, &d)| {
        let v = (p - viewpoint) * (2.0 * radius / d - 1.0);
        [v.x, v.y, v.z]
    }));
    drop(norms);
    // the points and the viewpoint are finite (checked above), so are the
    // flipped points (|p'| < 2R); scaled by a power of two (exact) so that
    // the orientation predicates' products cannot overflow
    let max_abs = flipped.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
    if max_abs > 0.0 {
        let scale = 2f64.powi(-(max_abs.log2().ceil() as i32));
        flipped.iter_mut().for_each(|q| *q = q.map(|c| c * scale));
    }
    let n = points.len();
    let hull_error = |e: Error| Error::InvalidInput(format!("hidden point removal: {e}"));
    let mut visible: Vec<usize> = match hull_candidates(&flipped, min_filtered) {
        // the hull of the points not certainly inside (with the viewpoint,
        // last) has the same vertices as the hull of all
        Some(keep) => {
            let mut sub: Vec<[f64; 3]> = keep.iter().map(|&i| flipped[i as usize]).collect();
            drop(flipped);
            sub.push([0.0; 3]);
            let hull = hull_of_coordinates(sub).map_err(hull_error)?;
            hull.vertices
                .into_iter()
                .filter(|&i| i < keep.len())
                .map(|i| keep[i] as usize)
                .collect()
        }
        None => {
            flipped.push([0.0; 3]);
            let hull = hull_of_coordinates(flipped).map_err(hull_error)?;
            hull.vertices.into_iter().filter(|&i| i < n).collect()
        }
    };
    // the hull keeps one of several identical points: the others are visible too
    let key = |p: &Point3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let seen: HashSet<[u64; 3]> = visible.iter().map(|&i| key(&points[i])).collect();
    let mut is_visible = vec![false; n];
    for &i in &visible {
        is_visible[i] = true;
    }
    let before = visible.len();
    for (i, p) in points.iter().enumerate() {
        if !is_visible[i] && seen.contains(&key(p)) {
            visible.push(i);
        }
    }
    if visible.len() > before {
        visible.sort_unstable();
    }
    Ok(visible)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::testutil::Rng;

    fn sphere(n: usize, seed: u64) -> Vec<Point3> {
        let mut rng = Rng::new(seed);
        (0..n).map(|_| Point3::from(rng.unit_vector())).collect()
    }

    #[test]
    fn a_sphere_shows_its_near_cap() {
        let p = sphere(20_000, 1);
        let centre = Point3::origin();
        let eye = Point3::new(0.0, 0.0, 3.0);
        let vis = hidden_point_removal(&p, &eye, &HprConfig::default()).unwrap();
        assert!(vis.windows(2).all(|w| w[0] < w[1]));
        // every visible point faces the viewer: (p - c).(v - c) > 0
        for &i in &vis {
            assert!(
                (p[i] - centre).dot(&(eye - centre)) > 0.0,
                "point {i} {}",
                p[i]
            );
        }
        // geometrically visible: the cap z > 1/3 (tangent cone from distance 3)
        let cap: Vec<usize> = (0..p.len()).filter(|&i| p[i].z > 1.0 / 3.0).collect();
        let inner: Vec<usize> = (0..p.len()).filter(|&i| p[i].z > 0.5).collect();
        let is_vis = {
            let mut v = vec![false; p.len()];
            vis.iter().for_each(|&i| v[i] = true);
            v
        };
        let frac =
            |set: &[usize]| set.iter().filter(|&&i| is_vis[i]).count() as f64 / set.len() as f64;
        let (f_cap, f_inner) = (frac(&cap), frac(&inner));
        assert!(f_inner > 0.99, "inner cap visible: {f_inner}");
        assert!(f_cap > 0.95, "cap visible: {f_cap}");
        // nothing beyond the tangent circle (with a sampling margin)
        assert!(vis.iter().all(|&i| p[i].z > 0.25));
        // the far hemisphere is hidden entirely; a smaller gamma sees less
        let small = hidden_point_removal(&p, &eye, &HprConfig { gamma: 0.5 }).unwrap();
        assert!(small.len() < vis.len());
        // the trade-off of R: too large a radius makes the hull facets between
        // sparse neighbours bulge past the hidden points behind them
        // (bulge ~ R * spacing^2 / 4): with gamma = 8 the far side shows
        assert!(small.iter().all(|&i| p[i].z > 0.25));
        let huge = hidden_point_removal(&p, &eye, &HprConfig { gamma: 8.0 }).unwrap();
        assert!(huge.len() > 19_000, "{}", huge.len());
    }

    #[test]
    fn a_box_shows_the_faces_turned_to_the_viewer() {
        // surface samples of [0,2]x[0,1]x[0,1]
        let mut p = Vec::new();
        let m = 40;
        for i in 0..=m {
            for j in 0..=m {
                let (s, t) = (i as f64 / m as f64, j as f64 / m as f64);
                p.push(Point3::new(2.0 * s, t, 0.0));
                p.push(Point3::new(2.0 * s, t, 1.0));
                p.push(Point3::new(2.0 * s, 0.0, t));
                p.push(Point3::new(2.0 * s, 1.0, t));
                p.push(Point3::new(0.0, s, t));
                p.push(Point3::new(2.0, s, t));
            }
        }
        // from above the top face's centre: only the top face (z = 1) is seen
        let eye = Point3::new(1.0, 0.5, 5.0);
        let vis = hidden_point_removal(&p, &eye, &HprConfig::default()).unwrap();
        assert!(
            vis.iter().all(|&i| p[i].z > 0.999),
            "a side or bottom point is visible"
        );
        let top = p.iter().filter(|q| q.z == 1.0).count();
        let top_vis = vis.iter().filter(|&&i| p[i].z == 1.0).count();
        assert!(top_vis as f64 > 0.99 * top as f64, "{top_vis} of {top}");
        // from a corner direction: the three faces x = 2, y = 1, z = 1
        let eye = Point3::new(6.0, 5.0, 5.0);
        let vis = hidden_point_removal(&p, &eye, &HprConfig::default()).unwrap();
        let on_front = |q: &Point3| q.x == 2.0 || q.y == 1.0 || q.z == 1.0;
        assert!(vis.iter().all(|&i| on_front(&p[i])));
        let front = p.iter().filter(|q| on_front(q)).count();
        assert!(
            vis.len() as f64 > 0.95 * front as f64,
            "{} of {front}",
            vis.len()
        );
    }

    #[test]
    fn points_behind_a_nearer_sheet_are_removed() {
        let mut p = Vec::new();
        let mut rng = Rng::new(4);
        // near sheet [-1,1]^2 at z = 0, far sheet [-3,3]^2 at z = -1
        for _ in 0..4000 {
            p.push(Point3::new(
                2.0 * rng.uniform() - 1.0,
                2.0 * rng.uniform() - 1.0,
                0.0,
            ));
        }
        for _ in 0..8000 {
            p.push(Point3::new(
                6.0 * rng.uniform() - 3.0,
                6.0 * rng.uniform() - 3.0,
                -1.0,
            ));
        }
        let eye = Point3::new(0.0, 0.0, 5.0);
        let vis = hidden_point_removal(&p, &eye, &HprConfig::default()).unwrap();
        let mut is_vis = vec![false; p.len()];
        vis.iter().for_each(|&i| is_vis[i] = true);
        // the near sheet's shadow on the far sheet is |x|,|y| < 1.2
        let shadowed = |q: &Point3| q.z < 0.0 && q.x.abs() < 1.1 && q.y.abs() < 1.1;
        let exposed = |q: &Point3| q.z < 0.0 && (q.x.abs() > 1.5 || q.y.abs() > 1.5);
        let n_shadow_vis = (0..p.len())
            .filter(|&i| shadowed(&p[i]) && is_vis[i])
            .count();
        assert_eq!(n_shadow_vis, 0);
        let near_vis = (0..4000).filter(|&i| is_vis[i]).count();
        assert!(near_vis > 3900, "{near_vis} of 4000 near points visible");
        let exp: Vec<usize> = (0..p.len()).filter(|&i| exposed(&p[i])).collect();
        let exp_vis = exp.iter().filter(|&&i| is_vis[i]).count();
        assert!(
            exp_vis as f64 > 0.95 * exp.len() as f64,
            "{exp_vis} of {}",
            exp.len()
        );
    }

    /// A bumpy, noisy closed surface: `r(d) = 1 + 0.15 sin(5x) cos(4y) + 0.1 z^2`.
    fn bumpy_blob(n: usize, seed: u64) -> Vec<Point3> {
        let mut rng = Rng::new(seed);
        (0..n)
            .map(|_| {
                let d = rng.unit_vector();
                let r = 1.0 + 0.15 * (5.0 * d.x).sin() * (4.0 * d.y).cos() + 0.1 * d.z * d.z;
                Point3::from(d * (r + 2e-3 * (rng.uniform() - 0.5)))
            })
            .collect()
    }

    #[test]
    fn the_interior_filter_keeps_the_visible_set_exactly() {
        // the filtered hull against the plain hull of all flipped points
        let clouds = [sphere(30_000, 21), bumpy_blob(40_000, 22)];
        let eyes = [
            Point3::new(0.0, 0.0, 3.0),
            Point3::new(2.5, -1.0, 0.7),
            Point3::new(0.3, 4.0, -6.0),
            Point3::new(0.0, 1.3, 0.0),
            // inside the cloud: the directions fill the sphere, no filter
            Point3::new(0.1, 0.0, 0.05),
        ];
        for (c, p) in clouds.iter().enumerate() {
            for eye in &eyes {
                for gamma in [0.5, 2.0, 4.0] {
                    let cfg = HprConfig { gamma };
                    let plain = hpr_filtered_above(p, eye, &cfg, usize::MAX).unwrap();
                    let filtered = hpr_filtered_above(p, eye, &cfg, 0).unwrap();
                    assert_eq!(plain, filtered, "cloud {c}, eye {eye}, gamma {gamma}");
                }
            }
        }
        // the box's face grids (many coplanar and collinear points before flipping)
        let mut p = Vec::new();
        for i in 0..=120 {
            for j in 0..=120 {
                let (s, t) = (i as f64 / 120.0, j as f64 / 120.0);
                p.push(Point3::new(2.0 * s, t, 0.0));
                p.push(Point3::new(2.0 * s, t, 1.0));
                p.push(Point3::new(2.0 * s, 0.0, t));
                p.push(Point3::new(0.0, s, t));
            }
        }
        for eye in [Point3::new(1.0, 0.5, 5.0), Point3::new(6.0, 5.0, 5.0)] {
            let cfg = HprConfig::default();
            let plain = hpr_filtered_above(&p, &eye, &cfg, usize::MAX).unwrap();
            let filtered = hpr_filtered_above(&p, &eye, &cfg, 0).unwrap();
            assert_eq!(plain, filtered, "box grid, eye {eye}");
        }
    }

    #[test]
    fn duplicates_and_bad_input() {
        let mut p = sphere(500, 2);
        let front = (0..500).find(|&i| p[i].z > 0.8).unwrap();
        p.push(p[front]);
        let eye = Point3::new(0.0, 0.0, 3.0);
        let vis = hidden_point_removal(&p, &eye, &HprConfig::default()).unwrap();
        assert!(vis.contains(&front) && vis.contains(&500));
        // a point at the viewpoint
        let err = hidden_point_removal(&p, &p[7], &HprConfig::default()).unwrap_err();
        assert!(format!("{err}").contains("point 7 coincides"), "{err}");
        assert!(matches!(
            hidden_point_removal(&p[..3], &eye, &HprConfig::default()),
            Err(Error::TooFewPoints { got: 3, .. })
        ));
        for gamma in [0.0, -1.0, f64::NAN, 13.0] {
            assert!(hidden_point_removal(&p, &eye, &HprConfig { gamma }).is_err());
        }
        assert!(
            hidden_point_removal(&p, &Point3::new(f64::NAN, 0., 0.), &HprConfig::default())
                .is_err()
        );
        // all points and the viewpoint on one plane
        let flat: Vec<Point3> = (0..20)
            .map(|i| Point3::new(i as f64, (i * i % 7) as f64, 0.0))
            .collect();
        let err = hidden_point_removal(&flat, &Point3::new(-5.0, 1.0, 0.0), &HprConfig::default())
            .unwrap_err();
        assert!(format!("{err}").contains("coplanar"), "{err}");
    }
}
