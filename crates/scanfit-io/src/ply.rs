//! PLY writers (binary little-endian or ASCII): point sets with any per-point
//! scalar attributes (u, v, residual, ...) and triangle meshes with normals and
//! an optional per-vertex scalar (deviation) and colour.

use std::fmt::Write as _;

use rayon::prelude::*;
use scanfit::bspline::Mesh;
use scanfit::Point3;

/// Encoding of a PLY file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyFormat {
    /// `binary_little_endian 1.0` (compact, exact).
    Binary,
    /// `ascii 1.0` (readable; shortest round-trip decimal form).
    Ascii,
}

/// The narrowest PLY type that holds every value of a column exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Column {
    /// `int`: integers in the i32 range (indices, labels, counts).
    Int,
    /// `float`: values an f32 holds exactly (float input stays float).
    Float,
    /// `double`: everything else.
    Double,
}

impl Column {
    /// The type of `values`; coordinates (`integers` false) are never `int`.
    fn of(values: impl Iterator<Item = f64> + Clone, integers: bool) -> Self {
        let int = |v: f64| {
            v.trunc() == v
                && (f64::from(i32::MIN)..=f64::from(i32::MAX)).contains(&v)
                && !(v == 0.0 && v.is_sign_negative())
        };
        if integers && values.clone().all(int) {
            Column::Int
        } else if values.into_iter().all(|v| f64::from(v as f32) == v) {
            Column::Float
        } else {
            Column::Double
        }
    }

    /// Bytes of a binary value.
    fn width(self) -> usize {
        if self == Column::Double {
            8
        } else {
            4
        }
    }

    /// The little-endian bytes of `v` as this type: the first
    /// [`Column::width`] of the eight.
    fn le_bytes(self, v: f64) -> [u8; 8] {
        let mut b = [0; 8];
        match self {
            Column::Int => b[..4].copy_from_slice(&(v as i32).to_le_bytes()),
            Column::Float => b[..4].copy_from_slice(&(v as f32).to_le_bytes()),
            Column::Double => b = v.to_le_bytes(),
        }
        b
    }

    fn name(self) -> &'static str {
        match self {
            Column::Int => "int",
            Column::Float => "float",
            Column::Double => "double",
        }
    }

    fn push(self, out: &mut Vec<u8>, v: f64, format: PlyFormat) {
        // Debug: the shortest form that reads back exactly, with exponents
        match (self, format) {
            (_, PlyFormat::Binary) => out.extend_from_slice(&self.le_bytes(v)[..self.width()]),
            (Column::Int, PlyFormat::Ascii) => {
                let _ = write!(Text(out), "{}", v as i32);
            }
            (Column::Float, PlyFormat::Ascii) => {
                let _ = write!(Text(out), "{:?}", v as f32);
            }
            (Column::Double, PlyFormat::Ascii) => {
                let _ = write!(Text(out), "{v:?}");
            }
        }
    }
}

/// `fmt::Write` into a byte buffer.
struct Text<'a>(&'a mut Vec<u8>);

impl std::fmt::Write for Text<'_> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.extend_from_slice(s.as_bytes());
        Ok(())
    }
}

