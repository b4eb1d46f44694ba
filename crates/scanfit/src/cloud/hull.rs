//! Convex hull of a 3D point set: quickhull (Barber, Dobkin & Huhdanpaa
//! 1996, "The quickhull algorithm for convex hulls") on exact orientation
//! predicates.
//!
//! Every "is point `q` above face `abc`" decision is exact: a floating-point
//! filter (the face normal times `q - a`, trusted when it exceeds the
//! rounding-error bound of Shewchuk's orient3d) and otherwise Shewchuk's
//! adaptive exact `orient3d` (the `robust` crate), so coplanar and duplicate points
//! never make the algorithm inconsistent: a point exactly on a face plane
//! counts as inside, and the hull is always a closed, outward-oriented
//! triangulated polytope. Floating-point plane distances are only used to pick
//! the farthest outside point of a face (quickhull's choice of the next
//! vertex), which affects speed, not correctness.
//!
//! Input that spans no volume (fewer than 4 points, all points coincident,
//! collinear or coplanar within [`DEGENERACY_TOLERANCE`] of the extent) is an
//! error, never a panic.

use robust::{orient3d, Coord3D};

use crate::{validate_points, Error, Point3, Result};

/// Relative tolerance below which the point set counts as degenerate: the
/// largest distance of a point from the line (plane) through the initial
/// simplex's points is compared with `DEGENERACY_TOLERANCE` times the largest
/// pairwise distance of the axis-extreme points.
pub const DEGENERACY_TOLERANCE: f64 = 1e-10;

const NIL: u32 = u32::MAX;

/// A convex hull as a closed triangle mesh over the input points.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexHull {
    /// Triangles as indices into the input points, counter-clockwise seen
    /// from outside: `(b - a) x (c - a)` points out of the hull. Faces of a
    /// planar facet with more than three vertices are triangulated
    /// (coplanar neighbouring triangles are not merged).
    pub faces: Vec<[usize; 3]>,
    /// Indices of the points that are hull vertices, sorted ascending. Of
    /// duplicate points only one is a vertex.
    pub vertices: Vec<usize>,
}

impl ConvexHull {
    /// Enclosed volume (divergence theorem over the faces). `points` must be
    /// the points the hull was computed from.
    pub fn volume(&self, points: &[Point3]) -> Result<f64> {
        let Some(&[o, _, _]) = self.faces.first() else {
            return Ok(0.0);
        };
        let o = self.point(points, o)?;
        let mut sum = 0.0;
        for &[a, b, c] in &self.faces {
            let [a, b, c] = [a, b, c].map(|i| self.point(points, i));
            sum += (a? - o).dot(&(b? - o).cross(&(c? - o)));
        }
        Ok(sum / 6.0)
    }

    /// Surface area. `points` must be the points the hull was computed from.
    pub fn area(&self, points: &[Point3]) -> Result<f64> {
        let mut sum = 0.0;
        for &[a, b, c] in &self.faces {
            let [a, b, c] = [a, b, c].map(|i| self.point(points, i));
            let a = a?;
            sum += 0.5 * (b? - a).cross(&(c? - a)).norm();
        }
        Ok(sum)
    }

    fn point(&self, points: &[Point3], i: usize) -> Result<Point3> {
        points.get(i).copied().ok_or_else(|| {
            Error::InvalidInput(format!(
                "hull vertex {i} is out of range for {} points; pass the points the hull was computed from",
                points.len()
            ))
        })
    }
}

#[derive(Debug, Clone)]
struct Face {
    /// Vertices, counter-clockwise seen from outside.
    v: [u32; 3],
    /// `nb[i]`: the face across edge `(v[i], v[(i + 1) % 3])`.
    nb: [u32; 3],
    /// Outward normal `(b - a) x (c - a)` as computed in floating point.
    n: [f64; 3],
    /// `|u_y v_z| + |u_z v_y|`, ... for `u = b - a`, `v = c - a`: the
    /// magnitudes behind `n`, for the rounding-error bound of `n . (q - a)`.
    perm: [f64; 3],
    /// `1 / |n|`, to turn `n . (q - a)` into a distance.
    inv_len: f64,
    /// First point of the outside set (linked through `Hull::next`).
    head: u32,
    /// Farthest outside point and its distance.
    far: u32,
    far_d: f64,
    alive: bool,
    /// Visibility bookkeeping of the current iteration.
    stamp: u32,
    visible: bool,
}

