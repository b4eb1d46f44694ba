//! Pointwise LAZ test files (point formats 0-5, LASzip items of version 2):
//! generated records that exercise every coding path of the point-10, GPS
//! time, RGB, wave packet and extra-bytes items, written by the `laz`
//! crate's compressor into a LAS 1.2 file, and both decoders run on them.
//! Shared by `tests/laz10.rs` and the streaming tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::io::{Cursor, Seek, SeekFrom};

use laz::las::{Point0, Point1, Point2, Point3, Point4, Point5};
use laz::record::{RecordCompressor, SequentialPointRecordCompressor};
use laz::{LazItemRecordBuilder, LazVlr};
use scanfit_io::laz14::{Point10, PointwiseLaz, PointwiseRecord};

#[path = "laz_gen.rs"]
pub mod laz_gen;
use laz_gen::{laszip_vlr, with_laszip_vlr, write_points};
pub use laz_gen::{table_end, Chunks, Laz, Rng};

/// Bytes of a record of `format` (0-5) with `extra` extra bytes.
pub fn record_len(format: u8, extra: usize) -> usize {
    [20, 28, 26, 34, 57, 63][usize::from(format)] + extra
}

fn has_gps(format: u8) -> bool {
    matches!(format, 1 | 3 | 4 | 5)
}
fn has_rgb(format: u8) -> bool {
    matches!(format, 2 | 3 | 5)
}
fn has_wave(format: u8) -> bool {
    matches!(format, 4 | 5)
}

/// Raw records of `format` (0 to 5) with `extra` extra bytes: `n` points
/// from `seed`.
pub fn records(format: u8, extra: usize, n: usize, seed: u64) -> Vec<u8> {
    let len = record_len(format, extra);
    let mut rng = Rng(seed | 1);
    let mut out = Vec::with_capacity(n * len);
    let mut times = [2.0e8f64, 4.0e8, 6.5e8, 8.0e8];
    let mut seq = 0usize;
    let (mut x, mut y, mut z) = (1000i32, -2000i32, 500i32);
    let (mut class, mut flags, mut source, mut angle, mut user) = (2u8, 0u8, 7u16, 0i8, 0u8);
    let mut rgb = [1000u16, 2000, 3000];
    let mut bytes = vec![0u8; extra];
    let mut k = 0;
    while k < n {
        // one pulse: 1 to 5 returns (sometimes up to 7), one GPS time
        let returns = if rng.below(100) < 3 {
            6 + rng.below(2) as u8
        } else {
            1 + rng.below(5) as u8
        };
        match rng.below(100) {
            0..=1 => {
                // a jump to a new far time (a new sequence)
                seq = (seq + 1) % 4;
                times[seq] += 1.0e7 * (1 + rng.below(50)) as f64;
            }
            2..=4 => seq = rng.below(4) as usize, // back to another sequence
            5..=14 => {}                          // time repeated
            15..=19 => times[seq] += 0.001 * rng.below(3000) as f64,
            _ => times[seq] += 1.0e-5,
        }
        for r in 1..=returns {
            if k == n {
                break;
            }
            x = x.wrapping_add(rng.below(400) as i32 - 200);
            y = y.wrapping_add(if rng.below(100) < 2 {
                1 << 20
            } else {
                rng.below(60) as i32 - 30
            });
            z = z.wrapping_add(rng.below(100) as i32 - 50 - 20 * i32::from(r));
            if rng.below(100) < 10 {
                class = [1, 2, 3, 5, 6, 9, 17, 64, 200][rng.below(9) as usize];
            }
            if rng.below(100) < 5 {
                flags = (rng.below(4) as u8) << 6;
            }
            if rng.below(100) < 4 {
                source = rng.below(65536) as u16;
            }
            if rng.below(100) < 30 {
                angle = (rng.below(181) as i32 - 90) as i8;
            }
            if rng.below(100) < 5 {
                user = rng.below(256) as u8;
            }
            if rng.below(100) < 40 {
                if rng.below(100) < 30 {
                    let g = rng.below(65536) as u16;
                    rgb = [g, g, g];
                } else {
                    for c in &mut rgb {
                        *c = c.wrapping_add(rng.below(600) as u16).wrapping_sub(300);
                    }
                }
            }
            for b in &mut bytes {
                if rng.below(100) < 20 {
                    *b = b.wrapping_add(rng.below(7) as u8);
                }
            }
            let intensity = (rng.below(4000) + 100 * u64::from(r)) as u16;
            let mut rec = vec![0u8; len];
            rec[0..4].copy_from_slice(&x.to_le_bytes());
            rec[4..8].copy_from_slice(&y.to_le_bytes());
            rec[8..12].copy_from_slice(&z.to_le_bytes());
            rec[12..14].copy_from_slice(&intensity.to_le_bytes());
            rec[14] = (r & 7) | ((returns & 7) << 3) | flags;
            rec[15] = class;
            rec[16] = angle as u8;
            rec[17] = user;
            rec[18..20].copy_from_slice(&source.to_le_bytes());
            let mut at = 20;
            if has_gps(format) {
                rec[at..at + 8].copy_from_slice(&times[seq].to_le_bytes());
                at += 8;
            }
            if has_rgb(format) {
                for (c, v) in rgb.iter().enumerate() {
                    rec[at + 2 * c..at + 2 + 2 * c].copy_from_slice(&v.to_le_bytes());
                }
                at += 6;
            }
            if has_wave(format) {
                // descriptor, offset (same, after the last, a jump), size,
                // return point, dx dy dz
                rec[at] = 1 + rng.below(3) as u8;
                let offset = match rng.below(4) {
                    0 => 256 * k as u64,
                    1 => 256 * k as u64 + 7,
                    2 => 1 << 40,
                    // (the laz encoder subtracts offsets as i64: keep them below 2^60)
                    _ => rng.next() >> 4,
                };
                rec[at + 1..at + 9].copy_from_slice(&offset.to_le_bytes());
                rec[at + 9..at + 13].copy_from_slice(&256u32.to_le_bytes());
                for (j, v) in [r as f32, 0.5, -0.25, 1.0].iter().enumerate() {
                    rec[at + 13 + 4 * j..at + 17 + 4 * j].copy_from_slice(&v.to_le_bytes());
                }
                at += 29;
            }
            rec[at..at + extra].copy_from_slice(&bytes);
            out.extend_from_slice(&rec);
            k += 1;
        }
    }
    out
}

