//! The LASzip VLR's item list and the chunks of a layered LAZ file. A
//! chunk is: the first point raw (every item's bytes), its point count
//! (u32), the byte size of every layer (u32 each, items in VLR order), then
//! the layers in the same order. Chunks follow each other after the 8-byte
//! chunk-table offset at the start of the point data.

use super::arithmetic::{Decoder, Fault};
use super::color::{NirDecoder, RgbDecoder};
use super::point::{Layers, PointDecoder};
use super::{Laz14Error, Point14};

/// Point-14 layers: XY/returns/channel, Z, classification, flags,
/// intensity, scan angle, user data, point source, GPS time.
const POINT_LAYERS: usize = 9;
const POINT_BYTES: usize = 30;
const NAMES: [&str; POINT_LAYERS] = [
    "channel/returns/XY",
    "Z",
    "classification",
    "flags",
    "intensity",
    "scan angle",
    "user data",
    "point source",
    "GPS time",
];

pub(super) fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(
        b.get(at..at.checked_add(2)?)?.try_into().ok()?,
    ))
}
pub(super) fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(
        b.get(at..at.checked_add(4)?)?.try_into().ok()?,
    ))
}

/// The fixed fields of a LASzip VLR that both compressors read: the
/// compressor, the chunk size (`u32::MAX`: variable-size chunks) and the
/// items as (type, size, version).
pub(super) struct VlrItems {
    pub(super) compressor: u16,
    pub(super) chunk_size: u32,
    pub(super) items: Vec<(u16, u16, u16)>,
}

impl VlrItems {
    /// Reads the VLR payload `vlr` (found at byte `at`, for messages) of a
    /// file whose compressor must be one of `compressors`; `uses` says
    /// which points use them, in the message of another compressor.
    pub(super) fn read(
        vlr: &[u8],
        at: u64,
        compressors: &[u16],
        uses: &str,
    ) -> Result<Self, Laz14Error> {
        let err = Laz14Error::at(at);
        let (Some(compressor), Some(chunk_size), Some(count)) =
            (u16_at(vlr, 0), u32_at(vlr, 12), u16_at(vlr, 32))
        else {
            return Err(err(format!(
                "the LASzip VLR has {} bytes, too few for its fixed fields; the file is damaged",
                vlr.len()
            )));
        };
        let items = (0..usize::from(count))
            .map(|k| {
                match (
                    u16_at(vlr, 34 + 6 * k),
                    u16_at(vlr, 36 + 6 * k),
                    u16_at(vlr, 38 + 6 * k),
                ) {
                    (Some(kind), Some(size), Some(version)) => Ok((kind, size, version)),
                    _ => Err(err(format!("the LASzip VLR declares {count} items, but its {} bytes hold fewer; the file is damaged", vlr.len()))),
                }
            })
            .collect::<Result<_, _>>()?;
        if !compressors.contains(&compressor) {
            return Err(err(format!(
                "the LASzip VLR declares compressor {compressor}; {uses}"
            )));
        }
        Ok(Self {
            compressor,
            chunk_size,
            items,
        })
    }
}

/// The chunks of a file found by a walk from the point data's start:
/// `next(c, pos, left)` checks chunk `c` at byte `pos` with `left` points
/// still to come and returns the points expected from it (before the cap
/// by `left`) and its size in bytes. A chunk expected to hold no point is
/// an error.
pub(super) fn walk_chunks(
    start: u64,
    count: u64,
    mut next: impl FnMut(usize, u64, u64) -> Result<(u64, u64), Laz14Error>,
) -> Result<(Vec<ChunkSpan>, Vec<u64>), Laz14Error> {
    let mut chunks = Vec::new();
    let mut sizes = Vec::new();
    let mut pos = start;
    let mut done = 0u64;
    while done < count {
        let c = chunks.len();
        let (expected, bytes) = next(c, pos, count - done)?;
        let points = expected.min(count - done);
        if points == 0 {
            return Err(Laz14Error {
                offset: pos,
                message: format!("LAZ chunk {c} holds no points, but {} of the header's {count} points are still to come; the file is damaged", count - done),
            });
        }
        chunks.push(ChunkSpan {
            offset: pos,
            points,
            first_point: done,
        });
        sizes.push(bytes);
        done += points;
        pos = pos.saturating_add(bytes);
    }
    Ok((chunks, sizes))
}