struct Hull<'a> {
    p: &'a [[f64; 3]],
    faces: Vec<Face>,
    free: Vec<u32>,
    /// Outside-set links: `next[q]` follows point `q` in its face's list.
    next: Vec<u32>,
}

pub(super) fn c3(p: &[f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl Hull<'_> {
    /// Whether `q` is strictly above (outside) the plane of face `f` (exact).
    fn above(&self, f: u32, q: u32) -> bool {
        let face = &self.faces[f as usize];
        let v = face.v;
        // floating-point filter: the determinant n . (q - a) with the error
        // bound of Shewchuk's orient3d, (7 + 56 eps) eps * permanent, rounded
        // up to 1e-15 (~9 eps); undecided cases go to the exact predicate
        let d = sub(&self.p[q as usize], &self.p[v[0] as usize]);
        let det = dot(&face.n, &d);
        let bound = 1e-15
            * (face.perm[0] * d[0].abs() + face.perm[1] * d[1].abs() + face.perm[2] * d[2].abs());
        if det > bound {
            return true;
        }
        if det < -bound {
            return false;
        }
        // robust's orient3d is negative when the fourth point is on the side
        // from which the first three appear counter-clockwise
        orient3d(
            c3(&self.p[v[0] as usize]),
            c3(&self.p[v[1] as usize]),
            c3(&self.p[v[2] as usize]),
            c3(&self.p[q as usize]),
        ) < 0.0
    }

    fn new_face(&mut self, v: [u32; 3]) -> u32 {
        let [a, b, c] = v.map(|i| &self.p[i as usize]);
        let (u, w) = (sub(b, a), sub(c, a));
        let n = cross(&u, &w);
        let perm = [
            (u[1] * w[2]).abs() + (u[2] * w[1]).abs(),
            (u[2] * w[0]).abs() + (u[0] * w[2]).abs(),
            (u[0] * w[1]).abs() + (u[1] * w[0]).abs(),
        ];
        let len = norm(&n);
        let face = Face {
            v,
            nb: [NIL; 3],
            n,
            perm,
            inv_len: if len > 0.0 { 1.0 / len } else { 0.0 },
            head: NIL,
            far: NIL,
            far_d: f64::NEG_INFINITY,
            alive: true,
            stamp: 0,
            visible: false,
        };
        match self.free.pop() {
            Some(id) => {
                self.faces[id as usize] = face;
                id
            }
            None => {
                self.faces.push(face);
                (self.faces.len() - 1) as u32
            }
        }
    }

    /// Adds `q` to the outside set of the first face of `candidates` it is
    /// strictly above; returns whether it was outside any.
    fn assign(&mut self, q: u32, candidates: &[u32]) -> bool {
        for &f in candidates {
            if self.above(f, q) {
                let face = &mut self.faces[f as usize];
                let a = &self.p[face.v[0] as usize];
                let d = dot(&face.n, &sub(&self.p[q as usize], a)) * face.inv_len;
                self.next[q as usize] = face.head;
                face.head = q;
                if d > face.far_d {
                    face.far_d = d;
                    face.far = q;
                }
                return true;
            }
        }
        false
    }

    /// Points `nb` of face `f` at face `g` across the edge `(a, b)` of `f`.
    fn link(&mut self, f: u32, a: u32, b: u32, g: u32) -> Result<()> {
        let face = &mut self.faces[f as usize];
        for i in 0..3 {
            if face.v[i] == a && face.v[(i + 1) % 3] == b {
                face.nb[i] = g;
                return Ok(());
            }
        }
        Err(internal("a face lost its neighbour across a horizon edge"))
    }
}

fn internal(what: &str) -> Error {
    Error::InvalidInput(format!(
        "convex hull: inconsistent topology ({what}); this is a bug, please report it with the input points"
    ))
}

/// The convex hull of `points` (quickhull, Barber et al. 1996, with exact
/// `orient3d` predicates).
///
/// Errors: fewer than 4 points; all points coincident, collinear or
/// coplanar (relative to [`DEGENERACY_TOLERANCE`]); more than 2^32 - 1
/// points; non-finite coordinates.
pub fn convex_hull(points: &[Point3]) -> Result<ConvexHull> {
    validate_points(points)?;
    if points.len() < 4 {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: 4,
            what: "a 3D convex hull".into(),
        });
    }
    let p: Vec<[f64; 3]> = points.iter().map(|q| [q.x, q.y, q.z]).collect();
    hull_of_coordinates(p)
}

