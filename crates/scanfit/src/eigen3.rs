//! Eigenvalues and the smallest eigenvector of a symmetric 3 x 3 matrix in
//! closed form: the covariance of a point's neighbourhood, whose smallest
//! eigenvector is the point's normal ([`crate::cloud::normals`]).
//!
//! * Eigenvalues: the trigonometric solution of the characteristic cubic
//!   (Smith 1961, "Eigenvalues of a symmetric 3 x 3 matrix", CACM 4(4) 168):
//!   with `q = tr(A) / 3`, `p = sqrt(|A - q I|_F^2 / 6)`,
//!   `r = det((A - q I) / p) / 2` and `phi = acos(r) / 3`, the eigenvalues
//!   are `q + 2 p cos(phi + 2 pi j / 3)`, `j = 0, 1, 2`.
//! * The eigenvector of the smallest eigenvalue `l3`: the rows of
//!   `A - l3 I` span the plane perpendicular to it, so the largest of the
//!   three cross products of two rows points along it (Kopp 2008, "Efficient
//!   numerical diagonalization of hermitian 3x3 matrices", Int. J. Mod. Phys.
//!   C 19(3) 523, section 2.3). One Rayleigh-quotient step then replaces
//!   `l3` by `v^T A v` and takes the cross product again: the trigonometric
//!   `l3` carries an absolute error of a few `eps |A|`, the Rayleigh quotient
//!   of a vector `delta` off only `delta^2 |A|`.
//! * The returned eigenvalues: `l3` the Rayleigh quotient of the final
//!   vector, `l1` and `l2` those of the 2 x 2 matrix of `A` in an orthonormal
//!   basis of the plane perpendicular to it (where `l1` and `l2` repeat, the
//!   trigonometric form loses half their digits; the 2 x 2 form does not).
//!
//! The closed form is accurate only where the smallest eigenvalue stands
//! apart: the vector's angular error is about `eps l1 / (l2 - l3)` (and
//! `acos` amplifies the rounding of `r` as `l2` nears `l3`). Where
//! `l2 - l3 <= GAP * (l1 - l3)` (with [`GAP`] = 10^-3: a neighbourhood
//! close to a line, an isotropic blob, a zero matrix) [`smallest_eigen`]
//! returns `None` and the caller falls back to an iterative solver
//! (nalgebra's `SymmetricEigen`, [`crate::pca`]). Measured against that
//! solver on random covariances (the tests of this module): the smallest
//! eigenvectors agree within 1e-11 rad, the eigenvalues within
//! 1e-13 of `l1`.

use crate::Vector3;

/// The relative gap `(l2 - l3) / (l1 - l3)` below which [`smallest_eigen`]
/// declines (the closed form's vector would lose more than about
/// `eps * 10^3` of its direction before the Rayleigh step).
pub const GAP: f64 = 1e-3;

/// Eigenvalues (descending) and a unit eigenvector of the smallest one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmallestEigen {
    /// `l1 >= l2 >= l3`.
    pub values: [f64; 3],
    /// Unit eigenvector of `l3`, its largest-magnitude component positive
    /// (ties: the first).
    pub vector: Vector3,
}

