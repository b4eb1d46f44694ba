//! Decoding of fixed-size binary records (PLY, PCD): a plan of byte offsets
//! per property, read with `from_le_bytes`/`from_be_bytes`, in parallel over
//! chunks of records (rayon's indexed `collect_into_vec` writes the output in
//! place, so a column costs one pass and no temporary).

use rayon::prelude::*;
use scanfit::Point3;

/// Records per rayon task: small inputs stay on one thread.
const MIN_RECORDS_PER_TASK: usize = 1 << 15;

/// A scalar type of a binary property.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    /// Size in bytes.
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    /// Whether the type is an integer type.
    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// Reads one value from the start of `bytes`; `None` if `bytes` is too short.
    pub(crate) fn read(self, bytes: &[u8], big: bool) -> Option<f64> {
        macro_rules! rd {
            ($t:ty) => {{
                let a = bytes.get(..std::mem::size_of::<$t>())?.try_into().ok()?;
                Some(if big {
                    <$t>::from_be_bytes(a) as f64
                } else {
                    <$t>::from_le_bytes(a) as f64
                })
            }};
        }
        match self {
            Scalar::I8 => rd!(i8),
            Scalar::U8 => rd!(u8),
            Scalar::I16 => rd!(i16),
            Scalar::U16 => rd!(u16),
            Scalar::I32 => rd!(i32),
            Scalar::U32 => rd!(u32),
            Scalar::I64 => rd!(i64),
            Scalar::U64 => rd!(u64),
            Scalar::F32 => rd!(f32),
            Scalar::F64 => rd!(f64),
        }
    }
}

/// One scalar column inside a byte buffer: value `i` starts at
/// `data[i * stride + offset]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Column<'a> {
    pub data: &'a [u8],
    pub stride: usize,
    pub offset: usize,
    pub ty: Scalar,
    pub big: bool,
}

/// The `N` bytes at `off` of a record (zeros if out of range, which the
/// callers' plans exclude: every offset + size is at most the stride).
#[inline(always)]
fn get<const N: usize>(record: &[u8], off: usize) -> [u8; N] {
    let mut a = [0u8; N];
    if let Some(s) = record.get(off..off + N) {
        a.copy_from_slice(s);
    }
    a
}

impl Column<'_> {
    /// The first `n` records of the column's buffer (fewer if it is shorter;
    /// the callers check the size first).
    fn records(&self, n: usize) -> &[u8] {
        let len = n.saturating_mul(self.stride).min(self.data.len());
        self.data.get(..len).unwrap_or_default()
    }
}

/// Runs the caller's local macro `$run!(T)` with the Rust type `T` of the
/// scalar type `$scalar` (one monomorphised decoding loop per type).
macro_rules! by_scalar {
    ($scalar:expr, $run:ident) => {
        match $scalar {
            Scalar::I8 => $run!(i8),
            Scalar::U8 => $run!(u8),
            Scalar::I16 => $run!(i16),
            Scalar::U16 => $run!(u16),
            Scalar::I32 => $run!(i32),
            Scalar::U32 => $run!(u32),
            Scalar::I64 => $run!(i64),
            Scalar::U64 => $run!(u64),
            Scalar::F32 => $run!(f32),
            Scalar::F64 => $run!(f64),
        }
    };
}

/// Decodes `n` values of a column as `f64`.
pub(crate) fn decode_column(c: Column<'_>, n: usize) -> Vec<f64> {
    let mut out = Vec::new();
    if c.stride == 0 {
        return out;
    }
    let body = c.records(n);
    let off = c.offset;
    macro_rules! run {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            let it = body
                .par_chunks_exact(c.stride)
                .with_min_len(MIN_RECORDS_PER_TASK);
            if c.big {
                it.map(|r| <$t>::from_be_bytes(get::<N>(r, off)) as f64)
                    .collect_into_vec(&mut out)
            } else {
                it.map(|r| <$t>::from_le_bytes(get::<N>(r, off)) as f64)
                    .collect_into_vec(&mut out)
            }
        }};
    }
    by_scalar!(c.ty, run);
    out
}

/// Decodes `n` points from three columns. When x, y and z share one buffer,
/// stride, type and byte order (the usual case) it is one pass over the
/// records; otherwise the three columns are decoded and zipped.
pub(crate) fn decode_points(x: Column<'_>, y: Column<'_>, z: Column<'_>, n: usize) -> Vec<Point3> {
    let same = std::ptr::eq(x.data, y.data)
        && std::ptr::eq(x.data, z.data)
        && x.stride == y.stride
        && x.stride == z.stride
        && x.ty == y.ty
        && x.ty == z.ty
        && x.big == y.big
        && x.big == z.big
        && x.stride > 0;
    let mut out = Vec::new();
    if !same {
        let (xs, ys, zs) = (
            decode_column(x, n),
            decode_column(y, n),
            decode_column(z, n),
        );
        xs.into_par_iter()
            .zip(ys)
            .zip(zs)
            .map(|((x, y), z)| Point3::new(x, y, z))
            .collect_into_vec(&mut out);
        return out;
    }
    let body = x.records(n);
    let (ox, oy, oz) = (x.offset, y.offset, z.offset);
    macro_rules! run {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            let it = body
                .par_chunks_exact(x.stride)
                .with_min_len(MIN_RECORDS_PER_TASK);
            if x.big {
                it.map(|r| {
                    Point3::new(
                        <$t>::from_be_bytes(get::<N>(r, ox)) as f64,
                        <$t>::from_be_bytes(get::<N>(r, oy)) as f64,
                        <$t>::from_be_bytes(get::<N>(r, oz)) as f64,
                    )
                })
                .collect_into_vec(&mut out)
            } else {
                it.map(|r| {
                    Point3::new(
                        <$t>::from_le_bytes(get::<N>(r, ox)) as f64,
                        <$t>::from_le_bytes(get::<N>(r, oy)) as f64,
                        <$t>::from_le_bytes(get::<N>(r, oz)) as f64,
                    )
                })
                .collect_into_vec(&mut out)
            }
        }};
    }
    by_scalar!(x.ty, run);
    out
}