/// [`convex_hull`] of points given as coordinate triples, already checked
/// to be at least 4 and finite; they are scaled in place.
pub(crate) fn hull_of_coordinates(mut p: Vec<[f64; 3]>) -> Result<ConvexHull> {
    if p.len() >= NIL as usize {
        return Err(Error::InvalidInput(format!(
            "{} points exceed the convex hull's limit of 2^32 - 1; thin the cloud",
            p.len()
        )));
    }
    // scale by a power of two (exact) so that orient3d's products cannot overflow
    let max_abs = p.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
    let scale = if max_abs > 0.0 {
        2f64.powi(-(max_abs.log2().ceil() as i32))
    } else {
        1.0
    };
    for q in &mut p {
        *q = q.map(|c| c * scale);
    }
    let simplex = initial_simplex(&p)?;
    let faces = quickhull(&p, simplex)?;
    let mut is_vertex = vec![false; p.len()];
    for &v in faces.iter().flatten() {
        is_vertex[v] = true;
    }
    let vertices: Vec<usize> = (0..p.len()).filter(|&i| is_vertex[i]).collect();
    Ok(ConvexHull { faces, vertices })
}

/// Four affinely independent points (indices), or an error naming the
/// degeneracy.
fn initial_simplex(p: &[[f64; 3]]) -> Result<[u32; 4]> {
    let mut ext = [0usize; 6];
    for (i, q) in p.iter().enumerate() {
        for k in 0..3 {
            if q[k] < p[ext[2 * k]][k] {
                ext[2 * k] = i;
            }
            if q[k] > p[ext[2 * k + 1]][k] {
                ext[2 * k + 1] = i;
            }
        }
    }
    let (mut a, mut b, mut best) = (0, 0, 0.0);
    for &i in &ext {
        for &j in &ext {
            let d = norm(&sub(&p[i], &p[j]));
            if d > best {
                (a, b, best) = (i, j, d);
            }
        }
    }
    if best == 0.0 {
        return Err(Error::InvalidInput(
            "all points coincide: a convex hull needs points spanning a volume".into(),
        ));
    }
    let tol = DEGENERACY_TOLERANCE * best;
    let ab = sub(&p[b], &p[a]);
    let (mut c, mut best_c) = (0, -1.0);
    for (i, q) in p.iter().enumerate() {
        let d = norm(&cross(&ab, &sub(q, &p[a]))) / best;
        if d > best_c {
            (c, best_c) = (i, d);
        }
    }
    if best_c <= tol {
        return Err(Error::InvalidInput(format!(
            "all points are collinear (farthest point {c} is {best_c:e} from the line through points {a} and {b}, extent {best:e}); a convex hull needs points spanning a volume"
        )));
    }
    let n = cross(&ab, &sub(&p[c], &p[a]));
    let nl = norm(&n);
    let (mut d, mut best_d) = (0, -1.0);
    for (i, q) in p.iter().enumerate() {
        let dist = dot(&n, &sub(q, &p[a])).abs() / nl;
        if dist > best_d {
            (d, best_d) = (i, dist);
        }
    }
    if best_d <= tol {
        return Err(Error::InvalidInput(format!(
            "all points are coplanar (farthest point {d} is {best_d:e} from the plane through points {a}, {b}, {c}, extent {best:e}); a convex hull needs points spanning a volume (for planar data use a 2D method)"
        )));
    }
    Ok([a as u32, b as u32, c as u32, d as u32])
}

