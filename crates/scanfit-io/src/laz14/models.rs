//! Adaptive probability models of the LASzip arithmetic coder: a binary
//! model and a multi-symbol model whose cumulative distribution is rebuilt
//! from symbol counts at growing intervals. The update rules (interval
//! growth by 5/4, count halving past 2^15 or 2^13) are part of the format:
//! the decoder must adapt exactly as the encoder did.

/// Probabilities of a [`SymbolModel`] are in units of 2^-15.
pub(super) const SYMBOL_SHIFT: u32 = 15;
const SYMBOL_MAX_TOTAL: u32 = 1 << SYMBOL_SHIFT;
/// Probabilities of a [`BitModel`] are in units of 2^-13.
pub(super) const BIT_SHIFT: u32 = 13;
const BIT_MAX_TOTAL: u32 = 1 << BIT_SHIFT;

/// Adaptive model of one binary decision.
#[derive(Clone, Debug)]
pub(super) struct BitModel {
    zeros: u32,
    total: u32,
    /// probability of a 0, in units of 2^-13
    pub(super) zero_probability: u32,
    until_update: u32,
    cycle: u32,
}

impl BitModel {
    pub(super) fn new() -> Self {
        Self {
            zeros: 1,
            total: 2,
            zero_probability: 1 << (BIT_SHIFT - 1),
            until_update: 4,
            cycle: 4,
        }
    }

    /// Counts one decoded bit and refreshes the probability when due.
    #[inline]
    pub(super) fn record(&mut self, bit: bool) {
        if !bit {
            self.zeros += 1;
        }
        self.until_update -= 1;
        if self.until_update == 0 {
            self.refresh();
        }
    }

    fn refresh(&mut self) {
        self.total += self.cycle;
        if self.total > BIT_MAX_TOTAL {
            self.total = (self.total + 1) >> 1;
            self.zeros = (self.zeros + 1) >> 1;
            if self.zeros == self.total {
                self.total += 1;
            }
        }
        let scale = 0x8000_0000u32 / self.total;
        self.zero_probability = (self.zeros * scale) >> (31 - BIT_SHIFT);
        self.cycle = ((5 * self.cycle) >> 2).min(64);
        self.until_update = self.cycle;
    }
}

/// Adaptive model of a symbol from `0..symbols` (2 to 2048 symbols).
#[derive(Clone, Debug)]
pub(super) struct SymbolModel {
    /// cumulative probability of each symbol's start, in units of 2^-15
    pub(super) start: Vec<u32>,
    counts: Vec<u32>,
    /// for models of more than 16 symbols: `first[t]` is the symbol whose
    /// interval holds the probability `t << shift` (`first[len - 1]` is the
    /// last symbol), narrowing the search of [`SymbolModel::find`]
    first: Vec<u32>,
    shift: u32,
    total: u32,
    cycle: u32,
    until_update: u32,
}

impl SymbolModel {
    pub(super) fn new(symbols: u32) -> Self {
        debug_assert!((2..=2048).contains(&symbols));
        let (first, shift) = if symbols > 16 {
            let mut bits = 3;
            while symbols > 1 << (bits + 2) {
                bits += 1;
            }
            (vec![0; (1 << bits) + 1], SYMBOL_SHIFT - bits)
        } else {
            (Vec::new(), 0)
        };
        let mut model = Self {
            start: vec![0; symbols as usize],
            counts: vec![1; symbols as usize],
            first,
            shift,
            total: 0,
            cycle: symbols,
            until_update: 0,
        };
        model.refresh();
        model.cycle = (symbols + 6) >> 1;
        model.until_update = model.cycle;
        model
    }

    /// The last symbol (its interval ends at the decoder's full length).
    #[inline]
    pub(super) fn last(&self) -> u32 {
        self.start.len() as u32 - 1
    }

    /// The largest symbol whose interval starts at or below `value` (in
    /// units of 2^-15; any value, also past the end).
    #[inline]
    pub(super) fn find(&self, value: u32) -> u32 {
        let (mut low, mut high) = if self.first.is_empty() {
            (0, self.last())
        } else {
            let t = (value >> self.shift) as usize;
            let top = self.first.len() - 1;
            if t >= top {
                (self.first[top], self.last())
            } else {
                (self.first[t], self.first[t + 1])
            }
        };
        // invariant: start[low] <= value, and the answer is <= high
        while low < high {
            let mid = (low + high + 1) >> 1;
            if self.start[mid as usize] <= value {
                low = mid;
            } else {
                high = mid - 1;
            }
        }
        low
    }

    /// Counts one decoded symbol and rebuilds the distribution when due.
    #[inline]
    pub(super) fn record(&mut self, symbol: u32) {
        self.counts[symbol as usize] += 1;
        self.until_update -= 1;
        if self.until_update == 0 {
            self.refresh();
        }
    }

    fn refresh(&mut self) {
        self.total += self.cycle;
        if self.total > SYMBOL_MAX_TOTAL {
            self.total = 0;
            for c in &mut self.counts {
                *c = (*c + 1) >> 1;
                self.total += *c;
            }
        }
        let scale = 0x8000_0000u32 / self.total;
        let mut sum = 0u32;
        for (s, c) in self.start.iter_mut().zip(&self.counts) {
            *s = (scale * sum) >> (31 - SYMBOL_SHIFT);
            sum += c;
        }
        if !self.first.is_empty() {
            let top = self.first.len() - 1;
            let mut symbol = 0usize;
            for t in 0..top {
                let at = (t as u32) << self.shift;
                while symbol + 1 < self.start.len() && self.start[symbol + 1] <= at {
                    symbol += 1;
                }
                self.first[t] = symbol as u32;
            }
            self.first[top] = self.last();
        }
        let symbols = self.start.len() as u32;
        self.cycle = ((5 * self.cycle) >> 2).min((symbols + 6) << 3);
        self.until_update = self.cycle;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn find_agrees_with_a_linear_scan_after_updates() -> Result<(), String> {
        for symbols in [2u32, 5, 16, 17, 64, 256, 515] {
            let mut m = SymbolModel::new(symbols);
            for k in 0..5000u32 {
                // a skewed stream: small symbols often
                m.record((k * k + 7 * k) % symbols.min(1 + k % 40));
                for v in (0..(1 << 15) + 50).step_by(97) {
                    let linear = (0..symbols)
                        .rev()
                        .find(|&s| m.start[s as usize] <= v)
                        .ok_or("no symbol starts at or below the value")?;
                    assert_eq!(m.find(v), linear, "symbols {symbols}, value {v}");
                }
                if k > 50 {
                    break;
                }
            }
        }
        Ok(())
    }

    #[test]
    fn starts_are_strictly_increasing_and_below_one() -> Result<(), String> {
        let mut m = SymbolModel::new(256);
        for k in 0..100_000u32 {
            m.record(if k % 3 == 0 { 255 } else { 0 });
        }
        assert!(m.start.windows(2).all(|w| w[0] < w[1]));
        assert!(*m.start.last().ok_or("no symbols")? < 1 << 15);
        Ok(())
    }
}
