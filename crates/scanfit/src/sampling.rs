//! Seeded random samples of big point sets, for the statistical diagnostics
//! of the surface assessment ([`crate::pipeline::assess`], issue 18): the
//! median point spacing and the parameterization's fold-overs and stretch
//! are measured on a sample once a cloud has more points than
//! [`crate::pipeline::assess::AssessConfig::sample_points`].
//!
//! * [`sample_indices`]: a uniform random `k`-subset of `0..n` (Knuth,
//!   TAOCP vol. 2, 3.4.2, Algorithm S: every subset equally likely, indices
//!   in increasing order), for statistics of single points (the spacing).
//! * [`CellSample`]: whole cells of a grid over the parameters (a
//!   cluster sample, one cell drawn from each run of consecutive cells),
//!   with a margin of points around each, for statistics of triangles. A
//!   Delaunay triangle of the sampled points counts when its circumcentre
//!   lies in a taken cell and its circumcircle inside that cell's margin:
//!   it is then exactly a triangle of the Delaunay triangulation of all
//!   points (nothing of the whole set lies in its circumcircle, or it would
//!   be in the sample), and every triangle of the whole set belongs to one
//!   cell by its circumcentre, so each is counted with its cell's
//!   probability whatever its size or shape. Fold-overs and stretch are
//!   then measured on the very triangles the full computation uses, at the
//!   data's own density, without favouring small triangles (the earlier
//!   rule, a circumcircle inside the taken cells, kept a triangle with a
//!   probability falling with its circumradius).
//! * [`HashSample`]: the `k` points whose indices have the smallest seeded
//!   hash (a bottom-k sketch, Cohen & Kaplan 2007): a uniform random
//!   `k`-subset like [`sample_indices`], but needing no count in advance
//!   and mergeable (the sample of two sets of points is the `k` smallest of
//!   their two samples), so a streamed or distributed pass over chunks in
//!   any order and grouping gathers exactly the sample of one call.
//!
//! All draw from SplitMix64 (Steele, Lea & Flood 2014) started at a fixed
//! seed, so a sample is the same on every run, thread count and machine.

/// The seed of every sample the assessment draws (issue 18), unless its
/// configuration gives another.
pub const DEFAULT_SEED: u64 = 18;

use rayon::prelude::*;

use crate::wire::{Reader, Writer};
use crate::{Error, Point3, Result};

/// Points per cell of a [`CellSample`] on average (16 x 16 points): small
/// cells, so that a sample of 50 000 points spreads over about 200 of them
/// (on the turntable's blob, 16 x 16 cells halve the spread of the sampled
/// L2 stretch over seeds against 32 x 32), large enough that the margin of
/// [`HALO`] adds less than their own points.
const POINTS_PER_CELL: f64 = 256.0;

/// The SplitMix64 generator.
#[derive(Debug, Clone)]
struct SplitMix64(u64);

/// SplitMix64's increment (the golden ratio times 2^64, odd).
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GOLDEN);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform draw from `0..bound` (`bound >= 1`; Lemire's
    /// multiply-shift, bias below `bound / 2^64`).
    fn below(&mut self, bound: u64) -> u64 {
        ((u128::from(self.next()) * u128::from(bound)) >> 64) as u64
    }
}

/// `k` indices of `0..n`, every `k`-subset equally likely, in increasing
/// order; all of `0..n` when `k >= n`. Deterministic in `seed`.
///
/// ```
/// use scanfit::sampling::sample_indices;
/// let s = sample_indices(1000, 10, 18);
/// assert_eq!(s.len(), 10);
/// assert!(s.windows(2).all(|w| w[0] < w[1]) && s[9] < 1000);
/// assert_eq!(s, sample_indices(1000, 10, 18));
/// assert_eq!(sample_indices(5, 10, 18), vec![0, 1, 2, 3, 4]);
/// ```
pub fn sample_indices(n: usize, k: usize, seed: u64) -> Vec<usize> {
    if k >= n {
        return (0..n).collect();
    }
    let mut rng = SplitMix64(seed);
    let mut chosen = Vec::with_capacity(k);
    for i in 0..n {
        // Algorithm S: take i with probability (still needed) / (left)
        let needed = (k - chosen.len()) as u64;
        if needed == 0 {
            break;
        }
        if rng.below((n - i) as u64) < needed {
            chosen.push(i);
        }
    }
    chosen
}

