//! Point normals: PCA over the k nearest neighbours, consistently oriented.
//!
//! The normal of point `i` is the eigenvector of the smallest eigenvalue of
//! the covariance of `i` and its k nearest neighbours (Hoppe et al. 1992,
//! "Surface reconstruction from unorganized points", section 3.2). PCA gives
//! the normal's line, not its sign; two orientations are offered:
//!
//! * [`Orientation::Viewpoint`]: every normal points towards a viewpoint (the
//!   scanner position), as PCL's `flipNormalTowardsViewpoint`.
//! * [`Orientation::SpanningTree`]: Hoppe's propagation: a minimum spanning
//!   tree of the neighbour graph with edge cost `1 - |n_i . n_j|` is walked
//!   from a seed whose normal is fixed, flipping each child to agree with its
//!   parent. The seed of every connected component is its point of largest
//!   `hint . p` (the extreme point along `hint`), oriented to `hint` (by
//!   default +z: a scan seen from above has its normals pointing up).
//!   Departure from Hoppe: the cost of an edge `i -> j` of direction `d`
//!   (unit) is `1 - |n_i . n_j| (1 - |n_i . d|) (1 - |n_j . d|)`, so an edge
//!   that leaves the tangent planes (across a thin neck or sheet, where the
//!   k nearest neighbours include the far side, whose normal is parallel as
//!   a line but opposite in sign) costs the most and the tree goes around
//!   it; with Hoppe's cost such an edge is free and flips everything after
//!   it (a bust's body points inward while its head points outward).
//!   [`Normals::disagreement`] measures what is left.
//! * [`Orientation::None`]: the eigen solver's signs (arbitrary: the
//!   closed form of [`crate::eigen3`] turns the largest component positive,
//!   nalgebra's iterative solver, used where the smallest eigenvalue is not
//!   separated, leaves its own).
//!
//! The normal is the smallest eigenvector by the closed form of
//! [`crate::eigen3`] (within 1e-11 rad of nalgebra's iterative
//! `SymmetricEigen`; on the 10^6-point panel of BENCHMARKS.md the normals
//! differ from the iterative solver's by at most 9e-14 rad), or by the
//! iterative solver where the closed form declines.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use rayon::prelude::*;

use super::forest::Forest;
use super::neighbours::Neighbourhoods;
use super::PointCloud;
use crate::eigen3::{least_aligned_axis, smallest_eigen};
use crate::geom::{covariance, pca_of, surface_variation};
use crate::{Error, Point3, Result, Vector3};

/// How to choose the sign of each normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    /// Leave the eigen solver's signs.
    None,
    /// Every normal points towards this viewpoint.
    Viewpoint(Point3),
    /// Propagate over a minimum spanning tree of the neighbour graph; each
    /// component's seed (its extreme point along the hint) points along the hint.
    SpanningTree {
        /// Direction the seed normals point along.
        hint: Vector3,
    },
}

/// Normal estimation settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalsConfig {
    /// Neighbours per point, the point itself excluded: the covariance is
    /// over the point and its `k` nearest others (default 16; at least 2).
    /// Open3D's `KDTreeSearchParamKNN(knn)` and PCL's `setKSearch(k)`
    /// count the point itself, so scanfit's `k` is their `k - 1`: the
    /// default 16 equals their 17, and their 30 is scanfit's 29.
    pub k: usize,
    /// Sign choice (default: spanning tree with hint +z).
    pub orientation: Orientation,
}

impl Default for NormalsConfig {
    fn default() -> Self {
        Self {
            k: 16,
            orientation: Orientation::SpanningTree { hint: Vector3::z() },
        }
    }
}

