//! The virtual turntable parameterization of cylindrical point clouds
//! ([TURN17]), end to end:
//!
//! 1. the axis ([`axis`]): given, or the cloud's principal axis; the centre
//!    `c0` from Ritter's farthest pair across the axis (section 3.2);
//! 2. the virtual turntable ([`views`]): `V` turns (eqs. 17-18), hidden
//!    point removal from `+z`, an MBA surface per view, grid rows per layer
//!    trimmed at the intersection pairs (sections 3.2-3.3);
//! 3. layer curves ([`layers`]): closed chord-length interpolation, uniform
//!    resampling, directed projection in the layer plane with weight eq. 19,
//!    repeated to a threshold (sections 3.4-3.5);
//! 4. the base surface ([`base_surface`]): periodic grid interpolation,
//!    refinement along the normal and relaxation (sections 3.6-3.7);
//! 5. parameters by orthogonal projection onto the base surface (`u`
//!    periodic around the axis), a least-squares B-spline surface periodic
//!    in `u`, its errors and the fold-overs of the parameterization
//!    (section 4).

pub mod axis;
pub mod base_surface;
pub mod ends;
pub mod layers;
pub mod views;

pub use axis::{principal_axis, AxisChoice, CylinderFrame};
pub use base_surface::{aligned_samples, initial_base_surface, refine_round, RefineConfig};
pub use ends::{end_shapes, EndShape};
pub use layers::{
    closed_curve, compare_weights, layer_heights, layer_heights_between, layer_loops,
    project_layers, uniform_samples, LayerConfig, LayerCurves, Rounds,
};
pub use views::{layer_polygon, turntable_views, View, ViewConfig};

use crate::bspline::Surface;
use crate::cloud::PointCloud;
use crate::fit::surface::{fit_surface, SurfaceFitConfig};
use crate::metrics::{ErrorStats, ParamQuality};
use crate::pipeline::assess::{parameterization, AssessConfig};
use crate::project::{InversionConfig, SurfaceInverter};
use crate::{Error, Point3, Result};

/// Everything the pipeline needs, with the paper's defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntableConfig {
    /// The turntable axis (default: the principal axis).
    pub axis: AxisChoice,
    /// Turns, hidden point removal, MBA, grid (default 4 views, 64 grid points).
    pub views: ViewConfig,
    /// Layers and their projection (default 40 layers, eq. 19).
    pub layers: LayerConfig,
    /// Refinement and relaxation (default 2 rounds).
    pub refine: RefineConfig,
    /// The final least-squares fit (default bicubic, 40 x 40, periodic in `u`).
    pub fit: SurfaceFitConfig,
    /// Orthogonal projection onto the base and fitted surfaces.
    pub inversion: InversionConfig,
    /// What happens to the points beyond the end layers (default: left out of the fit).
    pub ends: Ends,
    /// Decide from the data whether each end is open (a rim: the layers run
    /// to it, no margin) or closed (a bottom or a pole: the layer margin
    /// applies), [`ends::end_shapes`] (default true); false: the margin at
    /// both ends.
    pub detect_open_ends: bool,
    /// How the fold-overs and stretch of the parameters are measured: the
    /// `parameterization`, `measure`, `sample_points` and `seed` of
    /// [`AssessConfig`] (default: on a cluster sample above
    /// [`DEFAULT_SAMPLE_POINTS`](crate::pipeline::assess::DEFAULT_SAMPLE_POINTS)
    /// points, as every surface command; [`Measure::Full`](crate::pipeline::assess::Measure::Full):
    /// a Delaunay triangulation of all parameters).
    /// [`pipeline::turntable`](crate::pipeline::turntable) sets it from its
    /// `assess`.
    pub quality: AssessConfig,
}

/// The points beyond the first and last layer (the ends of the cloud: the
/// rims of a tube, the closed top of a head). Their orthogonal projection
/// lands on the base surface's `v` boundary; the paper does not say what to
/// do with them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ends {
    /// Keep their boundary parameters (`v` = 0 or 1) but leave them out of
    /// the least-squares fit (default): the surface spans the layers' range
    /// and is faithful there; the ends stay open.
    #[default]
    Exclude,
    /// Continue `v` beyond the boundary by the distance to the boundary
    /// projection and fit every point. The surface then reaches over the
    /// ends, but around a closed end (a pole) the rows beyond the data are
    /// barely constrained: on the blob sample the fitted surface flares up to
    /// 90 units away from the cloud, although every point is within 0.3 of it.
    Extend,
}

