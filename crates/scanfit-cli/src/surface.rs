//! `scanfit fit`: a least-squares B-spline surface through scattered points.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::base::plane_parameters;
use scanfit::bspline::{tessellate, Surface};
use scanfit::fit::correction::{correct_parameters, CorrectionConfig, CorrectionRound};
use scanfit::fit::surface::{fit_surface, KnotPlacement, SurfaceFitConfig};
use scanfit::metrics::{
    grid_rmse, nearest_points, orthogonal_errors, parameterization_quality, parametric_distances,
    ErrorStats, ParamQuality,
};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit_io::gltf::mesh_glb;
use scanfit_io::json::{Provenance, SurfaceDoc, SurfaceQualityDoc};
use scanfit_io::ply::{mesh_obj, mesh_ply, points_ply, points_xyz, PlyFormat};
use scanfit_io::render::{render_png, viridis, Colouring, RenderOptions};
use scanfit_io::step::CadItem;
use scanfit_io::{read_points, write_all_atomic};

use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit fit examples/data/terrain_50k.xyz --ctrl 40x40 -o terrain.json --png terrain.png
  scanfit fit scan.xyz --params uv-columns --periodic-u --ctrl 24x12 --smooth 1e-6
  scanfit fit patch.csv --correct 5 --points-out params.ply --mesh patch.obj --json

Parameters come from the best-fit plane of the points (--params plane, for
height-field-like patches) or from columns named u and v in the input
(--params uv-columns). The error table reports the PDE paper's eq. 15 errors at
the parameters, true orthogonal distances, the MBA paper's grid RMSE (eq. 17)
and the parameterization's fold-overs and stretch.";

/// Arguments of `scanfit fit`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct FitArgs {
    /// Input point file (XYZ, CSV or TXT).
    pub input: PathBuf,
    /// Where the parameters come from: `plane` (best-fit plane) or `uv-columns`.
    #[arg(long, default_value = "plane", value_name = "SOURCE")]
    pub params: String,
    /// Degrees, "PxQ" or "P".
    #[arg(long, default_value = "3x3", value_name = "PxQ")]
    pub degree: String,
    /// Control net, "NUxNV" or "N".
    #[arg(long, default_value = "16x16", value_name = "NUxNV")]
    pub ctrl: String,
    /// Knot placement: `distribution` (follows the parameters) or `uniform`.
    #[arg(long, default_value = "distribution", value_name = "PLACEMENT")]
    pub knots: String,
    /// Thin-plate smoothing weight λ on ∫∫ S_uu² + 2 S_uv² + S_vv² (0 = none).
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "L",
        allow_negative_numbers = true
    )]
    pub smooth: f64,
    /// The surface closes around in u (needs --params uv-columns).
    #[arg(long)]
    pub periodic_u: bool,
    /// Rounds of parameter correction (Hoschek: re-project, refit).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub correct: usize,
    /// Write the surface as JSON (schema scanfit/1).
    #[arg(short, long, value_name = "SURFACE.json")]
    pub output: Option<PathBuf>,
    /// Write the surface as a STEP file (AP214; a face in an open shell).
    #[arg(long, value_name = "OUT.stp")]
    pub step: Option<PathBuf>,
    /// Write the same as an IGES 5.3 file (entity 126 or 128).
    #[arg(long, value_name = "OUT.igs")]
    pub iges: Option<PathBuf>,
    /// Write a triangle mesh of the surface (.obj, .ply or .glb; PLY and glb
    /// carry the local fit error, the orthogonal distance of each vertex's
    /// nearest input point, as a colour, PLY also as the property `deviation`).
    #[arg(long, value_name = "OUT")]
    pub mesh: Option<PathBuf>,
    /// Write a shaded, height-coloured picture with the input points.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Write a picture of the surface coloured by the local fit error (the
    /// orthogonal distance of the nearest input point), with a colour bar and
    /// the error figures.
    #[arg(long, value_name = "OUT.png")]
    pub deviation_png: Option<PathBuf>,
    /// Write the points with u, v, residual and orthogonal distance (.ply or .xyz).
    #[arg(long, value_name = "POINTS")]
    pub points_out: Option<PathBuf>,
    #[command(flatten)]
    pub view: crate::view::ViewArgs,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

