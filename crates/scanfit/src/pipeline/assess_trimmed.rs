//! The surface-to-points half of the assessment ([`super::assess`]) over a
//! trimmed face instead of the whole parameter rectangle.
//!
//! A surface fitted over its points' parameter rectangle and trimmed to
//! their outline ([`crate::trim`]) keeps, outside the trim loops, the parts
//! of the rectangle where there are no data: the corners round a disc-shaped
//! scan, the inside of a hole. Those parts are not in the CAD face, the mesh
//! or the pictures, so they must not count in the measures of the face
//! either. [`assess_trimmed`] measures the sample-grid distances to the
//! points ([`SampleDistances`]) and the extent check ([`Extent`]) again on
//! the samples of the trimmed face: the vertices of its mesh on the same
//! sample grid ([`TrimmedSurface::tessellate`]), i.e. the grid points inside
//! the trim loops and the points where the loops cross the grid lines.
//!
//! One verdict stays the rectangle's: a surface whose rectangle has *left
//! the data* ([`Extent::leaves`]) keeps that extent, numbers and verdict,
//! even when its face stays near the data. The CAD file carries the whole
//! surface and its control net, and a fit that flew off over the empty
//! corners beyond the outline (measured: 450 diagonals for the bare fit of
//! `examples/data/nasty_face.xyz`) is no usable surface, trimmed or not; the
//! rule's allowance of a quarter of the diagonal already lets the corners
//! beyond a rounded outline pass.
//!
//! The other measures stay as the pipeline took them: the points-to-surface
//! errors (every point lies inside its own outline), the point spacing, the
//! parameterization quality, the control net's reach (the CAD file carries
//! the whole net), and [MBA18] eq. 17, the paper's measure at its knot grid.

use crate::metrics::ErrorStats;
use crate::pipeline::assess::{
    bounding_box, extent_in_box, grid_size, nearest_distances, AssessConfig, Measure,
    SurfaceQuality,
};
use crate::trim::TrimmedSurface;
use crate::{Error, Point3, PointCloud, Result};

/// Measures the surface-to-points distances and the extent of `quality`
/// (the assessment of `trimmed.surface` against `cloud` with `config`)
/// again over the trimmed face (see the module documentation). The sample
/// grid is `config`'s; `quality.samples_to_points.stats.count` becomes the
/// number of samples on the face, `grid` stays the grid's intervals; an
/// extent that leaves the data stays the rectangle's (see the module
/// documentation).
///
/// Errors: a trimmed face without a single sample (no grid triangle inside
/// its loops), an empty cloud.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::pipeline::assess::{assess_surface, AssessConfig};
/// use scanfit::pipeline::assess_trimmed::assess_trimmed;
/// use scanfit::trim::{trim_to_points, TrimConfig};
/// use scanfit::{Point3, PointCloud};
///
/// // a plane over [0, 2] x [0, 2] and points on the disc of radius 0.5
/// // about its centre: the rectangle's corners are 0.9 from the nearest point
/// let k = KnotVector::uniform_clamped(1, 2)?;
/// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
/// let s = Surface::new(k.clone(), k, vec![p(0., 0.), p(0., 2.), p(2., 0.), p(2., 2.)])?;
/// let (mut pts, mut uv) = (Vec::new(), Vec::new());
/// for i in 0..=60 {
///     for j in 0..=60 {
///         let (u, v) = (0.25 + i as f64 / 120.0, 0.25 + j as f64 / 120.0);
///         if (u - 0.5).hypot(v - 0.5) < 0.245 {
///             pts.push(s.point(u, v));
///             uv.push([u, v]);
///         }
///     }
/// }
/// let config = AssessConfig::default();
/// let mut q = assess_surface(&s, &pts, &uv, &config)?.quality;
/// assert!(q.samples_to_points.stats.max > 0.8);
/// let t = trim_to_points(&s, &pts, &uv, &TrimConfig::default())?;
/// assess_trimmed(&mut q, &t, &PointCloud::new(pts)?, &config)?;
/// // on the face, no sample is farther than a point spacing (1/60)
/// assert!(q.samples_to_points.stats.max < 1.0 / 60.0);
/// assert_eq!(q.samples_to_points.far_share, 0.0);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn assess_trimmed(
    quality: &mut SurfaceQuality,
    trimmed: &TrimmedSurface,
    cloud: &PointCloud,
    config: &AssessConfig,
) -> Result<()> {
    let surface = &trimmed.surface;
    let (nu, nv) = grid_size(surface, config);
    let samples = face_samples(trimmed, nu, nv);
    if samples.is_empty() {
        return Err(Error::InvalidInput(format!(
            "the trimmed face covers no triangle of the {nu} x {nv} sample grid: its trim loops enclose no area"
        )));
    }
    let Some(bbox) = bounding_box(cloud.points()) else {
        return Err(Error::InvalidInput(
            "no points to assess the surface against".into(),
        ));
    };
    let s = &mut quality.samples_to_points;
    if config.measure != Measure::None {
        let d = nearest_distances(cloud, &samples)?;
        let limit = s.far_spacings * s.spacing;
        let far = d.iter().filter(|&&x| x > limit).count();
        s.stats = ErrorStats::of(&d);
        s.far_share = far as f64 / d.len() as f64;
    }
    if !quality.extent.leaves {
        quality.extent = extent_in_box(surface, bbox, &samples, s.spacing, config);
    }
    Ok(())
}

