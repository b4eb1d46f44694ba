//! Multilevel B-spline approximation (MBA) of scattered 2.5D data
//! ([LWS97], as summarised in [MBA18] section 2.1 and
//! [TURN17] section 2.1), with [MBA18]'s projection
//! adjustment of control points (sections 2.2-2.4, [`adjust`]).
//!
//! The data `(x, y, z)` are mapped to the lattice rectangle: `x` from the
//! bounding box's `[x0, x0 + width]` to `[0, m]`, `y` likewise to `[0, n]`,
//! and `z` taken relative to its mean, so georeferenced coordinates
//! (10^6 and beyond) lose no precision. Level `k` fits a lattice of
//! `(m 2^k + 3) x (n 2^k + 3)` control values to the residuals of the
//! levels before it ([`lattice::Lattice::approximate`]); the levels are
//! combined as they go by refining the running sum (LWS97 section 5), so the
//! result is ONE uniform cubic lattice, returned as an ordinary clamped
//! bicubic B-spline surface of the kernel ([`Mba::surface`]) with
//! parameters `u = (x - x0) / width`, `v = (y - y0) / height` and control
//! points `(x, y, z)` at the Greville abscissae (so `S(u, v) = (x, y, f(x, y))`).

pub mod adjust;
mod cells;
mod fused;
pub mod lattice;
pub mod sums;

use std::time::Instant;

use rayon::prelude::*;

use crate::bspline::ops::greville;
use crate::bspline::{KnotVector, Surface};
use crate::metrics::ErrorStats;
use crate::{Error, Point3, Result};

pub(crate) use fused::mba_residuals;
pub use lattice::{ControlFormula, Lattice};
pub use sums::{BaAccumulator, FrameSums, LevelInputs, PassSums, ResidualSums};

/// When the level loop stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MbaConfig {
    /// Cells `(m, n)` of the first lattice along x and y (its control net is
    /// `(m + 3) x (n + 3)`). `None` (default): 1 cell along the shorter side
    /// of the bounding box and the rounded aspect ratio along the longer.
    pub base: Option<(usize, usize)>,
    /// Most levels (default 6: a `(2^5 m + 3)`-wide net at the last level).
    pub max_levels: usize,
    /// Stop as soon as the RMSE of the vertical residuals at the data points
    /// is at most this (data units); `None` (default) runs all levels.
    pub tolerance: Option<f64>,
    /// Control-value formula (default Lee, Wolberg & Shin's eq. 4).
    pub formula: ControlFormula,
    /// The function level 0 starts from (default [`Start::Fitted`]).
    pub start: Start,
}

/// The function the level loop starts from: level 0 fits the heights minus
/// it. BA does not reproduce constants (a lattice fitted to constant data
/// is not that constant), so the start shows in the final fit: measured on
/// Franke's function (10^6 points, 131 x 131 values, BENCHMARKS.md), the
/// held-out RMSE is 6.41e-5 fitted, 8.14e-5 from the mean, 7.25e-5 from zero (ddemidov/mba's
/// default, [LWS97]'s level 0 on the raw heights) and 1.10e-4 from a
/// least-squares plane; from zero it also depends on where the heights'
/// origin lies (4.6 times worse with the data raised by 10), so zero is no
/// default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Start {
    /// The mean height (the frame's `z0`): independent of the heights'
    /// origin; the level loop carries the heights alone.
    Mean,
    /// The constant of least squares (default): the level loop also runs
    /// the constant 1 through the same levels (MBA is linear in the
    /// heights), and the start `z0 + delta` with `delta = sum r c / sum c^2`
    /// (`r`, `c` the final residuals of the heights and of the constant)
    /// leaves the smallest residual at the points among all constant
    /// starts. In memory at the CPU time of [`Start::Mean`] (the in-memory
    /// loop carries the second value set for both starts); streamed and
    /// distributed ([`MbaLevels`]) the sums carry a second numerator per
    /// control value and one more pass follows the last level (for its
    /// `delta`). The adjustment ([`adjust::mba_adjusted`]) starts from the
    /// mean: it changes the lattices between levels, so the constant's
    /// levels no longer predict the start.
    #[default]
    Fitted,
}

