//! The point-cloud tools as library calls: statistics ([`info`]), oriented
//! normals ([`normals`]), hidden point removal ([`hpr`], Katz, Tal & Basri
//! 2007) and the boundary loop with its
//! corners and sides ([`boundary`]; alpha shape, corners by the Coons
//! paper's eqs. 10-12 or the three-point curvature of the PDE paper, 4.1),
//! and cleaning ([`clean`]: crops, statistical outliers, small fragments,
//! voxel thinning).
//!
//! Each takes the cloud, a `#[non_exhaustive]` config with documented
//! defaults and a progress callback, and returns a report the front renders;
//! none reads or writes files.

use crate::cloud::boundary::{boundary_loops, Boundary, BoundaryConfig};
use crate::cloud::clean::{
    inside_box, inside_sphere, small_fragments, statistical_outliers, voxel_thinning, OutlierConfig,
};
use crate::cloud::corners::{
    corner_values, find_corners, split_at_corners, CornerConfig, CornerCriterion, Corners,
};
use crate::cloud::hpr::{hidden_point_removal, HprConfig};
use crate::cloud::neighbours::Spacing;
use crate::cloud::normals::{estimate_normals, Normals, NormalsConfig};
use crate::progress::Progress;
use crate::{Error, Point3, PointCloud, Result};

/// Settings of [`info`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CloudInfoConfig {
    /// Measure the nearest-neighbour spacing (a KD-tree over the cloud;
    /// default true). Skipped anyway for fewer than 2 points.
    pub spacing: bool,
    /// Above this many points the spacing is measured on a seeded random
    /// sample of this many points ([`PointCloud::spacing_sample`]; default
    /// 1,000,000: on 10^7 points measuring all took 100 s, and a sample of
    /// 10^6 gives the median and mean to well under 1 %).
    pub spacing_sample: usize,
    /// Seed of the sample (default 1).
    pub seed: u64,
}

impl Default for CloudInfoConfig {
    fn default() -> Self {
        Self {
            spacing: true,
            spacing_sample: 1_000_000,
            seed: 1,
        }
    }
}

/// The range of one attribute.
#[derive(Debug, Clone, PartialEq)]
pub struct AttributeRange {
    /// Attribute name (e.g. `intensity`, `nx`).
    pub name: String,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// What [`info`] found.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CloudInfo {
    /// Number of points.
    pub points: usize,
    /// Corner of the bounding box with the smallest coordinates.
    pub bbox_min: Point3,
    /// Corner of the bounding box with the largest coordinates.
    pub bbox_max: Point3,
    /// Length of the bounding box's diagonal.
    pub diagonal: f64,
    /// Every attribute's range, in the cloud's order.
    pub attributes: Vec<AttributeRange>,
    /// Nearest-neighbour distances (`None` for fewer than 2 points or when
    /// not asked for); `measured` below `points` when sampled.
    pub spacing: Option<Spacing>,
}

/// Count, bounding box, attribute ranges and nearest-neighbour spacing of `cloud`.
///
/// Errors: an empty cloud.
///
/// ```
/// use scanfit::pipeline::cloud::{info, CloudInfoConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// let cloud = PointCloud::new(vec![
///     Point3::new(0.0, 0.0, 0.0),
///     Point3::new(3.0, 0.0, 0.0),
///     Point3::new(3.0, 4.0, 0.0),
/// ])?
/// .with_attribute("intensity", vec![5.0, 1.0, 9.0])?;
/// let r = info(&cloud, &CloudInfoConfig::default(), &NoProgress)?;
/// assert_eq!(r.points, 3);
/// assert_eq!(r.diagonal, 5.0);
/// assert_eq!((r.attributes[0].min, r.attributes[0].max), (1.0, 9.0));
/// let s = r.spacing.unwrap();
/// assert_eq!((s.min, s.max), (3.0, 4.0));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn info(
    cloud: &PointCloud,
    config: &CloudInfoConfig,
    progress: &dyn Progress,
) -> Result<CloudInfo> {
    progress.stage("statistics", None);
    let (lo, hi) = cloud.bounding_box().ok_or_else(|| Error::TooFewPoints {
        got: 0,
        needed: 1,
        what: "cloud statistics".into(),
    })?;
    let attributes = cloud
        .attributes()
        .iter()
        .map(|at| {
            let (min, max) = at
                .values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            AttributeRange {
                name: at.name.clone(),
                min,
                max,
            }
        })
        .collect();
    let spacing = if config.spacing && cloud.len() >= 2 {
        progress.stage("nearest-neighbour spacing", None);
        Some(cloud.spacing_sample(config.spacing_sample, config.seed)?)
    } else {
        None
    };
    Ok(CloudInfo {
        points: cloud.len(),
        bbox_min: lo,
        bbox_max: hi,
        diagonal: (hi - lo).norm(),
        attributes,
        spacing,
    })
}

