//! LASzip's pointwise compressor (LAS point formats 0-5, compressors 1 and
//! 2, items of version 2): a chunk is the first record raw, then one
//! arithmetic-coded stream in which every following point codes its items
//! in the order of the LASzip VLR: point-10 ([`super::point10`]), GPS time
//! ([`super::gps11`]), RGB (the byte-wise colour differences of
//! [`super::color`]), wave packet and extra bytes. Compressor 1 has a
//! single chunk starting at the point data; compressor 2 starts with the
//! 8-byte chunk-table offset, and the chunk table gives every chunk's size
//! in bytes (and, for variable-size chunks, in points).
//!
//! Files with items of version 1 (LASzip 1.x) are not handled here (the
//! `laz` crate reads them; its version-1 GPS decoder does not recurse).

use super::arithmetic::{Decoder, Fault, Step};
use super::color::{decode_rgb, RgbModels};
use super::gps11::Gps11Decoder;
use super::integer::IntegerDecoder;
use super::models::SymbolModel;
use super::point10::{Point10, Point10Decoder};
use super::{ChunkSpan, Laz14Error};

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(
        b.get(at..at.checked_add(2)?)?.try_into().ok()?,
    ))
}
fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(
        b.get(at..at.checked_add(4)?)?.try_into().ok()?,
    ))
}

/// One decoded point of formats 0-5: the point-10 fields, the GPS time
/// (0 when the format has none) and RGB (zero when it has none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointwiseRecord {
    /// the 20 bytes every record of formats 0-5 starts with
    pub point: Point10,
    /// GPS time (formats 1, 3, 4, 5)
    pub gps_time: f64,
    /// red, green, blue (formats 2, 3, 5)
    pub rgb: [u16; 3],
}

/// What follows the point-10 item in the record.
#[derive(Clone, Copy, Debug, Default)]
struct Items {
    gps: bool,
    rgb: bool,
    /// a wave packet item (29 bytes), decoded and dropped
    wave: bool,
    /// extra bytes, decoded and dropped
    extra: usize,
}

impl Items {
    fn record(&self) -> usize {
        20 + 8 * usize::from(self.gps)
            + 6 * usize::from(self.rgb)
            + 29 * usize::from(self.wave)
            + self.extra
    }

    /// Reads the item list of a LASzip VLR: point-10 first, then GPS time,
    /// RGB, wave packet and extra bytes, each optional and in this order,
    /// all of version 2 (a wave packet of version 1 or 2: LASzip has one).
    fn from_vlr(vlr: &[u8], at: u64) -> Result<(Self, u16, u32), Laz14Error> {
        let err = |message: String| Laz14Error {
            offset: at,
            message,
        };
        let (Some(compressor), Some(chunk_size), Some(count)) =
            (u16_at(vlr, 0), u32_at(vlr, 12), u16_at(vlr, 32))
        else {
            return Err(err(format!(
                "the LASzip VLR has {} bytes, too few for its fixed fields; the file is damaged",
                vlr.len()
            )));
        };
        if !matches!(compressor, 1 | 2) {
            return Err(err(format!("the LASzip VLR declares compressor {compressor}; point formats 0-5 use the pointwise compressors 1 and 2")));
        }
        let mut items = Items::default();
        let mut stage = 0; // 0: point-10 expected, then 1 GPS, 2 RGB, 3 wave packet, 4 extra bytes, 5 done
        for k in 0..usize::from(count) {
            let (Some(kind), Some(size), Some(version)) = (
                u16_at(vlr, 34 + 6 * k),
                u16_at(vlr, 36 + 6 * k),
                u16_at(vlr, 38 + 6 * k),
            ) else {
                return Err(err(format!("the LASzip VLR declares {count} items, but its {} bytes hold fewer; the file is damaged", vlr.len())));
            };
            let ok_version = version == 2 || (kind == 9 && version == 1);
            if !ok_version {
                return Err(err(format!("LASzip item {k} (type {kind}) has version {version}; scanfit decodes the pointwise items of version 2")));
            }
            stage = match (kind, size) {
                (6, 20) if stage == 0 => 1,
                (7, 8) if (1..=1).contains(&stage) => {
                    items.gps = true;
                    2
                }
                (8, 6) if (1..=2).contains(&stage) => {
                    items.rgb = true;
                    3
                }
                (9, 29) if (1..=3).contains(&stage) => {
                    items.wave = true;
                    4
                }
                (0, n) if n > 0 && (1..=4).contains(&stage) => {
                    items.extra = usize::from(n);
                    5
                }
                _ => {
                    return Err(err(format!(
                        "LASzip item {k} (type {kind}, {size} bytes) does not belong at this place of a point record of formats 0-5 (point-10, then GPS time, RGB, wave packet, extra bytes); the file is damaged"
                    )))
                }
            };
        }
        if stage == 0 {
            return Err(err(
                "the LASzip VLR lists no point-10 item; the file is damaged".into(),
            ));
        }
        Ok((items, compressor, chunk_size))
    }
}

