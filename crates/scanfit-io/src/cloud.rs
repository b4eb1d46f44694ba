//! One entry point for every point format: [`read_cloud`] picks the reader
//! by extension (or [`ReadOptions::format`]) and [`write_cloud`] writes a
//! [`PointCloud`] with all its attributes as PLY (binary or ascii) or XYZ.

use std::path::Path;

use scanfit::PointCloud;

use crate::ply::{points_ply, points_xyz, PlyFormat};
use crate::table::{Format, PointTable, ReadOptions};
use crate::{las, obj, pcd, ply_read, stl, write_atomic, xyz, Error, Result};

/// Reads a point file: PLY, PCD, LAS/LAZ, text (XYZ, CSV, TXT, PTS, ASC) or
/// a mesh as its vertices (STL, OBJ, PLY with faces; normals from the
/// triangles), the format chosen by [`ReadOptions::format`], else by the
/// extension (a text extension on a file whose first bytes say PLY, LAS,
/// PCD or STL is read as what it is, with a warning), else (no extension)
/// by the first bytes. Errors name the file and the line, byte
/// offset or point where the content is wrong, and what to change.
pub fn read_cloud(path: &Path, options: &ReadOptions) -> Result<PointTable> {
    let format = match options.format {
        Some(f) => Some(f),
        // an unknown extension is an error before the file is opened
        None => Format::from_path(path)?,
    };
    let io = |error| Error::Io {
        path: path.to_path_buf(),
        error,
    };
    // a binary PLY point file straight into the points (the common layout;
    // every other file is read whole)
    #[cfg(unix)]
    if format == Some(Format::Ply) {
        let file = std::fs::File::open(path).map_err(io)?;
        if let Some(table) = ply_read::direct::read(path, &file, options)? {
            return Ok(table);
        }
    }
    let bytes = std::fs::read(path).map_err(io)?;
    parse_cloud(path, &bytes, options)
}

/// Reads a point file's content from memory (`path` names it in messages and
/// gives its extension when [`ReadOptions::format`] is `None`).
pub fn parse_cloud(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    let mut note = None;
    let format = match options.format {
        Some(f) => f,
        None => match Format::from_path(path)? {
            // a text name on a file whose content says otherwise: by its
            // magic, or an OBJ's first statement (`v`, `o`, ...), which no
            // text point file starts with
            Some(Format::Text) => match Format::magic(bytes)
                .or_else(|| crate::obj::sniff(bytes).then_some(Format::Obj))
            {
                Some(f) => {
                    note = Some(format!(
                        "{}: the content is {} (by its first bytes), not text; read as {}",
                        path.display(),
                        f.name(),
                        f.name()
                    ));
                    f
                }
                None => Format::Text,
            },
            Some(f) => f,
            None => Format::sniff(bytes),
        },
    };
    let mut table = match format {
        Format::Ply => ply_read::parse(path, bytes, options),
        Format::Pcd => pcd::parse(path, bytes, options),
        Format::Las => las::parse(path, bytes, options),
        Format::Text => xyz::parse_bytes(path, bytes, options.non_finite),
        Format::Stl => stl::parse(path, bytes, options),
        Format::Obj => obj::parse(path, bytes, options),
    }?;
    table.warnings.extend(note);
    Ok(table)
}

/// The formats [`write_cloud`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WriteFormat {
    /// PLY `binary_little_endian`, every value a double (exact).
    PlyBinary,
    /// PLY `ascii`, shortest round-trip decimals (exact).
    PlyAscii,
    /// Space-separated text with a header line naming the columns
    /// (shortest round-trip decimals, exact).
    Xyz,
}

impl WriteFormat {
    /// The format for a file name: `.ply` binary PLY, `.xyz`/`.txt`/`.csv`/
    /// `.pts`/`.asc` text; `None` otherwise.
    pub fn from_path(path: &Path) -> Option<WriteFormat> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "ply" => Some(WriteFormat::PlyBinary),
            "xyz" | "txt" | "csv" | "pts" | "asc" => Some(WriteFormat::Xyz),
            _ => None,
        }
    }
}

/// An attribute name usable in a PLY header or an XYZ header line: runs of
/// whitespace, commas and semicolons become `_`, a name that reads as a
/// number gets a leading `_`, and an empty name becomes `attribute`.
pub fn column_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c == ',' || c == ';' {
                '_'
            } else {
                c
            }
        })
        .collect();
    if s.is_empty() {
        s = "attribute".into();
    }
    if s.parse::<f64>().is_ok() || s.starts_with('#') || s.starts_with("//") {
        s.insert(0, '_');
    }
    s
}

