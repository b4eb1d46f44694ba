//! Hand-made hostile files: each asks a reader for far more memory than the
//! file could hold, or lies in its header. Every one must be refused (or
//! read with a warning) with a message that says what is wrong, before
//! anything large is allocated: an allocation of gigabytes would abort the
//! test binary, so passing is part of the check.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Cursor;
use std::path::Path;

use scanfit_io::{parse_cloud, ReadOptions};

fn sample(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

fn read(name: &str, bytes: &[u8]) -> Result<scanfit_io::PointTable, String> {
    parse_cloud(Path::new(name), bytes, &ReadOptions::default()).map_err(|e| e.to_string())
}

/// A LAS 1.4 file of point format 6 (the layered LAZ compressor when
/// compressed) with `n` points, written by the las crate.
fn layered(n: usize, compressed: bool) -> Vec<u8> {
    let mut b = las::Builder::from((1, 4));
    b.point_format = las::point::Format::new(6).unwrap();
    b.point_format.is_compressed = compressed;
    let header = b.into_header().unwrap();
    let mut w = las::Writer::new(Cursor::new(Vec::new()), header).unwrap();
    for i in 0..n {
        let p = las::Point {
            x: i as f64 * 0.01,
            y: (i % 97) as f64,
            z: (i % 13) as f64 * 0.5,
            intensity: (i % 1000) as u16,
            gps_time: Some(i as f64),
            ..Default::default()
        };
        w.write_point(p).unwrap();
    }
    w.into_inner().unwrap().into_inner()
}

fn put_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}
fn put_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}
fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

#[test]
fn layered_laz_reads_and_its_layer_sizes_are_bounded() {
    // 120 000 points: three chunks of the default 50 000
    let good = layered(120_000, true);
    let t = read("l.laz", &good).unwrap();
    assert_eq!(t.points.len(), 120_000);
    assert_eq!(t.points[119_999].x, 1199.99);
    assert!(t.warnings.is_empty(), "{:?}", t.warnings);
    let plain = read("l.las", &layered(120_000, false)).unwrap();
    assert_eq!(plain.points, t.points);

    // the first chunk: 8-byte table offset, a 30-byte raw first point, the
    // point count, then nine 32-bit layer sizes
    let start = u32_at(&good, 96) as usize;
    let sizes = start + 8 + 30 + 4;
    assert_eq!(u32_at(&good, start + 8 + 30), 50_000);
    for layer in [0, 1, 8] {
        let mut bomb = good.clone();
        put_u32(&mut bomb, sizes + 4 * layer, u32::MAX);
        let e = read("l.laz", &bomb).unwrap_err();
        assert!(
            e.contains("LAZ chunk 0 declares") && e.contains("bytes of layers, but only"),
            "{e}"
        );
    }
    // the same lie in the last chunk, found by walking the chunks
    let mut pos = start + 8;
    for _ in 0..2 {
        let layers: u64 = (0..9)
            .map(|l| u64::from(u32_at(&good, pos + 34 + 4 * l)))
            .sum();
        pos += 34 + 36 + layers as usize;
    }
    assert_eq!(u32_at(&good, pos + 30), 20_000);
    let mut bomb = good.clone();
    put_u32(&mut bomb, pos + 34 + 4 * 4, 3_000_000_000);
    let e = read("l.laz", &bomb).unwrap_err();
    assert!(e.contains("LAZ chunk 2 declares"), "{e}");
}

