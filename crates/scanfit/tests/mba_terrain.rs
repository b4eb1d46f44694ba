//! The MBA paper's Table 1 experiment on real terrain: the Jacksboro fault
//! DEM sample (`examples/data/terrain_50k.xyz`, 50 000 points, metres), MBA
//! at lattice sizes 4x4 .. 35x35 control points, then the projection
//! adjustment at the same lattice. Prints the table (run with
//! `cargo test -p scanfit --test mba_terrain -- --nocapture`) that the
//! README quotes, and asserts its figures: the paper-literal step (alpha
//! 1.49, no guard) lowers the eq. 17 RMSE at every lattice size, the guarded
//! loop by more than 10%, and the vertical error gets worse on every lattice
//! but the finest.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit::cloud::PointCloud;
use scanfit::mba::adjust::{adjust_lattice, lattice_grid_rmse, paper_step, AdjustConfig};
use scanfit::mba::{mba, MbaConfig, Start};
use scanfit::Point3;

fn terrain() -> Vec<Point3> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/data/terrain_50k.xyz"
    );
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            Point3::new(v[0], v[1], v[2])
        })
        .collect()
}

#[test]
fn table_1_on_the_jacksboro_terrain() {
    let p = terrain();
    assert_eq!(p.len(), 50_000);
    let cloud = PointCloud::new(p.clone()).unwrap();
    println!("| control points | MBA RMSE eq. 17 (m) | adjusted RMSE eq. 17 (m) | change | MBA vertical RMSE (m) | adjusted vertical RMSE (m) |");
    println!("|---|---|---|---|---|---|");
    let mut last_mba = f64::INFINITY;
    for levels in 1..=6 {
        let r = mba(
            &p,
            // the paper's experiment: MBA, then the adjustment, which starts
            // from the mean (the table in the README)
            &MbaConfig {
                max_levels: levels,
                start: Start::Mean,
                ..Default::default()
            },
        )
        .unwrap();
        let mut lattice = r.lattice.clone();
        let before = lattice_grid_rmse(&cloud, &r.frame, &lattice).unwrap();
        let cfg = AdjustConfig::default();
        let literal = paper_step(&cloud, &r.frame, &lattice, cfg.alpha, &cfg.projection).unwrap();
        let lit = lattice_grid_rmse(&cloud, &r.frame, &literal).unwrap();
        adjust_lattice(&cloud, &r.frame, &mut lattice, &cfg).unwrap();
        let after = lattice_grid_rmse(&cloud, &r.frame, &lattice).unwrap();
        let vertical = |l: &scanfit::mba::Lattice| {
            let s: f64 = p
                .iter()
                .map(|q| {
                    let u = r.frame.unit(q);
                    let d = q.z - r.frame.z0 - l.eval(u[0] * l.m as f64, u[1] * l.n as f64);
                    d * d
                })
                .sum();
            (s / p.len() as f64).sqrt()
        };
        let (vb, va) = (vertical(&r.lattice), vertical(&lattice));
        let net = lattice.m + 3;
        println!(
            "| {net} x {net} | {before:.2} | {after:.2} | {:+.1}% | {vb:.2} | {va:.2} |",
            100.0 * (after - before) / before
        );
        eprintln!("{net} x {net}: one paper-literal step {before:.2} -> {lit:.2}");
        // the paper's claim, for its own step without our guard (measured:
        // -10% at 35 x 35 to -19% at 11 x 11)
        assert!(lit < 0.92 * before, "{net}: paper step {before} -> {lit}");
        // and the guarded loop's gain the README quotes (14-26%)
        assert!(after < 0.9 * before, "{net}: {before} -> {after}");
        // and MBA itself improves with the lattice
        assert!(before < last_mba, "{net}: {before} after {last_mba}");
        last_mba = before;
        // at the paper's 35 x 35 the adjusted surface is also closer to the
        // data vertically (48.9 m -> 43.3 m); at coarser lattices it is not
        // (see the README), which eq. 17 does not show
        if net == 35 {
            assert!(vb < 50.0 && va < 0.9 * vb, "{vb} {va}");
        } else {
            assert!(va > vb, "{net}: vertical {vb} -> {va}");
        }
    }
}
