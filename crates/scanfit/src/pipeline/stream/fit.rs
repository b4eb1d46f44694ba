//! `scanfit fit --chunk-points`: the least-squares surface of
//! [`crate::pipeline::surface_fit::run`] over points that arrive in passes of
//! chunks, every setting of the in-memory fit run as passes of mergeable sums:
//!
//! * parameters from the best-fit plane (`ParameterSource::Plane`): the
//!   covariance sums about the first point (the PCA normal) and, in the same
//!   pass, the seeded sample whose normals choose the projection direction
//!   ([`PlaneMoments`]: the best-fit plane, or a coordinate axis when the
//!   plane folds the points over and the axis does not; the sample is the
//!   points of smallest index hash, so it is the in-memory call's whatever
//!   the chunking), the convex hull in the plane ([`FlatHull`], its
//!   minimum-area rectangle, Freeman & Shapira 1975), the extents along the
//!   rectangle's axes ([`PlaneExtents`]): three passes, then every chunk's
//!   parameters from the [`PlaneMap`], as [`crate::base::plane_parameters`]
//!   computes them; given parameters come with the chunks;
//! * knots from the parameter distribution ([NURBS97] eq. 9.69): the few order
//!   statistics the knots need, found exactly by rounds of histograms
//!   ([`KnotSearch`], 2-3 passes);
//! * the normal equations ([NURBS97] eq. 9.63): one pass;
//! * Hoschek's parameter correction (`correction_rounds`,
//!   [`crate::fit::correction::correct_parameters`]): each round re-projects
//!   every point onto the surfaces of the accepted rounds in turn (no
//!   parameter is stored between passes), refits, and measures the errors at
//!   the parameters (one more pass per fit);
//! * the measures ([`StreamAssessor`]): one pass.
//!
//! The surface equals the in-memory one to the rounding of the sums (tested
//! at 1e-12 of the largest control point coordinate).

use crate::base::{FlatHull, PlaneExtents, PlaneMap, PlaneMoments, Projection, ProjectionAxis};
use crate::bspline::Surface;
use crate::fit::correction::CorrectionRound;
use crate::fit::knot_ranks::KnotSearch;
use crate::fit::surface::{KnotPlacement, SurfaceFitConfig};
use crate::mba::ResidualSums;
use crate::metrics::parametric_distances;
use crate::pipeline::assess::SurfaceQuality;
use crate::pipeline::surface_fit::{FitConfig, ParameterSource};
use crate::progress::Progress;
use crate::project::{InversionConfig, SurfaceInverter};
use crate::up_axis::UpAxis;
use crate::{Error, Point3, Result};

use super::{centring_pass, chunk_uv, Centred, Chunk, PointSource, StreamAssessor};

/// What [`fit`] returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct StreamedFit {
    /// The fitted surface (as the in-memory pipeline's).
    pub surface: Surface,
    /// Passes made over the points.
    pub passes: usize,
    /// The thin-plate weight used (after the pipeline's scaling rule).
    pub smoothing: f64,
    /// The errors at the parameters per correction round (round 0: the
    /// first fit), as [`crate::pipeline::surface_fit::FitReport::rounds`];
    /// empty without correction.
    pub rounds: Vec<CorrectionRound>,
    /// The streamed measures (see the [`super`] module documentation).
    pub quality: SurfaceQuality,
    /// With [`ParameterSource::Plane`]: the projection direction and the
    /// fold shares that chose it, as the in-memory
    /// [`crate::pipeline::surface_fit::FitReport::projection`].
    pub projection: Option<Projection>,
}

