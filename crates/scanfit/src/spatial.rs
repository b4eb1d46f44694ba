//! The one spatial index of the library: a static KD-tree over 3D points.
//!
//! Every nearest-neighbour query goes through [`KdTree`]: the neighbour
//! queries of a [`crate::PointCloud`], the start points of point inversion
//! ([`crate::project::SurfaceInverter`]) and the nearest grid vertex of the
//! [COONS19]'s grid iteration ([`crate::project::grid_iteration`]).
//! Distances are Euclidean (not squared); results of the multi-point queries
//! are sorted by distance, nearest first, ties by index (so no result
//! depends on how the tree was built or on the order of the queries).
//!
//! The tree (Friedman, Bentley & Finkel 1977) splits each cell (the
//! bounding box cut by the splits above) at the median along its widest
//! side down to buckets of at most [`BUCKET`] points and keeps the points
//! in its own depth-first order: a bucket's points lie side
//! by side in memory, and the tree order is a spatial order that batch work
//! over all the points follows ([`KdTree::spatial_order`]). The search
//! visits the nearer child first and skips a cell whose distance to the
//! query (kept per axis as the cell offsets of Arya & Mount 1993,
//! "Algorithms for fast vector quantization") exceeds the k-th distance
//! found; that bound is compared in the same floating-point sums as the
//! points' distances, so no point at the k-th distance is ever skipped and
//! ties resolve by index exactly. It replaced kiddo 6's `ImmutableKdTree`
//! (issue 18: the 17 nearest of each of 10^6 points cost 3.2 us of CPU per
//! query there, most of `scanfit cloud segment`); the tests check its
//! answers against kiddo's.

use std::num::NonZeroUsize;
use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;

use crate::{Error, Point3, Result};

/// Most points in a bucket (leaf) of the tree. 16 since the buckets are
/// scanned without a branch per point: against 12, the 20 nearest of
/// every point of a 10^6-point panel (`cloud normals`) took 6% less CPU,
/// `cloud segment` and `turntable` 3-4% less (BENCHMARKS.md, session 9).
pub const BUCKET: usize = 16;

/// One neighbour: its index among the indexed points and its distance to the
/// query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Index of the point (in the order the points were given).
    pub index: usize,
    /// Euclidean distance to the query point.
    pub distance: f64,
}

/// A static KD-tree over a set of 3D points (built once, queried from any
/// number of threads).
///
/// The cell over tree positions `lo..hi` (more than [`BUCKET`] of them)
/// splits at `mid = lo + (hi - lo) / 2` into `lo..mid` and `mid..hi`; every
/// inner cell has its own `mid`, where its split is stored.
pub struct KdTree {
    /// The points in tree order.
    pts: Vec<[f64; 3]>,
    /// For each tree position, the point's index in the input.
    ids: Vec<u32>,
    /// At an inner cell's `mid`: the coordinate of its split (every point
    /// below `mid` has at most this coordinate, every point from `mid` on at
    /// least this) ...
    split: Vec<f64>,
    /// ... and its axis.
    axis: Vec<u8>,
}

impl std::fmt::Debug for KdTree {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KdTree").field("len", &self.len()).finish()
    }
}

fn coords(p: &Point3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// Squared distance, summed x, y, z (the cell bound sums its offsets in the
/// same order, so it never exceeds a point's distance in floating point).
fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let (x, y, z) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    x * x + y * y + z * z
}

/// One candidate: squared distance, index in the input, tree position (16
/// bytes, as the pair without the position would be after padding). Packing
/// it in one `u128` ordered as (distance, index) was tried: more
/// instructions (callgrind), the same CPU time.
type Candidate = (f64, u32, u32);

/// The `k` best candidates so far, sorted by (squared distance, index),
/// among the points no farther (squared) than `cap`.
struct Best {
    k: usize,
    items: Vec<Candidate>,
    /// A squared distance known to be at least the `k`-th smallest
    /// (`INFINITY` when none is known): until `k` candidates are found,
    /// cells and points beyond it are skipped.
    cap: f64,
}

impl Best {
    fn new(k: usize) -> Self {
        Self {
            k,
            items: Vec::with_capacity(k.min(1 << 12) + 1),
            cap: f64::INFINITY,
        }
    }