/// Normals and what the estimate says about the surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Normals {
    /// Unit normal per point.
    pub normals: Vec<Vector3>,
    /// Surface variation per point (`l3 / (l1 + l2 + l3)` of the
    /// neighbourhood covariance): 0 on a plane, up to 1/3 at corners and noise.
    pub variation: Vec<f64>,
    /// Points whose neighbourhood spans no plane (all neighbours collinear or
    /// coincident); their normal is the best the line allows (perpendicular
    /// to it) and should not be trusted.
    pub degenerate: Vec<usize>,
    /// Connected components of the neighbour graph (1 for a well-sampled
    /// single surface; with the spanning-tree orientation each component is
    /// oriented on its own).
    pub components: usize,
    /// Share of neighbour pairs that disagree after orientation: among the
    /// pairs `(i, j)` of the neighbour graph that lie on one sheet (the edge
    /// within 30 degrees of both tangent planes, `|n . d| < 0.5`, and the
    /// normals within 60 degrees as lines, `|n_i . n_j| > 0.5`), the share
    /// with `n_i . n_j < 0`. 0 for a consistent orientation; a few percent
    /// means a region flipped (`None` without orientation or such pairs).
    pub disagreement: Option<f64>,
}

/// Estimates oriented normals of `cloud` (see the module documentation).
///
/// The neighbour search and the PCA run in one pass over the KD-tree's
/// order ([`crate::spatial::KdTree::graph_in_tree_order`]): each
/// neighbourhood's covariance is summed while its points are in the cache.
/// The neighbours and the sums are those of [`estimate_normals_on`] over
/// `cloud.knn_graph(k)`, so the normals are the same bit for bit.
pub fn estimate_normals(cloud: &PointCloud, config: &NormalsConfig) -> Result<Normals> {
    check(cloud, config)?;
    let tree = cloud.tree()?;
    let pts = tree.points_in_order();
    let flat_below = flat_below(cloud);
    let (rows, per_point) = tree.graph_in_tree_order(config.k, |t, row| {
        let hood = std::iter::once(t).chain(row.iter().map(|&s| s as usize));
        pca_normal(hood.map(|s| Vector3::from(pts[s])), flat_below)
    });
    let k = rows.len() / cloud.len();
    finish(cloud, per_point, Rows::Tree { rows, k }, config)
}

/// [`estimate_normals`] over a neighbour graph already built
/// (`cloud.knn_graph(k)`; its `k` is the one used), for callers that need
/// the graph too (segmentation grows regions over it).
///
/// ```
/// use scanfit::cloud::normals::{estimate_normals_on, NormalsConfig, Orientation};
/// use scanfit::{Point3, PointCloud};
/// let pts = (0..100).map(|i| Point3::new((i % 10) as f64, (i / 10) as f64, 0.0)).collect();
/// let cloud = PointCloud::new(pts)?;
/// let graph = cloud.knn_graph(8)?;
/// let cfg = NormalsConfig { k: 8, orientation: Orientation::None };
/// let n = estimate_normals_on(&cloud, &graph, &cfg)?;
/// assert!(n.normals.iter().all(|n| n.z.abs() > 1.0 - 1e-12));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn estimate_normals_on(
    cloud: &PointCloud,
    graph: &Neighbourhoods,
    config: &NormalsConfig,
) -> Result<Normals> {
    if graph.len() != cloud.len() {
        return Err(Error::LengthMismatch {
            what: "neighbour graph rows",
            expected: cloud.len(),
            got: graph.len(),
        });
    }
    check_hint(config)?;
    let n = cloud.len();
    // the work runs in the tree's order on the tree's copy of the points: a
    // point's neighbours lie close to it there (in the input they may lie
    // anywhere), and `at` (4 bytes a point) maps an input index to its place
    let tree = cloud.tree()?;
    let order = tree.spatial_order();
    let pts = tree.points_in_order();
    let at = positions(order);
    let flat_below = flat_below(cloud);
    let per_point: Vec<PerPoint> = (0..n)
        .into_par_iter()
        .with_min_len(1024)
        .map(|t| {
            let nb = graph.indices_of(order[t] as usize);
            let hood = std::iter::once(t).chain(nb.iter().map(|&j| at[j as usize] as usize));
            pca_normal(hood.map(|s| Vector3::from(pts[s])), flat_below)
        })
        .collect();
    finish(cloud, per_point, Rows::Input { graph, at }, config)
}

