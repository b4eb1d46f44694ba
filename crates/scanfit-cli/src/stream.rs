//! `scanfit fit --chunk-points N` and `scanfit mba --chunk-points N`: the
//! input read in chunks, in passes, over [`scanfit::pipeline::stream`].
//! Memory depends on the model, not on the point count (text inputs; other
//! formats are read whole, and a note says so).

use std::cell::RefCell;

use anyhow::{bail, Result};
use scanfit::pipeline::stream::{fit as fit_streamed, mba as mba_streamed, Chunk, PointSource};
use scanfit_io::chunks::PointChunks;
use scanfit_io::json::SurfaceDoc;
use scanfit_io::{write_all_atomic, ReadOptions};

use crate::args::option_note;
use crate::mba::MbaArgs;
use crate::outputs::{
    print_written, provenance, quality_doc, quality_rows, samples_json, Deviation, Picture,
    SurfaceOutputArgs,
};
use crate::progress::Progress;
use crate::surface::{FitArgs, ParamsArg};
use crate::table::{num, Table};

/// What the report says about the streamed measures.
const MEASURED: &str = "errors at the parameters, orthogonal distances, eq. 17 and sample distances over all points; point spacing from the first chunk; parameterization not measured";

/// A point file read in chunks, one [`PointChunks`] per pass.
struct FileSource<'a> {
    path: &'a std::path::Path,
    options: ReadOptions,
    chunk: usize,
    uv: bool,
    passes: usize,
    quiet: bool,
    /// The reader's error, kept for the message (the library sees a stand-in).
    failure: RefCell<Option<anyhow::Error>>,
}

impl FileSource<'_> {
    fn chunk_pass(&mut self, f: &mut dyn FnMut(Chunk<'_>) -> scanfit::Result<()>) -> Result<()> {
        let mut chunks = PointChunks::open(self.path, &self.options, self.chunk)?;
        if self.passes == 0 && !chunks.bounded() && !self.quiet {
            crate::print_stderr(format_args!(
                "note: {} is read whole (chunked reading covers text files: .xyz .csv .txt .pts .asc); memory grows with its point count",
                self.path.display()
            ));
        }
        while let Some(t) = chunks.next_chunk()? {
            let uv: Option<Vec<[f64; 2]>> = if self.uv {
                let (Some(u), Some(v)) = (t.column("u"), t.column("v")) else {
                    bail!(
                        "{} has no columns named u and v (its columns: {}); use --params uv-columns with such columns",
                        self.path.display(),
                        t.columns.join(", ")
                    );
                };
                Some(u.iter().zip(v).map(|(&u, &v)| [u, v]).collect())
            } else {
                None
            };
            let chunk = Chunk {
                points: &t.points,
                uv: uv.as_deref(),
            };
            f(chunk).map_err(|e| match e.point_indices().first() {
                Some(&i) => anyhow::anyhow!("{}: {e} ({})", self.path.display(), t.locate(i)),
                None => anyhow::Error::new(e),
            })?;
        }
        if self.passes == 0 {
            crate::print_warnings(chunks.warnings());
        }
        self.passes += 1;
        Ok(())
    }
}

impl PointSource for FileSource<'_> {
    fn pass(&mut self, f: &mut dyn FnMut(Chunk<'_>) -> scanfit::Result<()>) -> scanfit::Result<()> {
        self.chunk_pass(f).map_err(|e| {
            let message = e.to_string();
            *self.failure.borrow_mut() = Some(e);
            scanfit::Error::InvalidInput(message)
        })
    }
}

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

fn source<'a>(
    input: &'a crate::args::InputArgs,
    chunk: usize,
    uv: bool,
    quiet: bool,
) -> Result<FileSource<'a>> {
    if chunk == 0 {
        bail!("--chunk-points must be at least 1 (try 1000000)");
    }
    Ok(FileSource {
        path: &input.input,
        options: input.options(),
        chunk,
        uv,
        passes: 0,
        quiet,
        failure: RefCell::new(None),
    })
}

/// The library's error, or the reader's behind it.
fn explain(e: scanfit::Error, s: &FileSource, options: &[(&str, &str)]) -> anyhow::Error {
    match s.failure.borrow_mut().take() {
        Some(f) => f,
        None => anyhow::anyhow!("{}: {e}{}", s.path.display(), option_note(&e, options)),
    }
}

