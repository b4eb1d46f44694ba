//! The local point spacing that widens the alpha radius where a cloud's
//! points thin out.
//!
//! [PDE23] §4.1 takes one alpha for the whole patch. A scan whose density
//! falls towards its outline (a face scanned from the front, a terrain
//! scanned from one station) then has an alpha that is a fraction of the
//! spacing where the points are sparse, and the alpha shape bites bays and
//! notches into the outline there. Here the radius follows the density: a
//! Delaunay triangle is kept when its circumradius is below
//! `alpha * f`, where `f` is the median of a *local factor* at its three
//! vertices (the median, so that one stray point with a large factor cannot
//! pull in the big triangles it makes with the outline). The factor is the
//! local spacing over the global one, counted only where it exceeds
//! [`THRESHOLD`] (the estimate's noise on a uniform sample), and capped at
//! [`CAP`]:
//!
//! * square cells of side `4/3 alpha` (8 cells of the band's grid,
//!   [`super::band`]) count the points;
//! * a cell's local spacing is `sqrt(A / N)` over the smallest square window
//!   of `(2w + 1)^2` cells around it (`w >= 1`) holding at least
//!   [`WINDOW_POINTS`] points: `N` those points, `A` the area of the window's
//!   cells that hold a point or lie between two that do (so the empty plane
//!   beyond the outline or inside a large hole is not counted as area, while
//!   the gaps between the points of a sparse region are); where fewer than
//!   70% of those cells hold a point (a region sparser than about one point
//!   per cell, whose gaps are then undercounted), the same is measured on
//!   cells of twice the side, up to 8 times;
//! * the factor of a cell is its spacing over the median spacing over the
//!   points when that ratio exceeds `THRESHOLD`, else 1; at most `CAP`;
//!   then each cell takes the largest factor of the windows that cover it
//!   (so a sparse region's factor reaches the edge of the region, where the
//!   windows of the cells themselves lean into the dense side);
//! * holes of the alpha shape smaller in area than the square of their
//!   local alpha are filled ([`super::fill_small_holes`]).
//!
//! On a sample of even density every factor is 1 and the alpha shape is
//! [PDE23]'s (the tests check it point for point); where the spacing is `k`
//! times the median (`k > THRESHOLD`), alpha grows by `k`, so it is the
//! same number of local spacings as elsewhere of median ones. A hole stays
//! open where it is wider than twice the local alpha, as in [PDE23] with the
//! global one. Departure from [PDE23] (and from Edelsbrunner's alpha
//! shape, one radius everywhere): the radius varies with the density;
//! [`super::BoundaryConfig::local_alpha`] `= false` gives the paper's alpha
//! shape. A given alpha ([`super::BoundaryConfig::alpha`]) is the radius
//! where the points are not sparser than the median; the grid of factors
//! is skipped (one alpha everywhere) when it would have more than `2 n +
//! 2^16` cells (an alpha far below the spacing, or outliers stretching the
//! bounding box).

use super::Frame;

/// Points a window must hold: the spacing from 128 points has a relative
/// standard deviation of about 4.4% on a uniform sample.
pub(super) const WINDOW_POINTS: u64 = 128;
/// The local spacing counts where it exceeds this multiple of the median
/// one, so that the estimate's noise on a sample of even density leaves
/// every factor at 1 (the tests measure it).
pub const THRESHOLD: f64 = 1.25;
/// Largest factor: a region up to 5 times sparser (in spacing) than the
/// median gets its own alpha; the band of a big cloud is at most this much
/// wider there.
pub const CAP: f64 = 5.0;
/// Coarse cells per alpha (side `alpha / CELLS_PER_ALPHA`): 8 cells of the
/// band grid's `alpha / 6`.
pub(super) const CELLS_PER_ALPHA: f64 = 0.75;
/// Largest window half-width in cells.
const MAX_HALF_WIDTH: usize = 24;

/// The local factor per coarse cell over the projection's bounding box.
#[derive(Debug, Clone)]
pub(super) struct LocalSpacing {
    lo: [f64; 2],
    side: f64,
    dims: [usize; 2],
    /// Per cell, `j * dims[0] + i`: the factor, in `[1, CAP]`.
    factor: Vec<f64>,
    /// Largest factor.
    pub(super) max: f64,
}

