//! The one point/vector type of the library, and input validation shared by all algorithms.

use rayon::prelude::*;

use crate::wire::{Reader, Writer};
use crate::{Error, Result};

/// A point in 3D space (f64).
pub type Point3 = nalgebra::Point3<f64>;
/// A vector in 3D space (f64).
pub type Vector3 = nalgebra::Vector3<f64>;

/// Largest coordinate magnitude the library accepts: squared distances of
/// larger values overflow f64.
pub const MAX_COORDINATE: f64 = 1e150;

/// Checks that every coordinate is finite and of a magnitude whose squared
/// distances stay representable; the error names the first bad point.
pub fn validate_points(points: &[Point3]) -> Result<()> {
    // the first bad point and the extent, in one pass on all threads (at
    // 10^7 points every pass over them costs about as much as reading a
    // binary file)
    let scan = scan(points);
    if let Some((index, p)) = scan.first_bad.and_then(|i| Some((i, points.get(i)?))) {
        if let Some(v) = p.coords.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                index,
                value: v.to_string(),
            });
        }
        if let Some(v) = p.coords.iter().find(|v| v.abs() > MAX_COORDINATE) {
            return Err(Error::BadPoint {
                index,
                problem: format!(
                    "has a coordinate of magnitude {v:e}; values beyond {MAX_COORDINATE:e} overflow squared distances, rescale the data"
                ),
            });
        }
    }
    // tiny data: distances would underflow (points that differ would coincide)
    let extent = scan.bbox.map_or(0.0, |(lo, hi)| (hi - lo).norm());
    if points.len() > 1 && extent > 0.0 && extent < 1e-140 {
        return Err(Error::InvalidInput(format!(
            "the points span only {extent:e}; distances this small underflow, rescale the data"
        )));
    }
    Ok(())
}

/// Checks that no two consecutive points coincide (relative to the data's size).
/// With `closed`, the last and first points are consecutive too.
pub(crate) fn validate_distinct_consecutive(points: &[Point3], closed: bool) -> Result<()> {
    let scale = bbox_diagonal(points).max(f64::MIN_POSITIVE);
    let tol = scale * 1e-14;
    let n = points.len();
    let pairs = if closed && n > 1 {
        n
    } else {
        n.saturating_sub(1)
    };
    for i in 0..pairs {
        let j = (i + 1) % n;
        let d = (points[j] - points[i]).norm();
        if d <= tol {
            return Err(Error::DuplicatePoints {
                first: i,
                second: j,
                distance: d,
            });
        }
    }
    Ok(())
}

/// Length of the diagonal of the axis-aligned bounding box (0 for no points).
pub(crate) fn bbox_diagonal(points: &[Point3]) -> f64 {
    scan(points).bbox.map_or(0.0, |(lo, hi)| (hi - lo).norm())
}

/// What one pass over points finds: their axis-aligned bounding box and
/// the first point with a non-finite coordinate or one beyond
/// [`MAX_COORDINATE`].
pub(crate) struct Scan {
    /// The bounding box (`None` without points), with the comparisons of
    /// `Point3::inf` and `sup` (a NaN coordinate is kept only when it comes
    /// last).
    pub bbox: Option<(Point3, Point3)>,
    /// The index of the first bad point.
    pub first_bad: Option<usize>,
}

/// Points per task of [`scan`].
const SCAN_CHUNK: usize = 1 << 14;

/// [`Scan`] of `points`, in parallel over chunks (plain arrays, which the
/// compiler keeps in registers: nalgebra's generic component maps took
/// several times as long).
pub(crate) fn scan(points: &[Point3]) -> Scan {
    type Part = ([f64; 3], [f64; 3], Option<usize>);
    let Some(first) = points.first() else {
        return Scan {
            bbox: None,
            first_bad: None,
        };
    };
    let first: [f64; 3] = first.coords.into();
    let grow = |(mut lo, mut hi, bad): Part, p: &[f64; 3], at: Option<usize>| {
        for k in 0..3 {
            lo[k] = if lo[k] <= p[k] { lo[k] } else { p[k] };
            hi[k] = if hi[k] >= p[k] { hi[k] } else { p[k] };
        }
        let wrong = p.iter().any(|v| !v.is_finite() || v.abs() > MAX_COORDINATE);
        (lo, hi, bad.or(at.filter(|_| wrong)))
    };
    let (lo, hi, first_bad) = points
        .par_chunks(SCAN_CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            chunk
                .iter()
                .enumerate()
                .fold((first, first, None), |s, (i, p)| {
                    grow(s, &p.coords.into(), Some(c * SCAN_CHUNK + i))
                })
        })
        .reduce(
            || (first, first, None),
            |a, b| {
                let (lo, hi, bad) = grow(grow(a, &b.0, None), &b.1, None);
                (lo, hi, bad.or(b.2))
            },
        );
    Scan {
        bbox: Some((lo.into(), hi.into())),
        first_bad,
    }
}

