//! `scanfit fit` and `scanfit mba` over points read in chunks
//! (`--chunk-points`): memory depends on the model (lattice, normal
//! equations), not on the point count.
//!
//! The points come from a [`PointSource`], which reads them in passes of
//! chunks, always in the same order. The fits go through the same
//! accumulators as the in-memory pipelines ([`crate::mba::BaAccumulator`],
//! [`crate::fit::surface::NormalEquations`]), fed chunk after chunk in file order, so the surface
//! is the in-memory one: `fit`'s **bit for bit** with given parameters and uniform knots (to 1e-12
//! with the plane, distribution knots or correction), `mba`'s to 1e-12 of the largest control value
//! (the in-memory MBA sums the points in lattice-cell order, [`crate::mba::mba`]):
//!
//! * [`mba`]: one pass for the frame ([`FrameSums`]), one per level
//!   (residuals after the levels so far, [LWS97] eqs. 3-4), with the fitted
//!   start ([`crate::mba::Start::Fitted`], the default) one for the last
//!   level's start, one to measure (and eq. 17 of every level's surface).
//! * [`fit`] (in `stream/fit.rs`): every setting of the in-memory fit as
//!   passes of mergeable sums: the best-fit plane (covariance, convex hull,
//!   extents), the distribution knots (eq. 9.69, rounds of histograms), the
//!   normal equations ([NURBS97] eq. 9.63), the parameter correction (each
//!   round re-projects the points onto the accepted surfaces in turn), one
//!   pass to measure; the surface equals the in-memory one to 1e-12.
//!
//! The report is measured by streaming too ([`StreamAssessor`]): errors at
//! the parameters and orthogonal distances over every point; [MBA18] eq. 17
//! and the sample-grid distances exactly (the nearest point over all chunks
//! is the nearest of the chunks' nearest); the point spacing behind the
//! "far" share is the median nearest-neighbour distance **within the first
//! chunk** (a sample), and the parameterization's fold-overs and stretch are
//! not measured (they need a triangulation of all parameters).

use std::time::Instant;

use rayon::prelude::*;

use crate::bspline::Surface;
use crate::centring::Centring;
use crate::mba::sums::{pass_sums, residual};
use crate::mba::{
    lattice_surface, FrameSums, Lattice, MbaConfig, MbaLevels, PassSums, ResidualSums,
};
use crate::metrics::ParamQuality;
use crate::pipeline::assess::{
    per_point_sums, AssessConfig, Extent, Measure, SampleDistances, SurfaceQuality,
};
use crate::pipeline::mba::LevelRow;
use crate::progress::Progress;
use crate::project::power_form::PowerForm;
use crate::project::{InversionWorkspace, SurfaceInverter};
use crate::spatial::KdTree;
use crate::up_axis::UpAxis;
use crate::{Error, Point3, PointCloud, Result};

mod fit;
pub use fit::{fit, StreamedFit};

/// A chunk of points: positions and, when the source was asked for them,
/// parameters.
#[derive(Debug, Clone, Copy)]
pub struct Chunk<'a> {
    /// The positions.
    pub points: &'a [Point3],
    /// Parameters `(u, v)` per point (from two attributes), if any.
    pub uv: Option<&'a [[f64; 2]]>,
}

