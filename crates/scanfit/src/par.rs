//! Explicit, deterministic parallelism.
//!
//! * The thread-count knob: [`Threads`] and [`with_threads`] run a closure in
//!   a scoped rayon pool of that many threads, so every parallel loop of the
//!   library inside it (they all run on the current rayon pool) uses them. No
//!   global state is changed: two calls with different counts may run side by
//!   side.
//! * The one parallel-accumulation helper, [`accumulate`]: every sum over
//!   points that builds normal equations or a lattice (the surface least
//!   squares, [`crate::fit::surface`]; the MBA lattice, [LWS97] eq. 4 in
//!   [`crate::mba::lattice`]; the PDE Gram blocks, [PDE23] eq. 13 in
//!   [`crate::pde`]) goes through it. The items are cut into chunks of a size
//!   the caller fixes from the data (never from the thread count); each chunk
//!   is summed into its own partial accumulator (in parallel) and the partials
//!   are merged into the total strictly in chunk order. The floating-point
//!   operations and their order are therefore the same for 1, 2 or 64
//!   threads, and the result is bit-identical.
//!
//! Keys in brackets are those of `docs/references.md`.

use std::num::NonZeroUsize;
use std::ops::Range;

use rayon::prelude::*;

use crate::{Error, Result};

/// How many threads the library's parallel loops may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Threads {
    /// Whatever the current rayon pool has (by default one per core, or
    /// `RAYON_NUM_THREADS`).
    #[default]
    Auto,
    /// Exactly this many.
    Fixed(NonZeroUsize),
}

impl Threads {
    /// `0` means [`Threads::Auto`], anything else that many threads.
    ///
    /// ```
    /// use scanfit::par::Threads;
    /// assert_eq!(Threads::from_count(0), Threads::Auto);
    /// assert_eq!(Threads::from_count(2).count(), Some(2));
    /// ```
    pub fn from_count(n: usize) -> Self {
        NonZeroUsize::new(n).map_or(Self::Auto, Self::Fixed)
    }

    /// The fixed count, or `None` for [`Threads::Auto`].
    pub fn count(self) -> Option<usize> {
        match self {
            Self::Auto => None,
            Self::Fixed(n) => Some(n.get()),
        }
    }
}

/// Runs `f` with the library's parallel loops on `threads` threads (a scoped
/// rayon pool that ends with the call); [`Threads::Auto`] runs `f` on the
/// current pool. The results of the library do not depend on the count (see
/// the module documentation); only the wall time does.
///
/// ```
/// use scanfit::par::{accumulate, with_threads, Threads};
/// let harmonic = |threads| {
///     with_threads(Threads::from_count(threads), || {
///         accumulate(
///             10_000,
///             100,
///             || 0.0,
///             |s: &mut f64, r| *s += r.map(|i| 1.0 / (1.0 + i as f64)).sum::<f64>(),
///             |s, p| *s += p,
///         )
///     })
/// };
/// let (one, two) = (harmonic(1).unwrap(), harmonic(2).unwrap());
/// assert_eq!(one.to_bits(), two.to_bits());
/// ```
pub fn with_threads<R: Send>(threads: Threads, f: impl FnOnce() -> R + Send) -> Result<R> {
    match threads {
        Threads::Auto => Ok(f()),
        Threads::Fixed(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n.get())
                .build()
                .map_err(|e| {
                    Error::InvalidInput(format!(
                        "could not start a pool of {n} threads ({e}); ask for fewer threads"
                    ))
                })?;
            Ok(pool.install(f))
        }
    }
}

/// Chunks summed in parallel before their partials are merged (bounds the
/// memory to this many partial accumulators; a constant, so the merge order
/// does not depend on the thread count).
const WAVE: usize = 16;

/// Deterministic parallel accumulation over the items `0..len`.
///
/// The items are cut into chunks of `chunk` (the last one shorter); each
/// chunk's partial starts as `init()` and `fold(&mut partial, range)` adds the
/// items of `range` to it (in parallel across chunks); then
/// `merge(&mut total, partial)` adds the partials to `total = init()` one by
/// one in chunk order. Choose `chunk` from the data (the item count, the
/// accumulator's size), never from the number of threads: the result is then
/// bit-identical for every thread count. At most 16 partials exist at a time.
///
/// ```
/// use scanfit::par::accumulate;
/// let x: Vec<f64> = (0..1000).map(|i| (i as f64).sqrt()).collect();
/// // sum and sum of squares at once
/// let (s, s2) = accumulate(
///     x.len(),
///     64,
///     || (0.0, 0.0),
///     |acc: &mut (f64, f64), r| {
///         for v in &x[r] {
///             acc.0 += v;
///             acc.1 += v * v;
///         }
///     },
///     |acc, p| {
///         acc.0 += p.0;
///         acc.1 += p.1;
///     },
/// );
/// assert!((s2 - 499_500.0).abs() < 1e-9);
/// assert!(s > 21_000.0 && s < 21_100.0);
/// ```
pub fn accumulate<A: Send>(
    len: usize,
    chunk: usize,
    init: impl Fn() -> A + Sync,
    fold: impl Fn(&mut A, Range<usize>) + Sync,
    merge: impl FnMut(&mut A, A),
) -> A {
    accumulate_bounded(len, chunk, WAVE, init, fold, merge)
}

