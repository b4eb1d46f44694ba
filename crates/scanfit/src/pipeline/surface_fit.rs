//! `scanfit fit` as a library call: a least-squares B-spline surface through
//! scattered points.
//!
//! The points get their parameters from their best-fit plane
//! ([`ParameterSource::Plane`], for height-field-like patches; projected
//! along a coordinate axis instead when the best-fit plane folds the points
//! over and the axis does not, [`crate::base::choose_projection`]) or from two
//! attributes of the cloud ([`ParameterSource::Attributes`], e.g. the columns
//! `u` and `v` of the input file); the surface is the least-squares fit of
//! [`fit_surface`] (NURBS Book eq. 9.63 on a tensor-product basis, optional
//! thin-plate smoothing), optionally followed by Hoschek's parameter
//! correction ([`correct_parameters`]); the result is assessed by
//! [`assess_cloud`].
//!
//! By default the net follows the point density and the thin-plate weight
//! is scaled to the data ([`super::regularize`]), so sparsely covered spans
//! stay tame; `relative_smoothing = None` with `fit.smoothing = 0` and
//! `ctrl_from_density = false` is the bare fit of the paper.

use crate::base::{plane_parameters, Projection};
use crate::bspline::Surface;
use crate::centring::Centring;
use crate::fit::correction::{correct_parameters, CorrectionConfig, CorrectionRound};
use crate::fit::surface::{fit_surface, SurfaceFitConfig};
use crate::pipeline::assess::{assess_cloud, AssessConfig, Assessment};
use crate::pipeline::regularize::{density_ctrl, scaled_smoothing, DEFAULT_RELATIVE_SMOOTHING};
use crate::progress::Progress;
use crate::{Error, PointCloud, Result};

/// Where the points' parameters come from.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ParameterSource {
    /// Orthogonal projection onto the best-fit plane of the points, scaled to
    /// `[0, 1]^2` (the default); onto the plane across a coordinate axis
    /// when the best-fit plane folds the points over and the axis does not
    /// ([`crate::base::plane_parameters`]).
    #[default]
    Plane,
    /// Two attributes of the cloud hold `u` and `v`.
    Attributes {
        /// Name of the `u` attribute.
        u: String,
        /// Name of the `v` attribute.
        v: String,
    },
}

impl ParameterSource {
    /// The attributes named `u` and `v`.
    pub fn uv_attributes() -> Self {
        ParameterSource::Attributes {
            u: "u".into(),
            v: "v".into(),
        }
    }
}

/// Settings of [`run`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FitConfig {
    /// Where the parameters come from (default: the best-fit plane).
    pub params: ParameterSource,
    /// The least-squares fit (default [`SurfaceFitConfig::default`]: bicubic,
    /// 16 x 16 control points, knots from the parameter distribution (NURBS
    /// Book eq. 9.69), no smoothing, not periodic). Its `ctrl` is replaced
    /// when `ctrl_from_density` is set, its `smoothing` when
    /// `relative_smoothing` is.
    pub fit: SurfaceFitConfig,
    /// Choose the control net from the point count
    /// ([`density_ctrl`]) instead of `fit.ctrl` (default true).
    pub ctrl_from_density: bool,
    /// `Some(c)`: the thin-plate weight is [`scaled_smoothing`]`(c, points,
    /// net)` (default `Some(`[`DEFAULT_RELATIVE_SMOOTHING`]`)`); `None`:
    /// `fit.smoothing` as given (0 = the bare least-squares fit).
    pub relative_smoothing: Option<f64>,
    /// Rounds of Hoschek's parameter correction: re-project the points onto
    /// the surface and refit while the RMSE improves (default 0 = none).
    pub correction_rounds: usize,
    /// Stopping rule of the correction (default [`CorrectionConfig::default`];
    /// its `max_rounds` is replaced by `correction_rounds`).
    pub correction: CorrectionConfig,
    /// The assessment of the result (default [`AssessConfig::default`]).
    pub assess: AssessConfig,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            params: ParameterSource::default(),
            fit: SurfaceFitConfig::default(),
            ctrl_from_density: true,
            relative_smoothing: Some(DEFAULT_RELATIVE_SMOOTHING),
            correction_rounds: 0,
            correction: CorrectionConfig::default(),
            assess: AssessConfig::default(),
        }
    }
}

impl FitConfig {
    /// The bare least-squares fit of the paper on a given `nu x nv` net: no
    /// smoothing, no density rule.
    pub fn bare(ctrl: (usize, usize)) -> Self {
        let mut c = Self {
            ctrl_from_density: false,
            relative_smoothing: None,
            ..Self::default()
        };
        c.fit.ctrl = ctrl;
        c.fit.smoothing = 0.0;
        c
    }

