//! `scanfit report MODEL.json INPUT` as a library call: how well a
//! multi-patch model ([`PatchComplex`], e.g. written by
//! [`crate::pipeline::reconstruct`]) represents a cloud, per patch, per edge
//! and in total.
//!
//! * **Points to patches**: by the cloud's patch label
//!   ([`crate::network::read_labels`], the rules of `reconstruct`: the named
//!   attribute or the first of [`LABEL_NAMES`], negative and ignored ids out)
//!   when it has one; a label that no patch of the model carries leaves its
//!   points out (counted). Without a label attribute each point goes to the
//!   patch at the smallest orthogonal distance among its candidates (as the
//!   reconstruction measures a patch's points): the patches owning one of
//!   the point's [`CANDIDATE_SAMPLES`] nearest samples of a 33 x 33 grid
//!   over every face. The nearest sample alone would send a point near a
//!   shared edge to the patch whose grid happens to be closer, not to the
//!   surface it lies on, and overstate that patch's error.
//! * **Per patch**: the PDE paper's eq. 15 errors `|P_i - S(u_i, v_i)|` at
//!   the closest-point parameters on the Coons patch of the face's boundary
//!   (§4.4, as the reconstruction computes them), and the orthogonal
//!   distances to the surface, both by the one assessment
//!   ([`assess_surface`]). A face the Coons patch cannot be rebuilt for in
//!   the reconstruction's layout (a domain other than `[0, 1]^2`, a collapsed
//!   side other than `[3]`) is measured at the orthogonal projections'
//!   parameters instead ([`Parameters::Projection`]).
//! * **Per edge**: the largest gap between the edge curve and each face side
//!   on it and between the two faces ([`PatchComplex::boundary_gaps`]) and
//!   the largest angle between their normals, the G1 defect
//!   ([`PatchComplex::normal_angles`]).

use rayon::prelude::*;

use crate::base::CoonsPatch;
use crate::bspline::Curve;
use crate::metrics::ErrorStats;
use crate::network::{coons_uv, read_labels, LabelConfig, LABEL_NAMES};
use crate::pipeline::assess::{assess_projected, assess_surface, AssessConfig};
use crate::pipeline::reconstruct::pooled;
use crate::progress::Progress;
use crate::project::{InversionConfig, InversionWorkspace, SurfaceInverter};
use crate::topology::{Face, PatchComplex};
use crate::{Error, Point3, PointCloud, Result};

/// Settings of [`run`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ModelMeasureConfig {
    /// The label attribute and ignored ids (default: as `reconstruct`).
    pub labels: LabelConfig,
    /// The assessment of each patch (default: no parameterization measure).
    pub assess: AssessConfig,
    /// Samples per edge for the normal angle (default 65).
    pub edge_samples: usize,
}

impl Default for ModelMeasureConfig {
    fn default() -> Self {
        Self {
            labels: LabelConfig::default(),
            assess: AssessConfig {
                parameterization: false,
                ..AssessConfig::default()
            },
            edge_samples: 65,
        }
    }
}

/// How the points were given to the patches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Assignment {
    /// By the label attribute of this name.
    Labels(String),
    /// Each point to the nearby patch at the smallest orthogonal distance
    /// (the cloud has no label; see the module documentation).
    Nearest,
}

/// The parameters of a patch's eq. 15 errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameters {
    /// Closest points on the Coons patch of the face's boundary (PDE paper
    /// §4.4, as the reconstruction).
    Coons,
    /// The orthogonal projections onto the face (eq. 15 = orthogonal).
    Projection,
}

/// One patch's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchMeasure {
    /// The patch id.
    pub id: i64,
    /// Non-degenerate sides (3 or 4).
    pub sides: usize,
    /// Edges around it.
    pub edges: usize,
    /// Points assigned to it.
    pub points: usize,
    /// Where the eq. 15 parameters come from.
    pub parameters: Parameters,
    /// Eq. 15 errors (`None` without points).
    pub errors: Option<ErrorStats>,
    /// Orthogonal distances (`None` without points).
    pub orthogonal: Option<ErrorStats>,
}

/// One edge's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeMeasure {
    /// The edge index.
    pub edge: usize,
    /// The ids of the patches on it (1 on the border, 2 inside).
    pub patches: Vec<i64>,
    /// Largest gap between the edge curve and a face side on it, or between
    /// the two faces.
    pub max_gap: f64,
    /// Largest angle in degrees between the two faces' normals (`None` on
    /// the border).
    pub max_angle_deg: Option<f64>,
}

/// Totals over the model.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelTotals {
    /// Eq. 15 errors over all assigned points.
    pub errors: ErrorStats,
    /// Orthogonal distances over all assigned points.
    pub orthogonal: ErrorStats,
    /// Largest gap over the edges.
    pub max_gap: f64,
    /// Largest normal angle over the edges (degrees).
    pub max_angle_deg: f64,
    /// Whether every edge has two faces.
    pub closed: bool,
}

