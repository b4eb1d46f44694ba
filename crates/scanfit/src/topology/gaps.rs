//! Gaps between face sides and the shared edge curves, measured geometrically
//! (independent of how either curve is parameterized).
//!
//! For one edge, every face side that uses it is compared with the edge's
//! curve by the two-sided Hausdorff distance of the two curves, estimated from
//! dense samples (8 per knot span of either curve, at least 33) each projected
//! onto the other curve by a nearest sample followed by Newton's iteration on
//! `(C(t) - p) . C'(t) = 0` (NURBS Book §6.1, eq. 6.3). Two faces sharing
//! the edge are compared with each other the same way (`face_gap`): that is
//! the gap a CAD system sees between the patches.
//!
//! [`PatchComplex::normal_angles`] measures the other defect along a shared
//! edge: the angle between the two faces' unit normals `S_u x S_v / |.|`
//! (zero for a tangent-continuous, G1, join), at points matched by closest
//! point on the neighbour's side.

use super::{EdgeUse, PatchComplex, SideRef};
use crate::bspline::{BasisWorkspace, Curve};
use crate::{Error, Point3, Result, Vector3};

/// Measured gaps along one edge.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeGap {
    /// The edge's index.
    pub edge: usize,
    /// The face sides that use it.
    pub uses: Vec<SideRef>,
    /// Largest Hausdorff distance between the edge's curve and a face side
    /// that uses it (0 for an unused edge).
    pub curve_gap: f64,
    /// Hausdorff distance between the two face sides that share the edge (0
    /// for a border edge).
    pub face_gap: f64,
    /// The side with the largest `curve_gap`.
    pub worst_side: Option<SideRef>,
}

/// A curve with dense samples for repeated closest-point queries.
struct Probe<'c> {
    curve: &'c Curve,
    ts: Vec<f64>,
    pts: Vec<Point3>,
    ws: BasisWorkspace,
}

/// Spans of a curve's domain (distinct breakpoints minus one).
fn spans(c: &Curve) -> usize {
    c.knots().breakpoints().len().saturating_sub(1).max(1)
}

impl<'c> Probe<'c> {
    fn new(curve: &'c Curve, n: usize) -> Self {
        Self::on(curve, curve.domain(), n)
    }

