//! Layer curves ([TURN17] sections 3.4-3.5).
//!
//! On every layer (constant height along the axis) the polygon left by the
//! intersection pairs ([`super::views::layer_polygon`]), without its
//! outliers, is interpolated by a closed cubic B-spline (global
//! interpolation, [NURBS97] section 9.2.1, closed form) with chord
//! length parameters.
//!
//! Two departures from section 3.4, stated: (1) the paper interpolates an
//! *open* curve per layer, from and to the column grid points close to the
//! cloud; a closed curve is used here, since the layer of a cylinder-like
//! cloud goes all the way round and the base surface is periodic in u
//! anyway. (2) The paper names the averaging knots of Ma & Kruth; for a
//! closed curve the periodic knot vector whose domain knots are the
//! parameters themselves ([`crate::param::knots::periodic`]) is used. It
//! equals the averaged knots for uniform parameters and differs from them by
//! a fraction of the local spacing for chord-length parameters.
//!
//! The curve is then sampled uniformly in its parameter with as many samples
//! as the layer kept points, and every sample is moved by directed
//! projection ([Aza04], eqs. 7-14) along the curve normal inside the
//! layer plane, `n = C'(u) x a`, with the weight factor of eq. 19 by default
//! (eqs. 15 and 16 selectable). One round is one projection step per sample
//! (the paper's Tables 1-2 count these), followed by re-interpolation and
//! uniform resampling; rounds repeat until the RMSE of the samples' nearest
//! cloud distances improves by less than the threshold (section 3.5). Both
//! the curve and the directions stay in the layer plane, which is what keeps
//! the layers from looping or crossing (section 4).

use rayon::prelude::*;

use crate::bspline::{BasisWorkspace, Curve};
use crate::cloud::PointCloud;
use crate::fit::{interpolate, InterpolationConfig};
use crate::param::Method;
use crate::project::{project_directed_batch, DirectedConfig, WeightFactor};
use crate::{Error, Point3, Result, Vector3};

use super::axis::CylinderFrame;
use super::views::{layer_polygon, View};

/// Settings of the layer curves and their projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerConfig {
    /// Number of layers (default 40; the paper uses as many layers as grid
    /// points per row, see [`super::ViewConfig::grid_u`]).
    pub layers: usize,
    /// Fraction of the cloud's height left out at each end (default 0.03):
    /// the layers run over `[h_min + m H, h_max - m H]`, where a closed end
    /// (the top of a head) still has a section around the axis.
    pub margin: f64,
    /// A polygon point whose distance to the cloud exceeds this many times
    /// the layer's median distance (or the cloud's median spacing, when
    /// larger) is an outlier and left out (default 4).
    pub outlier_factor: f64,
    /// Directed projection of the samples: weight eq. 19 (`Moon`), the 32
    /// nearest points, and one step per round (`max_iterations = 1`).
    pub projection: DirectedConfig,
    /// Most projection rounds (default 10).
    pub max_rounds: usize,
    /// Stop when a round lowers the RMSE by less than this fraction (default 0.01).
    pub threshold: f64,
}

impl Default for LayerConfig {
    fn default() -> Self {
        Self {
            layers: 40,
            margin: 0.03,
            outlier_factor: 4.0,
            projection: DirectedConfig {
                max_iterations: 1,
                ..Default::default()
            },
            max_rounds: 10,
            threshold: 0.01,
        }
    }
}

impl LayerConfig {
    fn validate(&self) -> Result<()> {
        if !(4..=4096).contains(&self.layers) {
            return Err(Error::InvalidInput(format!(
                "{} layers: use between 4 (a bicubic base surface) and 4096",
                self.layers
            )));
        }
        if self.max_rounds > 1000 {
            return Err(Error::InvalidInput(format!(
                "{} projection rounds: use at most 1000 (the rounds stop at the threshold long before)",
                self.max_rounds
            )));
        }
        if !(0.0..0.5).contains(&self.margin) {
            return Err(Error::InvalidInput(format!(
                "layer margin {} must be in [0, 0.5)",
                self.margin
            )));
        }
        if !(self.outlier_factor.is_finite() && self.outlier_factor > 1.0) {
            return Err(Error::InvalidInput(format!(
                "outlier factor {} must be finite and > 1",
                self.outlier_factor
            )));
        }
        if !(self.threshold.is_finite() && self.threshold >= 0.0) {
            return Err(Error::InvalidInput(format!(
                "projection threshold {} must be finite and >= 0",
                self.threshold
            )));
        }
        Ok(())
    }
}