/// A PLY point set: x, y, z, then each attribute as a property with its
/// name, each column in the narrowest type that holds all its values
/// exactly: x, y, z as `float` when every coordinate is an f32 value (float
/// input stays float) and `double` otherwise; an attribute as `int` when
/// all its values are integers in the i32 range (indices, labels), else
/// `float` or `double` likewise. Attributes must hold one value per point.
///
/// ```
/// use scanfit_io::ply::{points_ply, PlyFormat};
/// use scanfit::Point3;
/// let pts = [Point3::new(0.5, 1.0, 2.0), Point3::new(0.25, 3.0, 0.1)];
/// let bytes = points_ply(&pts, &[("index", &[0.0, 1.0]), ("u", &[0.1, 0.2])], PlyFormat::Binary);
/// let head = String::from_utf8_lossy(&bytes);
/// // z = 0.1 needs a double; the index is an int, u = 0.1 a double
/// assert!(head.contains("property double x") && head.contains("property int index"));
/// let end = head.find("end_header\n").unwrap() + 11;
/// assert_eq!(bytes.len() - end, 2 * (3 * 8 + 4 + 8));
/// ```
pub fn points_ply(points: &[Point3], attributes: &[(&str, &[f64])], format: PlyFormat) -> Vec<u8> {
    let mut header = header_start(format);
    let _ = writeln!(header, "element vertex {}", points.len());
    let xyz = Column::of(points.iter().flat_map(|p| [p.x, p.y, p.z]), false);
    let columns: Vec<Column> = attributes
        .iter()
        .map(|(_, v)| Column::of(v.iter().copied(), true))
        .collect();
    for name in ["x", "y", "z"] {
        let _ = writeln!(header, "property {} {name}", xyz.name());
    }
    for ((name, _), c) in attributes.iter().zip(&columns) {
        let _ = writeln!(header, "property {} {name}", c.name());
    }
    header.push_str("end_header\n");
    let mut out = header.into_bytes();
    let row: usize = 3 * xyz.width() + columns.iter().map(|c| c.width()).sum::<usize>();
    if format == PlyFormat::Binary {
        // fixed-size records: parallel blocks of rows, each written in place
        const ROWS: usize = 1 << 14;
        let start = out.len();
        out.resize(start + row * points.len(), 0);
        out[start..]
            .par_chunks_mut(row * ROWS)
            .zip(points.par_chunks(ROWS))
            .enumerate()
            .for_each(|(b, (bytes, pts))| {
                let mut at = 0;
                let mut put = |c: Column, v: f64| {
                    let w = c.width();
                    bytes[at..at + w].copy_from_slice(&c.le_bytes(v)[..w]);
                    at += w;
                };
                for (r, p) in pts.iter().enumerate() {
                    let i = b * ROWS + r;
                    for v in [p.x, p.y, p.z] {
                        put(xyz, v);
                    }
                    for (c, (_, v)) in columns.iter().zip(attributes) {
                        put(*c, v[i]);
                    }
                }
            });
        return out;
    }
    for (i, p) in points.iter().enumerate() {
        let vals = [(xyz, p.x), (xyz, p.y), (xyz, p.z)]
            .into_iter()
            .chain(columns.iter().zip(attributes).map(|(c, (_, v))| (*c, v[i])));
        for (k, (c, v)) in vals.enumerate() {
            if format == PlyFormat::Ascii && k > 0 {
                out.push(b' ');
            }
            c.push(&mut out, v, format);
        }
        if format == PlyFormat::Ascii {
            out.push(b'\n');
        }
    }
    out
}

/// A PLY triangle mesh: vertices (double x, y, z, float nx, ny, nz), an optional
/// per-vertex scalar property `name` and RGB colour, and the faces.
pub fn mesh_ply(
    mesh: &Mesh,
    scalar: Option<(&str, &[f64])>,
    colours: Option<&[[u8; 3]]>,
    format: PlyFormat,
) -> Vec<u8> {
    let mut h = header_start(format);
    let _ = writeln!(h, "element vertex {}", mesh.vertices.len());
    h.push_str("property double x\nproperty double y\nproperty double z\n");
    h.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    if let Some((name, _)) = scalar {
        let _ = writeln!(h, "property double {name}");
    }
    if colours.is_some() {
        h.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\n");
    }
    let _ = writeln!(h, "element face {}", mesh.triangles.len());
    h.push_str("property list uchar int vertex_indices\nend_header\n");
    let mut out = h.into_bytes();
    for (i, (p, n)) in mesh.vertices.iter().zip(&mesh.normals).enumerate() {
        match format {
            PlyFormat::Binary => {
                for v in [p.x, p.y, p.z] {
                    out.extend_from_slice(&v.to_le_bytes());
                }
                for v in [n.x, n.y, n.z] {
                    out.extend_from_slice(&(v as f32).to_le_bytes());
                }
                if let Some((_, s)) = scalar {
                    out.extend_from_slice(&s[i].to_le_bytes());
                }
                if let Some(c) = colours {
                    out.extend_from_slice(&c[i]);
                }
            }
            PlyFormat::Ascii => {
                let mut line = format!(
                    "{:?} {:?} {:?} {:?} {:?} {:?}",
                    p.x, p.y, p.z, n.x as f32, n.y as f32, n.z as f32
                );
                if let Some((_, s)) = scalar {
                    let _ = write!(line, " {:?}", s[i]);
                }
                if let Some(c) = colours {
                    let _ = write!(line, " {} {} {}", c[i][0], c[i][1], c[i][2]);
                }
                line.push('\n');
                out.extend_from_slice(line.as_bytes());
            }
        }
    }
    for t in &mesh.triangles {
        match format {
            PlyFormat::Binary => {
                out.push(3);
                for &k in t {
                    out.extend_from_slice(&(k as i32).to_le_bytes());
                }
            }
            PlyFormat::Ascii => {
                out.extend_from_slice(format!("3 {} {} {}\n", t[0], t[1], t[2]).as_bytes())
            }
        }
    }
    out
}

