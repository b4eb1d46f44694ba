//! The revolve layout of a cylinder-like object (issue 16): `S` sectors x
//! `L` bands about its axis, and a closed end as `S` three-sided cap
//! patches meeting at the pole (the PDE paper's pot, Fig. 9 of [PDE23]: an
//! open-topped pot as `revolve:4x2` is its 12 subsets, 8 four-sided side
//! patches and 4 three-sided bottom patches).
//!
//! The axis, the centre and the angle about the axis are the virtual
//! turntable's ([TURN17] §3.2, [`CylinderFrame`]): the cloud's principal axis
//! unless one is given; the angle `atan2(x, z)` in the turntable frame. Which
//! ends are closed is decided from the data as the turntable decides it
//! ([`end_shapes`], with the turntable's layer margin): a closed end has
//! points near the axis, an open end (a rim) has none.
//!
//! * Sectors: `S` equal angle ranges, the first starting at angle `-pi`.
//! * Caps: at a closed end, the cap is the region around the pole where the
//!   surface faces along the axis. From the end inwards the points are cut
//!   into slices (2 spacings thick, at least 1/200 of the height); the cap
//!   reaches up to the last slice in which most points have a normal within
//!   45 degrees of the axis, before three slices in a row in which they do
//!   not (a bump, or an empty slice at the pole, does not end the cap; a
//!   flat bottom: the disk; a
//!   dome or a pole of an egg: the part flatter than 45 degrees). A point
//!   below that height whose normal is more than 60 degrees from the axis
//!   (`|n . a| < 0.5`) is a wall point and stays in the bands, so the cut
//!   follows the crease of a flat bottom exactly. When no slice faces the
//!   axis (a pointed end), the cap is the end `1 / (2 L + 4)` of the
//!   height. A cap patch is the cap's part of a sector: three-sided, its
//!   apex the pole, where all `S` cap patches meet.
//! * Bands: `L` equal height ranges between the caps (or the open ends).
//!
//! Labels: band `b`, sector `s` is `b S + s`; the low cap's sector `s` is
//! `L S + s`, then the high cap's (`L S + s`, or `L S + S + s` after a low
//! cap).
//!
//! The layout is valid only for an object around its axis. [`revolve_labels`]
//! refuses (naming where) points that do not go all the way around the axis
//! (no axis: a sheet, or the wrong axis), and two layers of surface on one
//! ray from the axis (a handle, an inner wall), found as the cube layout
//! finds them: bins of about 40 points in angle and height, the distances
//! from the axis of the wall points in each (normal more than 60 degrees
//! from the axis) sorted, a jump of more than 10 spacings.

use crate::base::turntable::{end_shapes, AxisChoice, CylinderFrame, EndShape, LayerConfig};
use crate::cloud::normals::{estimate_normals, NormalsConfig, Orientation};
use crate::{Error, PointCloud, Result};
use std::f64::consts::PI;

/// Fewest points a patch of a layout may have (the patch network's minimum).
pub const MIN_PATCH_POINTS: usize = 50;

/// The labels of the revolve layout and what it found.
#[derive(Debug, Clone, PartialEq)]
pub struct RevolveLayout {
    /// Per point its patch (see the module docs for the numbering).
    pub labels: Vec<i64>,
    /// The turntable frame: axis, centre, extent.
    pub frame: CylinderFrame,
    /// The low and high end, open or closed ([`end_shapes`]).
    pub ends: [EndShape; 2],
    /// The height (in the frame) where each closed end's cap meets the
    /// bands; `None` for an open end.
    pub caps: [Option<f64>; 2],
    /// Number of patches: `S L` plus `S` per closed end.
    pub patches: usize,
}

