//! LAS and LAZ files read in chunks ([`crate::chunks::PointChunks`]): the
//! header checks of the one-piece reader run on the file read at offsets
//! ([`super::view::FileView`]), then the points are decoded a unit at a
//! time with the one-piece reader's own code, so values, columns and errors
//! are the same:
//!
//! - uncompressed LAS (and LAZ of item version 1): the `las` crate's
//!   reader on the buffered file, asked for at most a chunk of points;
//! - LAZ of point formats 0-5 (items of version 2, compressors 1 and 2):
//!   at most a requested chunk of points at a time, decoded by
//!   [`crate::laz14::PointwiseLaz`] through a cursor that reads the LAZ
//!   chunk's bytes through a window of at most [`crate::laz14::WINDOW`]
//!   bytes, so a compressor-1 file (one LAZ chunk of all its points) is
//!   streamed like any other;
//! - LAZ of point formats 6-10 (layered): one LAZ chunk at a time, its
//!   bytes read from the file and decoded by [`crate::laz14::LayeredLaz`],
//!   then served in chunks of the requested size.
//!
//! Memory is bounded by the requested chunk (pointwise LAZ and LAS: the
//! chunk's decoded points plus the 1 MiB window), or the requested chunk
//! plus one layered LAZ chunk (typically 50,000 points), not by the file.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use scanfit::Point3;

use super::view::{u8_at, FileView, View};
use super::{
    crate_failed, header_warnings, layered, laz_check, pointwise, precheck, quietly, transforms,
    unread_chunks, Compressed, CrateReader, OwnLaz, Raw,
};
use crate::laz14::{LayeredLaz, PointwiseCursor, PointwiseLaz, PointwiseRecord};
use crate::table::{Format, Origin, PointTable};
use crate::{Error, Result};

/// Where the points come from.
enum Decoder {
    /// the `las` crate reading the file
    Crate(Box<CrateReader>),
    /// scanfit's pointwise LAZ decoder
    Pointwise(Box<PointwiseStream>),
    /// scanfit's layered LAZ decoder, the next LAZ chunk's index
    Layered(LayeredLaz, usize),
}

/// A pointwise LAZ file decoded a batch of points at a time.
struct PointwiseStream {
    file: PointwiseLaz,
    /// the next LAZ chunk to start
    next: usize,
    /// the LAZ chunk being decoded
    cursor: Option<PointwiseCursor>,
    /// the last batch decoded
    records: Vec<PointwiseRecord>,
    /// bytes of a LAZ chunk the cursor holds at a time
    window: usize,
}

