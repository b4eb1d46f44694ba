//! Knots from the parameter distribution ([NURBS97] eq. 9.69) for points
//! whose parameters arrive in chunks (a streamed or distributed fit), with
//! the knots of [`super::surface::distribution_knots`] exactly.
//!
//! Eq. 9.69 needs a few order statistics of the parameters (the values of
//! ranks `i - 1` and `i` per interior knot, [`eq_9_69_ranks`]), not all of
//! them sorted. [`RankSearch`] finds any set of ranks exactly in rounds
//! over the chunks: each round broadcasts a [`RankQuery`] (per wanted rank
//! a window of values known to hold it), every chunk returns
//! [`RankCounts`] (per window the count, smallest and largest value in
//! each of up to [`MAX_BINS`] equal bins, or the values themselves once a
//! window holds at most [`COLLECT_LIMIT`]), merged by adding counts; the
//! client narrows each window to the bin that holds its rank. A bin's new
//! window is its own smallest and largest value, so equal values end a
//! search at once. Rounds, for evenly spread values: 2 up to about 1.7 x
//! 10^7 values (4096 bins of at most 4096), 3 up to about 7 x 10^10;
//! clustered values may take more (each round narrows every window).
//! [`KnotSearch`] asks for the ranks of a surface fit's `u` and `v` knots
//! and builds its normal equations.

use super::surface::{
    distribution_applies, knots_from_interior, NormalEquations, SurfaceFitConfig,
};
use crate::bspline::KnotVector;
use crate::param::knots::{eq_9_69_knot, eq_9_69_ranks};
use crate::wire::{Reader, Writer};
use crate::{Error, Result};

/// Most bins of a window per round.
pub const MAX_BINS: usize = 4096;
/// A window holding at most this many values is collected (the values
/// themselves are returned) instead of binned.
pub const COLLECT_LIMIT: u64 = 4096;
/// Values per bin a window's bin count aims at.
const PER_BIN: u64 = 256;

/// The state of one wanted rank: the window `[lo, hi]` known to hold it,
/// the number of values below the window and in it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Target {
    rank: u64,
    lo: f64,
    hi: f64,
    below: u64,
    count: u64,
    value: Option<f64>,
}

/// Exact order statistics of values (per column) spread over chunks; see
/// the module documentation.
///
/// ```
/// use scanfit::fit::knot_ranks::RankSearch;
/// let values: Vec<f64> = (0..100_000).map(|k| ((k * 7919) % 100_000) as f64 / 1e5).collect();
/// let mut s = RankSearch::new(values.len() as u64, vec![vec![0, 4_999, 99_999]], (0.0, 1.0))?;
/// while !s.done() {
///     let q = s.query();
///     let (mut a, mut b) = (q.counts(), q.counts());
///     a.add(&q, 0, values[..30_000].iter().copied());
///     b.add(&q, 0, values[30_000..].iter().copied());
///     a.merge(&b)?;
///     s.push(&a)?;
/// }
/// assert_eq!(s.value(0, 4_999), Some(0.04999));
/// assert_eq!(s.value(0, 99_999), Some(0.99999));
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RankSearch {
    targets: Vec<Vec<Target>>,
    rounds: usize,
}

impl RankSearch {
    /// A search for `ranks[c]` (0-based) among `len` values per column `c`,
    /// all within `range` (values outside are an error when found missing).
    pub fn new(len: u64, ranks: Vec<Vec<u64>>, range: (f64, f64)) -> Result<Self> {
        let (lo, hi) = range;
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(Error::InvalidInput(format!(
                "the range [{lo}, {hi}] of a rank search is not one"
            )));
        }
        let targets = ranks
            .into_iter()
            .map(|mut r| {
                r.sort_unstable();
                r.dedup();
                r.into_iter()
                    .map(|rank| {
                        if rank >= len {
                            return Err(Error::InvalidInput(format!(
                                "rank {rank} asked of {len} values"
                            )));
                        }
                        Ok(Target {
                            rank,
                            lo,
                            hi,
                            below: 0,
                            count: len,
                            value: (lo == hi).then_some(lo),
                        })
                    })
                    .collect::<Result<Vec<_>>>()
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { targets, rounds: 0 })
    }

    /// Whether every rank is found.
    pub fn done(&self) -> bool {
        self.targets.iter().flatten().all(|t| t.value.is_some())
    }

    /// Rounds pushed so far.
    pub fn rounds(&self) -> usize {
        self.rounds
    }

    /// The value of rank `rank` in column `column`, once found.
    pub fn value(&self, column: usize, rank: u64) -> Option<f64> {
        let t = self.targets.get(column)?;
        let k = t.binary_search_by_key(&rank, |t| t.rank).ok()?;
        t[k].value
    }

