//! The `face` element of a PLY file: its `vertex_indices` (or
//! `vertex_index`) lists as triangles (polygons fanned), from which the
//! vertex normals are taken when the vertices carry none (`mesh.rs`). The
//! faces are not needed for the points: a face element that is truncated or
//! names a vertex that does not exist is a warning, and no normals are taken.

use std::path::Path;

use super::{list_len, skip_binary, truncated, Element, Encoding, Header, Kind};
use crate::mesh::{fan, Triangle};
use crate::table::split_lines;
use crate::{Error, Result};

/// The index of the face element and of its vertex list property, if the
/// file has one.
pub(super) fn face_element(header: &Header) -> Option<(usize, usize)> {
    header.elements.iter().enumerate().find_map(|(i, e)| {
        let list = e.props.iter().position(|p| {
            matches!(p.kind, Kind::List { .. })
                && (p.name == "vertex_indices" || p.name == "vertex_index")
        })?;
        (e.name == "face").then_some((i, list))
    })
}

/// The triangles of the face element `fi` (list property `li`) over
/// `vertices` points.
pub(super) fn read(
    path: &Path,
    bytes: &[u8],
    header: &Header,
    (fi, li): (usize, usize),
    vertices: usize,
) -> Result<Vec<Triangle>> {
    let elements = &header.elements;
    let Some(face) = elements.get(fi) else {
        return Ok(Vec::new());
    };
    match header.encoding {
        Encoding::Ascii => ascii(path, bytes, header, fi, li, vertices),
        Encoding::Little | Encoding::Big => {
            let big = header.encoding == Encoding::Big;
            let mut pos = header.body;
            for e in elements.get(..fi).unwrap_or_default() {
                pos = skip_binary(path, bytes, pos, e, big)?;
            }
            binary(path, bytes, pos, face, li, big, vertices)
        }
    }
}

/// Checks the corner indices of face `r` and appends its triangles.
fn add(
    ring: &[f64],
    r: u64,
    vertices: usize,
    out: &mut Vec<Triangle>,
) -> std::result::Result<(), String> {
    let mut idx = Vec::with_capacity(ring.len());
    for &v in ring {
        if !(v >= 0.0 && v.fract() == 0.0 && v < vertices as f64) {
            return Err(format!(
                "face {r} names vertex {v}, but the file has {vertices} vertices (0 to {})",
                vertices.saturating_sub(1)
            ));
        }
        idx.push(v as u32);
    }
    if idx.len() >= 3 {
        fan(&idx, out);
    }
    Ok(())
}

fn binary(
    path: &Path,
    bytes: &[u8],
    start: usize,
    e: &Element,
    li: usize,
    big: bool,
    vertices: usize,
) -> Result<Vec<Triangle>> {
    let mut out = Vec::new();
    let mut ring = Vec::new();
    let mut p = start;
    for r in 0..e.count {
        for (k, prop) in e.props.iter().enumerate() {
            match prop.kind {
                Kind::Scalar(t) => p = p.saturating_add(t.size()),
                Kind::List { count, item } => {
                    let what = format!("list '{}' of face {r}", prop.name);
                    let n = list_len(path, bytes, p, count, big, &what)?;
                    let at = p;
                    p = p.saturating_add(count.size());
                    let end = p.saturating_add(n.saturating_mul(item.size()));
                    if end > bytes.len() {
                        return Err(truncated(
                            path,
                            at,
                            format!("the file ends inside {what}; it is truncated or the face count is wrong"),
                        ));
                    }
                    if k == li {
                        ring.clear();
                        for j in 0..n {
                            let o = p + j * item.size();
                            ring.push(
                                bytes
                                    .get(o..)
                                    .and_then(|b| item.read(b, big))
                                    .unwrap_or(-1.0),
                            );
                        }
                        add(&ring, r, vertices, &mut out).map_err(|m| truncated(path, at, m))?;
                    }
                    p = end;
                }
            }
        }
        if p > bytes.len() {
            return Err(truncated(
                path,
                bytes.len(),
                format!("the file ends inside face {r} of {}; it is truncated or the face count is wrong", e.count),
            ));
        }
    }
    Ok(out)
}

fn ascii(
    path: &Path,
    bytes: &[u8],
    header: &Header,
    fi: usize,
    li: usize,
    vertices: usize,
) -> Result<Vec<Triangle>> {
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let Some(text) = bytes
        .get(header.body..)
        .and_then(|b| std::str::from_utf8(b).ok())
    else {
        return Ok(Vec::new());
    };
    let Some(face) = header.elements.get(fi) else {
        return Ok(Vec::new());
    };
    // records are one non-empty line each; elements without properties have none
    let skip: u64 = header.elements[..fi]
        .iter()
        .filter(|e| !e.props.is_empty())
        .map(|e| e.count)
        .fold(0, u64::saturating_add);
    let mut lines = split_lines(text)
        .map(|(i, l)| (header.lines + i, l))
        .filter(|(_, l)| !l.trim().is_empty());
    for _ in 0..skip {
        if lines.next().is_none() {
            return Ok(Vec::new());
        }
    }
    let mut out = Vec::new();
    let mut ring = Vec::new();
    for r in 0..face.count {
        let Some((no, line)) = lines.next() else {
            return Err(perr(
                header.lines + split_lines(text).count(),
                format!("the file ends after {r} of the {} faces the header declares; it is truncated or the face count is wrong", face.count),
            ));
        };
        let mut tok = line.split_ascii_whitespace();
        let mut number = |what: &str| -> Result<f64> {
            let t = tok.next().ok_or_else(|| {
                perr(
                    no,
                    format!("face {r} has too few values: {what} is missing"),
                )
            })?;
            t.parse::<f64>().map_err(|_| {
                perr(
                    no,
                    format!("value '{t}' of {what} of face {r} is not a number"),
                )
            })
        };
        for (k, prop) in face.props.iter().enumerate() {
            match prop.kind {
                Kind::Scalar(_) => {
                    number(&prop.name)?;
                }
                Kind::List { .. } => {
                    let n = number(&prop.name)?;
                    if !(n >= 0.0 && n.fract() == 0.0) {
                        return Err(perr(no, format!("list '{}' of face {r} has length {n}; a length must be a non-negative integer", prop.name)));
                    }
                    ring.clear();
                    for _ in 0..n as u64 {
                        let v = number(&prop.name)?;
                        if k == li {
                            ring.push(v);
                        }
                    }
                    if k == li {
                        add(&ring, r, vertices, &mut out).map_err(|m| perr(no, m))?;
                    }
                }
            }
        }
    }
    Ok(out)
}
