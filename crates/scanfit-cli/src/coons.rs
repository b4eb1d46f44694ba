//! `scanfit coons`: one patch of points -> boundary, corners, boundary curves,
//! bilinearly blended Coons patch, parameters, then either the Coons paper's
//! least-squares B-spline surface or the PDE paper's deformation surface.
//! The pipeline is [`scanfit::pipeline::coons`]; this file parses, reads,
//! calls, prints and writes.

use scanfit::trim::TrimmedSurface;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use scanfit::base::{BoundaryFit, CoonsProjection, Sides};
use scanfit::cloud::corners::CornerCriterion;
use scanfit::fit::surface::SurfaceFitConfig;
use scanfit::pde::PdeConfig;
use scanfit::pipeline::coons::{run as coons, CoonsConfig, CoonsReport, CoonsRoute};
use scanfit::pipeline::trim::{Loops, TrimInput};
use scanfit::project::{GridIterationConfig, InversionConfig};
use scanfit::Point3;
use scanfit_io::json::SurfaceDoc;
use scanfit_io::render::{Marker, Polyline};
use scanfit_io::write_all_atomic;

use crate::args::{choice, cli_message, value_name as name, InputArgs, Parsed, INDICES, NXM};
use crate::cloud::CriterionArg;
use crate::outputs::{
    points_file, print_written, provenance, quality_doc, samples_json, Deviation, Files, Picture,
    PngStyle, SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit coons examples/data/patch_20k.ply --pde 5x5 -o patch.json --png patch.png
  scanfit coons examples/data/patch_20k.ply --fit bspline --ctrl 20x20 -o patch.json --step patch.stp
  scanfit coons fan.xyz --sides 3 --criterion curvature --pde 10x10 --mesh fan.ply
  scanfit coons patch.ply --corners 0,130,260,390 --params closest --points-out params.ply --json

Pipeline: boundary loop of the points (alpha shape in their best-fit plane,
alpha widened where the points are sparse; --global-alpha: one alpha),
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

/// `--sides`: four, or three with one side collapsed to a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SidesArg {
    /// A four-sided patch.
    #[value(name = "4")]
    Four,
    /// A three-sided patch (the fourth side degenerates to the first corner).
    #[value(name = "3")]
    Three,
}

impl SidesArg {
    fn count(self) -> usize {
        match self {
            Self::Four => 4,
            Self::Three => 3,
        }
    }
}

/// `--curves`: how the boundary curves are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CurvesArg {
    /// End-pinned least squares (PDE paper 4.2).
    Lsq,
    /// Interpolation of every side point.
    Interpolate,
}

/// `--fit`: the surface route.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RouteArg {
    /// Least-squares B-spline surface (Coons paper).
    Bspline,
    /// PDE deformation of the Coons patch (PDE paper).
    Pde,
}

/// `--params`: how the points get their parameters on the Coons patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ParamsArg {
    /// Nearest grid vertex and iteration (Coons paper eqs. 17-22).
    Grid,
    /// Exact closest point (PDE paper 4.4).
    Closest,
}

/// `--corners`: detected, or loop positions.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CornersArg {
    /// Detected by the corner criterion.
    Auto,
    /// Loop positions of the outer boundary loop, in loop order.
    At(Vec<usize>),
}

/// `"auto"` or loop positions `"I,J,K[,L]"` ([`CornersArg`]).
pub const CORNERS: Parsed<CornersArg> = Parsed::new(corners);

fn corners(s: &str, what: &str) -> std::result::Result<CornersArg, String> {
    if s.trim() == "auto" {
        return Ok(CornersArg::Auto);
    }
    INDICES
        .parse_str(s, what)
        .map(|i| CornersArg::At(i.0))
        .map_err(|_| {
            format!("{what} '{s}' must be `auto` or loop positions I,J,K,L (whole numbers)")
        })
}

