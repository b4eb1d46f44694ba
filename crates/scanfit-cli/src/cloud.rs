//! `scanfit cloud ...`: look at and prepare point clouds: statistics,
//! normals, hidden point removal, boundary loops and corners.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use scanfit::cloud::boundary::{boundary_loops, BoundaryConfig};
use scanfit::cloud::corners::{
    corner_values, find_corners, split_at_corners, CornerConfig, CornerCriterion, Corners,
};
use scanfit::cloud::hpr::{hidden_point_removal, HprConfig};
use scanfit::cloud::normals::{estimate_normals, NormalsConfig, Orientation};
use scanfit::{Point3, PointCloud, Vector3};
use scanfit_io::render::{
    angles_facing, render_scene_png, viridis, Marker, PointScene, Polyline, RenderOptions,
};
use scanfit_io::{
    cloud_bytes, read_cloud, write_all_atomic, Format, NonFinite, ReadOptions, WriteFormat,
};

use crate::outputs::{check_extensions, extension};
use crate::progress::Progress;
use crate::table::{num, Table};

/// The `cloud` subcommands.
#[derive(Subcommand, Debug)]
pub enum CloudCommand {
    /// Count, bounding box, attributes and point spacing of a point file.
    Info(InfoArgs),
    /// Estimate oriented normals (PCA over k neighbours) and write them out.
    Normals(NormalsArgs),
    /// Keep the points visible from a viewpoint (hidden point removal).
    Hpr(HprArgs),
    /// Boundary loop of a sheet-like patch (alpha shape), its corners and sides.
    Boundary(BoundaryArgs),
}

const HPR_EXAMPLES: &str = "Examples:
  scanfit cloud hpr examples/data/blob_30k.ply --view 0,0,200 -o front.ply --png front.png
  scanfit cloud hpr scan.pcd --view 1500,0,0 --gamma 3 -o visible.ply

Hidden point removal (Katz, Tal & Basri 2007): the points are flipped about a
sphere of radius R = max|p - view| * 10^gamma centred at the viewpoint; the
points whose flips lie on the convex hull are the visible ones. A larger gamma
keeps more points (also some that are hidden); 2 suits most scans. The output
keeps the input's columns and adds `index`, the point's index in the input.";

/// Arguments of `scanfit cloud hpr`.
#[derive(Args, Debug)]
#[command(after_help = HPR_EXAMPLES)]
pub struct HprArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Viewpoint (scanner or camera position), in the units of the points.
    #[arg(long = "view", value_name = "X,Y,Z", allow_negative_numbers = true)]
    pub viewpoint: String,
    /// Flipping radius exponent: R = max distance * 10^gamma.
    #[arg(long, default_value_t = 2.0)]
    pub gamma: f64,
    /// Output: the visible points (.ply binary, or .xyz text).
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Picture of the cloud seen from the side: visible points coloured by
    /// height, hidden ones grey.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Camera azimuth and elevation of the picture [default: from the side of the view direction].
    #[arg(long = "camera", value_name = "AZ,EL", allow_negative_numbers = true)]
    pub camera: Option<String>,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

const BOUNDARY_EXAMPLES: &str = "Examples:
  scanfit cloud boundary examples/data/patch_20k.ply -o patch_boundary.json --png boundary.png
  scanfit cloud boundary patch.xyz --criterion curvature --corners 3 -o loop.ply
  scanfit cloud boundary patch.xyz --corner-at 0,120,260,400 -o loop.json

The points are projected onto their best-fit plane and triangulated (Delaunay);
triangles with a circumradius below alpha form the alpha shape, whose boundary
edges are chained into loops (outer loop counter-clockwise about the plane
normal, holes clockwise). alpha defaults to 2.5 x the median Delaunay edge.
Corners are the points of the outer loop with the smallest turning angle
(Coons paper eqs. 10-12) or the largest three-point curvature 4S/(abc) (PDE
paper 4.1), at least --min-separation of the loop length apart; the loop is
split at them into sides, each running from one corner to the next.
JSON output holds every loop, the corners and the sides (indices into the
input and coordinates); PLY/XYZ output holds the outer loop in order with the
attributes index, position, side and corner (1 at corners).";

