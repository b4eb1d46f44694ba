//! Neighbour queries on a [`PointCloud`]: k-nearest and radius search over
//! the library's one KD-tree ([`crate::spatial::KdTree`]), one query at a
//! time or batched in parallel (rayon).
//!
//! Distances returned are Euclidean (not squared). Results are sorted by
//! distance, nearest first; ties keep the tree's order.

use std::num::NonZeroUsize;

use rayon::prelude::*;

use super::PointCloud;
pub use crate::spatial::Neighbour;
use crate::spatial::{fill_rows_in_order, morton_order, KdTree};
use crate::{Error, Point3, Result};

/// The k nearest neighbours of many points, stored flat: row `i` holds the
/// neighbours of point (or query) `i`, nearest first.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbourhoods {
    /// Neighbours per row (`k`, or fewer when the cloud is smaller).
    pub k: usize,
    /// `k` indices per row.
    pub indices: Vec<u32>,
    /// `k` distances per row (empty for a graph built without them,
    /// [`PointCloud::knn_graph_indices`]).
    pub distances: Vec<f64>,
}

impl Neighbourhoods {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.indices.len().checked_div(self.k).unwrap_or(0)
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Indices of row `i`.
    pub fn indices_of(&self, i: usize) -> &[u32] {
        &self.indices[i * self.k..(i + 1) * self.k]
    }

    /// Distances of row `i` (empty for a graph built without them).
    pub fn distances_of(&self, i: usize) -> &[f64] {
        self.distances
            .get(i * self.k..(i + 1) * self.k)
            .unwrap_or(&[])
    }
}

impl PointCloud {
    /// The KD-tree over the points, built on first use (an error for an
    /// empty cloud or more than 2^32 points).
    ///
    /// ```
    /// use scanfit::{Point3, PointCloud};
    /// let cloud = PointCloud::new(vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)]).unwrap();
    /// assert_eq!(cloud.tree().unwrap().len(), 2);
    /// ```
    pub fn tree(&self) -> Result<&KdTree> {
        if self.points.is_empty() {
            return Err(Error::InvalidInput(
                "the point cloud is empty; neighbour queries need at least one point".into(),
            ));
        }
        if self.points.len() > u32::MAX as usize {
            return Err(Error::InvalidInput(format!(
                "{} points exceed the KD-tree's limit of 2^32; split the cloud",
                self.points.len()
            )));
        }
        if let Some(t) = self.tree.get() {
            return Ok(t);
        }
        let tree = KdTree::new(&self.points, "the cloud's points")?;
        Ok(self.tree.get_or_init(|| tree))
    }

    /// The nearest point to `query`.
    pub fn nearest(&self, query: &Point3) -> Result<Neighbour> {
        check_query(query, "the query point")?;
        self.nearest_batch(std::slice::from_ref(query))?
            .pop()
            .ok_or_else(|| Error::InvalidInput("no nearest point found".into()))
    }

    /// The nearest point of each of `queries`, in parallel.
    pub fn nearest_batch(&self, queries: &[Point3]) -> Result<Vec<Neighbour>> {
        for (i, q) in queries.iter().enumerate() {
            check_query(q, &format!("query point {i}"))?;
        }
        let tree = self.tree()?;
        Ok(queries.par_iter().map(|q| tree.nearest(q)).collect())
    }

    /// The `k` nearest points to `query` (fewer if the cloud is smaller),
    /// nearest first.
    pub fn knn(&self, query: &Point3, k: usize) -> Result<Vec<Neighbour>> {
        let k = checked_k(k)?;
        check_query(query, "the query point")?;
        Ok(self.tree()?.nearest_n(query, k))
    }