/// The bytes of a cloud in `format`: x, y, z, then every attribute in the
/// cloud's order under [`column_name`] of its name.
pub fn cloud_bytes(cloud: &PointCloud, format: WriteFormat) -> Vec<u8> {
    let names: Vec<String> = cloud
        .attributes()
        .iter()
        .map(|a| column_name(&a.name))
        .collect();
    let attrs: Vec<(&str, &[f64])> = names
        .iter()
        .zip(cloud.attributes())
        .map(|(n, a)| (n.as_str(), a.values.as_slice()))
        .collect();
    match format {
        WriteFormat::PlyBinary => points_ply(cloud.points(), &attrs, PlyFormat::Binary),
        WriteFormat::PlyAscii => points_ply(cloud.points(), &attrs, PlyFormat::Ascii),
        WriteFormat::Xyz => points_xyz(cloud.points(), &attrs),
    }
}

/// Writes a cloud with all its attributes to `path` atomically (temporary
/// file, then rename).
pub fn write_cloud(path: &Path, cloud: &PointCloud, format: WriteFormat) -> Result<()> {
    write_atomic(path, &cloud_bytes(cloud, format))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::NonFinite;
    use scanfit::{Point3, Vector3};

    fn cloud() -> PointCloud {
        let pts = vec![
            Point3::new(0.1, -2.5e-7, 1e100),
            Point3::new(1.0 / 3.0, 6.02e23, -0.0),
            Point3::new(-123456.789, 0.2, 5.0),
        ];
        let mut c = PointCloud::new(pts)
            .unwrap()
            .with_attribute("u", vec![0.0, 0.5, 1.0])
            .unwrap()
            .with_attribute("residual", vec![1e-17, f64::NAN, -3.25])
            .unwrap()
            .with_attribute("label", vec![1.0, 2.0, 65535.0])
            .unwrap();
        c.set_normals(&[Vector3::x(), Vector3::new(0.6, 0.8, 0.0), -Vector3::z()])
            .unwrap();
        c
    }

    /// Equality that treats NaN as equal to NaN.
    fn same(a: &PointCloud, b: &PointCloud) {
        assert_eq!(a.points(), b.points());
        assert_eq!(a.attributes().len(), b.attributes().len());
        for (x, y) in a.attributes().iter().zip(b.attributes()) {
            assert_eq!(x.name, y.name);
            let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&x.values), bits(&y.values), "{}", x.name);
        }
    }

    #[test]
    fn write_then_read_is_exact_in_every_format() {
        let dir = std::env::temp_dir().join(format!("scanfit-cloud-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let c = cloud();
        for (name, format) in [
            ("b.ply", WriteFormat::PlyBinary),
            ("a.ply", WriteFormat::PlyAscii),
            ("t.xyz", WriteFormat::Xyz),
        ] {
            let p = dir.join(name);
            write_cloud(&p, &c, format).unwrap();
            let back = read_cloud(&p, &ReadOptions::default()).unwrap();
            assert_eq!(
                back.columns,
                vec!["x", "y", "z", "u", "residual", "label", "nx", "ny", "nz"]
            );
            let back = back.into_cloud().unwrap();
            same(&c, &back);
            assert_eq!(back.normals().unwrap()[1], Vector3::new(0.6, 0.8, 0.0));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn dispatch_by_extension_option_and_content() {
        let bytes = cloud_bytes(&cloud(), WriteFormat::PlyAscii);
        let opts = ReadOptions::default();
        // no extension: sniffed
        assert_eq!(
            parse_cloud(Path::new("scan"), &bytes, &opts)
                .unwrap()
                .format,
            Format::Ply
        );
        // the option wins over the extension
        let forced = ReadOptions {
            format: Some(Format::Ply),
            non_finite: NonFinite::Reject,
        };
        assert_eq!(
            parse_cloud(Path::new("scan.dat"), &bytes, &forced)
                .unwrap()
                .points
                .len(),
            3
        );
        let e = parse_cloud(Path::new("scan.dat"), &bytes, &opts)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("scan.dat: '.dat' files are not supported; give a point file with one of the extensions .ply, .pcd, .las, .laz, .xyz, .csv, .txt, .pts, .asc, .stl, .obj"),
            "{e}"
        );
        // a PLY named .xyz is recognised by its first bytes, with a warning
        let t = parse_cloud(Path::new("scan.xyz"), &bytes, &opts).unwrap();
        assert_eq!((t.format, t.points.len()), (Format::Ply, 3));
        assert_eq!(
            t.warnings,
            ["scan.xyz: the content is PLY (by its first bytes), not text; read as PLY"]
        );
        assert_eq!(column_name("a b,c"), "a_b_c");
        assert_eq!(column_name("1e5"), "_1e5");
        assert_eq!(column_name(""), "attribute");
    }
}
