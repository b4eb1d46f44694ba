//! Points of the hidden point removal that certainly are not visible,
//! found before the convex hull ([Katz07] step 2) so that the hull only
//! sees the rest: an interior filter in the spirit of Akl & Toussaint
//! (1978, "A fast convex hull algorithm", Information Processing Letters
//! 7(5)), with the extreme points replaced by the hull of a sample.
//!
//! The spherically flipped points `p'` and the viewpoint `O` (the origin)
//! go into the hull. The hull `H_s` of a sample of the flipped points and
//! `O` lies inside the hull `H` of all of them, so a point strictly inside
//! `H_s` is strictly inside `H`: not a hull vertex, hence not visible, and
//! removing it leaves the vertex set of `H` unchanged.
//!
//! The test per point is exact. `H_s` contains `O` as a vertex, so every
//! ray from `O` that enters `H_s` leaves it through one facet not incident
//! to `O` (an *outer* facet). A point `q` is strictly inside `H_s` when,
//! for one outer triangle `abc`, (1) the ray `O q` passes through the open
//! triangle (`orient3d(O, a, b, q)`, `orient3d(O, b, c, q)`,
//! `orient3d(O, c, a, q)` all negative) and (2) `q` lies strictly below its
//! plane (`orient3d(a, b, c, q) > 0`, as `O` does): then `q` lies on the
//! open segment from `O` to a relative-interior point of a facet that does
//! not contain `O`, which is interior to `H_s`. Shewchuk's adaptive
//! predicates (the `robust` crate) decide both, so rounding never removes
//! a hull vertex. Which triangle to test comes from a floating-point
//! point location (the gnomonic projection of the ray directions onto a
//! plane, where the outer triangles tile a region, bucketed in a grid); a
//! point it cannot place, or that fails the exact test, is kept.
//!
//! The filter applies when the flipped points' directions from `O` lie in
//! a cone of half-angle below 78 degrees (the viewpoint outside the cloud,
//! as the turntable's views are); otherwise every point goes to the hull.

use rayon::prelude::*;
use robust::{orient3d, Coord3D};

use super::hull::{c3, cross, dot, hull_of_coordinates};

/// Clouds smaller than this go to the hull whole (the filter's sample hull
/// and grid would not pay for themselves).
pub(crate) const MIN_POINTS: usize = 50_000;

/// One point in `SAMPLE_STRIDE` (by index) forms the sample hull.
const SAMPLE_STRIDE: usize = 16;

/// Smallest cosine between a direction and the mean direction for which
/// the gnomonic projection is used (cos 78 degrees).
const MIN_COS: f64 = 0.2;

const ORIGIN: Coord3D<f64> = Coord3D {
    x: 0.0,
    y: 0.0,
    z: 0.0,
};

/// Indices (ascending) of the flipped points `p` that may be hull vertices
/// of `p` together with the origin: all but those certified strictly
/// inside the sample hull. `None` when the filter does not apply (fewer
/// than `min_points` points, directions not within one cone, or a sample
/// hull that spans no volume).
pub(crate) fn hull_candidates(p: &[[f64; 3]], min_points: usize) -> Option<Vec<u32>> {
    let n = p.len();
    if n < min_points.max(64) || n >= u32::MAX as usize {
        return None;
    }
    let gnomonic = Gnomonic::of(p)?;
    // the sample hull: every SAMPLE_STRIDE-th point and the origin (last)
    let mut sample: Vec<[f64; 3]> = p.iter().step_by(SAMPLE_STRIDE).copied().collect();
    let origin = sample.len();
    sample.push([0.0; 3]);
    let hull = hull_of_coordinates(sample.clone()).ok()?;
    let faces: Vec<[[f64; 3]; 3]> = hull
        .faces
        .iter()
        .filter(|f| !f.contains(&origin))
        .map(|f| f.map(|i| sample[i]))
        // the origin strictly below the plane (not on it): the certificate's premise
        .filter(|[a, b, c]| orient3d(c3(a), c3(b), c3(c), ORIGIN) > 0.0)
        .collect();
    drop(sample);
    let locator = Locator::new(&gnomonic, &faces)?;
    let keep: Vec<bool> = p
        .par_iter()
        .with_min_len(4096)
        .map(|q| !locator.certainly_inside(&gnomonic, &faces, q))
        .collect();
    Some(
        keep.iter()
            .enumerate()
            .filter(|(_, &k)| k)
            .map(|(i, _)| i as u32)
            .collect(),
    )
}

