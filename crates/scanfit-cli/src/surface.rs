//! `scanfit fit`: a least-squares B-spline surface through scattered points.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use scanfit::base::plane_parameters;
use scanfit::bspline::Surface;
use scanfit::fit::correction::{correct_parameters, CorrectionConfig, CorrectionRound};
use scanfit::fit::surface::{fit_surface, KnotPlacement, SurfaceFitConfig};
use scanfit::metrics::{
    grid_rmse, orthogonal_errors, parameterization_quality, parametric_distances, ErrorStats,
    ParamQuality,
};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit_io::json::{Provenance, SurfaceDoc, SurfaceQualityDoc};
use scanfit_io::{read_points, write_all_atomic};

use crate::args::pair;
use crate::outputs::{check_extensions, points_file, print_written, Deviation, Picture};
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
    #[command(flatten)]
    pub out: crate::outputs::SurfaceOutputArgs,
    /// Write the points with u, v, residual and orthogonal distance (.ply or .xyz).
    #[arg(long, value_name = "POINTS")]
    pub points_out: Option<PathBuf>,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
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
    a.out.check()?;
    check_extensions(&[(&a.points_out, "--points-out", &["ply", "xyz"][..])])?;
    let progress = Progress::spinner(a.quiet);
    progress.stage(format!("reading {}", a.input.display()));
    let table = read_points(&a.input)?;
    crate::print_warnings(&table.warnings);
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
    let dist: Vec<f64> = inv.iter().map(|r| r.distance).collect();
    let (mut files, exaggeration) = a.out.files(
        &surface,
        &doc,
        pts,
        &Deviation {
            per_point: &dist,
            stats: orth,
            name: "orthogonal distance",
        },
        &a.input,
        &Picture::default(),
    )?;
    if let Some(pout) = &a.points_out {
        let u: Vec<f64> = uv.iter().map(|t| t[0]).collect();
        let v: Vec<f64> = uv.iter().map(|t| t[1]).collect();
        let attrs: [(&str, &[f64]); 4] = [
            ("u", &u),
            ("v", &v),
            ("residual", &resid),
            ("distance", &dist),
        ];
        files.push((pout.clone(), points_file(pout, pts, &attrs)));
    }
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        let report = serde_json::json!({
            "input": a.input.display().to_string(),
            "point_count": pts.len(),
            "degree": [degree.0, degree.1],
            "control_points": [surface.counts().0, surface.counts().1],
            "parameters": a.params,
            "quality": quality,
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    print_report(&a, &surface, &par, &orth, unconverged, grid, &pq, &rounds);
    print_written(&files, a.out.png.as_deref(), exaggeration);
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
