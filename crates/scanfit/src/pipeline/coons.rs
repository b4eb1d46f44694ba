//! The Coons pipeline: one patch of points to a surface, by the Coons paper
//! (`coons-base-surface-parameterization`) or the PDE paper
//! (`pde-coons-surface-reconstruction`).
//!
//! 1. boundary loop of the points (alpha shape in their best-fit plane, PDE paper 4.1);
//! 2. corners (smallest turning angle, Coons paper eqs. 10-12, or three-point
//!    curvature, PDE paper 4.1), or given loop positions;
//! 3. one B-spline per side (PDE paper 4.2) and the bilinearly blended Coons
//!    patch on them (Coons paper eq. 16, PDE paper eq. 1; three-sided with one side
//!    collapsed to the first corner);
//! 4. parameters on the patch: the nearest grid vertex and the iteration of
//!    the Coons paper's eqs. 17-22, or the exact closest point (PDE paper 4.4);
//! 5. either the least-squares B-spline surface on those parameters
//!    ([`CoonsRoute::Bspline`], Coons paper) or the thin-plate PDE deformation
//!    `S = S_c + S_PDE` fitted by least squares ([`CoonsRoute::Pde`], PDE
//!    paper eqs. 11-14), exported as a B-spline within a tolerance;
//! 6. errors: the PDE paper's eq. 15 (`|P - S(u, v)|` at the parameters) for the patch
//!    and the result, and the [`SurfaceQuality`](super::assess::SurfaceQuality) of the exported surface
//!    (orthogonal distances both ways, fold-overs, grid RMSE).

use crate::base::{
    coons_from_cloud, coons_parameters, CoonsFromCloud, CoonsFromCloudConfig, CoonsParamConfig,
    CoonsParameters, CoonsProjection,
};
use crate::bspline::Surface;
use crate::centring::Centring;
use crate::fit::surface::{fit_surface, SurfaceFitConfig};
use crate::metrics::{parametric_distances, ErrorStats};
use crate::pde::{fit_pde, BsplineConversionConfig, PdeConfig, PdeFit};
use crate::progress::Progress;
use crate::project::{GridIterationConfig, InversionConfig};
use crate::{Error, PointCloud, Result};

use super::assess::{assess_surface, AssessConfig, Assessment};
use super::regularize::{density_ctrl, scaled_smoothing, DEFAULT_RELATIVE_SMOOTHING};

/// Which surface is fitted on the Coons patch's parameters.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum CoonsRoute {
    /// The Coons paper: a least-squares B-spline surface on the parameters
    /// (degree and control net from the config; periodicity is ignored).
    Bspline(SurfaceFitConfig),
    /// The PDE paper: `S = S_c + S_PDE` with `M x N` sine terms (PDE paper
    /// eqs. 11-14), exported as a B-spline.
    Pde {
        /// Terms and rigidity (paper: 5 x 5, D = 1).
        pde: PdeConfig,
        /// Largest deviation of the exported B-spline from `S`, data units;
        /// `None` (default): `1e-4` x the bounding-box diagonal of the points.
        export_tolerance: Option<f64>,
    },
}

impl CoonsRoute {
    /// The Coons paper's route with degrees `degree` and a `ctrl` control
    /// net (the default route is bicubic, 20 x 20).
    pub fn bspline(degree: (usize, usize), ctrl: (usize, usize)) -> Self {
        Self::Bspline(SurfaceFitConfig {
            degree,
            ctrl,
            ..Default::default()
        })
    }

    /// The PDE paper's route with `m x n` terms, rigidity 1 and the default
    /// export tolerance.
    pub fn pde(m: usize, n: usize) -> Self {
        Self::Pde {
            pde: PdeConfig { m, n, d: 1.0 },
            export_tolerance: None,
        }
    }

    /// One line that says what the route fits, e.g. "Coons patch + PDE
    /// deformation, 5 x 5 terms (PDE paper)".
    pub fn describe(&self) -> String {
        match self {
            Self::Bspline(f) => format!(
                "least-squares B-spline surface, {} x {} control points (Coons paper)",
                f.ctrl.0, f.ctrl.1
            ),
            Self::Pde { pde, .. } => format!(
                "Coons patch + PDE deformation, {} x {} terms (PDE paper)",
                pde.m, pde.n
            ),
        }
    }

