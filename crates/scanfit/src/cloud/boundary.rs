//! Boundary loops of a sheet-like patch from its alpha shape.
//!
//! The PDE/Coons reconstruction paper (Zhu et al.,
//! §4.1) extracts the boundary of each
//! segmented subset with alpha shapes (Edelsbrunner, ref. 29 there) and
//! tunes the alpha parameter when the boundary has outliers or too few
//! points. For a patch that is a height field over its best-fit plane this
//! is done in the plane:
//!
//! 1. project the points onto the best-fit plane
//!    ([`plane_parameters`]: PCA normal,
//!    minimum-area-rectangle axes);
//! 2. Delaunay-triangulate the projections (spade);
//! 3. keep the triangles whose circumradius is below `alpha` (the alpha
//!    complex's triangles: their empty circumcircle is smaller than the
//!    alpha ball);
//! 4. boundary edges are the edges of exactly one kept triangle; oriented as
//!    in that triangle (counter-clockwise), they have the kept region on their
//!    left, so chaining them gives the outer loop counter-clockwise and hole
//!    loops clockwise in the plane frame `(e1, e2)` (seen from the side the
//!    plane normal points to).
//!
//! Where two loops touch at one point (a pinch vertex, two kept wedges meeting
//! at a vertex), the chain leaving the vertex is the first boundary edge
//! clockwise from the incoming edge's reverse: the edge that closes the same
//! kept wedge. Each loop is then a simple polygon and the result does not
//! depend on the order the edges were found in.

use std::collections::HashMap;

use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use crate::base::plane_parameters;
use crate::{Error, Point3, Result, Vector3};

/// Parameters of [`boundary_loops`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryConfig {
    /// The alpha radius, in the units of the points: triangles with a
    /// circumradius below it are kept. `None` (default) takes
    /// `alpha_factor` times the point spacing, the median edge length of
    /// the Delaunay triangulation of the projected points.
    pub alpha: Option<f64>,
    /// Multiple of the spacing used when `alpha` is `None`. Default `2.5`.
    ///
    /// The spacing is the median Delaunay edge length rather than the
    /// median nearest-neighbour distance because it measures the same
    /// density alike for regular and random samples: one grid step on a
    /// grid, about `1.07 / sqrt(density)` on a uniform random sample, whose
    /// median nearest-neighbour distance is only `0.47 / sqrt(density)`
    /// (random points cluster). A regular grid needs a factor above
    /// `sqrt(2)/2` (its triangles' circumradius); a random sample's largest
    /// empty circles grow like `sqrt(ln n)` and reach about 2.3 spacings at
    /// 10^5 points, so 2.5 leaves no spurious interior holes up to
    /// ~10^6 points, while a real hole wider than about `2 * alpha_factor`
    /// spacings stays open. The tests of this module measure both.
    pub alpha_factor: f64,
}

impl Default for BoundaryConfig {
    fn default() -> Self {
        Self {
            alpha: None,
            alpha_factor: 2.5,
        }
    }
}

/// The plane the boundary was computed in (right-handed: `e1 x e2 = normal`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryPlane {
    /// Centroid of the points.
    pub origin: Point3,
    /// First in-plane axis (the long side of the minimum-area rectangle).
    pub e1: Vector3,
    /// Second in-plane axis.
    pub e2: Vector3,
    /// Unit normal; loops are counter-clockwise (outer) or clockwise (holes)
    /// seen from this side.
    pub normal: Vector3,
}

impl BoundaryPlane {
    /// In-plane coordinates `((p - origin) . e1, (p - origin) . e2)`.
    pub fn project(&self, p: &Point3) -> [f64; 2] {
        let d = p - self.origin;
        [d.dot(&self.e1), d.dot(&self.e2)]
    }
}

/// Boundary loops of a patch.
#[derive(Debug, Clone, PartialEq)]
pub struct Boundary {
    /// Closed loops as indices into the input points, in order, the first
    /// point not repeated at the end.
    pub loops: Vec<Vec<usize>>,
    /// Index into `loops` of the outer loop (largest enclosed area).
    pub outer: usize,
    /// Signed area of each loop in the plane frame: positive for
    /// counter-clockwise loops (the outer one), negative for holes.
    pub areas: Vec<f64>,
    /// The alpha radius used.
    pub alpha: f64,
    /// Median Delaunay edge length of the projected points (the grid step
    /// of a regular grid).
    pub spacing: f64,
    /// Number of Delaunay triangles kept (circumradius below `alpha`).
    pub triangles: usize,
    /// The plane of the projection.
    pub plane: BoundaryPlane,
}

