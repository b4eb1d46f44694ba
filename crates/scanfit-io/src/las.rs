//! LAS and LAZ reader, through the `las` crate (with its `laz` feature).
//!
//! Coordinates come out in the file's georeferenced frame (raw integer times
//! scale plus offset, as the crate computes them in f64). Kept per point:
//! intensity, return_number, number_of_returns, classification,
//! point_source_id, and when the point format has them gps_time, red, green,
//! blue and nir.
//!
//! Before the crate sees a file, the sizes that would make it allocate
//! (the extended VLR's length, the LAZ chunk count, the point count) are
//! checked against the file's size here; points are then read in batches so
//! memory grows with the data actually present.

use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::Mutex;

use scanfit::Point3;

use crate::table::{capacity, Format, Origin, PointTable, ReadOptions};
use crate::{Error, Result};

mod layered;
mod pointwise;
mod stream;
mod view;
use layered::read_layered;
use pointwise::read_pointwise;
pub(crate) use stream::LasChunks;
use view::{u16_at, u32_at, u64_at, u8_at, View, ViewReader};

/// Points decoded per call into the crate (fewer for long records: see
/// [`BATCH_BYTES`]).
const BATCH: u64 = 1 << 18;

/// Most bytes of decoded records per call into the crate.
const BATCH_BYTES: u64 = 16 << 20;

/// The LASzip VLR's payload (empty when it is not all in `bytes`).
fn vlr_bytes(bytes: &[u8], at: u64, len: u64) -> &[u8] {
    usize::try_from(at)
        .ok()
        .and_then(|at| bytes.get(at..at.checked_add(usize::try_from(len).ok()?)?))
        .unwrap_or(&[])
}

/// The header's (scale, offset) per axis.
fn transforms(path: &Path, bytes: &(impl View + ?Sized)) -> Result<[(f64, f64); 3]> {
    let mut transform = [(0.0, 0.0); 3];
    for (k, t) in transform.iter_mut().enumerate() {
        let (Some(scale), Some(offset)) = (u64_at(bytes, 131 + 8 * k), u64_at(bytes, 155 + 8 * k))
        else {
            return Err(Error::Invalid {
                path: path.to_path_buf(),
                message: "the file ends inside the LAS header's scale factors and offsets; it is truncated".into(),
            });
        };
        *t = (f64::from_bits(scale), f64::from_bits(offset));
    }
    Ok(transform)
}

/// What the raw header says, as far as the size checks need it.
struct Raw {
    offset_to_points: u64,
    compressed: bool,
    record_len: u64,
    /// where the point records end: the first EVLR, else the file's end
    data_end: u64,
    /// the 1.4 header's 64-bit count, when it and the legacy count disagree
    count_mismatch: Option<(u64, u64)>,
}

/// LAZ item types of the layered (point formats 6-10) compressor with the
/// size of their raw first point and their number of layers; `None` for a
/// type the layered compressor does not use.
fn layered_item(item_type: u16, size: u16) -> Option<(u64, u64)> {
    match item_type {
        10 => Some((30, 9)),
        11 => Some((6, 1)),
        12 => Some((8, 2)),
        13 => Some((29, 1)),
        14 => Some((u64::from(size), u64::from(size))),
        _ => None,
    }
}

