//! Patch labels without hand labelling (issue 16): where the patch ids of
//! the multi-patch pipeline come from when the cloud carries none.
//!
//! * [`LabelSource::Attribute`]: the cloud's own label attribute (hand
//!   labels, or `scanfit cloud segment`'s output edited by hand).
//! * [`LabelSource::Segment`]: regions between sharp edges
//!   ([`crate::cloud::segment`], [COONS19] §I).
//! * [`LabelSource::Layout`]: a layout for a smooth object ([`cube`],
//!   [`grid`], [`revolve`]).
//!
//! Every source ends as one integer id per point in the attribute
//! [`GENERATED_LABEL`], read by the same [`super::read_labels`] as hand
//! labels: nothing downstream knows where the ids came from.

pub mod cube;
pub mod grid;
pub mod grid_frame;
pub mod revolve;

pub use grid_frame::GridOptions;

use crate::base::turntable::AxisChoice;
use crate::cloud::segment::{segment, SegmentConfig};
use crate::progress::Progress;
use crate::{PointCloud, Result};

/// The attribute the generated labels are written to (replacing any the
/// cloud had).
pub const GENERATED_LABEL: &str = "label";

/// A layout for a smooth object.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Layout {
    /// Six four-sided patches by central projection onto a box
    /// ([`cube::cube_labels`]); for closed star-shaped objects.
    Cube,
    /// A sheet cut along iso-parameter lines of its Coons base into
    /// `rows x cols` patches ([`grid::grid_labels`]), its edges and control
    /// nets as `options` say ([`grid_frame`]).
    Grid {
        /// Patches along the base's `u`.
        rows: usize,
        /// Patches along the base's `v`.
        cols: usize,
        /// Cuts, edge curves and control nets.
        options: GridOptions,
    },
    /// A cylinder-like object cut into `sectors x bands` patches about its
    /// axis, each closed end into `sectors` three-sided caps
    /// ([`revolve::revolve_labels`]).
    Revolve {
        /// Angle ranges about the axis (at least 3).
        sectors: usize,
        /// Height ranges along the axis between the caps (or open ends).
        bands: usize,
        /// The axis (the turntable's choice; default the principal axis).
        axis: AxisChoice,
    },
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

/// Labels made by a segmentation or a layout.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedLabels {
    /// The patch id of every point.
    pub labels: Vec<i64>,
    /// One line on what was found (regions, the axis and ends of a revolve
    /// layout, ...), for the report.
    pub summary: String,
    /// The grid layout's cuts, parameters and detail (grid layouts only).
    pub grid: Option<(grid::GridLayout, GridOptions)>,
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
/// assert_eq!(ids.labels.iter().max(), Some(&5));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn generate_labels(
    cloud: &PointCloud,
    source: &LabelSource,
    progress: &dyn Progress,
) -> Result<Option<GeneratedLabels>> {
    match source {
        LabelSource::Attribute => Ok(None),
        LabelSource::Segment(cfg) => {
            progress.stage("segmentation by normal variation", None);
            let s = segment(cloud, cfg)?;
            Ok(Some(GeneratedLabels {
                labels: s.labels.iter().map(|&l| i64::from(l)).collect(),
                summary: format!(
                    "segmentation: {} regions between sharp edges",
                    s.regions.len()
                ),
                grid: None,
            }))
        }
        LabelSource::Layout(layout) => {
            let spacing = cloud.spacing()?.median;
            let mut grid = None;
            let (labels, summary) = match *layout {
                Layout::Cube => {
                    progress.stage("cube layout", None);
                    let c = cube::cube_labels(cloud, spacing)?;
                    (
                        c.labels,
                        "cube: 6 four-sided patches by central projection".into(),
                    )
                }
                Layout::Grid {
                    rows,
                    cols,
                    options,
                } => {
                    progress.stage("grid layout (Coons base)", None);
                    let g = grid::grid_labels(cloud, rows, cols, spacing)?;
                    let summary = format!(
                        "grid {rows}x{cols} along iso-lines of the sheet's Coons base; {} patches",
                        rows * cols
                    );
                    let labels = g.labels.clone();
                    grid = Some((g, options));
                    (labels, summary)
                }
                Layout::Revolve {
                    sectors,
                    bands,
                    axis,
                } => {
                    progress.stage("revolve layout", None);
                    let r = revolve::revolve_labels(cloud, sectors, bands, axis, spacing)?;
                    let summary = r.summary(sectors);
                    (r.labels, summary)
                }
            };
            Ok(Some(GeneratedLabels {
                labels,
                summary,
                grid,
            }))
        }
    }
}
