//! The turntable pipeline: the virtual turntable parameterization of a
//! cylinder-like cloud and a least-squares B-spline surface closed around its
//! axis (`cylindrical-turntable-parameterization`; the stages are those of
//! [`base::turntable`](crate::base::turntable)), optionally the paper's
//! comparison of the directed projection's weight factors (its Tables 1-2:
//! eq. 19 against eqs. 15 and 16 from the same layer curves), and the
//! [`SurfaceQuality`](super::assess::SurfaceQuality) of the fitted surface
//! over the points that entered the fit.

use crate::base::turntable::{compare_weights, turntable, Turntable, STAGES};
use crate::centring::Centring;
use crate::metrics::{grid_rmse, ErrorStats};
use crate::progress::Progress;
use crate::project::WeightFactor;
use crate::{Error, Point3, PointCloud, Result};

use super::assess::{assess_surface, AssessConfig, Assessment};

/// Most rounds of the weight comparison (each round projects every layer
/// sample once per weight factor).
pub const MAX_COMPARE_ROUNDS: usize = 1000;

/// The weight comparison of the turntable paper's Tables 1-2.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct WeightComparison {
    /// Projection rounds (default 5; 1 to [`MAX_COMPARE_ROUNDS`]).
    pub rounds: usize,
    /// The weight factors compared (default eq. 19, eq. 15, eq. 16).
    pub weights: Vec<WeightFactor>,
}

impl Default for WeightComparison {
    fn default() -> Self {
        Self {
            rounds: 5,
            weights: vec![
                WeightFactor::DistanceOffset,
                WeightFactor::PointDistance,
                WeightFactor::DampedDistanceOffset,
            ],
        }
    }
}

impl WeightComparison {
    /// The default comparison with `rounds` rounds.
    pub fn with_rounds(rounds: usize) -> Self {
        Self {
            rounds,
            ..Default::default()
        }
    }
}

/// Settings of [`run`], with the paper's defaults.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct TurntableConfig {
    /// The turntable itself: axis (principal), views (4), layers (40, eq.
    /// 19), refinement (2 rounds), the final fit (bicubic 40 x 40, periodic
    /// in `u`) and what happens beyond the end layers (left out of the fit).
    pub turntable: crate::base::turntable::TurntableConfig,
    /// Compare the weight factors on the same layer curves (default: no).
    pub compare_weights: Option<WeightComparison>,
    /// The assessment of the fitted surface; its `measure`, `sample_points`
    /// and `seed` also decide how the turntable measures the fold-overs and
    /// stretch of the parameters (replacing `turntable.quality`).
    pub assess: AssessConfig,
}

/// RMSE of the layer samples' nearest-point distances per projection round
/// (round 0 first) for one weight factor.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightRounds {
    /// The weight factor.
    pub weight: WeightFactor,
    /// RMSE before any round, then after each.
    pub rmse: Vec<f64>,
}

/// Everything [`run`] produced.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct TurntableReport {
    /// The turntable's results: frame, views, layer curves, base surface,
    /// parameters of every point, the fitted surface and its point and
    /// surface-to-cloud errors, fold-overs.
    pub turntable: Turntable,
    /// `|P_i - S(u_i, v_i)|` over the fitted points.
    pub parametric: ErrorStats,
    /// The assessment of the fitted surface over the fitted points (with
    /// their parameters), except its `grid_rmse` (eq. 17 of the MBA paper),
    /// measured to every point of the cloud; `turntable.surface_to_cloud`
    /// is the sample distance to every point.
    pub assessment: Assessment,
    /// The weight comparison, when asked for.
    pub weight_comparison: Option<Vec<WeightRounds>>,
}

impl TurntableReport {
    /// The fitted points (the points with `fitted` set) and their parameters.
    pub fn fitted_points(&self, cloud: &PointCloud) -> (Vec<Point3>, Vec<[f64; 2]>) {
        fitted_subset(cloud, &self.turntable)
    }
}

fn fitted_subset(cloud: &PointCloud, t: &Turntable) -> (Vec<Point3>, Vec<[f64; 2]>) {
    cloud
        .points()
        .iter()
        .zip(&t.uv)
        .zip(&t.fitted)
        .filter(|(_, &f)| f)
        .map(|((p, uv), _)| (*p, *uv))
        .unzip()
}