    /// All points within distance `radius` of `query` (inclusive), nearest first.
    pub fn within(&self, query: &Point3, radius: f64) -> Result<Vec<Neighbour>> {
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(Error::InvalidInput(format!(
                "search radius {radius} must be finite and >= 0"
            )));
        }
        check_query(query, "the query point")?;
        Ok(self.tree()?.within(query, radius))
    }

    /// The `k` nearest points of each of `queries`, in parallel (the
    /// queries are visited along a Morton curve for cache locality; each
    /// row is what [`PointCloud::knn`] gives).
    pub fn knn_batch(&self, queries: &[Point3], k: usize) -> Result<Neighbourhoods> {
        let kq = checked_k(k)?;
        for (i, q) in queries.iter().enumerate() {
            check_query(q, &format!("query point {i}"))?;
        }
        let tree = self.tree()?;
        let k = kq.get().min(self.points.len());
        let order = morton_order(queries);
        Ok(rows(tree, queries, &order, kq, k))
    }

    /// The neighbour count of a graph: `k` checked, and at most the number
    /// of other points.
    fn graph_k(&self, k: usize) -> Result<usize> {
        if self.points.len() < 2 {
            return Err(Error::TooFewPoints {
                got: self.points.len(),
                needed: 2,
                what: "a neighbour graph".into(),
            });
        }
        Ok(checked_k(k)?.get().min(self.points.len() - 1))
    }

    /// The `k` nearest *other* points of every point of the cloud (the point
    /// itself excluded), in parallel: the neighbour graph that normals,
    /// spacing statistics and orientation use.
    pub fn knn_graph(&self, k: usize) -> Result<Neighbourhoods> {
        let k = self.graph_k(k)?;
        let (indices, distances) = self.tree()?.graph_rows(k);
        Ok(Neighbourhoods {
            k,
            indices,
            distances,
        })
    }

    /// [`PointCloud::knn_graph`] without the distances (`distances` empty):
    /// the same rows in a third of the memory, for the normals, which need
    /// only who the neighbours are.
    ///
    /// ```
    /// use scanfit::{Point3, PointCloud};
    /// let pts = (0..50).map(|i| Point3::new(i as f64, (i * i % 7) as f64, 0.0)).collect();
    /// let cloud = PointCloud::new(pts)?;
    /// let (g, h) = (cloud.knn_graph(6)?, cloud.knn_graph_indices(6)?);
    /// assert_eq!((g.indices, h.k, h.distances.len()), (h.indices, 6, 0));
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn knn_graph_indices(&self, k: usize) -> Result<Neighbourhoods> {
        let k = self.graph_k(k)?;
        Ok(Neighbourhoods {
            k,
            indices: self.tree()?.graph_indices(k),
            distances: Vec::new(),
        })
    }
}

/// The rows of `k` neighbours of `queries` (asking the tree for `kq`),
/// computed in `order`.
fn rows(
    tree: &KdTree,
    queries: &[Point3],
    order: &[u32],
    kq: NonZeroUsize,
    k: usize,
) -> Neighbourhoods {
    let mut indices = vec![0u32; queries.len() * k];
    let mut distances = vec![0.0; queries.len() * k];
    fill_rows_in_order(order, k, &mut indices, &mut distances, |i, idx, dist| {
        for (j, n) in tree
            .nearest_n(&queries[i], kq)
            .into_iter()
            .take(k)
            .enumerate()
        {
            idx[j] = n.index as u32;
            dist[j] = n.distance;
        }
    });
    Neighbourhoods {
        k,
        indices,
        distances,
    }
}

/// Nearest-neighbour distance statistics of a cloud: the sampling density
/// that automatic parameters (alpha-shape radius, search radii) scale with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spacing {
    /// Smallest distance from a point to its nearest other point (0 with duplicates).
    pub min: f64,
    /// Median nearest-neighbour distance.
    pub median: f64,
    /// Mean nearest-neighbour distance.
    pub mean: f64,
    /// Largest nearest-neighbour distance (an isolated outlier shows here).
    pub max: f64,
    /// Points that coincide with another point (among the measured ones).
    pub duplicates: usize,
    /// Points whose nearest neighbour was measured: all of them, or the
    /// sample of [`PointCloud::spacing_sample`].
    pub measured: usize,
}

impl PointCloud {
    /// Nearest-neighbour distance statistics of every point (needs at least
    /// 2 points).
    pub fn spacing(&self) -> Result<Spacing> {
        let g = self.knn_graph(1)?;
        Ok(Spacing::of(g.distances))
    }

