//! `scanfit mba` as a library call: a bicubic B-spline surface z = f(x, y)
//! through scattered 2.5D points by multilevel B-spline approximation (Lee,
//! Wolberg & Shin 1997), optionally with the MBA paper's projection
//! adjustment of control points (sections 2.2-2.4, eq. 16), with the
//! per-level table the command prints and the one surface assessment.
//!
//! The parameters of a point are its (x, y) scaled to the unit square of
//! the data's bounding box ([`Frame::unit`]). The surface's error at the
//! parameters is by construction the vertical distance `|z - f(x, y)|`, the
//! residual the level loop fits; eq. 17 is measured on the lattice's own
//! knot grid ([`knot_grid`]), as the adjustment measures it.

use crate::centring::Centring;
use rayon::prelude::*;
use std::time::Instant;

use crate::bspline::Surface;
use crate::mba::adjust::{knot_grid, lattice_grid_rmse, mba_adjusted, AdjustConfig};
use crate::mba::{lattice_surface, mba, mba_residuals, Frame, Lattice, MbaConfig};
use crate::metrics::ErrorStats;
use crate::pipeline::assess::{assess_cloud_eq17, AssessConfig, Assessment, Measure};
use crate::progress::Progress;
use crate::up_axis::UpAxis;
use crate::{Error, PointCloud, Result};

/// Settings of [`run`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct MbaRunConfig {
    /// The level loop (default [`MbaConfig::default`]: base lattice from the
    /// aspect ratio, 6 levels, no tolerance, Lee-Wolberg-Shin eq. 4).
    pub mba: MbaConfig,
    /// The MBA paper's projection adjustment at every level (default `None`;
    /// `Some(AdjustConfig::default())` is alpha 1.49 and the turntable
    /// paper's weight factor eq. 19, up to 5 steps per level).
    pub adjust: Option<AdjustConfig>,
    /// The assessment of the final surface (default [`AssessConfig::default`]).
    pub assess: AssessConfig,
    /// The axis that is height (default z): the surface is `h = f(a, b)` in
    /// that axis's z-up frame ([`UpAxis::to_frame`]: y up fits `y = f(x, -z)`,
    /// x up `x = f(y, z)`), turned back to world axes. A y-up scan fitted
    /// with z as height is a wall of spikes; [`UpAxis::automatic`] finds the
    /// thin axis of a sheet.
    pub up: UpAxis,
}

/// The adjustment's effect at one level.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct AdjustedRow {
    /// RMSE of the vertical residuals after the adjustment.
    pub vertical_rmse: f64,
    /// Eq. 17 RMSE after the adjustment.
    pub grid_rmse: f64,
    /// Adjustment steps taken.
    pub steps: usize,
}

/// One row of the per-level table.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LevelRow {
    /// Level number (0 = base lattice).
    pub level: usize,
    /// Control net of the level's combined surface, `(m + 3, n + 3)`.
    pub control_points: (usize, usize),
    /// Vertical residuals `|z - f(x, y)|` at the data points after the level
    /// (before any adjustment).
    pub vertical: ErrorStats,
    /// Eq. 17 RMSE of the level's combined surface (before any adjustment;
    /// 0, not measured, with [`crate::pipeline::assess::Measure::None`]
    /// and no adjustment).
    pub grid_rmse: f64,
    /// The adjustment at this level, when it ran.
    pub adjusted: Option<AdjustedRow>,
    /// Wall time of the level in seconds.
    pub seconds: f64,
}

/// What [`run`] returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MbaReport {
    /// The final surface (clamped bicubic, x and y linear in u and v).
    pub surface: Surface,
    /// The map between data and lattice coordinates, in the up axis's z-up
    /// frame ([`MbaRunConfig::up`]; the world's when z is up).
    pub frame: Frame,
    /// The axis that is height.
    pub up: UpAxis,
    /// Cells `(m, n)` of the final lattice (control net `(m + 3) x (n + 3)`).
    pub cells: (usize, usize),
    /// Parameters of the points (x, y of the up frame scaled to the unit
    /// square).
    pub uv: Vec<[f64; 2]>,
    /// `|z - f(x, y)|` per point.
    pub vertical: Vec<f64>,
    /// One row per level.
    pub levels: Vec<LevelRow>,
    /// Wall time of the approximation (without the assessment) in seconds.
    pub seconds: f64,
    /// The assessment of the final surface; its `at_parameters` are the
    /// vertical residuals and its `grid_rmse` is eq. 17 at the lattice's
    /// knot grid.
    pub assessment: Assessment,
}

