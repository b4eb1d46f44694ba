//! Multilevel B-spline approximation (MBA) of scattered 2.5D data
//! ([LWS97], as summarised in [MBA18] section 2.1 and
//! [TURN17] section 2.1), with [MBA18]'s projection
//! adjustment of control points (sections 2.2-2.4, [`adjust`]).
//!
//! The data `(x, y, z)` are mapped to the lattice rectangle: `x` from the
//! bounding box's `[x0, x0 + width]` to `[0, m]`, `y` likewise to `[0, n]`,
//! and `z` taken relative to its mean, so georeferenced coordinates
//! (10^6 and beyond) lose no precision. Level `k` fits a lattice of
//! `(m 2^k + 3) x (n 2^k + 3)` control values to the residuals of the
//! levels before it ([`lattice::Lattice::approximate`]); the levels are
//! combined as they go by refining the running sum (LWS97 section 5), so the
//! result is ONE uniform cubic lattice, returned as an ordinary clamped
//! bicubic B-spline surface of the kernel ([`Mba::surface`]) with
//! parameters `u = (x - x0) / width`, `v = (y - y0) / height` and control
//! points `(x, y, z)` at the Greville abscissae (so `S(u, v) = (x, y, f(x, y))`).

pub mod adjust;
pub mod lattice;

use std::time::Instant;

use rayon::prelude::*;

use crate::bspline::ops::greville;
use crate::bspline::{KnotVector, Surface};
use crate::metrics::ErrorStats;
use crate::{validate_points, Error, Point3, Result};

pub use lattice::{ControlFormula, Lattice};

/// When the level loop stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MbaConfig {
    /// Cells `(m, n)` of the first lattice along x and y (its control net is
    /// `(m + 3) x (n + 3)`). `None` (default): 1 cell along the shorter side
    /// of the bounding box and the rounded aspect ratio along the longer.
    pub base: Option<(usize, usize)>,
    /// Most levels (default 6: a `(2^5 m + 3)`-wide net at the last level).
    pub max_levels: usize,
    /// Stop as soon as the RMSE of the vertical residuals at the data points
    /// is at most this (data units); `None` (default) runs all levels.
    pub tolerance: Option<f64>,
    /// Control-value formula (default Lee, Wolberg & Shin's eq. 4).
    pub formula: ControlFormula,
}

impl Default for MbaConfig {
    fn default() -> Self {
        Self {
            base: None,
            max_levels: 6,
            tolerance: None,
            formula: ControlFormula::LeeWolbergShin,
        }
    }
}

/// The map between data coordinates and lattice coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Smallest x of the data.
    pub x0: f64,
    /// Smallest y of the data.
    pub y0: f64,
    /// Extent in x (> 0).
    pub width: f64,
    /// Extent in y (> 0).
    pub height: f64,
    /// Mean z of the data (the lattices hold `z - z0`).
    pub z0: f64,
}

impl Frame {
    /// The frame of `points`; errors for data without extent in x or y.
    pub fn of(points: &[Point3]) -> Result<Self> {
        validate_points(points)?;
        if points.len() < 2 {
            return Err(Error::TooFewPoints {
                got: points.len(),
                needed: 2,
                what: "a multilevel B-spline approximation (a domain with extent in x and y)"
                    .into(),
            });
        }
        let (mut lo, mut hi) = (points[0].coords, points[0].coords);
        let mut zsum = 0.0;
        for p in points {
            lo = lo.inf(&p.coords);
            hi = hi.sup(&p.coords);
            zsum += p.z;
        }
        let (width, height) = (hi.x - lo.x, hi.y - lo.y);
        let scale = width.max(height).max(lo.x.abs().max(lo.y.abs()));
        for (extent, axis) in [(width, "x"), (height, "y")] {
            if extent <= 1e-12 * scale || extent.is_nan() {
                return Err(Error::InvalidInput(format!(
                    "all points have the same {axis} (extent {extent:e}): the data span no rectangle to approximate over; MBA needs 2.5D data z = f(x, y) spread in both x and y"
                )));
            }
        }
        Ok(Self {
            x0: lo.x,
            y0: lo.y,
            width,
            height,
            z0: zsum / points.len() as f64,
        })
    }

    /// Unit coordinates `((x - x0) / width, (y - y0) / height)`.
    pub fn unit(&self, p: &Point3) -> [f64; 2] {
        [(p.x - self.x0) / self.width, (p.y - self.y0) / self.height]
    }

