//! PLY reader: ascii, binary_little_endian and binary_big_endian.
//!
//! The header is parsed line by line (errors name `file:line`). The `vertex`
//! element gives the points: x, y, z (any scalar type) and every other scalar
//! property as an extra column by name (nx, red, label, u, ...); list
//! properties of the vertex element are skipped. Elements before the vertex
//! element are skipped (in binary files by reading their list lengths),
//! elements after it are not read, except a `face` element with a
//! `vertex_indices` list: when the vertices carry no normals, area-weighted
//! vertex normals are taken from its triangles (`ply_faces.rs`). Binary vertices without list properties
//! are fixed-size records, decoded column by column with a byte-offset plan
//! (see `binary.rs`); every size is checked against the body before anything
//! is allocated, so a header claiming 10^12 vertices is an error, not an
//! allocation.

use std::path::Path;

use scanfit::Point3;

#[path = "ply_faces.rs"]
mod faces;

#[path = "ply_chunks.rs"]
pub(crate) mod chunks;

#[path = "ply_direct.rs"]
pub(crate) mod direct;

use crate::binary::{decode_column, decode_points, Column, Scalar};
use crate::mesh::attach_normals;
use crate::table::{capacity, split_lines, Format, Origin, PointTable, ReadOptions, MAX_COLUMNS};
use crate::{Error, Result};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    line: usize,
}

impl Element {
    /// Bytes per record when every property is a scalar.
    fn fixed_stride(&self) -> Option<usize> {
        self.props.iter().try_fold(0usize, |s, p| match p.kind {
            Kind::Scalar(t) => Some(s + t.size()),
            Kind::List { .. } => None,
        })
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// byte offset of the body
    body: usize,
    /// number of header lines (the body's first line is `lines + 1`)
    lines: usize,
}

const TYPES: &str = "char, uchar, short, ushort, int, uint, float, double (or int8, uint8, int16, uint16, int32, uint32, float32, float64)";

fn scalar_type(name: &str) -> Option<Scalar> {
    Some(match name {
        "char" | "int8" => Scalar::I8,
        "uchar" | "uint8" => Scalar::U8,
        "short" | "int16" => Scalar::I16,
        "ushort" | "uint16" => Scalar::U16,
        "int" | "int32" => Scalar::I32,
        "uint" | "uint32" => Scalar::U32,
        "float" | "float32" => Scalar::F32,
        "double" | "float64" => Scalar::F64,
        _ => return None,
    })
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    // header lines end with LF (or CRLF); a header whose first line ends
    // with a lone CR (classic Mac) uses CR throughout
    let eol = if bytes.starts_with(b"ply\r") && bytes.get(4) != Some(&b'\n') {
        b'\r'
    } else {
        b'\n'
    };
    loop {
        let Some(rest) = bytes.get(pos..).filter(|r| !r.is_empty()) else {
            return Err(perr(
                line_no,
                "the header has no 'end_header' line: the file is truncated or not a PLY file"
                    .into(),
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
                "the header line is not UTF-8 text; the header is damaged or this is not a PLY file"
                    .into(),
            ));
        };
        let text = text.trim_end_matches('\r');
        if line_no == 1 {
            if text.trim() != "ply" {
                return Err(perr(
                    1,
                    "not a PLY file: the first line must be 'ply' (bad magic)".into(),
                ));
            }
            continue;
        }
        let mut tok = text.split_ascii_whitespace();
        let Some(key) = tok.next() else {
            continue;
        };
        match key {
            "comment" | "obj_info" => {}
            "format" => {
                encoding = Some(match tok.next() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    other => {
                        return Err(perr(
                            line_no,
                            format!(
                                "unknown format '{}'; PLY formats are ascii, binary_little_endian and binary_big_endian",
                                other.unwrap_or("")
                            ),
                        ))
                    }
                });
            }
            "element" => {
                let (Some(name), Some(count)) = (tok.next(), tok.next()) else {
                    return Err(perr(
                        line_no,
                        "an element line needs a name and a count: 'element vertex 100'".into(),
                    ));
                };
                let count = count.parse::<u64>().map_err(|_| {
                    perr(
                        line_no,
                        format!("element count '{count}' is not a non-negative integer"),
                    )
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: line_no,
                });
            }
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(perr(
                        line_no,
                        "a property line before any element line; declare the element first"
                            .into(),
                    ));
                };
                let words: Vec<&str> = tok.collect();
                let ty = |name: &str| {
                    scalar_type(name).ok_or_else(|| {
                        perr(
                            line_no,
                            format!("unknown property type '{name}'; PLY types are {TYPES}"),
                        )
                    })
                };
                let prop = match words.as_slice() {
                    ["list", count, item, name] => {
                        let count = ty(count)?;
                        if !count.is_integer() {
                            return Err(perr(
                                line_no,
                                format!("list '{name}' has a floating-point count type; use an integer type such as uchar or int"),
                            ));
                        }
                        Property {
                            name: name.to_string(),
                            kind: Kind::List {
                                count,
                                item: ty(item)?,
                            },
                        }
                    }
                    [t, name] if *t != "list" => Property {
                        name: name.to_string(),
                        kind: Kind::Scalar(ty(t)?),
                    },
                    _ => {
                        return Err(perr(
                            line_no,
                            format!("malformed property line '{text}'; expected 'property TYPE NAME' or 'property list COUNT_TYPE ITEM_TYPE NAME'"),
                        ))
                    }
                };
                element.props.push(prop);
            }
            "end_header" => break,
            _ => {
                return Err(perr(
                    line_no,
                    format!("unknown header line '{text}'; expected format, element, property, comment, obj_info or end_header"),
                ))
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err(perr(
            line_no,
            "the header has no format line; add 'format ascii 1.0' or 'format binary_little_endian 1.0'"
                .into(),
        ));
    };
    Ok(Header {
        encoding,
        elements,
        body: pos,
        lines: line_no,
    })
}