/// Multilevel B-spline approximation of `cloud` (see the module
/// documentation).
///
/// ```
/// use scanfit::pipeline::mba::{run, MbaRunConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// let pts: Vec<Point3> = (0..2500)
///     .map(|k| {
///         let (x, y) = ((k % 50) as f64, (k / 50) as f64);
///         Point3::new(x, y, (x / 8.0).sin() * (y / 11.0).cos())
///     })
///     .collect();
/// let mut cfg = MbaRunConfig::default();
/// cfg.mba.max_levels = 4;
/// let r = run(&PointCloud::new(pts)?, &cfg, &NoProgress)?;
/// assert_eq!(r.levels.len(), 4);
/// // every level lowers the vertical error
/// assert!(r.levels.windows(2).all(|w| w[1].vertical.rmse < w[0].vertical.rmse));
/// // the last row is the final surface
/// let e = r.assessment.quality.at_parameters.rmse;
/// assert!((r.levels[3].vertical.rmse - e).abs() < 1e-9 && e < 0.1 * r.levels[0].vertical.rmse);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    cloud: &PointCloud,
    config: &MbaRunConfig,
    progress: &dyn Progress,
) -> Result<MbaReport> {
    // computed relative to the data's centre, moved back exactly (issue 14)
    let centring = Centring::of(cloud.points());
    let local = centring.cloud(cloud)?;
    let up = config.up;
    if up == UpAxis::Z {
        return Ok(centring.restore(run_centred(&local, config, progress)?));
    }
    // the height field in the up axis's frame, turned back (a rotation:
    // distances, parameters and statistics are unchanged)
    let turned = PointCloud::new(
        local
            .points()
            .iter()
            .map(|p| up.point_to_frame(p))
            .collect(),
    )?;
    let mut r = run_centred(&turned, config, progress)?;
    let ctrl = r
        .surface
        .control_points()
        .iter()
        .map(|p| up.point_from_frame(p))
        .collect();
    r.surface = Surface::new(
        r.surface.knots_u().clone(),
        r.surface.knots_v().clone(),
        ctrl,
    )?;
    for inv in &mut r.assessment.inversions {
        inv.point = up.point_from_frame(&inv.point);
    }
    r.up = up;
    Ok(centring.restore(r))
}