/// Points read in passes of chunks, in the same order every pass.
pub trait PointSource {
    /// One pass over all points: `f` is called with each chunk in order.
    fn pass(&mut self, f: &mut dyn FnMut(Chunk<'_>) -> Result<()>) -> Result<()>;
}

/// Points in memory served in chunks of `chunk` (for tests and for callers
/// that hold the points but want the streamed arithmetic).
#[derive(Debug, Clone)]
pub struct SliceSource<'a> {
    /// The positions.
    pub points: &'a [Point3],
    /// Their parameters, if any.
    pub uv: Option<&'a [[f64; 2]]>,
    /// Points per chunk (at least 1).
    pub chunk: usize,
}

impl PointSource for SliceSource<'_> {
    fn pass(&mut self, f: &mut dyn FnMut(Chunk<'_>) -> Result<()>) -> Result<()> {
        let c = self.chunk.max(1);
        for s in (0..self.points.len()).step_by(c) {
            let e = (s + c).min(self.points.len());
            f(Chunk {
                points: &self.points[s..e],
                uv: self.uv.map(|u| &u[s..e]),
            })?;
        }
        Ok(())
    }
}

/// A pass for the bounding box: the data's [`Centring`] (the in-memory
/// pipelines compute relative to it) and the point count; with `sample`,
/// also an evenly spaced sample of at most [`UP_SAMPLE`] points (every
/// `2^k`-th point, `k` the smallest that fits) for [`UpAxis::automatic`].
fn centring_pass(
    source: &mut dyn PointSource,
    mut sample: Option<&mut Vec<Point3>>,
) -> Result<(Centring, usize)> {
    let (mut lo, mut hi, mut n) = (None::<Point3>, None::<Point3>, 0usize);
    let mut stride = 1usize;
    source.pass(&mut |c| {
        for p in c.points {
            lo = Some(lo.map_or(*p, |l| Point3::from(l.coords.inf(&p.coords))));
            hi = Some(hi.map_or(*p, |h| Point3::from(h.coords.sup(&p.coords))));
            if let Some(s) = sample.as_deref_mut() {
                if n % stride == 0 {
                    if s.len() == UP_SAMPLE {
                        // keep every other point: the sample stays every
                        // `stride`-th point of the input
                        let mut k = 0;
                        s.retain(|_| {
                            k += 1;
                            k % 2 == 1
                        });
                        stride *= 2;
                    }
                    if n % stride == 0 {
                        s.push(*p);
                    }
                }
            }
            n += 1;
        }
        Ok(())
    })?;
    let corners: Vec<Point3> = lo.into_iter().chain(hi).collect();
    Ok((Centring::of(&corners), n))
}

/// Most points of the sample the streamed MBA decides its automatic up axis
/// from (the 1st and 99th percentiles of 2^16 evenly spaced points).
pub const UP_SAMPLE: usize = 1 << 16;

/// `source` with every chunk moved by `-centre` and turned into the z-up
/// frame of `up`.
struct Centred<'a> {
    source: &'a mut dyn PointSource,
    centring: Centring,
    up: UpAxis,
}

impl PointSource for Centred<'_> {
    fn pass(&mut self, f: &mut dyn FnMut(Chunk<'_>) -> Result<()>) -> Result<()> {
        let (centring, up) = (self.centring, self.up);
        self.source.pass(&mut |c| {
            if centring.is_identity() && up == UpAxis::Z {
                return f(c);
            }
            let centre = centring.centre();
            let moved: Vec<Point3> = c
                .points
                .iter()
                .map(|p| up.point_to_frame(&(p - centre)))
                .collect();
            f(Chunk {
                points: &moved,
                uv: c.uv,
            })
        })
    }
}

/// What [`mba`] returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct StreamedMba {
    /// The final surface (as the in-memory pipeline's).
    pub surface: Surface,
    /// The axis that was height (the given one, or the automatic one from
    /// an evenly spaced sample of the first pass).
    pub up: UpAxis,
    /// Cells `(m, n)` of the final lattice.
    pub cells: (usize, usize),
    /// One row per level: vertical residuals (streamed) and eq. 17 of the
    /// level's combined lattice.
    pub levels: Vec<LevelRow>,
    /// Passes made over the points.
    pub passes: usize,
    /// Wall time of the approximation (without the measuring pass), seconds.
    pub seconds: f64,
    /// The streamed measures (see the module documentation); its
    /// `at_parameters` are the vertical residuals.
    pub quality: SurfaceQuality,
}