#[test]
fn a_few_kilobyte_laz_cannot_ask_for_gigabytes() {
    let good = sample("sample.laz");
    let start = u32_at(&good, 96) as usize;
    let table = u64::from_le_bytes(good[start..start + 8].try_into().unwrap()) as usize;
    // a chunk table of 4 billion entries (64 GB in the decoder)
    let mut bomb = good.clone();
    put_u32(&mut bomb, table + 4, u32::MAX);
    let e = read("s.laz", &bomb).unwrap_err();
    assert!(
        e.contains("the LAZ chunk table declares 4294967295 chunks"),
        "{e}"
    );
    // a point count of 4 billion in a 428-byte file
    let mut bomb = good.clone();
    put_u32(&mut bomb, 107, u32::MAX);
    let e = read("s.laz", &bomb).unwrap_err();
    assert!(e.contains("4294967295 points"), "{e}");
    // a LASzip item list that does not describe the header's records
    let mut bomb = good.clone();
    bomb[105..107].copy_from_slice(&60_000u16.to_le_bytes());
    let e = read("s.laz", &bomb).unwrap_err();
    assert!(
        e.contains("the LASzip items describe 34-byte points"),
        "{e}"
    );
}

#[test]
fn extended_vlr_lengths_are_checked_whatever_the_header_size() {
    // version 1.4 with a 1.2-sized header: the crate still reads the EVLR
    // fields at bytes 235..247 (here inside the point data)
    let good = sample("sample.las");
    for header_size in [227u16, 235] {
        let mut bomb = good.clone();
        bomb[25] = 4;
        bomb[94..96].copy_from_slice(&header_size.to_le_bytes());
        let evlr = 120usize; // inside the file
        put_u64(&mut bomb, 235, evlr as u64);
        put_u32(&mut bomb, 243, 1);
        put_u64(&mut bomb, evlr + 20, 1 << 50);
        let e = read("s.las", &bomb).unwrap_err();
        assert!(
            e.contains("byte offset 120: the extended VLR declared here (1125899906842624 bytes) does not fit"),
            "{header_size}: {e}"
        );
    }
}

#[test]
fn las_scale_factors_must_be_positive() {
    let good = sample("sample.las");
    for (axis, value) in [(0, 0.0), (1, -0.01), (2, f64::NAN)] {
        let mut bad = good.clone();
        put_u64(&mut bad, 131 + 8 * axis, f64::to_bits(value));
        let e = read("s.las", &bad).unwrap_err();
        let name = ["x", "y", "z"][axis];
        assert!(
            e.contains(&format!("the {name} scale factor is {value}; a LAS scale factor must be a positive finite number")),
            "{e}"
        );
    }
}

#[test]
fn las_counts_that_disagree_with_the_data() {
    let good = sample("sample.las");
    let n = u32_at(&good, 107);
    // fewer declared than present: read, with a warning
    let mut fewer = good.clone();
    put_u32(&mut fewer, 107, n - 1);
    let t = read("s.las", &fewer).unwrap();
    assert_eq!(t.points.len() as u32, n - 1);
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
    assert!(
        t.warnings[0].contains(&format!("the header declares {} point records, but", n - 1))
            && t.warnings[0].contains("(1 records of"),
        "{:?}",
        t.warnings
    );
    // more declared than present: an error
    let mut more = good.clone();
    put_u32(&mut more, 107, n + 1);
    let e = read("s.las", &more).unwrap_err();
    assert!(
        e.contains(&format!("declares {} point records", n + 1)),
        "{e}"
    );
    // the intact file: no warning
    assert!(read("s.las", &good).unwrap().warnings.is_empty());
}