/// Runs the turntable pipeline on `cloud`: the stages of
/// [`base::turntable::turntable`](crate::base::turntable::turntable), each
/// reported to `progress` by its name in [`STAGES`], then the weight
/// comparison (stage "weight factor comparison") and the assessment
/// (stage "assessment").
///
/// Errors: everything the turntable refuses (a zero axis, views outside
/// 3..=64, layers outside 2..=4096, more than 100 refinement rounds, too few
/// points for the control net), and a weight comparison with no weight or
/// with rounds outside `1..=`[`MAX_COMPARE_ROUNDS`].
///
/// ```
/// use scanfit::pipeline::turntable::{run, TurntableConfig, WeightComparison};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a noise-free cylinder of radius 10 and height 40 around z
/// let mut pts = Vec::new();
/// for j in 0..80 {
///     for i in 0..120 {
///         let t = i as f64 / 120.0 * std::f64::consts::TAU + 0.01 * j as f64;
///         pts.push(Point3::new(10.0 * t.cos(), 10.0 * t.sin(), j as f64 * 0.5));
///     }
/// }
/// let mut cfg = TurntableConfig::default();
/// cfg.turntable.fit.ctrl = (16, 12);
/// cfg.compare_weights = Some(WeightComparison::with_rounds(2));
/// let r = run(&PointCloud::new(pts)?, &cfg, &NoProgress)?;
/// assert_eq!(r.turntable.surface.periodic(), (true, false));
/// assert!(r.assessment.quality.orthogonal.rmse < 0.05);
/// assert_eq!(r.weight_comparison.map(|c| c.len()), Some(3));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    cloud: &PointCloud,
    config: &TurntableConfig,
    progress: &dyn Progress,
) -> Result<TurntableReport> {
    // computed relative to the data's centre, moved back exactly (issue 14)
    let centring = Centring::of(cloud.points());
    let local = centring.cloud(cloud)?;
    Ok(centring.restore(run_centred(&local, config, progress)?))
}

