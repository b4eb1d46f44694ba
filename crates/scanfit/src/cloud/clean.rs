//! Cleaning a scan before fitting: which points to keep.
//!
//! * [`statistical_outliers`]: PCL's statistical outlier removal (Rusu et
//!   al. 2008, "Towards 3D point cloud based object maps for household
//!   environments", section 4): the mean distance `d_i` of each point to its
//!   `k` nearest neighbours; a point is an outlier when `d_i > mean(d) +
//!   n_sigma * std(d)` (and, departures stated at [`OutlierConfig`], when
//!   `d_i` is also large against the median of all `d` and against its own
//!   neighbours' `d_j`, so that sparsely sampled parts of an unevenly
//!   sampled scan stay).
//! * [`small_fragments`]: connected components of the radius graph (points
//!   closer than `radius` are joined); components with fewer than
//!   `min_size` points are stray fragments.
//! * [`inside_box`], [`inside_sphere`]: crops.
//! * [`voxel_thinning`]: one point per cell of a regular grid (the point
//!   nearest the centroid of the cell's points, so every attribute is an
//!   original value, never an average).
//!
//! Each returns a keep-mask or the kept indices, for
//! [`PointCloud::select`](super::PointCloud::select), which keeps all
//! attributes.

use std::collections::HashMap;

use rayon::prelude::*;

use super::PointCloud;
use crate::{Error, Point3, Result, Vector3};

/// Settings of [`statistical_outliers`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutlierConfig {
    /// Neighbours whose mean distance is measured (default 50, PCL's
    /// tutorial value `setMeanK (50)`).
    pub k: usize,
    /// Outliers lie farther than `mean + n_sigma * std` (default 1.0,
    /// PCL's tutorial value `setStddevMulThresh (1.0)`).
    pub n_sigma: f64,
    /// ... and farther than `min_ratio` times the median of the mean
    /// distances (default 2.0). Departure from PCL: on a clean, evenly
    /// sampled sheet the spread of the mean distances is tiny, so PCL's
    /// threshold falls just above the interior and removes the whole
    /// boundary ring (whose neighbours lie on one side: 788 of 10,000 points
    /// of the test sheet at 1 sigma, 405 at 3 sigma); a stray point's mean
    /// distance is many times the median. 0 gives PCL's rule.
    pub min_ratio: f64,
    /// ... and farther than `local_ratio` times the median of its kept
    /// neighbours' mean distances, the kept set growing outward from the
    /// points within the first two bounds (default 2.0). Departure from PCL: on a
    /// scan whose density varies (dense where the scanner looked straight
    /// on, sparse at grazing angles), the global threshold falls between
    /// the dense and the sparse parts and removes the sparse ones whole
    /// (814 of the 6000 points of `examples/data/nasty_face.xyz`, whose
    /// density falls tenfold towards the outline, where it has 30 strays);
    /// a stray point's neighbours lie on the surface and their distances are
    /// a fraction of its own, while a point of a sparse part has neighbours
    /// as sparse as itself. 0 leaves the test out.
    pub local_ratio: f64,
}

impl Default for OutlierConfig {
    fn default() -> Self {
        Self {
            k: 50,
            n_sigma: 1.0,
            min_ratio: 2.0,
            local_ratio: 2.0,
        }
    }
}

/// What [`statistical_outliers`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Outliers {
    /// `true` for the points kept.
    pub keep: Vec<bool>,
    /// Mean over the points of their mean neighbour distance.
    pub mean: f64,
    /// Standard deviation of the mean neighbour distances.
    pub std: f64,
    /// The threshold `max(mean + n_sigma * std, min_ratio * median)`.
    pub threshold: f64,
    /// Points beyond `threshold` kept because their distance is below
    /// `local_ratio` times their kept neighbours' median.
    pub kept_local: usize,
}