/// Heights of the layers relative to the frame's centre.
pub fn layer_heights(frame: &CylinderFrame, cfg: &LayerConfig) -> Result<Vec<f64>> {
    layer_heights_between(frame, cfg, (cfg.margin, cfg.margin))
}

/// Heights of the layers with their own margin at the low and high end
/// (fractions of the height; 0 at an open end, [`super::ends`]).
pub fn layer_heights_between(
    frame: &CylinderFrame,
    cfg: &LayerConfig,
    margins: (f64, f64),
) -> Result<Vec<f64>> {
    cfg.validate()?;
    let (lo, hi) = frame.height;
    let span = hi - lo;
    let (a, b) = (lo + margins.0 * span, hi - margins.1 * span);
    Ok((0..cfg.layers)
        .map(|l| a + (b - a) * l as f64 / (cfg.layers - 1) as f64)
        .collect())
}

/// The closed polygon of every layer (section 3.3) without outliers and
/// coincident neighbours: the interpolation points of section 3.4.
pub fn layer_loops(
    cloud: &PointCloud,
    frame: &CylinderFrame,
    views: &[View],
    heights: &[f64],
    grid_u: usize,
    cfg: &LayerConfig,
) -> Result<Vec<Vec<Point3>>> {
    cfg.validate()?;
    let spacing = cloud.spacing()?.median;
    let tol = 1e-9 * cloud.diagonal();
    heights
        .iter()
        .enumerate()
        .map(|(l, &h)| {
            let (poly, per_view) = layer_polygon(frame, views, h, grid_u)?;
            // a view that keeps no grid point would let the layer curve cut
            // straight across its sector, through the object
            if let Some(k) = per_view.iter().position(|&n| n == 0) {
                return Err(Error::InvalidInput(format!(
                    "layer {l} (height {h:.4}): view {k} keeps no grid point between its neighbours' intersection pairs, so the layer curve would cut across its sector; check the axis (--axis), or use fewer --views or a finer --grid"
                )));
            }
            let d: Vec<f64> = cloud
                .nearest_batch(&poly)?
                .into_iter()
                .map(|n| n.distance)
                .collect();
            let mut sorted = d.clone();
            sorted.sort_by(f64::total_cmp);
            let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
            let limit = cfg.outlier_factor * median.max(spacing);
            let mut kept: Vec<Point3> = Vec::with_capacity(poly.len());
            for (p, &dist) in poly.iter().zip(&d) {
                if dist <= limit && kept.last().is_none_or(|q| (p - q).norm() > tol) {
                    kept.push(*p);
                }
            }
            while kept.len() > 1 && (kept[0] - kept[kept.len() - 1]).norm() <= tol {
                kept.pop();
            }
            if kept.len() < 8 {
                return Err(Error::InvalidInput(format!(
                    "layer {l} (height {h:.4}): only {} usable grid points around the axis; raise the grid count, lower the number of layers near the ends (a larger margin) or check the axis",
                    kept.len()
                )));
            }
            Ok(kept)
        })
        .collect()
}

/// The closed chord-length cubic through `points` (section 3.4).
pub fn closed_curve(points: &[Point3]) -> Result<Curve> {
    let cfg = InterpolationConfig {
        degree: 3,
        method: Method::ChordLength,
        end_derivatives: None,
        closed: true,
    };
    Ok(interpolate(points, &cfg)?.curve)
}

/// `n` samples of `curve` equally spaced in its parameter, with the in-plane
/// normals `C'(u) x axis`.
pub fn uniform_samples(curve: &Curve, n: usize, axis: &Vector3) -> (Vec<Point3>, Vec<Vector3>) {
    let (a, b) = curve.domain();
    let mut ws = BasisWorkspace::new(curve.degree(), 1);
    let mut d = [Vector3::zeros(); 2];
    (0..n)
        .map(|j| {
            let u = a + (b - a) * j as f64 / n as f64;
            curve.derivatives_into(u, &mut ws, &mut d);
            (Point3::from(d[0]), d[1].cross(axis))
        })
        .unzip()
}