/// Principal component analysis of a point set: centroid, covariance
/// eigenvalues (descending) and the matching unit axes. The last axis is the
/// normal of the best-fit (total least squares) plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pca {
    /// Mean of the points.
    pub centroid: Point3,
    /// Eigenvalues of the covariance matrix, largest first (variances along the axes).
    pub values: [f64; 3],
    /// Unit eigenvectors, in the order of `values`; the signs are the eigen solver's.
    pub axes: [Vector3; 3],
}

impl Pca {
    /// Surface variation `l3 / (l1 + l2 + l3)` (Pauly et al. 2002): 0 on a
    /// plane, 1/3 for isotropic noise; a cheap curvature/noise indicator.
    pub fn variation(&self) -> f64 {
        surface_variation(&self.values)
    }
}

/// [`Pca::variation`] of eigenvalues `l1 >= l2 >= l3`.
pub(crate) fn surface_variation(values: &[f64; 3]) -> f64 {
    let s = values[0] + values[1] + values[2];
    if s > 0.0 {
        values[2].max(0.0) / s
    } else {
        0.0
    }
}

/// Centroid and covariance of `points` (`None` for no points), the
/// covariance as `[c00, c11, c22, c01, c02, c12]`. It is accumulated about
/// the first point and then re-centred, which keeps it accurate for
/// coordinates far from the origin (georeferenced scans). The sums are
/// [`CovarianceSums`]' (one accumulation for the normals' neighbourhoods
/// and the chunked PCA).
pub(crate) fn covariance(points: impl IntoIterator<Item = Vector3>) -> Option<(Point3, [f64; 6])> {
    let mut it = points.into_iter();
    let first = it.next()?;
    let mut sums = CovarianceSums::new(Point3::from(first));
    // the first point adds zeros: counted, not summed
    sums.n = 1.0;
    for p in it {
        sums.add_offset(p - first);
    }
    Some(sums.centred())
}

/// PCA of `points` (`None` for no points). The covariance is accumulated
/// about the first point and then re-centred, which keeps it accurate for
/// coordinates far from the origin (georeferenced scans).
pub fn pca<'a>(points: impl IntoIterator<Item = &'a Point3>) -> Option<Pca> {
    let mut it = points.into_iter();
    let first = it.next()?;
    // the first point adds zeros: the same sums as starting the count at 1
    let mut sums = CovarianceSums::new(*first);
    sums.add(first);
    for p in it {
        sums.add(p);
    }
    sums.finish()
}

/// The sums behind [`pca`] (count, sum of `p - r` and of `(p - r)(p - r)^T`
/// about a reference point `r`), which can be built in pieces: points added
/// chunk by chunk, and the sums of other chunks with the same reference
/// merged, give the PCA of all of them (equal to [`pca`] with `r` its first
/// point up to the rounding of the merged additions).
///
/// ```
/// use scanfit::{pca, CovarianceSums, Point3};
/// let pts: Vec<Point3> = (0..50).map(|k| Point3::new(k as f64, (k * k % 7) as f64, 0.5)).collect();
/// let (mut a, mut b) = (CovarianceSums::new(pts[0]), CovarianceSums::new(pts[0]));
/// pts[..20].iter().for_each(|p| a.add(p));
/// pts[20..].iter().for_each(|p| b.add(p));
/// a.merge(&b)?;
/// let (merged, once) = (a.finish().unwrap(), pca(&pts).unwrap());
/// assert!((merged.centroid - once.centroid).norm() < 1e-12);
/// assert!((merged.values[0] - once.values[0]).abs() < 1e-12 * once.values[0]);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CovarianceSums {
    reference: Vector3,
    n: f64,
    sum: Vector3,
    /// The distinct sums of `(p - r)(p - r)^T`: xx, yy, zz, xy, xz, yz.
    cov: [f64; 6],
}

const COVARIANCE_TAG: &[u8; 8] = b"SFCOVS01";

