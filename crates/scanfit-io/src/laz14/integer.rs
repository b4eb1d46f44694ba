//! LASzip's integer decompressor: a value is a prediction plus a corrector.
//! The corrector's magnitude class `k` (its bit length) is an adaptive
//! symbol per context; the corrector within the class comes from an
//! adaptive model per class (its top 8 bits when the class is wider, the
//! rest raw), and `k = 0` is a single adaptive bit (corrector 0 or 1).

use super::arithmetic::{Decoder, Step};
use super::models::{BitModel, SymbolModel};

/// Class widths above this send their low bits raw.
const HIGH_BITS: u32 = 8;

/// Decompressor of `bits`-bit integers (1 to 32) under `contexts` contexts.
pub(super) struct IntegerDecoder {
    /// values wrap modulo this (0: modulo 2^32)
    range: u32,
    /// the corrector of class 32 (only reachable at width 32)
    smallest: i32,
    classes: Vec<SymbolModel>,
    zero_or_one: BitModel,
    within: Vec<Option<SymbolModel>>,
    /// the class of the last corrector decoded (a context for neighbours)
    pub(super) k: u32,
}

impl IntegerDecoder {
    pub(super) fn new(bits: u32, contexts: u32) -> Self {
        debug_assert!((1..=30).contains(&bits) || bits == 32);
        let (width, range, smallest) = if bits < 32 {
            (bits, 1u32 << bits, -((1i32 << bits) / 2))
        } else {
            (32, 0, i32::MIN)
        };
        Self {
            range,
            smallest,
            classes: (0..contexts).map(|_| SymbolModel::new(width + 1)).collect(),
            zero_or_one: BitModel::new(),
            within: (0..width).map(|_| None).collect(),
            k: 0,
        }
    }

    /// Decodes the value predicted by `prediction` under `context`.
    #[inline]
    pub(super) fn decode(
        &mut self,
        dec: &mut Decoder<'_>,
        prediction: i32,
        context: usize,
    ) -> Step<i32> {
        let k = dec.symbol(&mut self.classes[context])?;
        self.k = k;
        let corrector = if k == 0 {
            dec.bit(&mut self.zero_or_one)? as i32
        } else if k < 32 {
            let model = self.within[k as usize - 1]
                .get_or_insert_with(|| SymbolModel::new(1 << k.min(HIGH_BITS)));
            let mut c = dec.symbol(model)?;
            if k > HIGH_BITS {
                let low = k - HIGH_BITS;
                c = (c << low) | dec.raw_bits(low)?;
            }
            // class k holds the correctors of bit length k: the upper half
            // of 0..2^k are the positive ones 2^(k-1)..2^k, the lower half
            // the negative ones -(2^k - 1)..-2^(k-1)
            if c >= 1 << (k - 1) {
                c.wrapping_add(1) as i32
            } else {
                (c as i32).wrapping_sub(((1u64 << k) - 1) as i32)
            }
        } else {
            self.smallest
        };
        let mut real = prediction.wrapping_add(corrector);
        if self.range != 0 {
            let range = self.range as i32;
            if real < 0 {
                real += range;
            } else if real >= range {
                real -= range;
            }
        }
        Ok(real)
    }
}