/// Settings of [`normals`].
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct CloudNormalsConfig {
    /// Neighbours and orientation (default 16 neighbours, spanning-tree
    /// orientation with the seed along +z).
    pub normals: NormalsConfig,
}

/// What [`normals`] found.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CloudNormals {
    /// Normals, surface variation, degenerate neighbourhoods, components.
    pub normals: Normals,
    /// Mean surface variation over the points (0 on a plane).
    pub mean_variation: f64,
    /// The input cloud with the normals (`nx`, `ny`, `nz`) and the
    /// attribute `variation` added.
    pub cloud: PointCloud,
}

/// Oriented PCA normals of `cloud` over its `k` nearest neighbours, with
/// the surface variation (see [`estimate_normals`]).
///
/// Errors: `k < 2`, fewer than `k + 1` points, non-finite points.
///
/// ```
/// use scanfit::pipeline::cloud::{normals, CloudNormalsConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a tilted plane z = 0.5 x on a 10 x 10 grid
/// let pts = (0..100)
///     .map(|i| Point3::new((i % 10) as f64, (i / 10) as f64, 0.5 * (i % 10) as f64))
///     .collect();
/// let r = normals(&PointCloud::new(pts)?, &CloudNormalsConfig::default(), &NoProgress)?;
/// let n = r.normals.normals[55];
/// // (-0.5, 0, 1) / |.|, oriented along +z
/// assert!((n.x + 0.5 / 1.25f64.sqrt()).abs() < 1e-9 && n.z > 0.0, "{n}");
/// assert!(r.mean_variation < 1e-12);
/// assert_eq!(r.cloud.attribute("variation").map(<[f64]>::len), Some(100));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn normals(
    cloud: &PointCloud,
    config: &CloudNormalsConfig,
    progress: &dyn Progress,
) -> Result<CloudNormals> {
    progress.stage("normals", Some(cloud.len() as u64));
    let r = estimate_normals(cloud, &config.normals)?;
    let mut out = cloud.clone();
    out.set_normals(&r.normals)?;
    out.set_attribute("variation", r.variation.clone())?;
    let mean_variation = r.variation.iter().sum::<f64>() / r.variation.len().max(1) as f64;
    Ok(CloudNormals {
        normals: r,
        mean_variation,
        cloud: out,
    })
}

/// Settings of [`hpr`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CloudHprConfig {
    /// The viewpoint (scanner or camera position), in the units of the
    /// points (default the origin).
    pub viewpoint: Point3,
    /// Flipping radius exponent (default `gamma = 2`).
    pub hpr: HprConfig,
}

impl Default for CloudHprConfig {
    fn default() -> Self {
        Self {
            viewpoint: Point3::origin(),
            hpr: HprConfig::default(),
        }
    }
}

impl CloudHprConfig {
    /// The default settings seen from `viewpoint`.
    pub fn from_viewpoint(viewpoint: Point3) -> Self {
        Self {
            viewpoint,
            ..Default::default()
        }
    }
}

/// What [`hpr`] found.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CloudHpr {
    /// Indices of the visible points, ascending.
    pub visible: Vec<usize>,
    /// Number of hidden points.
    pub hidden: usize,
    /// The visible points with all their attributes and the attribute
    /// `index`, each point's index in the input.
    pub cloud: PointCloud,
}

impl CloudHpr {
    /// Per input point: whether it is visible.
    pub fn visible_mask(&self, points: usize) -> Vec<bool> {
        let mut m = vec![false; points];
        for &i in &self.visible {
            if let Some(x) = m.get_mut(i) {
                *x = true;
            }
        }
        m
    }
}

