//! `scanfit fit`: a least-squares B-spline surface through scattered points,
//! over [`scanfit::pipeline::surface_fit`].

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use scanfit::base::{Projection, ProjectionAxis};
use scanfit::bspline::Surface;
use scanfit::fit::surface::KnotPlacement;
use scanfit::pipeline::assess::SurfaceQuality;
use scanfit::pipeline::surface_fit::{run as fit, FitConfig, FitReport, ParameterSource};
use scanfit::pipeline::trim::{Loops, TrimInput};
use scanfit::PointCloud;
use scanfit_io::json::SurfaceDoc;
use scanfit_io::{write_all_atomic, PointTable};

use crate::args::{choice, cli_message, InputArgs, NXM};
use crate::outputs::{
    points_file, print_written, provenance, quality_doc, quality_rows, samples_json, Deviation,
    Picture, PngStyle,
};
use crate::progress::Progress;
use crate::table::{num, Table};

const EXAMPLES: &str = "Examples:
  scanfit fit examples/data/terrain_50k.xyz --ctrl 40x40 -o terrain.json --png terrain.png
  scanfit fit scan.xyz --params uv-columns --periodic-u --ctrl 24x12 --smooth 1e-6
  scanfit fit patch.csv --correct 5 --points-out params.ply --mesh patch.obj --json

Parameters come from the best-fit plane of the points (--params plane, for
height-field-like patches; along the x, y or z axis instead when the plane
folds the points over and the axis does not) or from columns named u and v in
the input (--params uv-columns). The error table reports the PDE paper's eq. 15 errors at
the parameters, true orthogonal distances, the MBA paper's grid RMSE (eq. 17)
and the parameterization's fold-overs and stretch.";

/// `--params`: where the parameters come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ParamsArg {
    /// The best-fit plane of the points (or the plane across x, y or z when
    /// the best-fit plane folds the points over and that axis does not).
    Plane,
    /// Columns named u and v in the input.
    UvColumns,
}

/// `--knots`: knot placement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum KnotsArg {
    /// Interior knots follow the parameter distribution.
    Distribution,
    /// Equally spaced interior knots.
    Uniform,
}

/// The value's name as typed on the command line.
fn name<T: ValueEnum>(v: &T) -> String {
    v.to_possible_value()
        .map(|p| p.get_name().to_string())
        .unwrap_or_default()
}

/// Arguments of `scanfit fit`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct FitArgs {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub outliers: crate::args::OutlierArgs,
    /// Where the parameters come from.
    #[arg(long, default_value = "plane", value_name = "SOURCE", value_parser = choice::<ParamsArg>())]
    pub params: ParamsArg,
    /// Degrees, "PxQ" or "P".
    #[arg(long, default_value = "3x3", value_name = "PxQ", value_parser = NXM)]
    pub degree: (usize, usize),
    /// Control net, "NUxNV" or "N" [default: from the point density,
    /// round(sqrt(points / 16)) per direction, 5 to 32].
    #[arg(long, value_name = "NUxNV", value_parser = NXM)]
    pub ctrl: Option<(usize, usize)>,
    /// Knot placement.
    #[arg(long, default_value = "distribution", value_name = "PLACEMENT", value_parser = choice::<KnotsArg>())]
    pub knots: KnotsArg,
    /// Thin-plate smoothing weight λ on ∫∫ S_uu² + 2 S_uv² + S_vv² (0 = the
    /// bare least-squares fit) [default: scaled to the data, 0.001 x points /
    /// (NU x NV)², which keeps sparsely covered spans from flying off].
    #[arg(long, value_name = "L", allow_negative_numbers = true)]
    pub smooth: Option<f64>,
    /// The surface closes around in u (needs --params uv-columns).
    #[arg(long)]
    pub periodic_u: bool,
    /// Rounds of parameter correction (Hoschek: re-project, refit).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub correct: usize,
    #[command(flatten)]
    pub out: crate::outputs::SurfaceOutputArgs,
    #[command(flatten)]
    pub trim: crate::cad::TrimArgs,
    /// Write the points with u, v, residual and orthogonal distance (.ply or .xyz).
    #[arg(long, value_name = "POINTS")]
    pub points_out: Option<PathBuf>,
    /// Read the input in chunks of N points, in passes, so memory depends on
    /// the control net, not the point count (every --params, --knots and
    /// --correct, as more passes; the face is not trimmed).
    #[arg(long, value_name = "N")]
    pub chunk_points: Option<usize>,
    /// Print the report as JSON on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

