//! Times scanfit's multilevel B-spline approximation (the level loop alone,
//! [`scanfit::mba::mba`]) on a binary PLY file, for the side-by-side run with
//! ddemidov/mba (`benches/peers/mba_peer.py` runs everything; the data come
//! from `benches/peers/mba_data.py`).
//!
//! Arguments: POINTS.ply HELDOUT.ply LEVELS [mean|fitted] (the start of
//! level 0, [`scanfit::mba::Start`]; default mean). Both files are binary
//! little-endian PLY with double x, y, z and nothing else. The lattice starts
//! 1 x 1 (the peer's 2 x 2 grid), so LEVELS = 8 ends on 131 x 131 control
//! values. Output (JSON on stdout): the read and fit wall times, the fit's
//! CPU time (user + system of all threads, from `/proc/self/stat`; null
//! elsewhere: on a shared machine the wall time carries the load), the
//! per-level seconds, the vertical RMSE at the points and the RMSE against
//! the held-out points' z (evaluated at their x, y, clamped to the data's
//! bounding box as the surface is).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use scanfit::mba::{mba, MbaConfig, Start};
use scanfit::Point3;

/// The points of a binary little-endian PLY of double x, y, z.
fn read_ply(path: &str) -> Vec<Point3> {
    let bytes = std::fs::read(path).expect("a PLY file");
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("a PLY header")
        + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    assert!(
        header.contains("binary_little_endian")
            && header.matches("property double").count() == 3
            && !header.contains("property float"),
        "{path}: expected binary little-endian double x, y, z"
    );
    bytes[end..]
        .chunks_exact(24)
        .map(|r| {
            let f = |k: usize| f64::from_le_bytes(r[8 * k..8 * k + 8].try_into().unwrap());
            Point3::new(f(0), f(1), f(2))
        })
        .collect()
}

/// User + system CPU seconds of this process so far (all threads), from
/// `/proc/self/stat` (Linux; clock ticks of 1/100 s).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // the fields after the command name in parentheses; utime, stime are 14, 15
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    assert!(
        args.len() == 4 || args.len() == 5,
        "usage: mba_timing POINTS.ply HELDOUT.ply LEVELS [mean|fitted]"
    );
    let start = match args.get(4).map(String::as_str) {
        None | Some("mean") => Start::Mean,
        Some("fitted") => Start::Fitted,
        Some(s) => panic!("unknown start {s}: mean or fitted"),
    };
    let t0 = Instant::now();
    let points = read_ply(&args[1]);
    let read = t0.elapsed().as_secs_f64();
    let levels: usize = args[3].parse().expect("LEVELS");
    let config = MbaConfig {
        base: Some((1, 1)),
        max_levels: levels,
        start,
        ..Default::default()
    };
    let (t1, c1) = (Instant::now(), cpu_seconds());
    let r = mba(&points, &config).expect("the fit");
    let fit = t1.elapsed().as_secs_f64();
    let fit_cpu = match (c1, cpu_seconds()) {
        (Some(a), Some(b)) => format!("{:.2}", b - a),
        _ => "null".into(),
    };
    let heldout = read_ply(&args[2]);
    let f = r.frame;
    let sq: f64 = heldout
        .iter()
        .map(|q| {
            let x = q.x.clamp(f.x0, f.x0 + f.width);
            let y = q.y.clamp(f.y0, f.y0 + f.height);
            (r.eval(x, y) - q.z).powi(2)
        })
        .sum();
    let last = r.reports.last().expect("a level");
    let per_level: Vec<String> = r
        .reports
        .iter()
        .map(|l| format!("{:.4}", l.seconds))
        .collect();
    println!(
        "{{\"points\": {}, \"read_s\": {read:.4}, \"fit_s\": {fit:.4}, \"fit_cpu_s\": {fit_cpu}, \"level_s\": [{}], \"control_points\": [{}, {}], \"rmse\": {:.6e}, \"heldout_rmse\": {:.6e}}}",
        points.len(),
        per_level.join(", "),
        r.lattice.m + 3,
        r.lattice.n + 3,
        last.residual.rmse,
        (sq / heldout.len() as f64).sqrt()
    );
}