    /// The projection this route uses when the config names none: the Coons
    /// paper's grid iteration for the B-spline route, the exact closest
    /// point for the PDE route (as each paper does).
    pub fn default_projection(&self) -> CoonsProjection {
        match self {
            Self::Bspline(_) => CoonsProjection::GridIteration(GridIterationConfig::default()),
            Self::Pde { .. } => CoonsProjection::Inversion(InversionConfig::default()),
        }
    }
}

impl Default for CoonsRoute {
    fn default() -> Self {
        Self::bspline((3, 3), (20, 20))
    }
}

/// Settings of [`run`], with the papers' defaults.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CoonsConfig {
    /// Boundary (alpha 2.5 x median Delaunay edge), corners (4, smallest
    /// turning angle), given corner positions (none) and boundary curves
    /// (cubic, end-pinned least squares).
    pub base: CoonsFromCloudConfig,
    /// The surface fitted on the parameters (default: B-spline, bicubic, 20 x 20).
    pub route: CoonsRoute,
    /// How the points get their parameters; `None` (default): the route's
    /// [`CoonsRoute::default_projection`].
    pub projection: Option<CoonsProjection>,
    /// Tangential offset beyond the boundary above which a point counts as
    /// outside the patch; `None` (default): `1e-3` x the diagonal of the
    /// patch's control-net bounding box.
    pub outside_tolerance: Option<f64>,
    /// The assessment of the resulting surface (orthogonal distances by
    /// point inversion, the sample grid of the surface-to-points direction).
    pub assess: AssessConfig,
    /// `Some(r)` (default `Some(`[`DEFAULT_RELATIVE_EPSILON`]`)`): the grid
    /// iteration's convergence threshold epsilon is `r` x the bounding-box
    /// diagonal of the points, whatever the projection's own epsilon (the
    /// Coons paper's 0.01 is in data units, which makes the same command
    /// behave differently in millimetres and metres); `None`: the
    /// projection's epsilon as given.
    pub relative_epsilon: Option<f64>,
    /// B-spline route: choose the control net from the point count
    /// ([`density_ctrl`]) instead of the route's `ctrl` (default true).
    pub ctrl_from_density: bool,
    /// B-spline route: `Some(c)` (default `Some(`[`DEFAULT_RELATIVE_SMOOTHING`]`)`):
    /// the thin-plate weight is [`scaled_smoothing`]`(c, points, net)`;
    /// `None`: the route's `smoothing` as given (0 = the bare fit).
    pub relative_smoothing: Option<f64>,
}

/// The default relative epsilon of the grid iteration: `1e-3` x the
/// diagonal (the Coons paper's 0.01 data units on a patch of diagonal 10).
pub const DEFAULT_RELATIVE_EPSILON: f64 = 1e-3;

impl Default for CoonsConfig {
    fn default() -> Self {
        Self {
            base: CoonsFromCloudConfig::default(),
            route: CoonsRoute::default(),
            projection: None,
            outside_tolerance: None,
            assess: AssessConfig::default(),
            relative_epsilon: Some(DEFAULT_RELATIVE_EPSILON),
            ctrl_from_density: true,
            relative_smoothing: Some(DEFAULT_RELATIVE_SMOOTHING),
        }
    }
}

impl CoonsConfig {
    /// The projection [`run`] uses: the configured one, or the route's
    /// default (before [`CoonsConfig::relative_epsilon`] is applied).
    pub fn projection(&self) -> CoonsProjection {
        self.projection
            .unwrap_or_else(|| self.route.default_projection())
    }

    /// The projection [`run`] uses on points of bounding-box diagonal
    /// `diagonal`: [`CoonsConfig::projection`] with the relative epsilon.
    pub fn scaled_projection(&self, diagonal: f64) -> CoonsProjection {
        match (self.projection(), self.relative_epsilon) {
            (CoonsProjection::GridIteration(mut g), Some(r)) => {
                g.epsilon = r * diagonal;
                CoonsProjection::GridIteration(g)
            }
            (p, _) => p,
        }
    }

    /// The least-squares settings of the B-spline route for `points`
    /// points, after the density and scaling rules.
    pub fn resolved_fit(&self, fit: &SurfaceFitConfig, points: usize) -> SurfaceFitConfig {
        let mut f = SurfaceFitConfig {
            periodic_u: false,
            ..fit.clone()
        };
        if self.ctrl_from_density {
            f.ctrl = density_ctrl(points, f.degree);
        }
        if let Some(c) = self.relative_smoothing {
            f.smoothing = scaled_smoothing(c, points, f.ctrl);
        }
        f
    }
}

