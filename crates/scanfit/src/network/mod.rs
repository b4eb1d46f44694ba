//! The patch network of a segmented cloud (issue 15; PDE paper §§4-5,
//! Coons paper §III).
//!
//! A cloud whose points carry a patch id ([`labels`]) is reconstructed as
//! patches that share their boundary curves, so that they join without gaps:
//!
//! 1. [`labels`]: the patch id of every point (negative and ignored ids out).
//! 2. [`borders`]: each patch's alpha-shape boundary loop and, for every loop
//!    point, the patch across (KD-tree within a contact radius of a few
//!    spacings) or the free boundary.
//! 3. [`junctions`]: corners where three or more patches meet, or where an
//!    interface reaches the free boundary, shared by all patches around
//!    them; edges from corner to corner, shared by the two patches along
//!    them; each patch's boundary a cycle of edges.
//! 4. [`curves`]: one end-pinned least-squares curve per edge (PDE paper
//!    §4.2), fitted once to the border points of both patches.
//! 5. [`face`]: per patch, 3 or 4 sides from its cycle, the Coons patch of
//!    the side curves, closest-point parameters, the PDE deformation (or a
//!    least-squares B-spline) inside the fixed boundary.
//!
//! The labels of step 1 can also be made here: [`layout`] segments the
//! cloud or lays patches over a smooth object.
//!
//! [`build_network`] runs steps 1-4; the pipeline
//! [`crate::pipeline::reconstruct`] adds step 5 for every patch in parallel.

pub mod borders;
pub mod curves;
pub mod face;
pub mod folds;
pub mod junctions;
pub mod labels;
pub mod layout;

pub use curves::{fit_edge_curve, EdgeCurve, EdgeCurveConfig};
pub use face::{
    coons_uv, fit_face, group_sides, side_curve, side_ranges, FaceConfig, FaceFit, FaceSurface,
};
pub use junctions::{NetEdge, NetUse, NetVertex};
pub use labels::{read_labels, LabelConfig, Labels, LABEL_NAMES};

use crate::bspline::Curve;
use crate::cloud::boundary::BoundaryConfig;
use crate::progress::Progress;
use crate::{Error, Point3, PointCloud, Result, Vector3};

/// Settings of [`build_network`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NetworkConfig {
    /// Where the patch ids come from (default: the first of [`LABEL_NAMES`]).
    pub labels: LabelConfig,
    /// Alpha shape of each patch's border (default: 2.5 spacings).
    pub boundary: BoundaryConfig,
    /// Contact radius as a multiple of the point spacing: a border point
    /// with a point of another patch this close faces that patch (default 3).
    pub contact_factor: f64,
    /// Fewest points a patch may have (default 50).
    pub min_points: usize,
    /// Shortest stretch of border facing one patch, as a multiple of the
    /// contact radius; shorter stretches are noise at a junction (default 2).
    pub min_run_factor: f64,
    /// The edge curves (default cubic, at most 16 spans).
    pub curves: EdgeCurveConfig,
}

impl Default for NetworkConfig {
    fn default() -> Self {
        Self {
            labels: LabelConfig::default(),
            boundary: BoundaryConfig::default(),
            contact_factor: 3.0,
            min_points: 50,
            min_run_factor: 2.0,
            curves: EdgeCurveConfig::default(),
        }
    }
}

/// An edge of the network with its shared curve.
#[derive(Debug, Clone)]
pub struct Edge {
    /// Start vertex.
    pub start: usize,
    /// End vertex.
    pub end: usize,
    /// The patches on either side (indices into [`Network::patches`]; the
    /// second is `None` on the free boundary).
    pub patches: [Option<usize>; 2],
    /// The curve from `start` to `end` on `[0, 1]`; both patches use it.
    pub curve: Curve,
    /// Number of border points it was fitted to (both sides).
    pub points: usize,
    /// Largest distance of its (binned) points from it.
    pub max_error: f64,
}

/// A patch of the network.
#[derive(Debug, Clone)]
pub struct Patch {
    /// The label.
    pub id: i64,
    /// Its points (indices into the input cloud).
    pub points: Vec<usize>,
    /// Its boundary as a cycle of edge uses, counter-clockwise about the
    /// patch's outward side (consistent across the network).
    pub cycle: Vec<NetUse>,
}

/// The patch network: vertices, shared edges with their curves, patches.
#[derive(Debug, Clone)]
pub struct Network {
    /// The label attribute read.
    pub attribute: String,
    /// Points left out (negative or ignored ids).
    pub ignored: usize,
    /// Point spacing (median over the patches).
    pub spacing: f64,
    /// Contact radius used.
    pub contact_radius: f64,
    /// Corners.
    pub vertices: Vec<Point3>,
    /// Edges.
    pub edges: Vec<Edge>,
    /// Patches.
    pub patches: Vec<Patch>,
}