/// Chunk `index` of `chunks`, and a maker of errors that name it.
pub(super) fn chunk_at(
    chunks: &[ChunkSpan],
    index: usize,
) -> Result<(ChunkSpan, impl Fn(String) -> Laz14Error), Laz14Error> {
    let span = *chunks.get(index).ok_or_else(|| Laz14Error {
        offset: 0,
        message: format!(
            "there is no LAZ chunk {index} (the file has {})",
            chunks.len()
        ),
    })?;
    let err = move |message: String| Laz14Error {
        offset: span.offset,
        message: format!(
            "LAZ chunk {index} (points {} to {}): {message}",
            span.first_point,
            span.first_point + span.points - 1
        ),
    };
    Ok((span, err))
}

/// The message of a point that cannot be decoded (`k`: its index in the
/// file); `ended` says what running out of bytes means for this chunk.
pub(super) fn point_fault(f: Fault, k: u64, ended: &str) -> String {
    let why = match f {
        Fault::Switches => "its GPS time switches sequences more often than there are sequences (an encoder switches at most once)",
        _ => ended,
    };
    format!("point {k} cannot be decoded: {why}; the file is damaged")
}

/// What follows the point-14 item in the record.
#[derive(Clone, Copy, Debug, Default)]
struct Items {
    rgb: bool,
    nir: bool,
    /// bytes (and layers) of extra bytes, not decoded
    extra: usize,
    /// a wave packet item (29 bytes, one layer), not decoded
    wave: bool,
    version4: bool,
}

impl Items {
    /// Raw bytes of a record.
    fn record(&self) -> usize {
        POINT_BYTES
            + 6 * usize::from(self.rgb)
            + 2 * usize::from(self.nir)
            + self.extra
            + 29 * usize::from(self.wave)
    }
    /// Layers of a chunk.
    fn layers(&self) -> usize {
        POINT_LAYERS
            + usize::from(self.rgb)
            + usize::from(self.nir)
            + self.extra
            + usize::from(self.wave)
    }

    /// Reads the item list of a LASzip VLR: a point-14 item first, then
    /// optionally RGB or RGB+NIR, extra bytes and a wave packet, all of
    /// the same version (3 or 4).
    fn from_vlr(vlr: &[u8], at: u64) -> Result<(Self, u32), Laz14Error> {
        let err = Laz14Error::at(at);
        let VlrItems {
            chunk_size,
            items: list,
            ..
        } = VlrItems::read(
            vlr,
            at,
            &[3],
            "LAS 1.4 points (formats 6-10) use the layered compressor 3",
        )?;
        let mut items = Items::default();
        let mut version = None;
        let mut stage = 0; // 0: point14 expected, 1: colour, 2: extra bytes, 3: wave packet, 4: done
        for (k, &(kind, size, v)) in list.iter().enumerate() {
            if !matches!(v, 3 | 4) || version.is_some_and(|w| w != v) {
                return Err(err(format!("LASzip item {k} has version {v}; the layered items of one file are all of version 3 or all of version 4")));
            }
            version = Some(v);
            let next = match (kind, size) {
                (10, 30) if stage == 0 => 1,
                (11, 6) if stage == 1 => {
                    items.rgb = true;
                    2
                }
                (12, 8) if stage == 1 => {
                    items.rgb = true;
                    items.nir = true;
                    2
                }
                (14, n) if n > 0 && (1..=2).contains(&stage) => {
                    items.extra = usize::from(n);
                    3
                }
                (13, 29) if (1..=3).contains(&stage) => {
                    items.wave = true;
                    4
                }
                _ => {
                    return Err(err(format!(
                        "LASzip item {k} (type {kind}, {size} bytes) does not belong at this place of a LAS 1.4 point record (point-14, then RGB or RGB+NIR, extra bytes, wave packet); the file is damaged"
                    )))
                }
            };
            stage = next;
        }
        if stage == 0 {
            return Err(err(
                "the LASzip VLR lists no point-14 item; the file is damaged".into(),
            ));
        }
        items.version4 = version == Some(4);
        Ok((items, chunk_size))
    }
}

