//! The point-10 item of LASzip's pointwise compressor, version 2 (point
//! formats 0-5: the 20 bytes every LAS 1.0-1.3 record starts with).
//!
//! Per point one symbol says which of the non-coordinate fields changed;
//! the return byte, classification, scan angle and user data are then coded
//! as symbols under a model picked by their last value, intensity and point
//! source as integers against their last value, X and Y as differences
//! predicted by a running median per return class, Z against the last
//! height of the same return level.

use super::arithmetic::{Decoder, Step};
use super::integer::IntegerDecoder;
use super::median::Median5;
use super::models::SymbolModel;

/// Return class (0-15) of a return number `r` of `n` returns (both 0-7),
/// which picks the intensity and X/Y predictors: LASzip's
/// `number_return_map`.
const RETURN_MAP: [[u8; 8]; 8] = [
    [15, 14, 13, 12, 11, 10, 9, 8],
    [14, 0, 1, 3, 6, 10, 10, 9],
    [13, 1, 2, 4, 7, 11, 11, 10],
    [12, 3, 4, 5, 8, 12, 12, 11],
    [11, 6, 7, 8, 9, 13, 13, 12],
    [10, 10, 11, 12, 13, 14, 14, 13],
    [9, 10, 11, 12, 13, 14, 15, 14],
    [8, 9, 10, 11, 12, 13, 14, 15],
];

/// The 20-byte point-10 record of LAS point formats 0-5, as stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Point10 {
    /// stored X integer
    pub x: i32,
    /// stored Y integer
    pub y: i32,
    /// stored Z integer
    pub z: i32,
    /// pulse return magnitude
    pub intensity: u16,
    /// byte 14: return number (bits 0-2), number of returns (3-5), scan
    /// direction (6), edge of flight line (7)
    pub returns: u8,
    /// byte 15: classification (bits 0-4) and its synthetic, key-point and
    /// withheld flags (5-7)
    pub classification: u8,
    /// scan angle rank in degrees
    pub scan_angle_rank: i8,
    /// user data byte
    pub user_data: u8,
    /// point source ID
    pub point_source_id: u16,
}

impl Point10 {
    /// The fields of a 20-byte raw record.
    ///
    /// ```
    /// use scanfit_io::laz14::Point10;
    /// let mut raw = [0u8; 20];
    /// raw[8..12].copy_from_slice(&(-7i32).to_le_bytes());
    /// raw[14] = 2 | (3 << 3); // return 2 of 3
    /// let p = Point10::from_record(&raw);
    /// assert_eq!((p.z, p.return_number(), p.number_of_returns()), (-7, 2, 3));
    /// ```
    pub fn from_record(raw: &[u8; 20]) -> Self {
        let i32_at = |k: usize| i32::from_le_bytes([raw[k], raw[k + 1], raw[k + 2], raw[k + 3]]);
        Self {
            x: i32_at(0),
            y: i32_at(4),
            z: i32_at(8),
            intensity: u16::from_le_bytes([raw[12], raw[13]]),
            returns: raw[14],
            classification: raw[15],
            scan_angle_rank: raw[16] as i8,
            user_data: raw[17],
            point_source_id: u16::from_le_bytes([raw[18], raw[19]]),
        }
    }

    /// The return number (0-7).
    pub fn return_number(&self) -> u8 {
        self.returns & 7
    }

    /// The number of returns of the pulse (0-7).
    pub fn number_of_returns(&self) -> u8 {
        (self.returns >> 3) & 7
    }

    fn scan_direction(&self) -> usize {
        usize::from((self.returns >> 6) & 1)
    }
}

/// A symbol model per previous value (256 of them), made on first use.
struct ByValue(Vec<Option<SymbolModel>>);

impl ByValue {
    fn new() -> Self {
        Self((0..256).map(|_| None).collect())
    }