impl Default for MbaConfig {
    fn default() -> Self {
        Self {
            base: None,
            max_levels: 6,
            tolerance: None,
            formula: ControlFormula::LeeWolbergShin,
            start: Start::Fitted,
        }
    }
}

/// The map between data coordinates and lattice coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Smallest x of the data.
    pub x0: f64,
    /// Smallest y of the data.
    pub y0: f64,
    /// Extent in x (> 0).
    pub width: f64,
    /// Extent in y (> 0).
    pub height: f64,
    /// Mean z of the data (the lattices hold `z - z0`).
    pub z0: f64,
}

impl Frame {
    /// The frame of `points`; errors for data without extent in x or y
    /// ([`FrameSums`] over all points).
    pub fn of(points: &[Point3]) -> Result<Self> {
        let mut sums = FrameSums::default();
        sums.add(points)?;
        sums.finish()
    }

    /// Unit coordinates `((x - x0) / width, (y - y0) / height)`.
    pub fn unit(&self, p: &Point3) -> [f64; 2] {
        [(p.x - self.x0) / self.width, (p.y - self.y0) / self.height]
    }

    /// The default first lattice: 1 cell along the shorter side, the
    /// rounded aspect ratio along the longer.
    pub fn default_base(&self) -> (usize, usize) {
        let r = self.width / self.height;
        if r >= 1.0 {
            ((r.round() as usize).clamp(1, 64), 1)
        } else {
            (1, ((1.0 / r).round() as usize).clamp(1, 64))
        }
    }
}

/// What one level did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelReport {
    /// Level number (0 = the base lattice).
    pub level: usize,
    /// Cells `(m, n)` of the lattice of this level (net `(m + 3) x (n + 3)`).
    pub cells: (usize, usize),
    /// Vertical residuals `|z - f(x, y)|` at the data points after this level.
    pub residual: ErrorStats,
    /// Wall time of the level in seconds.
    pub seconds: f64,
}

/// A multilevel approximation: the combined lattice, the level lattices
/// (for inspection and the sum-of-levels check) and the per-level reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Mba {
    /// The coordinate map.
    pub frame: Frame,
    /// The single combined lattice (all levels refined to the last one).
    pub lattice: Lattice,
    /// The lattice fitted at each level (level `k` has `2^k` times the base cells).
    pub levels: Vec<Lattice>,
    /// One report per level.
    pub reports: Vec<LevelReport>,
}

/// Lattice coordinates of unit coordinates on an `m x n` lattice.
fn to_cells(unit: &[[f64; 2]], m: usize, n: usize) -> Vec<[f64; 2]> {
    unit.iter()
        .map(|u| [u[0] * m as f64, u[1] * n as f64])
        .collect()
}

/// Multilevel B-spline approximation of `points` (see the module documentation).
///
/// The points are ordered once by lattice cell; then one pass over them per
/// level: the pass that sums a level's BA step first subtracts the level
/// before from the residuals and measures them. The result equals the
/// streamed level loop's ([`MbaLevels`] fed in file order) up to the
/// rounding of the order of the sums (see [`MbaLevels`]'s example).
pub fn mba(points: &[Point3], config: &MbaConfig) -> Result<Mba> {
    fused::mba(points, config)
}

