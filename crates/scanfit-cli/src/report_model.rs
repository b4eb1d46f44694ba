//! `scanfit report MODEL.json INPUT` for a multi-patch model (schema
//! `scanfit-model/1`, written by `scanfit reconstruct -o`): per patch, per
//! edge and total errors as tables or `--json`
//! (`scanfit::pipeline::measure_model`).

use anyhow::{bail, Result};
use scanfit::pipeline::measure_model::{
    run as measure, Assignment, ModelMeasureConfig, ModelMeasureReport, Parameters,
};
use scanfit_io::model::read_model;

use crate::args::Ids;
use crate::outputs::check_outputs;
use crate::progress::Progress;
use crate::report::ReportArgs;
use crate::table::{num, Table};

/// Whether the file at `path` is a model document (its schema, which the
/// writer puts first, is `scanfit-model/1`).
pub fn is_model(path: &std::path::Path) -> bool {
    use std::io::Read as _;
    let mut head = [0u8; 512];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut head))
        .unwrap_or(0);
    String::from_utf8_lossy(&head[..n]).contains(scanfit_io::model::MODEL_SCHEMA)
}

/// Runs `scanfit report` on a model.
pub fn run(a: ReportArgs) -> Result<()> {
    if a.output.is_some() {
        bail!(
            "{} is a multi-patch model: its report is the tables (or --json); the HTML page (-o) is for single surfaces, leave -o out",
            a.surface.display()
        );
    }
    check_outputs(&[&a.surface, &a.input.input], &[])?;
    let progress = Progress::spinner(a.quiet);
    progress.stage("reading");
    let (_, model) = read_model(&a.surface)?;
    let (cloud, _) = a.input.load_counted()?;
    let mut cfg = ModelMeasureConfig::default();
    cfg.labels.attribute = a.labels.clone();
    if let Some(Ids(list)) = &a.ignore {
        cfg.labels.ignore = list.clone();
    }
    let r = measure(&model, &cloud, &cfg, &progress)?;
    progress.finish();
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&json(&a, &r))?);
    } else {
        out!("{}", tables(&a, &r));
    }
    Ok(())
}

/// How the points were assigned, in words.
fn assignment(r: &ModelMeasureReport) -> String {
    match &r.assignment {
        Assignment::Labels(n) => format!("by the label attribute '{n}'"),
        Assignment::Nearest => {
            "to the patch at the smallest orthogonal distance (the cloud has no label attribute)"
                .into()
        }
    }
}

fn params(p: Parameters) -> &'static str {
    match p {
        Parameters::Coons => "coons",
        Parameters::Projection => "projection",
    }
}

/// The patch, edge and total tables.
fn tables(a: &ReportArgs, r: &ModelMeasureReport) -> String {
    let mut t = Table::new(
        &[
            "patch",
            "sides",
            "edges",
            "points",
            "params",
            "mean",
            "max",
            "rmse",
            "orth mean",
            "orth max",
            "orth rmse",
        ],
        &[],
    );
    let opt = |s: Option<f64>| s.map_or("-".into(), num);
    for p in &r.patches {
        let (e, o) = (p.errors, p.orthogonal);
        t.row(vec![
            p.id.to_string(),
            p.sides.to_string(),
            p.edges.to_string(),
            p.points.to_string(),
            params(p.parameters).into(),
            opt(e.map(|s| s.mean)),
            opt(e.map(|s| s.max)),
            opt(e.map(|s| s.rmse)),
            opt(o.map(|s| s.mean)),
            opt(o.map(|s| s.max)),
            opt(o.map(|s| s.rmse)),
        ]);
    }
    let mut et = Table::new(
        &["edge", "patches", "max gap", "max normal angle (deg)"],
        &[],
    );
    for e in &r.edges {
        let ids: Vec<String> = e.patches.iter().map(i64::to_string).collect();
        et.row(vec![
            e.edge.to_string(),
            ids.join(" | "),
            num(e.max_gap),
            opt(e.max_angle_deg),
        ]);
    }
    let tt = &r.totals;
    format!(
        "{} against {}: {} patches, {} edges, {}; points assigned {}{}\n\n\
         eq. 15 errors |P - S(u,v)| at the closest-point parameters and orthogonal distances (data units)\n{}\n{}\n\
         {} points: eq. 15 mean {} max {} rmse {}; orthogonal mean {} max {} rmse {}\n\
         largest gap along an edge {} (data units), largest normal angle {} deg\n",
        a.input.input.display(),
        a.surface.display(),
        r.patches.len(),
        r.edges.len(),
        if tt.closed { "closed" } else { "open" },
        assignment(r),
        if r.left_out > 0 {
            format!(", {} left out", r.left_out)
        } else {
            String::new()
        },
        t.render(),
        et.render(),
        tt.errors.count,
        num(tt.errors.mean),
        num(tt.errors.max),
        num(tt.errors.rmse),
        num(tt.orthogonal.mean),
        num(tt.orthogonal.max),
        num(tt.orthogonal.rmse),
        num(tt.max_gap),
        num(tt.max_angle_deg),
    )
}

/// The `--json` document.
fn json(a: &ReportArgs, r: &ModelMeasureReport) -> serde_json::Value {
    let stats = |s: &scanfit::metrics::ErrorStats| serde_json::json!({"mean": s.mean, "max": s.max, "rmse": s.rmse});
    serde_json::json!({
        "model": a.surface.display().to_string(),
        "input": a.input.input.display().to_string(),
        "assignment": match &r.assignment {
            Assignment::Labels(n) => serde_json::json!({"labels": n}),
            Assignment::Nearest => serde_json::json!("nearest"),
        },
        "left_out": r.left_out,
        "patches": r.patches.iter().map(|p| serde_json::json!({
            "id": p.id, "sides": p.sides, "edges": p.edges, "points": p.points,
            "parameters": params(p.parameters),
            "errors": p.errors.as_ref().map(stats), "orthogonal": p.orthogonal.as_ref().map(stats),
        })).collect::<Vec<_>>(),
        "edges": r.edges.iter().map(|e| serde_json::json!({
            "edge": e.edge, "patches": e.patches, "max_gap": e.max_gap,
            "max_normal_angle_deg": e.max_angle_deg,
        })).collect::<Vec<_>>(),
        "totals": {
            "points": r.totals.errors.count, "errors": stats(&r.totals.errors),
            "orthogonal": stats(&r.totals.orthogonal), "max_gap": r.totals.max_gap,
            "max_normal_angle_deg": r.totals.max_angle_deg, "closed": r.totals.closed,
        },
    })
}
