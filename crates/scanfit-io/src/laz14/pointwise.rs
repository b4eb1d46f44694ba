//! LASzip's pointwise compressor (LAS point formats 0-5, compressors 1 and
//! 2, items of version 2): a chunk is the first record raw, then one
//! arithmetic-coded stream in which every following point codes its items
//! in the order of the LASzip VLR: point-10 ([`super::point10`]), GPS time
//! ([`super::gps`]), RGB (the byte-wise colour differences of
//! [`super::color`]), wave packet and extra bytes. Compressor 1 has a
//! single chunk starting at the point data; compressor 2 starts with the
//! 8-byte chunk-table offset, and the chunk table gives every chunk's size
//! in bytes (and, for variable-size chunks, in points).
//!
//! A chunk is decoded through a [`PointwiseCursor`]: the decoders' state
//! and a window of at most [`WINDOW`] bytes of the chunk, read as the
//! stream advances, so any number of points can be taken at a time and
//! memory does not grow with the chunk (a compressor-1 file is one chunk of
//! all its points).
//!
//! Files with items of version 1 (LASzip 1.x) are not handled here (the
//! `laz` crate reads them; its version-1 GPS decoder does not recurse).

use super::arithmetic::{Decoder, Registers, Step, STEP_BYTES};
use super::chunk::{chunk_at, point_fault, u16_at, u32_at, walk_chunks, VlrItems};
use super::color::{decode_rgb, RgbModels};
use super::gps::{GpsTime, GpsVariant};
use super::integer::IntegerDecoder;
use super::models::SymbolModel;
use super::point10::{Point10, Point10Decoder};
use super::{ChunkSpan, Laz14Error};

/// Bytes of a chunk a [`PointwiseCursor`] holds at a time (unless one
/// point may need more: see [`PointwiseLaz::point_bytes`]).
pub const WINDOW: usize = 1 << 20;

/// Decoding steps of one point besides its extra bytes (one step each):
/// point-10 5 symbols and 5 integers of at most 4 steps (25), GPS time at
/// most 4 switches, a symbol and a full time of an integer and two raw
/// halves (11), RGB 7 symbols, a wave packet 2 symbols, an offset of 4 steps
/// and 5 integers (26).
const POINT_STEPS: usize = 25 + 11 + 7 + 26;

