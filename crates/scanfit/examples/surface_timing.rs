//! Times scanfit's least-squares surface fit and point inversion on a raw data
//! file, for side-by-side comparisons with other tools on the same input
//! (`benches/peers/surface_peers.py` writes the file and runs everything).
//!
//! Input: little-endian f64 records `u v x y z`; arguments: FILE COUNT_U COUNT_V.
//! Output (JSON on stdout): fit and inversion wall times (best of 3), RMSE,
//! control points (row-major, u slow) and, for the first 1000 points, the
//! inverted parameters and distances.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use scanfit::bspline::KnotVector;
use scanfit::fit::surface::{least_squares_surface_with, SurfaceLsqOptions};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit::Point3;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bytes = std::fs::read(&args[1]).expect("data file");
    let (nu, nv): (usize, usize) = (args[2].parse().unwrap(), args[3].parse().unwrap());
    let vals: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let uv: Vec<[f64; 2]> = vals.chunks_exact(5).map(|r| [r[0], r[1]]).collect();
    let pts: Vec<Point3> = vals
        .chunks_exact(5)
        .map(|r| Point3::new(r[2], r[3], r[4]))
        .collect();
    let ku = KnotVector::uniform_clamped(3, nu).unwrap();
    let kv = KnotVector::uniform_clamped(3, nv).unwrap();
    let mut fit_best = f64::INFINITY;
    let mut surface = None;
    for _ in 0..3 {
        let t = Instant::now();
        let s = least_squares_surface_with(
            &pts,
            &uv,
            ku.clone(),
            kv.clone(),
            SurfaceLsqOptions::default(),
        )
        .unwrap();
        fit_best = fit_best.min(t.elapsed().as_secs_f64());
        surface = Some(s);
    }
    let s = surface.unwrap();
    let rmse = (pts
        .iter()
        .zip(&uv)
        .map(|(p, t)| (s.point(t[0], t[1]) - p).norm_squared())
        .sum::<f64>()
        / pts.len() as f64)
        .sqrt();
    let mut inv_best = f64::INFINITY;
    let mut inv = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        let inverter = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
        inv = inverter.invert_all(&pts);
        inv_best = inv_best.min(t.elapsed().as_secs_f64());
    }
    let ctrl: Vec<[f64; 3]> = s.control_points().iter().map(|p| [p.x, p.y, p.z]).collect();
    let first: Vec<[f64; 3]> = inv
        .iter()
        .take(1000)
        .map(|r| [r.uv[0], r.uv[1], r.distance])
        .collect();
    println!(
        "{}",
        serde_json::json!({
            "points": pts.len(),
            "threads": rayon::current_num_threads(),
            "fit_seconds": fit_best,
            "inversion_seconds": inv_best,
            "rmse": rmse,
            "unconverged": inv.iter().filter(|r| !r.converged).count(),
            "mean_iterations": inv.iter().map(|r| r.iterations as f64).sum::<f64>() / inv.len() as f64,
            "control_points": ctrl,
            "inversions_first_1000": first,
        })
    );
}