/// Statistical outlier removal (see the module documentation).
///
/// Errors: `k = 0`, a negative or non-finite `n_sigma`, `min_ratio` or
/// `local_ratio`, fewer than 2 points.
///
/// ```
/// use scanfit::cloud::clean::{statistical_outliers, OutlierConfig};
/// use scanfit::{Point3, PointCloud};
///
/// // a 20 x 20 grid and one point far above it
/// let mut p: Vec<Point3> = (0..400)
///     .map(|i| Point3::new((i % 20) as f64, (i / 20) as f64, 0.0))
///     .collect();
/// p.push(Point3::new(10.0, 10.0, 50.0));
/// let r = statistical_outliers(&PointCloud::new(p)?, &OutlierConfig::default())?;
/// assert_eq!(r.keep.iter().filter(|k| !**k).count(), 1);
/// assert!(!r.keep[400]);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn statistical_outliers(cloud: &PointCloud, config: &OutlierConfig) -> Result<Outliers> {
    if !(config.n_sigma.is_finite() && config.n_sigma >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "outlier threshold {} standard deviations must be finite and >= 0 (1 is PCL's default)",
            config.n_sigma
        )));
    }
    if !(config.min_ratio.is_finite() && config.min_ratio >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "outlier ratio {} to the median distance must be finite and >= 0 (2 is the default)",
            config.min_ratio
        )));
    }
    if !(config.local_ratio.is_finite() && config.local_ratio >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "outlier ratio {} to the neighbours' distances must be finite and >= 0 (2 is the default)",
            config.local_ratio
        )));
    }
    let graph = cloud.knn_graph(config.k)?;
    let d: Vec<f64> = (0..cloud.len())
        .into_par_iter()
        .map(|i| {
            let row = graph.distances_of(i);
            row.iter().sum::<f64>() / row.len().max(1) as f64
        })
        .collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0).max(1.0);
    let std = var.sqrt();
    let mut sorted = d.clone();
    let mid = sorted.len() / 2;
    let (_, &mut median, _) = sorted.select_nth_unstable_by(mid, f64::total_cmp);
    let threshold = (mean + config.n_sigma * std).max(config.min_ratio * median);
    let mut keep: Vec<bool> = d.iter().map(|&x| x <= threshold).collect();
    if config.local_ratio > 0.0 {
        grow_sparse(&graph, &d, config.local_ratio, &mut keep);
    }
    let kept_local = (0..d.len())
        .filter(|&i| keep[i] && d[i] > threshold)
        .count();
    Ok(Outliers {
        keep,
        mean,
        std,
        threshold,
        kept_local,
    })
}

/// Takes back the points beyond the global bound that continue the kept
/// ones at a sparser density: in passes (each judged on the previous pass's
/// kept set, so the result does not depend on the order or the threads), a
/// point joins when some of its neighbours are kept and its mean distance
/// is at most `ratio` times their median. The kept set grows outward
/// through a part whose density falls gradually; a stray point (or a cloud
/// of strays), whose kept neighbours lie on the surface far closer together
/// than it lies to them, never joins.
fn grow_sparse(
    graph: &super::neighbours::Neighbourhoods,
    d: &[f64],
    ratio: f64,
    keep: &mut [bool],
) {
    loop {
        let join: Vec<usize> = (0..d.len())
            .into_par_iter()
            .filter(|&i| {
                if keep[i] {
                    return false;
                }
                let mut near: Vec<f64> = graph
                    .indices_of(i)
                    .iter()
                    .filter(|&&j| keep[j as usize])
                    .map(|&j| d[j as usize])
                    .collect();
                if near.is_empty() {
                    return false;
                }
                let mid = near.len() / 2;
                let local = *near.select_nth_unstable_by(mid, f64::total_cmp).1;
                d[i] <= ratio * local
            })
            .collect();
        if join.is_empty() {
            return;
        }
        for i in join {
            keep[i] = true;
        }
    }
}

