//! PCD reader (the Point Cloud Library's format, v0.7 and the older headers):
//! `DATA ascii`, `binary` and `binary_compressed` (LZF, decompressed here).
//!
//! Header keys: `FIELDS` (or the older `COLUMNS`), `SIZE`, `TYPE` (`F`
//! float, `I` signed, `U` unsigned; missing = all `F`), `COUNT` (missing =
//! all 1), `WIDTH`, `HEIGHT`, `POINTS` (missing = WIDTH x HEIGHT),
//! `VIEWPOINT` (read and ignored), `VERSION`. A field with COUNT > 1 becomes
//! the columns `name_0`, `name_1`, ...; PCL's padding fields named `_` are
//! skipped. PCL's packed colour fields `rgb` / `rgba` (4 bytes, whatever the
//! declared type) are kept as the packed 32-bit value `0xAARRGGBB` (exact in
//! an f64) and unpacked to `red`, `green`, `blue` (and `alpha` for `rgba`).

use std::path::Path;

use scanfit::Point3;

use crate::binary::{decode_column, decode_points, Column, Scalar};
use crate::table::{capacity, split_lines, Format, Origin, PointTable, ReadOptions, MAX_COLUMNS};
use crate::{Error, Result};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

#[derive(Debug, Clone)]
struct Field {
    name: String,
    ty: Scalar,
    count: usize,
}

impl Field {
    fn bytes(&self) -> usize {
        self.ty.size() * self.count
    }
    /// PCL's packed colour field.
    fn is_packed_colour(&self) -> bool {
        (self.name == "rgb" || self.name == "rgba") && self.ty.size() == 4 && self.count == 1
    }
}

