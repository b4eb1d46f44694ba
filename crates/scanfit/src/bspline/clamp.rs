//! Conversion of unclamped (e.g. periodic) B-splines to the clamped form with
//! the same shape on the same domain, for exchange formats and systems that
//! expect end knots of multiplicity `p + 1`.
//!
//! At the domain start `a = t_p`, knot `a` is inserted until its multiplicity
//! is `p` (A5.1, homogeneous coordinates); the curve then passes through the
//! control point before that run, and the knots below `a` with their control
//! points are dropped. The domain end is treated the same way on the reversed
//! parameterization. The result evaluates equal to the input (up to rounding).

use super::curve::insert_homogeneous;
use super::knots::{find_span, KnotVector};
use super::{Curve, Direction, Surface};
use crate::{Point3, Result};

/// Clamps the start of a homogeneous control polygon: returns new knots and points.
fn clamp_start(t: &[f64], p: usize, pw: &[[f64; 4]]) -> (Vec<f64>, Vec<[f64; 4]>) {
    let a = t[p];
    let s = t.iter().filter(|&&x| x == a).count();
    let (t2, q) = if s < p {
        let k = find_span(t, p, a);
        insert_homogeneous(t, p, pw, a, k, s, p - s)
    } else {
        (t.to_vec(), pw.to_vec())
    };
    // first index of the value a
    let first = t2.iter().position(|&x| x == a).unwrap_or(0);
    if first == 0 {
        return (t2, q); // already clamped
    }
    let mut knots = vec![a];
    knots.extend_from_slice(&t2[first..]);
    let points = q[first - 1..].to_vec();
    (knots, points)
}

/// Clamps both ends (the end via the reversed parameterization u -> a + b - u).
fn clamp_both(t: &[f64], p: usize, pw: &[[f64; 4]]) -> (Vec<f64>, Vec<[f64; 4]>) {
    let (t1, q1) = clamp_start(t, p, pw);
    let (a, b) = (t1[p], t1[t1.len() - 1 - p]);
    let rev_t: Vec<f64> = t1.iter().rev().map(|&x| a + b - x).collect();
    let rev_q: Vec<[f64; 4]> = q1.iter().rev().copied().collect();
    let (t2, q2) = clamp_start(&rev_t, p, &rev_q);
    let knots: Vec<f64> = t2.iter().rev().map(|&x| a + b - x).collect();
    let points: Vec<[f64; 4]> = q2.into_iter().rev().collect();
    (knots, points)
}

fn dehom(q: &[[f64; 4]]) -> (Vec<Point3>, Vec<f64>) {
    (
        q.iter()
            .map(|h| Point3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3]))
            .collect(),
        q.iter().map(|h| h[3]).collect(),
    )
}

impl Curve {
    /// The same curve with clamped knots (a no-op copy for clamped curves).
    pub fn to_clamped(&self) -> Result<Curve> {
        if self.knots().is_clamped() && !self.is_periodic() {
            return Ok(self.clone());
        }
        let p = self.degree();
        let (t, q) = clamp_both(self.knots().as_slice(), p, &self.homogeneous());
        let kv = KnotVector::new(t, p)?;
        let (ctrl, w) = dehom(&q);
        match self.weights() {
            Some(_) => Curve::new_rational(kv, ctrl, w),
            None => Curve::new(kv, ctrl),
        }
    }
}

impl Surface {
    /// The same surface with clamped knots in both directions.
    pub fn to_clamped(&self) -> Result<Surface> {
        let mut s = self.clone();
        for dir in [Direction::U, Direction::V] {
            s = s.clamp_direction(dir)?;
        }
        Ok(s)
    }