/// Checks the raw header's sizes against the file before the crate reads
/// it, mirroring what the crate reads: the EVLR fields whenever the version
/// is 1.4 (whatever the header size says), the first EVLR's 64-bit length,
/// the point count against the bytes, and the scale factors.
fn precheck(path: &Path, bytes: &(impl View + ?Sized)) -> Result<Raw> {
    let invalid = |message: String| Error::Invalid {
        path: path.to_path_buf(),
        message,
    };
    let binary = |offset: u64, message: String| Error::Binary {
        path: path.to_path_buf(),
        offset,
        message,
    };
    if bytes.read(0, 4).as_deref() != Some(b"LASF") {
        return Err(invalid(
            "not a LAS/LAZ file: it does not start with 'LASF' (bad magic)".into(),
        ));
    }
    let len = bytes.size();
    let (
        Some(major),
        Some(minor),
        Some(header_size),
        Some(offset),
        Some(format),
        Some(record_len),
        Some(legacy_count),
    ) = (
        u8_at(bytes, 24),
        u8_at(bytes, 25),
        u16_at(bytes, 94),
        u32_at(bytes, 96),
        u8_at(bytes, 104),
        u16_at(bytes, 105),
        u32_at(bytes, 107),
    )
    else {
        return Err(invalid(format!(
            "the file ends inside the LAS header ({len} bytes); it is truncated"
        )));
    };
    if u64::from(header_size) > len || u64::from(offset) > len {
        return Err(invalid(format!(
            "the header declares {header_size} header bytes and point data at byte {offset}, but the file has {len} bytes; it is truncated"
        )));
    }
    // the scale factors multiply every integer coordinate: 0 collapses the
    // cloud onto the offset, a negative one mirrors it, NaN poisons it
    for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
        if let Some(scale) = u64_at(bytes, 131 + 8 * k).map(f64::from_bits) {
            if !(scale.is_finite() && scale > 0.0) {
                return Err(binary(
                    131 + 8 * k as u64,
                    format!(
                        "the {axis} scale factor is {scale}; a LAS scale factor must be a positive finite number (typically 0.01 or 0.001); the header is damaged"
                    ),
                ));
            }
        }
    }
    let v14 = major == 1 && minor == 4;
    let mut data_end = len;
    let mut count = u64::from(legacy_count);
    let mut count_mismatch = None;
    if v14 {
        // the crate reads these fields for every 1.4 file, whatever
        // header_size says: check them the same way
        if let (Some(start), Some(evlrs)) = (u64_at(bytes, 235), u32_at(bytes, 243)) {
            if start > 0 && evlrs > 0 {
                let length = start
                    .checked_add(20)
                    .and_then(|at| usize::try_from(at).ok())
                    .and_then(|at| u64_at(bytes, at));
                let fits = length.is_some_and(|l| {
                    start
                        .checked_add(60)
                        .and_then(|s| s.checked_add(l))
                        .is_some_and(|end| end <= len)
                });
                if !fits {
                    return Err(binary(start, format!(
                        "the extended VLR declared here{} does not fit in the file's {len} bytes; the file is truncated or its header is damaged",
                        length.map_or(String::new(), |l| format!(" ({l} bytes)"))
                    )));
                }
                data_end = data_end.min(start);
            }
        }
        if let Some(large) = u64_at(bytes, 247) {
            if legacy_count == 0 {
                count = large;
            } else if large != u64::from(legacy_count) {
                count_mismatch = Some((u64::from(legacy_count), large));
            }
        }
    }
    let compressed = format & 0xc0 != 0;
    let end_of_points = u64::from(record_len)
        .checked_mul(count)
        .and_then(|b| b.checked_add(u64::from(offset)));
    if end_of_points.is_none() {
        return Err(invalid(format!(
            "the header declares {count} point records of {record_len} bytes, more than any file can hold; the header is damaged"
        )));
    }
    Ok(Raw {
        offset_to_points: u64::from(offset),
        compressed,
        record_len: u64::from(record_len),
        data_end,
        count_mismatch,
    })
}

