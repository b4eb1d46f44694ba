//! The vertices of a binary PLY point file read straight from the file into
//! the points (issue 18): the common layout of a point file, a vertex
//! element of fixed-size records and nothing else, in either byte order.
//!
//! The general reader ([`super::parse`]) takes the whole file into memory
//! first and then decodes it, so a 10^7-point file of 240 MB is held twice
//! and copied from the page cache on one thread. Here the header is parsed
//! from the file's first [`HEAD`] bytes by the same function, and the
//! records are read in blocks of [`BLOCK`] by positional reads on all
//! threads, each block decoded at once into its slice of the points and the
//! extra columns (one loop per column type, [`decode_points_into`]): the
//! file's bytes are never held whole.
//!
//! Every check of the general reader applies: a file this path does not
//! take ([`read`] returns `None`: text, lists, other elements, a header
//! longer than [`HEAD`], a vertex count the file's size does not hold, no
//! vertices) is read by the general reader, which reports its errors; a
//! file it takes gives the general reader's table (points, columns, origin,
//! warnings) and errors (non-finite coordinates) to the bit, as
//! `tests/ply_direct.rs` and the fuzz target `ply`
//! ([`crate::fuzz::point_file`]) check.

use std::path::Path;

use rayon::prelude::*;
use scanfit::Point3;

use super::{parse_header, plan, records_table, spare_warning, Encoding, Kind};
use crate::binary::{decode_column_into, decode_points_into, Column, Scalar};
use crate::table::{PointTable, ReadOptions};
use crate::{Error, Result};

/// Header bytes looked at: a longer header takes the general reader.
const HEAD: u64 = 64 << 10;

/// Records per block (768 KiB of 24-byte records): one positional read and
/// one decoding loop per column each.
const BLOCK: usize = 1 << 15;

/// Bytes that can be read at any offset from any thread: a file, or bytes
/// in memory (the fuzz target compares the two readers on them).
pub(crate) trait Source: Sync {
    /// The length in bytes.
    fn size(&self) -> std::io::Result<u64>;
    /// Fills `buf` from `offset` (an error if the source ends first).
    fn read_at(&self, buf: &mut [u8], offset: u64) -> std::io::Result<()>;
}

#[cfg(unix)]
impl Source for std::fs::File {
    fn size(&self) -> std::io::Result<u64> {
        Ok(self.metadata()?.len())
    }

    fn read_at(&self, buf: &mut [u8], offset: u64) -> std::io::Result<()> {
        std::os::unix::fs::FileExt::read_exact_at(self, buf, offset)
    }
}

impl Source for [u8] {
    fn size(&self) -> std::io::Result<u64> {
        Ok(self.len() as u64)
    }

    fn read_at(&self, buf: &mut [u8], offset: u64) -> std::io::Result<()> {
        let from = usize::try_from(offset)
            .ok()
            .and_then(|o| self.get(o..o.checked_add(buf.len())?));
        match from {
            Some(b) => {
                buf.copy_from_slice(b);
                Ok(())
            }
            None => Err(std::io::ErrorKind::UnexpectedEof.into()),
        }
    }
}

/// A block of records: its number, its slice of the points and of each
/// extra column.
type Block<'a> = (usize, &'a mut [Point3], Vec<&'a mut [f64]>);

