//! LAS and LAZ reader, through the `las` crate (with its `laz` feature).
//!
//! Coordinates come out in the file's georeferenced frame (raw integer times
//! scale plus offset, as the crate computes them in f64). Kept per point:
//! intensity, return_number, number_of_returns, classification,
//! point_source_id, and when the point format has them gps_time, red, green,
//! blue and nir.
//!
//! Before the crate sees a file, the sizes that would make it allocate
//! (the extended VLR's length, the LAZ chunk count, the point count) are
//! checked against the file's size here; points are then read in batches so
//! memory grows with the data actually present.

use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use scanfit::Point3;

use crate::table::{capacity, Format, Origin, PointTable, ReadOptions};
use crate::{Error, Result};

/// Points decoded per call into the crate.
const BATCH: u64 = 1 << 18;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    b.get(at..at + 2)?.try_into().ok().map(u16::from_le_bytes)
}
fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)?.try_into().ok().map(u32::from_le_bytes)
}
fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    b.get(at..at.checked_add(8)?)?
        .try_into()
        .ok()
        .map(u64::from_le_bytes)
}

/// What the raw header says, as far as the size checks need it.
struct Raw {
    offset_to_points: u64,
    compressed: bool,
    record_len: u64,
}

/// Checks the raw header's sizes against the file before the crate reads it.
fn precheck(path: &Path, bytes: &[u8]) -> Result<Raw> {
    let invalid = |message: String| Error::Invalid {
        path: path.to_path_buf(),
        message,
    };
    let binary = |offset: u64, message: String| Error::Binary {
        path: path.to_path_buf(),
        offset,
        message,
    };
    if !bytes.starts_with(b"LASF") {
        return Err(invalid(
            "not a LAS/LAZ file: it does not start with 'LASF' (bad magic)".into(),
        ));
    }
    let len = bytes.len() as u64;
    let (Some(minor), Some(header_size), Some(offset), Some(format), Some(record_len)) = (
        bytes.get(25).copied(),
        u16_at(bytes, 94),
        u32_at(bytes, 96),
        bytes.get(104).copied(),
        u16_at(bytes, 105),
    ) else {
        return Err(invalid(format!(
            "the file ends inside the LAS header ({len} bytes); it is truncated"
        )));
    };
    if u64::from(header_size) > len || u64::from(offset) > len {
        return Err(invalid(format!(
            "the header declares {header_size} header bytes and point data at byte {offset}, but the file has {len} bytes; it is truncated"
        )));
    }
    if minor >= 4 && header_size >= 247 {
        if let (Some(start), Some(count)) = (u64_at(bytes, 235), u32_at(bytes, 243)) {
            if start > 0 && count > 0 {
                let length = start
                    .checked_add(20)
                    .and_then(|at| usize::try_from(at).ok())
                    .and_then(|at| u64_at(bytes, at));
                let fits = length.is_some_and(|l| {
                    start
                        .checked_add(60)
                        .and_then(|s| s.checked_add(l))
                        .is_some_and(|end| end <= len)
                });
                if !fits {
                    return Err(binary(start, format!(
                        "the extended VLR declared here does not fit in the file's {len} bytes; the file is truncated or its header is damaged"
                    )));
                }
            }
        }
    }
    let compressed = format & 0xc0 != 0;
    if compressed {
        // the chunk table: its entry count sizes an allocation in the crate
        let at = u64_at(bytes, offset as usize).map(|v| v as i64);
        let table = match at {
            Some(-1) => bytes.len().checked_sub(8).and_then(|k| u64_at(bytes, k)),
            Some(v) if v > 0 => Some(v as u64),
            _ => None,
        };
        if let Some(t) = table.and_then(|t| usize::try_from(t).ok()) {
            if let Some(chunks) = t.checked_add(4).and_then(|k| u32_at(bytes, k)) {
                if u64::from(chunks) > len {
                    return Err(binary(t as u64, format!(
                        "the LAZ chunk table declares {chunks} chunks, more than the file's {len} bytes could hold; the file is damaged"
                    )));
                }
            }
        }
    }
    Ok(Raw {
        offset_to_points: u64::from(offset),
        compressed,
        record_len: u64::from(record_len),
    })
}

/// Columns read from the crate.
#[derive(Default)]
struct Decoded {
    points: Vec<Point3>,
    names: Vec<&'static str>,
    columns: Vec<Vec<f64>>,
    declared: u64,
}

