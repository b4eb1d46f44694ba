//! The one spatial index of the library: a static KD-tree over 3D points
//! (kiddo 6 `ImmutableKdTree` inside; its types never leave this module).
//!
//! Every nearest-neighbour query goes through [`KdTree`]: the neighbour
//! queries of a [`crate::PointCloud`], the start points of point inversion
//! ([`crate::project::SurfaceInverter`]) and the nearest grid vertex of the
//! [COONS19]'s grid iteration ([`crate::project::grid_iteration`]).
//! Distances are Euclidean (not squared); results of the multi-point queries
//! are sorted by distance, nearest first, ties in the tree's order.

use std::num::NonZeroUsize;
use std::sync::{Mutex, OnceLock, PoisonError};

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::{Error, Point3, Result};

/// One neighbour: its index among the indexed points and its distance to the
/// query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Index of the point (in the order the points were given).
    pub index: usize,
    /// Euclidean distance to the query point.
    pub distance: f64,
}

/// A static KD-tree over a set of 3D points (built once, queried from any
/// number of threads).
pub struct KdTree {
    tree: ImmutableKdTree<f64, 3>,
    len: usize,
    /// The indexed points' Morton order, computed on first use.
    order: OnceLock<Vec<u32>>,
}

impl std::fmt::Debug for KdTree {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KdTree").field("len", &self.len).finish()
    }
}

fn coords(p: &Point3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

impl KdTree {
    /// Indexes `points` (`what` names them in errors). An error for no
    /// points, more than 2^32 points, or a non-finite coordinate.
    ///
    /// ```
    /// use scanfit::spatial::KdTree;
    /// use scanfit::Point3;
    /// let pts: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let tree = KdTree::new(&pts, "the samples").unwrap();
    /// let n = tree.nearest(&Point3::new(3.2, 1.0, 0.0));
    /// assert_eq!(n.index, 3);
    /// assert!((n.distance - (0.04f64 + 1.0).sqrt()).abs() < 1e-15);
    /// assert!(KdTree::new(&[], "the samples").is_err());
    /// ```
    pub fn new(points: &[Point3], what: &str) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::InvalidInput(format!(
                "{what} are empty; a spatial index needs at least one point"
            )));
        }
        if points.len() > u32::MAX as usize {
            return Err(Error::InvalidInput(format!(
                "{} points in {what} exceed the KD-tree's limit of 2^32; split them",
                points.len()
            )));
        }
        if let Some(i) = points
            .iter()
            .position(|p| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(Error::InvalidInput(format!(
                "point {i} of {what} has a non-finite coordinate; a spatial index needs finite points"
            )));
        }
        let c: Vec<[f64; 3]> = points.iter().map(coords).collect();
        let tree = ImmutableKdTree::new_from_slice(&c)
            .map_err(|e| Error::InvalidInput(format!("could not index {what}: {e:?}")))?;
        Ok(Self {
            tree,
            len: points.len(),
            order: OnceLock::new(),
        })
    }

    /// The Morton order ([`morton_order`]) of `points`, the points this
    /// tree indexes (computed on the first call, kept with the tree): batch
    /// work over all the indexed points runs in this order, so consecutive
    /// queries visit the same leaves of the tree and the same points (the
    /// cache holds them), whatever order the points came in.
    pub(crate) fn spatial_order(&self, points: &[Point3]) -> &[u32] {
        self.order.get_or_init(|| morton_order(points))
    }

    /// Number of indexed points (at least 1).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false: a tree holds at least one point.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The nearest indexed point to `query` (a finite point).
    pub fn nearest(&self, query: &Point3) -> Neighbour {
        let r = self
            .tree
            .query(&coords(query))
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        Neighbour {
            index: r.item as usize,
            distance: r.distance.sqrt(),
        }
    }

    /// The `k` nearest indexed points to `query` (fewer if there are fewer
    /// points), nearest first.
    ///
    /// ```
    /// use std::num::NonZeroUsize;
    /// use scanfit::spatial::KdTree;
    /// use scanfit::Point3;
    /// let pts: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let tree = KdTree::new(&pts, "the points").unwrap();
    /// let k3 = tree.nearest_n(&Point3::new(6.9, 0.0, 0.0), NonZeroUsize::new(3).unwrap());
    /// let idx: Vec<usize> = k3.iter().map(|n| n.index).collect();
    /// assert_eq!(idx, [7, 6, 8]);
    /// ```
    pub fn nearest_n(&self, query: &Point3, k: NonZeroUsize) -> Vec<Neighbour> {
        // k is capped at the point count: the tree reserves room for k results
        let k = NonZeroUsize::new(k.get().min(self.len)).unwrap_or(NonZeroUsize::MIN);
        self.tree
            .query(&coords(query))
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute()
            .into_iter()
            .map(|r| Neighbour {
                index: r.item as usize,
                distance: r.distance.sqrt(),
            })
            .collect()
    }

    /// All indexed points within distance `radius` of `query` (inclusive),
    /// nearest first.
    ///
    /// ```
    /// use scanfit::spatial::KdTree;
    /// use scanfit::Point3;
    /// let pts: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let tree = KdTree::new(&pts, "the points").unwrap();
    /// let near = tree.within(&Point3::new(2.0, 0.0, 0.0), 1.0);
    /// assert_eq!(near.iter().map(|n| n.index).collect::<Vec<_>>(), [2, 1, 3]);
    /// ```
    pub fn within(&self, query: &Point3, radius: f64) -> Vec<Neighbour> {
        let mut out: Vec<Neighbour> = self
            .tree
            .query(&coords(query))
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .execute()
            .into_iter()
            .map(|r| Neighbour {
                index: r.item as usize,
                distance: r.distance.sqrt(),
            })
            .collect();
        out.sort_by(|a, b| a.distance.total_cmp(&b.distance));
        out
    }
}