/// [`run`] on data whose centre is at the origin.
fn run_centred(
    cloud: &PointCloud,
    config: &TurntableConfig,
    progress: &dyn Progress,
) -> Result<TurntableReport> {
    if let Some(c) = &config.compare_weights {
        if c.rounds == 0 || c.rounds > MAX_COMPARE_ROUNDS {
            return Err(Error::InvalidSetting {
                setting: "compare_weights.rounds",
                value: c.rounds.to_string(),
                hint: format!(
                    "the weight comparison needs 1 to {MAX_COMPARE_ROUNDS} rounds (the paper's tables show 5)"
                ),
            });
        }
        if c.weights.is_empty() {
            return Err(Error::InvalidSetting {
                setting: "compare_weights.weights",
                value: "[]".into(),
                hint: "name at least one weight factor to compare (moon, aza04, as05)".into(),
            });
        }
    }
    // the turntable measures the fold-overs and stretch of the parameters
    // as the assessment asks (sampled, full or not at all)
    let cfg = &crate::base::turntable::TurntableConfig {
        quality: config.assess,
        ..config.turntable.clone()
    };
    let t = turntable(cloud, cfg, &mut |i| {
        progress.stage(STAGES.get(i).copied().unwrap_or("turntable"), None);
        progress.advance(1);
    })?;
    let weight_comparison = match &config.compare_weights {
        Some(c) => {
            progress.stage("weight factor comparison", None);
            let r = compare_weights(cloud, &t.frame, &t.loops, &cfg.layers, c.rounds, &c.weights)?;
            Some(
                r.into_iter()
                    .map(|(weight, rmse)| WeightRounds { weight, rmse })
                    .collect(),
            )
        }
        None => None,
    };
    progress.stage("assessment", None);
    let (fp, fuv) = fitted_subset(cloud, &t);
    // the turntable measured the fitted points' fold-overs and stretch
    // already (the same call on the same points and parameters)
    let mut assessment = assess_surface(
        &t.surface,
        &fp,
        &fuv,
        &AssessConfig {
            parameterization: false,
            ..config.assess
        },
    )?;
    assessment.quality.parameterization = t.quality;
    if let (Some(s), Some(count)) = (assessment.sample.as_mut(), t.quality_sample) {
        s.parameterization_points = count;
    }
    if fp.len() < cloud.len() {
        // eq. 17 (surface to points) over the whole cloud, as the points
        // beyond the end layers are data the surface's end rows approach
        // too; `turntable.surface_to_cloud` is the whole cloud's sample
        // distance, `samples_to_points` the fitted points'
        assessment.quality.grid_rmse = grid_rmse(&t.surface, cloud.points(), None)?;
    }
    let parametric = assessment.quality.at_parameters;
    Ok(TurntableReport {
        turntable: t,
        parametric,
        assessment,
        weight_comparison,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    /// A closed-bottom cup: a cylinder of radius 10 around z with a disk at
    /// the bottom (the disk lies beyond the end layers).
    fn cup() -> PointCloud {
        let mut pts = Vec::new();
        for j in 0..60 {
            for i in 0..90 {
                let t = i as f64 / 90.0 * std::f64::consts::TAU + 0.013 * j as f64;
                pts.push(Point3::new(10.0 * t.cos(), 10.0 * t.sin(), j as f64 * 0.5));
            }
        }
        for r in 1..10 {
            for i in 0..(9 * r) {
                let t = i as f64 / (9 * r) as f64 * std::f64::consts::TAU;
                pts.push(Point3::new(r as f64 * t.cos(), r as f64 * t.sin(), 0.0));
            }
        }
        PointCloud::new(pts).unwrap()
    }

    #[test]
    fn weight_comparison_is_checked_before_any_work() {
        let mut cfg = TurntableConfig {
            compare_weights: Some(WeightComparison::with_rounds(0)),
            ..Default::default()
        };
        // an empty-looking cloud would fail later; the setting fails first
        let cloud = PointCloud::new(vec![Point3::origin(); 3]).unwrap();
        match run(&cloud, &cfg, &NoProgress) {
            Err(Error::InvalidSetting { setting, .. }) => {
                assert_eq!(setting, "compare_weights.rounds")
            }
            other => panic!("{other:?}"),
        }
        cfg.compare_weights = Some(WeightComparison {
            rounds: 2,
            weights: Vec::new(),
        });
        assert!(run(&cloud, &cfg, &NoProgress)
            .unwrap_err()
            .to_string()
            .contains("at least one weight factor"));
    }

    #[test]
    fn assessment_splits_the_fitted_points_from_the_whole_cloud() {
        let cloud = cup();
        let mut cfg = TurntableConfig::default();
        cfg.turntable.fit.ctrl = (16, 10);
        cfg.turntable.layers.layers = 16;
        cfg.compare_weights = Some(WeightComparison::with_rounds(2));
        let r = run(&cloud, &cfg, &NoProgress).unwrap();
        let t = &r.turntable;
        let fitted = t.fitted.iter().filter(|&&f| f).count();
        // the bottom disk lies beyond the end layers and is not fitted
        assert!(fitted < cloud.len() - 300, "{fitted}");
        let q = r.assessment.quality;
        assert_eq!(q.points, fitted);
        assert_eq!(q.at_parameters, r.parametric);
        // points to surface over the fitted points: the same distances the
        // turntable measured (inversions from other starts, same feet)
        assert!((q.orthogonal.rmse - t.errors.rmse).abs() < 1e-9 * (1.0 + t.errors.rmse));
        // eq. 17 over the whole cloud, fold-overs of the fitted points
        assert_eq!(
            q.grid_rmse,
            grid_rmse(&t.surface, cloud.points(), None).unwrap()
        );
        assert_eq!(q.parameterization, t.quality);
        assert!(q.parameterization.triangles > fitted);
        let cmp = r.weight_comparison.unwrap();
        assert_eq!(cmp.len(), 3);
        assert!(cmp
            .iter()
            .all(|w| w.rmse.len() == 3 && w.rmse[0] == cmp[0].rmse[0]));
    }

    #[test]
    fn the_fold_over_measures_follow_the_assessments_measure() {
        use crate::metrics::parameterization_quality;
        use crate::pipeline::assess::Measure;
        let cloud = cup();
        let mut cfg = TurntableConfig::default();
        cfg.turntable.fit.ctrl = (16, 10);
        cfg.turntable.layers.layers = 16;
        cfg.assess.measure = Measure::Full;
        let full = run(&cloud, &cfg, &NoProgress).unwrap();
        let t = &full.turntable;
        assert_eq!(t.quality_sample, None);
        // over every fitted point: the Delaunay measure of all their parameters
        let (fp, fuv) = full.fitted_points(&cloud);
        assert_eq!(
            t.quality,
            parameterization_quality(&t.surface, &fp, &fuv).unwrap()
        );
        assert!(t.quality.triangles > fp.len());
        // above `sample_points` fitted points: a cluster sample, reported
        cfg.assess.measure = Measure::Sample;
        cfg.assess.sample_points = 1000;
        let sampled = run(&cloud, &cfg, &NoProgress).unwrap();
        let s = &sampled.turntable;
        let count = s.quality_sample.unwrap();
        assert!(count > 100 && count < fp.len(), "{count}");
        assert_eq!(
            sampled.assessment.sample.unwrap().parameterization_points,
            count
        );
        assert!(s.quality.triangles > 0 && s.quality.triangles < t.quality.triangles);
        // the surface and the parameters do not depend on what is measured
        assert_eq!(s.surface, t.surface);
        assert_eq!(s.uv, t.uv);
        cfg.assess.measure = Measure::None;
        let none = run(&cloud, &cfg, &NoProgress).unwrap();
        assert_eq!(none.turntable.quality.triangles, 0);
        assert_eq!(none.turntable.surface, t.surface);
    }
}