/// The layer curves after projection.
#[derive(Debug, Clone)]
pub struct LayerCurves {
    /// One closed curve per layer, through its last projected samples.
    pub curves: Vec<Curve>,
    /// Samples per layer (the layer's count of interpolation points).
    pub counts: Vec<usize>,
    /// RMSE of the samples' nearest-point distances to the cloud: entry 0
    /// before any projection, entry `r` after round `r` (Tables 1-2).
    pub rmse: Vec<f64>,
}

/// How many projection rounds run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rounds {
    /// Until the threshold or `max_rounds` (section 3.5).
    UntilThreshold,
    /// Exactly this many (for comparing weight factors).
    Exactly(usize),
}

/// Sections 3.4-3.5 on the layer polygons `loops`.
pub fn project_layers(
    cloud: &PointCloud,
    frame: &CylinderFrame,
    loops: &[Vec<Point3>],
    cfg: &LayerConfig,
    rounds: Rounds,
) -> Result<LayerCurves> {
    cfg.validate()?;
    let axis = frame.axis;
    let counts: Vec<usize> = loops.iter().map(Vec::len).collect();
    let mut curves: Vec<Curve> = loops
        .par_iter()
        .enumerate()
        .map(|(l, pts)| {
            closed_curve(pts).map_err(|e| {
                Error::InvalidInput(format!("layer {l}: closed interpolation failed: {e}"))
            })
        })
        .collect::<Result<_>>()?;
    let sample = |curves: &[Curve]| -> (Vec<Point3>, Vec<Vector3>) {
        let mut pts = Vec::new();
        let mut dirs = Vec::new();
        for (c, &n) in curves.iter().zip(&counts) {
            let (p, d) = uniform_samples(c, n, &axis);
            pts.extend(p);
            dirs.extend(d);
        }
        (pts, dirs)
    };
    let (mut pts, mut dirs) = sample(&curves);
    let mut rmse = vec![crate::metrics::rmse_to_cloud(cloud, &pts)?];
    let limit = match rounds {
        Rounds::UntilThreshold => cfg.max_rounds,
        Rounds::Exactly(n) => n,
    };
    let tol = 1e-9 * cloud.diagonal();
    for _ in 0..limit {
        let projected: Vec<Point3> = project_directed_batch(cloud, &pts, &dirs, &cfg.projection)?
            .into_iter()
            .map(|r| r.point)
            .collect();
        let r = crate::metrics::rmse_to_cloud(cloud, &projected)?;
        let previous = rmse[rmse.len() - 1];
        rmse.push(r);
        // a round that made the layer samples worse is not taken
        if rounds == Rounds::UntilThreshold && r > previous {
            break;
        }
        // re-interpolate each layer through its projected samples
        let mut offset = 0;
        let layers: Vec<&[Point3]> = counts
            .iter()
            .map(|&n| {
                let s = &projected[offset..offset + n];
                offset += n;
                s
            })
            .collect();
        curves = layers
            .par_iter()
            .enumerate()
            .map(|(l, s)| {
                let mut q: Vec<Point3> = Vec::with_capacity(s.len());
                for p in s.iter() {
                    if q.last().is_none_or(|x| (p - x).norm() > tol) {
                        q.push(*p);
                    }
                }
                closed_curve(&q).map_err(|e| {
                    Error::InvalidInput(format!(
                        "layer {l}: closed interpolation of the projected samples failed: {e}"
                    ))
                })
            })
            .collect::<Result<_>>()?;
        if rounds == Rounds::UntilThreshold && previous - r <= cfg.threshold * previous {
            break;
        }
        (pts, dirs) = sample(&curves);
    }
    Ok(LayerCurves {
        curves,
        counts,
        rmse,
    })
}

