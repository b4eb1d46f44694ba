//! The in-memory level loop of [`super::mba`]: one pass over the points per
//! level, over the points ordered once by lattice cell ([`super::cells`]):
//! the pass that sums level `k`'s BA step ([LWS97] eq. 4, [MBA18]
//! eqs. 3-4) first subtracts level `k - 1` from each point's residuals and
//! measures them, so the points are read once per level instead of three
//! times (lattice coordinates, sums, residual update) plus a copy of the
//! absolute residuals for the statistics.
//!
//! The lattices equal those of the level loop fed one level at a time
//! ([`MbaLevels`], the streamed and distributed loop, which sums in file
//! order) up to the rounding of the order of the sums: tested to 1e-12 of
//! the largest control value, the bound of the distributed loop (issue 17).

use rayon::prelude::*;

use super::cells::{level_loop, Sorted};
use super::{Frame, FrameSums, Mba, MbaConfig, MbaLevels, Start};
use crate::{Point3, Result};

/// Multilevel B-spline approximation of points in memory, one pass per level
/// (see the module documentation).
pub(crate) fn mba(points: &[Point3], config: &MbaConfig) -> Result<Mba> {
    Ok(run(points, config, None)?.0)
}

/// What [`mba_residuals`] returns besides the approximation, per point in
/// the input's order.
pub(crate) struct AtPoints {
    /// The vertical residuals `|z - f(x, y)|` of the final surface.
    pub vertical: Vec<f64>,
    /// The parameters ([`Frame::unit`]).
    pub uv: Vec<[f64; 2]>,
}

/// [`mba`] and, at `points` (in their order), the final surface's vertical
/// residuals `|z - f(x, y)|`: the values the level loop's last pass
/// measures for the last row, so no second evaluation of the surface; and,
/// with `uv`, the points' parameters, written into the memory of the
/// sorted ones (else empty: a caller about to allocate much first, such as
/// a KD-tree, computes them afterwards).
pub(crate) fn mba_residuals(
    points: &[Point3],
    config: &MbaConfig,
    uv: bool,
) -> Result<(Mba, AtPoints)> {
    run(points, config, Some(uv))
}

/// [`mba`], and with `at_points` the residuals and (`Some(true)`) the
/// parameters (else empty).
fn run(points: &[Point3], config: &MbaConfig, at_points: Option<bool>) -> Result<(Mba, AtPoints)> {
    let frame = frame(points)?;
    let run = MbaLevels::new(frame, config)?;
    let c = match config.start {
        Start::Mean => 0.0,
        Start::Fitted => 1.0,
    };
    let mut sorted = Sorted::new(points, &frame, run.base, run.max_levels, c)?;
    let (r, delta) = level_loop(run, &mut sorted)?;
    let mut out = AtPoints {
        vertical: Vec::new(),
        uv: Vec::new(),
    };
    if let Some(uv) = at_points {
        out.vertical = sorted.residuals(delta);
        if uv {
            out.uv = sorted.into_unit();
            out.uv
                .par_iter_mut()
                .zip(points.par_iter())
                .for_each(|(u, p)| *u = frame.unit(p));
        }
    }
    Ok((r, out))
}

/// [`Frame::of`] with the points summed in blocks on all threads (the
/// blocks merged in order: the same frame for any thread count; the mean
/// height differs from the one-stream sum by its rounding only).
fn frame(points: &[Point3]) -> Result<Frame> {
    let parts: Vec<Result<FrameSums>> = points
        .par_chunks(super::sums::BA_BLOCK * 4)
        .map(|c| {
            let mut s = FrameSums::default();
            s.add(c).map(|()| s)
        })
        .collect();
    let mut total = FrameSums::default();
    let mut offset = 0;
    for (k, part) in parts.into_iter().enumerate() {
        match part {
            Ok(s) => total.merge(&s),
            // the index within the chunk, shifted to the whole input
            Err(e) => return Err(shift_index(e, offset)),
        }
        offset = (k + 1) * super::sums::BA_BLOCK * 4;
    }
    total.finish()
}

/// `e` with its point index (counted within a chunk) shifted by `offset`.
fn shift_index(e: crate::Error, offset: usize) -> crate::Error {
    match e {
        crate::Error::NonFinite { index, value } => crate::Error::NonFinite {
            index: index + offset,
            value,
        },
        crate::Error::BadPoint { index, problem } => crate::Error::BadPoint {
            index: index + offset,
            problem,
        },
        e => e,
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mba::{ControlFormula, Lattice};
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

    /// The largest difference of two lattices relative to the largest value of `b`.
    fn relative(a: &Lattice, b: &Lattice) -> f64 {
        assert_eq!((a.m, a.n), (b.m, b.n));
        let scale = b.phi.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        a.phi
            .iter()
            .zip(&b.phi)
            .fold(0.0f64, |w, (x, y)| w.max((x - y).abs()))
            / scale
    }

    #[test]
    fn fused_passes_give_the_level_at_a_time_lattices_to_1e12() {
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
                start: Start::Mean,
                ..Default::default()
            };
            let (a, b) = (mba(&p, &config).unwrap(), level_at_a_time(&p, &config));
            let worst = relative(&a.lattice, &b.lattice);
            assert!(worst <= 1e-12, "{formula:?} {tolerance:?}: {worst:e}");
            // not equal bit for bit: the sums' order differs
            assert_ne!(a.lattice, b.lattice);
            assert_eq!(a.levels.len(), b.levels.len());
            for (x, y) in a.levels.iter().zip(&b.levels) {
                assert!(relative(x, y) <= 1e-12);
            }
            assert_eq!(a.reports.len(), b.reports.len());
            if tolerance.is_some() {
                assert!(a.reports.len() < 7, "{}", a.reports.len());
            }
            for (x, y) in a.reports.iter().zip(&b.reports) {
                assert_eq!(x.cells, y.cells);
                assert_eq!(x.residual.max_index, y.residual.max_index);
                assert_eq!(x.residual.count, y.residual.count);
                for (a, b) in [
                    (x.residual.max, y.residual.max),
                    (x.residual.rmse, y.residual.rmse),
                    (x.residual.mean, y.residual.mean),
                ] {
                    assert!((a - b).abs() <= 1e-10 * b, "{x:?} {y:?}");
                }
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
}
