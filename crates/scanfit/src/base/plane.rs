//! The simplest base surface: the least-squares plane of the points.
//!
//! The points are projected onto the plane spanned by the two principal
//! directions of their covariance (PCA); the projections, scaled to the unit
//! square, are the parameters. This parameterizes any patch that is a height
//! field over its best-fit plane (terrain, a face seen from the front, a gently
//! curved panel); it folds over where the patch turns back over that plane.
//!
//! A height field of large relief (Franke's function over the unit square:
//! relief 1.2 on a side of 1) has a strongly tilted best-fit plane, and the
//! projection onto it folds where the bumps face away from the tilt, while
//! the projection along the heights' axis would not fold at all. So
//! [`plane_parameters`] measures the fold-over share of each candidate
//! direction ([`super::choose_projection`]: the best-fit plane's normal and
//! the three coordinate axes) on a seeded sample and projects along the
//! best; the best-fit plane is kept whenever it does not fold more than the
//! others, so a sheet over its plane is parameterized as before.

use super::projection::{fold_sample, projected_frame, Projection};
use crate::wire::{Reader, Writer};
use crate::{Error, Point3, Result, Vector3};

/// The plane and the parameters it gives.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneParameterization {
    /// Centroid of the points.
    pub origin: Point3,
    /// First principal direction (`u`).
    pub e1: Vector3,
    /// Second principal direction (`v`).
    pub e2: Vector3,
    /// Normal (`e1 x e2`).
    pub normal: Vector3,
    /// `(min, max)` of the projections on `e1` and `e2`.
    pub bounds: [(f64, f64); 2],
    /// Parameters in `[0, 1]^2`, one per point.
    pub uv: Vec<[f64; 2]>,
    /// The projection direction and why it was chosen.
    pub projection: Projection,
}

/// The best-fit plane's frame: the centroid, the in-plane axes along the
/// minimum-area bounding rectangle and the normal, without the parameters
/// (no per-point array is kept: the points are streamed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFrame {
    /// Centroid of the points.
    pub origin: Point3,
    /// First in-plane axis (the long side of the minimum-area rectangle).
    pub e1: Vector3,
    /// Second in-plane axis (`normal x e1`).
    pub e2: Vector3,
    /// Normal (`e1 x e2`; the covariance's smallest principal direction).
    pub normal: Vector3,
}

/// The frame of [`plane_parameters`] alone (the same steps: PCA normal, the
/// axes of the minimum-area rectangle of the projections, Freeman & Shapira
/// 1975, deterministic signs), without the per-point parameters: the hull
/// keeps only the points outside the octagon of extreme projections
/// (Akl & Toussaint 1978, in [`FlatHull::add`]), so the memory is that of the
/// few points near the outline, not a copy of the cloud.
///
/// Errors: invalid coordinates, fewer than 3 points, collinear points.
///
/// ```
/// use scanfit::base::plane_frame;
/// use scanfit::Point3;
/// let pts: Vec<Point3> = (0..60)
///     .map(|k| Point3::new((k % 10) as f64 * 2.0, (k / 10) as f64, 5.0))
///     .collect();
/// let f = plane_frame(&pts).unwrap();
/// assert!((f.normal.z - 1.0).abs() < 1e-12);
/// assert!((f.e1.x - 1.0).abs() < 1e-12); // the long side is along x
/// ```
pub fn plane_frame(points: &[Point3]) -> Result<PlaneFrame> {
    let map = plane_map(points)?;
    Ok(PlaneFrame {
        origin: map.origin,
        e1: map.e1,
        e2: map.e2,
        normal: map.normal,
    })
}

