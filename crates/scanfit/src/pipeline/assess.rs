//! The one assessment of a fitted surface against its points, used by every
//! surface pipeline and by `report`.
//!
//! [`assess_surface`] takes the surface, the points and their parameters and
//! measures both directions:
//!
//! * **points to surface**: `|P_i - S(u_i, v_i)|` at the parameters (the PDE
//!   paper's eq. 15 mean and maximum, plus RMSE), and the true orthogonal
//!   distance of every point by point inversion;
//! * **surface to points**: the MBA paper's eq. 17 (the RMSE over the surface
//!   points at the knot lines of the distance to the nearest input point),
//!   and the same distance over a uniform sample grid of the whole domain
//!   ([`SampleDistances`]: mean, maximum, RMSE and the share of samples
//!   farther than a stated multiple of the median point spacing). A surface
//!   that bulges or overshoots where there are no points is small in the first
//!   direction and large in the second;
//! * **parameterization quality**: fold-overs and stretch of the parameters
//!   ([`ParamQuality`], Sander et al. 2001);
//! * **extent**: how far the surface samples and the control net reach
//!   outside the points' bounding box ([`Extent`]). A surface whose samples
//!   leave the box by more than [`AssessConfig::leave_spacings`] point
//!   spacings and [`AssessConfig::leave_diagonal`] of its diagonal has *left
//!   the data* ([`Extent::leaves`]): a least-squares fit
//!   that flew off over a sparsely covered span, which the points-to-surface
//!   errors never show. The command line refuses to write such a surface
//!   unless told to (`--allow-extrapolation`).
//!
//! [`assess_projected`] does the same for points without parameters (they
//! get those of their orthogonal projections), as `scanfit report` needs.
//!
//! A pipeline whose error at the parameters is measured on another surface
//! than the one assessed (the PDE route measures eq. 15 on the PDE surface,
//! before its B-spline conversion) overwrites
//! [`SurfaceQuality::at_parameters`] after the call; the fields are public
//! for that.

use crate::bspline::Surface;
use crate::metrics::{parameterization_quality, parametric_distances, ErrorStats, ParamQuality};
use crate::project::{Inversion, InversionConfig, SurfaceInverter};
use crate::{Error, Point3, PointCloud, Result};

/// Settings of [`assess_surface`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct AssessConfig {
    /// Point inversion for the orthogonal distances (default
    /// [`InversionConfig::default`]).
    pub inversion: InversionConfig,
    /// Sample grid of the surface-to-points distances, `(nu, nv)` intervals,
    /// i.e. `(nu + 1) x (nv + 1)` samples uniform in the parameter domain.
    /// `None` (default): 4 intervals per control point in each direction,
    /// clamped to `[32, 200]`, the resolution of the mesh the pipelines
    /// write.
    pub samples: Option<(usize, usize)>,
    /// A surface sample counts as "far" from the data when its nearest input
    /// point is more than this many median point spacings away (default 3:
    /// beyond the gaps of regular sampling, which reach about 0.7 spacings
    /// at the centre of a square cell).
    pub far_spacings: f64,
    /// Measure the parameterization's fold-overs and stretch (default true;
    /// costs a Delaunay triangulation of the parameters).
    pub parameterization: bool,
    /// The surface has *left the data* ([`Extent::leaves`]) when a surface
    /// sample lies farther outside the points' bounding box than this many
    /// median point spacings (default 10) *and* than `leave_diagonal` x
    /// the box's diagonal.
    pub leave_spacings: f64,
    /// The share of the diagonal in that rule (default 0.25). A fit that
    /// covers the empty corners of its parameter rectangle by continuing the
    /// data's slope leaves the box by a share of the diagonal, not of the
    /// spacing (measured: 10% on the rounded outline of
    /// `examples/data/make_nasty.py`, 32 to 60 spacings); one that flew off
    /// over a sparse span leaves it by orders of magnitude more (there:
    /// 450 diagonals).
    pub leave_diagonal: f64,
}

impl Default for AssessConfig {
    fn default() -> Self {
        Self {
            inversion: InversionConfig::default(),
            samples: None,
            far_spacings: 3.0,
            parameterization: true,
            leave_spacings: 10.0,
            leave_diagonal: 0.25,
        }
    }
}