/// Arguments of `scanfit coons`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct CoonsArgs {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub outliers: crate::args::OutlierArgs,
    /// Corners: `auto` (detected) or loop positions I,J,K[,L] of the outer boundary loop.
    #[arg(long, default_value = "auto", value_name = "auto|I,J,K,L", value_parser = CORNERS)]
    pub corners: CornersArg,
    /// Number of sides of the patch: 4, or 3 (one side degenerates to a corner).
    #[arg(long, default_value = "4", value_name = "4|3", value_parser = choice::<SidesArg>())]
    pub sides: SidesArg,
    /// Corner criterion: `angle` (Coons paper) or `curvature` (PDE paper).
    #[arg(long, default_value = "angle", value_name = "C", value_parser = choice::<CriterionArg>())]
    pub criterion: CriterionArg,
    /// Alpha radius of the boundary [default: --alpha-factor x median spacing].
    #[arg(long, value_name = "A")]
    pub alpha: Option<f64>,
    /// Multiple of the median Delaunay edge used as alpha.
    #[arg(long, default_value_t = 2.5, value_name = "F")]
    pub alpha_factor: f64,
    /// One alpha everywhere, not widened where the points are sparse.
    #[arg(long)]
    pub global_alpha: bool,
    /// Boundary curves: `lsq` (end-pinned least squares) or `interpolate`.
    #[arg(long, default_value = "lsq", value_name = "HOW", value_parser = choice::<CurvesArg>())]
    pub curves: CurvesArg,
    /// Control points per boundary curve (lsq) [default: sqrt(side points), 4..30].
    #[arg(long, value_name = "N")]
    pub curve_ctrl: Option<usize>,
    /// Surface route: `bspline` (Coons paper) or `pde` (PDE paper; implied by --pde).
    #[arg(long, value_name = "ROUTE", value_parser = choice::<RouteArg>())]
    pub fit: Option<RouteArg>,
    /// Control net of the least-squares surface (bspline route), "NUxNV" or
    /// "N" [default: from the point density, round(sqrt(points / 16)) per
    /// direction, 5 to 32].
    #[arg(long, value_name = "NUxNV", value_parser = NXM)]
    pub ctrl: Option<(usize, usize)>,
    /// Degrees of the least-squares surface (bspline route), "PxQ" or "P".
    #[arg(long, default_value = "3x3", value_name = "PxQ", value_parser = NXM)]
    pub degree: (usize, usize),
    /// PDE deformation with M x N sine terms (PDE paper; 5x5 in the paper, 10x10 in its Table 2).
    #[arg(long, value_name = "MxN", value_parser = NXM)]
    pub pde: Option<(usize, usize)>,
    /// Flexural rigidity D of the PDE (does not change the surface; paper: 1).
    #[arg(long, default_value_t = 1.0, value_name = "D")]
    pub rigidity: f64,
    /// Parameters: `grid` (Coons paper) or `closest` (PDE paper) [default: grid
    /// for --fit bspline, closest for --pde].
    #[arg(long, value_name = "HOW", value_parser = choice::<ParamsArg>())]
    pub params: Option<ParamsArg>,
    /// Grid step h of --params grid (Coons paper: 0.001).
    #[arg(long, default_value_t = 0.001, value_name = "H")]
    pub h: f64,
    /// Convergence threshold epsilon of --params grid, data units (Coons
    /// paper: 0.01) [default: 1e-3 x the bounding-box diagonal].
    #[arg(long, value_name = "EPS")]
    pub epsilon: Option<f64>,
    /// Thin-plate smoothing weight λ of --fit bspline (0 = the bare
    /// least-squares fit) [default: scaled to the data, 0.001 x points /
    /// (NU x NV)²].
    #[arg(long, value_name = "L", allow_negative_numbers = true)]
    pub smooth: Option<f64>,
    /// Fit on the detected corners even when they are not clearly corners
    /// (turning by less than 30 degrees, or one side over 60% of the loop).
    #[arg(long)]
    pub force_corners: bool,
    /// Largest deviation of the exported B-spline from the PDE surface, data
    /// units [default: 1e-4 x the bounding-box diagonal].
    #[arg(long, value_name = "T")]
    pub export_tolerance: Option<f64>,
    #[command(flatten)]
    pub out: SurfaceOutputArgs,
    #[command(flatten)]
    pub trim: crate::cad::TrimArgs,
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