/// Multilevel B-spline approximation of the points of `source` by passes
/// (see the module documentation); the surface equals
/// [`crate::pipeline::mba::run`]'s with the same up axis (`up`; `None`:
/// [`UpAxis::automatic`] on an evenly spaced sample) to 1e-12 of the largest
/// control value (the in-memory loop sums in lattice-cell order). The
/// projection adjustment needs the
/// whole cloud and is not offered here.
///
/// ```
/// use scanfit::mba::{mba as mba_in_memory, lattice_surface, MbaConfig};
/// use scanfit::pipeline::assess::AssessConfig;
/// use scanfit::pipeline::stream::{mba, SliceSource};
/// use scanfit::progress::NoProgress;
/// use scanfit::Point3;
///
/// let p: Vec<Point3> = (0..4000)
///     .map(|k| {
///         let (x, y) = ((k * 37 % 200) as f64 * 0.5, (k / 40) as f64);
///         Point3::new(x, y, (x / 10.0).sin() * (y / 7.0).cos())
///     })
///     .collect();
/// let config = MbaConfig { max_levels: 4, ..Default::default() };
/// let mut source = SliceSource { points: &p, uv: None, chunk: 333 };
/// let r = mba(&mut source, &config, &AssessConfig::default(), None, &NoProgress)?;
/// let once = mba_in_memory(&p, &config)?;
/// let want = lattice_surface(&once.frame, &once.lattice)?;
/// let worst = r.surface.control_points().iter().zip(want.control_points())
///     .map(|(a, b)| (a.z - b.z).abs()).fold(0.0, f64::max);
/// assert!(worst < 1e-12);
/// // bounding box, frame, 4 levels, the fitted start of the last, measures
/// assert_eq!(r.passes, 8);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn mba(
    source: &mut dyn PointSource,
    config: &MbaConfig,
    assess: &AssessConfig,
    up: Option<UpAxis>,
    progress: &dyn Progress,
) -> Result<StreamedMba> {
    let t0 = Instant::now();
    progress.stage("pass 1: the bounding box", None);
    let mut sample = Vec::new();
    let (centring, _) = centring_pass(source, up.is_none().then_some(&mut sample))?;
    let up = up.unwrap_or_else(|| UpAxis::automatic(&sample));
    drop(sample);
    let source = &mut Centred {
        source,
        centring,
        up,
    };
    let mut frame_sums = FrameSums::default();
    source.pass(&mut |c| frame_sums.add(c.points))?;
    let frame = frame_sums.finish()?;
    let mut run = MbaLevels::new(frame, config)?;
    let mut passes = 2;
    while !run.done() {
        progress.stage(
            &format!(
                "pass {}: level {} ({} x {} cells)",
                passes + 1,
                run.levels().len(),
                run.next_cells().0,
                run.next_cells().1
            ),
            None,
        );
        let mut acc = run.accumulator()?;
        let mut sums = PassSums::default();
        let inputs = run.inputs();
        source.pass(&mut |c| {
            sums.merge(&acc.add_levels(&inputs, c.points)?);
            Ok(())
        })?;
        passes += 1;
        if run.record(&sums)? {
            break;
        }
        run.push(acc)?;
    }
    // the fitted start of the last level: one more pass
    while run.needs_pass() {
        progress.stage(&format!("pass {}: the start", passes + 1), None);
        let mut sums = PassSums::default();
        let inputs = run.inputs();
        source.pass(&mut |c| {
            sums.merge(&pass_sums(&inputs, c.points)?);
            Ok(())
        })?;
        passes += 1;
        run.record(&sums)?;
    }
    let result = run.finish();
    let surface = lattice_surface(&result.frame, &result.lattice)?;
    let seconds = t0.elapsed().as_secs_f64();
    progress.stage(&format!("pass {}: measuring", passes + 1), None);
    let mut assessor = StreamAssessor::new(&surface, assess)?;
    let mut vertical = ResidualSums::default();
    let mut last = ResidualSums::default();
    // eq. 17 of every level's combined lattice (the last: the surface's)
    let (queries, ends) = level_grids(&result)?;
    let mut grid = NearestSums::new(queries);
    source.pass(&mut |c| {
        let uv: Vec<[f64; 2]> = c.points.par_iter().map(|p| frame.unit(p)).collect();
        let (v, l) = vertical_sums(&surface, &frame, &result.levels, c.points, &uv);
        vertical.merge(&v);
        last.merge(&l);
        let tree = ChunkTree::new(c.points);
        grid.add_tree(&tree)?;
        assessor.add_tree(&tree, &uv)
    })?;
    passes += 1;
    let grid_rmse: Vec<f64> = ends
        .iter()
        .scan(0, |start, &end| {
            let d = &grid.distances()[*start..end];
            *start = end;
            Some((d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt())
        })
        .collect();
    let mut reports = result.reports;
    if let Some(r) = reports.last_mut().filter(|r| r.residual.count == 0) {
        r.residual = last.stats();
    }
    let mut quality = assessor.finish();
    quality.at_parameters = vertical.stats();
    quality.grid_rmse = grid_rmse.last().copied().unwrap_or(0.0);
    let levels = reports
        .iter()
        .zip(&grid_rmse)
        .map(|(rep, &g)| LevelRow {
            level: rep.level,
            control_points: (rep.cells.0 + 3, rep.cells.1 + 3),
            vertical: rep.residual,
            grid_rmse: g,
            adjusted: None,
            seconds: rep.seconds,
        })
        .collect();
    let ctrl = surface
        .control_points()
        .iter()
        .map(|p| up.point_from_frame(p))
        .collect();
    let surface = Surface::new(surface.knots_u().clone(), surface.knots_v().clone(), ctrl)?;
    Ok(StreamedMba {
        surface: centring.restore(surface),
        up,
        cells: (result.lattice.m, result.lattice.n),
        levels,
        passes,
        seconds,
        quality,
    })
}

/// The knot grids of the combined lattice of each level of `r` (the sum of
/// its levels so far, refined), one after the other, and where each ends.
fn level_grids(r: &crate::mba::Mba) -> Result<(Vec<Point3>, Vec<usize>)> {
    let (mut queries, mut ends) = (Vec::new(), Vec::new());
    let mut total: Option<Lattice> = None;
    for l in &r.levels {
        let t = match total.take() {
            None => l.clone(),
            Some(t) => {
                let mut t = t.refine()?;
                t.add(l)?;
                t
            }
        };
        queries.extend(crate::mba::adjust::knot_grid(&r.frame, &t));
        ends.push(queries.len());
        total = Some(t);
    }
    Ok((queries, ends))
}

/// The parameters of a chunk, an error when the source gave none.
fn chunk_uv<'a>(c: &Chunk<'a>) -> Result<&'a [[f64; 2]]> {
    c.uv.ok_or_else(|| {
        Error::InvalidInput("the point source gives no parameters (u, v) for the chunks".into())
    })
}

