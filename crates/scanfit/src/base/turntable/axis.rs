//! The turntable's axis and centre ([TURN17] section 3.2).
//!
//! The paper assumes the turntable axis is `y` and works in a frame where the
//! views look from `+z`. [`CylinderFrame`] is that frame for any axis: local
//! coordinates `(x, h, z) = ((p - c0).e1, (p - c0).a, (p - c0).e2)` with
//! `e1 x a = e2`, so for `a = y` it is the paper's frame up to the shift by
//! `c0`. The centre `c0` is the midpoint of the two farthest points of the
//! cloud projected on the plane normal to the axis, found as in Ritter's
//! bounding sphere (Ritter 1990, "An efficient bounding sphere", Graphics
//! Gems: from any point the farthest point `y`, from `y` the farthest `z`);
//! its height is the middle of the cloud's extent along the axis.

use crate::{pca, Error, Point3, Result, Vector3};

/// How the turntable axis is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum AxisChoice {
    /// A given direction (need not be unit; `y` is the paper's).
    Given(Vector3),
    /// The principal axis of the cloud: the eigenvector of the largest
    /// covariance eigenvalue (default). Right for clouds longer along the
    /// axis than across it (heads, bottles, arms); a squat cloud (a wheel)
    /// needs the axis given.
    #[default]
    Principal,
}

/// The local frame of the virtual turntable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderFrame {
    /// The centre `c0` (eq. 17): midpoint of the farthest pair across the
    /// axis, at the middle height of the cloud.
    pub centre: Point3,
    /// Unit axis `a` (the paper's `y`).
    pub axis: Vector3,
    /// Unit `e1` (the paper's `x`), normal to the axis.
    pub e1: Vector3,
    /// Unit `e2 = e1 x a` (the paper's `z`).
    pub e2: Vector3,
    /// Extent of the cloud along the axis, `(h_min, h_max)` relative to the centre.
    pub height: (f64, f64),
    /// Largest distance of a point from the axis (the bounding cylinder's radius).
    pub radius: f64,
}

impl CylinderFrame {
    /// The frame of `points` around the chosen axis.
    pub fn of(points: &[Point3], choice: AxisChoice) -> Result<Self> {
        crate::validate_points(points)?;
        if points.len() < 4 {
            return Err(Error::TooFewPoints {
                got: points.len(),
                needed: 4,
                what: "a turntable frame".into(),
            });
        }
        let axis = match choice {
            AxisChoice::Given(v) => {
                let n = v.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(Error::InvalidInput(format!(
                        "turntable axis {v:?} must be finite and non-zero; give e.g. y or 0,1,0"
                    )));
                }
                v / n
            }
            AxisChoice::Principal => principal_axis(points)?,
        };
        // e1: the world axis least aligned with `a`, made normal to it (x for a = y)
        let world = [Vector3::x(), Vector3::y(), Vector3::z()];
        let mut b = world[0];
        for w in world {
            if w.dot(&axis).abs() < b.dot(&axis).abs() - 1e-12 {
                b = w;
            }
        }
        let e1 = (b - b.dot(&axis) * axis).normalize();
        let e2 = e1.cross(&axis);
        // Ritter's farthest pair on the plane normal to the axis
        let origin = points[0];
        let flat = |p: &Point3| {
            let d = p - origin;
            nalgebra::Vector2::new(d.dot(&e1), d.dot(&e2))
        };
        let farthest = |from: nalgebra::Vector2<f64>| {
            points
                .iter()
                .map(flat)
                .max_by(|a, b| {
                    (a - from)
                        .norm_squared()
                        .total_cmp(&(b - from).norm_squared())
                })
                .unwrap_or(from)
        };
        let y = farthest(flat(&points[0]));
        let z = farthest(y);
        let mid = 0.5 * (y + z);
        let (mut hmin, mut hmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in points {
            let h = (p - origin).dot(&axis);
            hmin = hmin.min(h);
            hmax = hmax.max(h);
        }
        // relative to the cloud's size (not to 1: tiny clouds are clouds too)
        let size = crate::geom::bbox_diagonal(points).max(f64::MIN_POSITIVE);
        if hmax - hmin <= 1e-9 * size {
            return Err(Error::InvalidInput(format!(
                "the points have no extent along the turntable axis {axis:?}: a flat ring has no layers; give the axis of the cylinder (--axis)"
            )));
        }
        let hmid = 0.5 * (hmin + hmax);
        let centre = origin + mid.x * e1 + mid.y * e2 + hmid * axis;
        let radius = points
            .iter()
            .map(|p| {
                let d = p - centre;
                (d - d.dot(&axis) * axis).norm()
            })
            .fold(0.0, f64::max);
        if radius <= 1e-9 * size {
            return Err(Error::InvalidInput(
                "all points lie on the turntable axis: there is nothing to turn; check the axis"
                    .into(),
            ));
        }
        Ok(Self {
            centre,
            axis,
            e1,
            e2,
            height: (hmin - hmid, hmax - hmid),
            radius,
        })
    }