/// The plan for the vertex element: which property gives x, y, z and which
/// go to extra columns.
#[derive(Clone)]
struct Plan {
    xyz: [usize; 3],
    extra: Vec<usize>,
    columns: Vec<String>,
}

fn plan(path: &Path, v: &Element) -> Result<Plan> {
    if v.props.len() > MAX_COLUMNS {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: v.line,
            message: format!(
                "the vertex element declares {} properties; a point file may have at most {MAX_COLUMNS}",
                v.props.len()
            ),
        });
    }
    let find = |axis: &str| {
        v.props.iter().position(|p| p.name == axis).or_else(|| {
            v.props
                .iter()
                .position(|p| p.name.eq_ignore_ascii_case(axis))
        })
    };
    let mut xyz = [0usize; 3];
    for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
        let Some(i) = find(axis) else {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: v.line,
                message: format!(
                    "the vertex element has no property '{axis}' (its properties: {}); a point needs x, y and z",
                    v.props.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
                ),
            });
        };
        if matches!(v.props.get(i).map(|p| p.kind), Some(Kind::List { .. })) {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: v.line,
                message: format!("vertex property '{axis}' is a list; it must be a scalar"),
            });
        }
        xyz[k] = i;
    }
    let extra: Vec<usize> = (0..v.props.len())
        .filter(|i| !xyz.contains(i))
        .filter(|&i| matches!(v.props.get(i).map(|p| p.kind), Some(Kind::Scalar(_))))
        .collect();
    let mut columns: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
    columns.extend(
        extra
            .iter()
            .filter_map(|&i| v.props.get(i).map(|p| p.name.clone())),
    );
    Ok(Plan {
        xyz,
        extra,
        columns,
    })
}