/// A cluster sample of points by their parameters: a grid of about
/// [`POINTS_PER_CELL`] points per cell over the parameters' bounding box,
/// of which the share `target / n` of the cells is taken (one cell drawn
/// uniformly from each run of `n / target` consecutive cells), with the
/// points within a margin of [`HALO`] of each taken cell.
#[derive(Debug, Clone)]
pub struct CellSample {
    lo: [f64; 2],
    cell: [f64; 2],
    dims: [usize; 2],
    halo: [f64; 2],
    taken: Vec<bool>,
    indices: Vec<usize>,
}

impl CellSample {
    /// The sample of about `target` of the points with parameters `uv`;
    /// `None` when the parameters span no area (nothing to triangulate) or
    /// there are no more than `target` points.
    ///
    /// ```
    /// use scanfit::sampling::CellSample;
    /// let uv: Vec<[f64; 2]> = (0..200_000)
    ///     .map(|k| [(k % 500) as f64 / 499.0, (k / 500) as f64 / 399.0])
    ///     .collect();
    /// let s = CellSample::new(&uv, 20_000, 18).unwrap();
    /// // a tenth of the points in whole cells, and the margins around them
    /// let core = s.indices().iter().filter(|&&i| s.contains(uv[i])).count();
    /// assert!(core > 17_000 && core < 23_000, "{core}");
    /// assert!(s.indices().len() > core + 5_000 && s.indices().len() < 2 * core);
    /// ```
    pub fn new(uv: &[[f64; 2]], target: usize, seed: u64) -> Option<Self> {
        let n = uv.len();
        if n <= target || target == 0 {
            return None;
        }
        let bounds = |(mut lo, mut hi): ([f64; 2], [f64; 2]), t: &[f64; 2]| {
            for k in 0..2 {
                lo[k] = f64::min(lo[k], t[k]);
                hi[k] = f64::max(hi[k], t[k]);
            }
            (lo, hi)
        };
        let empty = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let (lo, hi) = uv.par_iter().fold(|| empty, bounds).reduce(
            || empty,
            |a, b| {
                let (lo, hi) = bounds(a, &b.0);
                bounds((lo, hi), &b.1)
            },
        );
        let span = [hi[0] - lo[0], hi[1] - lo[1]];
        if !(span[0] > 0.0 && span[1] > 0.0 && span[0].is_finite() && span[1].is_finite()) {
            return None;
        }
        // square cells (in parameter units) of POINTS_PER_CELL points on average
        let side = (span[0] * span[1] * POINTS_PER_CELL / n as f64).sqrt();
        let count = |s: f64| ((s / side).ceil() as usize).clamp(1, 1 << 15);
        let dims = [count(span[0]), count(span[1])];
        let cell = [span[0] / dims[0] as f64, span[1] / dims[1] as f64];
        let cells = dims[0] * dims[1];
        let k = ((cells as f64 * target as f64 / n as f64).round() as usize).clamp(1, cells);
        // stratified: one cell drawn from each of k runs of consecutive
        // cells (column by column), so the taken cells spread over the
        // whole parameter domain; each cell is taken with probability
        // 1 / (its run's length), k / cells up to one cell in a run
        let mut taken = vec![false; cells];
        let mut rng = SplitMix64(seed);
        for j in 0..k {
            let (a, b) = (j * cells / k, (j + 1) * cells / k);
            taken[a + rng.below((b - a) as u64) as usize] = true;
        }
        let mut s = Self {
            lo,
            cell,
            dims,
            halo: [HALO * cell[0], HALO * cell[1]],
            taken,
            indices: Vec::new(),
        };
        s.indices = (0..n)
            .into_par_iter()
            .filter(|&i| s.near_taken(uv[i]))
            .collect();
        Some(s)
    }

    /// The sampled points (indices into the parameters given, increasing):
    /// those of the taken cells and of their margins.
    pub fn indices(&self) -> &[usize] {
        &self.indices
    }

    /// The cell of coordinate `x` in direction `k` (clamped to the grid).
    fn cell_of(&self, x: f64, k: usize) -> usize {
        let c = ((x - self.lo[k]) / self.cell[k]).floor();
        if c.is_nan() || c < 0.0 {
            0
        } else {
            (c as usize).min(self.dims[k] - 1)
        }
    }

    /// Whether parameters `t` lie in a taken cell.
    pub fn contains(&self, t: [f64; 2]) -> bool {
        self.taken[self.cell_of(t[0], 0) * self.dims[1] + self.cell_of(t[1], 1)]
    }

