//! Tests of the PCD reader (kept in their own file, next to `pcd.rs`).
use super::*;
use crate::table::NonFinite;

fn read(bytes: &[u8]) -> Result<PointTable> {
    parse(Path::new("t.pcd"), bytes, &ReadOptions::default())
}

const HEAD: &str = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb normal _\nSIZE 4 4 8 4 2 1\nTYPE F F F F I U\nCOUNT 1 1 1 1 2 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";

fn record(x: f32, y: f32, z: f64, rgb: u32, n: [i16; 2]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend(x.to_le_bytes());
    b.extend(y.to_le_bytes());
    b.extend(z.to_le_bytes());
    b.extend(rgb.to_le_bytes());
    b.extend(n[0].to_le_bytes());
    b.extend(n[1].to_le_bytes());
    b.push(0);
    b
}

/// A column by name (empty when missing, which the comparisons then reject).
fn col<'a>(t: &'a PointTable, name: &str) -> &'a [f64] {
    t.column(name).unwrap_or(&[])
}

fn check(t: &PointTable) {
    assert_eq!(
        t.points,
        vec![Point3::new(1.5, -2.0, 0.1), Point3::new(0.0, 3.0, -1e10)]
    );
    assert_eq!(
        t.columns,
        vec!["x", "y", "z", "rgb", "normal_0", "normal_1", "red", "green", "blue"]
    );
    assert_eq!(col(t, "rgb"), &[0xff10_2030u32 as f64, 0x0000_00ff as f64]);
    assert_eq!(col(t, "normal_1"), &[-7.0, 32767.0]);
    assert_eq!(col(t, "red"), &[16.0, 0.0]);
    assert_eq!(col(t, "green"), &[32.0, 0.0]);
    assert_eq!(col(t, "blue"), &[48.0, 255.0]);
}

#[test]
fn binary_and_its_truncations() -> Result<()> {
    let mut b = format!("{HEAD}DATA binary\n").into_bytes();
    let h = b.len();
    b.extend(record(1.5, -2.0, 0.1, 0xff10_2030, [1, -7]));
    b.extend(record(0.0, 3.0, -1e10, 0xff, [0, 32767]));
    let t = read(&b)?;
    check(&t);
    assert_eq!(
        t.locate(1),
        format!("t.pcd: byte offset {} (point 1)", h + 25)
    );
    for cut in 0..b.len() {
        assert!(read(&b[..cut]).is_err(), "{cut}");
    }
    let e = read(&b[..h + 30]).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "t.pcd: byte offset {h}: the header declares 2 points of 25 bytes"
        )) && e.contains("1 complete"),
        "{e}"
    );
    Ok(())
}

#[test]
fn compressed_round_trip_with_a_hand_made_lzf_stream() -> Result<()> {
    // column-major: x block, y block, z block, rgb, normal, _
    let mut raw = Vec::new();
    for v in [1.5f32, 0.0] {
        raw.extend(v.to_le_bytes());
    }
    for v in [-2.0f32, 3.0] {
        raw.extend(v.to_le_bytes());
    }
    for v in [0.1f64, -1e10] {
        raw.extend(v.to_le_bytes());
    }
    for v in [0xff10_2030u32, 0xff] {
        raw.extend(v.to_le_bytes());
    }
    for v in [1i16, -7, 0, 32767] {
        raw.extend(v.to_le_bytes());
    }
    raw.extend([0u8, 0]);
    // LZF: literal runs of at most 32 bytes, then a back-reference that
    // repeats the last 2 bytes 3 times (overlapping copy)
    let mut lzf = Vec::new();
    for chunk in raw.chunks(32) {
        lzf.push(chunk.len() as u8 - 1);
        lzf.extend(chunk);
    }
    let mut expanded = raw.clone();
    expanded.extend([0, 0, 0, 0, 0, 0]);
    lzf.extend([(4 << 5) as u8, 1]);
    assert_eq!(lzf_decompress(&lzf, expanded.len()), Ok(expanded.clone()));
    assert!(lzf_decompress(&lzf, expanded.len() - 1).is_err());
    assert!(lzf_decompress(&[0x20, 5], 10)
        .unwrap_err()
        .contains("before the start"));
    // the file itself (without the extra bytes)
    let mut lzf = Vec::new();
    for chunk in raw.chunks(32) {
        lzf.push(chunk.len() as u8 - 1);
        lzf.extend(chunk);
    }
    let mut b = format!("{HEAD}DATA binary_compressed\n").into_bytes();
    b.extend((lzf.len() as u32).to_le_bytes());
    b.extend((raw.len() as u32).to_le_bytes());
    b.extend(&lzf);
    let t = read(&b)?;
    check(&t);
    assert_eq!(t.locate(1), "t.pcd: point 1");
    for cut in 0..b.len() {
        assert!(read(&b[..cut]).is_err(), "{cut}");
    }
    Ok(())
}

