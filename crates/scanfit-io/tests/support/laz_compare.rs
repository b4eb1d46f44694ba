//! Comparisons shared by the LAZ decoder tests (`tests/laz10.rs`,
//! `tests/laz14.rs`): decoded points against the `laz` crate's, and the
//! reader's columns against the `las` crate's.
#![allow(dead_code)]

use std::error::Error;
use std::fmt::Debug;
use std::io::Cursor;
use std::path::Path;

use scanfit_io::{parse_cloud, ReadOptions};

pub type TestResult = Result<(), Box<dyn Error>>;

/// Asserts the points `ours` equal to `theirs`, one by one, their GPS
/// times (`gps`) bit for bit.
pub fn same<T: PartialEq + Debug>(ours: &[T], theirs: &[T], gps: fn(&T) -> f64, what: &str) {
    assert_eq!(ours.len(), theirs.len(), "{what}: point counts");
    for (k, (p, q)) in ours.iter().zip(theirs).enumerate() {
        assert!(
            p == q && gps(p).to_bits() == gps(q).to_bits(),
            "{what}: point {k}:\n ours {p:?}\n laz  {q:?}"
        );
    }
}

/// A point's fields as the `las` crate gives them, named as the reader
/// names its columns: the five every format has, then GPS time, colour and
/// NIR where the crate gives them.
fn crate_fields(p: &las::Point) -> Vec<(&'static str, f64)> {
    let mut fields = vec![
        ("intensity", f64::from(p.intensity)),
        ("return_number", f64::from(p.return_number)),
        ("number_of_returns", f64::from(p.number_of_returns)),
        ("classification", f64::from(u8::from(p.classification))),
        ("point_source_id", f64::from(p.point_source_id)),
    ];
    fields.extend(p.gps_time.map(|t| ("gps_time", t)));
    if let Some(c) = p.color {
        fields.extend([
            ("red", f64::from(c.red)),
            ("green", f64::from(c.green)),
            ("blue", f64::from(c.blue)),
        ]);
    }
    fields.extend(p.nir.map(|v| ("nir", f64::from(v))));
    fields
}

/// The reader (`parse_cloud`) on the LAZ file `bytes` of `n` points gives
/// the columns, coordinates and column values the `las` crate gives for
/// the same file, bit for bit; returns the names of the extra columns.
pub fn reader_matches_the_las_crate(
    bytes: &[u8],
    n: usize,
    what: &str,
) -> Result<Vec<String>, Box<dyn Error>> {
    let table = parse_cloud(Path::new("f.laz"), bytes, &ReadOptions::default())?;
    let mut reader = las::Reader::new(Cursor::new(bytes.to_vec()))?;
    let pd = reader.read_points(n as u64)?;
    let points = pd.points().collect::<Result<Vec<las::Point>, _>>()?;
    assert_eq!((table.points.len(), points.len()), (n, n), "{what}");
    for (k, p) in points.iter().enumerate() {
        let q = table.points[k];
        assert_eq!(
            (q.x.to_bits(), q.y.to_bits(), q.z.to_bits()),
            (p.x.to_bits(), p.y.to_bits(), p.z.to_bits()),
            "{what}, point {k}"
        );
        let fields = crate_fields(p);
        let names: Vec<&str> = fields.iter().map(|f| f.0).collect();
        assert_eq!(table.columns[3..], names[..], "{what}, point {k}");
        for (c, (name, v)) in fields.iter().enumerate() {
            assert_eq!(
                table.extra[c][k].to_bits(),
                v.to_bits(),
                "{what}, point {k}, {name}"
            );
        }
    }
    Ok(table.columns[3..].to_vec())
}
