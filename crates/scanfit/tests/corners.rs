#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Automatic corners on sparse, noisy, scattered samples of four-sided
//! patches whose outline is tilted against their best-fit plane, and the
//! refusal of corners that are not corners (a rounded outline).

use std::f64::consts::PI;

use scanfit::base::{coons_from_cloud, CoonsFromCloudConfig};
use scanfit::testdata::SplitMix64;
use scanfit::Point3;

/// The patch: a doubly curved sheet over a skewed quadrilateral, twisted so
/// that its corners alternate above and below the best-fit plane (the
/// outline leaves the plane by up to 0.3 of a side).
fn surface(u: f64, v: f64) -> Point3 {
    let x = 1.0 * u + 0.25 * v + 0.05 * (PI * v).sin();
    let y = 0.8 * v - 0.04 * (PI * u).sin();
    let z = 0.6 * (u - 0.5) * (v - 0.5) + 0.15 * (PI * u).sin() * (PI * v).sin();
    Point3::new(x, y, z)
}

/// `n` uniformly scattered samples with Gaussian noise of `noise` (data units).
fn sample(n: usize, noise: f64, seed: u64) -> Vec<Point3> {
    let mut r = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let p = surface(r.uniform(), r.uniform());
            p + noise * scanfit::Vector3::new(r.normal(), r.normal(), r.normal())
        })
        .collect()
}

#[test]
fn corners_of_sparse_noisy_tilted_patches_are_within_three_percent_of_a_side() {
    let truth = [
        surface(0.0, 0.0),
        surface(1.0, 0.0),
        surface(1.0, 1.0),
        surface(0.0, 1.0),
    ];
    let side = 0.8; // the shortest side
    let mut worst: f64 = 0.0;
    for (n, noise, seed) in [
        (2000, 0.002, 1),
        (3000, 0.004, 2),
        (4000, 0.0, 3),
        (2500, 0.003, 4),
    ] {
        let pts = sample(n, noise, seed);
        let c = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap();
        let outer = c.boundary.outer_loop();
        for t in truth {
            let miss = c
                .corners
                .corners
                .iter()
                .map(|&k| (pts[outer[k]] - t).norm())
                .fold(f64::INFINITY, f64::min);
            // the sample need not hold a point at the corner: measure the
            // miss beyond the loop point nearest to it
            let nearest = outer
                .iter()
                .map(|&i| (pts[i] - t).norm())
                .fold(f64::INFINITY, f64::min);
            worst = worst.max((miss - nearest) / side);
            assert!(
                miss - nearest < 0.03 * side && miss < 0.08 * side,
                "{n} points, noise {noise}: corner {t:?} missed by {miss:.4} ({:.1}% of a side; nearest loop point {nearest:.4}); angles {:?}",
                100.0 * miss / side,
                c.corner_angles.iter().map(|a| a.to_degrees()).collect::<Vec<_>>()
            );
        }
    }
    eprintln!(
        "worst corner miss beyond the nearest loop point: {:.2}% of a side",
        100.0 * worst
    );
}

#[test]
fn a_rounded_outline_has_no_clear_corners_and_is_refused_unless_forced() {
    // an elliptical dome (a face's outline): every pick turns gently
    let mut r = SplitMix64::new(7);
    let pts: Vec<Point3> = (0..3000)
        .map(|_| {
            let (rad, t) = (r.uniform().sqrt(), 2.0 * PI * r.uniform());
            let (x, y) = (0.8 * rad * t.cos(), 1.1 * rad * t.sin());
            Point3::new(x, y, 0.5 * (1.0 - 0.8 * rad * rad).sqrt())
        })
        .collect();
    let e = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("not clearly corners"), "{msg}");
    assert!(msg.contains("turn by less than 30 degrees"), "{msg}");
    let forced = CoonsFromCloudConfig {
        force_corners: true,
        ..Default::default()
    };
    let c = coons_from_cloud(&pts, &forced).unwrap();
    // the strengths are reported: on the ellipse at least one pick turns by
    // less than the 30-degree limit (what the refusal above names) and none
    // comes near a true corner's 90 (a rectangle's turn by 90 +- 15 below)
    assert_eq!(c.corner_strengths.len(), 4);
    assert!(
        c.corner_strengths.iter().any(|s| s.to_degrees() < 30.0)
            && c.corner_strengths.iter().all(|s| s.to_degrees() < 45.0),
        "{:?}",
        c.corner_strengths
    );
    let shares: f64 = c.side_shares.iter().sum();
    assert!((shares - 1.0).abs() < 1e-9, "{shares}");
}

#[test]
fn a_rectangle_has_clear_corners_of_ninety_degrees() {
    let mut r = SplitMix64::new(8);
    let pts: Vec<Point3> = (0..3000)
        .map(|_| Point3::new(2.0 * r.uniform(), r.uniform(), 0.0))
        .collect();
    let c = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap();
    for s in &c.corner_strengths {
        assert!(
            (s.to_degrees() - 90.0).abs() < 15.0,
            "{:?}",
            c.corner_strengths
        );
    }
    // sides of 1/3 and 1/6 of the loop
    let mut shares = c.side_shares.clone();
    shares.sort_by(f64::total_cmp);
    assert!(
        (shares[0] - 1.0 / 6.0).abs() < 0.02 && (shares[3] - 1.0 / 3.0).abs() < 0.02,
        "{shares:?}"
    );
}
