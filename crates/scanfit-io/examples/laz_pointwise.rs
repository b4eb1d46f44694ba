//! Writes a LAS file of point formats 0-5 as a LAZ file of LASzip's
//! compressor 1 (pointwise, no chunk table: the whole point stream one
//! arithmetic-coded chunk), the input of the streamed-LAZ rows of
//! `benches/scale/run.py` (BENCHMARKS.md, "Streamed compressor-1 LAZ"):
//!
//! ```sh
//! python3 benches/scale/make_franke.py 10000000 /tmp/franke_10000000.las
//! cargo run --release -p scanfit-io --example laz_pointwise -- /tmp/franke_10000000.las /tmp/franke_10000000_c1.laz
//! ```
//!
//! The header and VLRs are copied, the point format marked compressed, the
//! LASzip VLR (items of version 2, as LASzip 2.x and later write them)
//! appended to the VLRs, and the records compressed by the `laz` crate's
//! pointwise record compressor as they are read. (The `laz` crate's
//! `LasZipCompressor` writes compressor 2, chunked, only.)
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};

use laz::record::{RecordCompressor, SequentialPointRecordCompressor};
use laz::{LazItemRecordBuilder, LazVlrBuilder};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = &args[..] else {
        panic!("usage: laz_pointwise INPUT.las OUTPUT.laz");
    };
    let mut src = BufReader::with_capacity(1 << 20, File::open(input).unwrap());
    let mut head = vec![0u8; 375];
    src.read_exact(&mut head[..227]).unwrap();
    let u16_at = |h: &[u8], k: usize| u16::from_le_bytes([h[k], h[k + 1]]);
    let u32_at = |h: &[u8], k: usize| u32::from_le_bytes(h[k..k + 4].try_into().unwrap());
    let start = u32_at(&head, 96) as usize;
    head.resize(start, 0);
    src.seek(SeekFrom::Start(0)).unwrap();
    src.read_exact(&mut head).unwrap();
    let format = head[104];
    assert!(
        format <= 5,
        "point format {format}: this writes formats 0-5"
    );
    let len = usize::from(u16_at(&head, 105));
    let standard = [20, 28, 26, 34, 57, 63][usize::from(format)];
    let items =
        LazItemRecordBuilder::default_for_point_format_id(format, (len - standard) as u16).unwrap();
    let vlr = LazVlrBuilder::new(items).build();
    let mut payload = Vec::new();
    vlr.write_to(&mut payload).unwrap();
    payload[0] = 1; // compressor 1: pointwise, one chunk
    let new_start = start + 54 + payload.len();
    head[96..100].copy_from_slice(&(new_start as u32).to_le_bytes());
    let vlrs = u32_at(&head, 100) + 1;
    head[100..104].copy_from_slice(&vlrs.to_le_bytes());
    head[104] = format | 0x80;
    let mut vh = [0u8; 54];
    vh[2..16].copy_from_slice(b"laszip encoded");
    vh[18..20].copy_from_slice(&22204u16.to_le_bytes());
    vh[20..22].copy_from_slice(&(payload.len() as u16).to_le_bytes());
    let mut out = BufWriter::with_capacity(1 << 20, File::create(output).unwrap());
    out.write_all(&head).unwrap();
    out.write_all(&vh).unwrap();
    out.write_all(&payload).unwrap();
    let mut c = SequentialPointRecordCompressor::new(out);
    c.set_fields_from(vlr.items()).unwrap();
    let n = u64::from(u32_at(&head, 107));
    let mut record = vec![0u8; len];
    for _ in 0..n {
        src.read_exact(&mut record).unwrap();
        c.compress_next(&record).unwrap();
    }
    c.done().unwrap();
    c.into_inner().flush().unwrap();
}
