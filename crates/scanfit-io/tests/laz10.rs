//! scanfit's pointwise-LAZ decoder (`scanfit_io::laz14::PointwiseLaz`,
//! point formats 0-5, items of version 2) against the `laz` crate's, bit
//! for bit: files of every format (and with extra bytes) are compressed
//! here with `laz::LasZipCompressor` (fixed chunks with a partial last
//! chunk, variable chunks of 1, 2, 700 and 1234 points) from generated
//! points that exercise every coding path (multiple returns, GPS time
//! repeats, steps, jumps to new sequences and returns to earlier ones,
//! changing classification, scan direction and edge flags, intensity,
//! scan angle, user data, point source, RGB including grey, wave packets
//! whose offsets repeat, follow, jump and are raw, extra bytes), then
//! decoded by both.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use scanfit_io::laz14::{PointwiseLaz, PointwiseRecord};
use scanfit_io::{parse_cloud, ReadOptions};

#[path = "support/laz10_gen.rs"]
mod laz10_gen;
use laz10_gen::laz_gen::laz_decode;
use laz10_gen::{compress, compress_single, fields, ours, record_len, records, Chunks};
#[path = "support/laz_compare.rs"]
mod laz_compare;
use laz_compare::TestResult;

fn same(a: &[PointwiseRecord], b: &[PointwiseRecord], what: &str) {
    laz_compare::same(a, b, |p| p.gps_time, what);
}

fn check(format: u8, extra: usize, chunks: Chunks, n: usize, seed: u64) -> usize {
    let raw = records(format, extra, n, seed);
    let f = compress(format, extra, chunks, &raw);
    let len = record_len(format, extra);
    let theirs = laz_decode(&f, n, len);
    assert_eq!(theirs, raw, "the laz crate round trip (format {format})");
    let (mine, chunks) = ours(&f, n as u64);
    same(
        &mine,
        &fields(&theirs, format, extra),
        &format!("format {format}, {extra} extra bytes"),
    );
    chunks
}

#[test]
fn formats_0_to_5_match_laz_with_fixed_chunks_and_a_partial_last_chunk() {
    for format in 0..=5u8 {
        assert_eq!(
            check(format, 0, Chunks::Fixed(1000), 4321, 11 + u64::from(format)),
            5
        );
    }
}

#[test]
fn extra_bytes_match_laz() {
    check(1, 3, Chunks::Fixed(1500), 4000, 33);
    check(5, 2, Chunks::Fixed(1500), 3000, 34);
}

#[test]
fn variable_chunks_match_laz() {
    // chunks of 1 point (nothing decoded after the raw record), 2, 700, 1234
    assert_eq!(
        check(3, 0, Chunks::Variable(&[1, 2, 700, 1234]), 3000, 44),
        8
    );
}

#[test]
fn many_seeds_of_format_3_match_laz() {
    for seed in 100..110 {
        check(3, 0, Chunks::Fixed(600), 1500, seed);
    }
}

/// The reader (`parse_cloud`) on LAZ files of formats 0-5 gives the
/// columns and coordinates the las crate gives, value for value.
#[test]
fn the_reader_uses_the_decoder_and_matches_the_las_crate() -> TestResult {
    for format in 0..=5u8 {
        let n = 2500;
        let raw = records(format, 0, n, 88 + u64::from(format));
        let f = compress(format, 0, Chunks::Fixed(1000), &raw);
        let names =
            laz_compare::reader_matches_the_las_crate(&f.bytes, n, &format!("format {format}"))?;
        // GPS time in 1, 3, 4, 5; RGB in 2, 3, 5
        assert_eq!(names.len(), [5, 6, 8, 9, 6, 9][usize::from(format)]);
    }
    Ok(())
}

/// A LAZ file of version-1 items (LASzip 1.x) is still read (through the
/// `laz` crate, whose version-1 GPS decoder does not recurse).
#[test]
fn version_1_items_are_read_through_the_laz_crate() {
    let n = 1200;
    let raw = records(1, 0, n, 5);
    let bytes = laz10_gen::compress_v1(n, 500);
    let table = parse_cloud(Path::new("f.laz"), &bytes, &ReadOptions::default()).unwrap();
    assert_eq!(table.points.len(), n);
    let gps = table.columns.iter().position(|c| c == "gps_time").unwrap() - 3;
    for (k, r) in raw.chunks_exact(28).enumerate() {
        let t = f64::from_le_bytes(r[20..28].try_into().unwrap());
        assert_eq!(table.extra[gps][k].to_bits(), t.to_bits(), "point {k}");
    }
}

/// Writes small pointwise LAZ seeds for the laz and las_stream fuzz targets
/// (formats 1 and 3 with GPS-time jumps and returns to earlier sequences,
/// format 5 with wave packets and extra bytes, format 3 with compressor 1)
/// into `$SCANFIT_SEED_DIR`:
/// `SCANFIT_SEED_DIR=fuzz/corpus/laz cargo test -p scanfit-io --test laz10 -- --ignored write_fuzz_seeds`
/// (and again with `fuzz/corpus/las_stream`)
#[test]
#[ignore = "writes fuzz seeds; run by hand"]
fn write_fuzz_seeds() {
    let dir = std::path::PathBuf::from(std::env::var_os("SCANFIT_SEED_DIR").unwrap());
    for (name, format, extra, n, chunk, seed) in [
        ("pointwise1.laz", 1u8, 0usize, 40usize, 16u32, 3u64),
        ("pointwise3.laz", 3, 0, 40, 16, 4),
        ("pointwise5-extra.laz", 5, 2, 24, 12, 5),
    ] {
        let raw = records(format, extra, n, seed);
        let f = compress(format, extra, Chunks::Fixed(chunk), &raw);
        std::fs::write(dir.join(name), &f.bytes).unwrap();
    }
    // compressor 1: all points one chunk without a chunk table, the case
    // the streamed reader's cursor suspends and resumes
    let raw = records(3, 0, 60, 6);
    let f = compress_single(3, 0, &raw);
    std::fs::write(dir.join("pointwise3-compressor1.laz"), &f.bytes).unwrap();
}

