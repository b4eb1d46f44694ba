//! The RGB and NIR items of the layered compressor (point formats 7, 8
//! and 10): one layer each, coded as byte-wise differences from the last
//! colour, with a model set per scanner-channel context.
//!
//! Which last value predicts follows the item version: version 4 always
//! predicts from the context's own last value; version 3 (what LASzip
//! writes) keeps predicting from the value of the context used before when
//! it switches to a context that already exists. The decoder must follow
//! whichever the file was written with.

use super::arithmetic::{Decoder, Step};
use super::models::SymbolModel;

fn clamp_u8(v: i32) -> u8 {
    v.clamp(0, 255) as u8
}

fn lo(v: u16) -> u8 {
    (v & 0xff) as u8
}

fn hi(v: u16) -> u8 {
    (v >> 8) as u8
}

/// Picks the last value that predicts, per context (shared by RGB and NIR).
struct Contexts<T: Copy> {
    used: [bool; 4],
    last: [T; 4],
    current: usize,
    version4: bool,
}

impl<T: Copy> Contexts<T> {
    fn new(first: T, context: usize, version4: bool) -> Self {
        let mut used = [false; 4];
        used[context] = true;
        Self {
            used,
            last: [first; 4],
            current: context,
            version4,
        }
    }

    /// Moves to `context`; returns the index of the predicting value.
    fn enter(&mut self, context: usize) -> usize {
        let mut predict = self.current;
        if self.current != context {
            let before = self.current;
            self.current = context;
            if !self.used[context] {
                self.last[context] = self.last[before];
                self.used[context] = true;
                predict = context;
            }
            if self.version4 {
                predict = context;
            }
        }
        predict
    }
}

pub(super) struct RgbModels {
    used: SymbolModel,
    bytes: [SymbolModel; 6],
}

impl RgbModels {
    pub(super) fn new() -> Box<Self> {
        Box::new(Self {
            used: SymbolModel::new(128),
            bytes: std::array::from_fn(|_| SymbolModel::new(256)),
        })
    }
}

/// RGB decoder of one chunk.
pub(super) struct RgbDecoder {
    contexts: Contexts<[u16; 3]>,
    models: [Option<Box<RgbModels>>; 4],
}

impl RgbDecoder {
    pub(super) fn new(first: [u16; 3], context: usize, version4: bool) -> Self {
        Self {
            contexts: Contexts::new(first, context, version4),
            models: [None, None, None, None],
        }
    }

    /// The next colour under `context` (`dec` is `None` for an empty layer).
    pub(super) fn next(&mut self, dec: Option<&mut Decoder<'_>>, context: usize) -> Step<[u16; 3]> {
        let at = self.contexts.enter(context);
        let last = self.contexts.last[at];
        let Some(dec) = dec else {
            return Ok(last);
        };
        let models = self.models[self.contexts.current].get_or_insert_with(RgbModels::new);
        let new = decode_rgb(dec, models, last)?;
        self.contexts.last[at] = new;
        Ok(new)
    }
}

/// One colour: which bytes changed, then red's bytes as differences, and
/// green's and blue's as differences from red's change (when not grey),
/// byte plane by byte plane (low byte: plane 0, high byte: plane 1).
pub(super) fn decode_rgb(
    dec: &mut Decoder<'_>,
    m: &mut RgbModels,
    last: [u16; 3],
) -> Step<[u16; 3]> {
    let used = dec.symbol(&mut m.used)?;
    let byte = |v: u16, plane: usize| (v >> (8 * plane)) as u8;
    // model k (0-5) = red low, red high, green low, green high, blue low,
    // blue high; `base` plus the decoded difference, or `base` unchanged
    let mut next = |k: usize, base: u8, dec: &mut Decoder<'_>| -> Step<u8> {
        if used & (1 << k) != 0 {
            Ok((dec.symbol(&mut m.bytes[k])? as u8).wrapping_add(base))
        } else {
            Ok(base)
        }
    };
    let mut out = [[0u8; 2]; 3];
    for plane in 0..2 {
        out[0][plane] = next(plane, byte(last[0], plane), dec)?;
    }
    let red = u16::from_le_bytes(out[0]);
    if used & (1 << 6) == 0 {
        return Ok([red, red, red]);
    }
    for plane in 0..2 {
        let (r, g, b) = (
            byte(last[0], plane),
            byte(last[1], plane),
            byte(last[2], plane),
        );
        let d = i32::from(out[0][plane]) - i32::from(r);
        out[1][plane] = if used & (1 << (2 + plane)) != 0 {
            next(2 + plane, clamp_u8(d + i32::from(g)), dec)?
        } else {
            g
        };
        out[2][plane] = if used & (1 << (4 + plane)) != 0 {
            let d = (d + i32::from(out[1][plane]) - i32::from(g)) / 2;
            next(4 + plane, clamp_u8(d + i32::from(b)), dec)?
        } else {
            b
        };
    }
    Ok(out.map(u16::from_le_bytes))
}

struct NirModels {
    used: SymbolModel,
    low: SymbolModel,
    high: SymbolModel,
}

/// NIR decoder of one chunk.
pub(super) struct NirDecoder {
    contexts: Contexts<u16>,
    models: [Option<Box<NirModels>>; 4],
}

impl NirDecoder {
    pub(super) fn new(first: u16, context: usize, version4: bool) -> Self {
        Self {
            contexts: Contexts::new(first, context, version4),
            models: [None, None, None, None],
        }
    }

    /// The next NIR value under `context` (`dec` is `None` for an empty layer).
    pub(super) fn next(&mut self, dec: Option<&mut Decoder<'_>>, context: usize) -> Step<u16> {
        let at = self.contexts.enter(context);
        let last = self.contexts.last[at];
        let Some(dec) = dec else {
            return Ok(last);
        };
        let m = self.models[self.contexts.current].get_or_insert_with(|| {
            Box::new(NirModels {
                used: SymbolModel::new(4),
                low: SymbolModel::new(256),
                high: SymbolModel::new(256),
            })
        });
        let used = dec.symbol(&mut m.used)?;
        let low = if used & 1 != 0 {
            (dec.symbol(&mut m.low)? as u8).wrapping_add(lo(last))
        } else {
            lo(last)
        };
        let high = if used & 2 != 0 {
            (dec.symbol(&mut m.high)? as u8).wrapping_add(hi(last))
        } else {
            hi(last)
        };
        let new = u16::from(low) | (u16::from(high) << 8);
        self.contexts.last[at] = new;
        Ok(new)
    }
}