/// Reads a PLY file's bytes (`path` is for messages).
pub(crate) fn parse(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    let header = parse_header(path, bytes)?;
    let Some(vi) = header.elements.iter().position(|e| e.name == "vertex") else {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "no 'vertex' element in the header (elements: {}); a point file needs 'element vertex N'",
                header.elements.iter().map(|e| e.name.as_str()).collect::<Vec<_>>().join(", ")
            ),
        });
    };
    let vertex = header
        .elements
        .get(vi)
        .cloned()
        .ok_or_else(|| Error::Invalid {
            path: path.to_path_buf(),
            message: "no vertex element".into(),
        })?;
    let plan = plan(path, &vertex)?;
    let before = header.elements.get(..vi).unwrap_or_default();
    let after = header.elements.get(vi + 1..).unwrap_or_default();
    let mut table = match header.encoding {
        Encoding::Ascii => read_ascii(path, bytes, &header, before, &vertex, plan)?,
        Encoding::Little | Encoding::Big => {
            let big = header.encoding == Encoding::Big;
            let mut pos = header.body;
            for e in before {
                pos = skip_binary(path, bytes, pos, e, big)?;
            }
            let mut table = read_binary(path, bytes, pos, &vertex, plan, big)?;
            // the elements after the vertices (faces, ...) are not read, but
            // a header whose counts disagree with the data is reported
            let mut end = pos.saturating_add(
                vertex
                    .fixed_stride()
                    .map_or(0, |s| s.saturating_mul(table.points.len())),
            );
            if let Origin::Offsets(_) = table.origin {
                end = skip_binary(path, bytes, pos, &vertex, big).unwrap_or(end);
            }
            for e in after {
                match skip_binary(path, bytes, end, e, big) {
                    Ok(next) => end = next,
                    Err(err) => {
                        table.warnings.push(format!(
                            "{err} (the '{}' element is not needed for the points, which were read)",
                            e.name
                        ));
                        end = bytes.len();
                        break;
                    }
                }
            }
            let spare = bytes.len().saturating_sub(end);
            let stride = vertex.fixed_stride().unwrap_or(1).max(1);
            let warning = spare_warning(path, spare as u128, stride, vertex.count);
            table.warnings.extend(warning);
            table
        }
    };
    if header.encoding == Encoding::Ascii {
        ascii_trailing(path, bytes, &header, &mut table, after);
    }
    if let Some(face) = faces::face_element(&header) {
        match faces::read(path, bytes, &header, face, table.points.len()) {
            Ok(triangles) => attach_normals(&mut table, &triangles),
            Err(err) => {
                // (a truncated element after the vertices is reported once)
                if !table
                    .warnings
                    .iter()
                    .any(|w| w.contains("the 'face' element"))
                {
                    table.warnings.push(format!(
                        "{err} (the 'face' element is not needed for the points, which were read; no normals were taken from it)"
                    ));
                }
            }
        }
    }
    table.finish(options.non_finite)
}

/// The warning for `spare` bytes after the last element the header
/// declares, when they are at least a vertex record (`stride` bytes).
fn spare_warning(path: &Path, spare: u128, stride: usize, count: u64) -> Option<String> {
    (spare >= stride as u128).then(|| {
        format!(
            "{}: {spare} bytes follow the last element the header declares; they were not read (is the vertex count {count} too small?)",
            path.display()
        )
    })
}

fn truncated(path: &Path, offset: usize, message: String) -> Error {
    Error::Binary {
        path: path.to_path_buf(),
        offset: offset as u64,
        message,
    }
}

/// Reads a list length at `pos` (a non-negative integer).
fn list_len(
    path: &Path,
    bytes: &[u8],
    pos: usize,
    ty: Scalar,
    big: bool,
    what: &str,
) -> Result<usize> {
    let Some(n) = bytes.get(pos..).and_then(|b| ty.read(b, big)) else {
        return Err(truncated(
            path,
            pos,
            format!("the file ends inside {what}; it is truncated"),
        ));
    };
    if n < 0.0 {
        return Err(truncated(
            path,
            pos,
            format!("{what} has a negative list length {n}"),
        ));
    }
    Ok(n as usize)
}

/// Skips one binary element from `pos`, returning where the next begins.
fn skip_binary(path: &Path, bytes: &[u8], pos: usize, e: &Element, big: bool) -> Result<usize> {
    let len = bytes.len();
    if let Some(stride) = e.fixed_stride() {
        let need = (e.count as u128) * (stride as u128);
        let avail = len.saturating_sub(pos);
        if need > avail as u128 {
            return Err(truncated(
                path,
                pos,
                format!(
                    "element '{}' declares {} records of {stride} bytes ({need} bytes), but only {avail} bytes follow; the file is truncated or the header's count is wrong",
                    e.name, e.count
                ),
            ));
        }
        return Ok(pos + need as usize);
    }
    // records with lists: each one is at least one byte (its first list
    // length), so this loop ends within the file's size
    let mut p = pos;
    for r in 0..e.count {
        for prop in &e.props {
            match prop.kind {
                Kind::Scalar(t) => p = p.saturating_add(t.size()),
                Kind::List { count, item } => {
                    let what = format!("list '{}' of {} {r}", prop.name, e.name);
                    let n = list_len(path, bytes, p, count, big, &what)?;
                    p = p
                        .saturating_add(count.size())
                        .saturating_add(n.saturating_mul(item.size()));
                }
            }
            if p > len {
                return Err(truncated(
                    path,
                    pos,
                    format!(
                        "element '{}' declares {} records, but the file ends inside record {r}; the file is truncated or the header's count is wrong",
                        e.name, e.count
                    ),
                ));
            }
        }
    }
    Ok(p)
}

