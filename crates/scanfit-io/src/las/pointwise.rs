//! LAS point formats 0-5 compressed with LASzip's pointwise compressor
//! (items of version 2), read with scanfit's own decoder
//! ([`crate::laz14::PointwiseLaz`]) instead of the `laz` crate's, whose
//! GPS-time decoder recurses without bound on damaged data. Columns and
//! coordinates are the ones the `las` crate gives for the same file.

use std::path::Path;

use super::layered::binary;
use super::{column_names, decode_in_order, Decoded, Field, OwnLaz, Pointwise};
use crate::laz14::{ChunkSpan, Laz14Error, PointwiseLaz, PointwiseRecord};
use crate::{Error, Result};

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

impl OwnLaz for PointwiseLaz {
    type Record = PointwiseRecord;
    fn spans(&self) -> &[ChunkSpan] {
        self.chunks()
    }
    fn span_bytes(&self, c: usize) -> u64 {
        self.chunk_bytes(c)
    }
    fn decode_span(
        &self,
        c: usize,
        data: &[u8],
        out: &mut Vec<PointwiseRecord>,
    ) -> std::result::Result<(), Laz14Error> {
        self.decode_chunk(c, data, out)
    }
    fn names(&self) -> Vec<&'static str> {
        column_names(self.has_gps_time(), self.has_rgb(), false)
    }
    fn xyz(r: &PointwiseRecord) -> [i32; 3] {
        [r.point.x, r.point.y, r.point.z]
    }
    fn fields(&self) -> Vec<Field<PointwiseRecord>> {
        let (gps, rgb) = (self.has_gps_time(), self.has_rgb());
        let fields: [Field<PointwiseRecord>; 9] = [
            (|r| f64::from(r.point.intensity), true),
            (|r| f64::from(r.point.return_number()), true),
            (|r| f64::from(r.point.number_of_returns()), true),
            (|r| f64::from(r.point.classification & 0x1f), true),
            (|r| f64::from(r.point.point_source_id), true),
            (|r| r.gps_time, gps),
            (|r| f64::from(r.rgb[0]), rgb),
            (|r| f64::from(r.rgb[1]), rgb),
            (|r| f64::from(r.rgb[2]), rgb),
        ];
        fields.to_vec()
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
    decode_in_order(path, bytes, &file, pw.count, pw.table_chunks)
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