impl Boundary {
    /// The outer loop.
    pub fn outer_loop(&self) -> &[usize] {
        self.loops.get(self.outer).map_or(&[], Vec::as_slice)
    }
}

#[derive(Debug, Clone, Copy)]
struct Vertex {
    pos: Point2<f64>,
    index: usize,
}

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// The boundary loops of a sheet-like patch: alpha shape of its projection
/// on the best-fit plane ([PDE23] §4.1, alpha shapes after Edelsbrunner).
///
/// Points that project onto the same spot are represented by the first of
/// them (smallest index); the others are on no loop.
///
/// Errors: fewer than 3 points; collinear or coincident points; a given
/// `alpha` or `alpha_factor` that is not finite and positive; an `alpha` so
/// small that no triangle is kept (raise it).
pub fn boundary_loops(points: &[Point3], config: &BoundaryConfig) -> Result<Boundary> {
    if points.len() < 3 {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: 3,
            what: "a boundary loop".into(),
        });
    }
    if !(config.alpha_factor.is_finite() && config.alpha_factor > 0.0) {
        return Err(Error::InvalidInput(format!(
            "alpha_factor = {} must be finite and > 0 (default 2.5)",
            config.alpha_factor
        )));
    }
    if let Some(a) = config.alpha {
        if !(a.is_finite() && a > 0.0) {
            return Err(Error::InvalidInput(format!(
                "alpha = {a} must be finite and > 0 (a radius in the points' units; None picks one from the spacing)"
            )));
        }
    }
    let pp = plane_parameters(points)?;
    let plane = BoundaryPlane {
        origin: pp.origin,
        e1: pp.e1,
        e2: pp.e2,
        normal: pp.normal,
    };
    let flat: Vec<[f64; 2]> = points.iter().map(|p| plane.project(p)).collect();
    // spade rejects coordinates below ~1e-42 in magnitude: work in units of
    // the extent, with negligible values set to zero
    let extent = flat
        .iter()
        .flat_map(|q| q.iter().map(|c| c.abs()))
        .fold(0.0f64, f64::max);
    if extent == 0.0 {
        return Err(Error::InvalidInput(
            "all points coincide in the plane: no boundary".into(),
        ));
    }
    let unit = |c: f64| {
        let v = c / extent;
        if v.abs() < 1e-30 {
            0.0
        } else {
            v
        }
    };
    let verts: Vec<Vertex> = flat
        .iter()
        .enumerate()
        .map(|(index, q)| Vertex {
            pos: Point2::new(unit(q[0]), unit(q[1])),
            index,
        })
        .collect();
    let tri: DelaunayTriangulation<Vertex> = DelaunayTriangulation::bulk_load(verts)
        .map_err(|e| Error::InvalidInput(format!("the plane triangulation failed: {e:?}")))?;
    if tri.num_inner_faces() == 0 {
        return Err(Error::InvalidInput(
            "the points are collinear in their best-fit plane: they bound no area".into(),
        ));
    }
    // typical spacing: the median Delaunay edge length
    let mut lengths: Vec<f64> = tri.undirected_edges().map(|e| e.length_2()).collect();
    let mid = lengths.len() / 2;
    let (_, &mut median, _) = lengths.select_nth_unstable_by(mid, f64::total_cmp);
    let median = median.sqrt();
    let spacing = median * extent;
    let alpha = config.alpha.unwrap_or(config.alpha_factor * spacing);
    let alpha_unit = alpha / extent;
    // keep the triangles with circumradius R = abc / (4 area) below alpha
    let mut kept = vec![false; tri.all_faces().len()];
    let mut n_kept = 0;
    for f in tri.inner_faces() {
        let [a, b, c] = f.positions();
        let (la, lb, lc) = (dist(b, c), dist(a, c), dist(a, b));
        let area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        if area2 > 0.0 && la * lb * lc < 2.0 * area2 * alpha_unit {
            kept[f.fix().index()] = true;
            n_kept += 1;
        }
    }
    if n_kept == 0 {
        return Err(Error::InvalidInput(format!(
            "alpha = {alpha:e} keeps no triangle (point spacing {spacing:e}); raise alpha or alpha_factor"
        )));
    }
    // boundary edges, kept triangle on the left: (from, to) as vertex handles
    let mut edges: Vec<(usize, usize)> = Vec::new();
    for f in tri.inner_faces() {
        if !kept[f.fix().index()] {
            continue;
        }
        for e in f.adjacent_edges() {
            let other = e.rev().face();
            let other_kept = other.as_inner().is_some() && kept[other.fix().index()];
            if !other_kept {
                edges.push((e.from().fix().index(), e.to().fix().index()));
            }
        }
    }
    let pos: Vec<[f64; 2]> = tri
        .vertices()
        .map(|v| [v.position().x, v.position().y])
        .collect();
    // spade keeps one of several identical positions, not necessarily the
    // first: represent each position by its smallest input index
    let key = |p: Point2<f64>| (p.x.to_bits(), p.y.to_bits());
    let mut first_of: HashMap<(u64, u64), usize> = HashMap::with_capacity(tri.num_vertices());
    for v in tri.vertices() {
        first_of.insert(key(v.position()), v.data().index);
    }
    if tri.num_vertices() < points.len() {
        for (i, q) in flat.iter().enumerate() {
            let k = key(Point2::new(unit(q[0]), unit(q[1])));
            if let Some(slot) = first_of.get_mut(&k) {
                *slot = (*slot).min(i);
            }
        }
    }
    let index_of: Vec<usize> = tri
        .vertices()
        .map(|v| {
            first_of
                .get(&key(v.position()))
                .copied()
                .unwrap_or(v.data().index)
        })
        .collect();
    let loops_v = chain(&edges, &pos, tri.num_vertices())?;
    let mut loops: Vec<Vec<usize>> = Vec::with_capacity(loops_v.len());
    let mut areas = Vec::with_capacity(loops_v.len());
    for lv in loops_v {
        let mut a = 0.0;
        for k in 0..lv.len() {
            let (p, q) = (pos[lv[k]], pos[lv[(k + 1) % lv.len()]]);
            a += p[0] * q[1] - p[1] * q[0];
        }
        areas.push(0.5 * a * extent * extent);
        loops.push(lv.into_iter().map(|v| index_of[v]).collect());
    }
    let outer = (0..areas.len())
        .max_by(|&i, &j| areas[i].abs().total_cmp(&areas[j].abs()))
        .unwrap_or(0);
    Ok(Boundary {
        loops,
        outer,
        areas,
        alpha,
        spacing,
        triangles: n_kept,
        plane,
    })
}