/// A pointwise LAZ file's chunks, found from its LASzip VLR and chunk
/// table and checked against the point data's bounds. Holds no file bytes:
/// [`PointwiseLaz::decode_chunk`] is given each chunk's bytes, so a caller
/// can read one chunk at a time.
pub struct PointwiseLaz {
    items: Items,
    chunks: Vec<ChunkSpan>,
    sizes: Vec<u64>,
}

impl PointwiseLaz {
    /// The chunks of a file whose LASzip VLR payload is `vlr` (at byte
    /// `vlr_at`, for messages), whose point data runs from `start` (the
    /// point data's offset) to `end` (the chunk table, the first EVLR or
    /// the file's end), with `count` points declared, and (compressor 2)
    /// the chunk table as (points, bytes) per chunk. Every chunk must lie
    /// within the point data and hold at least its first record; the
    /// points expected from a chunk come from the VLR's chunk size (or the
    /// table, for variable-size chunks) and the count left.
    ///
    /// ```
    /// use scanfit_io::laz14::PointwiseLaz;
    /// // the layered compressor is not pointwise
    /// let mut vlr = vec![0u8; 40];
    /// vlr[0] = 3;
    /// let e = PointwiseLaz::new(&vlr, 0, 0, 0, 0, None).err().unwrap();
    /// assert!(e.message.contains("compressor 3"));
    /// ```
    pub fn new(
        vlr: &[u8],
        vlr_at: u64,
        start: u64,
        end: u64,
        count: u64,
        table: Option<&[(u64, u64)]>,
    ) -> Result<Self, Laz14Error> {
        let (items, compressor, chunk_size) = Items::from_vlr(vlr, vlr_at)?;
        let record = items.record() as u64;
        let mut chunks = Vec::new();
        let mut sizes = Vec::new();
        if count == 0 {
            return Ok(Self {
                items,
                chunks,
                sizes,
            });
        }
        if compressor == 1 {
            // one chunk, no chunk-table offset
            let bytes = end.saturating_sub(start);
            if bytes < record {
                return Err(Laz14Error {
                    offset: start,
                    message: format!("the header declares {count} points, but the {bytes} bytes of point data do not hold the first record of {record} bytes; the file is truncated"),
                });
            }
            chunks.push(ChunkSpan {
                offset: start,
                points: count,
                first_point: 0,
            });
            sizes.push(bytes);
            return Ok(Self {
                items,
                chunks,
                sizes,
            });
        }
        let Some(table) = table else {
            return Err(Laz14Error {
                offset: start,
                message: "the LAZ chunk table cannot be read (its offset at the start of the point data and at the file's end points nowhere valid); the file is damaged or was not finished".into(),
            });
        };
        let mut pos = start.saturating_add(8);
        let mut done = 0u64;
        while done < count {
            let c = chunks.len();
            let err = |message: String| Laz14Error {
                offset: pos,
                message,
            };
            let Some(&(table_points, bytes)) = table.get(c) else {
                return Err(err(format!("the LAZ chunk table lists {} chunks, but the header's {count} points need more; the file is damaged", table.len())));
            };
            let expected = if chunk_size == u32::MAX {
                table_points
            } else {
                u64::from(chunk_size)
            };
            let points = expected.min(count - done);
            if points == 0 {
                return Err(err(format!("LAZ chunk {c} holds no points, but {} of the header's {count} points are still to come; the file is damaged", count - done)));
            }
            if bytes < record || pos.saturating_add(bytes) > end {
                return Err(err(format!(
                    "the LAZ chunk table gives chunk {c} {bytes} bytes, but {} bytes of point data are left and a chunk holds at least its first record of {record} bytes; the file is damaged",
                    end.saturating_sub(pos)
                )));
            }
            chunks.push(ChunkSpan {
                offset: pos,
                points,
                first_point: done,
            });
            sizes.push(bytes);
            done += points;
            pos += bytes;
        }
        Ok(Self {
            items,
            chunks,
            sizes,
        })
    }

