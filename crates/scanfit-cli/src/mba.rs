//! `scanfit mba`: a bicubic B-spline surface z = f(x, y) through scattered
//! 2.5D points by multilevel B-spline approximation, optionally with the MBA
//! paper's projection adjustment of control points.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::mba::adjust::{knot_grid, lattice_grid_rmse, mba_adjusted, AdjustConfig, AdjustedMba};
use scanfit::mba::{lattice_surface, mba, ControlFormula, MbaConfig};
use scanfit::metrics::{orthogonal_errors, parameterization_quality, rmse_to_cloud, ErrorStats};
use scanfit::project::{DirectedConfig, InversionConfig, SurfaceInverter, WeightFactor};
use scanfit_io::json::{Provenance, SurfaceDoc, SurfaceQualityDoc};
use scanfit_io::write_all_atomic;

use crate::args::pair;
use crate::outputs::{print_written, Deviation, Picture, SurfaceOutputArgs};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit mba examples/data/terrain_50k.xyz --levels 6 -o terrain.json --png terrain.png
  scanfit mba examples/data/terrain_50k.xyz --levels 6 --adjust --weight aza04 --deviation-png dev.png
  scanfit mba lidar.las --base 3x2 --tolerance 0.05 --mesh dem.ply

Level k fits a lattice of (m 2^k + 3) x (n 2^k + 3) control values to what the
levels before it missed (Lee, Wolberg & Shin 1997); the levels are combined into
one clamped bicubic B-spline surface by refinement. --adjust projects the grid
points at the knots onto the data along z (directed projection, weight factor
--weight) and moves each control value by --alpha times the signed distance (the
MBA paper, sections 2.2-2.4), never accepting a step that raises the eq. 17 RMSE;
with --tolerance, the next level runs only while that RMSE is above it.
The table's vertical error is |z - f(x, y)| at the data points; eq. 17 is the RMSE
of the distances from the grid points at the knots to their nearest data point.";

/// Arguments of `scanfit mba`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct MbaArgs {
    #[command(flatten)]
    pub input: crate::args::InputArgs,
    /// Cells of the first lattice, "MxN" (control net (M+3) x (N+3))
    /// [default: 1 along the shorter side, the aspect ratio along the longer].
    #[arg(long, value_name = "MxN")]
    pub base: Option<String>,
    /// Most levels (each doubles the lattice).
    #[arg(long, default_value_t = 6, value_name = "L")]
    pub levels: usize,
    /// Stop once the vertical RMSE (or, with --adjust, the eq. 17 RMSE) is at most E [data units].
    #[arg(long, value_name = "E", allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Hjelle's control-value formula (turntable paper eq. 6) instead of eq. 4.
    #[arg(long)]
    pub hjelle: bool,
    /// Adjust the control points by projecting the knot grid onto the data.
    #[arg(long)]
    pub adjust: bool,
    /// Step factor of the adjustment.
    #[arg(
        long,
        default_value_t = 1.49,
        value_name = "A",
        allow_negative_numbers = true
    )]
    pub alpha: f64,
    /// Weight factor of the projection: aza04 (eq. 13), as05 (eq. 14), axis4 (eq. 15), moon (turntable eq. 19).
    #[arg(long, default_value = "moon", value_name = "W")]
    pub weight: String,
    /// Most adjustment steps per lattice.
    #[arg(long, default_value_t = 5, value_name = "N")]
    pub adjust_steps: usize,
    #[command(flatten)]
    pub out: SurfaceOutputArgs,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// One row of the level table.
#[derive(Debug, Clone, serde::Serialize)]
struct Row {
    level: usize,
    control_points: [usize; 2],
    vertical_mean: f64,
    vertical_max: f64,
    vertical_rmse: f64,
    grid_rmse: f64,
    adjusted_vertical_rmse: Option<f64>,
    adjusted_grid_rmse: Option<f64>,
    adjust_steps: Option<usize>,
    seconds: f64,
}