    /// Nearest-neighbour distance statistics of a uniform random sample of
    /// `sample` points, each measured against the whole cloud: for big
    /// clouds, where measuring every point is the costly part. The sample
    /// is drawn by selection sampling (Knuth, TAOCP vol. 2, 3.4.2,
    /// Algorithm S: every `sample`-subset equally likely, indices in order)
    /// driven by SplitMix64 from `seed`, so it is the same on every run and
    /// machine. With no more points than `sample` every point is measured
    /// ([`PointCloud::spacing`]). `Spacing::measured` says how many were.
    ///
    /// ```
    /// use scanfit::{Point3, PointCloud};
    /// let pts: Vec<Point3> = (0..10_000).map(|k| Point3::new(k as f64, 0.0, 0.0)).collect();
    /// let cloud = PointCloud::new(pts)?;
    /// let s = cloud.spacing_sample(500, 7)?;
    /// assert_eq!(s.measured, 500);
    /// assert_eq!((s.min, s.median, s.max), (1.0, 1.0, 1.0));
    /// assert_eq!(s, cloud.spacing_sample(500, 7)?); // seeded: deterministic
    /// assert_eq!(cloud.spacing_sample(20_000, 7)?, cloud.spacing()?);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn spacing_sample(&self, sample: usize, seed: u64) -> Result<Spacing> {
        let n = self.points.len();
        if sample == 0 {
            return Err(Error::InvalidInput(
                "a spacing sample of 0 points; give at least 1".into(),
            ));
        }
        if n <= sample {
            return self.spacing();
        }
        let mut state = seed;
        let mut chosen = Vec::with_capacity(sample);
        for i in 0..n {
            // Algorithm S: take point i with probability (needed) / (left)
            let (needed, left) = ((sample - chosen.len()) as u64, (n - i) as u64);
            if needed == 0 {
                break;
            }
            if unit_draw(&mut state, left) < needed {
                chosen.push(i);
            }
        }
        let queries: Vec<Point3> = chosen.iter().map(|&i| self.points[i]).collect();
        let all = self.knn_batch(&queries, 2)?;
        let d = chosen
            .iter()
            .enumerate()
            .map(|(q, &i)| {
                let (row, drow) = (all.indices_of(q), all.distances_of(q));
                // the nearest other point: skip the point itself (or, among
                // duplicates, one copy of it) as `knn_graph` does
                let skip = row
                    .iter()
                    .position(|&j| j as usize == i)
                    .unwrap_or(row.len() - 1);
                drow[if skip == 0 { 1 } else { 0 }]
            })
            .collect();
        Ok(Spacing::of(d))
    }
}

/// A uniform draw from `0..bound` (`bound >= 1`) from the SplitMix64
/// stream in `state` (Lemire's multiply-shift; its bias, below
/// `bound / 2^64`, is far below anything a spacing statistic can show).
fn unit_draw(state: &mut u64, bound: u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    ((u128::from(z) * u128::from(bound)) >> 64) as u64
}

impl Spacing {
    /// The statistics of nearest-neighbour distances.
    fn of(mut d: Vec<f64>) -> Self {
        let duplicates = d.iter().filter(|&&x| x == 0.0).count();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let mid = d.len() / 2;
        let (lo, &mut median, hi) = d.select_nth_unstable_by(mid, f64::total_cmp);
        let min = lo.iter().copied().fold(median, f64::min);
        let max = hi.iter().copied().fold(median, f64::max);
        Spacing {
            min,
            median,
            mean,
            max,
            duplicates,
            measured: d.len(),
        }
    }
}

fn checked_k(k: usize) -> Result<NonZeroUsize> {
    NonZeroUsize::new(k)
        .ok_or_else(|| Error::InvalidInput("k = 0 neighbours asked for; give k >= 1".into()))
}