/// The revolve layout of `cloud` with `sectors` x `bands` side patches about
/// `axis` (see the module docs). `spacing` is the median point spacing.
///
/// Errors: fewer than 3 sectors or no band; points that do not go around
/// the axis; two layers on a ray from the axis; a patch with fewer than
/// [`MIN_PATCH_POINTS`] points.
///
/// ```
/// use scanfit::base::turntable::AxisChoice;
/// use scanfit::network::layout::revolve::revolve_labels;
/// use scanfit::{Point3, PointCloud};
/// // an open tube of radius 1 and height 4 along z
/// let pts = (0..8000).map(|i| {
///     let (a, z) = (i as f64 * 2.399963229728653, 4.0 * (i as f64 + 0.5) / 8000.0);
///     Point3::new(a.cos(), a.sin(), z)
/// }).collect();
/// let r = revolve_labels(&PointCloud::new(pts)?, 4, 2, AxisChoice::Principal, 0.05)?;
/// assert_eq!(r.patches, 8);
/// assert!(r.ends[0].open && r.ends[1].open);
/// assert_eq!(r.labels.iter().max(), Some(&7));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn revolve_labels(
    cloud: &PointCloud,
    sectors: usize,
    bands: usize,
    axis: AxisChoice,
    spacing: f64,
) -> Result<RevolveLayout> {
    if sectors < 3 || bands == 0 || sectors > 360 || bands > 1000 {
        return Err(Error::InvalidInput(format!(
            "revolve:{sectors}x{bands}: give 3 to 360 sectors (fewer than 3 leave the cap patches without a pole corner) and 1 to 1000 bands, e.g. revolve:4x3"
        )));
    }
    let pts = cloud.points();
    if axis == AxisChoice::Principal {
        clear_principal_axis(pts)?;
    }
    let frame = CylinderFrame::of(pts, axis)?;
    let ends = end_shapes(pts, &frame, LayerConfig::default().margin);
    // (height, distance from the axis, angle) of every point
    let local: Vec<(f64, f64, f64)> = pts
        .iter()
        .map(|p| {
            let l = frame.to_local(p);
            (l.y, l.x.hypot(l.z), l.x.atan2(l.z))
        })
        .collect();
    around_the_axis(&local, &frame)?;
    // |n . a| per point: caps face along the axis, walls across it
    let facing: Vec<f64> = estimate_normals(
        cloud,
        &NormalsConfig {
            k: 16,
            orientation: Orientation::None,
        },
    )?
    .normals
    .iter()
    .map(|n| n.dot(&frame.axis).abs())
    .collect();
    one_layer(&local, &facing, &frame, spacing)?;
    let (lo, hi) = frame.height;
    let closed = [!ends[0].open, !ends[1].open];
    let slice = (2.0 * spacing).max((hi - lo) / 200.0);
    let fallback = (hi - lo) / (2.0 * bands as f64 + 4.0);
    let caps = [
        closed[0].then(|| lo + cap_depth(&local, &facing, |h| h - lo, slice, hi - lo, fallback)),
        closed[1].then(|| hi - cap_depth(&local, &facing, |h| hi - h, slice, hi - lo, fallback)),
    ];
    let (b0, b1) = (caps[0].unwrap_or(lo), caps[1].unwrap_or(hi));
    let side = (sectors * bands) as i64;
    let high_cap = side + if closed[0] { sectors as i64 } else { 0 };
    let labels: Vec<i64> = local
        .iter()
        .enumerate()
        .map(|(i, &(h, _, a))| {
            let s = (((a + PI) / (2.0 * PI) * sectors as f64) as usize).min(sectors - 1) as i64;
            let wall = facing[i] < 0.5;
            match (caps[0], caps[1]) {
                (Some(c), _) if h < c && !wall => side + s,
                (_, Some(c)) if h > c && !wall => high_cap + s,
                _ => {
                    let t = ((h - b0) / (b1 - b0)).clamp(0.0, 1.0);
                    let b = ((t * bands as f64) as usize).min(bands - 1) as i64;
                    b * sectors as i64 + s
                }
            }
        })
        .collect();
    let patches = sectors * (bands + closed.iter().filter(|&&c| c).count());
    check_counts(&labels, patches, sectors, bands)?;
    Ok(RevolveLayout {
        labels,
        frame,
        ends,
        caps,
        patches,
    })
}

/// Below this ratio of the two largest covariance eigenvalues the principal
/// axis is no axis of the object (1.1): a squat object (wider than tall)
/// has two nearly equal variances across its axis and one of them wins by
/// chance (the shipped vessel without its lid: 1.017; with it: 1.29).
pub const MIN_AXIS_RATIO: f64 = 1.1;