    /// The default first lattice: 1 cell along the shorter side, the
    /// rounded aspect ratio along the longer.
    pub fn default_base(&self) -> (usize, usize) {
        let r = self.width / self.height;
        if r >= 1.0 {
            ((r.round() as usize).clamp(1, 64), 1)
        } else {
            (1, ((1.0 / r).round() as usize).clamp(1, 64))
        }
    }
}

/// What one level did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelReport {
    /// Level number (0 = the base lattice).
    pub level: usize,
    /// Cells `(m, n)` of the lattice of this level (net `(m + 3) x (n + 3)`).
    pub cells: (usize, usize),
    /// Vertical residuals `|z - f(x, y)|` at the data points after this level.
    pub residual: ErrorStats,
    /// Wall time of the level in seconds.
    pub seconds: f64,
}

/// A multilevel approximation: the combined lattice, the level lattices
/// (for inspection and the sum-of-levels check) and the per-level reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Mba {
    /// The coordinate map.
    pub frame: Frame,
    /// The single combined lattice (all levels refined to the last one).
    pub lattice: Lattice,
    /// The lattice fitted at each level (level `k` has `2^k` times the base cells).
    pub levels: Vec<Lattice>,
    /// One report per level.
    pub reports: Vec<LevelReport>,
}

/// Lattice coordinates of unit coordinates on an `m x n` lattice.
fn to_cells(unit: &[[f64; 2]], m: usize, n: usize) -> Vec<[f64; 2]> {
    unit.iter()
        .map(|u| [u[0] * m as f64, u[1] * n as f64])
        .collect()
}

/// Multilevel B-spline approximation of `points` (see the module documentation).
pub fn mba(points: &[Point3], config: &MbaConfig) -> Result<Mba> {
    let frame = Frame::of(points)?;
    let unit: Vec<[f64; 2]> = points.iter().map(|p| frame.unit(p)).collect();
    let mut residual: Vec<f64> = points.iter().map(|p| p.z - frame.z0).collect();
    let mut run = MbaRun::new(frame, config)?;
    for _ in 0..config.max_levels.max(1) {
        let done = run.level(&unit, &mut residual)?;
        if done {
            break;
        }
    }
    Ok(run.finish())
}

/// The level loop, one level at a time (the adjustment driver interleaves
/// its own steps between levels).
pub(crate) struct MbaRun {
    frame: Frame,
    base: (usize, usize),
    formula: ControlFormula,
    tolerance: Option<f64>,
    total: Option<Lattice>,
    levels: Vec<Lattice>,
    reports: Vec<LevelReport>,
}

impl MbaRun {
    pub(crate) fn new(frame: Frame, config: &MbaConfig) -> Result<Self> {
        let base = config.base.unwrap_or_else(|| frame.default_base());
        if base.0 == 0 || base.1 == 0 {
            return Err(Error::InvalidSetting {
                setting: "base",
                value: format!("{} x {}", base.0, base.1),
                hint: "the base lattice needs at least 1 x 1 cells".into(),
            });
        }
        if let Some(t) = config.tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::InvalidSetting {
                    setting: "tolerance",
                    value: t.to_string(),
                    hint: "the MBA tolerance must be a finite number >= 0".into(),
                });
            }
        }
        // the last level's lattice must fit (it doubles per level)
        let last = config.max_levels.max(1) - 1;
        let fits = u32::try_from(last)
            .ok()
            .and_then(|k| 1usize.checked_shl(k))
            .and_then(|f| base.0.checked_mul(f).zip(base.1.checked_mul(f)))
            .and_then(|(m, n)| (m.checked_add(3)?).checked_mul(n.checked_add(3)?))
            .is_some_and(|len| len <= lattice::MAX_LATTICE_VALUES);
        if !fits {
            return Err(Error::InvalidSetting {
                setting: "max_levels",
                value: config.max_levels.to_string(),
                hint: format!(
                    "{} levels on a {} x {} base lattice would need more than {} control values at the last level (a lattice doubles per level); lower the levels or the base lattice",
                    config.max_levels,
                    base.0,
                    base.1,
                    lattice::MAX_LATTICE_VALUES
                ),
            });
        }
        Ok(Self {
            frame,
            base,
            formula: config.formula,
            tolerance: config.tolerance,
            total: None,
            levels: Vec::new(),
            reports: Vec::new(),
        })
    }

    /// Fits the next level to `residual` (updated in place); returns whether
    /// the tolerance is met.
    pub(crate) fn level(&mut self, unit: &[[f64; 2]], residual: &mut [f64]) -> Result<bool> {
        let t0 = Instant::now();
        let k = self.levels.len();
        let (m, n) = (self.base.0 << k, self.base.1 << k);
        let cells = to_cells(unit, m, n);
        let phi = Lattice::approximate(m, n, &cells, residual, self.formula)?;
        residual
            .par_iter_mut()
            .zip(cells.par_iter())
            .for_each(|(r, c)| *r -= phi.eval(c[0], c[1]));
        self.total = Some(match self.total.take() {
            None => phi.clone(),
            Some(t) => {
                let mut t = t.refine()?;
                t.add(&phi)?;
                t
            }
        });
        self.levels.push(phi);
        let abs: Vec<f64> = residual.iter().map(|r| r.abs()).collect();
        let stats = ErrorStats::of(&abs);
        self.reports.push(LevelReport {
            level: k,
            cells: (m, n),
            residual: stats,
            seconds: t0.elapsed().as_secs_f64(),
        });
        Ok(self.tolerance.is_some_and(|t| stats.rmse <= t))
    }

    /// The combined lattice so far (mutable, for the adjustment).
    pub(crate) fn total_mut(&mut self) -> Option<&mut Lattice> {
        self.total.as_mut()
    }

    pub(crate) fn frame(&self) -> Frame {
        self.frame
    }

    pub(crate) fn finish(self) -> Mba {
        Mba {
            frame: self.frame,
            lattice: self.total.unwrap_or(Lattice {
                m: self.base.0,
                n: self.base.1,
                phi: vec![0.0; (self.base.0 + 3) * (self.base.1 + 3)],
            }),
            levels: self.levels,
            reports: self.reports,
        }
    }
}