/// Arguments of `scanfit cloud boundary`.
#[derive(Args, Debug)]
#[command(after_help = BOUNDARY_EXAMPLES)]
pub struct BoundaryArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Alpha radius in the units of the points [default: --alpha-factor x spacing].
    #[arg(long, value_name = "A")]
    pub alpha: Option<f64>,
    /// Multiple of the median Delaunay edge used as alpha.
    #[arg(long, default_value_t = 2.5, value_name = "F")]
    pub alpha_factor: f64,
    /// Number of corners (4 or 3 for Coons patches; 0 = loop only).
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub corners: usize,
    /// Corner criterion: `angle` (smallest turning angle) or `curvature` (three-point).
    #[arg(long, default_value = "angle", value_name = "C")]
    pub criterion: String,
    /// Neighbour offset m of the corner criterion [default: 1% of the loop].
    #[arg(long, value_name = "M")]
    pub corner_offset: Option<usize>,
    /// Smallest distance between corners along the loop, as a fraction of its length.
    #[arg(long, default_value_t = 0.03, value_name = "F")]
    pub min_separation: f64,
    /// Use these loop positions as the corners instead of detecting them.
    #[arg(long, value_name = "I,J,K,L")]
    pub corner_at: Option<String>,
    /// Output: the loops, corners and sides (.json), or the outer loop (.ply/.xyz).
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Picture of the patch with its boundary, sides and corners.
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
        CloudCommand::Hpr(a) => hpr(a),
        CloudCommand::Boundary(a) => boundary(a),
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
        crate::print_warnings(&table.warnings);
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
    check_extensions(&[
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
    write_all_atomic(&files)?;
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

fn parse_angles(s: &str, what: &str) -> Result<(f64, f64)> {
    let (a, e) = s
        .split_once(',')
        .with_context(|| format!("{what} needs two angles, AZ,EL"))?;
    let az: f64 = a
        .trim()
        .parse()
        .with_context(|| format!("{what} azimuth '{a}' is not a number"))?;
    let el: f64 = e
        .trim()
        .parse()
        .with_context(|| format!("{what} elevation '{e}' is not a number"))?;
    if !az.is_finite() || !(-90.0..=90.0).contains(&el) {
        bail!("{what} {s}: the elevation must lie in [-90, 90] degrees");
    }
    Ok((az, el))
}

fn hpr(a: HprArgs) -> Result<()> {
    check_extensions(&[
        (&a.output, "--output", &["ply", "xyz"][..]),
        (&a.png, "--png", &["png"][..]),
    ])?;
    let view = Point3::from(triple(&a.viewpoint, "--view")?);
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let (cloud, dropped) = a.input.load()?;
    note_dropped(dropped, a.json);
    progress.stage(format!("hidden point removal over {} points", cloud.len()));
    let t0 = Instant::now();
    let visible = hidden_point_removal(cloud.points(), &view, &HprConfig { gamma: a.gamma })
        .with_context(|| format!("hidden point removal on {}", a.input.input.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some(o) = &a.output {
        let mut out = cloud.select(&visible)?;
        out.set_attribute("index", visible.iter().map(|&i| i as f64).collect())?;
        files.push((o.clone(), cloud_file(o, &out)?));
    }
    if let Some(p) = &a.png {
        progress.stage("picture");
        let (lo, hi) = cloud.bounding_box().context("no points")?;
        let centre = Point3::from((lo.coords + hi.coords) / 2.0);
        let dir = view - centre;
        let (az, el) = match &a.camera {
            Some(c) => parse_angles(c, "--camera")?,
            // from the side: the visible cap shows as a half shell
            None => (dir.y.atan2(dir.x).to_degrees() + 90.0, 20.0),
        };
        let mut is_visible = vec![false; cloud.len()];
        for &i in &visible {
            is_visible[i] = true;
        }
        let along: Vec<f64> = cloud
            .points()
            .iter()
            .map(|p| (p - centre).dot(&dir))
            .collect();
        let (mn, mx) = along
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let colours: Vec<[u8; 3]> = (0..cloud.len())
            .map(|i| {
                if is_visible[i] {
                    viridis(((along[i] - mn) / (mx - mn).max(f64::MIN_POSITIVE)).clamp(0.0, 1.0))
                        .map(|c| (c * 255.0).round() as u8)
                } else {
                    [205, 205, 205]
                }
            })
            .collect();
        let opts = RenderOptions {
            azimuth: az,
            elevation: el,
            legend: vec![
                format!(
                    "{}: {} of {} points visible from ({}, {}, {}), gamma = {}",
                    a.input.input.display(),
                    visible.len(),
                    cloud.len(),
                    num(view.x),
                    num(view.y),
                    num(view.z),
                    a.gamma
                ),
                "visible: coloured by nearness to the viewpoint (yellow = near); hidden: grey"
                    .into(),
            ],
            ..Default::default()
        };
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
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        let report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": cloud.len(),
            "visible": visible.len(),
            "hidden": cloud.len() - visible.len(),
            "viewpoint": [view.x, view.y, view.z],
            "gamma": a.gamma,
            "seconds": secs,
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let mut t = Table::new(&["hidden point removal", "value"], &[true]);
    t.row(vec!["points".into(), cloud.len().to_string()]);
    t.row(vec!["visible".into(), visible.len().to_string()]);
    t.row(vec![
        "hidden".into(),
        (cloud.len() - visible.len()).to_string(),
    ]);
    t.row(vec![
        "viewpoint".into(),
        format!("{}, {}, {}", num(view.x), num(view.y), num(view.z)),
    ]);
    t.row(vec!["gamma".into(), a.gamma.to_string()]);
    t.row(vec!["time (s)".into(), format!("{secs:.3}")]);
    print!("{}", t.render());
    for (p, _) in &files {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// Colours of the sides of a patch (drawn over the points).
const SIDE_COLOURS: [[u8; 3]; 6] = [
    [220, 30, 30],
    [20, 150, 40],
    [30, 60, 220],
    [230, 130, 0],
    [160, 30, 180],
    [0, 160, 170],
];

fn boundary(a: BoundaryArgs) -> Result<()> {
    check_extensions(&[
        (&a.output, "--output", &["json", "ply", "xyz"][..]),
        (&a.png, "--png", &["png"][..]),
    ])?;
    let criterion = match a.criterion.as_str() {
        "angle" => CornerCriterion::TurningAngle,
        "curvature" => CornerCriterion::ThreePointCurvature,
        c => bail!("unknown --criterion '{c}'; use angle or curvature"),
    };
    let user_corners: Option<Vec<usize>> = match &a.corner_at {
        None => None,
        Some(s) => Some(
            s.split(',')
                .map(|x| x.trim().parse::<usize>())
                .collect::<std::result::Result<_, _>>()
                .with_context(|| {
                    format!("--corner-at '{s}' must be loop positions I,J,K,...  (whole numbers)")
                })?,
        ),
    };
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let (cloud, dropped) = a.input.load()?;
    note_dropped(dropped, a.json);
    progress.stage(format!("alpha shape of {} points", cloud.len()));
    let t0 = Instant::now();
    let b = boundary_loops(
        cloud.points(),
        &BoundaryConfig {
            alpha: a.alpha,
            alpha_factor: a.alpha_factor,
        },
    )
    .with_context(|| format!("boundary of {}", a.input.input.display()))?;
    let outer = b.outer_loop().to_vec();
    let loop_points: Vec<Point3> = outer.iter().map(|&i| cloud.points()[i]).collect();
    progress.stage("corners");
    let corners: Option<Corners> = match (&user_corners, a.corners) {
        (Some(c), _) => {
            let sides = split_at_corners(outer.len(), c).context("--corner-at")?;
            let values = corner_values(
                &loop_points,
                criterion,
                a.corner_offset
                    .unwrap_or_else(|| (outer.len() as f64 / 100.0).round().max(1.0) as usize),
            )?;
            Some(Corners {
                corners: c.clone(),
                sides,
                values,
                offset: a.corner_offset.unwrap_or(0),
            })
        }
        (None, 0) => None,
        (None, count) => Some(
            find_corners(
                &loop_points,
                &CornerConfig {
                    criterion,
                    count,
                    offset: a.corner_offset,
                    min_separation: a.min_separation,
                },
            )
            .with_context(|| format!("corners of the outer loop ({} points)", outer.len()))?,
        ),
    };
    let secs = t0.elapsed().as_secs_f64();
    let corner_value = |v: f64| match criterion {
        CornerCriterion::TurningAngle => v.to_degrees(),
        CornerCriterion::ThreePointCurvature => v,
    };
    let value_name = match criterion {
        CornerCriterion::TurningAngle => "angle_degrees",
        CornerCriterion::ThreePointCurvature => "curvature",
    };
    let pt = |i: usize| {
        let p = cloud.points()[i];
        [p.x, p.y, p.z]
    };
    let doc = serde_json::json!({
        "schema": "scanfit-boundary/1",
        "file": a.input.input.display().to_string(),
        "points": cloud.len(),
        "alpha": b.alpha,
        "spacing": b.spacing,
        "plane": {
            "origin": [b.plane.origin.x, b.plane.origin.y, b.plane.origin.z],
            "normal": [b.plane.normal.x, b.plane.normal.y, b.plane.normal.z],
        },
        "outer": b.outer,
        "loops": b.loops.iter().zip(&b.areas).map(|(l, area)| serde_json::json!({
            "indices": l,
            "area": area,
            "points": l.iter().map(|&i| pt(i)).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "corners": corners.as_ref().map(|c| c.corners.iter().map(|&k| serde_json::json!({
            "position": k,
            "index": outer[k],
            "point": pt(outer[k]),
            value_name: corner_value(c.values[k]),
        })).collect::<Vec<_>>()),
        "sides": corners.as_ref().map(|c| c.sides.iter().map(|s| s.iter().map(|&k| outer[k]).collect::<Vec<_>>()).collect::<Vec<_>>()),
        "seconds": secs,
    });
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some(o) = &a.output {
        if extension(o) == "json" {
            files.push((o.clone(), serde_json::to_string_pretty(&doc)?.into_bytes()));
        } else {
            let mut out = PointCloud::new(loop_points.clone())?;
            let n = outer.len();
            let mut side = vec![-1.0; n];
            let mut corner = vec![0.0; n];
            if let Some(c) = &corners {
                for (k, s) in c.sides.iter().enumerate() {
                    // a corner belongs to the side it starts
                    for &q in s.iter().rev() {
                        side[q] = k as f64;
                    }
                }
                for (k, &q) in c.corners.iter().enumerate() {
                    corner[q] = 1.0;
                    side[q] = k as f64;
                }
            }
            out.set_attribute("index", outer.iter().map(|&i| i as f64).collect())?;
            out.set_attribute("position", (0..n).map(|k| k as f64).collect())?;
            out.set_attribute("side", side)?;
            out.set_attribute("corner", corner)?;
            files.push((o.clone(), cloud_file(o, &out)?));
        }
    }
    if let Some(p) = &a.png {
        progress.stage("picture");
        let mut opts = a
            .view
            .options_or(cloud.points(), angles_facing(&b.plane.normal))?;
        opts.legend = vec![
            format!(
                "{}: {} points, {} boundary loop(s), outer loop {} points, alpha = {}",
                a.input.input.display(),
                cloud.len(),
                b.loops.len(),
                outer.len(),
                num(b.alpha)
            ),
            match &corners {
                Some(c) => format!(
                    "{} corners by {} (C0..), sides in colour from each corner to the next",
                    c.corners.len(),
                    a.criterion
                ),
                None => "outer loop red, holes purple".into(),
            },
        ];
        let pts: Vec<[u8; 3]> = vec![[150, 150, 150]; cloud.len()];
        let mut polylines = Vec::new();
        for (li, l) in b.loops.iter().enumerate() {
            if li != b.outer {
                polylines.push(Polyline {
                    points: l.iter().map(|&i| cloud.points()[i]).collect(),
                    rgb: [160, 30, 180],
                    closed: true,
                });
            }
        }
        let mut markers = Vec::new();
        match &corners {
            Some(c) => {
                for (k, s) in c.sides.iter().enumerate() {
                    polylines.push(Polyline {
                        points: s.iter().map(|&q| loop_points[q]).collect(),
                        rgb: SIDE_COLOURS[k % SIDE_COLOURS.len()],
                        closed: false,
                    });
                }
                for (k, &q) in c.corners.iter().enumerate() {
                    markers.push(Marker {
                        at: loop_points[q],
                        rgb: [255, 255, 255],
                        label: format!("C{k}"),
                    });
                }
            }
            None => polylines.push(Polyline {
                points: loop_points.clone(),
                rgb: [220, 30, 30],
                closed: true,
            }),
        }
        let png = render_scene_png(
            &PointScene {
                points: cloud.points(),
                colours: Some(&pts),
                polylines,
                markers,
            },
            &opts,
        )?;
        files.push((p.clone(), png));
    }
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(());
    }
    let mut t = Table::new(&["boundary", "value"], &[true]);
    t.row(vec!["points".into(), cloud.len().to_string()]);
    t.row(vec![
        "point spacing (median Delaunay edge)".into(),
        num(b.spacing),
    ]);
    t.row(vec!["alpha".into(), num(b.alpha)]);
    t.row(vec!["loops".into(), b.loops.len().to_string()]);
    t.row(vec!["outer loop points".into(), outer.len().to_string()]);
    t.row(vec![
        "outer loop area (in the plane)".into(),
        num(b.areas[b.outer].abs()),
    ]);
    t.row(vec!["time (s)".into(), format!("{secs:.3}")]);
    print!("{}", t.render());
    if let Some(c) = &corners {
        println!();
        let head = match criterion {
            CornerCriterion::TurningAngle => "angle (deg)",
            CornerCriterion::ThreePointCurvature => "curvature (1/unit)",
        };
        let mut t = Table::new(
            &[
                "corner",
                "loop position",
                "point index",
                "x",
                "y",
                "z",
                head,
                "side points",
            ],
            &[true],
        );
        for (k, &q) in c.corners.iter().enumerate() {
            let p = loop_points[q];
            t.row(vec![
                format!("C{k}"),
                q.to_string(),
                outer[q].to_string(),
                num(p.x),
                num(p.y),
                num(p.z),
                num(corner_value(c.values[q])),
                c.sides[k].len().to_string(),
            ]);
        }
        print!("{}", t.render());
    }
    for (p, _) in &files {
        println!("wrote {}", p.display());
    }
    Ok(())
}