/// The LAZ checks the decoder does not make: the LASzip VLR's items
/// against the point record, the chunk table's size against the file, and
/// (layered compressor, point formats 6-10) every chunk's layer sizes
/// against the bytes left, walking the chunks the way the decoder will.
/// Without them a few-kilobyte file can make the decoder allocate
/// gigabytes (it sizes buffers from these fields before reading).
///
/// Returns which decoder reads the points: scanfit's own for the layered
/// compressor ([`Layered`]) and for pointwise items of version 2
/// ([`Pointwise`]), the `laz` crate for pointwise items of version 1.
fn laz_check(path: &Path, bytes: &(impl View + ?Sized), raw: &Raw) -> Result<Compressed> {
    let binary = |offset: u64, message: String| Error::Binary {
        path: path.to_path_buf(),
        offset,
        message,
    };
    let len = bytes.size();
    let header_size = u64::from(u16_at(bytes, 94).unwrap_or(0));
    let vlrs = u32_at(bytes, 100).unwrap_or(0);
    let count = {
        let legacy = u64::from(u32_at(bytes, 107).unwrap_or(0));
        match (bytes.read(24, 2).as_deref(), u64_at(bytes, 247)) {
            (Some([1, 4]), Some(large)) if legacy == 0 => large,
            _ => legacy,
        }
    };
    // find the LASzip VLR (user id "laszip encoded", record 22204)
    let mut at = header_size;
    let mut laz = None;
    for _ in 0..vlrs {
        let Some(start) = usize::try_from(at).ok() else {
            break;
        };
        let (Some(user), Some(record), Some(length)) = (
            bytes.read(start as u64 + 2, 16),
            u16_at(bytes, start + 18),
            u16_at(bytes, start + 20),
        ) else {
            break;
        };
        let data = at + 54;
        if user.starts_with(b"laszip encoded") && record == 22204 {
            laz = Some((data, u64::from(length)));
            break;
        }
        at = data + u64::from(length);
    }
    let Some((vlr_at, vlr_len)) = laz else {
        // refused here: the crate may look for VLRs elsewhere (a header
        // size below the version's makes it read them after the full
        // header) and then trust a chunk table this walk never checked
        return Err(binary(header_size, format!(
            "the point format is compressed (LAZ), but none of the {vlrs} VLRs that follow the {header_size}-byte header is the LASzip VLR; the file is damaged"
        )));
    };
    let Some(vlr_payload) = bytes.read(vlr_at, vlr_len as usize) else {
        return Err(binary(vlr_at, format!(
            "the LASzip VLR declares {vlr_len} bytes, but the file ends before them; it is truncated"
        )));
    };
    let vlr: &[u8] = &vlr_payload;
    let compressor = u16_at(vlr, 0).unwrap_or(0);
    let chunk_size = u32_at(vlr, 12).unwrap_or(0);
    let items = u16_at(vlr, 32).unwrap_or(0);
    let mut items_size = 0u64;
    let mut first_point = 0u64;
    let mut layers = 0u64;
    let mut layered_ok = true;
    let mut version2 = false;
    for k in 0..usize::from(items) {
        version2 |= u16_at(vlr, 38 + 6 * k) == Some(2);
        let (Some(ty), Some(size)) = (u16_at(vlr, 34 + 6 * k), u16_at(vlr, 36 + 6 * k)) else {
            return Err(binary(vlr_at, format!(
                "the LASzip VLR declares {items} items, but its {vlr_len} bytes hold fewer; the file is damaged"
            )));
        };
        items_size += u64::from(size);
        match layered_item(ty, size) {
            Some((raw_size, n)) => {
                first_point += raw_size;
                layers += n;
            }
            None => layered_ok = false,
        }
    }
    if items_size != raw.record_len {
        return Err(binary(vlr_at, format!(
            "the LASzip items describe {items_size}-byte points, but the header's point records have {} bytes; the file is damaged",
            raw.record_len
        )));
    }
    // (even with no points: the decoder reads the chunk table when it is
    // built)
    let start = raw.offset_to_points;
    // the chunk table: its offset is the first 8 bytes of the point data
    // (or, when that is not past them, the last 8 bytes of the file)
    // (compressor 1 has no chunk table: its point data starts at once)
    let table = usize::try_from(start)
        .ok()
        .filter(|_| compressor != 1)
        .and_then(|s| u64_at(bytes, s))
        .and_then(|o| {
            if (o as i64) > start as i64 {
                Some(o)
            } else {
                (bytes.size() as usize)
                    .checked_sub(8)
                    .and_then(|k| u64_at(bytes, k))
                    .filter(|&o| (o as i64) > start as i64)
            }
        });
    let mut table_chunks = None;
    let data_end = match table {
        Some(t) if t < len => {
            // every chunk starts with one raw point: a table with more
            // entries than the data between could hold is a damaged file
            let chunks = usize::try_from(t)
                .ok()
                .and_then(|t| u32_at(bytes, t + 4))
                .unwrap_or(0);
            let room = t.saturating_sub(start + 8) / items_size.max(1);
            if u64::from(chunks) > room {
                return Err(binary(t, format!(
                    "the LAZ chunk table declares {chunks} chunks, but the {} bytes of point data hold at most {room}; the file is damaged",
                    t.saturating_sub(start + 8)
                )));
            }
            table_chunks = Some(u64::from(chunks));
            t
        }
        _ => raw.data_end,
    };
    // the decoder picks the layered record decompressor by the first item's
    // version (3 or 4), whatever the compressor field says: a pointwise
    // compressor with layered items would skip the layer-size walk below
    let layered_items = matches!(u16_at(vlr, 38), Some(3 | 4));
    if layered_items != (compressor == 3) {
        return Err(binary(vlr_at, format!(
            "the LASzip VLR declares compressor {compressor} with items of version {}; layered items (version 3 or 4) go with the layered compressor 3 only, so the file is damaged",
            u16_at(vlr, 38).unwrap_or(0)
        )));
    }
    // LAZ cannot compress a record below a few bits: a count beyond this is
    // a damaged header, not data (both decoders produce points from almost
    // no bytes on damaged data, so this bounds their output)
    if count / 64 > len {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the header declares {count} points, more than {len} compressed bytes can hold; the file is damaged"
            ),
        });
    }
    if compressor != 3 {
        if !version2 {
            return Ok(Compressed::Crate);
        }
        // the chunk table's point and byte counts (its size was checked
        // above; the crate's table reader runs on the checked bytes)
        let table = if compressor == 2 {
            let lazvlr = laz::LazVlr::from_buffer(vlr)
                .map_err(|e| binary(vlr_at, format!("the LASzip VLR is damaged: {e}")))?;
            quietly(|| {
                let mut cursor = std::io::BufReader::new(ViewReader {
                    view: bytes,
                    pos: start,
                });
                laz::laszip::ChunkTable::read_from(&mut cursor, &lazvlr)
                    .ok()
                    .map(|t| {
                        (0..t.len())
                            .map(|k| (t[k].point_count, t[k].byte_count))
                            .collect()
                    })
            })
            .flatten()
        } else {
            None
        };
        return Ok(Compressed::Pointwise(Pointwise {
            vlr_at,
            vlr_len,
            start,
            count,
            data_end,
            table,
            table_chunks,
        }));
    }
    if !layered_ok {
        return Err(binary(vlr_at, "the LASzip VLR uses the layered compressor with an item type it does not allow; the file is damaged".into()));
    }
    // the point counts of variable-size chunks come from the chunk table
    let table_counts: Option<Vec<u64>> = if chunk_size == u32::MAX {
        let lazvlr = laz::LazVlr::from_buffer(vlr)
            .map_err(|e| binary(vlr_at, format!("the LASzip VLR is damaged: {e}")))?;
        let mut cursor = std::io::BufReader::new(ViewReader {
            view: bytes,
            pos: start,
        });
        laz::laszip::ChunkTable::read_from(&mut cursor, &lazvlr)
            .ok()
            .map(|t| (0..t.len()).map(|k| t[k].point_count).collect())
    } else {
        None
    };
    // walk the chunks as the decoder reads them: a raw first point, the
    // point count, one 32-bit size per layer, then the layers
    let mut pos = start + 8;
    let mut left = count;
    let mut chunk = 0usize;
    while left > 0 {
        let head = first_point + 4 + 4 * layers;
        let Some(p) = usize::try_from(pos)
            .ok()
            .filter(|_| pos.saturating_add(head) <= data_end)
        else {
            return Err(binary(pos, format!(
                "the header declares {count} points, but the compressed data ends after {} of them (chunk {chunk}); the file is truncated",
                count - left
            )));
        };
        let in_chunk = u64::from(u32_at(bytes, p + first_point as usize).unwrap_or(0));
        let mut sizes = 0u64;
        for l in 0..layers as usize {
            sizes += u64::from(u32_at(bytes, p + (first_point + 4) as usize + 4 * l).unwrap_or(0));
        }
        let room = data_end - pos - head;
        if sizes > room {
            return Err(binary(pos, format!(
                "LAZ chunk {chunk} declares {sizes} bytes of layers, but only {room} bytes of point data follow; the file is damaged"
            )));
        }
        let points = match &table_counts {
            Some(t) => match t.get(chunk) {
                Some(&c) => c,
                None => {
                    return Err(binary(pos, format!(
                        "the LAZ chunk table lists {} chunks, but the header's {count} points need more; the file is damaged",
                        t.len()
                    )))
                }
            },
            None if chunk_size == u32::MAX => in_chunk,
            None => u64::from(chunk_size),
        };
        left = left.saturating_sub(points);
        pos += head + sizes;
        chunk += 1;
    }
    Ok(Compressed::Layered(Layered {
        vlr_at,
        vlr_len,
        count,
        data_end,
        table_counts,
        table_chunks,
    }))
}

