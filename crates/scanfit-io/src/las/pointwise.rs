//! LAS point formats 0-5 compressed with LASzip's pointwise compressor
//! (items of version 2), read with scanfit's own decoder
//! ([`crate::laz14::PointwiseLaz`]) instead of the `laz` crate's, whose
//! GPS-time decoder recurses without bound on damaged data. Columns and
//! coordinates are the ones the `las` crate gives for the same file.

use std::path::Path;

use scanfit::Point3;

use super::layered::binary;
use super::{column_names, decode_in_order, transforms, unread_chunks, Decoded, Pointwise};
use crate::laz14::{PointwiseLaz, PointwiseRecord};
use crate::{Error, Result};

/// The columns of a pointwise file's points (see [`column_names`]).
pub(super) fn names(file: &PointwiseLaz) -> Vec<&'static str> {
    column_names(file.has_gps_time(), file.has_rgb(), false)
}

/// The file's chunks, checked (see [`PointwiseLaz::new`]).
pub(super) fn open(
    path: &Path,
    bytes_len: u64,
    pw: &Pointwise,
    vlr: &[u8],
) -> Result<PointwiseLaz> {
    PointwiseLaz::new(
        vlr,
        pw.vlr_at,
        pw.start,
        pw.data_end.min(bytes_len),
        pw.count,
        pw.table.as_deref(),
    )
    .map_err(|e| binary(path, e))
}

/// The extra columns of decoded points, appended to `columns` (in the
/// order of [`column_names`]) and their coordinates to `points`.
pub(super) fn append(
    file: &PointwiseLaz,
    transform: &[(f64, f64); 3],
    chunk: &[PointwiseRecord],
    points: &mut Vec<Point3>,
    columns: &mut [Vec<f64>],
) {
    let at = |v: i32, k: usize| transform[k].0 * f64::from(v) + transform[k].1;
    points.extend(chunk.iter().map(|r| {
        let p = &r.point;
        Point3::new(at(p.x, 0), at(p.y, 1), at(p.z, 2))
    }));
    let fields: [&(dyn Fn(&PointwiseRecord) -> f64 + Sync); 9] = [
        &|r| f64::from(r.point.intensity),
        &|r| f64::from(r.point.return_number()),
        &|r| f64::from(r.point.number_of_returns()),
        &|r| f64::from(r.point.classification & 0x1f),
        &|r| f64::from(r.point.point_source_id),
        &|r| r.gps_time,
        &|r| f64::from(r.rgb[0]),
        &|r| f64::from(r.rgb[1]),
        &|r| f64::from(r.rgb[2]),
    ];
    let (gps, rgb) = (file.has_gps_time(), file.has_rgb());
    let used = [true, true, true, true, true, gps, rgb, rgb, rgb];
    let mut column = columns.iter_mut();
    for (f, _) in fields.iter().zip(used).filter(|(_, u)| *u) {
        if let Some(col) = column.next() {
            col.extend(chunk.iter().map(f));
        }
    }
}

/// Decodes every chunk of a pointwise LAZ file held in `bytes`.
pub(super) fn read_pointwise(path: &Path, bytes: &[u8], pw: &Pointwise) -> Result<Decoded> {
    let vlr = super::vlr_bytes(bytes, pw.vlr_at, pw.vlr_len);
    let file = open(path, bytes.len() as u64, pw, vlr)?;
    check_format(
        path,
        bytes.get(104).copied().unwrap_or(0) & 0x3f,
        &file,
        pw.vlr_at,
    )?;
    let transform = transforms(path, bytes)?;
    let names = names(&file);
    let mut decoded = decode_in_order(
        path,
        bytes,
        pw.count,
        names,
        file.chunks(),
        |c| file.chunk_bytes(c),
        |c, data, out| file.decode_chunk(c, data, out),
        |chunk, points, columns| append(&file, &transform, chunk, points, columns),
    )?;
    decoded.warnings = unread_chunks(path, pw.table_chunks, file.chunks().len(), pw.count);
    Ok(decoded)
}

/// The header's point format must be the one the LASzip items describe.
pub(super) fn check_format(
    path: &Path,
    format: u8,
    file: &PointwiseLaz,
    vlr_at: u64,
) -> Result<()> {
    let expect = match (file.has_gps_time(), file.has_rgb(), file.has_wave_packet()) {
        (false, false, false) => 0,
        (true, false, false) => 1,
        (false, true, false) => 2,
        (true, true, false) => 3,
        (true, false, true) => 4,
        (true, true, true) => 5,
        _ => 255,
    };
    if format != expect {
        return Err(Error::Binary {
            path: path.to_path_buf(),
            offset: vlr_at,
            message: format!(
                "the header declares point format {format}, but the LASzip VLR describes points of format {}; the file is damaged",
                if expect == 255 { "none of 0-5".to_string() } else { expect.to_string() }
            ),
        });
    }
    Ok(())
}