/// Fills `buf` with the file's bytes at an offset; `false` when they are
/// not all in the file.
pub type ReadInto<'r> = &'r mut dyn FnMut(u64, &mut [u8]) -> bool;

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
        let err = Laz14Error::at(at);
        let VlrItems {
            compressor,
            chunk_size,
            items: list,
        } = VlrItems::read(
            vlr,
            at,
            &[1, 2],
            "point formats 0-5 use the pointwise compressors 1 and 2",
        )?;
        let mut items = Items::default();
        let mut stage = 0; // 0: point-10 expected, then 1 GPS, 2 RGB, 3 wave packet, 4 extra bytes, 5 done
        for (k, &(kind, size, version)) in list.iter().enumerate() {
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
/// a chunk is decoded from bytes the caller reads ([`PointwiseLaz::decode`]
/// through a cursor, or [`PointwiseLaz::decode_chunk`] from the whole
/// chunk), so a caller can read one window of one chunk at a time.
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
        if compressor == 1 {
            // one chunk, no chunk-table offset
            let (chunks, sizes) = walk_chunks(start, count, |_, _, left| {
                let bytes = end.saturating_sub(start);
                if bytes < record {
                    return Err(Laz14Error {
                        offset: start,
                        message: format!("the header declares {count} points, but the {bytes} bytes of point data do not hold the first record of {record} bytes; the file is truncated"),
                    });
                }
                Ok((left, bytes))
            })?;
            return Ok(Self {
                items,
                chunks,
                sizes,
            });
        }
        let (chunks, sizes) = walk_chunks(start.saturating_add(8), count, |c, pos, _| {
            let err = Laz14Error::at(pos);
            let Some(table) = table else {
                return Err(Laz14Error {
                    offset: start,
                    message: "the LAZ chunk table cannot be read (its offset at the start of the point data and at the file's end points nowhere valid); the file is damaged or was not finished".into(),
                });
            };
            let Some(&(table_points, bytes)) = table.get(c) else {
                return Err(err(format!("the LAZ chunk table lists {} chunks, but the header's {count} points need more; the file is damaged", table.len())));
            };
            let expected = if chunk_size == u32::MAX {
                table_points
            } else {
                u64::from(chunk_size)
            };
            if expected > 0 && (bytes < record || pos.saturating_add(bytes) > end) {
                return Err(err(format!(
                    "the LAZ chunk table gives chunk {c} {bytes} bytes, but {} bytes of point data are left and a chunk holds at least its first record of {record} bytes; the file is damaged",
                    end.saturating_sub(pos)
                )));
            }
            Ok((expected, bytes))
        })?;
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

    /// The most compressed bytes one point can take: [`STEP_BYTES`] per
    /// decoding step, the fixed items' steps and one per extra byte, twice
    /// over for safety, plus the stream's four starting bytes. A cursor's
    /// window holds at least this much more than its first record.
    pub fn point_bytes(&self) -> usize {
        2 * STEP_BYTES * (POINT_STEPS + self.items.extra) + 4
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

    /// A cursor at the start of chunk `index`, holding at most [`WINDOW`]
    /// bytes of it at a time (more only if one point may need more).
    pub fn cursor(&self, index: usize) -> Result<PointwiseCursor, Laz14Error> {
        self.cursor_with_window(index, WINDOW)
    }

    /// A cursor at the start of chunk `index` whose window holds `window`
    /// bytes, raised to the first record plus [`PointwiseLaz::point_bytes`]
    /// (small windows make many refills: the tests' way to check that the
    /// stream resumes exactly).
    pub fn cursor_with_window(
        &self,
        index: usize,
        window: usize,
    ) -> Result<PointwiseCursor, Laz14Error> {
        let (span, _) = chunk_at(&self.chunks, index)?;
        Ok(PointwiseCursor {
            index,
            span,
            len: self.chunk_bytes(index),
            decoded: 0,
            state: None,
            registers: None,
            window: Vec::new(),
            at: 0,
            window_start: 0,
            capacity: window.max(self.items.record() + self.point_bytes()),
        })
    }

    /// Decodes at most `max` more points of the cursor's chunk, reading its
    /// bytes through `read` (at file offsets) as the window needs them,
    /// and appends them to `out`; returns how many (0 once the chunk is
    /// done). The points are those of [`PointwiseLaz::decode_chunk`], bit
    /// for bit, however the chunk is cut.
    ///
    /// ```
    /// use scanfit_io::laz14::PointwiseLaz;
    /// // a VLR of compressor 1 with one point-10 item of version 2
    /// let mut vlr = vec![0u8; 40];
    /// vlr[0] = 1;
    /// vlr[32] = 1;
    /// vlr[34..40].copy_from_slice(&[6, 0, 20, 0, 2, 0]);
    /// // one point: its raw record is all of the chunk
    /// let mut record = [0u8; 20];
    /// record[8] = 42; // Z
    /// let file = PointwiseLaz::new(&vlr, 0, 100, 120, 1, None).unwrap();
    /// let mut cursor = file.cursor(0).unwrap();
    /// let mut read = |at: u64, buf: &mut [u8]| {
    ///     let at = (at - 100) as usize;
    ///     buf.copy_from_slice(&record[at..at + buf.len()]);
    ///     true
    /// };
    /// let mut out = Vec::new();
    /// assert_eq!(file.decode(&mut cursor, &mut read, 10, &mut out).unwrap(), 1);
    /// assert_eq!((out[0].point.z, cursor.finished()), (42, true));
    /// ```
    pub fn decode(
        &self,
        cursor: &mut PointwiseCursor,
        read: ReadInto<'_>,
        max: usize,
        out: &mut Vec<PointwiseRecord>,
    ) -> Result<usize, Laz14Error> {
        let (span, err) = chunk_at(&self.chunks, cursor.index)?;
        let bound = self.point_bytes();
        let mut produced = 0usize;
        out.reserve((span.points - cursor.decoded).min(max as u64).min(1 << 16) as usize);
        if cursor.state.is_none() && max > 0 && cursor.decoded < span.points {
            let record = self.items.record();
            cursor.fill(read, record, &err)?;
            let raw = cursor.window.get(..record).ok_or_else(|| {
                err(format!("the chunk has {} bytes, fewer than its first record's {record}; the file is truncated", cursor.len))
            })?;
            let (state, first) = self.start_chunk(raw);
            cursor.state = Some(state);
            cursor.at = record;
            out.push(first);
            cursor.decoded = 1;
            produced = 1;
        }
        while produced < max && cursor.decoded < span.points {
            cursor.fill(read, bound, &err)?;
            let more = cursor.window_start + (cursor.window.len() as u64) < cursor.len;
            let stream = cursor.len.saturating_sub(self.items.record() as u64);
            let PointwiseCursor {
                window,
                at,
                registers,
                state,
                decoded,
                ..
            } = cursor;
            let Some(state) = state.as_mut() else {
                break;
            };
            let mut dec = match registers {
                Some(r) => Decoder::resume(window, *at, *r),
                None => Decoder::start(window, *at).map_err(|_| {
                    err(format!("its compressed stream ({} bytes) is shorter than 4 bytes or starts with a value no encoder writes; the file is damaged", stream))
                })?,
            };
            loop {
                let k = span.first_point + *decoded;
                let p = state.next(&mut dec).map_err(|f| {
                    err(point_fault(
                        f,
                        k,
                        "the chunk's bytes end before it, or hold data no encoder writes",
                    ))
                })?;
                out.push(p);
                *decoded += 1;
                produced += 1;
                let low = more && dec.position() + bound > window.len();
                if produced == max || *decoded == span.points || low {
                    break;
                }
            }
            let (position, r) = dec.suspend();
            *at = position;
            *registers = Some(r);
        }
        if cursor.finished() {
            // the chunk is done: its window is not needed any more
            cursor.window = Vec::new();
        }
        Ok(produced)
    }

    /// The item decoders after a chunk's raw first record, and that record.
    fn start_chunk(&self, raw: &[u8]) -> (ItemDecoders, PointwiseRecord) {
        let items = self.items;
        let mut head = [0u8; 20];
        head.copy_from_slice(&raw[..20]);
        let point = Point10::from_record(&head);
        let mut first = PointwiseRecord {
            point,
            ..PointwiseRecord::default()
        };
        let mut at = 20;
        let mut gps = None;
        if items.gps {
            let t = raw
                .get(at..at + 8)
                .and_then(|b| b.try_into().ok())
                .map(i64::from_le_bytes)
                .unwrap_or(0);
            first.gps_time = f64::from_bits(t as u64);
            gps = Some(GpsTime::new(t, GpsVariant::Pointwise));
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
        let extra = ExtraDecoder::new(raw.get(at..at + items.extra).unwrap_or(&[]));
        let state = ItemDecoders {
            point: Point10Decoder::new(&point),
            gps,
            rgb,
            wave,
            extra,
        };
        (state, first)
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
        let mut cursor = self.cursor(index)?;
        let offset = cursor.span.offset;
        let mut read = |at: u64, buf: &mut [u8]| {
            let Some(from) = at.checked_sub(offset).and_then(|a| usize::try_from(a).ok()) else {
                return false;
            };
            match bytes.get(from..from.saturating_add(buf.len())) {
                Some(b) => {
                    buf.copy_from_slice(b);
                    true
                }
                None => false,
            }
        };
        while self.decode(&mut cursor, &mut read, usize::MAX, out)? > 0 {}
        Ok(())
    }
}

/// The decoders of a pointwise chunk's items after its first record.
struct ItemDecoders {
    point: Point10Decoder,
    gps: Option<GpsTime>,
    rgb: Option<([u16; 3], Box<RgbModels>)>,
    wave: Option<WaveDecoder>,
    extra: ExtraDecoder,
}

impl ItemDecoders {
    /// The next point's items, in the VLR's order.
    fn next(&mut self, dec: &mut Decoder<'_>) -> Step<PointwiseRecord> {
        let mut p = PointwiseRecord {
            point: self.point.next(dec)?,
            ..PointwiseRecord::default()
        };
        if let Some(g) = self.gps.as_mut() {
            p.gps_time = f64::from_bits(g.next(dec)? as u64);
        }
        if let Some((last, models)) = self.rgb.as_mut() {
            *last = decode_rgb(dec, models, *last)?;
            p.rgb = *last;
        }
        if let Some(w) = self.wave.as_mut() {
            w.next(dec)?;
        }
        self.extra.next(dec)?;
        Ok(p)
    }
}

/// A pointwise chunk being decoded ([`PointwiseLaz::decode`]): the item
/// decoders' state, the arithmetic decoder's registers and a window of the
/// chunk's bytes. Its memory is the window (see
/// [`PointwiseCursor::buffer_capacity`]) and the adaptive models, whatever
/// the chunk's size.
pub struct PointwiseCursor {
    index: usize,
    span: ChunkSpan,
    /// the chunk's size in bytes
    len: u64,
    /// points of the chunk decoded so far
    decoded: u64,
    state: Option<ItemDecoders>,
    registers: Option<Registers>,
    window: Vec<u8>,
    /// the next byte of the window to decode
    at: usize,
    /// the chunk-relative offset of the window's first byte
    window_start: u64,
    /// the window's size
    capacity: usize,
}

impl PointwiseCursor {
    /// Whether every point of the chunk has been decoded.
    pub fn finished(&self) -> bool {
        self.decoded == self.span.points
    }

    /// The chunk.
    pub fn chunk(&self) -> ChunkSpan {
        self.span
    }

    /// Bytes the window holds allocated now (at most its size, set when the
    /// cursor was made; 0 once the chunk is done).
    pub fn buffer_capacity(&self) -> usize {
        self.window.capacity()
    }

    /// Makes the window hold at least `need` bytes past the decoding
    /// position (or all that is left of the chunk): drops the bytes decoded
    /// and reads up to the window's size.
    fn fill(
        &mut self,
        read: ReadInto<'_>,
        need: usize,
        err: &impl Fn(String) -> Laz14Error,
    ) -> Result<(), Laz14Error> {
        let held = self.window.len() - self.at;
        let end = self.window_start + self.window.len() as u64;
        if held >= need || end >= self.len {
            return Ok(());
        }
        if self.window.capacity() < self.capacity {
            self.window.reserve_exact(self.capacity - self.window.len());
        }
        self.window.copy_within(self.at.., 0);
        self.window.truncate(held);
        self.window_start += self.at as u64;
        self.at = 0;
        let grow = ((self.capacity - held) as u64).min(self.len - end) as usize;
        self.window.resize(held + grow, 0);
        if !read(self.span.offset + end, &mut self.window[held..]) {
            return Err(err(format!(
                "the chunk's {} bytes run past the end of the file; it is truncated",
                self.len
            )));
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