/// What [`run`] returns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ModelMeasureReport {
    /// How the points were assigned.
    pub assignment: Assignment,
    /// Points left out: negative or ignored labels, labels of no patch.
    pub left_out: usize,
    /// Per face, in the model's order.
    pub patches: Vec<PatchMeasure>,
    /// Per edge.
    pub edges: Vec<EdgeMeasure>,
    /// Totals.
    pub totals: ModelTotals,
}

/// The points of each face (indices into the cloud) and how they were found.
fn assign(
    model: &PatchComplex,
    cloud: &PointCloud,
    labels: &LabelConfig,
) -> Result<(Vec<Vec<usize>>, Assignment, usize)> {
    let has_label = labels.attribute.is_some()
        || cloud
            .attributes()
            .iter()
            .any(|a| LABEL_NAMES.iter().any(|n| a.name.eq_ignore_ascii_case(n)));
    let mut out = vec![Vec::new(); model.faces.len()];
    if has_label {
        let l = read_labels(cloud, labels)?;
        let mut left_out = l.ignored;
        for (id, members) in l.ids.iter().zip(l.members) {
            match model.faces.iter().position(|f| f.id == *id) {
                Some(k) => out[k] = members,
                None => left_out += members.len(),
            }
        }
        return Ok((out, Assignment::Labels(l.attribute), left_out));
    }
    for (i, k) in nearest_surface(model, cloud.points())?
        .into_iter()
        .enumerate()
    {
        out[k].push(i);
    }
    Ok((out, Assignment::Nearest, 0))
}

/// The Coons patch of a face's boundary in the reconstruction's layout
/// (domain `[0, 1]^2`, at most side 3 collapsed), or `None`.
/// Nearest samples of a point whose faces are its candidates in
/// [`nearest_surface`]: a point within a grid cell of a shared edge has
/// samples of both faces among them (the edge's samples coincide).
pub const CANDIDATE_SAMPLES: usize = 8;

/// Intervals per direction of each face's sample grid in [`nearest_surface`].
const SAMPLE_GRID: usize = 32;

/// For each of `points`, the index of the face of `model` at the smallest
/// orthogonal distance among its candidates (the faces owning one of its
/// [`CANDIDATE_SAMPLES`] nearest samples on a grid over every face), each
/// inverted from its nearest sample of that face.
fn nearest_surface(model: &PatchComplex, points: &[Point3]) -> Result<Vec<usize>> {
    let mut samples = Vec::new();
    let mut at: Vec<(usize, [f64; 2])> = Vec::new();
    for (k, f) in model.faces.iter().enumerate() {
        let ((u0, u1), (v0, v1)) = f.surface.domain();
        for i in 0..=SAMPLE_GRID {
            for j in 0..=SAMPLE_GRID {
                let t = i as f64 / SAMPLE_GRID as f64;
                let uv = [
                    u0 + (u1 - u0) * t,
                    v0 + (v1 - v0) * j as f64 / SAMPLE_GRID as f64,
                ];
                samples.push(f.surface.point(uv[0], uv[1]));
                at.push((k, uv));
            }
        }
    }
    let near = PointCloud::new(samples)?.knn_batch(points, CANDIDATE_SAMPLES)?;
    let inverters: Vec<SurfaceInverter> = model
        .faces
        .iter()
        .map(|f| SurfaceInverter::new(&f.surface, InversionConfig::default()))
        .collect::<Result<_>>()?;
    Ok(points
        .par_iter()
        .enumerate()
        .map_init(
            || -> Vec<InversionWorkspace<_>> {
                model
                    .faces
                    .iter()
                    .map(|f| InversionWorkspace::new(&f.surface))
                    .collect()
            },
            |ws, (i, p)| {
                // the candidates in order of their nearest sample, each once
                let mut first: Vec<(usize, [f64; 2])> = Vec::with_capacity(near.k);
                for &s in &near.indices[i * near.k..(i + 1) * near.k] {
                    let (k, uv) = at[s as usize];
                    if !first.iter().any(|c| c.0 == k) {
                        first.push((k, uv));
                    }
                }
                if first.len() == 1 {
                    return first[0].0;
                }
                first
                    .iter()
                    .map(|&(k, uv)| (k, inverters[k].invert_near(p, uv, &mut ws[k]).distance))
                    .fold(
                        (first[0].0, f64::INFINITY),
                        |b, c| if c.1 < b.1 { c } else { b },
                    )
                    .0
            },
        )
        .collect())
}

fn coons_of(f: &Face) -> Result<Option<CoonsPatch>> {
    let ((u0, u1), (v0, v1)) = f.surface.domain();
    if (u0, u1, v0, v1) != (0.0, 1.0, 0.0, 1.0) || (0..3).any(|k| f.sides[k].is_empty()) {
        return Ok(None);
    }
    let sides: Vec<Curve> = (0..4)
        .filter(|&k| !f.sides[k].is_empty())
        .map(|k| f.side_curve(k))
        .collect::<Result<_>>()?;
    Ok(CoonsPatch::from_loop(&sides).ok())
}