    /// Empties it for the next query (keeping its memory), with the bound
    /// `cap` (see the field).
    fn restart(&mut self, k: usize, cap: f64) {
        self.k = k;
        self.items.clear();
        self.cap = cap;
    }

    fn offer(&mut self, d2: f64, id: u32, pos: u32) {
        let before = |c: &Candidate| d2 < c.0 || (d2 == c.0 && id < c.1);
        let n = self.items.len();
        if n == self.k {
            if !before(&self.items[n - 1]) {
                return;
            }
            self.items[n - 1] = (d2, id, pos);
        } else {
            self.items.push((d2, id, pos));
        }
        // one insertion-sort step (k is small: no binary search, no memmove)
        let mut at = self.items.len() - 1;
        while at > 0 && before(&self.items[at - 1]) {
            self.items[at] = self.items[at - 1];
            at -= 1;
        }
        self.items[at] = (d2, id, pos);
    }
}

/// What a descent of the tree collects: the points of each bucket it
/// reaches, and the squared distance beyond which a cell holds nothing for it.
trait Visit {
    /// Cells farther than this (squared) are skipped.
    fn bound(&self) -> f64;
    /// Takes the points of the bucket `lo..hi`.
    fn bucket(&mut self, tree: &KdTree, lo: usize, hi: usize, q: &[f64; 3]);
}

impl Visit for Best {
    fn bound(&self) -> f64 {
        if self.items.len() < self.k {
            self.cap
        } else {
            self.items[self.k - 1].0
        }
    }

    fn bucket(&mut self, tree: &KdTree, lo: usize, hi: usize, q: &[f64; 3]) {
        // Most points of a bucket are farther than the k-th, and whether
        // one is not is a coin toss the processor mispredicts: no branch
        // per point, but every distance and the places of those within the
        // bound on entry (`<=`: an equal distance may win by index), then
        // the offers of those still within it as the offers shrink it.
        let pts = &tree.pts[lo..hi];
        let (mut d, mut pass, mut m) = ([0.0; BUCKET], [0u8; BUCKET], 0);
        let worst = self.bound();
        for (j, p) in pts.iter().enumerate() {
            let d2 = dist2(p, q);
            d[j] = d2;
            pass[m] = j as u8;
            m += usize::from(d2 <= worst);
        }
        for &j in &pass[..m] {
            let j = j as usize;
            if d[j] <= self.bound() {
                self.offer(d[j], tree.ids[lo + j], (lo + j) as u32);
            }
        }
    }
}

/// The points within a squared distance, unsorted.
struct Within {
    r2: f64,
    found: Vec<(f64, u32)>,
}

impl Visit for Within {
    fn bound(&self) -> f64 {
        self.r2
    }

    fn bucket(&mut self, tree: &KdTree, lo: usize, hi: usize, q: &[f64; 3]) {
        for j in lo..hi {
            let d2 = dist2(&tree.pts[j], q);
            if d2 <= self.r2 {
                self.found.push((d2, tree.ids[j]));
            }
        }
    }
}

/// Orders `items` into tree order, writing the splits of its inner cells
/// (`split` and `axis` are the slices of the same positions). `lo..hi` is
/// the cell: the points' bounding box at the root, then the parent's cell
/// cut at the split (no pass over the points per cell); the split axis is
/// the cell's widest side.
fn build(
    items: &mut [([f64; 3], u32)],
    split: &mut [f64],
    axis: &mut [u8],
    lo: [f64; 3],
    hi: [f64; 3],
) {
    if items.len() <= BUCKET {
        return;
    }
    let mut ax = 0;
    for a in 1..3 {
        if hi[a] - lo[a] > hi[ax] - lo[ax] {
            ax = a;
        }
    }
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |x, y| x.0[ax].total_cmp(&y.0[ax]).then(x.1.cmp(&y.1)));
    let at = items[mid].0[ax];
    split[mid] = at;
    axis[mid] = ax as u8;
    let (mut below, mut above) = (hi, lo);
    below[ax] = at;
    above[ax] = at;
    let (il, ir) = items.split_at_mut(mid);
    let (sl, sr) = split.split_at_mut(mid);
    let (al, ar) = axis.split_at_mut(mid);
    if il.len() > 1 << 14 {
        rayon::join(
            || build(il, sl, al, lo, below),
            || build(ir, sr, ar, above, hi),
        );
    } else {
        build(il, sl, al, lo, below);
        build(ir, sr, ar, above, hi);
    }
}