/// The pipeline's settings from the arguments.
fn config(a: &CoonsArgs) -> Result<CoonsConfig> {
    let sides = a.sides.count();
    let pde_terms = match (a.fit, a.pde) {
        (Some(RouteArg::Bspline), Some(_)) => {
            bail!("--fit bspline and --pde exclude each other; choose one route")
        }
        (_, Some(terms)) => Some(terms),
        (Some(RouteArg::Pde), None) => Some((5, 5)),
        (_, None) => None,
    };
    let mut cfg = CoonsConfig::default();
    cfg.assess = a.out.measure.config(cfg.assess, true);
    cfg.route = match pde_terms {
        None => {
            let mut f = SurfaceFitConfig {
                degree: a.degree,
                ..Default::default()
            };
            if let Some(ctrl) = a.ctrl {
                f.ctrl = ctrl;
                cfg.ctrl_from_density = false;
            }
            if let Some(l) = a.smooth {
                f.smoothing = l;
                cfg.relative_smoothing = None;
            }
            CoonsRoute::Bspline(f)
        }
        Some((m, n)) => CoonsRoute::Pde {
            pde: PdeConfig {
                m,
                n,
                d: a.rigidity,
            },
            export_tolerance: a.export_tolerance,
        },
    };
    let params = a.params.unwrap_or(match cfg.route {
        CoonsRoute::Bspline(_) => ParamsArg::Grid,
        _ => ParamsArg::Closest,
    });
    cfg.projection = Some(match params {
        ParamsArg::Grid => CoonsProjection::GridIteration(GridIterationConfig {
            h: a.h,
            epsilon: a.epsilon.unwrap_or(GridIterationConfig::default().epsilon),
            ..Default::default()
        }),
        ParamsArg::Closest => CoonsProjection::Inversion(InversionConfig::default()),
    });
    if a.epsilon.is_some() {
        cfg.relative_epsilon = None;
    }
    cfg.base.force_corners = a.force_corners;
    cfg.base.boundary.alpha = a.alpha;
    cfg.base.boundary.alpha_factor = a.alpha_factor;
    cfg.base.boundary.local_alpha = !a.global_alpha;
    cfg.base.corners.criterion = CornerCriterion::from(a.criterion);
    cfg.base.corners.count = sides;
    cfg.base.corner_positions = match &a.corners {
        CornersArg::Auto => None,
        CornersArg::At(c) if c.len() != sides => bail!(
            "--corners '{}' lists {} positions but --sides is {sides}; give one position per corner",
            c.iter().map(usize::to_string).collect::<Vec<_>>().join(","),
            c.len()
        ),
        CornersArg::At(c) => Some(c.clone()),
    };
    cfg.base.curves.degree = 3;
    cfg.base.curves.fit = match a.curves {
        CurvesArg::Lsq => BoundaryFit::LeastSquares {
            ctrl_count: a.curve_ctrl,
        },
        CurvesArg::Interpolate => BoundaryFit::Interpolation,
    };
    Ok(cfg)
}

