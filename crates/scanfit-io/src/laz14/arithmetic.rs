//! The LASzip arithmetic decoder (a range decoder with 32-bit registers
//! after Amir Said's FastAC, as LASzip uses it) reading one layer held in
//! a byte slice. It never reads past the slice: running out of bytes is
//! a [`Fault`], as are the states only damaged data can reach. A decoder
//! can be suspended ([`Decoder::suspend`]: its position and registers) and
//! resumed on another slice holding the same bytes from that position on,
//! which is how a long pointwise chunk is decoded through a bounded window.

use super::models::{BitModel, SymbolModel, BIT_SHIFT, SYMBOL_SHIFT};

/// Renormalise when the interval length drops below this.
const MIN_LENGTH: u32 = 1 << 24;

/// Why a layer cannot be decoded further.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Fault {
    /// its bytes ran out (or it has fewer than the 4 it starts with)
    Ended,
    /// it starts with a value no encoder writes
    Unwritten,
    /// its GPS times switch sequences more often than there are sequences
    Switches,
}

/// Result of one decoding step.
pub(super) type Step<T> = std::result::Result<T, Fault>;

/// The registers of a suspended [`Decoder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Registers {
    value: u32,
    length: u32,
}

/// Most bytes one decoding step ([`Decoder::bit`], [`Decoder::symbol`],
/// [`Decoder::raw_bits`]) reads: each starts with a length of at least
/// 2^24 and leaves at least 2^5 (a raw value of 19 bits; a symbol leaves
/// 2^9, a bit 2^11), so renormalising takes at most three bytes.
pub(super) const STEP_BYTES: usize = 3;

/// Decoder over one layer.
pub(super) struct Decoder<'a> {
    bytes: &'a [u8],
    at: usize,
    value: u32,
    length: u32,
}

impl<'a> Decoder<'a> {
    /// Starts decoding `bytes` (the first four bytes set the value).
    pub(super) fn new(bytes: &'a [u8]) -> Step<Self> {
        Self::start(bytes, 0)
    }

    /// Starts decoding `bytes` at `at` (the four bytes there set the value).
    pub(super) fn start(bytes: &'a [u8], at: usize) -> Step<Self> {
        let head: [u8; 4] = bytes
            .get(at..at.checked_add(4).ok_or(Fault::Ended)?)
            .ok_or(Fault::Ended)?
            .try_into()
            .map_err(|_| Fault::Ended)?;
        let value = u32::from_be_bytes(head);
        // an encoder's value is always below the initial length
        if value == u32::MAX {
            return Err(Fault::Unwritten);
        }
        Ok(Self {
            bytes,
            at: at + 4,
            value,
            length: u32::MAX,
        })
    }

    /// Continues a suspended decoder on `bytes`, whose byte `at` is the
    /// next one it reads.
    pub(super) fn resume(bytes: &'a [u8], at: usize, registers: Registers) -> Self {
        Self {
            bytes,
            at,
            value: registers.value,
            length: registers.length,
        }
    }

    /// The position of the next byte to read in the slice.
    pub(super) fn position(&self) -> usize {
        self.at
    }

    /// Where to resume: the next byte's position and the registers.
    pub(super) fn suspend(self) -> (usize, Registers) {
        (
            self.at,
            Registers {
                value: self.value,
                length: self.length,
            },
        )
    }

    #[inline]
    fn renormalise(&mut self) -> Step<()> {
        while self.length < MIN_LENGTH {
            let byte = *self.bytes.get(self.at).ok_or(Fault::Ended)?;
            self.at += 1;
            self.value = (self.value << 8) | u32::from(byte);
            self.length <<= 8;
        }
        Ok(())
    }

    /// One bit under an adaptive model.
    #[inline]
    pub(super) fn bit(&mut self, model: &mut BitModel) -> Step<u32> {
        let split = model.zero_probability * (self.length >> BIT_SHIFT);
        let one = self.value >= split;
        if one {
            self.value -= split;
            self.length -= split;
        } else {
            self.length = split;
        }
        self.renormalise()?;
        model.record(one);
        Ok(u32::from(one))
    }

    /// One symbol under an adaptive model.
    #[inline]
    pub(super) fn symbol(&mut self, model: &mut SymbolModel) -> Step<u32> {
        let unit = self.length >> SYMBOL_SHIFT;
        let symbol = model.find(self.value / unit);
        let low = model.start[symbol as usize] * unit;
        let high = if symbol == model.last() {
            self.length
        } else {
            model.start[symbol as usize + 1] * unit
        };
        self.value -= low;
        self.length = high - low;
        self.renormalise()?;
        model.record(symbol);
        Ok(symbol)
    }

    /// `bits` raw bits (1 to 32), all values equally likely.
    pub(super) fn raw_bits(&mut self, bits: u32) -> Step<u32> {
        debug_assert!((1..=32).contains(&bits));
        if bits > 19 {
            let low = self.raw_bits(16)?;
            let high = self.raw_bits(bits - 16)?;
            return Ok((high << 16) | low);
        }
        self.length >>= bits;
        let v = self.value / self.length;
        self.value -= self.length * v;
        self.renormalise()?;
        Ok(v)
    }

    /// A raw 32-bit value (low half first).
    pub(super) fn raw_u32(&mut self) -> Step<u32> {
        let low = self.raw_bits(16)?;
        let high = self.raw_bits(16)?;
        Ok((high << 16) | low)
    }
}
