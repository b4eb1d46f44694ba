//! The in-memory level loop of [`super::mba`] with one pass over the points
//! per level: the pass that sums level `k`'s BA step ([LWS97] eq. 4,
//! [MBA18] eqs. 3-4) first subtracts level `k - 1` from each point's
//! residual and takes the residual statistics of level `k - 1`, so the
//! points are read once per level instead of three times (lattice
//! coordinates, sums, residual update) plus a copy of the absolute
//! residuals for the statistics.
//!
//! With [`Start::Mean`] the arithmetic per point and the order of every
//! addition are those of [`super::sums::BaAccumulator::add`] (the same
//! blocks of points, summed in the same order, merged in block order) and of
//! the residual update of [`MbaLevels`]: the lattices equal the streamed
//! level loop's bit for bit (the exact scale-out contract of
//! [`super::sums`]).
//!
//! [`Start::Fitted`] runs over the points ordered by cell ([`super::cells`]).

use std::time::Instant;

use rayon::prelude::*;

use super::cells::{level_loop, Sorted};
use super::lattice::Lattice;
use super::sums::{add_point_values, ratio_lattice, ResidualSums, BA_BLOCK};
use super::{Frame, Mba, MbaConfig, MbaLevels, Start};
use crate::{Error, Point3, Result};

/// BA sums of `K` value sets: one numerator each and the shared denominator.
struct Sums<const K: usize> {
    num: [Vec<f64>; K],
    den: Vec<f64>,
}

impl<const K: usize> Sums<K> {
    fn zeros(len: usize) -> Self {
        Self {
            num: std::array::from_fn(|_| vec![0.0; len]),
            den: vec![0.0; len],
        }
    }

    /// Adds a block's sums (in block order: the merge of [`super::sums`]).
    fn merge(&mut self, part: Self) {
        for (t, p) in self.num.iter_mut().zip(&part.num) {
            t.iter_mut().zip(p).for_each(|(x, y)| *x += y);
        }
        self.den
            .iter_mut()
            .zip(&part.den)
            .for_each(|(x, y)| *x += y);
    }

    /// The lattice of value set `k` (eq. 4's ratios).
    fn lattice(&self, k: usize, m: usize, n: usize) -> Lattice {
        ratio_lattice(m, n, &self.num[k], &self.den)
    }
}

/// The lattice a pass sums: cells, control formula, points per block and
/// the partial sums alive at a time (the constants of [`super::sums`]).
#[derive(Clone, Copy)]
struct Target {
    m: usize,
    n: usize,
    formula: super::ControlFormula,
    block: usize,
    partials: usize,
}

/// What a pass measured.
struct Measured<const K: usize> {
    sums: Option<Sums<K>>,
    /// `|r|` after the update.
    after: ResidualSums,
    /// First point whose value is not finite after the update.
    bad: Option<usize>,
}

impl<const K: usize> Measured<K> {
    fn new(target: Option<&Target>) -> Self {
        Self {
            sums: target.map(|t| Sums::zeros((t.m + 3) * (t.n + 3))),
            after: ResidualSums::default(),
            bad: None,
        }
    }

    /// Adds the block after this one's points (of `count` points).
    fn merge(&mut self, part: Self, offset: usize) {
        if self.bad.is_none() {
            self.bad = part.bad.map(|i| i + offset);
        }
        if let (Some(t), Some(p)) = (self.sums.as_mut(), part.sums) {
            t.merge(p);
        }
        self.after.merge(&part.after);
    }
}

/// Multilevel B-spline approximation of points in memory, one pass per level
/// (see the module documentation).
pub(crate) fn mba(points: &[Point3], config: &MbaConfig) -> Result<Mba> {
    let frame = Frame::of(points)?;
    let unit: Vec<[f64; 2]> = points.par_iter().map(|p| frame.unit(p)).collect();
    let run = MbaLevels::in_memory(frame, config)?;
    match config.start {
        Start::Mean => {
            let mut values: Vec<[f64; 1]> = points.par_iter().map(|p| [p.z - frame.z0]).collect();
            mean_start(run, &unit, &mut values)
        }
        Start::Fitted => {
            let values: Vec<[f64; 2]> = points.par_iter().map(|p| [p.z - frame.z0, 1.0]).collect();
            let sorted = Sorted::new(&unit, values, run.base, run.max_levels)?;
            drop(unit);
            level_loop(run, sorted)
        }
    }
}

/// The next level's target, `None` when all levels are done.
fn target(run: &MbaLevels) -> Result<Option<Target>> {
    if run.done() {
        return Ok(None);
    }
    let acc = run.accumulator()?;
    let (m, n) = acc.cells();
    Ok(Some(Target {
        m,
        n,
        formula: acc.formula(),
        block: acc.block(),
        partials: acc.partials(),
    }))
}

