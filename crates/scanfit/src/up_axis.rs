//! The up axis of a scan: which coordinate is height.
//!
//! CAD and terrain store height in z; most mesh and scanner software store
//! it in y. Everything that treats one coordinate as height (the 2.5D MBA
//! surface `z = f(x, y)`, the pictures' camera) works in a z-up *frame*: the
//! data turned by a rotation (never a mirror) that takes the up axis to z,
//! and the results turned back.

use rayon::prelude::*;

use crate::distribution::percentile;
use crate::fit::knot_ranks::{RankQuery, RankSearch};
use crate::{Point3, Vector3};

/// The world axis that points up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// x up: the frame is (y, z, x).
    X,
    /// y up (most mesh and scanner software): the frame is (x, -z, y), so
    /// looking from +z shows x to the right and y up.
    Y,
    /// z up (CAD, terrain): the frame is the world's.
    #[default]
    Z,
}

impl UpAxis {
    /// `v` in the z-up frame (a rotation: exact, no mirroring).
    ///
    /// ```
    /// use scanfit::up_axis::UpAxis;
    /// use scanfit::Vector3;
    /// let v = Vector3::new(1.0, 2.0, 3.0);
    /// assert_eq!(UpAxis::Y.to_frame(&v), Vector3::new(1.0, -3.0, 2.0));
    /// assert_eq!(UpAxis::Y.from_frame(&UpAxis::Y.to_frame(&v)), v);
    /// ```
    pub fn to_frame(self, v: &Vector3) -> Vector3 {
        match self {
            UpAxis::Z => *v,
            UpAxis::Y => Vector3::new(v.x, -v.z, v.y),
            UpAxis::X => Vector3::new(v.y, v.z, v.x),
        }
    }

    /// The inverse of [`UpAxis::to_frame`]: a frame vector in world axes.
    pub fn from_frame(self, v: &Vector3) -> Vector3 {
        match self {
            UpAxis::Z => *v,
            UpAxis::Y => Vector3::new(v.x, v.z, -v.y),
            UpAxis::X => Vector3::new(v.z, v.x, v.y),
        }
    }

    /// A point in the z-up frame (see [`UpAxis::to_frame`]).
    pub fn point_to_frame(self, p: &Point3) -> Point3 {
        Point3::from(self.to_frame(&p.coords))
    }

    /// A frame point in world axes (see [`UpAxis::from_frame`]).
    pub fn point_from_frame(self, p: &Point3) -> Point3 {
        Point3::from(self.from_frame(&p.coords))
    }

    /// The coordinate of `p` along this axis (its height).
    pub fn height(self, p: &Point3) -> f64 {
        match self {
            UpAxis::X => p.x,
            UpAxis::Y => p.y,
            UpAxis::Z => p.z,
        }
    }

    /// The axis's name, `"x"`, `"y"` or `"z"`.
    pub fn name(self) -> &'static str {
        match self {
            UpAxis::X => "x",
            UpAxis::Y => "y",
            UpAxis::Z => "z",
        }
    }

    /// The up axis of `points` when none is given: the axis along which the
    /// data are thinnest when they are a sheet (that extent under half the
    /// next smaller one; extents between the 1st and 99th percentiles, so
    /// stray points do not count), else z. Terrain and relief scans then get
    /// their relief as height whichever axis they were stored with; bodies
    /// keep z.
    ///
    /// ```
    /// use scanfit::up_axis::UpAxis;
    /// use scanfit::Point3;
    /// // a 10 x 10 sheet, 1 thick, lying across y
    /// let sheet: Vec<Point3> = (0..400)
    ///     .map(|i| Point3::new((i % 20) as f64 * 0.5, (i % 3) as f64 * 0.5, (i / 20) as f64 * 0.5))
    ///     .collect();
    /// assert_eq!(UpAxis::automatic(&sheet), UpAxis::Y);
    /// ```
    pub fn automatic(points: &[Point3]) -> UpAxis {
        if points.len() < 3 {
            return UpAxis::Z;
        }
        let extents = ranked_extents(points).unwrap_or_else(|| {
            std::array::from_fn(|d| {
                let v: Vec<f64> = points.iter().map(|p| p[d]).collect();
                percentile(&v, 0.99).unwrap_or(0.0) - percentile(&v, 0.01).unwrap_or(0.0)
            })
        });
        UpAxis::of_extents(extents)
    }

    /// The rule of [`UpAxis::automatic`] on given extents along x, y and z
    /// (e.g. a bounding box's, when the points are streamed).
    pub fn of_extents(extents: [f64; 3]) -> UpAxis {
        let mut e = [
            (extents[0], UpAxis::X),
            (extents[1], UpAxis::Y),
            (extents[2], UpAxis::Z),
        ];
        if e.iter().any(|(x, _)| !x.is_finite()) {
            return UpAxis::Z;
        }
        e.sort_by(|a, b| a.0.total_cmp(&b.0));
        if e[0].0 < 0.5 * e[1].0 {
            e[0].1
        } else {
            UpAxis::Z
        }
    }
}