#[test]
fn json_documents_with_huge_degrees_are_errors() {
    use scanfit_io::json::{parse_curve, parse_surface};
    let curve = r#"{"schema":"scanfit/1","type":"bspline_curve","degree":DEG,"periodic":false,
        "knots":[0,0,1,1],"control_points":[[0,0,0],[1,1,1]],"weights":null}"#;
    assert!(parse_curve(Path::new("c.json"), &curve.replace("DEG", "1")).is_ok());
    for deg in ["18446744073709551615", "9223372036854775807", "65", "0"] {
        let e = parse_curve(Path::new("c.json"), &curve.replace("DEG", deg))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!("c.json: degree is {deg}; give a degree from 1 to 64"),
        );
    }
    let e = parse_curve(Path::new("c.json"), &curve.replace("DEG", "2"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("degree 2 needs at least 6 knots, but knots has 4"),
        "{e}"
    );
    let surface = r#"{"schema":"scanfit/1","type":"bspline_surface","degree_u":DU,"degree_v":DV,
      "periodic_u":false,"periodic_v":false,"knots_u":[0,0,1,1],"knots_v":[0,0,1,1],
      "count_u":CU,"count_v":CV,"control_points":[[0,0,0],[0,1,0],[1,0,0],[1,1,1]],"weights":null}"#;
    let doc = |du: &str, dv: &str, cu: &str, cv: &str| {
        surface
            .replace("DU", du)
            .replace("DV", dv)
            .replace("CU", cu)
            .replace("CV", cv)
    };
    assert!(parse_surface(Path::new("s.json"), &doc("1", "1", "2", "2")).is_ok());
    let e = parse_surface(
        Path::new("s.json"),
        &doc("18446744073709551615", "1", "2", "2"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("degree_u is 18446744073709551615"), "{e}");
    let e = parse_surface(
        Path::new("s.json"),
        &doc("1", "18446744073709551615", "2", "2"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("degree_v is 18446744073709551615"), "{e}");
    // a net whose size overflows
    let e = parse_surface(
        Path::new("s.json"),
        &doc("1", "1", "4294967296", "4294967296"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(
            "count_u x count_v = 4294967296 x 4294967296 does not match the 4 control points"
        ),
        "{e}"
    );
}

/// Writes the layered LAZ seeds of the fuzz corpus (`fuzz/corpus/laz`) when
/// `SCANFIT_WRITE_SEEDS` is set; otherwise checks that they still read.
#[test]
fn layered_laz_seeds() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus");
    let seeds = [
        ("laz/layered6.laz", layered(40, true)),
        ("las/las14_format6.las", layered(20, false)),
    ];
    for (name, bytes) in seeds {
        let path = dir.join(name);
        if std::env::var_os("SCANFIT_WRITE_SEEDS").is_some() {
            std::fs::write(&path, &bytes).unwrap();
        }
        let on_disk = std::fs::read(&path).unwrap();
        let n = if name.ends_with(".laz") { 40 } else { 20 };
        assert_eq!(read(name, &on_disk).unwrap().points.len(), n);
    }
}

/// Fuzz finding (laz target): a LAZ file declaring no points still has its
/// chunk table read by the decoder, which reserved 31 GB for it.
#[test]
fn a_chunk_table_is_checked_even_without_points() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/laz/chunk-table-with-zero-points.laz");
    let bytes = std::fs::read(path).unwrap();
    let e = read("f.laz", &bytes).unwrap_err();
    assert!(e.contains("the LAZ chunk table declares"), "{e}");
}

/// Fuzz finding (laz target, campaign of 2 December 2026): a LASzip VLR with
/// the pointwise compressor (1) but a layered point-14 item (version 3). The
/// decoder picks the layered decompressor by the item version, so the
/// layer sizes went unchecked and it reserved 2.9 GB for a 561-byte file.
#[test]
fn layered_items_need_the_layered_compressor() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/laz/pointwise-compressor-with-layered-items.laz");
    let bytes = std::fs::read(path).unwrap();
    let e = read("f.laz", &bytes).unwrap_err();
    assert!(
        e.contains("declares compressor 1 with items of version 3"),
        "{e}"
    );
}

/// Fuzz finding (laz target, 2 December 2026, after the laz14 decoder): a
/// 720-byte LAS 1.2 file whose header size (156) is below the version's
/// 227. The VLR walk from byte 156 found no LASzip VLR, the check stepped
/// aside, and the las crate (which reads the VLRs after the full header)
/// found one and reserved 27 GB for an unchecked chunk table.
#[test]
fn a_compressed_file_needs_its_laszip_vlr_where_the_header_says() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions/laz/header-size-hides-the-laszip-vlr.laz");
    let bytes = std::fs::read(path).unwrap();
    let e = read("f.laz", &bytes).unwrap_err();
    assert!(
        e.contains("none of the 1 VLRs that follow the 156-byte header is the LASzip VLR"),
        "{e}"
    );
}
