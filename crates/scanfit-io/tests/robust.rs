//! The readers never panic on damaged input: every truncation and many
//! single-byte corruptions of small valid files, random mutations and random
//! bytes behind each format's magic must give `Ok` or `Err`. Headers that
//! claim huge counts must be refused before allocating (a failed allocation
//! would abort the test binary, so passing is the check).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use proptest::prelude::*;
use scanfit::{Point3, PointCloud};
use scanfit_io::{cloud_bytes, parse_cloud, NonFinite, ReadOptions, WriteFormat};

fn sample(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

/// Small valid files of every format and encoding, named by extension.
fn samples() -> Vec<(&'static str, Vec<u8>)> {
    let cloud = PointCloud::new(vec![
        Point3::new(0.5, 1.0, -2.0),
        Point3::new(3.0, 0.25, 8.0),
    ])
    .unwrap()
    .with_attribute("u", vec![0.0, 1.0])
    .unwrap();
    vec![
        ("a.ply", sample("sample_ascii.ply")),
        ("le.ply", sample("sample_binary_le.ply")),
        ("be.ply", sample("sample_binary_be.ply")),
        ("w.ply", cloud_bytes(&cloud, WriteFormat::PlyBinary)),
        ("a.pcd", sample("sample_ascii.pcd")),
        ("b.pcd", sample("sample_binary.pcd")),
        ("c.pcd", sample("sample_binary_compressed.pcd")),
        ("t.xyz", cloud_bytes(&cloud, WriteFormat::Xyz)),
        ("s.las", sample("sample.las")),
        ("s.laz", sample("sample.laz")),
    ]
}

/// Reads with both non-finite policies; returning at all is the test.
fn read(name: &str, bytes: &[u8]) {
    for non_finite in [NonFinite::Reject, NonFinite::Drop] {
        let opts = ReadOptions {
            non_finite,
            ..Default::default()
        };
        let _ = parse_cloud(Path::new(name), bytes, &opts);
    }
}

/// Panics inside third-party crates (the `las` reader, caught there) would
/// print their message on every case: keep our own panics loud.
fn quiet_third_party_panics() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let ours = info
            .location()
            .is_none_or(|l| !l.file().contains(".cargo/registry"));
        if ours {
            default(info)
        }
    }));
}

#[test]
fn every_truncation_and_byte_corruption() {
    quiet_third_party_panics();
    for (name, bytes) in samples() {
        // the intact file reads
        let opts = ReadOptions {
            non_finite: NonFinite::Drop,
            ..Default::default()
        };
        assert!(
            parse_cloud(Path::new(name), &bytes, &opts).is_ok(),
            "{name}"
        );
        for cut in 0..bytes.len() {
            read(name, &bytes[..cut]);
        }
        for i in 0..bytes.len() {
            for v in [
                0u8,
                0xff,
                bytes[i] ^ 0x01,
                bytes[i] ^ 0x80,
                b'9',
                b'\n',
                b' ',
            ] {
                let mut b = bytes.clone();
                b[i] = v;
                read(name, &b);
            }
        }
    }
}

#[test]
fn huge_counts_are_refused_without_allocating() {
    let opts = ReadOptions::default();
    let huge = "1000000000000";
    for (name, bytes) in samples() {
        if name.ends_with(".las") || name.ends_with(".laz") {
            continue;
        }
        let text = String::from_utf8_lossy(&bytes).into_owned();
        for key in ["element vertex ", "element face ", "POINTS ", "WIDTH "] {
            let Some(at) = text.find(key) else { continue };
            let start = at + key.len();
            let end = start + text[start..].find(['\n', '\r']).unwrap();
            let mut b = bytes[..start].to_vec();
            b.extend(huge.as_bytes());
            b.extend(&bytes[end..]);
            let e = parse_cloud(Path::new(name), &b, &opts);
            // elements after the vertex element are not read
            let after_vertex =
                key == "element face " && text.find("element vertex").is_some_and(|v| v < at);
            assert_eq!(e.is_err(), !after_vertex, "{name} {key}");
        }
    }
    // PCD: a COUNT (values per field) larger than the file, and one whose
    // SIZE x COUNT overflows
    for count in ["1000000000000", "18446744073709551615"] {
        let text = format!(
            "VERSION .7\nFIELDS x y z n\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 {count}\nWIDTH 1\nPOINTS 0\nDATA ascii\n"
        );
        let e = parse_cloud(Path::new("c.pcd"), text.as_bytes(), &opts).unwrap_err();
        assert!(e.to_string().contains("larger than the whole file"), "{e}");
    }
    // LAS/LAZ: point counts (legacy and 64-bit) and the chunk-table count
    for name in ["s.las", "s.laz"] {
        let bytes = samples().into_iter().find(|s| s.0 == name).unwrap().1;
        let mut b = bytes.clone();
        b[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse_cloud(Path::new(name), &b, &opts).is_err(), "{name}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    #[test]
    fn random_mutations_and_truncations(
        which in 0usize..10,
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
    ) {
        quiet_third_party_panics();
        let (name, mut bytes) = samples().swap_remove(which);
        for (i, v) in edits {
            let k = i.index(bytes.len());
            bytes[k] = v;
        }
        let keep = cut.index(bytes.len() + 1);
        read(name, &bytes[..keep]);
        read(name, &bytes);
    }

    #[test]
    fn random_bytes_behind_each_magic(
        magic in prop::sample::select(vec![
            ("r.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"),
            ("r.ply", "ply\nformat binary_big_endian 1.0\nelement face 2\nproperty list uchar int vertex_indices\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nproperty list int uchar t\nend_header\n"),
            ("r.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"),
            ("r.ply", "ply\n"),
            ("r.pcd", "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary_compressed\n"),
            ("r.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n"),
            ("r.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nPOINTS 2\nDATA ascii\n"),
            ("r.pcd", "# .PCD v0.7\n"),
            ("r.las", "LASF"),
            ("r.xyz", ""),
        ]),
        tail in prop::collection::vec(any::<u8>(), 0..300),
    ) {
        quiet_third_party_panics();
        let mut b = magic.1.as_bytes().to_vec();
        b.extend(tail);
        read(magic.0, &b);
    }

    #[test]
    fn random_text_lines(lines in prop::collection::vec("[0-9eE.,;+ \\-nainf#x]{0,30}", 0..20)) {
        let text = lines.join("\n");
        read("r.xyz", text.as_bytes());
        read("r.csv", text.as_bytes());
    }
}
