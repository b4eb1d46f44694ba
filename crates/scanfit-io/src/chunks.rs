//! Point files read in chunks of a bounded number of points, for fits whose
//! memory should depend on the model, not on the point count
//! (`--chunk-points`).
//!
//! [`PointChunks::open`] starts a pass over a file; [`PointChunks::next_chunk`]
//! returns the next at most `chunk` points as a [`PointTable`] (positions,
//! extra columns, line numbers in the file), `None` at the end. Text files
//! (XYZ, CSV, TXT, PTS) are read through a buffer of 1 MiB plus one chunk
//! of points, with exactly the rules of the one-piece reader
//! ([`crate::xyz::parse_points_with`]: header, every line ending, empty
//! fields, non-finite policy; errors name the file's line). PLY files
//! (binary with fixed-size vertex records, or ascii) are read a chunk of
//! vertex records at a time by the PLY reader's own decoding
//! (`ply_chunks.rs`), LAS and LAZ files a chunk of records or one LAZ chunk at
//! a time (`las/stream.rs`). Other formats (and other PLY layouts) are read whole
//! and served in chunks ([`PointChunks::bounded`] says which): their memory
//! grows with the point count.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::table::{split_lines, Format, NonFinite, Origin, PointTable, ReadOptions};
use crate::xyz::{TextParser, TextRows};
use crate::{Error, Result};

/// Bytes read from a text file at a time.
const BLOCK: usize = 1 << 20;

/// One pass over a point file in chunks (see the module documentation).
///
/// ```
/// use scanfit_io::chunks::PointChunks;
/// use scanfit_io::ReadOptions;
/// let dir = std::env::temp_dir().join(format!("chunks-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("p.xyz");
/// let text: String = (0..10).map(|k| format!("{k} {} 0.5\n", 2 * k)).collect();
/// std::fs::write(&path, format!("x y z\n{text}"))?;
/// let mut chunks = PointChunks::open(&path, &ReadOptions::default(), 4)?;
/// let mut sizes = Vec::new();
/// while let Some(t) = chunks.next_chunk()? {
///     sizes.push(t.points.len());
/// }
/// assert_eq!(sizes, [4, 4, 2]);
/// assert!(chunks.bounded());
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct PointChunks {
    path: PathBuf,
    chunk: usize,
    source: Source,
    warnings: Vec<String>,
    points: usize,
}

enum Source {
    Text(TextSource),
    Ply(crate::ply_read::chunks::PlyChunks, NonFinite),
    Las(Box<crate::las::LasChunks>, NonFinite),
    Whole(Option<PointTable>),
}

struct TextSource {
    file: File,
    parser: TextParser,
    pending: Vec<u8>,
    lines: usize,
    ready: TextRows,
    at: usize,
    eof: bool,
    first: bool,
}

impl PointChunks {
    /// Starts a pass over `path` (format by [`ReadOptions::format`] or the
    /// extension), chunks of at most `chunk` points (at least 1).
    pub fn open(path: &Path, options: &ReadOptions, chunk: usize) -> Result<Self> {
        // without a format or a known extension the whole reader sniffs the content
        let format = match options.format {
            Some(f) => Some(f),
            None => Format::from_path(path)?,
        };
        let io = |error| Error::Io {
            path: path.to_path_buf(),
            error,
        };
        let source = if format == Some(Format::Text) {
            Source::Text(TextSource {
                file: File::open(path).map_err(io)?,
                parser: TextParser::new(path, options.non_finite),
                pending: Vec::new(),
                lines: 0,
                ready: TextRows::default(),
                at: 0,
                eof: false,
                first: true,
            })
        } else if format == Some(Format::Ply) {
            match crate::ply_read::chunks::PlyChunks::open(path)? {
                Some(p) => Source::Ply(p, options.non_finite),
                None => Source::Whole(Some(crate::read_cloud(path, options)?)),
            }
        } else if format == Some(Format::Las) {
            Source::Las(
                Box::new(crate::las::LasChunks::open(path)?),
                options.non_finite,
            )
        } else {
            Source::Whole(Some(crate::read_cloud(path, options)?))
        };
        Ok(Self {
            path: path.to_path_buf(),
            chunk: chunk.max(1),
            source,
            warnings: Vec::new(),
            points: 0,
        })
    }