/// Parameters of `points` on their best-fit plane, or, when that plane
/// folds the points over and a coordinate axis does not
/// ([`super::choose_projection`]), on the plane across that axis. Axis
/// signs are made deterministic (largest component positive), so the result
/// does not depend on the eigen solver.
///
/// The steps are those of a chunked or distributed run
/// ([`super::PlaneMoments`]: the covariance sums and the seeded sample that
/// chooses the direction; [`FlatHull`], [`PlaneExtents`], [`PlaneMap`]),
/// each fed all points at once here, the point's index its position in
/// `points`: a streamed or distributed run over the same points in the same
/// order makes the same choice and gives the same parameters (to the
/// rounding of the sums).
///
/// ```
/// use scanfit::base::{plane_parameters, ProjectionAxis};
/// use scanfit::Point3;
/// // a steep ridge over the unit square: its best-fit plane is tilted
/// let pts: Vec<Point3> = (0..2500)
///     .map(|k| {
///         let (x, y) = ((k % 50) as f64 / 49.0, (k / 50) as f64 / 49.0);
///         Point3::new(x, y, (-30.0 * (x - 0.3) * (x - 0.3)).exp() + 0.8 * x)
///     })
///     .collect();
/// let p = plane_parameters(&pts).unwrap();
/// assert_eq!(p.projection.axis, ProjectionAxis::Z);
/// assert_eq!(p.normal, scanfit::Vector3::z());
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn plane_parameters(points: &[Point3]) -> Result<PlaneParameterization> {
    let pca = checked_pca(points)?;
    let mut sample = fold_sample();
    sample.add(0, points);
    let (axes, mut projection) = projected_frame(&pca, &sample)?;
    let map = map_along(&axes, points)?;
    projection.extent = map.extent();
    let uv = points.iter().map(|p| map.uv(p)).collect();
    Ok(PlaneParameterization {
        origin: map.origin,
        e1: map.e1,
        e2: map.e2,
        normal: map.normal,
        bounds: map.bounds,
        uv,
        projection,
    })
}

/// The points' PCA, after checking that there are enough valid points.
pub(super) fn checked_pca(points: &[Point3]) -> Result<crate::Pca> {
    crate::validate_points(points)?;
    if points.len() < 3 {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: 3,
            what: "a best-fit plane".into(),
        });
    }
    crate::geom::pca(points).ok_or(Error::TooFewPoints {
        got: 0,
        needed: 3,
        what: "a best-fit plane".into(),
    })
}

/// The steps of a chunked or distributed run ([`PlaneAxes`] from the
/// covariance sums, [`FlatHull`], [`PlaneExtents`]), each fed all points at
/// once.
fn plane_map(points: &[Point3]) -> Result<PlaneMap> {
    let axes = PlaneAxes::of(&checked_pca(points)?)?;
    map_along(&axes, points)
}

/// [`FlatHull`] and [`PlaneExtents`] of `points` in the frame `axes`.
fn map_along(axes: &PlaneAxes, points: &[Point3]) -> Result<PlaneMap> {
    let mut hull = FlatHull::default();
    hull.add(axes, points);
    let mut extents = PlaneExtents::new(axes, hull.rectangle_direction());
    extents.add(points);
    extents.finish()
}

/// `v` with its largest component made positive (deterministic signs).
pub(super) fn orient(v: Vector3) -> Vector3 {
    let j = v.iamax();
    if v[j] < 0.0 {
        -v
    } else {
        v
    }
}

/// The best-fit plane's frame from the points' PCA: the centroid, the
/// first principal axis `a1`, the normal (the last axis) and `a2 = normal x
/// a1`, signs made deterministic. The in-plane axes are provisional: the
/// parameter axes are those of the minimum-area rectangle ([`FlatHull`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneAxes {
    /// Centroid of the points.
    pub origin: Point3,
    /// First principal direction.
    pub a1: Vector3,
    /// `normal x a1`.
    pub a2: Vector3,
    /// The plane's normal (least principal direction).
    pub normal: Vector3,
}

