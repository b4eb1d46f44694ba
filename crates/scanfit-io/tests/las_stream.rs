//! LAS and LAZ files read in chunks (`PointChunks`, the reader behind
//! `--chunk-points` and `FileSource`) give the one-piece reader's points,
//! columns, point locations and warnings, bit for bit, for every decoder:
//! uncompressed LAS (the `las` crate), pointwise LAZ of item versions 2
//! (scanfit's decoder) and 1 (the `laz` crate), layered LAZ (scanfit's
//! decoder); and a truncated LAZ file fails the same way.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use scanfit_io::chunks::PointChunks;
use scanfit_io::{read_cloud, ReadOptions};

#[path = "support/laz10_gen.rs"]
mod laz10_gen;

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("scanfit-las-stream-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Reads `path` whole and in chunks of `chunk` points; asserts the same
/// points, columns, locations and warnings; returns the chunk sizes.
fn same_streamed(path: &Path, chunk: usize) -> Vec<usize> {
    let options = ReadOptions::default();
    let whole = read_cloud(path, &options).unwrap();
    let mut chunks = PointChunks::open(path, &options, chunk).unwrap();
    assert!(chunks.bounded());
    let mut sizes = Vec::new();
    let mut k = 0;
    while let Some(t) = chunks.next_chunk().unwrap() {
        assert_eq!(t.columns, whole.columns);
        for i in 0..t.points.len() {
            let (p, q) = (t.points[i], whole.points[k]);
            assert_eq!(
                (p.x.to_bits(), p.y.to_bits(), p.z.to_bits()),
                (q.x.to_bits(), q.y.to_bits(), q.z.to_bits()),
                "{}: point {k}",
                path.display()
            );
            for (c, col) in t.extra.iter().enumerate() {
                assert_eq!(
                    col[i].to_bits(),
                    whole.extra[c][k].to_bits(),
                    "point {k}, {}",
                    t.columns[c + 3]
                );
            }
            assert_eq!(t.locate(i), whole.locate(k));
            k += 1;
        }
        sizes.push(t.points.len());
    }
    assert_eq!(k, whole.points.len());
    assert_eq!(chunks.warnings(), &whole.warnings[..]);
    sizes
}

fn laz_file(name: &str, format: u8, extra: usize, chunks: laz10_gen::Chunks, n: usize) -> PathBuf {
    let raw = laz10_gen::records(format, extra, n, 7 + u64::from(format));
    let f = laz10_gen::compress(format, extra, chunks, &raw);
    let path = dir().join(name);
    std::fs::write(&path, &f.bytes).unwrap();
    path
}

#[test]
fn uncompressed_las_streams_as_read_whole() {
    let n = 2345;
    let raw = laz10_gen::records(3, 0, n, 9);
    let len = laz10_gen::record_len(3, 0);
    let mut bytes = laz10_gen::las12_header(3, len, n as u64, 227, 0);
    bytes.extend_from_slice(&raw);
    // one record more than declared: the one-piece reader warns, so must the stream
    bytes.extend_from_slice(&raw[..len]);
    let path = dir().join("f3.las");
    std::fs::write(&path, &bytes).unwrap();
    assert_eq!(same_streamed(&path, 1000), [1000, 1000, 345]);
    assert_eq!(same_streamed(&path, 5000), [2345]);
}

#[test]
fn pointwise_laz_streams_one_laz_chunk_at_a_time() {
    use laz10_gen::Chunks;
    let path = laz_file("p3.laz", 3, 0, Chunks::Fixed(1000), 2500);
    // requested chunks never span two LAZ chunks
    assert_eq!(same_streamed(&path, 600), [600, 400, 600, 400, 500]);
    assert_eq!(same_streamed(&path, 100_000), [1000, 1000, 500]);
    let path = laz_file("p5.laz", 5, 2, Chunks::Variable(&[1, 2, 700]), 1500);
    assert_eq!(same_streamed(&path, 1000).iter().sum::<usize>(), 1500);
}

/// Compressor 1 (pointwise, the whole point stream one LAZ chunk) is read
/// a requested chunk at a time, not one LAZ chunk (all points) at a time:
/// the points, columns, locations and warnings are the one-piece reader's.
#[test]
fn a_compressor_1_laz_file_streams_in_requested_chunks() {
    for (format, extra) in [(1u8, 0usize), (5, 2)] {
        let n = 4000;
        let raw = laz10_gen::records(format, extra, n, 17 + u64::from(format));
        let f = laz10_gen::compress_single(format, extra, &raw);
        let path = dir().join(format!("single{format}.laz"));
        std::fs::write(&path, &f.bytes).unwrap();
        assert_eq!(same_streamed(&path, 1500), [1500, 1500, 1000]);
        assert_eq!(same_streamed(&path, 1).len(), n);
    }
}

#[test]
fn layered_laz_streams_one_laz_chunk_at_a_time() {
    use laz10_gen::laz_gen;
    let raw = laz_gen::records(7, 3000, 12);
    let f = laz_gen::compress(7, false, laz_gen::Chunks::Fixed(1100), &raw);
    let path = dir().join("l7.laz");
    std::fs::write(&path, &f.bytes).unwrap();
    assert_eq!(same_streamed(&path, 1000), [1000, 100, 1000, 100, 800]);
}

#[test]
fn a_truncated_laz_file_fails_streamed_as_whole() {
    use laz10_gen::Chunks;
    let path = laz_file("t.laz", 1, 0, Chunks::Fixed(500), 1500);
    let bytes = std::fs::read(&path).unwrap();
    // the last chunk's final 40 bytes overwritten: its points cannot all be decoded
    let cut = dir().join("cut.laz");
    let mut damaged = bytes.clone();
    let at = laz_start(&bytes);
    let table = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    for b in &mut damaged[table - 40..table] {
        *b = 0xff;
    }
    std::fs::write(&cut, &damaged).unwrap();
    let options = ReadOptions::default();
    let whole = read_cloud(&cut, &options).unwrap_err().to_string();
    let mut chunks = PointChunks::open(&cut, &options, 700).unwrap();
    let streamed = loop {
        match chunks.next_chunk() {
            Ok(Some(_)) => continue,
            Ok(None) => panic!("the damaged file was accepted"),
            Err(e) => break e.to_string(),
        }
    };
    assert_eq!(streamed, whole);
    assert!(
        whole.contains("LAZ chunk 2 (points 1000 to 1499)"),
        "{whole}"
    );
}

/// A LAZ header that declares fewer points than its chunk table's chunks
/// hold: the chunks beyond the count are not read, with a warning, read
/// whole and streamed alike (pointwise and layered).
#[test]
fn a_laz_count_below_the_chunk_table_is_a_warning() {
    use laz10_gen::{laz_gen, Chunks};
    let path = laz_file("fewer.laz", 1, 0, Chunks::Fixed(500), 1500);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[107..111].copy_from_slice(&900u32.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    assert_eq!(same_streamed(&path, 700), [500, 400]);
    let w = read_cloud(&path, &ReadOptions::default()).unwrap().warnings;
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].ends_with("the LAZ chunk table lists 3 chunks, but the header's 900 points fill only 2; the points of the other 1 were not read (the header's point count may be too small)"),
        "{w:?}"
    );
    let raw = laz_gen::records(6, 3000, 5);
    let f = laz_gen::compress(6, false, laz_gen::Chunks::Fixed(1000), &raw);
    let mut bytes = f.bytes.clone();
    bytes[247..255].copy_from_slice(&1000u64.to_le_bytes());
    let path = dir().join("fewer6.laz");
    std::fs::write(&path, &bytes).unwrap();
    assert_eq!(same_streamed(&path, 600), [600, 400]);
    let w = read_cloud(&path, &ReadOptions::default()).unwrap().warnings;
    assert!(
        w.len() == 1 && w[0].contains("lists 3 chunks, but the header's 1000 points fill only 1"),
        "{w:?}"
    );
    // the intact files: no warning
    let path = laz_file("intact.laz", 1, 0, Chunks::Fixed(500), 1500);
    assert!(read_cloud(&path, &ReadOptions::default())
        .unwrap()
        .warnings
        .is_empty());
}

