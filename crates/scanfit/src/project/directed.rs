//! Directed projection of a point onto a point cloud ([Aza04]), as
//! written in [MBA18] eqs. (5)-(15) and [TURN17] eqs.
//! (7)-(16) and (19).
//!
//! A point `p` moves along a direction `n` to `p* = p + t n` (eq. 8), the
//! minimiser of the weighted squared distance to the cloud
//! `E(p*) = sum_d a_d |p* - p_d|^2` (eq. 5). With the five-number summary
//! `c0 = sum a_d`, `(c1, c2, c3) = sum a_d p_d`, `c4 = sum a_d |p_d|^2`
//! (eq. 6), `E(p) = c0 |p|^2 - 2 c.p + c4` (eq. 7) and its minimum along the
//! line is `t = (lambda - p.n) / |n|^2`, `lambda = (c1 nx + c2 ny + c3 nz) / c0`
//! (eqs. 10-11; `E'' = 2 c0 |n|^2 > 0`, eq. 12). The sums are accumulated
//! relative to `p` (which leaves `t` unchanged) so that georeferenced
//! coordinates keep their precision.
//!
//! The weights `a_d` depend on `p`, so the projection is iterated: the
//! weights are recomputed at `p*` and the point moves again along `n`, until
//! the step is below a tolerance.
//!
//! Weight factors ([`WeightFactor`]), with `r_d = |p - p_d|` and
//! `e_d = |(p_d - p) x n|` (distance of `p_d` from the projection line, `n` unit):
//!
//! | factor (CLI name) | formula | source |
//! |---|---|---|
//! | `PointDistance` (`aza04`) | `1 / r^4` | [Aza04]; [MBA18] eq. 13, [TURN17] eq. 15 |
//! | `DampedDistanceOffset` (`as05`) | `1 / (1 + r^2 e^2)` | [AS05]; [MBA18] eq. 14, [TURN17] eq. 16 |
//! | `DistanceOffset` (`moon`) | `1 / (r^4 e^2)` | [TURN17] eq. 19, the modified factor |
//! | `LineOffset` (`axis4`) | `1 / e^4` | [MBA18] eq. 15 (its citation of the modified factor, as printed) |
//!
//! Guarded division: a cloud point with a zero denominator (on `p` itself,
//! or on the projection line for the factors with `e`) has an infinite
//! weight; the limit of eq. 11 is then the mean of those points alone, which
//! is what is computed.
//!
//! Neighbourhoods ([`Neighbourhood`]): the papers sum over all points
//! (`All`, exact, O(n) per step); the default sums over the k nearest points
//! of the current `p*` (fast; the distant points' weights are negligible, see
//! the test `nearest_neighbourhood_agrees_with_all_points`).

use rayon::prelude::*;

use crate::cloud::PointCloud;
use crate::{Error, Point3, Result, Vector3};

/// The weight factor `a_d` of [MBA18] eq. 5 (see the module table), named by
/// what it weights a cloud point `p_d` by: `r = |p - p_d|`, its distance to
/// the moving point, and `e = |(p_d - p) x n|`, its offset from the
/// projection line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WeightFactor {
    /// `1 / r^4`: the distance to the moving point ([Aza04]; [MBA18] eq. 13,
    /// [TURN17] eq. 15). Command-line name `aza04`.
    PointDistance,
    /// `1 / (1 + r^2 e^2)`: distance and line offset, damped by the `1 +`
    /// ([AS05]; [MBA18] eq. 14, [TURN17] eq. 16). Command-line name `as05`.
    DampedDistanceOffset,
    /// `1 / (r^4 e^2)`: distance and line offset ([TURN17] eq. 19, the
    /// modified factor). Command-line name `moon`.
    #[default]
    DistanceOffset,
    /// `1 / e^4`: the line offset alone ([MBA18] eq. 15 as printed, its
    /// citation of the modified factor). Command-line name `axis4`.
    LineOffset,
}

#[allow(non_upper_case_globals)]
impl WeightFactor {
    /// Old name of [`WeightFactor::PointDistance`].
    #[deprecated(note = "use WeightFactor::PointDistance")]
    pub const Aza04: Self = Self::PointDistance;
    /// Old name of [`WeightFactor::DampedDistanceOffset`].
    #[deprecated(note = "use WeightFactor::DampedDistanceOffset")]
    pub const As05: Self = Self::DampedDistanceOffset;
    /// Old name of [`WeightFactor::DistanceOffset`].
    #[deprecated(note = "use WeightFactor::DistanceOffset")]
    pub const Moon: Self = Self::DistanceOffset;
    /// Old name of [`WeightFactor::LineOffset`].
    #[deprecated(note = "use WeightFactor::LineOffset")]
    pub const Axis4: Self = Self::LineOffset;
}

