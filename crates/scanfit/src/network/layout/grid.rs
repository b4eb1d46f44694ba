//! The grid layout of a sheet (issue 16): one four-sided region cut along
//! iso-parameter lines of its Coons base surface into `R x C` patches, for
//! more detail per control point (a face scan, a car panel).
//!
//! The base is the Coons paper's ([COONS19] §II, [PDE23] §4.1-4.3, by
//! [`coons_from_cloud`]): the sheet's alpha-shape boundary loop, its four
//! corners (smallest turning angle, [COONS19] eqs. 10-12), one B-spline per
//! side and the bilinearly blended Coons patch on them (eq. 16). Every
//! point's `(u, v)` on it comes from the Coons paper's nearest grid vertex
//! and iteration (eqs. 17-22, [`coons_parameters`]). Point `(u, v)` goes to
//! row `floor(u R)`, column `floor(v C)`, label `row C + column`: the cuts
//! are the iso-lines `u = i / R` and `v = j / C` of the base.
//!
//! The layout is valid only for a sheet with one boundary of four clear
//! corners. [`grid_labels`] refuses a boundary whose corners are not clearly
//! corners (a round outline: the Coons base check), a sheet with a hole
//! (more than one boundary loop, named with where the hole is), and a closed
//! or folded object, which the base maps twice onto the same parameters:
//! the points' signed offsets along the base normal, binned in `(u, v)`
//! (about 40 points a bin) and sorted, jump by more than 10 spacings.

use crate::base::{coons_from_cloud, coons_parameters, CoonsFromCloudConfig, CoonsParamConfig};
use crate::bspline::BasisWorkspace;
use crate::{Error, Point3, PointCloud, Result, Vector3};

use super::revolve::MIN_PATCH_POINTS;

/// The labels of the grid layout and the Coons base they come from.
#[derive(Debug, Clone, PartialEq)]
pub struct GridLayout {
    /// Per point its patch, `row C + column`.
    pub labels: Vec<i64>,
    /// Per point its `(u, v)` on the Coons base.
    pub uv: Vec<[f64; 2]>,
    /// The base's four corners (where the sheet's boundary turns most).
    pub corners: [Point3; 4],
    /// The cuts along `u`, `u_i = i / R`: row `r` is `u_r <= u < u_(r+1)`.
    pub row_cuts: Vec<f64>,
    /// The cuts along `v`, `v_j = j / C`.
    pub col_cuts: Vec<f64>,
    /// The lengths of the base along `u` and `v` (the means of the corner
    /// distances of opposite sides), for densities per unit length.
    pub side_lengths: (f64, f64),
}

