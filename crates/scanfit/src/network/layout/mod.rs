//! Patch labels without hand labelling (issue 16): where the patch ids of
//! the multi-patch pipeline come from when the cloud carries none.
//!
//! * [`LabelSource::Attribute`]: the cloud's own label attribute (hand
//!   labels, or `scanfit cloud segment`'s output edited by hand).
//! * [`LabelSource::Segment`]: regions between sharp edges
//!   ([`crate::cloud::segment`], [COONS19] §I).
//! * [`LabelSource::Layout`]: a layout for a smooth object ([`cube`]).
//!
//! Every source ends as one integer id per point in the attribute
//! [`GENERATED_LABEL`], read by the same [`super::read_labels`] as hand
//! labels: nothing downstream knows where the ids came from.

pub mod cube;

use crate::cloud::segment::{segment, SegmentConfig};
use crate::progress::Progress;
use crate::{PointCloud, Result};

/// The attribute the generated labels are written to (replacing any the
/// cloud had).
pub const GENERATED_LABEL: &str = "label";

/// A layout for a smooth object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Layout {
    /// Six four-sided patches by central projection onto a box
    /// ([`cube::cube_labels`]); for closed star-shaped objects.
    Cube,
}

/// Where the patch ids come from.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub enum LabelSource {
    /// The cloud's label attribute (default).
    #[default]
    Attribute,
    /// Segmentation by normal variation.
    Segment(SegmentConfig),
    /// A layout for a smooth object.
    Layout(Layout),
}

/// The patch id of every point from `source`, or `None` for
/// [`LabelSource::Attribute`] (the cloud's own labels are used as they are).
///
/// ```
/// use scanfit::network::layout::{generate_labels, LabelSource, Layout};
/// use scanfit::progress::NoProgress;
/// use scanfit::{Point3, PointCloud};
/// let n = 3000;
/// let pts = (0..n).map(|i| {
///     let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
///     let (a, r) = (i as f64 * 2.399963229728653, (1.0 - z * z).sqrt());
///     Point3::new(r * a.cos(), r * a.sin(), z)
/// }).collect();
/// let cloud = PointCloud::new(pts)?;
/// let ids = generate_labels(&cloud, &LabelSource::Layout(Layout::Cube), &NoProgress)?.unwrap();
/// assert_eq!(ids.iter().max(), Some(&5));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn generate_labels(
    cloud: &PointCloud,
    source: &LabelSource,
    progress: &dyn Progress,
) -> Result<Option<Vec<i64>>> {
    match source {
        LabelSource::Attribute => Ok(None),
        LabelSource::Segment(cfg) => {
            progress.stage("segmentation by normal variation", None);
            let s = segment(cloud, cfg)?;
            Ok(Some(s.labels.iter().map(|&l| i64::from(l)).collect()))
        }
        LabelSource::Layout(Layout::Cube) => {
            progress.stage("cube layout", None);
            let spacing = cloud.spacing()?.median;
            Ok(Some(cube::cube_labels(cloud, spacing)?.labels))
        }
    }
}
