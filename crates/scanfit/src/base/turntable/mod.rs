//! The virtual turntable parameterization of cylindrical point clouds
//! (Kim et al., `cylindrical-turntable-parameterization.txt`), end to end:
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
pub mod layers;
pub mod views;

pub use axis::{principal_axis, AxisChoice, CylinderFrame};
pub use base_surface::{aligned_samples, initial_base_surface, refine_round, RefineConfig};
pub use layers::{
    closed_curve, compare_weights, layer_heights, layer_loops, project_layers, uniform_samples,
    LayerConfig, LayerCurves, Rounds,
};
pub use views::{layer_polygon, turntable_views, View, ViewConfig};

use crate::bspline::Surface;
use crate::cloud::PointCloud;
use crate::fit::surface::{fit_surface, SurfaceFitConfig};
use crate::metrics::{parameterization_quality, ErrorStats, ParamQuality};
use crate::project::{InversionConfig, SurfaceInverter};
use crate::{Point3, Result};

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
    /// the axis; `v` of the base surface, continued beyond the end layers by
    /// the height and rescaled).
    pub uv: Vec<[f64; 2]>,
    /// Points whose projection lies on the `v` boundary of the base surface
    /// (beyond the first or last layer: the ends of the cloud); their `v`
    /// continues linearly with the height along the axis.
    pub on_v_boundary: usize,
    /// The least-squares surface.
    pub surface: Surface,
    /// Orthogonal distance of every cloud point to the fitted surface.
    pub distances: Vec<f64>,
    /// Their statistics.
    pub errors: ErrorStats,
    /// Fold-overs and stretch of the parameterization on the fitted surface.
    pub quality: ParamQuality,
    /// The same over the points inside the layers' range (whose projection
    /// onto the base surface is interior). A closed end (the top of a head,
    /// the poles of an egg) is a singularity of any parameterization periodic
    /// around the axis: the pole maps to a whole row, and the triangles
    /// around it may fold; this count excludes them.
    pub quality_inside: ParamQuality,
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
    let heights = layer_heights(&frame, &cfg.layers)?;
    let loops = layer_loops(cloud, &frame, &views, &heights, cfg.views.grid_u, &cfg.layers)?;
    let layers = project_layers(cloud, &frame, &loops, &cfg.layers, Rounds::UntilThreshold)?;
    stage(3);
    let (mut fit, grid_u) = initial_base_surface(&layers.curves, &layers.counts, &frame)?;
    let initial_base = fit.surface.clone();
    stage(4);
    let mut refine_rmse = Vec::with_capacity(cfg.refine.rounds);
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
    // Points beyond the first or last layer (the ends of the cloud) project
    // onto the base surface's v boundary and would all share one v. The paper
    // leaves them unspecified; we continue v beyond the boundary by the
    // point's distance from its boundary projection, in units of the base
    // surface's length along v, and rescale to [0, 1], so the fitted surface
    // covers the ends too. (Distance rather than height: towards a closed
    // end the height changes ever more slowly, which would crowd the points
    // near the pole into a sliver of v that a polynomial cannot follow.)
    let length_v = length_along_v(&base);
    let eps = 1e-9;
    let mut inside = vec![true; points.len()];
    let raw: Vec<[f64; 2]> = inv
        .iter()
        .zip(inside.iter_mut())
        .map(|(r, inside)| {
            let mut v = (r.uv[1] - v0) / (v1 - v0);
            if v <= eps {
                *inside = false;
                v -= r.distance / length_v;
            } else if v >= 1.0 - eps {
                *inside = false;
                v += r.distance / length_v;
            }
            [((r.uv[0] - u0) / (u1 - u0)).rem_euclid(1.0), v]
        })
        .collect();
    let vmin = raw.iter().map(|t| t[1]).fold(0.0, f64::min);
    let vmax = raw.iter().map(|t| t[1]).fold(1.0, f64::max);
    let uv: Vec<[f64; 2]> = raw
        .iter()
        .map(|t| [t[0], ((t[1] - vmin) / (vmax - vmin)).clamp(0.0, 1.0)])
        .collect();
    stage(6);
    let surface = fit_surface(points, &uv, &cfg.fit)?;
    let fitted = SurfaceInverter::new(&surface, cfg.inversion)?;
    let distances: Vec<f64> = fitted
        .invert_all_from(points, &uv)
        .iter()
        .map(|r| r.distance)
        .collect();
    let errors = ErrorStats::of(&distances);
    let quality = parameterization_quality(&surface, points, &uv)?;
    let on_v_boundary = inside.iter().filter(|&&i| !i).count();
    let (pin, uvin): (Vec<Point3>, Vec<[f64; 2]>) = points
        .iter()
        .zip(&uv)
        .zip(&inside)
        .filter(|(_, &i)| i)
        .map(|((p, t), _)| (*p, *t))
        .unzip();
    let quality_inside = parameterization_quality(&surface, &pin, &uvin)?;
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
        surface,
        distances,
        errors,
        quality,
        quality_inside,
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