/// Refuses a principal axis that the data do not single out.
fn clear_principal_axis(pts: &[crate::Point3]) -> Result<()> {
    let Some(pc) = crate::pca(pts) else {
        return Ok(());
    };
    let [a, b, _] = pc.values;
    if b > 0.0 && a / b < MIN_AXIS_RATIO {
        let d = pc.axes[0];
        return Err(Error::InvalidInput(format!(
            "the principal axis ({:.3}, {:.3}, {:.3}) is not clear: the two largest variances of the points differ by only {:.1}% (an object wider than tall about its axis, or no axis at all); give the axis of revolution with --axis (x, y, z or X,Y,Z)",
            d.x,
            d.y,
            d.z,
            100.0 * (a / b - 1.0)
        )));
    }
    Ok(())
}

impl RevolveLayout {
    /// One line on what the layout found: the axis and each end.
    pub fn summary(&self, sectors: usize) -> String {
        let a = self.frame.axis;
        let end = |e: &EndShape| {
            if e.open {
                "open".to_string()
            } else {
                format!("closed ({sectors} three-sided caps)")
            }
        };
        format!(
            "revolve about the axis ({:.3}, {:.3}, {:.3}): low end {}, high end {}; {} patches",
            a.x,
            a.y,
            a.z,
            end(&self.ends[0]),
            end(&self.ends[1]),
            self.patches
        )
    }
}

/// How far from its end a closed end's cap reaches (see the module docs):
/// `depth(h)` is a height's distance from the end.
fn cap_depth(
    local: &[(f64, f64, f64)],
    facing: &[f64],
    depth: impl Fn(f64) -> f64,
    slice: f64,
    span: f64,
    fallback: f64,
) -> f64 {
    let count = ((0.45 * span / slice) as usize).max(1);
    let mut all = vec![0usize; count];
    let mut along = vec![0usize; count];
    for (&(h, _, _), &f) in local.iter().zip(facing) {
        let k = (depth(h) / slice) as usize;
        if k < count {
            all[k] += 1;
            // within 45 degrees of the axis
            along[k] += usize::from(f > std::f64::consts::FRAC_1_SQRT_2);
        }
    }
    // the last facing slice before three in a row that are not (a bump or
    // an empty slice at a pole does not end the cap)
    let mut run = 0;
    for k in 0..count {
        if all[k] > 0 && 2 * along[k] > all[k] {
            run = k + 1;
        } else if k >= run + 2 {
            break;
        }
    }
    if run == 0 {
        fallback
    } else {
        run as f64 * slice
    }
}

/// Refuses points that do not go all the way around the axis: angle bins
/// of 5 degrees (fewer for small clouds, about 20 points a bin) over the
/// middle 80% of the height, none may be empty.
fn around_the_axis(local: &[(f64, f64, f64)], frame: &CylinderFrame) -> Result<()> {
    let (lo, hi) = frame.height;
    let mid: Vec<f64> = local
        .iter()
        .filter(|(h, _, _)| (h - lo) > 0.1 * (hi - lo) && (hi - h) > 0.1 * (hi - lo))
        .map(|&(_, _, a)| a)
        .collect();
    let bins = (mid.len() / 20).clamp(8, 72);
    let mut filled = vec![false; bins];
    for a in &mid {
        filled[(((a + PI) / (2.0 * PI) * bins as f64) as usize).min(bins - 1)] = true;
    }
    if filled.iter().all(|&f| f) {
        return Ok(());
    }
    // the longest run of empty bins, cyclically
    let (mut best, mut best_len) = (0, 0);
    for start in 0..bins {
        let len = (0..bins)
            .take_while(|&k| !filled[(start + k) % bins])
            .count();
        if len > best_len {
            (best, best_len) = (start, len);
        }
    }
    let deg = |k: usize| -180.0 + 360.0 * k as f64 / bins as f64;
    let (a, c) = (frame.axis, frame.centre);
    Err(Error::InvalidInput(format!(
        "the revolve layout needs an object all around its axis, but around the axis ({:.3}, {:.3}, {:.3}) through ({:.4}, {:.4}, {:.4}) there are no points between {:.0} and {:.0} degrees ({} of {} angle ranges are empty): there is no axis to revolve about. Give the object's axis with --axis, use --layout grid:RxC for a sheet, or --layout cube for a closed star-shaped object",
        a.x, a.y, a.z, c.x, c.y, c.z,
        deg(best),
        deg(best + best_len),
        filled.iter().filter(|&&f| !f).count(),
        bins
    )))
}