impl Network {
    /// Whether every edge has two patches.
    pub fn is_closed(&self) -> bool {
        self.edges.iter().all(|e| e.patches[1].is_some())
    }
}

/// Builds the patch network of a labelled cloud (steps 1-4 of the module
/// docs).
///
/// Errors name the patch and what to change: a single patch (`scanfit
/// coons` fits one), a patch with too few points, a patch that is not a
/// topological disk, a border with no corner, a non-orientable network.
///
/// ```
/// use scanfit::network::{build_network, NetworkConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
/// // a 2 x 1 sheet: two labelled halves
/// let mut pts = Vec::new();
/// let mut lab = Vec::new();
/// for i in 0..80 {
///     for j in 0..40 {
///         pts.push(Point3::new(i as f64 / 40.0, j as f64 / 40.0, 0.0));
///         lab.push(if i < 40 { 1.0 } else { 2.0 });
///     }
/// }
/// let cloud = PointCloud::new(pts)?.with_attribute("label", lab)?;
/// let net = build_network(&cloud, &NetworkConfig::default(), &NoProgress)?;
/// assert_eq!(net.patches.len(), 2);
/// assert_eq!(net.vertices.len(), 6);
/// assert_eq!(net.edges.len(), 7);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn build_network(
    cloud: &PointCloud,
    cfg: &NetworkConfig,
    progress: &dyn Progress,
) -> Result<Network> {
    if !(cfg.contact_factor.is_finite() && cfg.contact_factor > 0.0) {
        return Err(Error::InvalidInput(format!(
            "contact factor {} must be a positive multiple of the spacing (default 3)",
            cfg.contact_factor
        )));
    }
    progress.stage("labels", None);
    let labels = read_labels(cloud, &cfg.labels)?;
    if labels.ids.len() < 2 {
        return Err(Error::InvalidInput(format!(
            "attribute '{}' has a single patch (label {}); reconstruct needs two or more labelled patches: fit one patch with `scanfit coons`, or label the cloud's patches",
            labels.attribute, labels.ids[0]
        )));
    }
    let min_points = cfg.min_points.max(10);
    for (id, m) in labels.ids.iter().zip(&labels.members) {
        if m.len() < min_points {
            return Err(Error::InvalidInput(format!(
                "patch {id} has {} points, fewer than the {min_points} a patch needs; merge it into a neighbour, relabel it, or leave it out with --ignore {id}",
                m.len()
            )));
        }
    }
    // the labelled points only, with their patch
    let kept: Vec<usize> = {
        let mut k: Vec<usize> = labels.members.iter().flatten().copied().collect();
        k.sort_unstable();
        k
    };
    let mut local = vec![usize::MAX; cloud.len()];
    for (l, &i) in kept.iter().enumerate() {
        local[i] = l;
    }
    let sub = PointCloud::new(kept.iter().map(|&i| cloud.points()[i]).collect())?;
    let mut patch_of = vec![0usize; kept.len()];
    let members: Vec<Vec<usize>> = labels
        .members
        .iter()
        .enumerate()
        .map(|(k, m)| {
            m.iter()
                .map(|&i| {
                    patch_of[local[i]] = k;
                    local[i]
                })
                .collect()
        })
        .collect();
    progress.stage("borders", Some(labels.ids.len() as u64));
    let loops = borders::patch_loops(sub.points(), &members, &labels.ids, &cfg.boundary)?;
    let mut sp: Vec<f64> = loops.iter().map(|l| l.1).collect();
    sp.sort_by(f64::total_cmp);
    let spacing = sp[sp.len() / 2];
    let radius = cfg.contact_factor * spacing;
    let bs = borders::across(&sub, &patch_of, &loops, radius)?;
    progress.advance(labels.ids.len() as u64);
    progress.stage("junctions", None);
    let j = junctions::junctions(sub.points(), &bs, &labels.ids, cfg.min_run_factor * radius)?;
    let mut cycles = j.cycles;
    orient(&mut cycles, &j.edges, &labels.ids)?;
    outward(&mut cycles, &j.edges, &j.vertices, sub.points());
    progress.stage("edge curves", Some(j.edges.len() as u64));
    let fitted: Vec<Result<EdgeCurve>> = {
        use rayon::prelude::*;
        j.edges
            .par_iter()
            .map(|e| {
                let guide: Vec<Point3> = e.points[0].iter().map(|&i| sub.points()[i]).collect();
                let others: Vec<Point3> = e.points[1].iter().map(|&i| sub.points()[i]).collect();
                let r = fit_edge_curve(
                    j.vertices[e.start].point,
                    j.vertices[e.end].point,
                    &guide,
                    &others,
                    spacing,
                    radius,
                    &cfg.curves,
                );
                progress.advance(1);
                r
            })
            .collect()
    };
    let mut edges = Vec::with_capacity(fitted.len());
    for (e, f) in j.edges.iter().zip(fitted) {
        let f = f.map_err(|err| {
            let who: Vec<String> = e
                .patches
                .iter()
                .flatten()
                .map(|&p| labels.ids[p].to_string())
                .collect();
            Error::InvalidInput(format!(
                "the edge of patch(es) {}: {err}",
                who.join(" and ")
            ))
        })?;
        edges.push(Edge {
            start: e.start,
            end: e.end,
            patches: e.patches,
            curve: f.curve,
            points: e.points[0].len() + e.points[1].len(),
            max_error: f.max_error,
        });
    }
    let patches = labels
        .ids
        .iter()
        .zip(&labels.members)
        .zip(cycles)
        .map(|((&id, m), cycle)| Patch {
            id,
            points: m.clone(),
            cycle,
        })
        .collect();
    Ok(Network {
        attribute: labels.attribute,
        ignored: labels.ignored,
        spacing,
        contact_radius: radius,
        vertices: j.vertices.iter().map(|v| v.point).collect(),
        edges,
        patches,
    })
}