/// The level loop started from the frame's mean height.
fn mean_start(mut run: MbaLevels, unit: &[[f64; 2]], values: &mut [[f64; 1]]) -> Result<Mba> {
    let mut seconds = Vec::new();
    loop {
        let started = Instant::now();
        let target = target(&run)?;
        let previous = run.levels.last().map(|l| [l]);
        let m = pass(unit, values, previous, target.as_ref())?;
        seconds.push(started.elapsed().as_secs_f64());
        if previous.is_some() {
            // this pass measured the residuals after the previous level
            if run.record_residual(m.after.stats()) {
                break;
            }
        }
        let (Some(t), Some(s)) = (target, m.sums) else {
            break;
        };
        run.push_lattice(s.lattice(0, t.m, t.n))?;
    }
    let mut r = run.finish();
    pass_seconds(&mut r, &seconds);
    Ok(r)
}

/// Level `k`'s wall time: pass `k` (its sums and the update of the level
/// before); the passes after the last level count for it.
pub(super) fn pass_seconds(r: &mut Mba, seconds: &[f64]) {
    let levels = r.reports.len();
    for (k, rep) in r.reports.iter_mut().enumerate() {
        rep.seconds = if k + 1 == levels {
            seconds[k.min(seconds.len())..].iter().sum()
        } else {
            seconds.get(k).copied().unwrap_or(0.0)
        };
    }
}

/// One pass: every point's values minus the `previous` levels at it (when
/// given), their statistics, and the BA sums of `target` (when given) of
/// the updated values.
fn pass<const K: usize>(
    unit: &[[f64; 2]],
    values: &mut [[f64; K]],
    previous: Option<[&Lattice; K]>,
    target: Option<&Target>,
) -> Result<Measured<K>> {
    // without a target: blocks of the BA block size anyway (the statistics
    // are the same for any block size up to rounding)
    let (block, wave) = target.map_or((BA_BLOCK, 16), |t| (t.block, t.partials));
    let mut total = Measured::new(target);
    let mut offset = 0;
    for (vw, uw) in values
        .chunks_mut(block * wave)
        .zip(unit.chunks(block * wave))
    {
        let parts: Vec<Measured<K>> = vw
            .par_chunks_mut(block)
            .zip(uw.par_chunks(block))
            .map(|(v, u)| block_pass(u, v, previous, target))
            .collect();
        for (b, p) in parts.into_iter().enumerate() {
            total.merge(p, offset + b * block);
        }
        offset += vw.len();
    }
    if let Some(at) = total.bad {
        return Err(Error::BadPoint {
            index: at,
            problem: format!(
                "has the residual {:?} after the levels so far; its height is too large to approximate",
                values[at]
            ),
        });
    }
    Ok(total)
}