    /// Samples of the piece `[a, b]` of the curve's domain only.
    fn on(curve: &'c Curve, (a, b): (f64, f64), n: usize) -> Self {
        let ts: Vec<f64> = (0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect();
        let mut pts = vec![Point3::origin(); n];
        curve.eval_many(&ts, &mut pts);
        Self {
            curve,
            ts,
            pts,
            ws: BasisWorkspace::new(curve.degree(), 2),
        }
    }

    /// `(t, distance)` of the closest point of the curve to `p`.
    fn closest(&mut self, p: &Point3) -> (f64, f64) {
        let (mut best_i, mut best_d) = (0, f64::INFINITY);
        for (i, q) in self.pts.iter().enumerate() {
            let d = (q - p).norm_squared();
            if d < best_d {
                best_d = d;
                best_i = i;
            }
        }
        let n = self.ts.len();
        let lo = self.ts[best_i.saturating_sub(1)];
        let hi = self.ts[(best_i + 1).min(n - 1)];
        let mut t = self.ts[best_i];
        let mut best_t = t;
        let mut best = best_d.sqrt();
        let mut d = [Vector3::zeros(); 3];
        for _ in 0..20 {
            self.curve.derivatives_into(t, &mut self.ws, &mut d);
            let r = d[0] - p.coords;
            let dist = r.norm();
            if dist < best {
                best = dist;
                best_t = t;
            }
            let f = r.dot(&d[1]);
            let fp = d[1].norm_squared() + r.dot(&d[2]);
            if fp.is_nan() || fp <= 0.0 {
                break;
            }
            let next = (t - f / fp).clamp(lo, hi);
            if (next - t).abs() <= 1e-15 * (hi - lo).abs().max(f64::MIN_POSITIVE) {
                break;
            }
            t = next;
        }
        let q = self.curve.point(t);
        let dist = (q - p).norm();
        if dist < best {
            best = dist;
            best_t = t;
        }
        (best_t, best)
    }
}

fn sample_count(a: &Curve, b: &Curve) -> usize {
    (8 * (spans(a) + spans(b)) + 1).clamp(33, 4097)
}

/// Two-sided Hausdorff distance of the pieces `ra` of `a` and `rb` of `b`
/// (parameter ranges), from samples.
fn hausdorff_on(a: &Curve, ra: (f64, f64), b: &Curve, rb: (f64, f64)) -> f64 {
    let n = sample_count(a, b);
    let mut pa = Probe::on(a, ra, n);
    let mut pb = Probe::on(b, rb, n);
    let ab = pa
        .pts
        .clone()
        .iter()
        .map(|p| pb.closest(p).1)
        .fold(0.0f64, f64::max);
    let ba = pb
        .pts
        .clone()
        .iter()
        .map(|p| pa.closest(p).1)
        .fold(0.0f64, f64::max);
    ab.max(ba)
}

/// Closest point of `curve` to `p`: `(parameter, distance)` (nearest of dense
/// samples, refined by Newton's iteration, NURBS Book eq. 6.3).
///
/// ```
/// use scanfit::bspline::{Curve, KnotVector};
/// use scanfit::topology::distance_to_curve;
/// use scanfit::Point3;
/// let line = Curve::new(KnotVector::uniform_clamped(1, 2).unwrap(),
///     vec![Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 0.0, 0.0)]).unwrap();
/// let (t, d) = distance_to_curve(&line, &Point3::new(0.5, 1.0, 0.0));
/// assert!((t - 0.25).abs() < 1e-12 && (d - 1.0).abs() < 1e-12);
/// ```
pub fn distance_to_curve(curve: &Curve, p: &Point3) -> (f64, f64) {
    let n = sample_count(curve, curve);
    Probe::new(curve, n).closest(p)
}

/// Where the edges of a side's `chain` meet on the side's curve `side`: the
/// parameters of the inner junction vertices (closest points, in order) and
/// their largest distance from the side. Errors when the junctions do not
/// follow each other strictly along the side.
pub(super) fn chain_junctions(
    side: &Curve,
    chain: &[EdgeUse],
    model: &PatchComplex,
    fi: usize,
    k: usize,
) -> Result<(Vec<f64>, f64)> {
    let (a, b) = side.domain();
    let mut probe = Probe::new(side, sample_count(side, side).max(16 * chain.len() + 1));
    let mut ts = Vec::with_capacity(chain.len().saturating_sub(1));
    let mut worst = 0.0f64;
    let mut last = a;
    for u in &chain[..chain.len().saturating_sub(1)] {
        let Some((_, v)) = u.oriented_vertices(&model.edges) else {
            return Err(Error::InvalidInput(format!(
                "face {fi} side {k} uses edge {}, which does not exist",
                u.edge
            )));
        };
        let p = model
            .vertices
            .get(v)
            .map(|v| v.point)
            .ok_or_else(|| Error::InvalidInput(format!("vertex {v} does not exist")))?;
        let (t, d) = probe.closest(&p);
        if !(t > last && t < b) {
            return Err(Error::InvalidInput(format!(
                "face {fi} side {k}: vertex {v}, where its edges {} and the next meet, lies at parameter {t} of the side, not after the previous junction ({last}) and before its end ({b}); list the side's edges in order along it",
                u.edge
            )));
        }
        worst = worst.max(d);
        last = t;
        ts.push(t);
    }
    Ok((ts, worst))
}

/// The parameter range on the side curve of every edge of its chain.
fn chain_params(side: &Curve, junctions: &[f64]) -> Vec<(f64, f64)> {
    let (a, b) = side.domain();
    let mut cuts = vec![a];
    cuts.extend_from_slice(junctions);
    cuts.push(b);
    cuts.windows(2).map(|w| (w[0], w[1])).collect()
}

/// Every non-degenerate side of every face: its curve and the parameter
/// range of each edge of its chain.
type SidePieces = Vec<[Option<(Curve, Vec<(f64, f64)>)>; 4]>;

impl PatchComplex {
    /// The fractions `[s0, s1]` of side `k` of face `fi` (0 at the side's
    /// start, 1 at its end, see [`super::Face::side_parameters`]) that each
    /// edge of the side's chain covers: cut where the chain's inner vertices
    /// are closest to the side. `[(0, 1)]` for a one-edge side, empty for a
    /// degenerate one.
    pub fn chain_ranges(&self, fi: usize, k: usize) -> Result<Vec<(f64, f64)>> {
        let f = self
            .faces
            .get(fi)
            .ok_or_else(|| Error::InvalidInput(format!("face {fi} does not exist")))?;
        let chain = &f.sides[k % 4];
        match chain.len() {
            0 => Ok(Vec::new()),
            1 => Ok(vec![(0.0, 1.0)]),
            _ => {
                let c = f.side_curve(k)?;
                let (a, b) = c.domain();
                let (ts, _) = chain_junctions(&c, chain, self, fi, k)?;
                Ok(chain_params(&c, &ts)
                    .iter()
                    .map(|&(s, t)| ((s - a) / (b - a), (t - a) / (b - a)))
                    .collect())
            }
        }
    }