impl PlaneAxes {
    /// The frame of `pca`; errors for collinear or coincident points.
    pub fn of(pca: &crate::Pca) -> Result<Self> {
        let a1 = orient(pca.axes[0]);
        let normal = orient(pca.axes[2]);
        let a2 = normal.cross(&a1);
        let (l1, l2) = (pca.values[0], pca.values[1]);
        if l2.is_nan() || l2 <= 1e-24 * l1.max(f64::MIN_POSITIVE) {
            return Err(Error::InvalidInput(
                "the points are collinear (or coincide): they span no plane to parameterize over"
                    .into(),
            ));
        }
        Ok(Self {
            origin: pca.centroid,
            a1,
            a2,
            normal,
        })
    }

    /// Coordinates of `p` along `a1` and `a2` about the centroid.
    pub fn flat(&self, p: &Point3) -> [f64; 2] {
        let d = p.coords - self.origin.coords;
        [d.dot(&self.a1), d.dot(&self.a2)]
    }
}

/// The convex hull of points in the plane's coordinates ([`PlaneAxes::flat`]):
/// mergeable (the hull of two hulls is the hull of all their points), and
/// what the minimum-area rectangle needs.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlatHull {
    hull: Vec<[f64; 2]>,
}

const HULL_TAG: &[u8; 8] = b"SFHULL01";

impl FlatHull {
    /// Adds points (in space; flattened by `axes`).
    pub fn add(&mut self, axes: &PlaneAxes, points: &[Point3]) {
        // only points outside the octagon of extreme projections can be hull
        // vertices (Akl & Toussaint 1978): no copy of the chunk
        let mut flat = std::mem::take(&mut self.hull);
        flat.extend(hull_candidates(points.iter().map(|p| axes.flat(p))));
        self.hull = convex_hull(&flat);
    }

    /// Adds the hull of other points.
    pub fn merge(&mut self, other: &Self) {
        let mut flat = std::mem::take(&mut self.hull);
        flat.extend_from_slice(&other.hull);
        self.hull = convex_hull(&flat);
    }

    /// Vertices of the hull, counter-clockwise.
    pub fn vertices(&self) -> &[[f64; 2]] {
        &self.hull
    }

    /// Direction `(cos, sin)`, in the `a1, a2` frame, of an edge of the
    /// minimum-area rectangle enclosing the points.
    pub fn rectangle_direction(&self) -> (f64, f64) {
        rectangle_direction(&self.hull)
    }

    /// The hull as exact bytes ([`crate::wire`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(HULL_TAG);
        let flat: Vec<f64> = self.hull.iter().flatten().copied().collect();
        w.f64s(&flat);
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, HULL_TAG, "a convex hull")?;
        let flat = r.f64s()?;
        if flat.len() % 2 != 0 {
            return Err(r.corrupt("the hull's coordinates"));
        }
        r.end()?;
        Ok(Self {
            hull: flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
        })
    }
}

/// Mergeable extents of the points along the candidate parameter axes of
/// the minimum-area rectangle: its edge direction `e` and `normal x e`
/// (the longer becomes `u`), oriented, and the bounds along the chosen
/// axes.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneExtents {
    axes: PlaneAxes,
    /// `e`, `normal x e`, then the oriented `(e1, e2)` pair of each choice.
    dirs: [Vector3; 6],
    lo: [f64; 6],
    hi: [f64; 6],
}

const EXTENTS_TAG: &[u8; 8] = b"SFPLEXT1";

impl PlaneExtents {
    /// No points yet; `direction` from [`FlatHull::rectangle_direction`].
    pub fn new(axes: &PlaneAxes, direction: (f64, f64)) -> Self {
        let (cos, sin) = direction;
        let e = axes.a1 * cos + axes.a2 * sin;
        let f = axes.normal.cross(&e);
        let (ea, fa) = (orient(e), orient(f));
        Self {
            axes: *axes,
            dirs: [e, f, ea, axes.normal.cross(&ea), fa, axes.normal.cross(&fa)],
            lo: [f64::INFINITY; 6],
            hi: [f64::NEG_INFINITY; 6],
        }
    }

