//! The in-memory level loop of [`super::mba`], over the points ordered once
//! by lattice cell, for either start ([`Start::Fitted`], [`Start::Mean`]).
//!
//! The points are sorted by their cell of the last level's lattice, cells in
//! Morton order within each base cell (a counting sort), so the points of
//! every cell of every level lie next to each other, and the cells of level
//! `k` are ranges of the sort's cell bounds ([`Sorted::runs`]): no pass
//! computes a point's cell. A level's pass walks the points in runs of one
//! cell: the 4 x 4 control values of the level before, which every point of
//! the run reads to update its residuals, are loaded once per run, and the
//! run's BA sums ([LWS97] eq. 4, [MBA18] eqs. 3-4) are added up in a 4 x 4
//! block and written to the lattice once per run, in the factored form of
//! [`super::sums::BaFactors`] (one division per point).
//!
//! Each pass carries two value sets (the heights' residual `r` and the
//! constant 1's `c`, [`super::Start::Fitted`]), subtracts the level before,
//! and measures: `sum r^2, sum r c, sum c^2` after the update (the level's
//! fitted start `delta = sum r c / sum c^2` and its RMSE) and, with the
//! `delta` of the level before the previous one, the statistics of
//! `|r - delta c|` before the update (that level's row).
//!
//! The mean start runs the same passes with the constant's values 0 (its
//! lattices are then zero and its delta 0), so both starts cost the same;
//! the lattices equal the streamed level loop's ([`MbaLevels`] fed in
//! chunks, which sums in file order) up to the rounding of the sums'
//! order (tested to 1e-12 of the largest control value).
//!
//! [`Start::Fitted`]: super::Start::Fitted
//! [`Start::Mean`]: super::Start::Mean

use std::ops::Range;

use rayon::prelude::*;

use super::lattice::{ControlFormula, Lattice};
use super::sums::{ratio_lattice, PassSums, ResidualSums, BA_BLOCK};
use super::{Frame, Mba, MbaLevels};
use crate::metrics::ErrorStats;
use crate::{Error, Point3, Result};

/// The points in cell order: unit coordinates, the two value sets, the
/// original index of each, and where each cell's points start.
pub(super) struct Sorted {
    unit: Vec<[f64; 2]>,
    values: Vec<[f64; 2]>,
    index: Vec<u32>,
    /// The sorted position of each point (the inverse of `index`).
    pos: Vec<u32>,
    /// `bounds[c]..bounds[c + 1]`: the points of the last level's cell of
    /// key `c` (base cell, then Morton order).
    bounds: Vec<u32>,
    base: (usize, usize),
    /// Levels after the base lattice (the last level has `2^shift` times
    /// the base cells).
    shift: u32,
}

/// Interleaves the low `bits` bits of `a` (odd positions) and `b`.
fn morton(a: usize, b: usize, bits: u32) -> usize {
    let mut key = 0;
    for bit in (0..bits).rev() {
        key = (key << 2) | (((a >> bit) & 1) << 1) | ((b >> bit) & 1);
    }
    key
}

/// The inverse of [`morton`]: `(a, b)` of a key of `bits` bits each.
fn unmorton(key: usize, bits: u32) -> (usize, usize) {
    let (mut a, mut b) = (0, 0);
    for bit in (0..bits).rev() {
        a = (a << 1) | ((key >> (2 * bit + 1)) & 1);
        b = (b << 1) | ((key >> (2 * bit)) & 1);
    }
    (a, b)
}

/// The cell of lattice coordinate `x` on `cells` cells (as [`locate`],
/// whose floor is a library call without SSE4.1: the truncation of a
/// clamped, non-negative `x` is its floor).
#[inline]
fn cell(x: f64, cells: usize) -> usize {
    (x.clamp(0.0, cells as f64) as usize).min(cells - 1)
}

/// The points of one cell of a level: sorted positions and the cell.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    start: usize,
    end: usize,
    i: usize,
    j: usize,
}