/// What the PDE route adds to the report.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PdeOutcome {
    /// The fitted PDE surface with its eq. 15 errors and residuals.
    pub fit: PdeFit,
    /// The export tolerance used (data units).
    pub export_tolerance: f64,
    /// Largest deviation of the exported B-spline from the PDE surface: the
    /// tolerance reached (above `export_tolerance` when `export_capped`).
    pub export_deviation: f64,
    /// The export stopped at the control-point cap (never more control
    /// points than input points) before it met `export_tolerance`.
    pub export_capped: bool,
}

/// Everything [`run`] produced.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CoonsReport {
    /// The Coons patch and what was found on the way: boundary loops,
    /// corners with their turning angles, side points, boundary curves.
    pub base: CoonsFromCloud,
    /// The Coons patch in B-spline form (domain `[0, 1]^2`).
    pub coons_surface: Surface,
    /// The projection that gave the parameters.
    pub projection: CoonsProjection,
    /// The points' parameters on the patch, with the outside flags.
    pub parameters: CoonsParameters,
    /// `|P_i - S_c(u_i, v_i)|` per point (PDE paper eq. 15 for the patch alone).
    pub coons_distances: Vec<f64>,
    /// Their statistics.
    pub coons_errors: ErrorStats,
    /// One line naming the route (as [`CoonsRoute::describe`]).
    pub route: String,
    /// The PDE surface and its export, on the PDE route.
    pub pde: Option<PdeOutcome>,
    /// The resulting B-spline surface (the exported form on the PDE route).
    pub surface: Surface,
    /// The assessment of the resulting surface: orthogonal distances from
    /// the points and from surface samples to the points, fold-overs, the
    /// grid RMSE. Its `at_parameters` is the PDE paper's eq. 15 of the fitted surface
    /// (of the PDE surface itself on the PDE route); its `residuals` are
    /// `|P_i - S(u_i, v_i)|` on the resulting B-spline surface.
    pub assessment: Assessment,
}

impl CoonsReport {
    /// `"grid"` (the Coons paper's grid iteration) or `"closest"` (exact
    /// closest point): the name the command line uses for the projection.
    pub fn projection_name(&self) -> &'static str {
        projection_name(&self.projection)
    }
}

/// `"grid"` or `"closest"` for a projection.
pub fn projection_name(p: &CoonsProjection) -> &'static str {
    match p {
        CoonsProjection::GridIteration(_) => "grid",
        CoonsProjection::Inversion(_) => "closest",
    }
}

/// Stages of [`run`], as reported to the progress callback.
pub const STAGES: [&str; 5] = [
    "boundary and corners",
    "parameters on the Coons patch",
    "surface fit",
    "B-spline form of the PDE surface",
    "assessment (orthogonal distances)",
];

/// Runs the Coons pipeline on `cloud` (see the module documentation).
///
/// Errors: whatever [`coons_from_cloud`] refuses (too few points, a boundary
/// with fewer corners than asked, bad corner positions), a failed
/// projection or fit (too few points for the control net or the sine
/// terms), and a non-positive export tolerance.
///
/// ```
/// use scanfit::pipeline::coons::{run, CoonsConfig, CoonsRoute};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a gently curved 10 x 7 panel on a 41 x 29 grid
/// let mut pts = Vec::new();
/// for i in 0..=40 {
///     for j in 0..=28 {
///         let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
///         pts.push(Point3::new(x, y, 0.02 * x * y));
///     }
/// }
/// let cloud = PointCloud::new(pts)?;
/// let mut cfg = CoonsConfig::default();
/// cfg.route = CoonsRoute::pde(4, 4);
/// let r = run(&cloud, &cfg, &NoProgress)?;
/// assert_eq!(r.base.corners.corners.len(), 4);
/// // a bilinear patch z = 0.02 x y is its own Coons patch
/// let e = r.assessment.quality.at_parameters;
/// assert!(e.max < 1e-3, "{e:?}");
/// assert_eq!(r.projection_name(), "closest");
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    cloud: &PointCloud,
    config: &CoonsConfig,
    progress: &dyn Progress,
) -> Result<CoonsReport> {
    // computed relative to the data's centre, moved back exactly (issue 14)
    let centring = Centring::of(cloud.points());
    let local = centring.cloud(cloud)?;
    Ok(centring.restore(run_centred(&local, config, progress)?))
}