    /// Whether memory is bounded by the chunk size (text files, PLY files
    /// in the layouts of [`crate::ply_read::chunks`]), rather than the whole
    /// file being read at once.
    pub fn bounded(&self) -> bool {
        matches!(
            self.source,
            Source::Text(_) | Source::Ply(..) | Source::Las(..)
        )
    }

    /// Sets the window of compressed bytes a pointwise LAZ chunk is
    /// decoded through (by default [`crate::laz14::WINDOW`]; raised to the
    /// least one point needs), before the first chunk is read: the fuzz
    /// target of the streamed reader makes it small so that the decoder is
    /// suspended and resumed every few points.
    pub(crate) fn set_laz_window(&mut self, window: usize) {
        if let Source::Las(l, _) = &mut self.source {
            l.set_window(window);
        }
    }

    /// Warnings of the reader, complete once the pass has ended.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The next chunk, `None` at the end of the file.
    pub fn next_chunk(&mut self) -> Result<Option<PointTable>> {
        let got = match &mut self.source {
            Source::Whole(table) => whole_chunk(table, self.chunk, &mut self.warnings),
            Source::Ply(p, policy) => {
                let policy = *policy;
                finished_chunks(
                    || p.next(self.chunk),
                    policy,
                    &self.path,
                    self.points,
                    &mut self.warnings,
                )?
            }
            Source::Las(l, policy) => {
                let policy = *policy;
                let chunk = self.chunk;
                let got = finished_chunks(
                    || l.next(chunk),
                    policy,
                    &self.path,
                    self.points,
                    &mut self.warnings,
                )?;
                if got.is_none() {
                    self.warnings.extend_from_slice(l.warnings());
                }
                got
            }
            Source::Text(t) => {
                let got = t.next(&self.path, self.chunk)?;
                if got.is_none() {
                    t.parser.check_not_empty(self.points)?;
                    self.warnings = t.parser.warnings(self.points);
                }
                got
            }
        };
        if let Some(t) = &got {
            self.points += t.points.len();
        }
        Ok(got)
    }
}

/// The next chunk of a table read whole.
fn whole_chunk(
    table: &mut Option<PointTable>,
    chunk: usize,
    warnings: &mut Vec<String>,
) -> Option<PointTable> {
    let t = table.as_mut()?;
    if t.points.is_empty() {
        *table = None;
        return None;
    }
    warnings.append(&mut t.warnings);
    let n = chunk.min(t.points.len());
    let rest_points = t.points.split_off(n);
    let rest_extra: Vec<Vec<f64>> = t.extra.iter_mut().map(|c| c.split_off(n)).collect();
    let points = std::mem::replace(&mut t.points, rest_points);
    let extra = std::mem::replace(&mut t.extra, rest_extra);
    Some(PointTable {
        path: t.path.clone(),
        format: t.format,
        points,
        columns: t.columns.clone(),
        extra,
        origin: Origin::Indices,
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    })
}

impl TextSource {
    /// Reads blocks until a chunk is ready or the file ends.
    fn next(&mut self, path: &Path, chunk: usize) -> Result<Option<PointTable>> {
        if self.at == self.ready.points.len() {
            self.ready.points.clear();
            self.ready.lines.clear();
            self.ready.extra.iter_mut().for_each(Vec::clear);
            self.at = 0;
        }
        while self.ready.points.len() - self.at < chunk && !self.eof {
            self.read_block(path)?;
        }
        if self.ready.points.len() == self.at {
            return Ok(None);
        }
        // the chunk is copied out; the rows read stay until all are served
        let range = self.at..(self.at + chunk).min(self.ready.points.len());
        self.at = range.end;
        let rows = TextRows {
            points: self.ready.points[range.clone()].to_vec(),
            extra: self
                .ready
                .extra
                .iter()
                .map(|c| c[range.clone()].to_vec())
                .collect(),
            lines: self.ready.lines[range].to_vec(),
        };
        Ok(Some(PointTable {
            path: path.to_path_buf(),
            format: Format::Text,
            points: rows.points,
            columns: self.parser.columns(),
            extra: rows.extra,
            origin: Origin::Lines(rows.lines),
            file_index: None,
            dropped_non_finite: 0,
            warnings: Vec::new(),
        }))
    }