    /// What the chunks count next: per column the distinct windows of the
    /// ranks not found yet, sorted and disjoint.
    pub fn query(&self) -> RankQuery {
        let columns = self
            .targets
            .iter()
            .map(|ts| {
                let mut w: Vec<Window> = ts
                    .iter()
                    .filter(|t| t.value.is_none())
                    .map(|t| Window {
                        lo: t.lo,
                        hi: t.hi,
                        bins: if t.count <= COLLECT_LIMIT {
                            0
                        } else {
                            t.count.div_ceil(PER_BIN).clamp(2, MAX_BINS as u64) as usize
                        },
                    })
                    .collect();
                w.sort_by(|a, b| a.lo.total_cmp(&b.lo));
                w.dedup_by(|a, b| a.lo == b.lo && a.hi == b.hi);
                w
            })
            .collect();
        RankQuery { columns }
    }

    /// Narrows every window by the merged counts of all chunks for
    /// [`query`](Self::query); errors when the counts miss values (a chunk
    /// left out, or values outside the range).
    pub fn push(&mut self, counts: &RankCounts) -> Result<()> {
        let q = self.query();
        if counts.columns.len() != q.columns.len()
            || counts
                .columns
                .iter()
                .zip(&q.columns)
                .any(|(c, w)| c.len() != w.len())
        {
            return Err(Error::InvalidInput(
                "rank counts of another query: count every chunk with the current query".into(),
            ));
        }
        for (c, ts) in self.targets.iter_mut().enumerate() {
            for t in ts.iter_mut().filter(|t| t.value.is_none()) {
                let k = q.columns[c]
                    .iter()
                    .position(|w| w.lo == t.lo && w.hi == t.hi)
                    .ok_or_else(|| Error::InvalidInput("a rank's window is missing".into()))?;
                narrow(t, &counts.columns[c][k])?;
            }
        }
        self.rounds += 1;
        Ok(())
    }
}

/// Moves `t` into the part of its window that holds its rank.
fn narrow(t: &mut Target, counts: &WindowCounts) -> Result<()> {
    let lost = |have: u64| {
        Error::InvalidInput(format!(
            "the counted values miss rank {}: {have} values in its window, {} expected; every chunk must be counted once, with values inside the search's range (parameters in [0, 1])",
            t.rank, t.count
        ))
    };
    let mut at = t.rank - t.below;
    match counts {
        WindowCounts::Values(v) => {
            if v.len() as u64 != t.count {
                return Err(lost(v.len() as u64));
            }
            let mut v = v.clone();
            v.sort_by(f64::total_cmp);
            t.value = Some(v[at as usize]);
        }
        WindowCounts::Bins { count, min, max } => {
            let total: u64 = count.iter().sum();
            if total != t.count {
                return Err(lost(total));
            }
            for b in 0..count.len() {
                if at < count[b] {
                    t.lo = min[b];
                    t.hi = max[b];
                    t.count = count[b];
                    if t.lo == t.hi {
                        t.value = Some(t.lo);
                    }
                    return Ok(());
                }
                at -= count[b];
                t.below += count[b];
            }
            return Err(lost(total));
        }
    }
    Ok(())
}

/// One window of a [`RankQuery`]: values in `[lo, hi]`, counted in `bins`
/// equal bins (0: collected).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Window {
    lo: f64,
    hi: f64,
    bins: usize,
}

impl Window {
    /// The bin of `x` (inside the window).
    #[inline]
    fn bin(&self, x: f64) -> usize {
        let w = self.hi - self.lo;
        if w > 0.0 {
            (((x - self.lo) / w * self.bins as f64) as usize).min(self.bins - 1)
        } else {
            0
        }
    }
}

/// What every chunk counts in one round of a [`RankSearch`] (broadcast).
#[derive(Debug, Clone, PartialEq)]
pub struct RankQuery {
    columns: Vec<Vec<Window>>,
}

const QUERY_TAG: &[u8; 8] = b"SFRANKQ1";
const COUNTS_TAG: &[u8; 8] = b"SFRANKC1";

impl RankQuery {
    /// Empty counts for this query.
    pub fn counts(&self) -> RankCounts {
        let columns = self
            .columns
            .iter()
            .map(|ws| {
                ws.iter()
                    .map(|w| {
                        if w.bins == 0 {
                            WindowCounts::Values(Vec::new())
                        } else {
                            WindowCounts::Bins {
                                count: vec![0; w.bins],
                                min: vec![f64::INFINITY; w.bins],
                                max: vec![f64::NEG_INFINITY; w.bins],
                            }
                        }
                    })
                    .collect()
            })
            .collect();
        RankCounts { columns }
    }