    /// Adds points.
    pub fn add(&mut self, points: &[Point3]) {
        let c = self.axes.origin.coords;
        for p in points {
            let d = p.coords - c;
            for k in 0..6 {
                let s = d.dot(&self.dirs[k]);
                self.lo[k] = self.lo[k].min(s);
                self.hi[k] = self.hi[k].max(s);
            }
        }
    }

    /// Adds the extents of other points (the same axes and direction).
    pub fn merge(&mut self, other: &Self) -> Result<()> {
        if self.axes != other.axes || self.dirs != other.dirs {
            return Err(Error::InvalidInput(
                "cannot merge plane extents along different axes; every chunk must use the same plane".into(),
            ));
        }
        for k in 0..6 {
            self.lo[k] = self.lo[k].min(other.lo[k]);
            self.hi[k] = self.hi[k].max(other.hi[k]);
        }
        Ok(())
    }

    /// The parameter map: `u` along the longer side of the rectangle.
    pub fn finish(&self) -> Result<PlaneMap> {
        if self.lo[0] > self.hi[0] {
            return Err(Error::InvalidInput(
                "the plane's extents hold no point".into(),
            ));
        }
        let extent = |k: usize| self.hi[k] - self.lo[k];
        let k = if extent(1) > extent(0) { 4 } else { 2 };
        Ok(PlaneMap {
            origin: self.axes.origin,
            e1: self.dirs[k],
            e2: self.dirs[k + 1],
            normal: self.axes.normal,
            bounds: [(self.lo[k], self.hi[k]), (self.lo[k + 1], self.hi[k + 1])],
        })
    }

    /// The extents as exact bytes ([`crate::wire`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(EXTENTS_TAG);
        let a = &self.axes;
        let mut v: Vec<f64> = a.origin.coords.iter().copied().collect();
        for x in [a.a1, a.a2, a.normal].iter().chain(&self.dirs) {
            v.extend(x.iter());
        }
        v.extend(self.lo);
        v.extend(self.hi);
        w.f64s(&v);
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, EXTENTS_TAG, "plane extents")?;
        let v = r.f64s()?;
        if v.len() != 3 * 10 + 12 {
            return Err(r.corrupt("the plane extents' values"));
        }
        r.end()?;
        let vec = |k: usize| Vector3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
        let mut lo = [0.0; 6];
        let mut hi = [0.0; 6];
        lo.copy_from_slice(&v[30..36]);
        hi.copy_from_slice(&v[36..42]);
        Ok(Self {
            axes: PlaneAxes {
                origin: Point3::from(vec(0)),
                a1: vec(1),
                a2: vec(2),
                normal: vec(3),
            },
            dirs: [vec(4), vec(5), vec(6), vec(7), vec(8), vec(9)],
            lo,
            hi,
        })
    }
}

/// The map from a point to its parameters on the best-fit plane: the
/// projection on `e1`, `e2` about the centroid, scaled from `bounds` to
/// `[0, 1]` (clamped).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneMap {
    /// Centroid of the points.
    pub origin: Point3,
    /// The `u` axis.
    pub e1: Vector3,
    /// The `v` axis (`normal x e1`).
    pub e2: Vector3,
    /// The plane's normal.
    pub normal: Vector3,
    /// `(min, max)` of the projections on `e1` and `e2`.
    pub bounds: [(f64, f64); 2],
}

impl PlaneMap {
    /// Lengths of the parameter rectangle's sides along `u` and `v` (data
    /// units).
    pub fn extent(&self) -> [f64; 2] {
        let [(lo1, hi1), (lo2, hi2)] = self.bounds;
        [hi1 - lo1, hi2 - lo2]
    }

    /// The parameters of `p`.
    #[inline]
    pub fn uv(&self, p: &Point3) -> [f64; 2] {
        let d = p.coords - self.origin.coords;
        let (s, t) = (d.dot(&self.e1), d.dot(&self.e2));
        let [(lo1, hi1), (lo2, hi2)] = self.bounds;
        [
            ((s - lo1) / (hi1 - lo1)).clamp(0.0, 1.0),
            ((t - lo2) / (hi2 - lo2)).clamp(0.0, 1.0),
        ]
    }

