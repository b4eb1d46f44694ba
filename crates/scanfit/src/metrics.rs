//! Error and parameterization measures of fitted surfaces.
//!
//! * [`ErrorStats`] of `|P_i - S(u_i, v_i)|` at the points' parameters: mean and
//!   maximum are the PDE paper's eq. 15, plus RMSE;
//! * true orthogonal distances through point inversion ([`orthogonal_errors`]);
//! * the MBA paper's eq. 17 ([`grid_rmse`]): RMSE over surface grid points of
//!   the distance to the nearest input point;
//! * parameterization quality ([`parameterization_quality`]): fold-overs
//!   (triangles of the Delaunay triangulation of the parameters whose
//!   orientation flips on the surface) and stretch (Sander et al. 2001) in
//!   the surface's tangent plane.

use rayon::prelude::*;
use spade::{DelaunayTriangulation, HasPosition, Triangulation};

use crate::bspline::{BasisWorkspace, Surface};
use crate::project::{Inversion, SurfaceInverter};
use crate::{Error, Point3, PointCloud, Result, Vector3};

/// Mean, maximum and RMSE of a set of distances.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorStats {
    /// Number of distances.
    pub count: usize,
    /// Mean (eq. 15, `Err_Mean`).
    pub mean: f64,
    /// Maximum (eq. 15, `Err_Max`).
    pub max: f64,
    /// Index of the maximum.
    pub max_index: usize,
    /// Root mean square.
    pub rmse: f64,
}

impl ErrorStats {
    /// Statistics of `d`.
    pub fn of(d: &[f64]) -> Self {
        let (mut sum, mut sum2, mut max, mut max_index) = (0.0, 0.0, 0.0f64, 0);
        for (i, &x) in d.iter().enumerate() {
            sum += x;
            sum2 += x * x;
            if x > max {
                max = x;
                max_index = i;
            }
        }
        let n = d.len().max(1) as f64;
        Self {
            count: d.len(),
            mean: sum / n,
            max,
            max_index,
            rmse: (sum2 / n).sqrt(),
        }
    }
}

/// `|P_i - S(u_i, v_i)|` for every point (in parallel).
pub fn parametric_distances(surface: &Surface, points: &[Point3], uv: &[[f64; 2]]) -> Vec<f64> {
    points
        .par_iter()
        .zip(uv.par_iter())
        .map(|(p, t)| (surface.point(t[0], t[1]) - p).norm())
        .collect()
}

/// Orthogonal distances by point inversion, with the projections.
pub fn orthogonal_errors(
    inverter: &SurfaceInverter,
    points: &[Point3],
) -> (ErrorStats, Vec<Inversion>) {
    let inv = inverter.invert_all(points);
    let d: Vec<f64> = inv.iter().map(|r| r.distance).collect();
    (ErrorStats::of(&d), inv)
}

