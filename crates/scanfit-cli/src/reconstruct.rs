//! `scanfit reconstruct`: a segmented cloud (a patch id per point) -> patches
//! that share their corners and edge curves -> one surface per patch whose
//! boundary is exactly those curves (PDE paper §§4-5), as a sewn model.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use scanfit::base::turntable::AxisChoice;
use scanfit::bspline::{tessellate, Mesh};
use scanfit::metrics::nearest_points;
use scanfit::network::layout::{LabelSource, Layout};
use scanfit::network::FaceFit;
use scanfit::pde::PdeConfig;
use scanfit::pipeline::reconstruct::{self, ReconstructConfig, ReconstructReport};
use scanfit::topology::PatchComplex;
use scanfit::{Point3, PointCloud};
use scanfit_io::gltf::mesh_glb;
use scanfit_io::iges::iges_model_file_with;
use scanfit_io::json::Provenance;
use scanfit_io::model::{self, ModelDoc, ModelReport, ModelTotals};
use scanfit_io::ply::{mesh_obj, mesh_ply, PlyFormat};
use scanfit_io::render::{
    render_surface_scene_png, ColourScale, Colouring, Marker, Polyline, DEVIATION_PERCENTILE,
};
use scanfit_io::step_shell::step_shell_file_with;
use scanfit_io::write_all_atomic;

use crate::args::{choice, Ids, InputArgs, Parsed, IDS, NXM};
use crate::outputs::{check_outputs, extension, print_written, Files};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit reconstruct examples/data/vessel_30k.ply --step vessel.stp --png vessel.png
  scanfit reconstruct examples/data/umbrella_20k.ply --pde 8x8 -o umbrella.json --mesh umbrella.glb
  scanfit reconstruct examples/data/vessel_30k.ply --labels label --ignore 14 --fit bspline --ctrl 12x12 --json
  scanfit reconstruct examples/data/blob_30k.ply --layout cube --step blob.stp
  scanfit reconstruct examples/data/part_30k.ply --segment --png part.png
  scanfit reconstruct examples/data/vessel_30k.ply --layout revolve:4x3 --step pot.stp
  scanfit reconstruct examples/data/terrain_50k.xyz --layout grid:3x3 --fit bspline --png dem.png

Input: a point cloud whose points carry an integer patch id (PLY/PCD property
or text column `label`, `segment`, `segment_id`, `class` or `scalar_label`,
case-insensitive, or the one named by --labels); negative ids and the ids of
--ignore are left out. Without labels: --segment cuts the cloud at its sharp
edges (as `scanfit cloud segment`), --layout cube lays six patches over a
closed star-shaped object, --layout grid:RxC cuts a four-sided sheet along
iso-lines of its Coons base (corners and edge curves from one least-squares
surface of the whole sheet; with --fit bspline each patch's net follows its
detail within R x C nets of --ctrl), --layout revolve:SxL cuts an object about its axis
(--axis, default the principal axis) into S sectors x L bands with S three-sided
caps at each closed end; their ids replace the file's and take the same path.
Pipeline: each patch's border (alpha shape), the patch across every border
point (within 3 spacings), corners where three or more patches meet or an
interface reaches the free border, edges between corners shared by the two
patches along them, one end-pinned least-squares curve per edge fitted to both
patches' border points (PDE paper 4.2), 3 or 4 sides per patch (with more
corners the flattest are merged into sides), the Coons patch of the side
curves, closest-point parameters, then the PDE deformation (--pde MxN, default
5x5) or a least-squares B-spline (--fit bspline --ctrl NxM). The boundary
control points of every exported surface are the shared edge curves', so
neighbouring patches meet without gaps: the table's gap column measures it by
sampling each edge on both patches; its angle column is the angle between the
two patches' normals along the edge (the G1 defect).";

/// Arguments of `scanfit reconstruct`.
/// `--fit`: the surface of each patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FitRoute {
    /// Coons patch + thin-plate PDE deformation (PDE paper eqs. 11-14).
    Pde,
    /// Least-squares B-spline with the boundary rows fixed to the edge curves.
    Bspline,
}

