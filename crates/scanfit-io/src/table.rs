//! The table every point reader fills: positions, named extra columns and
//! where each point came from in the file (a line, a byte offset or an index),
//! plus the options of the readers.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use scanfit::{Point3, PointCloud};

use crate::{Error, Result};

/// A point-file format the readers know.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stanford PLY: ascii, binary_little_endian or binary_big_endian.
    Ply,
    /// PCL's PCD: ascii, binary or binary_compressed.
    Pcd,
    /// ASPRS LAS, compressed (LAZ) or not.
    Las,
    /// Text: XYZ, CSV, TXT, PTS, ASC (one point per line).
    Text,
    /// STL, binary or ascii: the triangles' corners (welded) with
    /// area-weighted vertex normals.
    Stl,
    /// Wavefront OBJ: the `v` vertices with normals from `vn` or the faces.
    Obj,
}

/// File extensions the readers know, with their format.
pub const EXTENSIONS: [(&str, Format); 11] = [
    ("ply", Format::Ply),
    ("pcd", Format::Pcd),
    ("las", Format::Las),
    ("laz", Format::Las),
    ("xyz", Format::Text),
    ("csv", Format::Text),
    ("txt", Format::Text),
    ("pts", Format::Text),
    ("asc", Format::Text),
    ("stl", Format::Stl),
    ("obj", Format::Obj),
];

impl Format {
    /// The format of a file by its extension (ASCII case-insensitive):
    /// `Ok(None)` without an extension, an error naming the supported ones
    /// for an unknown extension.
    pub fn from_path(path: &Path) -> Result<Option<Format>> {
        let Some(ext) = path.extension() else {
            return Ok(None);
        };
        let ext = ext.to_string_lossy().to_ascii_lowercase();
        match EXTENSIONS.iter().find(|(e, _)| *e == ext) {
            Some(&(_, f)) => Ok(Some(f)),
            None => Err(Error::Invalid {
                path: path.to_path_buf(),
                message: format!(
                    "'.{ext}' files are not supported; give a point file with one of the extensions {} (or {FORMAT_ADVICE})",
                    EXTENSIONS
                        .iter()
                        .map(|(e, _)| format!(".{e}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }),
        }
    }

    /// The format of a file by its first bytes: PLY (`ply`), LAS (`LASF`),
    /// PCD (`# .PCD` or `VERSION`), STL (ascii `solid` with facets, or a
    /// binary file whose size matches its triangle count), OBJ (a first
    /// statement `v`, `vn`, `o`, ...), otherwise text.
    pub fn sniff(bytes: &[u8]) -> Format {
        match Format::magic(bytes) {
            Some(f) => f,
            None if crate::obj::sniff(bytes) => Format::Obj,
            None => Format::Text,
        }
    }

    /// The format of a file whose first bytes say it without doubt, as a
    /// file named `.xyz` may still be a PLY: `ply` followed by a line end,
    /// `LASF`, `# .PCD`, an ascii STL (`solid` with facets) or a binary STL
    /// whose size matches its count.
    pub fn magic(bytes: &[u8]) -> Option<Format> {
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r") {
            Some(Format::Ply)
        } else if bytes.starts_with(b"LASF") {
            Some(Format::Las)
        } else if bytes.starts_with(b"# .PCD") || bytes.starts_with(b"VERSION") {
            Some(Format::Pcd)
        } else if crate::stl::sniff(bytes) {
            Some(Format::Stl)
        } else if bytes.starts_with(b"ply") {
            Some(Format::Ply)
        } else {
            None
        }
    }

    /// The format's name in messages (`PLY`, `text`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "PLY",
            Format::Pcd => "PCD",
            Format::Las => "LAS/LAZ",
            Format::Text => "text",
            Format::Stl => "STL",
            Format::Obj => "OBJ",
        }
    }

    /// The word for one record of the format in messages (`vertex` for PLY).
    pub fn record_noun(self) -> &'static str {
        match self {
            Format::Ply | Format::Stl | Format::Obj => "vertex",
            Format::Las => "point record",
            Format::Pcd | Format::Text => "point",
        }
    }
}

/// The advice in reader messages on dropping non-finite points; a front
/// with its own words for it replaces it ([`Error::with_advice`]).
pub const DROP_ADVICE: &str =
    "read with ReadOptions { non_finite: NonFinite::Drop, .. } to leave such points out";

/// The advice in reader messages on choosing the format whatever the
/// extension; replaced as [`DROP_ADVICE`] is.
pub const FORMAT_ADVICE: &str = "choose the format with ReadOptions::format";

/// What to do with points whose x, y or z is NaN or infinite.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NonFinite {
    /// Fail, naming the first such point and where it is in the file.
    #[default]
    Reject,
    /// Leave such points out; [`PointTable::dropped_non_finite`] counts them.
    Drop,
}

