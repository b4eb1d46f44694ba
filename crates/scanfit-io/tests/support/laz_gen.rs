//! Layered LAZ test files: generated LAS 1.4 points (formats 6-10) that
//! exercise every coding path of the point-14, RGB and NIR layers, written
//! by the `laz` crate's compressor, and both decoders run on them. Shared by
//! `tests/laz14.rs` and `benches/laz14.rs`.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::io::{Cursor, Seek, SeekFrom};

use laz::las::{Point10, Point6, Point7, Point8, Point9};
use laz::{LasZipCompressor, LasZipDecompressor, LazItemRecordBuilder, LazVlr, LazVlrBuilder};
use scanfit_io::laz14::{LayeredLaz, Point14};

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
    fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }
}

/// Raw LAS records of `format` (6 to 10): `n` points from `seed`.
pub fn records(format: u8, n: usize, seed: u64) -> Vec<u8> {
    let len = record_len(format);
    let mut rng = Rng(seed | 1);
    let mut out = Vec::with_capacity(n * len);
    let mut times = [1.0e8f64, 3.0e8, 5.5e8, 7.0e8];
    let mut seq = 0usize;
    let (mut channel, mut x, mut y, mut z) = (0u8, 1000i32, -2000i32, 500i32);
    let (mut class, mut flags, mut source, mut angle, mut user) = (2u8, 0u8, 7u16, 0i16, 0u8);
    let (mut rgb, mut nir) = ([1000u16, 2000, 3000], 4000u16);
    let mut k = 0;
    while k < n {
        // one pulse: 1 to 5 returns (sometimes up to 15), one GPS time
        let returns = if rng.chance(3) {
            6 + rng.below(10) as u8
        } else {
            1 + rng.below(5) as u8
        };
        if rng.chance(8) {
            channel = rng.below(4) as u8;
        }
        match rng.below(100) {
            0..=1 => {
                // a jump to a new far time (a new sequence)
                seq = (seq + 1) % 4;
                times[seq] += 1.0e7 * (1 + rng.below(50)) as f64;
            }
            2..=4 => seq = rng.below(4) as usize, // back to another sequence
            5..=9 => {}                           // time repeated
            10..=14 => times[seq] += 0.001 * rng.below(3000) as f64,
            _ => times[seq] += 1.0e-5,
        }
        for r in 1..=returns {
            if k == n {
                break;
            }
            x = x.wrapping_add(rng.below(400) as i32 - 200);
            y = y.wrapping_add(if rng.chance(2) {
                1 << 20
            } else {
                rng.below(60) as i32 - 30
            });
            z = z.wrapping_add(rng.below(100) as i32 - 50 - 20 * i32::from(r));
            if rng.chance(10) {
                class = [1, 2, 3, 5, 6, 9, 17, 64, 200][rng.below(9) as usize];
            }
            if rng.chance(5) {
                flags = rng.below(256) as u8;
            }
            if rng.chance(4) {
                source = rng.below(65536) as u16;
            }
            if rng.chance(30) {
                angle = (rng.below(60001) as i32 - 30000) as i16;
            }
            if rng.chance(5) {
                user = rng.below(256) as u8;
            }
            if rng.chance(40) {
                if rng.chance(30) {
                    let g = rng.below(65536) as u16;
                    rgb = [g, g, g];
                } else {
                    for c in &mut rgb {
                        *c = c.wrapping_add(rng.below(600) as u16).wrapping_sub(300);
                    }
                }
            }
            if rng.chance(30) {
                nir = nir.wrapping_add(rng.below(2000) as u16).wrapping_sub(1000);
            }
            let intensity = (rng.below(4000) + 100 * u64::from(r)) as u16;
            let mut rec = vec![0u8; len];
            rec[0..4].copy_from_slice(&x.to_le_bytes());
            rec[4..8].copy_from_slice(&y.to_le_bytes());
            rec[8..12].copy_from_slice(&z.to_le_bytes());
            rec[12..14].copy_from_slice(&intensity.to_le_bytes());
            rec[14] = (r & 0x0f) | (returns << 4);
            rec[15] = (flags & 0xcf) | (channel << 4);
            rec[16] = class;
            rec[17] = user;
            rec[18..20].copy_from_slice(&angle.to_le_bytes());
            rec[20..22].copy_from_slice(&source.to_le_bytes());
            rec[22..30].copy_from_slice(&times[seq].to_le_bytes());
            if matches!(format, 7 | 8 | 10) {
                for (c, v) in rgb.iter().enumerate() {
                    rec[30 + 2 * c..32 + 2 * c].copy_from_slice(&v.to_le_bytes());
                }
            }
            if matches!(format, 8 | 10) {
                rec[36..38].copy_from_slice(&nir.to_le_bytes());
            }
            // wave packet (formats 9, 10; not decoded by us, only skipped):
            // descriptor, growing offset, size, return point, dx dy dz
            if matches!(format, 9 | 10) {
                let w = len - 29;
                rec[w] = 1 + rng.below(3) as u8;
                rec[w + 1..w + 9].copy_from_slice(&(256 * k as u64).to_le_bytes());
                rec[w + 9..w + 13].copy_from_slice(&256u32.to_le_bytes());
                for (j, v) in [r as f32, 0.5, -0.25, 1.0].iter().enumerate() {
                    rec[w + 13 + 4 * j..w + 17 + 4 * j].copy_from_slice(&v.to_le_bytes());
                }
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
    Laz {
        bytes: c.into_inner().into_inner(),
        vlr,
        vlr_payload: payload,
        start,
    }
}

pub fn compress(format: u8, version4: bool, chunks: Chunks, raw: &[u8]) -> Laz {
    let (vlr, payload) = laszip_vlr(items(format, version4), chunks);
    let len = record_len(format);
    let n = (raw.len() / len) as u64;
    let start = 375 + 54 + payload.len() as u64;
    let mut h = vec![0u8; 375];
    h[0..4].copy_from_slice(b"LASF");
    h[24] = 1;
    h[25] = 4;
    h[94..96].copy_from_slice(&375u16.to_le_bytes());
    h[96..100].copy_from_slice(&(start as u32).to_le_bytes());
    h[100..104].copy_from_slice(&1u32.to_le_bytes());
    h[104] = format | 0x80;
    h[105..107].copy_from_slice(&(len as u16).to_le_bytes());
    for (k, s) in [0.01f64, 0.01, 0.001].iter().enumerate() {
        h[131 + 8 * k..139 + 8 * k].copy_from_slice(&s.to_le_bytes());
        h[155 + 8 * k..163 + 8 * k].copy_from_slice(&(1.0e5 * (k + 1) as f64).to_le_bytes());
    }
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

/// Ours, chunk by chunk.
pub fn ours(f: &Laz, n: u64, variable: bool) -> (Vec<Point14>, usize) {
    let table = if variable {
        let mut c = Cursor::new(&f.bytes);
        c.set_position(f.start);
        let t = laz::laszip::ChunkTable::read_from(&mut c, &f.vlr).unwrap();
        Some((0..t.len()).map(|k| t[k].point_count).collect::<Vec<_>>())
    } else {
        None
    };
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
    let mut out = Vec::new();
    for c in 0..file.chunks().len() {
        let at = file.chunks()[c].offset as usize;
        let bytes = &f.bytes[at..at + file.chunk_bytes(c) as usize];
        file.decode_chunk(c, bytes, &mut out).unwrap();
    }
    (out, file.chunks().len())
}