/// `--layout`: `cube`, `grid:RxC` or `revolve:SxL`.
pub const LAYOUT: Parsed<LayoutArg> = Parsed::new(layout);

/// `--layout`: patches for a smooth object without labels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LayoutArg {
    /// Six four-sided patches, central projection onto a box (star-shaped objects).
    Cube,
    /// A sheet cut into R x C patches along iso-lines of its Coons base.
    Grid(usize, usize),
    /// S sectors x L bands about the axis, three-sided caps at closed ends.
    Revolve(usize, usize),
}

fn layout(s: &str, what: &str) -> std::result::Result<LayoutArg, String> {
    let t = s.trim().to_ascii_lowercase();
    let usage = format!(
        "{what} '{s}' must be cube, grid:RxC (a four-sided sheet, e.g. grid:3x3) or revolve:SxL (S >= 3 sectors x L bands about the axis, e.g. revolve:4x3)"
    );
    let count = |x: &str| match crate::args::NXM.parse_str(x, what) {
        Ok((a, b)) if x.contains(['x', 'X']) && a > 0 && b > 0 => Ok((a, b)),
        _ => Err(usage.clone()),
    };
    match t.split_once(':') {
        None if t == "cube" => Ok(LayoutArg::Cube),
        Some(("grid", n)) => count(n).map(|(r, c)| LayoutArg::Grid(r, c)),
        Some(("revolve", n)) => count(n).map(|(a, b)| LayoutArg::Revolve(a, b)),
        _ => Err(usage),
    }
}

#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct ReconstructArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Attribute holding the patch ids [default: the first of label, segment,
    /// segment_id, class, scalar_label].
    #[arg(long, value_name = "NAME")]
    pub labels: Option<String>,
    /// Make the patch ids by segmenting the cloud at its sharp edges (as
    /// `scanfit cloud segment`; thresholds --angle, --min-cell, --min-region).
    #[arg(long, conflicts_with = "layout")]
    pub segment: bool,
    #[command(flatten)]
    pub segment_options: crate::segment::SegmentOptions,
    /// Make the patch ids by a layout for a smooth object: `cube` (six
    /// four-sided patches by central projection onto a box about the centre;
    /// closed star-shaped objects), `grid:RxC` (a four-sided sheet cut along
    /// iso-lines of its Coons base into R x C patches, control points where
    /// the detail is), `revolve:SxL` (S
    /// sectors x L bands about the axis, S three-sided caps at each closed
    /// end).
    #[arg(long, value_name = "LAYOUT", value_parser = LAYOUT)]
    pub layout: Option<LayoutArg>,
    /// Axis of `--layout revolve`: x, y, z, a direction "X,Y,Z", or "auto"
    /// (the cloud's principal axis, as `scanfit turntable`).
    #[arg(long, value_name = "AXIS", value_parser = crate::turntable::AXIS)]
    pub axis: Option<AxisChoice>,
    /// Patch ids to leave out, e.g. "0,99" (negative ids always are).
    #[arg(long, value_name = "LIST", allow_hyphen_values = true, value_parser = IDS)]
    pub ignore: Option<Ids>,
    /// Surface route: `pde` (PDE paper, default) or `bspline`.
    #[arg(long, value_name = "ROUTE", value_parser = choice::<FitRoute>())]
    pub fit: Option<FitRoute>,
    /// PDE deformation with M x N sine terms per patch (PDE paper: 5x5).
    #[arg(long, value_name = "MxN", value_parser = NXM)]
    pub pde: Option<(usize, usize)>,
    /// Control net of each least-squares patch (--fit bspline), at least 4x4;
    /// the side curves' knots are added, so the net can be larger.
    #[arg(long, default_value = "8x8", value_name = "NxM", value_parser = NXM)]
    pub ctrl: (usize, usize),
    /// Contact radius between patches, in point spacings.
    #[arg(long, default_value_t = 3.0, value_name = "F")]
    pub contact: f64,
    /// Largest deviation of each exported B-spline from its PDE surface, data
    /// units [default: 1e-4 x the bounding-box diagonal].
    #[arg(long, value_name = "T")]
    pub export_tolerance: Option<f64>,
    /// Write the model as JSON (schema scanfit-model/1).
    #[arg(short, long, value_name = "MODEL.json")]
    pub output: Option<PathBuf>,
    /// Write the model as one STEP shell whose faces share their edges.
    #[arg(long, value_name = "OUT.stp")]
    pub step: Option<PathBuf>,
    /// Write the model as IGES 5.3 (entity 128 per patch, 126 per edge).
    #[arg(long, value_name = "OUT.igs")]
    pub iges: Option<PathBuf>,
    #[command(flatten)]
    pub units: crate::cad::UnitsArgs,
    /// Write a triangle mesh (.glb, .ply or .obj), one colour per patch.
    #[arg(long, value_name = "OUT")]
    pub mesh: Option<PathBuf>,
    /// Write a picture: patches in distinct colours, edges drawn, corners marked.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Write a picture of every patch coloured by the local fit error.
    #[arg(long, value_name = "OUT.png")]
    pub deviation_png: Option<PathBuf>,
    #[command(flatten)]
    pub view: crate::view::ViewArgs,
    /// Write the model even when a patch leaves its data (samples farther
    /// outside the bounding box of the patch's points than 10 point spacings
    /// and a quarter of its diagonal).
    #[arg(long)]
    pub allow_extrapolation: bool,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `scanfit reconstruct`.