    /// Whether parameters `t` lie in a taken cell or in its margin (within
    /// the halo of its sides): whether the point is in the sample.
    fn near_taken(&self, t: [f64; 2]) -> bool {
        let (i0, i1) = (
            self.cell_of(t[0] - self.halo[0], 0),
            self.cell_of(t[0] + self.halo[0], 0),
        );
        let (j0, j1) = (
            self.cell_of(t[1] - self.halo[1], 1),
            self.cell_of(t[1] + self.halo[1], 1),
        );
        (i0..=i1).any(|i| (j0..=j1).any(|j| self.taken[i * self.dims[1] + j]))
    }

    /// Whether the disc of `radius` about `centre` lies inside the taken
    /// cell of `centre` grown by the halo (a side on the grid's border
    /// grows without bound: no point lies beyond it).
    fn in_own_cell(&self, centre: [f64; 2], radius: f64) -> bool {
        (0..2).all(|k| {
            let c = self.cell_of(centre[k], k);
            let lo = self.lo[k] + c as f64 * self.cell[k] - self.halo[k];
            let hi = self.lo[k] + (c + 1) as f64 * self.cell[k] + self.halo[k];
            (c == 0 || centre[k] - radius >= lo)
                && (c + 1 == self.dims[k] || centre[k] + radius <= hi)
        }) && self.contains(centre)
    }

    /// Whether the triangle `a, b, c` of the sample's Delaunay triangulation
    /// counts: its circumcentre lies in a taken cell (so each triangle of
    /// the whole set belongs to exactly one cell, and is counted with that
    /// cell's probability whatever its size or shape) and its circumcircle
    /// inside that cell and its margin, whose points are all in the sample,
    /// so that the triangle is one of the whole set's Delaunay triangles
    /// too (a degenerate triangle is not kept).
    pub fn keeps_triangle(&self, a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
        let (bx, by) = (b[0] - a[0], b[1] - a[1]);
        let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
        let d = 2.0 * (bx * cy - by * cx);
        if d == 0.0 || !d.is_finite() {
            return false;
        }
        let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
        let ux = (cy * b2 - by * c2) / d;
        let uy = (bx * c2 - cx * b2) / d;
        let (centre, radius) = ([a[0] + ux, a[1] + uy], ux.hypot(uy));
        if !(radius.is_finite() && centre[0].is_finite() && centre[1].is_finite()) {
            return false;
        }
        self.in_own_cell(centre, radius)
    }
}

/// The hash [`HashSample`] ranks point `index` by under `seed`: the
/// `index + 1`-th output of SplitMix64 started at `seed` (its state after
/// `index + 1` steps is `seed + (index + 1) * GOLDEN`, and its output
/// function is a bijection), so distinct indices never share a hash.
///
/// ```
/// use scanfit::sampling::index_hash;
/// assert_ne!(index_hash(7, 0), index_hash(7, 1));
/// assert_eq!(index_hash(7, 41), index_hash(7, 41));
/// ```
pub fn index_hash(seed: u64, index: u64) -> u64 {
    SplitMix64(seed.wrapping_add(index.wrapping_mul(GOLDEN))).next()
}

/// The `k` points of smallest [`index_hash`] among those added (a bottom-k
/// sketch, Cohen & Kaplan 2007): each point comes with its global index
/// (its position in the whole data, however the data are split), so every
/// `k`-subset of the indices is equally likely (up to the hash) and the
/// sample is a function of the data alone: points added chunk by chunk, in
/// any order, or merged from samples of other chunks ([`merge`](Self::merge))
/// give exactly the sample of one call over all of them. Memory: at most
/// `2k` points while adding; `k` between calls.
///
/// ```
/// use scanfit::sampling::HashSample;
/// use scanfit::Point3;
/// let pts: Vec<Point3> = (0..1000).map(|k| Point3::new(k as f64, 0.0, 0.0)).collect();
/// let mut once = HashSample::new(50, 18);
/// once.add(0, &pts);
/// // two chunks sampled apart (say, on two workers) and merged
/// let (mut a, mut b) = (HashSample::new(50, 18), HashSample::new(50, 18));
/// b.add(600, &pts[600..]);
/// a.add(0, &pts[..600]);
/// b.merge(&a)?;
/// assert_eq!(b, once);
/// assert_eq!(once.points().len(), 50);
/// assert_eq!(HashSample::from_bytes(&once.to_bytes())?, once);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct HashSample {
    k: usize,
    seed: u64,
    /// `(hash, index, point)`, increasing in hash, at most `k` between calls.
    kept: Vec<(u64, u64, Point3)>,
}

