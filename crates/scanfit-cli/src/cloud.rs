//! `scanfit cloud ...`: look at and prepare point clouds: statistics,
//! normals, hidden point removal, boundary loops and corners. The tools are
//! [`scanfit::pipeline::cloud`]; this file parses, reads, calls, prints and
//! writes.

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use scanfit::cloud::corners::CornerCriterion;
use scanfit::cloud::normals::Orientation;
use scanfit::pipeline::cloud::{
    boundary as find_boundary, hpr as remove_hidden, info as cloud_info, normals as estimate,
    CloudBoundary, CloudBoundaryConfig, CloudHpr, CloudHprConfig, CloudInfo, CloudInfoConfig,
    CloudNormalsConfig,
};
use scanfit::{Point3, PointCloud, Vector3};
use scanfit_io::render::{
    render_scene_png, viridis, Camera, Marker, PointScene, Polyline, RenderOptions,
};
use scanfit_io::{cloud_bytes, write_all_atomic, WriteFormat};

pub use crate::args::InputArgs;
use crate::args::{choice, cli_message, value_name, Indices, Parsed, INDICES, VECTOR3};
use crate::outputs::{check_outputs, extension, Files};
use crate::progress::Progress;
use crate::table::{num, Table};
use crate::view::DefaultView;

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
    /// Remove stray points and fragments, crop, thin; report what each step removed.
    Clean(crate::clean::CleanArgs),
    /// Regions between sharp edges (normal variation, octree cells) as a `label` property.
    Segment(crate::segment::SegmentArgs),
}

/// `--criterion`: the corner measure (`cloud boundary`, `coons`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CriterionArg {
    /// Smallest turning angle (Coons paper eqs. 10-12).
    Angle,
    /// Largest three-point curvature 4S/(abc) (PDE paper 4.1).
    Curvature,
}

impl From<CriterionArg> for CornerCriterion {
    fn from(c: CriterionArg) -> Self {
        match c {
            CriterionArg::Angle => Self::TurningAngle,
            CriterionArg::Curvature => Self::ThreePointCurvature,
        }
    }
}

/// `--orient`: how normals get their sign.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrientArg {
    /// Spanning-tree propagation from the seed along `--hint`.
    Mst,
    /// Every normal towards this viewpoint.
    View(Point3),
    /// The eigen solver's signs.
    None,
}

impl fmt::Display for OrientArg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Mst => write!(f, "mst"),
            Self::View(p) => write!(f, "view:{},{},{}", p.x, p.y, p.z),
            Self::None => write!(f, "none"),
        }
    }
}

/// `"mst"`, `"none"` or `"view:X,Y,Z"` ([`OrientArg`]).
pub const ORIENT: Parsed<OrientArg> = Parsed::new(orient);

