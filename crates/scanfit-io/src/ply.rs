//! PLY writers (binary little-endian or ASCII): point sets with any per-point
//! scalar attributes (u, v, residual, ...) and triangle meshes with normals and
//! an optional per-vertex scalar (deviation) and colour.

use std::fmt::Write as _;

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

/// A PLY point set: x, y, z as doubles, then each attribute as a double
/// property with its name. Attributes must hold one value per point.
pub fn points_ply(points: &[Point3], attributes: &[(&str, &[f64])], format: PlyFormat) -> Vec<u8> {
    let mut header = header_start(format);
    let _ = writeln!(header, "element vertex {}", points.len());
    for name in ["x", "y", "z"]
        .iter()
        .chain(attributes.iter().map(|(n, _)| n))
    {
        let _ = writeln!(header, "property double {name}");
    }
    header.push_str("end_header\n");
    let mut out = header.into_bytes();
    for (i, p) in points.iter().enumerate() {
        let vals = [p.x, p.y, p.z]
            .into_iter()
            .chain(attributes.iter().map(|(_, v)| v[i]));
        push_values(&mut out, vals, format);
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

fn push_values(out: &mut Vec<u8>, vals: impl Iterator<Item = f64>, format: PlyFormat) {
    match format {
        PlyFormat::Binary => vals.for_each(|v| out.extend_from_slice(&v.to_le_bytes())),
        PlyFormat::Ascii => {
            // Debug: the shortest form that reads back exactly, with exponents
            let line: Vec<String> = vals.map(|v| format!("{v:?}")).collect();
            out.extend_from_slice(line.join(" ").as_bytes());
            out.push(b'\n');
        }
    }
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
        assert!(text.contains("element vertex 2") && text.contains("property double u"));
        assert_eq!(bytes.len() - end, 2 * 4 * 8);
        let v = f64::from_le_bytes(bytes[end + 24..end + 32].try_into().unwrap());
        assert_eq!(v, 0.25);
        let ascii = String::from_utf8(points_ply(&pts, &[("u", &u)], PlyFormat::Ascii)).unwrap();
        assert!(ascii.ends_with("-1.0 0.5 1e-300 0.75\n"), "{ascii}");
    }
}
