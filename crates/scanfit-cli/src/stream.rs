//! `scanfit fit --chunk-points N` and `scanfit mba --chunk-points N`: the
//! input read in chunks, in passes ([`scanfit_io::source::FileSource`]
//! over [`scanfit::pipeline::stream`]). Memory depends on the model, not on
//! the point count, for the formats [`reads_in_chunks`] names (text, PLY,
//! LAS/LAZ);
//! other formats are read whole, and a note says so. The reports are those
//! of the in-memory commands (the same title, tables and JSON keys), plus
//! what streaming measured.

use anyhow::{bail, Result};
use scanfit::pipeline::stream::{fit as fit_streamed, mba as mba_streamed, StreamedFit};
use scanfit_io::json::SurfaceDoc;
use scanfit_io::source::{reads_in_chunks, FileSource};
use scanfit_io::write_all_atomic;

use crate::args::{cli_message, InputArgs};
use crate::mba::MbaArgs;
use crate::outputs::{
    print_written, provenance, quality_doc, samples_json, Deviation, Files, Picture,
    SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::surface::{
    fit_title, projection_json, projection_line, quality_table, FitArgs, ParamsArg,
};

/// What the report says about the streamed measures.
const MEASURED: &str = "errors at the parameters, orthogonal distances, eq. 17 and sample distances over all points; point spacing from the first chunk; parameterization not measured";

/// The outputs a streamed run can write: the surface documents and an OBJ
/// mesh (the others colour the surface by per-point deviations).
fn check_outputs(out: &SurfaceOutputArgs) -> Result<()> {
    let mesh_needs_points = out
        .mesh
        .as_deref()
        .is_some_and(|m| crate::outputs::extension(m) != "obj");
    if out.png.is_some() || out.deviation_png.is_some() || mesh_needs_points {
        bail!("--png, --deviation-png and a .ply/.glb --mesh colour the surface by each point's deviation and need all points at once; leave them out with --chunk-points (an .obj --mesh, -o, --step and --iges are fine)");
    }
    Ok(())
}

/// The file as a source of chunks; a note when it is read whole.
fn source(input: &InputArgs, chunk: usize, uv: bool, quiet: bool) -> Result<FileSource> {
    if chunk == 0 {
        bail!("--chunk-points must be at least 1 (try 1000000)");
    }
    let options = input.options();
    if !quiet && !reads_in_chunks(&input.input, &options)? {
        crate::print_stderr(format_args!(
            "note: {} is read whole (chunked reading covers text files .xyz .csv .txt .pts .asc, LAS/LAZ, and PLY: ascii, and binary without list properties in the vertices); memory grows with its point count",
            input.input.display()
        ));
    }
    Ok(FileSource::new(&input.input, options, chunk, uv))
}

/// The library's error, or the reader's behind it; the reader's warnings.
fn finish_source(
    r: scanfit::Result<()>,
    s: &mut FileSource,
    options: &[(&str, &str)],
) -> Result<()> {
    if let Err(e) = r {
        return Err(match s.take_failure() {
            Some(f) => f.into(),
            None => anyhow::anyhow!("{}: {}", s.path().display(), cli_message(&e, options)),
        });
    }
    crate::print_warnings(s.warnings());
    Ok(())
}

/// Runs `scanfit fit --chunk-points N`.
pub fn fit(a: &FitArgs, chunk: usize) -> Result<()> {
    check_outputs(&a.out)?;
    if a.points_out.is_some() {
        bail!("--points-out writes every point's parameters and errors and needs all points at once; leave it out with --chunk-points");
    }
    let uv = a.params == ParamsArg::UvColumns;
    trim_note(a, !uv)?;
    let progress = Progress::spinner(a.quiet || a.json);
    let mut s = source(&a.input, chunk, uv, a.quiet || a.json)?;
    let options = [
        ("knots", "--knots"),
        ("params", "--params"),
        ("correction_rounds", "--correct"),
        ("smoothing", "--smooth"),
    ];
    let r = fit_streamed(&mut s, &a.config(), &progress);
    let r = match r {
        Ok(r) => {
            finish_source(Ok(()), &mut s, &options)?;
            r
        }
        Err(e) => return finish_source(Err(e), &mut s, &options),
    };
    let q = &r.quality;
    let mut doc = SurfaceDoc::new(&r.surface);
    let name = if uv { "uv-columns" } else { "plane" };
    doc.provenance = Some(provenance(
        "fit (least-squares surface)",
        Some(name.into()),
        &a.input.input,
        q.points,
        a.settings(r.surface.counts(), r.smoothing),
    ));
    doc.quality = Some(quality_doc(
        q,
        r.rounds.iter().map(|r| r.errors.rmse).collect(),
    ));
    let deviation = Deviation {
        per_point: &[],
        stats: q.orthogonal,
        name: "orthogonal distance",
    };
    let (files, exaggeration) = a.out.files(
        &r.surface,
        &doc,
        &[],
        &deviation,
        &a.input.input,
        &Picture::default(),
    )?;
    write_all_atomic(&files)?;
    progress.finish();
    let (report, before) = fit_report(a, &r, chunk, name);
    report.print(
        q,
        &files,
        exaggeration,
        &a.out,
        "|P - S(u,v)| at the parameters (eq. 15)",
        &before,
    )
}

/// The streamed fit's report (the in-memory fit's keys, with the projection
/// direction) and the projection's line above its table.
fn fit_report(a: &FitArgs, r: &StreamedFit, chunk: usize, name: &str) -> (Report, String) {
    let (cu, cv) = r.surface.counts();
    let mut extra = serde_json::json!({
        "input": a.input.input.display().to_string(),
        "degree": [a.degree.0, a.degree.1],
        "control_points": [cu, cv],
        "parameters": name,
        "trim": crate::cad::trim_json(None),
    });
    let mut before = String::new();
    if let Some(p) = &r.projection {
        extra["projection"] = projection_json(p);
        before = format!("{}\n\n", projection_line(p));
    }
    let report = Report {
        json: a.json,
        title: fit_title(a, r.quality.points, &r.surface, r.smoothing),
        chunk,
        passes: r.passes,
        extra,
    };
    (report, before)
}

/// The streamed fit keeps the parameter rectangle: `--trim` is refused with
/// the reason, and the plane's default (trimmed) gets a note.
fn trim_note(a: &FitArgs, plane: bool) -> Result<()> {
    if a.trim.trim {
        bail!("--trim cannot be used with --chunk-points: the face's outline and holes (an alpha shape) need all points at once; leave --trim out, or run without --chunk-points");
    }
    if plane && !a.trim.no_trim && !(a.quiet || a.json) {
        crate::print_stderr(format_args!(
            "note: the surface is NOT trimmed: --chunk-points fits the whole parameter rectangle, since the outline needs all points at once; --no-trim silences this note"
        ));
    }
    Ok(())
}

/// Why a streamed `mba` gives the untrimmed rectangle, and how to get a
/// trimmed face instead (the note of the default, the refusal of `--trim`).
pub const TRIM_STREAMED: &str = "--chunk-points fits the whole xy rectangle, since the outline (alpha shape) needs all points at once; for a face trimmed to the outline and holes run without --chunk-points, or on a thinned copy that fits in memory (scanfit cloud clean IN --voxel-spacings 2 -o thin.ply, then scanfit mba thin.ply)";

/// Runs `scanfit mba --chunk-points N`.
pub fn mba(a: &MbaArgs, chunk: usize) -> Result<()> {
    check_outputs(&a.out)?;
    if a.adjust {
        bail!("--adjust projects the knot grid onto the whole cloud (nearest points along z) and needs all points at once; leave it out with --chunk-points");
    }
    let quiet = a.quiet || a.json;
    if !quiet && !a.trim.no_trim {
        crate::print_stderr(format_args!(
            "note: the surface is NOT trimmed: {TRIM_STREAMED}; --no-trim silences this note"
        ));
    }
    let progress = Progress::spinner(quiet);
    let mut s = source(&a.input, chunk, false, quiet)?;
    let config = a.config();
    let options = [
        ("base", "--base"),
        ("max_levels", "--levels"),
        ("tolerance", "--tolerance"),
    ];
    let up = a.out.view.up_given();
    let r = match mba_streamed(&mut s, &config.mba, &config.assess, up, &progress) {
        Ok(r) => {
            finish_source(Ok(()), &mut s, &options)?;
            r
        }
        Err(e) => return finish_source(Err(e), &mut s, &options),
    };
    let q = &r.quality;
    let mut doc = SurfaceDoc::new(&r.surface);
    doc.provenance = Some(provenance(
        "mba (multilevel B-spline approximation)",
        Some(crate::mba::height_names(r.up).1.into()),
        &a.input.input,
        q.points,
        a.settings(r.levels.len(), r.cells),
    ));
    doc.quality = Some(quality_doc(q, Vec::new()));
    let deviation = Deviation {
        per_point: &[],
        stats: q.at_parameters,
        name: crate::mba::height_names(r.up).0,
    };
    let (files, exaggeration) = a.out.files(
        &r.surface,
        &doc,
        &[],
        &deviation,
        &a.input.input,
        &Picture::default(),
    )?;
    write_all_atomic(&files)?;
    progress.finish();
    let (m, n) = r.cells;
    let report = Report {
        json: a.json,
        title: format!(
            "{}: {} points -> bicubic B-spline surface, {} x {} control points ({} levels, {:.3} s)",
            a.input.input.display(),
            q.points,
            m + 3,
            n + 3,
            r.levels.len(),
            r.seconds
        ),
        chunk,
        passes: r.passes,
        extra: serde_json::json!({
            "input": a.input.input.display().to_string(),
            "control_points": [m + 3, n + 3],
            "levels": crate::mba::rows(&r.levels),
            "trim": crate::cad::trim_json(None),
            "seconds": r.seconds,
        }),
    };
    let levels = format!(
        "{}(errors in data units)\n\n",
        crate::mba::levels_table(&r.levels, false, true)
    );
    report.print(
        q,
        &files,
        exaggeration,
        &a.out,
        crate::mba::height_names(r.up).0,
        &levels,
    )
}

/// The report of a streamed run: the in-memory command's title and keys,
/// and how the points were read.
struct Report {
    json: bool,
    title: String,
    chunk: usize,
    passes: usize,
    /// The command's own JSON keys.
    extra: serde_json::Value,
}

impl Report {
    /// Prints the tables (`before` ahead of the measures), or the JSON.
    fn print(
        self,
        q: &scanfit::pipeline::assess::SurfaceQuality,
        files: &Files,
        exaggeration: f64,
        out: &SurfaceOutputArgs,
        at_parameters: &str,
        before: &str,
    ) -> Result<()> {
        if self.json {
            let mut report = serde_json::json!({
                "point_count": q.points,
                "quality": quality_doc(q, Vec::new()),
                "samples_to_points": samples_json(q),
                "streamed": {"chunk_points": self.chunk, "passes": self.passes, "measured": MEASURED},
                "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
            });
            if let (Some(r), Some(e)) = (report.as_object_mut(), self.extra.as_object()) {
                r.extend(e.clone());
            }
            out!(
                "{}",
                scanfit_io::json::finite_json(&report, "the JSON report")?
            );
            return Ok(());
        }
        outln!(
            "{} (read in chunks of {} points, {} passes)\n",
            self.title,
            self.chunk,
            self.passes
        );
        out!("{before}");
        out!(
            "{}",
            quality_table(
                "measure",
                at_parameters,
                q,
                "grid points to nearest point (MBA eq. 17)"
            )
        );
        outln!("\nmeasured by streaming: {MEASURED}");
        print_written(files, out.png.as_deref(), exaggeration)
    }
}