/// Which decoder reads a compressed file's points ([`laz_check`]).
enum Compressed {
    /// pointwise items of version 1: the `laz` crate
    Crate,
    /// pointwise items of version 2: [`crate::laz14::PointwiseLaz`]
    Pointwise(Pointwise),
    /// the layered compressor: [`crate::laz14::LayeredLaz`]
    Layered(Layered),
}

/// A pointwise LAZ file (point formats 0-5, items of version 2) as
/// [`laz_check`] found it.
struct Pointwise {
    vlr_at: u64,
    vlr_len: u64,
    /// the point data's offset
    start: u64,
    count: u64,
    /// where the chunks end: the chunk table, the first EVLR or the file's end
    data_end: u64,
    /// the chunk table as (points, bytes) per chunk (compressor 2)
    table: Option<Vec<(u64, u64)>>,
    /// the number of chunks the chunk table lists
    table_chunks: Option<u64>,
}

/// A layered LAZ file (point formats 6-10) as [`laz_check`] found it.
struct Layered {
    vlr_at: u64,
    vlr_len: u64,
    count: u64,
    /// where the chunks end: the chunk table, the first EVLR or the file's end
    data_end: u64,
    /// the chunk table's point counts (variable-size chunks only)
    table_counts: Option<Vec<u64>>,
    /// the number of chunks the chunk table lists
    table_chunks: Option<u64>,
}

