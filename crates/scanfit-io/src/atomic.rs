//! Atomic file writes: temporary file in the target's directory, then rename.

use std::io::Write;
use std::path::Path;

use crate::{Error, Result};

/// Writes `bytes` to `path` atomically: the content goes to a hidden temporary
/// file in the same directory, which is renamed over `path` only when fully
/// written and flushed. On error the temporary file is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes several files as a group: every content goes to its temporary file
/// first, and only when all of them are written are they renamed into place.
/// If any write fails, no target is touched and the temporaries are removed.
/// Paths and contents may be owned or borrowed (`(PathBuf, Vec<u8>)`,
/// `(&Path, &[u8])`, ...).
pub fn write_all_atomic<P: AsRef<Path>, B: AsRef<[u8]>>(files: &[(P, B)]) -> Result<()> {
    let mut staged: Vec<(std::path::PathBuf, &Path)> = Vec::new();
    let cleanup = |staged: &[(std::path::PathBuf, &Path)]| {
        for (tmp, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for (path, bytes) in files {
        let (path, bytes) = (path.as_ref(), bytes.as_ref());
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => std::path::PathBuf::from("."),
        };
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
        let r = (|| {
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(bytes)?;
            f.sync_all()
        })();
        if let Err(error) = r {
            let _ = std::fs::remove_file(&tmp);
            cleanup(&staged);
            return Err(Error::Io {
                path: path.to_path_buf(),
                error,
            });
        }
        staged.push((tmp, path));
    }
    for (k, (tmp, path)) in staged.iter().enumerate() {
        if let Err(error) = std::fs::rename(tmp, path) {
            cleanup(&staged[k..]);
            return Err(Error::Io {
                path: path.to_path_buf(),
                error,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_and_replaces() {
        let dir = std::env::temp_dir().join(format!("scanfit-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        // no temporary file left behind
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        // a missing directory is an error naming the file, and nothing is created
        let bad = dir.join("missing/b.txt");
        let e = write_atomic(&bad, b"x").unwrap_err();
        assert!(e.to_string().contains("missing/b.txt"), "{e}");
        // a group with one unwritable target writes nothing
        let ok = dir.join("c.txt");
        let e = write_all_atomic(&[(&ok, b"c"), (&bad, b"x")]).unwrap_err();
        assert!(e.to_string().contains("missing/b.txt"));
        assert!(!ok.exists());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
