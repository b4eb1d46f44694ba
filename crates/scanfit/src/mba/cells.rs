//! The in-memory level loop with the fitted start ([`Start::Fitted`]), over
//! the points ordered once by lattice cell.
//!
//! The points are sorted by their cell of the last level's lattice, cells in
//! Morton order within each base cell, so the points of every cell of every
//! level lie next to each other. A level's pass then walks the points in
//! runs of one cell: the 4 x 4 control values of the level before, which
//! every point of the run reads to update its residuals, are loaded once
//! per run, and the run's BA sums ([LWS97] eq. 4, [MBA18] eqs. 3-4) are
//! added up in a 4 x 4 block and written to the lattice once per run, in
//! the factored form of [`BaFactors`] (one division per value).
//!
//! Each pass carries two value sets (the heights' residual `r` and the
//! constant 1's `c`, [`super::Start::Fitted`]), subtracts the level before,
//! and measures: `sum r^2, sum r c, sum c^2` after the update (the level's
//! fitted start `delta = sum r c / sum c^2` and its RMSE) and, with the
//! `delta` of the level before the previous one, the statistics of
//! `|r - delta c|` before the update (that level's row).

use rayon::prelude::*;

use super::lattice::{locate, uniform_cubic_basis, ControlFormula, Lattice};
use super::sums::{ratio_lattice, BaFactors, ResidualSums, BA_BLOCK};
use super::{Mba, MbaLevels};
use crate::metrics::ErrorStats;
use crate::{Error, Result};

/// The points in cell order: unit coordinates, the two value sets and the
/// original index of each.
pub(super) struct Sorted {
    unit: Vec<[f64; 2]>,
    values: Vec<[f64; 2]>,
    index: Vec<u32>,
}

/// Interleaves the low `bits` bits of `a` (odd positions) and `b`.
fn morton(a: usize, b: usize, bits: u32) -> usize {
    let mut key = 0;
    for bit in (0..bits).rev() {
        key = (key << 2) | (((a >> bit) & 1) << 1) | ((b >> bit) & 1);
    }
    key
}

/// The cell of lattice coordinate `x` on `cells` cells (as [`locate`]).
#[inline]
fn cell(x: f64, cells: usize) -> usize {
    locate(x.clamp(0.0, cells as f64), cells).0
}

impl Sorted {
    /// `unit` and `values` ordered by the cell of the last level
    /// (`levels` levels on a `base` lattice), Morton order within each base
    /// cell (a counting sort).
    pub(super) fn new(
        unit: &[[f64; 2]],
        values: Vec<[f64; 2]>,
        base: (usize, usize),
        levels: usize,
    ) -> Result<Self> {
        if u32::try_from(unit.len()).is_err() {
            return Err(Error::InvalidInput(format!(
                "{} points are more than the fitted start orders at once (2^32); use the mean start",
                unit.len()
            )));
        }
        let shift = (levels.max(1) - 1) as u32;
        let (m, n) = (base.0 << shift, base.1 << shift);
        let mask = (1usize << shift) - 1;
        let keys: Vec<u32> = unit
            .par_iter()
            .map(|u| {
                let (i, j) = (cell(u[0] * m as f64, m), cell(u[1] * n as f64, n));
                let b = (i >> shift) * base.1 + (j >> shift);
                ((b << (2 * shift)) | morton(i & mask, j & mask, shift)) as u32
            })
            .collect();
        let mut start = vec![0u32; m * n + 1];
        for &k in &keys {
            start[k as usize + 1] += 1;
        }
        for c in 1..start.len() {
            start[c] += start[c - 1];
        }
        let mut index = vec![0u32; unit.len()];
        for (p, &k) in keys.iter().enumerate() {
            let at = &mut start[k as usize];
            index[*at as usize] = p as u32;
            *at += 1;
        }
        let unit = index.par_iter().map(|&p| unit[p as usize]).collect();
        let values = index.par_iter().map(|&p| values[p as usize]).collect();
        Ok(Self {
            unit,
            values,
            index,
        })
    }
}