struct Header {
    fields: Vec<Field>,
    points: u64,
    data: Data,
    body: usize,
    lines: usize,
    /// header fields that disagree with each other
    warnings: Vec<String>,
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    if !(bytes.starts_with(b"#") || bytes.starts_with(b"VERSION") || bytes.starts_with(b"FIELDS")) {
        return Err(perr(
            1,
            "not a PCD file: it must start with a '# .PCD' comment or a VERSION line (bad magic)"
                .into(),
        ));
    }
    let mut names: Option<(usize, Vec<String>)> = None;
    let mut sizes: Option<(usize, Vec<usize>)> = None;
    let mut types: Option<(usize, Vec<char>)> = None;
    let mut counts: Option<(usize, Vec<usize>)> = None;
    let (mut width, mut height, mut points) = (None::<u64>, None::<u64>, None::<u64>);
    let mut pos = 0usize;
    let mut line_no = 0usize;
    // header lines end with LF (or CRLF); a header whose first line ends
    // with a lone CR (classic Mac) uses CR throughout
    let first = bytes.iter().position(|&b| b == b'\n' || b == b'\r');
    let eol = match first {
        Some(k) if bytes.get(k) == Some(&b'\r') && bytes.get(k + 1) != Some(&b'\n') => b'\r',
        _ => b'\n',
    };
    let data = loop {
        let Some(rest) = bytes.get(pos..).filter(|r| !r.is_empty()) else {
            return Err(perr(
                line_no,
                "the header has no DATA line: the file is truncated or not a PCD file".into(),
            ));
        };
        let (raw, next) = match rest.iter().position(|&b| b == eol) {
            Some(k) => (rest.get(..k).unwrap_or_default(), pos + k + 1),
            None => (rest, bytes.len()),
        };
        line_no += 1;
        pos = next;
        let Ok(text) = std::str::from_utf8(raw) else {
            return Err(perr(
                line_no,
                "the header line is not UTF-8 text; the header is damaged or this is not a PCD file"
                    .into(),
            ));
        };
        let text = text.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let mut tok = text.split_ascii_whitespace();
        let key = tok.next().unwrap_or_default().to_ascii_uppercase();
        let words: Vec<&str> = tok.collect();
        let ints = |what: &str| -> Result<Vec<usize>> {
            words
                .iter()
                .map(|w| {
                    w.parse::<usize>().map_err(|_| {
                        perr(
                            line_no,
                            format!("{what} value '{w}' is not a non-negative integer"),
                        )
                    })
                })
                .collect()
        };
        let one = |what: &str| -> Result<u64> {
            match words.as_slice() {
                [w] => w.parse::<u64>().map_err(|_| {
                    perr(
                        line_no,
                        format!("{what} '{w}' is not a non-negative integer"),
                    )
                }),
                _ => Err(perr(line_no, format!("{what} needs exactly one number"))),
            }
        };
        match key.as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => {
                names = Some((line_no, words.iter().map(|s| s.to_string()).collect()))
            }
            "SIZE" => sizes = Some((line_no, ints("SIZE")?)),
            "COUNT" => counts = Some((line_no, ints("COUNT")?)),
            "TYPE" => {
                let mut t = Vec::new();
                for w in &words {
                    match w.to_ascii_uppercase().as_str() {
                        "F" => t.push('F'),
                        "I" => t.push('I'),
                        "U" => t.push('U'),
                        _ => {
                            return Err(perr(
                                line_no,
                                format!("unknown TYPE '{w}'; PCD types are F (float), I (signed) and U (unsigned)"),
                            ))
                        }
                    }
                }
                types = Some((line_no, t));
            }
            "WIDTH" => width = Some(one("WIDTH")?),
            "HEIGHT" => height = Some(one("HEIGHT")?),
            "POINTS" => points = Some(one("POINTS")?),
            "DATA" => {
                break match words.first().map(|w| w.to_ascii_lowercase()).as_deref() {
                    Some("ascii") => Data::Ascii,
                    Some("binary") => Data::Binary,
                    Some("binary_compressed") => Data::Compressed,
                    _ => {
                        return Err(perr(
                            line_no,
                            format!(
                                "unknown DATA '{}'; PCD data is ascii, binary or binary_compressed",
                                words.join(" ")
                            ),
                        ))
                    }
                };
            }
            _ => {
                return Err(perr(
                    line_no,
                    format!("unknown header line '{text}'; expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS or DATA"),
                ))
            }
        }
    };
    let Some((fline, names)) = names else {
        return Err(perr(line_no, "the header has no FIELDS line".into()));
    };
    let Some((sline, sizes)) = sizes else {
        return Err(perr(line_no, "the header has no SIZE line".into()));
    };
    let n = names.len();
    let check = |line: usize, what: &str, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(perr(
                line,
                format!("{what} has {len} entries for the {n} FIELDS; give one per field"),
            ))
        }
    };
    check(sline, "SIZE", sizes.len())?;
    let types = match types {
        Some((l, t)) => {
            check(l, "TYPE", t.len())?;
            t
        }
        None => vec!['F'; n],
    };
    let counts = match counts {
        Some((l, c)) => {
            check(l, "COUNT", c.len())?;
            c
        }
        None => vec![1; n],
    };
    let mut fields = Vec::with_capacity(n);
    for (((name, &size), &t), &count) in names.iter().zip(&sizes).zip(&types).zip(&counts) {
        let ty = match (t, size) {
            ('F', 4) => Scalar::F32,
            ('F', 8) => Scalar::F64,
            ('I', 1) => Scalar::I8,
            ('I', 2) => Scalar::I16,
            ('I', 4) => Scalar::I32,
            ('I', 8) => Scalar::I64,
            ('U', 1) => Scalar::U8,
            ('U', 2) => Scalar::U16,
            ('U', 4) => Scalar::U32,
            ('U', 8) => Scalar::U64,
            _ => {
                return Err(perr(
                    fline,
                    format!("field '{name}' has TYPE {t} with SIZE {size}; F takes 4 or 8 bytes, I and U take 1, 2, 4 or 8"),
                ))
            }
        };
        fields.push(Field {
            name: name.clone(),
            ty,
            count,
        });
    }
    // a record holds sum(COUNT) values of at least one byte each (binary) or
    // one character each (ascii): more than the file's size is a damaged or
    // hostile header, refused before anything is allocated from it
    let record = fields.iter().try_fold(0usize, |acc, f| {
        f.ty.size()
            .checked_mul(f.count)
            .and_then(|b| acc.checked_add(b))
    });
    let values = fields
        .iter()
        .try_fold(0usize, |acc, f| acc.checked_add(f.count));
    match (record, values) {
        (Some(r), Some(v)) if r <= bytes.len() && v <= bytes.len() => {}
        _ => {
            return Err(perr(
                line_no,
                format!(
                    "the COUNT and SIZE lines describe records larger than the whole file ({} bytes); the header is damaged",
                    bytes.len()
                ),
            ))
        }
    }
    if let Some(v) = values.filter(|&v| v > MAX_COLUMNS) {
        return Err(perr(
            line_no,
            format!("the fields declare {v} values per point; a point file may have at most {MAX_COLUMNS}"),
        ));
    }
    let mut warnings = Vec::new();
    if let (Some(p), Some(w)) = (points, width) {
        let wh = w.saturating_mul(height.unwrap_or(1));
        if p != wh {
            warnings.push(format!(
                "{}: the header declares POINTS {p} but WIDTH x HEIGHT = {wh}; the {p} points of POINTS were read (fix the header)",
                path.display()
            ));
        }
    }
    let points = match (points, width, height) {
        (Some(p), _, _) => p,
        (None, Some(w), Some(h)) => w.saturating_mul(h),
        (None, Some(w), None) => w,
        _ => {
            return Err(perr(
                line_no,
                "the header gives neither POINTS nor WIDTH; add 'POINTS N'".into(),
            ))
        }
    };
    Ok(Header {
        fields,
        points,
        data,
        body: pos,
        lines: line_no,
        warnings,
    })
}