/// Runs `scanfit coons`.
pub fn run(a: CoonsArgs) -> Result<()> {
    a.out.check(
        &a.input.input,
        &[(&a.points_out, "--points-out", &["ply", "xyz"][..])],
    )?;
    a.out.check_measured(
        PngStyle::Deviation,
        a.points_out.as_ref().map(|_| "--points-out"),
    )?;
    let cfg = config(&a)?;
    let t0 = Instant::now();
    let progress = Progress::spinner(a.quiet || a.json);
    let input = a.input.input.display().to_string();
    progress.stage(format!("reading {input}"));
    let mut cloud = a.outliers.apply(a.input.load(a.json)?, a.json)?;
    let mut r = coons(&cloud, &cfg, &progress)
        .map_err(|e| {
            let message = cli_message(
                &e,
                &[
                    ("export_tolerance", "--export-tolerance"),
                    (
                        "corners",
                        "--corners I,J,K,L with loop positions from `scanfit cloud boundary`, or --force-corners; a rounded outline is better fitted by `scanfit fit` or `scanfit mba`, trimmed to it",
                    ),
                    (
                        "alpha_factor",
                        "--alpha-factor, about twice the value above, or --corners I,J,K,L with loop positions from `scanfit cloud boundary --alpha-factor F --png loop.png`; an outline that is not four-sided is better fitted by `scanfit fit` or `scanfit mba`, trimmed to it",
                    ),
                ],
            );
            anyhow::anyhow!("{message}")
        })
        .with_context(|| format!("Coons patch of {input} ({} sides)", a.sides.count()))?;
    let secs = t0.elapsed().as_secs_f64();
    let trim = TrimInput {
        surface: &r.surface,
        cloud: &mut cloud,
        uv: &r.parameters.uv,
        loops: Loops::Given(&r.base.boundary),
    };
    let q = &mut r.assessment.quality;
    let trimmed = a.trim.apply(true, trim, q, &cfg.assess, &progress)?;
    let pts = cloud.points();
    a.out.guard(
        q,
        "check the corners (--corners), use fewer control points (--ctrl) or fewer PDE terms (--pde)",
    )?;
    progress.stage("writing");
    let (files, exaggeration) = outputs(&a, pts, &r, trimmed.as_ref())?;
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        return print_json(&a, pts, &r, secs, &files, trimmed.as_ref());
    }
    print_tables(&a, pts, &r, secs)?;
    crate::cad::print_trim(trimmed.as_ref())?;
    print_written(&files, a.out.png.as_deref(), exaggeration)?;
    Ok(())
}

/// The surface document: the surface, its provenance and quality record.
fn document(a: &CoonsArgs, points: usize, r: &CoonsReport) -> SurfaceDoc {
    let mut settings = BTreeMap::new();
    settings.insert("sides".into(), a.sides.count().into());
    settings.insert(
        "corners".into(),
        serde_json::json!(r.base.corners.corners.clone()),
    );
    settings.insert("criterion".into(), name(&a.criterion).into());
    settings.insert("curves".into(), name(&a.curves).into());
    match &r.pde {
        Some(p) => {
            let (m, n) = p.fit.surface.deformation.terms();
            settings.insert("pde_terms".into(), serde_json::json!([m, n]));
            settings.insert("rigidity".into(), a.rigidity.into());
            settings.insert("export_tolerance".into(), p.export_tolerance.into());
            settings.insert("export_deviation".into(), p.export_deviation.into());
        }
        None => {
            let (cu, cv) = r.surface.counts();
            settings.insert("ctrl".into(), serde_json::json!([cu, cv]));
            settings.insert("degree".into(), serde_json::json!([a.degree.0, a.degree.1]));
        }
    }
    let mut doc = SurfaceDoc::new(&r.surface);
    doc.provenance = Some(provenance(
        format!("coons ({})", r.route),
        Some(format!("Coons patch, {}", r.projection_name())),
        &a.input.input,
        points,
        settings,
    ));
    doc.quality = Some(quality_doc(&r.assessment.quality, Vec::new()));
    doc
}

/// The boundary curves (in loop order) and the corners over the pictures.
fn picture(points: &[Point3], r: &CoonsReport) -> Picture {
    let p = &r.base.patch;
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
    let outer = r.base.boundary.outer_loop();
    Picture {
        style: PngStyle::Deviation,
        lines: curves
            .into_iter()
            .zip(SIDE_COLOURS)
            .map(|(points, rgb)| Polyline {
                points,
                rgb,
                closed: false,
            })
            .collect(),
        markers: r
            .base
            .corners
            .corners
            .iter()
            .enumerate()
            .map(|(k, &q)| Marker {
                at: points[outer[q]],
                rgb: [255, 255, 255],
                label: format!("C{k}"),
            })
            .collect(),
        legend: vec![format!(
            "{}; dots = points, lines = boundary curves, C0.. = corners",
            r.route
        )],
        ..Default::default()
    }
}