fn read_binary(
    path: &Path,
    bytes: &[u8],
    start: usize,
    v: &Element,
    plan: Plan,
    big: bool,
) -> Result<PointTable> {
    let body = bytes.get(start..).unwrap_or_default();
    let Some(stride) = v.fixed_stride() else {
        return read_binary_lists(path, bytes, start, v, plan, big);
    };
    let need = (v.count as u128) * (stride as u128);
    if need > body.len() as u128 {
        return Err(truncated(
            path,
            start,
            format!(
                "the header declares {} vertices of {stride} bytes ({need} bytes from here), but only {} bytes follow: {} complete vertices; the file is truncated or its vertex count is wrong",
                v.count,
                body.len(),
                body.len() / stride.max(1)
            ),
        ));
    }
    let n = v.count as usize;
    let mut offsets = Vec::with_capacity(v.props.len());
    let mut o = 0usize;
    for p in &v.props {
        offsets.push(o);
        if let Kind::Scalar(t) = p.kind {
            o += t.size();
        }
    }
    let column = |i: usize| -> Column<'_> {
        let ty = match v.props.get(i).map(|p| p.kind) {
            Some(Kind::Scalar(t)) => t,
            _ => Scalar::U8,
        };
        Column {
            data: body,
            stride,
            offset: offsets.get(i).copied().unwrap_or(0),
            ty,
            big,
        }
    };
    let [xi, yi, zi] = plan.xyz;
    let points = decode_points(column(xi), column(yi), column(zi), n);
    let extra = plan
        .extra
        .iter()
        .map(|&i| decode_column(column(i), n))
        .collect();
    Ok(records_table(
        path,
        points,
        plan.columns,
        extra,
        start,
        stride,
    ))
}

/// The table of fixed-size vertex records from byte `start`, `stride`
/// bytes each (the general reader's and the direct one's).
fn records_table(
    path: &Path,
    points: Vec<Point3>,
    columns: Vec<String>,
    extra: Vec<Vec<f64>>,
    start: usize,
    stride: usize,
) -> PointTable {
    PointTable {
        path: path.to_path_buf(),
        format: Format::Ply,
        points,
        columns,
        extra,
        origin: Origin::Records {
            start: start as u64,
            stride: stride as u64,
        },
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    }
}

/// Binary vertices with list properties: variable-size records, read one by
/// one (each at least one byte, so the loop ends within the file's size).
fn read_binary_lists(
    path: &Path,
    bytes: &[u8],
    start: usize,
    v: &Element,
    plan: Plan,
    big: bool,
) -> Result<PointTable> {
    let cap = capacity(v.count, bytes.len().saturating_sub(start));
    let mut points = Vec::with_capacity(cap);
    let mut extra = vec![Vec::with_capacity(cap); plan.extra.len()];
    let mut offsets = Vec::with_capacity(cap);
    let mut values = vec![0.0; v.props.len()];
    let mut p = start;
    for r in 0..v.count {
        offsets.push(p as u64);
        for (k, prop) in v.props.iter().enumerate() {
            match prop.kind {
                Kind::Scalar(t) => {
                    let Some(x) = bytes.get(p..).and_then(|b| t.read(b, big)) else {
                        return Err(truncated(path, p, format!(
                            "the file ends inside vertex {r} of {}; it is truncated or its vertex count is wrong",
                            v.count
                        )));
                    };
                    if let Some(slot) = values.get_mut(k) {
                        *slot = x;
                    }
                    p += t.size();
                }
                Kind::List { count, item } => {
                    let what = format!("list '{}' of vertex {r}", prop.name);
                    let n = list_len(path, bytes, p, count, big, &what)?;
                    p = p
                        .saturating_add(count.size())
                        .saturating_add(n.saturating_mul(item.size()));
                    if p > bytes.len() {
                        return Err(truncated(path, p.min(bytes.len()), format!(
                            "the file ends inside {what} of {} vertices; it is truncated or its vertex count is wrong",
                            v.count
                        )));
                    }
                }
            }
        }
        let get = |i: usize| values.get(i).copied().unwrap_or(0.0);
        let [xi, yi, zi] = plan.xyz;
        points.push(Point3::new(get(xi), get(yi), get(zi)));
        for (col, &i) in extra.iter_mut().zip(&plan.extra) {
            col.push(get(i));
        }
    }
    Ok(PointTable {
        path: path.to_path_buf(),
        format: Format::Ply,
        points,
        columns: plan.columns,
        extra,
        origin: Origin::Offsets(offsets),
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    })
}