impl LocalSpacing {
    /// The factors of the points of `frame` at the alpha radius
    /// `alpha_unit` (unit coordinates); `None` when the grid would hold
    /// more than `2 n + 2^16` cells (an outlier stretching the bounding
    /// box, or a tiny alpha): the caller keeps the global alpha.
    pub(super) fn new(frame: &Frame, alpha_unit: f64) -> Option<Self> {
        let n = frame.len();
        let side = alpha_unit / CELLS_PER_ALPHA;
        let cells = |k: usize| ((frame.hi[k] - frame.lo[k]) / side).floor() + 1.0;
        let (nx, ny) = (cells(0), cells(1));
        let limit = (2 * n + (1 << 16)) as f64;
        if !(side > 0.0 && nx.is_finite() && ny.is_finite() && nx * ny <= limit) {
            return None;
        }
        let dims = [nx as usize, ny as usize];
        let mut grid = Self {
            lo: frame.lo,
            side,
            dims,
            factor: Vec::new(),
            max: 1.0,
        };
        let mut counts = vec![0u32; dims[0] * dims[1]];
        for q in frame.units() {
            let c = grid.cell(q);
            counts[c] = counts[c].saturating_add(1);
        }
        let (raw, half_widths) = cell_spacings(&counts, dims);
        // the median spacing over the points (each cell weighs its count)
        let mut order: Vec<usize> = (0..counts.len()).filter(|&c| counts[c] > 0).collect();
        order.sort_unstable_by(|&a, &b| raw[a].total_cmp(&raw[b]).then(a.cmp(&b)));
        let half = counts.iter().map(|&c| u64::from(c)).sum::<u64>() / 2;
        let mut seen = 0u64;
        let mut median = f64::NAN;
        for &c in &order {
            seen += u64::from(counts[c]);
            if seen > half {
                median = raw[c];
                break;
            }
        }
        if median.is_nan() || median <= 0.0 {
            return None;
        }
        grid.factor = raw
            .iter()
            .zip(&counts)
            .map(|(&r, &c)| {
                let ratio = r / median;
                if c == 0 || ratio <= THRESHOLD {
                    1.0
                } else {
                    ratio.min(CAP)
                }
            })
            .collect();
        grid.spread(&half_widths);
        grid.max = grid.factor.iter().copied().fold(1.0, f64::max);
        Some(grid)
    }

    /// Gives every cell the largest factor of the cells whose windows
    /// cover it: a window's spacing holds for its whole window. Where the
    /// density falls, the windows of the cells near the change reach into
    /// the dense side and lag behind the sparse spacing; the sparse cells
    /// further out, whose windows reach the change, carry their factor to
    /// it (else the alpha shape opens holes of a spacing or so there).
    fn spread(&mut self, half_widths: &[u32]) {
        let [nx, ny] = self.dims;
        let mut out = self.factor.clone();
        for (c, &f) in self.factor.iter().enumerate() {
            if f <= 1.0 {
                continue;
            }
            let w = half_widths[c] as usize;
            let (i, j) = (c % nx, c / nx);
            for jj in j.saturating_sub(w)..=(j + w).min(ny - 1) {
                for v in &mut out[jj * nx + i.saturating_sub(w)..=jj * nx + (i + w).min(nx - 1)] {
                    *v = v.max(f);
                }
            }
        }
        self.factor = out;
    }

    /// Number of cells.
    pub(super) fn cells(&self) -> usize {
        self.factor.len()
    }

    /// The cell of unit coordinates `q`.
    #[inline]
    pub(super) fn cell(&self, q: [f64; 2]) -> usize {
        let idx = |k: usize| {
            let c = ((q[k] - self.lo[k]) / self.side).floor();
            let c = if c > 0.0 { c as usize } else { 0 };
            c.min(self.dims[k] - 1)
        };
        idx(1) * self.dims[0] + idx(0)
    }

    /// The factor at unit coordinates `q`.
    #[inline]
    pub(super) fn at(&self, q: [f64; 2]) -> f64 {
        self.factor[self.cell(q)]
    }

    /// The factor of a triangle: the median of its vertices' factors.
    #[inline]
    pub(super) fn triangle(&self, a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
        let (x, y, z) = (self.at(a), self.at(b), self.at(c));
        x.max(y).min(x.min(y).max(z))
    }

