//! The trimmed face of a fitted surface as one library call: which boundary
//! loops bound it, whether a failure keeps the rectangle or is an error,
//! and the surface-to-points measures taken again on the face.
//!
//! Every surface command (`fit`, `mba`, `coons`) ends the same way: the
//! surface fitted over its points' parameter rectangle is bounded by the
//! cloud's boundary loops ([`crate::trim`], the alpha shape of [PDE23]
//! §4.1), and the parts of the rectangle outside the loops leave the
//! measures ([`super::assess_trimmed`]). What differs is the plane the alpha
//! shape is taken in ([`Loops`]):
//!
//! * **MBA** ([`Loops::Parameters`]): its parameters are an affine map of
//!   the horizontal coordinates in the up axis's frame, `(u, v) = ((x - x0)
//!   / width, (y - y0) / height)`, so the alpha shape is taken on the
//!   parameters scaled back to lengths, `(u width, v height)`
//!   ([`crate::cloud::boundary::boundary_loops_2d`]): the plane the surface
//!   is a height field over. The points' 3D best-fit plane is tilted under a
//!   bumpy height field (Franke's function: 234 spurious holes at 10^6
//!   points); in the parameters a uniformly sampled square has one loop on
//!   the domain's edges, so nothing is trimmed and the boundary band stays
//!   thin. The scaling keeps the metric: an alpha disc is a disc in the data,
//!   not an ellipse stretched by the aspect ratio of the bounding box.
//! * **`fit --params plane`** ([`Loops::BestFitPlane`]): the parameters
//!   are the projections on the points' best-fit plane
//!   ([`crate::base::plane_parameters`]), and the boundary's best-fit plane
//!   ([`crate::cloud::boundary::boundary_loops`]) is the same plane
//!   ([`crate::base::plane_frame`], one `plane_map`), so the alpha shape is
//!   taken in exactly the parameters' plane, in lengths (the parameters are
//!   scaled to the unit square, anisotropically). After `--correct` the
//!   parameters move off the plane map; the loops stay those of the plane
//!   the fit started from, and map into the corrected parameters by index.
//!   With `--params uv-columns` (trimmed only on request) the given
//!   parameters are of unknown metric (a cylinder unrolled, a chart of any
//!   scale), so the best-fit plane is the only metric plane at hand; a
//!   periodic surface is refused by [`crate::trim::trim_surface`].
//! * **Coons and PDE** ([`Loops::Given`]): the pipeline has computed the
//!   boundary already (its corners and sides come from it) and maps it onto
//!   the unit square's edges; the trim uses those same loops, so its outline
//!   is the rectangle's own and only holes are trimmed.

use crate::bspline::Surface;
use crate::cloud::boundary::{boundary_loops, boundary_loops_2d, Boundary, BoundaryConfig};
use crate::pipeline::assess::{AssessConfig, SurfaceQuality};
use crate::pipeline::assess_trimmed::assess_trimmed;
use crate::progress::Progress;
use crate::trim::{trim_surface, TrimConfig, TrimmedSurface};
use crate::{Error, PointCloud, Result};

/// Where the loops that bound the face come from (see the module
/// documentation).
#[derive(Debug, Clone, Copy)]
pub enum Loops<'a> {
    /// Loops the pipeline computed (Coons, PDE), indexed like the points.
    Given(&'a Boundary),
    /// The alpha shape of the parameters scaled by `scale` (MBA: the
    /// lattice frame's width and height), so that the scaled parameters
    /// are lengths alike in both directions.
    Parameters {
        /// Length of the `u` and `v` unit intervals.
        scale: [f64; 2],
    },
    /// The alpha shape of the points projected on their best-fit plane
    /// (`fit --params plane`: the plane its parameters were made in).
    BestFitPlane,
}

/// Whether to trim.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TrimMode {
    /// Keep the rectangle.
    Off,
    /// Trim when the loops allow it; a loop that cannot be trimmed keeps
    /// the rectangle, and the report says why ([`TrimReport::kept_rectangle`]).
    #[default]
    Default,
    /// Trim, or fail with the reason.
    Required,
}

