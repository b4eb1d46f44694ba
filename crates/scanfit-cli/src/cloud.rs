//! `scanfit cloud ...`: look at and prepare point clouds: statistics,
//! normals, hidden point removal, boundary loops and corners.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use scanfit::cloud::normals::{estimate_normals, NormalsConfig, Orientation};
use scanfit::{Point3, PointCloud, Vector3};
use scanfit_io::render::{render_scene_png, PointScene, RenderOptions};
use scanfit_io::{
    cloud_bytes, read_cloud, write_all_atomic, Format, NonFinite, ReadOptions, WriteFormat,
};

use crate::progress::Progress;
use crate::table::{num, Table};

/// The `cloud` subcommands.
#[derive(Subcommand, Debug)]
pub enum CloudCommand {
    /// Count, bounding box, attributes and point spacing of a point file.
    Info(InfoArgs),
    /// Estimate oriented normals (PCA over k neighbours) and write them out.
    Normals(NormalsArgs),
}

const INFO_EXAMPLES: &str = "Examples:
  scanfit cloud info examples/data/terrain_50k.xyz
  scanfit cloud info scan.ply --json

Spacing is the distance of each point to its nearest other point (KD-tree).";

/// Arguments of `scanfit cloud info`.
#[derive(Args, Debug)]
#[command(after_help = INFO_EXAMPLES)]
pub struct InfoArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
}

const NORMALS_EXAMPLES: &str = "Examples:
  scanfit cloud normals examples/data/terrain_50k.xyz -o terrain_normals.ply --png normals.png
  scanfit cloud normals scan.ply --k 24 --orient view:0,0,1000 -o scan_normals.ply

Normals are the smallest principal axis of each point's k nearest neighbours.
--orient mst propagates one orientation over a minimum spanning tree of the
neighbour graph (Hoppe 1992), starting at the extreme point along --hint;
--orient view:X,Y,Z turns every normal towards a scanner position. The
output keeps the input's columns and adds nx, ny, nz and `variation`
(0 on a plane, up to 1/3 at edges and noise). The picture shades every point
by its normal: wrongly oriented normals show as dark speckles.";

/// Arguments of `scanfit cloud normals`.
#[derive(Args, Debug)]
#[command(after_help = NORMALS_EXAMPLES)]
pub struct NormalsArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Neighbours per point.
    #[arg(long, default_value_t = 16)]
    pub k: usize,
    /// Orientation: `mst`, `view:X,Y,Z` or `none`.
    #[arg(long, default_value = "mst", value_name = "HOW")]
    pub orient: String,
    /// Direction the seed normal of each connected part points along (with --orient mst).
    #[arg(
        long,
        default_value = "0,0,1",
        value_name = "X,Y,Z",
        allow_negative_numbers = true
    )]
    pub hint: String,
    /// Output points with normals (.ply binary, or .xyz text).
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Picture of the points shaded by their normals.
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

/// Runs a `cloud` subcommand.
pub fn run(c: CloudCommand) -> Result<()> {
    match c {
        CloudCommand::Info(a) => info(a),
        CloudCommand::Normals(a) => normals(a),
    }
}

/// The input file of a `cloud` command and how to read it.
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Input point file (.ply, .pcd, .las/.laz, .xyz/.csv/.txt/.pts/.asc).
    pub input: PathBuf,
    /// Read as this format whatever the extension: ply, pcd, las, text.
    #[arg(long, value_name = "FORMAT")]
    pub format: Option<String>,
    /// Drop points with NaN or infinite coordinates (and report how many)
    /// instead of stopping at the first one.
    #[arg(long)]
    pub drop_non_finite: bool,
}

impl InputArgs {
    /// Reads the file into a cloud that keeps every extra column as an
    /// attribute; returns it with the number of non-finite points dropped.
    pub fn load(&self) -> Result<(PointCloud, usize)> {
        let format = match self
            .format
            .as_deref()
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            None => None,
            Some("ply") => Some(Format::Ply),
            Some("pcd") => Some(Format::Pcd),
            Some("las") | Some("laz") => Some(Format::Las),
            Some("text") | Some("xyz") | Some("csv") | Some("txt") => Some(Format::Text),
            Some(f) => bail!("unknown --format '{f}'; use ply, pcd, las or text"),
        };
        let options = ReadOptions {
            format,
            non_finite: if self.drop_non_finite {
                NonFinite::Drop
            } else {
                NonFinite::Reject
            },
        };
        let table = read_cloud(&self.input, &options)?;
        let dropped = table.dropped_non_finite;
        Ok((table.into_cloud()?, dropped))
    }
}

