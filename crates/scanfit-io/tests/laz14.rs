//! scanfit's layered-LAZ decoder (`scanfit_io::laz14`) against the `laz`
//! crate's, bit for bit: files of point formats 6, 7, 8, 9 and 10 are
//! compressed here with `laz::LasZipCompressor` (item versions 3 and 4,
//! fixed and variable chunks, a partial last chunk) from generated points
//! that exercise every coding path (four scanner channels, multiple
//! returns, GPS time repeats, steps, jumps and returns to an earlier
//! sequence, changing classification, flags, intensity, scan angle, user
//! data, point source, RGB including grey, NIR), then decoded by both.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use scanfit_io::laz14::Point14;
use scanfit_io::{parse_cloud, ReadOptions};

#[path = "support/laz_gen.rs"]
mod laz_gen;
use laz_gen::{compress, fields, laz_decode, ours, record_len, records, table_end, Chunks, Rng};
#[path = "support/laz_compare.rs"]
mod laz_compare;
use laz_compare::TestResult;

fn same(a: &[Point14], b: &[Point14], what: &str) {
    laz_compare::same(a, b, |p| p.gps_time, what);
}

fn check(format: u8, version4: bool, chunks: Chunks, n: usize, seed: u64) -> usize {
    let raw = records(format, n, seed);
    let f = compress(format, version4, chunks, &raw);
    let len = record_len(format);
    let theirs = laz_decode(&f, n, len);
    assert_eq!(theirs, raw, "the laz crate round trip (format {format})");
    let (mine, chunks) = ours(&f, n as u64, matches!(chunks, Chunks::Variable(_)));
    same(
        &mine,
        &fields(&theirs, format),
        &format!("format {format}, version {}", if version4 { 4 } else { 3 }),
    );
    chunks
}

#[test]
fn format_6_matches_laz_with_fixed_chunks_and_a_partial_last_chunk() {
    assert_eq!(check(6, false, Chunks::Fixed(1000), 4321, 11), 5);
}

#[test]
fn format_7_matches_laz() {
    assert_eq!(check(7, false, Chunks::Fixed(2000), 5003, 22), 3);
}

#[test]
fn format_8_matches_laz() {
    assert_eq!(check(8, false, Chunks::Fixed(1500), 4000, 33), 3);
}

#[test]
fn variable_chunks_match_laz() {
    // chunks of 1 point (no layers decoded), 2, 700 and 1234 points
    assert_eq!(
        check(8, false, Chunks::Variable(&[1, 2, 700, 1234]), 3000, 44),
        8
    );
}

#[test]
fn item_version_4_matches_laz() {
    for format in [6, 7, 8] {
        check(
            format,
            true,
            Chunks::Fixed(900),
            2500,
            55 + u64::from(format),
        );
    }
}

#[test]
fn wave_packet_formats_9_and_10_match_laz_for_the_point_fields() {
    check(9, false, Chunks::Fixed(800), 2000, 66);
    check(10, false, Chunks::Fixed(800), 2000, 77);
}

#[test]
fn many_seeds_of_format_8_match_laz() {
    for seed in 100..110 {
        check(8, false, Chunks::Fixed(600), 1500, seed);
    }
}

/// The reader (`parse_cloud`) on files of formats 6, 7 and 8 gives the
/// columns and coordinates the las crate gives, value for value.
#[test]
fn the_reader_uses_the_decoder_and_matches_the_las_crate() -> TestResult {
    for format in [6, 7, 8] {
        let n = 3000;
        let raw = records(format, n, 88);
        let f = compress(format, false, Chunks::Fixed(1000), &raw);
        let names =
            laz_compare::reader_matches_the_las_crate(&f.bytes, n, &format!("format {format}"))?;
        // GPS time always, RGB in 7 and 8, NIR in 8
        assert_eq!(names.len(), [6, 9, 10][usize::from(format - 6)]);
    }
    Ok(())
}

/// Fuzz finding (laz target, `docs/robustness.md` finding 2): a 993-byte
/// file whose GPS-time layer keeps switching sequences. The laz crate
/// recursed on every switch until the stack overflowed (an abort); the
/// reader now refuses it with one error naming the chunk and the point.
#[test]
fn the_gps_time_recursion_input_is_a_clear_error() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/laz/gps-time-recursion.laz");
    let bytes = std::fs::read(path).unwrap();
    let read = |b: &[u8]| {
        parse_cloud(Path::new("f.laz"), b, &ReadOptions::default())
            .unwrap_err()
            .to_string()
    };
    // its GPS-time layer starts with 0xFFFFFFFF, a value no encoder writes
    let e = read(&bytes);
    assert!(
        e.contains("LAZ chunk 0 (points 0 to 39): its GPS time layer")
            && e.contains("starts with a value no encoder writes"),
        "{e}"
    );
    // with a start the decoder accepts, the switches run on until the
    // bound on sequence switches stops them (or the layer's bytes end)
    let chunk = 477;
    let sizes: Vec<usize> = (0..9)
        .map(|l| u32_le(&bytes, chunk + 34 + 4 * l) as usize)
        .collect();
    let gps = chunk + 34 + 36 + sizes[..8].iter().sum::<usize>();
    let mut variant = bytes.clone();
    variant[gps..gps + 4].copy_from_slice(&[0xff, 0xff, 0xff, 0xfe]);
    let e = read(&variant);
    assert!(e.contains("LAZ chunk 0 (points 0 to 39): point 1 cannot be decoded: its GPS time switches sequences more often than there are sequences"), "{e}");
    // (kept in the replayed corpus too)
    let kept = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/laz/gps-time-switches.laz");
    assert_eq!(std::fs::read(kept).unwrap(), variant);
}

fn u32_le(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// Damaged layers (random bytes changed anywhere in the compressed data of
/// a format 8 file) give an error or points, never a panic, and the
/// decoder reports the chunk it failed in.
#[test]
fn damaged_chunks_are_errors_never_panics() {
    let raw = records(8, 900, 5);
    let f = compress(8, false, Chunks::Fixed(300), &raw);
    let (from, to) = (f.start + 8, table_end(&f));
    let mut rng = Rng(99);
    let mut errors = 0;
    for _ in 0..200 {
        let mut b = f.bytes.clone();
        for _ in 0..1 + rng.below(6) {
            let at = (from + rng.below(to - from)) as usize;
            b[at] = rng.below(256) as u8;
        }
        if let Err(e) = parse_cloud(Path::new("f.laz"), &b, &ReadOptions::default()) {
            let e = e.to_string();
            assert!(e.contains("chunk"), "{e}");
            errors += 1;
        }
    }
    assert!(errors > 0);
}