/// Where one chunk is and how many points it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChunkSpan {
    /// byte offset of the chunk (its raw first point) in the file
    pub offset: u64,
    /// points decoded from it
    pub points: u64,
    /// index of its first point in the file
    pub first_point: u64,
}

/// Reads `n` bytes of a file at an offset (`None` when they are not all
/// in the file).
pub type ReadAt<'r> = &'r dyn Fn(u64, usize) -> Option<Vec<u8>>;

/// A layered LAZ file whose chunk headers have been walked and checked.
/// Holds no file bytes: [`LayeredLaz::decode_chunk`] is given each chunk's
/// bytes, so a caller can read one chunk at a time.
pub struct LayeredLaz {
    items: Items,
    chunks: Vec<ChunkSpan>,
    sizes: Vec<u64>,
}

impl LayeredLaz {
    /// Walks the chunks of a file (its chunk headers read through `read`,
    /// at their offsets): `vlr` is the LASzip
    /// VLR's payload (found at byte `vlr_at`, for messages), the point data
    /// runs from `start` (the 8-byte chunk-table offset) to `end` (the
    /// chunk table, the first EVLR or the file's end), `count` points are
    /// declared, and `table_counts` are the chunk table's point counts
    /// (needed for variable-size chunks; without it the counts the chunks
    /// declare are used). Each chunk's header must fit before `end` and its
    /// layers in the bytes left; its declared count must cover the points
    /// expected from it.
    ///
    /// ```
    /// use scanfit_io::laz14::LayeredLaz;
    /// // a LASzip VLR with the pointwise compressor is not a layered file
    /// let mut vlr = vec![0u8; 40];
    /// vlr[0] = 2;
    /// let e = LayeredLaz::new(&|_, _| None, &vlr, 0, 0, 0, 0, None).err().unwrap();
    /// assert!(e.message.contains("compressor 2"));
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        read: ReadAt<'_>,
        vlr: &[u8],
        vlr_at: u64,
        start: u64,
        end: u64,
        count: u64,
        table_counts: Option<&[u64]>,
    ) -> Result<Self, Laz14Error> {
        let (items, chunk_size) = Items::from_vlr(vlr, vlr_at)?;
        let head = (items.record() + 4 + 4 * items.layers()) as u64;
        let (chunks, sizes) = walk_chunks(start.saturating_add(8), count, |c, pos, left| {
            let err = Laz14Error::at(pos);
            if pos.saturating_add(head) > end {
                return Err(err(format!(
                    "the header declares {count} points, but the compressed data ends after {} of them (before the header of chunk {c}); the file is truncated",
                    count - left
                )));
            }
            let header = read(pos, head as usize).unwrap_or_default();
            let declared = u64::from(u32_at(&header, items.record()).unwrap_or(0));
            let sizes: u64 = (0..items.layers())
                .map(|l| u64::from(u32_at(&header, items.record() + 4 + 4 * l).unwrap_or(0)))
                .sum();
            let room = end - pos - head;
            if sizes > room {
                return Err(err(format!(
                    "LAZ chunk {c} declares {sizes} bytes of layers, but only {room} bytes of point data follow; the file is damaged"
                )));
            }
            let expected = match table_counts {
                Some(t) => *t.get(c).ok_or_else(|| {
                    err(format!("the LAZ chunk table lists {} chunks, but the header's {count} points need more; the file is damaged", t.len()))
                })?,
                None if chunk_size == u32::MAX => declared,
                None => u64::from(chunk_size),
            };
            let points = expected.min(left);
            if points > 0 && declared < points {
                return Err(err(format!(
                    "LAZ chunk {c} declares {declared} points, but {points} are expected from it (chunk size and point count); the file is damaged"
                )));
            }
            Ok((expected, head + sizes))
        })?;
        Ok(Self {
            items,
            chunks,
            sizes,
        })
    }

    /// The size in bytes of chunk `index` (0 for no such chunk).
    pub fn chunk_bytes(&self, index: usize) -> u64 {
        self.sizes.get(index).copied().unwrap_or(0)
    }

    /// The chunks, in file order.
    pub fn chunks(&self) -> &[ChunkSpan] {
        &self.chunks
    }

    /// Whether the points have RGB (formats 7, 8, 10).
    pub fn has_rgb(&self) -> bool {
        self.items.rgb
    }

    /// Whether the points have NIR (formats 8, 10).
    pub fn has_nir(&self) -> bool {
        self.items.nir
    }

    /// Decodes chunk `index` (of [`LayeredLaz::chunks`]) from `bytes` (its
    /// [`LayeredLaz::chunk_bytes`] bytes, starting at its offset),
    /// appending its points to `out`.
    pub fn decode_chunk(
        &self,
        index: usize,
        bytes: &[u8],
        out: &mut Vec<Point14>,
    ) -> Result<(), Laz14Error> {
        let (span, err) = chunk_at(&self.chunks, index)?;
        let items = self.items;
        // the walk in `new` checked that the header and layers fit
        let p = 0usize;
        let record = bytes
            .get(p..p + items.record())
            .ok_or_else(|| err("the chunk is truncated".into()))?;
        let raw: &[u8; POINT_BYTES] = record[..POINT_BYTES]
            .try_into()
            .map_err(|_| err("the chunk is truncated".into()))?;
        let mut first = Point14::from_record(raw);
        let u16_of = |k: usize| u16_at(record, k).unwrap_or(0);
        if items.rgb {
            first.rgb = [u16_of(30), u16_of(32), u16_of(34)];
        }
        if items.nir {
            first.nir = u16_of(36);
        }
        let sizes_at = p + items.record() + 4;
        let mut layer_at = sizes_at + 4 * items.layers();
        let mut layers: Vec<&[u8]> = Vec::with_capacity(items.layers());
        for l in 0..items.layers() {
            let size = u32_at(bytes, sizes_at + 4 * l).unwrap_or(0) as usize;
            let layer = bytes
                .get(layer_at..layer_at + size)
                .ok_or_else(|| err("the chunk's layers run past the data".into()))?;
            layers.push(layer);
            layer_at += size;
        }
        let open = |l: usize| -> Result<Option<Decoder<'_>>, Laz14Error> {
            if layers[l].is_empty() {
                return Ok(None);
            }
            Decoder::new(layers[l]).map(Some).map_err(|_| {
                let name = NAMES.get(l).copied().unwrap_or(if l == POINT_LAYERS { "RGB" } else { "NIR" });
                err(format!("its {name} layer ({} bytes) is shorter than 4 bytes or starts with a value no encoder writes; the file is damaged", layers[l].len()))
            })
        };
        if span.points == 1 {
            out.push(first);
            return Ok(());
        }
        let xy = open(0)?.ok_or_else(|| {
            err("its channel/returns/XY layer is empty, but the chunk has more than one point; the file is damaged".into())
        })?;
        let mut pl = Layers {
            xy,
            z: open(1)?,
            classification: open(2)?,
            flags: open(3)?,
            intensity: open(4)?,
            scan_angle: open(5)?,
            user_data: open(6)?,
            point_source: open(7)?,
            gps_time: open(8)?,
        };
        let mut rgb_layer = if items.rgb { open(POINT_LAYERS)? } else { None };
        let mut nir_layer = if items.nir {
            open(POINT_LAYERS + 1)?
        } else {
            None
        };
        let context = usize::from(first.scanner_channel());
        let mut points = PointDecoder::new(&first);
        let mut rgb = RgbDecoder::new(first.rgb, context, items.version4);
        let mut nir = NirDecoder::new(first.nir, context, items.version4);
        out.reserve(span.points.min(1 << 16) as usize);
        out.push(first);
        let mut point = first;
        for k in 1..span.points {
            let fail = |f: Fault| {
                err(point_fault(
                    f,
                    span.first_point + k,
                    "a layer ends before it, or holds data no encoder writes",
                ))
            };
            let switched = points.next(&mut pl, &mut point).map_err(fail)?;
            // version 3 hands the colour items the new channel only on the
            // point where it changes (channel 0 otherwise), version 4 always
            let context = if items.version4 || switched {
                points.channel()
            } else {
                0
            };
            if items.rgb {
                point.rgb = rgb.next(rgb_layer.as_mut(), context).map_err(fail)?;
            }
            if items.nir {
                point.nir = nir.next(nir_layer.as_mut(), context).map_err(fail)?;
            }
            out.push(point);
        }
        Ok(())
    }
}
