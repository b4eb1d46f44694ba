//! Layered LAZ test files: generated LAS 1.4 points (formats 6-10) that
//! exercise every coding path of the point-14, RGB and NIR layers, written
//! by the `laz` crate's compressor, and both decoders run on them. Shared by
//! `tests/laz14.rs` and `benches/laz14.rs`.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::io::{Cursor, Seek, SeekFrom};

use laz::las::{Point10, Point6, Point7, Point8, Point9};
use laz::{LasZipCompressor, LasZipDecompressor, LazItemRecordBuilder, LazVlr, LazVlrBuilder};
use scanfit_io::laz14::{ChunkSpan, LayeredLaz, Laz14Error, Point14};

/// xorshift64*: deterministic test data
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    pub fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }
}

/// A generated scan, shared by the pointwise and the layered generators:
/// a seeded random walk of the position, four GPS-time sequences, and the
/// attributes that change from point to point. Each generator draws its
/// format's own fields from `rng` between these steps.
pub struct Scan {
    pub rng: Rng,
    times: [f64; 4],
    seq: usize,
    xyz: [i32; 3],
    pub class: u8,
    pub flags: u8,
    pub source: u16,
    pub angle: i16,
    pub user: u8,
    pub rgb: [u16; 3],
}

impl Scan {
    /// A scan from `seed` whose four GPS-time sequences start at `times`.
    pub fn new(seed: u64, times: [f64; 4]) -> Self {
        Self {
            rng: Rng(seed | 1),
            times,
            seq: 0,
            xyz: [1000, -2000, 500],
            class: 2,
            flags: 0,
            source: 7,
            angle: 0,
            user: 0,
            rgb: [1000, 2000, 3000],
        }
    }

    /// A pulse's number of returns: 1 to 5, in 3 % of pulses 6 to 5 + `more`.
    pub fn returns(&mut self, more: u64) -> u8 {
        if self.rng.chance(3) {
            6 + self.rng.below(more) as u8
        } else {
            1 + self.rng.below(5) as u8
        }
    }

    /// Moves to the next pulse's GPS time: in 2 % of pulses a jump to a new
    /// far time (a new sequence), in 3 % back to another sequence, in
    /// `repeat` % the time repeated, in 5 % a step of up to 3 s, otherwise a
    /// step of 10 µs. Returns the time.
    pub fn pulse_time(&mut self, repeat: u64) -> f64 {
        let rng = &mut self.rng;
        match rng.below(100) {
            0..=1 => {
                // a jump to a new far time (a new sequence)
                self.seq = (self.seq + 1) % 4;
                self.times[self.seq] += 1.0e7 * (1 + rng.below(50)) as f64;
            }
            2..=4 => self.seq = rng.below(4) as usize, // back to another sequence
            d if d < 5 + repeat => {}                  // time repeated
            d if d < 10 + repeat => self.times[self.seq] += 0.001 * rng.below(3000) as f64,
            _ => self.times[self.seq] += 1.0e-5,
        }
        self.times[self.seq]
    }

    /// Moves to return `r` of the pulse and changes the attributes, drawing
    /// new flags with `flags` and a new scan angle with `angle`.
    pub fn next_return(&mut self, r: u8, flags: fn(&mut Rng) -> u8, angle: fn(&mut Rng) -> i16) {
        let rng = &mut self.rng;
        let [x, y, z] = &mut self.xyz;
        *x = x.wrapping_add(rng.below(400) as i32 - 200);
        *y = y.wrapping_add(if rng.chance(2) {
            1 << 20
        } else {
            rng.below(60) as i32 - 30
        });
        *z = z.wrapping_add(rng.below(100) as i32 - 50 - 20 * i32::from(r));
        if rng.chance(10) {
            self.class = [1, 2, 3, 5, 6, 9, 17, 64, 200][rng.below(9) as usize];
        }
        if rng.chance(5) {
            self.flags = flags(rng);
        }
        if rng.chance(4) {
            self.source = rng.below(65536) as u16;
        }
        if rng.chance(30) {
            self.angle = angle(rng);
        }
        if rng.chance(5) {
            self.user = rng.below(256) as u8;
        }
        if rng.chance(40) {
            if rng.chance(30) {
                let g = rng.below(65536) as u16;
                self.rgb = [g, g, g];
            } else {
                for c in &mut self.rgb {
                    *c = c.wrapping_add(rng.below(600) as u16).wrapping_sub(300);
                }
            }
        }
    }

