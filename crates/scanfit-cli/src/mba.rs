//! `scanfit mba`: a bicubic B-spline surface z = f(x, y) through scattered
//! 2.5D points by multilevel B-spline approximation, optionally with the MBA
//! paper's projection adjustment of control points, over
//! [`scanfit::pipeline::mba`].

use std::collections::BTreeMap;

use anyhow::Result;
use clap::{Args, ValueEnum};
use scanfit::mba::adjust::AdjustConfig;
use scanfit::mba::{ControlFormula, Start};
use scanfit::pipeline::mba::{run as mba, LevelRow, MbaReport, MbaRunConfig};
use scanfit::pipeline::trim::{Loops, TrimInput};
use scanfit::project::{DirectedConfig, WeightFactor};
use scanfit_io::json::SurfaceDoc;
use scanfit_io::render::Up;
use scanfit_io::write_all_atomic;

use crate::args::{choice, cli_message, InputArgs, NXM};
use crate::outputs::{
    print_written, provenance, quality_doc, samples_json, Deviation, Picture, SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit mba examples/data/terrain_50k.xyz --levels 6 -o terrain.json --png terrain.png
  scanfit mba examples/data/terrain_50k.xyz --levels 6 --units m --view top --png terrain_map.png
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
of the distances from the grid points at the knots to their nearest data point.
Height is the up axis (--up, default auto: the thin axis of a sheet, else z):
a y-up scan is fitted as y = f(x, -z), never as a wall of spikes over x, y.";

/// `--weight`: the weight factor of the directed projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum WeightArg {
    /// MBA paper eq. 13 (Azariadis 2004).
    Aza04,
    /// MBA paper eq. 14 (Azariadis & Sapidis 2005).
    As05,
    /// MBA paper eq. 15 as printed.
    Axis4,
    /// Turntable paper eq. 19.
    Moon,
}

/// `--start`: the function level 0 starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum StartArg {
    /// The mean height.
    Mean,
    /// The constant of least squares.
    Fitted,
}

impl From<WeightArg> for WeightFactor {
    fn from(w: WeightArg) -> Self {
        match w {
            WeightArg::Aza04 => WeightFactor::PointDistance,
            WeightArg::As05 => WeightFactor::DampedDistanceOffset,
            WeightArg::Axis4 => WeightFactor::LineOffset,
            WeightArg::Moon => WeightFactor::DistanceOffset,
        }
    }
}

/// Arguments of `scanfit mba`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct MbaArgs {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub outliers: crate::args::OutlierArgs,
    /// Cells of the first lattice, "MxN" (control net (M+3) x (N+3))
    /// [default: 1 along the shorter side, the aspect ratio along the longer].
    #[arg(long, value_name = "MxN", value_parser = NXM)]
    pub base: Option<(usize, usize)>,
    /// Most levels (each doubles the lattice).
    #[arg(long, default_value_t = 6, value_name = "L")]
    pub levels: usize,
    /// Stop once the vertical RMSE (or, with --adjust, the eq. 17 RMSE) is at most E [data units].
    #[arg(long, value_name = "E", allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Start of level 0: fitted (the constant that leaves the smallest
    /// final residual at the points: 21% lower held-out error than the mean
    /// on Franke's function, at the same CPU time in memory; streamed, one
    /// more pass) or mean (the mean height) [default: fitted; mean with
    /// --adjust, which refuses fitted].
    #[arg(long, value_name = "S", value_parser = choice::<StartArg>())]
    pub start: Option<StartArg>,
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
    #[arg(long, default_value = "moon", value_name = "W", value_parser = choice::<WeightArg>())]
    pub weight: WeightArg,
    /// Most adjustment steps per lattice.
    #[arg(long, default_value_t = 5, value_name = "N")]
    pub adjust_steps: usize,
    #[command(flatten)]
    pub out: SurfaceOutputArgs,
    /// Read the input in chunks of N points, one pass per level, so memory
    /// depends on the lattice, not the point count (not with --adjust; text
    /// inputs are read in chunks, others whole).
    #[arg(long, value_name = "N")]
    pub chunk_points: Option<usize>,
    #[command(flatten)]
    pub trim: crate::cad::TrimArgs,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