/// Options of [`crate::read_cloud`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadOptions {
    /// The format; `None` chooses it by the file's extension (and by its
    /// first bytes when it has none).
    pub format: Option<Format>,
    /// Points with a non-finite coordinate: reject (default) or drop.
    pub non_finite: NonFinite,
}

/// Where the points of a table are in their file.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// Text: the 1-based line number of each point.
    Lines(Vec<usize>),
    /// Fixed-size binary records: record `k` of the file starts at byte
    /// `start + k * stride`.
    Records {
        /// byte offset of the first record
        start: u64,
        /// bytes per record
        stride: u64,
    },
    /// Variable-size binary records: the byte offset of each point's record.
    Offsets(Vec<u64>),
    /// Compressed data: only the record's index in the file is known.
    Indices,
}

/// Points read from a file, with their extra columns and where each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct PointTable {
    /// The file the points came from.
    pub path: PathBuf,
    /// The file's format.
    pub format: Format,
    /// The positions.
    pub points: Vec<Point3>,
    /// Names of all columns: `x`, `y`, `z`, then one per extra column.
    pub columns: Vec<String>,
    /// Extra columns beyond x, y, z: `extra[c][i]` is column `c + 3` of point `i`.
    pub extra: Vec<Vec<f64>>,
    /// Where the points are in the file (see [`PointTable::locate`]).
    pub origin: Origin,
    /// The record index in the file of each point when some were dropped
    /// (`None`: point `i` is record `i`).
    pub file_index: Option<Vec<usize>>,
    /// How many points were left out for a non-finite coordinate
    /// ([`NonFinite::Drop`]).
    pub dropped_non_finite: usize,
    /// What the reader accepted but the caller should hear about, one
    /// sentence each, naming the file: a header count that disagrees with
    /// the data, bytes after the last record, ... (the CLI prints them).
    pub warnings: Vec<String>,
}

impl PointTable {
    /// The record index in the file of point `index`.
    pub fn file_index(&self, index: usize) -> usize {
        match &self.file_index {
            Some(v) => v.get(index).copied().unwrap_or(index),
            None => index,
        }
    }

    /// The 1-based line of point `index` for a text file.
    pub fn line(&self, index: usize) -> Option<usize> {
        match &self.origin {
            Origin::Lines(l) => l.get(index).copied(),
            _ => None,
        }
    }

    /// The byte offset of point `index`'s record for a binary file.
    pub fn byte_offset(&self, index: usize) -> Option<u64> {
        if index >= self.points.len() {
            return None;
        }
        match &self.origin {
            Origin::Records { start, stride } => {
                Some(start.saturating_add(stride.saturating_mul(self.file_index(index) as u64)))
            }
            Origin::Offsets(o) => o.get(index).copied(),
            Origin::Lines(_) | Origin::Indices => None,
        }
    }

    /// Where point `index` is, for messages: `file:line` for text,
    /// `file: byte offset N (vertex k)` for binary records, `file: point k`
    /// for compressed data.
    pub fn locate(&self, index: usize) -> String {
        let path = self.path.display();
        if index >= self.points.len() {
            return path.to_string();
        }
        let noun = self.format.record_noun();
        let k = self.file_index(index);
        if let Some(l) = self.line(index) {
            format!("{path}:{l}")
        } else if let Some(o) = self.byte_offset(index) {
            format!("{path}: byte offset {o} ({noun} {k})")
        } else {
            format!("{path}: {noun} {k}")
        }
    }

    /// An error about point `index` located as [`PointTable::locate`] does;
    /// `message` follows the location and should say what to change.
    pub fn error_at(&self, index: usize, message: String) -> Error {
        let path = self.path.clone();
        let noun = self.format.record_noun();
        let k = self.file_index(index);
        if let Some(line) = self.line(index) {
            Error::Parse {
                path,
                line,
                message,
            }
        } else if let Some(offset) = self.byte_offset(index) {
            Error::Binary {
                path,
                offset,
                message: format!("{noun} {k}: {message}"),
            }
        } else {
            Error::Invalid {
                path,
                message: format!("{noun} {k}: {message}"),
            }
        }
    }