/// Refuses two layers of surface on one ray from the axis (see the module
/// docs), among the points whose normal is more than 60 degrees from the
/// axis (walls; a second layer such as a handle or an inner wall is one).
fn one_layer(
    local: &[(f64, f64, f64)],
    facing: &[f64],
    frame: &CylinderFrame,
    spacing: f64,
) -> Result<()> {
    let (lo, hi) = frame.height;
    let cells = (local.len() / 40).max(1);
    // square-ish bins: angle bins over the circumference, height bins over the height
    let ratio = (2.0 * PI * frame.radius / (hi - lo)).max(1e-6);
    let na = ((cells as f64 * ratio).sqrt().round() as usize).clamp(4, 720);
    let nh = (cells / na).max(1);
    let mut bins: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new(); na * nh];
    // wall points only: a surface across the axis (a flat bottom) crosses
    // height bins and would leave a false gap between its part in a bin
    // and the wall
    for (&(h, r, a), _) in local.iter().zip(facing).filter(|(_, &f)| f < 0.5) {
        let i = (((a + PI) / (2.0 * PI) * na as f64) as usize).min(na - 1);
        let j = (((h - lo) / (hi - lo) * nh as f64) as usize).min(nh - 1);
        bins[j * na + i].push((r, h, a));
    }
    let jump = 10.0 * spacing;
    for bin in &mut bins {
        bin.sort_by(|x, y| x.0.total_cmp(&y.0));
        if let Some(w) = bin.windows(2).find(|w| w[1].0 - w[0].0 > jump) {
            return Err(Error::InvalidInput(format!(
                "the object has two layers of surface on one ray from its axis ({:.3}, {:.3}, {:.3}): at height {:.4} and angle {:.0} degrees, at distances {:.4} and {:.4} from the axis (a handle, an inner wall); the revolve layout would fold there. Remove the second layer, give another axis with --axis, use --segment for a part with sharp edges, or label the patches by hand",
                frame.axis.x, frame.axis.y, frame.axis.z,
                w[0].1,
                w[0].2.to_degrees(),
                w[0].0,
                w[1].0
            )));
        }
    }
    Ok(())
}

