//! `scanfit report` as a library call: how well a surface represents a set
//! of points it may not have been fitted to.
//!
//! The points are projected orthogonally onto the surface and the result is
//! the one assessment ([`assess_projected`]: orthogonal distances, eq. 17,
//! surface samples to points, the fold-overs of the projected parameters),
//! plus the distribution of the orthogonal distances: median, 95th
//! percentile and a histogram over the 99th percentile with an overflow bin
//! ([`Histogram`]: a few stray points do not squeeze the bulk into one bin).

use crate::bspline::Surface;
use crate::centring::{Centring, Translate};
use crate::distribution::{percentile_sorted, Histogram};
use crate::pipeline::assess::{assess_projected, AssessConfig, Assessment};
use crate::progress::Progress;
use crate::{Point3, Result};

/// Settings of [`run`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MeasureConfig {
    /// The assessment (default [`AssessConfig::default`]).
    pub assess: AssessConfig,
    /// Bins of the distance histogram over `[0, top]` (default 24).
    pub bins: usize,
    /// The percentile that is the histogram's `top` (default 99; the
    /// distances above it are counted in the overflow bin).
    pub histogram_percentile: f64,
}

impl Default for MeasureConfig {
    fn default() -> Self {
        Self {
            assess: AssessConfig::default(),
            bins: 24,
            histogram_percentile: 99.0,
        }
    }
}

/// What [`run`] returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MeasureReport {
    /// The assessment; the points' parameters are their projections'
    /// (`assessment.inversions[i].uv`).
    pub assessment: Assessment,
    /// Median orthogonal distance.
    pub median: f64,
    /// 95th percentile of the orthogonal distances.
    pub p95: f64,
    /// The orthogonal distances in `bins` equal bins over `[0, top]`, `top`
    /// their `histogram_percentile`-th percentile, plus an overflow bin.
    pub histogram: Histogram,
}

/// Measures `points` against `surface` (see the module documentation).
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::pipeline::measure::{run, MeasureConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::Point3;
///
/// let k = KnotVector::uniform_clamped(1, 2)?;
/// let c = vec![
///     Point3::new(0., 0., 0.), Point3::new(0., 1., 0.),
///     Point3::new(1., 0., 0.), Point3::new(1., 1., 0.),
/// ];
/// let s = Surface::new(k.clone(), k, c)?;
/// // 100 points, the k-th 0.001 k above the plane
/// let pts: Vec<Point3> = (0..100)
///     .map(|i| Point3::new((i % 10) as f64 / 9.0, (i / 10) as f64 / 9.0, 0.001 * i as f64))
///     .collect();
/// let r = run(&s, &pts, &MeasureConfig::default(), &NoProgress)?;
/// assert!((r.assessment.quality.orthogonal.max - 0.099).abs() < 1e-9);
/// assert!((r.median - 0.050).abs() < 1e-9);
/// assert_eq!(r.histogram.counts.iter().sum::<usize>() + r.histogram.overflow, 100);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    surface: &Surface,
    points: &[Point3],
    config: &MeasureConfig,
    progress: &dyn Progress,
) -> Result<MeasureReport> {
    // the histogram's settings checked before the work
    Histogram::over_percentile(&[], config.bins, config.histogram_percentile)?;
    progress.stage(&format!("projecting {} points", points.len()), None);
    // relative to the points' centre (issue 14): surface and points moved
    // exactly, the foot points moved back
    let centring = Centring::of(points);
    let assessment = if centring.is_identity() {
        assess_projected(surface, points, &config.assess)?
    } else {
        let mut local = surface.clone();
        local.translate(&-centring.centre());
        let pts = centring.points(points);
        centring.restore(assess_projected(&local, &pts, &config.assess)?)
    };
    let mut sorted = assessment.distances();
    sorted.sort_by(f64::total_cmp);
    // nearest-rank percentiles; `assess_projected` refused an empty set
    let pct = |f: f64| percentile_sorted(&sorted, f).unwrap_or(0.0);
    let (median, p95) = (pct(0.5), pct(0.95));
    let histogram = Histogram::over_percentile(&sorted, config.bins, config.histogram_percentile)?;
    Ok(MeasureReport {
        assessment,
        median,
        p95,
        histogram,
    })
}
