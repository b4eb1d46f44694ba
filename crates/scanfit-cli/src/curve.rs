//! `scanfit curve fit` and `scanfit curve compare`, over
//! [`scanfit::pipeline::curve`].

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::{Args, Subcommand};
use scanfit::param::Method;
use scanfit::pipeline::curve::{
    compare, run as fit_curve, CompareConfig, CurveConfig, CurveFitKind, CurveReport, MethodResult,
};
use scanfit::quality::CurveQuality;
use scanfit_io::json::{CurveDoc, QualityDoc};
use scanfit_io::step::CadItem;
use scanfit_io::svg::{curve_panels, curve_panels_png, Panel, PanelSize};
use scanfit_io::{write_all_atomic, PointTable};
use serde::Serialize;

use crate::args::{cli_message, InputArgs, Parsed, Vectors, VECTORS};
use crate::outputs::{check_outputs, provenance};
use crate::progress::Progress;
use crate::table::{num, Table};

/// `--param METHOD`: a parameterization method, `name[:a]`.
const METHOD: Parsed<Method> = Parsed(|s, _| Method::parse(s).map_err(|e| e.to_string()));

/// Curve subcommands.
#[derive(Subcommand, Debug)]
pub enum CurveCommand {
    /// Fit one B-spline curve (interpolation or least squares) and report its quality.
    #[command(after_help = FIT_EXAMPLES)]
    Fit(FitArgs),
    /// Interpolate with every parameterization method and compare them side by side.
    #[command(after_help = COMPARE_EXAMPLES)]
    Compare(CompareArgs),
}

const FIT_EXAMPLES: &str = "Examples:
  scanfit curve fit examples/data/dataset1.csv -o curve.json
  scanfit curve fit examples/data/dataset6.csv --ctrl 20 --smooth 1e-4 --svg fit.svg
  scanfit curve fit loop.xyz --closed --param centripetal --json

Parameterization methods (--param): uniform, chord, centripetal, exponential[:a]
(a = 0.8 by default), universal, hybrid, proposed[:a] (the curve paper's new method,
the default). Input: XYZ/CSV/TXT text, one point per line, optional header.";

const COMPARE_EXAMPLES: &str = "Examples:
  scanfit curve compare examples/data/dataset5.csv
  scanfit curve compare examples/data/dataset3.csv --degree 2 -o ds3.svg --json";

/// Arguments of `scanfit curve fit`.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// The input point file (points in curve order) and how to read it.
    #[command(flatten)]
    pub input: InputArgs,
    /// Parameterization method [default: proposed; centripetal with --closed,
    /// as the basis-maxima methods are defined for open curves only].
    #[arg(short, long = "param", value_name = "METHOD", value_parser = METHOD)]
    pub param: Option<Method>,
    /// Degree of the curve.
    #[arg(short, long, default_value_t = 3)]
    pub degree: usize,
    /// Least squares with this many control points (distinct ones when --closed).
    #[arg(long, value_name = "N", conflicts_with = "interpolate")]
    pub ctrl: Option<usize>,
    /// Interpolate every point (the default when --ctrl is not given).
    #[arg(long)]
    pub interpolate: bool,
    /// The points form a closed loop: fit a periodic curve.
    #[arg(long)]
    pub closed: bool,
    /// Smoothing weight λ (least squares only): minimises Σ|Q_k − C(u_k)|² + λ ∫₀¹|C''(u)|² du.
    /// Both terms scale alike with the data's size, so λ is scale-free; it grows with
    /// the number of points (try 1e-6 … 1e-2 times the point count).
    #[arg(
        long,
        value_name = "W",
        default_value_t = 0.0,
        requires = "ctrl",
        allow_negative_numbers = true
    )]
    pub smooth: f64,
    /// Let the curve's ends move (least squares only; default: pinned to the first and last points).
    #[arg(long, requires = "ctrl")]
    pub free_ends: bool,
    /// End derivatives for interpolation, "dx,dy,dz;dx,dy,dz" (start; end): dC/du
    /// with u running over [0, 1], so a length about that of the data polygon
    /// gives a natural speed (e.g. the first chord's direction times the polygon length).
    #[arg(
        long,
        value_name = "D0;D1",
        conflicts_with_all = ["ctrl", "closed"],
        allow_hyphen_values = true,
        value_parser = VECTORS
    )]
    pub end_tangents: Option<Vectors>,
    /// Write the curve as JSON (schema scanfit/1) to this file.
    #[arg(short, long, value_name = "OUT.json")]
    pub output: Option<PathBuf>,
    /// Write a picture of the data, curve and control polygon.
    #[arg(long, value_name = "OUT.svg")]
    pub svg: Option<PathBuf>,
    /// Write the same picture as a PNG.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Write the curve as a STEP file (AP214 wireframe).
    #[arg(long, value_name = "OUT.stp")]
    pub step: Option<PathBuf>,
    /// Write the same as an IGES 5.3 file (entity 126 or 128).
    #[arg(long, value_name = "OUT.igs")]
    pub iges: Option<PathBuf>,
    #[command(flatten)]
    pub units: crate::cad::UnitsArgs,
    /// Print the result as JSON on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Arguments of `scanfit curve compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The input point file (points in curve order) and how to read it.
    #[command(flatten)]
    pub input: InputArgs,
    /// Degree of the interpolating curves.
    #[arg(short, long, default_value_t = 3)]
    pub degree: usize,
    /// The SVG with one panel per method [default: INPUT-compare.svg].
    #[arg(short, long, value_name = "OUT.svg")]
    pub output: Option<PathBuf>,
    /// Also write the panels as a PNG.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Print the comparison as JSON on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs a curve subcommand.
