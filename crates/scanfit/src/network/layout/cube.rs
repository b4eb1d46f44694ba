//! The cube layout of a closed star-shaped object (issue 16): six
//! four-sided patches by central projection onto a box about the centre,
//! the cube-sphere layout (Ronchi, Iacono & Paolucci 1996, "The cubed
//! sphere"), here on the object's own bounding box so that an elongated
//! object gets patches of comparable size.
//!
//! The centre is the centroid of the points. Point `p` belongs to the face of
//! the box that the ray from the centre through `p` leaves by: the axis `i`
//! with the largest `|p_i - c_i| / h_i` (`h` the half extents of the box
//! about the centre), label `2 i` on the positive side, `2 i + 1` on the
//! negative. The cuts between patches are the planes `d_i / h_i = ± d_j / h_j`
//! through the centre; the eight box corners become the shell's corners,
//! where three patches meet.
//!
//! The layout is valid only if every ray from the centre meets the surface
//! once (star-shaped). [`cube_labels`] checks it: the directions are binned
//! on the cube sphere (about 40 points a bin) and the distances from the
//! centre in each bin sorted; a jump of more than 10 point spacings between
//! consecutive distances means two layers of surface on one ray.

use crate::{Error, Point3, PointCloud, Result, Vector3};

/// Where a ray from the centre meets the surface twice.
#[derive(Debug, Clone, PartialEq)]
pub struct DoubleHit {
    /// Unit direction of the ray.
    pub direction: Vector3,
    /// The nearer point on it.
    pub near: Point3,
    /// The farther point on it.
    pub far: Point3,
}

/// The labels of the cube layout and the box it projects on.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeLayout {
    /// Per point its face: `2 i` (+axis i) or `2 i + 1` (-axis i).
    pub labels: Vec<i64>,
    /// The centre of projection (the centroid).
    pub centre: Point3,
    /// Half extents of the box about the centre.
    pub half: Vector3,
}

/// The face of direction `d` on the box of half extents `h`, and the two
/// other coordinates scaled to `[-1, 1]`.
fn face_of(d: &Vector3, h: &Vector3) -> (usize, f64, f64) {
    let s = Vector3::new(d.x / h.x, d.y / h.y, d.z / h.z);
    let i = s.iamax();
    let m = s[i].abs().max(f64::MIN_POSITIVE);
    let label = 2 * i + usize::from(s[i] < 0.0);
    (label, s[(i + 1) % 3] / m, s[(i + 2) % 3] / m)
}

/// The cube layout of `cloud` (see the module docs). `spacing` is the
/// median point spacing (the star-shape test's scale).
///
/// Errors: fewer than 60 points, a flat object (a zero box extent), and a
/// ray meeting the surface twice, named with its direction and both points.
///
/// ```
/// use scanfit::network::layout::cube::cube_labels;
/// use scanfit::{Point3, PointCloud};
/// // a sphere from a Fibonacci lattice
/// let n = 4000;
/// let pts = (0..n).map(|i| {
///     let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
///     let a = i as f64 * 2.399963229728653;
///     let r = (1.0 - z * z).sqrt();
///     Point3::new(r * a.cos(), r * a.sin(), z)
/// }).collect();
/// let cube = cube_labels(&PointCloud::new(pts)?, 0.03)?;
/// for f in 0..6 {
///     let k = cube.labels.iter().filter(|&&l| l == f).count();
///     assert!((600..740).contains(&k), "face {f}: {k}");
/// }
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn cube_labels(cloud: &PointCloud, spacing: f64) -> Result<CubeLayout> {
    let pts = cloud.points();
    if pts.len() < 60 {
        return Err(Error::TooFewPoints {
            got: pts.len(),
            needed: 60,
            what: "the cube layout".into(),
        });
    }
    let centre = Point3::from(pts.iter().map(|p| p.coords).sum::<Vector3>() / pts.len() as f64);
    let half = pts
        .iter()
        .fold(Vector3::zeros(), |h, p| h.sup(&(p - centre).abs()));
    if half.min() <= 1e-9 * half.max() {
        return Err(Error::InvalidInput(format!(
            "the cube layout needs a closed object around its centre, but the points are flat (box half extents {:.4}, {:.4}, {:.4}); use --layout grid:RxC for a sheet",
            half.x, half.y, half.z
        )));
    }
    let bins = ((pts.len() as f64 / 6.0 / 40.0).sqrt().floor() as usize).max(2);
    let mut cells: Vec<Vec<(f64, usize)>> = vec![Vec::new(); 6 * bins * bins];
    let mut labels = Vec::with_capacity(pts.len());
    for (k, p) in pts.iter().enumerate() {
        let d = p - centre;
        let (f, a, b) = face_of(&d, &half);
        labels.push(f as i64);
        let bin = |t: f64| (((t + 1.0) / 2.0 * bins as f64) as usize).min(bins - 1);
        cells[(f * bins + bin(a)) * bins + bin(b)].push((d.norm(), k));
    }
    let jump = 10.0 * spacing;
    for cell in &mut cells {
        cell.sort_by(|x, y| x.0.total_cmp(&y.0));
        if let Some(w) = cell.windows(2).find(|w| w[1].0 - w[0].0 > jump) {
            let (near, far) = (pts[w[0].1], pts[w[1].1]);
            let direction = (far - centre).normalize();
            let hit = DoubleHit {
                direction,
                near,
                far,
            };
            return Err(not_star_shaped(&centre, &hit));
        }
    }
    Ok(CubeLayout {
        labels,
        centre,
        half,
    })
}