    /// The extra column named `name` (ASCII case-insensitive), if any.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.extra
            .get(self.extra_index(name)?)
            .map(|v| v.as_slice())
    }

    /// Moves the extra column `name` out of the table (no copy; as
    /// [`PointTable::column`] finds it), leaving it empty.
    pub fn take_column(&mut self, name: &str) -> Option<Vec<f64>> {
        let i = self.extra_index(name)?;
        self.extra.get_mut(i).map(std::mem::take)
    }

    /// The index in `extra` of the column `name` (exact name first, then
    /// ignoring case); `None` for x, y, z and unknown names.
    fn extra_index(&self, name: &str) -> Option<usize> {
        let i = self.columns.iter().position(|c| c == name).or_else(|| {
            self.columns
                .iter()
                .position(|c| c.eq_ignore_ascii_case(name))
        })?;
        i.checked_sub(3)
    }

    /// The points as a [`PointCloud`] with every extra column as an attribute.
    pub fn to_cloud(&self) -> Result<PointCloud> {
        self.clone().into_cloud()
    }

    /// Turns the table into a [`PointCloud`] with every extra column as an
    /// attribute (a name that repeats keeps its last column).
    pub fn into_cloud(self) -> Result<PointCloud> {
        let geometry = |path: &Path, error| Error::Geometry {
            path: path.to_path_buf(),
            error,
        };
        let mut cloud = PointCloud::new(self.points).map_err(|e| geometry(&self.path, e))?;
        for (name, values) in self.columns.iter().skip(3).zip(self.extra) {
            cloud
                .set_attribute(name, values)
                .map_err(|e| geometry(&self.path, e))?;
        }
        Ok(cloud)
    }

    /// Applies the non-finite policy and the empty-file check: the last step
    /// of every binary reader.
    pub(crate) fn finish(mut self, policy: NonFinite) -> Result<PointTable> {
        let finite = |p: &Point3| p.coords.iter().all(|v| v.is_finite());
        if let Some(i) = self.points.par_iter().position_first(|p| !finite(p)) {
            match policy {
                NonFinite::Reject => {
                    let p = self.points.get(i).copied().unwrap_or_else(Point3::origin);
                    let (axis, v) = ["x", "y", "z"]
                        .into_iter()
                        .zip(p.coords.iter().copied())
                        .find(|(_, v)| !v.is_finite())
                        .unwrap_or(("x", f64::NAN));
                    return Err(self.error_at(
                        i,
                        format!(
                            "{axis} is {v}; every coordinate must be a finite number (fix the file, or {DROP_ADVICE})"
                        ),
                    ));
                }
                NonFinite::Drop => self.drop_non_finite(),
            }
        }
        if self.points.is_empty() {
            return Err(Error::Invalid {
                path: self.path,
                message: if self.dropped_non_finite > 0 {
                    format!(
                        "no points left: all {} have a non-finite coordinate",
                        self.dropped_non_finite
                    )
                } else {
                    "no points found (the file declares none); give a file with at least one point"
                        .into()
                },
            });
        }
        Ok(self)
    }

    /// Removes the points with a non-finite coordinate, keeping the columns,
    /// origins and file indices of the others.
    fn drop_non_finite(&mut self) {
        let keep: Vec<bool> = self
            .points
            .par_iter()
            .map(|p| p.coords.iter().all(|v| v.is_finite()))
            .collect();
        let before = self.points.len();
        self.retain(&keep);
        self.dropped_non_finite += before - self.points.len();
    }

    /// Keeps the points `i` with `keep[i]` (a missing entry keeps), with
    /// their columns, and where they are in the file (lines, offsets, record
    /// indices), so messages about the kept points still name their place.
    ///
    /// ```
    /// use scanfit_io::{parse_cloud, ReadOptions};
    /// let mut t = parse_cloud("p.xyz".as_ref(), b"0 0 0\n1 1 1\n2 2 2\n", &ReadOptions::default())?;
    /// t.retain(&[true, false, true]);
    /// assert_eq!((t.points.len(), t.locate(1)), (2, "p.xyz:3".to_string()));
    /// # Ok::<(), scanfit_io::Error>(())
    /// ```
    pub fn retain(&mut self, keep: &[bool]) {
        let keep: Vec<bool> = (0..self.points.len())
            .map(|i| keep.get(i).copied().unwrap_or(true))
            .collect();
        fn filter<T: Copy>(v: &[T], keep: &[bool]) -> Vec<T> {
            v.iter()
                .zip(keep)
                .filter(|(_, &k)| k)
                .map(|(&x, _)| x)
                .collect()
        }
        let index: Vec<usize> = match &self.file_index {
            Some(v) => filter(v, &keep),
            None => (0..keep.len())
                .zip(&keep)
                .filter(|(_, &k)| k)
                .map(|(i, _)| i)
                .collect(),
        };
        self.points = filter(&self.points, &keep);
        for c in &mut self.extra {
            *c = filter(c, &keep);
        }
        match &mut self.origin {
            Origin::Lines(l) => *l = filter(l, &keep),
            Origin::Offsets(o) => *o = filter(o, &keep),
            Origin::Records { .. } | Origin::Indices => {}
        }
        self.file_index = Some(index);
    }
}

