//! Entry points of the fuzz targets (`fuzz/`, cargo-fuzz) and of the test
//! that replays their corpora on stable (`tests/fuzz_corpus.rs`): each feeds
//! arbitrary bytes to one reader the way the command line does, and returns
//! whether the reader accepted them. A panic, an abort or an allocation
//! beyond the harness's limit is a finding; the reader's `Ok` and `Err` are
//! both fine. Where two readers of the same file are compared, their
//! disagreement is returned as a [`Disagreement`] (a finding too: the fuzz
//! targets and the replay test fail on it); nothing here panics.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::chunks::PointChunks;
use crate::table::{NonFinite, PointTable, ReadOptions};

/// Two readers of the same bytes disagree (a finding): what differs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Disagreement(pub String);

impl std::fmt::Display for Disagreement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Disagreement {}

/// `Err(Disagreement)` with `what` unless `same`.
fn agree(same: bool, what: impl FnOnce() -> String) -> Result<(), Disagreement> {
    if same {
        Ok(())
    } else {
        Err(Disagreement(what()))
    }
}

/// Reads `data` as the point file `name` (its extension picks the reader)
/// with both non-finite policies, and turns an accepted table into a
/// `PointCloud` as the commands do. A `.ply` name is also read by the
/// direct binary PLY reader ([`crate::read_cloud`]'s path for a vertex-only
/// file of fixed records), which must agree with the general one. Returns
/// whether the file was accepted, or the readers' [`Disagreement`].
///
/// ```
/// use scanfit_io::fuzz::point_file;
/// assert_eq!(point_file("f.xyz", b"1 2 3\n4 5 6\n"), Ok(true));
/// assert_eq!(point_file("f.ply", b"ply\nformat"), Ok(false));
/// ```
pub fn point_file(name: &str, data: &[u8]) -> Result<bool, Disagreement> {
    let mut accepted = false;
    for non_finite in [NonFinite::Reject, NonFinite::Drop] {
        let options = ReadOptions {
            non_finite,
            ..ReadOptions::default()
        };
        let general = crate::parse_cloud(Path::new(name), data, &options);
        if name.ends_with(".ply") {
            same_as_direct(name, data, &options, &general)?;
        }
        if let Ok(table) = general {
            let n = table.points.len();
            for i in [0, n / 2, n.saturating_sub(1)] {
                let _ = table.locate(i);
            }
            accepted |= table.into_cloud().is_ok();
        }
    }
    Ok(accepted)
}

/// The direct binary PLY reader ([`crate::read_cloud`]'s path for a
/// vertex-only file of fixed records) on `data`: where it takes the file,
/// it must give the general reader's `general` result (the same table, or
/// an error where the general reader has one).
fn same_as_direct(
    name: &str,
    data: &[u8],
    options: &ReadOptions,
    general: &crate::Result<PointTable>,
) -> Result<(), Disagreement> {
    let direct = crate::ply_read::direct::read(Path::new(name), data, options);
    match (direct, general) {
        (Ok(None), _) | (Err(_), Err(_)) => Ok(()),
        (Ok(Some(d)), Ok(g)) => same_tables(&d, g).map_err(|Disagreement(what)| {
            Disagreement(format!(
                "direct and general PLY readers give other tables: {what}"
            ))
        }),
        (d, g) => Err(Disagreement(format!(
            "the direct PLY reader {} the file, the general one {} it",
            if d.is_ok() { "accepts" } else { "refuses" },
            if g.is_ok() { "accepts" } else { "refuses" }
        ))),
    }
}

/// Whether two reads of one file gave the same table: the values bit for
/// bit (a NaN in an extra column equals itself), the columns, locations,
/// record indices, counts and warnings (else what differs first).
fn same_tables(a: &PointTable, b: &PointTable) -> Result<(), Disagreement> {
    // (`same_points` walks `a`'s columns and points: the counts first)
    let lengths = |t: &PointTable| {
        let columns: Vec<usize> = t.extra.iter().map(Vec::len).collect();
        (t.points.len(), columns)
    };
    agree(lengths(a) == lengths(b), || {
        format!(
            "points and column lengths {:?} and {:?}",
            lengths(a),
            lengths(b)
        )
    })?;
    same_points(b, std::slice::from_ref(a))?;
    agree(a.format == b.format, || "format".into())?;
    agree(a.file_index == b.file_index, || "record indices".into())?;
    agree(a.dropped_non_finite == b.dropped_non_finite, || {
        format!(
            "dropped points {} and {}",
            a.dropped_non_finite, b.dropped_non_finite
        )
    })?;
    agree(a.warnings == b.warnings, || {
        format!("warnings {:?} and {:?}", a.warnings, b.warnings)
    })
}

