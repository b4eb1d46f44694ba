//! Point-file read benchmarks (criterion, throughput in bytes of file):
//! binary little-endian PLY of 10^7 points (float x, y, z), and for
//! reference 10^6 points as ascii PLY, binary PCD and XYZ text. The files are
//! written to the temporary directory in the setup; the timed part is
//! `read_cloud` (file read from the page cache, header, decode, finite check).
//!
//! Run: `cargo bench -p scanfit-io --bench read -- --sample-size 10`

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use scanfit_io::{read_cloud, ReadOptions};

/// A deterministic wavy sheet of `n` points.
fn point(i: usize) -> [f32; 3] {
    let (u, v) = ((i % 4096) as f32 * 0.01, (i / 4096) as f32 * 0.01);
    [u, v, (u * 3.0).sin() * (v * 2.0).cos()]
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn ply_binary(n: usize) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    )
    .into_bytes();
    b.reserve(n * 12);
    for i in 0..n {
        for v in point(i) {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}

fn ply_ascii(n: usize) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    );
    for i in 0..n {
        let [x, y, z] = point(i);
        let _ = writeln!(s, "{x} {y} {z}");
    }
    s.into_bytes()
}

fn pcd_binary(n: usize) -> Vec<u8> {
    let mut b = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n"
    )
    .into_bytes();
    for i in 0..n {
        for v in point(i) {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}

fn xyz(n: usize) -> Vec<u8> {
    let mut s = String::from("x y z\n");
    for i in 0..n {
        let [x, y, z] = point(i);
        let _ = writeln!(s, "{x} {y} {z}");
    }
    s.into_bytes()
}

fn read(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("scanfit-read-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let files = [
        (
            "ply_binary_le_1e7",
            write(&dir, "b.ply", &ply_binary(10_000_000)),
            10_000_000,
        ),
        (
            "ply_ascii_1e6",
            write(&dir, "a.ply", &ply_ascii(1_000_000)),
            1_000_000,
        ),
        (
            "pcd_binary_1e6",
            write(&dir, "b.pcd", &pcd_binary(1_000_000)),
            1_000_000,
        ),
        ("xyz_1e6", write(&dir, "t.xyz", &xyz(1_000_000)), 1_000_000),
    ];
    let mut g = c.benchmark_group("read");
    for (name, path, n) in &files {
        let size = std::fs::metadata(path).unwrap().len();
        g.throughput(Throughput::Bytes(size));
        g.bench_function(*name, |b| {
            b.iter(|| {
                let t = read_cloud(black_box(path), &ReadOptions::default()).unwrap();
                assert_eq!(t.points.len(), *n);
                t
            })
        });
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, read);
criterion_main!(benches);
