//! `scanfit turntable`: the virtual turntable parameterization of a
//! cylinder-like cloud (a head, a bottle, an arm) and a least-squares
//! B-spline surface closed around the axis. The pipeline is
//! [`scanfit::pipeline::turntable`]; this file parses, reads, calls, prints
//! and writes.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use scanfit::base::turntable::{AxisChoice, EndShape, Ends, STAGES};
use scanfit::pipeline::turntable::{
    run as turntable, TurntableConfig, TurntableReport, WeightComparison,
};
use scanfit::project::WeightFactor;
use scanfit::{PointCloud, Vector3};
use scanfit_io::json::SurfaceDoc;
use scanfit_io::write_all_atomic;

use crate::args::{choice, cli_message, InputArgs, Parsed, NXM};
use crate::outputs::{
    print_written, provenance, quality_doc, samples_json, Deviation, Files, Picture, PngStyle,
    SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit turntable examples/data/blob_30k.ply -o blob.json --png blob.png
  scanfit turntable head.ply --axis y --layers 50 --ctrl 40x60 --mesh head.ply --points-out params.ply
  scanfit turntable bottle.xyz --axis -0.34,0.91,0.24 --compare-weights

The cloud turns about the axis (principal axis unless --axis) in --views steps;
each turn keeps the points visible from +z (hidden point removal) and fits a
height field to them (multilevel B-splines). On each of --layers layers across
the axis the height fields' grid rows, trimmed where neighbouring views cross,
form a closed curve; its samples are projected onto the cloud inside the layer
plane (directed projection, --weight) until the RMSE stops improving. The layer
curves make a base surface closed around the axis, refined along its normal and
relaxed; every point's orthogonal projection onto it gives (u, v), and a
least-squares surface periodic in u is fitted (--ctrl). --png shows the points
and the fitted surface coloured by each point's distance to it.";

/// `--weight`: the weight factor of the directed projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum WeightArg {
    /// Eq. 19 of the turntable paper (default).
    Moon,
    /// Eq. 15 (Azariadis 2004).
    Aza04,
    /// Eq. 16 (Azariadis & Sapidis 2005).
    As05,
    /// `1 / |(p_d - p) x n|^4`, the MBA paper's eq. 15 as printed (not in
    /// the turntable paper; accepted, not listed).
    #[value(hide = true)]
    Axis4,
}

impl From<WeightArg> for WeightFactor {
    fn from(w: WeightArg) -> Self {
        match w {
            WeightArg::Moon => Self::DistanceOffset,
            WeightArg::Aza04 => Self::PointDistance,
            WeightArg::As05 => Self::DampedDistanceOffset,
            WeightArg::Axis4 => Self::LineOffset,
        }
    }
}

/// `--ends`: the points beyond the end layers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum EndsArg {
    /// Kept out of the fit; the surface spans the layers.
    Exclude,
    /// `v` continued past the base surface and every point fitted.
    Extend,
}

/// `--axis`: `auto`/`principal`, `x`, `y`, `z` or a direction `X,Y,Z`.
pub const AXIS: Parsed<AxisChoice> = Parsed::new(axis);

fn axis(s: &str, what: &str) -> std::result::Result<AxisChoice, String> {
    Ok(match s.trim().to_ascii_lowercase().as_str() {
        "auto" | "principal" => AxisChoice::Principal,
        "x" => AxisChoice::Given(Vector3::x()),
        "y" => AxisChoice::Given(Vector3::y()),
        "z" => AxisChoice::Given(Vector3::z()),
        _ => AxisChoice::Given(crate::args::VECTOR3.parse_str(s, what).map_err(|_| {
            format!(
                "{what} '{s}' must be auto, x, y, z or a direction X,Y,Z (three finite numbers)"
            )
        })?),
    })
}