    /// A bound `F` on the factor of a kept triangle at a point of the cell
    /// of `q`: such a triangle has circumradius `R < alpha F_t`, `F_t` its
    /// factor, the median of its vertices' (so at most the largest within
    /// `2R` of the point), and all of it lies within `2R`. Scanning rings of
    /// cells outward, a ring `r` (at least `(r - 1) side` away) can hold a
    /// vertex of such a triangle only if `(r - 1) side < 2 alpha phi_r`,
    /// `phi_r` the largest factor up to ring `r`; the largest such `phi_r`
    /// bounds `F_t`, so every kept triangle at the point lies within
    /// `2 alpha F`. (`r - 2` is used: `q` may be a band cell's centre, in the
    /// neighbouring cell of some of that band cell's points.)
    pub(super) fn bound(&self, q: [f64; 2], alpha_unit: f64) -> f64 {
        let c = self.cell(q);
        let (ci, cj) = ((c % self.dims[0]) as isize, (c / self.dims[0]) as isize);
        let rings = (2.0 * alpha_unit * CAP / self.side).ceil() as isize + 2;
        let (mut phi, mut bound) = (1.0f64, 1.0f64);
        for r in 0..=rings {
            for (i, j) in ring(ci, cj, r) {
                if i >= 0 && j >= 0 && (i as usize) < self.dims[0] && (j as usize) < self.dims[1] {
                    phi = phi.max(self.factor[j as usize * self.dims[0] + i as usize]);
                }
            }
            if (r - 2).max(0) as f64 * self.side < 2.0 * alpha_unit * phi {
                bound = bound.max(phi);
            }
        }
        bound
    }
}

/// The cells `(i, j)` at Chebyshev distance `r` from `(ci, cj)`.
fn ring(ci: isize, cj: isize, r: isize) -> impl Iterator<Item = (isize, isize)> {
    (-r..=r).flat_map(move |dj| {
        let step = if dj.abs() == r { 1 } else { (2 * r).max(1) };
        (-r..=r)
            .step_by(step as usize)
            .map(move |di| (ci + di, cj + dj))
    })
}

/// Per cell: the local spacing in cells (0 for empty cells), from the
/// finest of [`LEVELS`] cell sizes (1, 2, 4, ... cells) whose window holds
/// at least [`MIN_OCCUPANCY`] occupied cells among its covered ones (a
/// sparse region, where most small cells are empty, is measured on larger
/// cells; the coarsest level is taken when none is).
fn cell_spacings(counts: &[u32], dims: [usize; 2]) -> (Vec<f64>, Vec<u32>) {
    let [nx, ny] = dims;
    let mut out = vec![0.0; nx * ny];
    let mut half = vec![0u32; nx * ny];
    let mut todo: Vec<usize> = (0..nx * ny).filter(|&c| counts[c] > 0).collect();
    let mut level_counts = counts.to_vec();
    let mut level_dims = dims;
    for level in 0..LEVELS {
        let last = level + 1 == LEVELS;
        let at = Level::new(&level_counts, level_dims);
        let size = 1usize << level;
        todo.retain(|&c| {
            let (i, j) = ((c % nx) / size, (c / nx) / size);
            let (spacing, occupancy, w) = at.window(i, j);
            if occupancy >= MIN_OCCUPANCY || last {
                out[c] = spacing * size as f64;
                half[c] = (w * size) as u32;
                false
            } else {
                true
            }
        });
        if todo.is_empty() || last {
            break;
        }
        // the next level: 2 x 2 cells summed
        let next = [level_dims[0].div_ceil(2), level_dims[1].div_ceil(2)];
        let mut sum = vec![0u32; next[0] * next[1]];
        for j in 0..level_dims[1] {
            for i in 0..level_dims[0] {
                let k = (j / 2) * next[0] + i / 2;
                sum[k] = sum[k].saturating_add(level_counts[j * level_dims[0] + i]);
            }
        }
        level_counts = sum;
        level_dims = next;
    }
    (out, half)
}

/// Levels of cell size tried by [`cell_spacings`] (cells up to 8 times the
/// finest, 32/3 alpha).
const LEVELS: usize = 4;
/// Share of a window's covered cells that must hold a point for its level
/// to measure the spacing (a uniform sample of 1.4 points per cell has
/// about 0.76).
const MIN_OCCUPANCY: f64 = 0.7;

/// The counts of one level of cells, summed for windows.
struct Level {
    dims: [usize; 2],
    counts: SummedArea,
    covered: SummedArea,
    occupied: SummedArea,
}

