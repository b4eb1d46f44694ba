//! `scanfit coons`: one patch of points -> boundary, corners, boundary curves,
//! bilinearly blended Coons patch, parameters, then either the Coons paper's
//! least-squares B-spline surface or the PDE paper's deformation surface.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::base::{
    coons_from_cloud, coons_parameters, BoundaryCurveConfig, BoundaryFit, CoonsFromCloudConfig,
    CoonsParamConfig, CoonsProjection, Sides,
};
use scanfit::cloud::boundary::BoundaryConfig;
use scanfit::cloud::corners::{CornerConfig, CornerCriterion};
use scanfit::fit::surface::{fit_surface, SurfaceFitConfig};
use scanfit::metrics::{
    grid_rmse, orthogonal_errors, parameterization_quality, parametric_distances, ErrorStats,
};
use scanfit::pde::{fit_pde, BsplineConversionConfig, PdeConfig};
use scanfit::project::{GridIterationConfig, InversionConfig, SurfaceInverter};
use scanfit::Point3;
use scanfit_io::json::{Provenance, SurfaceDoc, SurfaceQualityDoc};
use scanfit_io::render::{Marker, Polyline};
use scanfit_io::write_all_atomic;

use crate::args::pair;
use crate::cloud::InputArgs;
use crate::outputs::{
    check_extensions, points_file, print_written, Deviation, Picture, PngStyle, SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit coons examples/data/patch_20k.ply --pde 5x5 -o patch.json --png patch.png
  scanfit coons examples/data/patch_20k.ply --fit bspline --ctrl 20x20 -o patch.json --step patch.stp
  scanfit coons fan.xyz --sides 3 --criterion curvature --pde 10x10 --mesh fan.ply
  scanfit coons patch.ply --corners 0,130,260,390 --params closest --points-out params.ply --json

Pipeline: boundary loop of the points (alpha shape in their best-fit plane),
corners (smallest turning angle, Coons paper eqs. 10-12, or three-point
curvature, PDE paper 4.1; --corners gives loop positions as listed by
`scanfit cloud boundary`), one B-spline per side (end-pinned least squares on
chord-length parameters with uniform knots, PDE paper 4.2), the bilinearly
blended Coons patch (Coons paper eq. 16, PDE paper eq. 1; with --sides 3 the
three sides are C0->C1, C1->C2, C2->C0 and the fourth side collapses to the
first corner C0, the apex: list the corner you want as apex first in
--corners), parameters on
it (--params grid: the Coons paper's nearest grid vertex at step h plus the
iteration of eqs. 17-22; closest: exact closest point), then
  --fit bspline: least-squares B-spline surface on those parameters (Coons paper);
  --pde MxN:     S = S_c + thin-plate deformation with M x N sine terms fitted by
                 least squares (PDE paper eqs. 11-14), exported as a B-spline
                 within --export-tolerance.
Errors: eq. 15 of the PDE paper (|P - S(u,v)| at the parameters) for the Coons
patch and the result, and orthogonal distances to the exported surface.
Points outside the patch project onto its boundary sideways; they are counted.";

/// Arguments of `scanfit coons`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct CoonsArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Corners: `auto` (detected) or loop positions I,J,K[,L] of the outer boundary loop.
    #[arg(long, default_value = "auto", value_name = "auto|I,J,K,L")]
    pub corners: String,
    /// Number of sides of the patch: 4, or 3 (one side degenerates to a corner).
    #[arg(long, default_value_t = 4, value_name = "4|3")]
    pub sides: usize,
    /// Corner criterion: `angle` (Coons paper) or `curvature` (PDE paper).
    #[arg(long, default_value = "angle", value_name = "C")]
    pub criterion: String,
    /// Alpha radius of the boundary [default: --alpha-factor x median spacing].
    #[arg(long, value_name = "A")]
    pub alpha: Option<f64>,
    /// Multiple of the median Delaunay edge used as alpha.
    #[arg(long, default_value_t = 2.5, value_name = "F")]
    pub alpha_factor: f64,
    /// Boundary curves: `lsq` (end-pinned least squares) or `interpolate`.
    #[arg(long, default_value = "lsq", value_name = "HOW")]
    pub curves: String,
    /// Control points per boundary curve (lsq) [default: sqrt(side points), 4..30].
    #[arg(long, value_name = "N")]
    pub curve_ctrl: Option<usize>,
    /// Surface route: `bspline` (Coons paper) or `pde` (PDE paper; implied by --pde).
    #[arg(long, value_name = "ROUTE")]
    pub fit: Option<String>,
    /// Control net of the least-squares surface (bspline route), "NUxNV" or "N".
    #[arg(long, default_value = "20x20", value_name = "NUxNV")]
    pub ctrl: String,
    /// Degrees of the least-squares surface (bspline route), "PxQ" or "P".
    #[arg(long, default_value = "3x3", value_name = "PxQ")]
    pub degree: String,
    /// PDE deformation with M x N sine terms (PDE paper; 5x5 in the paper, 10x10 in its Table 2).
    #[arg(long, value_name = "MxN")]
    pub pde: Option<String>,
    /// Flexural rigidity D of the PDE (does not change the surface; paper: 1).
    #[arg(long, default_value_t = 1.0, value_name = "D")]
    pub rigidity: f64,
    /// Parameters: `grid` (Coons paper) or `closest` (PDE paper) [default: grid
    /// for --fit bspline, closest for --pde].
    #[arg(long, value_name = "HOW")]
    pub params: Option<String>,
    /// Grid step h of --params grid (Coons paper: 0.001).
    #[arg(long, default_value_t = 0.001, value_name = "H")]
    pub h: f64,
    /// Convergence threshold epsilon of --params grid, data units (Coons paper: 0.01).
    #[arg(long, default_value_t = 0.01, value_name = "EPS")]
    pub epsilon: f64,
    /// Largest deviation of the exported B-spline from the PDE surface, data
    /// units [default: 1e-4 x the bounding-box diagonal].
    #[arg(long, value_name = "T")]
    pub export_tolerance: Option<f64>,
    #[command(flatten)]
    pub out: SurfaceOutputArgs,
    /// Write the points with u, v, coons (|P - S_c|), residual (|P - S|),
    /// distance (orthogonal) and outside (1 = outside the patch).
    #[arg(long, value_name = "POINTS")]
    pub points_out: Option<PathBuf>,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

const SIDE_COLOURS: [[u8; 3]; 4] = [[220, 30, 30], [30, 110, 220], [230, 140, 0], [150, 40, 190]];

/// Runs `scanfit coons`.
pub fn run(a: CoonsArgs) -> Result<()> {
    a.out.check()?;
    check_extensions(&[(&a.points_out, "--points-out", &["ply", "xyz"][..])])?;
    if a.sides != 3 && a.sides != 4 {
        bail!(
            "--sides {}: a Coons patch has 4 sides, or 3 with one degenerate",
            a.sides
        );
    }
    let pde_terms = match (a.fit.as_deref(), &a.pde) {
        (Some("bspline"), Some(_)) => {
            bail!("--fit bspline and --pde exclude each other; choose one route")
        }
        (None | Some("pde"), Some(t)) => Some(pair(t, "--pde")?),
        (Some("pde"), None) => Some((5, 5)),
        (None | Some("bspline"), None) => None,
        (Some(f), _) => bail!("unknown --fit '{f}'; use bspline or pde (with --pde MxN)"),
    };
    let criterion = match a.criterion.as_str() {
        "angle" => CornerCriterion::TurningAngle,
        "curvature" => CornerCriterion::ThreePointCurvature,
        c => bail!("unknown --criterion '{c}'; use angle or curvature"),
    };
    let corner_positions: Option<Vec<usize>> = match a.corners.as_str() {
        "auto" => None,
        s => {
            let c: Vec<usize> = s
                .split(',')
                .map(|x| x.trim().parse::<usize>())
                .collect::<std::result::Result<_, _>>()
                .with_context(|| {
                    format!(
                        "--corners '{s}' must be `auto` or loop positions I,J,K,L (whole numbers)"
                    )
                })?;
            if c.len() != a.sides {
                bail!(
                    "--corners '{s}' lists {} positions but --sides is {}; give one position per corner",
                    c.len(),
                    a.sides
                );
            }
            Some(c)
        }
    };
    let fit = match a.curves.as_str() {
        "lsq" => BoundaryFit::LeastSquares {
            ctrl_count: a.curve_ctrl,
        },
        "interpolate" => BoundaryFit::Interpolation,
        c => bail!("unknown --curves '{c}'; use lsq or interpolate"),
    };
    let params_how = a.params.clone().unwrap_or_else(|| {
        if pde_terms.is_some() {
            "closest"
        } else {
            "grid"
        }
        .into()
    });
    let projection = match params_how.as_str() {
        "grid" => CoonsProjection::GridIteration(GridIterationConfig {
            h: a.h,
            epsilon: a.epsilon,
            ..Default::default()
        }),
        "closest" => CoonsProjection::Inversion(InversionConfig::default()),
        p => bail!("unknown --params '{p}'; use grid or closest"),
    };
    let (degree, ctrl) = (pair(&a.degree, "--degree")?, pair(&a.ctrl, "--ctrl")?);

    let t0 = Instant::now();
    let progress = Progress::spinner(a.quiet || a.json);
    let input = a.input.input.display().to_string();
    progress.stage(format!("reading {input}"));
    let (cloud, dropped) = a.input.load()?;
    if dropped > 0 && !a.json {
        eprintln!("note: {dropped} points with NaN or infinite coordinates dropped");
    }
    let pts = cloud.points();
    progress.stage(format!("boundary and corners of {} points", pts.len()));
    let cfg = CoonsFromCloudConfig {
        boundary: BoundaryConfig {
            alpha: a.alpha,
            alpha_factor: a.alpha_factor,
        },
        corners: CornerConfig {
            criterion,
            count: a.sides,
            ..Default::default()
        },
        corner_positions,
        curves: BoundaryCurveConfig { degree: 3, fit },
        ..Default::default()
    };
    let base = coons_from_cloud(pts, &cfg)
        .with_context(|| format!("Coons patch of {input} ({} sides)", a.sides))?;
    let coons_b = base.patch.to_bspline()?;
    progress.stage(format!("parameters on the Coons patch ({params_how})"));
    let par = coons_parameters(
        &coons_b,
        pts,
        &CoonsParamConfig {
            projection,
            outside_tolerance: None,
        },
    )?;
    let coons_err = ErrorStats::of(&parametric_distances(&coons_b, pts, &par.uv));
    let diag = cloud.diagonal();
    let (surface, fit_err, export_dev, route) = match pde_terms {
        None => {
            progress.stage(format!(
                "least-squares surface, {} x {} control points",
                ctrl.0, ctrl.1
            ));
            let s = fit_surface(
                pts,
                &par.uv,
                &SurfaceFitConfig {
                    degree,
                    ctrl,
                    ..Default::default()
                },
            )?;
            let e = ErrorStats::of(&parametric_distances(&s, pts, &par.uv));
            (
                s,
                e,
                None,
                format!(
                    "least-squares B-spline surface, {} x {} control points (Coons paper)",
                    ctrl.0, ctrl.1
                ),
            )
        }
        Some((m, n)) => {
            progress.stage(format!("PDE deformation, {m} x {n} terms"));
            let f = fit_pde(
                &base.patch,
                pts,
                &par.uv,
                &PdeConfig {
                    m,
                    n,
                    d: a.rigidity,
                },
            )?;
            let tol = a.export_tolerance.unwrap_or(1e-4 * diag);
            progress.stage("B-spline form of the PDE surface");
            let b = f.surface.to_bspline(&BsplineConversionConfig::new(tol))?;
            (
                b.surface,
                f.errors,
                Some((b.max_deviation, tol)),
                format!("Coons patch + PDE deformation, {m} x {n} terms (PDE paper)"),
            )
        }
    };
    progress.stage("orthogonal distances");
    let inverter = SurfaceInverter::new(&surface, InversionConfig::default())?;
    let (orth, inv) = orthogonal_errors(&inverter, pts);
    let resid: Vec<f64> = match pde_terms {
        None => parametric_distances(&surface, pts, &par.uv),
        Some(_) => Vec::new(),
    };
    let secs = t0.elapsed().as_secs_f64();

    progress.stage("writing");
    let curve_ctrl: Vec<usize> = base
        .curves
        .iter()
        .map(|c| c.curve.control_points().len())
        .collect();
    let curve_err: Vec<f64> = base.curves.iter().map(|c| c.max_error).collect();
    let outer = base.boundary.outer_loop();
    // the MBA paper's eq. 17 and the parameterization's fold-overs and stretch
    let grid = grid_rmse(&surface, pts, None)?;
    let pq = parameterization_quality(&surface, pts, &par.uv).unwrap_or_default();
    let quality = SurfaceQualityDoc {
        points: pts.len(),
        mean_error: fit_err.mean,
        max_error: fit_err.max,
        rmse: fit_err.rmse,
        mean_distance: orth.mean,
        max_distance: orth.max,
        rmse_distance: orth.rmse,
        unconverged: inv.iter().filter(|r| !r.converged).count(),
        grid_rmse: grid,
        triangles: pq.triangles,
        fold_overs: pq.fold_overs,
        l2_stretch: pq.l2_stretch,
        max_anisotropy: pq.max_anisotropy,
        correction_rmse: Vec::new(),
    };
    let mut settings = std::collections::BTreeMap::new();
    settings.insert("sides".into(), a.sides.into());
    settings.insert(
        "corners".into(),
        serde_json::json!(base.corners.corners.clone()),
    );
    settings.insert("criterion".into(), a.criterion.clone().into());
    settings.insert("curves".into(), a.curves.clone().into());
    match pde_terms {
        Some((m, n)) => {
            settings.insert("pde_terms".into(), serde_json::json!([m, n]));
            settings.insert("rigidity".into(), a.rigidity.into());
            if let Some((dev, tol)) = export_dev {
                settings.insert("export_tolerance".into(), tol.into());
                settings.insert("export_deviation".into(), dev.into());
            }
        }
        None => {
            settings.insert("ctrl".into(), serde_json::json!([ctrl.0, ctrl.1]));
            settings.insert("degree".into(), serde_json::json!([degree.0, degree.1]));
        }
    }
    let mut doc = SurfaceDoc::new(&surface);
    doc.provenance = Some(Provenance {
        tool: format!("scanfit {}", env!("CARGO_PKG_VERSION")),
        operation: format!("coons ({route})"),
        parameterization: Some(format!("Coons patch, {params_how}")),
        input: Some(input.clone()),
        point_count: Some(pts.len()),
        settings,
    });
    doc.quality = Some(quality.clone());
    let p = &base.patch;
    let sample = |f: &dyn Fn(f64) -> Point3| -> Vec<Point3> {
        (0..=200).map(|k| f(k as f64 / 200.0)).collect()
    };
    // in loop order: C0->C1 (v = 0), C1->C2 (u = 1), C2->C3 (v = 1 backwards), C3->C0 (u = 0)
    let mut curves = vec![
        sample(&|t| p.bottom().point(t)),
        sample(&|t| p.right().point(t)),
        sample(&|t| p.top().point(1.0 - t)),
    ];
    if p.sides() == Sides::Four {
        curves.push(sample(&|t| p.left().point(1.0 - t)));
    }
    let picture = Picture {
        style: PngStyle::Deviation,
        lines: curves
            .into_iter()
            .enumerate()
            .map(|(k, points)| Polyline {
                points,
                rgb: SIDE_COLOURS[k],
                closed: false,
            })
            .collect(),
        markers: base
            .corners
            .corners
            .iter()
            .enumerate()
            .map(|(k, &q)| Marker {
                at: pts[outer[q]],
                rgb: [255, 255, 255],
                label: format!("C{k}"),
            })
            .collect(),
        legend: vec![format!(
            "{route}; dots = points, lines = boundary curves, C0.. = corners"
        )],
    };
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
        &a.input.input,
        &picture,
    )?;
    if let Some(pout) = &a.points_out {
        let u: Vec<f64> = par.uv.iter().map(|t| t[0]).collect();
        let v: Vec<f64> = par.uv.iter().map(|t| t[1]).collect();
        let coons_d = parametric_distances(&coons_b, pts, &par.uv);
        let residual = if resid.is_empty() {
            parametric_distances(&surface, pts, &par.uv)
        } else {
            resid
        };
        let outside: Vec<f64> = par
            .outside
            .iter()
            .map(|&o| f64::from(u8::from(o)))
            .collect();
        let attrs: [(&str, &[f64]); 6] = [
            ("u", &u),
            ("v", &v),
            ("coons", &coons_d),
            ("residual", &residual),
            ("distance", &dist),
            ("outside", &outside),
        ];
        files.push((pout.clone(), points_file(pout, pts, &attrs)));
    }
    write_all_atomic(&files)?;
    progress.finish();

    let (cu, cv) = surface.counts();
    let (dp, dq) = surface.degrees();
    if a.json {
        let report = serde_json::json!({
            "input": input,
            "point_count": pts.len(),
            "sides": a.sides,
            "boundary": {
                "outer_loop_points": outer.len(),
                "alpha": base.boundary.alpha,
            },
            "corners": base.corners.corners.iter().zip(&base.corner_angles).map(|(&q, ang)| serde_json::json!({
                "position": q,
                "index": outer[q],
                "point": [pts[outer[q]].x, pts[outer[q]].y, pts[outer[q]].z],
                "angle_degrees": ang.to_degrees(),
            })).collect::<Vec<_>>(),
            "curves": base.curves.iter().zip(&base.side_points).map(|(c, s)| serde_json::json!({
                "side_points": s.len(),
                "control_points": c.curve.control_points().len(),
                "max_error": c.max_error,
            })).collect::<Vec<_>>(),
            "parameters": {
                "method": params_how,
                "outside": par.outside_count,
                "outside_tolerance": par.outside_tolerance,
                "unconverged": par.unconverged,
                "mean_iterations": par.mean_iterations,
            },
            "route": route,
            "coons_error": {"mean": coons_err.mean, "max": coons_err.max, "rmse": coons_err.rmse},
            "fit_error": {"mean": fit_err.mean, "max": fit_err.max, "rmse": fit_err.rmse},
            "orthogonal": {"mean": orth.mean, "max": orth.max, "rmse": orth.rmse},
            "export_deviation": export_dev.map(|(d, _)| d),
            "surface": {"degree": [dp, dq], "control_points": [cu, cv]},
            "seconds": secs,
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "{input}: {} points -> {}-sided Coons patch -> {route}\n",
        pts.len(),
        a.sides
    );
    let mut t = Table::new(&["step", "result"], &[true, true]);
    t.row(vec![
        "boundary".into(),
        format!(
            "outer loop of {} points, alpha {}",
            outer.len(),
            num(base.boundary.alpha)
        ),
    ]);
    t.row(vec![
        "corners (loop position: angle)".into(),
        base.corners
            .corners
            .iter()
            .zip(&base.corner_angles)
            .enumerate()
            .map(|(k, (q, ang))| format!("C{k} {q}: {:.0} deg", ang.to_degrees()))
            .collect::<Vec<_>>()
            .join(", "),
    ]);
    t.row(vec![
        format!("boundary curves ({})", a.curves),
        format!(
            "{} control points, max error {}",
            curve_ctrl
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join("/"),
            curve_err
                .iter()
                .map(|&e| num(e))
                .collect::<Vec<_>>()
                .join("/")
        ),
    ]);
    t.row(vec![
        format!("parameters ({params_how})"),
        format!(
            "{} outside the patch ({:.2}%), {} unconverged, {:.1} iterations on average",
            par.outside_count,
            100.0 * par.outside_count as f64 / pts.len().max(1) as f64,
            par.unconverged,
            par.mean_iterations
        ),
    ]);
    t.row(vec![
        "surface".into(),
        format!(
            "degree {dp} x {dq}, {cu} x {cv} control points{}",
            export_dev
                .map(|(d, tol)| format!(
                    " (B-spline form within {} of S; tolerance {})",
                    num(d),
                    num(tol)
                ))
                .unwrap_or_default()
        ),
    ]);
    t.row(vec!["time (s)".into(), format!("{secs:.2}")]);
    print!("{}", t.render());
    println!();
    let mut t = Table::new(
        &["error", "mean", "max", "RMSE", "unit"],
        &[true, false, false, false, true],
    );
    t.row(vec![
        "Coons patch |P - S_c(u,v)| (eq. 15)".into(),
        num(coons_err.mean),
        num(coons_err.max),
        num(coons_err.rmse),
        "data units".into(),
    ]);
    t.row(vec![
        format!(
            "{} |P - S(u,v)| (eq. 15)",
            if pde_terms.is_some() {
                "PDE surface"
            } else {
                "B-spline surface"
            }
        ),
        num(fit_err.mean),
        num(fit_err.max),
        num(fit_err.rmse),
        "data units".into(),
    ]);
    t.row(vec![
        "orthogonal distance to the exported surface".into(),
        num(orth.mean),
        num(orth.max),
        num(orth.rmse),
        "data units".into(),
    ]);
    print!("{}", t.render());
    print_written(&files, a.out.png.as_deref(), exaggeration);
    Ok(())
}