/// Spreads the low 21 bits of `v` to every third bit.
fn spread3(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// A permutation of `points` along the Morton (Z-order) curve of their
/// bounding cube cut into 2^21 cells per axis (ties by index): points close
/// in the order are close in space. Batched neighbour queries visit their
/// queries in this order for cache locality; it decides only the order of
/// the work, never a result.
///
/// ```
/// use scanfit::spatial::morton_order;
/// use scanfit::Point3;
/// let p = |x, y| Point3::new(x, y, 0.0);
/// let pts = [p(1.0, 1.0), p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)];
/// assert_eq!(morton_order(&pts), [1, 2, 3, 0]);
/// ```
pub fn morton_order(points: &[Point3]) -> Vec<u32> {
    let Some(first) = points.first() else {
        return Vec::new();
    };
    let (lo, hi) = points
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let ext = (hi - lo).max();
    let scale = if ext > 0.0 {
        ((1u64 << 21) - 1) as f64 / ext
    } else {
        0.0
    };
    let cell = |p: &Point3, a: usize| ((p[a] - lo[a]) * scale) as u64;
    let mut keys: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let code = spread3(cell(p, 0)) | spread3(cell(p, 1)) << 1 | spread3(cell(p, 2)) << 2;
            (code, i as u32)
        })
        .collect();
    keys.par_sort_unstable();
    keys.into_iter().map(|k| k.1).collect()
}

/// Queries visited per task of the ordered batch helpers.
const CHUNK: usize = 1024;

/// Runs `fill(i, a_row, b_row)` for every item `i` listed in `order`
/// (parallel chunks of consecutive entries of `order`, so one task works on
/// points close in space) and stores the rows at their item's place in `a`
/// and `b` (`width` values per item in each). Each row is filled exactly as
/// by a loop in item order: the order decides only the speed.
pub(crate) fn fill_rows_in_order<A, B, F>(
    order: &[u32],
    width: usize,
    a: &mut [A],
    b: &mut [B],
    fill: F,
) where
    A: Copy + Default + Send,
    B: Copy + Default + Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync,
{
    if width == 0 {
        return;
    }
    let out = Mutex::new((a, b));
    order.par_chunks(CHUNK).for_each(|chunk| {
        let mut ra = vec![A::default(); chunk.len() * width];
        let mut rb = vec![B::default(); chunk.len() * width];
        for ((x, y), &i) in ra.chunks_mut(width).zip(rb.chunks_mut(width)).zip(chunk) {
            fill(i as usize, x, y);
        }
        let mut o = out.lock().unwrap_or_else(PoisonError::into_inner);
        for (k, &i) in chunk.iter().enumerate() {
            let (from, to) = (k * width..(k + 1) * width, i as usize * width);
            o.0[to..to + width].copy_from_slice(&ra[from.clone()]);
            o.1[to..to + width].copy_from_slice(&rb[from]);
        }
    });
}