/// Decodes the first `out.len()` values of a column into `out` on this
/// thread (a block of a reader that runs blocks in parallel): one loop per
/// type, no dispatch per value.
pub(crate) fn decode_column_into(c: Column<'_>, out: &mut [f64]) {
    if c.stride == 0 {
        return;
    }
    let records = c.records(out.len()).chunks_exact(c.stride);
    let off = c.offset;
    macro_rules! run {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            if c.big {
                for (o, r) in out.iter_mut().zip(records) {
                    *o = <$t>::from_be_bytes(get::<N>(r, off)) as f64;
                }
            } else {
                for (o, r) in out.iter_mut().zip(records) {
                    *o = <$t>::from_le_bytes(get::<N>(r, off)) as f64;
                }
            }
        }};
    }
    by_scalar!(c.ty, run);
}

/// Decodes the first `out.len()` points of three columns into `out` on
/// this thread, as [`decode_points`] does: one loop over the records when
/// x, y and z share their type and byte order, else column by column.
pub(crate) fn decode_points_into(x: Column<'_>, y: Column<'_>, z: Column<'_>, out: &mut [Point3]) {
    let same = x.ty == y.ty && x.ty == z.ty && x.big == y.big && x.big == z.big;
    if !same || x.stride == 0 || x.stride != y.stride || x.stride != z.stride {
        let mut v = vec![0.0; out.len()];
        for (k, c) in [x, y, z].into_iter().enumerate() {
            decode_column_into(c, &mut v);
            for (p, a) in out.iter_mut().zip(&v) {
                p.coords[k] = *a;
            }
        }
        return;
    }
    let records = x.records(out.len()).chunks_exact(x.stride);
    let (ox, oy, oz) = (x.offset, y.offset, z.offset);
    macro_rules! run {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            if x.big {
                let rd = |r: &[u8], o| <$t>::from_be_bytes(get::<N>(r, o)) as f64;
                for (p, r) in out.iter_mut().zip(records) {
                    *p = Point3::new(rd(r, ox), rd(r, oy), rd(r, oz));
                }
            } else {
                let rd = |r: &[u8], o| <$t>::from_le_bytes(get::<N>(r, o)) as f64;
                for (p, r) in out.iter_mut().zip(records) {
                    *p = Point3::new(rd(r, ox), rd(r, oy), rd(r, oz));
                }
            }
        }};
    }
    by_scalar!(x.ty, run);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_and_points_in_both_byte_orders() {
        // records: f32 x, i16 label, f32 y, f32 z (14 bytes)
        let mut le = Vec::new();
        let mut be = Vec::new();
        for i in 0..3 {
            let (x, y, z, l) = (i as f32 + 0.5, -(i as f32), 2.0f32.powi(i), -3 - i as i16);
            le.extend(x.to_le_bytes());
            le.extend(l.to_le_bytes());
            le.extend(y.to_le_bytes());
            le.extend(z.to_le_bytes());
            be.extend(x.to_be_bytes());
            be.extend(l.to_be_bytes());
            be.extend(y.to_be_bytes());
            be.extend(z.to_be_bytes());
        }
        for (data, big) in [(&le, false), (&be, true)] {
            let col = |offset, ty| Column {
                data,
                stride: 14,
                offset,
                ty,
                big,
            };
            let p = decode_points(
                col(0, Scalar::F32),
                col(6, Scalar::F32),
                col(10, Scalar::F32),
                3,
            );
            assert_eq!(p[2], Point3::new(2.5, -2.0, 4.0));
            assert_eq!(
                decode_column(col(4, Scalar::I16), 3),
                vec![-3.0, -4.0, -5.0]
            );
            // mixed types take the column-by-column path
            let q = decode_points(
                col(0, Scalar::F32),
                col(4, Scalar::I16),
                col(10, Scalar::F32),
                3,
            );
            assert_eq!(q[1], Point3::new(1.5, -4.0, 2.0));
            assert_eq!(Scalar::I16.read(&data[18..], big), Some(-4.0));
        }
        assert_eq!(Scalar::F64.read(&[0; 7], false), None);
    }
}