/// Distances from surface samples to their nearest input point (the
/// surface-to-points direction; the MBA paper's eq. 17 over a uniform grid).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct SampleDistances {
    /// Sample grid, `(nu + 1) x (nv + 1)` samples.
    pub grid: (usize, usize),
    /// Mean, maximum and RMSE of the distances (`count` = samples).
    pub stats: ErrorStats,
    /// Median nearest-neighbour distance of the input points (0 for a single point).
    pub spacing: f64,
    /// The multiple of `spacing` beyond which a sample counts as far.
    pub far_spacings: f64,
    /// Share of samples (0..=1) farther than `far_spacings * spacing` from
    /// every input point: surface where there are no data.
    pub far_share: f64,
}

/// How far a surface reaches outside the data's extent (the axis-aligned
/// bounding box of the input points).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Extent {
    /// Bounding-box diagonal of the points.
    pub diagonal: f64,
    /// Largest distance of a surface sample (the grid of
    /// [`SampleDistances`]) outside the bounding box (0 when all are inside).
    pub samples_outside: f64,
    /// Largest distance of a control point outside the bounding box.
    pub control_outside: f64,
    /// `samples_outside` in median point spacings (0 for a single point).
    pub samples_outside_spacings: f64,
    /// The distance beyond which the surface leaves the data: the larger of
    /// [`AssessConfig::leave_spacings`] spacings and
    /// [`AssessConfig::leave_diagonal`] x the diagonal.
    pub limit: f64,
    /// The surface has left the data: `samples_outside > limit`, or a
    /// non-finite sample or control point.
    pub leaves: bool,
}

/// The quality record of a surface fitted to points: one for every pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct SurfaceQuality {
    /// Number of points measured.
    pub points: usize,
    /// `|P_i - S(u_i, v_i)|` at the points' parameters (PDE paper eq. 15:
    /// mean and maximum; plus RMSE).
    pub at_parameters: ErrorStats,
    /// Orthogonal distances of the points to the surface (point inversion).
    pub orthogonal: ErrorStats,
    /// Points whose inversion did not converge (their distance is the best found).
    pub unconverged: usize,
    /// The MBA paper's eq. 17: RMSE over the surface points at the knot lines
    /// of the distance to the nearest input point.
    pub grid_rmse: f64,
    /// Surface samples to the nearest input point.
    pub samples_to_points: SampleDistances,
    /// Fold-overs and stretch of the parameters (all zero when not measured
    /// or when the parameters cannot be triangulated).
    pub parameterization: ParamQuality,
    /// How far the surface and its control net reach outside the data's
    /// bounding box, and whether it has left the data.
    pub extent: Extent,
}

/// [`SurfaceQuality`] with the per-point values it summarises.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Assessment {
    /// The summary.
    pub quality: SurfaceQuality,
    /// `|P_i - S(u_i, v_i)|` per point.
    pub residuals: Vec<f64>,
    /// The orthogonal projection of each point.
    pub inversions: Vec<Inversion>,
}

impl Assessment {
    /// The orthogonal distance of each point.
    pub fn distances(&self) -> Vec<f64> {
        self.inversions.iter().map(|r| r.distance).collect()
    }
}

/// Assesses `surface` against `points` with parameters `uv` (see the module
/// documentation for what is measured).
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::pipeline::assess::{assess_surface, AssessConfig};
/// use scanfit::Point3;
///
/// // the plane z = 0 over [0, 2] x [0, 1], points on it and 0.1 above
/// let k = KnotVector::uniform_clamped(1, 2)?;
/// let c = vec![
///     Point3::new(0., 0., 0.), Point3::new(0., 1., 0.),
///     Point3::new(2., 0., 0.), Point3::new(2., 1., 0.),
/// ];
/// let s = Surface::new(k.clone(), k, c)?;
/// let mut pts = Vec::new();
/// let mut uv = Vec::new();
/// for i in 0..=20 {
///     for j in 0..=10 {
///         let (u, v) = (i as f64 / 20.0, j as f64 / 10.0);
///         uv.push([u, v]);
///         pts.push(Point3::new(2.0 * u, v, if (i + j) % 2 == 0 { 0.1 } else { 0.0 }));
///     }
/// }
/// let a = assess_surface(&s, &pts, &uv, &AssessConfig::default())?;
/// let q = a.quality;
/// assert!((q.at_parameters.max - 0.1).abs() < 1e-12);
/// assert!((q.orthogonal.max - 0.1).abs() < 1e-9);
/// assert_eq!(q.parameterization.fold_overs, 0);
/// // every sample of the plane is within a cell of a point: none is far
/// assert_eq!(q.samples_to_points.far_share, 0.0);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn assess_surface(
    surface: &Surface,
    points: &[Point3],
    uv: &[[f64; 2]],
    config: &AssessConfig,
) -> Result<Assessment> {
    if points.is_empty() {
        return Err(Error::InvalidInput(
            "no points to assess the surface against".into(),
        ));
    }
    if points.len() != uv.len() {
        return Err(Error::LengthMismatch {
            what: "parameter pairs",
            expected: points.len(),
            got: uv.len(),
        });
    }
    check(config)?;
    let residuals = parametric_distances(surface, points, uv);
    let inverter = SurfaceInverter::new(surface, config.inversion)?;
    let inversions = inverter.invert_all(points);
    finish(surface, points, uv, residuals, inversions, config)
}