    /// Columns of the search.
    pub fn columns(&self) -> usize {
        self.columns.len()
    }

    /// The query as exact bytes ([`crate::wire`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(QUERY_TAG);
        w.usize(self.columns.len());
        for ws in &self.columns {
            w.usize(ws.len());
            for x in ws {
                w.f64(x.lo);
                w.f64(x.hi);
                w.usize(x.bins);
            }
        }
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, QUERY_TAG, "a rank query")?;
        let n = r.usize()?;
        let mut columns = Vec::new();
        for _ in 0..n {
            let m = r.usize()?;
            let mut ws = Vec::new();
            for _ in 0..m {
                let (lo, hi, bins) = (r.f64()?, r.f64()?, r.usize()?);
                if bins > MAX_BINS || lo.is_nan() || hi.is_nan() || lo > hi {
                    return Err(r.corrupt("a window"));
                }
                ws.push(Window { lo, hi, bins });
            }
            columns.push(ws);
        }
        r.end()?;
        Ok(Self { columns })
    }
}

/// The counts of one window (see [`RankCounts`]).
#[derive(Debug, Clone, PartialEq)]
enum WindowCounts {
    Bins {
        count: Vec<u64>,
        min: Vec<f64>,
        max: Vec<f64>,
    },
    Values(Vec<f64>),
}

impl WindowCounts {
    /// Counts `x`, a value inside the window `w`.
    #[inline]
    fn add(&mut self, w: &Window, x: f64) {
        match self {
            WindowCounts::Values(v) => v.push(x),
            WindowCounts::Bins { count, min, max } => {
                let b = w.bin(x);
                count[b] += 1;
                min[b] = min[b].min(x);
                max[b] = max[b].max(x);
            }
        }
    }
}

/// The counts of some chunks for a [`RankQuery`]: mergeable, exact.
#[derive(Debug, Clone, PartialEq)]
pub struct RankCounts {
    columns: Vec<Vec<WindowCounts>>,
}

impl RankCounts {
    /// Counts the values of column `column` of a chunk (the query these
    /// counts were made for).
    pub fn add(&mut self, query: &RankQuery, column: usize, values: impl Iterator<Item = f64>) {
        let (Some(ws), Some(cs)) = (query.columns.get(column), self.columns.get_mut(column)) else {
            return;
        };
        if let ([w], [c]) = (ws.as_slice(), cs.as_mut_slice()) {
            // one window (every rank in the first round): no search per value
            for x in values.filter(|&x| w.lo <= x && x <= w.hi) {
                c.add(w, x);
            }
            return;
        }
        for x in values {
            // the last window starting at or below x (windows are disjoint)
            let k = ws.partition_point(|w| w.lo <= x);
            if k == 0 || x > ws[k - 1].hi {
                continue;
            }
            cs[k - 1].add(&ws[k - 1], x);
        }
    }

    /// Adds the counts of other chunks (the same query).
    pub fn merge(&mut self, other: &Self) -> Result<()> {
        let mismatch =
            || Error::InvalidInput("cannot merge rank counts of different queries".into());
        if self.columns.len() != other.columns.len() {
            return Err(mismatch());
        }
        for (a, b) in self.columns.iter_mut().zip(&other.columns) {
            if a.len() != b.len() {
                return Err(mismatch());
            }
            for (x, y) in a.iter_mut().zip(b) {
                match (x, y) {
                    (WindowCounts::Values(v), WindowCounts::Values(w)) => v.extend_from_slice(w),
                    (
                        WindowCounts::Bins { count, min, max },
                        WindowCounts::Bins {
                            count: c2,
                            min: n2,
                            max: x2,
                        },
                    ) if count.len() == c2.len() => {
                        for b in 0..count.len() {
                            count[b] += c2[b];
                            min[b] = min[b].min(n2[b]);
                            max[b] = max[b].max(x2[b]);
                        }
                    }
                    _ => return Err(mismatch()),
                }
            }
        }
        Ok(())
    }

    /// Bytes of the counts (what a chunk returns).
    pub fn bytes(&self) -> usize {
        self.columns
            .iter()
            .flatten()
            .map(|c| match c {
                WindowCounts::Values(v) => 8 * v.len(),
                WindowCounts::Bins { count, .. } => 24 * count.len(),
            })
            .sum()
    }

