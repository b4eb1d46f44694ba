//! LAS 1.4 point formats 6-10 compressed with LASzip's layered compressor,
//! read with scanfit's own decoder ([`crate::laz14`]) instead of the `laz`
//! crate's. Columns and coordinates are the ones the `las` crate gives for
//! the same file (coordinates: scale times the stored integer plus
//! offset, in f64).

use std::path::Path;

use super::{column_names, decode_in_order, vlr_bytes, Decoded, Field, Layered, OwnLaz, Raw};
use crate::laz14::{ChunkSpan, LayeredLaz, Laz14Error, Point14, ReadAt};
use crate::Error;

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
) -> crate::Result<LayeredLaz> {
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

impl OwnLaz for LayeredLaz {
    type Record = Point14;
    fn spans(&self) -> &[ChunkSpan] {
        self.chunks()
    }
    fn span_bytes(&self, c: usize) -> u64 {
        self.chunk_bytes(c)
    }
    fn decode_span(&self, c: usize, data: &[u8], out: &mut Vec<Point14>) -> Result<(), Laz14Error> {
        self.decode_chunk(c, data, out)
    }
    fn names(&self) -> Vec<&'static str> {
        column_names(true, self.has_rgb(), self.has_nir())
    }
    fn xyz(p: &Point14) -> [i32; 3] {
        [p.x, p.y, p.z]
    }
    fn fields(&self) -> Vec<Field<Point14>> {
        let (rgb, nir) = (self.has_rgb(), self.has_nir());
        let fields: [Field<Point14>; 10] = [
            (|p| f64::from(p.intensity), true),
            (|p| f64::from(p.return_number), true),
            (|p| f64::from(p.number_of_returns), true),
            (|p| f64::from(p.classification), true),
            (|p| f64::from(p.point_source_id), true),
            (|p| p.gps_time, true),
            (|p| f64::from(p.rgb[0]), rgb),
            (|p| f64::from(p.rgb[1]), rgb),
            (|p| f64::from(p.rgb[2]), rgb),
            (|p| f64::from(p.nir), nir),
        ];
        fields.to_vec()
    }
}

/// Decodes every chunk of a layered LAZ file held in `bytes`.
pub(super) fn read_layered(
    path: &Path,
    bytes: &[u8],
    raw: &Raw,
    layered: &Layered,
) -> crate::Result<Decoded> {
    let format = bytes.get(104).copied().unwrap_or(0) & 0x3f;
    let vlr = vlr_bytes(bytes, layered.vlr_at, layered.vlr_len);
    let read = |at: u64, n: usize| -> Option<Vec<u8>> {
        let at = usize::try_from(at).ok()?;
        bytes.get(at..at.checked_add(n)?).map(<[u8]>::to_vec)
    };
    let file = open(path, &read, vlr, format, raw, layered)?;
    decode_in_order(path, bytes, &file, layered.count, layered.table_chunks)
}