/// The grid layout of `cloud` with `rows x cols` patches (see the module
/// docs). `spacing` is the median point spacing.
///
/// Errors: fewer than two patches; what [`coons_from_cloud`] refuses (no
/// four clear corners); a hole; two layers over one parameter cell; a
/// patch with fewer than [`MIN_PATCH_POINTS`] points.
///
/// ```
/// use scanfit::network::layout::grid::grid_labels;
/// use scanfit::{Point3, PointCloud};
/// // a gently curved 2 x 1 sheet
/// let mut pts = Vec::new();
/// for i in 0..=80 {
///     for j in 0..=40 {
///         let (x, y) = (i as f64 / 40.0, j as f64 / 40.0);
///         pts.push(Point3::new(x, y, 0.1 * (x * y).sin()));
///     }
/// }
/// let g = grid_labels(&PointCloud::new(pts)?, 2, 3, 0.025)?;
/// assert_eq!(g.labels.iter().max(), Some(&5));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn grid_labels(
    cloud: &PointCloud,
    rows: usize,
    cols: usize,
    spacing: f64,
) -> Result<GridLayout> {
    if rows == 0 || cols == 0 || rows * cols < 2 || rows > 1000 || cols > 1000 {
        return Err(Error::InvalidInput(format!(
            "grid:{rows}x{cols}: give 1 to 1000 rows and columns and at least two patches, e.g. grid:3x3 (one patch is `scanfit coons`)"
        )));
    }
    let pts = cloud.points();
    let base = coons_from_cloud(pts, &CoonsFromCloudConfig::default()).map_err(|e| {
        Error::InvalidInput(format!(
            "the grid layout needs a sheet with four clear corners, and this one's Coons base fails: {e}. For a closed object use --layout cube or --layout revolve:SxL; for a sheet with a round outline, label the patches by hand"
        ))
    })?;
    if base.boundary.loops.len() > 1 {
        return Err(hole(&base.boundary, pts));
    }
    let surface = base.patch.to_bspline()?;
    let par = coons_parameters(&surface, pts, &CoonsParamConfig::default())?;
    one_layer(pts, &par.uv, &surface, spacing)?;
    let uniform = |n: usize| (0..=n).map(|i| i as f64 / n as f64).collect::<Vec<f64>>();
    let (row_cuts, col_cuts) = (uniform(rows), uniform(cols));
    let labels: Vec<i64> = par
        .uv
        .iter()
        .map(|&[u, v]| {
            let r = ((u * rows as f64) as usize).min(rows - 1);
            let c = ((v * cols as f64) as usize).min(cols - 1);
            (r * cols + c) as i64
        })
        .collect();
    let mut count = vec![0usize; rows * cols];
    for &l in &labels {
        count[l as usize] += 1;
    }
    if let Some((k, &c)) = count
        .iter()
        .enumerate()
        .find(|(_, &c)| c < MIN_PATCH_POINTS)
    {
        return Err(Error::InvalidInput(format!(
            "grid:{rows}x{cols} leaves patch {k} (row {}, column {}) only {c} points, fewer than the {MIN_PATCH_POINTS} a patch needs; use fewer rows or columns",
            k / cols,
            k % cols
        )));
    }
    let c = base.patch.corners();
    let side_lengths = (
        0.5 * ((c[1] - c[0]).norm() + (c[2] - c[3]).norm()),
        0.5 * ((c[3] - c[0]).norm() + (c[2] - c[1]).norm()),
    );
    Ok(GridLayout {
        labels,
        uv: par.uv,
        corners: c,
        row_cuts,
        col_cuts,
        side_lengths,
    })
}

/// The error for a sheet with a hole: where the largest hole is.
fn hole(b: &crate::cloud::boundary::Boundary, pts: &[Point3]) -> Error {
    let k = (0..b.loops.len())
        .filter(|&k| k != b.outer)
        .max_by(|&x, &y| b.areas[x].abs().total_cmp(&b.areas[y].abs()))
        .unwrap_or(0);
    let l = &b.loops[k];
    let c = l.iter().map(|&i| pts[i].coords).sum::<Vector3>() / l.len().max(1) as f64;
    Error::InvalidInput(format!(
        "the grid layout needs a sheet with one boundary (four sides), but this one has {} hole(s); the largest, about {:.4} across, is around ({:.4}, {:.4}, {:.4}). Fill the hole, or label patches around it by hand",
        b.loops.len() - 1,
        2.0 * (b.areas[k].abs() / std::f64::consts::PI).sqrt(),
        c.x,
        c.y,
        c.z
    ))
}

