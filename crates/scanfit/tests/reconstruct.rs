//! Whole-object reconstruction (issue 15) on synthetic labelled objects:
//! network counts, the gap along every edge sampled from both sides, fit
//! errors against the noise, and bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit::network::{build_network, NetworkConfig};
use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
use scanfit::progress::NoProgress;
use scanfit::{Point3, PointCloud};
use std::f64::consts::{PI, TAU};

/// SplitMix64 normal noise, reproducible.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

fn labelled(pts: Vec<Point3>, labels: Vec<f64>) -> PointCloud {
    PointCloud::new(pts)
        .unwrap()
        .with_attribute("label", labels)
        .unwrap()
}

/// A closed cylinder (radius 1, height 2): 4 side sectors (labels 0-3) and
/// two caps (10 bottom, 11 top), normal noise `sigma` along the normal.
fn can(sigma: f64, seed: u64) -> PointCloud {
    can_sectors(sigma, seed, 4)
}

fn can_sectors(sigma: f64, seed: u64, sectors: usize) -> PointCloud {
    let mut rng = Rng(seed);
    let h = 0.035;
    let (mut pts, mut lab) = (Vec::new(), Vec::new());
    let nt = (TAU / h).round() as usize;
    let nz = (2.0 / h).round() as usize;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64 * TAU;
        for j in 0..nz {
            let z = (j as f64 + 0.5) / nz as f64 * 2.0;
            let r = 1.0 + sigma * rng.normal();
            pts.push(Point3::new(r * t.cos(), r * t.sin(), z));
            lab.push(
                (t / (TAU / sectors as f64))
                    .floor()
                    .min(sectors as f64 - 1.0),
            );
        }
    }
    let n = (2.0 / h).round() as i64;
    for (z, l) in [(0.0, 10.0), (2.0, 11.0)] {
        for i in -n..=n {
            for j in -n..=n {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                if x * x + y * y < (1.0 - 0.5 * h) * (1.0 - 0.5 * h) {
                    pts.push(Point3::new(x, y, z + sigma * rng.normal()));
                    lab.push(l);
                }
            }
        }
    }
    labelled(pts, lab)
}

/// A square sheet `[0, 2]^2` on a gentle dome in 2 x 2 labelled quarters.
fn sheet(sigma: f64) -> PointCloud {
    let mut rng = Rng(7);
    let n = 60;
    let (mut pts, mut lab) = (Vec::new(), Vec::new());
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                (i as f64 + 0.5) * 2.0 / n as f64,
                (j as f64 + 0.5) * 2.0 / n as f64,
            );
            let z = 0.2 * (x * (2.0 - x) + y * (2.0 - y)) / 2.0 + sigma * rng.normal();
            pts.push(Point3::new(x, y, z));
            lab.push(f64::from(u8::from(x > 1.0)) + 2.0 * f64::from(u8::from(y > 1.0)));
        }
    }
    labelled(pts, lab)
}

/// An umbrella: a spherical cap (radius 2, 50 degrees) in 8 three-sided panels.
fn umbrella(sigma: f64) -> PointCloud {
    let mut rng = Rng(11);
    let (mut pts, mut lab) = (Vec::new(), Vec::new());
    let r = 2.0;
    let cap = 50f64.to_radians();
    let h = 0.04;
    let n = (r * cap.sin() / h).ceil() as i64;
    for i in -n..=n {
        for j in -n..=n {
            let (x, y) = ((i as f64 + 0.37) * h, (j as f64 + 0.21) * h);
            let rho = (x * x + y * y).sqrt();
            if rho >= r * cap.sin() {
                continue;
            }
            let z = (r * r - rho * rho).sqrt() + sigma * rng.normal();
            pts.push(Point3::new(x, y, z));
            let a = y.atan2(x).rem_euclid(TAU);
            lab.push((a / (TAU / 8.0)).floor().min(7.0));
        }
    }
    labelled(pts, lab)
}