/// Every requested output file, and the exaggeration of `--png`.
fn outputs(
    a: &CoonsArgs,
    points: &[Point3],
    r: &CoonsReport,
    trimmed: Option<&TrimmedSurface>,
) -> Result<(Files, f64)> {
    let dist = r.assessment.distances();
    let (mut files, exaggeration) = a.out.files_with(
        &r.surface,
        trimmed,
        &document(a, points.len(), r),
        points,
        &Deviation {
            per_point: dist,
            stats: r.assessment.quality.orthogonal,
            name: "orthogonal distance",
        },
        &a.input.input,
        &picture(points, r),
    )?;
    if let Some(pout) = &a.points_out {
        let uv = &r.parameters.uv;
        let u: Vec<f64> = uv.iter().map(|t| t[0]).collect();
        let v: Vec<f64> = uv.iter().map(|t| t[1]).collect();
        let outside: Vec<f64> = r
            .parameters
            .outside
            .iter()
            .map(|&o| f64::from(u8::from(o)))
            .collect();
        let attrs: [(&str, &[f64]); 6] = [
            ("u", &u),
            ("v", &v),
            ("coons", &r.coons_distances),
            ("residual", &r.assessment.residuals),
            ("distance", dist),
            ("outside", &outside),
        ];
        files.push((pout.clone(), points_file(pout, points, &attrs)));
    }
    Ok((files, exaggeration))
}

/// Mean, max and RMSE as JSON.
fn stats_json(e: &scanfit::metrics::ErrorStats) -> serde_json::Value {
    serde_json::json!({"mean": e.mean, "max": e.max, "rmse": e.rmse})
}

/// `--json`: the report on stdout.
fn print_json(
    a: &CoonsArgs,
    points: &[Point3],
    r: &CoonsReport,
    secs: f64,
    files: &Files,
    trimmed: Option<&TrimmedSurface>,
) -> Result<()> {
    let outer = r.base.boundary.outer_loop();
    let (cu, cv) = r.surface.counts();
    let (dp, dq) = r.surface.degrees();
    let q = &r.assessment.quality;
    let par = &r.parameters;
    let mut report = serde_json::json!({
        "input": a.input.input.display().to_string(),
        "point_count": points.len(),
        "sides": a.sides.count(),
        "boundary": {
            "outer_loop_points": outer.len(),
            "alpha": r.base.boundary.alpha,
        },
        "corners": r.base.corners.corners.iter().zip(&r.base.corner_angles).map(|(&k, ang)| {
            let p = points[outer[k]];
            serde_json::json!({
                "position": k,
                "index": outer[k],
                "point": [p.x, p.y, p.z],
                "angle_degrees": ang.to_degrees(),
                "turning_degrees": 180.0 - ang.to_degrees(),
            })
        }).collect::<Vec<_>>(),
        "curves": r.base.curves.iter().zip(&r.base.side_points).map(|(c, s)| serde_json::json!({
            "side_points": s.len(),
            "control_points": c.curve.control_points().len(),
            "max_error": c.max_error,
        })).collect::<Vec<_>>(),
        "parameters": {
            "method": r.projection_name(),
            "outside": par.outside_count,
            "outside_tolerance": par.outside_tolerance,
            "unconverged": par.unconverged,
            "mean_iterations": par.mean_iterations,
        },
        "route": r.route,
        "trim": crate::cad::trim_json(trimmed),
        "coons_error": stats_json(&r.coons_errors),
        "fit_error": stats_json(&q.at_parameters),
        "orthogonal": stats_json(&q.orthogonal),
        "surface_to_points": samples_json(q),
        "surface": {"degree": [dp, dq], "control_points": [cu, cv]},
        "seconds": secs,
        "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
    });
    if let Some(p) = &r.pde {
        report["export_deviation"] = p.export_deviation.into();
        report["export_capped"] = p.export_capped.into();
    }
    out!(
        "{}",
        scanfit_io::json::finite_json(&report, "the JSON report")?
    );
    Ok(())
}