/// The warning of a LAZ file whose chunk table lists more chunks than the
/// header's point count needs (`used`): their points are not read.
fn unread_chunks(path: &Path, table_chunks: Option<u64>, used: usize, count: u64) -> Vec<String> {
    match table_chunks {
        Some(listed) if listed > used as u64 => vec![format!(
            "{}: the LAZ chunk table lists {listed} chunks, but the header's {count} points fill only {used}; the points of the other {} were not read (the header's point count may be too small)",
            path.display(),
            listed - used as u64
        )],
        _ => Vec::new(),
    }
}

/// Runs `f`, turning a panic into `None` without the panic message on
/// stderr: the panic hook is swapped for a silent one around the call (a
/// counter under a lock keeps concurrent callers from losing the hook) and
/// restored afterwards.
fn quietly<T>(f: impl FnOnce() -> T) -> Option<T> {
    type Hook = Box<dyn Fn(&std::panic::PanicHookInfo<'_>) + Sync + Send + 'static>;
    static SAVED: Mutex<(usize, Option<Hook>)> = Mutex::new((0, None));
    let lock = || SAVED.lock().unwrap_or_else(|e| e.into_inner());
    {
        let mut saved = lock();
        if saved.0 == 0 {
            saved.1 = Some(std::panic::take_hook());
            std::panic::set_hook(Box::new(|_| {}));
        }
        saved.0 += 1;
    }
    let result = catch_unwind(AssertUnwindSafe(f)).ok();
    let mut saved = lock();
    saved.0 -= 1;
    if saved.0 == 0 {
        if let Some(hook) = saved.1.take() {
            std::panic::set_hook(hook);
        }
    }
    result
}

/// The extra columns of a point format: the fields every format has, then
/// GPS time, colour and NIR when it has them.
fn column_names(gps_time: bool, color: bool, nir: bool) -> Vec<&'static str> {
    let mut names = vec![
        "intensity",
        "return_number",
        "number_of_returns",
        "classification",
        "point_source_id",
    ];
    if gps_time {
        names.push("gps_time");
    }
    if color {
        names.extend(["red", "green", "blue"]);
    }
    if nir {
        names.push("nir");
    }
    names
}

/// A column value of a decoded record, and whether a file's records have
/// it.
type Field<R> = (fn(&R) -> f64, bool);