pub fn run(a: ReconstructArgs) -> Result<()> {
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["json"][..]),
            (&a.step, "--step", &["stp", "step"][..]),
            (&a.iges, "--iges", &["igs", "iges"][..]),
            (&a.mesh, "--mesh", &["obj", "ply", "glb"][..]),
            (&a.png, "--png", &["png"][..]),
            (&a.deviation_png, "--deviation-png", &["png"][..]),
        ],
    )?;
    let cfg = config(&a)?;
    let t0 = Instant::now();
    let (cloud, dropped) = a.input.load_counted()?;
    let progress = Progress::spinner(a.quiet);
    let settings = crate::segment::SegmentOptions::SETTINGS;
    let r = reconstruct::run(&cloud, &cfg, &progress)
        .map_err(|e| anyhow::anyhow!("{}", error_message(&e, &cfg, &settings)))
        .with_context(|| format!("reconstructing {}", a.input.input.display()))?;
    progress.finish();
    let seconds = t0.elapsed().as_secs_f64();
    let files = outputs(&a, &r, &cloud)?;
    write_all_atomic(&files)?;
    if a.json {
        let report = json_report(&r, &a, seconds, dropped);
        out!(
            "{}",
            scanfit_io::json::finite_json(&report, "the JSON report")?
        );
    } else {
        out!("{}", tables(&r, seconds));
        print_written(&files, None, 1.0)?;
    }
    Ok(())
}

/// The pipeline settings from the options.
fn config(a: &ReconstructArgs) -> Result<ReconstructConfig> {
    let mut cfg = ReconstructConfig::default();
    cfg.network.labels.attribute = a.labels.clone();
    cfg.source = source(a)?;
    if let Some(Ids(list)) = &a.ignore {
        cfg.network.labels.ignore = list.clone();
    }
    cfg.network.contact_factor = a.contact;
    cfg.tolerance = a.export_tolerance;
    cfg.allow_extrapolation = a.allow_extrapolation;
    cfg.fit = match (a.fit, a.pde) {
        (Some(FitRoute::Bspline), Some(_)) => {
            bail!("--fit bspline and --pde exclude each other; choose one route")
        }
        (Some(FitRoute::Bspline), None) => FaceFit::Bspline { ctrl: a.ctrl },
        (None | Some(FitRoute::Pde), t) => {
            let (m, n) = t.unwrap_or((5, 5));
            FaceFit::Pde(PdeConfig {
                m,
                n,
                ..Default::default()
            })
        }
    };
    Ok(cfg)
}