    /// The least-squares settings [`run`] uses for `points` points: the net
    /// and thin-plate weight after the density and scaling rules.
    pub fn resolved_fit(&self, points: usize) -> SurfaceFitConfig {
        let mut f = self.fit.clone();
        if self.ctrl_from_density {
            f.ctrl = density_ctrl(points, f.degree);
        }
        if let Some(c) = self.relative_smoothing {
            f.smoothing = scaled_smoothing(c, points, f.ctrl);
        }
        f
    }
}

/// What [`run`] returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FitReport {
    /// The fitted surface.
    pub surface: Surface,
    /// The parameters of the points on it (after correction, if any).
    pub uv: Vec<[f64; 2]>,
    /// RMSE and maximum error after each correction round (round 0 = the
    /// first fit; empty without correction).
    pub rounds: Vec<CorrectionRound>,
    /// The assessment of `surface` against the points at `uv`.
    pub assessment: Assessment,
    /// The thin-plate weight `lambda` used (0 for the bare fit).
    pub smoothing: f64,
    /// With [`ParameterSource::Plane`]: the projection direction and the
    /// fold shares that chose it.
    pub projection: Option<Projection>,
}

/// Fits a least-squares B-spline surface to `cloud` (see the module
/// documentation).
///
/// Errors: too few points for the control net, parameters outside the
/// domain or missing attributes, each with the point index or setting as
/// data ([`Error::point_indices`]).
///
/// ```
/// use scanfit::pipeline::surface_fit::{run, FitConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a gentle saddle sampled on a 30 x 30 grid
/// let pts: Vec<Point3> = (0..900)
///     .map(|k| {
///         let (x, y) = ((k % 30) as f64 / 29.0, (k / 30) as f64 / 29.0);
///         Point3::new(x, y, 0.2 * (x - 0.5) * (y - 0.5))
///     })
///     .collect();
/// let cfg = FitConfig::bare((6, 6));
/// let r = run(&PointCloud::new(pts)?, &cfg, &NoProgress)?;
/// assert_eq!(r.surface.counts(), (6, 6));
/// // a bicubic net reproduces the bilinear saddle
/// assert!(r.assessment.quality.orthogonal.max < 1e-9);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(cloud: &PointCloud, config: &FitConfig, progress: &dyn Progress) -> Result<FitReport> {
    // computed relative to the data's centre, moved back exactly (issue 14)
    let centring = Centring::of(cloud.points());
    let local = centring.cloud(cloud)?;
    Ok(centring.restore(run_centred(&local, config, progress)?))
}