/// The level loop of MBA, one level at a time, for drivers that hold the
/// points themselves or not at all: the in-memory [`mba`], the adjustment
/// ([`adjust::mba_adjusted`]), a file read in chunks, or a cluster.
///
/// Per level: [`accumulator`](Self::accumulator) gives the level's empty BA
/// sums ([`BaAccumulator`], lattice of `2^k` times the base cells); the
/// points go in with [`BaAccumulator::add_levels`] given
/// [`inputs`](Self::inputs) (what a driver broadcasts: the frame, the
/// lattices so far and the row to measure), in any number of accumulators
/// merged afterwards, and each returns its [`PassSums`]; the merged
/// `PassSums` are [`record`](Self::record)ed (the row of a level before,
/// the fitted start so far, and whether the tolerance is met), then
/// [`push`](Self::push) finishes the level and adds it to the combined
/// lattice (refined, [LWS97] section 5). With the fitted start the start of
/// the last level needs one more pass ([`needs_pass`](Self::needs_pass),
/// [`sums::pass_sums`]). The last row, which only a pass over the final
/// surface measures, is recorded with [`record_last`](Self::record_last).
///
/// ```
/// use scanfit::mba::{mba, sums::pass_sums, FrameSums, MbaConfig, MbaLevels, PassSums};
/// use scanfit::Point3;
///
/// let p: Vec<Point3> = (0..3000)
///     .map(|k| {
///         let (x, y) = ((k * 7 % 100) as f64, (k / 30) as f64);
///         Point3::new(x, y, (x / 9.0).sin() + (y / 13.0).cos())
///     })
///     .collect();
/// let config = MbaConfig { max_levels: 4, ..Default::default() };
/// // a first pass for the frame, then one pass per level over two "tiles"
/// let mut f = FrameSums::default();
/// f.add(&p)?;
/// let mut run = MbaLevels::new(f.finish()?, &config)?;
/// while !run.done() {
///     let mut a = run.accumulator()?;
///     let mut b = run.accumulator()?;
///     let mut sums = a.add_levels(&run.inputs(), &p[..1000])?;
///     sums.merge(&b.add_levels(&run.inputs(), &p[1000..])?);
///     a.merge(b)?;
///     run.record(&sums)?;
///     run.push(a)?;
/// }
/// // the fitted start (the default) of the last level: one more pass
/// while run.needs_pass() {
///     let sums = pass_sums(&run.inputs(), &p)?;
///     run.record(&sums)?;
/// }
/// let tiles = run.finish();
/// let once = mba(&p, &config)?;
/// let worst = tiles.lattice.phi.iter().zip(&once.lattice.phi).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
/// assert!(worst < 1e-12);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct MbaLevels {
    frame: Frame,
    base: (usize, usize),
    formula: ControlFormula,
    tolerance: Option<f64>,
    max_levels: usize,
    start: Start,
    total: Option<Lattice>,
    levels: Vec<Lattice>,
    /// The fitted start's constant: its level lattices.
    ones: Vec<Lattice>,
    /// `deltas[k]`: the fitted start of levels `0..=k`.
    deltas: Vec<f64>,
    /// Rows recorded (from the first).
    rows: usize,
    reports: Vec<LevelReport>,
    started: Instant,
}