/// An ascii file with more records than its header declares: the
/// non-empty lines after the vertices and the elements that follow them are
/// reported as a warning (they are not read).
fn ascii_trailing(
    path: &Path,
    bytes: &[u8],
    header: &Header,
    table: &mut PointTable,
    after: &[Element],
) {
    let Some(text) = bytes
        .get(header.body..)
        .and_then(|b| std::str::from_utf8(b).ok())
    else {
        return;
    };
    let last_vertex = match &table.origin {
        Origin::Lines(l) => l.last().copied().unwrap_or(header.lines),
        _ => return,
    };
    let expected: u64 = after
        .iter()
        .filter(|e| !e.props.is_empty())
        .map(|e| e.count)
        .fold(0u64, u64::saturating_add);
    let later = split_lines(text)
        .filter(|(i, l)| header.lines + i > last_vertex && !l.trim().is_empty())
        .count() as u64;
    if later > expected {
        table.warnings.push(format!(
            "{}: {} more non-empty lines follow the records the header declares; they were not read (is the vertex count {} too small?)",
            path.display(),
            later - expected,
            table.points.len()
        ));
    }
}

fn read_ascii(
    path: &Path,
    bytes: &[u8],
    header: &Header,
    before: &[Element],
    v: &Element,
    plan: Plan,
) -> Result<PointTable> {
    let body = bytes.get(header.body..).unwrap_or_default();
    let text = std::str::from_utf8(body).map_err(|e| {
        let line = header.lines
            + 1
            + body
                .get(..e.valid_up_to())
                .unwrap_or_default()
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
        Error::Parse {
            path: path.to_path_buf(),
            line,
            message: "not UTF-8 text in an ascii PLY body; is the format line wrong?".into(),
        }
    })?;
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    // non-empty lines with their 1-based numbers
    let mut lines = split_lines(text)
        .map(|(i, l)| (header.lines + i, l))
        .filter(|(_, l)| !l.trim().is_empty());
    let last_line = header.lines + split_lines(text).count();
    for e in before {
        if e.props.is_empty() {
            continue;
        }
        for r in 0..e.count {
            if lines.next().is_none() {
                return Err(perr(last_line, format!(
                    "the file ends after {r} of the {} '{}' records the header declares; it is truncated or the count is wrong",
                    e.count, e.name
                )));
            }
        }
    }
    let cap = capacity(v.count, text.len() / (2 * v.props.len().max(1)) + 1);
    let mut points = Vec::with_capacity(cap);
    let mut extra = vec![Vec::with_capacity(cap); plan.extra.len()];
    let mut line_numbers = Vec::with_capacity(cap);
    let mut values = vec![0.0; v.props.len()];
    for r in 0..v.count {
        let Some((line_no, line)) = lines.next() else {
            return Err(perr(last_line, format!(
                "the file ends after {r} of the {} vertices the header declares; it is truncated or the vertex count is wrong",
                v.count
            )));
        };
        let mut tok = line.split_ascii_whitespace();
        let mut number = |k: usize| -> Result<f64> {
            let Some(t) = tok.next() else {
                return Err(perr(
                    line_no,
                    format!(
                        "vertex {r} has too few values: property {} ('{}') is missing",
                        k + 1,
                        v.props.get(k).map_or("", |p| p.name.as_str())
                    ),
                ));
            };
            t.parse::<f64>().map_err(|_| {
                perr(
                    line_no,
                    format!(
                        "value '{t}' of property '{}' of vertex {r} is not a number",
                        v.props.get(k).map_or("", |p| p.name.as_str())
                    ),
                )
            })
        };
        for (k, prop) in v.props.iter().enumerate() {
            match prop.kind {
                Kind::Scalar(_) => {
                    let x = number(k)?;
                    if let Some(slot) = values.get_mut(k) {
                        *slot = x;
                    }
                }
                Kind::List { .. } => {
                    let n = number(k)?;
                    if !(n >= 0.0 && n.fract() == 0.0) {
                        return Err(perr(line_no, format!(
                            "list '{}' of vertex {r} has length {n}; a length must be a non-negative integer",
                            prop.name
                        )));
                    }
                    for _ in 0..n as u64 {
                        number(k)?;
                    }
                }
            }
        }
        if tok.next().is_some() {
            return Err(perr(
                line_no,
                format!(
                    "vertex {r} has more values than the {} properties the header declares",
                    v.props.len()
                ),
            ));
        }
        let get = |i: usize| values.get(i).copied().unwrap_or(0.0);
        let [xi, yi, zi] = plan.xyz;
        points.push(Point3::new(get(xi), get(yi), get(zi)));
        for (col, &i) in extra.iter_mut().zip(&plan.extra) {
            col.push(get(i));
        }
        line_numbers.push(line_no);
    }
    Ok(PointTable {
        path: path.to_path_buf(),
        format: Format::Ply,
        points,
        columns: plan.columns,
        extra,
        origin: Origin::Lines(line_numbers),
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    /// Tests return errors instead of unwrapping them.
    type TestResult = std::result::Result<(), Box<dyn std::error::Error>>;
    use super::*;
    use crate::table::NonFinite;

    fn read(bytes: &[u8]) -> Result<PointTable> {
        parse(Path::new("t.ply"), bytes, &ReadOptions::default())
    }

    fn binary(big: bool, junk: &str) -> Vec<u8> {
        let enc = if big { "big" } else { "little" };
        let mut b = format!(
            "ply\nformat binary_{enc}_endian 1.0\ncomment c\nelement edge 2\nproperty list uchar int ids\nproperty short w\nelement vertex 2\nproperty uchar label\nproperty float x\nproperty list ushort {junk} junk\nproperty double y\nproperty float z\nend_header\n"
        )
        .into_bytes();
        // two edges: [0, 1] w=5 and [] w=-1
        b.push(2);
        for v in [0i32, 1] {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
        b.extend(if big {
            5i16.to_be_bytes()
        } else {
            5i16.to_le_bytes()
        });
        b.push(0);
        b.extend(if big {
            (-1i16).to_be_bytes()
        } else {
            (-1i16).to_le_bytes()
        });
        // vertices (uint64 is not a PLY type: the header above must be rejected)
        b
    }

    #[test]
    fn header_errors_name_the_line() {
        let e = read(&binary(false, "uint64")).unwrap_err().to_string();
        assert!(
            e.starts_with("t.ply:10: unknown property type 'uint64'"),
            "{e}"
        );
        let e = read(b"plx\nformat ascii 1.0\n").unwrap_err().to_string();
        assert!(e.contains("bad magic"), "{e}");
        // a blank first line is no magic either
        let e = read(b"\nformat ascii 1.0\nelement vertex 0\nend_header\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad magic"), "{e}");
        let e = read(b"ply\nformat utf8 1.0\nend_header\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.ply:2: unknown format 'utf8'"), "{e}");
        let e = read(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.ply:3: the vertex element has no property 'z'"),
            "{e}"
        );
        let e = read(b"ply\nformat ascii 1.0\nelement vertex 1\nfoo\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.ply:4: unknown header line 'foo'"), "{e}");
        let e = read(b"ply\nformat ascii 1.0\nelement vertex 1\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no 'end_header'"), "{e}");
        let e = read(b"ply\ncomment \xff\xfe\nend_header\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.ply:2: the header line is not UTF-8"),
            "{e}"
        );
    }

    #[test]
    fn binary_with_lists_before_and_in_the_vertex_element() -> TestResult {
        for big in [false, true] {
            let mut b = binary(big, "int8");
            let put = |b: &mut Vec<u8>, label: u8, x: f32, junk: &[i8], y: f64, z: f32| {
                b.push(label);
                b.extend(if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                });
                let n = junk.len() as u16;
                b.extend(if big {
                    n.to_be_bytes()
                } else {
                    n.to_le_bytes()
                });
                b.extend(junk.iter().map(|&j| j as u8));
                b.extend(if big {
                    y.to_be_bytes()
                } else {
                    y.to_le_bytes()
                });
                b.extend(if big {
                    z.to_be_bytes()
                } else {
                    z.to_le_bytes()
                });
            };
            put(&mut b, 7, 1.5, &[1, 2, 3], -2.25, 1e-3);
            put(&mut b, 255, -0.5, &[], 1e300, 3.0);
            let t = read(&b)?;
            assert_eq!(
                t.points,
                vec![
                    Point3::new(1.5, -2.25, 1e-3f32 as f64),
                    Point3::new(-0.5, 1e300, 3.0)
                ]
            );
            assert_eq!(t.columns, vec!["x", "y", "z", "label"]);
            assert_eq!(t.column("label").ok_or("no such column")?, &[7.0, 255.0]);
            // vertex 0 is 22 bytes, vertex 1 is 19
            let start = b.len() - 22 - 19;
            assert_eq!(
                t.locate(1),
                format!("t.ply: byte offset {} (vertex 1)", start + 22)
            );
            // every truncation of the body is an error, never a panic
            let body = b
                .windows(11)
                .position(|w| w == b"end_header\n")
                .ok_or("no end_header")?
                + 11;
            for cut in 0..b.len() {
                let e = read(&b[..cut]).unwrap_err().to_string();
                assert!(cut < body || e.contains("truncated"), "{cut}: {e}");
            }
        }
        Ok(())
    }

    #[test]
    fn binary_fixed_records_and_counts() -> TestResult {
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nend_header\n".to_vec();
        let h = b.len();
        for i in 0..3 {
            for v in [i as f32, 2.0 * i as f32, f32::NAN] {
                b.extend(if i == 1 || !v.is_nan() {
                    v.to_le_bytes()
                } else {
                    0.5f32.to_le_bytes()
                });
            }
            b.push(10 * i as u8);
        }
        let e = read(&b).unwrap_err().to_string();
        assert_eq!(
            e,
            format!("t.ply: byte offset {}: vertex 1: z is NaN; every coordinate must be a finite number (fix the file, or read with ReadOptions {{ non_finite: NonFinite::Drop, .. }} to leave such points out)", h + 13)
        );
        let opts = ReadOptions {
            non_finite: NonFinite::Drop,
            ..Default::default()
        };
        let t = parse(Path::new("t.ply"), &b, &opts)?;
        assert_eq!(
            t.points,
            vec![Point3::new(0., 0., 0.5), Point3::new(2., 4., 0.5)]
        );
        assert_eq!(t.column("red").ok_or("no such column")?, &[0.0, 20.0]);
        assert_eq!(t.dropped_non_finite, 1);
        assert_eq!(
            t.locate(1),
            format!("t.ply: byte offset {} (vertex 2)", h + 26)
        );
        // a header claiming 10^12 vertices is an error before any allocation
        let huge = String::from_utf8_lossy(&b)
            .replace("vertex 3", "vertex 1000000000000")
            .into_bytes();
        let e = read(&huge).unwrap_err().to_string();
        assert!(
            e.contains("declares 1000000000000 vertices of 13 bytes")
                && e.contains("3 complete vertices"),
            "{e}"
        );
        let e = read(&b[..h + 30]).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!(
                "t.ply: byte offset {h}: the header declares 3 vertices"
            )) && e.contains("2 complete"),
            "{e}"
        );
        Ok(())
    }

    #[test]
    fn ascii_with_faces_before_and_after() -> TestResult {
        let text = "ply\r\nformat ascii 1.0\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nelement vertex 2\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\nproperty list uchar float tex\r\nproperty int label\r\nelement edge 1\r\nproperty int a\r\nend_header\r\n3 0 1 1\r\n1 2 3 2 0.5 0.5 -4\r\n\r\n-1e-5 0.1 7 0 9\r\n0 1\r\n";
        let t = read(text.as_bytes())?;
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(-1e-5, 0.1, 7.)]
        );
        assert_eq!(t.column("label").ok_or("no such column")?, &[-4.0, 9.0]);
        assert_eq!(t.locate(1), "t.ply:17");
        let e = read(text.replace("0.1 7", "0.1 x7").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.ply:17: value 'x7' of property 'z' of vertex 1"),
            "{e}"
        );
        let e = read(
            text.replace("element vertex 2", "element vertex 1000000000000")
                .as_bytes(),
        )
        .unwrap_err()
        .to_string();
        // the edge record is taken for a vertex
        assert!(
            e.starts_with("t.ply:18: vertex 2 has too few values"),
            "{e}"
        );
        let e = read(
            text.replace("element vertex 2", "element vertex 1000000000000")
                .replace("0 1\r\n", "")
                .as_bytes(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("t.ply:17: the file ends after 2 of the 1000000000000 vertices"),
            "{e}"
        );
        let e = read(text.replace("0.5 -4", "0.5 -4 8").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.ply:15"), "{e}");
        Ok(())
    }

    #[test]
    fn every_line_ending_in_ascii_files() -> TestResult {
        for eol in ["\n", "\r\n", "\r"] {
            let text = [
                "ply",
                "format ascii 1.0",
                "element vertex 2",
                "property float x",
                "property float y",
                "property float z",
                "end_header",
                "1 2 3",
                "4 5 6",
            ]
            .join(eol)
                + eol;
            let t = read(text.as_bytes())?;
            assert_eq!(
                t.points,
                vec![Point3::new(1., 2., 3.), Point3::new(4., 5., 6.)],
                "{eol:?}"
            );
            assert_eq!(t.locate(1), "t.ply:9", "{eol:?}");
            assert!(t.warnings.is_empty(), "{eol:?}: {:?}", t.warnings);
        }
        Ok(())
    }

    #[test]
    fn counts_smaller_than_the_data_are_warnings() -> TestResult {
        let head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
        // ascii: a third vertex line the header does not declare
        let t = read(format!("{head}end_header\n1 2 3\n4 5 6\n7 8 9\n").as_bytes())?;
        assert_eq!(t.points.len(), 2);
        assert_eq!(
            t.warnings,
            ["t.ply: 1 more non-empty lines follow the records the header declares; they were not read (is the vertex count 2 too small?)"]
        );
        // with a face element after the vertices, its lines are expected
        let faces = format!(
            "{head}element face 1\nproperty list uchar int vertex_indices\nend_header\n1 2 3\n4 5 6\n3 0 1 0\n"
        );
        // (its one face is degenerate: no normals, and a warning that says why)
        let w = read(faces.as_bytes())?.warnings;
        assert!(
            w.len() == 1 && w[0].contains("2 of 2 vertices lie on no triangle of non-zero area"),
            "{w:?}"
        );
        // binary: a third record after the declared two
        let mut b = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
            .as_bytes()
            .to_vec();
        for v in 0..9 {
            b.extend((v as f32).to_le_bytes());
        }
        let t = read(&b)?;
        assert_eq!(t.points.len(), 2);
        assert_eq!(
            t.warnings,
            ["t.ply: 12 bytes follow the last element the header declares; they were not read (is the vertex count 2 too small?)"]
        );
        // a declared face element that the file does not hold: a warning
        let mut f = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n"
            .as_bytes()
            .to_vec();
        for v in 0..6 {
            f.extend((v as f32).to_le_bytes());
        }
        let t = read(&f)?;
        assert_eq!(t.points.len(), 2);
        assert!(
            t.warnings.len() == 1
                && t.warnings[0].contains("the file ends inside list 'vertex_indices' of face 0"),
            "{:?}",
            t.warnings
        );
        // more declared than present stays an error
        let e = read(format!("{head}end_header\n1 2 3\n").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("the file ends after 1 of the 2 vertices"), "{e}");
        Ok(())
    }

    #[test]
    fn too_many_properties_are_refused() {
        let mut h = String::from("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n");
        for k in 0..MAX_COLUMNS {
            h.push_str(&format!("property uchar p{k}\n"));
        }
        h.push_str("end_header\n");
        let e = read(h.as_bytes()).unwrap_err().to_string();
        assert!(
            e.contains(
                "the vertex element declares 1027 properties; a point file may have at most 1024"
            ),
            "{e}"
        );
    }
}
