//! Regions between the edge points ([COONS19] §I and §III): grown over the
//! neighbour graph without crossing edge points, tiny regions dissolved, and
//! the edge points handed to the regions on either side.

use rayon::prelude::*;

use crate::cloud::forest::Forest;
use crate::cloud::neighbours::Neighbourhoods;
use crate::spatial::{map_in_order, KdTree};
use crate::{Point3, Result, Vector3};

/// Connected components of the points with `open[i]`, over the first `k`
/// neighbours of each point in `graph`, joining two neighbours only when
/// their normals are within `max_angle` of each other (sign-free). Returns a
/// region index per point (`u32::MAX` for closed points), regions numbered
/// by decreasing size (ties: by smallest point index).
pub fn grow(
    graph: &Neighbourhoods,
    k: usize,
    open: &[bool],
    normals: &[Vector3],
    max_angle: f64,
) -> Vec<u32> {
    let order: Vec<u32> = (0..open.len() as u32).collect();
    grow_in(graph, k, open, normals, max_angle, &order)
}

/// [`grow`] with the points visited in `order` (a permutation; the tree order
/// keeps the forest's and the normals' entries of neighbouring
/// points in the cache). The regions do not depend on it: the unions join
/// by index.
pub(crate) fn grow_in(
    graph: &Neighbourhoods,
    k: usize,
    open: &[bool],
    normals: &[Vector3],
    max_angle: f64,
    order: &[u32],
) -> Vec<u32> {
    let n = open.len();
    let cos = max_angle.cos();
    let joins = |i: usize, t: usize, j: u32| {
        t < k && open[i] && open[j as usize] && normals[i].dot(&normals[j as usize]).abs() >= cos
    };
    let mut forest = Forest::new(n);
    if k <= 64 {
        // which of its first k neighbours each point joins, in parallel (the
        // normals' reads dominate); the unions then run serially
        let masks: Vec<u64> = map_in_order(order, |i| {
            let row = graph.indices_of(i).iter().enumerate();
            row.filter(|&(t, &j)| joins(i, t, j))
                .fold(0u64, |m, (t, _)| m | 1 << t)
        });
        for &i in order {
            let (i, mut m) = (i as usize, masks[i as usize]);
            while m != 0 {
                let t = m.trailing_zeros() as usize;
                forest.join(i as u32, graph.indices_of(i)[t]);
                m &= m - 1;
            }
        }
    } else {
        for &i in order {
            let i = i as usize;
            for (t, &j) in graph.indices_of(i).iter().enumerate() {
                if joins(i, t, j) {
                    forest.join(i as u32, j);
                }
            }
        }
    }
    let mut size = vec![0usize; n];
    let roots: Vec<u32> = (0..n as u32)
        .map(|i| {
            if open[i as usize] {
                let r = forest.root(i);
                size[r as usize] += 1;
                r
            } else {
                u32::MAX
            }
        })
        .collect();
    // roots are the smallest index of their component (union by index)
    let mut order: Vec<u32> = (0..n as u32).filter(|&r| size[r as usize] > 0).collect();
    order.sort_by_key(|&r| (std::cmp::Reverse(size[r as usize]), r));
    let mut rank = vec![u32::MAX; n];
    for (k, &r) in order.iter().enumerate() {
        rank[r as usize] = k as u32;
    }
    roots
        .into_iter()
        .map(|r| if r == u32::MAX { r } else { rank[r as usize] })
        .collect()
}

/// Hands every unassigned point (`region[i] == u32::MAX`) to a region: among
/// its `k` nearest assigned points, the region of the one whose tangent
/// plane passes closest to it (`|n_q . (p - q)|`, plus a tenth of the
/// distance to break ties). On a crease the point lies in the plane of the
/// face it was sampled from and away from the other's, so the split follows
/// the crease rather than the middle of the edge band ([COONS19] §III: the
/// edge points are the boundary points of the regions on either side).
pub fn hand_off(
    points: &[Point3],
    normals: &[Vector3],
    region: &mut [u32],
    k: usize,
) -> Result<()> {
    let assigned: Vec<usize> = (0..points.len())
        .filter(|&i| region[i] != u32::MAX)
        .collect();
    let pts: Vec<Point3> = assigned.iter().map(|&i| points[i]).collect();
    let tree = KdTree::new(&pts, "the region points")?;
    let k = std::num::NonZeroUsize::new(k.max(1)).unwrap_or(std::num::NonZeroUsize::MIN);
    let todo: Vec<usize> = (0..points.len())
        .filter(|&i| region[i] == u32::MAX)
        .collect();
    let given: Vec<u32> = todo
        .par_iter()
        .map(|&i| {
            let p = points[i];
            let mut best = (f64::INFINITY, u32::MAX);
            for nb in tree.nearest_n(&p, k) {
                let q = assigned[nb.index];
                let score = normals[q].dot(&(p - points[q])).abs() + 0.1 * nb.distance;
                if score < best.0 {
                    best = (score, region[q]);
                }
            }
            best.1
        })
        .collect();
    for (&i, g) in todo.iter().zip(given) {
        region[i] = g;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PointCloud;

    #[test]
    fn two_strips_split_by_a_closed_row_and_handed_back_by_plane() {
        // a fold: z = 0 for x <= 0, x = 0 plane rising for the second half
        let mut p = Vec::new();
        let mut nrm = Vec::new();
        for i in -10..=10 {
            for j in 0..10 {
                let t = i as f64 * 0.1;
                if i <= 0 {
                    p.push(Point3::new(t, j as f64 * 0.1, 0.0));
                    nrm.push(Vector3::z());
                } else {
                    p.push(Point3::new(0.0, j as f64 * 0.1, t));
                    nrm.push(Vector3::x());
                }
            }
        }
        let cloud = PointCloud::new(p.clone()).unwrap();
        let g = cloud.knn_graph(8).unwrap();
        // the two rows either side of the fold are edge points
        let open: Vec<bool> = p.iter().map(|q| q.x < -0.15 || q.z > 0.15).collect();
        let mut r = grow(&g, 8, &open, &nrm, 0.3);
        assert_eq!(r.iter().filter(|&&x| x == u32::MAX).count(), 30);
        // 90 flat points (region 0: same size, smaller first index) and 90 upright
        assert_eq!(r.iter().filter(|&&x| x == 0).count(), 90);
        assert_eq!(r.iter().filter(|&&x| x == 1).count(), 90);
        hand_off(&p, &nrm, &mut r, 12).unwrap();
        for (q, &x) in p.iter().zip(&r) {
            // the fold line itself lies in both planes
            if q.x < 0.0 {
                assert_eq!(x, 0, "{q:?}");
            } else if q.z > 0.0 {
                assert_eq!(x, 1, "{q:?}");
            }
        }
    }
}
