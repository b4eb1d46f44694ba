//! The exponential family of parameterizations (Lee 1989): uniform (a = 0),
//! centripetal (a = 1/2), chord length (a = 1) and general exponential a.
//!
//! [CURVE12] Table 1 and section 2.1: `u_0 = 0`, `u_n = 1`,
//! `u_i = u_{i-1} + |P_i - P_{i-1}|^a / sum_j |P_j - P_{j-1}|^a`.
//! Each parameter is the running sum divided by the total (not a sum of
//! divided increments), and the last is set to exactly 1.

use crate::{Point3, Result};

/// Parameters of the exponential method with exponent `a` (0 = uniform,
/// 0.5 = centripetal, 1 = chord length). With `closed`, the chord from the last
/// point back to the first is included and `points.len() + 1` parameters are
/// returned (the last, 1.0, belongs to the repeated first point).
///
/// Zero-length chords give coincident parameters; [`super::parameterize`]
/// reports them as an error naming the two points.
pub fn params(points: &[Point3], a: f64, closed: bool) -> Result<Vec<f64>> {
    let n = points.len();
    let segs = if closed { n } else { n - 1 };
    let mut acc = Vec::with_capacity(segs + 1);
    acc.push(0.0);
    let mut total = 0.0;
    for i in 0..segs {
        let d = chord(&points[i], &points[(i + 1) % n]);
        // a = 0 is uniform whatever the distance (0^0 = 1 by convention)
        total += if a == 0.0 { 1.0 } else { d.powf(a) };
        acc.push(total);
    }
    if total > 0.0 {
        for v in acc.iter_mut() {
            *v /= total;
        }
    }
    if let Some(last) = acc.last_mut() {
        *last = 1.0;
    }
    Ok(acc)
}

/// Euclidean distance computed as `sqrt(dx*dx + dy*dy + dz*dz)`.
#[inline]
pub(crate) fn chord(a: &Point3, b: &Point3) -> f64 {
    let (dx, dy, dz) = (b.x - a.x, b.y - a.y, b.z - a.z);
    (dx * dx + dy * dy + dz * dz).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    fn pts() -> Vec<Point3> {
        vec![
            Point3::new(0., 0., 0.),
            Point3::new(1., 0., 0.),
            Point3::new(1., 2., 0.),
            Point3::new(4., 6., 0.),
        ]
    }

    #[test]
    fn known_values() {
        let p = pts();
        assert_eq!(
            params(&p, 0.0, false).unwrap(),
            vec![0., 1. / 3., 2. / 3., 1.]
        );
        let c = params(&p, 1.0, false).unwrap();
        assert!((c[1] - 0.125).abs() < 1e-15 && (c[2] - 0.375).abs() < 1e-15);
        let s = params(&p, 0.5, false).unwrap();
        let tot = 1.0 + 2f64.sqrt() + 5f64.sqrt();
        assert!((s[1] - 1.0 / tot).abs() < 1e-15);
        let closed = params(&p, 1.0, true).unwrap();
        assert_eq!(closed.len(), 5);
        let loop_len = 8.0 + 52f64.sqrt();
        assert!((closed[3] - 8.0 / loop_len).abs() < 1e-15);
    }

    #[test]
    fn invariant_under_rigid_motion_and_scaling() {
        let p = pts();
        let rot = Rotation3::from_axis_angle(&Vector3::y_axis(), 0.7)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), -1.1);
        let moved: Vec<Point3> = p
            .iter()
            .map(|q| Point3::from(rot * q.coords * 3.7 + Vector3::new(10., -5., 2.)))
            .collect();
        for a in [0.5, 0.8, 1.0] {
            let u = params(&p, a, false).unwrap();
            let v = params(&moved, a, false).unwrap();
            for (x, y) in u.iter().zip(&v) {
                assert!((x - y).abs() < 1e-14, "a={a}: {x} vs {y}");
            }
        }
    }
}