    /// The counts as exact bytes ([`crate::wire`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(COUNTS_TAG);
        w.usize(self.columns.len());
        for cs in &self.columns {
            w.usize(cs.len());
            for c in cs {
                match c {
                    WindowCounts::Values(v) => {
                        w.u64(0);
                        w.f64s(v);
                    }
                    WindowCounts::Bins { count, min, max } => {
                        w.u64(1);
                        w.usize(count.len());
                        for &n in count {
                            w.u64(n);
                        }
                        w.f64s(min);
                        w.f64s(max);
                    }
                }
            }
        }
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, COUNTS_TAG, "rank counts")?;
        let n = r.usize()?;
        let mut columns = Vec::new();
        for _ in 0..n {
            let m = r.usize()?;
            let mut cs = Vec::new();
            for _ in 0..m {
                cs.push(match r.u64()? {
                    0 => WindowCounts::Values(r.f64s()?),
                    1 => {
                        let len = r.usize()?;
                        if len > MAX_BINS {
                            return Err(r.corrupt("a window's bins"));
                        }
                        let count = (0..len).map(|_| r.u64()).collect::<Result<Vec<_>>>()?;
                        let (min, max) = (r.f64s()?, r.f64s()?);
                        if min.len() != len || max.len() != len {
                            return Err(r.corrupt("a window's bins"));
                        }
                        WindowCounts::Bins { count, min, max }
                    }
                    x => return Err(r.corrupt(&format!("window kind {x}"))),
                });
            }
            columns.push(cs);
        }
        r.end()?;
        Ok(Self { columns })
    }
}

/// The knot placement of one direction of a [`KnotSearch`]: degree,
/// control count, and eq. 9.69's `(i, alpha)` per interior knot (`None`:
/// uniform knots).
#[derive(Debug, Clone, PartialEq)]
struct Direction {
    degree: usize,
    count: usize,
    ranks: Option<Vec<(usize, f64)>>,
}

/// The `u` and `v` knots of [`fit_surface`](super::surface::fit_surface)
/// with [`KnotPlacement::Distribution`](super::surface::KnotPlacement) for
/// `len` points whose parameters arrive in chunks: the order statistics
/// of eq. 9.69 found by a [`RankSearch`] (parameters in `[0, 1]`), then the
/// normal equations with those knots.
///
/// ```
/// use scanfit::fit::knot_ranks::KnotSearch;
/// use scanfit::fit::surface::{distribution_knots, SurfaceFitConfig};
/// let uv: Vec<[f64; 2]> = (0..20_000)
///     .map(|k| { let t = (k as f64 * 0.618034) % 1.0; [t * t, (k as f64 / 20_000.0).sqrt()] })
///     .collect();
/// let cfg = SurfaceFitConfig { ctrl: (12, 9), ..Default::default() };
/// let mut s = KnotSearch::new(uv.len(), &cfg)?;
/// while !s.done() {
///     let q = s.query();
///     let mut c = q.counts();
///     for part in uv.chunks(6_000) {
///         let mut d = q.counts();
///         KnotSearch::add(&q, &mut d, part);
///         c.merge(&d)?;
///     }
///     s.push(&c)?;
/// }
/// let (ku, kv) = s.knots()?;
/// assert_eq!(ku, distribution_knots(uv.iter().map(|t| t[0]), 3, 12)?);
/// assert_eq!(kv, distribution_knots(uv.iter().map(|t| t[1]), 3, 9)?);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct KnotSearch {
    directions: [Direction; 2],
    search: RankSearch,
    periodic_u: bool,
}

impl KnotSearch {
    /// The search for `len` points fitted with `cfg` (its degrees, net and
    /// periodicity; a periodic `u` has uniform knots).
    pub fn new(len: usize, cfg: &SurfaceFitConfig) -> Result<Self> {
        let direction = |degree: usize, count: usize, uniform: bool| Direction {
            degree,
            count,
            ranks: (!uniform && distribution_applies(len, degree, count))
                .then(|| eq_9_69_ranks(len, degree, count)),
        };
        let directions = [
            direction(cfg.degree.0, cfg.ctrl.0, cfg.periodic_u),
            direction(cfg.degree.1, cfg.ctrl.1, false),
        ];
        let ranks = directions
            .iter()
            .map(|d| {
                d.ranks
                    .iter()
                    .flatten()
                    .flat_map(|&(i, _)| [i as u64 - 1, i as u64])
                    .collect()
            })
            .collect();
        Ok(Self {
            directions,
            search: RankSearch::new(len as u64, ranks, (0.0, 1.0))?,
            periodic_u: cfg.periodic_u,
        })
    }

    /// Whether the knots are known.
    pub fn done(&self) -> bool {
        self.search.done()
    }