/// The level a pass sums.
#[derive(Clone, Copy)]
struct Target {
    m: usize,
    n: usize,
    formula: ControlFormula,
}

/// The sums of a pass (or of a block of it).
struct Measured {
    /// Numerators of `r` and `c` and the shared denominator (empty without
    /// a target).
    num: [Vec<f64>; 2],
    den: Vec<f64>,
    /// `sum r^2, sum r c, sum c^2` after the update.
    quad: [f64; 3],
    /// `|r - delta c|` before the update (with the delta given).
    before: ResidualSums,
    /// First point (sorted position) whose values are not finite.
    bad: Option<usize>,
}

impl Measured {
    fn new(len: usize) -> Self {
        Self {
            num: [vec![0.0; len], vec![0.0; len]],
            den: vec![0.0; len],
            quad: [0.0; 3],
            before: ResidualSums::default(),
            bad: None,
        }
    }

    /// Adds the block after this one's points (`offset` its first point).
    fn merge(&mut self, part: Self, offset: usize) {
        if self.bad.is_none() {
            self.bad = part.bad.map(|i| i + offset);
        }
        for (t, p) in self
            .num
            .iter_mut()
            .chain([&mut self.den])
            .zip(part.num.iter().chain([&part.den]))
        {
            t.iter_mut().zip(p).for_each(|(x, y)| *x += y);
        }
        for (a, b) in self.quad.iter_mut().zip(part.quad) {
            *a += b;
        }
        self.before.merge(&part.before);
    }
}

/// The least-squares start `sum r c / sum c^2` and the RMSE it leaves.
fn fitted(quad: [f64; 3], count: usize) -> (f64, f64) {
    let [rr, rc, cc] = quad;
    let delta = if cc > 0.0 { rc / cc } else { 0.0 };
    let ss = (rr - 2.0 * delta * rc + delta * delta * cc).max(0.0);
    (delta, (ss / count.max(1) as f64).sqrt())
}

/// The level loop with the fitted start over `sorted` (see the module
/// documentation); `run` is fresh.
pub(super) fn level_loop(mut run: MbaLevels, mut sorted: Sorted) -> Result<Mba> {
    let count = sorted.unit.len();
    let mut ones: Vec<Lattice> = Vec::new();
    let mut deltas: Vec<f64> = Vec::new();
    let mut rows: Vec<ErrorStats> = Vec::new();
    let mut seconds = Vec::new();
    let mut stop = false;
    loop {
        let started = std::time::Instant::now();
        let target = if stop || run.done() {
            None
        } else {
            let (m, n) = run.next_cells();
            Some(Target {
                m,
                n,
                formula: run.formula,
            })
        };
        let previous = match (run.levels.last(), ones.last()) {
            (Some(z), Some(c)) if !stop => Some([z, c]),
            _ => None,
        };
        // the values before this pass's update are the residuals after the
        // level of the last delta known
        let before = deltas.last().copied();
        let m = pass(&mut sorted, previous, target, before)?;
        seconds.push(started.elapsed().as_secs_f64());
        if before.is_some() {
            let mut stats = m.before.stats();
            stats.max_index = sorted.index.get(stats.max_index).map_or(0, |&i| i as usize);
            rows.push(stats);
        }
        if stop {
            break;
        }
        if previous.is_some() {
            let (delta, rmse) = fitted(m.quad, count);
            deltas.push(delta);
            if run.tolerance.is_some_and(|t| rmse <= t) || target.is_none() {
                // one more pass (no update) measures the last row
                stop = true;
                continue;
            }
        }
        let Some(t) = target else {
            break;
        };
        ones.push(ratio_lattice(t.m, t.n, &m.num[1], &m.den));
        run.push_lattice(ratio_lattice(t.m, t.n, &m.num[0], &m.den))?;
    }
    let mut r = combine(run, &ones, &deltas, &rows)?;
    super::fused::pass_seconds(&mut r, &seconds);
    Ok(r)
}