pub fn run(cmd: CurveCommand) -> Result<()> {
    match cmd {
        CurveCommand::Fit(a) => fit_cmd(a),
        CurveCommand::Compare(a) => compare_cmd(a),
    }
}

/// Adds `file:line` to library errors that name point indices.
fn locate(e: &scanfit::Error, table: &PointTable) -> anyhow::Error {
    let at = |i: usize| table.locate(i);
    match e.point_indices()[..] {
        [i] => anyhow::anyhow!("{e} (point {i} is at {})", at(i)),
        [i, j, ..] => anyhow::anyhow!("{e} (points {i} and {j} are at {} and {})", at(i), at(j)),
        [] => {
            let options = [
                ("smoothing", "--smooth"),
                ("end_derivatives", "--end-tangents"),
            ];
            anyhow::anyhow!("{}", cli_message(e, &options))
        }
    }
}

#[derive(Serialize)]
struct FitReport<'a> {
    input: String,
    point_count: usize,
    fit: &'a str,
    parameterization: String,
    degree: usize,
    control_points: usize,
    closed: bool,
    condition: f64,
    quality: QualityDoc,
    #[serde(skip_serializing_if = "Option::is_none")]
    output: Option<String>,
}

impl FitArgs {
    /// The pipeline's settings.
    fn config(&self) -> Result<CurveConfig> {
        let mut c = CurveConfig::default();
        c.degree = self.degree;
        c.method = self.param;
        c.closed = self.closed;
        c.kind = match self.ctrl {
            Some(n) => CurveFitKind::LeastSquares {
                ctrl_count: n,
                fix_ends: !self.free_ends,
                smoothing: self.smooth,
            },
            None => CurveFitKind::Interpolation {
                end_derivatives: match self.end_tangents.as_ref().map(|v| &v.0[..]) {
                    None => None,
                    Some(&[d0, d1]) => Some((d0, d1)),
                    Some(v) => anyhow::bail!(
                        "--end-tangents needs two vectors separated by ';' (start; end), {} given",
                        v.len()
                    ),
                },
            },
        };
        Ok(c)
    }

    /// The curve document with provenance and quality.
    fn doc(&self, r: &CurveReport, point_count: usize) -> CurveDoc {
        let mut doc = CurveDoc::new(&r.fit.curve);
        let mut settings = std::collections::BTreeMap::new();
        settings.insert("degree".to_string(), self.degree.into());
        settings.insert("closed".to_string(), self.closed.into());
        if let Some(n) = self.ctrl {
            settings.insert("ctrl".to_string(), n.into());
            settings.insert("smoothing".to_string(), self.smooth.into());
            settings.insert("fix_ends".to_string(), (!self.free_ends).into());
        }
        let kind = if self.ctrl.is_some() {
            "least squares"
        } else {
            "interpolation"
        };
        doc.provenance = Some(provenance(
            format!("curve fit ({kind})"),
            Some(r.fit.method.to_string()),
            &self.input.input,
            point_count,
            settings,
        ));
        doc.params = Some(r.fit.params.clone());
        doc.quality = Some(QualityDoc::from(&r.quality));
        doc
    }
}

