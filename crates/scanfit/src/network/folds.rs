//! Fold-overs of a patch's parameters (issue 16): points where the map from
//! the surface to its `(u, v)` turns over, so that the parameters of
//! neighbouring points run the wrong way round. A layout that cuts a patch
//! the surface folds back into (or a Coons patch too far from its points)
//! shows here before it shows as a bad fit.
//!
//! For each point and each pair of its nearest neighbours in the patch, the
//! triangle's orientation about the surface normal at the point,
//! `N . ((p_j - p_i) x (p_k - p_i))` with `N = S_u x S_v`, is compared with
//! its orientation in the parameter plane; a point is folded when more of
//! its well-shaped triangles (3D area at least a tenth of the largest
//! possible) disagree than agree.

use std::num::NonZeroUsize;

use rayon::prelude::*;

use crate::bspline::{BasisWorkspace, Surface};
use crate::spatial::KdTree;
use crate::{Point3, Result, Vector3};

/// Neighbours each point's triangles are made of.
const NEIGHBOURS: usize = 8;

/// The number of folded points of a patch: `points` with parameters `uv`
/// on `surface` (see the module docs).
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::network::folds::fold_overs;
/// use scanfit::Point3;
/// let k = KnotVector::uniform_clamped(1, 2)?;
/// let plane = Surface::new(k.clone(), k, vec![
///     Point3::new(0., 0., 0.), Point3::new(0., 1., 0.),
///     Point3::new(1., 0., 0.), Point3::new(1., 1., 0.),
/// ])?;
/// let pts: Vec<Point3> = (0..400).map(|i| Point3::new((i % 20) as f64 / 19.0, (i / 20) as f64 / 19.0, 0.0)).collect();
/// let uv: Vec<[f64; 2]> = pts.iter().map(|p| [p.x, p.y]).collect();
/// assert_eq!(fold_overs(&pts, &uv, &plane)?, 0);
/// // mirrored parameters fold every point
/// let flipped: Vec<[f64; 2]> = pts.iter().map(|p| [p.y, p.x]).collect();
/// assert_eq!(fold_overs(&pts, &flipped, &plane)?, 400);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn fold_overs(points: &[Point3], uv: &[[f64; 2]], surface: &Surface) -> Result<usize> {
    if points.len() < 3 {
        return Ok(0);
    }
    let tree = KdTree::new(points, "the patch points")?;
    let k = NonZeroUsize::new(NEIGHBOURS + 1).unwrap_or(NonZeroUsize::MIN);
    let (p, q) = surface.degrees();
    let folded = (0..points.len())
        .into_par_iter()
        .map_init(
            || (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1)),
            |(wu, wv), i| {
                let n: Vector3 = surface.normal(uv[i][0], uv[i][1], wu, wv);
                let nb: Vec<usize> = tree
                    .nearest_n(&points[i], k)
                    .into_iter()
                    .map(|x| x.index)
                    .filter(|&j| j != i)
                    .collect();
                let (mut agree, mut disagree) = (0usize, 0usize);
                for (a, &j) in nb.iter().enumerate() {
                    for &l in &nb[a + 1..] {
                        let (dj, dl) = (points[j] - points[i], points[l] - points[i]);
                        let o3 = n.dot(&dj.cross(&dl));
                        if o3.abs() < 0.1 * dj.norm() * dl.norm() {
                            continue;
                        }
                        let (a1, a2) = (uv[j][0] - uv[i][0], uv[j][1] - uv[i][1]);
                        let (b1, b2) = (uv[l][0] - uv[i][0], uv[l][1] - uv[i][1]);
                        let o2 = a1 * b2 - a2 * b1;
                        if o2 * o3 > 0.0 {
                            agree += 1;
                        } else if o2 * o3 < 0.0 {
                            disagree += 1;
                        }
                    }
                }
                usize::from(disagree > agree)
            },
        )
        .sum();
    Ok(folded)
}
