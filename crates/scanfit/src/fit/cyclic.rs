//! Cyclic band systems: band matrices whose band wraps around the corners, as
//! in periodic (closed) B-spline interpolation and least squares.
//!
//! With half-bandwidth `w`, the last `w` unknowns are taken as a border:
//! `[[B, C], [D, E]] [x1; x2] = [f1; f2]`, where `B` (order `n - w`) is an
//! ordinary band matrix. Block elimination gives the `w x w` Schur complement
//! `S = E - D B^{-1} C`, solved densely. `B` is a leading principal submatrix
//! (SPD normal equations) or a collocation submatrix satisfying the
//! Schoenberg-Whitney conditions (interpolation), so it is factored by
//! [`super::banded`] without pivoting. Cost `O(n w^2)`, memory `O(n w)`.

use super::banded::{dense_solve, hager_inverse_norm1, BandMatrix};
use crate::{Error, Result};

/// An `n x n` matrix whose non-zeros lie within cyclic distance `w` of the diagonal.
#[derive(Debug, Clone)]
pub struct CyclicBandMatrix {
    n: usize,
    w: usize,
    data: Vec<f64>,
}

impl CyclicBandMatrix {
    /// The zero matrix of order `n` and cyclic half-bandwidth `w` (`2w + 1 <= n`).
    pub fn zeros(n: usize, w: usize) -> Result<Self> {
        if 2 * w + 1 > n {
            return Err(Error::InvalidInput(format!(
                "a cyclic band of half-width {w} needs order at least {}, got {n}",
                2 * w + 1
            )));
        }
        Ok(Self {
            n,
            w,
            data: vec![0.0; n * (2 * w + 1)],
        })
    }

    #[inline]
    fn slot(&self, i: usize, j: usize) -> usize {
        let d = (j + self.n + self.w - i) % self.n;
        debug_assert!(d <= 2 * self.w, "({i},{j}) outside the cyclic band");
        i * (2 * self.w + 1) + d
    }