/// Writes the GPS-switch recursion input (see `laz10_gen::gps_switches`) to
/// `$SCANFIT_SEED_DIR/gps-time-switches-pointwise.laz`.
#[test]
#[ignore = "writes a regression input; run by hand"]
fn write_gps_switch_input() {
    let dir = std::path::PathBuf::from(std::env::var_os("SCANFIT_SEED_DIR").unwrap());
    std::fs::write(
        dir.join("gps-time-switches-pointwise.laz"),
        laz10_gen::gps_switches(1_000_000),
    )
    .unwrap();
}

/// Finding 5 of `docs/robustness.md`: a 429-byte format-1 file whose second
/// point's GPS time is a million "switch sequence" symbols (written by
/// `write_gps_switch_input`). The laz crate's version-2 GPS decoder
/// recursed once per switch and overflowed the stack (SIGSEGV: exit 139,
/// no message); the reader now refuses it with one error naming the chunk
/// and the point, and the points before it decode as written.
#[test]
fn the_pointwise_gps_time_recursion_input_is_a_clear_error() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/laz/gps-time-switches-pointwise.laz");
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(bytes, laz10_gen::gps_switches(1_000_000));
    let e = parse_cloud(Path::new("f.laz"), &bytes, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("LAZ chunk 0 (points 0 to 1): point 1 cannot be decoded: its GPS time switches sequences more often than there are sequences"),
        "{e}"
    );
    // four switches (one per sequence) are followed; the time is the
    // first sequence's again, unchanged
    let ok = parse_cloud(
        Path::new("f.laz"),
        &laz10_gen::gps_switches(4),
        &ReadOptions::default(),
    )
    .unwrap();
    let gps = ok.columns.iter().position(|c| c == "gps_time").unwrap() - 3;
    assert_eq!(ok.extra[gps], [1.0e8, 1.0e8]);
}

/// Compressor 1 (pointwise, no chunk table: all points one arithmetic-coded
/// chunk) decodes as the laz crate decodes it, and a cursor taking any
/// number of points at a time through a window of any size gives the same
/// points bit for bit, while the window it holds stays at its size (never
/// grows with the chunk): the resumable decoder behind the streamed reader.
#[test]
fn compressor_1_resumes_anywhere_with_a_bounded_window() {
    for (format, extra, n) in [(1u8, 0usize, 6000usize), (3, 0, 5000), (5, 2, 3000)] {
        let raw = records(format, extra, n, 70 + u64::from(format));
        let f = compress_single(format, extra, &raw);
        let theirs = laz_decode(&f, n, record_len(format, extra));
        assert_eq!(theirs, raw, "the laz crate round trip (format {format})");
        let file = PointwiseLaz::new(
            &f.vlr_payload,
            227 + 54,
            f.start,
            f.bytes.len() as u64,
            n as u64,
            None,
        )
        .unwrap();
        assert_eq!(file.chunks().len(), 1, "compressor 1 is one chunk");
        let at = f.start as usize;
        let mut whole = Vec::new();
        file.decode_chunk(0, &f.bytes[at..], &mut whole).unwrap();
        let what = format!("format {format}, compressor 1");
        same(&whole, &fields(&raw, format, extra), &what);
        let smallest = file.record_len() + file.point_bytes();
        let chunk_bytes = f.bytes.len() - at;
        for (window, take) in [(0usize, 1usize), (0, 7), (3000, 1000), (1 << 20, 64)] {
            let mut cursor = file.cursor_with_window(0, window).unwrap();
            let (mut reads, mut largest_read) = (0usize, 0usize);
            let mut read = |offset: u64, buf: &mut [u8]| {
                reads += 1;
                largest_read = largest_read.max(buf.len());
                let o = offset as usize;
                buf.copy_from_slice(&f.bytes[o..o + buf.len()]);
                true
            };
            let mut streamed = Vec::new();
            let mut batch = Vec::new();
            let mut held = 0;
            loop {
                batch.clear();
                let got = file
                    .decode(&mut cursor, &mut read, take, &mut batch)
                    .unwrap();
                if got == 0 {
                    break;
                }
                assert!(got <= take);
                held = held.max(cursor.buffer_capacity());
                streamed.extend_from_slice(&batch);
            }
            let size = window.max(smallest);
            same(
                &streamed,
                &whole,
                &format!("{what}, window {window}, {take} at a time"),
            );
            assert!(
                held <= size,
                "{what}: window of {held} bytes, more than {size}"
            );
            assert!(largest_read <= size);
            assert_eq!(cursor.buffer_capacity(), 0, "released at the end");
            // the chunk did not fit: the decoder was suspended and resumed
            if size < chunk_bytes {
                assert!(reads >= chunk_bytes / size, "{what}: {reads} reads");
            }
        }
    }
}