/// What [`small_fragments`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Fragments {
    /// `true` for the points kept (in a component of at least `min_size`).
    pub keep: Vec<bool>,
    /// Number of connected components.
    pub components: usize,
    /// Number of components removed (fewer than `min_size` points).
    pub removed_components: usize,
}

/// Connected components of the graph joining points closer than `radius`
/// (inclusive); the points of components with fewer than `min_size` points
/// are marked for removal.
///
/// Errors: a non-positive or non-finite radius.
///
/// ```
/// use scanfit::cloud::clean::small_fragments;
/// use scanfit::{Point3, PointCloud};
///
/// // a row of 10 points 1 apart, and a pair 100 away
/// let mut p: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
/// p.push(Point3::new(100.0, 0.0, 0.0));
/// p.push(Point3::new(101.0, 0.0, 0.0));
/// let r = small_fragments(&PointCloud::new(p)?, 1.5, 3)?;
/// assert_eq!((r.components, r.removed_components), (2, 1));
/// assert_eq!(r.keep.iter().filter(|k| **k).count(), 10);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn small_fragments(cloud: &PointCloud, radius: f64, min_size: usize) -> Result<Fragments> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::InvalidInput(format!(
            "fragment radius {radius} must be finite and > 0"
        )));
    }
    let tree = cloud.tree()?;
    let points = cloud.points();
    let near: Vec<Vec<u32>> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            tree.within(p, radius)
                .into_iter()
                .filter(|n| n.index > i)
                .map(|n| n.index as u32)
                .collect()
        })
        .collect();
    let mut uf = UnionFind::new(points.len());
    for (i, row) in near.iter().enumerate() {
        for &j in row {
            uf.union(i, j as usize);
        }
    }
    drop(near);
    let roots: Vec<usize> = (0..points.len()).map(|i| uf.find(i)).collect();
    let mut size: HashMap<usize, usize> = HashMap::new();
    for &r in &roots {
        *size.entry(r).or_insert(0) += 1;
    }
    let removed_components = size.values().filter(|&&s| s < min_size).count();
    Ok(Fragments {
        keep: roots.iter().map(|r| size[r] >= min_size).collect(),
        components: size.len(),
        removed_components,
    })
}

/// Disjoint sets with path halving and union by size.
struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}

/// `true` for the points inside the axis-aligned box `[lo, hi]` (inclusive).
pub fn inside_box(cloud: &PointCloud, lo: &Point3, hi: &Point3) -> Vec<bool> {
    cloud
        .points()
        .iter()
        .map(|p| (0..3).all(|c| p[c] >= lo[c] && p[c] <= hi[c]))
        .collect()
}

/// `true` for the points inside the ball of `centre` and `radius` (inclusive).
pub fn inside_sphere(cloud: &PointCloud, centre: &Point3, radius: f64) -> Vec<bool> {
    cloud
        .points()
        .iter()
        .map(|p| (p - centre).norm() <= radius)
        .collect()
}

