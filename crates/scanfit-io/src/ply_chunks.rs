//! The vertices of a PLY file read in chunks ([`crate::chunks`]): the header
//! from the file's first bytes, then at most a chunk of vertex records at a
//! time, decoded by the one-piece reader's own functions (`read_binary`,
//! `read_ascii` of the parent module on the chunk), so values, columns and
//! errors are the same.
//!
//! Covered: binary files (either byte order) whose vertex element and the
//! elements before it have fixed-size records (no list properties), and
//! ascii files with LF or CRLF line ends. Other layouts (binary list
//! properties in or before the vertices, CR-only line ends, a header over
//! 4 MiB, a binary file shorter than its header declares) return `None`
//! from [`PlyChunks::open`]
//! and are read whole by the caller, which reports their errors exactly.
//! Elements after the vertices (faces) are not read: the chunks carry no
//! normals taken from faces.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};

use super::{parse_header, plan, read_ascii, read_binary, Element, Encoding, Header, Plan};
use crate::table::{Origin, PointTable};
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// Most header bytes looked at.
const HEADER_LIMIT: u64 = 4 << 20;

/// A pass over the vertices of a PLY file (see the module documentation).
pub(crate) struct PlyChunks {
    path: PathBuf,
    file: BufReader<File>,
    vertex: Element,
    plan: Plan,
    left: u64,
    body: Body,
}

enum Body {
    /// Fixed-size records: the stride, the byte order, the next record's offset.
    Binary {
        stride: usize,
        big: bool,
        offset: u64,
    },
    /// Lines: the number of the last line read.
    Ascii { line: usize },
}

impl PlyChunks {
    /// Starts a pass over `path`; `None` for a layout read whole (see the
    /// module documentation).
    pub(crate) fn open(path: &Path) -> Result<Option<Self>> {
        let io = |error| Error::Io {
            path: path.to_path_buf(),
            error,
        };
        let mut file = File::open(path).map_err(io)?;
        let size = file.metadata().map_err(io)?.len();
        let mut head = Vec::new();
        (&mut file)
            .take(HEADER_LIMIT)
            .read_to_end(&mut head)
            .map_err(io)?;
        if head.starts_with(b"ply\r") && head.get(4) != Some(&b'\n') {
            return Ok(None);
        }
        let Ok(header) = parse_header(path, &head) else {
            return Ok(None);
        };
        let Some(vi) = header.elements.iter().position(|e| e.name == "vertex") else {
            return Ok(None);
        };
        let vertex = header.elements[vi].clone();
        let plan = plan(path, &vertex)?;
        if vertex.count == 0 {
            return Ok(None);
        }
        let before = &header.elements[..vi];
        let body = match header.encoding {
            Encoding::Ascii => {
                let mut reader = BufReader::new(file);
                reader
                    .seek(SeekFrom::Start(header.body as u64))
                    .map_err(io)?;
                let mut s = Self {
                    path: path.to_path_buf(),
                    file: reader,
                    vertex,
                    plan,
                    left: 0,
                    body: Body::Ascii { line: header.lines },
                };
                let skip: u64 = before
                    .iter()
                    .filter(|e| !e.props.is_empty())
                    .map(|e| e.count)
                    .sum();
                let mut text = Vec::new();
                if s.lines(skip, &mut text)? < skip {
                    return Ok(None);
                }
                s.left = s.vertex.count;
                return Ok(Some(s));
            }
            Encoding::Little | Encoding::Big => {
                let mut skip = 0u128;
                for e in before {
                    let Some(stride) = e.fixed_stride() else {
                        return Ok(None);
                    };
                    skip += u128::from(e.count) * stride as u128;
                }
                let Some(stride) = vertex.fixed_stride().filter(|&s| s > 0) else {
                    return Ok(None);
                };
                let start = header.body as u128 + skip;
                if start + u128::from(vertex.count) * stride as u128 > u128::from(size) {
                    return Ok(None);
                }
                Body::Binary {
                    stride,
                    big: header.encoding == Encoding::Big,
                    offset: start as u64,
                }
            }
        };
        let offset = match body {
            Body::Binary { offset, .. } => offset,
            Body::Ascii { .. } => 0,
        };
        let mut file = BufReader::with_capacity(1 << 20, file);
        file.seek(SeekFrom::Start(offset)).map_err(io)?;
        Ok(Some(Self {
            path: path.to_path_buf(),
            file,
            left: vertex.count,
            vertex,
            plan,
            body,
        }))
    }

    /// Reads lines into `text` until `want` non-empty ones were read or the
    /// file ends; returns how many were.
    fn lines(&mut self, want: u64, text: &mut Vec<u8>) -> Result<u64> {
        let Body::Ascii { line } = &mut self.body else {
            return Ok(0);
        };
        let mut got = 0;
        while got < want {
            let at = text.len();
            let k = self
                .file
                .read_until(b'\n', text)
                .map_err(|error| Error::Io {
                    path: self.path.clone(),
                    error,
                })?;
            if k == 0 {
                break;
            }
            *line += 1;
            if text[at..].iter().any(|b| !b.is_ascii_whitespace()) {
                got += 1;
            }
        }
        Ok(got)
    }

    /// The next at most `chunk` vertices (at least 1), `None` after the last.
    pub(crate) fn next(&mut self, chunk: usize) -> Result<Option<PointTable>> {
        if self.left == 0 {
            return Ok(None);
        }
        let n = (chunk.max(1) as u64).min(self.left);
        let mut v = self.vertex.clone();
        v.count = n;
        let table = match self.body {
            Body::Binary {
                stride,
                big,
                offset,
            } => {
                let mut buf = vec![0u8; n as usize * stride];
                self.file.read_exact(&mut buf).map_err(|error| Error::Io {
                    path: self.path.clone(),
                    error,
                })?;
                let mut t = read_binary(&self.path, &buf, 0, &v, self.plan.clone(), big)?;
                // the vertex element's start: records are numbered from it
                let done = self.vertex.count - self.left;
                t.origin = Origin::Records {
                    start: offset - done * stride as u64,
                    stride: stride as u64,
                };
                self.body = Body::Binary {
                    stride,
                    big,
                    offset: offset + n * stride as u64,
                };
                t
            }
            Body::Ascii { line } => {
                let mut text = Vec::new();
                self.lines(n, &mut text)?;
                // the chunk's lines as a body whose first line is `line + 1`
                let header = Header {
                    encoding: Encoding::Ascii,
                    elements: Vec::new(),
                    body: 0,
                    lines: line,
                };
                read_ascii(&self.path, &text, &header, &[], &v, self.plan.clone())?
            }
        };
        // points are named by their record number in the file
        let first = (self.vertex.count - self.left) as usize;
        let mut table = table;
        if first > 0 {
            table.file_index = Some((first..first + n as usize).collect());
        }
        self.left -= n;
        Ok(Some(table))
    }
}