#[test]
fn closed_can_six_faces_no_gaps() {
    let sigma = 0.002;
    let cloud = can(sigma, 3);
    let r = run(&cloud, &ReconstructConfig::default(), &NoProgress).unwrap();
    assert_eq!(r.network.patches.len(), 6);
    assert_eq!(r.network.vertices.len(), 8, "{:?}", r.network.vertices);
    assert_eq!(r.network.edges.len(), 12);
    assert!(r.totals.closed);
    assert!(r.patches.iter().all(|p| p.sides == 4 && p.edges == 4));
    // every edge sampled from both patches: rounding only
    let tol = 1e-9 * r.totals.diagonal;
    for e in &r.edges {
        assert!(
            e.max_gap <= tol,
            "edge {:?}: gap {:e}",
            e.patches,
            e.max_gap
        );
        assert!(e.patches[1].is_some());
    }
    // the shared model: valid to 1e-9 of its size, closed, outward normals,
    // the volume of the can (pi r^2 h) within 1%
    let model = &r.complex;
    model.validate_with(1e-9).unwrap();
    assert!(model.is_closed());
    let v = model.signed_volume();
    assert!((v / (2.0 * PI) - 1.0).abs() < 0.01, "volume {v}");
    // the fit follows the noise: orthogonal RMSE within 3 sigma
    for p in &r.patches {
        assert!(
            p.orthogonal.rmse < 3.0 * sigma,
            "patch {}: {:?}",
            p.id,
            p.orthogonal
        );
        assert!(
            p.errors.rmse < 3.0 * sigma,
            "patch {}: {:?}",
            p.id,
            p.errors
        );
        assert!(p.conversion_deviation <= 1e-4 * r.totals.diagonal);
    }
    // neighbouring sectors meet almost tangentially, sectors and caps at 90 degrees
    for e in &r.edges {
        let caps = e.patches.iter().flatten().filter(|&&id| id >= 10).count();
        if caps == 0 {
            assert!(
                e.max_angle < 8f64.to_radians(),
                "{:?}: {}",
                e.patches,
                e.max_angle.to_degrees()
            );
        } else {
            assert!(
                (e.max_angle - PI / 2.0).abs() < 0.35,
                "{:?}: {}",
                e.patches,
                e.max_angle.to_degrees()
            );
        }
    }
}

#[test]
fn caps_with_six_corners_merge_into_four_sides() {
    let sigma = 0.002;
    let r = run(
        &can_sectors(sigma, 9, 6),
        &ReconstructConfig::default(),
        &NoProgress,
    )
    .unwrap();
    assert_eq!(r.network.vertices.len(), 12);
    assert_eq!(r.network.edges.len(), 18);
    for p in &r.patches {
        assert_eq!(p.sides, 4);
        assert_eq!(p.edges, if p.id >= 10 { 6 } else { 4 }, "patch {}", p.id);
        assert!(
            p.orthogonal.rmse < 3.0 * sigma,
            "patch {}: {:?}",
            p.id,
            p.orthogonal
        );
    }
    // the caps' sides hold two edges each: still no gap along any edge
    assert!(
        r.totals.max_gap <= 1e-9 * r.totals.diagonal,
        "{:e}",
        r.totals.max_gap
    );
    // the model holds the caps' sides as chains of two edges each: valid,
    // closed, every chain's edges measured at round-off from both faces, and
    // the volume of the can (pi r^2 h) within 1%
    let m = &r.complex;
    m.validate_with(1e-9).unwrap();
    assert!(m.is_closed());
    for f in &m.faces {
        assert_eq!(f.side_count(), 4, "patch {}", f.id);
        let want = if f.id >= 10 { 6 } else { 4 };
        assert_eq!(f.use_count(), want, "patch {}", f.id);
    }
    let gap = m.max_boundary_gap().unwrap();
    assert!(gap <= 1e-9 * r.totals.diagonal, "{gap:e}");
    let v = m.signed_volume();
    assert!((v / (2.0 * PI) - 1.0).abs() < 0.01, "volume {v}");
}

#[test]
fn closed_can_with_bspline_fit() {
    let sigma = 0.002;
    let cloud = can(sigma, 5);
    let mut cfg = ReconstructConfig::default();
    cfg.fit = scanfit::network::FaceFit::Bspline { ctrl: (8, 8) };
    let r = run(&cloud, &cfg, &NoProgress).unwrap();
    assert_eq!(r.patches.len(), 6);
    assert!(
        r.totals.max_gap <= 1e-9 * r.totals.diagonal,
        "{:e}",
        r.totals.max_gap
    );
    for p in &r.patches {
        assert!(
            p.orthogonal.rmse < 3.0 * sigma,
            "patch {}: {:?}",
            p.id,
            p.orthogonal
        );
    }
}