/// The one line for a failed run: a patch that left its data names the
/// option that makes its surface stiffer (the route's own) and
/// `--allow-extrapolation`.
fn error_message(e: &scanfit::Error, cfg: &ReconstructConfig, settings: &[(&str, &str)]) -> String {
    match e {
        scanfit::Error::LeavesData {
            patch: Some(id),
            extent,
        } => {
            let fix = match cfg.fit {
                FaceFit::Bspline { ctrl: (m, n) } => {
                    format!("fit its patches with a coarser net (--ctrl, now {m}x{n})")
                }
                FaceFit::Pde(p) => {
                    format!(
                        "fit its patches with fewer sine terms (--pde, now {}x{})",
                        p.m, p.n
                    )
                }
                _ => "fit its patches with fewer control points".to_string(),
            };
            format!("patch {id}: {}", crate::extent::message(extent, &fix))
        }
        _ => crate::args::cli_message(e, settings),
    }
}

/// Where the patch ids come from: the file, `--segment` or `--layout`.
fn source(a: &ReconstructArgs) -> Result<LabelSource> {
    if a.axis.is_some() && !matches!(a.layout, Some(LayoutArg::Revolve(..))) {
        bail!("--axis sets the axis of --layout revolve:SxL; give that layout or leave --axis out");
    }
    Ok(match (a.segment, a.layout) {
        (true, _) => LabelSource::Segment(a.segment_options.config()),
        (false, Some(LayoutArg::Cube)) => LabelSource::Layout(Layout::Cube),
        (false, Some(LayoutArg::Grid(rows, cols))) => LabelSource::Layout(Layout::Grid {
            rows,
            cols,
            options: Default::default(),
        }),
        (false, Some(LayoutArg::Revolve(sectors, bands))) => LabelSource::Layout(Layout::Revolve {
            sectors,
            bands,
            axis: a.axis.unwrap_or_default(),
        }),
        (false, None) => LabelSource::Attribute,
    })
}

