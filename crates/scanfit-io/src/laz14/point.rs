//! The point-14 item (LAS 1.4 point formats 6-10, 30 bytes) of the layered
//! compressor: one layer for scanner channel, returns and X/Y, and one
//! each for Z, classification, flags, intensity, scan angle, user data,
//! point source ID and GPS time. Every scanner channel (up to four) has
//! its own context: last point, predictors and models.

use super::arithmetic::{Decoder, Step};
use super::gps::{GpsTime, GpsVariant};
use super::integer::IntegerDecoder;
use super::median::Median5;
use super::models::SymbolModel;
use super::Point14;

/// Context of return pairs (number of returns, return number) for X/Y
/// (a constant table of the LASzip format).
const RETURN_MAP: [[u8; 16]; 16] = [
    [0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5],
    [1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3],
    [2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3],
    [3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4],
    [4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4],
    [5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4],
    [3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4],
    [4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4],
    [4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4],
    [5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4],
    [5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4],
    [5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4],
    [5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4],
    [5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4],
    [5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5],
    [5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5],
];

/// Which Z of the last eight predicts: the distance between return number
/// and number of returns, at most 7.
fn return_level(n: u8, r: u8) -> usize {
    usize::from(n.abs_diff(r).min(7))
}

/// The nine layers of a point-14 item in a chunk (`None`: the layer is
/// empty because the field never changed in the chunk).
pub(super) struct Layers<'a> {
    pub(super) xy: Decoder<'a>,
    pub(super) z: Option<Decoder<'a>>,
    pub(super) classification: Option<Decoder<'a>>,
    pub(super) flags: Option<Decoder<'a>>,
    pub(super) intensity: Option<Decoder<'a>>,
    pub(super) scan_angle: Option<Decoder<'a>>,
    pub(super) user_data: Option<Decoder<'a>>,
    pub(super) point_source: Option<Decoder<'a>>,
    pub(super) gps_time: Option<Decoder<'a>>,
}

/// Models created on first use, one per previous value.
fn lazy(slot: &mut Option<SymbolModel>, symbols: u32) -> &mut SymbolModel {
    slot.get_or_insert_with(|| SymbolModel::new(symbols))
}

/// Everything one scanner channel remembers.
struct Channel {
    last: Point14,
    /// whether the last point's GPS time changed (a context)
    time_changed: bool,
    intensities: [u16; 8],
    dx: [Median5; 12],
    dy: [Median5; 12],
    zs: [i32; 8],
    changes: Vec<SymbolModel>,
    channel_step: SymbolModel,
    returns_count: Vec<Option<SymbolModel>>,
    return_number: Vec<Option<SymbolModel>>,
    return_same_time: SymbolModel,
    classification: Vec<Option<SymbolModel>>,
    flags: Vec<Option<SymbolModel>>,
    user_data: Vec<Option<SymbolModel>>,
    ix: IntegerDecoder,
    iy: IntegerDecoder,
    iz: IntegerDecoder,
    iintensity: IntegerDecoder,
    iscan: IntegerDecoder,
    isource: IntegerDecoder,
    gps: GpsTime,
}

impl Channel {
    fn new(last: &Point14) -> Box<Self> {
        Box::new(Self {
            last: *last,
            time_changed: false,
            intensities: [last.intensity; 8],
            dx: [Median5::new(); 12],
            dy: [Median5::new(); 12],
            zs: [last.z; 8],
            changes: (0..8).map(|_| SymbolModel::new(128)).collect(),
            channel_step: SymbolModel::new(3),
            returns_count: vec![None; 16],
            return_number: vec![None; 16],
            return_same_time: SymbolModel::new(13),
            classification: vec![None; 64],
            flags: vec![None; 64],
            user_data: vec![None; 64],
            ix: IntegerDecoder::new(32, 2),
            iy: IntegerDecoder::new(32, 22),
            iz: IntegerDecoder::new(32, 20),
            iintensity: IntegerDecoder::new(16, 4),
            iscan: IntegerDecoder::new(16, 2),
            isource: IntegerDecoder::new(16, 1),
            gps: GpsTime::new(last.gps_time.to_bits() as i64, GpsVariant::Point14),
        })
    }
}

/// Point-14 decoder state of one chunk.
pub(super) struct PointDecoder {
    channels: [Option<Box<Channel>>; 4],
    current: usize,
}

impl PointDecoder {
    /// Starts a chunk whose first (raw) point is `first`.
    pub(super) fn new(first: &Point14) -> Self {
        let current = usize::from(first.scanner_channel());
        let mut channels: [Option<Box<Channel>>; 4] = [None, None, None, None];
        channels[current] = Some(Channel::new(first));
        Self { channels, current }
    }

    /// The current scanner channel.
    pub(super) fn channel(&self) -> usize {
        self.current
    }