fn pair(s: &str, what: &str) -> Result<(usize, usize)> {
    let parse = |x: &str| {
        x.trim()
            .parse::<usize>()
            .with_context(|| format!("{what} '{s}' must be N or NxM with whole numbers"))
    };
    match s.split_once(['x', 'X']) {
        Some((a, b)) => Ok((parse(a)?, parse(b)?)),
        None => {
            let n = parse(s)?;
            Ok((n, n))
        }
    }
}

fn extension(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Runs `scanfit fit`.
pub fn run(a: FitArgs) -> Result<()> {
    let degree = pair(&a.degree, "--degree")?;
    let ctrl = pair(&a.ctrl, "--ctrl")?;
    let knots = match a.knots.as_str() {
        "distribution" => KnotPlacement::Distribution,
        "uniform" => KnotPlacement::Uniform,
        k => bail!("unknown knot placement '{k}'; use distribution or uniform"),
    };
    for (p, what, allowed) in [
        (&a.mesh, "--mesh", &["obj", "ply", "glb"][..]),
        (&a.deviation_png, "--deviation-png", &["png"][..]),
        (&a.points_out, "--points-out", &["ply", "xyz"][..]),
        (&a.png, "--png", &["png"][..]),
        (&a.step, "--step", &["stp", "step"][..]),
        (&a.iges, "--iges", &["igs", "iges"][..]),
    ] {
        if let Some(p) = p {
            if !allowed.contains(&extension(p).as_str()) {
                bail!(
                    "{what} {}: the file name must end in .{}",
                    p.display(),
                    allowed.join(" or .")
                );
            }
        }
    }
    let progress = Progress::spinner(a.quiet);
    progress.stage(format!("reading {}", a.input.display()));
    let table = read_points(&a.input)?;
    let pts = &table.points;
    progress.stage("parameterizing");
    let mut uv: Vec<[f64; 2]> = match a.params.as_str() {
        "plane" => {
            if a.periodic_u {
                bail!("--periodic-u needs parameters that go around (--params uv-columns); a plane cannot close");
            }
            plane_parameters(pts)
                .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?
                .uv
        }
        "uv-columns" => {
            let (Some(u), Some(v)) = (table.column("u"), table.column("v")) else {
                bail!(
                    "{} has no columns named u and v (its columns: {}); use --params plane or add them",
                    a.input.display(),
                    table.columns.join(", ")
                );
            };
            u.iter().zip(v).map(|(&u, &v)| [u, v]).collect()
        }
        s => bail!("unknown parameter source '{s}'; use plane or uv-columns"),
    };
    let cfg = SurfaceFitConfig {
        degree,
        ctrl,
        periodic_u: a.periodic_u,
        knots,
        smoothing: a.smooth,
        weights: None,
    };
    let locate = |e: scanfit::Error| -> anyhow::Error {
        let msg = e.to_string();
        // point indices in the library's messages map to lines of the file
        if let Some(i) = msg
            .strip_prefix("point ")
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse::<usize>().ok())
        {
            anyhow::anyhow!("{msg} ({})", table.locate(i))
        } else {
            anyhow::anyhow!("{msg}")
        }
    };
    progress.stage(format!(
        "fitting {} x {} control points to {} points",
        ctrl.0,
        ctrl.1,
        pts.len()
    ));
    let (surface, rounds): (Surface, Vec<CorrectionRound>) = if a.correct > 0 {
        let cc = CorrectionConfig {
            max_rounds: a.correct,
            ..Default::default()
        };
        correct_parameters(pts, &mut uv, |t| fit_surface(pts, t, &cfg), &cc).map_err(locate)?
    } else {
        (fit_surface(pts, &uv, &cfg).map_err(locate)?, Vec::new())
    };
    progress.stage("measuring");
    let resid = parametric_distances(&surface, pts, &uv);
    let par = ErrorStats::of(&resid);
    let inverter = SurfaceInverter::new(&surface, InversionConfig::default())?;
    let (orth, inv) = orthogonal_errors(&inverter, pts);
    let unconverged = inv.iter().filter(|r| !r.converged).count();
    let grid = grid_rmse(&surface, pts, None)?;
    let pq = parameterization_quality(&surface, pts, &uv).unwrap_or_default();
    let quality = SurfaceQualityDoc {
        points: pts.len(),
        mean_error: par.mean,
        max_error: par.max,
        rmse: par.rmse,
        mean_distance: orth.mean,
        max_distance: orth.max,
        rmse_distance: orth.rmse,
        unconverged,
        grid_rmse: grid,
        triangles: pq.triangles,
        fold_overs: pq.fold_overs,
        l2_stretch: pq.l2_stretch,
        max_anisotropy: pq.max_anisotropy,
        correction_rmse: rounds.iter().map(|r| r.errors.rmse).collect(),
    };
    progress.stage("writing");
    let mut doc = SurfaceDoc::new(&surface);
    let mut settings = std::collections::BTreeMap::new();
    settings.insert(
        "degree".to_string(),
        serde_json::json!([degree.0, degree.1]),
    );
    settings.insert("ctrl".to_string(), serde_json::json!([ctrl.0, ctrl.1]));
    settings.insert("knots".to_string(), a.knots.clone().into());
    settings.insert("smoothing".to_string(), a.smooth.into());
    settings.insert("periodic_u".to_string(), a.periodic_u.into());
    settings.insert("correction_rounds".to_string(), a.correct.into());
    doc.provenance = Some(Provenance {
        tool: format!("scanfit {}", env!("CARGO_PKG_VERSION")),
        operation: "fit (least-squares surface)".into(),
        parameterization: Some(a.params.clone()),
        input: Some(a.input.display().to_string()),
        point_count: Some(pts.len()),
        settings,
    });
    doc.quality = Some(quality.clone());
    let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
    if let Some(o) = &a.output {
        files.push((o, doc.to_json().into_bytes()));
    }
    files.extend(crate::cad::cad_files(
        &a.step,
        &a.iges,
        CadItem::Surface(&surface),
        &a.input,
    )?);
    let (cu, cv) = surface.counts();
    let mesh = tessellate(&surface, (cu * 4).clamp(32, 400), (cv * 4).clamp(32, 400));
    // fit error on the surface: each mesh vertex shows the orthogonal distance
    // of its nearest input point (the local residual), on the same scale as
    // the error table
    let deviation =
        if a.deviation_png.is_some() || a.mesh.as_deref().is_some_and(|m| extension(m) != "obj") {
            let near = nearest_points(pts, &mesh.vertices)?;
            Some(
                near.iter()
                    .map(|&(i, _)| inv[i].distance)
                    .collect::<Vec<f64>>(),
            )
        } else {
            None
        };
    let dmax = orth.max;
    let colours: Option<Vec<[u8; 3]>> = deviation.as_ref().map(|d| {
        d.iter()
            .map(|&x| {
                viridis(if dmax > 0.0 { x / dmax } else { 0.0 }).map(|c| (c * 255.0).round() as u8)
            })
            .collect()
    });
    if let Some(m) = &a.mesh {
        let name = a
            .input
            .file_stem()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let bytes = match extension(m).as_str() {
            "obj" => mesh_obj(
                &mesh,
                &format!("scanfit surface fitted to {}", a.input.display()),
            ),
            "glb" => mesh_glb(&mesh, colours.as_deref(), &name),
            _ => mesh_ply(
                &mesh,
                deviation.as_deref().map(|d| ("deviation", d)),
                colours.as_deref(),
                PlyFormat::Binary,
            ),
        };
        files.push((m, bytes));
    }
    if let (Some(dp), Some(d)) = (&a.deviation_png, &deviation) {
        let opts = RenderOptions {
            legend: vec![
                format!(
                    "{}: colour = orthogonal distance of the nearest input point to the surface [data units]",
                    a.input.display()
                ),
                format!(
                    "input points to surface (orthogonal): mean {}  max {}  RMSE {}  [data units]",
                    num(orth.mean),
                    num(orth.max),
                    num(orth.rmse)
                ),
            ],
            ..a.view.options(pts)?
        };
        let bytes = render_png(
            &mesh,
            None,
            Colouring::Scalar {
                values: d,
                range: (0.0, dmax),
            },
            &opts,
        )?;
        files.push((dp, bytes));
    }
    if let Some(pout) = &a.points_out {
        let u: Vec<f64> = uv.iter().map(|t| t[0]).collect();
        let v: Vec<f64> = uv.iter().map(|t| t[1]).collect();
        let dist: Vec<f64> = inv.iter().map(|r| r.distance).collect();
        let attrs: [(&str, &[f64]); 4] = [
            ("u", &u),
            ("v", &v),
            ("residual", &resid),
            ("distance", &dist),
        ];
        let bytes = if extension(pout) == "ply" {
            points_ply(pts, &attrs, PlyFormat::Binary)
        } else {
            points_xyz(pts, &attrs)
        };
        files.push((pout, bytes));
    }
    let mut exaggeration = 1.0;
    if let Some(png) = &a.png {
        // at most 5,000 points drawn, evenly picked; flat data (terrain) exaggerated
        let step = (pts.len() / 5_000).max(1);
        let shown: Vec<_> = pts.iter().step_by(step).copied().collect();
        let opts = a.view.options(pts)?;
        exaggeration = opts.z_scale;
        let bytes = render_png(&mesh, Some(&shown), Colouring::Height, &opts)?;
        files.push((png, bytes));
    }
    let refs: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (*p, b.as_slice())).collect();
    write_all_atomic(&refs)?;
    progress.finish();
    if a.json {
        let report = serde_json::json!({
            "input": a.input.display().to_string(),
            "point_count": pts.len(),
            "degree": [degree.0, degree.1],
            "control_points": [cu, cv],
            "parameters": a.params,
            "quality": quality,
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    print_report(&a, &surface, &par, &orth, unconverged, grid, &pq, &rounds);
    for (p, _) in &files {
        if a.png.as_deref() == Some(*p) && exaggeration != 1.0 {
            println!(
                "wrote {} (vertical exaggeration {exaggeration}x)",
                p.display()
            );
        } else {
            println!("wrote {}", p.display());
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn print_report(
    a: &FitArgs,
    s: &Surface,
    par: &ErrorStats,
    orth: &ErrorStats,
    unconverged: usize,
    grid: f64,
    pq: &ParamQuality,
    rounds: &[CorrectionRound],
) {
    let (p, q) = s.degrees();
    let (cu, cv) = s.counts();
    println!(
        "{}: {} points -> B-spline surface of degree {p} x {q}, {cu} x {cv} control points ({} parameters, {} knots{}{})\n",
        a.input.display(),
        par.count,
        a.params,
        a.knots,
        if a.smooth > 0.0 { format!(", smoothing {}", a.smooth) } else { String::new() },
        if a.periodic_u { ", periodic in u" } else { "" },
    );
    let mut t = Table::new(
        &["measure", "mean", "max", "RMSE", "unit"],
        &[true, false, false, false, true],
    );
    t.row(vec![
        "|P - S(u,v)| at the parameters (eq. 15)".into(),
        num(par.mean),
        num(par.max),
        num(par.rmse),
        "data units".into(),
    ]);
    t.row(vec![
        "orthogonal distance to the surface".into(),
        num(orth.mean),
        num(orth.max),
        num(orth.rmse),
        "data units".into(),
    ]);
    t.row(vec![
        "grid points to nearest point (MBA eq. 17)".into(),
        "-".into(),
        "-".into(),
        num(grid),
        "data units".into(),
    ]);
    print!("{}", t.render());
    println!(
        "\nparameterization: {} fold-overs in {} triangles, L2 stretch {:.3} (1 = uniform), max anisotropy {}",
        pq.fold_overs,
        pq.triangles,
        pq.l2_stretch,
        num(pq.max_anisotropy)
    );
    if unconverged > 0 {
        println!("note: {unconverged} point inversions did not converge (their distance is the best found)");
    }
    if !rounds.is_empty() {
        println!();
        let mut t = Table::new(
            &["correction round", "RMSE", "max error", "unit"],
            &[false, false, false, true],
        );
        for r in rounds {
            t.row(vec![
                r.round.to_string(),
                num(r.errors.rmse),
                num(r.errors.max),
                "data units".into(),
            ]);
        }
        print!("{}", t.render());
    }
}
