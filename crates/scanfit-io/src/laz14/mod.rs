//! scanfit's own decoder of LAZ point formats 6 to 10 (LAS 1.4 points,
//! LASzip's "layered" compressor, item versions 3 and 4), written from the
//! LASzip format: an adaptive arithmetic decoder ([`arithmetic`],
//! [`models`]), the integer decompressor with its corrector classes
//! ([`integer`]), and per chunk the point-14 layers ([`point`], GPS time in
//! [`gps`]) and the RGB and NIR layers ([`color`]).
//!
//! It exists because the `laz` crate decodes point-14 GPS times by
//! recursion, and a crafted or damaged file of a few hundred bytes drives
//! that recursion deep enough to overflow any stack (an abort no error
//! handling can catch; `docs/robustness.md`, finding 2). Here nothing
//! recurses, every layer is decoded from a slice of the file whose bounds
//! were checked against the chunk and the data before use, point counts
//! come from the LASzip VLR or the chunk table and are checked against the
//! count each chunk declares, and any failure is one [`Laz14Error`] naming
//! the chunk.
//!
//! Decoded: every field of the point-14 item, RGB (formats 7, 8, 10) and
//! NIR (8, 10). Extra bytes and wave packets (formats 9, 10) are not
//! decoded: their layers are skipped (layers are independent, so the
//! fields above are unaffected).
//!
//! The pointwise compressor of point formats 0-5 (compressors 1 and 2,
//! items of version 2: [`point10`], GPS time in [`gps`] (shared with the
//! layered compressor), RGB, wave packet and extra bytes in [`pointwise`])
//! is decoded here too, for the same reason: the `laz` crate's version-2
//! GPS-time decoder recurses on every "switch sequence" symbol (finding 5
//! of `docs/robustness.md`). A pointwise chunk is decoded through a
//! [`PointwiseCursor`] holding a bounded window of its bytes, any number
//! of points at a time: a compressor-1 file is one chunk of all its points.
//!
//! The API works per chunk, so that a caller can decode chunks in any
//! order or in parallel: [`LayeredLaz::new`] walks the chunk headers and
//! checks them, [`LayeredLaz::decode_chunk`] decodes one chunk.

mod arithmetic;
mod chunk;
mod color;
mod gps;
mod integer;
mod median;
mod models;
mod point;
mod point10;
mod pointwise;

pub use chunk::{ChunkSpan, LayeredLaz, ReadAt};
pub use point10::Point10;
pub use pointwise::{PointwiseCursor, PointwiseLaz, PointwiseRecord, ReadInto, WINDOW};

/// One decoded point: the raw fields of the LAS 1.4 point record (formats
/// 6-10), coordinates as the stored integers (apply the header's scale and
/// offset), plus RGB and NIR (zero when the format has none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point14 {
    /// stored X integer
    pub x: i32,
    /// stored Y integer
    pub y: i32,
    /// stored Z integer
    pub z: i32,
    /// pulse return magnitude
    pub intensity: u16,
    /// return number (0-15)
    pub return_number: u8,
    /// number of returns of the pulse (0-15)
    pub number_of_returns: u8,
    /// byte 15 of the record: classification flags (bits 0-3), scanner
    /// channel (4-5), scan direction (6), edge of flight line (7)
    pub flags: u8,
    /// classification (0-255)
    pub classification: u8,
    /// user data byte
    pub user_data: u8,
    /// scan angle in units of 0.006 degrees
    pub scan_angle: i16,
    /// point source ID
    pub point_source_id: u16,
    /// GPS time
    pub gps_time: f64,
    /// red, green, blue (formats 7, 8, 10)
    pub rgb: [u16; 3],
    /// near infrared (formats 8, 10)
    pub nir: u16,
}

impl Point14 {
    /// The point-14 fields from a 30-byte raw record (RGB and NIR zero).
    ///
    /// ```
    /// use scanfit_io::laz14::Point14;
    /// let mut raw = [0u8; 30];
    /// raw[0..4].copy_from_slice(&(-5i32).to_le_bytes());
    /// raw[14] = 0x21; // return 1 of 2
    /// raw[15] = 0x30; // scanner channel 3
    /// raw[22..30].copy_from_slice(&1.5f64.to_le_bytes());
    /// let p = Point14::from_record(&raw);
    /// assert_eq!((p.x, p.return_number, p.number_of_returns), (-5, 1, 2));
    /// assert_eq!((p.scanner_channel(), p.gps_time), (3, 1.5));
    /// ```
    pub fn from_record(raw: &[u8; 30]) -> Self {
        let i32_at = |k: usize| i32::from_le_bytes([raw[k], raw[k + 1], raw[k + 2], raw[k + 3]]);
        let u16_at = |k: usize| u16::from_le_bytes([raw[k], raw[k + 1]]);
        let mut time = [0u8; 8];
        time.copy_from_slice(&raw[22..30]);
        Self {
            x: i32_at(0),
            y: i32_at(4),
            z: i32_at(8),
            intensity: u16_at(12),
            return_number: raw[14] & 0x0f,
            number_of_returns: raw[14] >> 4,
            flags: raw[15],
            classification: raw[16],
            user_data: raw[17],
            scan_angle: u16_at(18) as i16,
            point_source_id: u16_at(20),
            gps_time: f64::from_le_bytes(time),
            rgb: [0; 3],
            nir: 0,
        }
    }

    /// The scanner channel (0-3).
    pub fn scanner_channel(&self) -> u8 {
        (self.flags >> 4) & 3
    }

    fn set_scanner_channel(&mut self, channel: u8) {
        self.flags = (self.flags & !0x30) | ((channel & 3) << 4);
    }
}

/// Why a layered LAZ file cannot be decoded: where, and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Laz14Error {
    /// byte offset in the file (the chunk's start, or the LASzip VLR's)
    pub offset: u64,
    /// what is wrong and what to do, naming the chunk where there is one
    pub message: String,
}

impl Laz14Error {
    /// A maker of errors at byte `offset`.
    pub(crate) fn at(offset: u64) -> impl Fn(String) -> Laz14Error {
        move |message| Laz14Error { offset, message }
    }
}

impl std::fmt::Display for Laz14Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "byte offset {}: {}", self.offset, self.message)
    }
}

impl std::error::Error for Laz14Error {}