/// RMSE per projection round for each weight factor, all from the same
/// layer polygons (the paper's Tables 1-2).
pub fn compare_weights(
    cloud: &PointCloud,
    frame: &CylinderFrame,
    loops: &[Vec<Point3>],
    cfg: &LayerConfig,
    rounds: usize,
    weights: &[WeightFactor],
) -> Result<Vec<(WeightFactor, Vec<f64>)>> {
    weights
        .iter()
        .map(|&w| {
            let mut c = *cfg;
            c.projection.weight = w;
            Ok((
                w,
                project_layers(cloud, frame, loops, &c, Rounds::Exactly(rounds))?.rmse,
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::axis::AxisChoice;
    use super::*;
    use std::f64::consts::PI;

    /// A cylinder of radius 1 around y, heights in [-2, 2], on a lattice.
    fn cylinder() -> PointCloud {
        let mut pts = Vec::new();
        for j in 0..41 {
            for i in 0..120 {
                let t = 2.0 * PI * (i as f64 + 0.5 * (j % 2) as f64) / 120.0;
                pts.push(Point3::new(t.sin(), -2.0 + 0.1 * j as f64, t.cos()));
            }
        }
        PointCloud::new(pts).unwrap()
    }

    fn ring(r: f64, h: f64, n: usize) -> Vec<Point3> {
        (0..n)
            .map(|i| {
                let t = 2.0 * PI * i as f64 / n as f64;
                Point3::new(r * t.sin(), h, r * t.cos())
            })
            .collect()
    }

    #[test]
    fn closed_curve_samples_and_in_plane_normals() {
        let c = closed_curve(&ring(2.0, 0.5, 24)).unwrap();
        let (p, n) = uniform_samples(&c, 48, &Vector3::y());
        for (q, d) in p.iter().zip(&n) {
            let r = q.x.hypot(q.z);
            assert!((r - 2.0).abs() < 1e-3, "radius {r}");
            assert!((q.y - 0.5).abs() < 1e-12);
            // the normal lies in the layer plane and points along the radius
            assert!(d.y.abs() < 1e-12);
            let radial = Vector3::new(q.x, 0.0, q.z) / r;
            assert!(d.normalize().dot(&radial).abs() > 0.999);
        }
    }

    #[test]
    fn projection_rounds_pull_a_loose_ring_onto_the_cylinder() {
        let cloud = cylinder();
        let frame = CylinderFrame::of(cloud.points(), AxisChoice::Given(Vector3::y())).unwrap();
        // rings 20% too wide at three heights (centre height 0)
        let loops: Vec<Vec<Point3>> = [-1.0, 0.0, 1.0].iter().map(|&h| ring(1.2, h, 40)).collect();
        let cfg = LayerConfig::default();
        let r = project_layers(&cloud, &frame, &loops, &cfg, Rounds::UntilThreshold).unwrap();
        assert_eq!(r.counts, vec![40, 40, 40]);
        // 0.2 before; on the cylinder after the rounds
        assert!((r.rmse[0] - 0.2).abs() < 0.01, "{:?}", r.rmse);
        assert!(r.rmse.last().unwrap() < &0.03, "{:?}", r.rmse);
        assert!(r.rmse.len() <= cfg.max_rounds + 1);
        for c in &r.curves {
            let (p, _) = uniform_samples(c, 40, &Vector3::y());
            for q in p {
                assert!((q.x.hypot(q.z) - 1.0).abs() < 0.03);
            }
        }
        // exactly N rounds when asked
        let r = project_layers(&cloud, &frame, &loops, &cfg, Rounds::Exactly(3)).unwrap();
        assert_eq!(r.rmse.len(), 4);
    }

    #[test]
    fn heights_and_bad_settings() {
        let cloud = cylinder();
        let frame = CylinderFrame::of(cloud.points(), AxisChoice::Given(Vector3::y())).unwrap();
        let cfg = LayerConfig {
            layers: 5,
            margin: 0.25,
            ..Default::default()
        };
        assert_eq!(
            layer_heights(&frame, &cfg).unwrap(),
            vec![-1.0, -0.5, 0.0, 0.5, 1.0]
        );
        let bad = LayerConfig {
            layers: 3,
            ..Default::default()
        };
        assert!(layer_heights(&frame, &bad)
            .unwrap_err()
            .to_string()
            .contains("between 4"));
        let huge = LayerConfig {
            layers: 1 << 62,
            ..Default::default()
        };
        assert!(layer_heights(&frame, &huge)
            .unwrap_err()
            .to_string()
            .contains("and 4096"));
        let bad = LayerConfig {
            margin: 0.5,
            ..Default::default()
        };
        assert!(layer_heights(&frame, &bad).is_err());
    }
}