fn items(format: u8, extra: u16) -> Vec<laz::LazItem> {
    match format {
        0 => LazItemRecordBuilder::version_2_of::<Point0>(extra),
        1 => LazItemRecordBuilder::version_2_of::<Point1>(extra),
        2 => LazItemRecordBuilder::version_2_of::<Point2>(extra),
        3 => LazItemRecordBuilder::version_2_of::<Point3>(extra),
        4 => LazItemRecordBuilder::version_2_of::<Point4>(extra),
        5 => LazItemRecordBuilder::version_2_of::<Point5>(extra),
        _ => unreachable!(),
    }
}

/// The LAS 1.2 header (and VLR header) of a file of `n` records of
/// `format` with `len` bytes, points at `start`.
pub fn las12_header(format: u8, len: usize, n: u64, start: u64, vlrs: u32) -> Vec<u8> {
    let mut h = vec![0u8; 227];
    h[0..4].copy_from_slice(b"LASF");
    h[24] = 1;
    h[25] = 2;
    h[94..96].copy_from_slice(&227u16.to_le_bytes());
    h[96..100].copy_from_slice(&(start as u32).to_le_bytes());
    h[100..104].copy_from_slice(&vlrs.to_le_bytes());
    h[104] = format;
    h[105..107].copy_from_slice(&(len as u16).to_le_bytes());
    h[107..111].copy_from_slice(&(n as u32).to_le_bytes());
    for (k, s) in [0.01f64, 0.01, 0.001].iter().enumerate() {
        h[131 + 8 * k..139 + 8 * k].copy_from_slice(&s.to_le_bytes());
        h[155 + 8 * k..163 + 8 * k].copy_from_slice(&(1.0e5 * (k + 1) as f64).to_le_bytes());
    }
    h
}

/// A LAS 1.2 LAZ file of the records `raw` (compressor 2: chunks and a
/// chunk table), written by the laz crate.
pub fn compress(format: u8, extra: usize, chunks: Chunks, raw: &[u8]) -> Laz {
    let (vlr, payload) = laszip_vlr(items(format, extra as u16), chunks);
    let len = record_len(format, extra);
    let n = (raw.len() / len) as u64;
    let start = 227 + 54 + payload.len() as u64;
    let head = with_laszip_vlr(las12_header(format | 0x80, len, n, start, 1), &payload);
    write_points(head, vlr, payload, chunks, raw, len)
}

/// A LAS 1.2 LAZ file of the records `raw` with LASzip's compressor 1
/// (pointwise, no chunk table: the whole point stream one chunk), the
/// records compressed by the laz crate's pointwise record compressor.
pub fn compress_single(format: u8, extra: usize, raw: &[u8]) -> Laz {
    let (_, mut payload) = laszip_vlr(items(format, extra as u16), Chunks::Fixed(50_000));
    payload[0] = 1; // compressor 1: pointwise, one chunk
    let vlr = LazVlr::from_buffer(&payload).unwrap();
    let len = record_len(format, extra);
    let n = (raw.len() / len) as u64;
    let start = 227 + 54 + payload.len() as u64;
    let head = with_laszip_vlr(las12_header(format | 0x80, len, n, start, 1), &payload);
    let mut cursor = Cursor::new(head);
    cursor.seek(SeekFrom::End(0)).unwrap();
    let mut c = SequentialPointRecordCompressor::new(cursor);
    c.set_fields_from(vlr.items()).unwrap();
    c.compress_many(raw).unwrap();
    c.done().unwrap();
    Laz {
        bytes: c.into_inner().into_inner(),
        vlr,
        vlr_payload: payload,
        start,
    }
}