/// The samples of the trimmed face on the `nu x nv` grid: the vertices of
/// the kept triangles of its mesh.
fn face_samples(trimmed: &TrimmedSurface, nu: usize, nv: usize) -> Vec<Point3> {
    let mesh = trimmed.tessellate(nu, nv);
    let mut used = vec![false; mesh.vertices.len()];
    for t in &mesh.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    mesh.vertices
        .iter()
        .zip(used)
        .filter_map(|(p, u)| u.then_some(*p))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::{KnotVector, Surface};
    use crate::pipeline::assess::assess_surface;
    use crate::trim::{trim_to_points, TrimConfig};

    /// A bicubic bowl over the unit square, z = h r^2 at the control points
    /// (r the distance from the centre), and its points on the disc of
    /// radius 0.5 at spacing 1/40 in the parameters.
    fn bowl(h: f64) -> (Surface, Vec<Point3>, Vec<[f64; 2]>) {
        let k = KnotVector::uniform_clamped(3, 6).unwrap();
        let mut c = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                let (x, y) = (i as f64 / 5.0, j as f64 / 5.0);
                c.push(Point3::new(
                    x,
                    y,
                    h * ((x - 0.5).powi(2) + (y - 0.5).powi(2)),
                ));
            }
        }
        let s = Surface::new(k.clone(), k, c).unwrap();
        let (mut pts, mut uv) = (Vec::new(), Vec::new());
        for i in 0..=40 {
            for j in 0..=40 {
                let (u, v) = (i as f64 / 40.0, j as f64 / 40.0);
                if (u - 0.5).hypot(v - 0.5) < 0.49 {
                    pts.push(s.point(u, v));
                    uv.push([u, v]);
                }
            }
        }
        (s, pts, uv)
    }

    #[test]
    fn the_bowls_corners_count_untrimmed_and_not_on_the_trimmed_face() {
        let (s, pts, uv) = bowl(1.0);
        let config = AssessConfig::default();
        let mut q = assess_surface(&s, &pts, &uv, &config).unwrap().quality;
        let whole = q;
        // the rectangle's corners rise to z = 0.5, the data stop below
        // z = 0.25: the corner samples are a third of a unit from the data
        // and leave the points' box by a quarter, within the limit (a
        // quarter of the diagonal, 0.36)
        assert!(whole.samples_to_points.stats.max > 0.3, "{whole:?}");
        assert!(whole.samples_to_points.far_share > 0.1);
        assert!(whole.extent.samples_outside > 0.22 && !whole.extent.leaves);
        let t = trim_to_points(&s, &pts, &uv, &TrimConfig::default()).unwrap();
        let cloud = PointCloud::new(pts).unwrap();
        assess_trimmed(&mut q, &t, &cloud, &config).unwrap();
        let spacing = q.samples_to_points.spacing;
        assert!(spacing > 0.01 && spacing < 0.03, "{spacing}");
        let st = q.samples_to_points;
        // the face samples within a spacing of the data on average and two
        // at most (where the trim curve smooths the boundary's zig-zag),
        // none far; untrimmed, the corners were 0.5 away
        assert!(
            st.stats.mean < spacing && st.stats.max < 2.5 * spacing,
            "{st:?}"
        );
        assert_eq!(st.far_share, 0.0);
        // the corners left out: the disc covers pi/4 of the square, and the
        // face's samples add the points where the loop crosses the grid lines
        let share = st.stats.count as f64 / whole.samples_to_points.stats.count as f64;
        assert!(share > 0.75 && share < 0.92, "{share}");
        assert!(!q.extent.leaves && q.extent.samples_outside < spacing);
        // the other measures untouched
        assert_eq!(q.orthogonal, whole.orthogonal);
        assert_eq!(q.extent.control_outside, whole.extent.control_outside);
    }

    #[test]
    fn measure_none_keeps_the_distances_and_checks_the_extent() {
        let (s, pts, uv) = bowl(1.0);
        let config = AssessConfig {
            measure: Measure::None,
            ..AssessConfig::default()
        };
        let mut q = assess_surface(&s, &pts, &uv, &config).unwrap().quality;
        assert!(q.extent.samples_outside > 0.22);
        let t = trim_to_points(&s, &pts, &uv, &TrimConfig::default()).unwrap();
        assess_trimmed(&mut q, &t, &PointCloud::new(pts).unwrap(), &config).unwrap();
        assert_eq!(q.samples_to_points.stats.count, 0);
        assert!(q.extent.samples_outside < 0.01, "{:?}", q.extent);
    }

    #[test]
    fn a_rectangle_that_leaves_the_data_keeps_its_verdict_when_trimmed() {
        // twice as steep: the corners leave the box by half a unit, above
        // the limit (0.37)
        let (s, pts, uv) = bowl(2.0);
        let config = AssessConfig::default();
        let mut q = assess_surface(&s, &pts, &uv, &config).unwrap().quality;
        let whole = q;
        assert!(whole.extent.samples_outside > 0.45 && whole.extent.leaves);
        let t = trim_to_points(&s, &pts, &uv, &TrimConfig::default()).unwrap();
        assess_trimmed(&mut q, &t, &PointCloud::new(pts).unwrap(), &config).unwrap();
        // the face's samples are near the data, the verdict is the rectangle's
        assert!(q.samples_to_points.stats.max < 3.0 * q.samples_to_points.spacing);
        assert_eq!(q.extent, whole.extent);
    }
}