fn orient(s: &str, what: &str) -> std::result::Result<OrientArg, String> {
    match s.trim() {
        "mst" => Ok(OrientArg::Mst),
        "none" => Ok(OrientArg::None),
        v => match v.strip_prefix("view:") {
            Some(p) => Ok(OrientArg::View(Point3::from(
                VECTOR3.parse_str(p, &format!("{what} view:"))?,
            ))),
            None => Err(format!("unknown {what} '{s}'; use mst, view:X,Y,Z or none")),
        },
    }
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
    #[arg(long = "view", value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = VECTOR3)]
    pub viewpoint: Vector3,
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
    /// Camera of the picture: front, top, iso, or azimuth and elevation in
    /// degrees around the up axis [default: from the side of the view direction].
    #[arg(long = "camera", value_name = "VIEW", allow_hyphen_values = true, value_parser = crate::view::VIEW)]
    pub camera: Option<crate::view::View>,
    /// The axis that is up in the picture: x, y, z, or auto (the thin axis
    /// of sheet-like data; z otherwise).
    #[arg(long, value_name = "AXIS", default_value = "auto", value_parser = crate::args::choice::<crate::view::UpArg>())]
    pub up: crate::view::UpArg,
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
normal, holes clockwise). alpha defaults to 2.5 x the median Delaunay edge;
where the points are sparser (local spacing over 1.25 x the median, from
cell counts), alpha grows with the local spacing, up to 5 x, so a scan that
thins out towards its outline keeps its outline (--global-alpha: one alpha
everywhere, the PDE paper's alpha shape).
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
    /// One alpha everywhere, not widened where the points are sparse.
    #[arg(long)]
    pub global_alpha: bool,
    /// Number of corners (4 or 3 for Coons patches; 0 = loop only).
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub corners: usize,
    /// Corner criterion: `angle` (smallest turning angle) or `curvature` (three-point).
    #[arg(long, default_value = "angle", value_name = "C", value_parser = choice::<CriterionArg>())]
    pub criterion: CriterionArg,
    /// Neighbour offset m of the corner criterion [default: 1% of the loop].
    #[arg(long, value_name = "M")]
    pub corner_offset: Option<usize>,
    /// Smallest distance between corners along the loop, as a fraction of its length.
    #[arg(long, default_value_t = 0.03, value_name = "F")]
    pub min_separation: f64,
    /// Use these loop positions as the corners instead of detecting them.
    #[arg(long, value_name = "I,J,K,L", value_parser = INDICES)]
    pub corner_at: Option<Indices>,
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
    /// Neighbours per point, the point itself not counted (Open3D's knn and
    /// PCL's k count it: --k 16 here is their 17).
    #[arg(long, default_value_t = 16)]
    pub k: usize,
    /// Orientation: `mst`, `view:X,Y,Z` or `none`.
    #[arg(long, default_value = "mst", value_name = "HOW", value_parser = ORIENT)]
    pub orient: OrientArg,
    /// Direction the seed normal of each connected part points along (with --orient mst).
    #[arg(
        long,
        default_value = "0,0,1",
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        value_parser = VECTOR3
    )]
    pub hint: Vector3,
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
        CloudCommand::Clean(a) => crate::clean::run(a),
        CloudCommand::Segment(a) => crate::segment::run(a),
    }
}

/// The bytes of `cloud` with all its attributes as binary PLY or XYZ text, by extension.
pub fn cloud_file(path: &Path, cloud: &PointCloud) -> Result<Vec<u8>> {
    let format = WriteFormat::from_path(path)
        .with_context(|| format!("{}: write points as .ply or .xyz", path.display()))?;
    Ok(cloud_bytes(cloud, format))
}

/// Prints `wrote FILE` for each file.
fn print_files(files: &Files) -> Result<()> {
    for (p, _) in files {
        outln!("wrote {}", p.display());
    }
    Ok(())
}

fn info(a: InfoArgs) -> Result<()> {
    let t0 = Instant::now();
    let (cloud, dropped) = a.input.load_counted()?;
    let read_s = t0.elapsed().as_secs_f64();
    let r = cloud_info(
        &cloud,
        &CloudInfoConfig::default(),
        &scanfit::progress::NoProgress,
    )
    .with_context(|| a.input.input.display().to_string())?;
    if a.json {
        let (lo, hi) = (r.bbox_min, r.bbox_max);
        let mut report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": r.points,
            "dropped_non_finite": dropped,
            "bbox_min": [lo.x, lo.y, lo.z],
            "bbox_max": [hi.x, hi.y, hi.z],
            "diagonal": r.diagonal,
            "attributes": r.attributes.iter().map(|at| serde_json::json!({"name": at.name, "min": at.min, "max": at.max})).collect::<Vec<_>>(),
            "read_seconds": read_s,
        });
        if let Some(s) = r.spacing {
            report["spacing"] = serde_json::json!({"min": s.min, "median": s.median, "mean": s.mean, "max": s.max, "duplicates": s.duplicates, "measured_points": s.measured, "sampled": s.measured < r.points});
        }
        out!(
            "{}",
            scanfit_io::json::finite_json(&report, "the JSON report")?
        );
        return Ok(());
    }
    print_info(&a.input.input, &r, read_s)?;
    Ok(())
}