    /// Adds `v` to entry `(i, j)`.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let s = self.slot(i, j);
        self.data[s] += v;
    }

    /// Entry `(i, j)` (zero outside the cyclic band).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let d = (j + self.n + self.w - i) % self.n;
        if d > 2 * self.w {
            0.0
        } else {
            self.data[i * (2 * self.w + 1) + d]
        }
    }

    /// Solves `A X = F` (`nrhs` columns, row-major) in place; returns the
    /// 1-norm condition estimate of the whole matrix (Hager/Higham, with solves
    /// by `A` and `A^T`).
    pub fn solve(&self, f: &mut [f64], nrhs: usize, what: &str) -> Result<f64> {
        self.solve_raw(f, nrhs, what)?;
        self.condition_estimate(what)
    }

    /// `A^T`, also a cyclic band matrix.
    fn transpose(&self) -> Self {
        let mut t = Self {
            n: self.n,
            w: self.w,
            data: vec![0.0; self.data.len()],
        };
        for i in 0..self.n {
            for k in 0..=2 * self.w {
                let j = (i + self.n + k - self.w) % self.n;
                t.add(j, i, self.data[i * (2 * self.w + 1) + k]);
            }
        }
        t
    }

    /// Hager's estimate of `||A||_1 ||A^{-1}||_1` (Higham 1988, Algorithm 2.1).
    fn condition_estimate(&self, what: &str) -> Result<f64> {
        let n = self.n;
        let mut col = vec![0.0f64; n];
        for i in 0..n {
            for k in 0..=2 * self.w {
                col[(i + n + k - self.w) % n] += self.data[i * (2 * self.w + 1) + k].abs();
            }
        }
        let norm = col.into_iter().fold(0.0, f64::max);
        let at = self.transpose();
        let est = hager_inverse_norm1(
            n,
            |y| self.solve_raw(y, 1, what),
            |z| at.solve_raw(z, 1, what),
        )?;
        Ok(if est.is_finite() {
            est * norm
        } else {
            f64::INFINITY
        })
    }

    /// The solve itself (see [`Self::solve`]).
    fn solve_raw(&self, f: &mut [f64], nrhs: usize, what: &str) -> Result<()> {
        let (n, w) = (self.n, self.w);
        let singular = |condition: f64, hint: &str| Error::Singular {
            what: what.to_string(),
            condition,
            hint: hint.to_string(),
        };
        if n <= 4 * w + 2 {
            // small: dense LU with partial pivoting
            let mut a = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    a[i * n + j] = self.get(i, j);
                }
            }
            dense_solve(&mut a, n, f, nrhs)
                .ok_or_else(|| singular(f64::INFINITY, "a pivot vanishes"))?;
            return Ok(());
        }
        let m = n - w;
        let mut b = BandMatrix::zeros(m, w, w);
        let mut c = vec![0.0; m * w]; // m x w
        let mut d = vec![0.0; w * m]; // w x m
        let mut e = vec![0.0; w * w];
        for i in 0..n {
            for k in 0..=2 * w {
                let v = self.data[i * (2 * w + 1) + k];
                if v == 0.0 {
                    continue;
                }
                let j = (i + n + k - w) % n;
                match (i < m, j < m) {
                    (true, true) => b.set(i, j, v),
                    (true, false) => c[i * w + j - m] = v,
                    (false, true) => d[(i - m) * m + j] = v,
                    (false, false) => e[(i - m) * w + j - m] = v,
                }
            }
        }
        let lu = b.factor(what)?;
        // X = B^{-1} C, y = B^{-1} f1
        lu.solve_in_place(&mut c, w);
        let mut f1 = f[..m * nrhs].to_vec();
        lu.solve_in_place(&mut f1, nrhs);
        // S = E - D X, r = f2 - D y
        let mut s = e;
        let mut r = f[m * nrhs..].to_vec();
        for a in 0..w {
            for j in 0..m {
                let dv = d[a * m + j];
                if dv == 0.0 {
                    continue;
                }
                for bcol in 0..w {
                    s[a * w + bcol] -= dv * c[j * w + bcol];
                }
                for col in 0..nrhs {
                    r[a * nrhs + col] -= dv * f1[j * nrhs + col];
                }
            }
        }
        dense_solve(&mut s, w, &mut r, nrhs)
            .ok_or_else(|| singular(f64::INFINITY, "the border block is singular"))?;
        // x1 = y - X x2
        for j in 0..m {
            for col in 0..nrhs {
                let mut v = f1[j * nrhs + col];
                for a in 0..w {
                    v -= c[j * w + a] * r[a * nrhs + col];
                }
                f[j * nrhs + col] = v;
            }
        }
        f[m * nrhs..].copy_from_slice(&r);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_cyclic_tridiagonal_like_dense() {
        for n in [5usize, 9, 40] {
            let mut a = CyclicBandMatrix::zeros(n, 2).unwrap();
            for i in 0..n {
                a.add(i, i, 6.0);
                a.add(i, (i + 1) % n, 1.5);
                a.add(i, (i + n - 1) % n, -1.0);
                a.add(i, (i + 2) % n, 0.5);
                a.add(i, (i + n - 2) % n, 0.25);
            }
            let x: Vec<f64> = (0..2 * n).map(|k| (k as f64 * 0.37).cos()).collect();
            let mut f = vec![0.0; 2 * n];
            for i in 0..n {
                for j in 0..n {
                    for c in 0..2 {
                        f[i * 2 + c] += a.get(i, j) * x[j * 2 + c];
                    }
                }
            }
            let cond = a.solve(&mut f, 2, "test").unwrap();
            for (u, v) in f.iter().zip(&x) {
                assert!((u - v).abs() < 1e-13, "n={n}: {u} vs {v}");
            }
            // exact 1-norm condition from the dense inverse (columns by solves)
            let mut inv_norm = 0.0f64;
            for j in 0..n {
                let mut e = vec![0.0; n];
                e[j] = 1.0;
                a.solve_raw(&mut e, 1, "t").unwrap();
                inv_norm = inv_norm.max(e.iter().map(|v| v.abs()).sum());
            }
            let norm = (0..n)
                .map(|j| (0..n).map(|i| a.get(i, j).abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let exact = norm * inv_norm;
            assert!(
                cond <= exact * (1.0 + 1e-12) && cond >= exact / 3.0,
                "n={n}: {cond} vs {exact}"
            );
        }
    }
}
