//! Octree cells subdivided where the normals vary ([COONS19] §I, the
//! telephone receiver: "small sized cells were on edge points and larger
//! sized cells were on planar areas", Fig. 3).
//!
//! The paper computes "the variations in the unit normal vectors between
//! neighboring points ... by forming the cells": here each point's variation
//! is the largest angle between its normal and a neighbour's
//! ([`neighbour_variation`], sign-free), and a cell's is the largest over its
//! points. A cell whose variation exceeds the threshold is split into eight
//! until its side would drop below the minimum size; the smallest cells
//! still above the threshold are the edge cells.
//!
//! (A cell's own spread of normals was tried first: on a crease blurred by
//! the PCA neighbourhood a small cell in the middle of the blur holds only
//! intermediate normals and its spread stays under the threshold, leaving
//! holes in the edge band; the neighbour variation there is half the crease
//! angle whatever the cell.)

use crate::cloud::neighbours::Neighbourhoods;
use crate::spatial::map_in_order;
use crate::{Point3, Vector3};

/// A leaf cell of the octree.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Its lowest corner.
    pub origin: Point3,
    /// Its side length.
    pub size: f64,
    /// Points in it.
    pub points: usize,
    /// Largest neighbour variation (radians) of its points.
    pub variation: f64,
    /// An edge cell: at the minimum size and its variation above the threshold.
    pub edge: bool,
}

/// The leaves of the octree and, for every point, its leaf.
#[derive(Debug, Clone)]
pub struct Octree {
    /// Leaf cells (non-empty), in depth-first order.
    pub cells: Vec<Cell>,
    /// Per point the index of its leaf in `cells`.
    pub cell_of: Vec<u32>,
}

/// The variation of the normals between neighbouring points: for each
/// point the largest angle (radians, sign-free) between its normal and the
/// normal of any of its neighbours in `graph`.
pub fn neighbour_variation(graph: &Neighbourhoods, normals: &[Vector3]) -> Vec<f64> {
    let order: Vec<u32> = (0..normals.len() as u32).collect();
    neighbour_variation_in(graph, normals, &order)
}

/// [`neighbour_variation`] with the points visited in `order` (a
/// permutation of the points: the tree order keeps the neighbours'
/// normals in the cache); the result does not depend on it.
pub(crate) fn neighbour_variation_in(
    graph: &Neighbourhoods,
    normals: &[Vector3],
    order: &[u32],
) -> Vec<f64> {
    map_in_order(order, |i| {
        let least = graph
            .indices_of(i)
            .iter()
            .map(|&j| normals[i].dot(&normals[j as usize]).abs())
            .fold(1.0_f64, f64::min);
        least.clamp(0.0, 1.0).acos()
    })
}

/// Subdivides the bounding cube of `points` (see the module docs): cells
/// whose variation (the largest of their points' `variation`) exceeds
/// `max_angle` (radians) are split while their children are at least
/// `min_size` wide.
pub fn subdivide(points: &[Point3], variation: &[f64], min_size: f64, max_angle: f64) -> Octree {
    let mut cell_of = vec![0u32; points.len()];
    let mut cells = Vec::new();
    if points.is_empty() {
        return Octree { cells, cell_of };
    }
    let (lo, hi) = points.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    // a cube slightly larger than the box, so no point sits on its far faces
    let size = (hi - lo).max().max(min_size) * (1.0 + 1e-9);
    let mut stack: Vec<(Point3, f64, Vec<u32>)> =
        vec![(Point3::from(lo), size, (0..points.len() as u32).collect())];
    while let Some((origin, size, members)) = stack.pop() {
        let cell = members
            .iter()
            .map(|&i| variation[i as usize])
            .fold(0.0, f64::max);
        let half = size / 2.0;
        if cell > max_angle && half >= min_size && members.len() > 1 {
            let mid = origin.coords + Vector3::repeat(half);
            let mut children: [Vec<u32>; 8] = Default::default();
            for &i in &members {
                let p = points[i as usize];
                let k = usize::from(p.x >= mid.x)
                    | usize::from(p.y >= mid.y) << 1
                    | usize::from(p.z >= mid.z) << 2;
                children[k].push(i);
            }
            for (k, c) in children.into_iter().enumerate().rev() {
                if !c.is_empty() {
                    let off = Vector3::new(
                        (k & 1) as f64 * half,
                        (k >> 1 & 1) as f64 * half,
                        (k >> 2 & 1) as f64 * half,
                    );
                    stack.push((origin + off, half, c));
                }
            }
            continue;
        }
        let id = cells.len() as u32;
        for &i in &members {
            cell_of[i as usize] = id;
        }
        cells.push(Cell {
            origin,
            size,
            points: members.len(),
            variation: cell,
            edge: cell > max_angle,
        });
    }
    Octree { cells, cell_of }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PointCloud;

    #[test]
    fn variation_is_the_widest_neighbour_angle_sign_free() {
        let pts: Vec<Point3> = (0..4).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
        let g = PointCloud::new(pts).unwrap().knn_graph(1).unwrap();
        let t = 0.3_f64;
        let n = [
            Vector3::z(),
            -Vector3::z(),
            Vector3::new(0.0, t.sin(), t.cos()),
            Vector3::z(),
        ];
        let v = neighbour_variation(&g, &n);
        // 0 and 1 are each other's nearest (tie broken to the lower index for 1)
        assert!(v[0].abs() < 1e-12 && v[1].abs() < 1e-7, "{v:?}");
        assert!((v[3] - t).abs() < 1e-12, "{v:?}");
    }

    #[test]
    fn crease_cells_are_small_and_flat_cells_large() {
        // two half-planes meeting at a right angle along the y axis
        let (mut p, mut var) = (Vec::new(), Vec::new());
        for i in 0..64 {
            for j in 0..64 {
                let (a, b) = (i as f64 / 8.0, j as f64 / 8.0);
                // points within 0.3 of the crease see both planes' normals
                let v = if a < 0.3 { 0.8 } else { 0.0 };
                p.push(Point3::new(a, b, 0.0));
                p.push(Point3::new(0.0, b, a + 0.0625));
                var.extend([v, v]);
            }
        }
        let t = subdivide(&p, &var, 0.5, 0.2);
        let edge: Vec<&Cell> = t.cells.iter().filter(|c| c.edge).collect();
        assert!(!edge.is_empty());
        // every edge cell is at the minimum size and on the crease
        assert!(edge.iter().all(|c| c.size < 1.0 && c.size >= 0.5));
        assert!(edge.iter().all(|c| c.origin.x < 0.5 && c.origin.z < 0.5));
        // flat areas keep cells larger than the minimum
        assert!(t.cells.iter().any(|c| !c.edge && c.size >= 2.0));
        // every point sits in the cell it is assigned to
        for (i, q) in p.iter().enumerate() {
            let c = &t.cells[t.cell_of[i] as usize];
            assert!((0..3).all(|a| q[a] >= c.origin[a] && q[a] < c.origin[a] + c.size));
        }
    }
}
