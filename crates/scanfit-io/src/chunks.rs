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
//! fields, non-finite policy; errors name the file's line). Other formats
//! are read whole and served in chunks ([`PointChunks::bounded`] says
//! which): their memory grows with the point count.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::table::{split_lines, Format, Origin, PointTable, ReadOptions};
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

    /// Whether memory is bounded by the chunk size (text files), rather than
    /// the whole file being read at once.
    pub fn bounded(&self) -> bool {
        matches!(self.source, Source::Text(_))
    }

    /// Warnings of the reader, complete once the pass has ended.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The next chunk, `None` at the end of the file.
    pub fn next_chunk(&mut self) -> Result<Option<PointTable>> {
        let got = match &mut self.source {
            Source::Whole(table) => whole_chunk(table, self.chunk, &mut self.warnings),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::NonFinite;

    fn all_chunks(path: &Path, options: &ReadOptions, chunk: usize) -> Result<Vec<PointTable>> {
        let mut c = PointChunks::open(path, options, chunk)?;
        let mut out = Vec::new();
        while let Some(t) = c.next_chunk()? {
            out.push(t);
        }
        Ok(out)
    }

    #[test]
    fn chunks_concatenate_to_the_one_piece_read_for_every_line_ending() {
        let dir = std::env::temp_dir().join(format!("scanfit-chunks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
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
            std::fs::write(&path, body.replace('\n', eol)).unwrap();
            let whole = crate::read_cloud(&path, &ReadOptions::default()).unwrap();
            for chunk in [1usize, 999, 60_000, 100_000] {
                if chunk == 1 && name != "lf" {
                    continue;
                }
                let parts = all_chunks(&path, &ReadOptions::default(), chunk).unwrap();
                assert!(parts
                    .iter()
                    .all(|t| t.points.len() <= chunk && t.columns == whole.columns));
                let points: Vec<_> = parts.iter().flat_map(|t| t.points.clone()).collect();
                assert_eq!(points, whole.points, "{name} {chunk}");
                let u: Vec<f64> = parts
                    .iter()
                    .flat_map(|t| t.column("u").unwrap().to_vec())
                    .collect();
                assert_eq!(u, whole.column("u").unwrap());
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
        std::fs::write(&path, &text).unwrap();
        let e = all_chunks(&path, &ReadOptions::default(), 5000)
            .unwrap_err()
            .to_string();
        let one = crate::read_cloud(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert_eq!(e, one);
        assert!(e.contains("50001"), "{e}");
        let drop = ReadOptions {
            non_finite: NonFinite::Drop,
            ..Default::default()
        };
        let n: usize = all_chunks(&path, &drop, 5000)
            .unwrap()
            .iter()
            .map(|t| t.points.len())
            .sum();
        assert_eq!(n, 50_000);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