impl MbaLevels {
    /// The loop for data in `frame` (from [`Frame::of`] or [`FrameSums`]);
    /// errors for a zero base lattice, a bad tolerance, or a last level
    /// beyond [`lattice::MAX_LATTICE_VALUES`].
    pub fn new(frame: Frame, config: &MbaConfig) -> Result<Self> {
        let base = config.base.unwrap_or_else(|| frame.default_base());
        if base.0 == 0 || base.1 == 0 {
            return Err(Error::InvalidSetting {
                setting: "base",
                value: format!("{} x {}", base.0, base.1),
                hint: "the base lattice needs at least 1 x 1 cells".into(),
            });
        }
        if let Some(t) = config.tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::InvalidSetting {
                    setting: "tolerance",
                    value: t.to_string(),
                    hint: "the MBA tolerance must be a finite number >= 0".into(),
                });
            }
        }
        if last_lattice_values(base, config.max_levels).is_none() {
            return Err(Error::InvalidSetting {
                setting: "max_levels",
                value: config.max_levels.to_string(),
                hint: format!(
                    "{} levels on a {} x {} base lattice would need more than {} control values at the last level (a lattice doubles per level); lower the levels or the base lattice",
                    config.max_levels,
                    base.0,
                    base.1,
                    lattice::MAX_LATTICE_VALUES
                ),
            });
        }
        Ok(Self {
            frame,
            base,
            formula: config.formula,
            tolerance: config.tolerance,
            max_levels: config.max_levels.max(1),
            start: config.start,
            total: None,
            levels: Vec::new(),
            ones: Vec::new(),
            deltas: Vec::new(),
            rows: 0,
            reports: Vec::new(),
            started: Instant::now(),
        })
    }

    /// The map between data and lattice coordinates.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The start of level 0.
    pub fn start(&self) -> Start {
        self.start
    }

    /// The lattices of the levels so far (level `k` has `2^k` times the
    /// base cells): what the residuals of the next level subtract.
    pub fn levels(&self) -> &[Lattice] {
        &self.levels
    }

    /// The constant's lattices of the levels so far (the fitted start;
    /// empty for the mean).
    pub fn constant_levels(&self) -> &[Lattice] {
        &self.ones
    }

    /// What the next pass over the points needs: the frame, the lattices so
    /// far and the row it measures (the mean start: the last level's; the
    /// fitted start: the last level whose start is known, which the pass
    /// after it found).
    pub fn inputs(&self) -> LevelInputs<'_> {
        let row = match self.start {
            Start::Mean => (!self.levels.is_empty()).then_some((self.levels.len(), 0.0)),
            Start::Fitted => self.deltas.last().map(|&d| (self.deltas.len(), d)),
        };
        LevelInputs {
            frame: self.frame,
            heights: &self.levels,
            constant: &self.ones,
            start: self.start,
            row,
        }
    }

    /// Cells `(m, n)` of the next level's lattice.
    pub fn next_cells(&self) -> (usize, usize) {
        let k = self.levels.len();
        (self.base.0 << k, self.base.1 << k)
    }

    /// Whether all levels of the configuration are done.
    pub fn done(&self) -> bool {
        self.levels.len() >= self.max_levels
    }

    /// Whether the fitted start of the last level is still unknown: one
    /// more pass ([`sums::pass_sums`], then [`record`](Self::record))
    /// finds it before [`finish`](Self::finish).
    pub fn needs_pass(&self) -> bool {
        self.start == Start::Fitted && self.deltas.len() < self.levels.len()
    }

    /// Empty BA sums of the next level.
    pub fn accumulator(&self) -> Result<BaAccumulator> {
        let (m, n) = self.next_cells();
        BaAccumulator::for_start(m, n, self.formula, self.start)
    }

    /// Records what a pass over all points measured (its merged
    /// [`PassSums`], from the [`inputs`](Self::inputs) of now): the row it
    /// measured and, for the fitted start, the start of the levels so far.
    /// Returns whether the tolerance is met (the RMSE at the points after
    /// the levels so far, with their fitted start), i.e. whether the loop
    /// should stop before pushing another level. Call it once per pass;
    /// the pass of level 0 records nothing.
    pub fn record(&mut self, sums: &PassSums) -> Result<bool> {
        if self.levels.is_empty() {
            return Ok(false);
        }
        match self.start {
            Start::Mean => Ok(self.record_residual(sums.row.stats())),
            Start::Fitted => {
                if !self.needs_pass() {
                    return Err(Error::InvalidInput(format!(
                        "the start of the {} levels so far is recorded already; record each pass's sums once",
                        self.levels.len()
                    )));
                }
                let j = self.deltas.len();
                if j > 0 {
                    self.reports[j - 1].residual = sums.row.stats();
                    self.rows = j;
                }
                self.deltas.push(sums.start());
                if let Some(r) = self.reports.last_mut() {
                    r.seconds += self.started.elapsed().as_secs_f64();
                }
                self.started = Instant::now();
                Ok(self.tolerance.is_some_and(|t| sums.start_rmse() <= t))
            }
        }
    }

    /// Finishes the next level from its (merged) sums and adds it to the
    /// combined lattice; its report has no residual statistics until a
    /// later pass records them.
    pub fn push(&mut self, sums: BaAccumulator) -> Result<()> {
        if sums.cells() != self.next_cells() || sums.start() != self.start {
            let (m, n) = sums.cells();
            let (nm, nn) = self.next_cells();
            return Err(Error::InvalidInput(format!(
                "the sums are of a {m} x {n} lattice for the {:?} start, but level {} has {nm} x {nn} cells and the {:?} start",
                sums.start(),
                self.levels.len(),
                self.start
            )));
        }
        if self.needs_pass() {
            return Err(Error::InvalidInput(format!(
                "the pass of level {} was not recorded; record its sums before pushing the level",
                self.levels.len()
            )));
        }
        let mut sets = sums.finish_sets().into_iter();
        match (sets.next(), sets.next()) {
            (Some(z), c) => self.push_lattices(z, c),
            (None, _) => Err(Error::InvalidInput("BA sums without a value set".into())),
        }
    }

    /// Adds the finished lattices of the next level (of
    /// [`next_cells`](Self::next_cells)), the heights' and (fitted start)
    /// the constant's, to the combined lattices.
    fn push_lattices(&mut self, phi: Lattice, one: Option<Lattice>) -> Result<()> {
        self.total = Some(add_refined(self.total.take(), &phi)?);
        if let Some(c) = one.filter(|_| self.start == Start::Fitted) {
            self.ones.push(c);
        }
        self.reports.push(LevelReport {
            level: self.levels.len(),
            cells: (phi.m, phi.n),
            residual: ErrorStats::default(),
            seconds: self.started.elapsed().as_secs_f64(),
        });
        self.started = Instant::now();
        self.levels.push(phi);
        Ok(())
    }

    /// Records the statistics of the residuals after the last level pushed
    /// (and the time spent measuring them); returns whether they meet the
    /// tolerance, i.e. whether the loop should stop (the mean start's
    /// [`record`](Self::record)).
    pub fn record_residual(&mut self, stats: ErrorStats) -> bool {
        if let Some(r) = self.reports.last_mut() {
            r.residual = stats;
            r.seconds += self.started.elapsed().as_secs_f64();
            self.rows = self.reports.len();
        }
        self.started = Instant::now();
        self.tolerance.is_some_and(|t| stats.rmse <= t)
    }

    /// Records the statistics of the last row if no pass recorded it: the
    /// vertical residuals of the finished surface, from a measuring pass.
    pub fn record_last(&mut self, stats: ErrorStats) {
        if self.rows < self.reports.len() {
            self.record_residual(stats);
        }
    }

    /// Fits the next level to `residual` at the unit coordinates `unit`
    /// (residuals updated in place, the points in memory, the mean start);
    /// returns whether the tolerance is met.
    pub(crate) fn level(&mut self, unit: &[[f64; 2]], residual: &mut [f64]) -> Result<bool> {
        let (m, n) = self.next_cells();
        let cells = to_cells(unit, m, n);
        let mut sums = BaAccumulator::new(m, n, self.formula)?;
        sums.add(&cells, residual)?;
        self.push_lattices(sums.finish(), None)?;
        let phi = &self.levels[self.levels.len() - 1];
        residual
            .par_iter_mut()
            .zip(cells.par_iter())
            .for_each(|(r, c)| *r -= phi.eval(c[0], c[1]));
        let abs: Vec<f64> = residual.iter().map(|r| r.abs()).collect();
        Ok(self.record_residual(ErrorStats::of(&abs)))
    }

    /// The combined lattice so far (mutable, for the adjustment).
    pub(crate) fn total_mut(&mut self) -> Option<&mut Lattice> {
        self.total.as_mut()
    }

    /// The approximation: the combined lattice (zero when no level was
    /// pushed), the level lattices and their reports. With the fitted start
    /// `z0 + d` (`d` the start of the last level, [`needs_pass`](Self::needs_pass)
    /// false; else the last start known) level `k` is `Z_k - d C_k` (the
    /// constant's level `C_k`), with `d` added to level 0 (a constant lattice
    /// is the constant function), and the combined lattice likewise.
    pub fn finish(self) -> Mba {
        let zero = || Lattice {
            m: self.base.0,
            n: self.base.1,
            phi: vec![0.0; (self.base.0 + 3) * (self.base.1 + 3)],
        };
        let mut levels = self.levels;
        let mut total = self.total;
        if self.start == Start::Fitted {
            let d = self.deltas.last().copied().unwrap_or(0.0);
            total = None;
            for (k, (z, c)) in levels.iter_mut().zip(&self.ones).enumerate() {
                for (a, b) in z.phi.iter_mut().zip(&c.phi) {
                    *a -= d * b;
                }
                if k == 0 {
                    z.phi.iter_mut().for_each(|a| *a += d);
                }
                // the sizes were refined and added once already in push
                total = add_refined(total.take(), z).ok();
            }
        }
        Mba {
            frame: self.frame,
            lattice: total.unwrap_or_else(zero),
            levels,
            reports: self.reports,
        }
    }
}

