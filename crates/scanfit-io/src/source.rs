//! A point file as a [`PointSource`] of the streamed fits
//! ([`scanfit::pipeline::stream`]): every pass opens the file again and
//! reads it in chunks ([`PointChunks`]), in file order, so the streamed
//! surface is the in-memory one bit for bit. Memory depends on the chunk
//! size (for the formats [`reads_in_chunks`] names), not on the point count.
//!
//! The library sees the reader's errors as [`scanfit::Error::InvalidInput`]
//! with the reader's message; the reader's own error (with its file, line or
//! byte offset) is kept for the caller ([`FileSource::take_failure`]), and
//! so is a library error about one point, with that point's place in the
//! file.

use std::path::{Path, PathBuf};

use scanfit::pipeline::stream::{Chunk, PointSource};

use crate::chunks::PointChunks;
use crate::{Error, ReadOptions, Result};

/// Whether [`PointChunks`] reads `path` a chunk at a time (text files; PLY
/// files, ascii or with fixed-size binary vertex records; LAS and LAZ
/// files), rather than whole. Reads at most the PLY header.
///
/// ```
/// use scanfit_io::source::reads_in_chunks;
/// use scanfit_io::ReadOptions;
/// let dir = std::env::temp_dir().join(format!("reads-in-chunks-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("p.xyz");
/// std::fs::write(&path, "0 0 0\n1 1 1\n")?;
/// assert!(reads_in_chunks(&path, &ReadOptions::default())?);
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reads_in_chunks(path: &Path, options: &ReadOptions) -> Result<bool> {
    let format = match options.format {
        Some(f) => Some(f),
        None => crate::Format::from_path(path)?,
    };
    Ok(match format {
        Some(crate::Format::Text) => true,
        Some(crate::Format::Ply) => crate::ply_read::chunks::PlyChunks::open(path)?.is_some(),
        Some(crate::Format::Las) => true,
        _ => false,
    })
}

/// A point file read in chunks, one [`PointChunks`] per pass (see the
/// module documentation).
///
/// ```
/// use scanfit::pipeline::stream::PointSource;
/// use scanfit_io::source::FileSource;
/// use scanfit_io::ReadOptions;
/// let dir = std::env::temp_dir().join(format!("file-source-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("p.xyz");
/// let text: String = (0..10).map(|k| format!("{k} {} 0.5\n", k % 3)).collect();
/// std::fs::write(&path, text)?;
/// let mut s = FileSource::new(&path, ReadOptions::default(), 4, false);
/// let mut sizes = Vec::new();
/// s.pass(&mut |c| {
///     sizes.push(c.points.len());
///     Ok(())
/// })?;
/// assert_eq!((sizes, s.passes()), (vec![4, 4, 2], 1));
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct FileSource {
    path: PathBuf,
    options: ReadOptions,
    chunk: usize,
    uv: bool,
    passes: usize,
    warnings: Vec<String>,
    failure: Option<Error>,
}

impl FileSource {
    /// A source reading `path` in chunks of `chunk` points (at least 1);
    /// with `uv`, every chunk carries the parameters of the columns `u` and
    /// `v` (an error names the file's columns when it has none).
    pub fn new(path: &Path, options: ReadOptions, chunk: usize, uv: bool) -> Self {
        Self {
            path: path.to_path_buf(),
            options,
            chunk: chunk.max(1),
            uv,
            passes: 0,
            warnings: Vec::new(),
            failure: None,
        }
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Passes completed.
    pub fn passes(&self) -> usize {
        self.passes
    }

    /// The reader's warnings, from the first complete pass.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The error behind the last failed pass, as the reader (or, for a
    /// point the library refused, the point's place in the file) gave it.
    pub fn take_failure(&mut self) -> Option<Error> {
        self.failure.take()
    }

    fn chunk_pass(
        &mut self,
        f: &mut dyn FnMut(Chunk<'_>) -> scanfit::Result<()>,
    ) -> std::result::Result<(), Failure> {
        let mut chunks = PointChunks::open(&self.path, &self.options, self.chunk)?;
        while let Some(t) = chunks.next_chunk()? {
            let uv: Option<Vec<[f64; 2]>> = if self.uv {
                let (Some(u), Some(v)) = (t.column("u"), t.column("v")) else {
                    return Err(Failure::Read(Error::Invalid {
                        path: self.path.clone(),
                        message: format!(
                            "no columns named u and v (its columns: {}); the parameters come from such columns",
                            t.columns.join(", ")
                        ),
                    }));
                };
                Some(u.iter().zip(v).map(|(&u, &v)| [u, v]).collect())
            } else {
                None
            };
            let chunk = Chunk {
                points: &t.points,
                uv: uv.as_deref(),
            };
            f(chunk).map_err(|e| match e.point_indices().first() {
                Some(&i) => Failure::Read(Error::Invalid {
                    path: self.path.clone(),
                    message: format!("{e} (at {})", t.locate(i)),
                }),
                None => Failure::Library(e),
            })?;
        }
        if self.passes == 0 {
            self.warnings = chunks.warnings().to_vec();
        }
        self.passes += 1;
        Ok(())
    }
}

/// Why a pass stopped: the reader (kept for the caller) or the library.
enum Failure {
    Read(Error),
    Library(scanfit::Error),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Self::Read(e)
    }
}

impl PointSource for FileSource {
    fn pass(&mut self, f: &mut dyn FnMut(Chunk<'_>) -> scanfit::Result<()>) -> scanfit::Result<()> {
        self.chunk_pass(f).map_err(|e| match e {
            Failure::Read(e) => {
                let message = e.to_string();
                self.failure = Some(e);
                scanfit::Error::InvalidInput(message)
            }
            Failure::Library(e) => e,
        })
    }
}