/// The points of `cloud` visible from the viewpoint, by the hidden point
/// removal operator (spherical flipping and convex hull, Katz, Tal & Basri 2007, eq. 1).
///
/// Errors: those of [`hidden_point_removal`] (fewer than 4 points, a point
/// at the viewpoint, gamma outside `(0, 12]`, a planar set seen edge-on).
///
/// ```
/// use scanfit::pipeline::cloud::{hpr, CloudHprConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a sphere of 400 points seen from far along +z: about half is visible
/// let pts = (0..400)
///     .map(|i| {
///         let z = 1.0 - (2 * i + 1) as f64 / 400.0;
///         let r = (1.0 - z * z).sqrt();
///         let t = i as f64 * 2.399963;
///         Point3::new(r * t.cos(), r * t.sin(), z)
///     })
///     .collect();
/// let cfg = CloudHprConfig::from_viewpoint(Point3::new(0.0, 0.0, 100.0));
/// let r = hpr(&PointCloud::new(pts)?, &cfg, &NoProgress)?;
/// assert!(r.visible.len() > 160 && r.visible.len() < 240, "{}", r.visible.len());
/// assert_eq!(r.visible.len() + r.hidden, 400);
/// assert_eq!(r.cloud.attribute("index").map(|x| x[0] as usize), Some(r.visible[0]));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn hpr(
    cloud: &PointCloud,
    config: &CloudHprConfig,
    progress: &dyn Progress,
) -> Result<CloudHpr> {
    progress.stage("hidden point removal", None);
    let visible = hidden_point_removal(cloud.points(), &config.viewpoint, &config.hpr)?;
    let mut out = cloud.select(&visible)?;
    out.set_attribute("index", visible.iter().map(|&i| i as f64).collect())?;
    Ok(CloudHpr {
        hidden: cloud.len() - visible.len(),
        visible,
        cloud: out,
    })
}

/// Settings of [`boundary`].
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct CloudBoundaryConfig {
    /// The alpha shape (default alpha = 2.5 x the median Delaunay edge).
    pub boundary: BoundaryConfig,
    /// Corner detection on the outer loop (default 4 corners, smallest
    /// turning angle, offset 1% of the loop, separation 3%); `count` 0 finds
    /// none. With `corner_positions` only `criterion` and `offset` are used
    /// (for the values reported at the corners).
    pub corners: CornerConfig,
    /// Loop positions to use as the corners instead of detecting them.
    pub corner_positions: Option<Vec<usize>>,
}

/// What [`boundary`] found.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CloudBoundary {
    /// The loops (indices into the cloud), their areas, alpha, spacing, plane.
    pub boundary: Boundary,
    /// The outer loop's points, in loop order.
    pub loop_points: Vec<Point3>,
    /// Corners (loop positions), sides and the criterion's value at every
    /// loop position; `None` when no corners were asked for.
    pub corners: Option<Corners>,
    /// The criterion the values are of.
    pub criterion: CornerCriterion,
}

impl CloudBoundary {
    /// The outer loop (indices into the cloud).
    pub fn outer(&self) -> &[usize] {
        self.boundary.outer_loop()
    }

    /// The criterion's value at loop position `q` in display units: degrees
    /// for the turning angle, 1 / (units of the points) for the curvature.
    pub fn corner_value(&self, q: usize) -> Option<f64> {
        let v = *self.corners.as_ref()?.values.get(q)?;
        Some(match self.criterion {
            CornerCriterion::TurningAngle => v.to_degrees(),
            CornerCriterion::ThreePointCurvature => v,
        })
    }

    /// The outer loop as a cloud, in loop order, with the attributes
    /// `index` (into the input), `position` (in the loop), `side` (the side
    /// each point belongs to, a corner to the side it starts; -1 without
    /// corners) and `corner` (1 at corners).
    pub fn loop_cloud(&self) -> Result<PointCloud> {
        let outer = self.outer();
        let n = outer.len();
        let mut side = vec![-1.0; n];
        let mut corner = vec![0.0; n];
        if let Some(c) = &self.corners {
            for (k, s) in c.sides.iter().enumerate() {
                for &q in s.iter().rev() {
                    side[q] = k as f64;
                }
            }
            for (k, &q) in c.corners.iter().enumerate() {
                corner[q] = 1.0;
                side[q] = k as f64;
            }
        }
        PointCloud::new(self.loop_points.clone())?
            .with_attribute("index", outer.iter().map(|&i| i as f64).collect())?
            .with_attribute("position", (0..n).map(|k| k as f64).collect())?
            .with_attribute("side", side)?
            .with_attribute("corner", corner)
    }
}