impl Mba {
    /// `f(x, y)` of the combined surface at a data-space point.
    pub fn eval(&self, x: f64, y: f64) -> f64 {
        lattice_height(&self.frame, &self.lattice, x, y)
    }

    /// The sum of the level lattices' functions at `(x, y)`: equal to
    /// [`eval`](Self::eval) up to round-off (LWS97 section 5).
    pub fn eval_levels(&self, x: f64, y: f64) -> f64 {
        let u = self.frame.unit(&Point3::new(x, y, 0.0));
        self.frame.z0
            + self
                .levels
                .iter()
                .map(|l| l.eval(u[0] * l.m as f64, u[1] * l.n as f64))
                .sum::<f64>()
    }

    /// The combined lattice as a clamped bicubic B-spline surface.
    pub fn surface(&self) -> Result<Surface> {
        lattice_surface(&self.frame, &self.lattice)
    }
}

/// `f(x, y)` of `lattice` in `frame` at a data-space point.
pub(crate) fn lattice_height(frame: &Frame, lattice: &Lattice, x: f64, y: f64) -> f64 {
    let u = frame.unit(&Point3::new(x, y, 0.0));
    frame.z0 + lattice.eval(u[0] * lattice.m as f64, u[1] * lattice.n as f64)
}

/// The uniform knots `(a - 3) / cells`, `a = 0..cells + 6`, of a lattice
/// direction in unit coordinates (domain `[0, 1]`).
fn uniform_knots(cells: usize) -> Result<KnotVector> {
    KnotVector::new(
        (0..cells + 7)
            .map(|a| (a as f64 - 3.0) / cells as f64)
            .collect(),
        3,
    )
}

