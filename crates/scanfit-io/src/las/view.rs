//! The bytes of a LAS/LAZ file as the header checks read them: a slice
//! held in memory, or the file itself read at offsets ([`FileView`]), so
//! that a streamed read checks the same fields without loading the file.

use std::borrow::Cow;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::os::unix::fs::FileExt;

/// Random access to a file's bytes.
pub(crate) trait View {
    /// The file's size in bytes.
    fn size(&self) -> u64;
    /// `n` bytes at `at`, `None` when they are not all in the file.
    fn read(&self, at: u64, n: usize) -> Option<Cow<'_, [u8]>>;
}

impl View for [u8] {
    fn size(&self) -> u64 {
        self.len() as u64
    }
    fn read(&self, at: u64, n: usize) -> Option<Cow<'_, [u8]>> {
        let at = usize::try_from(at).ok()?;
        self.get(at..at.checked_add(n)?).map(Cow::Borrowed)
    }
}

/// A file read at offsets (`pread`), for the streamed reader.
pub(crate) struct FileView {
    pub(crate) file: File,
    pub(crate) len: u64,
}

impl View for FileView {
    fn size(&self) -> u64 {
        self.len
    }
    fn read(&self, at: u64, n: usize) -> Option<Cow<'_, [u8]>> {
        if at.checked_add(n as u64)? > self.len {
            return None;
        }
        let mut buf = vec![0u8; n];
        self.file.read_exact_at(&mut buf, at).ok()?;
        Some(Cow::Owned(buf))
    }
}

impl FileView {
    /// Fills `buf` with the bytes at `at`; `false` when they are not all
    /// in the file.
    pub(crate) fn read_into(&self, at: u64, buf: &mut [u8]) -> bool {
        at.checked_add(buf.len() as u64)
            .is_some_and(|end| end <= self.len)
            && self.file.read_exact_at(buf, at).is_ok()
    }
}

pub(crate) fn u8_at(b: &(impl View + ?Sized), at: usize) -> Option<u8> {
    b.read(at as u64, 1).map(|s| s[0])
}
pub(crate) fn u16_at(b: &(impl View + ?Sized), at: usize) -> Option<u16> {
    b.read(at as u64, 2)?
        .as_ref()
        .try_into()
        .ok()
        .map(u16::from_le_bytes)
}
pub(crate) fn u32_at(b: &(impl View + ?Sized), at: usize) -> Option<u32> {
    b.read(at as u64, 4)?
        .as_ref()
        .try_into()
        .ok()
        .map(u32::from_le_bytes)
}
pub(crate) fn u64_at(b: &(impl View + ?Sized), at: usize) -> Option<u64> {
    b.read(at as u64, 8)?
        .as_ref()
        .try_into()
        .ok()
        .map(u64::from_le_bytes)
}

/// A [`View`] as a `Read + Seek` stream (for the `laz` crate's chunk-table
/// reader).
pub(crate) struct ViewReader<'a, V: View + ?Sized> {
    pub(crate) view: &'a V,
    pub(crate) pos: u64,
}

impl<V: View + ?Sized> Read for ViewReader<'_, V> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf
            .len()
            .min(self.view.size().saturating_sub(self.pos) as usize)
            .min(1 << 16);
        if n == 0 {
            return Ok(0);
        }
        let got = self
            .view
            .read(self.pos, n)
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::UnexpectedEof))?;
        buf[..n].copy_from_slice(&got);
        self.pos += n as u64;
        Ok(n)
    }
}

impl<V: View + ?Sized> Seek for ViewReader<'_, V> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let base = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => self.view.size().checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        self.pos = base.ok_or_else(|| std::io::Error::from(std::io::ErrorKind::InvalidInput))?;
        Ok(self.pos)
    }
}