    /// The first 14 bytes of a record of return `r`, with a new intensity:
    /// X, Y, Z and the intensity.
    pub fn head(&mut self, r: u8) -> [u8; 14] {
        let intensity = (self.rng.below(4000) + 100 * u64::from(r)) as u16;
        let mut head = [0u8; 14];
        for (k, v) in self.xyz.iter().enumerate() {
            head[4 * k..4 * k + 4].copy_from_slice(&v.to_le_bytes());
        }
        head[12..14].copy_from_slice(&intensity.to_le_bytes());
        head
    }
}

/// The 29 bytes of a wave packet of return `r`: descriptor, byte offset,
/// size 256, return point and dx dy dz.
pub fn wave_packet(descriptor: u8, offset: u64, r: u8) -> [u8; 29] {
    let mut w = [0u8; 29];
    w[0] = descriptor;
    w[1..9].copy_from_slice(&offset.to_le_bytes());
    w[9..13].copy_from_slice(&256u32.to_le_bytes());
    for (j, v) in [f32::from(r), 0.5, -0.25, 1.0].iter().enumerate() {
        w[13 + 4 * j..17 + 4 * j].copy_from_slice(&v.to_le_bytes());
    }
    w
}

/// Raw LAS records of `format` (6 to 10): `n` points from `seed`.
pub fn records(format: u8, n: usize, seed: u64) -> Vec<u8> {
    let len = record_len(format);
    let mut scan = Scan::new(seed, [1.0e8, 3.0e8, 5.5e8, 7.0e8]);
    let mut out = Vec::with_capacity(n * len);
    let mut channel = 0u8;
    let mut nir = 4000u16;
    let mut k = 0;
    while k < n {
        // one pulse: 1 to 5 returns (sometimes up to 15), one GPS time
        let returns = scan.returns(10);
        if scan.rng.chance(8) {
            channel = scan.rng.below(4) as u8;
        }
        let time = scan.pulse_time(5);
        for r in 1..=returns {
            if k == n {
                break;
            }
            scan.next_return(
                r,
                |rng| rng.below(256) as u8,
                |rng| (rng.below(60001) as i32 - 30000) as i16,
            );
            if scan.rng.chance(30) {
                nir = nir
                    .wrapping_add(scan.rng.below(2000) as u16)
                    .wrapping_sub(1000);
            }
            let mut rec = vec![0u8; len];
            rec[..14].copy_from_slice(&scan.head(r));
            rec[14] = (r & 0x0f) | (returns << 4);
            rec[15] = (scan.flags & 0xcf) | (channel << 4);
            rec[16] = scan.class;
            rec[17] = scan.user;
            rec[18..20].copy_from_slice(&scan.angle.to_le_bytes());
            rec[20..22].copy_from_slice(&scan.source.to_le_bytes());
            rec[22..30].copy_from_slice(&time.to_le_bytes());
            if matches!(format, 7 | 8 | 10) {
                for (c, v) in scan.rgb.iter().enumerate() {
                    rec[30 + 2 * c..32 + 2 * c].copy_from_slice(&v.to_le_bytes());
                }
            }
            if matches!(format, 8 | 10) {
                rec[36..38].copy_from_slice(&nir.to_le_bytes());
            }
            // wave packet (formats 9, 10; not decoded by us, only skipped)
            // at a growing offset
            if matches!(format, 9 | 10) {
                let d = 1 + scan.rng.below(3) as u8;
                rec[len - 29..].copy_from_slice(&wave_packet(d, 256 * k as u64, r));
            }
            out.extend_from_slice(&rec);
            k += 1;
        }
    }
    out
}

pub fn record_len(format: u8) -> usize {
    match format {
        6 => 30,
        7 => 36,
        8 => 38,
        9 => 59,
        10 => 67,
        _ => unreachable!(),
    }
}

fn items(format: u8, version4: bool) -> Vec<laz::LazItem> {
    match (format, version4) {
        (6, false) => LazItemRecordBuilder::version_3_of::<Point6>(0),
        (7, false) => LazItemRecordBuilder::version_3_of::<Point7>(0),
        (8, false) => LazItemRecordBuilder::version_3_of::<Point8>(0),
        (9, false) => LazItemRecordBuilder::version_3_of::<Point9>(0),
        (10, false) => LazItemRecordBuilder::version_3_of::<Point10>(0),
        (6, true) => LazItemRecordBuilder::version_4_of::<Point6>(0),
        (7, true) => LazItemRecordBuilder::version_4_of::<Point7>(0),
        (8, true) => LazItemRecordBuilder::version_4_of::<Point8>(0),
        _ => unreachable!(),
    }
}