/// Assesses `surface` against `points` that have no parameters of their
/// own (a surface read from a file and a scan to compare with it): each
/// point's parameters are those of its orthogonal projection, so the error
/// at the parameters equals the orthogonal distance.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::pipeline::assess::{assess_projected, AssessConfig};
/// use scanfit::Point3;
///
/// let k = KnotVector::uniform_clamped(1, 2)?;
/// let c = vec![
///     Point3::new(0., 0., 0.), Point3::new(0., 1., 0.),
///     Point3::new(1., 0., 0.), Point3::new(1., 1., 0.),
/// ];
/// let s = Surface::new(k.clone(), k, c)?;
/// let pts: Vec<Point3> = (0..100)
///     .map(|i| Point3::new((i % 10) as f64 / 9.0, (i / 10) as f64 / 9.0, 0.01 * (i % 3) as f64))
///     .collect();
/// let a = assess_projected(&s, &pts, &AssessConfig::default())?;
/// assert!((a.quality.orthogonal.max - 0.02).abs() < 1e-9);
/// assert!((a.quality.at_parameters.mean - a.quality.orthogonal.mean).abs() < 1e-12);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn assess_projected(
    surface: &Surface,
    points: &[Point3],
    config: &AssessConfig,
) -> Result<Assessment> {
    if points.is_empty() {
        return Err(Error::InvalidInput(
            "no points to assess the surface against".into(),
        ));
    }
    check(config)?;
    let inverter = SurfaceInverter::new(surface, config.inversion)?;
    let inversions = inverter.invert_all(points);
    let uv: Vec<[f64; 2]> = inversions.iter().map(|r| r.uv).collect();
    let residuals: Vec<f64> = inversions.iter().map(|r| r.distance).collect();
    finish(surface, points, &uv, residuals, inversions, config)
}

/// Rejects settings the assessment cannot use.
fn check(config: &AssessConfig) -> Result<()> {
    if !(config.far_spacings.is_finite() && config.far_spacings > 0.0) {
        return Err(Error::InvalidSetting {
            setting: "far_spacings",
            value: config.far_spacings.to_string(),
            hint: "give a positive number of point spacings".into(),
        });
    }
    for (setting, v) in [
        ("leave_spacings", config.leave_spacings),
        ("leave_diagonal", config.leave_diagonal),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidSetting {
                setting,
                value: v.to_string(),
                hint: "give a positive multiple".into(),
            });
        }
    }
    if let Some((nu, nv)) = config.samples {
        if !(1..=4096).contains(&nu) || !(1..=4096).contains(&nv) {
            return Err(Error::InvalidSetting {
                setting: "samples",
                value: format!("{nu} x {nv}"),
                hint: "give 1 to 4096 sample intervals in each direction".into(),
            });
        }
    }
    Ok(())
}

/// The rest of the assessment once the residuals and projections are known.
fn finish(
    surface: &Surface,
    points: &[Point3],
    uv: &[[f64; 2]],
    residuals: Vec<f64>,
    inversions: Vec<Inversion>,
    config: &AssessConfig,
) -> Result<Assessment> {
    let at_parameters = ErrorStats::of(&residuals);
    let dist: Vec<f64> = inversions.iter().map(|r| r.distance).collect();
    let orthogonal = ErrorStats::of(&dist);
    let unconverged = inversions.iter().filter(|r| !r.converged).count();
    let cloud = PointCloud::new(points.to_vec())?;
    let grid_rmse = crate::metrics::rmse_to_cloud(&cloud, &knot_line_points(surface))?;
    let (samples_to_points, samples) = sample_distances(surface, &cloud, config)?;
    let extent = extent(surface, &cloud, &samples, samples_to_points.spacing, config);
    let parameterization = if config.parameterization {
        // a parameter set that cannot be triangulated (all collinear) has no
        // fold-overs or stretch to report
        parameterization_quality(surface, points, uv).unwrap_or_default()
    } else {
        ParamQuality::default()
    };
    Ok(Assessment {
        quality: SurfaceQuality {
            points: points.len(),
            at_parameters,
            orthogonal,
            unconverged,
            grid_rmse,
            samples_to_points,
            parameterization,
            extent,
        },
        residuals,
        inversions,
    })
}