impl WeightFactor {
    /// Short name used on the command line (`aza04`, `as05`, `moon`, `axis4`:
    /// the paper keys, unchanged by the renaming of the variants).
    ///
    /// ```
    /// use scanfit::project::WeightFactor;
    /// assert_eq!(WeightFactor::DistanceOffset.name(), "moon");
    /// assert_eq!(WeightFactor::from_name("AZA04"), Some(WeightFactor::PointDistance));
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Self::PointDistance => "aza04",
            Self::DampedDistanceOffset => "as05",
            Self::DistanceOffset => "moon",
            Self::LineOffset => "axis4",
        }
    }

    /// Parses a [`name`](Self::name).
    pub fn from_name(s: &str) -> Option<Self> {
        [
            Self::PointDistance,
            Self::DampedDistanceOffset,
            Self::DistanceOffset,
            Self::LineOffset,
        ]
        .into_iter()
        .find(|w| w.name().eq_ignore_ascii_case(s))
    }

    /// The denominator of the weight (`a_d = 1 / denominator`) from `r^2`
    /// and `e^2`. `As05` is not scale-invariant and gets real units; the
    /// others are homogeneous, so the caller may pass scaled distances.
    fn denominator(self, r2: f64, e2: f64) -> f64 {
        match self {
            Self::PointDistance => r2 * r2,
            Self::DampedDistanceOffset => 1.0 + r2 * e2,
            Self::DistanceOffset => r2 * r2 * e2,
            Self::LineOffset => e2 * e2,
        }
    }
}

/// Which cloud points enter the sums of eq. 6.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Neighbourhood {
    /// Every point of the cloud (the papers' definition; O(n) per step).
    All,
    /// The k nearest points of the current position (default k = 32).
    Nearest(usize),
    /// The points within this distance of the current position.
    Radius(f64),
}

/// Settings of the directed projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectedConfig {
    /// Weight factor (default [TURN17]'s eq. 19).
    pub weight: WeightFactor,
    /// Which points enter the sums (default the 32 nearest).
    pub neighbourhood: Neighbourhood,
    /// Stop when a step moves the point less than this fraction of the
    /// cloud's bounding-box diagonal (default 1e-9).
    pub tolerance: f64,
    /// Most re-weighting steps (default 50).
    pub max_iterations: usize,
}

impl Default for DirectedConfig {
    fn default() -> Self {
        Self {
            weight: WeightFactor::DistanceOffset,
            neighbourhood: Neighbourhood::Nearest(32),
            tolerance: 1e-9,
            max_iterations: 50,
        }
    }
}

/// The result of projecting one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    /// The projected point `p* = p + t n` (n normalised).
    pub point: Point3,
    /// Signed distance moved along the unit direction.
    pub t: f64,
    /// Weighted RMS distance of the cloud from `p*`, `sqrt(E(p*) / c0)`
    /// (eq. 7 with the weights of the last step).
    pub residual: f64,
    /// Re-weighting steps taken.
    pub iterations: usize,
    /// Whether the last step was below the tolerance.
    pub converged: bool,
    /// Cloud points in the final neighbourhood (0: nothing within the
    /// radius; the point did not move).
    pub neighbours: usize,
}

impl DirectedConfig {
    fn validate(&self) -> Result<()> {
        match self.neighbourhood {
            Neighbourhood::Nearest(0) => {
                return Err(Error::InvalidInput(
                    "directed projection needs k >= 1 nearest points".into(),
                ))
            }
            Neighbourhood::Radius(r) if !(r.is_finite() && r > 0.0) => {
                return Err(Error::InvalidInput(format!(
                    "directed projection radius {r} must be finite and > 0"
                )))
            }
            _ => {}
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(Error::InvalidInput(format!(
                "directed projection tolerance {} must be finite and > 0",
                self.tolerance
            )));
        }
        if self.max_iterations == 0 {
            return Err(Error::InvalidInput(
                "directed projection needs max_iterations >= 1".into(),
            ));
        }
        Ok(())
    }
}