/// The symmetric matrix `[[a00, a01, a02], [a01, a11, a12], [a02, a12, a22]]`
/// given as `[a00, a11, a22, a01, a02, a12]`: its eigenvalues and the
/// eigenvector of the smallest (see the module documentation), or `None`
/// where the smallest eigenvalue is not separated from the middle one by
/// more than [`GAP`] of the spread `l1 - l3` (then any vector in a plane is
/// nearly as good an eigenvector, and an iterative solver should decide),
/// and for a non-finite matrix.
///
/// ```
/// use scanfit::eigen3::smallest_eigen;
/// // diag(3, 2, 1) turned by 90 degrees about z: the smallest stays along z
/// let e = smallest_eigen(&[2.0, 3.0, 1.0, 0.0, 0.0, 0.0]).unwrap();
/// assert!((e.values[0] - 3.0).abs() < 1e-15 && (e.values[2] - 1.0).abs() < 1e-15);
/// assert!((e.vector.z - 1.0).abs() < 1e-15);
/// // a plane's covariance I - n n^T has its normal n as the smallest
/// // eigenvector (l1 = l2 = 1: the two largest may repeat)
/// let n = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
/// let a = [
///     1.0 - n[0] * n[0], 1.0 - n[1] * n[1], 1.0 - n[2] * n[2],
///     -n[0] * n[1], -n[0] * n[2], -n[1] * n[2],
/// ];
/// let e = smallest_eigen(&a).unwrap();
/// assert!((e.vector - scanfit::Vector3::from(n)).norm() < 1e-15);
/// assert!(e.values[2].abs() < 1e-15);
/// // an isotropic matrix has no distinguished smallest eigenvector
/// assert!(smallest_eigen(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).is_none());
/// ```
pub fn smallest_eigen(a: &[f64; 6]) -> Option<SmallestEigen> {
    // scale to entries of magnitude at most 1 (no overflow in the squares)
    let s = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(s > 0.0 && s.is_finite()) {
        return None;
    }
    let inv = 1.0 / s;
    let m = a.map(|x| x * inv);
    let [a00, a11, a22, a01, a02, a12] = m;
    let q = (a00 + a11 + a22) / 3.0;
    let (b00, b11, b22) = (a00 - q, a11 - q, a22 - q);
    let off = a01 * a01 + a02 * a02 + a12 * a12;
    let p2 = (b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * off) / 6.0;
    if p2 <= 0.0 {
        return None;
    }
    let p = p2.sqrt();
    // det(B) / 2 with B = (A - q I) / p
    let det = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02)
        + a02 * (a01 * a12 - b11 * a02);
    let r = (det / (2.0 * p2 * p)).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let third = 2.0 * std::f64::consts::FRAC_PI_3;
    let l1 = q + 2.0 * p * phi.cos();
    let l3 = q + 2.0 * p * (phi + third).cos();
    let l2 = 3.0 * q - l1 - l3;
    // (finite here: the scaled entries are at most 1 in magnitude)
    if l2 - l3 <= GAP * (l1 - l3) {
        return None;
    }
    let v = null_vector(&m, l3)?;
    // one Rayleigh-quotient step: l3 to second order in v's error, then v again
    let l3 = rayleigh(&m, &v);
    let v = null_vector(&m, l3)?;
    let l3 = rayleigh(&m, &v);
    let (l1, l2) = plane_eigenvalues(&m, &v);
    Some(SmallestEigen {
        values: [l1 * s, l2 * s, l3 * s],
        vector: canonical_sign(v),
    })
}

/// `A v`.
fn times(m: &[f64; 6], v: &Vector3) -> Vector3 {
    let [a00, a11, a22, a01, a02, a12] = *m;
    Vector3::new(
        a00 * v.x + a01 * v.y + a02 * v.z,
        a01 * v.x + a11 * v.y + a12 * v.z,
        a02 * v.x + a12 * v.y + a22 * v.z,
    )
}

/// `v^T A v` of a unit `v`.
fn rayleigh(m: &[f64; 6], v: &Vector3) -> f64 {
    v.dot(&times(m, v))
}

/// The two eigenvalues of `A` restricted to the plane perpendicular to the
/// unit eigenvector `v`, larger first: those of the 2 x 2 matrix in an
/// orthonormal basis of the plane (accurate also where they repeat, where
/// the trigonometric form loses half the digits).
fn plane_eigenvalues(m: &[f64; 6], v: &Vector3) -> (f64, f64) {
    let e1 = v.cross(&least_aligned_axis(v)).normalize();
    let e2 = v.cross(&e1);
    let (ae1, ae2) = (times(m, &e1), times(m, &e2));
    let (p, b, r) = (e1.dot(&ae1), e1.dot(&ae2), e2.dot(&ae2));
    let mean = 0.5 * (p + r);
    let rad = (0.25 * (p - r) * (p - r) + b * b).sqrt();
    (mean + rad, mean - rad)
}