/// Arguments of `scanfit turntable`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct TurntableArgs {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub outliers: crate::args::OutlierArgs,
    /// Turntable axis: x, y (the paper's), z, a direction "X,Y,Z", or "auto"
    /// (the cloud's principal axis).
    #[arg(long, default_value = "auto", value_name = "AXIS", allow_hyphen_values = true, value_parser = AXIS)]
    pub axis: AxisChoice,
    /// Turns of the virtual turntable (the paper: 4, every 90 degrees).
    #[arg(long, default_value_t = 4, value_name = "V")]
    pub views: usize,
    /// Layers across the axis (closed layer curves).
    #[arg(long, default_value_t = 40, value_name = "N")]
    pub layers: usize,
    /// Grid points per view and layer on the height fields.
    #[arg(long, default_value_t = 32, value_name = "N")]
    pub grid: usize,
    /// Control net of the fitted surface, "NUxNV" (NU around the axis, periodic).
    #[arg(long, default_value = "40x40", value_name = "NUxNV", value_parser = NXM)]
    pub ctrl: (usize, usize),
    /// Weight factor of the directed projection: moon (eq. 19), aza04 (eq. 15), as05 (eq. 16).
    #[arg(long, default_value = "moon", value_name = "W", value_parser = choice::<WeightArg>())]
    pub weight: WeightArg,
    /// Most projection rounds of the layer curves.
    #[arg(long, default_value_t = 10, value_name = "N")]
    pub rounds: usize,
    /// Refinement rounds of the base surface (projection along the normal, relaxation).
    #[arg(long, default_value_t = 2, value_name = "N")]
    pub refine: usize,
    /// Fraction of the cloud's height left out at each closed end of the
    /// layers (closed ends need a section around the axis); an end the data
    /// show to be open (a rim, no points near the axis) gets none.
    #[arg(long, default_value_t = 0.03, value_name = "F")]
    pub margin: f64,
    /// Points beyond the end layers: "exclude" (kept out of the fit; the
    /// surface spans the layers) or "extend" (v continued past the base
    /// surface and every point fitted; around a closed end the surface may
    /// flare where no points hold it).
    #[arg(long, default_value = "exclude", value_name = "MODE", value_parser = choice::<EndsArg>())]
    pub ends: EndsArg,
    /// Also print the RMSE per projection round for the three weight factors
    /// from the same layer curves (the paper's Tables 1-2).
    #[arg(long)]
    pub compare_weights: bool,
    /// Rounds of the weight comparison.
    #[arg(long, default_value_t = 5, value_name = "N")]
    pub compare_rounds: usize,
    /// Write the points with their parameters and deviation (attributes u, v,
    /// deviation) as .ply or .xyz.
    #[arg(long, value_name = "POINTS.ply")]
    pub points_out: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub out: SurfaceOutputArgs,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The pipeline's settings from the arguments.
fn config(a: &TurntableArgs) -> TurntableConfig {
    let weight = WeightFactor::from(a.weight);
    let mut cfg = TurntableConfig::default();
    cfg.assess = a.out.measure.config(cfg.assess, true);
    let t = &mut cfg.turntable;
    t.axis = a.axis;
    t.views.views = a.views;
    t.views.grid_u = a.grid;
    t.layers.layers = a.layers;
    t.layers.max_rounds = a.rounds;
    t.layers.projection.weight = weight;
    t.layers.margin = a.margin;
    t.refine.rounds = a.refine;
    t.refine.projection.weight = weight;
    t.ends = match a.ends {
        EndsArg::Exclude => Ends::Exclude,
        EndsArg::Extend => Ends::Extend,
    };
    t.fit.ctrl = a.ctrl;
    if a.compare_weights {
        cfg.compare_weights = Some(WeightComparison::with_rounds(a.compare_rounds));
    }
    cfg
}

/// Runs `scanfit turntable`.
pub fn run(a: TurntableArgs) -> Result<()> {
    a.out.check(
        &a.input.input,
        &[(&a.points_out, "--points-out", &["ply", "xyz"][..])],
    )?;
    let cfg = config(&a);
    let progress = Progress::bar(a.quiet || a.json, STAGES.len() as u64 + 2);
    progress.stage(format!("reading {}", a.input.input.display()));
    let cloud = a.outliers.apply(a.input.load(a.json)?, a.json)?;
    progress.inc();
    let t0 = Instant::now();
    let r = turntable(&cloud, &cfg, &progress)
        .map_err(|e| {
            let options = [("compare_weights.rounds", "--compare-rounds")];
            anyhow::anyhow!("{}", cli_message(&e, &options))
        })
        .with_context(|| a.input.input.display().to_string())?;
    let seconds = t0.elapsed().as_secs_f64();
    a.out.guard(
        &r.assessment.quality,
        "check the axis (--axis) or use fewer layers (--layers) or control points (--ctrl)",
    )?;
    progress.stage("writing");
    progress.inc();
    let (files, exaggeration) = outputs(&a, &cloud, &r)?;
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        return print_json(&a, &cloud, &r, seconds, &files);
    }
    print_report(&a, &cloud, &r, seconds)?;
    print_written(&files, a.out.png.as_deref(), exaggeration)?;
    Ok(())
}

/// The surface document: the surface, its provenance and quality record.
fn document(a: &TurntableArgs, points: usize, r: &TurntableReport) -> SurfaceDoc {
    let t = &r.turntable;
    let (ax, c) = (t.frame.axis, t.frame.centre);
    let mut settings = BTreeMap::new();
    settings.insert("axis".to_string(), serde_json::json!([ax.x, ax.y, ax.z]));
    settings.insert("centre".to_string(), serde_json::json!([c.x, c.y, c.z]));
    settings.insert("views".to_string(), a.views.into());
    settings.insert("layers".to_string(), a.layers.into());
    settings.insert("grid".to_string(), a.grid.into());
    settings.insert(
        "weight".to_string(),
        WeightFactor::from(a.weight).name().into(),
    );
    settings.insert("refine_rounds".to_string(), a.refine.into());
    let mut doc = SurfaceDoc::new(&t.surface);
    doc.provenance = Some(provenance(
        "turntable (virtual turntable base surface + least squares, periodic in u)",
        Some(
            "orthogonal projection onto the turntable base surface (u around the axis, periodic)"
                .into(),
        ),
        &a.input.input,
        points,
        settings,
    ));
    doc.quality = Some(quality_doc(&r.assessment.quality, Vec::new()));
    doc
}