    /// Rounds over the points so far.
    pub fn rounds(&self) -> usize {
        self.search.rounds()
    }

    /// The next round's query (broadcast to the chunks).
    pub fn query(&self) -> RankQuery {
        self.search.query()
    }

    /// Counts a chunk's parameters for `query` into `counts`.
    pub fn add(query: &RankQuery, counts: &mut RankCounts, uv: &[[f64; 2]]) {
        counts.add(query, 0, uv.iter().map(|t| t[0]));
        counts.add(query, 1, uv.iter().map(|t| t[1]));
    }

    /// Takes the merged counts of all chunks for the current query.
    pub fn push(&mut self, counts: &RankCounts) -> Result<()> {
        self.search.push(counts)
    }

    /// The knot vectors `(u, v)` once [`done`](Self::done).
    pub fn knots(&self) -> Result<(KnotVector, KnotVector)> {
        let knots = |c: usize| -> Result<KnotVector> {
            let d = &self.directions[c];
            let Some(ranks) = &d.ranks else {
                return if c == 0 && self.periodic_u {
                    KnotVector::uniform_periodic(d.degree, d.count)
                } else {
                    KnotVector::uniform_clamped(d.degree, d.count)
                };
            };
            let at = |r: usize| {
                self.search.value(c, r as u64).ok_or_else(|| {
                    Error::InvalidInput("the knot search is not done: push more rounds".into())
                })
            };
            let interior = ranks
                .iter()
                .map(|&(i, alpha)| Ok(eq_9_69_knot(at(i - 1)?, at(i)?, alpha)))
                .collect::<Result<Vec<f64>>>()?;
            knots_from_interior(interior, d.degree)
        };
        Ok((knots(0)?, knots(1)?))
    }

    /// Empty normal equations of `cfg` with these knots.
    pub fn equations(&self, cfg: &SurfaceFitConfig) -> Result<NormalEquations> {
        let (ku, kv) = self.knots()?;
        cfg.equations_with(ku, kv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A search run over `values` split into chunks of `chunk`.
    fn search(values: &[f64], ranks: Vec<u64>, chunk: usize) -> RankSearch {
        let mut s = RankSearch::new(values.len() as u64, vec![ranks], (0.0, 1.0)).unwrap();
        while !s.done() {
            let q = s.query();
            let mut total = q.counts();
            for part in values.chunks(chunk) {
                let mut c = RankCounts::from_bytes(&q.counts().to_bytes()).unwrap();
                c.add(&q, 0, part.iter().copied());
                total
                    .merge(&RankCounts::from_bytes(&c.to_bytes()).unwrap())
                    .unwrap();
            }
            s.push(&total).unwrap();
            assert!(s.rounds() < 10);
        }
        s
    }

    #[test]
    fn ranks_are_the_sorted_values_with_ties_and_clusters() {
        // a cluster of 300k values within 1e-9, ties, and the ends
        let mut v: Vec<f64> = (0..300_000).map(|k| 0.5 + k as f64 * 3e-15).collect();
        v.extend((0..50_000).map(|k| (k % 7) as f64 / 7.0));
        v.extend([0.0, 1.0, 1.0]);
        let mut sorted = v.clone();
        sorted.sort_by(f64::total_cmp);
        let ranks: Vec<u64> = vec![0, 1, 7_142, 7_143, 49_999, 150_000, 300_001, 350_002];
        let s = search(&v, ranks.clone(), 33_333);
        for r in ranks {
            assert_eq!(s.value(0, r), Some(sorted[r as usize]), "rank {r}");
        }
        assert!(s.rounds() <= 4, "{} rounds", s.rounds());
    }

    #[test]
    fn missing_values_and_other_queries_are_errors() {
        let v: Vec<f64> = (0..10_000).map(|k| k as f64 / 10_000.0).collect();
        let mut s = RankSearch::new(10_001, vec![vec![5_000]], (0.0, 1.0)).unwrap();
        let q = s.query();
        let mut c = q.counts();
        c.add(&q, 0, v.iter().copied());
        let e = s.push(&c).unwrap_err();
        assert!(e.to_string().contains("miss rank 5000"), "{e}");
        let other = RankSearch::new(10, vec![vec![1], vec![2]], (0.0, 1.0)).unwrap();
        assert!(s.push(&other.query().counts()).is_err());
        assert!(c.merge(&other.query().counts()).is_err());
        assert!(RankSearch::new(10, vec![vec![10]], (0.0, 1.0)).is_err());
        assert!(RankCounts::from_bytes(&q.to_bytes()).is_err());
        assert_eq!(RankQuery::from_bytes(&q.to_bytes()).unwrap(), q);
    }
}
