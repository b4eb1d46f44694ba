//! Computing relative to the data's centre (issue 14 item 6).
//!
//! Floating-point arithmetic on coordinates far from the origin loses the
//! digits that describe the shape: at an offset of `1e15` a double resolves
//! `0.125`, and every sum of squares, every `S(u, v) - P` and every
//! Gram matrix of the raw coordinates rounds at that level, so fits degrade
//! and point inversion never meets a relative convergence test. Every
//! pipeline therefore translates its input so that the data's bounding-box
//! centre is at the origin, computes there, and translates the result back:
//! a B-spline (also a rational one) translates with its control points, a
//! Coons patch with its boundary curves, a PDE surface with its Coons patch
//! (the sine deformation is a displacement), and distances, parameters and
//! statistics do not change.
//!
//! The translation is exact: a coordinate is shifted only when its midpoint
//! `c` is farther from 0 than the data's extent `w` in it, so every value
//! `x` of the data lies in `[c/2, 2c]` and `x - c` is exactly representable
//! (Sterbenz's lemma). The centred data therefore carry every bit of the
//! input, and translating the results back rounds them only at the input's
//! own resolution (`|c| * f64::EPSILON`). Data that already straddle the
//! origin are not copied or changed at all.

use std::borrow::Cow;

use crate::{Point3, PointCloud, Result, Vector3};

/// The translation that moves data to the origin, and its inverse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Centring {
    centre: Vector3,
}

impl Centring {
    /// The centring of `points`: per coordinate the bounding-box midpoint
    /// where it is larger than the data's extent in that coordinate, else 0.
    ///
    /// ```
    /// use scanfit::centring::Centring;
    /// use scanfit::{Point3, Vector3};
    /// let pts = [Point3::new(1e15, 2.0, -1.0), Point3::new(1e15 + 8.0, 3.0, 1.0)];
    /// let c = Centring::of(&pts);
    /// assert_eq!(c.centre(), Vector3::new(1e15 + 4.0, 2.5, 0.0));
    /// // the shift is exact: the centred data keep every bit of the input
    /// let local = c.points(&pts);
    /// assert_eq!(local[1].x, 4.0);
    /// assert_eq!(local[1].x + c.centre().x, pts[1].x);
    /// ```
    pub fn of(points: &[Point3]) -> Self {
        let Some((lo, hi)) = crate::pipeline::assess::bounding_box(points) else {
            return Self {
                centre: Vector3::zeros(),
            };
        };
        let mut centre = Vector3::zeros();
        for k in 0..3 {
            let (a, b) = (lo[k], hi[k]);
            if !(a.is_finite() && b.is_finite()) {
                continue;
            }
            let mid = 0.5 * a + 0.5 * b;
            if mid.abs() > b - a {
                centre[k] = mid;
            }
        }
        Self { centre }
    }

    /// The translation subtracted from the data (zero where no shift is needed).
    pub fn centre(&self) -> Vector3 {
        self.centre
    }

    /// Whether the data are used as they are.
    pub fn is_identity(&self) -> bool {
        self.centre == Vector3::zeros()
    }

    /// `points` moved by `-centre`.
    pub fn points(&self, points: &[Point3]) -> Vec<Point3> {
        points.iter().map(|p| p - self.centre).collect()
    }

    /// `cloud` moved by `-centre`, with its attributes; the cloud itself
    /// (no copy) when no shift is needed.
    pub fn cloud<'c>(&self, cloud: &'c PointCloud) -> Result<Cow<'c, PointCloud>> {
        if self.is_identity() {
            return Ok(Cow::Borrowed(cloud));
        }
        let mut local = PointCloud::new(self.points(cloud.points()))?;
        for a in cloud.attributes() {
            local.set_attribute(&a.name, a.values.clone())?;
        }
        Ok(Cow::Owned(local))
    }

    /// `value` computed on the centred data, moved back to the data's place.
    pub fn restore<T: Translate>(&self, mut value: T) -> T {
        if !self.is_identity() {
            value.translate(&self.centre);
        }
        value
    }
}

/// Geometry that can be moved by a vector: the results of the pipelines,
/// mapped back from the centred frame by [`Centring::restore`].
pub trait Translate {
    /// Adds `by` to every position (control points, points, origins); leaves
    /// directions, distances and parameters alone.
    fn translate(&mut self, by: &Vector3);
}