#[test]
fn ascii_with_nan_points() -> Result<()> {
    let text = format!(
        "{}DATA ascii\n1.5 -2 0.1 4279246896 1 -7 0\nnan nan nan 0 0 0 0\n0 3 -1e10 255 0 32767 0\n",
        HEAD.replace("POINTS 2", "POINTS 3")
    );
    let e = read(text.as_bytes()).unwrap_err().to_string();
    assert!(e.starts_with("t.pcd:13: x is NaN"), "{e}");
    let opts = ReadOptions {
        non_finite: NonFinite::Drop,
        ..Default::default()
    };
    let t = parse(Path::new("t.pcd"), text.as_bytes(), &opts)?;
    check(&t);
    assert_eq!(t.locate(1), "t.pcd:14");
    assert_eq!(t.dropped_non_finite, 1);
    // the older float form of a packed colour: the bits of the float
    let old = text.replace("4279246896", &format!("{:e}", f32::from_bits(0x0010_2030)));
    let t = parse(Path::new("t.pcd"), old.as_bytes(), &opts)?;
    assert_eq!(col(&t, "rgb")[0], 0x0010_2030 as f64);
    assert_eq!(col(&t, "green")[0], 32.0);
    let e = read(text.replace("POINTS 3", "POINTS 1000000000000").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("ends after 3 of the 1000000000000 points"),
        "{e}"
    );
    let e = read(
        text.replace("TYPE F F F F I U", "TYPE F F F F I Q")
            .as_bytes(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("t.pcd:5: unknown TYPE 'Q'"), "{e}");
    let e = read(b"ply\n").unwrap_err().to_string();
    assert!(e.contains("bad magic"), "{e}");
    Ok(())
}

#[test]
fn every_line_ending_in_ascii_files() -> Result<()> {
    for eol in ["\n", "\r\n", "\r"] {
        let text = [
            "# .PCD v0.7",
            "VERSION 0.7",
            "FIELDS x y z",
            "SIZE 4 4 4",
            "TYPE F F F",
            "WIDTH 2",
            "HEIGHT 1",
            "POINTS 2",
            "DATA ascii",
            "1 2 3",
            "4 5 6",
        ]
        .join(eol)
            + eol;
        let t = read(text.as_bytes())?;
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(4., 5., 6.)],
            "{eol:?}"
        );
        assert_eq!(t.locate(1), "t.pcd:11", "{eol:?}");
        assert!(t.warnings.is_empty(), "{eol:?}: {:?}", t.warnings);
    }
    Ok(())
}

#[test]
fn counts_that_disagree_with_the_data() -> Result<()> {
    let head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 2\n";
    // POINTS against WIDTH x HEIGHT, and a line more than POINTS: warnings
    let t = read(format!("{head}DATA ascii\n1 2 3\n4 5 6\n7 8 9\n").as_bytes())?;
    assert_eq!(t.points.len(), 2);
    assert_eq!(
        t.warnings,
        [
            "t.pcd: the header declares POINTS 2 but WIDTH x HEIGHT = 3; the 2 points of POINTS were read (fix the header)",
            "t.pcd: 1 more non-empty lines follow the 2 points the header declares; they were not read (is POINTS too small?)"
        ]
    );
    // binary: a record after the declared ones
    let mut b = format!("{head}DATA binary\n").into_bytes();
    for v in 0..9 {
        b.extend((v as f32).to_le_bytes());
    }
    let t = read(&b)?;
    assert_eq!(t.points[1], Point3::new(3., 4., 5.));
    assert!(
        t.warnings[1].contains("12 bytes (1 points of 12 bytes) follow the 2 points"),
        "{:?}",
        t.warnings
    );
    // fewer than POINTS: an error
    let e = read(format!("{head}DATA ascii\n1 2 3\n").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("the file ends after 1 of the 2 points"), "{e}");
    // too many values per point
    let wide = format!(
        "VERSION 0.7\nFIELDS x y z w\nSIZE 4 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 2000\nPOINTS 1\nDATA ascii\n{}\n",
        "0 ".repeat(2003)
    );
    let e = read(wide.as_bytes()).unwrap_err().to_string();
    assert!(
        e.contains("the fields declare 2003 values per point; a point file may have at most 1024"),
        "{e}"
    );
    Ok(())
}
