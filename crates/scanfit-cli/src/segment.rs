//! `scanfit cloud segment`: regions between sharp edges by the variation of
//! the normals ([COONS19] §I), written as an editable `label` property that
//! `scanfit reconstruct` reads back.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use scanfit::cloud::segment::{SegmentConfig, Segmentation};
use scanfit::pipeline::segment::{run as segment_cloud, SegmentReport};
use scanfit::PointCloud;
use scanfit_io::render::{render_scene_png, PointScene};
use scanfit_io::write_all_atomic;

use crate::args::{cli_message, InputArgs};
use crate::outputs::{check_outputs, print_written, Files};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit cloud segment examples/data/part_30k.ply -o part_labelled.ply --png segments.png
  scanfit cloud segment examples/data/part_30k.ply --angle 30 --min-cell 8 --json
  scanfit reconstruct part_labelled.ply --ignore 7 --step part.stp

Normals (PCA over 16 neighbours); octree cells over the points, split while
a point's normal differs from a neighbour's by more than --angle, down to
--min-cell point spacings:
the smallest cells still above it hold the edge points. Regions grow over
the 8-nearest-neighbour graph without crossing edge points; regions under
--min-region points are dissolved; every edge point goes to the region on
either side whose tangent plane passes closest. The output keeps the input's
columns and adds `label` (region id, largest region 0) and `edge` (1 on edge
points); edit `label` by hand (e.g. in CloudCompare) and give the file to
`scanfit reconstruct`. The picture colours the regions and draws edge points
dark.";

/// The thresholds of the segmentation (shared by `cloud segment` and
/// `reconstruct --segment`).
#[derive(Args, Debug, Clone)]
pub struct SegmentOptions {
    /// Angle between neighbouring points' normals (degrees) above which a
    /// cell is split; at the minimum size such a cell holds edge points.
    #[arg(long, default_value_t = 20.0, value_name = "DEG")]
    pub angle: f64,
    /// Smallest octree cell, in median point spacings.
    #[arg(long, default_value_t = 6.0, value_name = "SPACINGS")]
    pub min_cell: f64,
    /// Smallest region kept, points [default: 0.2% of the points, at least 30].
    #[arg(long, value_name = "POINTS")]
    pub min_region: Option<usize>,
}

impl SegmentOptions {
    /// The library settings these options set, with their option names
    /// (for [`crate::args::cli_message`]).
    pub const SETTINGS: [(&'static str, &'static str); 2] =
        [("max_angle_deg", "--angle"), ("min_cell", "--min-cell")];

    /// The library settings.
    pub fn config(&self) -> SegmentConfig {
        let mut c = SegmentConfig::default();
        c.max_angle_deg = self.angle;
        c.min_cell = self.min_cell;
        c.min_region = self.min_region;
        c
    }
}

/// Arguments of `scanfit cloud segment`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct SegmentArgs {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub segment: SegmentOptions,
    /// Labelled points (.ply binary, or .xyz text) with `label` and `edge`.
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Picture: regions in distinct colours, edge points dark.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    #[command(flatten)]
    pub view: crate::view::ViewArgs,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `scanfit cloud segment`.
pub fn run(a: SegmentArgs) -> Result<()> {
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["ply", "xyz"][..]),
            (&a.png, "--png", &["png"][..]),
        ],
    )?;
    let (cloud, dropped) = a.input.load_counted()?;
    let progress = Progress::spinner(a.quiet || a.json);
    let t0 = Instant::now();
    let r = segment_cloud(&cloud, &a.segment.config(), &progress)
        .map_err(|e| anyhow::anyhow!("{}", cli_message(&e, &SegmentOptions::SETTINGS)))
        .with_context(|| format!("segmenting {}", a.input.input.display()))?;
    let seconds = t0.elapsed().as_secs_f64();
    progress.finish();
    let mut files: Files = Vec::new();
    if let Some(o) = &a.output {
        files.push((o.clone(), crate::cloud::cloud_file(o, &r.cloud)?));
    }
    if let Some(p) = &a.png {
        files.push((p.clone(), picture(&a, &cloud, &r.segmentation)?));
    }
    write_all_atomic(&files)?;
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&json_report(&a, &r, seconds, dropped))?
        );
    } else {
        out!("{}", tables(&r.segmentation, cloud.len(), seconds));
        print_written(&files, None, 1.0)?;
    }
    Ok(())
}

/// Regions in distinct colours, edge points dark.
fn picture(a: &SegmentArgs, cloud: &PointCloud, s: &Segmentation) -> Result<Vec<u8>> {
    let colours: Vec<[u8; 3]> = s
        .labels
        .iter()
        .zip(&s.edge)
        .map(|(&l, &e)| {
            let c = crate::reconstruct::patch_colour(l as usize);
            if e {
                c.map(|v| v / 4)
            } else {
                c
            }
        })
        .collect();
    let mut opts = a.view.options(cloud.points())?;
    opts.legend = vec![format!(
        "{} regions (colours), {} edge points (dark)",
        s.regions.len(),
        s.edge.iter().filter(|&&e| e).count()
    )];
    let scene = PointScene {
        points: cloud.points(),
        colours: Some(&colours),
        ..Default::default()
    };
    Ok(render_scene_png(&scene, &opts)?)
}

/// The region table and the summary.
fn tables(s: &Segmentation, points: usize, seconds: f64) -> String {
    let mut t = Table::new(&["region", "points", "share (%)", "edge points"], &[]);
    for (k, r) in s.regions.iter().enumerate() {
        t.row(vec![
            k.to_string(),
            r.points.to_string(),
            format!("{:.1}", 100.0 * r.points as f64 / points as f64),
            r.edge_points.to_string(),
        ]);
    }
    let edges = s.edge.iter().filter(|&&e| e).count();
    let edge_cells = s.cells.iter().filter(|c| c.edge).count();
    format!(
        "{}\n{} regions over {points} points; {edges} edge points in {edge_cells} edge cells of side {} ({} cells in all, spacing {}); {} regions under {} points dissolved; {seconds:.2} s\n",
        t.render(),
        s.regions.len(),
        num(s.min_cell),
        s.cells.len(),
        num(s.spacing),
        s.dissolved,
        s.min_region,
    )
}

/// The report as JSON.
fn json_report(
    a: &SegmentArgs,
    r: &SegmentReport,
    seconds: f64,
    dropped: usize,
) -> serde_json::Value {
    let s = &r.segmentation;
    serde_json::json!({
        "input": a.input.input.display().to_string(),
        "points": s.labels.len(),
        "dropped_non_finite": dropped,
        "regions": s.regions.iter().enumerate().map(|(k, g)| serde_json::json!({
            "label": k, "points": g.points, "edge_points": g.edge_points,
        })).collect::<Vec<_>>(),
        "edge_points": s.edge.iter().filter(|&&e| e).count(),
        "cells": s.cells.len(),
        "edge_cells": s.cells.iter().filter(|c| c.edge).count(),
        "spacing": s.spacing,
        "min_cell": s.min_cell,
        "angle_deg": a.segment.angle,
        "min_region": s.min_region,
        "dissolved_regions": s.dissolved,
        "seconds": seconds,
    })
}