impl Level {
    fn new(counts: &[u32], dims: [usize; 2]) -> Self {
        let [nx, ny] = dims;
        let occ = |i: isize, j: isize| {
            i >= 0
                && j >= 0
                && (i as usize) < nx
                && (j as usize) < ny
                && counts[j as usize * nx + i as usize] > 0
        };
        // a cell counts as area when it holds a point or lies between two
        // that do (opposite neighbours): the gaps of a sparse region count,
        // the plane beyond the outline or inside a hole does not
        let mut covered = vec![0u32; nx * ny];
        let mut occupied = vec![0u32; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let (ii, jj) = (i as isize, j as isize);
                let here = counts[j * nx + i] > 0;
                let between = [(1, 0), (0, 1), (1, 1), (1, -1)]
                    .iter()
                    .any(|&(di, dj)| occ(ii + di, jj + dj) && occ(ii - di, jj - dj));
                covered[j * nx + i] = u32::from(here || between);
                occupied[j * nx + i] = u32::from(here);
            }
        }
        Self {
            dims,
            counts: SummedArea::new(counts, dims),
            covered: SummedArea::new(&covered, dims),
            occupied: SummedArea::new(&occupied, dims),
        }
    }

    /// The spacing `sqrt(A / N)` (in this level's cells) of the smallest
    /// window of `(2w + 1)^2` cells (`w >= 1`) around `(i, j)` holding
    /// [`WINDOW_POINTS`] points (or the largest, [`MAX_HALF_WIDTH`]), `N`
    /// its points and `A` its covered cells, and the share of those that
    /// hold a point, and `w`.
    fn window(&self, i: usize, j: usize) -> (f64, f64, usize) {
        let [nx, ny] = self.dims;
        let mut w = 1;
        loop {
            let (i0, i1) = (i.saturating_sub(w), (i + w).min(nx - 1));
            let (j0, j1) = (j.saturating_sub(w), (j + w).min(ny - 1));
            let n = self.counts.sum(i0, i1, j0, j1);
            let whole = i0 == 0 && j0 == 0 && i1 == nx - 1 && j1 == ny - 1;
            if n >= WINDOW_POINTS || w >= MAX_HALF_WIDTH || whole {
                let a = self.covered.sum(i0, i1, j0, j1) as f64;
                let o = self.occupied.sum(i0, i1, j0, j1) as f64;
                return ((a / n as f64).sqrt(), o / a, w);
            }
            w += 1;
        }
    }
}

/// Sums over rectangles of cells in constant time.
struct SummedArea {
    nx1: usize,
    s: Vec<u64>,
}

impl SummedArea {
    fn new(v: &[u32], [nx, ny]: [usize; 2]) -> Self {
        let nx1 = nx + 1;
        let mut s = vec![0u64; nx1 * (ny + 1)];
        for j in 0..ny {
            let mut row = 0u64;
            for i in 0..nx {
                row += u64::from(v[j * nx + i]);
                s[(j + 1) * nx1 + i + 1] = s[j * nx1 + i + 1] + row;
            }
        }
        Self { nx1, s }
    }