/// Runs `scanfit mba`.
pub fn run(a: MbaArgs) -> Result<()> {
    a.out.check()?;
    let weight = WeightFactor::from_name(&a.weight).with_context(|| {
        format!(
            "unknown --weight '{}'; use aza04, as05, axis4 or moon",
            a.weight
        )
    })?;
    if a.levels == 0 {
        bail!("--levels must be at least 1");
    }
    let config = MbaConfig {
        base: a.base.as_deref().map(|b| pair(b, "--base")).transpose()?,
        max_levels: a.levels,
        tolerance: a.tolerance,
        formula: if a.hjelle {
            ControlFormula::Hjelle
        } else {
            ControlFormula::LeeWolbergShin
        },
    };
    let adjust = AdjustConfig {
        alpha: a.alpha,
        projection: DirectedConfig {
            weight,
            ..Default::default()
        },
        max_steps: a.adjust_steps,
        ..Default::default()
    };
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage(format!("reading {}", a.input.input.display()));
    let cloud = a.input.load(a.json)?;
    let pts = cloud.points();
    let input = a.input.input.clone();
    let t0 = Instant::now();
    progress.stage(format!(
        "multilevel B-spline approximation of {} points",
        pts.len()
    ));
    let ctx = |e: scanfit::Error| anyhow::anyhow!("{}: {e}", input.display());
    let (result, rows): (AdjustedOrPlain, Vec<Row>) = if a.adjust {
        let r = mba_adjusted(pts, &config, &adjust).map_err(ctx)?;
        let rows = r
            .levels
            .iter()
            .zip(&r.mba.reports)
            .map(|(l, rep)| Row {
                level: rep.level,
                control_points: [l.cells.0 + 3, l.cells.1 + 3],
                vertical_mean: l.mba_vertical.mean,
                vertical_max: l.mba_vertical.max,
                vertical_rmse: l.mba_vertical.rmse,
                grid_rmse: l.mba_rmse,
                adjusted_vertical_rmse: Some(l.adjusted_vertical.rmse),
                adjusted_grid_rmse: Some(l.adjusted_rmse),
                adjust_steps: Some(l.steps),
                seconds: l.seconds,
            })
            .collect();
        (AdjustedOrPlain::Adjusted(r), rows)
    } else {
        let r = mba(pts, &config).map_err(ctx)?;
        // eq. 17 of each level's combined lattice (refine the sum level by level)
        let mut rows = Vec::new();
        let mut total: Option<scanfit::mba::Lattice> = None;
        for (lat, rep) in r.levels.iter().zip(&r.reports) {
            let mut t = match total.take() {
                None => lat.clone(),
                Some(t) => t.refine()?,
            };
            if rep.level > 0 {
                t.add(lat)?;
            }
            rows.push(Row {
                level: rep.level,
                control_points: [rep.cells.0 + 3, rep.cells.1 + 3],
                vertical_mean: rep.residual.mean,
                vertical_max: rep.residual.max,
                vertical_rmse: rep.residual.rmse,
                grid_rmse: lattice_grid_rmse(&cloud, &r.frame, &t)?,
                adjusted_vertical_rmse: None,
                adjusted_grid_rmse: None,
                adjust_steps: None,
                seconds: rep.seconds,
            });
            total = Some(t);
        }
        (AdjustedOrPlain::Plain(r), rows)
    };
    let mba_result = match &result {
        AdjustedOrPlain::Adjusted(r) => &r.mba,
        AdjustedOrPlain::Plain(r) => r,
    };
    let surface = lattice_surface(&mba_result.frame, &mba_result.lattice)?;
    let fit_seconds = t0.elapsed().as_secs_f64();
    progress.stage("measuring");
    let uv: Vec<[f64; 2]> = pts.iter().map(|p| mba_result.frame.unit(p)).collect();
    let vertical: Vec<f64> = pts
        .iter()
        .zip(&uv)
        .map(|(p, t)| (p.z - surface.point(t[0], t[1]).z).abs())
        .collect();
    let vstats = ErrorStats::of(&vertical);
    let inverter = SurfaceInverter::new(&surface, InversionConfig::default())?;
    let (orth, inv) = orthogonal_errors(&inverter, pts);
    let grid = rmse_to_cloud(&cloud, &knot_grid(&mba_result.frame, &mba_result.lattice))?;
    let pq = parameterization_quality(&surface, pts, &uv).unwrap_or_default();
    let mut doc = SurfaceDoc::new(&surface);
    let mut settings = BTreeMap::new();
    let (m, n) = (mba_result.lattice.m, mba_result.lattice.n);
    settings.insert("levels".to_string(), mba_result.reports.len().into());
    settings.insert("lattice_cells".to_string(), serde_json::json!([m, n]));
    settings.insert(
        "formula".to_string(),
        (if a.hjelle {
            "hjelle"
        } else {
            "lee-wolberg-shin"
        })
        .into(),
    );
    if a.adjust {
        settings.insert("adjust_alpha".to_string(), a.alpha.into());
        settings.insert("adjust_weight".to_string(), weight.name().into());
    }
    doc.provenance = Some(Provenance {
        tool: format!("scanfit {}", env!("CARGO_PKG_VERSION")),
        operation: if a.adjust {
            "mba (multilevel B-spline approximation + projection adjustment)".into()
        } else {
            "mba (multilevel B-spline approximation)".into()
        },
        parameterization: Some("xy (u = x, v = y, scaled to [0, 1])".into()),
        input: Some(input.display().to_string()),
        point_count: Some(pts.len()),
        settings,
    });
    doc.quality = Some(SurfaceQualityDoc {
        points: pts.len(),
        mean_error: vstats.mean,
        max_error: vstats.max,
        rmse: vstats.rmse,
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
    });
    progress.stage("writing");
    let (files, exaggeration) = a.out.files(
        &surface,
        &doc,
        pts,
        &Deviation {
            per_point: &vertical,
            stats: vstats,
            name: "vertical distance |z - f(x, y)|",
        },
        &input,
        &Picture::default(),
    )?;
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        let report = serde_json::json!({
            "input": input.display().to_string(),
            "point_count": pts.len(),
            "control_points": [m + 3, n + 3],
            "levels": rows,
            "quality": doc.quality,
            "seconds": fit_seconds,
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "{}: {} points -> bicubic B-spline surface, {} x {} control points ({} levels{}, {:.3} s)\n",
        input.display(),
        pts.len(),
        m + 3,
        n + 3,
        rows.len(),
        if a.adjust { ", adjusted" } else { "" },
        fit_seconds
    );
    let mut head = vec![
        "level",
        "control net",
        "vertical mean",
        "vertical max",
        "vertical RMSE",
        "eq. 17 RMSE",
    ];
    if a.adjust {
        head.extend(["adjusted vertical RMSE", "adjusted eq. 17 RMSE", "steps"]);
    }
    head.push("time (s)");
    let mut t = Table::new(&head, &[false, true]);
    for r in &rows {
        let mut cells = vec![
            r.level.to_string(),
            format!("{} x {}", r.control_points[0], r.control_points[1]),
            num(r.vertical_mean),
            num(r.vertical_max),
            num(r.vertical_rmse),
            num(r.grid_rmse),
        ];
        if a.adjust {
            cells.push(r.adjusted_vertical_rmse.map_or("-".into(), num));
            cells.push(r.adjusted_grid_rmse.map_or("-".into(), num));
            cells.push(r.adjust_steps.map_or("-".into(), |s| s.to_string()));
        }
        cells.push(format!("{:.3}", r.seconds));
        t.row(cells);
    }
    print!("{}", t.render());
    println!("(errors in data units)\n");
    let mut t = Table::new(
        &["final surface", "mean", "max", "RMSE", "unit"],
        &[true, false, false, false, true],
    );
    t.row(vec![
        "vertical distance |z - f(x, y)|".into(),
        num(vstats.mean),
        num(vstats.max),
        num(vstats.rmse),
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
        "grid points to nearest point (eq. 17)".into(),
        "-".into(),
        "-".into(),
        num(grid),
        "data units".into(),
    ]);
    print!("{}", t.render());
    print_written(&files, a.out.png.as_deref(), exaggeration);
    Ok(())
}

/// The result of either route.
enum AdjustedOrPlain {
    Adjusted(AdjustedMba),
    Plain(scanfit::mba::Mba),
}