/// The settings and the cloud checked before any work.
fn check(cloud: &PointCloud, config: &NormalsConfig) -> Result<()> {
    if config.k < 2 {
        return Err(Error::InvalidInput(format!(
            "normals need k >= 2 neighbours (got {}); 16 is a good default",
            config.k
        )));
    }
    if cloud.len() < 3 {
        return Err(Error::TooFewPoints {
            got: cloud.len(),
            needed: 3,
            what: "normal estimation".into(),
        });
    }
    check_hint(config)
}

fn check_hint(config: &NormalsConfig) -> Result<()> {
    match config.orientation {
        Orientation::SpanningTree { hint }
            if !(hint.iter().all(|c| c.is_finite()) && hint.norm() > 0.0) =>
        {
            Err(Error::InvalidInput(
                "the orientation hint must be a finite non-zero vector".into(),
            ))
        }
        _ => Ok(()),
    }
}

/// The second smallest eigenvalue at or below which a neighbourhood spans
/// no plane (relative to the cloud's size).
fn flat_below(cloud: &PointCloud) -> f64 {
    let scale = cloud.diagonal();
    1e-24 * scale * scale
}

/// What the PCA gives one point.
#[derive(Debug, Clone, Copy)]
struct PerPoint {
    normal: Vector3,
    variation: f64,
    /// No plane: the neighbourhood is collinear or coincident.
    flat: bool,
}

impl Default for PerPoint {
    fn default() -> Self {
        Self {
            normal: Vector3::z(),
            variation: 0.0,
            flat: true,
        }
    }
}

/// The PCA normal of one neighbourhood (the point first, then its
/// neighbours): the closed form of [`crate::eigen3`] where the smallest
/// eigenvalue stands apart (nearly every neighbourhood of a surface), else
/// the iterative solver; a collinear neighbourhood gets a perpendicular of
/// its line and is marked flat.
fn pca_normal(hood: impl Iterator<Item = Vector3>, flat_below: f64) -> PerPoint {
    let Some((centroid, cov)) = covariance(hood) else {
        return PerPoint::default();
    };
    if let Some(e) = smallest_eigen(&cov).filter(|e| e.values[1] > flat_below) {
        return PerPoint {
            normal: e.vector,
            variation: surface_variation(&e.values),
            flat: false,
        };
    }
    let p = pca_of(centroid, &cov);
    let flat = p.values[1] <= flat_below;
    let normal = if flat {
        // collinear neighbourhood: any perpendicular of the line
        p.axes[0].cross(&least_aligned_axis(&p.axes[0])).normalize()
    } else {
        p.axes[2]
    };
    PerPoint {
        normal,
        variation: p.variation(),
        flat,
    }
}

/// The neighbour graph the normals were estimated over.
enum Rows<'a> {
    /// `k` tree positions per tree position
    /// ([`crate::spatial::KdTree::graph_in_tree_order`]).
    Tree { rows: Vec<u32>, k: usize },
    /// A graph in input order, and the tree position of each input index.
    Input {
        graph: &'a Neighbourhoods,
        at: Vec<u32>,
    },
}

/// Orients the normals in the tree's order (`per_point`), counts the
/// components, measures the disagreement and returns it all in input order.
fn finish(
    cloud: &PointCloud,
    mut per_point: Vec<PerPoint>,
    rows: Rows<'_>,
    config: &NormalsConfig,
) -> Result<Normals> {
    let tree = cloud.tree()?;
    let order = tree.spatial_order();
    let pts = tree.points_in_order();
    match config.orientation {
        Orientation::None => {}
        Orientation::Viewpoint(v) => {
            // the tree's copy of the points is the input's, bit for bit
            per_point.par_iter_mut().zip(pts).for_each(|(r, p)| {
                if r.normal.dot(&(v - Point3::from(*p))) < 0.0 {
                    r.normal = -r.normal;
                }
            });
        }
        Orientation::SpanningTree { hint } => {
            return finish_spanning_tree(cloud, per_point, rows, &hint);
        }
    }
    let (flat_rows, k) = match &rows {
        Rows::Tree { rows, k } => (&rows[..], *k),
        Rows::Input { graph, .. } => (&graph.indices[..], graph.k),
    };
    let normal = |t: usize| per_point[t].normal;
    // the components and the input order (serial walks) run beside the
    // disagreement (parallel): all three only read
    let ((components, parts), disagreement) = rayon::join(
        || {
            let components = count_components(flat_rows, k, cloud.len());
            (components, into_input_order(&per_point, order))
        },
        || match (config.orientation, &rows) {
            (Orientation::None, _) => None,
            (_, Rows::Tree { rows, k }) => disagreement(pts, normal, |t| {
                rows[t * k..(t + 1) * k].iter().map(|&s| s as usize)
            }),
            (_, Rows::Input { graph, at }) => disagreement(pts, normal, |t| {
                let nb = graph.indices_of(order[t] as usize);
                nb.iter().map(|&j| at[j as usize] as usize)
            }),
        },
    );
    drop(rows);
    Ok(Normals::from_parts(parts, components, disagreement))
}