/// Refuses two layers of points over one parameter cell (see the module docs).
fn one_layer(
    pts: &[Point3],
    uv: &[[f64; 2]],
    surface: &crate::bspline::Surface,
    spacing: f64,
) -> Result<()> {
    let bins = ((pts.len() as f64 / 40.0).sqrt().floor() as usize).max(1);
    let (p, q) = surface.degrees();
    let (mut wu, mut wv) = (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1));
    let mut cells: Vec<Vec<(f64, usize)>> = vec![Vec::new(); bins * bins];
    for (k, (pt, &[u, v])) in pts.iter().zip(uv).enumerate() {
        let n = surface.normal(u, v, &mut wu, &mut wv);
        let offset = (pt - surface.point(u, v)).dot(&n);
        let bin = |t: f64| ((t * bins as f64) as usize).min(bins - 1);
        cells[bin(u) * bins + bin(v)].push((offset, k));
    }
    let jump = 10.0 * spacing;
    for cell in &mut cells {
        cell.sort_by(|x, y| x.0.total_cmp(&y.0));
        if let Some(w) = cell.windows(2).find(|w| w[1].0 - w[0].0 > jump) {
            let (a, b) = (pts[w[0].1], pts[w[1].1]);
            return Err(Error::InvalidInput(format!(
                "the grid layout needs a sheet, but its Coons base maps two layers of surface onto the same parameters: ({:.4}, {:.4}, {:.4}) and ({:.4}, {:.4}, {:.4}), {:.4} apart across the base (a closed or folded object). Use --layout cube or --layout revolve:SxL for a closed object, or label the patches by hand",
                a.x, a.y, a.z, b.x, b.y, b.z,
                w[1].0 - w[0].0
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sheet(n: usize) -> Vec<Point3> {
        let mut pts = Vec::new();
        for i in 0..=2 * n {
            for j in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                pts.push(Point3::new(x, y, 0.2 * (x * y).sin()));
            }
        }
        pts
    }

    #[test]
    fn cuts_are_iso_lines_of_the_base() {
        // on a sheet over a rectangle the Coons base is (nearly) the sheet
        // itself: rows and columns are equal fractions of the sides
        let pts = sheet(60);
        let g = grid_labels(&PointCloud::new(pts.clone()).unwrap(), 3, 2, 1.0 / 60.0).unwrap();
        let mut count = [0usize; 6];
        for &l in &g.labels {
            count[l as usize] += 1;
        }
        // 121 x 61 points; each patch a sixth of the area, the shared lines split by rounding
        let n = pts.len() as f64 / 6.0;
        assert!(
            count.iter().all(|&c| (c as f64 - n).abs() < 0.06 * n),
            "{count:?}"
        );
        // the two long sides (x from 0 to 2) carry the rows or the columns
        let far = |a: usize, b: usize| {
            let pa: Vec<&Point3> = pts
                .iter()
                .zip(&g.labels)
                .filter(|(_, &l)| l as usize == a)
                .map(|x| x.0)
                .collect();
            let pb: Vec<&Point3> = pts
                .iter()
                .zip(&g.labels)
                .filter(|(_, &l)| l as usize == b)
                .map(|x| x.0)
                .collect();
            let ca = pa.iter().map(|p| p.coords).sum::<Vector3>() / pa.len() as f64;
            let cb = pb.iter().map(|p| p.coords).sum::<Vector3>() / pb.len() as f64;
            (ca - cb).norm()
        };
        // neighbours along a row are a column width apart, never the whole sheet
        assert!(far(0, 1) < 1.1 && far(0, 5) > 1.0);
    }

    #[test]
    fn a_hole_is_named() {
        let pts: Vec<Point3> = sheet(60)
            .into_iter()
            .filter(|p| (p.x - 1.0).hypot(p.y - 0.5) > 0.2)
            .collect();
        let e = grid_labels(&PointCloud::new(pts).unwrap(), 3, 3, 1.0 / 60.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 hole(s)"), "{e}");
        // the hole's centre (1, 0.5, ~0.1)
        assert!(
            e.contains("(1.0000, 0.5000") || e.contains("(0.9999") || e.contains("(1.000"),
            "{e}"
        );
    }

    #[test]
    fn one_patch_is_not_a_grid() {
        let e = grid_labels(&PointCloud::new(sheet(20)).unwrap(), 1, 1, 0.05).unwrap_err();
        assert!(e.to_string().contains("at least two patches"), "{e}");
    }
}