/// A distinct colour for patch `k` (hues a golden angle apart).
pub(crate) fn patch_colour(k: usize) -> [u8; 3] {
    let h = (k as f64 * 0.618_033_988_75).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as usize {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    [r, g, b].map(|c| (40.0 + 190.0 * c) as u8)
}

/// All patches tessellated into one mesh, with each vertex's patch.
fn model_mesh(r: &ReconstructReport) -> (Mesh, Vec<usize>) {
    let mut all = Mesh {
        vertices: Vec::new(),
        normals: Vec::new(),
        uv: Vec::new(),
        triangles: Vec::new(),
    };
    let mut patch = Vec::new();
    for (k, f) in r.faces.iter().enumerate() {
        let m = tessellate(&f.surface, 48, 48);
        let base = all.vertices.len() as u32;
        patch.extend(std::iter::repeat_n(k, m.vertices.len()));
        all.vertices.extend(m.vertices);
        all.normals.extend(m.normals);
        all.uv.extend(m.uv);
        all.triangles
            .extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    (all, patch)
}

/// The local fit error at every mesh vertex: the orthogonal distance of the
/// nearest point of its patch.
fn vertex_deviation(
    r: &ReconstructReport,
    cloud: &PointCloud,
    mesh: &Mesh,
    patch: &[usize],
) -> Result<Vec<f64>> {
    let mut out = vec![0.0; mesh.vertices.len()];
    for (k, (p, f)) in r.network.patches.iter().zip(&r.faces).enumerate() {
        let pts: Vec<Point3> = p.points.iter().map(|&i| cloud.points()[i]).collect();
        let idx: Vec<usize> = (0..patch.len()).filter(|&i| patch[i] == k).collect();
        let q: Vec<Point3> = idx.iter().map(|&i| mesh.vertices[i]).collect();
        for (&i, (j, _)) in idx.iter().zip(nearest_points(&pts, &q)?) {
            out[i] = f.distances[j];
        }
    }
    Ok(out)
}

/// The edge network and the corners drawn over the pictures.
fn overlay(r: &ReconstructReport) -> (Vec<Polyline>, Vec<Marker>) {
    let lines = r.network.edges.iter().map(|e| Polyline {
        points: (0..=64).map(|i| e.curve.point(i as f64 / 64.0)).collect(),
        rgb: [20, 20, 20],
        closed: false,
    });
    let markers = r.network.vertices.iter().map(|&at| Marker {
        at,
        rgb: [230, 30, 30],
        label: String::new(),
    });
    (lines.collect(), markers.collect())
}

/// The bytes of every requested output.
fn outputs(a: &ReconstructArgs, r: &ReconstructReport, cloud: &PointCloud) -> Result<Files> {
    let mut files: Files = Vec::new();
    let cad = a.output.is_some() || a.step.is_some() || a.iges.is_some();
    if cad {
        let model = &r.complex;
        let name = a
            .input
            .input
            .file_stem()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        files.extend(model_files(a, r, model, &name)?);
    }
    if a.mesh.is_none() && a.png.is_none() && a.deviation_png.is_none() {
        return Ok(files);
    }
    let (mesh, patch) = model_mesh(r);
    let colours: Vec<[u8; 3]> = patch.iter().map(|&k| patch_colour(k)).collect();
    if let Some(m) = &a.mesh {
        let bytes = match extension(m).as_str() {
            "glb" => mesh_glb(&mesh, Some(&colours), "scanfit reconstruct"),
            "ply" => mesh_ply(&mesh, None, Some(&colours), PlyFormat::Binary),
            _ => mesh_obj(&mesh, "scanfit reconstruct"),
        };
        files.push((m.clone(), bytes));
    }
    if a.png.is_some() || a.deviation_png.is_some() {
        files.extend(pictures(a, r, cloud, &mesh, &patch)?);
    }
    Ok(files)
}

/// The `--png` (patches in distinct colours, edge network, corners) and
/// `--deviation-png` pictures.
fn pictures(
    a: &ReconstructArgs,
    r: &ReconstructReport,
    cloud: &PointCloud,
    mesh: &Mesh,
    patch: &[usize],
) -> Result<Files> {
    let mut files: Files = Vec::new();
    let (lines, markers) = overlay(r);
    let mut opts = a.view.options(cloud.points())?;
    opts.iso_lines = 0;
    opts.units = a.units.label().into();
    if let Some(p) = &a.png {
        let colours: Vec<[u8; 3]> = patch.iter().map(|&k| patch_colour(k)).collect();
        opts.legend = vec![format!(
            "{} patches, {} edges, {} corners",
            r.faces.len(),
            r.network.edges.len(),
            r.network.vertices.len()
        )];
        let png = render_surface_scene_png(
            mesh,
            None,
            Colouring::Rgb(&colours),
            &lines,
            &markers,
            &opts,
        )?;
        files.push((p.clone(), png));
    }
    if let Some(p) = &a.deviation_png {
        let dev = vertex_deviation(r, cloud, mesh, patch)?;
        // the scale: 0 to the 99th percentile of the points' distances
        let per_point: Vec<f64> = r
            .faces
            .iter()
            .flat_map(|f| f.distances.iter().copied())
            .collect();
        let units = a.units.label();
        let scale = ColourScale::deviation(
            format!("orthogonal distance [{units}]"),
            &per_point,
            DEVIATION_PERCENTILE,
        );
        opts.legend = vec![
            format!(
                "colour = orthogonal distance of the nearest point, 0 to the {}",
                match scale.high {
                    Some(c) => format!("{}th percentile (max on the bar)", c.percentile),
                    None => "max".into(),
                }
            ),
            format!(
                "mean {}  max {}  rmse {}  [{units}]",
                num(r.totals.orthogonal.mean),
                num(r.totals.orthogonal.max),
                num(r.totals.orthogonal.rmse)
            ),
        ];
        let png = render_surface_scene_png(
            mesh,
            None,
            Colouring::Scalar {
                values: &dev,
                scale: &scale,
            },
            &lines,
            &markers,
            &opts,
        )?;
        files.push((p.clone(), png));
    }
    Ok(files)
}

/// The patch, edge and total tables.
fn tables(r: &ReconstructReport, seconds: f64) -> String {
    let mut t = Table::new(
        &[
            "patch",
            "sides",
            "edges",
            "points",
            "coons mean",
            "coons max",
            "mean",
            "max",
            "rmse",
            "orth rmse",
            "orth max",
            "folds",
        ],
        &[],
    );
    for p in &r.patches {
        t.row(vec![
            p.id.to_string(),
            p.sides.to_string(),
            p.edges.to_string(),
            p.points.to_string(),
            num(p.coons_errors.mean),
            num(p.coons_errors.max),
            num(p.errors.mean),
            num(p.errors.max),
            num(p.errors.rmse),
            num(p.orthogonal.rmse),
            num(p.orthogonal.max),
            p.fold_overs.to_string(),
        ]);
    }
    let mut e = Table::new(
        &[
            "edge",
            "from",
            "to",
            "patches",
            "max gap",
            "normal angle (deg)",
            "curve err",
        ],
        &[false, false, false, true],
    );
    for (k, x) in r.edges.iter().enumerate() {
        let who = |p: Option<i64>| p.map_or("free".to_string(), |p| p.to_string());
        e.row(vec![
            k.to_string(),
            x.vertices[0].to_string(),
            x.vertices[1].to_string(),
            format!("{} | {}", who(x.patches[0]), who(x.patches[1])),
            num(x.max_gap),
            format!("{:.2}", x.max_angle.to_degrees()),
            num(x.curve_error),
        ]);
    }
    let tt = &r.totals;
    let layout = r
        .layout
        .as_ref()
        .map_or(String::new(), |l| format!("{l}\n"));
    format!(
        "{layout}{}\n{}\n{} patches, {} edges, {} corners, {}; {} points (eq. 15: mean {}, max {}, rmse {}; orthogonal rmse {}, max {})\nlargest gap along an edge {} ({:.1e} of the diagonal {}), largest normal angle {:.2} deg; {:.2} s\n",
        t.render(), e.render(),
        r.faces.len(), r.network.edges.len(), r.network.vertices.len(),
        if tt.closed { "closed" } else { "open" },
        tt.errors.count, num(tt.errors.mean), num(tt.errors.max), num(tt.errors.rmse),
        num(tt.orthogonal.rmse), num(tt.orthogonal.max),
        num(tt.max_gap), tt.max_gap / tt.diagonal.max(f64::MIN_POSITIVE), num(tt.diagonal),
        tt.max_angle.to_degrees(), seconds
    )
}

/// The report as JSON.
fn json_report(
    r: &ReconstructReport,
    a: &ReconstructArgs,
    seconds: f64,
    dropped: usize,
) -> serde_json::Value {
    let stats = |s: &scanfit::metrics::ErrorStats| serde_json::json!({"mean": s.mean, "max": s.max, "rmse": s.rmse, "count": s.count});
    serde_json::json!({
        "input": a.input.input.display().to_string(),
        "labels": r.network.attribute,
        "layout": r.layout.as_deref().unwrap_or("the file's labels"),
        "ignored_points": r.network.ignored,
        "dropped_non_finite": dropped,
        "spacing": r.network.spacing,
        "contact_radius": r.network.contact_radius,
        "patches": r.patches.iter().map(|p| serde_json::json!({
            "id": p.id, "sides": p.sides, "edges": p.edges, "points": p.points,
            "coons": stats(&p.coons_errors), "errors": stats(&p.errors), "orthogonal": stats(&p.orthogonal),
            "bspline_deviation": p.conversion_deviation, "fold_overs": p.fold_overs,
            "outside_box": p.extent.samples_outside, "outside_box_spacings": p.extent.samples_outside_spacings,
            "control_net_outside_box": p.extent.control_outside, "outside_box_limit": p.extent.limit,
            "leaves_data": p.extent.leaves,
        })).collect::<Vec<_>>(),
        "edges": r.edges.iter().map(|e| serde_json::json!({
            "vertices": e.vertices, "patches": e.patches.iter().flatten().collect::<Vec<_>>(), "max_gap": e.max_gap,
            "max_normal_angle_deg": e.max_angle.to_degrees(), "curve_error": e.curve_error,
        })).collect::<Vec<_>>(),
        "corners": r.network.vertices.iter().map(|v| [v.x, v.y, v.z]).collect::<Vec<_>>(),
        "totals": {
            "faces": r.faces.len(), "edges": r.network.edges.len(), "corners": r.network.vertices.len(),
            "closed": r.totals.closed, "errors": stats(&r.totals.errors), "orthogonal": stats(&r.totals.orthogonal),
            "max_gap": r.totals.max_gap, "max_normal_angle_deg": r.totals.max_angle.to_degrees(),
            "diagonal": r.totals.diagonal, "seconds": seconds,
        },
    })
}

/// `-o`, `--step` and `--iges` of the model.
fn model_files(
    a: &ReconstructArgs,
    r: &ReconstructReport,
    model: &PatchComplex,
    name: &str,
) -> Result<Files> {
    let mut files: Files = Vec::new();
    if let Some(o) = &a.output {
        files.push((o.clone(), model_doc(a, r, model).to_json()?.into_bytes()));
    }
    if let Some(p) = &a.step {
        files.push((
            p.clone(),
            step_shell_file_with(model, name, &a.units.options())?
                .text
                .into_bytes(),
        ));
    }
    if let Some(p) = &a.iges {
        files.push((
            p.clone(),
            iges_model_file_with(model, name, &a.units.options())?.into_bytes(),
        ));
    }
    Ok(files)
}

/// The scanfit-model/1 document with provenance and the report.
fn model_doc(a: &ReconstructArgs, r: &ReconstructReport, model: &PatchComplex) -> ModelDoc {
    let stats = |s: &scanfit::metrics::ErrorStats| model::ErrorStats {
        mean: s.mean,
        max: s.max,
        rmse: s.rmse,
    };
    let mut doc = ModelDoc::new(model);
    let mut settings = std::collections::BTreeMap::new();
    settings.insert("fit".into(), r_fit(a).into());
    settings.insert("labels".into(), r.network.attribute.clone().into());
    settings.insert("contact_radius".into(), r.network.contact_radius.into());
    doc.provenance = Some(Provenance {
        tool: format!("scanfit {}", env!("CARGO_PKG_VERSION")),
        operation: "reconstruct (patch network, shared edge curves, Coons + PDE per patch)".into(),
        parameterization: Some("closest point on the Coons patch".into()),
        input: Some(a.input.input.display().to_string()),
        point_count: Some(r.totals.errors.count),
        settings,
    });
    doc.report = Some(ModelReport {
        patches: r
            .patches
            .iter()
            .map(|p| model::PatchReport {
                id: p.id,
                sides: p.sides,
                points: p.points,
                coons_error: Some(stats(&p.coons_errors)),
                error: Some(stats(&p.errors)),
                distance: Some(stats(&p.orthogonal)),
                extra: Default::default(),
            })
            .collect(),
        edges: r
            .edges
            .iter()
            .enumerate()
            .map(|(k, e)| model::EdgeReport {
                edge: k,
                patches: e.patches.iter().flatten().copied().collect(),
                points: r.network.edges[k].points,
                max_gap: e.max_gap,
                max_normal_angle_deg: e.patches[1].map(|_| e.max_angle.to_degrees()),
                extra: Default::default(),
            })
            .collect(),
        totals: ModelTotals {
            patches: r.patches.len(),
            edges: r.edges.len(),
            vertices: r.network.vertices.len(),
            points: r.totals.errors.count,
            max_gap: r.totals.max_gap,
            max_normal_angle_deg: Some(r.totals.max_angle.to_degrees()),
            error: Some(stats(&r.totals.errors)),
            volume: r.totals.closed.then(|| model.signed_volume().abs()),
            extra: Default::default(),
        },
    });
    doc
}

/// The fit route as named in the provenance.
fn r_fit(a: &ReconstructArgs) -> String {
    match (a.fit, a.pde) {
        (Some(FitRoute::Bspline), _) => format!("bspline {}x{}", a.ctrl.0, a.ctrl.1),
        (_, Some((m, n))) => format!("pde {m}x{n}"),
        _ => "pde 5x5".into(),
    }
}
