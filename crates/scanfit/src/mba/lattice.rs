//! The uniform cubic B-spline control lattice of [MBA18]s and its
//! B-spline approximation (BA) of scattered values.
//!
//! A lattice of `(m + 3) x (n + 3)` values `phi` over the rectangle
//! `[0, m] x [0, n]` of lattice coordinates defines ([MBA18] eq. 1)
//! `f(x, y) = sum_{k,l=0..3} B_k(s) B_l(t) phi_(i+k)(j+l)` with
//! `i = floor(x) - 1`, `j = floor(y) - 1`, `s = x - floor(x)`,
//! `t = y - floor(y)` and the uniform cubic B-spline basis `B_0..B_3`. The
//! paper numbers the lattice from -1; here index `a = i + 1` runs from 0.

use super::sums::BaAccumulator;
use crate::{Error, Result};

/// The four uniform cubic B-spline basis functions at `s` in [0, 1]
/// ([LWS97], eq. 2).
#[inline]
pub fn uniform_cubic_basis(s: f64) -> [f64; 4] {
    let t = 1.0 - s;
    let s2 = s * s;
    let s3 = s2 * s;
    [
        t * t * t / 6.0,
        (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0,
        (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0,
        s3 / 6.0,
    ]
}

/// Most control values of one lattice (2^24: 128 MiB of f64, a 4096 x 4096
/// net), so that a level count or base lattice from the command line cannot
/// exhaust memory.
pub const MAX_LATTICE_VALUES: usize = 1 << 24;

/// How a control value is chosen from the candidates `phi_c` of the points
/// in its 4 x 4 neighbourhood.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ControlFormula {
    /// Lee, Wolberg & Shin ([MBA18] eq. 4, [TURN17] eq. 5): the
    /// mean of the candidates weighted by `w_c^2`, `w_c = B_k(s) B_l(t)`,
    /// which minimises the local error `sum_c (w_c phi - w_c phi_c)^2`.
    #[default]
    LeeWolbergShin,
    /// Hjelle 2001 ([TURN17] eq. 6): the mean weighted by `w_c`
    /// itself, less dominated by the points nearest the control point and
    /// so less sensitive to outliers. The OCR text of eq. 6 prints the
    /// denominator squared, which would not reproduce a constant (all
    /// `phi_c = c` would give `c sum w / sum w^2`); the weighted mean
    /// `sum w phi_c / sum w` of Hjelle's report is used.
    Hjelle,
}

/// A control lattice of `(m + 3) x (n + 3)` values, `phi[a * (n + 3) + b]`
/// for lattice index `a` along x and `b` along y.
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice {
    /// Cells along x (the domain is `[0, m]` in lattice coordinates).
    pub m: usize,
    /// Cells along y.
    pub n: usize,
    /// The control values, row-major along x.
    pub phi: Vec<f64>,
}

/// The cell `(i, j)` of a point and its basis values along x and y.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Basis {
    pub(crate) i: usize,
    pub(crate) j: usize,
    pub(crate) bs: [f64; 4],
    pub(crate) bt: [f64; 4],
}

/// Span index and local coordinate of `x` in `[0, cells]`: `x = cells`
/// belongs to the last cell (with `s = 1`).
#[inline]
pub(crate) fn locate(x: f64, cells: usize) -> (usize, f64) {
    let i = (x.floor().max(0.0) as usize).min(cells - 1);
    (i, x - i as f64)
}

