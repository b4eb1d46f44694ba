//! Segmentation of a scan by the variation of its normals ([COONS19] §I) as
//! a pipeline: the regions ([`crate::cloud::segment`]) and the cloud with
//! its `label` (region id) and `edge` (1 on edge points) attributes, ready
//! to be edited and read back by the multi-patch pipeline
//! ([`crate::pipeline::reconstruct`]).

use crate::cloud::segment::{segment, SegmentConfig, Segmentation};
use crate::network::layout::GENERATED_LABEL;
use crate::progress::Progress;
use crate::{PointCloud, Result};

/// The result of [`run`].
#[derive(Debug, Clone)]
pub struct SegmentReport {
    /// Regions, edge points, cells.
    pub segmentation: Segmentation,
    /// The input with `label` (region id, replacing any it had) and `edge`.
    pub cloud: PointCloud,
}

/// Segments `cloud` (see [`segment`]) and labels a copy of it.
///
/// ```
/// use scanfit::cloud::segment::SegmentConfig;
/// use scanfit::pipeline::segment::run;
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
/// // two faces of a fold
/// let mut pts = Vec::new();
/// for i in 0..60 {
///     for j in 0..60 {
///         let (a, b) = (i as f64 / 60.0 + 0.004, j as f64 / 60.0);
///         pts.extend([Point3::new(a, b, 0.0), Point3::new(0.0, b, a)]);
///     }
/// }
/// let r = run(&PointCloud::new(pts)?, &SegmentConfig::default(), &NoProgress)?;
/// assert_eq!(r.segmentation.regions.len(), 2);
/// let label = r.cloud.attribute("label").unwrap();
/// assert_ne!(label[0], label[1]);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    cloud: &PointCloud,
    config: &SegmentConfig,
    progress: &dyn Progress,
) -> Result<SegmentReport> {
    progress.stage("normals, octree cells, regions", None);
    let s = segment(cloud, config)?;
    let mut out = cloud.clone();
    out.set_attribute(
        GENERATED_LABEL,
        s.labels.iter().map(|&l| f64::from(l)).collect(),
    )?;
    out.set_attribute(
        "edge",
        s.edge.iter().map(|&e| f64::from(u8::from(e))).collect(),
    )?;
    Ok(SegmentReport {
        segmentation: s,
        cloud: out,
    })
}
