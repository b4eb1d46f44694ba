//! The direction [`super::plane_parameters`] projects the points along: the
//! best-fit plane's normal, or a coordinate axis when that plane folds the
//! points over and the axis does not.
//!
//! A height field of large relief (Franke's function over the unit square:
//! relief 1.2 on a side of 1) has a strongly tilted best-fit plane, and the
//! projection onto it folds where the bumps face away from the tilt, while
//! the projection along the heights' axis does not fold at all. So the fold
//! share of each candidate direction is measured on a seeded sample
//! ([`choose_projection_from`]) and the best is taken; the best-fit plane is
//! kept whenever it does not fold more than the others, so a sheet over its
//! plane is parameterized as before.
//!
//! The sample is the [`FOLD_SAMPLE`] points of smallest seeded index hash
//! ([`crate::sampling::HashSample`], a bottom-k sketch [CK07]): a function of
//! the points and their order alone, gathered in the same pass as the
//! covariance sums ([`PlaneMoments`]) and mergeable across chunks and
//! workers, so the in-memory fit, the streamed fit
//! ([`crate::pipeline::stream::fit`]) and a distributed one (Dask) sample the
//! same points, compute the same normals and make the same choice.

use super::plane::{orient, PlaneAxes};
use crate::sampling::HashSample;
use crate::wire::{Reader, Writer};
use crate::{CovarianceSums, Error, Pca, Point3, Result, Vector3};

/// The directions [`super::plane_parameters`] can project the points along.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProjectionAxis {
    /// The normal of the points' best-fit plane (PCA).
    BestFitPlane,
    /// The `x` axis (the points' `y, z`).
    X,
    /// The `y` axis (the points' `x, z`).
    Y,
    /// The `z` axis (the points' `x, y`).
    Z,
}

impl ProjectionAxis {
    /// The candidates in the order of [`Projection::fold_shares`].
    pub const ALL: [ProjectionAxis; 4] = [
        ProjectionAxis::BestFitPlane,
        ProjectionAxis::X,
        ProjectionAxis::Y,
        ProjectionAxis::Z,
    ];

    /// `"best-fit plane"`, `"x"`, `"y"` or `"z"`.
    pub fn name(self) -> &'static str {
        match self {
            ProjectionAxis::BestFitPlane => "best-fit plane",
            ProjectionAxis::X => "x",
            ProjectionAxis::Y => "y",
            ProjectionAxis::Z => "z",
        }
    }
}

/// The direction the points are projected along, and the measure that
/// chose it ([`choose_projection`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// The chosen candidate.
    pub axis: ProjectionAxis,
    /// Its unit direction (the parameter plane's normal).
    pub direction: Vector3,
    /// Share of sampled points on the folded-back side, per candidate in
    /// the order of [`ProjectionAxis::ALL`] (all 0 when the cloud is too
    /// small to measure, [`FOLD_MIN_POINTS`]).
    pub fold_shares: [f64; 4],
    /// Points sampled for the measure (0: not measured, the best-fit plane
    /// kept).
    pub sampled: usize,
    /// Lengths of the parameter rectangle's sides along `u` and `v` (data
    /// units): the parameters times these are lengths in the projection
    /// plane ([`super::PlaneMap::extent`]).
    pub extent: [f64; 2],
}

/// Points sampled by [`choose_projection`] (seeded, [`FOLD_SEED`]).
pub const FOLD_SAMPLE: usize = 4000;
/// Seed of the sample of [`choose_projection`].
pub const FOLD_SEED: u64 = 0x5ca1_f01d;
/// Below this many points the best-fit plane is kept unmeasured (too few
/// for 16-neighbour normals that say anything about folds).
pub const FOLD_MIN_POINTS: usize = 64;
/// Margin by which a coordinate axis must fold less than the best-fit
/// plane to replace it: 0.2% of the sample (8 of 4000 normals, noise at
/// the borders), so a sheet over its plane keeps it.
pub const FOLD_MARGIN: f64 = 0.002;

/// An empty sample of the points [`choose_projection_from`] measures:
/// [`FOLD_SAMPLE`] points ranked by their index's hash under [`FOLD_SEED`].
///
/// ```
/// use scanfit::base::{fold_sample, FOLD_SAMPLE};
/// use scanfit::Point3;
/// let pts: Vec<Point3> = (0..10_000).map(|k| Point3::new(k as f64, 0.0, 0.0)).collect();
/// let mut s = fold_sample();
/// s.add(0, &pts);
/// assert_eq!(s.len(), FOLD_SAMPLE);
/// ```
pub fn fold_sample() -> HashSample {
    HashSample::new(FOLD_SAMPLE, FOLD_SEED)
}