/// The points of the binary PLY file `source` (named `path` in messages)
/// when its only element is the vertex element, of fixed-size records that
/// the file holds; `Ok(None)` for every other file, which the general
/// reader then reads (see the module documentation).
pub(crate) fn read<S: Source + ?Sized>(
    path: &Path,
    source: &S,
    options: &ReadOptions,
) -> Result<Option<PointTable>> {
    let io = |error| Error::Io {
        path: path.to_path_buf(),
        error,
    };
    let size = source.size().map_err(io)?;
    let mut head = vec![0u8; size.min(HEAD) as usize];
    source.read_at(&mut head, 0).map_err(io)?;
    let Ok(header) = parse_header(path, &head) else {
        return Ok(None);
    };
    let big = match header.encoding {
        Encoding::Little => false,
        Encoding::Big => true,
        Encoding::Ascii => return Ok(None),
    };
    let [vertex] = header.elements.as_slice() else {
        return Ok(None);
    };
    let Some(stride) = vertex.fixed_stride().filter(|&s| s > 0) else {
        return Ok(None);
    };
    let start = header.body as u64;
    let need = u128::from(vertex.count) * stride as u128;
    if vertex.name != "vertex" || vertex.count == 0 || u128::from(start) + need > size.into() {
        return Ok(None);
    }
    let Ok(plan) = plan(path, vertex) else {
        return Ok(None);
    };
    let n = vertex.count as usize;
    // the byte offset and type of each property within a record
    let mut at = 0;
    let props: Vec<(usize, Scalar)> = vertex
        .props
        .iter()
        .map(|p| {
            let t = match p.kind {
                Kind::Scalar(t) => t,
                Kind::List { .. } => Scalar::U8,
            };
            at += t.size();
            (at - t.size(), t)
        })
        .collect();
    let mut points = Vec::with_capacity(n);
    points.par_extend(rayon::iter::repeat_n(Point3::origin(), n));
    let mut extra: Vec<Vec<f64>> = plan.extra.iter().map(|_| vec![0.0; n]).collect();
    // each block's slices of the points and of every extra column
    let mut columns: Vec<_> = extra.iter_mut().map(|c| c.chunks_mut(BLOCK)).collect();
    let blocks: Vec<Block<'_>> = points
        .chunks_mut(BLOCK)
        .enumerate()
        .map(|(b, p)| {
            (
                b,
                p,
                columns.iter_mut().filter_map(Iterator::next).collect(),
            )
        })
        .collect();
    blocks
        .into_par_iter()
        .try_for_each_init(Vec::new, |buf: &mut Vec<u8>, (b, out, mut cols)| {
            buf.resize(out.len() * stride, 0);
            source.read_at(buf, start + (b * BLOCK * stride) as u64)?;
            let column = |i: usize| {
                let (offset, ty) = props.get(i).copied().unwrap_or((0, Scalar::U8));
                Column {
                    data: buf,
                    stride,
                    offset,
                    ty,
                    big,
                }
            };
            let [x, y, z] = plan.xyz.map(column);
            decode_points_into(x, y, z, out);
            for (c, &i) in cols.iter_mut().zip(&plan.extra) {
                decode_column_into(column(i), c);
            }
            Ok(())
        })
        .map_err(io)?;
    let end = u128::from(start) + need;
    let mut table = records_table(path, points, plan.columns, extra, header.body, stride);
    table.warnings.extend(spare_warning(
        path,
        u128::from(size) - end,
        stride,
        vertex.count,
    ));
    table.finish(options.non_finite).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::NonFinite;

    /// Tests return errors instead of unwrapping them.
    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;

    /// A binary PLY of `n` vertices with the properties `props` (type,
    /// name), value `f(i, k)` for property `k` of vertex `i`, then `tail`.
    fn ply(big: bool, props: &[(&str, &str)], n: u64, f: impl Fn(usize, usize) -> f64) -> Vec<u8> {
        let enc = if big { "big" } else { "little" };
        let mut b = format!("ply\nformat binary_{enc}_endian 1.0\nelement vertex {n}\n");
        for (t, name) in props {
            b.push_str(&format!("property {t} {name}\n"));
        }
        b.push_str("end_header\n");
        let mut b = b.into_bytes();
        for i in 0..n as usize {
            for (k, (t, _)) in props.iter().enumerate() {
                let v = f(i, k);
                macro_rules! put {
                    ($ty:ty) => {
                        b.extend(if big {
                            (v as $ty).to_be_bytes()
                        } else {
                            (v as $ty).to_le_bytes()
                        })
                    };
                }
                match *t {
                    "double" => put!(f64),
                    "float" => put!(f32),
                    "int" => put!(i32),
                    "uchar" => put!(u8),
                    "short" => put!(i16),
                    other => panic!("no type {other} here"),
                }
            }
        }
        b
    }

    /// The direct reader's answer (`None`: not taken) and the general
    /// reader's, on the same bytes.
    fn both(
        bytes: &[u8],
        non_finite: NonFinite,
    ) -> (Option<Result<PointTable>>, Result<PointTable>) {
        let (path, options) = (
            Path::new("t.ply"),
            ReadOptions {
                non_finite,
                ..ReadOptions::default()
            },
        );
        (
            read(path, bytes, &options).transpose(),
            super::super::parse(path, bytes, &options),
        )
    }

    /// Asserts the direct reader takes `bytes` and answers as the general one.
    fn same(bytes: &[u8], non_finite: NonFinite) -> Result<PointTable> {
        let (direct, general) = both(bytes, non_finite);
        let Some(direct) = direct else {
            panic!("the direct reader did not take the file");
        };
        match (&direct, &general) {
            (Ok(a), Ok(b)) => {
                assert_eq!(a, b);
                // to the bit (signed zeros too)
                for (p, q) in a.points.iter().zip(&b.points) {
                    for k in 0..3 {
                        assert_eq!(p[k].to_bits(), q[k].to_bits());
                    }
                }
            }
            (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
            _ => panic!("direct {direct:?}, general {general:?}"),
        }
        direct
    }

    /// A value of vertex `i`, property `k`: distinct, signed, fractional.
    fn value(i: usize, k: usize) -> f64 {
        let v = ((i * 7919 + k * 104_729) % 10_007) as f64 / 64.0 - 78.0;
        if (i + k) % 97 == 0 {
            -0.0
        } else {
            v
        }
    }

    #[test]
    fn layouts_read_as_the_general_reader_reads_them() -> TestResult {
        // more than two blocks, and a last block cut short
        let n = 2 * BLOCK as u64 + 17;
        let layouts: [&[(&str, &str)]; 6] = [
            &[("double", "x"), ("double", "y"), ("double", "z")],
            &[("float", "x"), ("float", "y"), ("float", "z")],
            // mixed types: column by column
            &[("float", "x"), ("double", "y"), ("int", "z")],
            // extra properties around and between, another order
            &[
                ("uchar", "red"),
                ("float", "z"),
                ("float", "x"),
                ("short", "label"),
                ("float", "y"),
                ("double", "nx"),
            ],
            &[
                ("double", "X"),
                ("double", "Y"),
                ("double", "Z"),
                ("double", "u"),
            ],
            &[("int", "x"), ("int", "y"), ("short", "z")],
        ];
        for big in [false, true] {
            for props in layouts {
                let t = same(&ply(big, props, n, value), NonFinite::Reject)?;
                assert_eq!(t.points.len(), n as usize);
                assert_eq!(t.extra.len(), props.len() - 3);
            }
        }
        // one vertex
        let one = same(&ply(false, layouts[0], 1, value), NonFinite::Reject)?;
        assert_eq!(
            one.points,
            vec![Point3::new(value(0, 0), value(0, 1), value(0, 2))]
        );
        Ok(())
    }

    /// `bytes` with the first `from` of its header replaced by `to`.
    fn header_replaced(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
        let end = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap_or(0)
            + 11;
        let head = String::from_utf8_lossy(&bytes[..end]).replacen(from, to, 1);
        [head.as_bytes(), &bytes[end..]].concat()
    }

    #[test]
    fn hostile_files_are_refused_or_left_to_the_general_reader() {
        let xyz = [("double", "x"), ("double", "y"), ("double", "z")];
        let good = ply(false, &xyz, 100, value);
        // bytes after the last record: the same warning
        let mut spare = good.clone();
        spare.extend([0u8; 30]);
        let t = same(&spare, NonFinite::Reject);
        assert!(t.is_ok_and(|t| t.warnings.len() == 1 && t.warnings[0].contains("30 bytes follow")));
        // non-finite coordinates: the same error, or the same points dropped
        let nan = ply(false, &xyz, 100, |i, k| {
            if i == 41 && k == 1 {
                f64::NAN
            } else {
                value(i, k)
            }
        });
        assert!(same(&nan, NonFinite::Reject).is_err());
        assert!(same(&nan, NonFinite::Drop)
            .is_ok_and(|t| t.points.len() == 99 && t.dropped_non_finite == 1));
        let inf = ply(
            true,
            &[("float", "x"), ("float", "y"), ("float", "z")],
            100,
            |i, _| {
                if i == 99 {
                    f64::INFINITY
                } else {
                    1.0
                }
            },
        );
        assert!(same(&inf, NonFinite::Reject).is_err());
        // what the direct reader leaves to the general one, which refuses
        // it or reads it: counts the file does not hold (10^12 vertices
        // too: nothing is allocated), a truncated file, no vertices, text,
        // lists, a face element, a bad or cut header
        let mut not_taken: Vec<Vec<u8>> = vec![
            header_replaced(&good, "vertex 100", "vertex 1000000000000"),
            good[..good.len() - 5].to_vec(),
            ply(false, &xyz, 0, value),
        ];
        not_taken.push(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n".to_vec());
        let mut list = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar int n\nend_header\n".to_vec();
        list.extend([0u8; 12]);
        list.push(0);
        not_taken.push(list);
        not_taken.push(header_replaced(
            &good,
            "end_header",
            "element face 0\nproperty list uchar int vertex_indices\nend_header",
        ));
        not_taken.push(good[..20].to_vec());
        not_taken.push(b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0123456789ab".to_vec());
        not_taken.push(b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty quad x\nend_header\n".to_vec());
        for (k, bytes) in not_taken.iter().enumerate() {
            for policy in [NonFinite::Reject, NonFinite::Drop] {
                let (direct, _) = both(bytes, policy);
                assert!(direct.is_none(), "case {k}: taken");
            }
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_file_reads_as_its_bytes() -> TestResult {
        let dir = std::env::temp_dir().join(format!("scanfit_ply_direct_{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let path = dir.join("p.ply");
        let bytes = ply(
            false,
            &[
                ("double", "x"),
                ("float", "y"),
                ("double", "z"),
                ("int", "label"),
            ],
            BLOCK as u64 + 3,
            value,
        );
        std::fs::write(&path, &bytes)?;
        let options = ReadOptions::default();
        let file = std::fs::File::open(&path)?;
        let direct = read(&path, &file, &options)?.ok_or("not taken")?;
        assert_eq!(direct, super::super::parse(&path, &bytes, &options)?);
        assert_eq!(crate::read_cloud(&path, &options)?, direct);
        std::fs::remove_dir_all(&dir)?;
        Ok(())
    }
}
