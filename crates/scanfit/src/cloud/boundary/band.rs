//! The band of a big cloud's projection that holds its alpha shape's
//! boundary, and the loops from the triangulation of that band alone.
//!
//! Grid the projection with square cells of side `h = alpha / 6`.
//!
//! * A boundary vertex `p` lies on the circle of an open disc of radius
//!   `alpha` that holds no point: across a boundary edge lies a triangle
//!   with circumradius `R >= alpha` (its open circumdisc holds no point and
//!   contains the disc of radius `alpha` tangent to its circle at `p`) or the
//!   open half-plane beyond the hull (which contains that disc too). Let `c`
//!   be the cell of the disc's centre `o`. A cell `c + (a, b)` lies within
//!   `h sqrt((|a| + 1)^2 + (|b| + 1)^2)` of `o`, so the cells with
//!   `(|a| + 1)^2 + (|b| + 1)^2 < 36` (the *template*: rows of half-width
//!   4, 4, 4, 3, 2 cells at row offsets 0 to 4, 69 cells, all within
//!   `0.972 alpha` of `o`, far from the circle beyond any rounding) lie
//!   inside the disc and are empty. `p` is `alpha` (6 cells) from `o`, so
//!   within 7 cells of `c`, 8 with the rounding of its cell index. Hence
//!   every boundary vertex is in a *candidate* cell: an occupied cell with
//!   the centre of an empty template within [`NEAR`] cells (cells beyond the
//!   points' bounding box are empty; the grid is padded by `REACH`).
//! * A kept triangle (`R < alpha`) with a vertex `p` has its circumdisc, and
//!   so its other vertices, within `2R < 2 alpha` of `p`. If the triangulated
//!   set holds every point within `2 alpha` of `p` (every point of the cells
//!   within `REACH` of `p`'s cell: the *band*), such a triangle is empty
//!   with respect to the band exactly when it is with respect to all points:
//!   the band's kept triangles at candidate points are the full
//!   triangulation's, and an edge between candidate points is a boundary
//!   edge (one kept triangle on its left, none on its right) in one exactly
//!   when it is in the other.
//!
//! So the boundary edges between candidate points of the band's
//! triangulation are the full alpha shape's boundary edges, chained into the
//! same loops in the same order. (Where 4 or more points are cocircular the
//! two triangulations may split a Delaunay cell differently; its triangles
//! share one circumradius, so they are all kept or all dropped and the
//! boundary edges, sides of the cells, are the same. Only a circumradius
//! within rounding, ~1e-15 relative, of `alpha` could be decided apart.)
//! `REACH` is 14 cells rather than 13 to leave room for the rounding of the
//! cell index. With the local factors of [`super::local`] (at least 1, so
//! the candidates are the same) a kept triangle reaches `2 alpha F`, `F` its
//! factor; the candidate cells whose surroundings have factors above 1 are
//! dilated further, by the reach [`LocalSpacing::bound`] gives.
//!
//! Why a template of small cells: a single empty cell of side `alpha / 2`
//! would do for the proof, but on a uniform random sample at the default
//! alpha such a cell is empty with probability 17%, so nearly every point
//! would be a candidate; an empty template (1.92 alpha^2, about 14 points
//! expected at the default alpha) is rare inside a patch: on 10^7 uniform
//! points the 7 x 7 blocks used before (1.36 alpha^2, about 10 points)
//! were empty often enough to put a tenth of the points in the band. The
//! grid costs two bytes per cell
//! (flags and one row buffer), about five cells per point on a cloud that
//! fills its bounding box; a grid of more than `8 n + 2^20` cells (an
//! outlier stretching the box, or a tiny alpha) is not built and the whole
//! cloud is triangulated instead.

use super::local::LocalSpacing;
use super::{Boundary, Frame, Site, SiteTriangulation};
use crate::Result;

/// Cells per alpha.
const CELLS_PER_ALPHA: f64 = 6.0;
/// Half the side of the square inside the template, in cells (7 x 7).
const HALF_BLOCK: usize = 3;
/// Half-widths of the template's rows at row offsets 0 to 4 (see the
/// module documentation).
const TEMPLATE: [usize; 5] = [4, 4, 4, 3, 2];
/// Cells between a candidate and the centre of an empty template.
const NEAR: usize = 8;
/// Cells between a point's cell and the cells that decide about it.
const REACH: usize = 14;
/// Occupied cell.
const OCC: u8 = 1;
/// The template around the cell holds an occupied cell (else the cell is
/// the centre of an empty template).
const NEAR_OCC: u8 = 2;
/// The centre of an empty template lies within `NEAR`.
const NEAR_EMPTY: u8 = 4;
/// A candidate cell (occupied, empty block near).
const CANDIDATE: u8 = OCC | NEAR_EMPTY;
/// A candidate cell lies within `REACH`: its points are triangulated.
const BAND: u8 = 8;
/// Bits of a candidate cell's reach class `k` (reach `REACH + CLASS_STEP k` cells)
/// where the local alpha is wider than the global one.
const CLASS_SHIFT: u8 = 4;
/// Reach added per class, in cells.
const CLASS_STEP: usize = 4;