/// The tables of `cloud info`.
fn print_info(input: &Path, r: &CloudInfo, read_s: f64) -> Result<()> {
    let (lo, hi) = (r.bbox_min, r.bbox_max);
    outln!(
        "{}: {} points (read in {:.3} s)\n",
        input.display(),
        r.points,
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
    out!("{}", t.render());
    outln!("bounding-box diagonal {}\n", num(r.diagonal));
    if !r.attributes.is_empty() {
        let mut t = Table::new(&["attribute", "min", "max"], &[true]);
        for at in &r.attributes {
            t.row(vec![at.name.clone(), num(at.min), num(at.max)]);
        }
        out!("{}", t.render());
        outln!();
    }
    if let Some(s) = r.spacing {
        let mut t = Table::new(&["nearest-neighbour distance", "value"], &[true]);
        for (n, v) in [
            ("min", s.min),
            ("median", s.median),
            ("mean", s.mean),
            ("max", s.max),
        ] {
            t.row(vec![n.to_string(), num(v)]);
        }
        out!("{}", t.render());
        if s.measured < r.points {
            outln!(
                "(nearest-neighbour distances of a seeded random sample of {} of the {} points)",
                s.measured,
                r.points
            );
        }
        if s.duplicates > 0 {
            outln!("{} points coincide with another point", s.duplicates);
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
    let camera = Camera::new(opts);
    let d = camera.toward;
    let light = (d + Vector3::new(0.0, 0.0, 0.5)).normalize();
    normals
        .iter()
        .map(|n| {
            let m = camera.normal(n);
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
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["ply", "xyz"][..]),
            (&a.png, "--png", &["png"][..]),
        ],
    )?;
    let mut cfg = CloudNormalsConfig::default();
    cfg.normals.k = a.k;
    cfg.normals.orientation = match a.orient {
        OrientArg::Mst => Orientation::SpanningTree { hint: a.hint },
        OrientArg::View(p) => Orientation::Viewpoint(p),
        OrientArg::None => Orientation::None,
    };
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let cloud = a.input.load(a.json)?;
    progress.stage(format!("normals of {} points", cloud.len()));
    let t0 = Instant::now();
    let r = estimate(&cloud, &cfg, &progress)
        .with_context(|| format!("normals of {}", a.input.input.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    warn_disagreement(r.normals.disagreement);
    let mut files: Files = Vec::new();
    if let Some(o) = &a.output {
        files.push((o.clone(), cloud_file(o, &r.cloud)?));
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
        let colours = normal_shading(&r.normals.normals, &opts);
        let scene = PointScene {
            points: cloud.points(),
            colours: Some(&colours),
            ..Default::default()
        };
        files.push((p.clone(), render_scene_png(&scene, &opts)?));
    }
    write_all_atomic(&files)?;
    progress.finish();
    print_normals(&a, cloud.len(), &r, secs, &files)
}

/// Share of disagreeing neighbour pairs above which `cloud normals` warns.
const DISAGREEMENT_WARNING: f64 = 0.01;

/// Warns on stderr when more than 1% of the same-sheet neighbour pairs
/// disagree after orientation (a region flipped).
fn warn_disagreement(d: Option<f64>) {
    if let Some(d) = d.filter(|&d| d > DISAGREEMENT_WARNING) {
        crate::print_stderr(format_args!(
            "warning: {:.1}% of neighbouring normals disagree after orientation (a region is flipped); try --orient view:X,Y,Z from outside the object, a smaller --k, or another --hint",
            100.0 * d
        ));
    }
}

/// The report of `cloud normals`: JSON or a table, then the files written.
fn print_normals(
    a: &NormalsArgs,
    points: usize,
    r: &scanfit::pipeline::cloud::CloudNormals,
    secs: f64,
    files: &Files,
) -> Result<()> {
    let n = &r.normals;
    if a.json {
        let report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": points,
            "k": a.k,
            "orientation": a.orient.to_string(),
            "components": n.components,
            "degenerate": n.degenerate.len(),
            "mean_variation": r.mean_variation,
            "disagreeing_neighbours": n.disagreement,
            "seconds": secs,
        });
        out!(
            "{}",
            scanfit_io::json::finite_json(&report, "the JSON report")?
        );
        return Ok(());
    }
    let mut t = Table::new(&["normals", "value"], &[true]);
    t.row(vec!["points".into(), points.to_string()]);
    t.row(vec!["neighbours k".into(), a.k.to_string()]);
    t.row(vec!["orientation".into(), a.orient.to_string()]);
    t.row(vec!["connected parts".into(), n.components.to_string()]);
    t.row(vec![
        "degenerate neighbourhoods".into(),
        n.degenerate.len().to_string(),
    ]);
    t.row(vec!["mean surface variation".into(), num(r.mean_variation)]);
    if let Some(d) = n.disagreement {
        t.row(vec!["disagreeing neighbours (%)".into(), num(100.0 * d)]);
    }
    t.row(vec!["time (s)".into(), format!("{secs:.3}")]);
    out!("{}", t.render());
    print_files(files)?;
    Ok(())
}

/// The picture of `cloud hpr`: the cloud from the side of the view
/// direction, visible points coloured by nearness to the viewpoint, hidden
/// ones grey.
fn hpr_picture(a: &HprArgs, cloud: &PointCloud, view: Point3, r: &CloudHpr) -> Result<Vec<u8>> {
    let (lo, hi) = cloud.bounding_box().context("no points")?;
    let centre = Point3::from((lo.coords + hi.coords) / 2.0);
    let dir = view - centre;
    let up = crate::view::ViewArgs {
        view: None,
        up: a.up,
        z_scale: None,
    }
    .up(cloud.points());
    let (az, el) = match a.camera {
        Some(c) => c.angles(),
        // from the side: the visible cap shows as a half shell
        None => {
            let d = up.to_frame(&dir);
            (d.y.atan2(d.x).to_degrees() + 90.0, 20.0)
        }
    };
    let is_visible = r.visible_mask(cloud.len());
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
    let colours: Vec<[u8; 3]> = along
        .iter()
        .zip(&is_visible)
        .map(|(&t, &vis)| {
            if vis {
                viridis(((t - mn) / (mx - mn).max(f64::MIN_POSITIVE)).clamp(0.0, 1.0))
                    .map(|c| (c * 255.0).round() as u8)
            } else {
                [205, 205, 205]
            }
        })
        .collect();
    let opts = RenderOptions {
        azimuth: az,
        elevation: el,
        up,
        legend: vec![
            format!(
                "{}: {} of {} points visible from ({}, {}, {}), gamma = {}",
                a.input.input.display(),
                r.visible.len(),
                cloud.len(),
                num(view.x),
                num(view.y),
                num(view.z),
                a.gamma
            ),
            "visible: coloured by nearness to the viewpoint (yellow = near); hidden: grey".into(),
        ],
        ..Default::default()
    };
    let scene = PointScene {
        points: cloud.points(),
        colours: Some(&colours),
        ..Default::default()
    };
    Ok(render_scene_png(&scene, &opts)?)
}

fn hpr(a: HprArgs) -> Result<()> {
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["ply", "xyz"][..]),
            (&a.png, "--png", &["png"][..]),
        ],
    )?;
    let view = Point3::from(a.viewpoint);
    let mut cfg = CloudHprConfig::from_viewpoint(view);
    cfg.hpr.gamma = a.gamma;
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let cloud = a.input.load(a.json)?;
    progress.stage(format!("hidden point removal over {} points", cloud.len()));
    let t0 = Instant::now();
    let r = remove_hidden(&cloud, &cfg, &progress)
        .with_context(|| format!("hidden point removal on {}", a.input.input.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    let mut files: Files = Vec::new();
    if let Some(o) = &a.output {
        files.push((o.clone(), cloud_file(o, &r.cloud)?));
    }
    if let Some(p) = &a.png {
        progress.stage("picture");
        files.push((p.clone(), hpr_picture(&a, &cloud, view, &r)?));
    }
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        let report = serde_json::json!({
            "file": a.input.input.display().to_string(),
            "points": cloud.len(),
            "visible": r.visible.len(),
            "hidden": r.hidden,
            "viewpoint": [view.x, view.y, view.z],
            "gamma": a.gamma,
            "seconds": secs,
        });
        out!(
            "{}",
            scanfit_io::json::finite_json(&report, "the JSON report")?
        );
        return Ok(());
    }
    let mut t = Table::new(&["hidden point removal", "value"], &[true]);
    t.row(vec!["points".into(), cloud.len().to_string()]);
    t.row(vec!["visible".into(), r.visible.len().to_string()]);
    t.row(vec!["hidden".into(), r.hidden.to_string()]);
    t.row(vec![
        "viewpoint".into(),
        format!("{}, {}, {}", num(view.x), num(view.y), num(view.z)),
    ]);
    t.row(vec!["gamma".into(), a.gamma.to_string()]);
    t.row(vec!["time (s)".into(), format!("{secs:.3}")]);
    out!("{}", t.render());
    print_files(&files)?;
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

/// The JSON document of `cloud boundary` (`-o OUT.json` and `--json`).
fn boundary_doc(
    a: &BoundaryArgs,
    cloud: &PointCloud,
    r: &CloudBoundary,
    secs: f64,
) -> serde_json::Value {
    let b = &r.boundary;
    let outer = r.outer();
    let value_name = match r.criterion {
        CornerCriterion::TurningAngle => "angle_degrees",
        CornerCriterion::ThreePointCurvature => "curvature",
    };
    let pt = |i: usize| {
        let p = cloud.points()[i];
        [p.x, p.y, p.z]
    };
    serde_json::json!({
        "schema": "scanfit-boundary/1",
        "file": a.input.input.display().to_string(),
        "points": cloud.len(),
        "alpha": b.alpha,
        "local_factor": b.local_factor,
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
        // `--corners 0`: empty lists (a JSON output holds no null)
        "corners": r.corners.as_ref().map_or_else(Vec::new, |c| c.corners.iter().map(|&k| serde_json::json!({
            "position": k,
            "index": outer[k],
            "point": pt(outer[k]),
            value_name: r.corner_value(k),
        })).collect::<Vec<_>>()),
        "sides": r.corners.as_ref().map_or_else(Vec::new, |c| c.sides.iter().map(|s| s.iter().map(|&k| outer[k]).collect::<Vec<_>>()).collect::<Vec<_>>()),
        "seconds": secs,
    })
}

/// The picture of `cloud boundary`: the points grey, holes purple, the
/// sides in colour with the corners labelled (or the outer loop red).
fn boundary_picture(a: &BoundaryArgs, cloud: &PointCloud, r: &CloudBoundary) -> Result<Vec<u8>> {
    let b = &r.boundary;
    let mut opts = a
        .view
        .options_or(cloud.points(), DefaultView::Facing(b.plane.normal))?;
    opts.legend = vec![
        format!(
            "{}: {} points, {} boundary loop(s), outer loop {} points, alpha = {} (x up to {} where sparse)",
            a.input.input.display(),
            cloud.len(),
            b.loops.len(),
            r.outer().len(),
            num(b.alpha),
            num(b.local_factor)
        ),
        match &r.corners {
            Some(c) => format!(
                "{} corners by {} (C0..), sides in colour from each corner to the next",
                c.corners.len(),
                value_name(&a.criterion)
            ),
            None => "outer loop red, holes purple".into(),
        },
    ];
    let grey: Vec<[u8; 3]> = vec![[150, 150, 150]; cloud.len()];
    let mut polylines: Vec<Polyline> = b
        .loops
        .iter()
        .enumerate()
        .filter(|&(li, _)| li != b.outer)
        .map(|(_, l)| Polyline {
            points: l.iter().map(|&i| cloud.points()[i]).collect(),
            rgb: [160, 30, 180],
            closed: true,
        })
        .collect();
    let mut markers = Vec::new();
    match &r.corners {
        Some(c) => {
            for (k, s) in c.sides.iter().enumerate() {
                polylines.push(Polyline {
                    points: s.iter().map(|&q| r.loop_points[q]).collect(),
                    rgb: SIDE_COLOURS[k % SIDE_COLOURS.len()],
                    closed: false,
                });
            }
            for (k, &q) in c.corners.iter().enumerate() {
                markers.push(Marker {
                    at: r.loop_points[q],
                    rgb: [255, 255, 255],
                    label: format!("C{k}"),
                });
            }
        }
        None => polylines.push(Polyline {
            points: r.loop_points.clone(),
            rgb: [220, 30, 30],
            closed: true,
        }),
    }
    let scene = PointScene {
        points: cloud.points(),
        colours: Some(&grey),
        polylines,
        markers,
    };
    Ok(render_scene_png(&scene, &opts)?)
}

/// The tables of `cloud boundary`: the loops, then the corners.
fn print_boundary(cloud: &PointCloud, r: &CloudBoundary, secs: f64) -> Result<()> {
    let b = &r.boundary;
    let outer = r.outer();
    let mut t = Table::new(&["boundary", "value"], &[true]);
    t.row(vec!["points".into(), cloud.len().to_string()]);
    t.row(vec![
        "point spacing (median Delaunay edge)".into(),
        num(b.spacing),
    ]);
    t.row(vec!["alpha".into(), num(b.alpha)]);
    t.row(vec![
        "largest local alpha factor (sparse parts)".into(),
        num(b.local_factor),
    ]);
    t.row(vec!["loops".into(), b.loops.len().to_string()]);
    t.row(vec!["outer loop points".into(), outer.len().to_string()]);
    t.row(vec![
        "outer loop area (in the plane)".into(),
        num(b.areas[b.outer].abs()),
    ]);
    t.row(vec!["time (s)".into(), format!("{secs:.3}")]);
    out!("{}", t.render());
    let Some(c) = &r.corners else {
        return Ok(());
    };
    outln!();
    let head = match r.criterion {
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
        let p = r.loop_points[q];
        t.row(vec![
            format!("C{k}"),
            q.to_string(),
            outer[q].to_string(),
            num(p.x),
            num(p.y),
            num(p.z),
            num(r.corner_value(q).unwrap_or(f64::NAN)),
            c.sides[k].len().to_string(),
        ]);
    }
    out!("{}", t.render());
    Ok(())
}

fn boundary(a: BoundaryArgs) -> Result<()> {
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["json", "ply", "xyz"][..]),
            (&a.png, "--png", &["png"][..]),
        ],
    )?;
    let mut cfg = CloudBoundaryConfig::default();
    cfg.boundary.alpha = a.alpha;
    cfg.boundary.alpha_factor = a.alpha_factor;
    cfg.boundary.local_alpha = !a.global_alpha;
    cfg.corners.criterion = CornerCriterion::from(a.criterion);
    cfg.corners.count = a.corners;
    cfg.corners.offset = a.corner_offset;
    cfg.corners.min_separation = a.min_separation;
    cfg.corner_positions = a.corner_at.as_ref().map(|c| c.0.clone());
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage("reading");
    let cloud = a.input.load(a.json)?;
    progress.stage(format!("alpha shape of {} points", cloud.len()));
    let t0 = Instant::now();
    let r = find_boundary(&cloud, &cfg, &progress)
        .map_err(|e| {
            anyhow::anyhow!(
                "{}",
                cli_message(&e, &[("corner_positions", "--corner-at")])
            )
        })
        .with_context(|| format!("boundary of {}", a.input.input.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    let doc = boundary_doc(&a, &cloud, &r, secs);
    let mut files: Files = Vec::new();
    if let Some(o) = &a.output {
        let bytes = if extension(o) == "json" {
            scanfit_io::json::finite_json(&doc, &o.display().to_string())?.into_bytes()
        } else {
            cloud_file(o, &r.loop_cloud()?)?
        };
        files.push((o.clone(), bytes));
    }
    if let Some(p) = &a.png {
        progress.stage("picture");
        files.push((p.clone(), boundary_picture(&a, &cloud, &r)?));
    }
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        out!(
            "{}",
            scanfit_io::json::finite_json(&doc, "the JSON report")?
        );
        return Ok(());
    }
    print_boundary(&cloud, &r, secs)?;
    print_files(&files)?;
    Ok(())
}