/// `total` refined to the cells of `phi`, plus `phi` (`phi` alone first).
fn add_refined(total: Option<Lattice>, phi: &Lattice) -> Result<Lattice> {
    Ok(match total {
        None => phi.clone(),
        Some(t) => {
            let mut t = t.refine()?;
            t.add(phi)?;
            t
        }
    })
}

/// Control values of the last level's lattice of `levels` levels on a
/// `base` lattice, or `None` beyond [`lattice::MAX_LATTICE_VALUES`].
pub fn last_lattice_values(base: (usize, usize), levels: usize) -> Option<usize> {
    let last = levels.max(1) - 1;
    u32::try_from(last)
        .ok()
        .and_then(|k| 1usize.checked_shl(k))
        .and_then(|f| base.0.checked_mul(f).zip(base.1.checked_mul(f)))
        .and_then(|(m, n)| (m.checked_add(3)?).checked_mul(n.checked_add(3)?))
        .filter(|&len| len <= lattice::MAX_LATTICE_VALUES)
}

impl Mba {
    /// `f(x, y)` of the combined surface at a data-space point.
    pub fn eval(&self, x: f64, y: f64) -> f64 {
        lattice_height(&self.frame, &self.lattice, x, y)
    }

    /// The sum of the level lattices' functions at `(x, y)`: equal to
    /// [`eval`](Self::eval) up to round-off (LWS97 section 5).
    pub fn eval_levels(&self, x: f64, y: f64) -> f64 {
        let u = self.frame.unit(&Point3::new(x, y, 0.0));
        self.frame.z0
            + self
                .levels
                .iter()
                .map(|l| l.eval(u[0] * l.m as f64, u[1] * l.n as f64))
                .sum::<f64>()
    }