impl KdTree {
    /// Indexes `points` (`what` names them in errors). An error for no
    /// points, more than 2^32 points, or a non-finite coordinate.
    ///
    /// ```
    /// use scanfit::spatial::KdTree;
    /// use scanfit::Point3;
    /// let pts: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let tree = KdTree::new(&pts, "the samples").unwrap();
    /// let n = tree.nearest(&Point3::new(3.2, 1.0, 0.0));
    /// assert_eq!(n.index, 3);
    /// assert!((n.distance - (0.04f64 + 1.0).sqrt()).abs() < 1e-15);
    /// assert!(KdTree::new(&[], "the samples").is_err());
    /// ```
    pub fn new(points: &[Point3], what: &str) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::InvalidInput(format!(
                "{what} are empty; a spatial index needs at least one point"
            )));
        }
        if points.len() > u32::MAX as usize {
            return Err(Error::InvalidInput(format!(
                "{} points in {what} exceed the KD-tree's limit of 2^32; split them",
                points.len()
            )));
        }
        if let Some(i) = points
            .iter()
            .position(|p| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(Error::InvalidInput(format!(
                "point {i} of {what} has a non-finite coordinate; a spatial index needs finite points"
            )));
        }
        let mut items: Vec<([f64; 3], u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (coords(p), i as u32))
            .collect();
        let n = items.len();
        let (mut split, mut axis) = (vec![0.0; n], vec![0u8; n]);
        let (lo, hi) = items
            .iter()
            .fold((items[0].0, items[0].0), |(mut lo, mut hi), (p, _)| {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
                (lo, hi)
            });
        build(&mut items, &mut split, &mut axis, lo, hi);
        let (pts, ids) = items.into_iter().unzip();
        Ok(Self {
            pts,
            ids,
            split,
            axis,
        })
    }

    /// Number of indexed points (at least 1).
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Always false: a tree holds at least one point.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The indexed points' indices in the tree's order: a spatial order
    /// (a bucket's points, then its neighbouring bucket's...), in which
    /// batch work over all the indexed points runs so that consecutive
    /// queries visit the same buckets and the same points (the cache holds
    /// them), whatever order the points came in.
    pub fn spatial_order(&self) -> &[u32] {
        &self.ids
    }

    /// The indexed points' coordinates in the tree's order: those of the
    /// point `spatial_order()[t]` at `t` (copies of the input, bit for bit).
    /// Batch work that follows the tree order reads a point's neighbours
    /// here, close in memory, instead of scattered over the input.
    pub(crate) fn points_in_order(&self) -> &[[f64; 3]] {
        &self.pts
    }

    /// The `k` nearest *other* indexed points of every indexed point, as
    /// rows in input order (`k` indices and `k` distances each, nearest
    /// first): among the `k + 1` nearest of a point, the point itself (or,
    /// among coincident points, the first copy found in the sorted row:
    /// itself when it sorts first), else the last, is left out. The queries
    /// run in tree order on the tree's own copy of the points, so
    /// consecutive queries share their buckets.
    pub(crate) fn graph_rows(&self, k: usize) -> (Vec<u32>, Vec<f64>) {
        let mut distances = vec![0.0; self.len() * k];
        let indices = self.graph_rows_into(k, &mut distances, f64::sqrt);
        (indices, distances)
    }

    /// [`KdTree::graph_rows`] without the distances (a quarter of the
    /// memory with 4-byte indices and 8-byte distances: the normals need
    /// only the indices).
    pub(crate) fn graph_indices(&self, k: usize) -> Vec<u32> {
        // a Vec of () holds no memory
        let mut none = vec![(); self.len() * k];
        self.graph_rows_into(k, &mut none, |_| ())
    }

    fn graph_rows_into<B: Copy + Default + Send>(
        &self,
        k: usize,
        distances: &mut [B],
        dist: fn(f64) -> B,
    ) -> Vec<u32> {
        let n = self.len();
        let mut indices = vec![0u32; n * k];
        let positions: Vec<u32> = (0..n as u32).collect();
        // one `Best` per chunk of consecutive positions: each query starts
        // from the bound of the one before (see `own_row`)
        let rows = |best: &mut Best, pos: usize, idx: &mut [u32], d: &mut [B]| {
            for (j, (d2, id, _)) in self.own_row(pos, k, best).enumerate() {
                idx[j] = id;
                d[j] = dist(d2);
            }
        };
        // rows land at the input index of the tree position
        let scratch = || Best::new(k + 1);
        fill_rows_with(
            &positions,
            &self.ids,
            k,
            (&mut indices, distances),
            scratch,
            rows,
        );
        indices
    }

    /// The `k` nearest others of the point at tree position `pos` (at most
    /// `len() - 1`), nearest first, as [`KdTree::graph_rows`] chooses them;
    /// `best` is scratch space.
    fn own_row<'b>(
        &self,
        pos: usize,
        k: usize,
        best: &'b mut Best,
    ) -> impl Iterator<Item = Candidate> + 'b {
        let q = &self.pts[pos];
        let want = (k + 1).min(self.len());
        // The previous query's `want` points (the queries run in tree
        // order: mostly a neighbouring point's) are `want` distinct points,
        // so the farthest of them from `q` bounds `q`'s `want`-th distance
        // (Friedman, Bentley & Finkel's bound, known before the descent):
        // cells and points beyond it hold no answer. It is the same sum
        // `dist2` the bucket test compares, so no answer (nor tie) is lost.
        let cap = if best.items.len() == want {
            best.items
                .iter()
                .map(|c| dist2(&self.pts[c.2 as usize], q))
                .fold(0.0, f64::max)
        } else {
            f64::INFINITY
        };
        best.restart(want, cap);
        self.descend(0, self.len(), q, &mut [0.0; 3], best);
        let found = &best.items;
        let me = self.ids[pos];
        let skip = found
            .iter()
            .position(|c| c.1 == me)
            .unwrap_or(found.len() - 1);
        found
            .iter()
            .enumerate()
            .filter(move |&(j, _)| j != skip)
            .map(|(_, c)| *c)
            .take(k)
    }

    /// The neighbour graph of [`KdTree::graph_rows`] in the tree's own
    /// terms, with per-point work done while a point's neighbours are fresh
    /// in the cache: row `t` (`k` values, `k` at most `len() - 1`) holds
    /// the tree positions of the `k` nearest others of the point at tree
    /// position `t` (the same points, in the same order, as the row of the
    /// input index `spatial_order()[t]` in `graph_rows`), and `f(t, row)`
    /// is evaluated with it; both are returned in tree order. Parallel
    /// chunks of consecutive positions, no allocation per query.
    pub(crate) fn graph_in_tree_order<T, F>(&self, k: usize, f: F) -> (Vec<u32>, Vec<T>)
    where
        T: Copy + Default + Send,
        F: Fn(usize, &[u32]) -> T + Sync,
    {
        let n = self.len();
        let k = k.min(n - 1);
        let mut rows = vec![0u32; n * k];
        let mut out = vec![T::default(); n];
        if k == 0 {
            return (rows, out);
        }
        rows.par_chunks_mut(CHUNK * k)
            .zip(out.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (rows, out))| {
                let mut best = Best::new(k + 1);
                for (r, (row, o)) in rows.chunks_mut(k).zip(out).enumerate() {
                    let t = c * CHUNK + r;
                    for (x, c) in row.iter_mut().zip(self.own_row(t, k, &mut best)) {
                        *x = c.2;
                    }
                    *o = f(t, row);
                }
            });
        (rows, out)
    }

    /// Hands `visit` the buckets of the cell `lo..hi` that may hold what it
    /// collects, the nearer child first; `off` holds the cell's offset from
    /// `q` per axis, and a cell whose sum of squared offsets exceeds
    /// `visit.bound()` is skipped.
    fn descend<V: Visit>(
        &self,
        lo: usize,
        hi: usize,
        q: &[f64; 3],
        off: &mut [f64; 3],
        visit: &mut V,
    ) {
        if hi - lo <= BUCKET {
            visit.bucket(self, lo, hi, q);
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let a = self.axis[mid] as usize;
        let diff = q[a] - self.split[mid];
        let (near, far) = if diff < 0.0 {
            ((lo, mid), (mid, hi))
        } else {
            ((mid, hi), (lo, mid))
        };
        self.descend(near.0, near.1, q, off, visit);
        let old = off[a];
        off[a] = diff;
        let rd = off[0] * off[0] + off[1] * off[1] + off[2] * off[2];
        if rd <= visit.bound() {
            self.descend(far.0, far.1, q, off, visit);
        }
        off[a] = old;
    }

    /// The `k` nearest (by distance, then index) to `q`.
    fn best(&self, q: &[f64; 3], k: usize) -> Best {
        let mut best = Best::new(k);
        self.descend(0, self.len(), q, &mut [0.0; 3], &mut best);
        best
    }

    /// The nearest indexed point to `query` (a finite point; the one of
    /// smallest index among equally near ones).
    pub fn nearest(&self, query: &Point3) -> Neighbour {
        let b = self.best(&coords(query), 1);
        let (d2, id, _) = b.items[0];
        Neighbour {
            index: id as usize,
            distance: d2.sqrt(),
        }
    }

    /// The `k` nearest indexed points to `query` (fewer if there are fewer
    /// points), nearest first.
    ///
    /// ```
    /// use std::num::NonZeroUsize;
    /// use scanfit::spatial::KdTree;
    /// use scanfit::Point3;
    /// let pts: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let tree = KdTree::new(&pts, "the points").unwrap();
    /// let k3 = tree.nearest_n(&Point3::new(6.9, 0.0, 0.0), NonZeroUsize::new(3).unwrap());
    /// let idx: Vec<usize> = k3.iter().map(|n| n.index).collect();
    /// assert_eq!(idx, [7, 6, 8]);
    /// ```
    pub fn nearest_n(&self, query: &Point3, k: NonZeroUsize) -> Vec<Neighbour> {
        let k = k.get().min(self.len());
        self.best(&coords(query), k)
            .items
            .into_iter()
            .map(|(d2, id, _)| Neighbour {
                index: id as usize,
                distance: d2.sqrt(),
            })
            .collect()
    }

    /// All indexed points within distance `radius` of `query` (inclusive),
    /// nearest first.
    ///
    /// ```
    /// use scanfit::spatial::KdTree;
    /// use scanfit::Point3;
    /// let pts: Vec<Point3> = (0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let tree = KdTree::new(&pts, "the points").unwrap();
    /// let near = tree.within(&Point3::new(2.0, 0.0, 0.0), 1.0);
    /// assert_eq!(near.iter().map(|n| n.index).collect::<Vec<_>>(), [2, 1, 3]);
    /// ```
    pub fn within(&self, query: &Point3, radius: f64) -> Vec<Neighbour> {
        let mut within = Within {
            r2: radius * radius,
            found: Vec::new(),
        };
        let q = coords(query);
        self.descend(0, self.len(), &q, &mut [0.0; 3], &mut within);
        let mut out = within.found;
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.into_iter()
            .map(|(d2, id)| Neighbour {
                index: id as usize,
                distance: d2.sqrt(),
            })
            .collect()
    }
}