/// Reverses a cycle (the patch seen from its other side).
fn flip(cycle: &mut [NetUse]) {
    cycle.reverse();
    for u in cycle.iter_mut() {
        u.reversed = !u.reversed;
    }
}

/// Makes the patches' orientations agree: the two patches along an edge
/// traverse it in opposite directions (breadth-first over the edges).
fn orient(cycles: &mut [Vec<NetUse>], edges: &[junctions::NetEdge], ids: &[i64]) -> Result<()> {
    let n = cycles.len();
    let mut done = vec![false; n];
    for root in 0..n {
        if done[root] {
            continue;
        }
        done[root] = true;
        let mut queue = vec![root];
        while let Some(a) = queue.pop() {
            let uses = cycles[a].clone();
            for u in uses {
                let e = &edges[u.edge];
                let Some(b) = e.patches.iter().flatten().copied().find(|&p| p != a) else {
                    continue;
                };
                let ub = cycles[b].iter().find(|x| x.edge == u.edge).copied();
                let Some(ub) = ub else { continue };
                let agree = ub.reversed != u.reversed;
                if done[b] {
                    if !agree {
                        return Err(Error::InvalidInput(format!(
                            "patches {} and {} cannot be oriented consistently (the network is not orientable, like a Moebius strip); split a patch across the twist",
                            ids[a], ids[b]
                        )));
                    }
                } else {
                    if !agree {
                        flip(&mut cycles[b]);
                    }
                    done[b] = true;
                    queue.push(b);
                }
            }
        }
    }
    Ok(())
}

/// Turns the patches so that their border polygons enclose a positive
/// volume about the cloud's centroid (outward normals for a closed object;
/// the side away from the centroid for an open one).
fn outward(
    cycles: &mut [Vec<NetUse>],
    edges: &[junctions::NetEdge],
    vertices: &[NetVertex],
    points: &[Point3],
) {
    let c = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len().max(1) as f64;
    let mut volume = 0.0;
    for (k, cy) in cycles.iter().enumerate() {
        // the polygon of the cycle through its edges' border points
        let mut poly: Vec<Vector3> = Vec::new();
        for u in cy {
            let e = &edges[u.edge];
            let side = usize::from(e.patches[0] != Some(k));
            let mut pts: Vec<Vector3> = e.points[side]
                .iter()
                .map(|&i| points[i].coords - c)
                .collect();
            let from = vertices[if u.reversed { e.end } else { e.start }]
                .point
                .coords
                - c;
            if let (Some(a), Some(b)) = (pts.first(), pts.last()) {
                if (a - from).norm() > (b - from).norm() {
                    pts.reverse();
                }
            }
            poly.extend(pts);
        }
        if poly.len() < 3 {
            continue;
        }
        let m = poly.iter().sum::<Vector3>() / poly.len() as f64;
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            volume += m.dot(&a.cross(&b));
        }
    }
    if volume < 0.0 {
        for cy in cycles.iter_mut() {
            flip(cy);
        }
    }
}