    fn clamp_direction(&self, dir: Direction) -> Result<Surface> {
        let (cu, cv) = self.counts();
        let kv = match dir {
            Direction::U => self.knots_u(),
            Direction::V => self.knots_v(),
        };
        let periodic = match dir {
            Direction::U => self.periodic().0,
            Direction::V => self.periodic().1,
        };
        if kv.is_clamped() && !periodic {
            return Ok(self.clone());
        }
        let p = kv.degree();
        let hw = |i: usize, j: usize| {
            let c = self.control_point(i, j);
            let w = self.weights().map_or(1.0, |w| w[i * cv + j]);
            [c.x * w, c.y * w, c.z * w, w]
        };
        let (lines, len) = match dir {
            Direction::U => (cv, cu),
            Direction::V => (cu, cv),
        };
        let mut new_knots = Vec::new();
        let mut cols: Vec<Vec<[f64; 4]>> = Vec::with_capacity(lines);
        for line in 0..lines {
            let pw: Vec<[f64; 4]> = (0..len)
                .map(|e| match dir {
                    Direction::U => hw(e, line),
                    Direction::V => hw(line, e),
                })
                .collect();
            let (t, q) = clamp_both(kv.as_slice(), p, &pw);
            new_knots = t;
            cols.push(q);
        }
        let new_len = cols.first().map_or(0, |c| c.len());
        let (nu, nv) = match dir {
            Direction::U => (new_len, cv),
            Direction::V => (cu, new_len),
        };
        let mut h = vec![[0.0; 4]; nu * nv];
        for (line, q) in cols.iter().enumerate() {
            for (e, x) in q.iter().enumerate() {
                let idx = match dir {
                    Direction::U => e * nv + line,
                    Direction::V => line * nv + e,
                };
                h[idx] = *x;
            }
        }
        let (ctrl, w) = dehom(&h);
        let new_kv = KnotVector::new(new_knots, p)?;
        let (ku, kv2) = match dir {
            Direction::U => (new_kv, self.knots_v().clone()),
            Direction::V => (self.knots_u().clone(), new_kv),
        };
        let (pu, pv) = match dir {
            Direction::U => (false, self.periodic().1),
            Direction::V => (self.periodic().0, false),
        };
        Surface::with_options(ku, kv2, ctrl, self.weights().map(|_| w), pu, pv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_curve_clamps_to_the_same_shape() {
        for p in [2, 3, 4] {
            let n = 7;
            let kv = KnotVector::uniform_periodic(p, n).unwrap();
            let mut ctrl: Vec<Point3> = (0..n)
                .map(|k| {
                    let a = k as f64 / n as f64 * std::f64::consts::TAU;
                    Point3::new(a.cos() * (1.0 + 0.2 * k as f64), a.sin(), 0.1 * k as f64)
                })
                .collect();
            for j in 0..p {
                ctrl.push(ctrl[j]);
            }
            let c = Curve::new_periodic(kv, ctrl, None).unwrap();
            let k = c.to_clamped().unwrap();
            assert!(k.knots().is_clamped());
            assert_eq!(k.domain(), c.domain());
            for s in 0..=200 {
                let u = s as f64 / 200.0;
                assert!((k.point(u) - c.point(u)).norm() < 1e-12, "p={p} u={u}");
            }
        }
    }

    #[test]
    fn periodic_surface_clamps_to_the_same_shape() {
        let p = 3;
        let nd = 8;
        let ku = KnotVector::uniform_periodic(p, nd).unwrap();
        let kv = KnotVector::uniform_clamped(2, 4).unwrap();
        let mut c = Vec::new();
        for i in 0..nd + p {
            let a = (i % nd) as f64 / nd as f64 * std::f64::consts::TAU;
            for j in 0..4 {
                c.push(Point3::new(
                    a.cos() * (2.0 + 0.1 * j as f64),
                    a.sin(),
                    j as f64 + 0.3 * ((i % nd) as f64).sin(),
                ));
            }
        }
        let s = Surface::with_options(ku, kv, c, None, true, false).unwrap();
        let k = s.to_clamped().unwrap();
        assert!(k.knots_u().is_clamped() && !k.periodic().0);
        for a in 0..=40 {
            for b in 0..=10 {
                let (u, v) = (a as f64 / 40.0, b as f64 / 10.0);
                assert!((k.point(u, v) - s.point(u, v)).norm() < 1e-12);
            }
        }
    }
}