fn quickhull(p: &[[f64; 3]], s: [u32; 4]) -> Result<Vec<[usize; 3]>> {
    let n = p.len();
    let mut h = Hull {
        p,
        faces: Vec::with_capacity(64),
        free: Vec::new(),
        next: vec![NIL; n],
    };
    // the tetrahedron, each face oriented away from the opposite vertex
    let tri = [[0, 1, 2, 3], [0, 3, 1, 2], [1, 3, 2, 0], [0, 2, 3, 1]];
    for t in tri {
        let (mut v, opp) = ([s[t[0]], s[t[1]], s[t[2]]], s[t[3]]);
        let [a, b, c, d] = [v[0], v[1], v[2], opp].map(|i| c3(&p[i as usize]));
        if orient3d(a, b, c, d) < 0.0 {
            // the opposite vertex is above: flip
            v.swap(1, 2);
        }
        h.new_face(v);
    }
    // neighbours by edge matching
    for f in 0..4 {
        for i in 0..3 {
            let (a, b) = (h.faces[f].v[i], h.faces[f].v[(i + 1) % 3]);
            let g = (0..4)
                .find(|&g| {
                    g != f && (0..3).any(|j| h.faces[g].v[j] == b && h.faces[g].v[(j + 1) % 3] == a)
                })
                .ok_or_else(|| internal("the initial tetrahedron is not closed"))?;
            h.faces[f].nb[i] = g as u32;
        }
    }
    let first: Vec<u32> = (0..4).collect();
    for q in 0..n as u32 {
        if !s.contains(&q) {
            h.assign(q, &first);
        }
    }
    let mut stack: Vec<u32> = first
        .iter()
        .copied()
        .filter(|&f| h.faces[f as usize].head != NIL)
        .collect();
    let mut start_of = vec![NIL; n];
    let mut visible: Vec<u32> = Vec::new();
    let mut horizon: Vec<(u32, u32, u32)> = Vec::new();
    let mut new_faces: Vec<u32> = Vec::new();
    let mut iter: u32 = 0;
    while let Some(f) = stack.pop() {
        let face = &h.faces[f as usize];
        if !face.alive || face.head == NIL {
            continue;
        }
        let q = face.far;
        iter = iter.wrapping_add(1);
        if iter == 0 {
            for face in &mut h.faces {
                face.stamp = 0;
            }
            iter = 1;
        }
        // faces strictly visible from q: a connected set around f
        visible.clear();
        visible.push(f);
        h.faces[f as usize].stamp = iter;
        h.faces[f as usize].visible = true;
        let mut k = 0;
        while k < visible.len() {
            let g = visible[k];
            for e in 0..3 {
                let nb = h.faces[g as usize].nb[e];
                if h.faces[nb as usize].stamp == iter {
                    continue;
                }
                let vis = h.above(nb, q);
                let nf = &mut h.faces[nb as usize];
                nf.stamp = iter;
                nf.visible = vis;
                if vis {
                    visible.push(nb);
                }
            }
            k += 1;
        }
        // horizon: edges between visible and invisible faces
        horizon.clear();
        for &g in &visible {
            let face = &h.faces[g as usize];
            for e in 0..3 {
                let nb = face.nb[e];
                if !h.faces[nb as usize].visible {
                    horizon.push((face.v[e], face.v[(e + 1) % 3], nb));
                }
            }
        }
        // the cone of new faces from the horizon to q
        new_faces.clear();
        for &(a, b, nb) in &horizon {
            let id = h.new_face([a, b, q]);
            h.faces[id as usize].nb[0] = nb;
            h.link(nb, b, a, id)?;
            if start_of[a as usize] != NIL {
                return Err(internal("the horizon is not a simple cycle"));
            }
            start_of[a as usize] = id;
            new_faces.push(id);
        }
        for &id in &new_faces {
            let b = h.faces[id as usize].v[1];
            let other = start_of[b as usize];
            if other == NIL {
                return Err(internal("the horizon is not closed"));
            }
            h.faces[id as usize].nb[1] = other;
            h.faces[other as usize].nb[2] = id;
        }
        for &(a, _, _) in &horizon {
            start_of[a as usize] = NIL;
        }
        // hand the outside points of the removed faces to the new ones
        for &g in &visible {
            let mut r = h.faces[g as usize].head;
            while r != NIL {
                let next = h.next[r as usize];
                if r != q {
                    h.assign(r, &new_faces);
                }
                r = next;
            }
            let face = &mut h.faces[g as usize];
            face.alive = false;
            face.visible = false;
            face.head = NIL;
            h.free.push(g);
        }
        for &id in &new_faces {
            if h.faces[id as usize].head != NIL {
                stack.push(id);
            }
        }
    }
    Ok(h.faces
        .iter()
        .filter(|f| f.alive)
        .map(|f| f.v.map(|v| v as usize))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::testutil::Rng;

    /// Brute force: all triples whose plane has every point on its inner
    /// side (strictly, for points in general position), oriented outward.
    fn brute_force_faces(p: &[Point3]) -> Vec<[usize; 3]> {
        let c = |q: &Point3| Coord3D {
            x: q.x,
            y: q.y,
            z: q.z,
        };
        let n = p.len();
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    let signs: Vec<f64> = (0..n)
                        .filter(|&m| m != i && m != j && m != k)
                        .map(|m| orient3d(c(&p[i]), c(&p[j]), c(&p[k]), c(&p[m])))
                        .collect();
                    if signs.iter().all(|&s| s > 0.0) {
                        out.push(canonical([i, j, k]));
                    } else if signs.iter().all(|&s| s < 0.0) {
                        out.push(canonical([i, k, j]));
                    }
                }
            }
        }
        out.sort_unstable();
        out
    }

    /// Rotates a triangle so its smallest index comes first (keeps orientation).
    fn canonical(t: [usize; 3]) -> [usize; 3] {
        let m = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
        [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
    }

    /// Checks closedness (every directed edge has its reverse exactly once),
    /// Euler's formula and that every point is inside or on every face.
    fn check_hull(p: &[Point3], hull: &ConvexHull) {
        use std::collections::HashMap;
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        for &[a, b, c] in &hull.faces {
            for (x, y) in [(a, b), (b, c), (c, a)] {
                *edges.entry((x, y)).or_default() += 1;
            }
        }
        for (&(x, y), &count) in &edges {
            assert_eq!(count, 1, "directed edge {x}->{y} used {count} times");
            assert_eq!(edges.get(&(y, x)), Some(&1), "edge {x}->{y} has no twin");
        }
        let (v, e, f) = (hull.vertices.len(), edges.len() / 2, hull.faces.len());
        assert_eq!(
            v as i64 - e as i64 + f as i64,
            2,
            "Euler: V={v} E={e} F={f}"
        );
        let c = |q: &Point3| Coord3D {
            x: q.x,
            y: q.y,
            z: q.z,
        };
        for &[a, b, cc] in &hull.faces {
            for q in p {
                assert!(orient3d(c(&p[a]), c(&p[b]), c(&p[cc]), c(q)) >= 0.0);
            }
        }
    }

    #[test]
    fn random_points_in_general_position_match_brute_force() {
        let mut rng = Rng::new(7);
        for trial in 0..20 {
            let n = 8 + trial * 4;
            let p: Vec<Point3> = (0..n)
                .map(|_| Point3::new(rng.uniform(), rng.uniform(), rng.uniform()))
                .collect();
            let hull = convex_hull(&p).unwrap();
            check_hull(&p, &hull);
            let mut faces: Vec<[usize; 3]> = hull.faces.iter().map(|&t| canonical(t)).collect();
            faces.sort_unstable();
            assert_eq!(faces, brute_force_faces(&p), "trial {trial}, n = {n}");
            // vertices are exactly the extreme points: those on a brute-force facet
            let mut ext: Vec<usize> = brute_force_faces(&p).into_iter().flatten().collect();
            ext.sort_unstable();
            ext.dedup();
            assert_eq!(hull.vertices, ext);
        }
    }

    #[test]
    fn every_point_on_a_sphere_is_a_vertex() {
        let mut rng = Rng::new(11);
        let n = 2000;
        let p: Vec<Point3> = (0..n)
            .map(|_| rng.unit_vector() * 3.0 + Vector3::new(5., -2., 1.))
            .map(Point3::from)
            .collect();
        let hull = convex_hull(&p).unwrap();
        check_hull(&p, &hull);
        assert_eq!(hull.vertices, (0..n).collect::<Vec<_>>());
        assert_eq!(hull.faces.len(), 2 * n - 4);
        let vol = hull.volume(&p).unwrap();
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * 27.0;
        assert!(vol < sphere && vol > 0.98 * sphere, "{vol} vs {sphere}");
    }

    use crate::Vector3;

    #[test]
    fn cube_with_coplanar_and_interior_points() {
        let mut rng = Rng::new(3);
        let mut p = Vec::new();
        // interior points first so the corners are not the first indices
        for _ in 0..500 {
            p.push(Point3::new(
                rng.uniform() * 2.0,
                rng.uniform() * 2.0,
                rng.uniform() * 2.0,
            ));
        }
        // points on the faces, on edges (grid, exactly coplanar and collinear)
        for i in 0..=8 {
            for j in 0..=8 {
                let (s, t) = (i as f64 * 0.25, j as f64 * 0.25);
                for q in [
                    [s, t, 0.0],
                    [s, t, 2.0],
                    [s, 0.0, t],
                    [s, 2.0, t],
                    [0.0, s, t],
                    [2.0, s, t],
                ] {
                    p.push(Point3::new(q[0], q[1], q[2]));
                }
            }
        }
        let hull = convex_hull(&p).unwrap();
        check_hull(&p, &hull);
        assert!(
            (hull.volume(&p).unwrap() - 8.0).abs() < 1e-12,
            "{}",
            hull.volume(&p).unwrap()
        );
        assert!(
            (hull.area(&p).unwrap() - 24.0).abs() < 1e-12,
            "{}",
            hull.area(&p).unwrap()
        );
        // all 8 corners are vertices; every vertex is on the cube's surface
        for corner in 0..8 {
            let c = Point3::new(
                2.0 * (corner & 1) as f64,
                2.0 * ((corner >> 1) & 1) as f64,
                2.0 * ((corner >> 2) & 1) as f64,
            );
            assert!(
                hull.vertices.iter().any(|&v| p[v] == c),
                "corner {c} missing"
            );
        }
        for &v in &hull.vertices {
            assert!(
                p[v].coords.iter().any(|&x| x == 0.0 || x == 2.0),
                "{}",
                p[v]
            );
        }
    }

    #[test]
    fn rotated_cube_grid_nearly_coplanar_points() {
        // face grids of a rotated cube: coplanar up to rounding, the hard
        // case for the floating-point filter in front of orient3d
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let mut p = Vec::new();
        for i in 0..=20 {
            for j in 0..=20 {
                let (s, t) = (i as f64 * 0.1, j as f64 * 0.1);
                for q in [
                    [s, t, 0.0],
                    [s, t, 2.0],
                    [s, 0.0, t],
                    [s, 2.0, t],
                    [0.0, s, t],
                    [2.0, s, t],
                ] {
                    p.push(rot * Point3::new(q[0] + 10.0, q[1] - 5.0, q[2] + 3.0));
                }
            }
        }
        let hull = convex_hull(&p).unwrap();
        check_hull(&p, &hull);
        assert!(
            (hull.volume(&p).unwrap() - 8.0).abs() < 1e-9,
            "{}",
            hull.volume(&p).unwrap()
        );
        assert!(
            (hull.area(&p).unwrap() - 24.0).abs() < 1e-9,
            "{}",
            hull.area(&p).unwrap()
        );
    }

    #[test]
    fn duplicates_keep_one_vertex_each() {
        let mut rng = Rng::new(5);
        let base: Vec<Point3> = (0..300).map(|_| Point3::from(rng.unit_vector())).collect();
        let mut p = base.clone();
        p.extend(base.iter().copied());
        p.extend(base.iter().copied());
        let hull = convex_hull(&p).unwrap();
        check_hull(&p, &hull);
        assert_eq!(hull.vertices.len(), 300);
        let single = convex_hull(&base).unwrap();
        assert!((hull.volume(&p).unwrap() - single.volume(&base).unwrap()).abs() < 1e-12);
    }

    #[test]
    fn degenerate_input_is_an_error() {
        let q = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let few = [q(0., 0., 0.), q(1., 0., 0.), q(0., 1., 0.)];
        assert!(matches!(
            convex_hull(&few),
            Err(Error::TooFewPoints {
                got: 3,
                needed: 4,
                ..
            })
        ));
        let same = vec![q(1., 2., 3.); 10];
        assert!(format!("{}", convex_hull(&same).unwrap_err()).contains("coincide"));
        let line: Vec<Point3> = (0..10).map(|i| q(i as f64, 2.0 * i as f64, 1.0)).collect();
        assert!(format!("{}", convex_hull(&line).unwrap_err()).contains("collinear"));
        let plane: Vec<Point3> = (0..50)
            .map(|i| {
                q(
                    (i % 7) as f64,
                    (i / 7) as f64,
                    0.3 * (i % 7) as f64 + 0.1 * (i / 7) as f64,
                )
            })
            .collect();
        assert!(format!("{}", convex_hull(&plane).unwrap_err()).contains("coplanar"));
        let mut bad = plane.clone();
        bad.push(q(f64::NAN, 0., 0.));
        assert!(convex_hull(&bad).is_err());
    }

    #[test]
    fn huge_and_tiny_coordinates() {
        let mut rng = Rng::new(9);
        for s in [1e140, 1e-130] {
            let p: Vec<Point3> = (0..200)
                .map(|_| Point3::from(rng.unit_vector() * s))
                .collect();
            let hull = convex_hull(&p).unwrap();
            assert_eq!(hull.vertices.len(), 200);
            assert_eq!(hull.faces.len(), 396);
        }
    }
}