impl Sorted {
    /// The unit coordinates of `points` in `frame` and the value sets
    /// `(z - z0, c)` ordered by the cell of the last level (`levels`
    /// levels on a `base` lattice), Morton order within each base cell (a
    /// counting sort). `c` is 1 for the fitted start (the constant run
    /// through the levels beside the heights) and 0 for the mean start
    /// (its levels are zero and its delta 0: the heights' levels alone).
    pub(super) fn new(
        points: &[Point3],
        frame: &Frame,
        base: (usize, usize),
        levels: usize,
        c: f64,
    ) -> Result<Self> {
        if u32::try_from(points.len()).is_err() {
            return Err(Error::InvalidInput(format!(
                "{} points are more than the in-memory level loop orders at once (2^32); read them in chunks (--chunk-points, or the level loop MbaLevels)",
                points.len()
            )));
        }
        let shift = (levels.max(1) - 1) as u32;
        let (m, n) = (base.0 << shift, base.1 << shift);
        let mask = (1usize << shift) - 1;
        let keys: Vec<u32> = points
            .par_iter()
            .map(|p| {
                let u = frame.unit(p);
                let (i, j) = (cell(u[0] * m as f64, m), cell(u[1] * n as f64, n));
                let b = (i >> shift) * base.1 + (j >> shift);
                ((b << (2 * shift)) | morton(i & mask, j & mask, shift)) as u32
            })
            .collect();
        let (bounds, index, pos) = counting_sort(keys, m * n);
        let (unit, values) = index
            .par_iter()
            .map(|&p| {
                let q = &points[p as usize];
                (frame.unit(q), [q.z - frame.z0, c])
            })
            .unzip();
        Ok(Self {
            unit,
            values,
            index,
            pos,
            bounds,
            base,
            shift,
        })
    }

    /// The non-empty cells of level `level` (at most the last) in sort
    /// order, with their points: ranges of the last level's cell bounds.
    fn runs(&self, level: u32) -> Vec<Run> {
        let d = self.shift - level;
        let per_base = 1usize << (2 * level);
        let cells = self.base.0 * self.base.1 * per_base;
        (0..cells)
            .filter_map(|c| {
                let (start, end) = (
                    self.bounds[c << (2 * d)] as usize,
                    self.bounds[(c + 1) << (2 * d)] as usize,
                );
                if start == end {
                    return None;
                }
                let (b, (a, bb)) = (c / per_base, unmorton(c % per_base, level));
                Some(Run {
                    start,
                    end,
                    i: ((b / self.base.1) << level) | a,
                    j: ((b % self.base.1) << level) | bb,
                })
            })
            .collect()
    }
}

/// Points per chunk of [`counting_sort`] (at least).
const SORT_CHUNK: usize = 1 << 16;

/// The stable counting sort of the points by `keys` (below `cells`):
/// `bounds[k]` the number of keys below `k` (`cells + 1` entries), `index`
/// the points in sorted order, `pos` the sorted position of each point.
/// In parallel over fixed chunks of the points (of at least `cells` points,
/// so the chunks' histograms take no more memory than the keys): each
/// chunk's histogram, the chunks' starts per key in chunk order, then each
/// chunk writes its points to their places, so the order is the serial
/// sort's for any thread count.
fn counting_sort(mut keys: Vec<u32>, cells: usize) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    use std::sync::atomic::{AtomicU32, Ordering::Relaxed};
    let n = keys.len();
    let chunk = SORT_CHUNK.max(cells).max(n.div_ceil(64)).max(1);
    let mut starts: Vec<Vec<u32>> = keys
        .par_chunks(chunk)
        .map(|ks| {
            let mut h = vec![0u32; cells];
            for &k in ks {
                h[k as usize] += 1;
            }
            h
        })
        .collect();
    let mut bounds = vec![0u32; cells + 1];
    let mut at = 0u32;
    for (k, b) in bounds.iter_mut().enumerate().take(cells) {
        *b = at;
        for h in starts.iter_mut() {
            let count = h[k];
            h[k] = at;
            at += count;
        }
    }
    bounds[cells] = at;
    // every place is written once, by the chunk whose point goes there
    let index: Vec<AtomicU32> = (0..n).into_par_iter().map(|_| AtomicU32::new(0)).collect();
    keys.par_chunks_mut(chunk)
        .zip(starts.par_iter_mut())
        .enumerate()
        .for_each(|(c, (ks, start))| {
            for (i, k) in ks.iter_mut().enumerate() {
                let a = &mut start[*k as usize];
                index[*a as usize].store((c * chunk + i) as u32, Relaxed);
                // the key's memory becomes the point's position
                *k = *a;
                *a += 1;
            }
        });
    let index = index.into_iter().map(AtomicU32::into_inner).collect();
    (bounds, index, keys)
}