/// Rejects a query point with a NaN or infinite coordinate (the tree would
/// return fewer neighbours than asked for, or none).
fn check_query(query: &Point3, which: &str) -> Result<()> {
    if query.coords.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "{which} ({}, {}, {}) has a non-finite coordinate; neighbour queries need finite points",
            query.x, query.y, query.z
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vector3;

    /// Issue 14: `cloud info` measures the spacing of more than 10^6 points
    /// on a sample of 10^6. On 2 x 10^6 scattered points (uniform in a
    /// 1 x 1 x 0.01 slab, so distances vary over two orders of magnitude)
    /// the sampled median and mean agree with the full computation within
    /// 1 %, the duplicate share within 1 % of the points, and the sampled
    /// extremes lie inside the full ones.
    #[test]
    fn a_sample_of_a_million_gives_the_spacing_of_two_million() {
        let mut state = 12345u64;
        let pts: Vec<Point3> = (0..2_000_000)
            .map(|_| {
                let mut r = || unit_draw(&mut state, 1 << 40) as f64 / (1u64 << 40) as f64;
                Point3::new(r(), r(), 0.01 * r())
            })
            .collect();
        let cloud = PointCloud::new(pts).unwrap();
        let full = cloud.spacing().unwrap();
        let part = cloud.spacing_sample(1_000_000, 1).unwrap();
        assert_eq!((full.measured, part.measured), (2_000_000, 1_000_000));
        for (a, b) in [(full.median, part.median), (full.mean, part.mean)] {
            assert!((a - b).abs() <= 0.01 * a, "{full:?} vs {part:?}");
        }
        assert!(part.min >= full.min && part.max <= full.max);
        let share = |s: &Spacing| s.duplicates as f64 / s.measured as f64;
        assert!((share(&full) - share(&part)).abs() <= 0.01);
        // another seed, another sample, the same statistics to 1 %
        let other = cloud.spacing_sample(1_000_000, 2).unwrap();
        assert_ne!(other, part);
        assert!((other.median - part.median).abs() <= 0.01 * part.median);
    }

    fn grid(n: usize) -> PointCloud {
        let mut p = Vec::new();
        for i in 0..n {
            for j in 0..n {
                p.push(Point3::new(i as f64, j as f64, 0.0));
            }
        }
        PointCloud::new(p).unwrap()
    }

    fn brute(cloud: &PointCloud, q: &Point3, k: usize) -> Vec<f64> {
        let mut d: Vec<f64> = cloud.points().iter().map(|p| (p - q).norm()).collect();
        d.sort_by(f64::total_cmp);
        d.truncate(k);
        d
    }

    /// The batch and graph queries run in a spatial order (Morton, tree); every row is still
    /// exactly the tree's answer for its own point, in input order (here a
    /// cloud in random order, over several chunks of work).
    #[test]
    fn batch_rows_are_the_single_queries_whatever_the_visiting_order() {
        let mut rng = crate::testdata::Lcg::new(3);
        let pts: Vec<Point3> = (0..5000)
            .map(|_| Point3::new(rng.next_f64(), rng.next_f64(), 0.1 * rng.next_f64()))
            .collect();
        let cloud = PointCloud::new(pts.clone()).unwrap();
        let qs: Vec<Point3> = pts
            .iter()
            .rev()
            .take(3000)
            .map(|p| p + Vector3::repeat(0.01))
            .collect();
        let b = cloud.knn_batch(&qs, 6).unwrap();
        for (i, q) in qs.iter().enumerate() {
            let one = cloud.knn(q, 6).unwrap();
            assert_eq!(
                b.indices_of(i),
                one.iter().map(|n| n.index as u32).collect::<Vec<_>>()
            );
            assert_eq!(
                b.distances_of(i),
                one.iter().map(|n| n.distance).collect::<Vec<_>>()
            );
        }
        let g = cloud.knn_graph(5).unwrap();
        for (i, p) in pts.iter().enumerate() {
            let one: Vec<Neighbour> = cloud.knn(p, 6).unwrap();
            let rest: Vec<&Neighbour> = one.iter().filter(|n| n.index != i).collect();
            assert_eq!(rest.len(), 5);
            assert_eq!(
                g.indices_of(i),
                rest.iter().map(|n| n.index as u32).collect::<Vec<_>>()
            );
            assert_eq!(
                g.distances_of(i),
                rest.iter().map(|n| n.distance).collect::<Vec<_>>()
            );
        }
    }

    #[test]
    fn knn_matches_brute_force() {
        let c = grid(20);
        let q = Point3::new(3.3, 7.9, 0.4);
        let got: Vec<f64> = c.knn(&q, 9).unwrap().iter().map(|n| n.distance).collect();
        let want = brute(&c, &q, 9);
        for (a, b) in got.iter().zip(&want) {
            assert!((a - b).abs() < 1e-12);
        }
        assert_eq!(c.nearest(&q).unwrap().index, 3 * 20 + 8);
    }

    #[test]
    fn within_returns_the_disc() {
        let c = grid(20);
        let q = Point3::new(10.0, 10.0, 0.0);
        let r = c.within(&q, 1.0).unwrap();
        // the centre and its four axis neighbours (distance exactly 1: inclusive)
        assert_eq!(r.len(), 5);
        assert_eq!(r[0].index, 10 * 20 + 10);
        assert!(c.within(&q, f64::NAN).is_err());
    }

    #[test]
    fn graph_excludes_self_and_caps_k() {
        let c = grid(3);
        let g = c.knn_graph(4).unwrap();
        assert_eq!(g.k, 4);
        for i in 0..c.len() {
            assert!(!g.indices_of(i).contains(&(i as u32)));
            assert!(g.distances_of(i).iter().all(|&d| d >= 1.0 - 1e-12));
        }
        // the centre's four neighbours are at distance 1
        assert_eq!(g.distances_of(4), &[1.0, 1.0, 1.0, 1.0]);
        assert_eq!(c.knn_graph(100).unwrap().k, 8);
        let batch = c.knn_batch(&[Point3::new(0.0, 0.0, 0.0)], 50).unwrap();
        assert_eq!(batch.k, 9);
    }

    #[test]
    fn graph_excludes_one_copy_of_a_multiply_duplicated_point() {
        // three coincident points and two others: each copy's neighbours are
        // the other two copies first
        let p = vec![
            Point3::new(1.0, 1.0, 1.0),
            Point3::new(1.0, 1.0, 1.0),
            Point3::new(1.0, 1.0, 1.0),
            Point3::new(2.0, 1.0, 1.0),
            Point3::new(1.0, 3.0, 1.0),
        ];
        let g = PointCloud::new(p).unwrap().knn_graph(2).unwrap();
        for i in 0..3 {
            let row = g.indices_of(i);
            assert!(!row.contains(&(i as u32)), "row {i}: {row:?}");
            assert_eq!(g.distances_of(i), &[0.0, 0.0]);
        }
        assert_eq!(g.distances_of(3), &[1.0, 1.0]);
    }

    #[test]
    fn spacing_of_a_grid_with_a_duplicate() {
        let mut p: Vec<Point3> = grid(5).points().to_vec();
        p.push(Point3::new(2.0, 2.0, 0.0));
        p.push(Point3::new(10.0, 0.0, 0.0));
        let s = PointCloud::new(p).unwrap().spacing().unwrap();
        assert_eq!((s.min, s.median, s.max, s.duplicates), (0.0, 1.0, 6.0, 2));
        assert!((s.mean - (24.0 + 6.0) / 27.0).abs() < 1e-15, "{s:?}");
    }

    #[test]
    fn empty_and_bad_input_are_errors() {
        let c = PointCloud::new(vec![]).unwrap();
        assert!(c.knn(&Point3::origin(), 3).is_err());
        assert!(grid(2).knn(&Point3::origin(), 0).is_err());
        assert!(PointCloud::new(vec![Point3::new(f64::NAN, 0.0, 0.0)]).is_err());
        let one = PointCloud::new(vec![Point3::origin()]).unwrap();
        assert!(one.knn_graph(3).is_err());
        // a huge k is capped at the cloud's size, a non-finite query refused
        let g = grid(3);
        assert_eq!(g.knn(&Point3::origin(), usize::MAX).unwrap().len(), 9);
        let nan = Point3::new(f64::NAN, 0.0, 0.0);
        assert!(g.knn(&nan, 2).is_err() && g.nearest(&nan).is_err());
        assert!(g.within(&nan, 1.0).is_err());
        let e = g.knn_batch(&[Point3::origin(), nan], 2).unwrap_err();
        assert!(e.to_string().contains("query point 1"), "{e}");
    }
}