impl Translate for Point3 {
    fn translate(&mut self, by: &Vector3) {
        *self += by;
    }
}

impl<T: Translate> Translate for Vec<T> {
    fn translate(&mut self, by: &Vector3) {
        for x in self {
            x.translate(by);
        }
    }
}

impl<T: Translate> Translate for Option<T> {
    fn translate(&mut self, by: &Vector3) {
        if let Some(x) = self {
            x.translate(by);
        }
    }
}

impl<T: Translate, E> Translate for std::result::Result<T, E> {
    fn translate(&mut self, by: &Vector3) {
        if let Ok(x) = self {
            x.translate(by);
        }
    }
}

/// Implements [`Translate`] for a struct by translating the listed fields.
macro_rules! translate_fields {
    ($($ty:ty => [$($field:ident),+]);+ $(;)?) => {
        $(impl Translate for $ty {
            fn translate(&mut self, by: &Vector3) {
                $(self.$field.translate(by);)+
            }
        })+
    };
}

translate_fields! {
    crate::project::Inversion => [point];
    crate::pipeline::assess::Assessment => [inversions];
    crate::base::BoundaryCurve => [curve];
    crate::cloud::boundary::Boundary => [plane];
    crate::cloud::boundary::BoundaryPlane => [origin];
    crate::base::CoonsFromCloud => [patch, boundary, side_points, curves];
    crate::pde::PdeSurface => [coons];
    crate::pde::PdeFit => [surface];
    crate::base::turntable::CylinderFrame => [centre];
    crate::base::turntable::LayerCurves => [curves];
    crate::base::turntable::Turntable => [frame, loops, layers, initial_base, base, surface];
    crate::network::Edge => [curve];
    crate::network::Network => [vertices, edges];
    crate::network::FaceSurface => [coons, pde, surface];
    crate::topology::Vertex => [point];
    crate::topology::Edge => [curve];
    crate::topology::Face => [surface];
    crate::topology::PatchComplex => [vertices, edges, faces];
    crate::fit::CurveFit => [curve];
    crate::pipeline::surface_fit::FitReport => [surface, assessment];
    crate::pipeline::curve::CurveReport => [fit];
    crate::pipeline::coons::PdeOutcome => [fit];
    crate::pipeline::coons::CoonsReport => [base, coons_surface, pde, surface, assessment];
    crate::pipeline::turntable::TurntableReport => [turntable, assessment];
    crate::pipeline::reconstruct::ReconstructReport => [network, faces, complex];
}

/// The surface and the assessment move by `by`; the MBA frame, which lies in
/// the up axis's z-up frame, by `by` turned into that frame.
impl Translate for crate::pipeline::mba::MbaReport {
    fn translate(&mut self, by: &Vector3) {
        self.surface.translate(by);
        self.assessment.translate(by);
        self.frame.translate(&self.up.to_frame(by));
    }
}

/// The MBA frame's origin `(x0, y0, z0)` moves; its extents do not.
impl Translate for crate::mba::Frame {
    fn translate(&mut self, by: &Vector3) {
        self.x0 += by.x;
        self.y0 += by.y;
        self.z0 += by.z;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_around_the_origin_are_left_alone_and_far_data_shift_exactly() {
        let near = [Point3::new(-1.0, 5.0, 100.0), Point3::new(3.0, 6.0, 101.0)];
        let c = Centring::of(&near);
        // z: midpoint 100.5 > extent 1 -> shifted; x straddles 0; y: 5.5 > 1
        assert_eq!(c.centre(), Vector3::new(0.0, 5.5, 100.5));
        let origin = [Point3::new(-1.0, -2.0, -3.0), Point3::new(1.0, 2.0, 3.0)];
        assert!(Centring::of(&origin).is_identity());
        let far: Vec<Point3> = (0..100)
            .map(|k| Point3::new(1e15 + 0.125 * k as f64, -3e10 + 0.37 * k as f64, 7e5))
            .collect();
        let c = Centring::of(&far);
        for (p, q) in far.iter().zip(c.points(&far)) {
            // Sterbenz: the difference is exact, so adding back restores the input
            assert_eq!(q + c.centre(), *p);
        }
    }
}