impl Default for TurntableConfig {
    fn default() -> Self {
        Self {
            axis: AxisChoice::Principal,
            views: ViewConfig::default(),
            layers: LayerConfig::default(),
            refine: RefineConfig::default(),
            fit: SurfaceFitConfig {
                ctrl: (40, 40),
                periodic_u: true,
                ..Default::default()
            },
            inversion: InversionConfig::default(),
            ends: Ends::Exclude,
            detect_open_ends: true,
            quality: AssessConfig::default(),
        }
    }
}

/// The pipeline's stages, reported to the caller's progress callback.
pub const STAGES: [&str; 7] = [
    "axis and centre",
    "virtual turntable (hidden point removal, MBA)",
    "layer curves and projection",
    "initial base surface",
    "refinement and relaxation",
    "parameters (orthogonal projection)",
    "least-squares fit and errors",
];

/// What the pipeline produced.
#[derive(Debug, Clone)]
pub struct Turntable {
    /// The low and high end (along the axis): open (fitted to the rim) or
    /// closed (left out by the layer margin), [`ends::end_shapes`].
    pub end_shapes: [EndShape; 2],
    /// The turntable frame (axis, centre, extent).
    pub frame: CylinderFrame,
    /// The views with their visible sets and MBA surfaces.
    pub views: Vec<View>,
    /// Layer heights relative to the centre.
    pub heights: Vec<f64>,
    /// Each layer's interpolation points after trimming and outlier removal.
    pub loops: Vec<Vec<Point3>>,
    /// The projected layer curves and the RMSE per round.
    pub layers: LayerCurves,
    /// Samples around the axis per layer in the base surface grid.
    pub grid_u: usize,
    /// The initial base surface (section 3.6).
    pub initial_base: Surface,
    /// RMSE of the projected grid per refinement round (section 3.7).
    pub refine_rmse: Vec<f64>,
    /// The final base surface.
    pub base: Surface,
    /// Distances of the cloud points to the base surface.
    pub base_errors: ErrorStats,
    /// Parameters of every cloud point in `[0, 1]^2` (`u` periodic around
    /// the axis; `v` of the base surface, 0 or 1 beyond the end layers, or
    /// continued there with [`Ends::Extend`]).
    pub uv: Vec<[f64; 2]>,
    /// Points whose projection lies on the `v` boundary of the base surface
    /// (beyond the first or last layer: the ends of the cloud).
    pub on_v_boundary: usize,
    /// Per point: whether it entered the least-squares fit (all points with
    /// [`Ends::Extend`], those inside the layers' range with [`Ends::Exclude`]).
    pub fitted: Vec<bool>,
    /// The least-squares surface.
    pub surface: Surface,
    /// Orthogonal distance of every cloud point to the fitted surface.
    pub distances: Vec<f64>,
    /// Point inversions onto the fitted surface that did not converge
    /// (their distance is the best found).
    pub unconverged: usize,
    /// Their statistics over the fitted points (with [`Ends::Exclude`], the
    /// points inside the layers' range).
    pub errors: ErrorStats,
    /// Their statistics over every point (with [`Ends::Exclude`] the points
    /// beyond the end layers, which no surface row covers, count too).
    pub errors_all: ErrorStats,
    /// Distance from the fitted surface to the cloud: from each sample of a
    /// `4 n_u x 4 n_v` parameter grid to its nearest cloud point. The point
    /// errors above cannot see a surface that wanders off where there are no
    /// points; this can.
    pub surface_to_cloud: ErrorStats,
    /// Fold-overs and stretch of the parameterization of the fitted points
    /// on the fitted surface.
    pub quality: ParamQuality,
    /// The same over the points inside the layers' range (whose projection
    /// onto the base surface is interior). A closed end (the top of a head,
    /// the poles of an egg) is a singularity of any parameterization periodic
    /// around the axis: the pole maps to a whole row, and the triangles
    /// around it may fold; this count excludes them.
    pub quality_inside: ParamQuality,
    /// Parameters of the points' orthogonal projections onto the fitted
    /// surface (one round of parameter correction, Hoschek 1988; not part of
    /// the paper).
    pub uv_fitted: Vec<[f64; 2]>,
    /// Fold-overs and stretch with those parameters. The base surface's
    /// normals differ a little from the fitted surface's, so a noisy point
    /// moves sideways by its noise times that angle when projected onto the
    /// base surface; two close points can swap (on the blob sample, 0 to 3
    /// of 56 000 triangles, depending on the layer count). On the fitted
    /// surface itself they cannot (0 in every case measured).
    pub quality_fitted: ParamQuality,
    /// Points of the cluster sample the fold-overs and stretch were measured
    /// on (`None`: on every point), [`TurntableConfig::quality`].
    pub quality_sample: Option<usize>,
}