/// One step of eqs. 5-11 at `p` along unit `n` over the points `ids` (all
/// points when `None`): returns `(t, residual, count)`.
fn step(
    points: &[Point3],
    ids: Option<&[usize]>,
    p: &Point3,
    n: &Vector3,
    weight: WeightFactor,
    scale: f64,
) -> (f64, f64, usize) {
    // homogeneous factors work in units of the cloud's size (no overflow of r^8)
    let unit = if weight == WeightFactor::DampedDistanceOffset {
        1.0
    } else {
        scale
    };
    let tiny = 1e-280;
    // (c0, c1..c3 relative to p as one vector, c4 relative to p)
    let mut c0 = 0.0;
    let mut c = Vector3::zeros();
    let mut c4 = 0.0;
    // the infinite-weight points (limit of eq. 11): count, sum, sum of squares
    let (mut z0, mut zc, mut z4) = (0usize, Vector3::zeros(), 0.0);
    let mut visit = |d: Vector3| {
        let dv = d / unit;
        let r2 = dv.norm_squared();
        let e2 = dv.cross(n).norm_squared();
        let den = weight.denominator(r2, e2);
        if den <= tiny {
            z0 += 1;
            zc += d;
            z4 += d.norm_squared();
        } else {
            let a = 1.0 / den;
            c0 += a;
            c += a * d;
            c4 += a * d.norm_squared();
        }
    };
    let count = match ids {
        Some(ids) => {
            for &i in ids {
                visit(points[i] - p);
            }
            ids.len()
        }
        None => {
            for q in points {
                visit(q - p);
            }
            points.len()
        }
    };
    let (c0, c, c4) = if z0 > 0 {
        (z0 as f64, zc, z4)
    } else {
        (c0, c, c4)
    };
    if !(c0 > 0.0 && c0.is_finite()) {
        return (0.0, 0.0, 0);
    }
    // eq. 10-11 with p as the origin: t = lambda = (c . n) / c0, |n| = 1
    let t = c.dot(n) / c0;
    // eq. 7 at p* = p + t n (origin at p): E/c0 = t^2 - 2 t (c.n)/c0 + c4/c0
    let e = (t * t - 2.0 * t * c.dot(n) / c0 + c4 / c0).max(0.0);
    (t, e.sqrt(), count)
}

/// Projects `p` along `direction` onto `cloud` (see the module documentation).
pub fn project_directed(
    cloud: &PointCloud,
    p: &Point3,
    direction: &Vector3,
    config: &DirectedConfig,
) -> Result<Projected> {
    config.validate()?;
    if cloud.is_empty() {
        return Err(Error::InvalidInput(
            "cannot project onto an empty point cloud".into(),
        ));
    }
    if !p.coords.iter().all(|c| c.is_finite()) {
        return Err(Error::InvalidInput(format!(
            "the point to project ({p:?}) is not finite"
        )));
    }
    let len = direction.norm();
    if !(len.is_finite() && len > 0.0) {
        return Err(Error::InvalidInput(format!(
            "projection direction {direction:?} must be finite and non-zero"
        )));
    }
    let n = direction / len;
    let scale = cloud.diagonal().max(f64::MIN_POSITIVE);
    if !matches!(config.neighbourhood, Neighbourhood::All) {
        cloud.tree()?;
    }
    project_one(cloud, p, &n, config, scale)
}

fn project_one(
    cloud: &PointCloud,
    p0: &Point3,
    n: &Vector3,
    config: &DirectedConfig,
    scale: f64,
) -> Result<Projected> {
    let points = cloud.points();
    let mut total = 0.0;
    let mut p = *p0;
    let mut ids: Vec<usize> = Vec::new();
    let mut result = Projected {
        point: p,
        t: 0.0,
        residual: 0.0,
        iterations: 0,
        converged: false,
        neighbours: 0,
    };
    for it in 1..=config.max_iterations {
        let sel = match config.neighbourhood {
            Neighbourhood::All => None,
            Neighbourhood::Nearest(k) => {
                ids.clear();
                ids.extend(cloud.knn(&p, k)?.into_iter().map(|nb| nb.index));
                Some(ids.as_slice())
            }
            Neighbourhood::Radius(r) => {
                ids.clear();
                ids.extend(cloud.within(&p, r)?.into_iter().map(|nb| nb.index));
                Some(ids.as_slice())
            }
        };
        let (t, residual, count) = step(points, sel, &p, n, config.weight, scale);
        if count == 0 {
            result.iterations = it;
            return Ok(result);
        }
        total += t;
        p = p0 + total * n;
        result = Projected {
            point: p,
            t: total,
            residual,
            iterations: it,
            converged: t.abs() <= config.tolerance * scale,
            neighbours: count,
        };
        if result.converged {
            break;
        }
    }
    Ok(result)
}