impl FitArgs {
    /// The pipeline's settings.
    pub(crate) fn config(&self) -> FitConfig {
        let mut c = FitConfig::default();
        c.params = match self.params {
            ParamsArg::Plane => ParameterSource::Plane,
            ParamsArg::UvColumns => ParameterSource::uv_attributes(),
        };
        c.fit.degree = self.degree;
        if let Some(ctrl) = self.ctrl {
            c.fit.ctrl = ctrl;
            c.ctrl_from_density = false;
        }
        c.fit.periodic_u = self.periodic_u;
        c.fit.knots = match self.knots {
            KnotsArg::Distribution => KnotPlacement::Distribution,
            KnotsArg::Uniform => KnotPlacement::Uniform,
        };
        if let Some(l) = self.smooth {
            c.fit.smoothing = l;
            c.relative_smoothing = None;
        }
        c.correction_rounds = self.correct;
        // per-point residuals and distances only for the outputs that show them
        let per_point = self.points_out.is_some() || self.out.needs_deviation(PngStyle::Height);
        c.assess = self.out.measure.config(c.assess, per_point);
        c
    }

    /// The settings recorded in the surface document (the net `(cu, cv)`
    /// and thin-plate weight the fit used).
    pub(crate) fn settings(
        &self,
        (cu, cv): (usize, usize),
        smoothing: f64,
    ) -> BTreeMap<String, serde_json::Value> {
        let mut s = BTreeMap::new();
        s.insert(
            "degree".into(),
            serde_json::json!([self.degree.0, self.degree.1]),
        );
        s.insert("ctrl".into(), serde_json::json!([cu, cv]));
        s.insert("knots".into(), name(&self.knots).into());
        s.insert("smoothing".into(), smoothing.into());
        s.insert("periodic_u".into(), self.periodic_u.into());
        s.insert("correction_rounds".into(), self.correct.into());
        s
    }
}

/// The points of `table` as a cloud, with its u and v columns as attributes
/// when the parameters come from them. The points and those columns move
/// out of the table (no copy); what stays locates points in the file.
fn cloud_of(a: &FitArgs, table: &mut PointTable) -> Result<PointCloud> {
    if a.params == ParamsArg::Plane && a.periodic_u {
        bail!("--periodic-u needs parameters that go around (--params uv-columns); a plane cannot close");
    }
    let given = table.column("u").is_some() && table.column("v").is_some();
    if a.params != ParamsArg::Plane && !given {
        bail!(
            "{} has no columns named u and v (its columns: {}); use --params plane or add them",
            a.input.input.display(),
            table.columns.join(", ")
        );
    }
    // checked here, where a bad point can still be located in the file
    scanfit::validate_points(&table.points).map_err(|e| locate(e, table))?;
    let cloud = PointCloud::new(std::mem::take(&mut table.points))?;
    if a.params == ParamsArg::Plane {
        return Ok(cloud);
    }
    let u = table.take_column("u").unwrap_or_default();
    let v = table.take_column("v").unwrap_or_default();
    Ok(cloud.with_attribute("u", u)?.with_attribute("v", v)?)
}

/// The library's error with the file and line of the point it names.
fn locate(e: scanfit::Error, table: &PointTable) -> anyhow::Error {
    let file = table.path.display();
    let options = [
        ("smoothing", "--smooth"),
        ("periodic_u", "--periodic-u"),
        ("ctrl", "--ctrl"),
        ("params", "--params"),
        ("knots", "--knots"),
    ];
    match e.point_indices().first() {
        Some(&i) => anyhow::anyhow!("{file}: {e} ({})", table.locate(i)),
        None => anyhow::anyhow!("{file}: {}", cli_message(&e, &options)),
    }
}

/// Reads the input and fits; an error names the file and the place in it
/// of the point it is about.
fn read_and_fit(a: &FitArgs, progress: &Progress) -> Result<(PointCloud, FitReport)> {
    progress.stage(format!("reading {}", a.input.input.display()));
    let mut table = a.outliers.apply_table(a.input.table(a.json)?, a.json)?;
    let cloud = cloud_of(a, &mut table)?;
    match fit(&cloud, &a.config(), progress) {
        Ok(r) => Ok((cloud, r)),
        Err(e) => {
            // the points back into the table, to locate the one named
            table.points = cloud.into_parts().0;
            Err(locate(e, &table))
        }
    }
}

