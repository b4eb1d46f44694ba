//! GPS time of LASzip's pointwise compressor, item version 2 (point
//! formats 1, 3, 4 and 5). Like the point-14 GPS layer ([`super::gps`]),
//! times are the 64-bit integers of their IEEE bit patterns, up to four
//! sequences each keep a last time and a last difference, and per point one
//! symbol says how the time relates to the current sequence; the symbol
//! alphabets and contexts differ (a sequence without a difference has its
//! own six-symbol model).
//!
//! LASzip (and the `laz` crate, `gps.rs`, `v2::GpsTimeDecompressor`) decode
//! a switch to another sequence by recursion, which damaged data can drive
//! deep enough to overflow any stack (`docs/robustness.md`, finding 5).
//! Here it is a loop, and since an encoder switches at most once per point
//! (to a sequence whose difference fits), more switches than there are
//! sequences is refused as damaged data.

use super::arithmetic::{Decoder, Fault, Step};
use super::integer::IntegerDecoder;
use super::models::SymbolModel;

/// Largest multiple of the last difference coded directly.
const MULTI: i32 = 500;
/// Largest negative multiple (its magnitude).
const MULTI_MINUS: i32 = 10;
/// Symbol of an unchanged time.
const UNCHANGED: u32 = (MULTI + MULTI_MINUS + 1) as u32;
/// Symbol of a full time opening a new sequence; symbols above it switch.
const CODE_FULL: u32 = (MULTI + MULTI_MINUS + 2) as u32;
/// Symbols of the multiple model: the codes plus three switches.
const MULTI_TOTAL: u32 = (MULTI + MULTI_MINUS + 6) as u32;
/// Most sequence switches accepted before a time.
const MAX_SWITCHES: usize = 4;

/// GPS-time decoder of one chunk.
pub(super) struct Gps11Decoder {
    current: usize,
    newest: usize,
    times: [i64; 4],
    diffs: [i32; 4],
    extremes: [u32; 4],
    multi: SymbolModel,
    no_diff: SymbolModel,
    ints: IntegerDecoder,
}

impl Gps11Decoder {
    /// The decoder after the chunk's raw first time (an IEEE bit pattern).
    pub(super) fn new(time: i64) -> Self {
        Self {
            current: 0,
            newest: 0,
            times: [time, 0, 0, 0],
            diffs: [0; 4],
            extremes: [0; 4],
            multi: SymbolModel::new(MULTI_TOTAL),
            no_diff: SymbolModel::new(6),
            ints: IntegerDecoder::new(32, 9),
        }
    }

    /// Opens a new sequence with a full 64-bit time: its high half coded
    /// against the current time's high half, its low half raw.
    fn full(&mut self, dec: &mut Decoder<'_>) -> Step<()> {
        self.newest = (self.newest + 1) & 3;
        let high = self
            .ints
            .decode(dec, (self.times[self.current] >> 32) as i32, 8)?;
        let low = dec.raw_u32()?;
        self.times[self.newest] = (i64::from(high) << 32) | i64::from(low);
        self.current = self.newest;
        self.diffs[self.current] = 0;
        self.extremes[self.current] = 0;
        Ok(())
    }

    /// A difference far from the expected one: after more than three in a
    /// row it becomes the sequence's difference.
    fn extreme(&mut self, diff: i32) {
        let c = self.current;
        self.extremes[c] += 1;
        if self.extremes[c] > 3 {
            self.diffs[c] = diff;
            self.extremes[c] = 0;
        }
    }

    /// The next time (an IEEE bit pattern).
    pub(super) fn next(&mut self, dec: &mut Decoder<'_>) -> Step<i64> {
        for _ in 0..=MAX_SWITCHES {
            let c = self.current;
            if self.diffs[c] == 0 {
                match dec.symbol(&mut self.no_diff)? {
                    0 => {}
                    1 => {
                        let diff = self.ints.decode(dec, 0, 0)?;
                        self.diffs[c] = diff;
                        self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                        self.extremes[c] = 0;
                    }
                    2 => self.full(dec)?,
                    s => {
                        self.current = (c + s as usize - 2) & 3;
                        continue;
                    }
                }
                return Ok(self.times[self.current]);
            }
            let last = self.diffs[c];
            let multi = dec.symbol(&mut self.multi)?;
            if multi == 1 {
                let diff = self.ints.decode(dec, last, 1)?;
                self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                self.extremes[c] = 0;
            } else if multi < UNCHANGED {
                let m = multi as i32;
                let diff = if multi == 0 {
                    let d = self.ints.decode(dec, 0, 7)?;
                    self.extreme(d);
                    d
                } else if m < MULTI {
                    let context = if m < 10 { 2 } else { 3 };
                    self.ints.decode(dec, m.wrapping_mul(last), context)?
                } else if m == MULTI {
                    let d = self.ints.decode(dec, MULTI.wrapping_mul(last), 4)?;
                    self.extreme(d);
                    d
                } else {
                    // 501-510: the multiples -1 to -10
                    let m = MULTI - m;
                    if m > -MULTI_MINUS {
                        self.ints.decode(dec, m.wrapping_mul(last), 5)?
                    } else {
                        let d = self
                            .ints
                            .decode(dec, (-MULTI_MINUS).wrapping_mul(last), 6)?;
                        self.extreme(d);
                        d
                    }
                };
                self.times[c] = self.times[c].wrapping_add(i64::from(diff));
            } else if multi == CODE_FULL {
                self.full(dec)?;
            } else if multi > CODE_FULL {
                self.current = (c + (multi - CODE_FULL) as usize) & 3;
                continue;
            }
            return Ok(self.times[self.current]);
        }
        Err(Fault::Switches)
    }
}