/// No gap along any edge beyond round-off, and the orthogonal RMSE over
/// every point within 3 `sigma` of the noise.
fn gapless_within_noise(r: &scanfit::pipeline::reconstruct::ReconstructReport, sigma: f64) {
    assert!(
        r.totals.max_gap <= 1e-9 * r.totals.diagonal,
        "{:e}",
        r.totals.max_gap
    );
    assert!(
        r.totals.orthogonal.rmse < 3.0 * sigma,
        "{:?}",
        r.totals.orthogonal
    );
}

#[test]
fn sheet_in_four_quarters() {
    let sigma = 0.001;
    let r = run(&sheet(sigma), &ReconstructConfig::default(), &NoProgress).unwrap();
    assert_eq!(r.patches.len(), 4);
    // centre, 4 where an interface meets the free border, 4 sheet corners
    assert_eq!(r.network.vertices.len(), 9);
    assert_eq!(r.network.edges.len(), 12);
    assert!(!r.totals.closed);
    assert_eq!(r.edges.iter().filter(|e| e.patches[1].is_none()).count(), 8);
    assert!(r.patches.iter().all(|p| p.sides == 4));
    gapless_within_noise(&r, sigma);
    // the centre vertex near (1, 1)
    let c = r
        .network
        .vertices
        .iter()
        .map(|v| ((v.x - 1.0).powi(2) + (v.y - 1.0).powi(2)).sqrt())
        .fold(f64::INFINITY, f64::min);
    assert!(c < 0.1, "{c}");
}

#[test]
fn umbrella_of_three_sided_panels() {
    let sigma = 0.002;
    let r = run(&umbrella(sigma), &ReconstructConfig::default(), &NoProgress).unwrap();
    assert_eq!(r.patches.len(), 8);
    assert_eq!(r.network.vertices.len(), 9);
    assert_eq!(r.network.edges.len(), 16);
    assert!(r.patches.iter().all(|p| p.sides == 3));
    let model = &r.complex;
    model.validate_with(1e-9).unwrap();
    assert_eq!(model.border_edges().len(), 8);
    gapless_within_noise(&r, sigma);
    // the apex: the vertex all 8 radial edges share, on top of the cap
    let top = r
        .network
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::MIN, f64::max);
    assert!((top - 2.0).abs() < 0.02, "{top}");
}

fn err(cloud: &PointCloud) -> String {
    build_network(cloud, &NetworkConfig::default(), &NoProgress)
        .map(|_| ())
        .unwrap_err()
        .to_string()
}

/// The network's error on the noiseless [`sheet`] labelled point by point
/// by `label`.
fn relabelled_err(label: impl Fn(&Point3) -> f64) -> String {
    let c = sheet(0.0);
    let lab: Vec<f64> = c.points().iter().map(label).collect();
    err(&c.with_attribute("label", lab).unwrap())
}

#[test]
fn single_label_points_to_coons() {
    let c = sheet(0.0);
    let n = c.len();
    let c = c.with_attribute("label", vec![4.0; n]).unwrap();
    let e = err(&c);
    assert!(
        e.contains("single patch") && e.contains("label 4") && e.contains("scanfit coons"),
        "{e}"
    );
}

#[test]
fn tiny_patch_is_named() {
    let c = sheet(0.0);
    let mut lab = c.attribute("label").unwrap().to_vec();
    lab[0] = 9.0;
    lab[1] = 9.0;
    let c = c.with_attribute("label", lab).unwrap();
    let e = err(&c);
    assert!(
        e.contains("patch 9 has 2 points") && e.contains("--ignore 9"),
        "{e}"
    );
}

#[test]
fn patch_in_two_pieces_is_named() {
    // the sheet's left and right thirds carry label 5, the middle label 6
    let e = relabelled_err(|p| if (p.x - 1.0).abs() < 0.34 { 6.0 } else { 5.0 });
    assert!(
        e.contains("patch 5 is not a topological disk") && e.contains("pieces"),
        "{e}"
    );
}

#[test]
fn patch_with_a_hole_is_named() {
    let e = relabelled_err(|p| {
        if (p.x - 1.0).hypot(p.y - 1.0) < 0.4 {
            2.0
        } else {
            1.0
        }
    });
    assert!(
        e.contains("patch 1 is not a topological disk") && e.contains("hole"),
        "{e}"
    );
}

#[test]
fn patch_between_two_others_without_corner() {
    // a disk (label 2) in the middle of the sheet, the upper part label 1,
    // the lower part label 3: the disk meets two patches and no free border,
    // so it has only two corners
    let e = relabelled_err(|p| {
        if (p.x - 1.0).hypot(p.y - 1.0) < 0.4 {
            2.0
        } else if p.y > 1.0 {
            1.0
        } else {
            3.0
        }
    });
    assert!(
        e.contains("patch 2 has only 2 corner(s)") && e.contains("three"),
        "{e}"
    );
}