    /// Reads up to [`BLOCK`] bytes and parses the complete lines among them.
    fn read_block(&mut self, path: &Path) -> Result<()> {
        let start = self.pending.len();
        self.pending.resize(start + BLOCK, 0);
        let mut got = 0;
        while got < BLOCK {
            let k = self
                .file
                .read(&mut self.pending[start + got..])
                .map_err(|error| Error::Io {
                    path: path.to_path_buf(),
                    error,
                })?;
            if k == 0 {
                self.eof = true;
                break;
            }
            got += k;
        }
        self.pending.truncate(start + got);
        // complete lines only; a CR at the very end may be half of a CRLF
        let cut = if self.eof {
            self.pending.len()
        } else {
            match self.pending.iter().rposition(|&b| b == b'\n' || b == b'\r') {
                Some(k) if self.pending[k] == b'\r' && k + 1 == self.pending.len() => k,
                Some(k) => k + 1,
                None if self.pending.len() > 64 * BLOCK => return Err(Error::Parse {
                    path: path.to_path_buf(),
                    line: self.lines + 1,
                    message:
                        "a line longer than 64 MiB; is this a point file with one point per line?"
                            .into(),
                }),
                None => 0,
            }
        };
        let rest = self.pending.split_off(cut);
        let block = std::mem::replace(&mut self.pending, rest);
        let mut bytes = &block[..];
        if self.first {
            bytes = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes);
            self.first = bytes.is_empty() && !self.eof;
        }
        let text = std::str::from_utf8(bytes).map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: self.lines
                + 1
                + split_lines(std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or(""))
                    .count()
                    .saturating_sub(1),
            message: "not UTF-8 text; is this a binary file?".into(),
        })?;
        self.parser.block(text, self.lines, &mut self.ready)?;
        self.lines += split_lines(text).count();
        Ok(())
    }
}