/// `f(i)` for every item `i` of `order` (a permutation of `0..order.len()`),
/// evaluated in parallel chunks in the order's sequence, returned in item
/// order.
pub(crate) fn map_in_order<T, F>(order: &[u32], f: F) -> Vec<T>
where
    T: Copy + Default + Send,
    F: Fn(usize) -> T + Sync,
{
    let mut out = vec![T::default(); order.len()];
    let mut none: Vec<()> = vec![(); order.len()];
    fill_rows_in_order(order, 1, &mut out, &mut none, |i, row, _| row[0] = f(i));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_agree_with_brute_force() {
        let mut rng = crate::testdata::Lcg::new(5);
        let mut rnd = || rng.next_f64();
        let pts: Vec<Point3> = (0..500).map(|_| Point3::new(rnd(), rnd(), rnd())).collect();
        let tree = KdTree::new(&pts, "points").unwrap();
        assert_eq!(tree.len(), 500);
        assert!(!tree.is_empty());
        for _ in 0..50 {
            let q = Point3::new(rnd(), rnd(), rnd());
            let mut brute: Vec<(f64, usize)> = pts
                .iter()
                .enumerate()
                .map(|(i, p)| ((p - q).norm(), i))
                .collect();
            brute.sort_by(|a, b| a.0.total_cmp(&b.0));
            assert_eq!(tree.nearest(&q).index, brute[0].1);
            let k = tree.nearest_n(&q, NonZeroUsize::new(5).unwrap());
            let want: Vec<usize> = brute[..5].iter().map(|b| b.1).collect();
            assert_eq!(k.iter().map(|n| n.index).collect::<Vec<_>>(), want);
            // a radius between the 8th and 9th distance (squared distances
            // round differently from the norms at the exact 8th)
            let r = 0.5 * (brute[7].0 + brute[8].0);
            let w = tree.within(&q, r);
            assert_eq!(w.len(), 8);
            assert!((w[7].distance - brute[7].0).abs() < 1e-15);
        }
        // more neighbours asked for than points: all of them
        let all = tree.nearest_n(&pts[0], NonZeroUsize::new(10_000).unwrap());
        assert_eq!(all.len(), 500);
    }

    #[test]
    fn morton_order_is_a_permutation_that_keeps_cells_together() {
        let mut rng = crate::testdata::Lcg::new(9);
        let pts: Vec<Point3> = (0..5000)
            .map(|_| Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
            .collect();
        let order = morton_order(&pts);
        let mut seen = vec![false; pts.len()];
        for &i in &order {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // the octant of the first level changes 7 times along the curve
        let octant = |p: &Point3| (p.x >= 0.5, p.y >= 0.5, p.z >= 0.5);
        let changes = order
            .windows(2)
            .filter(|w| octant(&pts[w[0] as usize]) != octant(&pts[w[1] as usize]))
            .count();
        assert!(changes <= 7, "{changes}");
        // consecutive points are close: mean step far below that of the input order
        let step = |o: &[u32]| {
            o.windows(2)
                .map(|w| (pts[w[0] as usize] - pts[w[1] as usize]).norm())
                .sum::<f64>()
                / (o.len() - 1) as f64
        };
        let input: Vec<u32> = (0..pts.len() as u32).collect();
        assert!(step(&order) < 0.2 * step(&input), "{} vs {}", step(&order), step(&input));
        assert!(morton_order(&[]).is_empty());
        assert_eq!(morton_order(&[Point3::origin(); 3]), [0, 1, 2]);
    }

    #[test]
    fn rows_filled_in_any_order_land_at_their_items() {
        // a permutation over several chunks
        let n = 3 * CHUNK + 17;
        let order: Vec<u32> = (0..n as u32).map(|i| (i * 7919) % n as u32).collect();
        let (mut a, mut b) = (vec![0u32; 2 * n], vec![0.0; 2 * n]);
        fill_rows_in_order(&order, 2, &mut a, &mut b, |i, x, y| {
            x.copy_from_slice(&[i as u32, 2 * i as u32]);
            y.copy_from_slice(&[i as f64 / 2.0, -(i as f64)]);
        });
        for i in 0..n {
            assert_eq!(a[2 * i..2 * i + 2], [i as u32, 2 * i as u32]);
            assert_eq!(b[2 * i..2 * i + 2], [i as f64 / 2.0, -(i as f64)]);
        }
        assert_eq!(map_in_order(&order, |i| i * i), (0..n).map(|i| i * i).collect::<Vec<_>>());
    }

    #[test]
    fn bad_points_are_refused_with_their_index() {
        let mut pts = vec![Point3::origin(); 4];
        pts[2].y = f64::NAN;
        let e = KdTree::new(&pts, "the grid").unwrap_err().to_string();
        assert!(e.contains("point 2 of the grid"), "{e}");
    }
}