/// Distance of `p` outside the box `(lo, hi)` (0 inside; infinite for a
/// non-finite point).
fn outside_box(p: &Point3, lo: &Point3, hi: &Point3) -> f64 {
    if !p.coords.iter().all(|c| c.is_finite()) {
        return f64::INFINITY;
    }
    let d = (lo - p).sup(&(p - hi)).sup(&Point3::origin().coords);
    d.norm()
}

/// The [`Extent`] of `surface` (its `samples`) against the box of `cloud`.
fn extent(
    surface: &Surface,
    cloud: &PointCloud,
    samples: &[Point3],
    spacing: f64,
    config: &AssessConfig,
) -> Extent {
    match cloud.bounding_box() {
        Some(b) => extent_in_box(surface, b, samples, spacing, config),
        None => Extent::default(),
    }
}

/// The [`Extent`] of `surface` (its `samples`) against the points' bounding
/// box `(lo, hi)` (also used by the streamed assessment, which gathers the
/// box chunk by chunk).
pub(crate) fn extent_in_box(
    surface: &Surface,
    (lo, hi): (Point3, Point3),
    samples: &[Point3],
    spacing: f64,
    config: &AssessConfig,
) -> Extent {
    let far = |pts: &[Point3]| {
        pts.iter()
            .map(|p| outside_box(p, &lo, &hi))
            .fold(0.0, f64::max)
    };
    let samples_outside = far(samples);
    let control_outside = far(surface.control_points());
    let samples_outside_spacings = if spacing > 0.0 {
        samples_outside / spacing
    } else {
        0.0
    };
    let diagonal = (hi - lo).norm();
    let limit = (config.leave_spacings * spacing).max(config.leave_diagonal * diagonal);
    Extent {
        diagonal,
        samples_outside,
        control_outside,
        samples_outside_spacings,
        limit,
        leaves: samples_outside > limit
            || !samples_outside.is_finite()
            || !control_outside.is_finite(),
    }
}

/// The surface points at the knot lines (every pair of breakpoints), where
/// [MBA18] eq. 17 is measured (`u_i = s_{i+3}` in the MBA paper).
pub(crate) fn knot_line_points(surface: &Surface) -> Vec<Point3> {
    let (us, vs) = (
        surface.knots_u().breakpoints(),
        surface.knots_v().breakpoints(),
    );
    us.iter()
        .flat_map(|&u| vs.iter().map(move |&v| (u, v)))
        .map(|(u, v)| surface.point(u, v))
        .collect()
}

/// The sample grid of `config` (intervals `(nu, nv)`) and its surface points.
pub(crate) fn sample_grid(
    surface: &Surface,
    config: &AssessConfig,
) -> Result<((usize, usize), Vec<Point3>)> {
    check(config)?;
    let (cu, cv) = surface.counts();
    let (nu, nv) = config
        .samples
        .unwrap_or(((cu * 4).clamp(32, 200), (cv * 4).clamp(32, 200)));
    let ((u0, u1), (v0, v1)) = surface.domain();
    let samples: Vec<Point3> = (0..=nu)
        .flat_map(|i| (0..=nv).map(move |j| (i, j)))
        .map(|(i, j)| {
            surface.point(
                u0 + (u1 - u0) * i as f64 / nu as f64,
                v0 + (v1 - v0) * j as f64 / nv as f64,
            )
        })
        .collect();
    Ok(((nu, nv), samples))
}