impl CovarianceSums {
    /// No points yet; sums about `reference` (a point of the data keeps them
    /// accurate far from the origin).
    pub fn new(reference: Point3) -> Self {
        Self {
            reference: reference.coords,
            n: 0.0,
            sum: Vector3::zeros(),
            cov: [0.0; 6],
        }
    }

    /// Adds one point.
    #[inline]
    pub fn add(&mut self, p: &Point3) {
        self.add_offset(p.coords - self.reference);
    }

    /// Adds the point at `d` from the reference.
    #[inline]
    fn add_offset(&mut self, d: Vector3) {
        self.sum += d;
        self.cov[0] += d.x * d.x;
        self.cov[1] += d.y * d.y;
        self.cov[2] += d.z * d.z;
        self.cov[3] += d.x * d.y;
        self.cov[4] += d.x * d.z;
        self.cov[5] += d.y * d.z;
        self.n += 1.0;
    }

    /// Points added (over all merged sums).
    pub fn count(&self) -> f64 {
        self.n
    }

    /// Adds the sums of other points (the same reference point, bit for bit).
    pub fn merge(&mut self, other: &Self) -> Result<()> {
        if self.reference != other.reference {
            return Err(Error::InvalidInput(format!(
                "cannot merge covariance sums about different reference points ({:?} and {:?}); every chunk must be summed about the same point",
                self.reference, other.reference
            )));
        }
        self.sum += other.sum;
        for (a, b) in self.cov.iter_mut().zip(&other.cov) {
            *a += b;
        }
        self.n += other.n;
        Ok(())
    }

    /// The PCA of the points added (`None` for none).
    pub fn finish(&self) -> Option<Pca> {
        if self.n == 0.0 {
            return None;
        }
        let (centroid, cov) = self.centred();
        Some(pca_of(centroid, &cov))
    }

    /// The centroid and the covariance about it (of at least one point), in
    /// [`covariance`]'s form.
    fn centred(&self) -> (Point3, [f64; 6]) {
        let (n, c) = (self.n, &self.cov);
        let m = self.sum / n;
        let cov = [
            c[0] / n - m.x * m.x,
            c[1] / n - m.y * m.y,
            c[2] / n - m.z * m.z,
            c[3] / n - m.x * m.y,
            c[4] / n - m.x * m.z,
            c[5] / n - m.y * m.z,
        ];
        (Point3::from(self.reference + m), cov)
    }

    /// The sums as exact bytes ([`crate::wire`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(COVARIANCE_TAG);
        self.write(&mut w);
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, COVARIANCE_TAG, "covariance sums")?;
        let s = Self::read(&mut r)?;
        r.end()?;
        Ok(s)
    }

    /// Writes the fields into a record.
    pub fn write(&self, w: &mut Writer) {
        w.f64s(self.reference.as_slice());
        w.f64(self.n);
        w.f64s(self.sum.as_slice());
        // the whole symmetric matrix, column by column (the format of the
        // first version, which summed all nine)
        let [xx, yy, zz, xy, xz, yz] = self.cov;
        w.f64s(&[xx, xy, xz, xy, yy, yz, xz, yz, zz]);
    }

    /// Reads the fields [`write`](Self::write) wrote.
    pub fn read(r: &mut Reader<'_>) -> Result<Self> {
        let reference = r.f64s()?;
        let n = r.f64()?;
        let (sum, cov) = (r.f64s()?, r.f64s()?);
        if reference.len() != 3 || sum.len() != 3 || cov.len() != 9 {
            return Err(r.corrupt("the vectors of covariance sums"));
        }
        Ok(Self {
            reference: Vector3::from_column_slice(&reference),
            n,
            sum: Vector3::from_column_slice(&sum),
            cov: [cov[0], cov[4], cov[8], cov[3], cov[6], cov[7]],
        })
    }
}

/// The PCA of a covariance from [`covariance`] (nalgebra's iterative
/// symmetric eigen solver).
pub(crate) fn pca_of(centroid: Point3, c: &[f64; 6]) -> Pca {
    let cov = nalgebra::Matrix3::new(c[0], c[3], c[4], c[3], c[1], c[5], c[4], c[5], c[2]);
    let eig = nalgebra::SymmetricEigen::new(cov);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    Pca {
        centroid,
        values: idx.map(|i| eig.eigenvalues[i]),
        axes: idx.map(|i| eig.eigenvectors.column(i).into()),
    }
}