/// The least-squares surface of the points of `source` with the settings of
/// `config` (see the module documentation for the passes); the surface
/// equals [`crate::pipeline::surface_fit::run`]'s to the rounding of the sums.
///
/// ```
/// use scanfit::pipeline::stream::{fit, SliceSource};
/// use scanfit::pipeline::surface_fit::{self, FitConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// let p: Vec<Point3> = (0..3000)
///     .map(|k| {
///         let (x, y) = ((k % 60) as f64 / 59.0, (k / 60) as f64 / 49.0);
///         Point3::new(x, y, (2.0 * x).sin() * y)
///     })
///     .collect();
/// // the defaults: the best-fit plane, distribution knots
/// let mut cfg = FitConfig::default();
/// cfg.fit.ctrl = (8, 8);
/// cfg.correction_rounds = 1;
/// let mut source = SliceSource { points: &p, uv: None, chunk: 700 };
/// let r = fit(&mut source, &cfg, &NoProgress)?;
/// let once = surface_fit::run(&PointCloud::new(p.clone())?, &cfg, &NoProgress)?;
/// for (a, b) in r.surface.control_points().iter().zip(once.surface.control_points()) {
///     assert!((a - b).norm() < 1e-12);
/// }
/// assert_eq!(r.rounds.len(), once.rounds.len());
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn fit(
    source: &mut dyn PointSource,
    config: &FitConfig,
    progress: &dyn Progress,
) -> Result<StreamedFit> {
    let plane = config.params == ParameterSource::Plane;
    if plane && config.fit.periodic_u {
        return Err(Error::InvalidSetting {
            setting: "periodic_u",
            value: "true".into(),
            hint: "a periodic surface needs parameters that go around (ParameterSource::Attributes); a plane cannot close".into(),
        });
    }
    let (centring, count) = centring_pass(source, None)?;
    let source = &mut Centred {
        source,
        centring,
        up: UpAxis::Z,
    };
    let mut passes = Passes { count: 1, progress };
    let (map, projection) = if plane {
        let (m, p) = plane_map(source, count, &mut passes)?;
        (Some(m), Some(p))
    } else {
        (None, None)
    };
    let start = ChunkParameters {
        plane: map,
        chain: Vec::new(),
    };
    let fit_config = config.resolved_fit(count);
    let correcting = config.correction_rounds > 0;
    let first = fit_once(source, &start, &fit_config, count, correcting, &mut passes)?;
    let (surface, param, rounds) = if correcting {
        correct(
            source,
            first,
            start,
            config,
            &fit_config,
            count,
            &mut passes,
        )?
    } else {
        (first.0, start, Vec::new())
    };
    passes.stage("measuring");
    let mut assessor = StreamAssessor::new(&surface, &config.assess)?;
    source.pass(&mut |c| assessor.add(c.points, &param.uv(&c)?))?;
    Ok(StreamedFit {
        quality: assessor.finish(),
        surface: centring.restore(surface),
        passes: passes.count,
        smoothing: fit_config.smoothing,
        rounds,
        projection,
    })
}

/// Counts the passes and names each to the progress display.
struct Passes<'p> {
    count: usize,
    progress: &'p dyn Progress,
}

impl Passes<'_> {
    /// The next pass starts: `what` it computes.
    fn stage(&mut self, what: &str) {
        self.count += 1;
        self.progress
            .stage(&format!("pass {}: {what}", self.count), None);
    }
}

/// How a chunk's points get their parameters: from the plane (or the
/// chunk's own), then re-projected onto the surfaces of the accepted
/// correction rounds in turn, as [`crate::fit::correction::correct_parameters`]
/// re-projects all points round after round (each from the parameters before).
struct ChunkParameters {
    plane: Option<PlaneMap>,
    chain: Vec<Surface>,
}

impl ChunkParameters {
    fn uv(&self, c: &Chunk<'_>) -> Result<Vec<[f64; 2]>> {
        let mut uv: Vec<[f64; 2]> = match &self.plane {
            Some(m) => c.points.iter().map(|p| m.uv(p)).collect(),
            None => chunk_uv(c)?.to_vec(),
        };
        for s in &self.chain {
            let inverter = SurfaceInverter::new(s, InversionConfig::default())?;
            uv = inverter
                .invert_all_from(c.points, &uv)
                .iter()
                .map(|r| r.uv)
                .collect();
        }
        Ok(uv)
    }

    /// These parameters re-projected onto `surface` too.
    fn then(&self, surface: Surface) -> Self {
        let mut chain = self.chain.clone();
        chain.push(surface);
        Self {
            plane: self.plane,
            chain,
        }
    }
}