/// Projects every `points[i]` along `directions[i]` onto `cloud`, in parallel.
/// An error names the first bad query index.
pub fn project_directed_batch(
    cloud: &PointCloud,
    points: &[Point3],
    directions: &[Vector3],
    config: &DirectedConfig,
) -> Result<Vec<Projected>> {
    if points.len() != directions.len() {
        return Err(Error::InvalidInput(format!(
            "{} points but {} directions to project along; give one direction per point",
            points.len(),
            directions.len()
        )));
    }
    config.validate()?;
    if cloud.is_empty() {
        return Err(Error::InvalidInput(
            "cannot project onto an empty point cloud".into(),
        ));
    }
    if !matches!(config.neighbourhood, Neighbourhood::All) {
        cloud.tree()?;
    }
    let scale = cloud.diagonal().max(f64::MIN_POSITIVE);
    points
        .par_iter()
        .zip(directions.par_iter())
        .enumerate()
        .map(|(i, (p, d))| {
            let len = d.norm();
            if !(len.is_finite() && len > 0.0 && p.coords.iter().all(|c| c.is_finite())) {
                return Err(Error::InvalidInput(format!(
                    "query {i}: point {p:?} / direction {d:?} must be finite, the direction non-zero"
                )));
            }
            project_one(cloud, p, &(d / len), config, scale)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of z = f(x, y) on a jittered grid over [-1, 1]^2.
    fn height_field(n: usize, f: impl Fn(f64, f64) -> f64) -> PointCloud {
        let mut p = Vec::new();
        let mut rng = crate::testdata::Lcg::new(12345);
        let mut rnd = || rng.next_f64() - 0.5;
        let h = 2.0 / (n - 1) as f64;
        for i in 0..n {
            for j in 0..n {
                let x = -1.0 + h * (i as f64 + 0.3 * rnd());
                let y = -1.0 + h * (j as f64 + 0.3 * rnd());
                p.push(Point3::new(x, y, f(x, y)));
            }
        }
        PointCloud::new(p).unwrap()
    }

    /// Eqs. 6, 10, 11 transcribed literally (absolute coordinates, c0..c4),
    /// one step, all points: the reference for the centred implementation.
    fn literal_step(cloud: &PointCloud, p: &Point3, n: &Vector3, w: WeightFactor) -> f64 {
        let (mut c0, mut c1, mut c2, mut c3) = (0.0, 0.0, 0.0, 0.0);
        for q in cloud.points() {
            let r2 = (p - q).norm_squared();
            let e2 = (q - p).cross(n).norm_squared();
            let a = match w {
                WeightFactor::PointDistance => 1.0 / (r2 * r2),
                WeightFactor::DampedDistanceOffset => 1.0 / (1.0 + r2 * e2),
                WeightFactor::DistanceOffset => 1.0 / (r2 * r2 * e2),
                WeightFactor::LineOffset => 1.0 / (e2 * e2),
            };
            c0 += a;
            c1 += a * q.x;
            c2 += a * q.y;
            c3 += a * q.z;
        }
        let lambda = (c1 * n.x + c2 * n.y + c3 * n.z) / c0;
        (lambda - p.coords.dot(n)) / n.norm_squared()
    }

    #[test]
    fn one_step_matches_the_literal_equations() {
        let cloud = height_field(15, |x, y| 0.3 * x * x - 0.2 * x * y + 0.1);
        let p = Point3::new(0.123, -0.321, 0.9);
        let n = Vector3::new(0.1, 0.05, -1.0).normalize();
        for w in [
            WeightFactor::PointDistance,
            WeightFactor::DampedDistanceOffset,
            WeightFactor::DistanceOffset,
            WeightFactor::LineOffset,
        ] {
            let cfg = DirectedConfig {
                weight: w,
                neighbourhood: Neighbourhood::All,
                max_iterations: 1,
                ..Default::default()
            };
            let r = project_directed(&cloud, &p, &n, &cfg).unwrap();
            let want = literal_step(&cloud, &p, &n, w);
            assert!((r.t - want).abs() < 1e-12, "{w:?}: {} vs {want}", r.t);
            assert_eq!(r.neighbours, cloud.len());
        }
    }

    #[test]
    fn projection_lands_on_the_sampled_surface() {
        let f = |x: f64, y: f64| 0.5 * (2.0 * x).sin() * y + 0.2;
        let cloud = height_field(60, f);
        for w in [
            WeightFactor::PointDistance,
            WeightFactor::DistanceOffset,
            WeightFactor::LineOffset,
        ] {
            let cfg = DirectedConfig {
                weight: w,
                ..Default::default()
            };
            for &(x, y) in &[(0.1, 0.2), (-0.55, 0.7), (0.8, -0.8)] {
                let r = project_directed(
                    &cloud,
                    &Point3::new(x, y, 3.0),
                    &Vector3::new(0.0, 0.0, -2.0),
                    &cfg,
                )
                .unwrap();
                assert!(r.converged, "{w:?} {x} {y}: {r:?}");
                // stays on the line
                assert!((r.point.x - x).abs() < 1e-15 && (r.point.y - y).abs() < 1e-15);
                // within 6% of the spacing (1/30) of the surface (measured 1.2e-3)
                assert!(
                    (r.point.z - f(x, y)).abs() < 2e-3,
                    "{w:?}: {r:?} vs {}",
                    f(x, y)
                );
            }
        }
    }

    #[test]
    fn nearest_neighbourhood_agrees_with_all_points() {
        // the stated tolerance: 1e-4 of the diagonal (2.8) on a smooth sheet of 40x40
        let f = |x: f64, y: f64| 0.4 * x * x + 0.3 * y;
        let cloud = height_field(40, f);
        let mut worst: f64 = 0.0;
        for w in [
            WeightFactor::PointDistance,
            WeightFactor::DistanceOffset,
            WeightFactor::LineOffset,
        ] {
            for &(x, y) in &[(0.0, 0.0), (0.33, -0.6), (-0.7, 0.45), (0.9, 0.9)] {
                let p = Point3::new(x, y, 1.5);
                let n = Vector3::new(0.0, 0.0, -1.0);
                let all = DirectedConfig {
                    weight: w,
                    neighbourhood: Neighbourhood::All,
                    ..Default::default()
                };
                let near = DirectedConfig {
                    weight: w,
                    ..Default::default()
                };
                let a = project_directed(&cloud, &p, &n, &all).unwrap();
                let b = project_directed(&cloud, &p, &n, &near).unwrap();
                worst = worst.max((a.point - b.point).norm());
            }
        }
        // measured 2.1e-4 = 7.5e-5 of the diagonal, 0.4% of the point spacing
        assert!(worst < 1e-4 * cloud.diagonal(), "worst {worst}");
    }

    #[test]
    fn a_point_on_the_line_dominates() {
        let cloud = PointCloud::new(vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 1.0),
            Point3::new(0.0, 1.0, -1.0),
        ])
        .unwrap();
        // the line x = y = 0 passes exactly through point 0: infinite weight for Moon/Axis4
        for w in [WeightFactor::DistanceOffset, WeightFactor::LineOffset] {
            let cfg = DirectedConfig {
                weight: w,
                neighbourhood: Neighbourhood::All,
                ..Default::default()
            };
            let r =
                project_directed(&cloud, &Point3::new(0.0, 0.0, 5.0), &Vector3::z(), &cfg).unwrap();
            assert_eq!(r.point, Point3::origin());
            assert!(r.converged);
        }
    }

    #[test]
    fn batch_equals_single_and_bad_input_is_an_error() {
        let cloud = height_field(20, |x, y| x * y);
        let pts: Vec<Point3> = (0..50)
            .map(|i| Point3::new(-0.9 + 0.036 * i as f64, 0.3, 2.0))
            .collect();
        let dirs = vec![Vector3::new(0.0, 0.0, -1.0); pts.len()];
        let cfg = DirectedConfig::default();
        let b = project_directed_batch(&cloud, &pts, &dirs, &cfg).unwrap();
        for (p, r) in pts.iter().zip(&b) {
            assert_eq!(*r, project_directed(&cloud, p, &dirs[0], &cfg).unwrap());
        }
        let mut bad = dirs.clone();
        bad[7] = Vector3::zeros();
        let e = project_directed_batch(&cloud, &pts, &bad, &cfg).unwrap_err();
        assert!(e.to_string().contains("query 7"), "{e}");
        assert!(project_directed_batch(&cloud, &pts, &dirs[..3], &cfg).is_err());
        let radius = DirectedConfig {
            neighbourhood: Neighbourhood::Radius(0.01),
            ..cfg
        };
        let far =
            project_directed(&cloud, &Point3::new(9.0, 9.0, 9.0), &Vector3::z(), &radius).unwrap();
        assert_eq!(far.neighbours, 0);
        assert!(!far.converged);
        assert_eq!(far.point, Point3::new(9.0, 9.0, 9.0));
    }
}