/// The MBA paper's eq. 17: `sqrt(sum_i min_j |G_i - P_j|^2 / n_g)` over the
/// surface points `G_i` on a parameter grid; by default (`grid = None`) the grid
/// of the surface's knot lines, as in the paper (`u_i = s_{i+3}`), otherwise
/// `(nu + 1) x (nv + 1)` equally spaced parameters.
pub fn grid_rmse(
    surface: &Surface,
    points: &[Point3],
    grid: Option<(usize, usize)>,
) -> Result<f64> {
    if points.is_empty() {
        return Err(Error::InvalidInput(
            "no input points for the grid RMSE".into(),
        ));
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (us, vs): (Vec<f64>, Vec<f64>) = match grid {
        None => (
            surface.knots_u().breakpoints(),
            surface.knots_v().breakpoints(),
        ),
        Some((nu, nv)) => (
            (0..=nu.max(1))
                .map(|i| u0 + (u1 - u0) * i as f64 / nu.max(1) as f64)
                .collect(),
            (0..=nv.max(1))
                .map(|j| v0 + (v1 - v0) * j as f64 / nv.max(1) as f64)
                .collect(),
        ),
    };
    let g: Vec<Point3> = us
        .iter()
        .flat_map(|&u| vs.iter().map(move |&v| (u, v)))
        .map(|(u, v)| surface.point(u, v))
        .collect();
    rmse_to_cloud(&PointCloud::new(points.to_vec())?, &g)
}

/// The MBA paper's eq. 17 for given grid points: the RMSE over `grid` of the
/// distance from each grid point to its nearest point of `cloud` (the
/// cloud's KD-tree, built once, serves repeated calls).
pub fn rmse_to_cloud(cloud: &PointCloud, grid: &[Point3]) -> Result<f64> {
    if grid.is_empty() {
        return Err(Error::InvalidInput(
            "no grid points for the grid RMSE".into(),
        ));
    }
    let d = cloud.nearest_batch(grid)?;
    let sum: f64 = d.iter().map(|n| n.distance * n.distance).sum();
    Ok((sum / grid.len() as f64).sqrt())
}

/// Distance from each of `queries` to the nearest of `points` (KD-tree, in
/// parallel): the deviation of a surface's sample points (mesh vertices, grid
/// points) from the data.
pub fn nearest_distances(points: &[Point3], queries: &[Point3]) -> Result<Vec<f64>> {
    Ok(nearest_points(points, queries)?
        .into_iter()
        .map(|(_, d)| d)
        .collect())
}

/// Index of and distance to the nearest of `points` for each of `queries`.
pub fn nearest_points(points: &[Point3], queries: &[Point3]) -> Result<Vec<(usize, f64)>> {
    if points.is_empty() {
        return Err(Error::InvalidInput(
            "no points to measure distances to".into(),
        ));
    }
    Ok(PointCloud::new(points.to_vec())?
        .nearest_batch(queries)?
        .into_iter()
        .map(|n| (n.index, n.distance))
        .collect())
}

/// Quality of a parameterization of scattered points on a surface.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ParamQuality {
    /// Triangles of the Delaunay triangulation of the parameters (without the
    /// slivers along its hull, whose longest edge exceeds 4x the median).
    pub triangles: usize,
    /// Triangles whose orientation on the surface (data points, signed by the
    /// surface normal) is opposite to their orientation in `(u, v)`, among
    /// all but the slivers along the border (see `l2_stretch`): such a
    /// sliver joins three nearly collinear outline points, and its sign is
    /// round-off (a regular 30 x 30 grid of a bump, projected on its
    /// best-fit plane, had 16 of them "folded").
    pub fold_overs: usize,
    /// Area-weighted L2 stretch of the map `(u, v) -> P` (Sander et al. 2001),
    /// normalised so that a map uniform up to scale gives 1, with each
    /// triangle's map taken into the surface's tangent plane at its centroid
    /// parameters (the points' offsets along the normal projected away; so
    /// are the areas and the two measures below). The offsets along the
    /// normal are the data's noise, the fit's error: left in, they made the
    /// measure a property of the noise and the density, not of the
    /// parameters (on the turntable's blob, noise 0.4 point spacings, 1.73
    /// over all 10^6 points, 1.15 over a quarter of them, 1.07 over a
    /// sixteenth; in the tangent plane 1.056, 1.055, 1.055, the surface's own
    /// map 1.055), and carried by the narrowest triangles (the top 0.1% of
    /// them held 40% of the sum), which no sample can estimate. This and the
    /// two measures below leave out the slivers along the border of the
    /// triangulation (an angle over 150 degrees opposite a border edge:
    /// nearly collinear outline points, not surface; see `inner_faces`).
    pub l2_stretch: f64,
    /// Largest ratio of the singular values of a triangle's map (anisotropy).
    pub max_anisotropy: f64,
    /// 5th, 50th and 95th percentile of the triangles' area ratio
    /// (area in the tangent plane / parameter area, normalised by the
    /// global ratio).
    pub area_ratio_percentiles: [f64; 3],
}

#[derive(Clone, Copy)]
struct Vertex {
    pos: spade::Point2<f64>,
    index: usize,
}

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> spade::Point2<f64> {
        self.pos
    }
}

/// Fold-overs and stretch of the parameterization `uv` of `points` on `surface`.
pub fn parameterization_quality(
    surface: &Surface,
    points: &[Point3],
    uv: &[[f64; 2]],
) -> Result<ParamQuality> {
    parameterization_quality_where(surface, points, uv, |_| true)
}