/// Settings of [`run`].
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct TrimRunConfig {
    /// Whether to trim (default [`TrimMode::Default`]).
    pub mode: TrimMode,
    /// The alpha shape when the loops are computed here (default
    /// [`BoundaryConfig::default`]: alpha 2.5 spacings, widened with the
    /// local spacing where the points are sparser than the median).
    pub boundary: BoundaryConfig,
    /// The trim curves (default [`TrimConfig::default`]).
    pub trim: TrimConfig,
    /// The assessment the face is measured with again (the pipeline's own;
    /// default [`AssessConfig::default`]).
    pub assess: AssessConfig,
}

/// What [`run`] returns.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct TrimReport {
    /// The trimmed face; `None` when not trimmed, or when the loops are
    /// the rectangle's own edges without holes (nothing to trim).
    pub trimmed: Option<TrimmedSurface>,
    /// Why the face kept its rectangle under [`TrimMode::Default`] (the
    /// error that trimming gave), for the front to show.
    pub kept_rectangle: Option<String>,
}

/// What [`run`] trims: the fitted surface, the points and their parameters
/// (indexed alike), and where the loops come from.
#[derive(Debug)]
pub struct TrimInput<'a> {
    /// The fitted surface.
    pub surface: &'a Surface,
    /// The points it was fitted to. When the loops are computed here, the
    /// cloud's cached KD-tree is released first
    /// ([`PointCloud::release_tree`]; about 37 bytes per point, idle while
    /// the alpha shape allocates) and built again only if a face is
    /// measured: `mba` on 10^7 points then peaks in its assessment, not in
    /// its trim (BENCHMARKS.md).
    pub cloud: &'a mut PointCloud,
    /// Each point's parameters on the surface.
    pub uv: &'a [[f64; 2]],
    /// The loops' source.
    pub loops: Loops<'a>,
}

/// Bounds the surface of `input` by the cloud's boundary loops and, when a
/// face results, measures `quality` (the pipeline's assessment of the
/// surface, taken with `config.assess`) again on that face
/// ([`assess_trimmed`]).
///
/// Errors: under [`TrimMode::Required`], whatever kept the rectangle (a
/// periodic surface, an alpha shape that does not hold the cloud
/// together); under any mode, a face with no sample or a parameter count
/// that differs from the point count.
///
/// ```
/// use scanfit::pipeline::mba::{run as mba, MbaRunConfig};
/// use scanfit::pipeline::trim::{run, Loops, TrimInput, TrimRunConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a bump over a 60 x 60 grid with a square hole of 10 x 10 cells
/// let pts: Vec<Point3> = (0..3600)
///     .map(|k| ((k % 60) as f64, (k / 60) as f64))
///     .filter(|&(x, y)| !((25.0..35.0).contains(&x) && (25.0..35.0).contains(&y)))
///     .map(|(x, y)| Point3::new(x, y, 20.0 * (-((x - 30.0).powi(2) + (y - 30.0).powi(2)) / 400.0).exp()))
///     .collect();
/// let mut cloud = PointCloud::new(pts)?;
/// let r = mba(&cloud, &MbaRunConfig::default(), &NoProgress)?;
/// let mut quality = r.assessment.quality;
/// let input = TrimInput {
///     surface: &r.surface,
///     cloud: &mut cloud,
///     uv: &r.uv,
///     loops: Loops::Parameters { scale: [r.frame.width, r.frame.height] },
/// };
/// let t = run(input, &mut quality, &TrimRunConfig::default(), &NoProgress)?;
/// let face = t.trimmed.expect("the hole is trimmed");
/// // the outline is the lattice's rectangle, the hole its one trim loop
/// assert!(face.outer.is_none() && face.holes.len() == 1);
/// assert!(!face.contains(0.5, 0.5) && face.contains(0.1, 0.1));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    input: TrimInput,
    quality: &mut SurfaceQuality,
    config: &TrimRunConfig,
    progress: &dyn Progress,
) -> Result<TrimReport> {
    if config.mode == TrimMode::Off {
        return Ok(TrimReport::default());
    }
    let points = input.cloud.points();
    if input.uv.len() != points.len() {
        return Err(Error::InvalidInput(format!(
            "{} parameter pairs for {} points: cannot trim",
            input.uv.len(),
            points.len()
        )));
    }
    progress.stage("trimming: boundary loops", None);
    if !matches!(input.loops, Loops::Given(_)) {
        input.cloud.release_tree();
    }
    let trimmed = face(&input, config);
    let trimmed = match (trimmed, config.mode) {
        (Ok(t), _) => t,
        (Err(e), TrimMode::Default) => {
            return Ok(TrimReport {
                trimmed: None,
                kept_rectangle: Some(e.to_string()),
            })
        }
        (Err(e), _) => return Err(e),
    };
    // a boundary that is the rectangle's own, without holes, trims nothing
    let trimmed = (trimmed.outer.is_some() || !trimmed.holes.is_empty()).then_some(trimmed);
    if let Some(t) = &trimmed {
        progress.stage("trimming: measuring the face", None);
        assess_trimmed(quality, t, input.cloud, &config.assess)?;
    }
    Ok(TrimReport {
        trimmed,
        kept_rectangle: None,
    })
}

