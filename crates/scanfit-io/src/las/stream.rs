//! LAS and LAZ files read in chunks ([`crate::chunks::PointChunks`]): the
//! header checks of the one-piece reader run on the file read at offsets
//! ([`super::view::FileView`]), then the points are decoded a unit at a
//! time with the one-piece reader's own code, so values, columns and errors
//! are the same:
//!
//! - uncompressed LAS (and LAZ of item version 1): the `las` crate's
//!   reader on the buffered file, asked for at most a chunk of points;
//! - LAZ of point formats 0-5 (items of version 2) and 6-10: one LAZ chunk
//!   at a time, its bytes read from the file and decoded by
//!   [`crate::laz14`], then served in chunks of the requested size.
//!
//! Memory is bounded by the requested chunk plus one LAZ chunk (typically
//! 50,000 points; a LAZ chunk holds at most what its bytes can hold), not
//! by the file.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use scanfit::Point3;

use super::view::{u8_at, FileView, View};
use super::{
    crate_failed, header_warnings, layered, laz_check, pointwise, precheck, quietly, transforms,
    Compressed, CrateReader, Raw,
};
use crate::laz14::{LayeredLaz, PointwiseLaz};
use crate::table::{Format, Origin, PointTable};
use crate::{Error, Result};

/// Where the points come from.
enum Decoder {
    /// the `las` crate reading the file
    Crate(Box<CrateReader>),
    /// scanfit's pointwise LAZ decoder, the next LAZ chunk's index
    Pointwise(PointwiseLaz, usize),
    /// scanfit's layered LAZ decoder, the next LAZ chunk's index
    Layered(LayeredLaz, usize),
}

/// One pass over a LAS/LAZ file in chunks (see the module documentation).
pub(crate) struct LasChunks {
    path: PathBuf,
    view: FileView,
    raw: Raw,
    transform: [(f64, f64); 3],
    decoder: Decoder,
    columns: Vec<String>,
    declared: u64,
    /// points served so far
    served: u64,
    /// decoded points not yet served (of the current LAZ chunk)
    points: Vec<Point3>,
    extra: Vec<Vec<f64>>,
    at: usize,
    warnings: Vec<String>,
}

impl LasChunks {
    /// Checks the header of `path` as the one-piece reader does and starts
    /// a pass.
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let io = |error| Error::Io {
            path: path.to_path_buf(),
            error,
        };
        let file = File::open(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        let view = FileView { file, len };
        let raw = precheck(path, &view)?;
        let compressed = if raw.compressed {
            laz_check(path, &view, &raw)?
        } else {
            Compressed::Crate
        };
        let format = u8_at(&view, 104).unwrap_or(0) & 0x3f;
        let read = |at: u64, n: usize| view.read(at, n).map(|b| b.into_owned());
        let (decoder, names, declared) = match compressed {
            Compressed::Layered(l) => {
                let vlr = view.read(l.vlr_at, l.vlr_len as usize).unwrap_or_default();
                let file = layered::open(path, &read, &vlr, format, &raw, &l)?;
                let names = layered::names(&file);
                (Decoder::Layered(file, 0), names, l.count)
            }
            Compressed::Pointwise(pw) => {
                let vlr = view
                    .read(pw.vlr_at, pw.vlr_len as usize)
                    .unwrap_or_default();
                let file = pointwise::open(path, len, &pw, &vlr)?;
                pointwise::check_format(path, format, &file, pw.vlr_at)?;
                let names = pointwise::names(&file);
                (Decoder::Pointwise(file, 0), names, pw.count)
            }
            Compressed::Crate => {
                let source = BufReader::with_capacity(1 << 20, File::open(path).map_err(io)?);
                let r = quietly(|| CrateReader::new(path, source, len, &raw))
                    .ok_or_else(|| crate_failed(path))??;
                let (names, declared) = (r.names.clone(), r.declared);
                (Decoder::Crate(Box::new(r)), names, declared)
            }
        };
        let transform = transforms(path, &view)?;
        let mut columns: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
        columns.extend(names.iter().map(|s| s.to_string()));
        let extra = vec![Vec::new(); names.len()];
        Ok(Self {
            path: path.to_path_buf(),
            view,
            raw,
            transform,
            decoder,
            columns,
            declared,
            served: 0,
            points: Vec::new(),
            extra,
            at: 0,
            warnings: Vec::new(),
        })
    }