#[test]
fn float_labels_are_refused() {
    let c = sheet(0.0);
    let n = c.len();
    let lab: Vec<f64> = (0..n).map(|i| (i % 4) as f64 + 0.25).collect();
    let c = c.with_attribute("label", lab).unwrap();
    let e = err(&c);
    assert!(e.contains("integers") && e.contains("point 0"), "{e}");
}

/// `scanfit report MODEL INPUT` measures the written model again: the same
/// per-patch numbers as the reconstruction's own report (the B-spline route
/// evaluates eq. 15 on the exported surface, as the report does; the PDE
/// route on the PDE surface, which its B-spline form follows to the
/// conversion deviation), and the points given by label or by nearness.
#[test]
fn model_report_reproduces_the_reconstruction_numbers() {
    use scanfit::network::FaceFit;
    use scanfit::pipeline::measure_model::{self, Assignment, ModelMeasureConfig, Parameters};
    let cloud = can_sectors(0.002, 5, 6);
    let bspline = FaceFit::Bspline { ctrl: (8, 8) };
    for (fit, exact) in [(bspline, true), (FaceFit::default(), false)] {
        let mut c = ReconstructConfig::default();
        c.fit = fit;
        let r = run(&cloud, &c, &NoProgress).unwrap();
        let m = measure_model::run(
            &r.complex,
            &cloud,
            &ModelMeasureConfig::default(),
            &NoProgress,
        )
        .unwrap();
        assert_eq!(m.assignment, Assignment::Labels("label".into()));
        assert_eq!(m.left_out, 0);
        assert!(m.totals.closed);
        for (a, b) in m.patches.iter().zip(&r.patches) {
            assert_eq!((a.id, a.points, a.sides), (b.id, b.points, b.sides));
            assert_eq!(a.parameters, Parameters::Coons);
            let (e, o) = (a.errors.unwrap(), a.orthogonal.unwrap());
            let tol = if exact {
                1e-9 * b.errors.rmse
            } else {
                b.conversion_deviation
            };
            assert!(
                (e.rmse - b.errors.rmse).abs() <= tol,
                "patch {}: eq. 15 rmse {} vs {} (fit {fit:?})",
                a.id,
                e.rmse,
                b.errors.rmse
            );
            assert!(
                (o.rmse - b.orthogonal.rmse).abs() <= 1e-9 * b.orthogonal.rmse,
                "patch {}: orthogonal rmse {} vs {}",
                a.id,
                o.rmse,
                b.orthogonal.rmse
            );
        }
        // the edges: the model's gaps at round-off, the angles those of the
        // reconstruction's samples (the same G1 defect, other sample points)
        assert!(m.totals.max_gap <= 1e-9 * r.totals.diagonal);
        let want = r.totals.max_angle.to_degrees();
        assert!(
            (m.totals.max_angle_deg - want).abs() < 0.05 * want,
            "{} vs {want}",
            m.totals.max_angle_deg
        );
    }
    // without labels every point goes to its nearest patch: nearly the
    // labelled split (only points near the borders can change patch)
    let bare = PointCloud::new(cloud.points().to_vec()).unwrap();
    let r = run(&cloud, &ReconstructConfig::default(), &NoProgress).unwrap();
    let m = measure_model::run(
        &r.complex,
        &bare,
        &ModelMeasureConfig::default(),
        &NoProgress,
    )
    .unwrap();
    assert_eq!(m.assignment, Assignment::Nearest);
    assert_eq!(m.totals.errors.count, cloud.len());
    for (a, b) in m.patches.iter().zip(&r.patches) {
        let d = a.points.abs_diff(b.points);
        assert!(
            d * 20 < b.points,
            "patch {}: {} vs {}",
            a.id,
            a.points,
            b.points
        );
    }
}

/// The sheet of [`sheet`] with 0.01 of noise, its quarter 3 (x, y > 1)
/// thinned to every third row and column over `[1.1, 1.9]^2`: a 12 x 12
/// least-squares net there has control points held by a few noisy points at
/// the fringe of their support, and flies off.
fn sheet_with_a_sparse_quarter() -> PointCloud {
    let base = sheet(0.0);
    let labels = base.attribute("label").unwrap();
    let mut rng = Rng(3);
    let (mut pts, mut lab) = (Vec::new(), Vec::new());
    for (p, &l) in base.points().iter().zip(labels) {
        let (i, j) = ((p.x * 30.0) as usize, (p.y * 30.0) as usize);
        let inner = (p.x - 1.5).abs() < 0.4 && (p.y - 1.5).abs() < 0.4;
        if l == 3.0 && inner && (i % 3 != 0 || j % 3 != 0) {
            continue;
        }
        pts.push(Point3::new(p.x, p.y, p.z + 0.01 * rng.normal()));
        lab.push(l);
    }
    labelled(pts, lab)
}