/// The plane's map in three passes (the covariance sums with the fold
/// sample, hull, extents): [`crate::base::plane_parameters`]'s steps, fed
/// chunk after chunk, the points numbered in the order they come; the
/// direction is the one-call choice ([`PlaneMoments`]).
fn plane_map(
    source: &mut dyn PointSource,
    count: usize,
    passes: &mut Passes<'_>,
) -> Result<(PlaneMap, Projection)> {
    if count < 3 {
        return Err(Error::TooFewPoints {
            got: count,
            needed: 3,
            what: "a best-fit plane".into(),
        });
    }
    passes.stage("best-fit plane (covariance about the first point, fold sample)");
    let mut moments: Option<PlaneMoments> = None;
    let mut next = 0u64;
    source.pass(&mut |c| {
        if let Some(p) = c.points.first() {
            moments
                .get_or_insert_with(|| PlaneMoments::new(*p))
                .add(next, c.points);
        }
        next += c.points.len() as u64;
        Ok(())
    })?;
    let (axes, mut projection) = moments
        .unwrap_or_else(|| PlaneMoments::new(Point3::origin()))
        .finish()?;
    let plane = match projection.axis {
        ProjectionAxis::BestFitPlane => "best-fit plane".to_string(),
        a => format!("plane across the {} axis", a.name()),
    };
    passes.stage(&format!("{plane} (convex hull in the plane)"));
    let mut hull = FlatHull::default();
    source.pass(&mut |c| {
        hull.add(&axes, c.points);
        Ok(())
    })?;
    passes.stage(&format!("{plane} (extents along the rectangle)"));
    let mut extents = PlaneExtents::new(&axes, hull.rectangle_direction());
    source.pass(&mut |c| {
        extents.add(c.points);
        Ok(())
    })?;
    let map = extents.finish()?;
    projection.extent = map.extent();
    Ok((map, projection))
}

/// One least-squares fit to the parameters of `param`: the distribution
/// knots' rounds (unless uniform), the normal equations, and with `errors`
/// the errors at the parameters (for the correction's comparison).
fn fit_once(
    source: &mut dyn PointSource,
    param: &ChunkParameters,
    cfg: &SurfaceFitConfig,
    count: usize,
    errors: bool,
    passes: &mut Passes<'_>,
) -> Result<(Surface, ResidualSums)> {
    let mut eq = if cfg.knots == KnotPlacement::Uniform {
        cfg.uniform_equations()?
    } else {
        let mut search = KnotSearch::new(count, cfg)?;
        while !search.done() {
            passes.stage("knots from the parameter distribution (eq. 9.69)");
            let query = search.query();
            let mut counts = query.counts();
            source.pass(&mut |c| {
                KnotSearch::add(&query, &mut counts, &param.uv(&c)?);
                Ok(())
            })?;
            search.push(&counts)?;
        }
        search.equations(cfg)?
    };
    let (cu, cv) = cfg.ctrl;
    passes.stage(&format!("normal equations of {cu} x {cv} control points"));
    source.pass(&mut |c| eq.add(c.points, &param.uv(&c)?, None))?;
    let surface = eq.finish(cfg.smoothing)?;
    let mut sums = ResidualSums::default();
    if errors {
        passes.stage("errors at the parameters");
        source.pass(&mut |c| {
            let d = parametric_distances(&surface, c.points, &param.uv(&c)?);
            d.iter().for_each(|&x| sums.push(x));
            Ok(())
        })?;
    }
    Ok((surface, sums))
}

/// Hoschek's parameter correction from the first fit, with the rules of
/// [`crate::fit::correction::correct_parameters`] (a round is kept while it
/// lowers the RMSE at the parameters, and the rounds stop when the gain is
/// under `min_improvement`): the surface, its parameters and the rounds.
fn correct(
    source: &mut dyn PointSource,
    first: (Surface, ResidualSums),
    start: ChunkParameters,
    config: &FitConfig,
    cfg: &SurfaceFitConfig,
    count: usize,
    passes: &mut Passes<'_>,
) -> Result<(Surface, ChunkParameters, Vec<CorrectionRound>)> {
    let (mut surface, sums) = first;
    let mut param = start;
    let mut errors = sums.stats();
    let mut rounds = vec![CorrectionRound { round: 0, errors }];
    for round in 1..=config.correction_rounds {
        let next = param.then(surface.clone());
        let (candidate, sums) = fit_once(source, &next, cfg, count, true, passes)?;
        let e = sums.stats();
        rounds.push(CorrectionRound { round, errors: e });
        if e.rmse < errors.rmse {
            let gain = (errors.rmse - e.rmse) / errors.rmse.max(f64::MIN_POSITIVE);
            (surface, param, errors) = (candidate, next, e);
            if gain < config.correction.min_improvement {
                break;
            }
        } else {
            break;
        }
    }
    Ok((surface, param, rounds))
}