/// [`finish`] with the spanning-tree orientation: Prim's tree runs in input
/// order (its ties by input index) over the graph in input order, on the
/// normals already in input order (the tree-order results are dropped
/// before the adjacency, the largest thing the normals hold, is built).
fn finish_spanning_tree(
    cloud: &PointCloud,
    per_point: Vec<PerPoint>,
    rows: Rows<'_>,
    hint: &Vector3,
) -> Result<Normals> {
    let tree = cloud.tree()?;
    let order = tree.spatial_order();
    let built: Neighbourhoods;
    let (graph, at) = match rows {
        Rows::Input { graph, at } => (graph, at),
        Rows::Tree { rows, k } => {
            built = input_graph(&rows, k, order);
            drop(rows);
            (&built, positions(order))
        }
    };
    let (mut normals, variation, degenerate) = into_input_order(&per_point, order);
    drop(per_point);
    let adj = Adjacency::of(graph);
    let components = orient_by_spanning_tree(cloud.points(), &adj, &mut normals, hint);
    drop(adj);
    let normal = |t: usize| normals[order[t] as usize];
    let disagreement = disagreement(tree.points_in_order(), normal, |t| {
        let nb = graph.indices_of(order[t] as usize);
        nb.iter().map(|&j| at[j as usize] as usize)
    });
    let parts = (normals, variation, degenerate);
    Ok(Normals::from_parts(parts, components, disagreement))
}

/// Normals, variations and degenerate points (ascending), in input order.
type Parts = (Vec<Vector3>, Vec<f64>, Vec<usize>);

impl Normals {
    fn from_parts(parts: Parts, components: usize, disagreement: Option<f64>) -> Self {
        let (normals, variation, degenerate) = parts;
        Self {
            normals,
            variation,
            degenerate,
            components,
            disagreement,
        }
    }
}

/// The [`Parts`] of the results in the tree's order.
fn into_input_order(per_point: &[PerPoint], order: &[u32]) -> Parts {
    let n = per_point.len();
    let mut normals = vec![Vector3::zeros(); n];
    let mut variation = vec![0.0; n];
    let mut degenerate = Vec::new();
    for (&i, r) in order.iter().zip(per_point) {
        normals[i as usize] = r.normal;
        variation[i as usize] = r.variation;
        if r.flat {
            degenerate.push(i as usize);
        }
    }
    degenerate.sort_unstable();
    (normals, variation, degenerate)
}

/// The tree position of each input index (`order` inverted).
fn positions(order: &[u32]) -> Vec<u32> {
    let mut at = vec![0u32; order.len()];
    for (t, &i) in order.iter().enumerate() {
        at[i as usize] = t as u32;
    }
    at
}

/// The rows of [`Rows::Tree`] as a graph in input order (what
/// `knn_graph_indices(k)` gives).
fn input_graph(rows: &[u32], k: usize, order: &[u32]) -> Neighbourhoods {
    let mut indices = vec![0u32; rows.len()];
    for (t, row) in rows.chunks_exact(k).enumerate() {
        let i = order[t] as usize;
        for (x, &s) in indices[i * k..(i + 1) * k].iter_mut().zip(row) {
            *x = order[s as usize];
        }
    }
    Neighbourhoods {
        k,
        indices,
        distances: Vec::new(),
    }
}