/// Runs `scanfit fit --chunk-points N`.
pub fn fit(a: &FitArgs, chunk: usize) -> Result<()> {
    check_outputs(&a.out)?;
    if a.points_out.is_some() {
        bail!("--points-out writes every point's parameters and errors and needs all points at once; leave it out with --chunk-points");
    }
    let progress = Progress::spinner(a.quiet || a.json);
    let mut s = source(
        &a.input,
        chunk,
        a.params == ParamsArg::UvColumns,
        a.quiet || a.json,
    )?;
    let options = [
        ("knots", "--knots"),
        ("params", "--params"),
        ("correction_rounds", "--correct"),
        ("smoothing", "--smooth"),
    ];
    let r = fit_streamed(&mut s, &a.config(), &progress).map_err(|e| explain(e, &s, &options))?;
    let q = &r.quality;
    let mut doc = SurfaceDoc::new(&r.surface);
    let name = if a.params == ParamsArg::UvColumns {
        "uv-columns"
    } else {
        "plane"
    };
    doc.provenance = Some(provenance(
        "fit (least-squares surface)",
        Some(name.into()),
        &a.input.input,
        q.points,
        a.settings(&r.surface, r.smoothing),
    ));
    doc.quality = Some(quality_doc(q, Vec::new()));
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
    let (cu, cv) = r.surface.counts();
    let title = format!(
        "{}: {} points -> {cu} x {cv} control points (read in chunks of {chunk} points, {} passes)",
        a.input.input.display(),
        q.points,
        r.passes
    );
    print(
        a.json,
        &title,
        q,
        &files,
        exaggeration,
        a.out.png.as_deref(),
        serde_json::json!({"control_points": [cu, cv], "degree": [a.degree.0, a.degree.1]}),
        chunk,
        r.passes,
    )
}

/// Runs `scanfit mba --chunk-points N`.
pub fn mba(a: &MbaArgs, chunk: usize) -> Result<()> {
    check_outputs(&a.out)?;
    if a.adjust {
        bail!("--adjust projects the knot grid onto the whole cloud (nearest points along z) and needs all points at once; leave it out with --chunk-points");
    }
    let progress = Progress::spinner(a.quiet || a.json);
    let mut s = source(&a.input, chunk, false, a.quiet || a.json)?;
    let config = a.config();
    let options = [
        ("base", "--base"),
        ("max_levels", "--levels"),
        ("tolerance", "--tolerance"),
    ];
    let r = mba_streamed(&mut s, &config.mba, &config.assess, &progress)
        .map_err(|e| explain(e, &s, &options))?;
    let q = &r.quality;
    let mut doc = SurfaceDoc::new(&r.surface);
    let settings = a.settings(r.levels.len(), r.cells);
    doc.provenance = Some(provenance(
        "mba (multilevel B-spline approximation)",
        Some("xy (u = x, v = y, scaled to [0, 1])".into()),
        &a.input.input,
        q.points,
        settings,
    ));
    doc.quality = Some(quality_doc(q, Vec::new()));
    let deviation = Deviation {
        per_point: &[],
        stats: q.at_parameters,
        name: "vertical distance |z - f(x, y)|",
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
    let title = format!("{}: {} points -> {} x {} control points, {} levels (read in chunks of {chunk} points, {} passes, {:.3} s)", a.input.input.display(), q.points, m + 3, n + 3, r.levels.len(), r.passes, r.seconds);
    let levels: Vec<serde_json::Value> = r.levels.iter().map(|l| serde_json::json!({
        "level": l.level, "control_points": [l.control_points.0, l.control_points.1],
        "vertical_mean": l.vertical.mean, "vertical_max": l.vertical.max, "vertical_rmse": l.vertical.rmse,
        "grid_rmse": l.grid_rmse, "seconds": l.seconds})).collect();
    print(
        a.json,
        &title,
        q,
        &files,
        exaggeration,
        a.out.png.as_deref(),
        serde_json::json!({"control_points": [m + 3, n + 3], "levels": levels}),
        chunk,
        r.passes,
    )
}

/// Prints the report of a streamed run (tables, or JSON with `extra`'s keys).
#[allow(clippy::too_many_arguments)]
fn print(
    json: bool,
    title: &str,
    q: &scanfit::pipeline::assess::SurfaceQuality,
    files: &crate::outputs::Files,
    exaggeration: f64,
    png: Option<&std::path::Path>,
    extra: serde_json::Value,
    chunk: usize,
    passes: usize,
) -> Result<()> {
    if json {
        let mut report = serde_json::json!({
            "point_count": q.points,
            "quality": quality_doc(q, Vec::new()),
            "samples_to_points": samples_json(q),
            "streamed": {"chunk_points": chunk, "passes": passes, "measured": MEASURED},
            "outputs": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
        });
        if let (Some(r), Some(e)) = (report.as_object_mut(), extra.as_object()) {
            r.extend(e.clone());
        }
        outln!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    outln!("{title}\n");
    let mut t = Table::new(
        &["measure", "mean", "max", "RMSE", "unit"],
        &[true, false, false, false, true],
    );
    let e = &q.at_parameters;
    t.row(vec![
        "error at the parameters".into(),
        num(e.mean),
        num(e.max),
        num(e.rmse),
        "data units".into(),
    ]);
    quality_rows(&mut t, q, "grid points to nearest point (MBA eq. 17)");
    out!("{}", t.render());
    outln!("\nmeasured by streaming: {MEASURED}");
    print_written(files, png, exaggeration)
}