/// The sums of the vertical errors of `surface` at the points of a chunk
/// (at their parameters `uv`) and of the residuals after the last of
/// `levels`, in parallel blocks merged in order.
fn vertical_sums(
    surface: &Surface,
    frame: &crate::mba::Frame,
    levels: &[Lattice],
    points: &[Point3],
    uv: &[[f64; 2]],
) -> (ResidualSums, ResidualSums) {
    const BLOCK: usize = 1 << 14;
    let parts: Vec<(ResidualSums, ResidualSums)> = points
        .par_chunks(BLOCK)
        .zip(uv.par_chunks(BLOCK))
        .map(|(p, t)| {
            let (mut v, mut l) = (ResidualSums::default(), ResidualSums::default());
            for (p, t) in p.iter().zip(t) {
                v.push((p.z - surface.point(t[0], t[1]).z).abs());
                l.push(residual(frame, levels, p, *t).abs());
            }
            (v, l)
        })
        .collect();
    let (mut v, mut l) = (ResidualSums::default(), ResidualSums::default());
    for (a, b) in &parts {
        v.merge(a);
        l.merge(b);
    }
    (v, l)
}

/// The KD-tree of one chunk's points, built at the first query and shared by
/// every [`NearestSums`] of the pass (one tree per chunk, not one per
/// measure).
pub struct ChunkTree<'a> {
    points: &'a [Point3],
    tree: std::sync::OnceLock<KdTree>,
}

impl<'a> ChunkTree<'a> {
    /// The (not yet built) tree of `points`.
    pub fn new(points: &'a [Point3]) -> Self {
        Self {
            points,
            tree: std::sync::OnceLock::new(),
        }
    }

    /// The tree, built on first use; `None` for an empty chunk.
    fn get(&self) -> Result<Option<&KdTree>> {
        if self.points.is_empty() {
            return Ok(None);
        }
        if self.tree.get().is_none() {
            let t = KdTree::new(self.points, "the chunk's points")?;
            let _ = self.tree.set(t);
        }
        Ok(self.tree.get())
    }
}

/// The smallest distance from each of a fixed set of query points to the
/// points of all chunks seen (exact: the minimum over chunks).
#[derive(Debug, Clone)]
pub struct NearestSums {
    queries: Vec<Point3>,
    best: Vec<f64>,
}

impl NearestSums {
    /// No chunk seen yet: every distance infinite.
    pub fn new(queries: Vec<Point3>) -> Self {
        let best = vec![f64::INFINITY; queries.len()];
        Self { queries, best }
    }

    /// Takes the chunk's points into account.
    pub fn add(&mut self, points: &[Point3]) -> Result<()> {
        self.add_tree(&ChunkTree::new(points))
    }

    /// Takes the chunk of `tree` into account (queries in parallel).
    pub fn add_tree(&mut self, tree: &ChunkTree<'_>) -> Result<()> {
        if self.queries.is_empty() {
            return Ok(());
        }
        let Some(tree) = tree.get()? else {
            return Ok(());
        };
        self.best
            .par_iter_mut()
            .zip(self.queries.par_iter())
            .for_each(|(b, q)| *b = b.min(tree.nearest(q).distance));
        Ok(())
    }

    /// The query points.
    pub fn queries(&self) -> &[Point3] {
        &self.queries
    }

    /// The distances so far.
    pub fn distances(&self) -> &[f64] {
        &self.best
    }

    /// Their root mean square (0 without queries).
    pub fn rmse(&self) -> f64 {
        let n = self.best.len().max(1) as f64;
        (self.best.iter().map(|d| d * d).sum::<f64>() / n).sqrt()
    }
}