/// [`pass`] over one block of points, in order.
fn block_pass<const K: usize>(
    unit: &[[f64; 2]],
    values: &mut [[f64; K]],
    previous: Option<[&Lattice; K]>,
    target: Option<&Target>,
) -> Measured<K> {
    let mut out = Measured::new(target);
    let prev = previous.map(|l| (l, l[0].m as f64, l[0].n as f64));
    let next = target.map(|t| (t, t.m as f64, t.n as f64));
    for (i, (u, v)) in unit.iter().zip(values.iter_mut()).enumerate() {
        if let Some((l, m, n)) = prev {
            let b = l[0].basis(u[0] * m, u[1] * n);
            for (x, lk) in v.iter_mut().zip(l) {
                *x -= lk.eval_at(&b);
            }
            out.after.push(v[0].abs());
        }
        if let (Some((t, m, n)), Some(s)) = (next, out.sums.as_mut()) {
            if !v.iter().all(|x| x.is_finite()) {
                out.bad.get_or_insert(i);
                continue;
            }
            let mut num = s.num.each_mut().map(|x| x.as_mut_slice());
            add_point_values(
                &mut num,
                &mut s.den,
                t.m,
                t.n,
                t.formula,
                [u[0] * m, u[1] * n],
                *v,
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mba::ControlFormula;
    use crate::testdata::{franke, scattered};

    /// The level loop one level at a time (three passes per level), as the
    /// in-memory loop ran before the passes were fused.
    fn level_at_a_time(points: &[Point3], config: &MbaConfig) -> Mba {
        let frame = Frame::of(points).unwrap();
        let unit: Vec<[f64; 2]> = points.iter().map(|p| frame.unit(p)).collect();
        let mut residual: Vec<f64> = points.iter().map(|p| p.z - frame.z0).collect();
        let mut run = MbaLevels::new(frame, config).unwrap();
        for _ in 0..config.max_levels {
            if run.level(&unit, &mut residual).unwrap() {
                break;
            }
        }
        run.finish()
    }

    #[test]
    fn fused_passes_give_the_level_at_a_time_lattices_bit_for_bit() {
        // 50 000 points: several blocks per level; a 2 x 1 base
        let p = scattered(50_000, 3, [10.0, -4.0, 2.0, 1.0], |x, y| {
            franke((x - 10.0) / 2.0, y + 4.0)
        });
        for (formula, tolerance) in [
            (ControlFormula::LeeWolbergShin, None),
            (ControlFormula::Hjelle, None),
            (ControlFormula::LeeWolbergShin, Some(2e-3)),
        ] {
            let config = MbaConfig {
                max_levels: 7,
                formula,
                tolerance,
                ..Default::default()
            };
            let (a, b) = (mba(&p, &config).unwrap(), level_at_a_time(&p, &config));
            assert_eq!(a.lattice, b.lattice, "{formula:?} {tolerance:?}");
            assert_eq!(a.levels, b.levels);
            assert_eq!(a.reports.len(), b.reports.len());
            if tolerance.is_some() {
                assert!(a.reports.len() < 7, "{}", a.reports.len());
            }
            for (x, y) in a.reports.iter().zip(&b.reports) {
                assert_eq!(x.cells, y.cells);
                assert_eq!(
                    (x.residual.max, x.residual.max_index),
                    (y.residual.max, y.residual.max_index)
                );
                assert!((x.residual.rmse - y.residual.rmse).abs() <= 1e-13 * y.residual.rmse);
                assert!((x.residual.mean - y.residual.mean).abs() <= 1e-13 * y.residual.mean);
            }
        }
    }

    /// RMSE of `z - f(x, y)` at the points, evaluated from the lattice.
    fn rmse(r: &Mba, p: &[Point3]) -> f64 {
        (p.iter()
            .map(|q| (q.z - r.eval(q.x, q.y)).powi(2))
            .sum::<f64>()
            / p.len() as f64)
            .sqrt()
    }

    #[test]
    fn the_fitted_start_beats_the_mean_and_its_rows_are_the_shorter_runs() {
        let p = scattered(40_000, 5, [0.0, 0.0, 1.0, 1.0], franke);
        let config = |levels, start| MbaConfig {
            base: Some((1, 1)),
            max_levels: levels,
            start,
            ..Default::default()
        };
        let mean = mba(&p, &config(6, Start::Mean)).unwrap();
        let fit = mba(&p, &config(6, Start::Fitted)).unwrap();
        let (em, ef) = (rmse(&mean, &p), rmse(&fit, &p));
        // measured 2.7e-4 from the mean, 2.2e-4 fitted
        assert!(ef < 0.95 * em, "fitted {ef:e}, mean {em:e}");
        // the last row is the final surface, measured independently
        let last = fit.reports.last().unwrap().residual;
        assert!((last.rmse - ef).abs() <= 1e-9 * ef, "{last:?} {ef:e}");
        // the combined lattice is the sum of the levels
        for q in p.iter().step_by(97) {
            assert!((fit.eval(q.x, q.y) - fit.eval_levels(q.x, q.y)).abs() < 1e-12);
        }
        // row k is what k + 1 levels give (each with its own fitted start)
        for levels in [1, 3] {
            let short = mba(&p, &config(levels, Start::Fitted)).unwrap();
            let (a, b) = (
                short.reports.last().unwrap().residual,
                fit.reports[levels - 1].residual,
            );
            assert_eq!(a.max_index, b.max_index);
            for (x, y) in [(a.rmse, b.rmse), (a.mean, b.mean), (a.max, b.max)] {
                assert!((x - y).abs() <= 1e-12 * y, "{levels}: {a:?} {b:?}");
            }
            assert!((rmse(&short, &p) - a.rmse).abs() <= 1e-9 * a.rmse);
        }
        // independent of the heights' origin (the mean start is too; zero is not)
        let raised: Vec<Point3> = p
            .iter()
            .map(|q| Point3::new(q.x, q.y, q.z + 1000.0))
            .collect();
        let up = mba(&raised, &config(6, Start::Fitted)).unwrap();
        assert!((rmse(&up, &raised) - ef).abs() < 1e-3 * ef);
        // a tolerance stops it where the fitted RMSE meets it
        let mut tol = config(6, Start::Fitted);
        tol.tolerance = Some(fit.reports[2].residual.rmse * 1.0001);
        let stopped = mba(&p, &tol).unwrap();
        assert_eq!(stopped.reports.len(), 3);
        assert!((rmse(&stopped, &p) - fit.reports[2].residual.rmse).abs() <= 1e-9 * ef);
    }

    #[test]
    fn the_chunked_level_loop_refuses_the_fitted_start() {
        let p = scattered(100, 1, [0.0, 0.0, 1.0, 1.0], franke);
        let config = MbaConfig {
            start: Start::Fitted,
            ..Default::default()
        };
        let e = MbaLevels::new(Frame::of(&p).unwrap(), &config).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidSetting {
                    setting: "start",
                    ..
                }
            ),
            "{e}"
        );
    }
}
