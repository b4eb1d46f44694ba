//! Entry points of the fuzz targets (`fuzz/`, cargo-fuzz) and of the test
//! that replays their corpora on stable (`tests/fuzz_corpus.rs`): each feeds
//! arbitrary bytes to one reader the way the command line does, and returns
//! whether the reader accepted them. A panic, an abort or an allocation
//! beyond the harness's limit is a finding; `Ok` and `Err` are both fine.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::chunks::PointChunks;
use crate::table::{NonFinite, PointTable, ReadOptions};

/// Reads `data` as the point file `name` (its extension picks the reader)
/// with both non-finite policies, and turns an accepted table into a
/// `PointCloud` as the commands do. Returns whether the file was accepted.
///
/// ```
/// assert!(scanfit_io::fuzz::point_file("f.xyz", b"1 2 3\n4 5 6\n"));
/// assert!(!scanfit_io::fuzz::point_file("f.ply", b"ply\nformat"));
/// ```
pub fn point_file(name: &str, data: &[u8]) -> bool {
    let mut accepted = false;
    for non_finite in [NonFinite::Reject, NonFinite::Drop] {
        let options = ReadOptions {
            non_finite,
            ..ReadOptions::default()
        };
        let general = crate::parse_cloud(Path::new(name), data, &options);
        if name.ends_with(".ply") {
            same_as_direct(name, data, &options, &general);
        }
        if let Ok(table) = general {
            let n = table.points.len();
            for i in [0, n / 2, n.saturating_sub(1)] {
                let _ = table.locate(i);
            }
            accepted |= table.into_cloud().is_ok();
        }
    }
    accepted
}

/// The direct binary PLY reader ([`crate::read_cloud`]'s path for a
/// vertex-only file of fixed records) on `data`: where it takes the file,
/// it must give the general reader's `general` result (the same table, or
/// an error where the general reader has one); a disagreement panics (a
/// finding).
fn same_as_direct(
    name: &str,
    data: &[u8],
    options: &ReadOptions,
    general: &crate::Result<PointTable>,
) {
    let direct = crate::ply_read::direct::read(Path::new(name), data, options);
    match (direct, general) {
        (Ok(None), _) | (Err(_), Err(_)) => {}
        (Ok(Some(d)), Ok(g)) => assert!(d == *g, "direct and general PLY readers disagree"),
        (d, g) => panic!(
            "direct PLY reader {} where the general one {}",
            if d.is_ok() { "accepts" } else { "refuses" },
            if g.is_ok() { "accepts" } else { "refuses" }
        ),
    }
}

/// Reads `data` as a LAS/LAZ file twice, whole (the in-memory reader) and
/// streamed ([`PointChunks`], the reader of `--chunk-points`) from a
/// temporary file in chunks of `1 + data.len() % 7` points, with a
/// pointwise LAZ chunk decoded through the smallest window its cursor
/// allows (so the arithmetic decoder is suspended and resumed every few
/// points, where the whole read decodes a fuzzer-sized chunk in one go).
/// The two must agree: both refuse the file, or both give the same points,
/// columns, point locations and warnings, bit for bit; a disagreement
/// panics (a finding). Returns whether the file was accepted.
///
/// ```
/// assert!(!scanfit_io::fuzz::streamed_las_file(b"LASF"));
/// ```
pub fn streamed_las_file(data: &[u8]) -> bool {
    static FILES: AtomicUsize = AtomicUsize::new(0);
    let path = std::env::temp_dir().join(format!(
        "scanfit-fuzz-{}-{}.laz",
        std::process::id(),
        FILES.fetch_add(1, Ordering::Relaxed)
    ));
    if std::fs::write(&path, data).is_err() {
        return false;
    }
    let options = ReadOptions::default();
    let whole = crate::parse_cloud(&path, data, &options);
    let streamed = read_streamed(&path, &options, 1 + data.len() % 7);
    let _ = std::fs::remove_file(&path);
    match (whole, streamed) {
        (Ok(whole), Ok((chunks, warnings))) => {
            same_points(&whole, &chunks);
            assert_eq!(warnings, whole.warnings, "warnings, streamed and whole");
            true
        }
        (Err(_), Err(_)) => false,
        (Ok(_), Err(e)) => panic!("the whole read accepts the file, the streamed read fails: {e}"),
        (Err(e), Ok(_)) => panic!("the streamed read accepts the file, the whole read fails: {e}"),
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
        assert!(
            (1..=chunk).contains(&t.points.len()),
            "a chunk of {} points, {chunk} asked for",
            t.points.len()
        );
        chunks.push(t);
    }
    Ok((chunks, reader.warnings().to_vec()))
}

/// Asserts that `chunks` hold the points of `whole`, bit for bit, with the
/// same columns and locations.
fn same_points(whole: &PointTable, chunks: &[PointTable]) {
    let mut k = 0;
    for t in chunks {
        assert_eq!(t.columns, whole.columns, "columns, streamed and whole");
        for (i, p) in t.points.iter().enumerate() {
            let q = whole.points.get(k).copied();
            let bits = |p: &scanfit::Point3| p.coords.map(f64::to_bits);
            assert_eq!(Some(bits(p)), q.as_ref().map(bits), "point {k}");
            for (c, col) in t.extra.iter().enumerate() {
                let w = whole.extra.get(c).and_then(|w| w.get(k));
                assert_eq!(
                    col.get(i).map(|v| v.to_bits()),
                    w.map(|v| v.to_bits()),
                    "point {k}, column {c}"
                );
            }
            assert_eq!(t.locate(i), whole.locate(k), "point {k}");
            k += 1;
        }
    }
    assert_eq!(k, whole.points.len(), "points, streamed and whole");
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