    /// The chunks, in file order.
    pub fn chunks(&self) -> &[ChunkSpan] {
        &self.chunks
    }

    /// The size in bytes of chunk `index` (0 for no such chunk).
    pub fn chunk_bytes(&self, index: usize) -> u64 {
        self.sizes.get(index).copied().unwrap_or(0)
    }

    /// Bytes of a raw record.
    pub fn record_len(&self) -> usize {
        self.items.record()
    }

    /// Whether the points have a GPS time (formats 1, 3, 4, 5).
    pub fn has_gps_time(&self) -> bool {
        self.items.gps
    }

    /// Whether the points have RGB (formats 2, 3, 5).
    pub fn has_rgb(&self) -> bool {
        self.items.rgb
    }

    /// Whether the points have a wave packet (formats 4, 5).
    pub fn has_wave_packet(&self) -> bool {
        self.items.wave
    }

    /// Decodes chunk `index` from `bytes` (the chunk's
    /// [`PointwiseLaz::chunk_bytes`] bytes, starting at its offset),
    /// appending its points to `out`.
    pub fn decode_chunk(
        &self,
        index: usize,
        bytes: &[u8],
        out: &mut Vec<PointwiseRecord>,
    ) -> Result<(), Laz14Error> {
        let span = *self.chunks.get(index).ok_or_else(|| Laz14Error {
            offset: 0,
            message: format!(
                "there is no LAZ chunk {index} (the file has {})",
                self.chunks.len()
            ),
        })?;
        let err = |message: String| Laz14Error {
            offset: span.offset,
            message: format!(
                "LAZ chunk {index} (points {} to {}): {message}",
                span.first_point,
                span.first_point + span.points - 1
            ),
        };
        let items = self.items;
        let record = items.record();
        let (Some(raw), Some(stream)) = (bytes.get(..record), bytes.get(record..)) else {
            return Err(err(format!(
                "the chunk has {} bytes, fewer than its first record's {record}; the file is truncated",
                bytes.len()
            )));
        };
        let head: &[u8; 20] = raw[..20]
            .try_into()
            .map_err(|_| err("the chunk is truncated".into()))?;
        let first_point = Point10::from_record(head);
        let mut at = 20;
        let mut gps = None;
        let mut first = PointwiseRecord {
            point: first_point,
            ..PointwiseRecord::default()
        };
        if items.gps {
            let t = raw
                .get(at..at + 8)
                .and_then(|b| b.try_into().ok())
                .map(i64::from_le_bytes)
                .unwrap_or(0);
            first.gps_time = f64::from_bits(t as u64);
            gps = Some(Gps11Decoder::new(t));
            at += 8;
        }
        let mut rgb = None;
        if items.rgb {
            let c = |k: usize| u16_at(raw, at + 2 * k).unwrap_or(0);
            first.rgb = [c(0), c(1), c(2)];
            rgb = Some((first.rgb, RgbModels::new()));
            at += 6;
        }
        let mut wave = None;
        if items.wave {
            wave = Some(WaveDecoder::new(raw.get(at..at + 29).unwrap_or(&[])));
            at += 29;
        }
        let mut extra = ExtraDecoder::new(raw.get(at..at + items.extra).unwrap_or(&[]));
        out.reserve(span.points.min(1 << 16) as usize);
        out.push(first);
        if span.points == 1 {
            return Ok(());
        }
        let mut dec = Decoder::new(stream).map_err(|_| {
            err(format!("its compressed stream ({} bytes) is shorter than 4 bytes or starts with a value no encoder writes; the file is damaged", stream.len()))
        })?;
        let mut points = Point10Decoder::new(&first_point);
        for k in 1..span.points {
            let fail = |f: Fault| {
                let why = match f {
                    Fault::Switches => "its GPS time switches sequences more often than there are sequences (an encoder switches at most once)",
                    _ => "the chunk's bytes end before it, or hold data no encoder writes",
                };
                err(format!(
                    "point {} cannot be decoded: {why}; the file is damaged",
                    span.first_point + k
                ))
            };
            let mut p = PointwiseRecord {
                point: points.next(&mut dec).map_err(fail)?,
                ..PointwiseRecord::default()
            };
            if let Some(g) = gps.as_mut() {
                p.gps_time = f64::from_bits(g.next(&mut dec).map_err(fail)? as u64);
            }
            if let Some((last, models)) = rgb.as_mut() {
                *last = decode_rgb(&mut dec, models, *last).map_err(fail)?;
                p.rgb = *last;
            }
            if let Some(w) = wave.as_mut() {
                w.next(&mut dec).map_err(fail)?;
            }
            extra.next(&mut dec).map_err(fail)?;
            out.push(p);
        }
        Ok(())
    }
}

