//! How many control points a multi-patch model has, each counted once.
//!
//! In a [`PatchComplex`] every face's boundary rows and columns are its edge
//! curves (refined to the face's knots, so a face may store more of them
//! than the curve has), and the curves end at the vertices. What a model
//! really holds is therefore its vertices, the inner control points of its
//! edge curves and the inner control points of its faces: the count of
//! [`PatchComplex::control_point_count`]. For a single face it is the size
//! of its net, `nu x nv`, so a single patch and a multi-patch model are
//! counted the same way.

use super::PatchComplex;

impl PatchComplex {
    /// The control points of the model, each counted once: the vertices,
    /// every edge curve's control points but its two ends, and every face's
    /// control points off its boundary rows and columns (`(nu - 2)(nv - 2)`;
    /// those rows are the edge curves).
    ///
    /// ```
    /// use scanfit::bspline::{KnotVector, Surface};
    /// use scanfit::topology::{FaceCorners, PatchComplex};
    /// use scanfit::Point3;
    /// // two bicubic 5 x 4 faces side by side, sharing the side x = 1
    /// let (ku, kv) = (KnotVector::uniform_clamped(3, 5)?, KnotVector::uniform_clamped(3, 4)?);
    /// let face = |x0: f64| {
    ///     let net = (0..5)
    ///         .flat_map(|i| (0..4).map(move |j| Point3::new(x0 + i as f64 / 4.0, j as f64 / 3.0, 0.0)))
    ///         .collect();
    ///     Surface::new(ku.clone(), kv.clone(), net)
    /// };
    /// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
    /// let verts = vec![p(0., 0.), p(1., 0.), p(2., 0.), p(0., 1.), p(1., 1.), p(2., 1.)];
    /// let one = PatchComplex::assemble(verts[..2].iter().chain(&verts[3..5]).copied().collect(),
    ///     vec![scanfit::topology::FaceCorners { id: 0, surface: face(0.0)?, corners: [0, 1, 3, 2] }])?;
    /// assert_eq!(one.control_point_count(), 20);
    /// let two = PatchComplex::assemble(verts, vec![
    ///     FaceCorners { id: 1, surface: face(0.0)?, corners: [0, 1, 4, 3] },
    ///     FaceCorners { id: 2, surface: face(1.0)?, corners: [1, 2, 5, 4] },
    /// ])?;
    /// // 2 x 20 stored, the 4 of the shared side once: 36
    /// assert_eq!(two.control_point_count(), 36);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn control_point_count(&self) -> usize {
        let edges: usize = self
            .edges
            .iter()
            .map(|e| e.curve.control_points().len().saturating_sub(2))
            .sum();
        let faces: usize = self
            .faces
            .iter()
            .map(|f| {
                let (nu, nv) = f.surface.counts();
                nu.saturating_sub(2) * nv.saturating_sub(2)
            })
            .sum();
        self.vertices.len() + edges + faces
    }
}