/// The unit vector perpendicular to the rows of `A - l I`: the largest
/// cross product of two of them (`None` if all three vanish).
fn null_vector(m: &[f64; 6], l: f64) -> Option<Vector3> {
    let [a00, a11, a22, a01, a02, a12] = *m;
    let r0 = Vector3::new(a00 - l, a01, a02);
    let r1 = Vector3::new(a01, a11 - l, a12);
    let r2 = Vector3::new(a02, a12, a22 - l);
    let c = [r0.cross(&r1), r0.cross(&r2), r1.cross(&r2)];
    let n = c.map(|v| v.norm_squared());
    let best = if n[0] >= n[1] && n[0] >= n[2] {
        0
    } else if n[1] >= n[2] {
        1
    } else {
        2
    };
    (n[best] > 0.0).then(|| c[best] / n[best].sqrt())
}

/// The coordinate axis least aligned with `v` (its smallest component;
/// ties: the first): `v x axis` is a well-conditioned perpendicular.
pub(crate) fn least_aligned_axis(v: &Vector3) -> Vector3 {
    let a = v.abs();
    if a.x <= a.y && a.x <= a.z {
        Vector3::x()
    } else if a.y <= a.z {
        Vector3::y()
    } else {
        Vector3::z()
    }
}

/// `v` or `-v`, whichever has its largest-magnitude component positive.
fn canonical_sign(v: Vector3) -> Vector3 {
    let a = v.abs();
    let big = if a.x >= a.y && a.x >= a.z {
        v.x
    } else if a.y >= a.z {
        v.y
    } else {
        v.z
    };
    if big < 0.0 {
        -v
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::testutil::Rng;
    use nalgebra::{Matrix3, SymmetricEigen};

    fn packed(a: &Matrix3<f64>) -> [f64; 6] {
        [
            a[(0, 0)],
            a[(1, 1)],
            a[(2, 2)],
            a[(0, 1)],
            a[(0, 2)],
            a[(1, 2)],
        ]
    }

    /// nalgebra's eigenvalues (descending) and smallest eigenvector.
    fn reference(a: &Matrix3<f64>) -> ([f64; 3], Vector3) {
        let e = SymmetricEigen::new(*a);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&x, &y| e.eigenvalues[y].total_cmp(&e.eigenvalues[x]));
        (
            idx.map(|i| e.eigenvalues[i]),
            e.eigenvectors.column(idx[2]).into(),
        )
    }

    /// A random rotation (from a random unit quaternion).
    fn rotation(rng: &mut Rng) -> Matrix3<f64> {
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
            rng.uniform() - 0.5,
        ));
        *q.to_rotation_matrix().matrix()
    }

    /// Compares with nalgebra; returns (angle, eigenvalue error / l1).
    fn compare(a: &Matrix3<f64>) -> Option<(f64, f64)> {
        let e = smallest_eigen(&packed(a))?;
        let (values, v) = reference(a);
        // the sine of the angle (acos of the dot product is blind below 1.5e-8)
        let angle = e.vector.cross(&v).norm();
        let scale = values[0].abs().max(values[2].abs());
        let dv = (0..3)
            .map(|i| (e.values[i] - values[i]).abs() / scale)
            .fold(0.0, f64::max);
        assert!((e.vector.norm() - 1.0).abs() < 1e-15);
        Some((angle, dv))
    }

    #[test]
    fn random_covariances_agree_with_nalgebra() {
        let mut rng = Rng::new(7);
        let (mut worst_angle, mut worst_value, mut taken) = (0.0f64, 0.0f64, 0);
        for t in 0..20_000 {
            // covariance of 21 random points, squashed along a random axis
            // by up to 10^-6 (noisy planes to thick blobs), far from the origin
            let squash = 10f64.powf(-6.0 * rng.uniform());
            let r = rotation(&mut rng);
            let offset = Vector3::new(1e3, -2e3, 5e2) * (t % 3) as f64;
            let pts: Vec<Vector3> = (0..21)
                .map(|_| {
                    let p = Vector3::new(rng.uniform(), rng.uniform(), squash * rng.uniform());
                    r * p + offset
                })
                .collect();
            let mean = pts.iter().sum::<Vector3>() / 21.0;
            let cov = pts
                .iter()
                .map(|p| (p - mean) * (p - mean).transpose())
                .sum::<Matrix3<f64>>()
                / 21.0;
            if let Some((angle, dv)) = compare(&cov) {
                worst_angle = worst_angle.max(angle);
                worst_value = worst_value.max(dv);
                taken += 1;
            }
        }
        // the tolerances of the module documentation
        assert!(worst_angle < 1e-11, "angle {worst_angle:e}");
        assert!(worst_value < 1e-13, "eigenvalue {worst_value:e}");
        assert!(
            taken > 19_000,
            "closed form declined {} of 20000",
            20_000 - taken
        );
    }

    #[test]
    fn prescribed_spectra_including_repeated_and_near_repeated() {
        let mut rng = Rng::new(11);
        for spectrum in [
            [3.0, 2.0, 1.0],
            [1.0, 1.0, 0.0],   // disk: the two largest repeated
            [1.0, 1.0, 1e-12], // nearly flat disk
            [1.0, 0.5, 0.0],   // exact plane
            [1.0, 1e-2, 0.0],  // an elongated plane
            [5.0, 5.0, -1.0],  // indefinite
            [1e-30, 5e-31, 1e-32],
            [1e30, 5e29, 1e28],
            [1.0, 0.0, -1.0],
        ] {
            for _ in 0..200 {
                let r = rotation(&mut rng);
                let d = Matrix3::from_diagonal(&Vector3::from(spectrum));
                let a = r * d * r.transpose();
                let a = (a + a.transpose()) / 2.0;
                let (angle, dv) = compare(&a).unwrap_or_else(|| panic!("{spectrum:?} declined"));
                let want = r.column(2).into_owned();
                // the rotated axis itself (the matrix is rounded to about eps)
                let off = smallest_eigen(&packed(&a))
                    .map(|e| e.vector.cross(&want).norm())
                    .unwrap_or(1.0);
                assert!(
                    angle < 1e-11 && dv < 1e-13,
                    "{spectrum:?}: {angle:e} {dv:e}"
                );
                assert!(off < 1e-13, "{spectrum:?}: {off:e}");
            }
        }
    }

    #[test]
    fn declines_where_the_smallest_is_not_separated() {
        let mut rng = Rng::new(3);
        for spectrum in [
            [1.0, 1.0, 1.0],
            [2.0, 1.0, 1.0],        // a line's covariance: l2 = l3
            [2.0, 1.0 + 1e-9, 1.0], // nearly so
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
        ] {
            let r = rotation(&mut rng);
            let a = r * Matrix3::from_diagonal(&Vector3::from(spectrum)) * r.transpose();
            assert!(smallest_eigen(&packed(&a)).is_none(), "{spectrum:?}");
        }
        assert!(smallest_eigen(&[f64::NAN, 1.0, 0.0, 0.0, 0.0, 0.0]).is_none());
        assert!(smallest_eigen(&[f64::INFINITY, 1.0, 0.0, 0.0, 0.0, 0.0]).is_none());
        // just above the gap it answers, and accurately
        let a = Matrix3::from_diagonal(&Vector3::new(1.0, 2.5e-3, 0.0));
        let r = rotation(&mut rng);
        let a = r * a * r.transpose();
        let (angle, _) = compare(&a).unwrap();
        assert!(angle < 1e-11, "{angle:e}");
    }

    #[test]
    fn the_sign_is_canonical() {
        let e = smallest_eigen(&[2.0, 3.0, 1.0, 0.0, 0.0, 0.0]).unwrap();
        assert_eq!(e.vector, Vector3::z());
        let n = Vector3::new(-0.6, 0.0, 0.8);
        let a = Matrix3::identity() - n * n.transpose();
        let e = smallest_eigen(&packed(&a)).unwrap();
        assert!((e.vector - n).norm() < 1e-15, "{}", e.vector);
        let n = Vector3::new(-0.8, 0.0, 0.6);
        let a = Matrix3::identity() - n * n.transpose();
        let e = smallest_eigen(&packed(&a)).unwrap();
        assert!((e.vector + n).norm() < 1e-15, "{}", e.vector);
    }
}