/// How the compressor cuts chunks.
#[derive(Clone, Copy)]
pub enum Chunks {
    Fixed(u32),
    /// variable-size chunks of these point counts, cycled
    Variable(&'static [usize]),
}

/// A whole LAS 1.4 LAZ file: a 375-byte header, the LASzip VLR, the
/// compressed points (and their chunk table), written by the laz crate.
pub struct Laz {
    pub bytes: Vec<u8>,
    pub vlr: LazVlr,
    pub vlr_payload: Vec<u8>,
    pub start: u64,
}

impl Laz {
    /// The file a compressor wrote into `file` after its head, the points
    /// starting at `start`, compressed as `vlr` (of payload `payload`) says.
    pub fn written(file: Cursor<Vec<u8>>, vlr: LazVlr, payload: Vec<u8>, start: u64) -> Self {
        Laz {
            bytes: file.into_inner(),
            vlr,
            vlr_payload: payload,
            start,
        }
    }
}

/// The LASzip VLR of `items` cut into `chunks`, and its payload bytes.
pub fn laszip_vlr(items: Vec<laz::LazItem>, chunks: Chunks) -> (LazVlr, Vec<u8>) {
    let builder = LazVlrBuilder::new(items);
    let vlr = match chunks {
        Chunks::Fixed(c) => builder.with_fixed_chunk_size(c),
        Chunks::Variable(_) => builder.with_variable_chunk_size(),
    }
    .build();
    let mut payload = Vec::new();
    vlr.write_to(&mut payload).unwrap();
    (vlr, payload)
}

/// `header` followed by the LASzip VLR (its 54-byte VLR header and
/// `payload`).
pub fn with_laszip_vlr(mut header: Vec<u8>, payload: &[u8]) -> Vec<u8> {
    let mut vh = vec![0u8; 54];
    vh[2..16].copy_from_slice(b"laszip encoded");
    vh[18..20].copy_from_slice(&22204u16.to_le_bytes());
    vh[20..22].copy_from_slice(&(payload.len() as u16).to_le_bytes());
    header.extend_from_slice(&vh);
    header.extend_from_slice(payload);
    header
}

/// A whole LAZ file: `head` (the LAS header and the LASzip VLR, ending
/// where the points start), then the records `raw` of `len` bytes
/// compressed by the laz crate in `chunks` (and the chunk table).
pub fn write_points(
    head: Vec<u8>,
    vlr: LazVlr,
    payload: Vec<u8>,
    chunks: Chunks,
    raw: &[u8],
    len: usize,
) -> Laz {
    let start = head.len() as u64;
    let mut cursor = Cursor::new(head);
    cursor.seek(SeekFrom::End(0)).unwrap();
    let mut c = LasZipCompressor::new(cursor, vlr.clone()).unwrap();
    match chunks {
        Chunks::Fixed(_) => c.compress_many(raw).unwrap(),
        Chunks::Variable(sizes) => {
            let mut at = 0;
            for &s in sizes.iter().cycle() {
                if at == raw.len() {
                    break;
                }
                let end = (at + s * len).min(raw.len());
                c.compress_many(&raw[at..end]).unwrap();
                c.finish_current_chunk().unwrap();
                at = end;
            }
        }
    }
    c.done().unwrap();
    Laz::written(c.into_inner(), vlr, payload, start)
}

/// A LAS header of version 1.`minor` (`size` bytes) for records of
/// `len` bytes of `format` (with bit 7 set for LAZ), the points at `start`
/// after `vlrs` VLRs, scale factors 0.01, 0.01, 0.001 and offsets 1e5,
/// 2e5, 3e5. The point count is left for the caller to set.
pub fn las_header(minor: u8, size: u16, format: u8, len: usize, start: u64, vlrs: u32) -> Vec<u8> {
    let mut h = vec![0u8; usize::from(size)];
    h[0..4].copy_from_slice(b"LASF");
    h[24] = 1;
    h[25] = minor;
    h[94..96].copy_from_slice(&size.to_le_bytes());
    h[96..100].copy_from_slice(&(start as u32).to_le_bytes());
    h[100..104].copy_from_slice(&vlrs.to_le_bytes());
    h[104] = format;
    h[105..107].copy_from_slice(&(len as u16).to_le_bytes());
    for (k, s) in [0.01f64, 0.01, 0.001].iter().enumerate() {
        h[131 + 8 * k..139 + 8 * k].copy_from_slice(&s.to_le_bytes());
        h[155 + 8 * k..163 + 8 * k].copy_from_slice(&(1.0e5 * (k + 1) as f64).to_le_bytes());
    }
    h
}

pub fn compress(format: u8, version4: bool, chunks: Chunks, raw: &[u8]) -> Laz {
    let (vlr, payload) = laszip_vlr(items(format, version4), chunks);
    let len = record_len(format);
    let n = (raw.len() / len) as u64;
    let start = 375 + 54 + payload.len() as u64;
    let mut h = las_header(4, 375, format | 0x80, len, start, 1);
    h[247..255].copy_from_slice(&n.to_le_bytes());
    let head = with_laszip_vlr(h, &payload);
    write_points(head, vlr, payload, chunks, raw, len)
}

/// The records as the laz crate decodes them.
pub fn laz_decode(f: &Laz, n: usize, len: usize) -> Vec<u8> {
    let mut src = Cursor::new(&f.bytes);
    src.set_position(f.start);
    let mut d = LasZipDecompressor::new(src, f.vlr.clone()).unwrap();
    let mut out = vec![0u8; n * len];
    d.decompress_many(&mut out).unwrap();
    out
}

/// The point-14 fields (plus RGB and NIR) of raw records.
pub fn fields(raw: &[u8], format: u8) -> Vec<Point14> {
    raw.chunks_exact(record_len(format))
        .map(|r| {
            let mut p = Point14::from_record(r[..30].try_into().unwrap());
            let u16_at = |k: usize| u16::from_le_bytes([r[k], r[k + 1]]);
            if matches!(format, 7 | 8 | 10) {
                p.rgb = [u16_at(30), u16_at(32), u16_at(34)];
            }
            if matches!(format, 8 | 10) {
                p.nir = u16_at(36);
            }
            p
        })
        .collect()
}

pub fn table_end(f: &Laz) -> u64 {
    let s = f.start as usize;
    u64::from_le_bytes(f.bytes[s..s + 8].try_into().unwrap())
}

/// The chunk table as (points, bytes) per chunk.
pub fn table(f: &Laz) -> Vec<(u64, u64)> {
    let mut c = Cursor::new(&f.bytes);
    c.set_position(f.start);
    let t = laz::laszip::ChunkTable::read_from(&mut c, &f.vlr).unwrap();
    (0..t.len())
        .map(|k| (t[k].point_count, t[k].byte_count))
        .collect()
}

/// Every chunk of `f` (`spans`, chunk `c` of `size(c)` bytes) decoded
/// with `decode`, in file order.
pub fn each_chunk<T>(
    f: &Laz,
    spans: &[ChunkSpan],
    size: impl Fn(usize) -> u64,
    decode: impl Fn(usize, &[u8], &mut Vec<T>) -> Result<(), Laz14Error>,
) -> Vec<T> {
    let mut out = Vec::new();
    for (c, span) in spans.iter().enumerate() {
        let at = span.offset as usize;
        decode(c, &f.bytes[at..at + size(c) as usize], &mut out).unwrap();
    }
    out
}

/// Ours, chunk by chunk.
pub fn ours(f: &Laz, n: u64, variable: bool) -> (Vec<Point14>, usize) {
    let table = variable.then(|| table(f).iter().map(|t| t.0).collect::<Vec<_>>());
    let read = |at: u64, n: usize| {
        let at = at as usize;
        f.bytes.get(at..at + n).map(<[u8]>::to_vec)
    };
    let file = LayeredLaz::new(
        &read,
        &f.vlr_payload,
        375 + 54,
        f.start,
        table_end(f),
        n,
        table.as_deref(),
    )
    .unwrap();
    let out = each_chunk(
        f,
        file.chunks(),
        |c| file.chunk_bytes(c),
        |c, b, out| file.decode_chunk(c, b, out),
    );
    (out, file.chunks().len())
}