/// A column of the table: element `k` of field `f`.
struct Plan {
    xyz: [(usize, usize); 3],
    extra: Vec<(usize, usize)>,
    columns: Vec<String>,
}

fn plan(path: &Path, fields: &[Field]) -> Result<Plan> {
    let find = |axis: &str| {
        fields
            .iter()
            .position(|f| f.name == axis && f.count == 1)
            .or_else(|| {
                fields
                    .iter()
                    .position(|f| f.name.eq_ignore_ascii_case(axis) && f.count == 1)
            })
    };
    let mut xyz = [(0, 0); 3];
    for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
        xyz[k] = (
            find(axis).ok_or_else(|| Error::Invalid {
                path: path.to_path_buf(),
                message: format!(
                    "no field '{axis}' with COUNT 1 (fields: {}); a point needs x, y and z",
                    fields
                        .iter()
                        .map(|f| f.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })?,
            0,
        );
    }
    let mut extra = Vec::new();
    let mut columns: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
    for (i, f) in fields.iter().enumerate() {
        if f.name == "_" || xyz.contains(&(i, 0)) {
            continue;
        }
        for k in 0..f.count {
            extra.push((i, k));
            columns.push(if f.count == 1 {
                f.name.clone()
            } else {
                format!("{}_{k}", f.name)
            });
        }
    }
    for f in fields.iter().filter(|f| f.is_packed_colour()) {
        columns.extend(["red", "green", "blue"].map(String::from));
        if f.name == "rgba" {
            columns.push("alpha".into());
        }
    }
    Ok(Plan {
        xyz,
        extra,
        columns,
    })
}

/// Maximum expansion of LZF: a 3-byte back-reference copies at most 264 bytes.
const LZF_MAX_RATIO: usize = 88;

/// Decompresses LZF data (liblzf's format, as PCL writes it) into exactly
/// `out_len` bytes. Errors say what is inconsistent.
pub(crate) fn lzf_decompress(input: &[u8], out_len: usize) -> std::result::Result<Vec<u8>, String> {
    let mut out: Vec<u8> = Vec::with_capacity(out_len);
    let mut ip = 0usize;
    let byte = |i: usize| {
        input
            .get(i)
            .map(|&b| b as usize)
            .ok_or_else(|| format!("a back-reference at compressed byte {i} is cut off"))
    };
    while let Some(&ctrl) = input.get(ip) {
        let ctrl = ctrl as usize;
        ip += 1;
        if ctrl < 32 {
            let len = ctrl + 1;
            let lit = input.get(ip..ip + len).ok_or_else(|| {
                format!("a literal run of {len} bytes at compressed byte {ip} is cut off")
            })?;
            if out.len() + len > out_len {
                return Err(format!(
                    "the data decompresses to more than the {out_len} bytes declared"
                ));
            }
            out.extend_from_slice(lit);
            ip += len;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len += byte(ip)?;
                ip += 1;
            }
            let back = ((ctrl & 0x1f) << 8) + byte(ip)? + 1;
            ip += 1;
            len += 2;
            if back > out.len() {
                return Err(format!(
                    "a back-reference at compressed byte {} points {back} bytes back, before the start of the data",
                    ip - 2
                ));
            }
            if out.len() + len > out_len {
                return Err(format!(
                    "the data decompresses to more than the {out_len} bytes declared"
                ));
            }
            let start = out.len() - back;
            if back >= len {
                out.extend_from_within(start..start + len);
            } else {
                // overlapping copy: byte by byte (repeats the last `back` bytes)
                for k in start..start + len {
                    let b = out.get(k).copied().unwrap_or(0);
                    out.push(b);
                }
            }
        }
    }
    if out.len() != out_len {
        return Err(format!(
            "the data decompresses to {} bytes, but the header declares {out_len}",
            out.len()
        ));
    }
    Ok(out)
}