/// The loops of the alpha shape of radius `alpha` (times the local factors
/// of `local`) from the triangulation of the band; `None` when the grid
/// would be too large.
///
/// With local factors a kept triangle at a candidate point reaches further
/// than `2 alpha`; [`LocalSpacing::bound`] bounds how far from the factors
/// around the point, and the candidate cells are dilated by that reach
/// (in classes of [`CLASS_STEP`] cells) instead of [`REACH`]. The candidate
/// cells stay the same: a boundary vertex still lies on an empty disc of
/// radius at least `alpha` (the factors are at least 1).
pub(super) fn band_loops(
    frame: &Frame,
    alpha: f64,
    spacing: f64,
    local: Option<&LocalSpacing>,
) -> Result<Option<Boundary>> {
    let alpha_unit = alpha / frame.extent;
    let n = frame.len();
    let Some(mut grid) = Grid::new(frame, alpha_unit / CELLS_PER_ALPHA, n) else {
        return Ok(None);
    };
    for q in frame.units() {
        let c = grid.cell(q);
        grid.flags[c] |= OCC;
    }
    grid.dilate(|f| f & OCC != 0, HALF_BLOCK, NEAR_OCC);
    grid.template_rest();
    grid.dilate(|f| f & NEAR_OCC == 0, NEAR, NEAR_EMPTY);
    grid.dilate(|f| f & CANDIDATE == CANDIDATE, REACH, BAND);
    if let Some(l) = local.filter(|l| l.max > 1.0) {
        let classes = grid.classify(l, alpha_unit);
        for k in 1..16u8 {
            if classes & (1 << k) != 0 {
                let is_k = move |f: u8| f & CANDIDATE == CANDIDATE && f >> CLASS_SHIFT == k;
                grid.dilate(is_k, REACH + CLASS_STEP * usize::from(k), BAND);
            }
        }
    }
    let mut sites = Vec::new();
    let mut candidates = 0usize;
    for (index, pos) in frame.units().enumerate() {
        let f = grid.flags[grid.cell(pos)];
        let inner = f & CANDIDATE == CANDIDATE;
        candidates += usize::from(inner);
        if f & BAND != 0 {
            sites.push(Site { pos, index, inner });
        }
    }
    drop(grid);
    let tri = SiteTriangulation::new(sites, frame)?;
    let a = tri.alpha_loops(alpha_unit, local)?;
    // Euler's formula for the kept region with its pinch vertices split
    // (a union of planar domains): T = 2 V_inner + E_loops - 2 chi, where
    // chi = outer loops - hole loops and every point off the candidate
    // cells is an inner vertex (else an empty disc of radius alpha would
    // touch it)
    let mut on_loop = vec![false; tri.sites.len()];
    let mut loop_edges = 0i64;
    for l in &a.loops {
        loop_edges += l.len() as i64;
        for &v in l {
            on_loop[v] = true;
        }
    }
    let inner_candidates = (0..tri.sites.len())
        .filter(|&v| tri.sites[v].inner && a.on_kept[v] && !on_loop[v])
        .count();
    let inner = (n - candidates - tri.outer_repeats + inner_candidates) as i64;
    let b = a.to_boundary(&tri, frame, (alpha, local), spacing, 0)?;
    let chi: i64 = b.areas.iter().map(|&x| if x > 0.0 { 1 } else { -1 }).sum();
    let triangles = (2 * inner + loop_edges - 2 * chi).max(0) as usize;
    Ok(Some(super::fill_small_holes(
        Boundary { triangles, ..b },
        frame,
        local,
    )))
}

/// One byte of flags per cell of side `h` over the unit bounding box,
/// padded by [`REACH`] cells; cell `(i, j)` at `j * dims[0] + i`.
struct Grid {
    lo: [f64; 2],
    h: f64,
    dims: [usize; 2],
    flags: Vec<u8>,
}

impl Grid {
    fn new(frame: &Frame, h: f64, n: usize) -> Option<Self> {
        let limit = (8 * n + (1 << 20)) as f64;
        let cells = |k: usize| ((frame.hi[k] - frame.lo[k]) / h).floor() + 1.0 + 2.0 * REACH as f64;
        let (nx, ny) = (cells(0), cells(1));
        if !(h > 0.0 && nx.is_finite() && ny.is_finite() && nx * ny <= limit) {
            return None;
        }
        let dims = [nx as usize, ny as usize];
        Some(Self {
            lo: frame.lo,
            h,
            dims,
            flags: vec![0; dims[0] * dims[1]],
        })
    }