/// Central projection of ray directions onto the plane at unit distance
/// along the mean direction `m`: `x -> (x.e1, x.e2) / x.m`.
struct Gnomonic {
    m: [f64; 3],
    e1: [f64; 3],
    e2: [f64; 3],
}

fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(&a, &a).sqrt();
    (l > 0.0 && l.is_finite()).then(|| a.map(|c| c / l))
}

impl Gnomonic {
    /// The projection about the points' mean direction, if every direction
    /// is within `acos(MIN_COS)` of it.
    fn of(p: &[[f64; 3]]) -> Option<Self> {
        let sum = p
            .par_iter()
            .with_min_len(4096)
            .map(|q| unit(*q).unwrap_or([0.0; 3]))
            .reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        let m = unit(sum)?;
        let inside = p.par_iter().with_min_len(4096).all(|q| {
            let d = dot(q, q).sqrt();
            dot(q, &m) > MIN_COS * d
        });
        if !inside {
            return None;
        }
        let k = (0..3)
            .min_by(|&i, &j| m[i].abs().total_cmp(&m[j].abs()))
            .unwrap_or(0);
        let mut axis = [0.0; 3];
        axis[k] = 1.0;
        let e1 = unit(cross(&m, &axis))?;
        let e2 = cross(&m, &e1);
        Some(Self { m, e1, e2 })
    }

    fn project(&self, q: &[f64; 3]) -> [f64; 2] {
        let w = dot(q, &self.m);
        [dot(q, &self.e1) / w, dot(q, &self.e2) / w]
    }
}

/// The outer triangles' projections, bucketed in a uniform grid.
struct Locator {
    tri: Vec<[[f64; 2]; 3]>,
    lo: [f64; 2],
    inv_cell: [f64; 2],
    dims: [usize; 2],
    /// Triangles per cell (CSR): `ids[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    ids: Vec<u32>,
}