    /// The sum over cells `i0..=i1` x `j0..=j1`.
    fn sum(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> u64 {
        let at = |i: usize, j: usize| self.s[j * self.nx1 + i];
        at(i1 + 1, j1 + 1) + at(i0, j0) - at(i0, j1 + 1) - at(i1 + 1, j0)
    }
}

/// Random points of the disc of radius 1 (or, `square`, of the square
/// `[-1, 1]^2`): `dense` points per unit area within `core` of the centre
/// (Chebyshev distance for the square), `ratio^2` times fewer outside (a
/// spacing `ratio` times larger), none in the round `hole` (centre,
/// radius).
#[cfg(test)]
pub(super) fn sparse_rim(
    dense: f64,
    ratio: f64,
    core: f64,
    hole: Option<([f64; 2], f64)>,
    square: bool,
    seed: u64,
) -> Vec<crate::Point3> {
    let mut rng = crate::testdata::SplitMix64::new(seed);
    // thinning a uniform sample of the bounding square keeps it uniform
    // in each region
    let n = (4.0 * dense) as usize;
    let mut p = Vec::new();
    for _ in 0..n {
        let (x, y) = (2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
        let keep = rng.uniform();
        let r = if square {
            x.abs().max(y.abs())
        } else {
            x.hypot(y)
        };
        let in_hole = hole.is_some_and(|(c, h)| (x - c[0]).hypot(y - c[1]) < h);
        if r <= 1.0 && !in_hole && (r < core || keep < 1.0 / (ratio * ratio)) {
            p.push(crate::Point3::new(x, y, 0.05 * x * y));
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::boundary::{boundary_loops, Boundary, BoundaryConfig};
    use crate::Point3;

    fn loops(p: &[Point3], local_alpha: bool) -> Boundary {
        let cfg = BoundaryConfig {
            local_alpha,
            ..Default::default()
        };
        boundary_loops(p, &cfg).unwrap()
    }

    /// Distance from `q` to the closed polygon of `p[l]` (plane x, y).
    fn to_polygon(q: [f64; 2], p: &[Point3], l: &[usize]) -> f64 {
        (0..l.len())
            .map(|k| {
                let (a, b) = (p[l[k]], p[l[(k + 1) % l.len()]]);
                let (dx, dy) = (b.x - a.x, b.y - a.y);
                let t =
                    (((q[0] - a.x) * dx + (q[1] - a.y) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
                (q[0] - a.x - t * dx).hypot(q[1] - a.y - t * dy)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Hausdorff distance between the outer loop and the true outline (the
    /// unit circle, or the square's border), both ways: loop points to the
    /// outline, outline samples to the loop polygon.
    fn hausdorff(p: &[Point3], b: &Boundary, square: bool) -> f64 {
        let l = b.outer_loop();
        let outline = |x: f64, y: f64| {
            if square {
                (1.0 - x.abs()).min(1.0 - y.abs()).abs()
            } else {
                (1.0 - x.hypot(y)).abs()
            }
        };
        let out = l
            .iter()
            .map(|&i| outline(p[i].x, p[i].y))
            .fold(0.0, f64::max);
        let samples = (0..2000).map(|k| {
            let t = k as f64 / 2000.0;
            if square {
                let s = 8.0 * t;
                let (side, u) = ((s / 2.0).floor(), s % 2.0 - 1.0);
                match side as i32 {
                    0 => [u, -1.0],
                    1 => [1.0, u],
                    2 => [-u, 1.0],
                    _ => [-1.0, -u],
                }
            } else {
                let a = std::f64::consts::TAU * t;
                [a.cos(), a.sin()]
            }
        });
        samples.map(|q| to_polygon(q, p, l)).fold(out, f64::max)
    }

    #[test]
    fn even_samples_keep_the_papers_alpha_shape() {
        // the factors stay 1 on uniform random samples (the cell spacings
        // stay below THRESHOLD times their median), so the loops are
        // [PDE23]'s point for point, through the full triangulation and
        // (250,000 points) through the band
        let mut rng = crate::testdata::SplitMix64::new(5);
        for n in [10_000, 60_000, 250_000] {
            let p: Vec<Point3> = (0..n)
                .map(|_| Point3::new(rng.uniform(), 0.5 * rng.uniform(), 0.0))
                .collect();
            let (l, g) = (loops(&p, true), loops(&p, false));
            assert_eq!(l.local_factor, 1.0, "n = {n}");
            assert_eq!(l, g, "n = {n}");
        }
    }

    #[test]
    fn sparse_rims_are_followed_within_a_local_spacing() {
        // a dense core (spacing s) in a disc or square whose rim is 3 or 5
        // times sparser (spacing ratio * s), a round hole of 5 rim spacings
        // radius in the rim: [PDE23]'s one alpha (2.5 s, below the rim's
        // spacing) shreds the rim into bays and spurious holes; the local
        // alpha follows the true outline within 2 rim spacings and keeps
        // the hole as the one inner loop
        for (ratio, square, seed) in [(3.0, false, 1), (5.0, false, 2), (3.0, true, 3)] {
            let dense: f64 = 40_000.0;
            let s_rim = ratio * 1.07 / dense.sqrt();
            let hole = ([0.0, -0.75], 5.0 * s_rim);
            let p = sparse_rim(dense, ratio, 0.5, Some(hole), square, seed);
            let (l, g) = (loops(&p, true), loops(&p, false));
            let name = format!("ratio {ratio}, square {square}");
            let dl = hausdorff(&p, &l, square) / s_rim;
            let dg = hausdorff(&p, &g, square) / s_rim;
            eprintln!(
                "{name}: {} points, local: {} loops, factor {:.2}, Hausdorff {dl:.2} rim spacings; global: {} loops, {dg:.2}",
                p.len(),
                l.loops.len(),
                l.local_factor,
                g.loops.len(),
            );
            assert!(dl < 2.0, "{name}: {dl}");
            assert!(dg > 3.0 && g.loops.len() > 10, "{name}: {dg}");
            assert_eq!(l.loops.len(), 2, "{name}: {:?}", l.areas);
            // the inner loop is the hole: its area is the disc's, less
            // the band of a spacing along its rim the alpha shape cuts
            let inner = 1 - l.outer;
            let a = -l.areas[inner];
            let exact = std::f64::consts::PI * hole.1 * hole.1;
            assert!(a > exact && a < exact * 1.6, "{name}: hole {a} of {exact}");
        }
    }
}