impl MbaArgs {
    /// The pipeline's settings.
    pub(crate) fn config(&self) -> MbaRunConfig {
        let mut c = MbaRunConfig::default();
        c.mba.base = self.base;
        c.mba.max_levels = self.levels;
        c.mba.tolerance = self.tolerance;
        c.mba.formula = if self.hjelle {
            ControlFormula::Hjelle
        } else {
            ControlFormula::LeeWolbergShin
        };
        c.mba.start = match self.start() {
            StartArg::Mean => Start::Mean,
            StartArg::Fitted => Start::Fitted,
        };
        c.adjust = self.adjust.then(|| AdjustConfig {
            alpha: self.alpha,
            projection: DirectedConfig {
                weight: self.weight.into(),
                ..Default::default()
            },
            max_steps: self.adjust_steps,
            ..Default::default()
        });
        // the outputs show the vertical distances, which the report keeps
        // anyway: the assessment keeps no per-point values
        c.assess = self.out.measure.config(c.assess, false);
        c
    }

    /// The start of level 0: the one given, else fitted (mean with
    /// `--adjust`, which starts from the mean).
    pub(crate) fn start(&self) -> StartArg {
        self.start.unwrap_or(if self.adjust {
            StartArg::Mean
        } else {
            StartArg::Fitted
        })
    }

    /// The settings recorded in the surface document.
    pub(crate) fn settings(
        &self,
        levels: usize,
        cells: (usize, usize),
    ) -> BTreeMap<String, serde_json::Value> {
        let mut s = BTreeMap::new();
        s.insert("levels".into(), levels.into());
        s.insert(
            "lattice_cells".into(),
            serde_json::json!([cells.0, cells.1]),
        );
        let formula = if self.hjelle {
            "hjelle"
        } else {
            "lee-wolberg-shin"
        };
        s.insert("formula".into(), formula.into());
        let start = match self.start() {
            StartArg::Fitted => "fitted",
            StartArg::Mean => "mean",
        };
        s.insert("start".into(), start.into());
        if self.adjust {
            s.insert("adjust_alpha".into(), self.alpha.into());
            s.insert(
                "adjust_weight".into(),
                WeightFactor::from(self.weight).name().into(),
            );
        }
        s
    }
}

/// One row of the level table, as `--json` prints it.
#[derive(Debug, Clone, serde::Serialize)]
pub(crate) struct Row {
    level: usize,
    control_points: [usize; 2],
    vertical_mean: f64,
    vertical_max: f64,
    vertical_rmse: f64,
    grid_rmse: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    adjusted_vertical_rmse: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    adjusted_grid_rmse: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    adjust_steps: Option<usize>,
    seconds: f64,
}

/// The per-level rows of the JSON report (in memory and streamed).
pub(crate) fn rows(levels: &[LevelRow]) -> Vec<Row> {
    levels
        .iter()
        .map(|l| Row {
            level: l.level,
            control_points: [l.control_points.0, l.control_points.1],
            vertical_mean: l.vertical.mean,
            vertical_max: l.vertical.max,
            vertical_rmse: l.vertical.rmse,
            grid_rmse: l.grid_rmse,
            adjusted_vertical_rmse: l.adjusted.map(|a| a.vertical_rmse),
            adjusted_grid_rmse: l.adjusted.map(|a| a.grid_rmse),
            adjust_steps: l.adjusted.map(|a| a.steps),
            seconds: l.seconds,
        })
        .collect()
}