/// The fields scanfit decodes, of raw records.
pub fn fields(raw: &[u8], format: u8, extra: usize) -> Vec<PointwiseRecord> {
    raw.chunks_exact(record_len(format, extra))
        .map(|r| {
            let mut p = PointwiseRecord {
                point: Point10::from_record(r[..20].try_into().unwrap()),
                ..PointwiseRecord::default()
            };
            let mut at = 20;
            if has_gps(format) {
                p.gps_time = f64::from_le_bytes(r[20..28].try_into().unwrap());
                at += 8;
            }
            if has_rgb(format) {
                let c = |k: usize| u16::from_le_bytes([r[at + 2 * k], r[at + 2 * k + 1]]);
                p.rgb = [c(0), c(1), c(2)];
            }
            p
        })
        .collect()
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

/// Ours, chunk by chunk.
pub fn ours(f: &Laz, n: u64) -> (Vec<PointwiseRecord>, usize) {
    let t = table(f);
    let file =
        PointwiseLaz::new(&f.vlr_payload, 227 + 54, f.start, table_end(f), n, Some(&t)).unwrap();
    let mut out = Vec::new();
    for c in 0..file.chunks().len() {
        let at = file.chunks()[c].offset as usize;
        let bytes = &f.bytes[at..at + file.chunk_bytes(c) as usize];
        file.decode_chunk(c, bytes, &mut out).unwrap();
    }
    (out, file.chunks().len())
}

/// A LAS 1.2 LAZ file of `n` format-1 points with items of version 1
/// (LASzip 1.x), in chunks of `chunk` points.
pub fn compress_v1(n: usize, chunk: u32) -> Vec<u8> {
    let raw = records(1, 0, n, 5);
    let chunks = Chunks::Fixed(chunk);
    let (vlr, payload) = laszip_vlr(LazItemRecordBuilder::version_1_of::<Point1>(0), chunks);
    let start = 227 + 54 + payload.len() as u64;
    let head = with_laszip_vlr(las12_header(0x81, 28, n as u64, start, 1), &payload);
    write_points(head, vlr, payload, chunks, &raw, 28).bytes
}

/// A two-point LAZ file of format 1 (compressor 1: one chunk, no chunk
/// table) whose second point's GPS time is `switches` "switch to another
/// sequence" symbols followed by "unchanged": the stream LASzip's version-2
/// GPS decoder follows by recursion, one call per switch. Encoded with the
/// `laz` crate's own arithmetic encoder and models, so the point-10 fields
/// before it decode as written (nothing changed, X, Y and Z differences 0).
pub fn gps_switches(switches: usize) -> Vec<u8> {
    use laz::compressors::IntegerCompressor;
    use laz::encoders::ArithmeticEncoder;
    use laz::models::ArithmeticModelBuilder;
    let mut enc = ArithmeticEncoder::new(Cursor::new(Vec::new()));
    let model = |n: u32| {
        ArithmeticModelBuilder::new(n)
            .with_compression(true)
            .build()
    };
    let ic = |bits, contexts| {
        let mut c = IntegerCompressor::new(bits, contexts, 8, 0);
        c.init();
        c
    };
    let (mut dx, mut dy, mut dz) = (ic(32, 2), ic(32, 22), ic(32, 20));
    // point 2: no field changed, then X, Y, Z (one return of one: n == 1)
    enc.encode_symbol(&mut model(64), 0).unwrap();
    dx.compress(&mut enc, 0, 0, 1).unwrap();
    let k = dx.k();
    dy.compress(&mut enc, 0, 0, 1 + if k < 20 { k & !1 } else { 20 })
        .unwrap();
    let k = (dx.k() + dy.k()) / 2;
    dz.compress(&mut enc, 0, 0, 1 + if k < 18 { k & !1 } else { 18 })
        .unwrap();
    // GPS time: every sequence starts without a difference, so each switch
    // lands on the six-symbol model again
    let mut no_diff = model(6);
    for _ in 0..switches {
        enc.encode_symbol(&mut no_diff, 3).unwrap();
    }
    enc.encode_symbol(&mut no_diff, 0).unwrap();
    enc.done().unwrap();
    let stream = enc.into_inner().into_inner();
    let (_, mut payload) = laszip_vlr(
        LazItemRecordBuilder::version_2_of::<Point1>(0),
        Chunks::Fixed(u32::MAX - 1),
    );
    payload[0] = 1; // compressor 1: pointwise, one chunk
    let start = 227 + 54 + payload.len() as u64;
    let mut f = with_laszip_vlr(las12_header(0x81, 28, 2, start, 1), &payload);
    // the first point raw: X = Y = Z = 0, return 1 of 1, GPS time 1e8
    let mut first = [0u8; 28];
    first[14] = 1 | (1 << 3);
    first[20..28].copy_from_slice(&1.0e8f64.to_le_bytes());
    f.extend_from_slice(&first);
    f.extend_from_slice(&stream);
    f
}