fn fit_cmd(a: FitArgs) -> Result<()> {
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["json"][..]),
            (&a.svg, "--svg", &["svg"][..]),
            (&a.png, "--png", &["png"][..]),
            (&a.step, "--step", &["stp", "step"][..]),
            (&a.iges, "--iges", &["igs", "iges"][..]),
        ],
    )?;
    let config = a.config()?;
    let progress = Progress::spinner(a.quiet);
    progress.stage(format!("reading {}", a.input.input.display()));
    let table = a.input.table(false)?;
    let pts = &table.points;
    let r = fit_curve(pts, &config, &progress).map_err(|e| locate(&e, &table))?;
    progress.finish();
    let kind = config.kind.label();
    let doc = a.doc(&r, pts.len());
    // outputs are built first and written together, atomically, only after
    // everything succeeded: a failed run leaves no file behind
    let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
    if let Some(out) = &a.output {
        files.push((out, doc.to_json()?.into_bytes()));
    }
    let panel = || Panel {
        title: format!("{} ({kind}, degree {})", r.fit.method, a.degree),
        subtitle: summary(&r.quality),
        points: &pts[..r.fitted_points],
        curve: Some(&r.fit.curve),
    };
    if let Some(svg) = &a.svg {
        let bytes = curve_panels(&[panel()], 1, "", PanelSize::SINGLE).into_bytes();
        files.push((svg, bytes));
    }
    if let Some(png) = &a.png {
        files.push((png, curve_panels_png(&[panel()], 1, "", PanelSize::SINGLE)?));
    }
    let cad = CadItem::Curve(&r.fit.curve);
    files.extend(crate::cad::cad_files(
        &a.step,
        &a.iges,
        cad,
        &a.input.input,
        &a.units.options(),
    )?);
    write_all_atomic(&files)?;
    if a.json {
        let report = FitReport {
            input: a.input.input.display().to_string(),
            point_count: pts.len(),
            fit: kind,
            parameterization: r.fit.method.to_string(),
            degree: a.degree,
            control_points: r.fit.curve.control_points().len(),
            closed: a.closed,
            condition: r.fit.condition,
            quality: QualityDoc::from(&r.quality),
            output: a.output.as_ref().map(|p| p.display().to_string()),
        };
        out!(
            "{}",
            scanfit_io::json::finite_json(&report, "the JSON report")?
        );
        return Ok(());
    }
    print_fit(&a, &r, kind, pts.len())?;
    Ok(())
}

fn summary(q: &CurveQuality) -> String {
    format!(
        "loops {} · inflections {} · length ratio {:.3} · max curvature {} · max deviation {}",
        q.self_intersections,
        q.curvature_sign_changes,
        q.length_ratio,
        num(q.max_curvature),
        num(q.max_deviation),
    )
}

fn print_fit(a: &FitArgs, r: &CurveReport, kind: &str, n: usize) -> Result<()> {
    let (fit, q) = (&r.fit, &r.quality);
    let c = &fit.curve;
    outln!(
        "{}: {n} points -> {} B-spline of degree {} by {kind}, {} parameterization",
        a.input.input.display(),
        if c.is_periodic() {
            "closed (periodic)"
        } else {
            "open"
        },
        c.degree(),
        fit.method
    );
    outln!(
        "{} control points, {} knots, condition estimate {:.1e}\n",
        c.control_points().len(),
        c.knots().len(),
        fit.condition
    );
    let mut t = Table::new(&["measure", "value", "unit"], &[true, false, true]);
    let rows: [(&str, String, &str); 11] = [
        (
            "max deviation (at point parameters)",
            num(q.max_deviation),
            "data units",
        ),
        ("  at point", q.max_deviation_index.to_string(), "index"),
        ("mean deviation", num(q.mean_deviation), "data units"),
        ("RMS deviation", num(q.rms_deviation), "data units"),
        ("max orthogonal distance", num(q.max_distance), "data units"),
        ("max curvature", num(q.max_curvature), "1/data units"),
        (
            "curvature sign changes",
            q.curvature_sign_changes.to_string(),
            "count",
        ),
        (
            "self-intersections (loops)",
            q.self_intersections.to_string(),
            "count",
        ),
        ("curve length", num(q.length), "data units"),
        ("data polygon length", num(q.polygon_length), "data units"),
        (
            "length ratio curve/polygon",
            format!("{:.4}", q.length_ratio),
            "-",
        ),
    ];
    for (m, v, u) in rows {
        t.row(vec![m.into(), v, u.into()]);
    }
    out!("{}", t.render());
    for (what, p) in [
        ("curve", &a.output),
        ("picture", &a.svg),
        ("PNG picture", &a.png),
        ("STEP file", &a.step),
        ("IGES file", &a.iges),
    ] {
        if let Some(p) = p {
            outln!("wrote {what}: {}", p.display());
        }
    }
    Ok(())
}

