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
use laz_gen::{
    each_chunk, las_header, laszip_vlr, wave_packet, with_laszip_vlr, write_points, Scan,
};
pub use laz_gen::{table, table_end, Chunks, Laz};

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
    let mut scan = Scan::new(seed, [2.0e8, 4.0e8, 6.5e8, 8.0e8]);
    let mut out = Vec::with_capacity(n * len);
    let mut bytes = vec![0u8; extra];
    let mut k = 0;
    while k < n {
        // one pulse: 1 to 5 returns (sometimes up to 7), one GPS time
        let returns = scan.returns(2);
        let time = scan.pulse_time(10);
        for r in 1..=returns {
            if k == n {
                break;
            }
            scan.next_return(
                r,
                |rng| (rng.below(4) as u8) << 6,
                |rng| rng.below(181) as i16 - 90,
            );
            for b in &mut bytes {
                if scan.rng.chance(20) {
                    *b = b.wrapping_add(scan.rng.below(7) as u8);
                }
            }
            let mut rec = vec![0u8; len];
            rec[..14].copy_from_slice(&scan.head(r));
            rec[14] = (r & 7) | ((returns & 7) << 3) | scan.flags;
            rec[15] = scan.class;
            rec[16] = scan.angle as i8 as u8;
            rec[17] = scan.user;
            rec[18..20].copy_from_slice(&scan.source.to_le_bytes());
            let mut at = 20;
            if has_gps(format) {
                rec[at..at + 8].copy_from_slice(&time.to_le_bytes());
                at += 8;
            }
            if has_rgb(format) {
                for (c, v) in scan.rgb.iter().enumerate() {
                    rec[at + 2 * c..at + 2 + 2 * c].copy_from_slice(&v.to_le_bytes());
                }
                at += 6;
            }
            if has_wave(format) {
                // the offset: the same, after the last, a jump or raw
                let d = 1 + scan.rng.below(3) as u8;
                let offset = match scan.rng.below(4) {
                    0 => 256 * k as u64,
                    1 => 256 * k as u64 + 7,
                    2 => 1 << 40,
                    // (the laz encoder subtracts offsets as i64: keep them below 2^60)
                    _ => scan.rng.next() >> 4,
                };
                rec[at..at + 29].copy_from_slice(&wave_packet(d, offset, r));
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

/// The LAS 1.2 header of a file of `n` records of `format` with `len`
/// bytes, points at `start` after `vlrs` VLRs.
pub fn las12_header(format: u8, len: usize, n: u64, start: u64, vlrs: u32) -> Vec<u8> {
    let mut h = las_header(2, 227, format, len, start, vlrs);
    h[107..111].copy_from_slice(&(n as u32).to_le_bytes());
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
    Laz::written(c.into_inner(), vlr, payload, start)
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

/// Ours, chunk by chunk.
pub fn ours(f: &Laz, n: u64) -> (Vec<PointwiseRecord>, usize) {
    let t = table(f);
    let file =
        PointwiseLaz::new(&f.vlr_payload, 227 + 54, f.start, table_end(f), n, Some(&t)).unwrap();
    let out = each_chunk(
        f,
        file.chunks(),
        |c| file.chunk_bytes(c),
        |c, b, out| file.decode_chunk(c, b, out),
    );
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