    /// The combined lattice as a clamped bicubic B-spline surface.
    pub fn surface(&self) -> Result<Surface> {
        lattice_surface(&self.frame, &self.lattice)
    }
}

/// `f(x, y)` of `lattice` in `frame` at a data-space point.
pub(crate) fn lattice_height(frame: &Frame, lattice: &Lattice, x: f64, y: f64) -> f64 {
    let u = frame.unit(&Point3::new(x, y, 0.0));
    frame.z0 + lattice.eval(u[0] * lattice.m as f64, u[1] * lattice.n as f64)
}

/// The uniform knots `(a - 3) / cells`, `a = 0..cells + 6`, of a lattice
/// direction in unit coordinates (domain `[0, 1]`).
fn uniform_knots(cells: usize) -> Result<KnotVector> {
    KnotVector::new(
        (0..cells + 7)
            .map(|a| (a as f64 - 3.0) / cells as f64)
            .collect(),
        3,
    )
}

/// `lattice` in `frame` as a clamped bicubic B-spline surface over
/// `[0, 1]^2` with control points `(x, y, z)`: x and y at the Greville
/// abscissae (which reproduce the linear maps exactly), z the control values.
pub fn lattice_surface(frame: &Frame, lattice: &Lattice) -> Result<Surface> {
    let (m, n) = (lattice.m, lattice.n);
    let (ku, kv) = (uniform_knots(m)?, uniform_knots(n)?);
    // (a - 1) / cells on these knots, up to rounding
    let (xi, eta) = (greville(&ku), greville(&kv));
    let mut ctrl = Vec::with_capacity(lattice.phi.len());
    for (a, x) in xi.iter().enumerate() {
        for (b, y) in eta.iter().enumerate() {
            ctrl.push(Point3::new(
                frame.x0 + frame.width * x,
                frame.y0 + frame.height * y,
                frame.z0 + lattice.get(a, b),
            ));
        }
    }
    Surface::new(ku, kv, ctrl)?.to_clamped()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testdata::franke;

    fn random_points(n: usize, f: impl Fn(f64, f64) -> f64, offset: [f64; 2]) -> Vec<Point3> {
        let mut rng = crate::testdata::Lcg::new(99);
        let mut rnd = || rng.next_f64();
        (0..n)
            .map(|_| {
                let (x, y) = (rnd(), rnd());
                Point3::new(x + offset[0], y + offset[1], f(x, y))
            })
            .collect()
    }

    #[test]
    fn franke_error_falls_at_every_level() {
        let p = random_points(10_000, franke, [0.0, 0.0]);
        let r = mba(
            &p,
            &MbaConfig {
                max_levels: 7,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(r.reports.len(), 7);
        for w in r.reports.windows(2) {
            assert!(
                w[1].residual.rmse < w[0].residual.rmse,
                "{:?}",
                r.reports
                    .iter()
                    .map(|l| l.residual.rmse)
                    .collect::<Vec<_>>()
            );
        }
        // 67 x 67 control values over 10^4 points: close to the function
        assert!(r.reports[6].residual.rmse < 2e-3, "{:?}", r.reports[6]);
        assert_eq!(r.reports[6].cells, (64, 64));
    }

    #[test]
    fn combined_surface_equals_the_sum_of_levels() {
        // a non-square domain far from the origin (georeferenced)
        let p: Vec<Point3> = random_points(5000, franke, [0.0, 0.0])
            .into_iter()
            .map(|q| Point3::new(5.0e6 + 300.0 * q.x, 4.0e6 + 120.0 * q.y, 200.0 + 50.0 * q.z))
            .collect();
        let r = mba(&p, &MbaConfig::default()).unwrap();
        assert_eq!(r.reports[0].cells, (3, 1));
        let s = r.surface().unwrap();
        assert!(s.knots_u().is_clamped() && s.degrees() == (3, 3));
        let mut worst: f64 = 0.0;
        for q in p.iter().take(2000) {
            let (a, b) = (r.eval(q.x, q.y), r.eval_levels(q.x, q.y));
            let u = r.frame.unit(q);
            let on = s.point(u[0], u[1]);
            worst = worst.max((a - b).abs()).max((on.z - a).abs());
            // the surface's x, y are the data's x, y
            assert!((on.x - q.x).abs() < 1e-7 && (on.y - q.y).abs() < 1e-7);
        }
        assert!(worst < 1e-10, "{worst}");
    }

    #[test]
    fn degenerate_input_is_an_error_or_well_defined() {
        let line: Vec<Point3> = (0..10).map(|i| Point3::new(1.0, i as f64, 0.0)).collect();
        let e = mba(&line, &MbaConfig::default()).unwrap_err().to_string();
        assert!(e.contains("same x"), "{e}");
        assert!(mba(&[Point3::new(1.0, 2.0, 3.0)], &MbaConfig::default()).is_err());
        let nan = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(f64::NAN, 1.0, 1.0)];
        assert!(mba(&nan, &MbaConfig::default()).is_err());
        // the same (x, y) with two heights: the mean, not NaN
        let mut p = random_points(200, |x, y| x + y, [0.0, 0.0]);
        p.push(Point3::new(0.5, 0.5, 10.0));
        p.push(Point3::new(0.5, 0.5, -10.0));
        let r = mba(&p, &MbaConfig::default()).unwrap();
        assert!(r.eval(0.5, 0.5).is_finite());
        assert!(r
            .surface()
            .unwrap()
            .control_points()
            .iter()
            .all(|c| c.z.is_finite()));
        // points on a diagonal line: a defined surface (zero away from the data)
        let diag: Vec<Point3> = (0..50)
            .map(|i| Point3::new(i as f64, i as f64, (i as f64 * 0.2).sin()))
            .collect();
        let r = mba(&diag, &MbaConfig::default()).unwrap();
        assert!(r.reports.last().unwrap().residual.max < 0.05);
        // 10^8-sized coordinates: the same fit as at the origin
        let near = random_points(2000, franke, [0.0, 0.0]);
        let far: Vec<Point3> = near
            .iter()
            .map(|q| Point3::new(q.x + 1e8, q.y - 3e8, q.z + 1e8))
            .collect();
        let (a, b) = (
            mba(&near, &MbaConfig::default()).unwrap(),
            mba(&far, &MbaConfig::default()).unwrap(),
        );
        for (ra, rb) in a.reports.iter().zip(&b.reports) {
            assert!(
                (ra.residual.rmse - rb.residual.rmse).abs() < 1e-6,
                "{ra:?} {rb:?}"
            );
        }
        let s = b.surface().unwrap();
        assert!(s.control_points().iter().all(|c| c.z.is_finite()));
        let bad = MbaConfig {
            base: Some((0, 2)),
            ..Default::default()
        };
        assert!(mba(&diag, &bad).is_err());
    }
}
