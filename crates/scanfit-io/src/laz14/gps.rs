//! GPS time of the point-14 layers. Times are handled as the 64-bit
//! integers of their IEEE bit patterns; up to four "sequences" (for
//! interleaved flight lines or pulses) each keep a last time and a last
//! difference. Per point one symbol says how the time relates to the
//! current sequence: a multiple of its difference (with a corrector), a new
//! difference, a full 64-bit time opening a new sequence, or a switch to
//! another sequence followed by the time coded against that one.
//!
//! LASzip decodes a switch by recursion; here it is a loop, and since an
//! encoder writes at most one switch per point (it switches to the
//! sequence that fits), more switches than there are sequences is refused
//! as damaged data instead of being followed.

use super::arithmetic::{Decoder, Fault, Step};
use super::integer::IntegerDecoder;
use super::models::SymbolModel;

/// Largest multiple of the last difference coded directly.
const MULTI: u32 = 500;
/// Largest negative multiple (its magnitude).
const MULTI_MINUS: u32 = 10;
/// Symbol of a full time opening a new sequence; symbols above it switch.
const CODE_FULL: u32 = MULTI + MULTI_MINUS + 1;
/// Symbols of the multiple model: the codes plus three switches.
const MULTI_TOTAL: u32 = MULTI + MULTI_MINUS + 5;
/// Most sequence switches accepted before a time.
const MAX_SWITCHES: usize = 4;

/// Time state of one scanner channel.
pub(super) struct GpsState {
    current: usize,
    newest: usize,
    times: [i64; 4],
    diffs: [i32; 4],
    extremes: [u32; 4],
    multi: SymbolModel,
    no_diff: SymbolModel,
    ints: IntegerDecoder,
}

impl GpsState {
    /// State whose first sequence holds `time` (an IEEE bit pattern).
    pub(super) fn new(time: i64) -> Self {
        Self {
            current: 0,
            newest: 0,
            times: [time, 0, 0, 0],
            diffs: [0; 4],
            extremes: [0; 4],
            multi: SymbolModel::new(MULTI_TOTAL),
            no_diff: SymbolModel::new(5),
            ints: IntegerDecoder::new(32, 9),
        }
    }

    /// The time of the current sequence (bit pattern).
    pub(super) fn time(&self) -> i64 {
        self.times[self.current]
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

    /// Decodes the next time (a point whose time changed).
    pub(super) fn read(&mut self, dec: &mut Decoder<'_>) -> Step<()> {
        for _ in 0..=MAX_SWITCHES {
            let c = self.current;
            if self.diffs[c] == 0 {
                match dec.symbol(&mut self.no_diff)? {
                    0 => {
                        let diff = self.ints.decode(dec, 0, 0)?;
                        self.diffs[c] = diff;
                        self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                        self.extremes[c] = 0;
                    }
                    1 => self.full(dec)?,
                    s => {
                        self.current = (c + s as usize - 1) & 3;
                        continue;
                    }
                }
                return Ok(());
            }
            let last = self.diffs[c];
            let s = dec.symbol(&mut self.multi)?;
            match s {
                1 => {
                    let diff = self.ints.decode(dec, last, 1)?;
                    self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                    self.extremes[c] = 0;
                }
                0 => {
                    let diff = self.ints.decode(dec, 0, 7)?;
                    self.extreme(diff);
                    self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                }
                s if s < MULTI => {
                    let context = if s < 10 { 2 } else { 3 };
                    let diff = self
                        .ints
                        .decode(dec, (s as i32).wrapping_mul(last), context)?;
                    self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                }
                MULTI => {
                    let diff = self
                        .ints
                        .decode(dec, (MULTI as i32).wrapping_mul(last), 4)?;
                    self.extreme(diff);
                    self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                }
                s if s < CODE_FULL => {
                    // negative multiples -1 .. -10
                    let m = MULTI as i32 - s as i32;
                    let diff = if m > -(MULTI_MINUS as i32) {
                        self.ints.decode(dec, m.wrapping_mul(last), 5)?
                    } else {
                        let diff =
                            self.ints
                                .decode(dec, (-(MULTI_MINUS as i32)).wrapping_mul(last), 6)?;
                        self.extreme(diff);
                        diff
                    };
                    self.times[c] = self.times[c].wrapping_add(i64::from(diff));
                }
                CODE_FULL => self.full(dec)?,
                s => {
                    self.current = (c + (s - CODE_FULL) as usize) & 3;
                    continue;
                }
            }
            return Ok(());
        }
        Err(Fault::Switches)
    }
}
