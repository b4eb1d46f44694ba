//! Whole-object reconstruction from a segmented cloud (issue 15): the patch
//! network, one shared curve per edge, one surface per patch whose boundary
//! is exactly those curves (PDE paper §§4-5, Coons paper §III).
//!
//! [`run`] builds the network ([`crate::network::build_network`]), groups
//! each patch's edges into 3 or 4 sides, and fits every patch inside its
//! side curves ([`crate::network::fit_face`]: Coons patch, closest-point
//! parameters, PDE deformation or least-squares B-spline), the patches in
//! parallel. It then samples every edge from each patch that uses it: the
//! gap (which is rounding only, since the boundary control rows are the edge
//! curves) and the angle between the two patches' normals (the G1 defect;
//! the PDE paper makes no attempt at tangent continuity, nor does this).

use crate::centring::Centring;
use rayon::prelude::*;

use crate::bspline::{BasisWorkspace, Curve, Surface};
use crate::metrics::ErrorStats;
use crate::network::folds::fold_overs;
use crate::network::layout::grid_frame::grid_frame;
use crate::network::layout::{generate_labels, LabelSource, GENERATED_LABEL};
use crate::network::{
    build_network, fit_face, group_sides, side_curve, side_ranges, FaceConfig, FaceFit,
    FaceSurface, NetUse, Network, NetworkConfig,
};
use crate::pipeline::assess::{bounding_box, extent_in_box, sample_grid, AssessConfig, Extent};
use crate::progress::Progress;
use crate::project::InversionConfig;
use crate::topology::{self, PatchComplex};
use crate::{Error, Point3, PointCloud, Result, Vector3};

/// Uniform spans per row and column of a grid frame on the PDE route (the
/// network's own edge curves have at most 16, a power of two near the square
/// root of their points).
const GRID_PDE_FRAME_SPANS: usize = 8;

/// Settings of [`run`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ReconstructConfig {
    /// Where the patch ids come from (default: the cloud's label attribute;
    /// or a segmentation, or a layout, whose ids replace it: see
    /// [`crate::network::layout`]).
    pub source: LabelSource,
    /// Labels, borders, junctions and edge curves (see [`NetworkConfig`]).
    pub network: NetworkConfig,
    /// The fit inside each patch's boundary: PDE deformation with 5 x 5
    /// terms (default, the PDE paper's), or a least-squares B-spline.
    pub fit: FaceFit,
    /// Closest-point projection for the parameters and the orthogonal
    /// distances (default [`InversionConfig::default`]).
    pub inversion: InversionConfig,
    /// Largest distance between a PDE surface and its exported B-spline
    /// form, in data units; `None` (default): `1e-4` x the model diagonal.
    pub tolerance: Option<f64>,
    /// Samples per edge for the gap and normal-angle measures (default 65).
    pub edge_samples: usize,
    /// Per-patch fits replacing [`ReconstructConfig::fit`] for the patches
    /// named (by label), e.g. a denser control net where the data carry more
    /// detail (default none).
    pub patch_fit: Vec<(i64, FaceFit)>,
    /// Return the model even when a patch leaves its data (default `false`:
    /// [`run`] fails with [`Error::LeavesData`] naming the first such patch).
    /// Each patch's surface is sampled on the grid of
    /// [`AssessConfig::samples`] and measured against the bounding box of
    /// the patch's own points, with the single-patch commands' limit: the
    /// larger of [`AssessConfig::leave_spacings`] point spacings and
    /// [`AssessConfig::leave_diagonal`] x the patch's diagonal.
    pub allow_extrapolation: bool,
}

impl Default for ReconstructConfig {
    fn default() -> Self {
        Self {
            source: LabelSource::default(),
            network: NetworkConfig::default(),
            fit: FaceFit::default(),
            inversion: InversionConfig::default(),
            tolerance: None,
            edge_samples: 65,
            patch_fit: Vec::new(),
            allow_extrapolation: false,
        }
    }
}