/// Every requested output file, and the exaggeration of `--png`.
fn outputs(a: &TurntableArgs, cloud: &PointCloud, r: &TurntableReport) -> Result<(Files, f64)> {
    let t = &r.turntable;
    let pts = cloud.points();
    let (mut files, exaggeration) = a.out.files(
        &t.surface,
        &document(a, pts.len(), r),
        pts,
        &Deviation {
            per_point: &t.distances,
            stats: t.errors,
            name: "orthogonal distance (scale: fitted points)",
        },
        &a.input.input,
        &Picture {
            style: PngStyle::Deviation,
            scale_points: Some(t.fitted.clone()),
            ..Default::default()
        },
    )?;
    if let Some(p) = &a.points_out {
        let out = PointCloud::new(pts.to_vec())?
            .with_attribute("u", t.uv.iter().map(|x| x[0]).collect())?
            .with_attribute("v", t.uv.iter().map(|x| x[1]).collect())?
            .with_attribute("deviation", t.distances.clone())?;
        files.push((p.clone(), crate::cloud::cloud_file(p, &out)?));
    }
    Ok((files, exaggeration))
}

/// Mean, max and RMSE as JSON.
fn stats_json(e: &scanfit::metrics::ErrorStats) -> serde_json::Value {
    serde_json::json!({"mean": e.mean, "max": e.max, "rmse": e.rmse})
}

/// `--json`: the report on stdout.
fn print_json(
    a: &TurntableArgs,
    cloud: &PointCloud,
    r: &TurntableReport,
    seconds: f64,
    files: &Files,
) -> Result<()> {
    let t = &r.turntable;
    let (ax, c) = (t.frame.axis, t.frame.centre);
    let quality = quality_doc(&r.assessment.quality, Vec::new());
    let mut report = serde_json::json!({
        "input": a.input.input.display().to_string(),
        "point_count": cloud.len(),
        "axis": [ax.x, ax.y, ax.z],
        "centre": [c.x, c.y, c.z],
        "radius": t.frame.radius,
        "visible": t.views.iter().map(|v| v.visible.len()).collect::<Vec<_>>(),
        "layer_points": t.loops.iter().map(Vec::len).collect::<Vec<_>>(),
        "layer_rmse": t.layers.rmse,
        "base_grid": [t.grid_u, t.heights.len()],
        "refine_rmse": t.refine_rmse,
        "base_distance": stats_json(&t.base_errors),
        "beyond_end_layers": t.on_v_boundary,
        "ends": crate::args::value_name(&a.ends),
        "open_ends": [t.end_shapes[0].open, t.end_shapes[1].open],
        "distance_all_points": stats_json(&t.errors_all),
        "surface_to_cloud": stats_json(&t.surface_to_cloud),
        "surface_to_points": samples_json(&r.assessment.quality),
        "control_points": [a.ctrl.0, a.ctrl.1],
        "quality": quality,
        "fold_overs_inside_layers": t.quality_inside.fold_overs,
        "fold_overs_corrected": t.quality_fitted.fold_overs,
        "measure": crate::measure::json(&r.assessment),
        "seconds": seconds,
        "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
    });
    if let Some(c) = &r.weight_comparison {
        report["weight_comparison"] = c
            .iter()
            .map(|w| serde_json::json!({"weight": w.weight.name(), "rmse": w.rmse}))
            .collect();
    }
    out!(
        "{}",
        scanfit_io::json::finite_json(&report, "the JSON report")?
    );
    Ok(())
}

/// "ends: low closed (3% left out), high open (fitted to the rim)".
fn ends_line(shapes: &[EndShape; 2], margin: f64) -> String {
    let say = |e: &EndShape| {
        if e.open {
            "open (fitted to the rim)".to_string()
        } else {
            format!(
                "closed ({:.0}% of the height left out; {:.0}% of its points near the axis)",
                100.0 * margin,
                100.0 * e.inner_share
            )
        }
    };
    format!(
        "ends (along the axis): low {}, high {}",
        say(&shapes[0]),
        say(&shapes[1])
    )
}