/// A LAZ file read by scanfit's own decoders ([`crate::laz14`], pointwise
/// or layered): its chunks, how one is decoded, and the columns its
/// records give.
trait OwnLaz: Sync {
    /// A decoded point.
    type Record: Send;
    /// The chunks, in file order.
    fn spans(&self) -> &[crate::laz14::ChunkSpan];
    /// The size in bytes of chunk `c`.
    fn span_bytes(&self, c: usize) -> u64;
    /// Decodes chunk `c` from its bytes `data`, appending to `out`.
    fn decode_span(
        &self,
        c: usize,
        data: &[u8],
        out: &mut Vec<Self::Record>,
    ) -> std::result::Result<(), crate::laz14::Laz14Error>;
    /// The extra columns of its points (see [`column_names`]).
    fn names(&self) -> Vec<&'static str>;
    /// The record's stored coordinates.
    fn xyz(record: &Self::Record) -> [i32; 3];
    /// Every column value a record of this kind can give, in the order of
    /// [`column_names`], with whether this file's records have it.
    fn fields(&self) -> Vec<Field<Self::Record>>;

    /// Appends decoded records: coordinates (scale times the stored
    /// integer plus offset, per axis of `transform`) to `points`, and the
    /// values of [`OwnLaz::names`] to `columns`.
    fn append(
        &self,
        transform: &[(f64, f64); 3],
        chunk: &[Self::Record],
        points: &mut Vec<Point3>,
        columns: &mut [Vec<f64>],
    ) {
        let at = |v: i32, k: usize| transform[k].0 * f64::from(v) + transform[k].1;
        points.extend(chunk.iter().map(|r| {
            let [x, y, z] = Self::xyz(r);
            Point3::new(at(x, 0), at(y, 1), at(z, 2))
        }));
        let mut column = columns.iter_mut();
        for (f, _) in self.fields().into_iter().filter(|(_, used)| *used) {
            if let Some(col) = column.next() {
                col.extend(chunk.iter().map(f));
            }
        }
    }
}

/// Decodes every chunk of `file`, a LAZ file held in `bytes` with
/// `declared` points (`table_chunks`: the chunks its chunk table lists),
/// a few chunks per thread at a time (chunks are independent), and
/// appends each chunk's points in file order; the first damaged chunk in
/// file order is the error.
fn decode_in_order<F: OwnLaz>(
    path: &Path,
    bytes: &[u8],
    file: &F,
    declared: u64,
    table_chunks: Option<u64>,
) -> Result<Decoded> {
    use rayon::prelude::*;
    let transform = transforms(path, bytes)?;
    let names = file.names();
    let cap = capacity(declared, bytes.len()).min(1 << 24);
    let mut points = Vec::with_capacity(cap);
    let mut columns = vec![Vec::with_capacity(cap); names.len()];
    let group = 2 * rayon::current_num_threads().max(1);
    let spans = file.spans();
    let count = spans.len();
    for first in (0..count).step_by(group) {
        let decoded: Vec<_> = (first..(first + group).min(count))
            .into_par_iter()
            .map(|c| {
                let at = spans[c].offset as usize;
                let data = bytes
                    .get(at..at.saturating_add(file.span_bytes(c) as usize))
                    .unwrap_or(&[]);
                let mut chunk = Vec::new();
                file.decode_span(c, data, &mut chunk).map(|()| chunk)
            })
            .collect();
        for chunk in decoded {
            let chunk = chunk.map_err(|e| layered::binary(path, e))?;
            file.append(&transform, &chunk, &mut points, &mut columns);
        }
    }
    Ok(Decoded {
        points,
        names,
        columns,
        declared,
        warnings: unread_chunks(path, table_chunks, count, declared),
    })
}

/// Columns read from the crate.
#[derive(Default)]
struct Decoded {
    points: Vec<Point3>,
    names: Vec<&'static str>,
    columns: Vec<Vec<f64>>,
    declared: u64,
    /// the decoder's warnings (after the header's)
    warnings: Vec<String>,
}

/// A `las` crate reader past its header, with the declared count checked
/// against the bytes present (uncompressed records), the columns it gives
/// and a point buffer for it.
struct CrateReader {
    reader: las::Reader,
    pd: las::PointData,
    names: Vec<&'static str>,
    declared: u64,
    record: u64,
}