/// Spreads the low 21 bits of `v` to every third bit.
fn spread3(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// A permutation of `points` along the Morton (Z-order) curve of their
/// bounding cube cut into 2^21 cells per axis (ties by index): points close
/// in the order are close in space. Batched neighbour queries visit their
/// queries in this order for cache locality; it decides only the order of
/// the work, never a result.
///
/// ```
/// use scanfit::spatial::morton_order;
/// use scanfit::Point3;
/// let p = |x, y| Point3::new(x, y, 0.0);
/// let pts = [p(1.0, 1.0), p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)];
/// assert_eq!(morton_order(&pts), [1, 2, 3, 0]);
/// ```
pub fn morton_order(points: &[Point3]) -> Vec<u32> {
    let Some(first) = points.first() else {
        return Vec::new();
    };
    let (lo, hi) = points
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let ext = (hi - lo).max();
    let scale = if ext > 0.0 {
        ((1u64 << 21) - 1) as f64 / ext
    } else {
        0.0
    };
    let cell = |p: &Point3, a: usize| ((p[a] - lo[a]) * scale) as u64;
    let mut keys: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let code = spread3(cell(p, 0)) | spread3(cell(p, 1)) << 1 | spread3(cell(p, 2)) << 2;
            (code, i as u32)
        })
        .collect();
    keys.par_sort_unstable();
    keys.into_iter().map(|k| k.1).collect()
}

