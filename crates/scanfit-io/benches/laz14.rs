//! Layered LAZ decoding speed: scanfit's `laz14` decoder against the `laz`
//! crate's, on 10^6 generated points of format 8 (point-14 + RGB + NIR,
//! chunks of 50,000, item version 3; the generator of `tests/laz14.rs`),
//! decoded from memory. Both decode every field; `read_cloud`-level costs
//! (columns, coordinates) are not included.
//!
//! Run: `cargo bench -p scanfit-io --bench laz14 -- --sample-size 10`

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

#[path = "../tests/support/laz_gen.rs"]
mod laz_gen;
use laz_gen::{compress, laz_decode, ours, record_len, records, Chunks};

fn decode(c: &mut Criterion) {
    let n = 1_000_000;
    let raw = records(8, n, 2026);
    let file = compress(8, false, Chunks::Fixed(50_000), &raw);
    drop(raw);
    let mut g = c.benchmark_group("laz14_format8_1e6");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("laz crate", |b| {
        b.iter(|| black_box(laz_decode(&file, n, record_len(8))))
    });
    g.bench_function("scanfit laz14", |b| {
        b.iter(|| black_box(ours(&file, n as u64, false)))
    });
    g.finish();
}

criterion_group!(benches, decode);
criterion_main!(benches);