fn crate_error(path: &Path) -> impl Fn(las::Error) -> Error + '_ {
    move |e| Error::Invalid {
        path: path.to_path_buf(),
        message: format!("cannot read the LAS/LAZ data: {e}"),
    }
}

impl CrateReader {
    /// Reads the header of `source` (a file of `total` bytes).
    fn new<R>(path: &Path, source: R, total: u64, raw: &Raw) -> Result<Self>
    where
        R: std::io::Read + std::io::Seek + Send + Sync + std::fmt::Debug + 'static,
    {
        let reader = las::Reader::new(source).map_err(crate_error(path))?;
        let header = reader.header().clone();
        let n = header.number_of_points();
        let fmt = *header.point_format();
        let record = u64::from(fmt.len()).max(1);
        let avail = total.saturating_sub(raw.offset_to_points);
        if !raw.compressed && (n as u128) * (record as u128) > avail as u128 {
            return Err(Error::Binary {
                path: path.to_path_buf(),
                offset: raw.offset_to_points,
                message: format!(
                    "the header declares {n} point records of {record} bytes, but only {avail} bytes follow: {} complete records; the file is truncated or its point count is wrong",
                    avail / record
                ),
            });
        }
        Ok(Self {
            pd: las::PointDataBuilder::new().for_header(&header).build(),
            reader,
            names: column_names(fmt.has_gps_time, fmt.has_color, fmt.has_nir),
            declared: n,
            record,
        })
    }

    /// Reads at most `batch` points and appends their coordinates and
    /// columns (in the order of `names`); returns how many were read.
    fn fill(
        &mut self,
        path: &Path,
        batch: u64,
        points: &mut Vec<Point3>,
        columns: &mut [Vec<f64>],
    ) -> Result<u64> {
        let got = self
            .reader
            .fill_points(batch, &mut self.pd)
            .map_err(crate_error(path))?;
        let pd = &self.pd;
        points.extend(
            pd.x()
                .zip(pd.y())
                .zip(pd.z())
                .map(|((x, y), z)| Point3::new(x, y, z)),
        );
        let mut cols = columns.iter_mut();
        let mut push = |values: &mut dyn Iterator<Item = f64>| {
            if let Some(c) = cols.next() {
                c.extend(values);
            }
        };
        push(&mut pd.intensity().map(f64::from));
        push(&mut pd.return_number().map(f64::from));
        push(&mut pd.number_of_returns().map(f64::from));
        push(&mut pd.classification().map(f64::from));
        push(&mut pd.point_source_id().map(f64::from));
        if let Some(g) = pd.gps_time() {
            push(&mut g.into_iter());
        }
        if let Some(rgb) = pd.rgb() {
            let rgb: Vec<(u16, u16, u16)> = rgb.collect();
            push(&mut rgb.iter().map(|c| f64::from(c.0)));
            push(&mut rgb.iter().map(|c| f64::from(c.1)));
            push(&mut rgb.iter().map(|c| f64::from(c.2)));
        }
        if let Some(nir) = pd.nir() {
            push(&mut nir.map(f64::from));
        }
        Ok(got)
    }
}

/// Everything that calls into the `las` crate. It runs inside
/// `catch_unwind` (see `parse`): the crate is third-party code, and a panic
/// on a damaged file must become an error, not a crash.
fn read_with_crate(path: &Path, bytes: Vec<u8>, raw: &Raw) -> Result<Decoded> {
    let total = bytes.len() as u64;
    let mut r = CrateReader::new(path, Cursor::new(bytes), total, raw)?;
    let (n, record) = (r.declared, r.record);
    let avail = total.saturating_sub(raw.offset_to_points);
    let cap = capacity(n, (avail / record) as usize).min(1 << 24);
    let mut points = Vec::with_capacity(cap);
    let mut columns = vec![Vec::with_capacity(cap); r.names.len()];
    let batch = (BATCH_BYTES / record).clamp(1, BATCH);
    let mut read = 0u64;
    while read < n {
        let got = r.fill(path, batch, &mut points, &mut columns)?;
        if got == 0 {
            break;
        }
        read += got;
    }
    Ok(Decoded {
        points,
        names: r.names,
        columns,
        declared: n,
        warnings: Vec::new(),
    })
}