/// [`run`] on data whose centre is at the origin.
fn run_centred(
    cloud: &PointCloud,
    config: &MbaRunConfig,
    progress: &dyn Progress,
) -> Result<MbaReport> {
    if config.mba.max_levels == 0 {
        return Err(Error::InvalidSetting {
            setting: "max_levels",
            value: "0".into(),
            hint: "give at least 1 level".into(),
        });
    }
    let pts = cloud.points();
    let t0 = Instant::now();
    progress.stage(
        &format!("multilevel B-spline approximation of {} points", pts.len()),
        None,
    );
    // the vertical residuals of the final surface: without the adjustment,
    // the level loop's last pass measures them (its last row)
    let (result, levels, residuals) = match &config.adjust {
        Some(adjust) => {
            let r = mba_adjusted(pts, &config.mba, adjust)?;
            let rows = r
                .levels
                .iter()
                .zip(&r.mba.reports)
                .map(|(l, rep)| LevelRow {
                    level: rep.level,
                    control_points: (l.cells.0 + 3, l.cells.1 + 3),
                    vertical: l.mba_vertical,
                    grid_rmse: l.mba_rmse,
                    adjusted: Some(AdjustedRow {
                        vertical_rmse: l.adjusted_vertical.rmse,
                        grid_rmse: l.adjusted_rmse,
                        steps: l.steps,
                    }),
                    seconds: l.seconds,
                })
                .collect();
            (r.mba, rows, None)
        }
        None => {
            // the parameters in the sorted points' memory, unless eq. 17's
            // KD-tree is built next (its building would then add to them)
            // eq. 17 per level needs a KD-tree of all points, which only the
            // measuring builds anyway (at 10^7 points the tree costs more than
            // the levels): not with `Measure::None`
            let none = config.assess.measure == Measure::None;
            if none {
                let (r, at) = mba_residuals(pts, &config.mba, true)?;
                let rows = plain_rows(cloud, &r, false)?;
                (r, rows, Some(at))
            } else {
                // the measuring pass evaluates the residuals beside the
                // orthogonal distances: holding the loop's from here on
                // raised the peak at 10^7 points above 100 bytes a point
                let r = mba(pts, &config.mba)?;
                let rows = plain_rows(cloud, &r, true)?;
                (r, rows, None)
            }
        }
    };
    let surface = lattice_surface(&result.frame, &result.lattice)?;
    let seconds = t0.elapsed().as_secs_f64();
    progress.stage("measuring: parameters", None);
    let frame = result.frame;
    let (residuals, uv) = match residuals {
        Some(at) if !at.uv.is_empty() => (Some(at.vertical), at.uv),
        at => (
            at.map(|a| a.vertical),
            pts.par_iter().map(|p| frame.unit(p)).collect(),
        ),
    };
    // eq. 17 at the lattice's knot grid in the assessment's pass, and the
    // vertical errors there unless the level loop measured them (its last
    // row: the same residuals to rounding, 1e-12 of the heights' range)
    let eq17 = knot_grid(&frame, &result.lattice);
    let known = residuals.as_ref().and(levels.last().map(|l| l.vertical));
    let mut assessment =
        assess_cloud_eq17(&surface, cloud, &uv, eq17, known, &config.assess, progress)?;
    let vertical = match residuals {
        Some(v) if known.is_some() => v,
        _ => std::mem::take(&mut assessment.residuals),
    };
    if config.assess.per_point {
        assessment.residuals.clone_from(&vertical);
    }
    Ok(MbaReport {
        surface,
        frame,
        up: UpAxis::Z,
        cells: (result.lattice.m, result.lattice.n),
        uv,
        vertical,
        levels,
        seconds,
        assessment,
    })
}

