//! Accumulators as bytes: the partial sums of a chunked or distributed run
//! ([`crate::mba::BaAccumulator`], [`crate::mba::FrameSums`],
//! [`crate::mba::ResidualSums`], [`crate::fit::surface::NormalEquations`])
//! sent between processes (a Dask worker returns its sums to the client,
//! which merges them). The encoding is exact (every `f64` as its 8
//! little-endian bytes), so an accumulator read back continues, merges and
//! finishes bit for bit as the original would.
//!
//! A record is an 8-byte tag naming the type (7 bytes) and the format
//! version (the last, a digit: bytes of another version are refused as
//! such, never misread), then
//! fixed-width fields: `u64` and `f64` little-endian, a vector as its `u64`
//! length and its values. [`Reader`] checks the tag, every length against
//! the bytes left, and that nothing follows the record; a wrong or damaged
//! record is an [`Error::InvalidInput`] naming what was expected, never a
//! panic or an allocation beyond the input's size.
//!
//! ```
//! use scanfit::wire::{Reader, Writer};
//! let mut w = Writer::new(b"EXAMPLE1");
//! w.u64(7);
//! w.f64s(&[0.5, -1.0]);
//! let bytes = w.finish();
//! let mut r = Reader::new(&bytes, b"EXAMPLE1", "an example record")?;
//! assert_eq!(r.u64()?, 7);
//! assert_eq!(r.f64s()?, [0.5, -1.0]);
//! r.end()?;
//! // another type's tag is refused with a message naming both
//! assert!(Reader::new(&bytes, b"OTHER001", "another record").is_err());
//! # Ok::<(), scanfit::Error>(())
//! ```

use crate::par::BlockSum;
use crate::{Error, Result};

/// Builds a record (see the module documentation).
#[derive(Debug, Clone)]
pub struct Writer {
    bytes: Vec<u8>,
}

impl Writer {
    /// A record starting with `tag`.
    pub fn new(tag: &[u8; 8]) -> Self {
        Self {
            bytes: tag.to_vec(),
        }
    }

    /// Appends an unsigned integer.
    pub fn u64(&mut self, x: u64) {
        self.bytes.extend_from_slice(&x.to_le_bytes());
    }

    /// Appends a count or size.
    pub fn usize(&mut self, x: usize) {
        self.u64(x as u64);
    }

    /// Appends a number (all 64 bits).
    pub fn f64(&mut self, x: f64) {
        self.bytes.extend_from_slice(&x.to_le_bytes());
    }

    /// Appends a vector: its length, then its values.
    pub fn f64s(&mut self, x: &[f64]) {
        self.usize(x.len());
        self.bytes.reserve(8 * x.len());
        for v in x {
            self.f64(*v);
        }
    }

    /// Appends another record (its length, then its bytes), to be read
    /// back by [`Reader::record`].
    pub fn record(&mut self, bytes: &[u8]) {
        self.usize(bytes.len());
        self.bytes.extend_from_slice(bytes);
    }

    /// The record.
    pub fn finish(self) -> Vec<u8> {
        self.bytes
    }
}

/// Reads a record written by [`Writer`] (see the module documentation).
#[derive(Debug, Clone)]
pub struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    what: &'static str,
}

impl<'a> Reader<'a> {
    /// Starts reading `bytes`, which must begin with `tag`; `what` names the
    /// record in errors ("the BA sums of an MBA level").
    pub fn new(bytes: &'a [u8], tag: &[u8; 8], what: &'static str) -> Result<Self> {
        if bytes.get(..8) != Some(&tag[..]) {
            // the same type in another format version: say so
            if let Some(t) = bytes
                .get(..8)
                .filter(|t| t[..7] == tag[..7] && t[7].is_ascii_digit())
            {
                return Err(Error::InvalidInput(format!(
                    "these bytes are {what} in format version {}, but this scanfit reads version {}; make them again with this scanfit version (every worker and the client must run the same one)",
                    t[7] as char, tag[7] as char
                )));
            }
            let got = bytes.get(..8).map_or_else(
                || format!("{} bytes", bytes.len()),
                |t| format!("tag {:?}", String::from_utf8_lossy(t)),
            );
            return Err(Error::InvalidInput(format!(
                "these bytes are not {what} (expected tag {:?}, got {got}); pass the bytes that object's to_bytes() made, with the same scanfit version",
                String::from_utf8_lossy(tag)
            )));
        }
        Ok(Self { bytes, at: 8, what })
    }

    fn truncated(&self, need: usize) -> Error {
        Error::InvalidInput(format!(
            "{} cut short: {need} more bytes needed at byte {} of {}",
            self.what,
            self.at,
            self.bytes.len()
        ))
    }

    fn take8(&mut self) -> Result<[u8; 8]> {
        let b = self
            .bytes
            .get(self.at..self.at + 8)
            .ok_or_else(|| self.truncated(8))?;
        self.at += 8;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(a)
    }