/// The error of a panic caught in the `las` crate.
fn crate_failed(path: &Path) -> Error {
    Error::Invalid {
        path: path.to_path_buf(),
        message: "the LAS/LAZ decoder failed on this file (it is damaged, or uses a variant the las crate does not handle)".into(),
    }
}

/// The header's warnings: a LAS 1.4 count that disagrees with the legacy
/// count, and (uncompressed) whole records after the `n` read.
fn header_warnings(path: &Path, raw: &Raw, n: u64) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some((legacy, large)) = raw.count_mismatch {
        warnings.push(format!(
            "{}: the LAS 1.4 header's point count is {large}, but its legacy count is {legacy}; the {legacy} points of the legacy count were read, as the LAS 1.4 specification asks (repair the header)",
            path.display()
        ));
    }
    if !raw.compressed {
        let used = raw.offset_to_points + raw.record_len * n;
        let spare = raw.data_end.saturating_sub(used);
        if raw.record_len > 0 && spare >= raw.record_len {
            warnings.push(format!(
                "{}: the header declares {n} point records, but {spare} more bytes ({} records of {} bytes) follow them; they were not read (the header's point count may be wrong)",
                path.display(),
                spare / raw.record_len,
                raw.record_len
            ));
        }
    }
    warnings
}

/// Reads a LAS or LAZ file's bytes (`path` is for messages).
pub(crate) fn parse(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    let raw = precheck(path, bytes)?;
    let compressed = if raw.compressed {
        laz_check(path, bytes, &raw)?
    } else {
        Compressed::Crate
    };
    let decoded = match compressed {
        // LAZ with version-2 pointwise items or layered (LAS 1.4) points:
        // scanfit's own decoders (the laz crate's GPS-time decoders recurse
        // on damaged data until the stack overflows)
        Compressed::Layered(layered) => read_layered(path, bytes, &raw, &layered)?,
        Compressed::Pointwise(pw) => read_pointwise(path, bytes, &pw)?,
        // the crate is third-party code: a panic on a damaged file becomes
        // one error, without its message on stderr. Our own readers return
        // errors and never panic on file content.
        Compressed::Crate => quietly(|| read_with_crate(path, bytes.to_vec(), &raw))
            .ok_or_else(|| crate_failed(path))??,
    };
    let n = decoded.points.len();
    if (n as u64) < decoded.declared {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the header declares {} points, but the data holds {n}; the file is truncated",
                decoded.declared
            ),
        });
    }
    if decoded.columns.iter().any(|c| c.len() != n) {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: "the LAS/LAZ columns have different lengths; the file is damaged".into(),
        });
    }
    let mut columns: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
    columns.extend(decoded.names.iter().map(|s| s.to_string()));
    let mut warnings = header_warnings(path, &raw, n as u64);
    warnings.extend(decoded.warnings);
    PointTable {
        path: path.to_path_buf(),
        format: Format::Las,
        points: decoded.points,
        columns,
        extra: decoded.columns,
        origin: if raw.compressed {
            Origin::Indices
        } else {
            Origin::Records {
                start: raw.offset_to_points,
                stride: raw.record_len,
            }
        },
        file_index: None,
        dropped_non_finite: 0,
        warnings,
    }
    .finish(options.non_finite)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    static SEEN: AtomicUsize = AtomicUsize::new(0);

    #[test]
    fn decoder_panics_are_caught_silently_and_the_hook_restored() {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(|info| {
            if info.payload().downcast_ref::<&str>() == Some(&"quietly-test") {
                SEEN.fetch_add(1, Ordering::SeqCst);
            }
        }));
        // inside: caught, and the hook (which would count it) not called
        assert_eq!(quietly(|| -> u32 { panic!("quietly-test") }), None);
        assert_eq!(quietly(|| 7), Some(7));
        assert_eq!(SEEN.load(Ordering::SeqCst), 0);
        // outside: the hook is back
        let _ = std::panic::catch_unwind(|| panic!("quietly-test"));
        assert_eq!(SEEN.load(Ordering::SeqCst), 1);
        std::panic::set_hook(previous);
    }
}