/// Runs `scanfit fit`.
pub fn run(a: FitArgs) -> Result<()> {
    a.out.check(
        &a.input.input,
        &[(&a.points_out, "--points-out", &["ply", "xyz"][..])],
    )?;
    a.out.check_measured(
        PngStyle::Height,
        a.points_out.as_ref().map(|_| "--points-out"),
    )?;
    if let Some(n) = a.chunk_points {
        return crate::stream::fit(&a, n);
    }
    let progress = Progress::spinner(a.quiet);
    let (mut cloud, mut r) = read_and_fit(&a, &progress)?;
    let plane = matches!(a.params, ParamsArg::Plane) && !a.periodic_u;
    let trim = TrimInput {
        surface: &r.surface,
        cloud: &mut cloud,
        uv: &r.uv,
        loops: loops_of(r.projection.as_ref()),
    };
    let q = &mut r.assessment.quality;
    let trimmed = a
        .trim
        .apply(plane, trim, q, &a.config().assess, &progress)?;
    let pts = cloud.points();
    a.out.guard(q, &leaves_fix(q, r.projection.as_ref()))?;
    progress.stage("writing");
    let q = &r.assessment.quality;
    let quality = quality_doc(q, r.rounds.iter().map(|r| r.errors.rmse).collect());
    let mut doc = SurfaceDoc::new(&r.surface);
    doc.provenance = Some(provenance(
        "fit (least-squares surface)",
        Some(name(&a.params)),
        &a.input.input,
        pts.len(),
        a.settings(r.surface.counts(), r.smoothing),
    ));
    doc.quality = Some(quality.clone());
    let dist = r.assessment.distances();
    let deviation = Deviation {
        per_point: dist,
        stats: q.orthogonal,
        name: "orthogonal distance",
    };
    let (mut files, exaggeration) = a.out.files_with(
        &r.surface,
        trimmed.as_ref(),
        &doc,
        pts,
        &deviation,
        &a.input.input,
        &Picture::default(),
    )?;
    if let Some(pout) = &a.points_out {
        let u: Vec<f64> = r.uv.iter().map(|t| t[0]).collect();
        let v: Vec<f64> = r.uv.iter().map(|t| t[1]).collect();
        let attrs: [(&str, &[f64]); 4] = [
            ("u", &u),
            ("v", &v),
            ("residual", &r.assessment.residuals),
            ("distance", dist),
        ];
        files.push((pout.clone(), points_file(pout, pts, &attrs)));
    }
    write_all_atomic(&files)?;
    progress.finish();
    if a.json {
        let mut report = serde_json::json!({
            "input": a.input.input.display().to_string(),
            "point_count": pts.len(),
            "degree": [a.degree.0, a.degree.1],
            "control_points": [r.surface.counts().0, r.surface.counts().1],
            "parameters": name(&a.params),
            "quality": quality,
            "samples_to_points": samples_json(q),
            "measure": crate::measure::json(&r.assessment),
            "trim": crate::cad::trim_json(trimmed.as_ref()),
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        if let Some(p) = &r.projection {
            report["projection"] = projection_json(p);
        }
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

/// The trim's loops: in the best-fit plane the parameters were made in, or,
/// when they were projected along a coordinate axis, in the parameters
/// scaled back to lengths (the projection is linear, so the scaled
/// parameters are the points' coordinates across that axis).
fn loops_of(projection: Option<&Projection>) -> Loops<'static> {
    match projection {
        Some(p) if p.axis != ProjectionAxis::BestFitPlane => Loops::Parameters { scale: p.extent },
        _ => Loops::BestFitPlane,
    }
}

/// Share of the parameterization's triangles that fold over above which a
/// surface that leaves the data is blamed on the parameters, not on the
/// smoothing (0.5%: noise at the borders stays below it).
const FOLDED_SHARE: f64 = 0.005;

/// What to change when the surface leaves the data: the smoothing or the
/// net, and, when the parameters fold over too, the parameters (a noisy
/// scan's sparse outline can fold a few triangles and still be cured by the
/// smoothing, so the smoothing advice stays).
fn leaves_fix(q: &SurfaceQuality, projection: Option<&Projection>) -> String {
    let pq = &q.parameterization;
    let share = pq.fold_overs as f64 / pq.triangles.max(1) as f64;
    let smoothing = "raise the smoothing (--smooth; by default it is scaled to the data) or use fewer control points (--ctrl)";
    if share <= FOLDED_SHARE {
        return smoothing.into();
    }
    let tried = match projection {
        Some(p) => format!(
            " (projected along {}, the least folding of the best-fit plane's normal and the x, y, z axes)",
            p.axis.name()
        ),
        None => String::new(),
    };
    format!(
        "{smoothing}; the parameters also fold over in {} of {} triangles ({:.1}%){tried}: if that persists, give parameters that do not fold (--params uv-columns), or use `scanfit mba` for a height field, `scanfit coons` or `scanfit turntable` for a closed or overhanging shape",
        pq.fold_overs,
        pq.triangles,
        100.0 * share
    )
}

/// The report's line on the projection direction.
pub(crate) fn projection_line(p: &Projection) -> String {
    let shares: Vec<String> = ProjectionAxis::ALL
        .iter()
        .zip(p.fold_shares)
        .map(|(a, s)| format!("{} {:.1}%", a.name(), 100.0 * s))
        .collect();
    if p.sampled == 0 {
        return "projected onto the best-fit plane (too few points to measure folds)".into();
    }
    format!(
        "projected along {} ({}): sampled normals on the folded-back side: {} ({} points, seed {})",
        p.axis.name(),
        vec_text(&p.direction),
        shares.join(", "),
        p.sampled,
        scanfit::base::FOLD_SEED,
    )
}

fn vec_text(v: &scanfit::Vector3) -> String {
    format!("{:.4}, {:.4}, {:.4}", v.x, v.y, v.z)
}

/// The projection in the JSON report.
pub(crate) fn projection_json(p: &Projection) -> serde_json::Value {
    let shares: serde_json::Map<String, serde_json::Value> = ProjectionAxis::ALL
        .iter()
        .zip(p.fold_shares)
        .map(|(a, s)| (a.name().to_string(), s.into()))
        .collect();
    serde_json::json!({
        "axis": p.axis.name(),
        "direction": [p.direction.x, p.direction.y, p.direction.z],
        "fold_shares": shares,
        "sampled": p.sampled,
        "extent": p.extent,
    })
}

/// ", smoothing λ = ... (scaled to the data)" for the report's first line.
fn smoothing_note(given: Option<f64>, used: f64) -> String {
    match given {
        None => format!(", smoothing {used:.3e} (scaled to the data)"),
        Some(l) if l > 0.0 => format!(", smoothing {l}"),
        Some(_) => ", no smoothing".to_string(),
    }
}

/// The first line of the report of `scanfit fit` (in memory and streamed).
pub(crate) fn fit_title(a: &FitArgs, points: usize, surface: &Surface, smoothing: f64) -> String {
    let (p, qd) = surface.degrees();
    let (cu, cv) = surface.counts();
    format!(
        "{}: {} points -> B-spline surface of degree {p} x {qd}, {cu} x {cv} control points ({} parameters, {} knots{}{})",
        a.input.input.display(),
        points,
        name(&a.params),
        name(&a.knots),
        smoothing_note(a.smooth, smoothing),
        if a.periodic_u { ", periodic in u" } else { "" },
    )
}

/// The table of a surface's measures: `at_parameters` names the errors at
/// the points' parameters, then the orthogonal distances, eq. 17 and the
/// samples (shared by `fit` and `mba`, in memory and streamed).
pub(crate) fn quality_table(
    head: &str,
    at_parameters: &str,
    q: &SurfaceQuality,
    eq17: &str,
) -> String {
    let mut t = Table::new(
        &[head, "mean", "max", "RMSE", "unit"],
        &[true, false, false, false, true],
    );
    let e = &q.at_parameters;
    t.row(vec![
        at_parameters.into(),
        num(e.mean),
        num(e.max),
        num(e.rmse),
        "data units".into(),
    ]);
    quality_rows(&mut t, q, eq17);
    t.render()
}

fn print_report(a: &FitArgs, r: &FitReport) -> Result<()> {
    let q = &r.assessment.quality;
    outln!("{}", fit_title(a, q.points, &r.surface, r.smoothing));
    if let Some(p) = &r.projection {
        outln!("{}", projection_line(p));
    }
    outln!();
    out!(
        "{}",
        quality_table(
            "measure",
            "|P - S(u,v)| at the parameters (eq. 15)",
            q,
            "grid points to nearest point (MBA eq. 17)"
        )
    );
    let pq = &q.parameterization;
    if let Some(note) = crate::measure::note(&r.assessment) {
        outln!("{note}");
    }
    if pq.triangles > 0 {
        // a sample's largest anisotropy is a lower bound of the whole set's
        let of = if r.assessment.sample.is_some() {
            " (in the sample)"
        } else {
            ""
        };
        outln!(
            "\nparameterization: {} fold-overs in {} triangles, L2 stretch {:.3} (1 = uniform), max anisotropy{of} {}",
            pq.fold_overs,
            pq.triangles,
            pq.l2_stretch,
            num(pq.max_anisotropy)
        );
    }
    if q.unconverged > 0 {
        outln!(
            "note: {} point inversions did not converge (their distance is the best found)",
            q.unconverged
        );
    }
    if !r.rounds.is_empty() {
        outln!();
        let mut t = Table::new(
            &["correction round", "RMSE", "max error", "unit"],
            &[false, false, false, true],
        );
        for r in &r.rounds {
            t.row(vec![
                r.round.to_string(),
                num(r.errors.rmse),
                num(r.errors.max),
                "data units".into(),
            ]);
        }
        out!("{}", t.render());
    }
    Ok(())
}