const SAMPLE_TAG: &[u8; 8] = b"SFHSMPL1";

impl HashSample {
    /// An empty sample of at most `k` points, ranked by [`index_hash`] under
    /// `seed`.
    pub fn new(k: usize, seed: u64) -> Self {
        Self {
            k,
            seed,
            kept: Vec::new(),
        }
    }

    /// The hash no further point can beat without entering: the largest kept
    /// when `k` are kept (every hash is distinct), else none.
    fn bar(&self) -> u64 {
        match self.kept.last() {
            Some(&(h, _, _)) if self.kept.len() >= self.k => h,
            _ => u64::MAX,
        }
    }

    /// Keeps the `k` smallest hashes, increasing, each index once.
    fn compact(&mut self) {
        self.kept.sort_unstable_by_key(|e| e.0);
        self.kept.dedup_by_key(|e| e.0);
        self.kept.truncate(self.k);
    }

    /// Adds `points`, the first of which has the global index `first` (the
    /// next `first + 1`, and so on).
    pub fn add(&mut self, first: u64, points: &[Point3]) {
        if self.k == 0 {
            return;
        }
        let mut bar = self.bar();
        let before = self.kept.len();
        for (j, p) in points.iter().enumerate() {
            let index = first.wrapping_add(j as u64);
            let h = index_hash(self.seed, index);
            if h < bar || (h == u64::MAX && self.kept.len() < self.k) {
                self.kept.push((h, index, *p));
                if self.kept.len() >= 2 * self.k {
                    self.compact();
                    bar = self.bar();
                }
            }
        }
        if self.kept.len() != before {
            self.compact();
        }
    }

    /// Adds the sample of other points (disjoint from these, of the same `k`
    /// and seed).
    pub fn merge(&mut self, other: &Self) -> Result<()> {
        if (self.k, self.seed) != (other.k, other.seed) {
            return Err(Error::InvalidInput(format!(
                "cannot merge a sample of {} points (seed {}) with one of {} points (seed {}); every chunk must be sampled alike",
                self.k, self.seed, other.k, other.seed
            )));
        }
        self.kept.extend_from_slice(&other.kept);
        self.compact();
        Ok(())
    }

    /// The most points kept.
    pub fn k(&self) -> usize {
        self.k
    }

    /// The seed of the hash.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Points kept (`min(k, points added)`).
    pub fn len(&self) -> usize {
        self.kept.len()
    }

    /// Whether no point was kept.
    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// The global indices of the sample, increasing.
    pub fn indices(&self) -> Vec<u64> {
        let mut i: Vec<u64> = self.kept.iter().map(|e| e.1).collect();
        i.sort_unstable();
        i
    }

    /// The sampled points in the order of their global indices.
    pub fn points(&self) -> Vec<Point3> {
        let mut e: Vec<(u64, Point3)> = self.kept.iter().map(|e| (e.1, e.2)).collect();
        e.sort_unstable_by_key(|e| e.0);
        e.into_iter().map(|e| e.1).collect()
    }

    /// The sample as exact bytes ([`crate::wire`]): `k`, the seed, then per
    /// point its index and coordinates (the hashes are recomputed on reading).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(SAMPLE_TAG);
        w.usize(self.k);
        w.u64(self.seed);
        w.usize(self.kept.len());
        for (_, i, p) in &self.kept {
            w.u64(*i);
            for c in p.coords.iter() {
                w.f64(*c);
            }
        }
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote; refuses records that
    /// hold more than `k` points or points out of hash order.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, SAMPLE_TAG, "a seeded point sample")?;
        let (k, seed, n) = (r.usize()?, r.u64()?, r.usize()?);
        if n > k || n > bytes.len() / 32 {
            return Err(r.corrupt(&format!("{n} points for a sample of {k}")));
        }
        let mut kept = Vec::with_capacity(n);
        for _ in 0..n {
            let i = r.u64()?;
            let p = Point3::new(r.f64()?, r.f64()?, r.f64()?);
            let h = index_hash(seed, i);
            if kept.last().is_some_and(|&(g, _, _)| g >= h) {
                return Err(r.corrupt("points out of hash order"));
            }
            kept.push((h, i, p));
        }
        r.end()?;
        Ok(Self { k, seed, kept })
    }
}