impl Lattice {
    /// A zero lattice over `m x n` cells (both at least 1).
    pub fn zeros(m: usize, n: usize) -> Result<Self> {
        if m == 0 || n == 0 {
            return Err(Error::InvalidInput(format!(
                "a control lattice needs at least 1 x 1 cells, got {m} x {n}"
            )));
        }
        let len = m
            .checked_add(3)
            .zip(n.checked_add(3))
            .and_then(|(a, b)| a.checked_mul(b))
            .filter(|&l| l <= MAX_LATTICE_VALUES)
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "a lattice of {m} x {n} cells exceeds the limit of {MAX_LATTICE_VALUES} control values (about 4093 x 4093 cells); lower the level count or the base lattice"
                ))
            })?;
        Ok(Self {
            m,
            n,
            phi: vec![0.0; len],
        })
    }

    /// Control values along y per row.
    #[inline]
    fn stride(&self) -> usize {
        self.n + 3
    }

    /// The value `phi_ab`.
    pub fn get(&self, a: usize, b: usize) -> f64 {
        self.phi[a * self.stride() + b]
    }

    /// `f(x, y)` at lattice coordinates (eq. 1); points outside `[0, m] x
    /// [0, n]` are clamped to it.
    pub fn eval(&self, x: f64, y: f64) -> f64 {
        self.eval_at(&self.basis(x, y))
    }

    /// The cell and the basis values of lattice coordinates `(x, y)`
    /// (clamped to `[0, m] x [0, n]`), for evaluating several lattices of
    /// the same size at one point.
    #[inline]
    pub(crate) fn basis(&self, x: f64, y: f64) -> Basis {
        let (i, s) = locate(x.clamp(0.0, self.m as f64), self.m);
        let (j, t) = locate(y.clamp(0.0, self.n as f64), self.n);
        Basis {
            i,
            j,
            bs: uniform_cubic_basis(s),
            bt: uniform_cubic_basis(t),
        }
    }

    /// Eq. 1 at a point of [`basis`](Self::basis) (of a lattice of this size).
    #[inline]
    pub(crate) fn eval_at(&self, b: &Basis) -> f64 {
        let (i, j, bs, bt) = (b.i, b.j, &b.bs, &b.bt);
        let st = self.stride();
        let mut f = 0.0;
        for k in 0..4 {
            let row = &self.phi[(i + k) * st + j..(i + k) * st + j + 4];
            let mut r = 0.0;
            for l in 0..4 {
                r += bt[l] * row[l];
            }
            f += bs[k] * r;
        }
        f
    }

    /// The B-spline approximation (BA) of the values `z` at the lattice
    /// coordinates `xy` ([MBA18] eqs. 2-4, or Hjelle's eq. 6): every point
    /// proposes `phi_c = w_c z / sum_ab w_ab^2` (eq. 3) for each of its 16
    /// control values, and each control value is the weighted mean of its
    /// proposals; a control value no point reaches is 0.
    pub fn approximate(
        m: usize,
        n: usize,
        xy: &[[f64; 2]],
        z: &[f64],
        formula: ControlFormula,
    ) -> Result<Self> {
        let mut sums = BaAccumulator::new(m, n, formula)?;
        sums.add(xy, z)?;
        Ok(sums.finish())
    }

    /// The same function on the lattice with twice the cells in each
    /// direction ([LWS97], section 5: B-spline refinement by
    /// subdivision, `(1, 6, 1) / 8` at even and `(1, 1) / 2` at odd fine
    /// indices, applied along x and then along y). Exact: the refined lattice
    /// evaluates equal to this one at corresponding coordinates.
    pub fn refine(&self) -> Result<Self> {
        let (m, n) = (self.m, self.n);
        let mut fine = Self::zeros(2 * m, 2 * n)?;
        // along x: (m + 3) x (n + 3) -> (2m + 3) x (n + 3)
        let st = self.stride();
        let mut half = vec![0.0; (2 * m + 3) * st];
        for b in 0..st {
            let c = |a: usize| self.phi[a * st + b];
            for f in 0..(2 * m + 3) {
                half[f * st + b] = subdivide(f, c);
            }
        }
        // along y: -> (2m + 3) x (2n + 3)
        let fst = fine.stride();
        for a in 0..(2 * m + 3) {
            let c = |b: usize| half[a * st + b];
            for f in 0..(2 * n + 3) {
                fine.phi[a * fst + f] = subdivide(f, c);
            }
        }
        Ok(fine)
    }

    /// Adds `other` (a lattice of the same size) to this one.
    pub fn add(&mut self, other: &Lattice) -> Result<()> {
        if (self.m, self.n) != (other.m, other.n) {
            return Err(Error::InvalidInput(format!(
                "cannot add a {} x {} lattice to a {} x {} one",
                other.m, other.n, self.m, self.n
            )));
        }
        for (a, b) in self.phi.iter_mut().zip(&other.phi) {
            *a += b;
        }
        Ok(())
    }
}

