//! GPS time of both LASzip compressors: the point-14 GPS-time layer (point
//! formats 6-10, item versions 3 and 4) and the pointwise GPS-time item of
//! version 2 (point formats 1, 3, 4 and 5). Times are handled as the 64-bit
//! integers of their IEEE bit patterns; up to four "sequences" (for
//! interleaved flight lines or pulses) each keep a last time and a last
//! difference ([`GpsSequences`]). Per point one symbol says how the time
//! relates to the current sequence: a multiple of its difference (with a
//! corrector), a new difference, a full 64-bit time opening a new
//! sequence, or a switch to another sequence followed by the time coded
//! against that one. The two compressors share every rule but one: the
//! pointwise item codes "unchanged" as a symbol of its own (one more in
//! each alphabet, [`GpsVariant::Pointwise`]); the point-14 layer is only
//! consulted when the point says its time changed.
//!
//! LASzip (and the `laz` crate) decode a switch by recursion, which damaged
//! data can drive deep enough to overflow any stack (`docs/robustness.md`,
//! findings 2 and 5). Here it is a loop, and since an encoder writes at most
//! one switch per point (it switches to the sequence that fits), more
//! switches than there are sequences is refused as damaged data.

use super::arithmetic::{Decoder, Fault, Step};
use super::integer::IntegerDecoder;
use super::models::SymbolModel;

/// Largest multiple of the last difference coded directly.
const MULTI: u32 = 500;
/// Largest negative multiple (its magnitude).
const MULTI_MINUS: u32 = 10;
/// The last symbol of a multiple (501-510: the multiples -1 to -10).
const LAST_MULTIPLE: u32 = MULTI + MULTI_MINUS;
/// Most sequence switches accepted before a time.
const MAX_SWITCHES: usize = 4;

/// Which compressor's GPS-time alphabet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum GpsVariant {
    /// the point-14 layer (no "unchanged" symbol)
    Point14,
    /// the pointwise item of version 2 ("unchanged" is a symbol)
    Pointwise,
}

/// The four time sequences and the integer decompressor their differences
/// and full times are coded with.
struct GpsSequences {
    current: usize,
    newest: usize,
    times: [i64; 4],
    diffs: [i32; 4],
    extremes: [u32; 4],
    ints: IntegerDecoder,
}

impl GpsSequences {
    fn new(time: i64) -> Self {
        Self {
            current: 0,
            newest: 0,
            times: [time, 0, 0, 0],
            diffs: [0; 4],
            extremes: [0; 4],
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

    /// A new difference for the current sequence (which had none).
    fn first_difference(&mut self, dec: &mut Decoder<'_>) -> Step<()> {
        let c = self.current;
        let diff = self.ints.decode(dec, 0, 0)?;
        self.diffs[c] = diff;
        self.times[c] = self.times[c].wrapping_add(i64::from(diff));
        self.extremes[c] = 0;
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

    /// The time after multiple symbol `s` (0 to [`LAST_MULTIPLE`]) of the
    /// current sequence's difference: 1 the difference itself (with a
    /// corrector), 0 a difference of its own, 2-500 that many times the
    /// difference, 501-510 the multiples -1 to -10 (500, -10 and the
    /// unpredicted one count as extreme).
    fn multiple(&mut self, dec: &mut Decoder<'_>, s: u32) -> Step<()> {
        let c = self.current;
        let last = self.diffs[c];
        let diff = match s {
            1 => {
                let d = self.ints.decode(dec, last, 1)?;
                self.extremes[c] = 0;
                d
            }
            0 => {
                let d = self.ints.decode(dec, 0, 7)?;
                self.extreme(d);
                d
            }
            s if s < MULTI => {
                let context = if s < 10 { 2 } else { 3 };
                self.ints
                    .decode(dec, (s as i32).wrapping_mul(last), context)?
            }
            MULTI => {
                let d = self
                    .ints
                    .decode(dec, (MULTI as i32).wrapping_mul(last), 4)?;
                self.extreme(d);
                d
            }
            s => {
                let m = MULTI as i32 - s as i32;
                if m > -(MULTI_MINUS as i32) {
                    self.ints.decode(dec, m.wrapping_mul(last), 5)?
                } else {
                    let d = self
                        .ints
                        .decode(dec, (-(MULTI_MINUS as i32)).wrapping_mul(last), 6)?;
                    self.extreme(d);
                    d
                }
            }
        };
        self.times[c] = self.times[c].wrapping_add(i64::from(diff));
        Ok(())
    }
}

/// GPS-time decoder of one chunk (point-14: of one scanner channel).
pub(super) struct GpsTime {
    sequences: GpsSequences,
    /// 1 when "unchanged" is a symbol ([`GpsVariant::Pointwise`]), else 0
    unchanged: u32,
    multi: SymbolModel,
    no_diff: SymbolModel,
}

impl GpsTime {
    /// The decoder after the chunk's raw first time (an IEEE bit pattern).
    pub(super) fn new(time: i64, variant: GpsVariant) -> Self {
        let unchanged = u32::from(variant == GpsVariant::Pointwise);
        Self {
            sequences: GpsSequences::new(time),
            unchanged,
            // the multiples, unchanged (pointwise), full, three switches
            multi: SymbolModel::new(LAST_MULTIPLE + 1 + unchanged + 4),
            // unchanged (pointwise), difference, full, three switches
            no_diff: SymbolModel::new(unchanged + 5),
        }
    }

    /// Decodes the next time and returns it (bit pattern).
    pub(super) fn next(&mut self, dec: &mut Decoder<'_>) -> Step<i64> {
        let u = self.unchanged;
        let seq = &mut self.sequences;
        for _ in 0..=MAX_SWITCHES {
            let c = seq.current;
            // the symbol's offset past "full" is the switch
            let switch = if seq.diffs[c] == 0 {
                match dec.symbol(&mut self.no_diff)? {
                    s if s < u => None,
                    s if s == u => {
                        seq.first_difference(dec)?;
                        None
                    }
                    s if s == u + 1 => {
                        seq.full(dec)?;
                        None
                    }
                    s => Some(s - u - 1),
                }
            } else {
                let full = LAST_MULTIPLE + 1 + u;
                match dec.symbol(&mut self.multi)? {
                    s if s <= LAST_MULTIPLE => {
                        seq.multiple(dec, s)?;
                        None
                    }
                    s if s < full => None,
                    s if s == full => {
                        seq.full(dec)?;
                        None
                    }
                    s => Some(s - full),
                }
            };
            match switch {
                Some(by) => seq.current = (c + by as usize) & 3,
                None => return Ok(seq.times[seq.current]),
            }
        }
        Err(Fault::Switches)
    }
}