    /// Decodes the next point into `out` (its point-14 fields); returns
    /// whether the scanner channel changed at this point.
    pub(super) fn next(&mut self, l: &mut Layers<'_>, out: &mut Point14) -> Step<bool> {
        let mut ch = self.channels[self.current]
            .take()
            .ok_or(super::arithmetic::Fault::Ended)?;
        let lpr = usize::from(ch.last.return_number == 1)
            + 2 * usize::from(ch.last.return_number >= ch.last.number_of_returns)
            + 4 * usize::from(ch.time_changed);
        let changes = l.xy.symbol(&mut ch.changes[lpr])?;
        let switched = changes & (1 << 6) != 0;
        if switched {
            let step = l.xy.symbol(&mut ch.channel_step)? as usize;
            let next = (self.current + step + 1) & 3;
            let mut other = match self.channels[next].take() {
                Some(c) => c,
                None => Channel::new(&ch.last),
            };
            other.last.set_scanner_channel(next as u8);
            self.channels[self.current] = Some(ch);
            self.current = next;
            ch = other;
        }
        let result = decode_fields(&mut ch, changes, l);
        *out = ch.last;
        self.channels[self.current] = Some(ch);
        result.map(|()| switched)
    }
}

/// The fields after the change mask (and any channel switch).
fn decode_fields(ch: &mut Channel, changes: u32, l: &mut Layers<'_>) -> Step<()> {
    let source_changed = changes & (1 << 5) != 0;
    let time_changed = changes & (1 << 4) != 0;
    let angle_changed = changes & (1 << 3) != 0;
    let time = usize::from(time_changed);
    let last_n = ch.last.number_of_returns;
    let last_r = ch.last.return_number;
    let n = if changes & (1 << 2) != 0 {
        l.xy.symbol(lazy(&mut ch.returns_count[usize::from(last_n)], 16))? as u8
    } else {
        last_n
    };
    let r = match changes & 3 {
        0 => last_r,
        1 => (last_r + 1) % 16,
        2 => (last_r + 15) % 16,
        _ if time_changed => {
            l.xy.symbol(lazy(&mut ch.return_number[usize::from(last_r)], 16))? as u8
        }
        _ => {
            let s = l.xy.symbol(&mut ch.return_same_time)? as u8;
            (last_r + s + 2) % 16
        }
    };
    ch.last.number_of_returns = n;
    ch.last.return_number = r;
    let m = usize::from(RETURN_MAP[usize::from(n)][usize::from(r)]);
    let level = return_level(n, r);
    // single (3), first (2), last (1) or intermediate (0) return
    let cpr = 2 * usize::from(r == 1) + usize::from(r >= n);
    let single = usize::from(n == 1);

    let idx = (m << 1) | time;
    let diff = ch.ix.decode(&mut l.xy, ch.dx[idx].get(), single)?;
    ch.last.x = ch.last.x.wrapping_add(diff);
    ch.dx[idx].add(diff);
    let k = ch.ix.k;
    let context = single + if k < 20 { (k & !1) as usize } else { 20 };
    let diff = ch.iy.decode(&mut l.xy, ch.dy[idx].get(), context)?;
    ch.last.y = ch.last.y.wrapping_add(diff);
    ch.dy[idx].add(diff);

    if let Some(dec) = &mut l.z {
        let k = (ch.ix.k + ch.iy.k) / 2;
        let context = single + if k < 18 { (k & !1) as usize } else { 18 };
        ch.last.z = ch.iz.decode(dec, ch.zs[level], context)?;
        ch.zs[level] = ch.last.z;
    }
    if let Some(dec) = &mut l.classification {
        let ccc = (usize::from(ch.last.classification & 0x1f) << 1) + usize::from(cpr == 3);
        ch.last.classification = dec.symbol(lazy(&mut ch.classification[ccc], 256))? as u8;
    }
    if let Some(dec) = &mut l.flags {
        let f = ch.last.flags;
        // edge of flight line (bit 5), scan direction (bit 4), class flags
        let last = usize::from(((f >> 7) << 5) | (((f >> 6) & 1) << 4) | (f & 0x0f));
        let s = dec.symbol(lazy(&mut ch.flags[last], 64))? as u8;
        ch.last.flags = (((s >> 5) & 1) << 7) | (((s >> 4) & 1) << 6) | (f & 0x30) | (s & 0x0f);
    }
    if let Some(dec) = &mut l.intensity {
        let idx = (cpr << 1) | time;
        let v = ch
            .iintensity
            .decode(dec, i32::from(ch.intensities[idx]), cpr)?;
        ch.last.intensity = v as u16;
        ch.intensities[idx] = ch.last.intensity;
    }
    if let (Some(dec), true) = (&mut l.scan_angle, angle_changed) {
        let v = ch.iscan.decode(dec, i32::from(ch.last.scan_angle), time)?;
        ch.last.scan_angle = v as i16;
    }
    if let Some(dec) = &mut l.user_data {
        let model = lazy(&mut ch.user_data[usize::from(ch.last.user_data / 4)], 256);
        ch.last.user_data = dec.symbol(model)? as u8;
    }
    if let (Some(dec), true) = (&mut l.point_source, source_changed) {
        let v = ch
            .isource
            .decode(dec, i32::from(ch.last.point_source_id), 0)?;
        ch.last.point_source_id = v as u16;
    }
    ch.time_changed = time_changed;
    if let (Some(dec), true) = (&mut l.gps_time, time_changed) {
        ch.last.gps_time = f64::from_bits(ch.gps.next(dec)? as u64);
    }
    Ok(())
}