/// Reads a PCD file's bytes (`path` is for messages).
pub(crate) fn parse(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    let header = parse_header(path, bytes)?;
    let plan = plan(path, &header.fields)?;
    let mut table = match header.data {
        Data::Ascii => read_ascii(path, bytes, &header, plan)?,
        Data::Binary | Data::Compressed => read_binary(path, bytes, &header, plan)?,
    };
    table.warnings.splice(0..0, header.warnings);
    table.finish(options.non_finite)
}

fn read_binary(path: &Path, bytes: &[u8], h: &Header, plan: Plan) -> Result<PointTable> {
    let record: usize = h.fields.iter().map(Field::bytes).sum();
    let start = h.body;
    let body = bytes.get(start..).unwrap_or_default();
    let berr = |offset: usize, message: String| Error::Binary {
        path: path.to_path_buf(),
        offset: offset as u64,
        message,
    };
    let need = (h.points as u128) * (record as u128);
    let n = h.points as usize;
    // where each field's values are: row-major records, or (compressed) one
    // block per field
    let storage: Vec<u8>;
    let mut warnings = Vec::new();
    let mut columns_at: Vec<(&[u8], usize, usize)> = Vec::with_capacity(h.fields.len());
    let origin;
    if h.data == Data::Binary {
        if need > body.len() as u128 {
            return Err(berr(start, format!(
                "the header declares {} points of {record} bytes ({need} bytes from here), but only {} bytes follow: {} complete points; the file is truncated or POINTS is wrong",
                h.points,
                body.len(),
                body.len() / record.max(1)
            )));
        }
        let spare = body.len() as u128 - need;
        if record > 0 && spare >= record as u128 {
            warnings.push(format!(
                "{}: {spare} bytes ({} points of {record} bytes) follow the {} points the header declares; they were not read (is POINTS too small?)",
                path.display(),
                spare / record as u128,
                h.points
            ));
        }
        let mut off = 0;
        for f in &h.fields {
            columns_at.push((body, record, off));
            off += f.bytes();
        }
        origin = Origin::Records {
            start: start as u64,
            stride: record as u64,
        };
    } else {
        let word = |k: usize| {
            body.get(k..k + 4)
                .and_then(|b| b.try_into().ok())
                .map(u32::from_le_bytes)
                .ok_or_else(|| {
                    berr(
                        start + k,
                        "the file ends inside the binary_compressed size words; it is truncated"
                            .into(),
                    )
                })
        };
        let (csize, usize_) = (word(0)? as usize, word(4)? as usize);
        let Some(compressed) = body.get(8..8 + csize) else {
            return Err(berr(start, format!(
                "the header of the compressed data declares {csize} compressed bytes, but only {} follow; the file is truncated",
                body.len().saturating_sub(8)
            )));
        };
        if need != usize_ as u128 {
            return Err(berr(start + 4, format!(
                "the compressed data declares {usize_} bytes uncompressed, but {} points of {record} bytes need {need}; the file is damaged or POINTS is wrong",
                h.points
            )));
        }
        if usize_ > csize.saturating_mul(LZF_MAX_RATIO).saturating_add(64) {
            return Err(berr(start + 4, format!(
                "{csize} compressed bytes cannot hold {usize_} bytes of data (LZF expands at most {LZF_MAX_RATIO} times); the file is damaged"
            )));
        }
        storage = if usize_ == 0 {
            Vec::new()
        } else {
            lzf_decompress(compressed, usize_).map_err(|m| berr(start + 8, m))?
        };
        let mut off = 0;
        for f in &h.fields {
            let len = f.bytes() * n;
            columns_at.push((
                storage.get(off..off + len).unwrap_or_default(),
                f.bytes(),
                0,
            ));
            off += len;
        }
        origin = Origin::Indices;
    }
    let column = |(f, k): (usize, usize)| -> Column<'_> {
        let (data, stride, off) = columns_at.get(f).copied().unwrap_or((&[], 0, 0));
        let ty = h.fields.get(f).map_or(Scalar::U8, |f| f.ty);
        Column {
            data,
            stride,
            offset: off + k * ty.size(),
            ty,
            big: false,
        }
    };
    let [x, y, z] = plan.xyz;
    let points = decode_points(column(x), column(y), column(z), n);
    let mut extra = Vec::with_capacity(plan.columns.len().saturating_sub(3));
    let mut colours = Vec::new();
    for &(f, k) in &plan.extra {
        let mut c = column((f, k));
        let packed = h.fields.get(f).is_some_and(Field::is_packed_colour);
        if packed {
            c.ty = Scalar::U32;
        }
        let values = decode_column(c, n);
        if packed {
            colours.push((
                h.fields.get(f).is_some_and(|f| f.name == "rgba"),
                values.clone(),
            ));
        }
        extra.push(values);
    }
    for (alpha, packed) in colours {
        extra.extend(unpack(&packed, alpha));
    }
    Ok(PointTable {
        path: path.to_path_buf(),
        format: Format::Pcd,
        points,
        columns: plan.columns,
        extra,
        origin,
        file_index: None,
        dropped_non_finite: 0,
        warnings,
    })
}