/// [`accumulate`] with at most `max_partials` (at least 1) partial
/// accumulators alive at a time, for accumulators so large that 16 of them
/// would not fit in memory. Choose it from the accumulator's size, never from
/// the thread count (it bounds the parallelism, not the result: the result is
/// the same for every `max_partials` too, since partials are merged in chunk
/// order in every case).
///
/// ```
/// use scanfit::par::accumulate_bounded;
/// let n = accumulate_bounded(100, 7, 2, || 0usize, |a, r| *a += r.len(), |a, p| *a += p);
/// assert_eq!(n, 100);
/// ```
pub fn accumulate_bounded<A: Send>(
    len: usize,
    chunk: usize,
    max_partials: usize,
    init: impl Fn() -> A + Sync,
    fold: impl Fn(&mut A, Range<usize>) + Sync,
    mut merge: impl FnMut(&mut A, A),
) -> A {
    let mut total = init();
    accumulate_into(
        &mut total,
        0..len,
        chunk,
        max_partials,
        init,
        fold,
        &mut merge,
    );
    total
}

/// The core of [`accumulate_bounded`]: the chunks of `items` (cut from
/// `items.start`) summed in parallel and merged into `total` in chunk order.
fn accumulate_into<A: Send>(
    total: &mut A,
    items: Range<usize>,
    chunk: usize,
    max_partials: usize,
    init: impl Fn() -> A + Sync,
    fold: impl Fn(&mut A, Range<usize>) + Sync,
    merge: &mut impl FnMut(&mut A, A),
) {
    let chunk = chunk.max(1);
    let wave = max_partials.max(1);
    let (start, len) = (items.start, items.len());
    let chunks = len.div_ceil(chunk);
    let range = |c: usize| start + c * chunk..start + ((c + 1) * chunk).min(len);
    for first in (0..chunks).step_by(wave) {
        let partials: Vec<A> = (first..(first + wave).min(chunks))
            .into_par_iter()
            .map(|c| {
                let mut a = init();
                fold(&mut a, range(c));
                a
            })
            .collect();
        for p in partials {
            merge(total, p);
        }
    }
}

/// A streamed [`accumulate`]: items arrive in batches of any size
/// ([`BlockSum::add`]), and the sum is the one [`accumulate`] gives over all
/// of them at once with `chunk = block`, **bit for bit**, however the items
/// were cut into batches. The items are cut into blocks of `block` counted
/// from the first item ever added (not from each batch): complete blocks are
/// summed in parallel and merged into the total in order, and the partial
/// block at the end of a batch stays open and continues with the next batch.
///
/// Two sums over different items merge ([`BlockSum::merge`], for chunks
/// summed on different machines); a merged sum equals the one-pass sum up to
/// the rounding of the additions (floating-point addition is not
/// associative), not bit for bit.
///
/// ```
/// use scanfit::par::{accumulate, BlockSum};
/// let x: Vec<f64> = (0..10_000).map(|i| 1.0 / (1.0 + i as f64)).collect();
/// let sum = |a: &mut f64, r: std::ops::Range<usize>| *a += x[r].iter().sum::<f64>();
/// let once = accumulate(x.len(), 64, || 0.0, |a, r| sum(a, r), |a, p| *a += p);
/// // the same items in batches of 1000, 333 and the rest
/// let mut s = BlockSum::new(0.0, 64);
/// let mut at = 0;
/// for len in [1000, 333, 10_000 - 1333] {
///     s.add(len, 4, || 0.0, |a, r| sum(a, at + r.start..at + r.end), |a, p| *a += p);
///     at += len;
/// }
/// assert_eq!(s.finish(|a, p| *a += p).to_bits(), once.to_bits());
/// ```
#[derive(Debug, Clone)]
pub struct BlockSum<A> {
    total: A,
    open: Option<A>,
    open_len: usize,
    block: usize,
    items: u64,
}

impl<A: Send> BlockSum<A> {
    /// An empty sum (`total` is the zero of the accumulator) cutting the
    /// items into blocks of `block` (at least 1).
    pub fn new(total: A, block: usize) -> Self {
        Self {
            total,
            open: None,
            open_len: 0,
            block: block.max(1),
            items: 0,
        }
    }

    /// The items added so far.
    pub fn items(&self) -> u64 {
        self.items
    }

