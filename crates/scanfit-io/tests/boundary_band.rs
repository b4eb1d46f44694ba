//! The alpha-shape boundary of big clouds is taken from a band along the
//! boundary (`scanfit::cloud::boundary`, [PDE23] §4.1): on every shipped
//! sample the band's loops are the full triangulation's, point for point and
//! in the same order, at the same alpha; and the default (sampled spacing
//! above 200,000 points) leaves the samples, all smaller, unchanged.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use scanfit::cloud::boundary::{boundary_loops, BoundaryConfig};

#[test]
fn band_loops_of_the_shipped_samples_equal_the_full_ones() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data");
    for file in [
        "terrain_50k.xyz",
        "patch_20k.ply",
        "nasty_face.xyz",
        "part_30k.ply",
        "umbrella_20k.ply",
        "bottle_12k.ply",
    ] {
        let t =
            scanfit_io::read_cloud(&dir.join(file), &scanfit_io::ReadOptions::default()).unwrap();
        let pts = &t.points;
        let full = boundary_loops(
            pts,
            &BoundaryConfig {
                sample_above: usize::MAX,
                ..Default::default()
            },
        )
        .unwrap();
        // the default: these samples are below the sampling threshold
        let default = boundary_loops(pts, &BoundaryConfig::default()).unwrap();
        assert_eq!(default, full, "{file}");
        // the band (sample_above 0) at the full triangulation's alpha
        let band = boundary_loops(
            pts,
            &BoundaryConfig {
                alpha: Some(full.alpha),
                sample_above: 0,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(band.loops, full.loops, "{file}");
        assert_eq!(band.areas, full.areas, "{file}");
        assert_eq!(band.triangles, full.triangles, "{file}");
        eprintln!(
            "{file}: {} points, {} loops ({} outer points), {} triangles",
            pts.len(),
            full.loops.len(),
            full.outer_loop().len(),
            full.triangles
        );
    }
}