/// One patch of the result.
#[derive(Debug, Clone)]
pub struct PatchReport {
    /// The label.
    pub id: i64,
    /// 3 or 4.
    pub sides: usize,
    /// Edges around it (more than `sides` where a side holds several).
    pub edges: usize,
    /// Points.
    pub points: usize,
    /// Eq. 15 errors of its Coons patch.
    pub coons_errors: ErrorStats,
    /// Eq. 15 errors of the fitted surface (mean, max, RMSE).
    pub errors: ErrorStats,
    /// Orthogonal distances to the exported B-spline surface.
    pub orthogonal: ErrorStats,
    /// Distance between the PDE surface and its B-spline form.
    pub conversion_deviation: f64,
    /// Points whose parameters fold over ([`crate::network::folds`]).
    pub fold_overs: usize,
    /// How far its surface reaches outside the bounding box of its own
    /// points (see [`ReconstructConfig::allow_extrapolation`]).
    pub extent: Extent,
}

/// One edge of the result.
#[derive(Debug, Clone)]
pub struct EdgeReport {
    /// Its vertices.
    pub vertices: [usize; 2],
    /// The labels of its patches (`None`: free boundary).
    pub patches: [Option<i64>; 2],
    /// Largest distance, over the samples, between the edge curve and each
    /// patch's surface along it, and between the two surfaces.
    pub max_gap: f64,
    /// Largest angle (radians) between the two patches' normals along it
    /// (the G1 defect; 0 on a free edge).
    pub max_angle: f64,
    /// Largest distance of its fitted border points from the curve.
    pub curve_error: f64,
}

/// Totals over the object.
#[derive(Debug, Clone)]
pub struct Totals {
    /// Eq. 15 errors over every patch's points.
    pub errors: ErrorStats,
    /// Orthogonal distances over every patch's points.
    pub orthogonal: ErrorStats,
    /// Largest gap over the edges.
    pub max_gap: f64,
    /// Largest normal angle over the edges (radians).
    pub max_angle: f64,
    /// Diagonal of the labelled points' bounding box.
    pub diagonal: f64,
    /// Whether every edge has two patches.
    pub closed: bool,
    /// Control points of the model, each counted once
    /// ([`PatchComplex::control_point_count`]).
    pub control_points: usize,
}

/// The result of [`run`].
#[derive(Debug, Clone)]
pub struct ReconstructReport {
    /// Vertices, edges with their shared curves, patches with their cycles.
    pub network: Network,
    /// Per patch (in the network's order) its sides: edge uses, counter-clockwise.
    pub sides: Vec<Vec<Vec<NetUse>>>,
    /// Per patch its fitted surface.
    pub faces: Vec<FaceSurface>,
    /// Per patch its numbers.
    pub patches: Vec<PatchReport>,
    /// Per edge its numbers.
    pub edges: Vec<EdgeReport>,
    /// Totals.
    pub totals: Totals,
    /// What the segmentation or layout found (`None`: the cloud's own labels).
    pub layout: Option<String>,
    /// The model as a [`PatchComplex`] (faces sharing edges, a side of a
    /// patch with more than four corners a chain of several), for the CAD
    /// writers.
    pub complex: PatchComplex,
}

/// The `(u, v)` of side `s` at side parameter `t` (counter-clockwise: side
/// 0 `S(t, 0)`, 1 `S(1, t)`, 2 `S(1 - t, 1)`, 3 `S(0, 1 - t)`).
pub fn side_uv(s: usize, t: f64) -> [f64; 2] {
    match s {
        0 => [t, 0.0],
        1 => [1.0, t],
        2 => [1.0 - t, 1.0],
        _ => [0.0, 1.0 - t],
    }
}

/// Where patch `sides` meets edge `edge` at edge parameter `t`: the `(u, v)`.
pub fn edge_uv(sides: &[Vec<NetUse>], curves: &[Curve], edge: usize, t: f64) -> Option<[f64; 2]> {
    for (s, uses) in sides.iter().enumerate() {
        let ranges = side_ranges(uses, curves);
        for (u, &(a, b)) in uses.iter().zip(&ranges) {
            if u.edge == edge {
                let tu = if u.reversed { 1.0 - t } else { t };
                return Some(side_uv(s, a + (b - a) * tu));
            }
        }
    }
    None
}

