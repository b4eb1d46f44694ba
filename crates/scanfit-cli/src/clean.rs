//! `scanfit cloud clean`: crops, statistical outliers, small fragments and
//! voxel thinning ([`scanfit::pipeline::cloud::clean`]); this file parses,
//! reads, calls, prints and writes.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::cloud::clean::OutlierConfig;
use scanfit::pipeline::cloud::{clean, CloudClean, CloudCleanConfig, FragmentConfig, VoxelSize};
use scanfit::Point3;
use scanfit_io::write_all_atomic;

use crate::args::{InputArgs, BOX, SPHERE};
use crate::cloud::cloud_file;
use crate::outputs::check_outputs;
use crate::progress::Progress;
use crate::table::{num, Table};

const CLEAN_EXAMPLES: &str = "Examples:
  scanfit cloud clean examples/data/patch_20k.ply --outliers -o clean.ply
  scanfit cloud clean scan.stl --outliers --fragments --voxel-spacings 2 -o thin.ply
  scanfit cloud clean terrain.xyz --box -10,-10,-5,10,10,5 --json -o crop.xyz

The steps run in the order crop box, crop sphere, outliers, fragments,
voxels; each says how many points it removed. Every attribute of the kept
points is kept (voxel thinning keeps, per cell, the point nearest the cell's
centroid, never an average).";

/// Arguments of `scanfit cloud clean`.
#[derive(Args, Debug)]
#[command(after_help = CLEAN_EXAMPLES)]
pub struct CleanArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Output points (.ply binary, or .xyz text), with all attributes.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Statistical outlier removal: mean distance to --k neighbours above
    /// mean + --sigma standard deviations (PCL's rule) and above twice the median.
    #[arg(long)]
    pub outliers: bool,
    /// Neighbours of the outlier statistics.
    #[arg(long, default_value_t = 50, value_name = "K")]
    pub k: usize,
    /// Standard deviations above the mean of the outlier threshold.
    #[arg(long, default_value_t = 1.0, value_name = "N")]
    pub sigma: f64,
    /// Remove small fragments: connected parts (points closer than
    /// --fragment-radius spacings joined) smaller than --min-fragment.
    #[arg(long)]
    pub fragments: bool,
    /// Joining radius of the fragments, in median point spacings.
    #[arg(long, default_value_t = 3.0, value_name = "F")]
    pub fragment_radius: f64,
    /// Fragments with fewer points are removed (default 1% of the points, at least 10).
    #[arg(long, value_name = "N")]
    pub min_fragment: Option<usize>,
    /// Keep the points inside this box.
    #[arg(long = "box", value_name = "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX", allow_hyphen_values = true, value_parser = BOX)]
    pub crop_box: Option<[f64; 6]>,
    /// Keep the points inside this sphere.
    #[arg(long, value_name = "X,Y,Z,R", allow_hyphen_values = true, value_parser = SPHERE)]
    pub sphere: Option<[f64; 4]>,
    /// Voxel thinning: one point per cube of this edge (units of the points).
    #[arg(long, value_name = "SIZE", conflicts_with = "voxel_spacings")]
    pub voxel: Option<f64>,
    /// Voxel thinning with the cube edge in median point spacings (2 keeps
    /// about a quarter of an evenly sampled surface).
    #[arg(long, value_name = "F")]
    pub voxel_spacings: Option<f64>,
    /// Print the report as JSON on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

impl CleanArgs {
    /// The library's settings for these options.
    fn config(&self) -> Result<CloudCleanConfig> {
        let mut cfg = CloudCleanConfig::default();
        cfg.crop_box = self
            .crop_box
            .map(|b| (Point3::new(b[0], b[1], b[2]), Point3::new(b[3], b[4], b[5])));
        cfg.crop_sphere = self.sphere.map(|s| (Point3::new(s[0], s[1], s[2]), s[3]));
        if self.outliers {
            cfg.outliers = Some(OutlierConfig {
                k: self.k,
                n_sigma: self.sigma,
                ..OutlierConfig::default()
            });
        }
        if self.fragments {
            let mut f = FragmentConfig::default();
            f.radius_spacings = self.fragment_radius;
            f.min_size = self.min_fragment;
            cfg.fragments = Some(f);
        }
        cfg.voxel = match (self.voxel, self.voxel_spacings) {
            (Some(s), _) => Some(VoxelSize::Absolute(s)),
            (None, Some(f)) => Some(VoxelSize::Spacings(f)),
            (None, None) => None,
        };
        if cfg == CloudCleanConfig::default() {
            bail!("nothing to do: give --outliers, --fragments, --box, --sphere, --voxel or --voxel-spacings");
        }
        Ok(cfg)
    }
}

/// Runs `scanfit cloud clean`.
pub fn run(a: CleanArgs) -> Result<()> {
    let out = Some(a.output.clone());
    check_outputs(
        &[&a.input.input],
        &[(&out, "--output", &["ply", "xyz"][..])],
    )?;
    let cfg = a.config()?;
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let cloud = a.input.load(a.json)?;
    let r = clean(&cloud, &cfg, &progress)
        .with_context(|| format!("cleaning {}", a.input.input.display()))?;
    let files = vec![(a.output.clone(), cloud_file(&a.output, &r.cloud)?)];
    write_all_atomic(&files)?;
    progress.finish();
    print_clean(&a, cloud.len(), &r)
}

/// The report: JSON or a table of the steps, then the file written.
fn print_clean(a: &CleanArgs, input: usize, r: &CloudClean) -> Result<()> {
    if a.json {
        let steps: Vec<_> = r
            .steps
            .iter()
            .map(|s| {
                serde_json::json!({
                    "operation": s.operation,
                    "before": s.before,
                    "removed": s.removed,
                    "detail": s.detail,
                })
            })
            .collect();
        let report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": input,
            "kept": r.cloud.len(),
            "removed": input - r.cloud.len(),
            "steps": steps,
            "output": a.output.display().to_string(),
        });
        outln!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let mut t = Table::new(
        &["step", "points before", "removed", "removed %", "detail"],
        &[true, false, false, false, true],
    );
    for s in &r.steps {
        t.row(vec![
            s.operation.into(),
            s.before.to_string(),
            s.removed.to_string(),
            num(100.0 * s.removed as f64 / s.before.max(1) as f64),
            s.detail.clone(),
        ]);
    }
    out!("{}", t.render());
    outln!(
        "kept {} of {} points; wrote {}",
        r.cloud.len(),
        input,
        a.output.display()
    );
    Ok(())
}