    /// Marks `NEAR_OCC` on the cells whose 7 x 7 square is empty but whose
    /// template is not: the template's cells beyond the square (rows 4
    /// away, columns 4 away) are checked directly; such centres are rare.
    fn template_rest(&mut self) {
        let [nx, ny] = self.dims;
        let occ = |flags: &[u8], i: isize, j: isize| {
            i >= 0
                && j >= 0
                && (i as usize) < nx
                && (j as usize) < ny
                && flags[j as usize * nx + i as usize] & OCC != 0
        };
        for c in 0..self.flags.len() {
            if self.flags[c] & NEAR_OCC != 0 {
                continue;
            }
            let (i, j) = ((c % nx) as isize, (c / nx) as isize);
            let beyond = (HALF_BLOCK + 1..TEMPLATE.len()).any(|a| {
                let (a, w) = (a as isize, TEMPLATE[a] as isize);
                (-w..=w).any(|b| {
                    occ(&self.flags, i + b, j + a)
                        || occ(&self.flags, i + b, j - a)
                        || occ(&self.flags, i + a, j + b)
                        || occ(&self.flags, i - a, j + b)
                })
            });
            if beyond {
                self.flags[c] |= NEAR_OCC;
            }
        }
    }

    /// The centre of cell `c` in unit coordinates.
    fn centre(&self, c: usize) -> [f64; 2] {
        let (i, j) = (c % self.dims[0], c / self.dims[0]);
        let at = |k: usize, i: usize| self.lo[k] + (i as f64 - REACH as f64 + 0.5) * self.h;
        [at(0, i), at(1, j)]
    }

    /// Stores in each candidate cell its reach class (the reach that
    /// [`LocalSpacing::bound`] asks beyond [`REACH`], in steps of
    /// [`CLASS_STEP`]); returns the classes present as bits.
    fn classify(&mut self, local: &LocalSpacing, alpha_unit: f64) -> u16 {
        let mut present = 0u16;
        // per coarse cell of `local`: its class, or u8::MAX before it is asked
        let mut cache = vec![u8::MAX; local.cells()];
        for c in 0..self.flags.len() {
            if self.flags[c] & CANDIDATE != CANDIDATE {
                continue;
            }
            let q = self.centre(c);
            let coarse = local.cell(q);
            if cache[coarse] == u8::MAX {
                // kept triangles at the cell's points lie within 2 alpha F
                // of them: 12 F cells, plus two for the rounding of the
                // cell indices and one as the cell's points lie within
                // half a cell of its centre (REACH when F = 1)
                let f = local.bound(q, alpha_unit);
                let class = if f > 1.0 {
                    let reach = (2.0 * alpha_unit * f / self.h).ceil() as usize + 3;
                    reach.saturating_sub(REACH).div_ceil(CLASS_STEP).min(15)
                } else {
                    0
                };
                cache[coarse] = class as u8;
            }
            let k = cache[coarse];
            self.flags[c] |= k << CLASS_SHIFT;
            present |= 1 << k;
        }
        present
    }

    fn cell(&self, q: [f64; 2]) -> usize {
        let idx = |k: usize| {
            let c = ((q[k] - self.lo[k]) / self.h).floor();
            let c = if c > 0.0 { c as usize } else { 0 };
            c.min(self.dims[k] - 2 * REACH - 1) + REACH
        };
        idx(1) * self.dims[0] + idx(0)
    }

    /// Sets `bit` on every cell with a cell satisfying `src` within `r`
    /// cells (Chebyshev distance): a sliding window count along the rows,
    /// then along the columns.
    fn dilate(&mut self, src: impl Fn(u8) -> bool, r: usize, bit: u8) {
        let [nx, ny] = self.dims;
        let mut rows = vec![0u8; self.flags.len()];
        for (row, out) in self.flags.chunks_exact(nx).zip(rows.chunks_exact_mut(nx)) {
            let mut count: usize = row[..=r.min(nx - 1)].iter().filter(|&&f| src(f)).count();
            for i in 0..nx {
                out[i] = u8::from(count > 0);
                if i + r + 1 < nx {
                    count += usize::from(src(row[i + r + 1]));
                }
                if i >= r {
                    count -= usize::from(src(row[i - r]));
                }
            }
        }
        let mut cols = vec![0u16; nx];
        let add = |cols: &mut [u16], row: &[u8], sign: i16| {
            for (c, &v) in cols.iter_mut().zip(row) {
                *c = c.wrapping_add_signed(sign * i16::from(v));
            }
        };
        for j in 0..=r.min(ny - 1) {
            add(&mut cols, &rows[j * nx..(j + 1) * nx], 1);
        }
        for j in 0..ny {
            for (f, &c) in self.flags[j * nx..(j + 1) * nx].iter_mut().zip(&cols) {
                if c > 0 {
                    *f |= bit;
                }
            }
            if j + r + 1 < ny {
                add(&mut cols, &rows[(j + r + 1) * nx..(j + r + 2) * nx], 1);
            }
            if j >= r {
                add(&mut cols, &rows[(j - r) * nx..(j - r + 1) * nx], -1);
            }
        }
    }
}