/// Runs `scanfit mba`.
pub fn run(a: MbaArgs) -> Result<()> {
    a.out.check(&a.input.input, &[])?;
    if a.levels == 0 {
        anyhow::bail!("--levels must be at least 1");
    }
    if a.adjust && a.start == Some(StartArg::Fitted) {
        anyhow::bail!(
            "--start fitted cannot be used with --adjust: the adjustment changes the lattices between levels, so the constant's levels no longer give the start; it starts from the mean (leave --start out)"
        );
    }
    if let Some(n) = a.chunk_points {
        if a.trim.trim {
            anyhow::bail!(
                "--trim cannot be used with --chunk-points: {}",
                crate::stream::TRIM_STREAMED
            );
        }
        return crate::stream::mba(&a, n);
    }
    let progress = Progress::spinner(a.quiet || a.json);
    progress.stage(format!("reading {}", a.input.input.display()));
    let mut cloud = a.outliers.apply(a.input.load(a.json)?, a.json)?;
    let up = a.out.view.up(cloud.points());
    let (residual_name, parameters) = height_names(up);
    note_lattice(&a, cloud.points());
    let input = &a.input.input;
    let options = [
        ("base", "--base"),
        ("max_levels", "--levels"),
        ("tolerance", "--tolerance"),
        ("alpha", "--alpha"),
        ("start", "--start"),
    ];
    let mut config = a.config();
    config.up = up;
    let mut r = mba(&cloud, &config, &progress)
        .map_err(|e| anyhow::anyhow!("{}: {}", input.display(), cli_message(&e, &options)))?;
    let trim = TrimInput {
        surface: &r.surface,
        cloud: &mut cloud,
        uv: &r.uv,
        loops: Loops::Parameters {
            scale: [r.frame.width, r.frame.height],
        },
    };
    let q = &mut r.assessment.quality;
    let trimmed = a.trim.apply(true, trim, q, &config.assess, &progress)?;
    let pts = cloud.points();
    a.out.guard(
        q,
        "remove stray points or use fewer levels (--levels) or a tolerance (--tolerance)",
    )?;
    let q = &r.assessment.quality;
    progress.stage("writing");
    let operation = if a.adjust {
        "mba (multilevel B-spline approximation + projection adjustment)"
    } else {
        "mba (multilevel B-spline approximation)"
    };
    let mut doc = SurfaceDoc::new(&r.surface);
    doc.provenance = Some(provenance(
        operation,
        Some(parameters.into()),
        input,
        pts.len(),
        a.settings(r.levels.len(), r.cells),
    ));
    doc.quality = Some(quality_doc(q, Vec::new()));
    let deviation = Deviation {
        per_point: &r.vertical,
        stats: q.at_parameters,
        name: residual_name,
    };
    let (files, exaggeration) = a.out.files_with(
        &r.surface,
        trimmed.as_ref(),
        &doc,
        pts,
        &deviation,
        input,
        &Picture::default(),
    )?;
    write_all_atomic(&files)?;
    progress.finish();
    let (m, n) = r.cells;
    if a.json {
        let report = serde_json::json!({
            "input": input.display().to_string(),
            "point_count": pts.len(),
            "control_points": [m + 3, n + 3],
            "levels": rows(&r.levels),
            "quality": doc.quality,
            "samples_to_points": samples_json(q),
            "measure": crate::measure::json(&r.assessment),
            "trim": crate::cad::trim_json(trimmed.as_ref()),
            "seconds": r.seconds,
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        out!(
            "{}",
            scanfit_io::json::finite_json(&report, "the JSON report")?
        );
        return Ok(());
    }
    print_report(&a, &r)?;
    crate::cad::print_trim(trimmed.as_ref())?;
    print_written(&files, a.out.png.as_deref(), exaggeration)?;
    Ok(())
}

/// Tells on stderr, before any work, when the last level's lattice has more
/// control values than there are points (most of them then see no data),
/// with the memory it takes.
fn note_lattice(a: &MbaArgs, points: &[scanfit::Point3]) {
    let base = a.base.or_else(|| {
        scanfit::mba::Frame::of(points)
            .ok()
            .map(|f| f.default_base())
    });
    let Some(values) = base.and_then(|b| scanfit::mba::last_lattice_values(b, a.levels)) else {
        return;
    };
    if values > 4 * points.len() && !a.quiet && !a.json {
        // BA sums (2), the level, the combined lattice and its refinement
        let mib = (values * 8 * 5) as f64 / (1 << 20) as f64;
        crate::print_stderr(format_args!(
            "note: --levels {} ends on a lattice of {values} control values (about {mib:.0} MiB and a pass over all of them per level) for {} points; most control values see no data; fewer levels give the same fit near the points",
            a.levels,
            points.len()
        ));
    }
}

/// The per-level table (in memory and streamed).
///
/// `eq17`: whether the rows' eq. 17 was measured (not with `--measure none`
/// in memory: it needs a KD-tree of all points; "-" then).
pub(crate) fn levels_table(levels: &[LevelRow], adjust: bool, eq17: bool) -> String {
    let mut head = vec![
        "level",
        "control net",
        "vertical mean",
        "vertical max",
        "vertical RMSE",
        "eq. 17 RMSE",
    ];
    if adjust {
        head.extend(["adjusted vertical RMSE", "adjusted eq. 17 RMSE", "steps"]);
    }
    head.push("time (s)");
    let mut t = Table::new(&head, &[false, true]);
    for l in levels {
        let mut cells = vec![
            l.level.to_string(),
            format!("{} x {}", l.control_points.0, l.control_points.1),
            num(l.vertical.mean),
            num(l.vertical.max),
            num(l.vertical.rmse),
            if eq17 || adjust {
                num(l.grid_rmse)
            } else {
                "-".into()
            },
        ];
        if adjust {
            cells.push(l.adjusted.map_or("-".into(), |x| num(x.vertical_rmse)));
            cells.push(l.adjusted.map_or("-".into(), |x| num(x.grid_rmse)));
            cells.push(l.adjusted.map_or("-".into(), |x| x.steps.to_string()));
        }
        cells.push(format!("{:.3}", l.seconds));
        t.row(cells);
    }
    t.render()
}

/// The height field's residual and parameters as the outputs name them,
/// for the height axis `up` (`--up`).
pub(crate) fn height_names(up: Up) -> (&'static str, &'static str) {
    match up {
        Up::Z => (
            "vertical distance |z - f(x, y)|",
            "xy (u = x, v = y, scaled to [0, 1])",
        ),
        Up::Y => (
            "vertical distance |y - f(x, -z)|",
            "x, -z (y up: u = x, v = -z, scaled to [0, 1])",
        ),
        Up::X => (
            "vertical distance |x - f(y, z)|",
            "yz (x up: u = y, v = z, scaled to [0, 1])",
        ),
    }
}

fn print_report(a: &MbaArgs, r: &MbaReport) -> Result<()> {
    let (m, n) = r.cells;
    outln!(
        "{}: {} points -> bicubic B-spline surface, {} x {} control points ({} levels{}, {:.3} s)\n",
        a.input.input.display(),
        r.uv.len(),
        m + 3,
        n + 3,
        r.levels.len(),
        if a.adjust { ", adjusted" } else { "" },
        r.seconds
    );
    let eq17 = !matches!(a.out.measure.measure, crate::measure::MeasureArg::None);
    out!("{}", levels_table(&r.levels, a.adjust, eq17));
    outln!("(errors in data units)\n");
    out!(
        "{}",
        crate::surface::quality_table(
            "final surface",
            height_names(r.up).0,
            &r.assessment.quality,
            "grid points to nearest point (eq. 17)"
        )
    );
    if let Some(note) = crate::measure::note(&r.assessment) {
        outln!("{note}");
    }
    Ok(())
}