/// Fine control value `f` (0-based) of a 1D uniform cubic subdivision of the
/// coarse values `c` (0-based): fine lattice coordinate `f - 1` is `2i` or
/// `2i + 1` for coarse coordinate `i` (index `i + 1`).
#[inline]
fn subdivide(f: usize, c: impl Fn(usize) -> f64) -> f64 {
    // fine coordinate f - 1 = 2i (even) or 2i + 1 (odd); coarse index a = i + 1
    if f % 2 == 1 {
        // even fine coordinate 2i: f = 2i + 1, a = i + 1 = (f + 1) / 2
        let a = f.div_ceil(2);
        (c(a - 1) + 6.0 * c(a) + c(a + 1)) / 8.0
    } else {
        // odd fine coordinate 2i + 1: f = 2i + 2, a = i + 1 = f / 2
        let a = f / 2;
        (c(a) + c(a + 1)) / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_a_partition_of_unity_with_the_known_values() {
        for s in [0.0, 0.25, 0.5, 1.0] {
            let b = uniform_cubic_basis(s);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
        assert_eq!(
            uniform_cubic_basis(0.0),
            [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0]
        );
    }

    #[test]
    fn refinement_is_exact() {
        let mut l = Lattice::zeros(3, 2).unwrap();
        for (k, p) in l.phi.iter_mut().enumerate() {
            *p = ((k * 37) % 11) as f64 - 4.0;
        }
        let f = l.refine().unwrap();
        assert_eq!((f.m, f.n), (6, 4));
        for i in 0..=30 {
            for j in 0..=20 {
                let (x, y) = (3.0 * i as f64 / 30.0, 2.0 * j as f64 / 20.0);
                assert!((l.eval(x, y) - f.eval(2.0 * x, 2.0 * y)).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn ba_of_one_point_interpolates_it_and_candidates_average() {
        // eq. 2: one point is interpolated exactly, by either formula
        for formula in [ControlFormula::LeeWolbergShin, ControlFormula::Hjelle] {
            let l = Lattice::approximate(2, 2, &[[0.7, 1.3]], &[5.0], formula).unwrap();
            assert!((l.eval(0.7, 1.3) - 5.0).abs() < 1e-14, "{formula:?}");
        }
        // two points in one cell: each control value is the weighted mean of
        // the two candidates phi_c = w z / sum w^2 (eq. 3), by eq. 4 with
        // weights w^2 and by Hjelle's with weights w
        let xy = [[0.25, 0.5], [0.75, 0.5]];
        let z = [1.0, 3.0];
        let w = |p: [f64; 2], k: usize, l: usize| {
            uniform_cubic_basis(p[0])[k] * uniform_cubic_basis(p[1])[l]
        };
        let sum2 = |p: [f64; 2]| {
            (0..4)
                .flat_map(|k| (0..4).map(move |l| (k, l)))
                .map(|(k, l)| w(p, k, l).powi(2))
                .sum::<f64>()
        };
        for (formula, pow) in [
            (ControlFormula::LeeWolbergShin, 2),
            (ControlFormula::Hjelle, 1),
        ] {
            let l = Lattice::approximate(1, 1, &xy, &z, formula).unwrap();
            for k in 0..4 {
                for m in 0..4 {
                    let (mut num, mut den) = (0.0, 0.0);
                    for (p, zc) in xy.iter().zip(z) {
                        let wc = w(*p, k, m);
                        let phi_c = wc * zc / sum2(*p);
                        num += wc.powi(pow) * phi_c;
                        den += wc.powi(pow);
                    }
                    assert!(
                        (l.get(k, m) - num / den).abs() < 1e-14,
                        "{formula:?} {k} {m}"
                    );
                }
            }
        }
        assert!(Lattice::zeros(0, 3).is_err());
    }
}