/// Measures one face against its points.
fn measure_face(f: &Face, pts: &[Point3], cfg: &ModelMeasureConfig) -> Result<PatchMeasure> {
    let mut m = PatchMeasure {
        id: f.id,
        sides: f.side_count(),
        edges: f.use_count(),
        points: pts.len(),
        parameters: Parameters::Projection,
        errors: None,
        orthogonal: None,
    };
    if pts.is_empty() {
        return Ok(m);
    }
    let ctx = |e: Error| Error::InvalidInput(format!("patch {}: {e}", f.id));
    let a = match coons_of(f)? {
        Some(coons) => {
            let uv = coons_uv(&coons, pts, cfg.assess.inversion).map_err(ctx)?;
            m.parameters = Parameters::Coons;
            assess_surface(&f.surface, pts, &uv, &cfg.assess).map_err(ctx)?
        }
        None => assess_projected(&f.surface, pts, &cfg.assess).map_err(ctx)?,
    };
    m.errors = Some(a.quality.at_parameters);
    m.orthogonal = Some(a.quality.orthogonal);
    Ok(m)
}

/// Measures `cloud` against `model` (see the module documentation).
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::pipeline::measure_model::{run, Assignment, ModelMeasureConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::topology::{FaceCorners, PatchComplex};
/// use scanfit::{Point3, PointCloud};
/// let k = KnotVector::uniform_clamped(1, 2)?;
/// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
/// let sq = |x0: f64| Surface::new(k.clone(), k.clone(),
///     vec![p(x0, 0.0), p(x0, 1.0), p(x0 + 1.0, 0.0), p(x0 + 1.0, 1.0)]);
/// let verts = vec![p(0., 0.), p(1., 0.), p(2., 0.), p(0., 1.), p(1., 1.), p(2., 1.)];
/// let model = PatchComplex::assemble(verts, vec![
///     FaceCorners { id: 1, surface: sq(0.0)?, corners: [0, 1, 4, 3] },
///     FaceCorners { id: 2, surface: sq(1.0)?, corners: [1, 2, 5, 4] },
/// ])?;
/// // points 0.01 above the left square, 0.03 above the right one, unlabelled
/// let pts: Vec<Point3> = (0..200)
///     .map(|i| {
///         let x = 0.05 + 1.9 * (i % 20) as f64 / 19.0;
///         Point3::new(x, 0.05 + 0.9 * (i / 20) as f64 / 9.0, if x < 1.0 { 0.01 } else { 0.03 })
///     })
///     .collect();
/// let r = run(&model, &PointCloud::new(pts)?, &ModelMeasureConfig::default(), &NoProgress)?;
/// assert_eq!(r.assignment, Assignment::Nearest);
/// assert_eq!((r.patches[0].points, r.patches[1].points), (100, 100));
/// assert!((r.patches[1].errors.unwrap().rmse - 0.03).abs() < 1e-9);
/// assert!(r.totals.max_gap < 1e-12);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    model: &PatchComplex,
    cloud: &PointCloud,
    cfg: &ModelMeasureConfig,
    progress: &dyn Progress,
) -> Result<ModelMeasureReport> {
    if !(2..=100_000).contains(&cfg.edge_samples) {
        return Err(Error::InvalidInput(format!(
            "{} edge samples: give 2 to 100000",
            cfg.edge_samples
        )));
    }
    model.validate_structure()?;
    progress.stage("assigning points", None);
    let (members, assignment, left_out) = assign(model, cloud, &cfg.labels)?;
    progress.stage("patches", Some(model.faces.len() as u64));
    let patches: Vec<PatchMeasure> = model
        .faces
        .par_iter()
        .zip(&members)
        .map(|(f, m)| {
            let pts: Vec<Point3> = m.iter().map(|&i| cloud.points()[i]).collect();
            let r = measure_face(f, &pts, cfg);
            progress.advance(1);
            r
        })
        .collect::<Result<_>>()?;
    progress.stage("edges", None);
    let gaps = model.boundary_gaps()?;
    let angles = model.normal_angles(cfg.edge_samples)?;
    let users = model.edge_faces();
    let edges: Vec<EdgeMeasure> = gaps
        .iter()
        .zip(&angles)
        .map(|(g, a)| EdgeMeasure {
            edge: g.edge,
            patches: users[g.edge]
                .iter()
                .map(|s| model.faces[s.face].id)
                .collect(),
            max_gap: g.curve_gap.max(g.face_gap),
            max_angle_deg: *a,
        })
        .collect();
    let totals = ModelTotals {
        errors: pooled(patches.iter().filter_map(|p| p.errors.as_ref())),
        orthogonal: pooled(patches.iter().filter_map(|p| p.orthogonal.as_ref())),
        max_gap: edges.iter().map(|e| e.max_gap).fold(0.0, f64::max),
        max_angle_deg: edges
            .iter()
            .filter_map(|e| e.max_angle_deg)
            .fold(0.0, f64::max),
        closed: model.is_closed(),
    };
    Ok(ModelMeasureReport {
        assignment,
        left_out,
        patches,
        edges,
        totals,
    })
}
