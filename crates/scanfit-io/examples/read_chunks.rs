//! Reads a point file in chunks of `N` points (`PointChunks`, the reader
//! of `--chunk-points`) and prints the point count and the coordinate sums,
//! so that `/usr/bin/time -v` gives the reader's peak memory alone
//! (BENCHMARKS.md, "Streamed compressor-1 LAZ"):
//!
//! ```sh
//! cargo run --release -p scanfit-io --example read_chunks -- /tmp/franke_10000000_c1.laz 1000000
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit_io::chunks::PointChunks;
use scanfit_io::ReadOptions;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, path, chunk] = &args[..] else {
        panic!("usage: read_chunks FILE CHUNK_POINTS");
    };
    let chunk: usize = chunk.parse().unwrap();
    let mut chunks = PointChunks::open(path.as_ref(), &ReadOptions::default(), chunk).unwrap();
    let (mut n, mut sum) = (0usize, [0.0f64; 3]);
    while let Some(t) = chunks.next_chunk().unwrap() {
        n += t.points.len();
        for p in &t.points {
            sum[0] += p.x;
            sum[1] += p.y;
            sum[2] += p.z;
        }
    }
    println!("{n} points, sums {:.6} {:.6} {:.6}", sum[0], sum[1], sum[2]);
}