/// Points per task of [`ranked_extents`]' passes.
const RANK_CHUNK: usize = 1 << 16;

/// The extents between the 1st and 99th percentiles of x, y and z
/// ([`percentile`]'s values exactly), found without copying the
/// coordinates: one parallel pass for their range, then [`RankSearch`]
/// rounds of parallel passes (2 for evenly spread coordinates; at 10^7
/// points the six copies and serial selections of the coordinates cost
/// more than reading a binary file). `None` for points with a non-finite
/// coordinate.
fn ranked_extents(points: &[Point3]) -> Option<[f64; 3]> {
    let n = points.len() as u64;
    let last = n.checked_sub(1)? as f64;
    let ranks = [0.01, 0.99].map(|q| (last * q).round() as u64);
    let (lo, hi) = crate::pipeline::assess::bounding_box(points)?;
    let mut searches = (0..3)
        .map(|d| RankSearch::new(n, vec![ranks.to_vec()], (lo[d], hi[d])).ok())
        .collect::<Option<Vec<_>>>()?;
    while !searches.iter().all(RankSearch::done) {
        let queries: Vec<RankQuery> = searches.iter().map(RankSearch::query).collect();
        let empty = || queries.iter().map(RankQuery::counts).collect::<Vec<_>>();
        let counts = points
            .par_chunks(RANK_CHUNK)
            .fold(empty, |mut c, chunk| {
                for (d, (c, q)) in c.iter_mut().zip(&queries).enumerate() {
                    c.add(q, 0, chunk.iter().map(|p| p[d]));
                }
                c
            })
            .map(Ok::<_, crate::Error>)
            .try_reduce(empty, |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    x.merge(y)?;
                }
                Ok(a)
            })
            .ok()?;
        for (s, c) in searches.iter_mut().zip(&counts) {
            s.push(c).ok()?;
        }
    }
    let value = |d: usize, k: usize| searches.get(d)?.value(0, ranks[k]);
    let mut out = [0.0; 3];
    for (d, e) in out.iter_mut().enumerate() {
        *e = value(d, 1)? - value(d, 0)?;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_rotations_and_invert_exactly() {
        let (a, b) = (Vector3::new(0.3, -1.7, 2.9), Vector3::new(-4.0, 0.25, 1.5));
        for up in [UpAxis::X, UpAxis::Y, UpAxis::Z] {
            let (fa, fb) = (up.to_frame(&a), up.to_frame(&b));
            // lengths, angles and handedness kept: a rotation
            assert_eq!(fa.norm(), a.norm());
            assert_eq!(fa.dot(&fb), a.dot(&b));
            assert_eq!(fa.cross(&fb), up.to_frame(&a.cross(&b)));
            // the up axis becomes z
            assert_eq!(up.to_frame(&a).z, up.height(&Point3::from(a)));
            assert_eq!(up.from_frame(&fa), a);
        }
    }

    #[test]
    fn ranked_extents_are_the_percentiles_of_the_copied_coordinates() {
        // 300 000 points: x spread evenly, y mostly one value with far
        // strays and signed zeros, z a dense cluster beside a wide spread
        let mut rng = crate::testdata::Lcg::new(5);
        let points: Vec<Point3> = (0..300_000)
            .map(|i| {
                let r = rng.next_f64();
                let y = match i % 50 {
                    0 => 1e9 * (r - 0.5),
                    1 => -0.0,
                    _ => 0.0,
                };
                let z = if i % 3 == 0 {
                    100.0 * r
                } else {
                    7.0 + 1e-12 * r
                };
                Point3::new(1e6 + 30.0 * r, y, z)
            })
            .collect();
        let copied: [f64; 3] = std::array::from_fn(|d| {
            let v: Vec<f64> = points.iter().map(|p| p[d]).collect();
            percentile(&v, 0.99).unwrap() - percentile(&v, 0.01).unwrap()
        });
        assert_eq!(ranked_extents(&points), Some(copied));
        // a non-finite coordinate: no ranks (automatic copies instead)
        let mut bad = points;
        bad[10].z = f64::NAN;
        assert_eq!(ranked_extents(&bad), None);
    }

    #[test]
    fn the_thin_axis_of_a_sheet_is_up_and_bodies_keep_z() {
        assert_eq!(UpAxis::of_extents([10.0, 1.0, 8.0]), UpAxis::Y);
        assert_eq!(UpAxis::of_extents([0.4, 1.0, 8.0]), UpAxis::X);
        assert_eq!(UpAxis::of_extents([10.0, 6.0, 8.0]), UpAxis::Z);
        assert_eq!(UpAxis::of_extents([10.0, f64::NAN, 8.0]), UpAxis::Z);
    }
}