/// A Wavefront OBJ mesh with vertex normals and texture coordinates (the
/// surface parameters), 1-based faces `f a/a/a b/b/b c/c/c`.
pub fn mesh_obj(mesh: &Mesh, comment: &str) -> Vec<u8> {
    let mut s = String::with_capacity(mesh.vertices.len() * 80);
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for p in &mesh.vertices {
        let _ = writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for t in &mesh.uv {
        let _ = writeln!(s, "vt {:?} {:?}", t[0], t[1]);
    }
    for n in &mesh.normals {
        let _ = writeln!(s, "vn {:?} {:?} {:?}", n.x, n.y, n.z);
    }
    for t in &mesh.triangles {
        let (a, b, c) = (t[0] + 1, t[1] + 1, t[2] + 1);
        let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
    }
    s.into_bytes()
}

/// Numbers in the text writers use Rust's `Debug` form: shortest round trip.
/// A space-separated XYZ text file with a header line naming the columns.
pub fn points_xyz(points: &[Point3], attributes: &[(&str, &[f64])]) -> Vec<u8> {
    let mut s = String::from("x y z");
    for (n, _) in attributes {
        s.push(' ');
        s.push_str(n);
    }
    s.push('\n');
    for (i, p) in points.iter().enumerate() {
        let _ = write!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
        for (_, v) in attributes {
            let _ = write!(s, " {:?}", v[i]);
        }
        s.push('\n');
    }
    s.into_bytes()
}

fn header_start(format: PlyFormat) -> String {
    let f = match format {
        PlyFormat::Binary => "binary_little_endian",
        PlyFormat::Ascii => "ascii",
    };
    format!(
        "ply\nformat {f} 1.0\ncomment written by scanfit {}\n",
        env!("CARGO_PKG_VERSION")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary_points_have_the_declared_size_and_values() {
        let pts = vec![Point3::new(1.0, 2.0, 3.0), Point3::new(-1.0, 0.5, 1e-300)];
        let u = [0.25, 0.75];
        let bytes = points_ply(&pts, &[("u", &u)], PlyFormat::Binary);
        let text = String::from_utf8_lossy(&bytes);
        let end = text.find("end_header\n").unwrap() + "end_header\n".len();
        // 1e-300 is no f32: double coordinates; u is an f32 value: float
        assert!(text.contains("element vertex 2") && text.contains("property double z"));
        assert!(text.contains("property float u"), "{text}");
        assert_eq!(bytes.len() - end, 2 * (3 * 8 + 4));
        let v = f32::from_le_bytes(bytes[end + 24..end + 28].try_into().unwrap());
        assert_eq!(v, 0.25);
        let ascii = String::from_utf8(points_ply(&pts, &[("u", &u)], PlyFormat::Ascii)).unwrap();
        assert!(ascii.ends_with("-1.0 0.5 1e-300 0.75\n"), "{ascii}");
    }

    /// The binary rows are written in parallel blocks of 2^14: over three
    /// blocks (the last one partial) every byte is where one row after the
    /// other puts it (double coordinates, an int and a float column).
    #[test]
    fn binary_blocks_hold_the_rows_in_order() {
        let n = 40_000;
        let pts: Vec<Point3> = (0..n)
            .map(|i| Point3::new(0.1 * i as f64, -(i as f64), 1e-300 * i as f64))
            .collect();
        let index: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let half: Vec<f64> = (0..n).map(|i| f64::from(i as f32 * 0.5)).collect();
        let bytes = points_ply(
            &pts,
            &[("index", &index), ("half", &half)],
            PlyFormat::Binary,
        );
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("property int index") && text.contains("property float half"));
        let end = text.find("end_header\n").unwrap() + "end_header\n".len();
        let mut want = Vec::new();
        for (i, p) in pts.iter().enumerate() {
            for v in [p.x, p.y, p.z] {
                want.extend_from_slice(&v.to_le_bytes());
            }
            want.extend_from_slice(&(i as i32).to_le_bytes());
            want.extend_from_slice(&(half[i] as f32).to_le_bytes());
        }
        assert!(bytes[end..] == want[..]);
    }

    #[test]
    fn float_input_stays_float_and_indices_are_integers() {
        // f32 coordinates (as read from a float PLY) and an index column
        let pts: Vec<Point3> = (0..5)
            .map(|i| {
                let f = |x: f32| f64::from(x);
                Point3::new(f(0.1 * i as f32), f(1.3), f(-2.7e-3 * i as f32))
            })
            .collect();
        let index: Vec<f64> = (0..5).map(|i| f64::from(i * 1000 - 2)).collect();
        let d = [0.1, 0.2, 0.3, 0.4, 0.5];
        let big = [1e10, 0.0, 0.0, 0.0, 0.0];
        let neg0 = [-0.0, 1.0, 2.0, 3.0, 4.0];
        let attrs = [
            ("index", &index[..]),
            ("d", &d[..]),
            ("big", &big[..]),
            ("neg0", &neg0[..]),
        ];
        let bytes = points_ply(&pts, &attrs, PlyFormat::Binary);
        let text = String::from_utf8_lossy(&bytes);
        for p in [
            "property float x",
            "property float z",
            "property int index",
            "property double d",
            "property float big",
            "property float neg0",
        ] {
            assert!(text.contains(p), "{p}: {text}");
        }
        let end = text.find("end_header\n").unwrap() + "end_header\n".len();
        assert_eq!(bytes.len() - end, 5 * (3 * 4 + 4 + 8 + 4 + 4));
        // every value reads back exactly
        let row = 3 * 4 + 4 + 8 + 4 + 4;
        for (i, p) in pts.iter().enumerate() {
            let at = end + i * row;
            let f = |o: usize| {
                f64::from(f32::from_le_bytes(
                    bytes[at + o..at + o + 4].try_into().unwrap(),
                ))
            };
            assert_eq!([f(0), f(4), f(8)], [p.x, p.y, p.z]);
            let k = i32::from_le_bytes(bytes[at + 12..at + 16].try_into().unwrap());
            assert_eq!(f64::from(k), index[i]);
            let dv = f64::from_le_bytes(bytes[at + 16..at + 24].try_into().unwrap());
            assert_eq!(dv, d[i]);
            assert_eq!(f(24), big[i]);
            assert_eq!(f(28).to_bits(), neg0[i].to_bits());
        }
        let ascii = String::from_utf8(points_ply(&pts, &attrs, PlyFormat::Ascii)).unwrap();
        let data = &ascii[ascii.find("end_header\n").unwrap() + 11..];
        assert_eq!(
            data.lines().nth(1),
            Some("0.1 1.3 -0.0027 998 0.2 0.0 1.0"),
            "{ascii}"
        );
    }
}