    /// Local coordinates `(x, h, z)` of `p`.
    pub fn to_local(&self, p: &Point3) -> Point3 {
        let d = p - self.centre;
        Point3::new(d.dot(&self.e1), d.dot(&self.axis), d.dot(&self.e2))
    }

    /// The world point of local coordinates `(x, h, z)`.
    pub fn to_world(&self, l: &Point3) -> Point3 {
        self.centre + l.x * self.e1 + l.y * self.axis + l.z * self.e2
    }

    /// Angle of `p` around the axis, `atan2(x, z)` in local coordinates: 0
    /// towards `e2` (the first view's `+z`), increasing towards `e1`.
    pub fn angle(&self, p: &Point3) -> f64 {
        let l = self.to_local(p);
        l.x.atan2(l.z)
    }
}

/// The principal axis of `points` (largest covariance eigenvalue).
pub fn principal_axis(points: &[Point3]) -> Result<Vector3> {
    let pc =
        pca(points).ok_or_else(|| Error::InvalidInput("no points to find an axis of".into()))?;
    if pc.values[0].is_nan() || pc.values[0] <= 0.0 {
        return Err(Error::InvalidInput(
            "the points have no spread: no principal axis; give the axis".into(),
        ));
    }
    Ok(pc.axes[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_frame_for_the_y_axis() {
        let pts: Vec<Point3> = (0..400)
            .map(|i| {
                let t = i as f64 * 0.7;
                Point3::new(3.0 + 2.0 * t.cos(), (i % 5) as f64, -1.0 + 2.0 * t.sin())
            })
            .collect();
        let f = CylinderFrame::of(&pts, AxisChoice::Given(Vector3::y())).unwrap();
        assert_eq!(f.e1, Vector3::x());
        assert_eq!(f.e2, Vector3::z());
        assert!(
            (f.centre - Point3::new(3.0, 2.0, -1.0)).norm() < 0.01,
            "{f:?}"
        );
        // Ritter's pair is the farthest pair only approximately
        assert!((f.radius - 2.0).abs() < 0.01);
        assert_eq!(f.height, (-2.0, 2.0));
        let p = Point3::new(1.0, 2.0, 3.0);
        assert!((f.to_world(&f.to_local(&p)) - p).norm() < 1e-12);
        // angle 0 towards +z, +90 degrees towards +x
        assert!(f.angle(&(f.centre + Vector3::z())).abs() < 1e-12);
        let q = f.angle(&(f.centre + Vector3::x()));
        assert!((q - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn principal_axis_of_a_long_cylinder() {
        let a = Vector3::new(1.0, 2.0, 2.0) / 3.0;
        let f = CylinderFrame::of(
            &(0..400)
                .map(|i| {
                    let t = i as f64 * 0.37;
                    let h = (i as f64 / 400.0 - 0.5) * 10.0;
                    let e1 = Vector3::new(2.0, -1.0, 0.0) / 5f64.sqrt();
                    let e2 = a.cross(&e1);
                    Point3::origin() + h * a + t.cos() * e1 + t.sin() * e2
                })
                .collect::<Vec<_>>(),
            AxisChoice::Principal,
        )
        .unwrap();
        assert!(f.axis.dot(&a).abs() > 1.0 - 1e-4);
        assert!((f.radius - 1.0).abs() < 0.03, "{f:?}");
        assert!((f.e1.dot(&f.axis)).abs() < 1e-12 && (f.e2.dot(&f.axis)).abs() < 1e-12);
    }

    #[test]
    fn a_flat_ring_across_the_axis_is_an_error() {
        let pts: Vec<Point3> = (0..20)
            .map(|i| {
                let t = i as f64 * 0.3;
                Point3::new(t.cos(), 0.0, t.sin())
            })
            .collect();
        let e = CylinderFrame::of(&pts, AxisChoice::Given(Vector3::y())).unwrap_err();
        assert!(e.to_string().contains("no extent along"), "{e}");
    }

    #[test]
    fn zero_axis_is_an_error() {
        let pts = vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ];
        let e = CylinderFrame::of(&pts, AxisChoice::Given(Vector3::zeros())).unwrap_err();
        assert!(e.to_string().contains("non-zero"));
    }
}
