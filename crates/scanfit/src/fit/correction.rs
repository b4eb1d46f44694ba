//! Parameter correction (Hoschek 1988, "Intrinsic parametrization for
//! approximation"): alternate the least-squares fit with the orthogonal
//! re-projection of the points onto the fitted surface, so that each point's
//! error vector becomes normal to the surface, until the RMSE stops improving.

use crate::bspline::Surface;
use crate::metrics::{parametric_distances, ErrorStats};
use crate::project::{InversionConfig, SurfaceInverter};
use crate::{Point3, Result};

/// Settings of [`correct_parameters`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectionConfig {
    /// Most re-projection rounds (default 5).
    pub max_rounds: usize,
    /// Stop when a round improves the RMSE by less than this fraction (default 1e-3).
    pub min_improvement: f64,
}

impl Default for CorrectionConfig {
    fn default() -> Self {
        Self {
            max_rounds: 5,
            min_improvement: 1e-3,
        }
    }
}

/// What one round achieved (round 0 is the initial fit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectionRound {
    /// Round number.
    pub round: usize,
    /// Errors at the points' parameters after the round's fit.
    pub errors: ErrorStats,
}

/// Fits with `fit`, then re-projects and refits while the RMSE improves.
/// `uv` is updated to the parameters of the returned (best) surface.
pub fn correct_parameters(
    points: &[Point3],
    uv: &mut Vec<[f64; 2]>,
    fit: impl Fn(&[[f64; 2]]) -> Result<Surface>,
    cfg: &CorrectionConfig,
) -> Result<(Surface, Vec<CorrectionRound>)> {
    let mut surface = fit(uv)?;
    let mut errors = ErrorStats::of(&parametric_distances(&surface, points, uv));
    let mut rounds = vec![CorrectionRound { round: 0, errors }];
    for round in 1..=cfg.max_rounds {
        let inverter = SurfaceInverter::new(&surface, InversionConfig::default())?;
        let new_uv: Vec<[f64; 2]> = inverter
            .invert_all_from(points, uv)
            .iter()
            .map(|r| r.uv)
            .collect();
        let candidate = fit(&new_uv)?;
        let e = ErrorStats::of(&parametric_distances(&candidate, points, &new_uv));
        rounds.push(CorrectionRound { round, errors: e });
        if e.rmse < errors.rmse {
            let gain = (errors.rmse - e.rmse) / errors.rmse.max(f64::MIN_POSITIVE);
            surface = candidate;
            *uv = new_uv;
            errors = e;
            if gain < cfg.min_improvement {
                break;
            }
        } else {
            break;
        }
    }
    Ok((surface, rounds))
}
