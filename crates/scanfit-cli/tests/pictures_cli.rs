//! Pictures end to end: `--up` (automatic for sheets stored y-up), the view
//! presets, and the colour bar kept off the drawing.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{ok, run, tmpdir};
use scanfit_io::render::viridis;

use std::path::Path;

/// A 60 x 40 wavy sheet stored y-up (thin along y), 2400 points.
fn y_up_sheet(path: &Path) {
    let mut s = String::from("x y z\n");
    for i in 0..60 {
        for j in 0..40 {
            let (x, z) = (i as f64, j as f64);
            let y = 2.0 * (x * 0.2).sin() * (z * 0.15).cos();
            s.push_str(&format!("{x} {y} {z}\n"));
        }
    }
    std::fs::write(path, s).unwrap();
}

/// The RGB pixels and width of a PNG.
fn pixels(path: &Path) -> (Vec<u8>, usize) {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    (buf, info.width as usize)
}

#[test]
fn up_auto_turns_a_y_up_sheet_as_up_y_does() {
    let d = tmpdir("pictures", "up");
    let input = d.join("sheet.xyz");
    y_up_sheet(&input);
    let picture = |up: &str| {
        let png = d.join(format!("n_{up}.png"));
        ok(&run(&[
            "cloud",
            "normals",
            input.to_str().unwrap(),
            "--up",
            up,
            "--view",
            "iso",
            "--png",
            png.to_str().unwrap(),
            "-q",
        ]));
        std::fs::read(&png).unwrap()
    };
    let (auto, y, z) = (picture("auto"), picture("y"), picture("z"));
    assert_eq!(auto, y, "--up auto on a sheet thin along y is --up y");
    assert_ne!(auto, z);
    let o = run(&["cloud", "normals", input.to_str().unwrap(), "--up", "w"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("unknown --up 'w'"), "{err}");
}

#[test]
fn view_presets_are_accepted_and_unknown_names_refused() {
    let d = tmpdir("pictures", "presets");
    let input = d.join("sheet.xyz");
    y_up_sheet(&input);
    let mut seen = Vec::new();
    for v in ["front", "top", "iso", "-60,35"] {
        let png = d.join(format!("{v}.png"));
        ok(&run(&[
            "cloud",
            "normals",
            input.to_str().unwrap(),
            "--view",
            v,
            "--up",
            "y",
            "--png",
            png.to_str().unwrap(),
            "-q",
        ]));
        seen.push(std::fs::read(&png).unwrap());
    }
    // four different pictures
    for a in 0..4 {
        for b in a + 1..4 {
            assert_ne!(seen[a], seen[b], "views {a} and {b}");
        }
    }
    let o = run(&[
        "cloud",
        "segment",
        input.to_str().unwrap(),
        "--view",
        "side",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("use front, top, iso or AZ,EL"), "{err}");
}

#[test]
fn the_deviation_bar_sits_right_of_the_surface_on_a_cloud_with_strays() {
    // a sheet (z up) with 5 points far above it: the fit's deviation picture
    // keeps its colours (99th percentile) and its bar in a strip of its own
    let d = tmpdir("pictures", "bar");
    let input = d.join("sheet.xyz");
    let mut s = String::from("x y z\n");
    for i in 0..50 {
        for j in 0..40 {
            let (x, y) = (i as f64, j as f64);
            let stray = if (i * 40 + j) % 400 == 7 { 30.0 } else { 0.0 };
            s.push_str(&format!("{x} {y} {}\n", (x * 0.2).sin() + stray));
        }
    }
    std::fs::write(&input, s).unwrap();
    let png = d.join("dev.png");
    ok(&run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "8",
        "--deviation-png",
        png.to_str().unwrap(),
        "--view",
        "top",
        "-q",
    ]));
    let (img, w) = pixels(&png);
    let h = img.len() / 3 / w;
    // the bar: the columns whose pixels at a quarter, half and three
    // quarters of the height are unshaded viridis colours (the surface's
    // are shaded)
    let rgb = |x: usize, y: usize| &img[(y * w + x) * 3..(y * w + x) * 3 + 3];
    let map: std::collections::HashSet<[u8; 3]> = (0..=10_000)
        .map(|k| viridis(k as f64 / 10_000.0).map(|c| (c * 255.0).round() as u8))
        .collect();
    let on_bar = |x: usize| {
        [h / 4, h / 2, 3 * h / 4]
            .iter()
            .all(|&y| map.contains(&[rgb(x, y)[0], rgb(x, y)[1], rgb(x, y)[2]]))
    };
    let bar: Vec<usize> = (w / 2..w).filter(|&x| on_bar(x)).collect();
    assert!(bar.len() >= 10, "{bar:?}");
    let bar_start = bar[0];
    let row = h / 2;
    let last_surface = (0..bar_start)
        .rev()
        .find(|&x| rgb(x, row) != [255, 255, 255])
        .unwrap();
    assert!(last_surface + 10 < bar_start, "{last_surface} {bar_start}");
    // the colours spread over the map: on a scale up to the strays'
    // deviation (0 .. max, 35 times the 99th percentile here) no pixel
    // would be brighter than viridis(0.03) (green channel < 20); up to the
    // 99th percentile the pulled region is green and yellow (measured 4.6%)
    let painted: Vec<&[u8]> = (0..last_surface)
        .flat_map(|x| (h / 4..3 * h / 4).map(move |y| (x, y)))
        .map(|(x, y)| rgb(x, y))
        .filter(|p| p != &[255, 255, 255])
        .collect();
    let bright = painted.iter().filter(|p| p[1] > 100).count();
    assert!(painted.len() > 10_000, "{}", painted.len());
    assert!(bright > painted.len() / 50, "{bright} of {}", painted.len());
}