impl PointwiseStream {
    /// Decodes at most `max` points of the current LAZ chunk (starting the
    /// next one when it is done) into `records`; `false` after the last.
    fn next_batch(&mut self, view: &FileView, path: &Path, max: usize) -> Result<bool> {
        self.records.clear();
        loop {
            let cursor = match &mut self.cursor {
                Some(c) if !c.finished() => c,
                _ => {
                    if self.next == self.file.chunks().len() {
                        self.cursor = None;
                        return Ok(false);
                    }
                    let c = self
                        .file
                        .cursor_with_window(self.next, self.window)
                        .map_err(|e| layered::binary(path, e))?;
                    self.next += 1;
                    self.cursor.insert(c)
                }
            };
            let mut read = |at: u64, buf: &mut [u8]| view.read_into(at, buf);
            let got = self
                .file
                .decode(cursor, &mut read, max, &mut self.records)
                .map_err(|e| layered::binary(path, e))?;
            if got > 0 {
                return Ok(true);
            }
        }
    }
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
    /// the decoder's warnings, known when the file is opened
    laz_warnings: Vec<String>,
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
        let (decoder, names, declared, laz_warnings) = match compressed {
            Compressed::Layered(l) => {
                let vlr = view.read(l.vlr_at, l.vlr_len as usize).unwrap_or_default();
                let file = layered::open(path, &read, &vlr, format, &raw, &l)?;
                let names = file.names();
                let w = unread_chunks(path, l.table_chunks, file.chunks().len(), l.count);
                (Decoder::Layered(file, 0), names, l.count, w)
            }
            Compressed::Pointwise(pw) => {
                let vlr = view
                    .read(pw.vlr_at, pw.vlr_len as usize)
                    .unwrap_or_default();
                let file = pointwise::open(path, len, &pw, &vlr)?;
                pointwise::check_format(path, format, &file, pw.vlr_at)?;
                let names = file.names();
                let w = unread_chunks(path, pw.table_chunks, file.chunks().len(), pw.count);
                let stream = PointwiseStream {
                    file,
                    next: 0,
                    cursor: None,
                    records: Vec::new(),
                    window: crate::laz14::WINDOW,
                };
                (Decoder::Pointwise(Box::new(stream)), names, pw.count, w)
            }
            Compressed::Crate => {
                let source = BufReader::with_capacity(1 << 20, File::open(path).map_err(io)?);
                let r = quietly(|| CrateReader::new(path, source, len, &raw))
                    .ok_or_else(|| crate_failed(path))??;
                let (names, declared) = (r.names.clone(), r.declared);
                (Decoder::Crate(Box::new(r)), names, declared, Vec::new())
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
            laz_warnings,
        })
    }

    /// Sets the window of a pointwise LAZ chunk's cursor (see
    /// [`crate::chunks::PointChunks::set_laz_window`]).
    pub(crate) fn set_window(&mut self, window: usize) {
        if let Decoder::Pointwise(s) = &mut self.decoder {
            s.window = window;
        }
    }

    /// The reader's warnings, complete once the pass has ended.
    pub(crate) fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Bytes allocated by the buffers of decoded points and by the LAZ
    /// decoder's window (what the memory bound is about).
    #[cfg(test)]
    fn held_bytes(&self) -> usize {
        let mut held = self.points.capacity() * std::mem::size_of::<Point3>()
            + self.extra.iter().map(|c| 8 * c.capacity()).sum::<usize>();
        if let Decoder::Pointwise(s) = &self.decoder {
            held += s.records.capacity() * std::mem::size_of::<PointwiseRecord>()
                + s.cursor
                    .as_ref()
                    .map_or(0, PointwiseCursor::buffer_capacity);
        }
        held
    }

    /// Decodes the next unit (a layered LAZ chunk, or at most `chunk`
    /// points of a pointwise LAZ chunk or from the crate) into the buffer;
    /// `false` at the end of the points.
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
            Decoder::Pointwise(stream) => {
                if !stream.next_batch(&self.view, &path, chunk)? {
                    return Ok(false);
                }
                stream.file.append(
                    &self.transform,
                    &stream.records,
                    &mut self.points,
                    &mut self.extra,
                );
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
                file.append(&self.transform, &decoded, &mut self.points, &mut self.extra);
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
                self.warnings.extend(self.laz_warnings.iter().cloned());
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

#[cfg(test)]
mod tests {
    use super::*;
    use laz::las::Point0;
    use laz::record::{RecordCompressor, SequentialPointRecordCompressor};
    use laz::{LazItemRecordBuilder, LazVlrBuilder};

    /// A LAS 1.2 file of `n` format-0 points compressed with LASzip's
    /// compressor 1 (no chunk table: all points one LAZ chunk).
    fn compressor_1_file(n: u32) -> Vec<u8> {
        let items = LazItemRecordBuilder::version_2_of::<Point0>(0);
        let vlr = LazVlrBuilder::new(items).build();
        let mut payload = Vec::new();
        vlr.write_to(&mut payload).unwrap();
        payload[0] = 1;
        let start = 227 + 54 + payload.len() as u32;
        let mut f = vec![0u8; 227 + 54];
        f[0..4].copy_from_slice(b"LASF");
        (f[24], f[25], f[104], f[105]) = (1, 2, 0x80, 20);
        f[94..96].copy_from_slice(&227u16.to_le_bytes());
        for (at, v) in [(96, start), (100, 1), (107, n)] {
            f[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        for k in 0..3 {
            f[131 + 8 * k..139 + 8 * k].copy_from_slice(&0.01f64.to_le_bytes());
        }
        f[229..243].copy_from_slice(b"laszip encoded");
        f[245..247].copy_from_slice(&22204u16.to_le_bytes());
        f[247..249].copy_from_slice(&(payload.len() as u16).to_le_bytes());
        f.extend_from_slice(&payload);
        let mut c = SequentialPointRecordCompressor::new(std::io::Cursor::new(f));
        c.get_mut().set_position(u64::from(start));
        c.set_fields_from(vlr.items()).unwrap();
        let mut record = [0u8; 20];
        for k in 0..n {
            let xyz = [k % 1013, (k / 7) % 997, (k * 31) % 509];
            for (j, v) in xyz.iter().enumerate() {
                record[4 * j..4 * j + 4].copy_from_slice(&v.to_le_bytes());
            }
            record[12] = k as u8; // intensity
            record[14] = 1 | (1 << 3);
            c.compress_next(&record).unwrap();
        }
        c.done().unwrap();
        c.into_inner().into_inner()
    }

    /// Streamed, a compressor-1 file holds one requested chunk of decoded
    /// points and the decoder's window, not its LAZ chunk (all points).
    #[test]
    fn a_compressor_1_file_is_held_a_requested_chunk_at_a_time() {
        let n = 300_000;
        let bytes = compressor_1_file(n);
        let path = std::env::temp_dir().join(format!("c1-held-{}.laz", std::process::id()));
        std::fs::write(&path, &bytes).unwrap();
        let mut chunks = LasChunks::open(&path).unwrap();
        let chunk = 1000;
        let per_point = std::mem::size_of::<Point3>()
            + 8 * chunks.extra.len()
            + std::mem::size_of::<PointwiseRecord>();
        let bound = 2 * chunk * per_point + crate::laz14::WINDOW;
        let (mut served, mut largest) = (0, 0);
        while let Some(t) = chunks.next(chunk).unwrap() {
            assert_eq!(t.points[0].x, 0.01 * f64::from(served % 1013));
            served += t.points.len() as u32;
            largest = largest.max(chunks.held_bytes());
        }
        std::fs::remove_file(&path).unwrap();
        assert_eq!(served, n);
        let whole = n as usize * per_point;
        assert!(
            largest <= bound && bound < whole / 4,
            "held {largest} bytes (bound {bound}, all points {whole})"
        );
    }
}