/// Parses "X,Y,Z".
pub fn triple(s: &str, what: &str) -> Result<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .with_context(|| format!("{what} '{s}' must be three numbers X,Y,Z"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([x, y, z]),
        _ => bail!("{what} '{s}' must be three finite numbers X,Y,Z"),
    }
}

fn extension(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Checks output extensions before any work is done.
pub fn check_outputs(outputs: &[(&Option<PathBuf>, &str, &[&str])]) -> Result<()> {
    for (p, what, allowed) in outputs {
        if let Some(p) = p {
            let e = extension(p);
            if !allowed.contains(&e.as_str()) {
                bail!(
                    "{what} {}: unsupported extension '.{e}'; use {}",
                    p.display(),
                    allowed
                        .iter()
                        .map(|a| format!(".{a}"))
                        .collect::<Vec<_>>()
                        .join(" or ")
                );
            }
        }
    }
    Ok(())
}

/// The bytes of `cloud` with all its attributes as binary PLY or XYZ text, by extension.
pub fn cloud_file(path: &Path, cloud: &PointCloud) -> Result<Vec<u8>> {
    let format = WriteFormat::from_path(path)
        .with_context(|| format!("{}: write points as .ply or .xyz", path.display()))?;
    Ok(cloud_bytes(cloud, format))
}

/// Tells on stderr how many non-finite points were dropped (unless JSON is printed).
fn note_dropped(dropped: usize, json: bool) {
    if dropped > 0 && !json {
        eprintln!("note: {dropped} points with NaN or infinite coordinates dropped");
    }
}

fn info(a: InfoArgs) -> Result<()> {
    let t0 = Instant::now();
    let (cloud, dropped) = a.input.load()?;
    let read_s = t0.elapsed().as_secs_f64();
    let (lo, hi) = cloud
        .bounding_box()
        .with_context(|| format!("{}: no points", a.input.input.display()))?;
    let spacing = if cloud.len() >= 2 {
        Some(cloud.spacing()?)
    } else {
        None
    };
    let attrs: Vec<(String, f64, f64)> = cloud
        .attributes()
        .iter()
        .map(|at| {
            let (mn, mx) = at
                .values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            (at.name.clone(), mn, mx)
        })
        .collect();
    if a.json {
        let report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": cloud.len(),
            "dropped_non_finite": dropped,
            "bbox_min": [lo.x, lo.y, lo.z],
            "bbox_max": [hi.x, hi.y, hi.z],
            "diagonal": (hi - lo).norm(),
            "attributes": attrs.iter().map(|(n, mn, mx)| serde_json::json!({"name": n, "min": mn, "max": mx})).collect::<Vec<_>>(),
            "spacing": spacing.map(|s| serde_json::json!({"min": s.min, "median": s.median, "mean": s.mean, "max": s.max, "duplicates": s.duplicates})),
            "read_seconds": read_s,
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "{}: {} points (read in {:.3} s)\n",
        a.input.input.display(),
        cloud.len(),
        read_s
    );
    let mut t = Table::new(&["axis", "min", "max", "size"], &[true]);
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        t.row(vec![
            name.to_string(),
            num(lo[k]),
            num(hi[k]),
            num(hi[k] - lo[k]),
        ]);
    }
    print!("{}", t.render());
    println!("bounding-box diagonal {}\n", num((hi - lo).norm()));
    if !attrs.is_empty() {
        let mut t = Table::new(&["attribute", "min", "max"], &[true]);
        for (n, mn, mx) in &attrs {
            t.row(vec![n.clone(), num(*mn), num(*mx)]);
        }
        print!("{}", t.render());
        println!();
    }
    if let Some(s) = spacing {
        let mut t = Table::new(&["nearest-neighbour distance", "value"], &[true]);
        for (n, v) in [
            ("min", s.min),
            ("median", s.median),
            ("mean", s.mean),
            ("max", s.max),
        ] {
            t.row(vec![n.to_string(), num(v)]);
        }
        print!("{}", t.render());
        if s.duplicates > 0 {
            println!("{} points coincide with another point", s.duplicates);
        }
    }
    Ok(())
}