/// Reads `data` as a LAS/LAZ file twice, whole (the in-memory reader) and
/// streamed ([`PointChunks`], the reader of `--chunk-points`) from a
/// temporary file in chunks of `1 + data.len() % 7` points, with a
/// pointwise LAZ chunk decoded through the smallest window its cursor
/// allows (so the arithmetic decoder is suspended and resumed every few
/// points, where the whole read decodes a fuzzer-sized chunk in one go).
/// The two must agree: both refuse the file, or both give the same points,
/// columns, point locations and warnings, bit for bit. Returns whether the
/// file was accepted, or the reads' [`Disagreement`].
///
/// ```
/// assert_eq!(scanfit_io::fuzz::streamed_las_file(b"LASF"), Ok(false));
/// ```
pub fn streamed_las_file(data: &[u8]) -> Result<bool, Disagreement> {
    static FILES: AtomicUsize = AtomicUsize::new(0);
    let path = std::env::temp_dir().join(format!(
        "scanfit-fuzz-{}-{}.laz",
        std::process::id(),
        FILES.fetch_add(1, Ordering::Relaxed)
    ));
    if std::fs::write(&path, data).is_err() {
        return Ok(false);
    }
    let options = ReadOptions::default();
    let whole = crate::parse_cloud(&path, data, &options);
    let chunk = 1 + data.len() % 7;
    let streamed = read_streamed(&path, &options, chunk);
    let _ = std::fs::remove_file(&path);
    match (whole, streamed) {
        (Ok(whole), Ok((chunks, warnings))) => {
            for t in &chunks {
                let n = t.points.len();
                agree((1..=chunk).contains(&n), || {
                    format!("a chunk of {n} points, {chunk} asked for")
                })?;
            }
            same_points(&whole, &chunks)?;
            agree(warnings == whole.warnings, || {
                format!(
                    "warnings, streamed {warnings:?} and whole {:?}",
                    whole.warnings
                )
            })?;
            Ok(true)
        }
        (Err(_), Err(_)) => Ok(false),
        (Ok(_), Err(e)) => Err(Disagreement(format!(
            "the whole read accepts the file, the streamed read fails: {e}"
        ))),
        (Err(e), Ok(_)) => Err(Disagreement(format!(
            "the streamed read accepts the file, the whole read fails: {e}"
        ))),
    }
}

/// Every chunk of a streamed read, and the reader's warnings at the end.
fn read_streamed(
    path: &Path,
    options: &ReadOptions,
    chunk: usize,
) -> crate::Result<(Vec<PointTable>, Vec<String>)> {
    let mut reader = PointChunks::open(path, options, chunk)?;
    reader.set_laz_window(0);
    let mut chunks = Vec::new();
    while let Some(t) = reader.next_chunk()? {
        chunks.push(t);
    }
    Ok((chunks, reader.warnings().to_vec()))
}

/// Whether `chunks` hold the points of `whole`, bit for bit, with the same
/// columns and locations (else what differs first).
fn same_points(whole: &PointTable, chunks: &[PointTable]) -> Result<(), Disagreement> {
    let mut k = 0;
    for t in chunks {
        agree(t.columns == whole.columns, || {
            format!("columns {:?} and {:?}", t.columns, whole.columns)
        })?;
        for (i, p) in t.points.iter().enumerate() {
            let q = whole.points.get(k).copied();
            let bits = |p: &scanfit::Point3| p.coords.map(f64::to_bits);
            agree(Some(bits(p)) == q.as_ref().map(bits), || {
                format!("point {k}")
            })?;
            for (c, col) in t.extra.iter().enumerate() {
                let w = whole.extra.get(c).and_then(|w| w.get(k));
                agree(
                    col.get(i).map(|v| v.to_bits()) == w.map(|v| v.to_bits()),
                    || format!("point {k}, column {c}"),
                )?;
            }
            agree(t.locate(i) == whole.locate(k), || {
                format!("location of point {k}")
            })?;
            k += 1;
        }
    }
    agree(k == whole.points.len(), || {
        format!("{k} points streamed, {} whole", whole.points.len())
    })
}

/// Parses `data` as a curve document and, when it is accepted, evaluates
/// the curve across its domain. Returns whether it was accepted.
///
/// ```
/// assert!(!scanfit_io::fuzz::curve_document(br#"{"degree": 18446744073709551615}"#));
/// ```
pub fn curve_document(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok((_, curve)) = crate::json::parse_curve(Path::new("f.json"), text) else {
        return false;
    };
    let (a, b) = curve.domain();
    for k in 0..=8 {
        let _ = curve.point(a + (b - a) * f64::from(k) / 8.0);
    }
    true
}

/// Parses `data` as a surface document and, when it is accepted, evaluates
/// the surface on a grid over its domain. Returns whether it was accepted.
///
/// ```
/// assert!(!scanfit_io::fuzz::surface_document(b"{}"));
/// ```
pub fn surface_document(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok((_, surface)) = crate::json::parse_surface(Path::new("f.json"), text) else {
        return false;
    };
    let ((u0, u1), (v0, v1)) = surface.domain();
    for i in 0..=4 {
        for j in 0..=4 {
            let _ = surface.point(
                u0 + (u1 - u0) * f64::from(i) / 4.0,
                v0 + (v1 - v0) * f64::from(j) / 4.0,
            );
        }
    }
    true
}

/// Feeds `data` to the model JSON document reader (`scanfit reconstruct -o`,
/// read by `report` and `export`): parses and builds the patch complex,
/// then validates its structure and geometry and takes its volume, as the
/// commands that read it do. Returns whether the document was accepted.
///
/// ```
/// assert!(!scanfit_io::fuzz::model_document(b"{}"));
/// assert!(!scanfit_io::fuzz::model_document(b"\xff"));
/// ```
pub fn model_document(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok((_, model)) = crate::model::parse_model(Path::new("f.json"), text) else {
        return false;
    };
    let _ = model.validate();
    let _ = model.edge_faces();
    let _ = model.border_edges();
    let _ = model.signed_volume();
    true
}