/// Refuses a layout with a patch of fewer than [`MIN_PATCH_POINTS`] points.
fn check_counts(labels: &[i64], patches: usize, sectors: usize, bands: usize) -> Result<()> {
    let mut count = vec![0usize; patches];
    for &l in labels {
        count[l as usize] += 1;
    }
    if let Some((k, &c)) = count
        .iter()
        .enumerate()
        .find(|(_, &c)| c < MIN_PATCH_POINTS)
    {
        let what = if k < sectors * bands {
            format!("sector {} of band {}", k % sectors, k / sectors)
        } else {
            format!("cap patch {k}")
        };
        return Err(Error::InvalidInput(format!(
            "revolve:{sectors}x{bands} leaves patch {k} ({what}) only {c} points, fewer than the {MIN_PATCH_POINTS} a patch needs; use fewer sectors or bands"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Point3, Vector3};

    /// A capsule along `axis` (radius 1, straight part of height 4), or only
    /// its tube when `open`.
    fn capsule(n: usize, open: bool) -> Vec<Point3> {
        (0..n)
            .filter_map(|i| {
                let a = i as f64 * 2.399_963_229_728_653;
                let t = (i as f64 + 0.5) / n as f64 * (4.0 + 2.0 * PI);
                if t < 4.0 {
                    return Some(Point3::new(a.cos(), a.sin(), t - 2.0));
                }
                if open {
                    return None;
                }
                // the hemispheres, area-uniform in height
                let z = (t - 4.0) / PI - 1.0;
                let r = (1.0 - z * z).sqrt();
                let zz = if z < 0.0 { z - 2.0 } else { z + 2.0 };
                Some(Point3::new(r * a.cos(), r * a.sin(), zz))
            })
            .collect()
    }

    #[test]
    fn a_capsule_gets_caps_at_45_degrees() {
        let pts = capsule(20_000, false);
        let r = revolve_labels(
            &PointCloud::new(pts.clone()).unwrap(),
            4,
            3,
            AxisChoice::Principal,
            0.03,
        )
        .unwrap();
        assert!(!r.ends[0].open && !r.ends[1].open, "{:?}", r.ends);
        assert_eq!(r.patches, 20);
        // caps where the hemisphere's normal is 45 degrees from the axis: |z| = 2 + sqrt(1/2)
        let c = 2.0 + 0.5f64.sqrt();
        for (k, cap) in r.caps.iter().enumerate() {
            let h = cap.unwrap();
            // the frame's height is centred; one slice (2 spacings) of resolution
            assert!((h.abs() - c).abs() < 0.1, "cap {k} at {h}");
        }
        // every label is the sector of the point's angle
        for (p, &l) in pts.iter().zip(&r.labels) {
            let s = l % 4;
            let a = r.frame.angle(p);
            let expect = (((a + PI) / (2.0 * PI) * 4.0) as i64).min(3);
            assert_eq!(s, expect);
        }
    }

    #[test]
    fn an_open_tube_has_no_caps() {
        let pts = capsule(8000, true);
        let r = revolve_labels(
            &PointCloud::new(pts).unwrap(),
            3,
            2,
            AxisChoice::Given(Vector3::z()),
            0.05,
        )
        .unwrap();
        assert_eq!(r.caps, [None, None]);
        assert_eq!(r.patches, 6);
        let mut count = [0usize; 6];
        for &l in &r.labels {
            count[l as usize] += 1;
        }
        // equal thirds and halves of a uniform tube (3112 of the 8000
        // capsule points): 519 each, within the lattice's rounding
        assert_eq!(count.iter().sum::<usize>(), 3112);
        assert!(count.iter().all(|&c| (510..530).contains(&c)), "{count:?}");
    }

    #[test]
    fn a_half_pipe_has_no_axis() {
        let pts: Vec<Point3> = capsule(8000, true)
            .into_iter()
            .filter(|p| p.y > 0.0)
            .collect();
        let e = revolve_labels(
            &PointCloud::new(pts).unwrap(),
            4,
            2,
            AxisChoice::Given(Vector3::z()),
            0.05,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("no axis to revolve about"), "{e}");
        assert!(e.contains("grid:RxC"), "{e}");
    }

    #[test]
    fn an_inner_wall_is_two_layers() {
        let mut pts = capsule(30_000, true);
        pts.extend(
            capsule(4000, true)
                .into_iter()
                .map(|p| Point3::new(0.3 * p.x, 0.3 * p.y, p.z)),
        );
        let cloud = PointCloud::new(pts).unwrap();
        let spacing = cloud.spacing().unwrap().median;
        let e = revolve_labels(&cloud, 4, 2, AxisChoice::Given(Vector3::z()), spacing)
            .unwrap_err()
            .to_string();
        assert!(e.contains("two layers"), "{e}");
    }

    #[test]
    fn too_few_sectors_and_too_many_patches() {
        let cloud = PointCloud::new(capsule(2000, true)).unwrap();
        let e = revolve_labels(&cloud, 2, 2, AxisChoice::Principal, 0.1).unwrap_err();
        assert!(e.to_string().contains("3 to 360 sectors"), "{e}");
        // a tube as wide as tall: no clear principal axis
        let squat: Vec<Point3> = capsule(8000, true)
            .into_iter()
            .map(|p| Point3::new(p.x, p.y, 0.6 * p.z))
            .collect();
        let e = revolve_labels(
            &PointCloud::new(squat).unwrap(),
            4,
            2,
            AxisChoice::Principal,
            0.1,
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("give the axis of revolution with --axis"),
            "{e}"
        );
        let e = revolve_labels(&cloud, 12, 8, AxisChoice::Given(Vector3::z()), 0.1).unwrap_err();
        assert!(e.to_string().contains("use fewer sectors or bands"), "{e}");
    }
}