/// Consecutive runs grouped into blocks of at least `points` points (the
/// last may have fewer): fixed by the data and the lattice, never by the
/// thread count.
fn blocks(runs: &[Run], points: usize) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut first = 0;
    for (r, run) in runs.iter().enumerate() {
        if run.end - runs[first].start >= points || r + 1 == runs.len() {
            out.push(first..r + 1);
            first = r + 1;
        }
    }
    out
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
    /// Numerators of `r` and `c` and the shared denominator over the box
    /// of control values from `(i0, j0)`, `rows x cols` (empty without a
    /// target): a block's runs are a compact piece of the lattice (Morton
    /// order), so its partial sums are small.
    num: [Vec<f64>; 2],
    den: Vec<f64>,
    i0: usize,
    j0: usize,
    cols: usize,
    /// `sum r^2, sum r c, sum c^2` after the update.
    quad: [f64; 3],
    /// `|r - delta c|` before the update (with the delta given).
    before: ResidualSums,
    /// Whether a value summed was not finite.
    bad: bool,
}

impl Measured {
    /// Zero sums over `rows x cols` control values from `(i0, j0)`.
    fn new(i0: usize, j0: usize, rows: usize, cols: usize) -> Self {
        let len = rows * cols;
        Self {
            num: [vec![0.0; len], vec![0.0; len]],
            den: vec![0.0; len],
            i0,
            j0,
            cols,
            quad: [0.0; 3],
            before: ResidualSums::default(),
            bad: false,
        }
    }

    /// Adds the block after this one's points (its box inside this one's).
    fn merge(&mut self, part: Self) {
        self.bad |= part.bad;
        if let Some(rows) = part.den.len().checked_div(part.cols) {
            for a in 0..rows {
                let at = (part.i0 - self.i0 + a) * self.cols + part.j0 - self.j0;
                let (to, from) = (at..at + part.cols, a * part.cols..(a + 1) * part.cols);
                for (t, p) in self
                    .num
                    .iter_mut()
                    .chain([&mut self.den])
                    .zip(part.num.iter().chain([&part.den]))
                {
                    t[to.clone()]
                        .iter_mut()
                        .zip(&p[from.clone()])
                        .for_each(|(x, y)| *x += y);
                }
            }
        }
        for (a, b) in self.quad.iter_mut().zip(part.quad) {
            *a += b;
        }
        self.before.merge(&part.before);
    }
}

/// The least-squares start `sum r c / sum c^2` and the RMSE it leaves.
fn fitted(quad: [f64; 3], count: usize) -> (f64, f64) {
    let sums = PassSums {
        count: count as u64,
        quad,
        ..Default::default()
    };
    (sums.start(), sums.start_rmse())
}

impl Sorted {
    /// `|r - delta c|` of every point in the input's order: after
    /// [`level_loop`], the residual `|z - f(x, y)|` of the final surface at
    /// each point, as the loop's last pass measured it (its last row).
    pub(super) fn residuals(&self, delta: f64) -> Vec<f64> {
        self.pos
            .par_iter()
            .map(|&a| {
                let v = self.values[a as usize];
                (v[0] - delta * v[1]).abs()
            })
            .collect()
    }

    /// The unit coordinates' memory (in cell order), for reuse.
    pub(super) fn into_unit(self) -> Vec<[f64; 2]> {
        self.unit
    }
}