/// The rows of a run without adjustment: eq. 17 of each level's combined
/// lattice (the sum refined level by level; 0, not measured, without `eq17`).
fn plain_rows(cloud: &PointCloud, r: &crate::mba::Mba, eq17: bool) -> Result<Vec<LevelRow>> {
    let mut rows = Vec::new();
    let mut total: Option<Lattice> = None;
    for (lat, rep) in r.levels.iter().zip(&r.reports) {
        let mut t = match total.take() {
            None => lat.clone(),
            Some(t) => t.refine()?,
        };
        if rep.level > 0 {
            t.add(lat)?;
        }
        rows.push(LevelRow {
            level: rep.level,
            control_points: (rep.cells.0 + 3, rep.cells.1 + 3),
            vertical: rep.residual,
            grid_rmse: if eq17 {
                lattice_grid_rmse(cloud, &r.frame, &t)?
            } else {
                0.0
            },
            adjusted: None,
            seconds: rep.seconds,
        });
        total = Some(t);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use crate::Point3;

    fn terrain() -> PointCloud {
        // scattered, not on a grid: a golden-angle spiral over a 40 x 30 box
        let pts = (0..3000)
            .map(|k| {
                let t = k as f64 * 0.618_033_988_75;
                let (x, y) = (40.0 * t.fract(), 30.0 * (k as f64 / 3000.0));
                Point3::new(x, y, 3.0 * (x / 7.0).sin() + (y / 5.0).cos())
            })
            .collect();
        PointCloud::new(pts).unwrap()
    }

    #[test]
    fn adjustment_lowers_eq17_at_the_last_level_and_rows_match_the_levels() {
        let c = terrain();
        let mut cfg = MbaRunConfig::default();
        cfg.mba.max_levels = 4;
        let plain = run(&c, &cfg, &NoProgress).unwrap();
        assert_eq!(plain.levels.len(), 4);
        assert!(plain.levels.iter().all(|l| l.adjusted.is_none()));
        // the final row is the final surface
        let last = plain.levels[3];
        assert_eq!(last.control_points, (plain.cells.0 + 3, plain.cells.1 + 3));
        let q = plain.assessment.quality;
        assert!(
            (last.vertical.rmse - q.at_parameters.rmse).abs() < 1e-9 * (1.0 + q.at_parameters.rmse)
        );
        assert!((last.grid_rmse - q.grid_rmse).abs() < 1e-12);
        cfg.adjust = Some(AdjustConfig::default());
        let adj = run(&c, &cfg, &NoProgress).unwrap();
        let a = adj.levels[3].adjusted.unwrap();
        // the adjustment took steps and moved the knot grid onto the data
        assert!(a.steps > 0);
        assert!(a.grid_rmse < adj.levels[3].grid_rmse, "{a:?}");
        assert!((a.grid_rmse - adj.assessment.quality.grid_rmse).abs() < 1e-12);
    }

    /// `|z - S_z(u, v)|` of the report's surface at every point, evaluated.
    fn evaluated(cloud: &PointCloud, r: &MbaReport) -> Vec<f64> {
        cloud
            .points()
            .iter()
            .zip(&r.uv)
            .map(|(p, t)| (p.z - r.surface.point(t[0], t[1]).z).abs())
            .collect()
    }

    #[test]
    fn vertical_errors_from_the_level_loop_equal_an_evaluation_of_the_surface() {
        use crate::mba::Start;
        use crate::testdata::{franke, scattered};
        // 60 000 points of Franke's function (several blocks per pass), at
        // the unit square and far from the origin (the centring)
        for offset in [[0.0, 0.0, 0.0], [3.0e5, -2.0e5, 800.0]] {
            let pts = scattered(60_000, 23, [0.0, 0.0, 1.0, 1.0], franke)
                .into_iter()
                .map(|p| Point3::new(p.x + offset[0], p.y + offset[1], p.z + offset[2]))
                .collect();
            let cloud = PointCloud::new(pts).unwrap();
            let (lo, hi) = crate::pipeline::assess::bounding_box(cloud.points()).unwrap();
            let range = hi.z - lo.z;
            for start in [Start::Fitted, Start::Mean] {
                for measure in [Measure::None, Measure::Sample] {
                    let mut cfg = MbaRunConfig::default();
                    cfg.mba.max_levels = 6;
                    cfg.mba.start = start;
                    cfg.assess.measure = measure;
                    let r = run(&cloud, &cfg, &NoProgress).unwrap();
                    let direct = evaluated(&cloud, &r);
                    let worst = r
                        .vertical
                        .iter()
                        .zip(&direct)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    assert!(worst <= 1e-12 * range, "{start:?} {measure:?}: {worst:e}");
                    // the statistics the report prints: the last row's, and
                    // those of the evaluated residuals to 1e-12
                    let (q, d) = (r.assessment.quality.at_parameters, ErrorStats::of(&direct));
                    // (with `Measure::None` the row itself; measuring, the
                    // pass beside the orthogonal distances evaluates them)
                    if measure == Measure::None {
                        assert_eq!(q, r.levels[5].vertical);
                    }
                    assert_eq!((q.count, q.max_index), (d.count, d.max_index));
                    // relative to the heights' range (both round at the
                    // heights' resolution; at the unit square the mean and
                    // RMSE also agree to about 1e-12 of themselves)
                    for (a, b) in [(q.mean, d.mean), (q.max, d.max), (q.rmse, d.rmse)] {
                        let tol = 1e-12 * range;
                        assert!((a - b).abs() <= tol, "{start:?} {measure:?}: {q:?} {d:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn zero_levels_is_a_typed_error() {
        let mut cfg = MbaRunConfig::default();
        cfg.mba.max_levels = 0;
        let e = run(&terrain(), &cfg, &NoProgress).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidSetting {
                    setting: "max_levels",
                    ..
                }
            ),
            "{e}"
        );
    }
}