/// The projection direction [`super::plane_parameters`] uses for `points`:
/// among the best-fit plane's normal and the `x`, `y`, `z` axes, the one
/// whose projection folds the fewest points over ([`choose_projection_from`]
/// on the [`fold_sample`] of the points, index = position in `points`).
///
/// Errors: those of [`super::plane_frame`] (invalid, too few or collinear
/// points).
///
/// ```
/// use scanfit::base::{choose_projection, ProjectionAxis};
/// use scanfit::Point3;
/// // a tilted flat sheet: its best-fit plane folds nothing and is kept
/// let pts: Vec<Point3> = (0..900)
///     .map(|k| {
///         let (x, y) = ((k % 30) as f64, (k / 30) as f64);
///         Point3::new(x, y, 2.0 * x + 0.5 * y)
///     })
///     .collect();
/// let c = choose_projection(&pts).unwrap();
/// assert_eq!(c.axis, ProjectionAxis::BestFitPlane);
/// assert_eq!(c.fold_shares[0], 0.0);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn choose_projection(points: &[Point3]) -> Result<Projection> {
    let pca = super::plane::checked_pca(points)?;
    let mut sample = fold_sample();
    sample.add(0, points);
    Ok(projected_frame(&pca, &sample)?.1)
}

/// The choice of [`choose_projection`] from the points' [`fold_sample`]
/// and their best-fit frame (the streamed and distributed fits gather both
/// in one pass, [`PlaneMoments`]).
///
/// The measure: the sampled points get normals by PCA over 16 neighbours,
/// oriented consistently over a minimum spanning tree ([Hoppe92] section 3,
/// [`crate::cloud::normals`]). Projecting a surface along a unit `d` maps
/// a tangent plane of normal `n` to the plane across `d` with the Jacobian
/// determinant `n . d` (the area element scales by `|n . d|`): the
/// projection is locally one-to-one and orientation-preserving where
/// `n . d` has one sign, and where the surface turns back over the plane
/// the sign flips. A candidate's fold share is the share of the sampled
/// normals on the minority side, `min(#{n . d > 0}, #{n . d < 0}) / sample`
/// (0 for a projection that does not fold; independent of the orientation's
/// global sign and of the data's scale). The best-fit plane is kept unless
/// an axis folds less by more than [`FOLD_MARGIN`]; among axes, the
/// smallest share wins, ties to the larger mean `|n . d|` (the less
/// stretched projection). Samples of fewer than [`FOLD_MIN_POINTS`] points
/// keep the best-fit plane.
///
/// ```
/// use scanfit::base::{choose_projection_from, fold_sample, PlaneAxes, ProjectionAxis};
/// use scanfit::Point3;
/// // Franke-like bumps of large relief over the unit square
/// let pts: Vec<Point3> = (0..2500)
///     .map(|k| {
///         let (x, y) = ((k % 50) as f64 / 49.0, (k / 50) as f64 / 49.0);
///         Point3::new(x, y, (-30.0 * (x - 0.3) * (x - 0.3)).exp() + 0.8 * x)
///     })
///     .collect();
/// let mut sample = fold_sample();
/// sample.add(0, &pts);
/// let best = PlaneAxes::of(&scanfit::pca(&pts).unwrap())?;
/// let c = choose_projection_from(&sample, &best)?;
/// assert_eq!(c.axis, ProjectionAxis::Z);
/// assert!(c.fold_shares[0] > c.fold_shares[3]);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn choose_projection_from(sample: &HashSample, best: &PlaneAxes) -> Result<Projection> {
    let dirs = [best.normal, Vector3::x(), Vector3::y(), Vector3::z()];
    let mut projection = Projection {
        axis: ProjectionAxis::BestFitPlane,
        direction: best.normal,
        fold_shares: [0.0; 4],
        sampled: 0,
        extent: [0.0; 2],
    };
    if sample.len() < FOLD_MIN_POINTS {
        return Ok(projection);
    }
    let cloud = crate::PointCloud::new(sample.points())?;
    let normals = crate::cloud::normals::estimate_normals(
        &cloud,
        &crate::cloud::normals::NormalsConfig::default(),
    )?
    .normals;
    let m = normals.len() as f64;
    let mut alignment = [0.0; 4];
    for (k, d) in dirs.iter().enumerate() {
        let (mut pos, mut neg, mut sum) = (0usize, 0usize, 0.0);
        for n in &normals {
            let c = n.dot(d);
            pos += usize::from(c > 0.0);
            neg += usize::from(c < 0.0);
            sum += c.abs();
        }
        projection.fold_shares[k] = pos.min(neg) as f64 / m;
        alignment[k] = sum / m;
    }
    projection.sampled = normals.len();
    let s = projection.fold_shares;
    let best_axis = (1..4)
        .min_by(|&a, &b| {
            s[a].total_cmp(&s[b])
                .then(alignment[b].total_cmp(&alignment[a]))
        })
        .unwrap_or(0);
    if s[best_axis] + FOLD_MARGIN < s[0] {
        projection.axis = ProjectionAxis::ALL[best_axis];
        projection.direction = dirs[best_axis];
    }
    Ok(projection)
}