/// [`run`] on data whose centre is at the origin.
fn run_centred(
    cloud: &PointCloud,
    config: &CoonsConfig,
    progress: &dyn Progress,
) -> Result<CoonsReport> {
    let pts = cloud.points();
    progress.stage(STAGES[0], None);
    let base = coons_from_cloud(pts, &config.base)?;
    let coons_surface = base.patch.to_bspline()?;
    progress.stage(STAGES[1], None);
    let projection = config.scaled_projection(cloud.diagonal());
    let parameters = coons_parameters(
        &coons_surface,
        pts,
        &CoonsParamConfig {
            projection,
            outside_tolerance: config.outside_tolerance,
        },
    )?;
    let coons_distances = parametric_distances(&coons_surface, pts, &parameters.uv);
    let coons_errors = ErrorStats::of(&coons_distances);
    progress.stage(STAGES[2], None);
    let (surface, pde) = match &config.route {
        CoonsRoute::Bspline(fit) => {
            let s = fit_surface(pts, &parameters.uv, &config.resolved_fit(fit, pts.len()))?;
            (s, None)
        }
        CoonsRoute::Pde {
            pde,
            export_tolerance,
        } => {
            let f = fit_pde(&base.patch, pts, &parameters.uv, pde)?;
            let tol = export_tolerance.unwrap_or(1e-4 * cloud.diagonal());
            if !(tol.is_finite() && tol > 0.0) {
                return Err(Error::InvalidSetting {
                    setting: "export_tolerance",
                    value: tol.to_string(),
                    hint: "the B-spline form of the PDE surface needs a positive, finite tolerance in data units (default 1e-4 x the diagonal)".into(),
                });
            }
            progress.stage(STAGES[3], None);
            let b = f.surface.to_bspline(&BsplineConversionConfig {
                max_control_points: Some(pts.len()),
                ..BsplineConversionConfig::new(tol)
            })?;
            (
                b.surface,
                Some(PdeOutcome {
                    fit: f,
                    export_tolerance: tol,
                    export_deviation: b.max_deviation,
                    export_capped: b.capped,
                }),
            )
        }
    };
    progress.stage(STAGES[4], None);
    let mut assessment = assess_surface(&surface, pts, &parameters.uv, &config.assess)?;
    if let Some(p) = &pde {
        // the PDE paper's eq. 15 is measured on S itself, not on its B-spline form
        assessment.quality.at_parameters = p.fit.errors;
    }
    Ok(CoonsReport {
        route: match &config.route {
            CoonsRoute::Bspline(f) => {
                CoonsRoute::Bspline(config.resolved_fit(f, pts.len())).describe()
            }
            r => r.describe(),
        },
        base,
        coons_surface,
        projection,
        parameters,
        coons_distances,
        coons_errors,
        pde,
        surface,
        assessment,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::Sides;
    use crate::metrics::grid_rmse;
    use crate::Point3;
    use std::f64::consts::PI;

    /// A curved 10 x 7 panel on a 41 x 29 grid: z = 0.3 sin(x / 3) + 0.01 x y,
    /// which a Coons patch reproduces from its boundary (a sum of functions
    /// of x and y and a bilinear term), plus a bump 0.5 sin(pi x / 10)
    /// sin(pi y / 7) that vanishes on the boundary, which it cannot.
    fn panel() -> PointCloud {
        let mut pts = Vec::new();
        for i in 0..=40 {
            for j in 0..=28 {
                let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
                let bump = 0.5 * (PI * x / 10.0).sin() * (PI * y / 7.0).sin();
                pts.push(Point3::new(
                    x,
                    y,
                    0.3 * (x / 3.0).sin() + 0.01 * x * y + bump,
                ));
            }
        }
        PointCloud::new(pts).unwrap()
    }

    #[test]
    fn bspline_route_fits_the_panel_on_grid_parameters() {
        let cloud = panel();
        // the paper's fit: the given net, no smoothing
        let cfg = CoonsConfig {
            route: CoonsRoute::bspline((3, 3), (12, 10)),
            ctrl_from_density: false,
            relative_smoothing: None,
            ..Default::default()
        };
        let r = run(&cloud, &cfg, &crate::progress::NoProgress).unwrap();
        assert_eq!(r.projection_name(), "grid");
        assert_eq!(r.surface.counts(), (12, 10));
        assert!(r.pde.is_none());
        let q = r.assessment.quality;
        // the Coons patch misses the bump (it only interpolates the
        // boundary curves); the fit follows it
        assert!(r.coons_errors.max > 0.45, "{:?}", r.coons_errors);
        // within the grid iteration's epsilon (0.01 data units; measured 0.0067)
        assert!(q.at_parameters.max < 0.01, "{:?}", q.at_parameters);
        assert!(q.orthogonal.max <= q.at_parameters.max + 1e-9);
        assert_eq!(q.points, 41 * 29);
        assert_eq!(r.assessment.residuals.len(), 41 * 29);
        assert_eq!(
            q.grid_rmse,
            grid_rmse(&r.surface, cloud.points(), None).unwrap()
        );
        // the corners are the grid's corners
        let outer = r.base.boundary.outer_loop();
        let mut c: Vec<[i64; 2]> = r
            .base
            .corners
            .corners
            .iter()
            .map(|&k| {
                let p = cloud.points()[outer[k]];
                [p.x.round() as i64, p.y.round() as i64]
            })
            .collect();
        c.sort();
        assert_eq!(c, vec![[0, 0], [0, 7], [10, 0], [10, 7]]);
    }

    #[test]
    fn pde_route_measures_eq15_on_the_pde_surface_and_exports_within_tolerance() {
        let cloud = panel();
        let cfg = CoonsConfig {
            route: CoonsRoute::pde(4, 4),
            ..Default::default()
        };
        let r = run(&cloud, &cfg, &crate::progress::NoProgress).unwrap();
        assert_eq!(r.projection_name(), "closest");
        let p = r.pde.as_ref().unwrap();
        assert!((p.export_tolerance - 1e-4 * cloud.diagonal()).abs() < 1e-15);
        assert!(p.export_deviation <= p.export_tolerance);
        let q = r.assessment.quality;
        assert_eq!(q.at_parameters, p.fit.errors);
        // the bump is the first sine term of the deformation (PDE paper eq. 11):
        // what is left is the boundary curves' error (measured: RMSE 0.242
        // for the Coons patch, 0.00053 for S, max 0.00092)
        assert!(r.coons_errors.rmse > 0.2, "{:?}", r.coons_errors);
        assert!(q.at_parameters.rmse < 0.01 * r.coons_errors.rmse, "{q:?}");
        assert!(q.at_parameters.max < 2e-3, "{q:?}");
        // each point is at most |P - S(u,v)| + |S - B| from the exported B
        for (k, d) in r.assessment.distances().iter().enumerate() {
            assert!(
                *d <= p.fit.residuals[k] + p.export_deviation + 1e-9,
                "point {k}"
            );
        }
        assert!(r.route.contains("4 x 4 terms"));
    }

    #[test]
    fn three_sided_patch_and_refused_settings() {
        // a curved triangle with corners (0,0), (10,0), (0,10)
        let mut pts = Vec::new();
        for i in 0..=40 {
            for j in 0..=(40 - i) {
                let (x, y) = (i as f64 / 4.0, j as f64 / 4.0);
                pts.push(Point3::new(x, y, 0.02 * (x * x + y * y)));
            }
        }
        let cloud = PointCloud::new(pts).unwrap();
        let mut cfg = CoonsConfig::default();
        cfg.base.corners.count = 3;
        cfg.route = CoonsRoute::pde(3, 3);
        let r = run(&cloud, &cfg, &crate::progress::NoProgress).unwrap();
        assert_eq!(r.base.patch.sides(), Sides::Three);
        assert!(r.assessment.quality.at_parameters.max < 0.02);
        cfg.route = CoonsRoute::Pde {
            pde: PdeConfig::default(),
            export_tolerance: Some(-1.0),
        };
        match run(&cloud, &cfg, &crate::progress::NoProgress) {
            Err(Error::InvalidSetting { setting, value, .. }) => {
                assert_eq!((setting, value.as_str()), ("export_tolerance", "-1"));
            }
            other => panic!("{other:?}"),
        }
        cfg.base.corners.count = 5;
        let e = run(&cloud, &cfg, &crate::progress::NoProgress).unwrap_err();
        assert!(e.to_string().contains("5 corners asked for"), "{e}");
    }
}