/// The loops of `input` and the face they bound.
fn face(input: &TrimInput, config: &TrimRunConfig) -> Result<TrimmedSurface> {
    let computed;
    let boundary = match input.loops {
        Loops::Given(b) => b,
        Loops::Parameters { scale } => {
            computed = boundary_loops_2d(input.uv, scale, &config.boundary)?;
            &computed
        }
        Loops::BestFitPlane => {
            computed = boundary_loops(input.cloud.points(), &config.boundary)?;
            &computed
        }
    };
    trim_surface(input.surface, input.uv, boundary, &config.trim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::testutil::Rng;
    use crate::pipeline::mba::{run as mba, MbaRunConfig};
    use crate::progress::NoProgress;
    use crate::Point3;

    /// Franke's function on `n` uniform random points of the unit square.
    fn franke(n: usize, seed: u64) -> PointCloud {
        let mut rng = Rng::new(seed);
        let pts = (0..n)
            .map(|_| {
                let (x, y) = (rng.uniform(), rng.uniform());
                Point3::new(x, y, crate::testdata::franke(x, y))
            })
            .collect();
        PointCloud::new(pts).unwrap()
    }

    #[test]
    fn mba_on_a_filled_square_keeps_the_rectangle_and_a_tilted_plane_did_not() {
        // Franke's bumps tilt the best-fit plane; in the plane [PDE23]'s
        // one alpha leaves spurious holes, in the parameters there is one
        // loop on the domain's edges
        let mut cloud = franke(100_000, 3);
        let r = mba(&cloud, &MbaRunConfig::default(), &NoProgress).unwrap();
        let scale = [r.frame.width, r.frame.height];
        let flat = boundary_loops_2d(&r.uv, scale, &BoundaryConfig::default()).unwrap();
        assert_eq!(flat.loops.len(), 1, "{:?}", flat.areas);
        let area = flat.areas[flat.outer] / (scale[0] * scale[1]);
        assert!(area > 0.99 && area <= 1.0, "{area}");
        // (with the paper's one alpha; the default local alpha widens it
        // where the tilted projection thins the points and heals them)
        let one_alpha = BoundaryConfig {
            local_alpha: false,
            ..BoundaryConfig::default()
        };
        let tilted = boundary_loops(cloud.points(), &one_alpha).unwrap();
        assert!(tilted.loops.len() > 10, "{}", tilted.loops.len());
        let local = boundary_loops(cloud.points(), &BoundaryConfig::default()).unwrap();
        assert_eq!(local.loops.len(), 1, "{:?}", local.areas);
        let mut q = r.assessment.quality;
        let input = TrimInput {
            surface: &r.surface,
            cloud: &mut cloud,
            uv: &r.uv,
            loops: Loops::Parameters { scale },
        };
        let t = run(input, &mut q, &TrimRunConfig::default(), &NoProgress).unwrap();
        assert!(t.trimmed.is_none() && t.kept_rectangle.is_none());
        assert_eq!(
            q, r.assessment.quality,
            "an untrimmed face is not measured again"
        );
    }
}