/// Runs the whole pipeline; `stage(i)` is called as stage `i` of [`STAGES`] starts.
pub fn turntable(
    cloud: &PointCloud,
    cfg: &TurntableConfig,
    stage: &mut dyn FnMut(usize),
) -> Result<Turntable> {
    let points = cloud.points();
    stage(0);
    let frame = CylinderFrame::of(points, cfg.axis)?;
    stage(1);
    let views = turntable_views(points, &frame, &cfg.views)?;
    stage(2);
    let end_shape = end_shapes(points, &frame, cfg.layers.margin);
    let margin_at = |e: &EndShape| {
        if cfg.detect_open_ends && e.open {
            0.0
        } else {
            cfg.layers.margin
        }
    };
    let heights = layer_heights_between(
        &frame,
        &cfg.layers,
        (margin_at(&end_shape[0]), margin_at(&end_shape[1])),
    )?;
    let loops = layer_loops(
        cloud,
        &frame,
        &views,
        &heights,
        cfg.views.grid_u,
        &cfg.layers,
    )?;
    let layers = project_layers(cloud, &frame, &loops, &cfg.layers, Rounds::UntilThreshold)?;
    stage(3);
    let (mut fit, grid_u) = initial_base_surface(&layers.curves, &layers.counts, &frame)?;
    let initial_base = fit.surface.clone();
    stage(4);
    if cfg.refine.rounds > 100 {
        return Err(Error::InvalidInput(format!(
            "{} refinement rounds: use at most 100 (the paper's refinement converges in a few)",
            cfg.refine.rounds
        )));
    }
    let mut refine_rmse = Vec::new();
    for _ in 0..cfg.refine.rounds {
        let (next, r) = refine_round(cloud, &fit, &cfg.refine)?;
        fit = next;
        refine_rmse.push(r);
    }
    let base = fit.surface;
    stage(5);
    let inverter = SurfaceInverter::new(&base, cfg.inversion)?;
    let inv = inverter.invert_all(points);
    let base_errors = ErrorStats::of(&inv.iter().map(|r| r.distance).collect::<Vec<_>>());
    let ((u0, u1), (v0, v1)) = base.domain();
    let eps = 1e-9;
    let mut inside = vec![true; points.len()];
    let mut raw: Vec<[f64; 2]> = inv
        .iter()
        .zip(inside.iter_mut())
        .map(|(r, inside)| {
            let v = (r.uv[1] - v0) / (v1 - v0);
            *inside = (eps..=1.0 - eps).contains(&v);
            [
                ((r.uv[0] - u0) / (u1 - u0)).rem_euclid(1.0),
                v.clamp(0.0, 1.0),
            ]
        })
        .collect();
    let on_v_boundary = inside.iter().filter(|&&i| !i).count();
    if cfg.ends == Ends::Extend {
        // continue v beyond the boundary by the point's distance from its
        // boundary projection, in units of the base surface's length along
        // v, then rescale to [0, 1]. (Distance rather than height: towards a
        // closed end the height changes ever more slowly.)
        let length_v = length_along_v(&base);
        for ((t, r), &ins) in raw.iter_mut().zip(&inv).zip(&inside) {
            if !ins {
                t[1] += if t[1] < 0.5 { -1.0 } else { 1.0 } * r.distance / length_v;
            }
        }
        let vmin = raw.iter().map(|t| t[1]).fold(0.0, f64::min);
        let vmax = raw.iter().map(|t| t[1]).fold(1.0, f64::max);
        for t in &mut raw {
            t[1] = ((t[1] - vmin) / (vmax - vmin)).clamp(0.0, 1.0);
        }
    }
    let uv = raw;
    drop(inv);
    stage(6);
    let fitted_points: Vec<bool> = match cfg.ends {
        Ends::Exclude => inside.clone(),
        Ends::Extend => vec![true; points.len()],
    };
    let subset = |mask: &[bool]| -> (Vec<Point3>, Vec<[f64; 2]>) {
        points
            .iter()
            .zip(&uv)
            .zip(mask)
            .filter(|(_, &m)| m)
            .map(|((p, t), _)| (*p, *t))
            .unzip()
    };
    let (fp, fuv) = subset(&fitted_points);
    let surface = fit_surface(&fp, &fuv, &cfg.fit)?;
    let fitted = SurfaceInverter::new(&surface, cfg.inversion)?;
    let feet = fitted.invert_all_from(points, &uv);
    let distances: Vec<f64> = feet.iter().map(|r| r.distance).collect();
    let unconverged = feet.iter().filter(|r| !r.converged).count();
    let ((fu0, fu1), (fv0, fv1)) = surface.domain();
    let uv_fitted: Vec<[f64; 2]> = feet
        .iter()
        .map(|r| {
            [
                ((r.uv[0] - fu0) / (fu1 - fu0)).rem_euclid(1.0),
                ((r.uv[1] - fv0) / (fv1 - fv0)).clamp(0.0, 1.0),
            ]
        })
        .collect();
    drop(feet);
    let pick = |mask: &[bool]| -> Vec<f64> {
        distances
            .iter()
            .zip(mask)
            .filter(|(_, &m)| m)
            .map(|(d, _)| *d)
            .collect()
    };
    let errors = ErrorStats::of(&pick(&fitted_points));
    let errors_all = ErrorStats::of(&distances);
    let surface_to_cloud = surface_to_cloud(cloud, &surface)?;
    // the fold-overs and stretch with the base surface's parameters and with
    // the fitted surface's: two Delaunay triangulations of the parameters
    // (serial each), side by side
    let fuv2: Vec<[f64; 2]> = uv_fitted
        .iter()
        .zip(&fitted_points)
        .filter(|(_, &m)| m)
        .map(|(t, _)| *t)
        .collect();
    let ((quality, quality_sample), (quality_fitted, _)) = rayon::join(
        || parameterization(&surface, &fp, &fuv, &cfg.quality),
        || parameterization(&surface, &fp, &fuv2, &cfg.quality),
    );
    // with Ends::Exclude the fitted points are the inside ones: the same
    // measure on the same points (measured once)
    let quality_inside = if inside == fitted_points {
        quality
    } else {
        let (pin, uvin) = subset(&inside);
        parameterization(&surface, &pin, &uvin, &cfg.quality).0
    };
    Ok(Turntable {
        frame,
        views,
        heights,
        loops,
        layers,
        grid_u,
        initial_base,
        refine_rmse,
        base,
        base_errors,
        uv,
        on_v_boundary,
        fitted: fitted_points,
        surface,
        distances,
        unconverged,
        errors,
        errors_all,
        quality,
        quality_sample,
        quality_inside,
        uv_fitted,
        quality_fitted,
        surface_to_cloud,
        end_shapes: end_shape,
    })
}