/// One point per occupied cell of the grid of cubes of edge `size` whose
/// corner is the cloud's bounding-box minimum: in each cell the point
/// nearest the centroid of the cell's points (the lowest index on a tie).
/// Returns the kept indices in increasing order.
///
/// Errors: a non-positive or non-finite size, or one so small that a cell
/// index would overflow (more than 2^62 cells along an axis).
///
/// ```
/// use scanfit::cloud::clean::voxel_thinning;
/// use scanfit::{Point3, PointCloud};
///
/// // a 10 x 10 grid of spacing 1 in cells of 2.5: 4 x 4 cells
/// let p = (0..100).map(|i| Point3::new((i % 10) as f64, (i / 10) as f64, 0.0)).collect();
/// assert_eq!(voxel_thinning(&PointCloud::new(p)?, 2.5)?.len(), 16);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn voxel_thinning(cloud: &PointCloud, size: f64) -> Result<Vec<usize>> {
    if !(size.is_finite() && size > 0.0) {
        return Err(Error::InvalidInput(format!(
            "voxel size {size} must be finite and > 0"
        )));
    }
    let Some((lo, hi)) = cloud.bounding_box() else {
        return Ok(Vec::new());
    };
    if ((hi - lo).max() / size) >= (1u64 << 62) as f64 {
        return Err(Error::InvalidInput(format!(
            "voxel size {size} is too small for data {} across (more than 2^62 cells along an axis); give a larger size",
            (hi - lo).max()
        )));
    }
    let cell =
        |p: &Point3| -> [i64; 3] { [0, 1, 2].map(|c| ((p[c] - lo[c]) / size).floor() as i64) };
    let mut cells: HashMap<[i64; 3], (Vector3, usize, Vec<usize>)> = HashMap::new();
    for (i, p) in cloud.points().iter().enumerate() {
        let e = cells
            .entry(cell(p))
            .or_insert_with(|| (Vector3::zeros(), 0, Vec::new()));
        e.0 += p - lo;
        e.1 += 1;
        e.2.push(i);
    }
    let points = cloud.points();
    let mut kept: Vec<usize> = cells
        .into_values()
        .map(|(sum, n, members)| {
            let c = sum / n as f64;
            members
                .into_iter()
                .min_by(|&a, &b| {
                    ((points[a] - lo) - c)
                        .norm_squared()
                        .total_cmp(&((points[b] - lo) - c).norm_squared())
                        .then(a.cmp(&b))
                })
                .unwrap_or(0)
        })
        .collect();
    kept.sort_unstable();
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy sheet z = 0.1 sin(3x) cos(2y) on a jittered 100 x 100 grid
    /// over [0, 1]^2 (spacing 0.01), and `strays` points scattered in the
    /// box [0, 1]^2 x [0.15, 0.6] (at least 0.05 = 5 spacings off the sheet).
    pub(crate) fn sheet_with_strays(strays: usize) -> Vec<Point3> {
        let mut s = 12345u64;
        let mut rnd = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut p = Vec::new();
        for i in 0..100 {
            for j in 0..100 {
                let x = (i as f64 + 0.3 * (rnd() - 0.5)) / 99.0;
                let y = (j as f64 + 0.3 * (rnd() - 0.5)) / 99.0;
                p.push(Point3::new(x, y, 0.1 * (3.0 * x).sin() * (2.0 * y).cos()));
            }
        }
        for _ in 0..strays {
            p.push(Point3::new(rnd(), rnd(), 0.15 + 0.45 * rnd()));
        }
        p
    }

    #[test]
    fn outlier_removal_takes_the_strays_and_no_surface_point() {
        let removed = |p: Vec<Point3>, cfg: OutlierConfig| -> Vec<usize> {
            let c = PointCloud::new(p).unwrap();
            let r = statistical_outliers(&c, &cfg).unwrap();
            (0..c.len()).filter(|&i| !r.keep[i]).collect()
        };
        let pcl = OutlierConfig {
            min_ratio: 0.0,
            local_ratio: 0.0,
            ..OutlierConfig::default()
        };
        // 107 strays: exactly they go, with or without the ratio floor
        for cfg in [OutlierConfig::default(), pcl] {
            let r = removed(sheet_with_strays(107), cfg);
            assert_eq!(r.len(), 107);
            assert!(r.iter().all(|&i| i >= 10_000));
        }
        // a clean sheet: PCL's rule takes its boundary ring, the floor nothing
        assert_eq!(removed(sheet_with_strays(0), pcl).len(), 788);
        assert_eq!(
            removed(sheet_with_strays(0), OutlierConfig::default()).len(),
            0
        );
        let c = PointCloud::new(sheet_with_strays(0)).unwrap();
        let bad = OutlierConfig {
            k: 0,
            ..OutlierConfig::default()
        };
        assert!(statistical_outliers(&c, &bad).is_err());
        let bad = OutlierConfig {
            n_sigma: f64::NAN,
            ..OutlierConfig::default()
        };
        assert!(statistical_outliers(&c, &bad).is_err());
    }

    #[test]
    fn sparse_parts_of_an_uneven_scan_stay_and_only_strays_go() {
        // the sheet thinned as a scan thins towards grazing angles: the
        // density falls tenfold from x = 1 to x = 0 (a point is kept with
        // probability 0.1 + 0.9 x, by a fixed hash of its index), plus 40
        // strays 0.15-0.6 above it (5-60 spacings)
        let all = sheet_with_strays(40);
        let hash = |i: usize| {
            ((i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 11) as f64 / (1u64 << 53) as f64
        };
        let p: Vec<Point3> = all
            .iter()
            .enumerate()
            .filter(|&(i, q)| i >= 10_000 || hash(i) < 0.1 + 0.9 * q.x)
            .map(|(_, q)| *q)
            .collect();
        let sheet = p.len() - 40;
        let c = PointCloud::new(p).unwrap();
        let removed = |cfg: OutlierConfig| -> Vec<usize> {
            let r = statistical_outliers(&c, &cfg).unwrap();
            (0..c.len()).filter(|&i| !r.keep[i]).collect()
        };
        let global = OutlierConfig {
            local_ratio: 0.0,
            ..OutlierConfig::default()
        };
        // the global bounds take the sparsest strip
        let g = removed(global);
        assert!(g.len() > 150, "{}", g.len());
        // the neighbour-relative bound takes exactly the strays
        let r = removed(OutlierConfig::default());
        assert_eq!(r, (sheet..sheet + 40).collect::<Vec<_>>());
        let bad = OutlierConfig {
            local_ratio: -1.0,
            ..OutlierConfig::default()
        };
        assert!(statistical_outliers(&c, &bad).is_err());
    }

    #[test]
    fn fragments_and_crops_and_voxels_count_exactly() {
        let mut p = sheet_with_strays(0);
        // two clumps of 5 points 0.002 apart, far from the sheet
        for k in 0..5 {
            p.push(Point3::new(3.0 + 0.002 * k as f64, 0.0, 0.0));
            p.push(Point3::new(0.0, 3.0, 0.002 * k as f64));
        }
        let c = PointCloud::new(p).unwrap();
        let r = small_fragments(&c, 0.03, 100).unwrap();
        assert_eq!((r.components, r.removed_components), (3, 2));
        assert_eq!(r.keep.iter().filter(|k| !**k).count(), 10);
        assert!(r.keep[..10_000].iter().all(|&k| k));
        let b = inside_box(
            &c,
            &Point3::new(2.0, -1.0, -1.0),
            &Point3::new(4.0, 1.0, 1.0),
        );
        assert_eq!(b.iter().filter(|k| **k).count(), 5);
        let s = inside_sphere(&c, &Point3::new(0.0, 3.0, 0.004), 0.0041);
        assert_eq!(s.iter().filter(|k| **k).count(), 5);
        // a 30 x 20 x 3 lattice of spacing 1 in cells of 2: 15 x 10 x 2
        let g: Vec<Point3> = (0..1800)
            .map(|i| Point3::new((i % 30) as f64, ((i / 30) % 20) as f64, (i / 600) as f64))
            .collect();
        let g = PointCloud::new(g).unwrap();
        let kept = voxel_thinning(&g, 2.0).unwrap();
        assert_eq!(kept.len(), 300);
        // each cell's 2 x 2 x 2 (or 2 x 2 x 1) points are equally near the centroid: the first
        assert_eq!(&kept[..3], &[0, 2, 4]);
        assert!(voxel_thinning(&g, 0.0).is_err());
        assert!(voxel_thinning(&g, 1e-300).is_err());
        assert!(small_fragments(&g, -1.0, 3).is_err());
    }
}