/// The fit started from `z0 + delta` (the last level's delta) from the
/// levels of the heights and of the constant: level `k` becomes
/// `Z_k - delta C_k`, the start `delta` goes into level 0 (a constant
/// lattice is the constant function), and the reports get the rows.
fn combine(run: MbaLevels, ones: &[Lattice], deltas: &[f64], rows: &[ErrorStats]) -> Result<Mba> {
    let delta = deltas.last().copied().unwrap_or(0.0);
    let mut r = run.finish();
    let kept = deltas.len().min(r.levels.len());
    r.levels.truncate(kept);
    r.reports.truncate(kept);
    for (k, (z, c)) in r.levels.iter_mut().zip(ones).enumerate() {
        for (a, b) in z.phi.iter_mut().zip(&c.phi) {
            *a -= delta * b;
        }
        if k == 0 {
            z.phi.iter_mut().for_each(|a| *a += delta);
        }
    }
    let mut total: Option<Lattice> = None;
    for l in &r.levels {
        total = Some(match total {
            None => l.clone(),
            Some(t) => {
                let mut t = t.refine()?;
                t.add(l)?;
                t
            }
        });
    }
    if let Some(t) = total {
        r.lattice = t;
    }
    for (rep, stats) in r.reports.iter_mut().zip(rows) {
        rep.residual = *stats;
    }
    Ok(r)
}

/// One pass over the sorted points in blocks (fixed by the point count and
/// the lattice, never by the thread count; partial sums merged in block
/// order, so the result does not depend on the threads).
fn pass(
    sorted: &mut Sorted,
    previous: Option<[&Lattice; 2]>,
    target: Option<Target>,
    delta: Option<f64>,
) -> Result<Measured> {
    let len = target.map_or(0, |t| (t.m + 3) * (t.n + 3));
    let count = sorted.unit.len();
    let block = BA_BLOCK.max(len).max(count.div_ceil(64));
    // at most 16 partials (and 256 MiB of them) at a time
    let wave = ((256usize << 20) / (24 * len.max(1))).clamp(1, 16);
    let mut total = Measured::new(len);
    let mut offset = 0;
    for (vw, uw) in sorted
        .values
        .chunks_mut(block * wave)
        .zip(sorted.unit.chunks(block * wave))
    {
        let parts: Vec<Measured> = vw
            .par_chunks_mut(block)
            .zip(uw.par_chunks(block))
            .map(|(v, u)| block_pass(u, v, previous, target, delta, len))
            .collect();
        for (b, p) in parts.into_iter().enumerate() {
            total.merge(p, offset + b * block);
        }
        offset += vw.len();
    }
    if let Some(at) = total.bad {
        return Err(Error::BadPoint {
            index: sorted.index[at] as usize,
            problem: format!(
                "has the residual {} after the levels so far; its height is too large to approximate",
                sorted.values[at][0]
            ),
        });
    }
    Ok(total)
}

/// 4 x 4 control values (or sums) of one cell's support.
type Block4 = [[f64; 4]; 4];

/// The 4 x 4 control values of `lattice` from cell `(i, j)`.
#[inline]
fn block4(lattice: &Lattice, i: usize, j: usize) -> Block4 {
    let st = lattice.n + 3;
    std::array::from_fn(|k| {
        let row = &lattice.phi[(i + k) * st + j..(i + k) * st + j + 4];
        [row[0], row[1], row[2], row[3]]
    })
}

/// Eq. 1 with the basis values and a 4 x 4 block of control values.
#[inline]
fn eval4(bs: &[f64; 4], bt: &[f64; 4], c: &Block4) -> f64 {
    let mut f = 0.0;
    for k in 0..4 {
        let mut r = 0.0;
        for l in 0..4 {
            r += bt[l] * c[k][l];
        }
        f += bs[k] * r;
    }
    f
}

/// A run's BA sums, added to the lattice when the run ends.
struct RunSums {
    i: usize,
    j: usize,
    num: [[[f64; 4]; 4]; 2],
    den: [[f64; 4]; 4],
}