/// The share of same-sheet neighbour pairs whose normals disagree (see
/// [`Normals::disagreement`]), over the points in the tree's order
/// (`pts[t]`), `normal(t)` the normal of the point at tree position `t` and
/// `neighbours(t)` the tree positions of its neighbours.
fn disagreement<I, N, F>(pts: &[[f64; 3]], normal: N, neighbours: F) -> Option<f64>
where
    I: Iterator<Item = usize>,
    N: Fn(usize) -> Vector3 + Sync,
    F: Fn(usize) -> I + Sync,
{
    let (pairs, bad) = (0..pts.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|t| {
            let (mut pairs, mut bad) = (0usize, 0usize);
            let p = Vector3::from(pts[t]);
            let a = normal(t);
            for s in neighbours(t) {
                // the normals' angle first: it needs no square root
                let b = normal(s);
                if a.dot(&b).abs() <= 0.5 {
                    continue;
                }
                // |n . d| < 0.5 |d| for both normals, squared: no square
                // root, no division (a coincident pair, |d| = 0, fails it)
                let d = Vector3::from(pts[s]) - p;
                let quarter = 0.25 * d.norm_squared();
                let (ad, bd) = (a.dot(&d), b.dot(&d));
                if ad * ad < quarter && bd * bd < quarter {
                    pairs += 1;
                    bad += usize::from(a.dot(&b) < 0.0);
                }
            }
            (pairs, bad)
        })
        .reduce(|| (0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
    (pairs > 0).then(|| bad as f64 / pairs as f64)
}

/// Undirected adjacency of the k-NN graph in compressed rows: the
/// neighbours of `i` are `targets[offsets[i]..offsets[i + 1]]` (both edge
/// directions; an edge found from both ends appears twice, which is harmless).
struct Adjacency {
    offsets: Vec<usize>,
    targets: Vec<u32>,
}

impl Adjacency {
    fn of(graph: &Neighbourhoods) -> Self {
        let n = graph.len();
        let mut offsets = vec![0usize; n + 1];
        for i in 0..n {
            offsets[i + 1] += graph.k;
            for &j in graph.indices_of(i) {
                offsets[j as usize + 1] += 1;
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut targets = vec![0u32; offsets[n]];
        for i in 0..n {
            for &j in graph.indices_of(i) {
                targets[fill[i]] = j;
                fill[i] += 1;
                targets[fill[j as usize]] = i as u32;
                fill[j as usize] += 1;
            }
        }
        Self { offsets, targets }
    }

    fn of_point(&self, i: usize) -> &[u32] {
        &self.targets[self.offsets[i]..self.offsets[i + 1]]
    }
}

/// Connected components of the (undirected) neighbour graph given as `k`
/// neighbours per point for `n` points (in any numbering: the count does not
/// depend on it), by union-find over its edges (no adjacency lists needed).
fn count_components(rows: &[u32], k: usize, n: usize) -> usize {
    let mut forest = Forest::new(n);
    let mut count = n;
    for (i, row) in rows.chunks_exact(k).enumerate() {
        for &j in row {
            count -= usize::from(forest.join(i as u32, j));
        }
    }
    count
}

/// The spanning-tree cost of the edge `i -> j` (see the module
/// documentation), in [0, 1].
fn edge_cost(points: &[Point3], normals: &[Vector3], i: usize, j: usize) -> f32 {
    let (a, b) = (normals[i], normals[j]);
    let d = points[j] - points[i];
    let len = d.norm();
    let (ta, tb) = if len > 0.0 {
        let d = d / len;
        (1.0 - a.dot(&d).abs(), 1.0 - b.dot(&d).abs())
    } else {
        (1.0, 1.0)
    };
    (1.0 - a.dot(&b).abs() * ta.max(0.0) * tb.max(0.0)).clamp(0.0, 1.0) as f32
}

/// Hoppe's orientation propagation (see the module documentation): Prim's
/// minimum spanning tree with edge cost `1 - |n_i . n_j|`, keeping for each
/// point its cheapest known edge (key) and parent, heap entries packed as
/// `(cost as f32 bits) << 32 | point` (costs are in [0, 1], where the f32
/// bit pattern orders like the value). Returns the number of components.
fn orient_by_spanning_tree(
    points: &[Point3],
    adj: &Adjacency,
    normals: &mut [Vector3],
    hint: &Vector3,
) -> usize {
    let n = points.len();
    // seeds: visit points by decreasing extent along the hint, so each
    // component starts at its extreme point
    let mut order: Vec<usize> = (0..n).collect();
    let along: Vec<f64> = points.iter().map(|p| hint.dot(&p.coords)).collect();
    order.sort_unstable_by(|&a, &b| along[b].total_cmp(&along[a]).then(a.cmp(&b)));
    let mut done = vec![false; n];
    let mut key = vec![f32::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut heap: BinaryHeap<Reverse<u64>> = BinaryHeap::new();
    let mut components = 0;
    for &seed in &order {
        if done[seed] {
            continue;
        }
        components += 1;
        if normals[seed].dot(hint) < 0.0 {
            normals[seed] = -normals[seed];
        }
        heap.push(Reverse(seed as u64));
        parent[seed] = seed as u32;
        while let Some(Reverse(entry)) = heap.pop() {
            let i = (entry & 0xffff_ffff) as usize;
            if done[i] {
                continue;
            }
            done[i] = true;
            let from = parent[i] as usize;
            if from != i && normals[i].dot(&normals[from]) < 0.0 {
                normals[i] = -normals[i];
            }
            for &j in adj.of_point(i) {
                let j = j as usize;
                if done[j] {
                    continue;
                }
                let cost = edge_cost(points, normals, i, j);
                if cost < key[j] {
                    key[j] = cost;
                    parent[j] = i as u32;
                    heap.push(Reverse(((cost.to_bits() as u64) << 32) | j as u64));
                }
            }
        }
    }
    components
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a sphere (Fibonacci lattice).
    fn sphere(n: usize, r: f64) -> Vec<Point3> {
        let g = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let s = (1.0 - z * z).sqrt();
                let a = g * i as f64;
                Point3::new(r * s * a.cos(), r * s * a.sin(), r * z)
            })
            .collect()
    }

    #[test]
    fn plane_normals_are_exact_and_point_up() {
        let mut p = Vec::new();
        for i in 0..30 {
            for j in 0..20 {
                // a tilted plane z = 0.3x - 0.2y + 5
                let (x, y) = (i as f64 * 0.1, j as f64 * 0.13);
                p.push(Point3::new(x, y, 0.3 * x - 0.2 * y + 5.0));
            }
        }
        let c = PointCloud::new(p).unwrap();
        let r = estimate_normals(&c, &NormalsConfig::default()).unwrap();
        let want = Vector3::new(-0.3, 0.2, 1.0).normalize();
        for n in &r.normals {
            assert!((n - want).norm() < 1e-10, "{n:?}");
        }
        assert!(r.variation.iter().all(|&v| v.abs() < 1e-14));
        assert_eq!(r.components, 1);
        assert!(r.degenerate.is_empty());
    }

    #[test]
    fn sphere_normals_point_outwards_by_spanning_tree_and_inwards_by_viewpoint() {
        let p = sphere(4000, 2.0);
        let c = PointCloud::new(p.clone()).unwrap();
        let r = estimate_normals(&c, &NormalsConfig::default()).unwrap();
        let mut worst: f64 = 1.0;
        for (n, q) in r.normals.iter().zip(&p) {
            worst = worst.min(n.dot(&(q.coords / 2.0)));
        }
        // every normal radial and outward (PCA error on a curved patch of 17 points)
        assert!(worst > 0.995, "worst cosine {worst}");
        let inward = estimate_normals(
            &c,
            &NormalsConfig {
                k: 16,
                orientation: Orientation::Viewpoint(Point3::origin()),
            },
        )
        .unwrap();
        assert!(inward
            .normals
            .iter()
            .zip(&p)
            .all(|(n, q)| n.dot(&q.coords) < 0.0));
    }

    /// A bust: a head (sphere of radius 1 at height 2.3) on a thin neck
    /// (cylinder of radius `neck`) on a body (ellipsoid 1.5 x 1 x 0.8), each
    /// part's points outside the others, with their true outward normals.
    pub(crate) fn bust(neck: f64) -> (Vec<Point3>, Vec<Vector3>) {
        let head_c = Point3::new(0.0, 0.0, 2.3);
        let axes = Vector3::new(1.5, 1.0, 0.8);
        let in_body = |p: &Point3| p.coords.component_div(&axes).norm() < 1.0;
        let in_head = |p: &Point3| (p - head_c).norm() < 1.0;
        let in_neck = |p: &Point3| p.x.hypot(p.y) < neck && p.z > 0.0 && p.z < head_c.z;
        let (mut p, mut n) = (Vec::new(), Vec::new());
        for q in sphere(5000, 1.0) {
            let x = head_c + q.coords;
            if !in_neck(&x) {
                p.push(x);
                n.push(q.coords);
            }
        }
        for q in sphere(6000, 1.0) {
            let x = Point3::from(q.coords.component_mul(&axes));
            if !in_neck(&x) {
                p.push(x);
                n.push(
                    x.coords
                        .component_div(&axes.component_mul(&axes))
                        .normalize(),
                );
            }
        }
        let ring = ((2.0 * std::f64::consts::PI * neck / 0.045).round() as usize).max(8);
        for k in 0..40 {
            for j in 0..ring {
                let a = (j as f64 + 0.5 * (k % 2) as f64) / ring as f64 * std::f64::consts::TAU;
                let x = Point3::new(neck * a.cos(), neck * a.sin(), 0.5 + 0.035 * k as f64);
                if !in_body(&x) && !in_head(&x) {
                    p.push(x);
                    n.push(Vector3::new(a.cos(), a.sin(), 0.0));
                }
            }
        }
        (p, n)
    }

    /// With Hoppe's cost `1 - |n_i . n_j|`, the 30 nearest neighbours of a
    /// neck of radius 0.05 (spacing about 0.045) reach across it, the tree
    /// takes a free cross edge and the body comes out inward: 45.5% of the
    /// points outward (measured before the change); with the tangent-plane
    /// factor every point is outward.
    #[test]
    fn a_bust_is_oriented_outward_across_its_thin_neck() {
        let mut s = 99u64;
        let mut rnd = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for (neck, k, noise) in [(0.05, 30, 0.0), (0.05, 30, 0.01), (0.3, 16, 0.005)] {
            let (p, truth) = bust(neck);
            let p: Vec<Point3> = p
                .iter()
                .map(|q| q + Vector3::new(rnd(), rnd(), rnd()) * noise)
                .collect();
            let c = PointCloud::new(p).unwrap();
            let cfg = NormalsConfig {
                k,
                ..Default::default()
            };
            let r = estimate_normals(&c, &cfg).unwrap();
            let outward = r
                .normals
                .iter()
                .zip(&truth)
                .filter(|(n, t)| n.dot(t) > 0.0)
                .count();
            let share = outward as f64 / truth.len() as f64;
            let dis = r.disagreement.unwrap();
            assert!(share > 0.99, "neck {neck} k {k}: {share}");
            assert!(dis < 0.01, "neck {neck} k {k}: {dis}");
        }
    }

    /// The one pass (neighbours and PCA together in the tree's order) gives
    /// what the graph built first and then summed over gives
    /// (`knn_graph_indices` + [`estimate_normals_on`], the path before the
    /// one pass), bit for bit, for each orientation: on a noisy bent sheet
    /// given in random order, a grid (tied distances everywhere, collinear
    /// rows) and the bust (two components' worth of thin neck).
    #[test]
    fn one_pass_equals_the_graph_path_bit_for_bit() {
        let mut rng = crate::testdata::Lcg::new(31);
        let mut rnd = || rng.next_f64();
        let sheet: Vec<Point3> = (0..6000)
            .map(|_| {
                let (u, v) = (rnd(), rnd());
                let z = 0.3 * (3.0 * u).sin() * v + 1e-3 * rnd();
                Point3::new(100.0 * u + 1e6, 70.0 * v - 5e5, 20.0 * z)
            })
            .collect();
        let grid: Vec<Point3> = (0..1200)
            .map(|i| Point3::new((i % 20) as f64, (i / 20 % 20) as f64, (i / 400) as f64))
            .collect();
        let orientations = [
            Orientation::None,
            Orientation::Viewpoint(Point3::new(50.0, 35.0, 1000.0)),
            Orientation::SpanningTree {
                hint: Vector3::new(0.1, 0.2, 1.0),
            },
        ];
        for (pts, k) in [(sheet, 20), (grid, 8), (bust(0.05).0, 16)] {
            let c = PointCloud::new(pts).unwrap();
            let graph = c.knn_graph_indices(k).unwrap();
            for orientation in orientations {
                let cfg = NormalsConfig { k, orientation };
                let one = estimate_normals(&c, &cfg).unwrap();
                let two = estimate_normals_on(&c, &graph, &cfg).unwrap();
                assert_eq!(one, two, "k {k}, {orientation:?}");
            }
        }
    }

    /// The disagreement counts exactly the same-sheet pairs whose normals
    /// point apart: two 30 x 30 grids 3 apart, each point joined to its
    /// grid neighbours and to its partner in the other grid. The lower grid
    /// points up except its first 10 columns, the upper grid points down:
    /// the partners' pairs are across the sheets (excluded), and of the
    /// 2 x 2 x 2 x 30 x 29 grid pairs (both directions) the 2 x 30 across
    /// the lower grid's flip disagree.
    #[test]
    fn disagreement_counts_the_flipped_pairs_of_same_sheet_neighbours() {
        let n = 30;
        let pts: Vec<[f64; 3]> = (0..2 * n * n)
            .map(|t| {
                let i = t % (n * n);
                [(i % n) as f64, (i / n) as f64, 3.0 * (t / (n * n)) as f64]
            })
            .collect();
        let normal = |t: usize| {
            if t >= n * n || t % n < 10 {
                -Vector3::z()
            } else {
                Vector3::z()
            }
        };
        let neighbours = |t: usize| {
            let (layer, i) = (t / (n * n), t % (n * n));
            let (x, y) = ((i % n) as i64, (i / n) as i64);
            let mut nb: Vec<usize> = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .map(|(dx, dy)| (x + dx, y + dy))
                .filter(|&(x, y)| (0..n as i64).contains(&x) && (0..n as i64).contains(&y))
                .map(|(x, y)| layer * n * n + (y as usize) * n + x as usize)
                .collect();
            nb.push((1 - layer) * n * n + i);
            nb.into_iter()
        };
        let share = disagreement(&pts, normal, neighbours).unwrap();
        let (bad, pairs) = (2 * n, 2 * 2 * 2 * n * (n - 1));
        assert_eq!(share, bad as f64 / pairs as f64);
        // every normal the same way: nothing disagrees; across the sheets only: no pairs
        assert_eq!(disagreement(&pts, |_| Vector3::z(), neighbours), Some(0.0));
        let across = |t: usize| std::iter::once((t + n * n) % (2 * n * n));
        assert_eq!(disagreement(&pts, normal, across), None);
    }

    #[test]
    fn separate_components_are_each_oriented() {
        let mut p = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                p.push(Point3::new(i as f64, j as f64, 0.0));
                p.push(Point3::new(i as f64 + 100.0, j as f64, 50.0));
            }
        }
        let c = PointCloud::new(p).unwrap();
        let r = estimate_normals(
            &c,
            &NormalsConfig {
                k: 8,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(r.components, 2);
        assert!(r.normals.iter().all(|n| (n - Vector3::z()).norm() < 1e-12));
    }

    #[test]
    fn bad_input() {
        let c = PointCloud::new(vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)]).unwrap();
        assert!(estimate_normals(&c, &NormalsConfig::default()).is_err());
        let line: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
        let c = PointCloud::new(line).unwrap();
        let r = estimate_normals(&c, &NormalsConfig::default()).unwrap();
        assert_eq!(r.degenerate.len(), 10);
        assert!(r
            .normals
            .iter()
            .all(|n| n.x.abs() < 1e-12 && (n.norm() - 1.0).abs() < 1e-12));
        let cfg = NormalsConfig {
            k: 1,
            ..Default::default()
        };
        assert!(estimate_normals(&c, &cfg).is_err());
    }
}