/// Colours that shade each point by its normal against a light from the
/// camera side: normals towards the camera are shaded orange, normals facing
/// away blue, so a consistent orientation gives one smooth colour and flipped
/// normals stand out. `z_scale` is the picture's vertical exaggeration (the
/// normals of the exaggerated shape are `(nx, ny, nz / z_scale)`).
fn normal_shading(normals: &[Vector3], opts: &RenderOptions) -> Vec<[u8; 3]> {
    let (az, el) = (opts.azimuth.to_radians(), opts.elevation.to_radians());
    let d = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let light = (d + Vector3::new(0.0, 0.0, 0.5)).normalize();
    let zs = opts.z_scale;
    normals
        .iter()
        .map(|n| {
            let m = Vector3::new(n.x, n.y, n.z / zs);
            let m = m / m.norm().max(f64::MIN_POSITIVE);
            let l = m.dot(&light);
            let (v, base) = if m.dot(&d) >= 0.0 {
                (0.25 + 0.75 * l.abs(), [235.0, 165.0, 70.0])
            } else {
                (0.35 + 0.65 * l.abs(), [50.0, 80.0, 220.0])
            };
            base.map(|c: f64| (c * v).round() as u8)
        })
        .collect()
}

fn normals(a: NormalsArgs) -> Result<()> {
    check_outputs(&[
        (&a.output, "--output", &["ply", "xyz"][..]),
        (&a.png, "--png", &["png"][..]),
    ])?;
    let orientation = match a.orient.as_str() {
        "mst" => Orientation::SpanningTree {
            hint: Vector3::from(triple(&a.hint, "--hint")?),
        },
        "none" => Orientation::None,
        v if v.starts_with("view:") => {
            Orientation::Viewpoint(Point3::from(triple(&v[5..], "--orient view:")?))
        }
        o => bail!("unknown --orient '{o}'; use mst, view:X,Y,Z or none"),
    };
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let (mut cloud, dropped) = a.input.load()?;
    note_dropped(dropped, a.json);
    progress.stage(format!("normals of {} points", cloud.len()));
    let t0 = Instant::now();
    let r = estimate_normals(
        &cloud,
        &NormalsConfig {
            k: a.k,
            orientation,
        },
    )
    .with_context(|| format!("normals of {}", a.input.input.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    cloud.set_normals(&r.normals)?;
    cloud.set_attribute("variation", r.variation.clone())?;
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some(o) = &a.output {
        files.push((o.clone(), cloud_file(o, &cloud)?));
    }
    if let Some(p) = &a.png {
        progress.stage("picture");
        let mut opts = a.view.options(cloud.points())?;
        opts.legend = vec![
            format!(
                "{}: normals of {} points, k = {}, orientation {}",
                a.input.input.display(),
                cloud.len(),
                a.k,
                a.orient
            ),
            "orange = normal towards the camera (shaded by the light), blue = normal facing away"
                .into(),
        ];
        let colours = normal_shading(&r.normals, &opts);
        let png = render_scene_png(
            &PointScene {
                points: cloud.points(),
                colours: Some(&colours),
                ..Default::default()
            },
            &opts,
        )?;
        files.push((p.clone(), png));
    }
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    write_all_atomic(&refs)?;
    progress.finish();
    let mean_var = r.variation.iter().sum::<f64>() / r.variation.len().max(1) as f64;
    if a.json {
        let report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": cloud.len(),
            "k": a.k,
            "orientation": a.orient,
            "components": r.components,
            "degenerate": r.degenerate.len(),
            "mean_variation": mean_var,
            "seconds": secs,
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let mut t = Table::new(&["normals", "value"], &[true]);
    t.row(vec!["points".into(), cloud.len().to_string()]);
    t.row(vec!["neighbours k".into(), a.k.to_string()]);
    t.row(vec!["orientation".into(), a.orient.clone()]);
    t.row(vec!["connected parts".into(), r.components.to_string()]);
    t.row(vec![
        "degenerate neighbourhoods".into(),
        r.degenerate.len().to_string(),
    ]);
    t.row(vec!["mean surface variation".into(), num(mean_var)]);
    t.row(vec!["time (s)".into(), format!("{secs:.3}")]);
    print!("{}", t.render());
    for (p, _) in &files {
        println!("wrote {}", p.display());
    }
    Ok(())
}