fn not_star_shaped(c: &Point3, h: &DoubleHit) -> Error {
    Error::InvalidInput(format!(
        "the object is not star-shaped about its centre ({:.4}, {:.4}, {:.4}): the ray towards ({:.3}, {:.3}, {:.3}) meets the surface at least twice, near ({:.4}, {:.4}, {:.4}) and again at ({:.4}, {:.4}, {:.4}); the cube layout would fold there. Use --layout revolve:SxL for an object turned about an axis, --segment for a part with sharp edges, or label the patches by hand",
        c.x, c.y, c.z, h.direction.x, h.direction.y, h.direction.z,
        h.near.x, h.near.y, h.near.z, h.far.x, h.far.y, h.far.z
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(n: usize, f: impl Fn(Point3) -> Option<Point3>) -> Vec<Point3> {
        (0..n)
            .filter_map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let a = i as f64 * 2.399_963_229_728_653;
                let r = (1.0 - z * z).sqrt();
                f(Point3::new(r * a.cos(), r * a.sin(), z))
            })
            .collect()
    }

    #[test]
    fn box_faces_follow_the_extents() {
        // an ellipsoid 3 x 1 x 1: the +-x caps are the ends beyond |x| > |y|, |z| in box units
        let pts = sphere(6000, |p| Some(Point3::new(3.0 * p.x, p.y, p.z)));
        let c = cube_labels(&PointCloud::new(pts.clone()).unwrap(), 0.05).unwrap();
        assert!((c.half.x / c.half.y - 3.0).abs() < 0.01, "{:?}", c.half);
        for (p, &l) in pts.iter().zip(&c.labels) {
            let s = [p.x / 3.0, p.y, p.z];
            let i = (0..3)
                .max_by(|&a, &b| s[a].abs().total_cmp(&s[b].abs()))
                .unwrap();
            assert_eq!(l, (2 * i + usize::from(s[i] < 0.0)) as i64);
        }
    }

    #[test]
    fn a_second_layer_is_named() {
        // a sphere of radius 1 with a shell of radius 0.5 inside, on the +x side only
        let mut pts = sphere(8000, Some);
        pts.extend(sphere(2000, |p| {
            (p.x > 0.5).then(|| Point3::from(p.coords * 0.5))
        }));
        let e = cube_labels(&PointCloud::new(pts).unwrap(), 0.02)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not star-shaped"), "{e}");
        assert!(e.contains("revolve"), "{e}");
        // the named ray points to +x
        let dir: Vec<f64> = e
            .split("the ray towards (")
            .nth(1)
            .and_then(|s| s.split(')').next())
            .unwrap()
            .split(", ")
            .map(|t| t.parse().unwrap())
            .collect();
        assert!(dir[0] > 0.4, "{e}");
    }
}