/// Reconstructs the labelled `cloud` as patches sharing their edge curves.
///
/// ```
/// use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
/// // a gently curved 2 x 1 sheet in two labelled halves
/// let (mut pts, mut lab) = (Vec::new(), Vec::new());
/// for i in 0..=60 {
///     for j in 0..=30 {
///         let (x, y) = (i as f64 / 30.0, j as f64 / 30.0);
///         pts.push(Point3::new(x, y, 0.1 * (x * y).sin()));
///         lab.push(if i < 30 { 0.0 } else { 1.0 });
///     }
/// }
/// let cloud = PointCloud::new(pts)?.with_attribute("label", lab)?;
/// let r = run(&cloud, &ReconstructConfig::default(), &NoProgress)?;
/// assert_eq!(r.patches.len(), 2);
/// assert!(r.totals.max_gap <= 1e-9 * r.totals.diagonal);
/// assert!(r.totals.orthogonal.rmse < 1e-3, "{:?}", r.totals.orthogonal);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    cloud: &PointCloud,
    cfg: &ReconstructConfig,
    progress: &dyn Progress,
) -> Result<ReconstructReport> {
    // computed relative to the data's centre, moved back exactly (issue 14)
    let centring = Centring::of(cloud.points());
    let local = centring.cloud(cloud)?;
    Ok(centring.restore(run_centred(&local, cfg, progress)?))
}

