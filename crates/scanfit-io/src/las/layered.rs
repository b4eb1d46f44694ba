//! LAS 1.4 point formats 6-10 compressed with LASzip's layered compressor,
//! read with scanfit's own decoder ([`crate::laz14`]) instead of the `laz`
//! crate's. Columns and coordinates are the ones the `las` crate gives for
//! the same file (coordinates: scale times the stored integer plus
//! offset, in f64).

use std::path::Path;

use rayon::prelude::*;
use scanfit::Point3;

use super::{column_names, transforms, vlr_bytes, Decoded, Layered, Raw};
use crate::laz14::{LayeredLaz, Laz14Error, Point14};
use crate::table::capacity;
use crate::{Error, Result};

/// Decodes every chunk of a layered LAZ file.
pub(super) fn read_layered(
    path: &Path,
    bytes: &[u8],
    raw: &Raw,
    layered: &Layered,
) -> Result<Decoded> {
    let binary = |e: Laz14Error| Error::Binary {
        path: path.to_path_buf(),
        offset: e.offset,
        message: e.message,
    };
    let format = bytes.get(104).copied().unwrap_or(0) & 0x3f;
    let vlr = vlr_bytes(bytes, layered.vlr_at, layered.vlr_len);
    let file = LayeredLaz::new(
        bytes,
        vlr,
        layered.vlr_at,
        raw.offset_to_points,
        layered.data_end,
        layered.count,
        layered.table_counts.as_deref(),
    )
    .map_err(binary)?;
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
    let transform = transforms(path, bytes)?;
    let names = column_names(true, rgb, nir);
    let cap = capacity(layered.count, bytes.len()).min(1 << 24);
    let mut points = Vec::with_capacity(cap);
    let mut columns = vec![Vec::with_capacity(cap); names.len()];
    let at = |v: i32, k: usize| transform[k].0 * f64::from(v) + transform[k].1;
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
    let used = [true, true, true, true, true, true, rgb, rgb, rgb, nir];
    // chunks are independent: decode a few per thread at a time, append in
    // file order (the first damaged chunk in file order is the error)
    let group = 2 * rayon::current_num_threads().max(1);
    let count = file.chunks().len();
    for first in (0..count).step_by(group) {
        let decoded: Vec<_> = (first..(first + group).min(count))
            .into_par_iter()
            .map(|c| {
                let mut chunk = Vec::new();
                file.decode_chunk(c, &mut chunk).map(|()| chunk)
            })
            .collect();
        for chunk in decoded {
            let chunk = chunk.map_err(binary)?;
            points.extend(
                chunk
                    .iter()
                    .map(|p| Point3::new(at(p.x, 0), at(p.y, 1), at(p.z, 2))),
            );
            let mut column = columns.iter_mut();
            for (f, _) in fields.iter().zip(used).filter(|(_, u)| *u) {
                if let Some(col) = column.next() {
                    col.extend(chunk.iter().map(f));
                }
            }
        }
    }
    Ok(Decoded {
        points,
        names,
        columns,
        declared: layered.count,
    })
}