    fn decode(&mut self, dec: &mut Decoder<'_>, last: u8) -> Step<u8> {
        let model = self.0[usize::from(last)].get_or_insert_with(|| SymbolModel::new(256));
        Ok(dec.symbol(model)? as u8)
    }
}

/// Point-10 decoder of one chunk.
pub(super) struct Point10Decoder {
    last: Point10,
    last_intensity: [u16; 16],
    x_median: [Median5; 16],
    y_median: [Median5; 16],
    last_height: [i32; 8],
    changed: SymbolModel,
    returns: ByValue,
    classification: ByValue,
    user_data: ByValue,
    scan_angle: [Option<SymbolModel>; 2],
    intensity: IntegerDecoder,
    point_source: IntegerDecoder,
    dx: IntegerDecoder,
    dy: IntegerDecoder,
    z: IntegerDecoder,
}

impl Point10Decoder {
    /// The decoder after the chunk's raw first point `first` (whose
    /// intensity does not predict: the intensity predictors start at 0).
    pub(super) fn new(first: &Point10) -> Self {
        let mut last = *first;
        last.intensity = 0;
        Self {
            last,
            last_intensity: [0; 16],
            x_median: [Median5::new(); 16],
            y_median: [Median5::new(); 16],
            last_height: [0; 8],
            changed: SymbolModel::new(64),
            returns: ByValue::new(),
            classification: ByValue::new(),
            user_data: ByValue::new(),
            scan_angle: [None, None],
            intensity: IntegerDecoder::new(16, 4),
            point_source: IntegerDecoder::new(16, 1),
            dx: IntegerDecoder::new(32, 2),
            dy: IntegerDecoder::new(32, 22),
            z: IntegerDecoder::new(32, 20),
        }
    }

    /// Decodes the next point.
    pub(super) fn next(&mut self, dec: &mut Decoder<'_>) -> Step<Point10> {
        let changed = dec.symbol(&mut self.changed)?;
        let p = &mut self.last;
        if changed & (1 << 5) != 0 {
            p.returns = self.returns.decode(dec, p.returns)?;
        }
        let (r, n) = (p.return_number(), p.number_of_returns());
        let m = usize::from(RETURN_MAP[usize::from(n)][usize::from(r)]);
        let level = usize::from(r.abs_diff(n));
        if changed & (1 << 4) != 0 {
            let v = self
                .intensity
                .decode(dec, i32::from(self.last_intensity[m]), m.min(3))?;
            p.intensity = v as u16;
            self.last_intensity[m] = p.intensity;
        } else {
            p.intensity = self.last_intensity[m];
        }
        if changed & (1 << 3) != 0 {
            p.classification = self.classification.decode(dec, p.classification)?;
        }
        if changed & (1 << 2) != 0 {
            let model =
                self.scan_angle[p.scan_direction()].get_or_insert_with(|| SymbolModel::new(256));
            p.scan_angle_rank = p
                .scan_angle_rank
                .wrapping_add(dec.symbol(model)? as u8 as i8);
        }
        if changed & (1 << 1) != 0 {
            p.user_data = self.user_data.decode(dec, p.user_data)?;
        }
        if changed & 1 != 0 {
            p.point_source_id =
                self.point_source
                    .decode(dec, i32::from(p.point_source_id), 0)? as u16;
        }
        let single = usize::from(n == 1);
        let diff = self.dx.decode(dec, self.x_median[m].get(), single)?;
        p.x = p.x.wrapping_add(diff);
        self.x_median[m].add(diff);
        let k = self.dx.k;
        let context = single + if k < 20 { (k & !1) as usize } else { 20 };
        let diff = self.dy.decode(dec, self.y_median[m].get(), context)?;
        p.y = p.y.wrapping_add(diff);
        self.y_median[m].add(diff);
        let k = (self.dx.k + self.dy.k) / 2;
        let context = single + if k < 18 { (k & !1) as usize } else { 18 };
        p.z = self.z.decode(dec, self.last_height[level], context)?;
        self.last_height[level] = p.z;
        Ok(*p)
    }
}