/// [`parameterization_quality`] over the Delaunay triangles of `uv` that
/// `keep` accepts (given the triangle's three parameter pairs): the sampled
/// measure keeps those of a cluster sample that are triangles of the whole
/// set too ([`crate::sampling::CellSample::keeps_triangle`]).
pub(crate) fn parameterization_quality_where(
    surface: &Surface,
    points: &[Point3],
    uv: &[[f64; 2]],
    keep: impl Fn([[f64; 2]; 3]) -> bool,
) -> Result<ParamQuality> {
    if points.len() != uv.len() {
        return Err(Error::InvalidInput(format!(
            "{} points but {} parameter pairs",
            points.len(),
            uv.len()
        )));
    }
    let verts: Vec<Vertex> = uv
        .iter()
        .enumerate()
        .map(|(index, t)| Vertex {
            pos: spade::Point2::new(t[0], t[1]),
            index,
        })
        .collect();
    let tri: DelaunayTriangulation<Vertex> = DelaunayTriangulation::bulk_load(verts)
        .map_err(|e| Error::InvalidInput(format!("cannot triangulate the parameters: {e:?}")))?;
    let all: Vec<[usize; 3]> = tri
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.data().index))
        .filter(|f| keep(f.map(|i| uv[i])))
        .collect();
    drop(tri);
    // Triangles with an edge longer than 4x the median edge are slivers along
    // the convex hull of the parameters (or across holes): artefacts of
    // triangulating a point set, not part of the parameterization.
    let edge = |a: usize, b: usize| (uv[a][0] - uv[b][0]).hypot(uv[a][1] - uv[b][1]);
    let longest = |f: &[usize; 3]| edge(f[0], f[1]).max(edge(f[1], f[2])).max(edge(f[2], f[0]));
    let mut lengths: Vec<f64> = all.iter().map(longest).collect();
    lengths.sort_by(f64::total_cmp);
    let limit = 4.0
        * lengths
            .get(lengths.len() / 2)
            .copied()
            .unwrap_or(f64::INFINITY);
    let faces: Vec<[usize; 3]> = all.into_iter().filter(|f| longest(f) <= limit).collect();
    let inner = inner_faces(&faces, uv);
    let (p, q) = surface.degrees();
    // per triangle: (folded, 3D area, uv area, L2^2, anisotropy)
    let per: Vec<(bool, f64, f64, f64, f64)> = faces
        .par_iter()
        .map_init(
            || (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1)),
            |(wu, wv), f| {
                let [a, b, c] = *f;
                let (ta, tb, tc) = (uv[a], uv[b], uv[c]);
                let area_uv =
                    0.5 * ((tb[0] - ta[0]) * (tc[1] - ta[1]) - (tc[0] - ta[0]) * (tb[1] - ta[1]));
                let cross = (points[b] - points[a]).cross(&(points[c] - points[a]));
                let cu = (ta[0] + tb[0] + tc[0]) / 3.0;
                let cv = (ta[1] + tb[1] + tc[1]) / 3.0;
                let n = surface.normal(cu, cv, wu, wv);
                let folded = area_uv > 0.0 && cross.dot(&n) < 0.0;
                // the map into the tangent plane at the centroid: the
                // points' offsets along the normal (noise, the fit's
                // error) are not stretch (see `ParamQuality::l2_stretch`);
                // where the surface has no normal (a pole), the map into space
                let has_normal = n.norm_squared() > 0.5;
                let tangent = |x: Vector3| if has_normal { x - n * x.dot(&n) } else { x };
                let area3 = 0.5
                    * if has_normal {
                        cross.dot(&n).abs()
                    } else {
                        cross.norm()
                    };
                // Sander et al.: partial derivatives of the affine map (s, t) -> q
                if area_uv <= 0.0 || area3 <= 0.0 {
                    return (folded, area3, area_uv.max(0.0), 0.0, 1.0);
                }
                let ss = tangent(
                    (points[a].coords * (tb[1] - tc[1])
                        + points[b].coords * (tc[1] - ta[1])
                        + points[c].coords * (ta[1] - tb[1]))
                        / (2.0 * area_uv),
                );
                let st = tangent(
                    (points[a].coords * (tc[0] - tb[0])
                        + points[b].coords * (ta[0] - tc[0])
                        + points[c].coords * (tb[0] - ta[0]))
                        / (2.0 * area_uv),
                );
                let (aa, bb, cc) = (ss.dot(&ss), ss.dot(&st), st.dot(&st));
                let root = ((aa - cc) * (aa - cc) + 4.0 * bb * bb).sqrt();
                let smax = (0.5 * (aa + cc + root)).sqrt();
                // smax * smin is the area ratio area3 / area_uv (both > 0
                // here), which gives smin without the cancellation of
                // (aa + cc - root): a sliver is a large but finite ratio
                let smin = area3 / area_uv / smax;
                let aniso = (smax / smin).max(1.0);
                (folded, area3, area_uv, 0.5 * (aa + cc), aniso)
            },
        )
        .collect();
    Ok(q_from(per, &inner, faces.len()))
}

