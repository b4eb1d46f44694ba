//! Seeded random samples of big point sets, for the statistical diagnostics
//! of the surface assessment ([`crate::pipeline::assess`], issue 18): the
//! median point spacing and the parameterization's fold-overs and stretch
//! are measured on a sample once a cloud has more points than
//! [`crate::pipeline::assess::AssessConfig::sample_points`].
//!
//! * [`sample_indices`]: a uniform random `k`-subset of `0..n` (Knuth,
//!   TAOCP vol. 2, 3.4.2, Algorithm S: every subset equally likely, indices
//!   in increasing order), for statistics of single points (the spacing).
//! * [`CellSample`]: whole cells of a grid over the parameters, each taken
//!   with the same probability (a cluster sample), for statistics of
//!   triangles: the Delaunay triangles of the sampled points whose
//!   circumcircle lies inside the taken cells are exactly triangles of the
//!   Delaunay triangulation of all points (nothing of the whole set lies in
//!   their circumcircles, or it would be in the sample), so fold-overs and
//!   stretch are measured on the very triangles the full computation uses,
//!   at the data's own density.
//!
//! Both draw from SplitMix64 (Steele, Lea & Flood 2014) started at a fixed
//! seed, so a sample is the same on every run, thread count and machine.

/// The seed of every sample the assessment draws (issue 18), unless its
/// configuration gives another.
pub const DEFAULT_SEED: u64 = 18;

use rayon::prelude::*;

/// Points per cell of a [`CellSample`] on average (32 x 32 points: a
/// triangle's circumcircle is a few spacings wide, so most triangles of a
/// taken cell are kept).
const POINTS_PER_CELL: f64 = 1024.0;

/// The SplitMix64 generator.
#[derive(Debug, Clone)]
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
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
/// of which the share `target / n` of the cells is taken (a uniform random
/// subset of them).
#[derive(Debug, Clone)]
pub struct CellSample {
    lo: [f64; 2],
    cell: [f64; 2],
    dims: [usize; 2],
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
    /// // about a tenth of the points, whole cells of them
    /// assert!(s.indices().len() > 10_000 && s.indices().len() < 30_000);
    /// assert!(s.indices().iter().all(|&i| s.contains(uv[i])));
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
        // the share target / n of the cells, drawn by Algorithm S
        let cells = dims[0] * dims[1];
        let k = ((cells as f64 * target as f64 / n as f64).round() as usize).clamp(1, cells);
        let mut taken = vec![false; cells];
        for c in sample_indices(cells, k, seed) {
            taken[c] = true;
        }
        let mut s = Self {
            lo,
            cell,
            dims,
            taken,
            indices: Vec::new(),
        };
        s.indices = (0..n)
            .into_par_iter()
            .filter(|&i| s.contains(uv[i]))
            .collect();
        Some(s)
    }

    /// The sampled points (indices into the parameters given, increasing).
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

    /// Whether the disc of `radius` about `centre` lies inside the taken
    /// cells (outside the grid there are no points, so that part counts as
    /// taken): every cell its bounding square meets is taken.
    pub fn contains_disc(&self, centre: [f64; 2], radius: f64) -> bool {
        if !(radius.is_finite() && centre[0].is_finite() && centre[1].is_finite()) {
            return false;
        }
        let (i0, i1) = (
            self.cell_of(centre[0] - radius, 0),
            self.cell_of(centre[0] + radius, 0),
        );
        let (j0, j1) = (
            self.cell_of(centre[1] - radius, 1),
            self.cell_of(centre[1] + radius, 1),
        );
        (i0..=i1).all(|i| (j0..=j1).all(|j| self.taken[i * self.dims[1] + j]))
    }

    /// Whether the triangle `a, b, c` of the sample's Delaunay triangulation
    /// is a triangle of the whole set's: its circumcircle lies inside the
    /// taken cells (a degenerate triangle is not kept).
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
        self.contains_disc([a[0] + ux, a[1] + uy], ux.hypot(uy))
    }
}

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

    #[test]
    fn circumcircle_test_keeps_inner_triangles_only() {
        let uv: Vec<[f64; 2]> = (0..100 * 100)
            .map(|k| [(k % 100) as f64, (k / 100) as f64])
            .collect();
        let mut s = CellSample::new(&uv, 5000, 1).unwrap();
        // take exactly the left half of the cells
        let dims = s.dims;
        for i in 0..dims[0] {
            for j in 0..dims[1] {
                s.taken[i * dims[1] + j] = (i as f64 + 0.5) * s.cell[0] < 49.5;
            }
        }
        // a small triangle deep in the left half is kept, one at x = 60 is not
        assert!(s.keeps_triangle([10.0, 10.0], [11.0, 10.0], [10.0, 11.0]));
        assert!(!s.keeps_triangle([60.0, 10.0], [61.0, 10.0], [60.0, 11.0]));
        // a flat triangle whose circumcircle reaches into the right half is not
        assert!(!s.keeps_triangle([10.0, 50.0], [40.0, 50.0], [25.0, 50.5]));
        // nor a degenerate one
        assert!(!s.keeps_triangle([1.0, 1.0], [2.0, 2.0], [3.0, 3.0]));
        // beyond the grid counts as taken: a triangle on the left edge is kept
        assert!(s.keeps_triangle([0.0, 10.0], [1.0, 10.0], [0.0, 11.0]));
    }
}