/// A patch whose surface leaves its points' box is refused by name, as the
/// single-patch commands refuse theirs; allowed, its extent is reported and
/// the other patches stay inside their limit.
#[test]
fn a_patch_that_flies_off_its_data_is_refused_by_name() {
    use scanfit::network::FaceFit;
    use scanfit::Error;
    let cloud = sheet_with_a_sparse_quarter();
    let mut c = ReconstructConfig::default();
    c.fit = FaceFit::Bspline { ctrl: (12, 12) };
    let e = run(&cloud, &c, &NoProgress).unwrap_err();
    let Error::LeavesData { patch, extent } = &e else {
        panic!("{e}");
    };
    assert_eq!(*patch, Some(3));
    // measured: 5654 outside a box of diagonal 1.38 (limit 0.25 of it)
    assert!(extent.samples_outside > 100.0 * extent.limit, "{extent:?}");
    // the single-patch rule: the larger of 10 spacings and 0.25 diagonals
    let spacing = extent.samples_outside / extent.samples_outside_spacings;
    let limit = (10.0 * spacing).max(0.25 * extent.diagonal);
    assert!((extent.limit - limit).abs() < 1e-9 * limit, "{extent:?}");
    let m = e.to_string();
    assert!(
        m.starts_with("patch 3: the surface leaves the data") && !m.contains('\n'),
        "{m}"
    );
    c.allow_extrapolation = true;
    let r = run(&cloud, &c, &NoProgress).unwrap();
    for p in &r.patches {
        assert_eq!(p.extent.leaves, p.id == 3, "patch {}: {:?}", p.id, p.extent);
    }
    // the default PDE route on the same data stays inside the limit
    let r = run(&cloud, &ReconstructConfig::default(), &NoProgress).unwrap();
    assert!(r.patches.iter().all(|p| !p.extent.leaves));
}

/// Without labels, `measure_model` gives each point to the patch at the
/// smallest orthogonal distance among those near it, so the per-patch
/// orthogonal RMSE of a two-patch sheet equals the labelled one (the points
/// the reconstruction fitted each patch to) within 3%. The nearest vertex
/// of a tessellation, the rule before, sent points near the shared edge to
/// the wrong patch: 0.130 against 0.094 on one grid.
#[test]
fn unlabelled_model_report_assigns_points_by_orthogonal_distance() {
    use scanfit::pipeline::measure_model::{self, Assignment, ModelMeasureConfig};
    let c = sheet(0.002);
    let halves: Vec<f64> = c
        .points()
        .iter()
        .map(|p| f64::from(u8::from(p.x > 1.0)))
        .collect();
    let c = c.with_attribute("label", halves).unwrap();
    let r = run(&c, &ReconstructConfig::default(), &NoProgress).unwrap();
    assert_eq!(r.patches.len(), 2);
    let cfg = ModelMeasureConfig::default();
    let labelled = measure_model::run(&r.complex, &c, &cfg, &NoProgress).unwrap();
    let bare = PointCloud::new(c.points().to_vec()).unwrap();
    let unlabelled = measure_model::run(&r.complex, &bare, &cfg, &NoProgress).unwrap();
    assert_eq!(unlabelled.assignment, Assignment::Nearest);
    let total: usize = unlabelled.patches.iter().map(|p| p.points).sum();
    assert_eq!(total, c.len());
    for (a, b) in unlabelled.patches.iter().zip(&labelled.patches) {
        let (oa, ob) = (a.orthogonal.unwrap().rmse, b.orthogonal.unwrap().rmse);
        assert!(
            (oa - ob).abs() <= 0.03 * ob,
            "patch {}: unlabelled orthogonal rmse {oa} ({} points) vs labelled {ob} ({} points)",
            a.id,
            a.points,
            b.points
        );
        // points change sides only along the shared edge (a column is 60)
        assert!(
            a.points.abs_diff(b.points) <= 60,
            "{} vs {}",
            a.points,
            b.points
        );
    }
}
