//! LAS 1.4 point formats 6-10 compressed with LASzip's layered compressor,
//! read with scanfit's own decoder ([`crate::laz14`]) instead of the `laz`
//! crate's. Columns and coordinates are the ones the `las` crate gives for
//! the same file (coordinates: scale times the stored integer plus
//! offset, in f64).

use std::path::Path;

use scanfit::Point3;

use super::{
    column_names, decode_in_order, transforms, unread_chunks, vlr_bytes, Decoded, Layered, Raw,
};
use crate::laz14::{LayeredLaz, Laz14Error, Point14, ReadAt};
use crate::{Error, Result};

pub(super) fn binary(path: &Path, e: Laz14Error) -> Error {
    Error::Binary {
        path: path.to_path_buf(),
        offset: e.offset,
        message: e.message,
    }
}

/// The file's chunks walked and checked, and its point format (`format`,
/// from the header) checked against the LASzip items.
pub(super) fn open(
    path: &Path,
    read: ReadAt<'_>,
    vlr: &[u8],
    format: u8,
    raw: &Raw,
    layered: &Layered,
) -> Result<LayeredLaz> {
    let file = LayeredLaz::new(
        read,
        vlr,
        layered.vlr_at,
        raw.offset_to_points,
        layered.data_end,
        layered.count,
        layered.table_counts.as_deref(),
    )
    .map_err(|e| binary(path, e))?;
    let (rgb, nir) = (matches!(format, 7 | 8 | 10), matches!(format, 8 | 10));
    if !(6..=10).contains(&format) || file.has_rgb() != rgb || file.has_nir() != nir {
        return Err(Error::Binary {
            path: path.to_path_buf(),
            offset: layered.vlr_at,
            message: format!(
                "the header declares point format {format}, but the LASzip VLR describes LAS 1.4 points {} RGB and {} NIR; the file is damaged",
                if file.has_rgb() { "with" } else { "without" },
                if file.has_nir() { "with" } else { "without" }
            ),
        });
    }
    Ok(file)
}

/// The columns of a layered file's points (see [`column_names`]).
pub(super) fn names(file: &LayeredLaz) -> Vec<&'static str> {
    column_names(true, file.has_rgb(), file.has_nir())
}

/// Appends decoded points: coordinates to `points`, the columns of
/// [`names`] to `columns`.
pub(super) fn append(
    file: &LayeredLaz,
    transform: &[(f64, f64); 3],
    chunk: &[Point14],
    points: &mut Vec<Point3>,
    columns: &mut [Vec<f64>],
) {
    let at = |v: i32, k: usize| transform[k].0 * f64::from(v) + transform[k].1;
    points.extend(
        chunk
            .iter()
            .map(|p| Point3::new(at(p.x, 0), at(p.y, 1), at(p.z, 2))),
    );
    let fields: [&(dyn Fn(&Point14) -> f64 + Sync); 10] = [
        &|p| f64::from(p.intensity),
        &|p| f64::from(p.return_number),
        &|p| f64::from(p.number_of_returns),
        &|p| f64::from(p.classification),
        &|p| f64::from(p.point_source_id),
        &|p| p.gps_time,
        &|p| f64::from(p.rgb[0]),
        &|p| f64::from(p.rgb[1]),
        &|p| f64::from(p.rgb[2]),
        &|p| f64::from(p.nir),
    ];
    let (rgb, nir) = (file.has_rgb(), file.has_nir());
    let used = [true, true, true, true, true, true, rgb, rgb, rgb, nir];
    let mut column = columns.iter_mut();
    for (f, _) in fields.iter().zip(used).filter(|(_, u)| *u) {
        if let Some(col) = column.next() {
            col.extend(chunk.iter().map(f));
        }
    }
}

/// Decodes every chunk of a layered LAZ file held in `bytes`.
pub(super) fn read_layered(
    path: &Path,
    bytes: &[u8],
    raw: &Raw,
    layered: &Layered,
) -> Result<Decoded> {
    let format = bytes.get(104).copied().unwrap_or(0) & 0x3f;
    let vlr = vlr_bytes(bytes, layered.vlr_at, layered.vlr_len);
    let read = |at: u64, n: usize| -> Option<Vec<u8>> {
        let at = usize::try_from(at).ok()?;
        bytes.get(at..at.checked_add(n)?).map(<[u8]>::to_vec)
    };
    let file = open(path, &read, vlr, format, raw, layered)?;
    let transform = transforms(path, bytes)?;
    let names = names(&file);
    let mut decoded = decode_in_order(
        path,
        bytes,
        layered.count,
        names,
        file.chunks(),
        |c| file.chunk_bytes(c),
        |c, data, out| file.decode_chunk(c, data, out),
        |chunk, points, columns| append(&file, &transform, chunk, points, columns),
    )?;
    decoded.warnings = unread_chunks(
        path,
        layered.table_chunks,
        file.chunks().len(),
        layered.count,
    );
    Ok(decoded)
}