    /// Adds a batch of `len` items: `fold(&mut partial, range)` adds the
    /// items `range` of the batch (indices from 0 within the batch) to a
    /// partial that started as `init()`; `merge` adds a partial to the
    /// total. At most `max_partials` partials exist at a time (it bounds the
    /// memory and the parallelism, not the result).
    pub fn add(
        &mut self,
        len: usize,
        max_partials: usize,
        init: impl Fn() -> A + Sync,
        fold: impl Fn(&mut A, Range<usize>) + Sync,
        mut merge: impl FnMut(&mut A, A),
    ) {
        let mut start = 0;
        if let Some(open) = self.open.as_mut() {
            let take = len.min(self.block - self.open_len);
            fold(open, 0..take);
            self.open_len += take;
            start = take;
            if self.open_len == self.block {
                if let Some(full) = self.open.take() {
                    merge(&mut self.total, full);
                }
                self.open_len = 0;
            }
        }
        let full_end = start + (len - start) / self.block * self.block;
        accumulate_into(
            &mut self.total,
            start..full_end,
            self.block,
            max_partials,
            &init,
            &fold,
            &mut merge,
        );
        if full_end < len {
            let mut open = init();
            fold(&mut open, full_end..len);
            self.open = Some(open);
            self.open_len = len - full_end;
        }
        self.items += len as u64;
    }

    /// Adds the items of `other` (summed separately, e.g. on another
    /// machine) to this sum; see the type's documentation for the rounding.
    pub fn merge(&mut self, other: Self, mut merge: impl FnMut(&mut A, A)) {
        let items = other.items;
        let theirs = other.finish(&mut merge);
        if let Some(open) = self.open.take() {
            merge(&mut self.total, open);
            self.open_len = 0;
        }
        merge(&mut self.total, theirs);
        self.items += items;
    }

    /// The state, for sending it elsewhere ([`crate::wire`]): the total of
    /// the complete blocks, the open block and its item count (0 without
    /// one), the block size and the items added.
    pub fn parts(&self) -> (&A, Option<&A>, usize, usize, u64) {
        (
            &self.total,
            self.open.as_ref(),
            self.open_len,
            self.block,
            self.items,
        )
    }

    /// A sum from the [`parts`](Self::parts) of another; `None` when they
    /// cannot be a sum's (an open block of 0 items or of a whole block or
    /// more, or more open items than items).
    pub fn from_parts(
        total: A,
        open: Option<(A, usize)>,
        block: usize,
        items: u64,
    ) -> Option<Self> {
        let block = block.max(1);
        let open_len = open.as_ref().map_or(0, |o| o.1);
        if open.is_some() && (open_len == 0 || open_len >= block || open_len as u64 > items) {
            return None;
        }
        Some(Self {
            total,
            open: open.map(|o| o.0),
            open_len,
            block,
            items,
        })
    }

    /// The total.
    pub fn finish(mut self, mut merge: impl FnMut(&mut A, A)) -> A {
        if let Some(open) = self.open.take() {
            merge(&mut self.total, open);
        }
        self.total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn harmonic(threads: usize, len: usize, chunk: usize) -> f64 {
        with_threads(Threads::from_count(threads), || {
            accumulate(
                len,
                chunk,
                || 0.0,
                |s: &mut f64, r| {
                    for i in r {
                        *s += 1.0 / (1.0 + i as f64);
                    }
                },
                |s, p| *s += p,
            )
        })
        .unwrap()
    }

    #[test]
    fn same_bits_for_every_thread_count() {
        let one = harmonic(1, 100_003, 97);
        for t in [2, 3, 7] {
            assert_eq!(
                one.to_bits(),
                harmonic(t, 100_003, 97).to_bits(),
                "{t} threads"
            );
        }
        // and the value is the harmonic number H_n = ln n + gamma + 1/(2n) - ...
        let n = 100_003.0f64;
        let h = n.ln() + 0.577_215_664_901_532_9 + 0.5 / n - 1.0 / (12.0 * n * n);
        assert!((one - h).abs() < 1e-10, "{one} vs {h}");
    }

    #[test]
    fn chunks_are_merged_in_order() {
        // the merge sees the partial of chunk 0, then 1, ...: record them
        let order = accumulate(
            1000,
            10,
            Vec::new,
            |v: &mut Vec<usize>, r| v.push(r.start),
            |v, p| v.extend(p),
        );
        assert_eq!(order, (0..100).map(|c| c * 10).collect::<Vec<_>>());
        // empty input: the identity; a chunk of 0 is taken as 1
        assert_eq!(accumulate(0, 5, || 7, |_, _| {}, |a, b| *a += b), 7);
        assert_eq!(
            accumulate(3, 0, || 0, |a, r| *a += r.len(), |a, b| *a += b),
            3
        );
    }

    #[test]
    fn pool_size_is_the_one_asked_for() {
        for t in [1, 3] {
            let n = with_threads(Threads::from_count(t), rayon::current_num_threads).unwrap();
            assert_eq!(n, t);
        }
        assert_eq!(Threads::from_count(0).count(), None);
    }
}