/// The surface-to-points distances over the sample grid of `config`.
fn sample_distances(
    surface: &Surface,
    cloud: &PointCloud,
    config: &AssessConfig,
) -> Result<(SampleDistances, Vec<Point3>)> {
    let ((nu, nv), samples) = sample_grid(surface, config)?;
    let d: Vec<f64> = cloud
        .nearest_batch(&samples)?
        .into_iter()
        .map(|n| n.distance)
        .collect();
    let spacing = if cloud.len() >= 2 {
        cloud.spacing()?.median
    } else {
        0.0
    };
    let limit = config.far_spacings * spacing;
    let far = d.iter().filter(|&&x| x > limit).count();
    let distances = SampleDistances {
        grid: (nu, nv),
        stats: ErrorStats::of(&d),
        spacing,
        far_spacings: config.far_spacings,
        far_share: far as f64 / d.len().max(1) as f64,
    };
    Ok((distances, samples))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::KnotVector;

    /// The plane z = 0 over [0, 4] x [0, 2], bilinear.
    fn plane() -> Surface {
        let k = KnotVector::uniform_clamped(1, 2).unwrap();
        let c = vec![
            Point3::new(0., 0., 0.),
            Point3::new(0., 2., 0.),
            Point3::new(4., 0., 0.),
            Point3::new(4., 2., 0.),
        ];
        Surface::new(k.clone(), k, c).unwrap()
    }

    /// Points on the plane with spacing 0.1 over [0, 4] x [0, ymax].
    fn points(ymax: f64) -> (Vec<Point3>, Vec<[f64; 2]>) {
        let (mut p, mut uv) = (Vec::new(), Vec::new());
        for i in 0..=40 {
            let mut j = 0;
            while j as f64 * 0.1 <= ymax + 1e-9 {
                let (x, y) = (i as f64 * 0.1, j as f64 * 0.1);
                p.push(Point3::new(x, y, 0.0));
                uv.push([x / 4.0, y / 2.0]);
                j += 1;
            }
        }
        (p, uv)
    }

    #[test]
    fn surface_without_data_shows_in_the_samples_only() {
        let s = plane();
        // data over the lower half of the plane only
        let (p, uv) = points(1.0);
        let a = assess_surface(&s, &p, &uv, &AssessConfig::default()).unwrap();
        let q = a.quality;
        // points to surface: all on it
        assert!(q.at_parameters.max < 1e-12, "{:?}", q.at_parameters);
        assert!(q.orthogonal.max < 1e-9, "{:?}", q.orthogonal);
        // surface to points: the upper half is up to 1.0 away
        assert!((q.samples_to_points.spacing - 0.1).abs() < 1e-9);
        // (samples at x = k/8 are up to 0.05 off the x = k/10 columns)
        let max = q.samples_to_points.stats.max;
        assert!(
            max >= 1.0 - 1e-9 && max <= (1.0f64 + 0.05 * 0.05).sqrt() + 1e-9,
            "{max}"
        );
        // default grid 32 x 32: the samples at v > 0.65 (y > 1.3) are farther
        // than 3 spacings; rows j = 21..=32 of 33
        let far = q.samples_to_points.far_share;
        assert!((far - 12.0 / 33.0).abs() < 1e-12, "{far}");
        assert_eq!(q.samples_to_points.grid, (32, 32));
        // eq. 17 at the knot lines of the bilinear patch, its 4 corners:
        // the two at y = 2 are 1.0 from the data
        assert!(
            (q.grid_rmse - 0.5f64.sqrt()).abs() < 1e-9,
            "{}",
            q.grid_rmse
        );
    }

    #[test]
    fn full_coverage_has_no_far_samples_and_offsets_show_in_both_directions() {
        let s = plane();
        let (mut p, uv) = points(2.0);
        for q in p.iter_mut().step_by(2) {
            q.z = 0.05;
        }
        let a = assess_surface(&s, &p, &uv, &AssessConfig::default()).unwrap();
        let q = a.quality;
        assert_eq!(q.samples_to_points.far_share, 0.0);
        assert!((q.at_parameters.max - 0.05).abs() < 1e-12);
        // about half the points at 0.05: RMSE 0.05 / sqrt(2)
        assert!((q.at_parameters.rmse - 0.05 / 2f64.sqrt()).abs() < 1e-3);
        assert_eq!(a.residuals.len(), p.len());
        assert_eq!(a.distances().len(), p.len());
        assert_eq!(q.points, p.len());
    }

    #[test]
    fn bad_input_is_an_error() {
        let s = plane();
        let (p, uv) = points(1.0);
        assert!(assess_surface(&s, &p, &uv[1..], &AssessConfig::default()).is_err());
        assert!(assess_surface(&s, &[], &[], &AssessConfig::default()).is_err());
        let c = AssessConfig {
            far_spacings: f64::NAN,
            ..Default::default()
        };
        assert!(assess_surface(&s, &p, &uv, &c).is_err());
        let c = AssessConfig {
            samples: Some((0, 3)),
            ..Default::default()
        };
        assert!(assess_surface(&s, &p, &uv, &c).is_err());
    }
}