    /// The reader's warnings, complete once the pass has ended.
    pub(crate) fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Decodes the next unit (a LAZ chunk, or at most `chunk` points from
    /// the crate) into the buffer; `false` at the end of the points.
    fn refill(&mut self, chunk: usize) -> Result<bool> {
        self.points.clear();
        self.extra.iter_mut().for_each(Vec::clear);
        self.at = 0;
        let left = self.declared - self.served;
        if left == 0 {
            return Ok(false);
        }
        let path = self.path.clone();
        let read_chunk = |offset: u64, bytes: u64| {
            self.view.read(offset, bytes as usize).ok_or_else(|| Error::Binary {
                path: path.clone(),
                offset,
                message: format!("the LAZ chunk here ({bytes} bytes) runs past the end of the file; it is truncated"),
            })
        };
        match &mut self.decoder {
            Decoder::Crate(r) => {
                let batch = (chunk as u64).min(left);
                let (points, extra) = (&mut self.points, &mut self.extra);
                quietly(|| r.fill(&path, batch, points, extra))
                    .ok_or_else(|| crate_failed(&path))??;
            }
            Decoder::Pointwise(file, next) => {
                if *next == file.chunks().len() {
                    return Ok(false);
                }
                let c = *next;
                let span = file.chunks()[c];
                let bytes = read_chunk(span.offset, file.chunk_bytes(c))?;
                let mut decoded = Vec::new();
                file.decode_chunk(c, &bytes, &mut decoded)
                    .map_err(|e| layered::binary(&path, e))?;
                pointwise::append(
                    file,
                    &self.transform,
                    &decoded,
                    &mut self.points,
                    &mut self.extra,
                );
                *next += 1;
            }
            Decoder::Layered(file, next) => {
                if *next == file.chunks().len() {
                    return Ok(false);
                }
                let c = *next;
                let span = file.chunks()[c];
                let bytes = read_chunk(span.offset, file.chunk_bytes(c))?;
                let mut decoded = Vec::new();
                file.decode_chunk(c, &bytes, &mut decoded)
                    .map_err(|e| layered::binary(&path, e))?;
                layered::append(
                    file,
                    &self.transform,
                    &decoded,
                    &mut self.points,
                    &mut self.extra,
                );
                *next += 1;
            }
        }
        if self.extra.iter().any(|c| c.len() != self.points.len()) {
            return Err(Error::Invalid {
                path,
                message: "the LAS/LAZ columns have different lengths; the file is damaged".into(),
            });
        }
        Ok(!self.points.is_empty())
    }

    /// The next at most `chunk` points (at least 1), `None` after the last.
    pub(crate) fn next(&mut self, chunk: usize) -> Result<Option<PointTable>> {
        let chunk = chunk.max(1);
        if self.at == self.points.len() && !self.refill(chunk)? {
            if self.served < self.declared {
                return Err(Error::Invalid {
                    path: self.path.clone(),
                    message: format!(
                        "the header declares {} points, but the data holds {}; the file is truncated",
                        self.declared, self.served
                    ),
                });
            }
            if self.warnings.is_empty() {
                self.warnings = header_warnings(&self.path, &self.raw, self.served);
            }
            return Ok(None);
        }
        let end = (self.at + chunk).min(self.points.len());
        let range = self.at..end;
        let first = self.served as usize;
        let n = end - self.at;
        let table = PointTable {
            path: self.path.clone(),
            format: Format::Las,
            points: self.points[range.clone()].to_vec(),
            columns: self.columns.clone(),
            extra: self
                .extra
                .iter()
                .map(|c| c[range.clone()].to_vec())
                .collect(),
            origin: if self.raw.compressed {
                Origin::Indices
            } else {
                Origin::Records {
                    start: self.raw.offset_to_points,
                    stride: self.raw.record_len,
                }
            },
            // points are named by their record number in the file
            file_index: (first > 0).then(|| (first..first + n).collect()),
            dropped_non_finite: 0,
            warnings: Vec::new(),
        };
        self.at = end;
        self.served += n as u64;
        Ok(Some(table))
    }
}