/// [`run`] on data whose centre is at the origin.
fn run_centred(
    cloud: &PointCloud,
    cfg: &ReconstructConfig,
    progress: &dyn Progress,
) -> Result<ReconstructReport> {
    // generated ids go into the label attribute of a copy, read as hand labels are
    let labelled;
    let mut net_cfg = cfg.network.clone();
    let mut generated = generate_labels(cloud, &cfg.source, progress)?;
    let layout = generated.as_ref().map(|g| g.summary.clone());
    let grid = generated.as_mut().and_then(|g| g.grid.take());
    let cloud = match generated {
        None => cloud,
        Some(g) => {
            labelled = cloud.clone().with_attribute(
                GENERATED_LABEL,
                g.labels.iter().map(|&i| i as f64).collect(),
            )?;
            net_cfg.labels.attribute = Some(GENERATED_LABEL.into());
            &labelled
        }
    };
    let mut network = build_network(cloud, &net_cfg, progress)?;
    let frame = match &grid {
        Some((g, options)) if options.frame => {
            progress.stage("grid frame", None);
            let ctrl = match cfg.fit {
                FaceFit::Bspline { ctrl } => ctrl,
                // the PDE route: frame spans as the network's own edge curves
                _ => (GRID_PDE_FRAME_SPANS + 3, GRID_PDE_FRAME_SPANS + 3),
            };
            let detail = options.detail_ctrl && matches!(cfg.fit, FaceFit::Bspline { .. });
            let f = grid_frame(cloud.points(), g, ctrl, detail)?;
            let along_u = f.apply(g, &mut network)?;
            Some((f, along_u))
        }
        _ => None,
    };
    let (lo, hi) = network
        .patches
        .iter()
        .flat_map(|p| p.points.iter().map(|&i| cloud.points()[i].coords))
        .fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(&p), hi.sup(&p)),
        );
    let diagonal = (hi - lo).norm();
    let tolerance = match cfg.tolerance {
        Some(t) if t.is_finite() && t > 0.0 => t,
        Some(t) => {
            return Err(Error::InvalidInput(format!(
                "B-spline form tolerance {t} must be a positive number of data units"
            )))
        }
        None => 1e-4 * diagonal,
    };
    if !(2..=100_000).contains(&cfg.edge_samples) {
        return Err(Error::InvalidInput(format!(
            "{} edge samples: give 2 to 100000",
            cfg.edge_samples
        )));
    }
    let curves: Vec<Curve> = network.edges.iter().map(|e| e.curve.clone()).collect();
    let sides: Vec<Vec<Vec<NetUse>>> = network
        .patches
        .iter()
        .map(|p| group_sides(&p.cycle, &curves, p.id))
        .collect::<Result<_>>()?;
    // a grid frame's nets, turned to each patch's own (u, v): its side 0
    // runs along the base's u or v
    let frame_fit: Vec<Option<FaceFit>> = network
        .patches
        .iter()
        .zip(&sides)
        .map(|(p, s)| match (&frame, cfg.fit) {
            (Some((f, along_u)), FaceFit::Bspline { .. }) => {
                let (a, b) = *f.ctrl.get(p.id as usize)?;
                let ctrl = if along_u[s[0][0].edge] {
                    (a, b)
                } else {
                    (b, a)
                };
                Some(FaceFit::Bspline { ctrl })
            }
            _ => None,
        })
        .collect();
    let face_cfg = FaceConfig {
        fit: cfg.fit,
        inversion: cfg.inversion,
        tolerance,
        ..FaceConfig::new(tolerance)
    };
    if let Some((id, _)) = cfg
        .patch_fit
        .iter()
        .find(|(id, _)| !network.patches.iter().any(|p| p.id == *id))
    {
        return Err(Error::InvalidInput(format!(
            "a fit is given for patch {id}, but no patch has that label"
        )));
    }
    progress.stage("patches", Some(network.patches.len() as u64));
    let faces: Vec<FaceSurface> = network
        .patches
        .par_iter()
        .zip(&sides)
        .zip(&frame_fit)
        .map(|((p, s), ff)| {
            let side_curves: Vec<Curve> = s
                .iter()
                .map(|uses| side_curve(uses, &curves))
                .collect::<Result<_>>()?;
            let pts: Vec<Point3> = p.points.iter().map(|&i| cloud.points()[i]).collect();
            let own = FaceConfig {
                fit: cfg
                    .patch_fit
                    .iter()
                    .find(|(id, _)| *id == p.id)
                    .map(|x| x.1)
                    .or(*ff)
                    .unwrap_or(face_cfg.fit),
                ..face_cfg
            };
            let f = fit_face(&pts, &side_curves, &own, p.id);
            progress.advance(1);
            f
        })
        .collect::<Result<_>>()?;
    progress.stage("edges", Some(network.edges.len() as u64));
    let edges: Vec<EdgeReport> = network
        .edges
        .par_iter()
        .enumerate()
        .map(|(k, e)| {
            let r = edge_report(k, e, &network, &sides, &faces, &curves, cfg.edge_samples);
            progress.advance(1);
            r
        })
        .collect();
    let patches: Vec<PatchReport> = network
        .patches
        .iter()
        .zip(&sides)
        .zip(&faces)
        .map(|((p, s), f)| {
            let pts: Vec<Point3> = p.points.iter().map(|&i| cloud.points()[i]).collect();
            Ok(PatchReport {
                id: p.id,
                sides: s.len(),
                edges: p.cycle.len(),
                points: p.points.len(),
                coons_errors: f.coons_errors,
                errors: f.errors,
                orthogonal: f.orthogonal,
                conversion_deviation: f.conversion_deviation,
                fold_overs: fold_overs(&pts, &f.uv, &f.surface)?,
                extent: patch_extent(&f.surface, &pts, network.spacing)?,
            })
        })
        .collect::<Result<_>>()?;
    if !cfg.allow_extrapolation {
        if let Some(p) = patches.iter().find(|p| p.extent.leaves) {
            return Err(Error::LeavesData {
                patch: Some(p.id),
                extent: p.extent,
            });
        }
    }
    let totals = Totals {
        errors: pooled(patches.iter().map(|p| &p.errors)),
        orthogonal: pooled(patches.iter().map(|p| &p.orthogonal)),
        max_gap: edges.iter().map(|e| e.max_gap).fold(0.0, f64::max),
        max_angle: edges.iter().map(|e| e.max_angle).fold(0.0, f64::max),
        diagonal,
        closed: network.is_closed(),
        control_points: 0,
    };
    let complex = complex(&network, &sides, &faces);
    let control_points = complex.control_point_count();
    let totals = Totals {
        control_points,
        ..totals
    };
    let layout = match (layout, &frame) {
        (Some(l), Some((f, _))) => Some(format!(
            "{l}; edges from a frame surface of the whole sheet ({} x {} spans), control nets {}; {control_points} control points counted once",
            f.row_spans.iter().sum::<usize>(),
            f.col_spans.iter().sum::<usize>(),
            if f.density.iter().all(|&d| d == f.density[0]) {
                "the same for every patch".to_string()
            } else {
                let nets: Vec<String> = f.ctrl.iter().map(|(a, b)| format!("{a}x{b}")).collect();
                format!("by detail ({})", nets.join(" "))
            }
        )),
        (l, _) => l,
    };
    Ok(ReconstructReport {
        network,
        sides,
        faces,
        patches,
        edges,
        totals,
        layout,
        complex,
    })
}