impl RunSums {
    fn flush(&self, m: &mut Measured, st: usize) {
        for k in 0..4 {
            let row = (self.i + k) * st + self.j..(self.i + k) * st + self.j + 4;
            for (s, num) in self.num.iter().enumerate() {
                for (a, b) in m.num[s][row.clone()].iter_mut().zip(num[k]) {
                    *a += b;
                }
            }
            for (a, b) in m.den[row].iter_mut().zip(self.den[k]) {
                *a += b;
            }
        }
    }
}

/// [`pass`] over one block of sorted points, in runs of one cell.
fn block_pass(
    unit: &[[f64; 2]],
    values: &mut [[f64; 2]],
    previous: Option<[&Lattice; 2]>,
    target: Option<Target>,
    delta: Option<f64>,
    len: usize,
) -> Measured {
    let mut out = Measured::new(len);
    // the finer of the two levels decides the runs
    let (rm, rn) = match (target, previous) {
        (Some(t), _) => (t.m, t.n),
        (None, Some(p)) => (p[0].m, p[0].n),
        (None, None) => (1, 1),
    };
    let halve = usize::from(target.is_some());
    let mut run: Option<RunSums> = None;
    let mut prev_block: Option<(Block4, Block4)> = None;
    let mut run_cell = (usize::MAX, usize::MAX);
    for (q, (u, v)) in unit.iter().zip(values.iter_mut()).enumerate() {
        let c = (cell(u[0] * rm as f64, rm), cell(u[1] * rn as f64, rn));
        if c != run_cell {
            run_cell = c;
            if let (Some(r), Some(_)) = (run.take(), target) {
                r.flush(&mut out, rn + 3);
            }
            prev_block = previous.map(|p| {
                let (i, j) = (c.0 >> halve, c.1 >> halve);
                (block4(p[0], i, j), block4(p[1], i, j))
            });
            run = target.map(|_| RunSums {
                i: c.0,
                j: c.1,
                num: [[[0.0; 4]; 4]; 2],
                den: [[0.0; 4]; 4],
            });
        }
        if let Some(d) = delta {
            out.before.push((v[0] - d * v[1]).abs());
        }
        if let (Some(p), Some((bz, bc))) = (previous, prev_block.as_ref()) {
            let (m, n) = (p[0].m, p[0].n);
            let (_, s) = locate((u[0] * m as f64).clamp(0.0, m as f64), m);
            let (_, t) = locate((u[1] * n as f64).clamp(0.0, n as f64), n);
            let (bs, bt) = (uniform_cubic_basis(s), uniform_cubic_basis(t));
            v[0] -= eval4(&bs, &bt, bz);
            v[1] -= eval4(&bs, &bt, bc);
            out.quad[0] += v[0] * v[0];
            out.quad[1] += v[0] * v[1];
            out.quad[2] += v[1] * v[1];
        }
        let (Some(t), Some(r)) = (target, run.as_mut()) else {
            continue;
        };
        if !(v[0].is_finite() && v[1].is_finite()) {
            out.bad.get_or_insert(q);
            continue;
        }
        let (_, s) = locate((u[0] * t.m as f64).clamp(0.0, t.m as f64), t.m);
        let (_, tt) = locate((u[1] * t.n as f64).clamp(0.0, t.n as f64), t.n);
        let f = BaFactors::new(s, tt, t.formula);
        let q = [v[0] / f.sum2, v[1] / f.sum2];
        let [rz, rc] = &mut r.num;
        for (k, ((nz, nc), den)) in rz.iter_mut().zip(rc).zip(&mut r.den).enumerate() {
            let (az, ac, d) = (q[0] * f.fs[k], q[1] * f.fs[k], f.ds[k]);
            for l in 0..4 {
                nz[l] += az * f.ft[l];
                nc[l] += ac * f.ft[l];
                den[l] += d * f.dt[l];
            }
        }
    }
    if let (Some(r), Some(_)) = (run, target) {
        r.flush(&mut out, rn + 3);
    }
    out
}