/// Everything that calls into the `las` crate. It runs inside
/// `catch_unwind` (see `parse`): the crate is third-party code, and a panic
/// on a damaged file must become an error, not a crash.
fn read_with_crate(path: &Path, bytes: Vec<u8>, raw: &Raw) -> Result<Decoded> {
    let total = bytes.len() as u64;
    let lerr = |e: las::Error| Error::Invalid {
        path: path.to_path_buf(),
        message: format!("cannot read the LAS/LAZ data: {e}"),
    };
    let mut reader = las::Reader::new(Cursor::new(bytes)).map_err(lerr)?;
    let header = reader.header().clone();
    let n = header.number_of_points();
    let fmt = *header.point_format();
    let record = u64::from(fmt.len()).max(1);
    let avail = total.saturating_sub(raw.offset_to_points);
    if !raw.compressed && (n as u128) * (record as u128) > avail as u128 {
        return Err(Error::Binary {
            path: path.to_path_buf(),
            offset: raw.offset_to_points,
            message: format!(
                "the header declares {n} point records of {record} bytes, but only {avail} bytes follow: {} complete records; the file is truncated or its point count is wrong",
                avail / record
            ),
        });
    }
    // LAZ cannot compress a record below a few bits: a count beyond this is
    // a damaged header, not data
    if raw.compressed && n / 64 > total {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the header declares {n} points, more than {total} compressed bytes can hold; the file is damaged"
            ),
        });
    }
    let mut names = vec![
        "intensity",
        "return_number",
        "number_of_returns",
        "classification",
        "point_source_id",
    ];
    if fmt.has_gps_time {
        names.push("gps_time");
    }
    if fmt.has_color {
        names.extend(["red", "green", "blue"]);
    }
    if fmt.has_nir {
        names.push("nir");
    }
    let cap = capacity(n, (avail / record) as usize).min(1 << 24);
    let mut points = Vec::with_capacity(cap);
    let mut columns = vec![Vec::with_capacity(cap); names.len()];
    let mut pd = las::PointDataBuilder::new().for_header(&header).build();
    let mut read = 0u64;
    while read < n {
        let got = reader.fill_points(BATCH, &mut pd).map_err(lerr)?;
        if got == 0 {
            break;
        }
        read += got;
        points.extend(
            pd.x()
                .zip(pd.y())
                .zip(pd.z())
                .map(|((x, y), z)| Point3::new(x, y, z)),
        );
        let mut cols = columns.iter_mut();
        let mut push = |values: &mut dyn Iterator<Item = f64>| {
            if let Some(c) = cols.next() {
                c.extend(values);
            }
        };
        push(&mut pd.intensity().map(f64::from));
        push(&mut pd.return_number().map(f64::from));
        push(&mut pd.number_of_returns().map(f64::from));
        push(&mut pd.classification().map(f64::from));
        push(&mut pd.point_source_id().map(f64::from));
        if let Some(g) = pd.gps_time() {
            push(&mut g.into_iter());
        }
        if let Some(rgb) = pd.rgb() {
            let rgb: Vec<(u16, u16, u16)> = rgb.collect();
            push(&mut rgb.iter().map(|c| f64::from(c.0)));
            push(&mut rgb.iter().map(|c| f64::from(c.1)));
            push(&mut rgb.iter().map(|c| f64::from(c.2)));
        }
        if let Some(nir) = pd.nir() {
            push(&mut nir.map(f64::from));
        }
    }
    Ok(Decoded {
        points,
        names,
        columns,
        declared: n,
    })
}

/// Reads a LAS or LAZ file's bytes (`path` is for messages).
pub(crate) fn parse(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    let raw = precheck(path, bytes)?;
    // catch_unwind is used here and only here, around the third-party `las`
    // crate: our own readers return errors and never panic on file content.
    let decoded = catch_unwind(AssertUnwindSafe(|| {
        read_with_crate(path, bytes.to_vec(), &raw)
    }))
    .map_err(|_| Error::Invalid {
        path: path.to_path_buf(),
        message: "the LAS/LAZ reader failed on this file (it is damaged or uses a variant the las crate does not handle)".into(),
    })??;
    let n = decoded.points.len();
    if (n as u64) < decoded.declared {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the header declares {} points, but the data holds {n}; the file is truncated",
                decoded.declared
            ),
        });
    }
    if decoded.columns.iter().any(|c| c.len() != n) {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: "the LAS/LAZ columns have different lengths; the file is damaged".into(),
        });
    }
    let mut columns: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
    columns.extend(decoded.names.iter().map(|s| s.to_string()));
    PointTable {
        path: path.to_path_buf(),
        format: Format::Las,
        points: decoded.points,
        columns,
        extra: decoded.columns,
        origin: if raw.compressed {
            Origin::Indices
        } else {
            Origin::Records {
                start: raw.offset_to_points,
                stride: raw.record_len,
            }
        },
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    }
    .finish(options.non_finite)
}