/// Mean length of the `v` iso-curves at 8 values of `u` (polylines of 128 segments).
fn length_along_v(s: &Surface) -> f64 {
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut total = 0.0;
    for i in 0..8 {
        let u = u0 + (u1 - u0) * i as f64 / 8.0;
        let mut prev = s.point(u, v0);
        for j in 1..=128 {
            let p = s.point(u, v0 + (v1 - v0) * j as f64 / 128.0);
            total += (p - prev).norm();
            prev = p;
        }
    }
    (total / 8.0).max(f64::MIN_POSITIVE)
}

/// Nearest-cloud distances of a `4 n_u x 4 n_v` grid of surface samples
/// (fewer for nets beyond 250 x 250, at most about 10^6 samples).
fn surface_to_cloud(cloud: &PointCloud, s: &Surface) -> Result<ErrorStats> {
    let (cu, cv) = s.counts();
    // 4 samples per control point in each direction, at most ~10^6 in all
    let scale = (1.0e6 / (16.0 * cu as f64 * cv as f64)).sqrt().min(1.0);
    let (nu, nv) = (
        ((4.0 * cu as f64 * scale) as usize).max(8),
        ((4.0 * cv as f64 * scale) as usize).max(8),
    );
    let ((u0, u1), (v0, v1)) = s.domain();
    let grid: Vec<Point3> = (0..nu)
        .flat_map(|i| {
            (0..=nv).map(move |j| {
                s.point(
                    u0 + (u1 - u0) * i as f64 / nu as f64,
                    v0 + (v1 - v0) * j as f64 / nv as f64,
                )
            })
        })
        .collect();
    let d: Vec<f64> = cloud
        .nearest_batch(&grid)?
        .into_iter()
        .map(|n| n.distance)
        .collect();
    Ok(ErrorStats::of(&d))
}