/// The boundary loops of a sheet-like `cloud` (alpha shape in its best-fit
/// plane), the outer loop's corners and its sides.
///
/// Errors: those of [`boundary_loops`] and [`find_corners`]; a given corner
/// position beyond the outer loop; positions that do not split the loop.
///
/// ```
/// use scanfit::pipeline::cloud::{boundary, CloudBoundaryConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// // a 30 x 20 grid: a rectangle with four 90-degree corners
/// let pts = (0..600)
///     .map(|i| Point3::new((i % 30) as f64, (i / 30) as f64, 0.0))
///     .collect();
/// let r = boundary(&PointCloud::new(pts)?, &CloudBoundaryConfig::default(), &NoProgress)?;
/// assert_eq!(r.outer().len(), 96); // 2 x (29 + 19) boundary grid points
/// let c = r.corners.as_ref().unwrap();
/// assert_eq!(c.corners.len(), 4);
/// for &q in &c.corners {
///     assert!((r.corner_value(q).unwrap() - 90.0).abs() < 1e-6);
/// }
/// assert_eq!(r.loop_cloud()?.attribute("corner").unwrap().iter().sum::<f64>(), 4.0);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn boundary(
    cloud: &PointCloud,
    config: &CloudBoundaryConfig,
    progress: &dyn Progress,
) -> Result<CloudBoundary> {
    progress.stage("alpha shape", None);
    let b = boundary_loops(cloud.points(), &config.boundary)?;
    let outer = b.outer_loop().to_vec();
    let loop_points: Vec<Point3> = outer.iter().map(|&i| cloud.points()[i]).collect();
    progress.stage("corners", None);
    let criterion = config.corners.criterion;
    let corners = match &config.corner_positions {
        Some(c) => {
            if let Some(&bad) = c.iter().find(|&&k| k >= outer.len()) {
                return Err(Error::InvalidSetting {
                    setting: "corner_positions",
                    value: bad.to_string(),
                    hint: format!(
                        "a corner position must lie in the outer loop, which has {} points (positions 0..{})",
                        outer.len(),
                        outer.len().saturating_sub(1)
                    ),
                });
            }
            let sides = split_at_corners(outer.len(), c)?;
            let offset = config
                .corners
                .offset
                .unwrap_or_else(|| ((outer.len() as f64 / 100.0).round() as usize).max(1));
            Some(Corners {
                corners: c.clone(),
                sides,
                values: corner_values(&loop_points, criterion, offset)?,
                offset,
            })
        }
        None if config.corners.count == 0 => None,
        None => Some(find_corners(&loop_points, &config.corners)?),
    };
    Ok(CloudBoundary {
        boundary: b,
        loop_points,
        corners,
        criterion,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    /// A 30 x 20 grid in the plane z = 0.
    fn grid() -> PointCloud {
        PointCloud::new(
            (0..600)
                .map(|i| Point3::new((i % 30) as f64, (i / 30) as f64, 0.0))
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn given_corners_split_the_loop_into_sides_on_the_loop_cloud() {
        let cloud = grid();
        let mut cfg = CloudBoundaryConfig {
            corner_positions: Some(vec![0, 20, 50, 70]),
            ..Default::default()
        };
        let r = boundary(&cloud, &cfg, &NoProgress).unwrap();
        let c = r.corners.as_ref().unwrap();
        assert_eq!(
            c.sides.iter().map(Vec::len).collect::<Vec<_>>(),
            [21, 31, 21, 27]
        );
        let lc = r.loop_cloud().unwrap();
        let side = lc.attribute("side").unwrap();
        // a corner belongs to the side it starts; the points between to theirs
        assert_eq!(
            (side[0], side[19], side[20], side[50], side[95]),
            (0.0, 0.0, 1.0, 2.0, 3.0)
        );
        assert_eq!(lc.attribute("position").unwrap()[95], 95.0);
        let index = lc.attribute("index").unwrap();
        assert_eq!(cloud.points()[index[20] as usize], r.loop_points[20]);
        cfg.corner_positions = Some(vec![0, 20, 50, 96]);
        match boundary(&cloud, &cfg, &NoProgress) {
            Err(Error::InvalidSetting {
                setting,
                value,
                hint,
            }) => {
                assert_eq!((setting, value.as_str()), ("corner_positions", "96"));
                assert!(hint.contains("96 points"), "{hint}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn no_corners_asked_leaves_the_loop_undivided() {
        let mut cfg = CloudBoundaryConfig::default();
        cfg.corners.count = 0;
        let r = boundary(&grid(), &cfg, &NoProgress).unwrap();
        assert!(r.corners.is_none() && r.corner_value(0).is_none());
        let lc = r.loop_cloud().unwrap();
        assert!(lc.attribute("side").unwrap().iter().all(|&s| s == -1.0));
        assert_eq!(lc.attribute("corner").unwrap().iter().sum::<f64>(), 0.0);
    }

    #[test]
    fn hpr_mask_and_normals_cloud_carry_the_results() {
        let cloud = grid();
        let r = hpr(
            &cloud,
            &CloudHprConfig::from_viewpoint(Point3::new(14.5, 9.5, 50.0)),
            &NoProgress,
        )
        .unwrap();
        // a plane seen from above: every point is visible
        assert_eq!((r.visible.len(), r.hidden), (600, 0));
        assert!(r.visible_mask(600).iter().all(|&v| v));
        let n = normals(&cloud, &CloudNormalsConfig::default(), &NoProgress).unwrap();
        let normals = n.cloud.normals().unwrap();
        assert!(normals.iter().all(|v| (v.z - 1.0).abs() < 1e-12));
        assert_eq!(n.mean_variation, 0.0);
        let i = info(
            &cloud,
            &CloudInfoConfig {
                spacing: false,
                ..Default::default()
            },
            &NoProgress,
        )
        .unwrap();
        assert!(i.spacing.is_none());
        assert_eq!(i.bbox_max, Point3::new(29.0, 19.0, 0.0));
    }
}

/// Small-fragment removal settings of [`clean`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct FragmentConfig {
    /// Points closer than this many median nearest-neighbour spacings are
    /// joined (default 3: a surface sampled at that spacing stays one piece
    /// across the gaps of uneven sampling).
    pub radius_spacings: f64,
    /// Components with fewer points are removed (default `None`: 1% of the
    /// points, at least 10).
    pub min_size: Option<usize>,
}

impl Default for FragmentConfig {
    fn default() -> Self {
        Self {
            radius_spacings: 3.0,
            min_size: None,
        }
    }
}

/// The cell size of voxel thinning in [`clean`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VoxelSize {
    /// An edge length in the units of the points.
    Absolute(f64),
    /// A multiple of the median nearest-neighbour spacing (2 keeps about a
    /// quarter of an evenly sampled surface).
    Spacings(f64),
}

/// Settings of [`clean`]: each step is off (`None`) unless set; the steps
/// run in the order crop box, crop sphere, outliers, fragments, voxels.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct CloudCleanConfig {
    /// Keep the points inside this axis-aligned box `(min, max)`.
    pub crop_box: Option<(Point3, Point3)>,
    /// Keep the points inside this ball `(centre, radius)`.
    pub crop_sphere: Option<(Point3, f64)>,
    /// Statistical outlier removal (see [`statistical_outliers`]).
    pub outliers: Option<OutlierConfig>,
    /// Small-fragment removal (see [`small_fragments`]).
    pub fragments: Option<FragmentConfig>,
    /// Voxel thinning (see [`voxel_thinning`]).
    pub voxel: Option<VoxelSize>,
}

impl CloudCleanConfig {
    /// Only statistical outlier removal with its defaults: what the surface
    /// commands' `--remove-outliers` runs.
    pub fn remove_outliers() -> Self {
        Self {
            outliers: Some(OutlierConfig::default()),
            ..Self::default()
        }
    }
}

/// One step of [`clean`] and what it removed.
#[derive(Debug, Clone, PartialEq)]
pub struct CleanStep {
    /// `crop box`, `crop sphere`, `outliers`, `fragments` or `voxels`.
    pub operation: &'static str,
    /// Points before the step.
    pub before: usize,
    /// Points the step removed.
    pub removed: usize,
    /// The step's measure: the distance threshold, the components, the
    /// cell size (in the units of the points).
    pub detail: String,
}

/// What [`clean`] did.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CloudClean {
    /// The points kept, with all their attributes, in input order.
    pub cloud: PointCloud,
    /// Input index of each kept point.
    pub kept: Vec<usize>,
    /// The steps run, in order.
    pub steps: Vec<CleanStep>,
}

/// Cleans a scan: crops, statistical outliers, small fragments and voxel
/// thinning, each only when configured (see [`crate::cloud::clean`]).
///
/// Errors: an invalid setting (a negative radius or size, `k = 0`), or no
/// point left after a step (the message names it).
///
/// ```
/// use scanfit::pipeline::cloud::{clean, CloudCleanConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
///
/// let mut p: Vec<Point3> = (0..400)
///     .map(|i| Point3::new((i % 20) as f64, (i / 20) as f64, 0.0))
///     .collect();
/// p.push(Point3::new(10.0, 10.0, 50.0));
/// let cloud = PointCloud::new(p)?.with_attribute("label", (0..401).map(f64::from).collect())?;
/// let r = clean(&cloud, &CloudCleanConfig::remove_outliers(), &NoProgress)?;
/// assert_eq!((r.cloud.len(), r.steps[0].removed), (400, 1));
/// assert_eq!(r.cloud.attribute("label").map(|l| l[399]), Some(399.0));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn clean(
    cloud: &PointCloud,
    config: &CloudCleanConfig,
    progress: &dyn Progress,
) -> Result<CloudClean> {
    let mut kept: Vec<usize> = (0..cloud.len()).collect();
    let mut current = cloud.clone();
    let mut steps = Vec::new();
    let mut apply = |operation: &'static str,
                     keep: Vec<bool>,
                     detail: String,
                     current: &mut PointCloud|
     -> Result<()> {
        let idx: Vec<usize> = (0..keep.len()).filter(|&i| keep[i]).collect();
        steps.push(CleanStep {
            operation,
            before: current.len(),
            removed: current.len() - idx.len(),
            detail,
        });
        if idx.is_empty() {
            return Err(Error::InvalidInput(format!(
                "{operation} removed all {} points; loosen it",
                current.len()
            )));
        }
        kept = idx.iter().map(|&i| kept[i]).collect();
        *current = current.select(&idx)?;
        Ok(())
    };
    if let Some((lo, hi)) = config.crop_box {
        let ok = (0..3).all(|c| lo[c].is_finite() && hi[c].is_finite() && lo[c] <= hi[c]);
        if !ok {
            return Err(Error::InvalidInput(format!(
                "crop box ({}, {}, {}) - ({}, {}, {}) needs finite corners with min <= max on every axis",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            )));
        }
        let keep = inside_box(&current, &lo, &hi);
        apply("crop box", keep, "outside the box".into(), &mut current)?;
    }
    if let Some((c, r)) = config.crop_sphere {
        if !(c.coords.iter().all(|v| v.is_finite()) && r.is_finite() && r > 0.0) {
            return Err(Error::InvalidInput(format!(
                "crop sphere radius {r} must be finite and > 0, its centre finite"
            )));
        }
        let keep = inside_sphere(&current, &c, r);
        apply(
            "crop sphere",
            keep,
            "outside the sphere".into(),
            &mut current,
        )?;
    }
    if let Some(o) = config.outliers {
        progress.stage("outliers", None);
        let r = statistical_outliers(&current, &o)?;
        let mut detail = format!(
            "mean distance to {} neighbours > {:.6} (mean {:.6} + {} x std {:.6})",
            o.k, r.threshold, r.mean, o.n_sigma, r.std
        );
        if o.local_ratio > 0.0 {
            detail += &format!(
                " and > {} x their kept neighbours' ({} sparse points beyond the first bound kept)",
                o.local_ratio, r.kept_local
            );
        }
        apply("outliers", r.keep, detail, &mut current)?;
    }
    if let Some(f) = config.fragments {
        progress.stage("fragments", None);
        if !(f.radius_spacings.is_finite() && f.radius_spacings > 0.0) {
            return Err(Error::InvalidInput(format!(
                "fragment radius {} spacings must be finite and > 0 (3 is the default)",
                f.radius_spacings
            )));
        }
        let spacing = current.spacing()?.median;
        let radius = f.radius_spacings * spacing;
        let min_size = f.min_size.unwrap_or((current.len() / 100).max(10));
        let r = small_fragments(&current, radius, min_size)?;
        let detail = format!(
            "{} of {} components under {min_size} points (radius {radius:.6})",
            r.removed_components, r.components
        );
        apply("fragments", r.keep, detail, &mut current)?;
    }
    if let Some(v) = config.voxel {
        progress.stage("voxels", None);
        let size = match v {
            VoxelSize::Absolute(s) => s,
            VoxelSize::Spacings(f) => f * current.spacing()?.median,
        };
        let idx = voxel_thinning(&current, size)?;
        let mut keep = vec![false; current.len()];
        for i in idx {
            keep[i] = true;
        }
        apply(
            "voxels",
            keep,
            format!("one point per cell of {size:.6}"),
            &mut current,
        )?;
    }
    Ok(CloudClean {
        cloud: current,
        kept,
        steps,
    })
}