/// Queries visited per task of the ordered batch helpers.
const CHUNK: usize = 1024;

/// Runs `fill(i, a_row, b_row)` for every item `i` listed in `order`
/// (parallel chunks of consecutive entries of `order`, so one task works on
/// points close in space) and stores the rows at their item's place in `a`
/// and `b` (`width` values per item in each). Each row is filled exactly as
/// by a loop in item order: the order decides only the speed.
pub(crate) fn fill_rows_in_order<A, B, F>(
    order: &[u32],
    width: usize,
    a: &mut [A],
    b: &mut [B],
    fill: F,
) where
    A: Copy + Default + Send,
    B: Copy + Default + Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync,
{
    fill_rows_at(order, order, width, a, b, fill);
}

/// [`fill_rows_in_order`] with the row of the work item `work[t]` stored
/// at item `place[t]` (`fill` gets the work item).
fn fill_rows_at<A, B, F>(
    work: &[u32],
    place: &[u32],
    width: usize,
    a: &mut [A],
    b: &mut [B],
    fill: F,
) where
    A: Copy + Default + Send,
    B: Copy + Default + Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync,
{
    let no_scratch = || ();
    fill_rows_with(work, place, width, (a, b), no_scratch, |_, i, x, y| {
        fill(i, x, y)
    });
}