/// The assessment of a surface against points that arrive in chunks (see
/// the module documentation for what is exact and what is sampled), with
/// the in-memory assessment's per-point kernel (in parallel over each
/// chunk) and its [`Measure`] levels: [`Measure::None`] measures the errors
/// at the parameters and the extent only, as in memory.
pub struct StreamAssessor<'s> {
    surface: &'s Surface,
    inverter: SurfaceInverter<'s>,
    form: Option<PowerForm>,
    at_parameters: ResidualSums,
    orthogonal: ResidualSums,
    unconverged: usize,
    knots: NearestSums,
    samples: NearestSums,
    grid: (usize, usize),
    far_spacings: f64,
    spacing: Option<f64>,
    config: AssessConfig,
    bounds: Option<(Point3, Point3)>,
}

impl<'s> StreamAssessor<'s> {
    /// An assessor of `surface` with the settings of `config`.
    pub fn new(surface: &'s Surface, config: &AssessConfig) -> Result<Self> {
        let (grid, samples) = crate::pipeline::assess::sample_grid(surface, config)?;
        let measured = config.measure != Measure::None;
        Ok(Self {
            surface,
            inverter: SurfaceInverter::new(surface, config.inversion)?,
            form: PowerForm::new(surface),
            at_parameters: ResidualSums::default(),
            orthogonal: ResidualSums::default(),
            unconverged: 0,
            knots: NearestSums::new(if measured {
                crate::pipeline::assess::knot_line_points(surface)
            } else {
                Vec::new()
            }),
            samples: NearestSums::new(samples),
            grid,
            far_spacings: config.far_spacings,
            spacing: None,
            config: *config,
            bounds: None,
        })
    }

    /// Adds a chunk of points with their parameters.
    pub fn add(&mut self, points: &[Point3], uv: &[[f64; 2]]) -> Result<()> {
        self.add_tree(&ChunkTree::new(points), uv)
    }

    /// [`Self::add`] with the chunk's shared tree (the chunk is the tree's
    /// points).
    pub fn add_tree(&mut self, chunk: &ChunkTree<'_>, uv: &[[f64; 2]]) -> Result<()> {
        let points = chunk.points;
        if points.len() != uv.len() {
            return Err(Error::LengthMismatch {
                what: "parameter pairs",
                expected: points.len(),
                got: uv.len(),
            });
        }
        let measured = self.config.measure != Measure::None;
        let (surface, inverter, form) = (self.surface, &self.inverter, &self.form);
        let sums = per_point_sums(
            points.len(),
            (false, false),
            measured,
            || InversionWorkspace::new(surface),
            |i, ws| {
                let (p, t) = (&points[i], uv[i]);
                let error = (p - surface.point(t[0], t[1])).norm();
                if !measured {
                    return (error, None);
                }
                let r = match form {
                    Some(f) => inverter
                        .invert_near_with(p, t, ws, |u, v, o, out, _| f.derivatives(u, v, o, out)),
                    None => inverter.invert_near(p, t, ws),
                };
                (error, Some((r.distance, r.converged)))
            },
        );
        self.at_parameters.merge(&sums.at_parameters);
        self.orthogonal.merge(&sums.orthogonal);
        self.unconverged += sums.unconverged.len();
        if measured {
            self.knots.add_tree(chunk)?;
            self.samples.add_tree(chunk)?;
            if self.spacing.is_none() && points.len() >= 2 {
                self.spacing = Some(PointCloud::new(points.to_vec())?.spacing()?.median);
            }
        }
        for p in points {
            let (lo, hi) = self.bounds.get_or_insert((*p, *p));
            *lo = lo.inf(p);
            *hi = hi.sup(p);
        }
        Ok(())
    }