/// The margin around each taken cell whose points join the sample, as a
/// share of the cell's side: 0.15 x 16 = 2.4 point spacings at
/// [`POINTS_PER_CELL`]. A Delaunay triangle with its circumcentre in the
/// cell is verified (and kept) when its circumcircle stays within the
/// margin; in a uniform random point set of unit density the circumradius
/// exceeds 2.4 spacings with probability `exp(-pi r^2) (1 + pi r^2)`, about
/// 3e-7 at r = 2.4, so only slivers along the outline are lost.
const HALO: f64 = 0.15;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn algorithm_s_is_uniform_and_exact_in_size() {
        // every index of 0..20 drawn about equally often over many seeds
        let mut hits = [0usize; 20];
        for seed in 0..4000 {
            let s = sample_indices(20, 5, seed);
            assert_eq!(s.len(), 5);
            for i in s {
                hits[i] += 1;
            }
        }
        // expected 1000 each; binomial sd about 27
        assert!(hits.iter().all(|&h| (850..1150).contains(&h)), "{hits:?}");
    }

    /// A vertex of the test triangulations: parameters and point index.
    #[derive(Clone, Copy)]
    struct Vertex([f64; 2], usize);

    impl spade::HasPosition for Vertex {
        type Scalar = f64;
        fn position(&self) -> spade::Point2<f64> {
            spade::Point2::new(self.0[0], self.0[1])
        }
    }

    /// The Delaunay triangles of the points `idx` of `uv`, as sorted index
    /// triples (spade, independently of the sample).
    fn delaunay(uv: &[[f64; 2]], idx: &[usize]) -> Vec<[usize; 3]> {
        use spade::Triangulation;
        let v: Vec<Vertex> = idx.iter().map(|&i| Vertex(uv[i], i)).collect();
        let t = spade::DelaunayTriangulation::<Vertex>::bulk_load(v).unwrap();
        t.inner_faces()
            .map(|f| {
                let mut k = f.vertices().map(|v| v.data().1);
                k.sort_unstable();
                k
            })
            .collect()
    }

    /// Circumcentre and circumradius of a triangle.
    fn circle(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> ([f64; 2], f64) {
        let (bx, by, cx, cy) = (b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
        let d = 2.0 * (bx * cy - by * cx);
        let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
        let (ux, uy) = ((cy * b2 - by * c2) / d, (bx * c2 - cx * b2) / d);
        ([a[0] + ux, a[1] + uy], ux.hypot(uy))
    }

    #[test]
    fn kept_triangles_are_the_whole_sets_with_their_circumcentre_in_a_taken_cell() {
        // 40 000 jittered points over [0, 2] x [0, 1], denser on the left
        let mut rng = crate::testdata::Lcg::new(7);
        let uv: Vec<[f64; 2]> = (0..40_000)
            .map(|_| {
                let x = rng.next_f64();
                [2.0 * x * x.sqrt(), rng.next_f64()]
            })
            .collect();
        let s = CellSample::new(&uv, 8000, 5).unwrap();
        // one cell from each stratum
        let cells = s.dims[0] * s.dims[1];
        let k = s.taken.iter().filter(|&&t| t).count();
        assert_eq!(k, ((cells as f64 * 8000.0 / 40_000.0).round() as usize));
        let full = delaunay(&uv, &(0..uv.len()).collect::<Vec<_>>());
        let (mut possible, mut certain) = (std::collections::HashSet::new(), 0usize);
        for t in &full {
            let (centre, r) = circle(uv[t[0]], uv[t[1]], uv[t[2]]);
            if s.contains(centre) {
                possible.insert(*t);
                certain += usize::from(r <= s.halo[0].min(s.halo[1]));
            }
        }
        let kept: Vec<[usize; 3]> = delaunay(&uv, s.indices())
            .into_iter()
            .filter(|t| s.keeps_triangle(uv[t[0]], uv[t[1]], uv[t[2]]))
            .collect();
        // every kept triangle is one of the whole set's, with its
        // circumcentre in a taken cell ...
        assert!(kept.iter().all(|t| possible.contains(t)));
        // ... and all of those are kept but the few with a circumcircle
        // wider than the margin (slivers along the outline)
        assert!(kept.len() >= certain, "{} < {certain}", kept.len());
        assert!(
            kept.len() as f64 >= 0.995 * possible.len() as f64,
            "{} of {}",
            kept.len(),
            possible.len()
        );
        // the taken cells hold about their share of the triangles
        let share = kept.len() as f64 / full.len() as f64;
        assert!((share - 0.2).abs() < 0.03, "{share}");
    }

    fn line(n: usize) -> Vec<Point3> {
        (0..n)
            .map(|k| Point3::new(k as f64, (k % 7) as f64, 0.5 * k as f64))
            .collect()
    }

    #[test]
    fn the_hash_sample_is_the_k_smallest_hashes_however_it_is_gathered() {
        let pts = line(30_000);
        let mut once = HashSample::new(400, 77);
        once.add(0, &pts);
        // independently: sort all indices by hash, take 400
        let mut all: Vec<u64> = (0..30_000).collect();
        all.sort_by_key(|&i| index_hash(77, i));
        let mut want = all[..400].to_vec();
        want.sort_unstable();
        assert_eq!(once.indices(), want);
        let got = once.points();
        assert!(want.iter().zip(&got).all(|(&i, p)| pts[i as usize] == *p));
        // chunkings, merged in several orders and trees, through bytes
        for cuts in [
            vec![0, 1, 2, 399, 400, 401, 12_345, 30_000],
            vec![0, 30_000],
            vec![0, 7, 7, 29_999, 30_000],
            vec![0, 800, 1600, 15_000, 15_001, 30_000],
        ] {
            let parts: Vec<HashSample> = cuts
                .windows(2)
                .map(|w| {
                    let mut s = HashSample::new(400, 77);
                    s.add(w[0] as u64, &pts[w[0]..w[1]]);
                    HashSample::from_bytes(&s.to_bytes()).unwrap()
                })
                .collect();
            let mut forward = HashSample::new(400, 77);
            parts.iter().for_each(|s| forward.merge(s).unwrap());
            let mut backward = HashSample::new(400, 77);
            parts.iter().rev().for_each(|s| backward.merge(s).unwrap());
            // a tree: pairs first
            let mut tree = HashSample::new(400, 77);
            for pair in parts.chunks(2) {
                let mut t = pair[0].clone();
                pair[1..].iter().for_each(|s| t.merge(s).unwrap());
                tree.merge(&t).unwrap();
            }
            for s in [&forward, &backward, &tree] {
                assert_eq!(*s, once, "{cuts:?}");
                assert_eq!(s.to_bytes(), once.to_bytes());
            }
        }
        // fewer points than k: all of them, in index order
        let mut few = HashSample::new(400, 77);
        few.add(10, &pts[..50]);
        assert_eq!(few.indices(), (10..60).collect::<Vec<u64>>());
        assert_eq!(few.points(), pts[..50].to_vec());
        // another seed is another (uniformly drawn) sample, and refuses to merge
        let mut other = HashSample::new(400, 78);
        other.add(0, &pts);
        assert_ne!(other.indices(), want);
        assert!(other.merge(&once).unwrap_err().to_string().contains("seed"));
    }

    #[test]
    fn the_hash_sample_is_uniform() {
        // every index of 0..40 is kept about equally often over many seeds
        let pts = line(40);
        let mut hits = [0usize; 40];
        for seed in 0..4000 {
            let mut s = HashSample::new(10, seed);
            s.add(0, &pts);
            s.indices().iter().for_each(|&i| hits[i as usize] += 1);
        }
        // expected 1000 each; binomial sd about 27
        assert!(hits.iter().all(|&h| (850..1150).contains(&h)), "{hits:?}");
    }

    #[test]
    fn damaged_sample_bytes_are_refused_with_the_reason() {
        let mut s = HashSample::new(20, 5);
        s.add(0, &line(100));
        let b = s.to_bytes();
        let e = HashSample::from_bytes(&b[..b.len() - 3]).unwrap_err();
        assert!(e.to_string().contains("cut short"), "{e}");
        let mut old = b.clone();
        old[7] = b'0';
        let e = HashSample::from_bytes(&old).unwrap_err();
        assert!(e.to_string().contains("format version 0"), "{e}");
        // two points swapped: out of hash order
        let mut swapped = b.clone();
        let at = 8 + 24;
        let (x, y) = (
            swapped[at..at + 32].to_vec(),
            swapped[at + 32..at + 64].to_vec(),
        );
        swapped[at..at + 32].copy_from_slice(&y);
        swapped[at + 32..at + 64].copy_from_slice(&x);
        let e = HashSample::from_bytes(&swapped).unwrap_err();
        assert!(e.to_string().contains("hash order"), "{e}");
        // more points than k
        let mut big = b.clone();
        big[8..16].copy_from_slice(&3u64.to_le_bytes());
        assert!(HashSample::from_bytes(&big).is_err());
    }
}