/// The summary of the per-triangle `(folded, 3D area, uv area, L2^2,
/// anisotropy)` of `count` triangles: the fold-overs and the stretch
/// measures over those `inner` marks.
fn q_from(per: Vec<(bool, f64, f64, f64, f64)>, inner: &[bool], count: usize) -> ParamQuality {
    let folds = per
        .iter()
        .zip(inner)
        .filter(|(t, &keep)| t.0 && keep)
        .count();
    let per: Vec<_> = per
        .into_iter()
        .zip(inner)
        .filter_map(|(t, &keep)| keep.then_some(t))
        .collect();
    let total3: f64 = per.iter().map(|t| t.1).sum();
    let total_uv: f64 = per.iter().map(|t| t.2).sum();
    let mut q = ParamQuality {
        triangles: count,
        fold_overs: folds,
        ..Default::default()
    };
    if total3 > 0.0 && total_uv > 0.0 {
        let l2: f64 = per.iter().map(|t| t.3 * t.1).sum::<f64>() / total3;
        q.l2_stretch = (l2 * total_uv / total3).sqrt();
        q.max_anisotropy = per
            .iter()
            .filter(|t| t.2 > 0.0)
            .map(|t| t.4)
            .fold(1.0, f64::max);
        let global = total3 / total_uv;
        let mut ratios: Vec<f64> = per
            .iter()
            .filter(|t| t.2 > 0.0)
            .map(|t| t.1 / t.2 / global)
            .collect();
        ratios.sort_by(f64::total_cmp);
        if !ratios.is_empty() {
            let pick = |f: f64| ratios[((ratios.len() - 1) as f64 * f).round() as usize];
            q.area_ratio_percentiles = [pick(0.05), pick(0.5), pick(0.95)];
        }
    }
    q
}

/// Largest angle of a triangle, opposite an edge of the triangulation's
/// border, above which [`inner_faces`] peels it off: 150 degrees.
const BORDER_SLIVER_COS: f64 = -0.866_025_403_784_438_6;