/// `lattice` in `frame` as a clamped bicubic B-spline surface over
/// `[0, 1]^2` with control points `(x, y, z)`: x and y at the Greville
/// abscissae (which reproduce the linear maps exactly), z the control values.
pub fn lattice_surface(frame: &Frame, lattice: &Lattice) -> Result<Surface> {
    let (m, n) = (lattice.m, lattice.n);
    let (ku, kv) = (uniform_knots(m)?, uniform_knots(n)?);
    // (a - 1) / cells on these knots, up to rounding
    let (xi, eta) = (greville(&ku), greville(&kv));
    let mut ctrl = Vec::with_capacity(lattice.phi.len());
    for (a, x) in xi.iter().enumerate() {
        for (b, y) in eta.iter().enumerate() {
            ctrl.push(Point3::new(
                frame.x0 + frame.width * x,
                frame.y0 + frame.height * y,
                frame.z0 + lattice.get(a, b),
            ));
        }
    }
    Surface::new(ku, kv, ctrl)?.to_clamped()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testdata::franke;

    fn random_points(n: usize, f: impl Fn(f64, f64) -> f64, offset: [f64; 2]) -> Vec<Point3> {
        let mut rng = crate::testdata::Lcg::new(99);
        let mut rnd = || rng.next_f64();
        (0..n)
            .map(|_| {
                let (x, y) = (rnd(), rnd());
                Point3::new(x + offset[0], y + offset[1], f(x, y))
            })
            .collect()
    }

    #[test]
    fn franke_error_falls_at_every_level() {
        let p = random_points(10_000, franke, [0.0, 0.0]);
        let r = mba(
            &p,
            &MbaConfig {
                max_levels: 7,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(r.reports.len(), 7);
        for w in r.reports.windows(2) {
            assert!(
                w[1].residual.rmse < w[0].residual.rmse,
                "{:?}",
                r.reports
                    .iter()
                    .map(|l| l.residual.rmse)
                    .collect::<Vec<_>>()
            );
        }
        // 67 x 67 control values over 10^4 points: close to the function
        assert!(r.reports[6].residual.rmse < 2e-3, "{:?}", r.reports[6]);
        assert_eq!(r.reports[6].cells, (64, 64));
    }

    #[test]
    fn combined_surface_equals_the_sum_of_levels() {
        // a non-square domain far from the origin (georeferenced)
        let p: Vec<Point3> = random_points(5000, franke, [0.0, 0.0])
            .into_iter()
            .map(|q| Point3::new(5.0e6 + 300.0 * q.x, 4.0e6 + 120.0 * q.y, 200.0 + 50.0 * q.z))
            .collect();
        let r = mba(&p, &MbaConfig::default()).unwrap();
        assert_eq!(r.reports[0].cells, (3, 1));
        let s = r.surface().unwrap();
        assert!(s.knots_u().is_clamped() && s.degrees() == (3, 3));
        let mut worst: f64 = 0.0;
        for q in p.iter().take(2000) {
            let (a, b) = (r.eval(q.x, q.y), r.eval_levels(q.x, q.y));
            let u = r.frame.unit(q);
            let on = s.point(u[0], u[1]);
            worst = worst.max((a - b).abs()).max((on.z - a).abs());
            // the surface's x, y are the data's x, y
            assert!((on.x - q.x).abs() < 1e-7 && (on.y - q.y).abs() < 1e-7);
        }
        assert!(worst < 1e-10, "{worst}");
    }

    #[test]
    fn degenerate_input_is_an_error_or_well_defined() {
        let line: Vec<Point3> = (0..10).map(|i| Point3::new(1.0, i as f64, 0.0)).collect();
        let e = mba(&line, &MbaConfig::default()).unwrap_err().to_string();
        assert!(e.contains("same x"), "{e}");
        assert!(mba(&[Point3::new(1.0, 2.0, 3.0)], &MbaConfig::default()).is_err());
        let nan = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(f64::NAN, 1.0, 1.0)];
        assert!(mba(&nan, &MbaConfig::default()).is_err());
        // the same (x, y) with two heights: the mean, not NaN
        let mut p = random_points(200, |x, y| x + y, [0.0, 0.0]);
        p.push(Point3::new(0.5, 0.5, 10.0));
        p.push(Point3::new(0.5, 0.5, -10.0));
        let r = mba(&p, &MbaConfig::default()).unwrap();
        assert!(r.eval(0.5, 0.5).is_finite());
        assert!(r
            .surface()
            .unwrap()
            .control_points()
            .iter()
            .all(|c| c.z.is_finite()));
        // points on a diagonal line: a defined surface (zero away from the data)
        let diag: Vec<Point3> = (0..50)
            .map(|i| Point3::new(i as f64, i as f64, (i as f64 * 0.2).sin()))
            .collect();
        let r = mba(&diag, &MbaConfig::default()).unwrap();
        assert!(r.reports.last().unwrap().residual.max < 0.05);
        // 10^8-sized coordinates: the same fit as at the origin
        let near = random_points(2000, franke, [0.0, 0.0]);
        let far: Vec<Point3> = near
            .iter()
            .map(|q| Point3::new(q.x + 1e8, q.y - 3e8, q.z + 1e8))
            .collect();
        let (a, b) = (
            mba(&near, &MbaConfig::default()).unwrap(),
            mba(&far, &MbaConfig::default()).unwrap(),
        );
        for (ra, rb) in a.reports.iter().zip(&b.reports) {
            assert!(
                (ra.residual.rmse - rb.residual.rmse).abs() < 1e-6,
                "{ra:?} {rb:?}"
            );
        }
        let s = b.surface().unwrap();
        assert!(s.control_points().iter().all(|c| c.z.is_finite()));
        let bad = MbaConfig {
            base: Some((0, 2)),
            ..Default::default()
        };
        assert!(mba(&diag, &bad).is_err());
    }
}