/// The [`Extent`] of one patch's `surface` against the bounding box of its
/// own `points` (sampled and limited as a single-patch fit's, with the
/// network's median `spacing`).
fn patch_extent(surface: &Surface, points: &[Point3], spacing: f64) -> Result<Extent> {
    let config = AssessConfig::default();
    let Some(b) = bounding_box(points) else {
        return Ok(Extent::default());
    };
    let (_, samples) = sample_grid(surface, &config)?;
    Ok(extent_in_box(surface, b, &samples, spacing, &config))
}

/// The network and the faces as a [`PatchComplex`] (see
/// [`ReconstructReport::complex`]).
fn complex(net: &Network, sides: &[Vec<Vec<NetUse>>], faces: &[FaceSurface]) -> PatchComplex {
    let faces = net
        .patches
        .iter()
        .zip(sides)
        .zip(faces)
        .map(|((p, s), f)| {
            let mut chains: [Vec<topology::EdgeUse>; 4] = Default::default();
            for (chain, side) in chains.iter_mut().zip(s) {
                *chain = side
                    .iter()
                    .map(|u| topology::EdgeUse {
                        edge: u.edge,
                        reversed: u.reversed,
                    })
                    .collect();
            }
            topology::Face {
                id: p.id,
                surface: f.surface.clone(),
                sides: chains,
            }
        })
        .collect();
    PatchComplex {
        vertices: net
            .vertices
            .iter()
            .map(|&point| topology::Vertex { point })
            .collect(),
        edges: net
            .edges
            .iter()
            .map(|e| topology::Edge {
                start: e.start,
                end: e.end,
                curve: e.curve.clone(),
            })
            .collect(),
        faces,
    }
}

/// The statistics of the union of several point sets from theirs.
pub(crate) fn pooled<'a>(stats: impl Iterator<Item = &'a ErrorStats>) -> ErrorStats {
    let (mut count, mut sum, mut sq, mut max) = (0usize, 0.0, 0.0, 0.0f64);
    for s in stats {
        count += s.count;
        sum += s.mean * s.count as f64;
        sq += s.rmse * s.rmse * s.count as f64;
        max = max.max(s.max);
    }
    let n = count.max(1) as f64;
    ErrorStats {
        count,
        mean: sum / n,
        max,
        max_index: 0,
        rmse: (sq / n).sqrt(),
    }
}

/// Gap and normal angle along edge `k`, sampled from every patch using it.
fn edge_report(
    k: usize,
    e: &crate::network::Edge,
    net: &Network,
    sides: &[Vec<Vec<NetUse>>],
    faces: &[FaceSurface],
    curves: &[Curve],
    samples: usize,
) -> EdgeReport {
    let users: Vec<usize> = e.patches.iter().flatten().copied().collect();
    let mut gap = 0.0f64;
    let mut angle = 0.0f64;
    let normal = |s: &Surface, uv: [f64; 2]| {
        let (p, q) = s.degrees();
        let (mut wu, mut wv) = (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1));
        s.normal(uv[0], uv[1], &mut wu, &mut wv)
    };
    for i in 0..samples {
        let t = i as f64 / (samples - 1) as f64;
        let c = e.curve.point(t);
        let mut at: Vec<(Point3, Vector3)> = Vec::new();
        for &f in &users {
            if let Some(uv) = edge_uv(&sides[f], curves, k, t) {
                let s = &faces[f].surface;
                let p = s.point(uv[0], uv[1]);
                gap = gap.max((p - c).norm());
                at.push((p, normal(s, uv)));
            }
        }
        if let [(a, na), (b, nb)] = at[..] {
            gap = gap.max((a - b).norm());
            // the ends are corners (an apex has no normal)
            if i > 0 && i + 1 < samples && na.norm() > 0.5 && nb.norm() > 0.5 {
                angle = angle.max(na.dot(&nb).clamp(-1.0, 1.0).acos());
            }
        }
    }
    EdgeReport {
        vertices: [e.start, e.end],
        patches: [
            e.patches[0].map(|p| net.patches[p].id),
            e.patches[1].map(|p| net.patches[p].id),
        ],
        max_gap: gap,
        max_angle: angle,
        curve_error: e.max_error,
    }
}