/// The lines above the error table: axis, views, layers, base surface, parameters.
fn print_steps(
    a: &TurntableArgs,
    cloud: &PointCloud,
    r: &TurntableReport,
    seconds: f64,
) -> Result<()> {
    let t = &r.turntable;
    let (ax, c) = (t.frame.axis, t.frame.centre);
    let join = |v: &[f64]| v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" -> ");
    outln!(
        "{}: {} points -> bicubic B-spline surface closed around the axis, {} x {} control points ({seconds:.2} s)",
        a.input.input.display(),
        cloud.len(),
        a.ctrl.0,
        a.ctrl.1,
    );
    outln!(
        "axis ({:.4}, {:.4}, {:.4}){}, centre ({}, {}, {}), radius {}, height {}",
        ax.x,
        ax.y,
        ax.z,
        if matches!(a.axis, AxisChoice::Principal) {
            " (principal axis)"
        } else {
            ""
        },
        num(c.x),
        num(c.y),
        num(c.z),
        num(t.frame.radius),
        num(t.frame.height.1 - t.frame.height.0)
    );
    let visible: Vec<String> = t
        .views
        .iter()
        .map(|v| v.visible.len().to_string())
        .collect();
    outln!(
        "views: {} (visible points {})",
        t.views.len(),
        visible.join(", ")
    );
    outln!("{}", ends_line(&t.end_shapes, a.margin));
    let counts: Vec<usize> = t.loops.iter().map(Vec::len).collect();
    outln!(
        "layers: {} ({} to {} samples); projection RMSE by round ({}): {}",
        counts.len(),
        counts.iter().min().copied().unwrap_or(0),
        counts.iter().max().copied().unwrap_or(0),
        WeightFactor::from(a.weight).name(),
        join(&t.layers.rmse)
    );
    outln!(
        "base surface: {} x {} grid, refinement RMSE {}; points to base surface: mean {}, max {}, RMSE {}",
        t.grid_u,
        t.heights.len(),
        join(&t.refine_rmse),
        num(t.base_errors.mean),
        num(t.base_errors.max),
        num(t.base_errors.rmse)
    );
    outln!(
        "parameters: {} points, {} beyond the end layers ({})\n",
        cloud.len(),
        t.on_v_boundary,
        match a.ends {
            EndsArg::Exclude => "left out of the fit",
            EndsArg::Extend => "v continued past the base surface, fitted",
        }
    );
    Ok(())
}

/// The whole text report: steps, errors, fold-overs, the weight comparison.
fn print_report(
    a: &TurntableArgs,
    cloud: &PointCloud,
    r: &TurntableReport,
    seconds: f64,
) -> Result<()> {
    print_steps(a, cloud, r, seconds)?;
    let t = &r.turntable;
    let mut tab = Table::new(
        &["error [data units]", "points", "mean", "max", "RMSE"],
        &[true],
    );
    for (label, e) in [
        ("orthogonal distance, fitted points", &t.errors),
        ("|P - S(u, v)|, fitted points", &r.parametric),
        ("orthogonal distance, all points", &t.errors_all),
        ("surface samples to nearest point", &t.surface_to_cloud),
    ] {
        tab.row(vec![
            label.into(),
            e.count.to_string(),
            num(e.mean),
            num(e.max),
            num(e.rmse),
        ]);
    }
    out!("{}", tab.render());
    outln!(
        "\nfold-overs: {} of {} triangles of the fitted points ({} of {} inside the layers' range); L2 stretch {}",
        t.quality.fold_overs,
        t.quality.triangles,
        t.quality_inside.fold_overs,
        t.quality_inside.triangles,
        num(t.quality.l2_stretch)
    );
    outln!(
        "fold-overs after projecting the points onto the fitted surface (parameter correction): {} of {}",
        t.quality_fitted.fold_overs, t.quality_fitted.triangles
    );
    if let Some(note) = crate::measure::note(&r.assessment) {
        outln!("{note}");
    }
    if let Some(cmp) = &r.weight_comparison {
        outln!("\nRMSE of the layer samples' nearest-point distances by projection round:");
        let names: Vec<String> = cmp
            .iter()
            .map(|w| match w.weight {
                WeightFactor::DistanceOffset => "eq. 19 (moon)".to_string(),
                WeightFactor::PointDistance => "eq. 15 (aza04)".to_string(),
                WeightFactor::DampedDistanceOffset => "eq. 16 (as05)".to_string(),
                other => other.name().to_string(),
            })
            .collect();
        let mut head = vec!["round"];
        head.extend(names.iter().map(String::as_str));
        let mut tab = Table::new(&head, &[false]);
        let rounds = cmp.iter().map(|w| w.rmse.len()).min().unwrap_or(0);
        for k in 0..rounds {
            let mut row = vec![k.to_string()];
            row.extend(cmp.iter().map(|w| num(w.rmse[k])));
            tab.row(row);
        }
        out!("{}", tab.render());
    }
    outln!();
    Ok(())
}