    /// The measures.
    pub fn finish(self) -> SurfaceQuality {
        let measured = self.config.measure != Measure::None;
        let spacing = self.spacing.unwrap_or(0.0);
        let samples_to_points = if measured {
            let d = self.samples.distances();
            let limit = self.far_spacings * spacing;
            let far = d.iter().filter(|&&x| x > limit).count();
            SampleDistances {
                grid: self.grid,
                stats: crate::metrics::ErrorStats::of(d),
                spacing,
                far_spacings: self.far_spacings,
                far_share: far as f64 / d.len().max(1) as f64,
            }
        } else {
            SampleDistances {
                grid: self.grid,
                far_spacings: self.far_spacings,
                ..Default::default()
            }
        };
        let extent = match self.bounds {
            Some(b) => crate::pipeline::assess::extent_in_box(
                self.surface,
                b,
                self.samples.queries(),
                spacing,
                &self.config,
            ),
            None => Extent::default(),
        };
        SurfaceQuality {
            points: usize::try_from(self.at_parameters.count).unwrap_or(usize::MAX),
            at_parameters: self.at_parameters.stats(),
            orthogonal: if measured {
                self.orthogonal.stats()
            } else {
                crate::metrics::ErrorStats::default()
            },
            unconverged: self.unconverged,
            grid_rmse: if measured { self.knots.rmse() } else { 0.0 },
            samples_to_points,
            parameterization: ParamQuality::default(),
            extent,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::ProjectionAxis;
    use crate::fit::surface::KnotPlacement;
    use crate::pipeline::{mba as mba_pipeline, surface_fit};
    use crate::progress::NoProgress;

    fn terrain(n: usize) -> Vec<Point3> {
        let mut rng = crate::testdata::Lcg::new(11);
        (0..n)
            .map(|_| {
                let (x, y) = (rng.next_f64() * 80.0, rng.next_f64() * 50.0);
                Point3::new(
                    x + 6.0e5,
                    y + 5.2e6,
                    3.0 * (x / 9.0).sin() + (y / 6.0).cos(),
                )
            })
            .collect()
    }

    #[test]
    fn streamed_mba_equals_the_in_memory_pipeline_and_its_report() {
        let p = terrain(20_000);
        let cloud = PointCloud::new(p.clone()).unwrap();
        let mut cfg = mba_pipeline::MbaRunConfig::default();
        cfg.mba.max_levels = 5;
        let once = mba_pipeline::run(&cloud, &cfg, &NoProgress).unwrap();
        for chunk in [1000, 7777, 20_000] {
            let mut s = SliceSource {
                points: &p,
                uv: None,
                chunk,
            };
            let r = mba(&mut s, &cfg.mba, &cfg.assess, None, &NoProgress).unwrap();
            // the in-memory MBA sums in lattice-cell order: equal to rounding
            let (cs, co) = (r.surface.control_points(), once.surface.control_points());
            assert_eq!(cs.len(), co.len());
            assert_eq!(r.surface.knots_u(), once.surface.knots_u());
            assert_eq!(r.surface.knots_v(), once.surface.knots_v());
            let scale = co.iter().fold(0.0f64, |m, q| m.max(q.z.abs()));
            for (a, b) in cs.iter().zip(co) {
                assert_eq!((a.x, a.y), (b.x, b.y), "chunk {chunk}");
                assert!((a.z - b.z).abs() <= 1e-12 * scale, "chunk {chunk}");
            }
            // bounding box, frame, 5 levels, the last start (fitted), measures
            assert_eq!(r.passes, 9);
            let (a, b) = (r.quality, once.assessment.quality);
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-10 * y.abs().max(1e-300);
            assert!(
                close(a.at_parameters.rmse, b.at_parameters.rmse),
                "{a:?} {b:?}"
            );
            assert!(close(a.at_parameters.max, b.at_parameters.max));
            assert!(close(a.orthogonal.rmse, b.orthogonal.rmse));
            assert!(close(a.grid_rmse, b.grid_rmse));
            assert!(close(
                a.samples_to_points.stats.max,
                b.samples_to_points.stats.max
            ));
            for (x, y) in r.levels.iter().zip(&once.levels) {
                assert_eq!((x.level, x.control_points), (y.level, y.control_points));
                assert!(close(x.vertical.rmse, y.vertical.rmse), "{x:?} {y:?}");
                assert!(close(x.grid_rmse, y.grid_rmse));
            }
        }
    }

    #[test]
    fn a_y_up_scan_is_the_z_up_fit_turned_in_memory_and_streamed() {
        // the same terrain stored y-up (far from the origin): height is y
        let zup = terrain(8_000);
        let yup: Vec<Point3> = zup.iter().map(|p| UpAxis::Y.point_from_frame(p)).collect();
        let mut cfg = mba_pipeline::MbaRunConfig::default();
        cfg.mba.max_levels = 4;
        let flat = mba_pipeline::run(&PointCloud::new(zup).unwrap(), &cfg, &NoProgress).unwrap();
        assert_eq!(UpAxis::automatic(&yup), UpAxis::Y);
        cfg.up = UpAxis::Y;
        let cloud = PointCloud::new(yup.clone()).unwrap();
        let turned = mba_pipeline::run(&cloud, &cfg, &NoProgress).unwrap();
        // exactly the z-up surface turned (negation and permutation are exact)
        let back: Vec<Point3> = flat
            .surface
            .control_points()
            .iter()
            .map(|p| UpAxis::Y.point_from_frame(p))
            .collect();
        assert_eq!(turned.surface.control_points(), &back[..]);
        assert_eq!(turned.up, UpAxis::Y);
        assert_eq!(
            turned.assessment.quality.orthogonal.rmse,
            flat.assessment.quality.orthogonal.rmse
        );
        // fitted with z as height, the same scan is a wall: far worse
        cfg.up = UpAxis::Z;
        let wall = mba_pipeline::run(&cloud, &cfg, &NoProgress).unwrap();
        assert!(
            wall.assessment.quality.orthogonal.rmse
                > 10.0 * turned.assessment.quality.orthogonal.rmse,
            "{} vs {}",
            wall.assessment.quality.orthogonal.rmse,
            turned.assessment.quality.orthogonal.rmse
        );
        // streamed, with the axis found from the first pass's sample
        let mut s = SliceSource {
            points: &yup,
            uv: None,
            chunk: 1500,
        };
        let r = mba(&mut s, &cfg.mba, &cfg.assess, None, &NoProgress).unwrap();
        assert_eq!(r.up, UpAxis::Y);
        // (the in-memory loop sums in cell order: equal to rounding)
        let (cs, co) = (r.surface.control_points(), turned.surface.control_points());
        let scale = co.iter().fold(0.0f64, |m, q| m.max(q.coords.abs().max()));
        for (a, b) in cs.iter().zip(co) {
            assert!((a - b).norm() <= 1e-12 * scale, "{a} {b}");
        }
    }

    /// `a`'s knots within 1e-12 of `b`'s (on `[0, 1]`), its control points
    /// within 1e-12 of `b`'s largest coordinate.
    fn assert_same_surface(a: &Surface, b: &Surface) {
        assert_eq!(a.knots_u().as_slice().len(), b.knots_u().as_slice().len());
        assert_eq!(a.knots_v().as_slice().len(), b.knots_v().as_slice().len());
        for (x, y) in [(a.knots_u(), b.knots_u()), (a.knots_v(), b.knots_v())] {
            for (s, t) in x.as_slice().iter().zip(y.as_slice()) {
                assert!((s - t).abs() <= 1e-12, "knots {s} {t}");
            }
        }
        let scale = b
            .control_points()
            .iter()
            .fold(0.0f64, |m, q| m.max(q.coords.abs().max()));
        assert_eq!(a.control_points().len(), b.control_points().len());
        for (x, y) in a.control_points().iter().zip(b.control_points()) {
            assert!((x - y).norm() <= 1e-12 * scale, "{x} {y}");
        }
    }

    #[test]
    fn streamed_fit_of_a_folding_height_field_makes_the_in_memory_choice() {
        use crate::pipeline::surface_fit::FitConfig;
        // Franke's function (relief 1.2 over the unit square), far from the
        // origin: its best-fit plane folds the bumps over, z does not; the
        // fold sample is gathered in the covariance pass, whatever the chunks
        let p: Vec<Point3> =
            crate::testdata::scattered(20_000, 29, [0.0, 0.0, 1.0, 1.0], crate::testdata::franke)
                .into_iter()
                .map(|q| Point3::new(q.x + 3.0e3, q.y - 7.0e3, q.z))
                .collect();
        let mut cfg = FitConfig::default();
        let once =
            surface_fit::run(&PointCloud::new(p.clone()).unwrap(), &cfg, &NoProgress).unwrap();
        let po = once.projection.unwrap();
        assert_eq!(po.axis, ProjectionAxis::Z);
        assert!(
            po.fold_shares[0] > 0.02 && po.fold_shares[3] == 0.0,
            "{po:?}"
        );
        assert_eq!(once.assessment.quality.parameterization.fold_overs, 0);
        for chunk in [999, 4096, 20_000] {
            let mut s = SliceSource {
                points: &p,
                uv: None,
                chunk,
            };
            let r = fit(&mut s, &cfg, &NoProgress).unwrap();
            let pr = r.projection.unwrap();
            assert_eq!(
                (pr.axis, pr.direction, pr.fold_shares, pr.sampled),
                (po.axis, po.direction, po.fold_shares, po.sampled),
                "chunk {chunk}"
            );
            assert!((pr.extent[0] - po.extent[0]).abs() <= 1e-12 * po.extent[0]);
            assert_same_surface(&r.surface, &once.surface);
            // bounding box, plane x3, knots x2, equations, measure
            assert_eq!(r.passes, 8);
        }
        // with a correction round too
        cfg.correction_rounds = 1;
        let once =
            surface_fit::run(&PointCloud::new(p.clone()).unwrap(), &cfg, &NoProgress).unwrap();
        let mut s = SliceSource {
            points: &p,
            uv: None,
            chunk: 3333,
        };
        let r = fit(&mut s, &cfg, &NoProgress).unwrap();
        assert_eq!(r.projection.unwrap().axis, ProjectionAxis::Z);
        assert_same_surface(&r.surface, &once.surface);
    }

    #[test]
    fn streamed_fit_equals_the_in_memory_pipeline_with_every_setting() {
        use crate::pipeline::surface_fit::{FitConfig, ParameterSource};
        let p = terrain(12_000);
        let uv: Vec<[f64; 2]> = p
            .iter()
            .map(|q| [(q.x - 6.0e5) / 80.0, (q.y - 5.2e6) / 50.0])
            .map(|t| [t[0].clamp(0.0, 1.0), t[1].clamp(0.0, 1.0)])
            .collect();
        let cloud = PointCloud::new(p.clone())
            .unwrap()
            .with_attribute("u", uv.iter().map(|t| t[0]).collect())
            .unwrap()
            .with_attribute("v", uv.iter().map(|t| t[1]).collect())
            .unwrap();
        let mut cfg = FitConfig {
            params: ParameterSource::uv_attributes(),
            ..Default::default()
        };
        cfg.fit.knots = KnotPlacement::Uniform;
        cfg.fit.ctrl = (20, 14);
        cfg.fit.smoothing = 1e-9;
        let once = surface_fit::run(&cloud, &cfg, &NoProgress).unwrap();
        let mut s = SliceSource {
            points: &p,
            uv: Some(&uv),
            chunk: 5000,
        };
        let r = fit(&mut s, &cfg, &NoProgress).unwrap();
        // given parameters and uniform knots: the same sums in the same order
        assert_eq!(r.surface, once.surface);
        assert_eq!(r.passes, 3);
        let (a, b) = (r.quality, once.assessment.quality);
        assert!(
            (a.at_parameters.rmse - b.at_parameters.rmse).abs() <= 1e-12 * b.at_parameters.rmse
        );
        assert_eq!(a.at_parameters.max, b.at_parameters.max);
        assert_eq!(a.grid_rmse, b.grid_rmse);
        // the plane, the distribution knots and the correction: more passes,
        // the in-memory surface to the rounding of the sums
        let close = assert_same_surface;
        for (params, knots, rounds, passes) in [
            // bounding box, plane x3, knots x2, equations, measure
            (ParameterSource::Plane, KnotPlacement::Distribution, 0, 8),
            (
                ParameterSource::uv_attributes(),
                KnotPlacement::Distribution,
                0,
                5,
            ),
            // plus the errors pass per fit, and a fit per round
            (
                ParameterSource::uv_attributes(),
                KnotPlacement::Uniform,
                2,
                0,
            ),
            (ParameterSource::Plane, KnotPlacement::Distribution, 2, 0),
        ] {
            let mut c = cfg.clone();
            c.params = params;
            c.fit.knots = knots;
            c.correction_rounds = rounds;
            let once = surface_fit::run(&cloud, &c, &NoProgress).unwrap();
            let r = fit(&mut s, &c, &NoProgress).unwrap();
            close(&r.surface, &once.surface);
            // the terrain does not fold over its best-fit plane: kept by both
            let key = |p: Option<crate::base::Projection>| p.map(|p| (p.axis, p.fold_shares));
            assert_eq!(key(r.projection), key(once.projection));
            if c.params == ParameterSource::Plane {
                let p = r.projection.unwrap();
                assert_eq!((p.axis, p.sampled), (ProjectionAxis::BestFitPlane, 4000));
            }
            assert_eq!(r.rounds.len(), once.rounds.len());
            for (x, y) in r.rounds.iter().zip(&once.rounds) {
                assert!((x.errors.rmse - y.errors.rmse).abs() <= 1e-12 * y.errors.rmse);
            }
            if passes > 0 {
                assert_eq!(r.passes, passes);
            } else {
                assert!(r.rounds.len() >= 2, "{:?}", r.rounds);
            }
        }
        // a plane cannot close around u
        let mut bad = cfg.clone();
        bad.params = ParameterSource::Plane;
        bad.fit.periodic_u = true;
        assert!(matches!(
            fit(&mut s, &bad, &NoProgress).unwrap_err(),
            Error::InvalidSetting { .. }
        ));
    }
}