    /// Writes the fields into a record ([`crate::wire`]).
    pub fn write(&self, w: &mut Writer) {
        let mut v: Vec<f64> = self.origin.coords.iter().copied().collect();
        for x in [self.e1, self.e2, self.normal] {
            v.extend(x.iter());
        }
        v.extend([
            self.bounds[0].0,
            self.bounds[0].1,
            self.bounds[1].0,
            self.bounds[1].1,
        ]);
        w.f64s(&v);
    }

    /// Reads the fields [`write`](Self::write) wrote.
    pub fn read(r: &mut Reader<'_>) -> Result<Self> {
        let v = r.f64s()?;
        if v.len() != 16 {
            return Err(r.corrupt("the plane map's values"));
        }
        let vec = |k: usize| Vector3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
        Ok(Self {
            origin: Point3::from(vec(0)),
            e1: vec(1),
            e2: vec(2),
            normal: vec(3),
            bounds: [(v[12], v[13]), (v[14], v[15])],
        })
    }
}

/// Direction `(cos, sin)` of an edge of the minimum-area rectangle enclosing
/// the convex polygon `hull` (Freeman & Shapira 1975: one side is collinear
/// with a hull edge).
fn rectangle_direction(hull: &[[f64; 2]]) -> (f64, f64) {
    let mut best = (f64::INFINITY, (1.0, 0.0));
    for k in 0..hull.len() {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        if len == 0.0 {
            continue;
        }
        let (c, s) = (dx / len, dy / len);
        let (mut lo1, mut hi1, mut lo2, mut hi2) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in hull {
            let (x, y) = (p[0] * c + p[1] * s, -p[0] * s + p[1] * c);
            lo1 = lo1.min(x);
            hi1 = hi1.max(x);
            lo2 = lo2.min(y);
            hi2 = hi2.max(y);
        }
        let area = (hi1 - lo1) * (hi2 - lo2);
        if area < best.0 {
            best = (area, (c, s));
        }
    }
    best.1
}

