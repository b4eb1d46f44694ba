//! Errors of the IO crate: each names the file and, where it applies, the line.

use std::path::PathBuf;

/// What went wrong reading or writing a file.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file could not be opened, read or written.
    #[error("{path}: {error}")]
    Io {
        /// the file
        path: PathBuf,
        /// the OS error (in the message, not chained, so it prints once)
        error: std::io::Error,
    },
    /// The file's content is malformed at a given line.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// the file
        path: PathBuf,
        /// 1-based line number
        line: usize,
        /// what is wrong and what to change
        message: String,
    },
    /// The binary content of the file is malformed at a given byte offset.
    #[error("{path}: byte offset {offset}: {message}")]
    Binary {
        /// the file
        path: PathBuf,
        /// byte offset from the start of the file
        offset: u64,
        /// what is wrong and what to change
        message: String,
    },
    /// The file as a whole is unusable (empty, wrong format).
    #[error("{path}: {message}")]
    Invalid {
        /// the file
        path: PathBuf,
        /// what is wrong and what to change
        message: String,
    },
    /// The geometry read from a file is invalid.
    #[error("{path}: {error}")]
    Geometry {
        /// the file
        path: PathBuf,
        /// the library's error
        error: scanfit::Error,
    },
    /// A document to be written holds a number JSON cannot represent (NaN
    /// or an infinity, which a JSON writer would turn into `null`).
    #[error("{what}: the value at {at} is not a finite number; JSON cannot hold NaN or infinity, so nothing was written (a computation produced it: please report this with the input)")]
    NonFinite {
        /// the document (a file name or "the JSON report")
        what: String,
        /// where in the document, as a path like `.quality.max_anisotropy`
        at: String,
    },
}

/// Result alias of the IO crate.
pub type Result<T> = std::result::Result<T, Error>;