    /// [`SidePieces`] of the whole model.
    fn side_pieces(&self) -> Result<SidePieces> {
        self.faces
            .iter()
            .enumerate()
            .map(|(fi, f)| {
                let mut out: [Option<(Curve, Vec<(f64, f64)>)>; 4] = Default::default();
                for (k, chain) in f.sides.iter().enumerate() {
                    if chain.is_empty() {
                        continue;
                    }
                    let c = f.side_curve(k)?;
                    let ranges = if chain.len() == 1 {
                        vec![c.domain()]
                    } else {
                        chain_params(&c, &chain_junctions(&c, chain, self, fi, k)?.0)
                    };
                    out[k] = Some((c, ranges));
                }
                Ok(out)
            })
            .collect()
    }

    /// Measured gaps of every edge: for each face side that uses it, the
    /// two-sided Hausdorff distance between the side (the surface's boundary
    /// iso-curve, [`super::Face::side_curve`]) and the edge's curve, and
    /// between the two sides sharing it; estimated from dense samples (8 per
    /// knot span of either curve, at least 33) projected onto the other curve
    /// by Newton's iteration (NURBS Book eq. 6.3), so independent of how the
    /// curves are parameterized. Needs [`PatchComplex::validate_structure`]
    /// to hold for the indices; an out-of-range use is skipped.
    pub fn boundary_gaps(&self) -> Result<Vec<EdgeGap>> {
        let users = self.edge_faces();
        let pieces = self.side_pieces()?;
        let mut out = Vec::with_capacity(self.edges.len());
        for (ei, e) in self.edges.iter().enumerate() {
            let uses = users.get(ei).cloned().unwrap_or_default();
            let mut sides = Vec::with_capacity(uses.len());
            for u in &uses {
                let piece = pieces.get(u.face).and_then(|p| p[u.side].as_ref());
                if let Some((c, r)) = piece {
                    if let Some(&range) = r.get(u.index) {
                        sides.push((*u, c, range));
                    }
                }
            }
            let mut curve_gap = 0.0f64;
            let mut worst_side = None;
            for &(u, c, r) in &sides {
                let g = hausdorff_on(c, r, &e.curve, e.curve.domain());
                if worst_side.is_none() || g > curve_gap || g.is_nan() {
                    curve_gap = g;
                    worst_side = Some(u);
                }
            }
            let face_gap = match sides.as_slice() {
                [(_, a, ra), (_, b, rb)] => hausdorff_on(a, *ra, b, *rb),
                _ => 0.0,
            };
            out.push(EdgeGap {
                edge: ei,
                uses,
                curve_gap,
                face_gap,
                worst_side,
            });
        }
        Ok(out)
    }

