//! Golden files written by independent implementations (plyfile, pypcd4 +
//! python-lzf, laspy + lazrs; see tests/data/make_samples.py): the values
//! read must be exactly the ones the generator wrote.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use scanfit::Point3;
use scanfit_io::{read_cloud, read_points, Format, NonFinite, PointTable, ReadOptions};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn body_start(path: &Path, marker: &[u8]) -> u64 {
    let b = std::fs::read(path).unwrap();
    (b.windows(marker.len()).position(|w| w == marker).unwrap() + marker.len()) as u64
}

fn col<'a>(t: &'a PointTable, name: &str) -> &'a [f64] {
    t.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", t.columns))
}

#[test]
fn ply_in_three_encodings() {
    for name in [
        "sample_ascii.ply",
        "sample_binary_le.ply",
        "sample_binary_be.ply",
    ] {
        let path = data(name);
        // read_points (what the CLI calls) dispatches by extension
        let t = read_points(&path).unwrap();
        assert_eq!(t.format, Format::Ply);
        assert_eq!(
            t.points,
            vec![
                Point3::new(0.5, -1.25, 2.0),
                Point3::new(1.5, 1024.0, -0.0625),
                Point3::new(-8.0, 0.375, 0.001),
                Point3::new(3.0, 4.0, 5.0),
            ],
            "{name}"
        );
        assert_eq!(
            t.columns,
            ["x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "label", "u", "v"]
        );
        assert_eq!(col(&t, "nx"), &[0.0, 0.6f32 as f64, -1.0, 0.0]);
        assert_eq!(col(&t, "ny"), &[0.0, 0.8f32 as f64, 0.0, -1.0]);
        assert_eq!(col(&t, "nz"), &[1.0, 0.0, 0.0, 0.0]);
        assert_eq!(col(&t, "red"), &[255.0, 1.0, 10.0, 0.0]);
        assert_eq!(col(&t, "green"), &[0.0, 2.0, 20.0, 128.0]);
        assert_eq!(col(&t, "blue"), &[16.0, 3.0, 30.0, 255.0]);
        assert_eq!(col(&t, "label"), &[-3.0, 7.0, 0.0, 65535.0]);
        assert_eq!(col(&t, "u"), &[0.0, 0.25, 0.75, 1.0]);
        assert_eq!(col(&t, "v"), &[0.125, 0.5, 0.875, 1.0]);
        let cloud = t.to_cloud().unwrap();
        assert_eq!(
            cloud.normals().unwrap()[3],
            scanfit::Vector3::new(0.0, -1.0, 0.0)
        );
        assert_eq!(cloud.attribute("label").unwrap()[3], 65535.0);
        // where vertex 1 is: a line, or the byte offset of its record
        let h = body_start(&path, b"end_header\n");
        let p = path.display();
        let expected = match name {
            "sample_ascii.ply" => format!("{p}:23"),
            // vertex 0 is 51 bytes of scalars and a list of 2 shorts
            "sample_binary_le.ply" => format!("{p}: byte offset {} (vertex 1)", h + 56),
            // two faces come first (1 + 3*4 and 1 + 4*4 bytes), then
            // fixed 51-byte vertices
            _ => format!("{p}: byte offset {} (vertex 1)", h + 13 + 17 + 51),
        };
        assert_eq!(t.locate(1), expected);
    }
}

#[test]
fn pcd_in_three_encodings_with_a_nan_point() {
    for name in [
        "sample_ascii.pcd",
        "sample_binary.pcd",
        "sample_binary_compressed.pcd",
    ] {
        let path = data(name);
        let p = path.display();
        let e = read_points(&path).unwrap_err().to_string();
        let h = body_start(&path, b"DATA ");
        let expected = match name {
            "sample_ascii.pcd" => format!("{p}:13: x is NaN"),
            "sample_binary.pcd" => {
                let h = h + "binary\n".len() as u64;
                format!("{p}: byte offset {}: point 2: x is NaN", h + 2 * 24)
            }
            _ => format!("{p}: point 2: x is NaN"),
        };
        assert!(e.starts_with(&expected), "{e}\n{expected}");
        assert!(e.contains("NonFinite::Drop"), "{e}");
        let opts = ReadOptions {
            non_finite: NonFinite::Drop,
            ..Default::default()
        };
        let t = read_cloud(&path, &opts).unwrap();
        assert_eq!(t.dropped_non_finite, 1);
        assert_eq!(
            t.points,
            vec![
                Point3::new(0.5, -1.25, 2.0),
                Point3::new(1.5, 1024.0, -0.0625),
                Point3::new(-8.0, 0.375, 0.125),
                Point3::new(3.0, 4.0, 5.0),
            ],
            "{name}"
        );
        // the compressed sample has no ring field (see make_samples.py)
        let ring = name != "sample_binary_compressed.pcd";
        let mut columns = vec!["x", "y", "z", "intensity", "rgb"];
        if ring {
            columns.extend(["ring_0", "ring_1"]);
        }
        columns.extend(["red", "green", "blue"]);
        assert_eq!(t.columns, columns);
        assert_eq!(col(&t, "intensity"), &[0.0, 0.5, 100.25, 7.0]);
        assert_eq!(col(&t, "rgb"), &[16711696.0, 66051.0, 660510.0, 33023.0]);
        assert_eq!(col(&t, "red"), &[255.0, 1.0, 10.0, 0.0]);
        assert_eq!(col(&t, "green"), &[0.0, 2.0, 20.0, 128.0]);
        assert_eq!(col(&t, "blue"), &[16.0, 3.0, 30.0, 255.0]);
        if ring {
            assert_eq!(col(&t, "ring_0"), &[1.0, 2.0, 3.0, 4.0]);
            assert_eq!(col(&t, "ring_1"), &[-1.0, -2.0, -300.0, 32767.0]);
        }
        // point 2 of the table is record 3 of the file
        assert_eq!(t.file_index(2), 3);
        assert!(t.locate(2).contains(match name {
            "sample_ascii.pcd" => ":14",
            _ => "point 3",
        }));
    }
}

#[test]
fn las_and_laz_keep_georeferenced_coordinates_and_attributes() {
    for name in ["sample.las", "sample.laz"] {
        let path = data(name);
        let t = read_points(&path).unwrap();
        assert_eq!(t.format, Format::Las);
        // the crate's transform: raw * scale + offset, in f64
        let x = |r: i32| r as f64 * 0.001 + 500000.0;
        let y = |r: i32| r as f64 * 0.001 + 4100000.0;
        let z = |r: i32| r as f64 * 0.01 + 100.0;
        assert_eq!(
            t.points,
            vec![
                Point3::new(x(123456), y(654321), z(1234)),
                Point3::new(x(-1), y(0), z(-250)),
                Point3::new(x(999999), y(5), z(0)),
            ],
            "{name}"
        );
        assert!((t.points[0].x - 500123.456).abs() < 1e-9);
        assert!((t.points[0].y - 4100654.321).abs() < 1e-9);
        assert!((t.points[1].z - 97.5).abs() < 1e-12);
        assert_eq!(col(&t, "intensity"), &[100.0, 0.0, 65535.0]);
        assert_eq!(col(&t, "return_number"), &[1.0, 2.0, 3.0]);
        assert_eq!(col(&t, "number_of_returns"), &[1.0, 3.0, 3.0]);
        assert_eq!(col(&t, "classification"), &[2.0, 5.0, 6.0]);
        assert_eq!(col(&t, "point_source_id"), &[7.0, 7.0, 8.0]);
        assert_eq!(col(&t, "gps_time"), &[1.5, 250000.25, 0.0]);
        assert_eq!(col(&t, "red"), &[65535.0, 0.0, 256.0]);
        assert_eq!(col(&t, "green"), &[0.0, 32768.0, 512.0]);
        assert_eq!(col(&t, "blue"), &[1.0, 2.0, 3.0]);
        let p = path.display();
        if name == "sample.las" {
            let b = std::fs::read(&path).unwrap();
            let start = u32::from_le_bytes(b[96..100].try_into().unwrap()) as u64;
            assert_eq!(
                t.locate(1),
                format!("{p}: byte offset {} (point record 1)", start + 34)
            );
        } else {
            assert_eq!(t.locate(1), format!("{p}: point record 1"));
        }
        assert_eq!(t.into_cloud().unwrap().attributes().len(), 9);
    }
}

#[test]
fn las_header_errors() {
    let b = std::fs::read(data("sample.las")).unwrap();
    let opts = ReadOptions::default();
    let parse = |b: &[u8]| scanfit_io::parse_cloud(Path::new("s.las"), b, &opts);
    // a point count larger than the body
    let mut more = b.clone();
    more[107..111].copy_from_slice(&1_000_000_000u32.to_le_bytes());
    let e = parse(&more).unwrap_err().to_string();
    assert!(
        e.contains("declares 1000000000 point records of 34 bytes") && e.contains("3 complete"),
        "{e}"
    );
    let e = parse(&b[..b.len() - 10]).unwrap_err().to_string();
    assert!(e.contains("2 complete records"), "{e}");
    let e = parse(b"LASX and more").unwrap_err().to_string();
    assert!(e.contains("bad magic"), "{e}");
    let e = parse(&b[..50]).unwrap_err().to_string();
    assert!(e.contains("ends inside the LAS header"), "{e}");
}