fn dist(a: Point2<f64>, b: Point2<f64>) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// Chains directed boundary edges into closed loops (vertex ids). At a
/// vertex with several outgoing edges the first one clockwise from the
/// incoming edge's reverse is taken (it bounds the same kept wedge).
fn chain(edges: &[(usize, usize)], pos: &[[f64; 2]], nv: usize) -> Result<Vec<Vec<usize>>> {
    // outgoing edges per vertex (CSR), in a deterministic order
    let mut order: Vec<usize> = (0..edges.len()).collect();
    order.sort_unstable_by_key(|&e| edges[e]);
    let mut start = vec![0usize; nv + 1];
    for &(u, _) in edges {
        start[u + 1] += 1;
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let out: Vec<usize> = order; // sorted by from-vertex, so CSR-compatible
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for &first in &out {
        if used[first] {
            continue;
        }
        let mut lp = Vec::new();
        let mut e = first;
        loop {
            used[e] = true;
            let (u, v) = edges[e];
            lp.push(u);
            let cands = &out[start[v]..start[v + 1]];
            let next = match cands {
                [] => {
                    return Err(Error::InvalidInput(format!(
                        "boundary chaining: vertex {v} has no outgoing boundary edge; this is a bug"
                    )))
                }
                [only] => *only,
                _ => {
                    let back = [pos[u][0] - pos[v][0], pos[u][1] - pos[v][1]];
                    let cw_angle = |c: usize| {
                        let w = pos[edges[c].1];
                        let d = [w[0] - pos[v][0], w[1] - pos[v][1]];
                        // clockwise angle from `back` to `d`, in (0, 2 pi]
                        let t = (d[0] * back[1] - d[1] * back[0])
                            .atan2(d[0] * back[0] + d[1] * back[1]);
                        if t <= 0.0 {
                            t + std::f64::consts::TAU
                        } else {
                            t
                        }
                    };
                    cands
                        .iter()
                        .copied()
                        .min_by(|&a, &b| cw_angle(a).total_cmp(&cw_angle(b)))
                        .unwrap_or(cands[0])
                }
            };
            if next == first {
                break;
            }
            if used[next] || lp.len() > edges.len() {
                return Err(Error::InvalidInput(
                    "boundary chaining: a boundary edge was reached twice; this is a bug".into(),
                ));
            }
            e = next;
        }
        loops.push(lp);
    }
    Ok(loops)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::testutil::Rng;

    fn grid(nx: usize, ny: usize, keep: impl Fn(f64, f64) -> bool) -> Vec<Point3> {
        let mut p = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (i as f64, j as f64);
                if keep(x, y) {
                    p.push(Point3::new(x, y, 0.02 * (0.3 * x).sin() * (0.2 * y).cos()));
                }
            }
        }
        p
    }

    #[test]
    fn grid_rectangle_outer_loop_is_its_156_border_points_in_order() {
        let p = grid(50, 30, |_, _| true);
        let b = boundary_loops(&p, &BoundaryConfig::default()).unwrap();
        assert_eq!(b.loops.len(), 1);
        let lp = b.outer_loop();
        assert_eq!(lp.len(), 2 * (49 + 29));
        assert!((b.spacing - 1.0).abs() < 1e-3, "{}", b.spacing);
        assert!(b.areas[b.outer] > 0.0);
        assert!((b.areas[b.outer].abs() - 49.0 * 29.0).abs() < 0.1);
        assert_eq!(b.triangles, 2 * 49 * 29);
        // consecutive loop points are grid neighbours on the border
        for k in 0..lp.len() {
            let (a, c) = (p[lp[k]], p[lp[(k + 1) % lp.len()]]);
            assert!(((a - c).xy().norm() - 1.0).abs() < 1e-9);
            let on_border = |q: Point3| q.x == 0.0 || q.x == 49.0 || q.y == 0.0 || q.y == 29.0;
            assert!(on_border(a));
        }
        let mut sorted = lp.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 156);
        // duplicated points: the first copy represents them, same loop
        let mut twice = p.clone();
        twice.extend(p.iter().copied());
        let b2 = boundary_loops(&twice, &BoundaryConfig::default()).unwrap();
        assert_eq!(b2.loops, b.loops);
    }

    #[test]
    fn disc_with_square_hole_gives_ccw_outer_and_cw_hole() {
        // grid samples of a disc of radius 20 minus the square |x|,|y| < 5
        let p = grid(41, 41, |x, y| {
            let (x, y) = (x - 20.0, y - 20.0);
            x.hypot(y) <= 20.0 && !(x.abs() < 5.0 && y.abs() < 5.0)
        });
        let b = boundary_loops(&p, &BoundaryConfig::default()).unwrap();
        assert_eq!(b.loops.len(), 2, "{:?}", b.areas);
        let hole = 1 - b.outer;
        assert!(b.areas[b.outer] > 0.0 && b.areas[hole] < 0.0);
        assert!((b.areas[b.outer] - std::f64::consts::PI * 400.0).abs() < 60.0);
        // the hole loop runs on the square's border |x|,|y| = 5; alpha
        // triangles (circumradius sqrt(2) < 2.5) cut each corner from
        // (5, 3) to (3, 5): area 100 - 4 * 2, three points fewer per corner
        for &i in &b.loops[hole] {
            let (x, y) = (p[i].x - 20.0, p[i].y - 20.0);
            assert!(x.abs().max(y.abs()) == 5.0);
        }
        assert!((b.areas[hole] + 92.0).abs() < 0.01, "{}", b.areas[hole]);
        assert_eq!(b.loops[hole].len(), 40 - 4 * 3);
    }

    #[test]
    fn random_square_samples_enclose_the_square_without_spurious_holes() {
        for (n, seed) in [(2_000, 1), (20_000, 2), (100_000, 3)] {
            let mut rng = Rng::new(seed);
            let p: Vec<Point3> = (0..n)
                .map(|_| Point3::new(rng.uniform(), rng.uniform(), 0.001 * rng.normal()))
                .collect();
            let b = boundary_loops(&p, &BoundaryConfig::default()).unwrap();
            let area = b.areas[b.outer];
            assert!(area > 0.95 && area <= 1.0, "n = {n}: area {area}");
            assert_eq!(b.loops.len(), 1, "n = {n}: {:?}", b.areas);
        }
    }

    #[test]
    fn alpha_factor_choice_is_measured() {
        // a random sample has empty circles of ~2.3 spacings (median Delaunay
        // edge) at 10^5 points: factor 1.5 opens spurious holes, 2.5 does not
        let mut rng = Rng::new(8);
        let p: Vec<Point3> = (0..50_000)
            .map(|_| Point3::new(rng.uniform(), rng.uniform(), 0.0))
            .collect();
        let loops = |f: f64| {
            let cfg = BoundaryConfig {
                alpha: None,
                alpha_factor: f,
            };
            boundary_loops(&p, &cfg).unwrap().loops.len()
        };
        assert!(loops(1.5) > 10);
        assert_eq!(loops(2.5), 1);
        // the disc's hole, 10 spacings wide, stays open up to factor 4
        let disc = grid(41, 41, |x, y| {
            let (x, y) = (x - 20.0, y - 20.0);
            x.hypot(y) <= 20.0 && !(x.abs() < 5.0 && y.abs() < 5.0)
        });
        let n_loops = |f: f64| {
            let cfg = BoundaryConfig {
                alpha: None,
                alpha_factor: f,
            };
            boundary_loops(&disc, &cfg).unwrap().loops.len()
        };
        for f in [1.0, 2.5, 4.0] {
            assert_eq!(n_loops(f), 2, "factor {f}");
        }
        assert_eq!(n_loops(5.0), 1);
    }

    #[test]
    fn pinch_vertex_splits_into_two_simple_loops() {
        // two triangular-lattice triangles (side 5, spacing 1) touching at
        // the origin: wedges 0..60 and 180..240 degrees, bridging triangles
        // have circumradius 1, lattice ones 1/sqrt(3)
        let h = 3f64.sqrt() / 2.0;
        let mut p = vec![Point3::origin()];
        for sign in [1.0, -1.0] {
            for a in 0..=5 {
                for b in 0..=5 - a {
                    if a + b > 0 {
                        let (x, y) = (a as f64 + 0.5 * b as f64, h * b as f64);
                        p.push(Point3::new(sign * x, sign * y, 0.0));
                    }
                }
            }
        }
        let cfg = BoundaryConfig {
            alpha: Some(0.8),
            ..Default::default()
        };
        let b = boundary_loops(&p, &cfg).unwrap();
        assert_eq!(b.loops.len(), 2);
        for (lp, a) in b.loops.iter().zip(&b.areas) {
            assert_eq!(lp.len(), 15);
            assert!(lp.contains(&0), "the pinch point is on both loops");
            assert!(*a > 0.0 && (a - 25.0 * h / 2.0).abs() < 1e-9, "{a}");
            let mut sorted = lp.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), 15, "a loop repeats a point");
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        let q = |x: f64, y: f64| Point3::new(x, y, 0.0);
        assert!(matches!(
            boundary_loops(&[q(0., 0.), q(1., 0.)], &BoundaryConfig::default()),
            Err(Error::TooFewPoints {
                got: 2,
                needed: 3,
                ..
            })
        ));
        let line: Vec<Point3> = (0..10).map(|i| q(i as f64, 2.0 * i as f64)).collect();
        assert!(format!(
            "{}",
            boundary_loops(&line, &BoundaryConfig::default()).unwrap_err()
        )
        .contains("collinear"));
        let p = grid(5, 5, |_, _| true);
        for alpha in [Some(0.0), Some(f64::NAN), Some(-1.0)] {
            assert!(boundary_loops(
                &p,
                &BoundaryConfig {
                    alpha,
                    ..Default::default()
                }
            )
            .is_err());
        }
        let err = boundary_loops(
            &p,
            &BoundaryConfig {
                alpha: Some(0.1),
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(format!("{err}").contains("keeps no triangle"));
    }
}