/// Most columns (x, y, z and the extra ones) a point file may have. Point
/// files carry tens of columns; a header or line declaring more is refused
/// before anything is allocated from it, which also keeps the work per
/// column (naming, attribute lookup) bounded.
pub const MAX_COLUMNS: usize = 1024;

/// The lines of `text`, split at LF, CRLF or a lone CR (classic Mac), with
/// their 1-based numbers; the terminators are not part of the lines. A
/// final terminator does not start an empty last line.
pub(crate) fn split_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut rest = text;
    let mut number = 0usize;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        number += 1;
        let (line, next) = match rest.find(['\n', '\r']) {
            Some(k) => {
                let after = if rest[k..].starts_with("\r\n") {
                    k + 2
                } else {
                    k + 1
                };
                (&rest[..k], &rest[after..])
            }
            None => (rest, ""),
        };
        rest = next;
        Some((number, line))
    })
}

/// Capacity to reserve for `claimed` records when at most `available` can
/// exist (each record needs at least one byte or line): a header that claims
/// 10^12 points never allocates more than the file could hold.
pub(crate) fn capacity(claimed: u64, available: usize) -> usize {
    usize::try_from(claimed)
        .unwrap_or(usize::MAX)
        .min(available)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(origin: Origin, points: Vec<Point3>) -> PointTable {
        let n = points.len();
        PointTable {
            path: "s.ply".into(),
            format: Format::Ply,
            points,
            columns: vec!["x".into(), "y".into(), "z".into(), "w".into()],
            extra: vec![(0..n).map(|i| i as f64).collect()],
            origin,
            file_index: None,
            dropped_non_finite: 0,
            warnings: Vec::new(),
        }
    }

    #[test]
    fn locate_and_drop_keep_file_positions() {
        let pts = vec![
            Point3::new(0., 0., 0.),
            Point3::new(f64::NAN, 0., 0.),
            Point3::new(1., 2., 3.),
        ];
        let t = table(
            Origin::Records {
                start: 100,
                stride: 12,
            },
            pts.clone(),
        );
        assert_eq!(t.locate(2), "s.ply: byte offset 124 (vertex 2)");
        let e = t.clone().finish(NonFinite::Reject).unwrap_err().to_string();
        assert!(
            e.starts_with("s.ply: byte offset 112: vertex 1: x is NaN"),
            "{e}"
        );
        let d = t.finish(NonFinite::Drop).unwrap();
        assert_eq!(d.dropped_non_finite, 1);
        assert_eq!(d.points, vec![pts[0], pts[2]]);
        assert_eq!(d.column("W").unwrap(), &[0.0, 2.0]);
        assert_eq!(d.locate(1), "s.ply: byte offset 124 (vertex 2)");
        let c = d.into_cloud().unwrap();
        assert_eq!(c.attribute("w").unwrap(), &[0.0, 2.0]);

        let t = table(Origin::Lines(vec![3, 5, 9]), pts.clone());
        let e = t.clone().finish(NonFinite::Reject).unwrap_err().to_string();
        assert!(e.starts_with("s.ply:5: x is NaN"), "{e}");
        let d = t.finish(NonFinite::Drop).unwrap();
        assert_eq!(d.locate(1), "s.ply:9");

        let t = table(Origin::Indices, vec![pts[1]]);
        let e = t.finish(NonFinite::Drop).unwrap_err().to_string();
        assert!(e.contains("no points left"), "{e}");
        assert_eq!(capacity(1 << 40, 10), 10);
    }
}