/// [`fill_rows_at`] with scratch space made by `scratch` once per chunk of
/// work items and handed to each `fill` of the chunk, in order.
fn fill_rows_with<A, B, S, I, F>(
    work: &[u32],
    place: &[u32],
    width: usize,
    (a, b): (&mut [A], &mut [B]),
    scratch: I,
    fill: F,
) where
    A: Copy + Default + Send,
    B: Copy + Default + Send,
    I: Fn() -> S + Sync,
    F: Fn(&mut S, usize, &mut [A], &mut [B]) + Sync,
{
    if width == 0 {
        return;
    }
    let out = Mutex::new((a, b));
    work.par_chunks(CHUNK)
        .zip(place.par_chunks(CHUNK))
        .for_each(|(chunk, at)| {
            let mut ra = vec![A::default(); chunk.len() * width];
            let mut rb = vec![B::default(); chunk.len() * width];
            let mut s = scratch();
            for ((x, y), &i) in ra.chunks_mut(width).zip(rb.chunks_mut(width)).zip(chunk) {
                fill(&mut s, i as usize, x, y);
            }
            let mut o = out.lock().unwrap_or_else(PoisonError::into_inner);
            for (k, &i) in at.iter().enumerate() {
                let (from, to) = (k * width..(k + 1) * width, i as usize * width);
                o.0[to..to + width].copy_from_slice(&ra[from.clone()]);
                o.1[to..to + width].copy_from_slice(&rb[from]);
            }
        });
}