impl Locator {
    fn new(g: &Gnomonic, faces: &[[[f64; 3]; 3]]) -> Option<Self> {
        if faces.is_empty() {
            return None;
        }
        let tri: Vec<[[f64; 2]; 3]> = faces.iter().map(|f| f.map(|v| g.project(&v))).collect();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for v in tri.iter().flatten() {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let ext = [hi[0] - lo[0], hi[1] - lo[1]];
        if !(ext[0] > 0.0 && ext[1] > 0.0 && ext[0].is_finite() && ext[1].is_finite()) {
            return None;
        }
        // about one triangle per cell, cells as square as the extent allows
        let cells = tri.len() as f64;
        let nx = ((cells * ext[0] / ext[1]).sqrt().ceil() as usize).clamp(1, 4096);
        let ny = ((cells * ext[1] / ext[0]).sqrt().ceil() as usize).clamp(1, 4096);
        let inv_cell = [nx as f64 / ext[0], ny as f64 / ext[1]];
        let cell_of = |x: f64, k: usize, dim: usize| {
            (((x - lo[k]) * inv_cell[k]).floor().max(0.0) as usize).min(dim - 1)
        };
        let range = |t: &[[f64; 2]; 3]| {
            let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for v in t {
                for k in 0..2 {
                    a[k] = a[k].min(v[k]);
                    b[k] = b[k].max(v[k]);
                }
            }
            (
                cell_of(a[0], 0, nx)..=cell_of(b[0], 0, nx),
                cell_of(a[1], 1, ny)..=cell_of(b[1], 1, ny),
            )
        };
        let mut count = vec![0u32; nx * ny + 1];
        for t in &tri {
            let (rx, ry) = range(t);
            for j in ry {
                for i in rx.clone() {
                    count[j * nx + i + 1] += 1;
                }
            }
        }
        for c in 1..count.len() {
            count[c] += count[c - 1];
        }
        let mut fill = count.clone();
        let mut ids = vec![0u32; *count.last()? as usize];
        for (f, t) in tri.iter().enumerate() {
            let (rx, ry) = range(t);
            for j in ry {
                for i in rx.clone() {
                    let c = j * nx + i;
                    ids[fill[c] as usize] = f as u32;
                    fill[c] += 1;
                }
            }
        }
        Some(Self {
            tri,
            lo,
            inv_cell,
            dims: [nx, ny],
            start: count,
            ids,
        })
    }

    /// Whether `q` is certified strictly inside the sample hull (module doc).
    fn certainly_inside(&self, g: &Gnomonic, faces: &[[[f64; 3]; 3]], q: &[f64; 3]) -> bool {
        let x = g.project(q);
        let cell = |k: usize| {
            let c = ((x[k] - self.lo[k]) * self.inv_cell[k]).floor();
            (c >= 0.0 && c < self.dims[k] as f64).then_some(c as usize)
        };
        let (Some(i), Some(j)) = (cell(0), cell(1)) else {
            return false;
        };
        let c = j * self.dims[0] + i;
        let ids = &self.ids[self.start[c] as usize..self.start[c + 1] as usize];
        let Some(&f) = ids.iter().find(|&&f| inside_2d(&self.tri[f as usize], &x)) else {
            return false;
        };
        let [a, b, c] = faces[f as usize].map(|v| c3(&v));
        let q = c3(q);
        orient3d(ORIGIN, a, b, q) < 0.0
            && orient3d(ORIGIN, b, c, q) < 0.0
            && orient3d(ORIGIN, c, a, q) < 0.0
            && orient3d(a, b, c, q) > 0.0
    }
}

/// Whether `x` is inside (or on) the 2D triangle `t`, either orientation.
fn inside_2d(t: &[[f64; 2]; 3], x: &[f64; 2]) -> bool {
    let side =
        |a: &[f64; 2], b: &[f64; 2]| (b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0]);
    let (s0, s1, s2) = (side(&t[0], &t[1]), side(&t[1], &t[2]), side(&t[2], &t[0]));
    (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::testutil::Rng;

    /// The flipped points of a unit sphere seen from `eye` (gamma = 2).
    fn flipped_sphere(n: usize, eye: [f64; 3]) -> Vec<[f64; 3]> {
        let mut rng = Rng::new(5);
        let p: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                let d = rng.unit_vector();
                [d.x - eye[0], d.y - eye[1], d.z - eye[2]]
            })
            .collect();
        let max = p.iter().map(|q| dot(q, q).sqrt()).fold(0.0, f64::max);
        let r = 100.0 * max;
        p.iter()
            .map(|q| q.map(|c| c * (2.0 * r / dot(q, q).sqrt() - 1.0)))
            .collect()
    }

    #[test]
    fn most_hidden_points_are_certified_and_no_visible_one() {
        let p = flipped_sphere(40_000, [0.0, 0.0, 3.0]);
        let keep = hull_candidates(&p, 0).unwrap();
        // about 0.47 of the sphere is visible from distance 3 (z > 1/3); the
        // far side is certified inside the sample hull
        let frac = keep.len() as f64 / p.len() as f64;
        assert!(frac < 0.6, "kept {frac}");
        let mut all = p.clone();
        all.push([0.0; 3]);
        let hull = hull_of_coordinates(all).unwrap();
        let vertices: Vec<u32> = hull
            .vertices
            .iter()
            .filter(|&&i| i < p.len())
            .map(|&i| i as u32)
            .collect();
        // every hull vertex is kept
        let mut k = 0;
        for v in vertices {
            while keep[k] < v {
                k += 1;
            }
            assert_eq!(keep[k], v);
        }
    }

    #[test]
    fn directions_beyond_a_cone_or_few_points_skip_the_filter() {
        // the viewpoint at the sphere's centre: directions everywhere
        let p = flipped_sphere(2_000, [0.0, 0.0, 0.0]);
        assert!(hull_candidates(&p, 0).is_none());
        let p = flipped_sphere(2_000, [0.0, 0.0, 3.0]);
        assert!(hull_candidates(&p, MIN_POINTS).is_none());
        assert!(hull_candidates(&p, 0).is_some());
    }
}