/// The steps table: boundary, corners, curves, parameters, surface, time.
fn steps_table(a: &CoonsArgs, points: usize, r: &CoonsReport, secs: f64) -> Table {
    let join = |v: Vec<String>, sep: &str| v.join(sep);
    let par = &r.parameters;
    let (cu, cv) = r.surface.counts();
    let (dp, dq) = r.surface.degrees();
    let mut t = Table::new(&["step", "result"], &[true, true]);
    t.row(vec![
        "boundary".into(),
        format!(
            "outer loop of {} points, alpha {}",
            r.base.boundary.outer_loop().len(),
            num(r.base.boundary.alpha)
        ),
    ]);
    t.row(vec![
        "corners (loop position: angle, turn)".into(),
        join(
            r.base
                .corners
                .corners
                .iter()
                .zip(&r.base.corner_angles)
                .enumerate()
                .map(|(k, (q, ang))| {
                    format!(
                        "C{k} {q}: {:.0} deg, turns {:.0} deg",
                        ang.to_degrees(),
                        180.0 - ang.to_degrees()
                    )
                })
                .collect(),
            ", ",
        ),
    ]);
    let curves = &r.base.curves;
    t.row(vec![
        format!("boundary curves ({})", name(&a.curves)),
        format!(
            "{} control points, max error {}",
            join(
                curves
                    .iter()
                    .map(|c| c.curve.control_points().len().to_string())
                    .collect(),
                "/"
            ),
            join(curves.iter().map(|c| num(c.max_error)).collect(), "/")
        ),
    ]);
    t.row(vec![
        format!("parameters ({})", r.projection_name()),
        format!(
            "{} outside the patch ({:.2}%), {} unconverged, {:.1} iterations on average",
            par.outside_count,
            100.0 * par.outside_count as f64 / points.max(1) as f64,
            par.unconverged,
            par.mean_iterations
        ),
    ]);
    let export = r.pde.as_ref().map(|p| {
        format!(
            " (B-spline form within {} of S; tolerance {}{})",
            num(p.export_deviation),
            num(p.export_tolerance),
            if p.export_capped {
                ", not reached: capped at the number of input points"
            } else {
                ""
            }
        )
    });
    t.row(vec![
        "surface".into(),
        format!(
            "degree {dp} x {dq}, {cu} x {cv} control points{}",
            export.unwrap_or_default()
        ),
    ]);
    t.row(vec!["time (s)".into(), format!("{secs:.2}")]);
    t
}

/// The tables: the steps, then the errors.
fn print_tables(a: &CoonsArgs, points: &[Point3], r: &CoonsReport, secs: f64) -> Result<()> {
    outln!(
        "{}: {} points -> {}-sided Coons patch -> {}\n",
        a.input.input.display(),
        points.len(),
        a.sides.count(),
        r.route
    );
    out!("{}", steps_table(a, points.len(), r, secs).render());
    outln!();
    let mut t = Table::new(
        &["error", "mean", "max", "RMSE", "unit"],
        &[true, false, false, false, true],
    );
    let q = &r.assessment.quality;
    let surface = if r.pde.is_some() {
        "PDE surface"
    } else {
        "B-spline surface"
    };
    for (label, e) in [
        (
            "Coons patch |P - S_c(u,v)| (eq. 15)".to_string(),
            &r.coons_errors,
        ),
        (format!("{surface} |P - S(u,v)| (eq. 15)"), &q.at_parameters),
        (
            "orthogonal distance to the exported surface".to_string(),
            &q.orthogonal,
        ),
    ] {
        t.row(vec![
            label,
            num(e.mean),
            num(e.max),
            num(e.rmse),
            "data units".into(),
        ]);
    }
    out!("{}", t.render());
    Ok(())
}