/// `f(i)` for every item `i` of `order` (a permutation of `0..order.len()`),
/// evaluated in parallel chunks in the order's sequence, returned in item
/// order.
pub(crate) fn map_in_order<T, F>(order: &[u32], f: F) -> Vec<T>
where
    T: Copy + Default + Send,
    F: Fn(usize) -> T + Sync,
{
    let mut out = vec![T::default(); order.len()];
    let mut none: Vec<()> = vec![(); order.len()];
    fill_rows_in_order(order, 1, &mut out, &mut none, |i, row, _| row[0] = f(i));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_agree_with_brute_force() {
        let mut rng = crate::testdata::Lcg::new(5);
        let mut rnd = || rng.next_f64();
        let pts: Vec<Point3> = (0..500).map(|_| Point3::new(rnd(), rnd(), rnd())).collect();
        let tree = KdTree::new(&pts, "points").unwrap();
        assert_eq!(tree.len(), 500);
        assert!(!tree.is_empty());
        for _ in 0..50 {
            let q = Point3::new(rnd(), rnd(), rnd());
            let mut brute: Vec<(f64, usize)> = pts
                .iter()
                .enumerate()
                .map(|(i, p)| ((p - q).norm(), i))
                .collect();
            brute.sort_by(|a, b| a.0.total_cmp(&b.0));
            assert_eq!(tree.nearest(&q).index, brute[0].1);
            let k = tree.nearest_n(&q, NonZeroUsize::new(5).unwrap());
            let want: Vec<usize> = brute[..5].iter().map(|b| b.1).collect();
            assert_eq!(k.iter().map(|n| n.index).collect::<Vec<_>>(), want);
            // a radius between the 8th and 9th distance (squared distances
            // round differently from the norms at the exact 8th)
            let r = 0.5 * (brute[7].0 + brute[8].0);
            let w = tree.within(&q, r);
            assert_eq!(w.len(), 8);
            assert!((w[7].distance - brute[7].0).abs() < 1e-15);
        }
        // more neighbours asked for than points: all of them
        let all = tree.nearest_n(&pts[0], NonZeroUsize::new(10_000).unwrap());
        assert_eq!(all.len(), 500);
    }

    /// Point sets that test ties: `n` random points in a unit square
    /// (heights scaled by `z`), a `side x side x layers` grid (equal
    /// distances everywhere) and random points with duplicates (the first
    /// 15% and then the first 2.5% again).
    fn hard_sets(seed: u64, n: usize, side: usize, layers: usize, z: f64) -> [Vec<Point3>; 3] {
        let mut rng = crate::testdata::Lcg::new(seed);
        let mut rnd = || rng.next_f64();
        let random: Vec<Point3> = (0..n)
            .map(|_| Point3::new(rnd(), rnd(), z * rnd()))
            .collect();
        let grid = (0..side * side * layers)
            .map(|i| {
                let (x, y, h) = (i % side, i / side % side, i / (side * side));
                Point3::new(x as f64, y as f64, h as f64)
            })
            .collect();
        let mut dups = random[..n * 3 / 20].to_vec();
        dups.extend_from_slice(&random[..n / 40]);
        [random, grid, dups]
    }

    /// The tree against kiddo 6's `ImmutableKdTree` (the index it replaced,
    /// an independent implementation): on random points, a grid (ties
    /// everywhere) and duplicates, the k nearest have the same distances,
    /// bit for bit, and the same indices wherever the distance decides;
    /// among equal distances ours are by index.
    #[test]
    fn answers_agree_with_kiddo() {
        use kiddo::{ImmutableKdTree, SquaredEuclidean};
        for pts in hard_sets(17, 20_000, 20, 10, 0.2) {
            let ours = KdTree::new(&pts, "points").unwrap();
            let c: Vec<[f64; 3]> = pts.iter().map(coords).collect();
            let theirs: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&c).unwrap();
            for (qi, q) in pts.iter().enumerate().step_by(7) {
                let q = q + crate::Vector3::new(0.0, 0.0, if qi % 2 == 0 { 0.0 } else { 0.3 });
                let k = NonZeroUsize::new(1 + qi % 24).unwrap();
                let a = ours.nearest_n(&q, k);
                let b = theirs
                    .query(&coords(&q))
                    .nearest_n::<SquaredEuclidean<f64>>(k)
                    .execute();
                assert_eq!(a.len(), b.len());
                let last = b[b.len() - 1].distance.sqrt();
                for (x, y) in a.iter().zip(&b) {
                    assert_eq!(x.distance, y.distance.sqrt(), "query {qi}");
                }
                // where the k-th distance does not tie, the same points
                let mut sa: Vec<usize> = a
                    .iter()
                    .filter(|n| n.distance < last)
                    .map(|n| n.index)
                    .collect();
                let mut sb: Vec<usize> = b
                    .iter()
                    .filter(|n| n.distance.sqrt() < last)
                    .map(|n| n.item as usize)
                    .collect();
                sa.sort_unstable();
                sb.sort_unstable();
                assert_eq!(sa, sb, "query {qi}");
                assert!(a
                    .windows(2)
                    .all(|w| (w[0].distance, w[0].index) < (w[1].distance, w[1].index)));
                assert_eq!(ours.nearest(&q).index, a[0].index);
            }
        }
    }

    /// The rows in tree order against a brute-force search over all pairs:
    /// on random points, a grid (ties everywhere) and duplicates, row `t`
    /// is the `k` nearest others of the point at tree position `t`, by
    /// (distance, index), the point itself left out (or, among coincident
    /// points ordered before it, the last of the `k + 1`), and equals the
    /// row of `graph_rows` at that point's input index.
    #[test]
    fn rows_in_tree_order_are_the_brute_force_neighbours() {
        let [random, grid, dups] = hard_sets(23, 1500, 10, 10, 0.1);
        for (pts, k) in [(random, 20), (grid, 9), (dups, 12), (grid_of(5), 4)] {
            let tree = KdTree::new(&pts, "points").unwrap();
            let order = tree.spatial_order();
            let (rows, firsts) = tree.graph_in_tree_order(k, |t, row| (t, row[0]));
            let (indices, _) = tree.graph_rows(k);
            let k = k.min(pts.len() - 1);
            assert_eq!(rows.len(), pts.len() * k);
            for (t, &i) in order.iter().enumerate() {
                let i = i as usize;
                let row: Vec<u32> = rows[t * k..(t + 1) * k]
                    .iter()
                    .map(|&s| order[s as usize])
                    .collect();
                assert_eq!(firsts[t], (t, rows[t * k]));
                assert_eq!(row, indices[i * k..(i + 1) * k], "point {i}");
                let q = coords(&pts[i]);
                let mut all: Vec<(f64, u32)> = pts
                    .iter()
                    .enumerate()
                    .map(|(j, p)| (dist2(&coords(p), &q), j as u32))
                    .collect();
                all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                all.truncate(k + 1);
                let me = all.iter().position(|c| c.1 as usize == i).unwrap_or(k);
                all.remove(me);
                let brute: Vec<u32> = all.iter().map(|c| c.1).collect();
                assert_eq!(row, brute, "point {i}");
            }
        }
    }

    /// `n` points on a line: fewer than the `k + 1` asked for.
    fn grid_of(n: usize) -> Vec<Point3> {
        (0..n).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect()
    }

    #[test]
    fn morton_order_is_a_permutation_that_keeps_cells_together() {
        let mut rng = crate::testdata::Lcg::new(9);
        let pts: Vec<Point3> = (0..5000)
            .map(|_| Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
            .collect();
        let order = morton_order(&pts);
        let mut seen = vec![false; pts.len()];
        for &i in &order {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // the octant of the first level changes 7 times along the curve
        let octant = |p: &Point3| (p.x >= 0.5, p.y >= 0.5, p.z >= 0.5);
        let changes = order
            .windows(2)
            .filter(|w| octant(&pts[w[0] as usize]) != octant(&pts[w[1] as usize]))
            .count();
        assert!(changes <= 7, "{changes}");
        // consecutive points are close: mean step far below that of the input order
        let step = |o: &[u32]| {
            o.windows(2)
                .map(|w| (pts[w[0] as usize] - pts[w[1] as usize]).norm())
                .sum::<f64>()
                / (o.len() - 1) as f64
        };
        let input: Vec<u32> = (0..pts.len() as u32).collect();
        assert!(
            step(&order) < 0.2 * step(&input),
            "{} vs {}",
            step(&order),
            step(&input)
        );
        assert!(morton_order(&[]).is_empty());
        assert_eq!(morton_order(&[Point3::origin(); 3]), [0, 1, 2]);
    }

    #[test]
    fn rows_filled_in_any_order_land_at_their_items() {
        // a permutation over several chunks
        let n = 3 * CHUNK + 17;
        let order: Vec<u32> = (0..n as u32).map(|i| (i * 7919) % n as u32).collect();
        let (mut a, mut b) = (vec![0u32; 2 * n], vec![0.0; 2 * n]);
        fill_rows_in_order(&order, 2, &mut a, &mut b, |i, x, y| {
            x.copy_from_slice(&[i as u32, 2 * i as u32]);
            y.copy_from_slice(&[i as f64 / 2.0, -(i as f64)]);
        });
        for i in 0..n {
            assert_eq!(a[2 * i..2 * i + 2], [i as u32, 2 * i as u32]);
            assert_eq!(b[2 * i..2 * i + 2], [i as f64 / 2.0, -(i as f64)]);
        }
        assert_eq!(
            map_in_order(&order, |i| i * i),
            (0..n).map(|i| i * i).collect::<Vec<_>>()
        );
    }

    #[test]
    fn bad_points_are_refused_with_their_index() {
        let mut pts = vec![Point3::origin(); 4];
        pts[2].y = f64::NAN;
        let e = KdTree::new(&pts, "the grid").unwrap_err().to_string();
        assert!(e.contains("point 2 of the grid"), "{e}");
    }
}