/// The level loop over `sorted` (see the module documentation); `run` is
/// fresh. Returns the approximation and the start `delta` of its last row
/// (the final residuals are then [`Sorted::residuals`] of `delta`).
pub(super) fn level_loop(mut run: MbaLevels, sorted: &mut Sorted) -> Result<(Mba, f64)> {
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
        let m = pass(sorted, previous, target, before)?;
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
        // the constant's level (zero for the mean start, whose loop keeps
        // it here only)
        let one = ratio_lattice(t.m, t.n, &m.num[1], &m.den);
        ones.push(one.clone());
        run.push_lattices(ratio_lattice(t.m, t.n, &m.num[0], &m.den), Some(one))?;
    }
    // the fitted start of the last level (`MbaLevels::finish` applies it)
    // and the rows
    let last = deltas.last().copied().unwrap_or(0.0);
    run.deltas = deltas;
    for (rep, stats) in run.reports.iter_mut().zip(&rows) {
        rep.residual = *stats;
    }
    run.rows = rows.len();
    let mut r = run.finish();
    super::fused::pass_seconds(&mut r, &seconds);
    Ok((r, last))
}

/// What one pass does, besides the statistics: the level whose cells are
/// the runs (`rm x rn` cells), the levels subtracted (`previous`, refined
/// to the runs' level) and the level summed (`target`, of the runs' level).
#[derive(Clone, Copy)]
struct Plan<'a> {
    rm: f64,
    rn: f64,
    previous: Option<[&'a Lattice; 2]>,
    target: Option<Target>,
    delta: Option<f64>,
}