/// Extra bytes (item type 0): each byte a symbol added to its last value,
/// with a model per byte.
struct ExtraDecoder {
    last: Vec<u8>,
    models: Vec<Option<SymbolModel>>,
}

impl ExtraDecoder {
    fn new(first: &[u8]) -> Self {
        Self {
            last: first.to_vec(),
            models: first.iter().map(|_| None).collect(),
        }
    }

    fn next(&mut self, dec: &mut Decoder<'_>) -> Step<()> {
        for (b, m) in self.last.iter_mut().zip(&mut self.models) {
            let m = m.get_or_insert_with(|| SymbolModel::new(256));
            *b = b.wrapping_add(dec.symbol(m)? as u8);
        }
        Ok(())
    }
}

/// The wave packet item (type 9): descriptor index, byte offset of the
/// waveform (same, after the last packet, a coded difference or raw),
/// packet size, return point and the direction floats (as integers of
/// their bit patterns). scanfit keeps none of it; it is decoded to reach
/// the items after it.
struct WaveDecoder {
    offset: u64,
    size: u32,
    floats: [i32; 4],
    offset_diff: i32,
    last_symbol: usize,
    index: SymbolModel,
    offset_models: [SymbolModel; 4],
    offset_ints: IntegerDecoder,
    size_ints: IntegerDecoder,
    return_ints: IntegerDecoder,
    xyz_ints: IntegerDecoder,
}

impl WaveDecoder {
    fn new(first: &[u8]) -> Self {
        let at = |k: usize| u32_at(first, k).unwrap_or(0);
        Self {
            offset: u64::from(at(1)) | (u64::from(at(5)) << 32),
            size: at(9),
            floats: [at(13) as i32, at(17) as i32, at(21) as i32, at(25) as i32],
            offset_diff: 0,
            last_symbol: 0,
            index: SymbolModel::new(256),
            offset_models: std::array::from_fn(|_| SymbolModel::new(4)),
            offset_ints: IntegerDecoder::new(32, 1),
            size_ints: IntegerDecoder::new(32, 1),
            return_ints: IntegerDecoder::new(32, 1),
            xyz_ints: IntegerDecoder::new(32, 3),
        }
    }

    fn next(&mut self, dec: &mut Decoder<'_>) -> Step<()> {
        dec.symbol(&mut self.index)?;
        self.last_symbol = dec.symbol(&mut self.offset_models[self.last_symbol])? as usize;
        self.offset = match self.last_symbol {
            0 => self.offset,
            1 => self.offset.wrapping_add(u64::from(self.size)),
            2 => {
                self.offset_diff = self.offset_ints.decode(dec, self.offset_diff, 0)?;
                self.offset.wrapping_add(self.offset_diff as u64)
            }
            _ => {
                let low = dec.raw_u32()?;
                let high = dec.raw_u32()?;
                u64::from(low) | (u64::from(high) << 32)
            }
        };
        self.size = self.size_ints.decode(dec, self.size as i32, 0)? as u32;
        self.floats[0] = self.return_ints.decode(dec, self.floats[0], 0)?;
        for k in 1..4 {
            self.floats[k] = self.xyz_ints.decode(dec, self.floats[k], k - 1)?;
        }
        Ok(())
    }
}
