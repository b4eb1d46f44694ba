//! Entry points of the fuzz targets (`fuzz/`, cargo-fuzz) and of the test
//! that replays their corpora on stable (`tests/fuzz_corpus.rs`): each feeds
//! arbitrary bytes to one reader the way the command line does, and returns
//! whether the reader accepted them. A panic, an abort or an allocation
//! beyond the harness's limit is a finding; `Ok` and `Err` are both fine.

use std::path::Path;

use crate::table::{NonFinite, ReadOptions};

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
        if let Ok(table) = crate::parse_cloud(Path::new(name), data, &options) {
            let n = table.points.len();
            for i in [0, n / 2, n.saturating_sub(1)] {
                let _ = table.locate(i);
            }
            accepted |= table.into_cloud().is_ok();
        }
    }
    accepted
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