    /// The next unsigned integer.
    pub fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take8()?))
    }

    /// The next count or size (refused beyond the address space).
    pub fn usize(&mut self) -> Result<usize> {
        let x = self.u64()?;
        usize::try_from(x).map_err(|_| self.corrupt(&format!("a size of {x}")))
    }

    /// The next number.
    pub fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take8()?))
    }

    /// The next vector (its length checked against the bytes left before
    /// anything is allocated).
    pub fn f64s(&mut self) -> Result<Vec<f64>> {
        let n = self.usize()?;
        let left = (self.bytes.len() - self.at) / 8;
        if n > left {
            return Err(self.truncated(8 * (n - left)));
        }
        (0..n).map(|_| self.f64()).collect()
    }

    /// The next record written by [`Writer::record`] (its length checked
    /// against the bytes left), to be read by that record's own reader.
    pub fn record(&mut self) -> Result<&'a [u8]> {
        let n = self.usize()?;
        let left = self.bytes.len() - self.at;
        if n > left {
            return Err(self.truncated(n - left));
        }
        let b = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(b)
    }

    /// An error for a field whose value cannot be right.
    pub fn corrupt(&self, field: &str) -> Error {
        Error::InvalidInput(format!(
            "{} holds {field} (before byte {}), which no scanfit accumulator writes; the bytes are damaged or of another version",
            self.what, self.at
        ))
    }

    /// Checks that the record has ended.
    pub fn end(&self) -> Result<()> {
        if self.at != self.bytes.len() {
            return Err(self.corrupt(&format!(
                "{} bytes after its end",
                self.bytes.len() - self.at
            )));
        }
        Ok(())
    }
}

/// Writes the state of a [`BlockSum`] of two vectors (numerators and
/// denominators, or a matrix band and right-hand sides).
pub(crate) fn write_pair_sums(w: &mut Writer, s: &BlockSum<(Vec<f64>, Vec<f64>)>) {
    let (total, open, open_len, block, items) = s.parts();
    w.usize(block);
    w.u64(items);
    w.f64s(&total.0);
    w.f64s(&total.1);
    match open {
        Some(o) => {
            w.usize(open_len);
            w.f64s(&o.0);
            w.f64s(&o.1);
        }
        None => w.usize(0),
    }
}

/// Reads what [`write_pair_sums`] wrote, checking the block size and the
/// vectors' lengths against `lens` (those of the accumulator's sums).
pub(crate) fn read_pair_sums(
    r: &mut Reader<'_>,
    lens: (usize, usize),
    block: usize,
) -> Result<BlockSum<(Vec<f64>, Vec<f64>)>> {
    let (l0, l1) = lens;
    let got_block = r.usize()?;
    if got_block != block {
        return Err(r.corrupt(&format!("a block of {got_block} points (expected {block})")));
    }
    let items = r.u64()?;
    let pair = |r: &mut Reader<'_>| -> Result<(Vec<f64>, Vec<f64>)> {
        let (a, b) = (r.f64s()?, r.f64s()?);
        if (a.len(), b.len()) != (l0, l1) {
            return Err(r.corrupt(&format!(
                "sums of {} and {} values (expected {l0} and {l1})",
                a.len(),
                b.len()
            )));
        }
        Ok((a, b))
    };
    let total = pair(r)?;
    let open_len = r.usize()?;
    let open = if open_len > 0 {
        Some((pair(r)?, open_len))
    } else {
        None
    };
    BlockSum::from_parts(total, open, block, items).ok_or_else(|| {
        r.corrupt(&format!(
            "an open block of {open_len} points with {items} points in all (blocks of {block})"
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damaged_records_are_refused_with_the_reason() -> Result<()> {
        let mut w = Writer::new(b"TESTREC1");
        w.f64s(&[1.0, 2.0, 3.0]);
        let bytes = w.finish();
        // cut anywhere: an error, never a panic
        for cut in 0..bytes.len() {
            let r = Reader::new(&bytes[..cut], b"TESTREC1", "a test record")
                .and_then(|mut r| r.f64s().map(|_| ()));
            assert!(r.is_err(), "cut at {cut}");
        }
        // a huge length is refused before any allocation
        let mut w = Writer::new(b"TESTREC1");
        w.u64(u64::MAX / 16);
        let e = Reader::new(&w.finish(), b"TESTREC1", "a test record")?
            .f64s()
            .unwrap_err()
            .to_string();
        assert!(e.contains("cut short"), "{e}");
        // trailing bytes
        let mut longer = bytes.clone();
        longer.push(0);
        let mut r = Reader::new(&longer, b"TESTREC1", "a test record")?;
        assert_eq!(r.f64s()?, [1.0, 2.0, 3.0]);
        assert!(r.end().unwrap_err().to_string().contains("1 bytes after"));
        Ok(())
    }
}