/// One pass over the sorted points in blocks of whole runs (fixed by the
/// point count and the lattice, never by the thread count; partial sums
/// merged in block order, so the result does not depend on the threads).
fn pass(
    sorted: &mut Sorted,
    previous: Option<[&Lattice; 2]>,
    target: Option<Target>,
    delta: Option<f64>,
) -> Result<Measured> {
    let len = target.map_or(0, |t| (t.m + 3) * (t.n + 3));
    let count = sorted.unit.len();
    // the runs are the cells of the finer of the two levels
    let level = match (target, previous) {
        (Some(t), _) => (t.m / sorted.base.0).trailing_zeros(),
        (None, Some(p)) => (p[0].m / sorted.base.0).trailing_zeros(),
        (None, None) => 0,
    };
    let runs = sorted.runs(level);
    // the level before refined to the level summed ([LWS97] section 5, the
    // same function): its values at a point take the basis values the sums
    // take, computed once
    let refined = match (previous, target) {
        (Some([z, c]), Some(_)) => Some([z.refine()?, c.refine()?]),
        _ => None,
    };
    let plan = Plan {
        rm: (sorted.base.0 << level) as f64,
        rn: (sorted.base.1 << level) as f64,
        previous: refined.as_ref().map(|[z, c]| [z, c]).or(previous),
        target,
        delta,
    };
    let block = BA_BLOCK.max(count.div_ceil(64));
    // at most 16 partials (and 256 MiB of them) at a time
    let wave = ((256usize << 20) / (24 * len.max(1))).clamp(1, 16);
    let blocks = blocks(&runs, block);
    let mut total = match target {
        Some(t) => Measured::new(0, 0, t.m + 3, t.n + 3),
        None => Measured::new(0, 0, 0, 0),
    };
    for group in blocks.chunks(wave) {
        let first = runs[group[0].start].start;
        let last = runs[group[group.len() - 1].end - 1].end;
        // the group's points cut into the blocks' slices
        let mut slices = Vec::with_capacity(group.len());
        let (mut unit, mut values) = (&sorted.unit[first..last], &mut sorted.values[first..last]);
        for b in group {
            let size = runs[b.end - 1].end - runs[b.start].start;
            let (u, ur) = unit.split_at(size);
            let (v, vr) = std::mem::take(&mut values).split_at_mut(size);
            slices.push((u, v, &runs[b.clone()]));
            (unit, values) = (ur, vr);
        }
        let parts: Vec<Measured> = slices
            .into_par_iter()
            .map(|(u, v, r)| match (previous.is_some(), target.is_some()) {
                (true, true) => block_pass::<true, true>(u, v, r, &plan),
                (true, false) => block_pass::<true, false>(u, v, r, &plan),
                (false, true) => block_pass::<false, true>(u, v, r, &plan),
                (false, false) => block_pass::<false, false>(u, v, r, &plan),
            })
            .collect();
        for p in parts {
            total.merge(p);
        }
    }
    if total.bad {
        let at = sorted
            .values
            .iter()
            .position(|v| !(v[0].is_finite() && v[1].is_finite()))
            .unwrap_or(0);
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

/// The uniform cubic B-spline basis at `L` local coordinates `s`
/// ([LWS97] eq. 2, as [`super::lattice::uniform_cubic_basis`] but
/// multiplying by 1/6 instead of dividing by 6), `[k][p]` for basis
/// function `k` at coordinate `p`.
#[inline(always)]
fn basis<const L: usize>(s: [f64; L]) -> [[f64; L]; 4] {
    const SIXTH: f64 = 1.0 / 6.0;
    let t = s.map(|s| 1.0 - s);
    let s2: [f64; L] = std::array::from_fn(|p| s[p] * s[p]);
    let s3: [f64; L] = std::array::from_fn(|p| s2[p] * s[p]);
    [
        std::array::from_fn(|p| t[p] * t[p] * t[p] * SIXTH),
        std::array::from_fn(|p| (3.0 * s3[p] - 6.0 * s2[p] + 4.0) * SIXTH),
        std::array::from_fn(|p| (-3.0 * s3[p] + 3.0 * s2[p] + 3.0 * s[p] + 1.0) * SIXTH),
        std::array::from_fn(|p| s3[p] * SIXTH),
    ]
}

/// What every point of a run shares.
struct RunContext {
    rm: f64,
    rn: f64,
    fi: f64,
    fj: f64,
    delta: Option<f64>,
    formula: ControlFormula,
    /// The 4 x 4 values of the level before (heights, constant).
    prev: [Block4; 2],
}

/// The per-block sums a step adds to, `L` lanes each.
struct Lanes<const L: usize> {
    quad: [[f64; L]; 3],
    finite: bool,
}

/// [`block_pass`]'s work on `L` points of one run at once (`L` = 2: every
/// operation on two points at a time, and one division for both).
#[inline(always)]
fn step<const L: usize, const PREV: bool, const SUM: bool>(
    c: &RunContext,
    u: &[[f64; 2]],
    v: &mut [[f64; 2]],
    before: &mut ResidualSums,
    lanes: &mut Lanes<L>,
    sums: &mut RunSums,
) {
    if let Some(d) = c.delta {
        for p in 0..L {
            before.push((v[p][0] - d * v[p][1]).abs());
        }
    }
    if !(PREV || SUM) {
        return;
    }
    let bs = basis::<L>(std::array::from_fn(|p| u[p][0] * c.rm - c.fi));
    let bt = basis::<L>(std::array::from_fn(|p| u[p][1] * c.rn - c.fj));
    if PREV {
        // eq. 1, columns first: az[l] = sum_k B_k(s) z_kl
        let (mut az, mut ac) = ([[0.0; L]; 4], [[0.0; L]; 4]);
        for k in 0..4 {
            for l in 0..4 {
                for p in 0..L {
                    az[l][p] += bs[k][p] * c.prev[0][k][l];
                    ac[l][p] += bs[k][p] * c.prev[1][k][l];
                }
            }
        }
        for p in 0..L {
            let (mut fz, mut fc) = (0.0, 0.0);
            for l in 0..4 {
                fz += az[l][p] * bt[l][p];
                fc += ac[l][p] * bt[l][p];
            }
            v[p][0] -= fz;
            v[p][1] -= fc;
            lanes.quad[0][p] += v[p][0] * v[p][0];
            lanes.quad[1][p] += v[p][0] * v[p][1];
            lanes.quad[2][p] += v[p][1] * v[p][1];
        }
    }
    if SUM {
        for p in 0..L {
            lanes.finite &= v[p][0].is_finite() & v[p][1].is_finite();
        }
        let s2 = bs.map(|b| b.map(|x| x * x));
        let t2 = bt.map(|b| b.map(|x| x * x));
        let (fs, ft, ds, dt) = match c.formula {
            ControlFormula::LeeWolbergShin => (
                std::array::from_fn::<_, 4, _>(|k| {
                    std::array::from_fn::<_, L, _>(|p| s2[k][p] * bs[k][p])
                }),
                std::array::from_fn::<_, 4, _>(|k| {
                    std::array::from_fn::<_, L, _>(|p| t2[k][p] * bt[k][p])
                }),
                s2,
                t2,
            ),
            ControlFormula::Hjelle => (s2, t2, bs, bt),
        };
        let inv: [f64; L] = std::array::from_fn(|p| {
            1.0 / ((s2[0][p] + s2[1][p] + s2[2][p] + s2[3][p])
                * (t2[0][p] + t2[1][p] + t2[2][p] + t2[3][p]))
        });
        let [nz, nc] = &mut sums.num;
        for p in 0..L {
            let q = [v[p][0] * inv[p], v[p][1] * inv[p]];
            for k in 0..4 {
                let (az, ac, d) = (q[0] * fs[k][p], q[1] * fs[k][p], ds[k][p]);
                for l in 0..4 {
                    nz[k][l] += az * ft[l][p];
                    nc[k][l] += ac * ft[l][p];
                    sums.den[k][l] += d * dt[l][p];
                }
            }
        }
    }
}

/// A run's BA sums, added to the block's lattice when the run ends.
struct RunSums {
    num: [Block4; 2],
    den: Block4,
}

impl RunSums {
    fn flush(&self, m: &mut Measured, i: usize, j: usize, st: usize) {
        for k in 0..4 {
            let row = (i + k) * st + j..(i + k) * st + j + 4;
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

/// [`pass`] over the runs of one block (`unit` and `values` the block's
/// points): `PREV` subtracts the previous levels, `SUM` sums the target.
fn block_pass<const PREV: bool, const SUM: bool>(
    unit: &[[f64; 2]],
    values: &mut [[f64; 2]],
    runs: &[Run],
    plan: &Plan,
) -> Measured {
    let mut out = match plan.target {
        Some(_) => {
            let (i0, i1) = runs
                .iter()
                .fold((usize::MAX, 0), |(a, b), r| (a.min(r.i), b.max(r.i)));
            let (j0, j1) = runs
                .iter()
                .fold((usize::MAX, 0), |(a, b), r| (a.min(r.j), b.max(r.j)));
            Measured::new(i0, j0, i1 - i0 + 4, j1 - j0 + 4)
        }
        None => Measured::new(0, 0, 0, 0),
    };
    let offset = runs.first().map_or(0, |r| r.start);
    let formula = plan
        .target
        .map_or(ControlFormula::LeeWolbergShin, |t| t.formula);
    let (mut two, mut one) = (
        Lanes::<2> {
            quad: [[0.0; 2]; 3],
            finite: true,
        },
        Lanes::<1> {
            quad: [[0.0; 1]; 3],
            finite: true,
        },
    );
    for r in runs {
        let zero = [[0.0; 4]; 4];
        let c = RunContext {
            rm: plan.rm,
            rn: plan.rn,
            fi: r.i as f64,
            fj: r.j as f64,
            delta: plan.delta,
            formula,
            prev: match plan.previous {
                Some(p) if PREV => [block4(p[0], r.i, r.j), block4(p[1], r.i, r.j)],
                _ => [zero, zero],
            },
        };
        let mut sums = RunSums {
            num: [zero; 2],
            den: zero,
        };
        let range = r.start - offset..r.end - offset;
        let (u, v) = (&unit[range.clone()], &mut values[range]);
        let mut pairs = u.chunks_exact(2).zip(v.chunks_exact_mut(2));
        for (u, v) in pairs.by_ref() {
            step::<2, PREV, SUM>(&c, u, v, &mut out.before, &mut two, &mut sums);
        }
        let (len, rest) = (u.len(), u.len() % 2);
        let (u, v) = (&u[len - rest..], &mut v[len - rest..]);
        if rest == 1 {
            step::<1, PREV, SUM>(&c, u, v, &mut out.before, &mut one, &mut sums);
        }
        if SUM {
            let (i, j, st) = (r.i - out.i0, r.j - out.j0, out.cols);
            sums.flush(&mut out, i, j, st);
        }
    }
    for (q, (a, b)) in out.quad.iter_mut().zip(two.quad.iter().zip(&one.quad)) {
        *q = a[0] + a[1] + b[0];
    }
    let finite = two.finite & one.finite;
    out.bad = !finite;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_keys_invert_and_runs_are_the_cells_of_each_level() {
        for bits in 0..6 {
            for a in 0..(1usize << bits) {
                for b in 0..(1usize << bits) {
                    assert_eq!(unmorton(morton(a, b, bits), bits), (a, b));
                }
            }
        }
        // points on a 3 x 2 base lattice, 4 levels: every run of every level
        // holds exactly the points of its cell, and the runs cover all points
        let n = 5000;
        let points: Vec<Point3> = (0..n)
            .map(|k| {
                let x = ((k * 7919) % 10007) as f64 / 10006.0;
                let y = ((k * 104_729) % 9973) as f64 / 9972.0;
                Point3::new(x, y, x * y)
            })
            .collect();
        let s = Sorted::new(&points, &Frame::of(&points).unwrap(), (3, 2), 4, 1.0).unwrap();
        for level in 0..4u32 {
            let (m, n_) = (3usize << level, 2usize << level);
            let runs = s.runs(level);
            assert_eq!(runs[0].start, 0);
            assert_eq!(runs.last().unwrap().end, n);
            for w in runs.windows(2) {
                assert_eq!(w[0].end, w[1].start);
            }
            let mut seen = std::collections::HashSet::new();
            for r in &runs {
                assert!(seen.insert((r.i, r.j)), "cell twice at level {level}");
                for u in &s.unit[r.start..r.end] {
                    let (x, y) = (u[0] * m as f64, u[1] * n_ as f64);
                    assert_eq!((cell(x, m), cell(y, n_)), (r.i, r.j));
                    let (lx, ly) = (
                        super::super::lattice::locate(x.clamp(0.0, m as f64), m).0,
                        super::super::lattice::locate(y.clamp(0.0, n_ as f64), n_).0,
                    );
                    assert_eq!((lx, ly), (r.i, r.j));
                }
            }
        }
        // blocks are whole runs with at least the points asked (but the last)
        let runs = s.runs(3);
        let b = blocks(&runs, 700);
        assert_eq!(b[0].start, 0);
        assert_eq!(b.last().unwrap().end, runs.len());
        for w in b.windows(2) {
            assert_eq!(w[0].end, w[1].start);
            assert!(runs[w[0].end - 1].end - runs[w[0].start].start >= 700);
        }
    }

    #[test]
    fn the_parallel_counting_sort_is_the_stable_serial_one() {
        // keys of 300 cells over 500 000 points (8 chunks), some cells empty
        let keys: Vec<u32> = (0..500_000u64)
            .map(|i| ((i * 2_654_435_761) % 997 % 300) as u32)
            .collect();
        let mut order: Vec<u32> = (0..keys.len() as u32).collect();
        order.sort_by_key(|&p| keys[p as usize]);
        let (bounds, index, pos) = counting_sort(keys.clone(), 300);
        assert_eq!(index, order);
        for (a, &p) in index.iter().enumerate() {
            assert_eq!(pos[p as usize] as usize, a);
        }
        for k in 0..300 {
            let below = keys.iter().filter(|&&x| (x as usize) < k).count();
            assert_eq!(bounds[k] as usize, below);
        }
        assert_eq!(bounds[300] as usize, keys.len());
    }

    #[test]
    fn the_basis_is_the_lattice_basis() {
        for k in 0..=64 {
            let s = k as f64 / 64.0;
            let (a, b) = (
                basis([s]).map(|x| x[0]),
                super::super::lattice::uniform_cubic_basis(s),
            );
            for (x, y) in a.iter().zip(b) {
                assert!((x - y).abs() <= 1e-16, "{s}: {a:?} {b:?}");
            }
        }
    }
}