/// The next chunk of a reader of fixed records (PLY, LAS/LAZ) with the
/// non-finite policy applied: a chunk whose points were all dropped is
/// skipped; a file with no point left is an error.
fn finished_chunks(
    mut next: impl FnMut() -> Result<Option<PointTable>>,
    policy: NonFinite,
    path: &Path,
    served: usize,
    warnings: &mut Vec<String>,
) -> Result<Option<PointTable>> {
    loop {
        let Some(t) = next()? else {
            if served == 0 {
                return Err(Error::Invalid {
                    path: path.to_path_buf(),
                    message: "no points left: every point has a non-finite coordinate".into(),
                });
            }
            return Ok(None);
        };
        let all_bad = t
            .points
            .iter()
            .all(|q| !q.coords.iter().all(|v| v.is_finite()));
        if all_bad && policy == NonFinite::Drop {
            continue;
        }
        let mut t = t.finish(policy)?;
        warnings.append(&mut t.warnings);
        return Ok(Some(t));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    fn all_chunks(path: &Path, options: &ReadOptions, chunk: usize) -> Result<Vec<PointTable>> {
        let mut c = PointChunks::open(path, options, chunk)?;
        let mut out = Vec::new();
        while let Some(t) = c.next_chunk()? {
            out.push(t);
        }
        Ok(out)
    }

    #[test]
    fn chunks_concatenate_to_the_one_piece_read_for_every_line_ending() -> TestResult {
        let dir = std::env::temp_dir().join(format!("scanfit-chunks-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        // more than one 1 MiB block, with a header, comments and extra columns
        let mut body = String::from("\u{feff}# scan\nu,x,y,z,v\n");
        for k in 0..60_000 {
            body.push_str(&format!(
                "{},{},{},{},{}\n",
                k as f64 / 7.0,
                k,
                k % 13,
                0.25 * k as f64,
                k % 5
            ));
            if k % 1000 == 0 {
                body.push_str("\n# gap\n");
            }
        }
        for (name, eol) in [("lf", "\n"), ("crlf", "\r\n"), ("cr", "\r")] {
            let path = dir.join(format!("{name}.csv"));
            std::fs::write(&path, body.replace('\n', eol))?;
            let whole = crate::read_cloud(&path, &ReadOptions::default())?;
            for chunk in [1usize, 999, 60_000, 100_000] {
                if chunk == 1 && name != "lf" {
                    continue;
                }
                let parts = all_chunks(&path, &ReadOptions::default(), chunk)?;
                assert!(parts
                    .iter()
                    .all(|t| t.points.len() <= chunk && t.columns == whole.columns));
                let points: Vec<_> = parts.iter().flat_map(|t| t.points.clone()).collect();
                assert_eq!(points, whole.points, "{name} {chunk}");
                let mut u = Vec::new();
                for t in &parts {
                    u.extend_from_slice(t.column("u").ok_or("a chunk without column u")?);
                }
                assert_eq!(u, whole.column("u").ok_or("no column u")?);
                let lines: Vec<usize> = parts
                    .iter()
                    .flat_map(|t| match &t.origin {
                        Origin::Lines(l) => l.clone(),
                        _ => Vec::new(),
                    })
                    .collect();
                assert_eq!(Origin::Lines(lines), whole.origin, "{name} {chunk}");
            }
        }
        // an error deep in the file names its line, as the one-piece reader does
        let path = dir.join("bad.xyz");
        let mut text: String = (0..50_000).map(|k| format!("{k} 1 2\n")).collect();
        text.push_str("1 2 nan\n");
        std::fs::write(&path, &text)?;
        let e = all_chunks(&path, &ReadOptions::default(), 5000)
            .err()
            .ok_or("the chunked read accepted a NaN")?
            .to_string();
        let one = crate::read_cloud(&path, &ReadOptions::default())
            .err()
            .ok_or("the one-piece read accepted a NaN")?
            .to_string();
        assert_eq!(e, one);
        assert!(e.contains("50001"), "{e}");
        let drop = ReadOptions {
            non_finite: NonFinite::Drop,
            ..Default::default()
        };
        let n: usize = all_chunks(&path, &drop, 5000)?
            .iter()
            .map(|t| t.points.len())
            .sum();
        assert_eq!(n, 50_000);
        std::fs::remove_dir_all(&dir)?;
        Ok(())
    }

    /// A PLY file of `n` vertices (x, y, z as float/double, a uchar label
    /// before them and a float u after), with an edge element before them.
    fn ply(encoding: &str, n: usize) -> Vec<u8> {
        let mut b = format!(
            "ply\r\nformat {encoding} 1.0\r\nelement edge 2\r\nproperty int a\r\nelement vertex {n}\r\nproperty uchar label\r\nproperty double x\r\nproperty float y\r\nproperty double z\r\nproperty float u\r\nend_header\r\n"
        )
        .into_bytes();
        let big = encoding.contains("big");
        let vertex = |k: usize| {
            (
                k % 251,
                k as f64 * 0.5 + 3e5,
                (k % 97) as f32,
                -(k as f64) / 7.0,
                (k % 13) as f32 * 0.25,
            )
        };
        if encoding == "ascii" {
            b.extend_from_slice(b"5\r\n\r\n6\r\n");
            for k in 0..n {
                let (l, x, y, z, u) = vertex(k);
                b.extend_from_slice(format!("{l} {x} {y} {z} {u}\r\n").as_bytes());
                if k % 1000 == 0 {
                    b.extend_from_slice(b"   \r\n");
                }
            }
            b.extend_from_slice(b"3 0 1 2\r\n");
            return b;
        }
        for a in [5i32, 6] {
            b.extend(if big {
                a.to_be_bytes()
            } else {
                a.to_le_bytes()
            });
        }
        for k in 0..n {
            let (l, x, y, z, u) = vertex(k);
            b.push(l as u8);
            if big {
                b.extend(x.to_be_bytes());
                b.extend(y.to_be_bytes());
                b.extend(z.to_be_bytes());
                b.extend(u.to_be_bytes());
            } else {
                b.extend(x.to_le_bytes());
                b.extend(y.to_le_bytes());
                b.extend(z.to_le_bytes());
                b.extend(u.to_le_bytes());
            }
        }
        b
    }

    #[test]
    fn ply_chunks_concatenate_to_the_one_piece_read_in_bounded_memory() -> TestResult {
        let dir = std::env::temp_dir().join(format!("scanfit-plychunks-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        for encoding in ["binary_little_endian", "binary_big_endian", "ascii"] {
            let path = dir.join(format!("{encoding}.ply"));
            std::fs::write(&path, ply(encoding, 25_000))?;
            let whole = crate::read_cloud(&path, &ReadOptions::default())?;
            for chunk in [1usize, 4096, 25_000, 30_000] {
                let mut c = PointChunks::open(&path, &ReadOptions::default(), chunk)?;
                assert!(c.bounded(), "{encoding}");
                let (mut points, mut u, mut label) = (Vec::new(), Vec::new(), Vec::new());
                while let Some(t) = c.next_chunk()? {
                    assert!(!t.points.is_empty() && t.points.len() <= chunk);
                    assert_eq!(t.columns, whole.columns);
                    points.extend_from_slice(&t.points);
                    u.extend_from_slice(t.column("u").ok_or("no u")?);
                    label.extend_from_slice(t.column("label").ok_or("no label")?);
                }
                assert_eq!(points, whole.points, "{encoding} {chunk}");
                assert_eq!(u, whole.column("u").ok_or("no u")?);
                assert_eq!(label, whole.column("label").ok_or("no label")?);
            }
            // a bad value deep in the file names the same place as the one-piece reader
            let mut bytes = ply(encoding, 25_000);
            if encoding == "ascii" {
                let text = String::from_utf8(bytes)?.replacen(" 310000.5 ", " nan ", 1);
                bytes = text.into_bytes();
            } else {
                let at = bytes.len() - 5 * (8 + 4 + 8 + 4 + 1) + 1;
                bytes[at..at + 8].copy_from_slice(&[0xff; 8]);
            }
            std::fs::write(&path, &bytes)?;
            let one = crate::read_cloud(&path, &ReadOptions::default())
                .err()
                .ok_or("the one-piece read accepted a NaN")?
                .to_string();
            let mut c = PointChunks::open(&path, &ReadOptions::default(), 3000)?;
            let chunked = loop {
                match c.next_chunk() {
                    Ok(Some(_)) => continue,
                    Ok(None) => break None,
                    Err(e) => break Some(e.to_string()),
                }
            }
            .ok_or("the chunked read accepted a NaN")?;
            assert_eq!(chunked, one, "{encoding}");
        }
        // list properties in binary vertices: read whole (and said so); in ascii ones: in chunks
        let path = dir.join("lists.ply");
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar int n\nend_header\n".to_vec();
        for k in 0..2u8 {
            for v in [1.0f32, 2.0, f32::from(k)] {
                b.extend(v.to_le_bytes());
            }
            b.push(0);
        }
        std::fs::write(&path, b)?;
        assert!(!PointChunks::open(&path, &ReadOptions::default(), 1)?.bounded());
        std::fs::write(
            &path,
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar int n\nend_header\n0 0 0 1 7\n1 1 1 0\n",
        )?;
        let mut c = PointChunks::open(&path, &ReadOptions::default(), 1)?;
        assert!(c.bounded());
        let mut n = 0;
        while let Some(t) = c.next_chunk()? {
            n += t.points.len();
        }
        assert_eq!(n, 2);
        std::fs::remove_dir_all(&dir)?;
        Ok(())
    }
}