/// red, green, blue (and alpha) columns from packed `0xAARRGGBB` values.
fn unpack(packed: &[f64], alpha: bool) -> Vec<Vec<f64>> {
    let shifts: &[u32] = if alpha { &[16, 8, 0, 24] } else { &[16, 8, 0] };
    shifts
        .iter()
        .map(|&s| {
            packed
                .iter()
                .map(|&v| ((v as u32 >> s) & 0xff) as f64)
                .collect()
        })
        .collect()
}

fn read_ascii(path: &Path, bytes: &[u8], h: &Header, plan: Plan) -> Result<PointTable> {
    let body = bytes.get(h.body..).unwrap_or_default();
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = std::str::from_utf8(body).map_err(|e| {
        let line = h.lines
            + 1
            + body
                .get(..e.valid_up_to())
                .unwrap_or_default()
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
        perr(
            line,
            "not UTF-8 text in DATA ascii; is the DATA line wrong?".into(),
        )
    })?;
    // index of each field's first value on a line
    let mut first = Vec::with_capacity(h.fields.len());
    let mut width = 0usize;
    for f in &h.fields {
        first.push(width);
        width += f.count;
    }
    let slot = |(f, k): (usize, usize)| first.get(f).copied().unwrap_or(0) + k;
    let cap = capacity(h.points, text.len() / (2 * width.max(1)) + 1);
    let mut points = Vec::with_capacity(cap);
    let mut extra = vec![Vec::with_capacity(cap); plan.extra.len()];
    let mut lines = Vec::with_capacity(cap);
    let mut colours: Vec<(bool, usize)> = Vec::new();
    for (c, &(f, _)) in plan.extra.iter().enumerate() {
        if let Some(field) = h.fields.get(f).filter(|f| f.is_packed_colour()) {
            colours.push((field.name == "rgba", c));
        }
    }
    // packed colours: PCL writes rgb as the unsigned integer; older files
    // wrote the float whose bits hold it
    let mut packed = vec![false; width];
    for (f, field) in h.fields.iter().enumerate() {
        if field.is_packed_colour() {
            if let Some(p) = packed.get_mut(slot((f, 0))) {
                *p = true;
            }
        }
    }
    let mut values = vec![0.0; width];
    let mut rows = split_lines(text)
        .map(|(i, l)| (h.lines + i, l))
        .filter(|(_, l)| !l.trim().is_empty());
    for r in 0..h.points {
        let Some((line_no, line)) = rows.next() else {
            return Err(perr(h.lines + split_lines(text).count(), format!(
                "the file ends after {r} of the {} points the header declares; it is truncated or POINTS is wrong",
                h.points
            )));
        };
        let mut count = 0;
        for (k, t) in line.split_ascii_whitespace().enumerate() {
            let Some(v) = values.get_mut(k) else {
                return Err(perr(
                    line_no,
                    format!("point {r} has more than the {width} values the fields declare"),
                ));
            };
            let colour = if packed.get(k) == Some(&true) {
                t.parse::<u32>()
                    .ok()
                    .or_else(|| t.parse::<f32>().ok().map(f32::to_bits))
            } else {
                None
            };
            *v = match colour {
                Some(c) => c as f64,
                None => t.parse::<f64>().map_err(|_| {
                    perr(
                        line_no,
                        format!("value {} ('{t}') of point {r} is not a number", k + 1),
                    )
                })?,
            };
            count += 1;
        }
        if count != width {
            return Err(perr(
                line_no,
                format!("point {r} has {count} values, but the fields declare {width}"),
            ));
        }
        let get = |s: usize| values.get(s).copied().unwrap_or(0.0);
        let [x, y, z] = plan.xyz;
        points.push(Point3::new(get(slot(x)), get(slot(y)), get(slot(z))));
        for (col, &fk) in extra.iter_mut().zip(&plan.extra) {
            col.push(get(slot(fk)));
        }
        lines.push(line_no);
    }
    let more = rows.count();
    let mut warnings = Vec::new();
    if more > 0 {
        warnings.push(format!(
            "{}: {more} more non-empty lines follow the {} points the header declares; they were not read (is POINTS too small?)",
            path.display(),
            h.points
        ));
    }
    let unpacked: Vec<Vec<f64>> = colours
        .iter()
        .flat_map(|&(alpha, c)| unpack(extra.get(c).map_or(&[][..], |v| v.as_slice()), alpha))
        .collect();
    extra.extend(unpacked);
    Ok(PointTable {
        path: path.to_path_buf(),
        format: Format::Pcd,
        points,
        columns: plan.columns,
        extra,
        origin: Origin::Lines(lines),
        file_index: None,
        dropped_non_finite: 0,
        warnings,
    })
}

#[cfg(test)]
#[path = "pcd_tests.rs"]
mod tests;