    /// For every edge shared by two faces, the largest angle in degrees
    /// between their unit normals along it (the G1 defect; `None` for a
    /// border edge). Sampled at `samples` points strictly inside the edge
    /// (at least 1), each matched to the neighbour by closest point on its
    /// side; points where either normal is undefined (a collapsed corner, a
    /// straight-angle corner) are skipped, and an edge with no defined
    /// sample is `None`.
    pub fn normal_angles(&self, samples: usize) -> Result<Vec<Option<f64>>> {
        let n = samples.max(1);
        let users = self.edge_faces();
        let pieces = self.side_pieces()?;
        let piece = |s: &SideRef| {
            pieces
                .get(s.face)
                .and_then(|p| p[s.side].as_ref())
                .and_then(|(c, r)| r.get(s.index).map(|&r| (c, r)))
        };
        let mut out = Vec::with_capacity(self.edges.len());
        for uses in users.iter() {
            let [a, b] = uses.as_slice() else {
                out.push(None);
                continue;
            };
            let (Some(fa), Some(fb)) = (self.faces.get(a.face), self.faces.get(b.face)) else {
                out.push(None);
                continue;
            };
            let (Some((ca, ra)), Some((cb, rb))) = (piece(a), piece(b)) else {
                out.push(None);
                continue;
            };
            let (t0, t1) = cb.domain();
            let (a0, a1) = ca.domain();
            let mut probe = Probe::on(cb, rb, sample_count(cb, cb));
            let (pa, qa) = fa.surface.degrees();
            let (pb, qb) = fb.surface.degrees();
            let mut wa = (BasisWorkspace::new(pa, 1), BasisWorkspace::new(qa, 1));
            let mut wb = (BasisWorkspace::new(pb, 1), BasisWorkspace::new(qb, 1));
            let mut worst: Option<f64> = None;
            for i in 0..n {
                let t = ra.0 + (ra.1 - ra.0) * (i as f64 + 0.5) / n as f64;
                let s = (t - a0) / (a1 - a0);
                let (ua, va) = fa.side_parameters(a.side, s);
                let p = fa.surface.point(ua, va);
                let (t, _) = probe.closest(&p);
                let sb = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
                let (ub, vb) = fb.side_parameters(b.side, sb);
                let na = unit_normal(&fa.surface, ua, va, &mut wa);
                let nb = unit_normal(&fb.surface, ub, vb, &mut wb);
                if let (Some(na), Some(nb)) = (na, nb) {
                    let angle = na.dot(&nb).clamp(-1.0, 1.0).acos().to_degrees();
                    worst = Some(worst.map_or(angle, |w: f64| w.max(angle)));
                }
            }
            out.push(worst);
        }
        Ok(out)
    }

    /// Largest gap over all edges: between a face side and its edge curve, or
    /// between the two faces sharing an edge.
    pub fn max_boundary_gap(&self) -> Result<f64> {
        Ok(self
            .boundary_gaps()?
            .iter()
            .map(|g| g.curve_gap.max(g.face_gap))
            .fold(0.0f64, f64::max))
    }
}

/// `S_u x S_v / |S_u x S_v|`, or `None` where the normal is undefined (the
/// cross product vanishes relative to `|S_u| |S_v|`).
fn unit_normal(
    s: &crate::bspline::Surface,
    u: f64,
    v: f64,
    ws: &mut (BasisWorkspace, BasisWorkspace),
) -> Option<Vector3> {
    let mut d = [Vector3::zeros(); 4];
    s.derivatives_into(u, v, &mut ws.0, &mut ws.1, 1, &mut d);
    // d[1] = S_v, d[2] = S_u
    let n = d[2].cross(&d[1]);
    let len = n.norm();
    let scale = d[2].norm() * d[1].norm();
    (len > 1e-9 * scale && len.is_finite()).then(|| n / len)
}