/// The frame the points are projected in, and the choice that gave it: the
/// best-fit plane's ([`PlaneAxes::of`]) or, when [`choose_projection_from`]
/// picks an axis, the plane across that axis through the centroid.
pub(crate) fn projected_frame(pca: &Pca, sample: &HashSample) -> Result<(PlaneAxes, Projection)> {
    let best = PlaneAxes::of(pca)?;
    let projection = choose_projection_from(sample, &best)?;
    let axes = match projection.axis {
        ProjectionAxis::BestFitPlane => best,
        _ => axis_frame(pca, projection.direction),
    };
    Ok((axes, projection))
}

/// The frame across the unit `axis` through the centroid: the provisional
/// in-plane axis is the first principal direction projected onto the plane
/// (or the second, if the first is nearly along `axis`); the parameter axes
/// are the minimum-area rectangle's, as for the best-fit plane.
fn axis_frame(pca: &Pca, axis: Vector3) -> PlaneAxes {
    let flat = |v: Vector3| v - axis * v.dot(&axis);
    let (f0, f1) = (flat(pca.axes[0]), flat(pca.axes[1]));
    let a1 = orient(if f0.norm() >= f1.norm() { f0 } else { f1 }.normalize());
    PlaneAxes {
        origin: pca.centroid,
        a1,
        a2: axis.cross(&a1),
        normal: axis,
    }
}

/// The first pass of the best-fit plane over chunks of points: the
/// covariance sums about a reference point (the plane's normal) and the
/// [`fold_sample`] (the projection direction), both mergeable, so a
/// streamed or distributed run makes [`super::plane_parameters`]'s choice
/// in the pass it needs for the plane anyway. The hull and extents passes
/// ([`super::FlatHull`], [`super::PlaneExtents`]) follow in the frame
/// [`finish`](Self::finish) returns.
///
/// ```
/// use scanfit::base::{plane_parameters, PlaneMoments};
/// use scanfit::Point3;
/// let pts: Vec<Point3> = (0..3000)
///     .map(|k| {
///         let (x, y) = ((k % 60) as f64 / 59.0, (k / 60) as f64 / 49.0);
///         Point3::new(x, y, (-30.0 * (x - 0.3) * (x - 0.3)).exp() + 0.8 * x)
///     })
///     .collect();
/// // two chunks, summed apart and merged
/// let (mut a, mut b) = (PlaneMoments::new(pts[0]), PlaneMoments::new(pts[0]));
/// a.add(0, &pts[..1800]);
/// b.add(1800, &pts[1800..]);
/// a.merge(&b)?;
/// let (axes, projection) = a.finish()?;
/// let once = plane_parameters(&pts)?;
/// assert_eq!(projection.axis, once.projection.axis);
/// assert_eq!(axes.normal, once.normal);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneMoments {
    sums: CovarianceSums,
    sample: HashSample,
}

const MOMENTS_TAG: &[u8; 8] = b"SFPLMOM1";

impl PlaneMoments {
    /// No points yet; covariance sums about `reference` (a point of the
    /// data, the same for every chunk).
    pub fn new(reference: Point3) -> Self {
        Self {
            sums: CovarianceSums::new(reference),
            sample: fold_sample(),
        }
    }

    /// Adds `points`, the first of which is the `first`-th point of the
    /// whole data (counting from 0, in the order of one in-memory call).
    pub fn add(&mut self, first: u64, points: &[Point3]) {
        points.iter().for_each(|p| self.sums.add(p));
        self.sample.add(first, points);
    }

    /// Adds the moments of other points (the same reference point).
    pub fn merge(&mut self, other: &Self) -> Result<()> {
        self.sums.merge(&other.sums)?;
        self.sample.merge(&other.sample)
    }

    /// Points added.
    pub fn count(&self) -> f64 {
        self.sums.count()
    }