#[derive(Serialize)]
struct CompareRow {
    method: String,
    ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    quality: Option<QualityDoc>,
    #[serde(skip_serializing_if = "Option::is_none")]
    condition: Option<f64>,
}

fn compare_cmd(a: CompareArgs) -> Result<()> {
    check_outputs(
        &[&a.input.input],
        &[
            (&a.output, "--output", &["svg"][..]),
            (&a.png, "--png", &["png"][..]),
        ],
    )?;
    let table = a.input.table(false)?;
    let pts = &table.points;
    let progress = Progress::bar(a.quiet, Method::ALL.len() as u64);
    let mut config = CompareConfig::default();
    config.degree = a.degree;
    let results = compare(pts, &config, &progress).map_err(|e| locate(&e, &table))?;
    progress.finish();
    let out = a.output.clone().unwrap_or_else(|| {
        let stem = a
            .input
            .input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "curve".into());
        PathBuf::from(format!("{stem}-compare.svg"))
    });
    let panels: Vec<Panel> = results
        .iter()
        .map(|m| match &m.result {
            Ok((f, q)) => Panel {
                title: m.method.to_string(),
                subtitle: summary(q),
                points: pts,
                curve: Some(&f.curve),
            },
            Err(e) => Panel {
                title: m.method.to_string(),
                subtitle: format!("error: {e}"),
                points: pts,
                curve: None,
            },
        })
        .collect();
    let title = format!(
        "{}: degree-{} interpolation, {} points",
        a.input
            .input
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        a.degree,
        pts.len()
    );
    let mut files: Vec<(&Path, Vec<u8>)> = vec![(
        &out,
        curve_panels(&panels, 4, &title, PanelSize::GRID).into_bytes(),
    )];
    if let Some(png) = &a.png {
        files.push((png, curve_panels_png(&panels, 4, &title, PanelSize::GRID)?));
    }
    write_all_atomic(&files)?;
    if a.json {
        return print_compare_json(&a, &results, &table, &out);
    }
    print_compare(&a, &results, &table)?;
    outln!("wrote picture: {}", out.display());
    if let Some(png) = &a.png {
        outln!("wrote picture: {}", png.display());
    }
    Ok(())
}

fn print_compare_json(
    a: &CompareArgs,
    results: &[MethodResult],
    table: &PointTable,
    out: &Path,
) -> Result<()> {
    let rows: Vec<CompareRow> = results
        .iter()
        .map(|m| match &m.result {
            Ok((f, q)) => CompareRow {
                method: m.method.to_string(),
                ok: true,
                error: None,
                quality: Some(q.into()),
                condition: Some(f.condition),
            },
            Err(e) => CompareRow {
                method: m.method.to_string(),
                ok: false,
                error: Some(locate(e, table).to_string()),
                quality: None,
                condition: None,
            },
        })
        .collect();
    let doc = serde_json::json!({
        "input": a.input.input.display().to_string(),
        "point_count": table.points.len(),
        "degree": a.degree,
        "picture": out.display().to_string(),
        "methods": rows,
    });
    out!(
        "{}",
        scanfit_io::json::finite_json(&doc, "the JSON report")?
    );
    Ok(())
}

fn print_compare(a: &CompareArgs, results: &[MethodResult], table: &PointTable) -> Result<()> {
    outln!(
        "{}: {} points, degree-{} interpolation with every parameterization\n",
        a.input.input.display(),
        table.points.len(),
        a.degree
    );
    let mut t = Table::new(
        &[
            "method",
            "result",
            "max curvature [1/unit]",
            "inflections",
            "loops",
            "length ratio",
            "condition",
        ],
        &[true, true, false, false, false, false, false],
    );
    let mut errors = Vec::new();
    for m in results {
        match &m.result {
            Ok((f, q)) => t.row(vec![
                m.method.to_string(),
                "ok".into(),
                num(q.max_curvature),
                q.curvature_sign_changes.to_string(),
                q.self_intersections.to_string(),
                format!("{:.4}", q.length_ratio),
                format!("{:.1e}", f.condition),
            ]),
            Err(e) => {
                let mut row = vec![m.method.to_string(), "error".into()];
                row.extend(std::iter::repeat_n("-".to_string(), 5));
                t.row(row);
                errors.push(format!("{}: {}", m.method, locate(e, table)));
            }
        }
    }
    out!("{}", t.render());
    for e in errors {
        outln!("  {e}");
    }
    outln!("\nlength ratio = curve length / data polygon length (1 = tight; large = bulges).");
    Ok(())
}
