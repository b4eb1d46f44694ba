//! `scanfit turntable`: the virtual turntable parameterization of a
//! cylinder-like cloud (a head, a bottle, an arm) and a least-squares
//! B-spline surface closed around the axis.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::base::turntable::{
    compare_weights, turntable, AxisChoice, Ends, TurntableConfig, STAGES,
};
use scanfit::metrics::{grid_rmse, parametric_distances};
use scanfit::project::WeightFactor;
use scanfit::{PointCloud, Vector3};
use scanfit_io::json::{Provenance, SurfaceDoc, SurfaceQualityDoc};
use scanfit_io::write_all_atomic;

use crate::args::pair;
use crate::outputs::{
    check_extensions, print_written, Deviation, Picture, PngStyle, SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit turntable examples/data/blob_30k.ply -o blob.json --png blob.png
  scanfit turntable head.ply --axis y --layers 50 --ctrl 40x60 --mesh head.ply --points-out params.ply
  scanfit turntable bottle.xyz --axis 0,0,1 --compare-weights

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

/// Arguments of `scanfit turntable`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct TurntableArgs {
    #[command(flatten)]
    pub input: crate::cloud::InputArgs,
    /// Turntable axis: x, y (the paper's), z, a direction "X,Y,Z", or "auto"
    /// (the cloud's principal axis).
    #[arg(long, default_value = "auto", value_name = "AXIS")]
    pub axis: String,
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
    #[arg(long, default_value = "40x40", value_name = "NUxNV")]
    pub ctrl: String,
    /// Weight factor of the directed projection: moon (eq. 19), aza04 (eq. 15), as05 (eq. 16).
    #[arg(long, default_value = "moon", value_name = "W")]
    pub weight: String,
    /// Most projection rounds of the layer curves.
    #[arg(long, default_value_t = 10, value_name = "N")]
    pub rounds: usize,
    /// Refinement rounds of the base surface (projection along the normal, relaxation).
    #[arg(long, default_value_t = 2, value_name = "N")]
    pub refine: usize,
    /// Fraction of the cloud's height left out at each end of the layers
    /// (0 for an open tube; closed ends need a section around the axis).
    #[arg(long, default_value_t = 0.03, value_name = "F")]
    pub margin: f64,
    /// Points beyond the end layers: "exclude" (kept out of the fit; the
    /// surface spans the layers) or "extend" (v continued past the base
    /// surface and every point fitted; around a closed end the surface may
    /// flare where no points hold it).
    #[arg(long, default_value = "exclude", value_name = "MODE")]
    pub ends: String,
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

fn parse_axis(s: &str) -> Result<AxisChoice> {
    Ok(match s.trim().to_ascii_lowercase().as_str() {
        "auto" | "principal" => AxisChoice::Principal,
        "x" => AxisChoice::Given(Vector3::x()),
        "y" => AxisChoice::Given(Vector3::y()),
        "z" => AxisChoice::Given(Vector3::z()),
        _ => {
            let v = crate::cloud::triple(s, "--axis")?;
            AxisChoice::Given(Vector3::new(v[0], v[1], v[2]))
        }
    })
}

/// Runs `scanfit turntable`.
pub fn run(a: TurntableArgs) -> Result<()> {
    a.out.check()?;
    check_extensions(&[(&a.points_out, "--points-out", &["ply", "xyz"][..])])?;
    let weight = WeightFactor::from_name(&a.weight).with_context(|| {
        format!(
            "unknown --weight '{}'; use moon, aza04 or as05 (or axis4)",
            a.weight
        )
    })?;
    let mut cfg = TurntableConfig {
        axis: parse_axis(&a.axis)?,
        ..Default::default()
    };
    cfg.views.views = a.views;
    cfg.views.grid_u = a.grid;
    cfg.layers.layers = a.layers;
    cfg.layers.max_rounds = a.rounds;
    cfg.layers.projection.weight = weight;
    cfg.refine.rounds = a.refine;
    cfg.layers.margin = a.margin;
    cfg.ends = match a.ends.to_ascii_lowercase().as_str() {
        "exclude" => Ends::Exclude,
        "extend" => Ends::Extend,
        other => bail!("unknown --ends '{other}'; use exclude or extend"),
    };
    cfg.refine.projection.weight = weight;
    cfg.fit.ctrl = pair(&a.ctrl, "--ctrl")?;
    if a.compare_weights && a.compare_rounds == 0 {
        bail!("--compare-rounds must be at least 1");
    }
    let progress = Progress::bar(a.quiet || a.json, STAGES.len() as u64 + 2);
    progress.stage(format!("reading {}", a.input.input.display()));
    let (cloud, dropped) = a.input.load()?;
    if dropped > 0 && !a.json {
        eprintln!("note: {dropped} points with NaN or infinite coordinates dropped");
    }
    progress.inc();
    let input = a.input.input.clone();
    let t0 = Instant::now();
    let t = turntable(&cloud, &cfg, &mut |i| {
        progress.stage(STAGES[i]);
        if i > 0 {
            progress.inc();
        }
    })
    .map_err(|e| anyhow::anyhow!("{}: {e}", input.display()))?;
    let seconds = t0.elapsed().as_secs_f64();
    let comparison = if a.compare_weights {
        progress.stage("weight factor comparison");
        Some(
            compare_weights(
                &cloud,
                &t.frame,
                &t.loops,
                &cfg.layers,
                a.compare_rounds,
                &[
                    WeightFactor::DistanceOffset,
                    WeightFactor::PointDistance,
                    WeightFactor::DampedDistanceOffset,
                ],
            )
            .map_err(|e| anyhow::anyhow!("{}: {e}", input.display()))?,
        )
    } else {
        None
    };
    progress.stage("writing");
    progress.inc();
    let pts = cloud.points();
    let param = scanfit::metrics::ErrorStats::of(
        &parametric_distances(&t.surface, pts, &t.uv)
            .into_iter()
            .zip(&t.fitted)
            .filter(|(_, &f)| f)
            .map(|(d, _)| d)
            .collect::<Vec<_>>(),
    );
    let mut doc = SurfaceDoc::new(&t.surface);
    let mut settings = BTreeMap::new();
    let ax = t.frame.axis;
    settings.insert("axis".to_string(), serde_json::json!([ax.x, ax.y, ax.z]));
    let c = t.frame.centre;
    settings.insert("centre".to_string(), serde_json::json!([c.x, c.y, c.z]));
    settings.insert("views".to_string(), a.views.into());
    settings.insert("layers".to_string(), a.layers.into());
    settings.insert("grid".to_string(), a.grid.into());
    settings.insert("weight".to_string(), weight.name().into());
    settings.insert("refine_rounds".to_string(), a.refine.into());
    doc.provenance = Some(Provenance {
        tool: format!("scanfit {}", env!("CARGO_PKG_VERSION")),
        operation: "turntable (virtual turntable base surface + least squares, periodic in u)"
            .into(),
        parameterization: Some(
            "orthogonal projection onto the turntable base surface (u around the axis, periodic)"
                .into(),
        ),
        input: Some(input.display().to_string()),
        point_count: Some(pts.len()),
        settings,
    });
    doc.quality = Some(SurfaceQualityDoc {
        points: t.errors.count,
        mean_error: param.mean,
        max_error: param.max,
        rmse: param.rmse,
        mean_distance: t.errors.mean,
        max_distance: t.errors.max,
        rmse_distance: t.errors.rmse,
        unconverged: t.unconverged,
        // the MBA paper's eq. 17 over the fitted surface's knot grid
        grid_rmse: grid_rmse(&t.surface, pts, None)?,
        triangles: t.quality.triangles,
        fold_overs: t.quality.fold_overs,
        l2_stretch: t.quality.l2_stretch,
        max_anisotropy: t.quality.max_anisotropy,
        correction_rmse: Vec::new(),
    });
    let (mut files, exaggeration) = a.out.files(
        &t.surface,
        &doc,
        pts,
        &Deviation {
            per_point: &t.distances,
            stats: t.errors,
            name: "orthogonal distance (scale: fitted points)",
        },
        &input,
        &Picture {
            style: PngStyle::Deviation,
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
    write_all_atomic(&files)?;
    progress.finish();
    let (cu, cv) = cfg.fit.ctrl;
    if a.json {
        let report = serde_json::json!({
            "input": input.display().to_string(),
            "point_count": pts.len(),
            "axis": [ax.x, ax.y, ax.z],
            "centre": [c.x, c.y, c.z],
            "radius": t.frame.radius,
            "visible": t.views.iter().map(|v| v.visible.len()).collect::<Vec<_>>(),
            "layer_points": t.loops.iter().map(Vec::len).collect::<Vec<_>>(),
            "layer_rmse": t.layers.rmse,
            "base_grid": [t.grid_u, t.heights.len()],
            "refine_rmse": t.refine_rmse,
            "base_distance": {"mean": t.base_errors.mean, "max": t.base_errors.max, "rmse": t.base_errors.rmse},
            "beyond_end_layers": t.on_v_boundary,
            "ends": a.ends.to_ascii_lowercase(),
            "distance_all_points": {"mean": t.errors_all.mean, "max": t.errors_all.max, "rmse": t.errors_all.rmse},
            "surface_to_cloud": {"mean": t.surface_to_cloud.mean, "max": t.surface_to_cloud.max, "rmse": t.surface_to_cloud.rmse},
            "control_points": [cu, cv],
            "quality": doc.quality,
            "fold_overs_inside_layers": t.quality_inside.fold_overs,
            "fold_overs_corrected": t.quality_fitted.fold_overs,
            "weight_comparison": comparison.as_ref().map(|c| c.iter().map(|(w, r)| serde_json::json!({"weight": w.name(), "rmse": r})).collect::<Vec<_>>()),
            "seconds": seconds,
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "{}: {} points -> bicubic B-spline surface closed around the axis, {cu} x {cv} control points ({seconds:.2} s)",
        input.display(),
        pts.len(),
    );
    println!(
        "axis ({:.4}, {:.4}, {:.4}){}, centre ({}, {}, {}), radius {}, height {}",
        ax.x,
        ax.y,
        ax.z,
        if matches!(cfg.axis, AxisChoice::Principal) {
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
    println!(
        "views: {} (visible points {})",
        t.views.len(),
        t.views
            .iter()
            .map(|v| v.visible.len().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let counts: Vec<usize> = t.loops.iter().map(Vec::len).collect();
    println!(
        "layers: {} ({} to {} samples); projection RMSE by round ({}): {}",
        counts.len(),
        counts.iter().min().copied().unwrap_or(0),
        counts.iter().max().copied().unwrap_or(0),
        weight.name(),
        t.layers
            .rmse
            .iter()
            .map(|&r| num(r))
            .collect::<Vec<_>>()
            .join(" -> ")
    );
    println!(
        "base surface: {} x {} grid, refinement RMSE {}; points to base surface: mean {}, max {}, RMSE {}",
        t.grid_u,
        t.heights.len(),
        t.refine_rmse
            .iter()
            .map(|&r| num(r))
            .collect::<Vec<_>>()
            .join(" -> "),
        num(t.base_errors.mean),
        num(t.base_errors.max),
        num(t.base_errors.rmse)
    );
    println!(
        "parameters: {} points, {} beyond the end layers ({})\n",
        pts.len(),
        t.on_v_boundary,
        match cfg.ends {
            Ends::Exclude => "left out of the fit",
            Ends::Extend => "v continued past the base surface, fitted",
        }
    );
    let mut tab = Table::new(
        &["error [data units]", "points", "mean", "max", "RMSE"],
        &[true],
    );
    tab.row(vec![
        "orthogonal distance, fitted points".into(),
        t.errors.count.to_string(),
        num(t.errors.mean),
        num(t.errors.max),
        num(t.errors.rmse),
    ]);
    tab.row(vec![
        "|P - S(u, v)|, fitted points".into(),
        param.count.to_string(),
        num(param.mean),
        num(param.max),
        num(param.rmse),
    ]);
    tab.row(vec![
        "orthogonal distance, all points".into(),
        t.errors_all.count.to_string(),
        num(t.errors_all.mean),
        num(t.errors_all.max),
        num(t.errors_all.rmse),
    ]);
    tab.row(vec![
        "surface samples to nearest point".into(),
        t.surface_to_cloud.count.to_string(),
        num(t.surface_to_cloud.mean),
        num(t.surface_to_cloud.max),
        num(t.surface_to_cloud.rmse),
    ]);
    print!("{}", tab.render());
    println!(
        "\nfold-overs: {} of {} triangles of the fitted points ({} of {} inside the layers' range); L2 stretch {}",
        t.quality.fold_overs,
        t.quality.triangles,
        t.quality_inside.fold_overs,
        t.quality_inside.triangles,
        num(t.quality.l2_stretch)
    );
    println!(
        "fold-overs after projecting the points onto the fitted surface (parameter correction): {} of {}",
        t.quality_fitted.fold_overs, t.quality_fitted.triangles
    );
    if let Some(cmp) = &comparison {
        println!("\nRMSE of the layer samples' nearest-point distances by projection round:");
        let mut head = vec!["round"];
        let names: Vec<String> = cmp
            .iter()
            .map(|(w, _)| {
                match w {
                    WeightFactor::DistanceOffset => "eq. 19 (moon)",
                    WeightFactor::PointDistance => "eq. 15 (aza04)",
                    WeightFactor::DampedDistanceOffset => "eq. 16 (as05)",
                    WeightFactor::LineOffset => "axis4",
                }
                .to_string()
            })
            .collect();
        head.extend(names.iter().map(String::as_str));
        let mut tab = Table::new(&head, &[false]);
        for r in 0..=a.compare_rounds {
            let mut row = vec![r.to_string()];
            row.extend(cmp.iter().map(|(_, v)| num(v[r])));
            tab.row(row);
        }
        print!("{}", tab.render());
    }
    println!();
    print_written(&files, a.out.png.as_deref(), exaggeration);
    Ok(())
}
