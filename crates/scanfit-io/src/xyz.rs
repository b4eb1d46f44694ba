//! Text point files: XYZ, CSV, TXT (and .pts/.asc).
//!
//! One point per line, values separated by commas, semicolons, tabs or spaces;
//! an optional header line naming the columns (the first line whose fields are
//! not all numbers); `#` comments and blank lines skipped. The first three
//! columns are x, y, z; further columns are kept by name (from the header, or
//! `col4`, `col5`, ... without one). Every point remembers its line number, so
//! errors about a point can name `file:line`.

use std::path::{Path, PathBuf};

use scanfit::Point3;

use crate::{Error, Result};

/// Points read from a file, with their extra columns and source lines.
#[derive(Debug, Clone, PartialEq)]
pub struct PointTable {
    /// The file the points came from.
    pub path: PathBuf,
    /// The points (x, y, z = the first three columns).
    pub points: Vec<Point3>,
    /// Names of all columns (header names, or x, y, z, col4, ...).
    pub columns: Vec<String>,
    /// Extra columns beyond x, y, z: `extra[c][i]` is column `c + 3` of point `i`.
    pub extra: Vec<Vec<f64>>,
    /// 1-based line number of each point in the file.
    pub lines: Vec<usize>,
}

impl PointTable {
    /// `file:line` of point `index` (for error messages).
    pub fn locate(&self, index: usize) -> String {
        match self.lines.get(index) {
            Some(l) => format!("{}:{l}", self.path.display()),
            None => self.path.display().to_string(),
        }
    }

    /// The extra column named `name`, if any.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        let i = self
            .columns
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))?;
        if i < 3 {
            return None;
        }
        self.extra.get(i - 3).map(|v| v.as_slice())
    }
}

/// File types the reader knows, by extension.
const TEXT_EXTENSIONS: [&str; 5] = ["xyz", "csv", "txt", "pts", "asc"];

/// Reads a text point file (see the module documentation).
pub fn read_points(path: &Path) -> Result<PointTable> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !ext.is_empty() && !TEXT_EXTENSIONS.contains(&ext.as_str()) {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "'.{ext}' files are not supported yet; give a text point file ({})",
                TEXT_EXTENSIONS.map(|e| format!(".{e}")).join(", ")
            ),
        });
    }
    let bytes = std::fs::read(path).map_err(|error| Error::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        Error::Parse {
            path: path.to_path_buf(),
            line,
            message: "not UTF-8 text; is this a binary file?".into(),
        }
    })?;
    parse_points(path, &text)
}

/// Parses the text of a point file (`path` is used for messages only).
pub fn parse_points(path: &Path, text: &str) -> Result<PointTable> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut columns: Option<Vec<String>> = None;
    let mut width = 0usize;
    let mut points = Vec::new();
    let mut extra: Vec<Vec<f64>> = Vec::new();
    let mut lines = Vec::new();
    let mut values: Vec<f64> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("//") {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        values.clear();
        let mut bad: Option<(usize, &str)> = None;
        for (k, f) in fields.iter().enumerate() {
            match f.parse::<f64>() {
                Ok(v) => values.push(v),
                Err(_) => {
                    bad = Some((k, f));
                    break;
                }
            }
        }
        if let Some((k, f)) = bad {
            // the header: before any data, and no field a number (a data line
            // with a typo such as `0,O,0` is an error, not a header)
            if points.is_empty()
                && columns.is_none()
                && values.is_empty()
                && fields.iter().all(|f| f.parse::<f64>().is_err())
            {
                // the first non-numeric line before any data is the header
                columns = Some(
                    fields
                        .iter()
                        .map(|s| s.trim_matches('"').to_string())
                        .collect(),
                );
                continue;
            }
            return Err(perr(
                line_no,
                format!("value {} ('{f}') is not a number", k + 1),
            ));
        }
        if width == 0 {
            width = columns.as_ref().map_or(fields.len(), |c| c.len());
            if width < 3 {
                return Err(perr(
                    line_no,
                    format!("{width} columns found; a point needs at least x, y, z"),
                ));
            }
            extra = vec![Vec::new(); width - 3];
        }
        if values.len() != width {
            return Err(perr(
                line_no,
                format!(
                    "{} values found, but the file has {width} columns",
                    values.len()
                ),
            ));
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(perr(
                line_no,
                format!(
                    "value {} is {}; every coordinate must be a finite number",
                    k + 1,
                    values[k]
                ),
            ));
        }
        points.push(Point3::new(values[0], values[1], values[2]));
        for (c, col) in extra.iter_mut().enumerate() {
            col.push(values[3 + c]);
        }
        lines.push(line_no);
    }
    if points.is_empty() {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: "no points found (the file is empty or holds only a header/comments)".into(),
        });
    }
    let columns = columns.unwrap_or_else(|| {
        let mut c: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
        c.extend((4..=width).map(|k| format!("col{k}")));
        c
    });
    Ok(PointTable {
        path: path.to_path_buf(),
        points,
        columns,
        extra,
        lines,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<PointTable> {
        parse_points(Path::new("t.csv"), text)
    }

    #[test]
    fn csv_with_header_and_extra_columns() {
        let t = parse("x,y,z,w\n1,2,3,0.5\n\n# c\n4,5,6,1.5\n").unwrap();
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(4., 5., 6.)]
        );
        assert_eq!(t.lines, vec![2, 5]);
        assert_eq!(t.column("w").unwrap(), &[0.5, 1.5]);
        assert_eq!(t.locate(1), "t.csv:5");
    }

    #[test]
    fn a_typo_in_the_first_line_is_not_a_header() {
        let e = parse("0,O,0\n1,1,1\n").unwrap_err().to_string();
        assert_eq!(e, "t.csv:1: value 2 ('O') is not a number");
    }

    #[test]
    fn whitespace_and_tabs_without_header() {
        let t = parse("1 2 3\n4\t5\t6\n-3.47E-15  1e2 10\n").unwrap();
        assert_eq!(t.points.len(), 3);
        assert_eq!(t.points[2], Point3::new(-3.47e-15, 100.0, 10.0));
        assert_eq!(t.columns, vec!["x", "y", "z"]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse("x,y,z\n1,2,3\n1,abc,3\n").unwrap_err().to_string();
        assert_eq!(e, "t.csv:3: value 2 ('abc') is not a number");
        let e = parse("1,2,3\n1,2\n").unwrap_err().to_string();
        assert!(e.starts_with("t.csv:2: 2 values found"), "{e}");
        let e = parse("1,2,3\n1,nan,3\n").unwrap_err().to_string();
        assert!(e.starts_with("t.csv:2: value 2 is NaN"), "{e}");
        let e = parse("1,inf,3\n").unwrap_err().to_string();
        assert!(e.contains("t.csv:1") && e.contains("inf"), "{e}");
        let e = parse("x,y,z\n").unwrap_err().to_string();
        assert!(e.contains("no points found"), "{e}");
        let e = parse("").unwrap_err().to_string();
        assert!(e.contains("no points found"), "{e}");
        let e = parse("1 2\n").unwrap_err().to_string();
        assert!(e.contains("at least x, y, z"), "{e}");
    }

    #[test]
    fn missing_file_and_unsupported_extension() {
        let e = read_points(Path::new("/nonexistent/p.xyz"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/p.xyz:"), "{e}");
        let e = read_points(Path::new("scan.e57")).unwrap_err().to_string();
        assert!(e.contains("not supported"), "{e}");
    }
}