/// Offset of the point data of a LAS 1.2 file.
fn laz_start(bytes: &[u8]) -> usize {
    u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize
}

#[test]
fn laz_of_item_version_1_streams_through_the_laz_crate() {
    let path = dir().join("v1.laz");
    std::fs::write(&path, laz10_gen::compress_v1(1200, 500)).unwrap();
    assert_eq!(same_streamed(&path, 700), [700, 500]);
}

/// `mba --chunk-points` on LAS and LAZ: the streamed surface (FileSource,
/// chunks of 700 points, which split LAZ chunks of 1000) is the in-memory
/// pipeline's, control point for control point (the PLY and text streaming
/// tests' criterion).
#[test]
fn streamed_mba_on_las_and_laz_gives_the_in_memory_surface() {
    use scanfit::pipeline::assess::AssessConfig;
    use scanfit::pipeline::mba::{run, MbaRunConfig};
    use scanfit::pipeline::stream::mba;
    use scanfit::progress::NoProgress;
    use scanfit_io::source::FileSource;
    let n = 3000;
    let raw = laz10_gen::records(0, 0, n, 21);
    let mut las = laz10_gen::las12_header(0, 20, n as u64, 227, 0);
    las.extend_from_slice(&raw);
    let las_path = dir().join("mba.las");
    std::fs::write(&las_path, &las).unwrap();
    let laz_path = laz_file("mba.laz", 1, 0, laz10_gen::Chunks::Fixed(1000), n);
    let mut config = MbaRunConfig::default();
    config.mba.max_levels = 5;
    for path in [las_path, laz_path] {
        let cloud = read_cloud(&path, &ReadOptions::default())
            .unwrap()
            .into_cloud()
            .unwrap();
        let whole = run(&cloud, &config, &NoProgress).unwrap();
        let mut source = FileSource::new(&path, ReadOptions::default(), 700, false);
        let streamed = mba(
            &mut source,
            &config.mba,
            &AssessConfig::default(),
            Some(config.up),
            &NoProgress,
        )
        .unwrap();
        // the in-memory loop sums in lattice-cell order: equal to rounding
        let (a, b) = (
            streamed.surface.control_points(),
            whole.surface.control_points(),
        );
        assert_eq!(a.len(), b.len());
        let scale = b.iter().fold(0.0f64, |m, q| m.max(q.coords.abs().max()));
        for (p, q) in a.iter().zip(b) {
            assert!(
                (p - q).norm() <= 1e-12 * scale,
                "{}: {p} {q}",
                path.display()
            );
        }
        assert_eq!(streamed.passes, 8);
    }
}