    /// The frame to project in and the choice of direction (its `extent`
    /// still 0: the extents pass gives it, [`super::PlaneMap::extent`]).
    ///
    /// Errors: no points, collinear points, the sample's normals failing.
    pub fn finish(&self) -> Result<(PlaneAxes, Projection)> {
        let pca = self.sums.finish().ok_or_else(|| Error::TooFewPoints {
            got: 0,
            needed: 3,
            what: "a best-fit plane".into(),
        })?;
        projected_frame(&pca, &self.sample)
    }

    /// The moments as exact bytes ([`crate::wire`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(MOMENTS_TAG);
        w.record(&self.sums.to_bytes());
        w.record(&self.sample.to_bytes());
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, MOMENTS_TAG, "the best-fit plane's moments")?;
        let sums = CovarianceSums::from_bytes(r.record()?)?;
        let sample = HashSample::from_bytes(r.record()?)?;
        r.end()?;
        if (sample.k(), sample.seed()) != (FOLD_SAMPLE, FOLD_SEED) {
            return Err(r.corrupt("a sample of another size or seed"));
        }
        Ok(Self { sums, sample })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::{plane_parameters, FlatHull, PlaneExtents};

    /// Franke's function on `n` seeded uniform points of the unit square.
    fn franke(n: usize) -> Vec<Point3> {
        crate::testdata::scattered(n, 29, [0.0, 0.0, 1.0, 1.0], crate::testdata::franke)
    }

    /// The moments of `pts` cut at `cuts`, each part through its bytes,
    /// merged in reverse order.
    fn moments_over(pts: &[Point3], cuts: &[usize]) -> PlaneMoments {
        let mut total = PlaneMoments::new(pts[0]);
        for w in cuts.windows(2).rev() {
            let mut part = PlaneMoments::new(pts[0]);
            part.add(w[0] as u64, &pts[w[0]..w[1]]);
            total
                .merge(&PlaneMoments::from_bytes(&part.to_bytes()).unwrap())
                .unwrap();
        }
        total
    }

    #[test]
    fn chunked_moments_choose_the_one_call_projection_and_parameters() {
        // a folding height field (z chosen) and the same data tilted 35
        // degrees about x (its tilt hides z: no axis is clean, the plane kept)
        let pts = franke(12_000);
        let (c, s) = (35f64.to_radians().cos(), 35f64.to_radians().sin());
        let tilted: Vec<Point3> = pts
            .iter()
            .map(|p| Point3::new(p.x, c * p.y - s * 0.1 * p.z, s * p.y + c * 0.1 * p.z))
            .collect();
        for (pts, axis) in [
            (&pts, ProjectionAxis::Z),
            (&tilted, ProjectionAxis::BestFitPlane),
        ] {
            let once = plane_parameters(pts).unwrap();
            assert_eq!(once.projection.axis, axis);
            for cuts in [
                vec![0, 12_000],
                vec![0, 1, 4000, 4000, 11_999, 12_000],
                vec![0, 3001, 6002, 9003, 12_000],
            ] {
                let m = moments_over(pts, &cuts);
                assert_eq!(m.count(), 12_000.0);
                let (axes, p) = m.finish().unwrap();
                assert_eq!(
                    (p.axis, p.fold_shares, p.sampled),
                    (
                        once.projection.axis,
                        once.projection.fold_shares,
                        once.projection.sampled
                    ),
                    "{cuts:?}"
                );
                // the hull and extents passes in that frame: the one-call map
                let mut hull = FlatHull::default();
                hull.add(&axes, pts);
                let mut ext = PlaneExtents::new(&axes, hull.rectangle_direction());
                ext.add(pts);
                let map = ext.finish().unwrap();
                assert!((map.normal - once.normal).norm() < 1e-12);
                assert!((map.e1 - once.e1).norm() < 1e-12);
                let worst = pts
                    .iter()
                    .zip(&once.uv)
                    .map(|(q, t)| {
                        let u = map.uv(q);
                        (u[0] - t[0]).abs().max((u[1] - t[1]).abs())
                    })
                    .fold(0.0, f64::max);
                assert!(worst < 1e-12, "{worst}");
            }
        }
        // another reference point does not merge; damaged bytes are refused
        let m = moments_over(&pts, &[0, 12_000]);
        assert!(PlaneMoments::new(pts[1]).merge(&m).is_err());
        let b = m.to_bytes();
        assert!(PlaneMoments::from_bytes(&b[..b.len() - 1]).is_err());
        // a sample of another size inside the record
        let mut w = Writer::new(MOMENTS_TAG);
        w.record(&CovarianceSums::new(pts[0]).to_bytes());
        w.record(&HashSample::new(10, FOLD_SEED).to_bytes());
        let e = PlaneMoments::from_bytes(&w.finish()).unwrap_err();
        assert!(e.to_string().contains("another size or seed"), "{e}");
    }
}
