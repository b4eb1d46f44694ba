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

use kiddo::{ImmutableKdTree, SquaredEuclidean};

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
        })
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
    fn bad_points_are_refused_with_their_index() {
        let mut pts = vec![Point3::origin(); 4];
        pts[2].y = f64::NAN;
        let e = KdTree::new(&pts, "the grid").unwrap_err().to_string();
        assert!(e.contains("point 2 of the grid"), "{e}");
    }
}