/// The points of `pts` that can be vertices of their convex hull: all but
/// those strictly inside the octagon of the extreme points in the directions
/// `x`, `y`, `x + y` and `x - y` (Akl & Toussaint 1978), with a margin of
/// 1e-9 of the extent so that rounding never drops a hull vertex. The hull
/// of the candidates is the hull of all points.
fn hull_candidates(pts: impl Iterator<Item = [f64; 2]> + Clone) -> Vec<[f64; 2]> {
    let dirs = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, 1.0]];
    // extreme point per direction and sign, in counter-clockwise order of
    // the outward directions (+x, +x+y, +y, -x+y, -x, -x-y, -y, x-y)
    let mut ext = [[f64::NAN; 2]; 8];
    let mut best = [f64::NEG_INFINITY; 8];
    let mut scale = 0.0f64;
    for p in pts.clone() {
        scale = scale.max(p[0].abs()).max(p[1].abs());
        for (k, d) in dirs.iter().enumerate() {
            let s = p[0] * d[0] + p[1] * d[1];
            if s > best[k] {
                (best[k], ext[k]) = (s, p);
            }
            if -s > best[k + 4] {
                (best[k + 4], ext[k + 4]) = (-s, p);
            }
        }
    }
    let mut octagon: Vec<[f64; 2]> = Vec::with_capacity(8);
    for q in ext {
        if octagon.last() != Some(&q) && octagon.first() != Some(&q) {
            octagon.push(q);
        }
    }
    let tol = 1e-9 * scale * scale;
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let inside = |p: [f64; 2]| {
        octagon.len() >= 3
            && (0..octagon.len())
                .all(|k| cross(octagon[k], octagon[(k + 1) % octagon.len()], p) > tol)
    };
    pts.filter(|&p| !inside(p)).collect()
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, no collinear points.
fn convex_hull(pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = pts.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let order: Vec<[f64; 2]> = if pass == 0 {
            p.clone()
        } else {
            p.iter().rev().copied().collect()
        };
        for q in order {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::{choose_projection, ProjectionAxis, FOLD_SAMPLE};
    use crate::cloud::testutil::Rng;

    /// Franke's function on `n` seeded uniform points of the unit square.
    fn franke(n: usize) -> Vec<Point3> {
        crate::testdata::scattered(n, 29, [0.0, 0.0, 1.0, 1.0], crate::testdata::franke)
    }

    #[test]
    fn a_height_field_of_large_relief_is_projected_along_its_heights() {
        // the best-fit plane of Franke's bumps is tilted and folds them over
        // (the fit through it had 13067 fold-overs in 199454 triangles at
        // 10^5 points); along z nothing folds
        let pts = franke(20_000);
        let p = plane_parameters(&pts).unwrap();
        let s = p.projection.fold_shares;
        assert!(s[0] > 0.02, "{s:?}");
        assert_eq!(s[3], 0.0, "{s:?}");
        assert_eq!(p.projection.axis, ProjectionAxis::Z);
        assert_eq!(p.projection.sampled, FOLD_SAMPLE);
        assert_eq!((p.normal, p.e1.z, p.e2.z), (Vector3::z(), 0.0, 0.0));
        // u, v are the points' x, y (in some order and sign) over the unit square
        let [(lo1, hi1), (lo2, hi2)] = p.bounds;
        assert!(p.e1.x.abs().max(p.e1.y.abs()) > 0.999, "{:?}", p.e1);
        assert!((hi1 - lo1 - 1.0).abs() < 1e-3 && (hi2 - lo2 - 1.0).abs() < 1e-3);
        assert!(
            (p.projection.extent[0] - 1.0).abs() < 1e-3,
            "{:?}",
            p.projection.extent
        );
        // the y-up copy of the same data picks y
        let yup: Vec<Point3> = pts.iter().map(|q| Point3::new(q.x, q.z, q.y)).collect();
        let c = choose_projection(&yup).unwrap();
        assert_eq!((c.axis, c.direction), (ProjectionAxis::Y, Vector3::y()));
        assert_eq!(c.fold_shares[2], 0.0);
    }

    #[test]
    fn a_clean_tilted_sheet_keeps_its_best_fit_plane() {
        // a gently curved sheet tilted 60 degrees about a rotated axis:
        // the best-fit plane folds nothing, z would not fold either but the
        // plane is kept, and the parameters are the best-fit plane map's
        let (c, s) = (0.4f64.cos(), 0.4f64.sin());
        let mut rng = Rng::new(3);
        let pts: Vec<Point3> = (0..5000)
            .map(|_| {
                let (x, y) = (rng.uniform() * 40.0, rng.uniform() * 25.0);
                let z = 1.7 * x + 0.5 * (x * 0.15).sin() * (y * 0.2).cos();
                Point3::new(x * c - y * s + 700.0, x * s + y * c, z - 30.0)
            })
            .collect();
        let p = plane_parameters(&pts).unwrap();
        assert_eq!(p.projection.axis, ProjectionAxis::BestFitPlane);
        assert_eq!(p.projection.fold_shares[0], 0.0);
        assert_eq!(p.projection.fold_shares[3], 0.0);
        let map = plane_map(&pts).unwrap();
        assert_eq!((p.normal, p.e1, p.bounds), (map.normal, map.e1, map.bounds));
        assert!(pts.iter().zip(&p.uv).all(|(q, t)| map.uv(q) == *t));
    }

    #[test]
    fn terrain_like_points_map_to_the_unit_square() {
        let pts: Vec<Point3> = (0..400)
            .map(|k| {
                let (x, y) = ((k % 20) as f64 * 3.0, (k / 20) as f64);
                Point3::new(x + 1000.0, y - 50.0, 0.1 * (x * 0.3).sin())
            })
            .collect();
        let pp = plane_parameters(&pts).unwrap();
        assert!((pp.normal.z.abs() - 1.0).abs() < 1e-3);
        assert!(pp.normal.z > 0.0);
        // u follows x (the longer extent), v follows y
        assert!((pp.uv[19][0] - 1.0).abs() < 1e-12 && pp.uv[0][0].abs() < 1e-12);
        assert!((pp.uv[399][1] - 1.0).abs() < 1e-12 || pp.uv[399][1].abs() < 1e-12);
        assert!(plane_parameters(&[
            Point3::origin(),
            Point3::new(1., 1., 1.),
            Point3::new(2., 2., 2.)
        ])
        .is_err());
    }

    #[test]
    fn the_passes_over_chunks_give_the_one_call_parameters() {
        // a tilted, rotated patch in three chunks: covariance sums about the
        // first point, hulls and extents merged, then the map per point
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let pts: Vec<Point3> = (0..3000)
            .map(|k| {
                let (x, y) = ((k * 37 % 101) as f64 * 0.7, (k * 53 % 89) as f64 * 0.4);
                let z = 0.3 * x + 0.05 * (x * 0.2).sin() * y;
                Point3::new(x * c - y * s + 50.0, x * s + y * c - 20.0, z)
            })
            .collect();
        let once = plane_parameters(&pts).unwrap();
        let chunks = [&pts[..700], &pts[700..700], &pts[700..2100], &pts[2100..]];
        let mut cov = crate::CovarianceSums::new(pts[0]);
        for ch in chunks {
            let mut part = crate::CovarianceSums::new(pts[0]);
            ch.iter().for_each(|p| part.add(p));
            let part = crate::CovarianceSums::from_bytes(&part.to_bytes()).unwrap();
            cov.merge(&part).unwrap();
        }
        let axes = PlaneAxes::of(&cov.finish().unwrap()).unwrap();
        let mut hull = FlatHull::default();
        for ch in chunks {
            let mut part = FlatHull::default();
            part.add(&axes, ch);
            hull.merge(&FlatHull::from_bytes(&part.to_bytes()).unwrap());
        }
        let mut ext = PlaneExtents::new(&axes, hull.rectangle_direction());
        for ch in chunks {
            let mut part = PlaneExtents::new(&axes, hull.rectangle_direction());
            part.add(ch);
            ext.merge(&PlaneExtents::from_bytes(&part.to_bytes()).unwrap())
                .unwrap();
        }
        let map = ext.finish().unwrap();
        let worst = pts
            .iter()
            .zip(&once.uv)
            .map(|(p, t)| {
                let q = map.uv(p);
                (q[0] - t[0]).abs().max((q[1] - t[1]).abs())
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "{worst}");
        assert!((map.e1 - once.e1).norm() < 1e-12 && (map.normal - once.normal).norm() < 1e-12);
        // different reference points do not merge
        let mut other = crate::CovarianceSums::new(pts[1]);
        assert!(other.merge(&cov).is_err());
    }

    #[test]
    fn a_rotated_square_patch_fills_the_parameter_square() {
        // a nearly square patch rotated by 20 degrees: PCA's in-plane axes are
        // arbitrary, the minimum-area rectangle's are not
        let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
        let mut pts = Vec::new();
        for i in 0..50 {
            for j in 0..48 {
                let (x, y) = (i as f64 * 0.61, j as f64 * 0.66);
                pts.push(Point3::new(
                    x * c - y * s,
                    x * s + y * c,
                    0.01 * ((i * j) % 7) as f64,
                ));
            }
        }
        let pp = plane_parameters(&pts).unwrap();
        // all four corners of the parameter square are occupied
        for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]] {
            let d = pp
                .uv
                .iter()
                .map(|t| (t[0] - corner[0]).hypot(t[1] - corner[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-4, "corner {corner:?} empty: {d}");
        }
    }
}