/// Which of `faces` (triangles of the Delaunay triangulation of `uv`) the
/// stretch measures use: all but the slivers along the border, peeled off
/// layer by layer. A border triangle whose angle opposite its border edge
/// exceeds 150 degrees joins three nearly collinear points of the outline
/// (on a grid clipped to a disc, exactly collinear up to round-off): a
/// triangle of the convex hull, not of the surface, whose parameter area is
/// a sliver of its 3D area, so it would make the L2 stretch (which divides
/// by the parameter area, Sander et al. 2001 eq. 3) as large as 1e11.
/// Interior triangles, however thin (scan lines), are kept: their shape is
/// the data's. The rule is relative to each triangle's own edges, so it does
/// not depend on the data's density or units.
fn inner_faces(faces: &[[usize; 3]], uv: &[[f64; 2]]) -> Vec<bool> {
    use std::collections::HashMap;
    let key = |a: usize, b: usize| (a.min(b), a.max(b));
    let mut uses: HashMap<(usize, usize), u32> = HashMap::with_capacity(3 * faces.len());
    for f in faces {
        for k in 0..3 {
            *uses.entry(key(f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    // the cosine of the angle at c, opposite the edge (a, b)
    let cos_at = |a: usize, b: usize, c: usize| {
        let (x, y) = (
            [uv[a][0] - uv[c][0], uv[a][1] - uv[c][1]],
            [uv[b][0] - uv[c][0], uv[b][1] - uv[c][1]],
        );
        let n = x[0].hypot(x[1]) * y[0].hypot(y[1]);
        if n > 0.0 {
            (x[0] * y[0] + x[1] * y[1]) / n
        } else {
            1.0
        }
    };
    let mut keep = vec![true; faces.len()];
    loop {
        let mut peeled = Vec::new();
        for (i, f) in faces.iter().enumerate().filter(|(i, _)| keep[*i]) {
            let sliver = (0..3).any(|k| {
                let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
                uses[&key(a, b)] == 1 && cos_at(a, b, c) < BORDER_SLIVER_COS
            });
            if sliver {
                peeled.push(i);
            }
        }
        if peeled.is_empty() {
            return keep;
        }
        for i in peeled {
            keep[i] = false;
            let f = faces[i];
            for k in 0..3 {
                if let Some(n) = uses.get_mut(&key(f[k], f[(k + 1) % 3])) {
                    *n -= 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::KnotVector;

    fn plane() -> Surface {
        let ku = KnotVector::uniform_clamped(1, 2).unwrap();
        let kv = KnotVector::uniform_clamped(1, 2).unwrap();
        let c = vec![
            Point3::new(0., 0., 0.),
            Point3::new(0., 2., 0.),
            Point3::new(4., 0., 0.),
            Point3::new(4., 2., 0.),
        ];
        Surface::new(ku, kv, c).unwrap()
    }

    fn grid_uv(n: usize) -> Vec<[f64; 2]> {
        (0..n * n)
            .map(|k| {
                [
                    ((k % n) as f64 + 0.3 * ((k * 7) % 5) as f64 / 5.0) / n as f64,
                    ((k / n) as f64 + 0.5) / n as f64,
                ]
            })
            .collect()
    }

    #[test]
    fn exact_parameterization_has_no_fold_and_unit_stretch() {
        let s = plane();
        let uv = grid_uv(20);
        let pts: Vec<Point3> = uv.iter().map(|t| s.point(t[0], t[1])).collect();
        let q = parameterization_quality(&s, &pts, &uv).unwrap();
        assert_eq!(q.fold_overs, 0);
        assert!(q.triangles > 600);
        // an affine map with singular values 4 and 2: normalised L2 stretch = sqrt(10/8)
        assert!(
            (q.l2_stretch - (10.0f64 / 8.0).sqrt()).abs() < 1e-9,
            "{}",
            q.l2_stretch
        );
        assert!((q.max_anisotropy - 2.0).abs() < 1e-9);
        for r in q.area_ratio_percentiles {
            assert!((r - 1.0).abs() < 1e-9);
        }
        let e = ErrorStats::of(&parametric_distances(&s, &pts, &uv));
        assert!(e.max < 1e-15);
    }

    #[test]
    fn swapped_parameters_fold_over() {
        let s = plane();
        let mut uv = grid_uv(10);
        let pts: Vec<Point3> = uv.iter().map(|t| s.point(t[0], t[1])).collect();
        // swap the parameters of two neighbouring points: their triangles flip
        uv.swap(44, 45);
        let q = parameterization_quality(&s, &pts, &uv).unwrap();
        assert!(q.fold_overs >= 2, "{}", q.fold_overs);
    }

    #[test]
    fn grid_rmse_of_points_on_the_grid_is_zero() {
        let s = plane();
        let mut pts = Vec::new();
        for i in 0..=10 {
            for j in 0..=10 {
                pts.push(s.point(i as f64 / 10.0, j as f64 / 10.0));
            }
        }
        assert!(grid_rmse(&s, &pts, Some((10, 10))).unwrap() < 1e-15);
        // a finer grid sees the gaps: the midpoint of a cell is 0.5*sqrt(0.4^2+0.2^2) away
        let r = grid_rmse(&s, &pts, Some((20, 20))).unwrap();
        assert!(r > 0.05 && r < 0.2, "{r}");
        // stats
        let e = ErrorStats::of(&[3.0, 4.0]);
        assert_eq!((e.mean, e.max, e.max_index), (3.5, 4.0, 1));
        assert!((e.rmse - 12.5f64.sqrt()).abs() < 1e-15);
    }
}