/// [`run`] on data whose centre is at the origin.
fn run_centred(
    cloud: &PointCloud,
    config: &FitConfig,
    progress: &dyn Progress,
) -> Result<FitReport> {
    let pts = cloud.points();
    progress.stage("parameterizing", None);
    let mut projection = None;
    let mut uv: Vec<[f64; 2]> = match &config.params {
        ParameterSource::Plane => {
            if config.fit.periodic_u {
                return Err(Error::InvalidSetting {
                    setting: "periodic_u",
                    value: "true".into(),
                    hint: "a periodic surface needs parameters that go around (ParameterSource::Attributes); a plane cannot close".into(),
                });
            }
            let p = plane_parameters(pts)?;
            projection = Some(p.projection);
            p.uv
        }
        ParameterSource::Attributes { u, v } => {
            let (Some(us), Some(vs)) = (cloud.attribute(u), cloud.attribute(v)) else {
                let names: Vec<&str> = cloud.attributes().iter().map(|a| a.name.as_str()).collect();
                return Err(Error::InvalidSetting {
                    setting: "params",
                    value: format!("attributes {u}, {v}"),
                    hint: format!(
                        "the cloud has no attributes named {u} and {v} (its attributes: {}); use the plane or add them",
                        if names.is_empty() { "none".to_string() } else { names.join(", ") }
                    ),
                });
            };
            us.iter().zip(vs).map(|(&u, &v)| [u, v]).collect()
        }
    };
    let fit_config = config.resolved_fit(pts.len());
    let (cu, cv) = fit_config.ctrl;
    progress.stage(
        &format!("fitting {cu} x {cv} control points to {} points", pts.len()),
        None,
    );
    let fit = |t: &[[f64; 2]]| fit_surface(pts, t, &fit_config);
    let (surface, rounds) = if config.correction_rounds > 0 {
        let cc = CorrectionConfig {
            max_rounds: config.correction_rounds,
            ..config.correction
        };
        correct_parameters(pts, &mut uv, fit, &cc)?
    } else {
        (fit(&uv)?, Vec::new())
    };
    let assessment = assess_cloud(&surface, cloud, &uv, &config.assess, progress)?;
    Ok(FitReport {
        surface,
        uv,
        rounds,
        assessment,
        smoothing: fit_config.smoothing,
        projection,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use crate::Point3;

    #[test]
    fn the_default_fit_of_a_height_field_of_large_relief_does_not_fold() {
        // Franke's function (relief 1.2 over the unit square): the best-fit
        // plane folded the bumps over; the default fit projects along z
        let pts =
            crate::testdata::scattered(20_000, 29, [0.0, 0.0, 1.0, 1.0], crate::testdata::franke);
        let r = run(
            &PointCloud::new(pts).unwrap(),
            &FitConfig::default(),
            &NoProgress,
        )
        .unwrap();
        let p = r.projection.unwrap();
        assert_eq!(p.axis, crate::base::ProjectionAxis::Z);
        let q = &r.assessment.quality;
        assert_eq!(q.parameterization.fold_overs, 0);
        assert!(!q.extent.leaves, "{:?}", q.extent);
        assert!(q.orthogonal.rmse < 1.2e-3, "{:?}", q.orthogonal);
    }

    /// A regular 30 x 30 grid of a bump, fitted with the defaults (best-fit
    /// plane parameters): no triangle folds. The grid's border rows are
    /// collinear in the plane; their hull slivers, of a parameter area of
    /// 1e-9 and a sign set by round-off, were counted as 16 fold-overs.
    #[test]
    fn a_regular_grid_has_no_fold_overs_along_its_border() {
        let pts: Vec<Point3> = (0..900)
            .map(|k| {
                let (x, y) = ((k % 30) as f64, (k / 30) as f64);
                let r2 = (x - 15.0).powi(2) + (y - 15.0).powi(2);
                Point3::new(x, y, 3.0 * (-r2 / 50.0).exp())
            })
            .collect();
        let mut config = FitConfig::default();
        config.fit.ctrl = (10, 10);
        config.ctrl_from_density = false;
        let r = run(&PointCloud::new(pts).unwrap(), &config, &NoProgress).unwrap();
        let q = &r.assessment.quality.parameterization;
        assert_eq!(q.fold_overs, 0, "{q:?}");
        assert!(q.triangles > 1600, "{q:?}");
    }

    fn wave(n: usize) -> Vec<Point3> {
        (0..n * n)
            .map(|k| {
                let (x, y) = (
                    (k % n) as f64 / (n - 1) as f64,
                    (k / n) as f64 / (n - 1) as f64,
                );
                Point3::new(x, y, 0.1 * (4.0 * x).sin() * (3.0 * y).cos())
            })
            .collect()
    }

    #[test]
    fn correction_lowers_the_error_and_attributes_give_the_parameters() {
        let cloud = PointCloud::new(wave(40)).unwrap();
        let mut cfg = FitConfig::bare((5, 5));
        let plain = run(&cloud, &cfg, &NoProgress).unwrap();
        assert!(plain.rounds.is_empty());
        cfg.correction_rounds = 3;
        let corrected = run(&cloud, &cfg, &NoProgress).unwrap();
        assert!(!corrected.rounds.is_empty());
        let (e0, e1) = (
            plain.assessment.quality.at_parameters.rmse,
            corrected.assessment.quality.at_parameters.rmse,
        );
        assert!(e1 < e0, "{e1} !< {e0}");
        assert_eq!(corrected.rounds[0].errors.rmse, e0);
        // the plane's parameters given as attributes reproduce the plain fit
        let u: Vec<f64> = plain.uv.iter().map(|t| t[0]).collect();
        let v: Vec<f64> = plain.uv.iter().map(|t| t[1]).collect();
        let with = cloud
            .clone()
            .with_attribute("u", u)
            .unwrap()
            .with_attribute("v", v)
            .unwrap();
        let mut cfg = FitConfig::bare((5, 5));
        cfg.params = ParameterSource::uv_attributes();
        let given = run(&with, &cfg, &NoProgress).unwrap();
        assert_eq!(given.surface, plain.surface);
    }

    #[test]
    fn bad_settings_are_typed_errors() {
        let cloud = PointCloud::new(wave(10)).unwrap();
        let mut cfg = FitConfig::default();
        cfg.fit.periodic_u = true;
        let e = run(&cloud, &cfg, &NoProgress).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidSetting {
                    setting: "periodic_u",
                    ..
                }
            ),
            "{e}"
        );
        let cfg = FitConfig {
            params: ParameterSource::uv_attributes(),
            ..Default::default()
        };
        let e = run(&cloud, &cfg, &NoProgress).unwrap_err();
        assert!(e.to_string().contains("no attributes named u and v"), "{e}");
        let cfg = FitConfig::bare((16, 16)); // 16 x 16 > 100 points
        let e = run(&cloud, &cfg, &NoProgress).unwrap_err();
        assert!(
            matches!(
                e,
                Error::TooFewPoints {
                    got: 100,
                    needed: 256,
                    ..
                }
            ),
            "{e}"
        );
    }
}
