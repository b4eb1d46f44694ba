//! Text point files: XYZ, CSV, TXT (and .pts/.asc).
//!
//! One point per line, values separated by commas, semicolons, tabs or spaces;
//! an optional header line naming the columns (the first line whose fields are
//! not all numbers); `#` comments and blank lines skipped. The first three
//! columns are x, y, z; further columns are kept by name (from the header, or
//! `col4`, `col5`, ... without one). Every point remembers its line number, so
//! errors about a point can name `file:line`.

use std::path::Path;

use scanfit::Point3;

use crate::table::{split_lines, Format, NonFinite, Origin, PointTable, ReadOptions, MAX_COLUMNS};
use crate::{Error, Result};

/// Reads a point file of any supported format with the default options:
/// the format by extension, non-finite coordinates rejected. Kept for the
/// callers of the text-only reader; see [`crate::read_cloud`].
pub fn read_points(path: &Path) -> Result<PointTable> {
    crate::read_cloud(path, &ReadOptions::default())
}

/// Parses the bytes of a text point file (`path` is used for messages only).
pub(crate) fn parse_bytes(path: &Path, bytes: &[u8], policy: NonFinite) -> Result<PointTable> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes
            .get(..e.valid_up_to())
            .unwrap_or_default()
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        Error::Parse {
            path: path.to_path_buf(),
            line,
            message: "not UTF-8 text; is this a binary file?".into(),
        }
    })?;
    parse_points_with(path, text, policy)
}

/// Parses the text of a point file (`path` is used for messages only),
/// rejecting non-finite coordinates.
pub fn parse_points(path: &Path, text: &str) -> Result<PointTable> {
    parse_points_with(path, text, NonFinite::Reject)
}

/// Splits a data line into its fields. Spaces and tabs separate fields
/// (a run of them counts once); a comma or semicolon is a delimiter, so two
/// of them with only blanks between (`1,,3`), or one at the start or end of
/// the line, enclose an empty field, returned as `""`. Linear in the line.
fn split_fields<'a>(line: &'a str, out: &mut Vec<&'a str>) {
    out.clear();
    let is_blank = |c: char| c == ' ' || c == '\t' || c.is_whitespace();
    let is_delim = |c: char| c == ',' || c == ';';
    let mut rest = line.trim_matches(is_blank);
    if rest.is_empty() {
        return;
    }
    loop {
        match rest.find(|c: char| is_blank(c) || is_delim(c)) {
            None => {
                out.push(rest);
                return;
            }
            Some(k) => {
                out.push(&rest[..k]);
                // the separator: blanks, at most one delimiter, blanks
                let mut tail = rest[k..].trim_start_matches(is_blank);
                let mut delimited = false;
                if let Some(t) = tail.strip_prefix(is_delim) {
                    delimited = true;
                    tail = t.trim_start_matches(is_blank);
                }
                if tail.is_empty() {
                    if delimited {
                        // `1,2,3,`: a delimiter ends the line
                        out.push("");
                    }
                    return;
                }
                rest = tail;
                // `1,,3` or `1, ;3`: a delimiter right after a delimiter
                if delimited {
                    while let Some(t) = rest.strip_prefix(is_delim) {
                        out.push("");
                        rest = t.trim_start_matches(is_blank);
                        if rest.is_empty() {
                            out.push("");
                            return;
                        }
                    }
                }
            }
        }
    }
}

/// Parses the text of a point file with a policy for non-finite coordinates
/// (`path` is used for messages only). Non-finite values in extra columns
/// are kept: they are data (a missing normal, an undefined curvature).
///
/// Lines end with LF, CRLF or a lone CR. An empty field (`1,,3`, a
/// delimiter at the start or end of a line) is an error naming the line
/// and the value, or a NaN under [`NonFinite::Drop`] (a point whose x, y or
/// z is empty is then dropped); it never shifts the columns. A Leica PTS
/// count line that disagrees with the number of points read is a warning
/// in [`PointTable::warnings`]. More than [`crate::table::MAX_COLUMNS`]
/// columns is an error. Time is linear in the size of the text.
pub fn parse_points_with(path: &Path, text: &str, policy: NonFinite) -> Result<PointTable> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut parser = TextParser::new(path, policy);
    let mut rows = TextRows::default();
    parser.block(text, 0, &mut rows)?;
    parser.check_not_empty(rows.points.len())?;
    let warnings = parser.warnings(rows.points.len());
    Ok(PointTable {
        path: path.to_path_buf(),
        format: Format::Text,
        points: rows.points,
        columns: parser.columns(),
        extra: rows.extra,
        origin: Origin::Lines(rows.lines),
        file_index: None,
        dropped_non_finite: parser.dropped,
        warnings,
    })
}

/// Points parsed from some lines of a text file.
#[derive(Debug, Default)]
pub(crate) struct TextRows {
    pub(crate) points: Vec<Point3>,
    pub(crate) extra: Vec<Vec<f64>>,
    pub(crate) lines: Vec<usize>,
}

/// The state of a text file's parse between blocks of lines (header,
/// columns, counts), so a file can be parsed in pieces
/// ([`crate::chunks`]) with the same rules as in one piece.
#[derive(Debug)]
pub(crate) struct TextParser {
    path: std::path::PathBuf,
    policy: NonFinite,
    columns: Option<Vec<String>>,
    width: usize,
    order: [usize; 3],
    extra_index: Vec<usize>,
    pts_count: Option<(usize, u64)>,
    pub(crate) dropped: usize,
    any_point: bool,
}

impl TextParser {
    pub(crate) fn new(path: &Path, policy: NonFinite) -> Self {
        Self {
            path: path.to_path_buf(),
            policy,
            columns: None,
            width: 0,
            order: [0, 1, 2],
            extra_index: Vec::new(),
            pts_count: None,
            dropped: 0,
            any_point: false,
        }
    }

    /// Parses the complete lines of `text` (numbered from `first_line + 1`)
    /// into `rows`.
    pub(crate) fn block(
        &mut self,
        text: &str,
        first_line: usize,
        rows: &mut TextRows,
    ) -> Result<()> {
        let (path, policy) = (self.path.clone(), self.policy);
        let perr = |line: usize, message: String| Error::Parse {
            path: path.to_path_buf(),
            line,
            message,
        };
        let mut fields: Vec<&str> = Vec::new();
        let mut values: Vec<f64> = Vec::new();
        let too_wide = |line_no: usize, n: usize| {
            perr(
                line_no,
                format!(
                    "{n} columns; a point file may have at most {} (is this a point file with one point per line?)",
                    MAX_COLUMNS
                ),
            )
        };
        for (line_no, raw) in split_lines(text) {
            let line_no = line_no + first_line;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with("//") {
                continue;
            }
            split_fields(line, &mut fields);
            if fields.len() > MAX_COLUMNS {
                return Err(too_wide(line_no, fields.len()));
            }
            values.clear();
            let mut bad: Option<(usize, &str)> = None;
            for (k, f) in fields.iter().enumerate() {
                if f.is_empty() {
                    if policy == NonFinite::Drop {
                        values.push(f64::NAN);
                        continue;
                    }
                    return Err(perr(
                        line_no,
                        format!(
                            "value {} is empty (two delimiters in a row, or one at the start or end of the line); write a number there (or 'nan', and read with ReadOptions {{ non_finite: NonFinite::Drop, .. }} to leave such points out)",
                            k + 1
                        ),
                    ));
                }
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
                if !self.any_point
                    && self.width == 0
                    && self.columns.is_none()
                    && values.is_empty()
                    && fields.iter().all(|f| f.parse::<f64>().is_err())
                {
                    if let Some(e) = fields.iter().position(|f| f.is_empty()) {
                        return Err(perr(
                            line_no,
                            format!(
                                "column {} of the header line has no name; name every column",
                                e + 1
                            ),
                        ));
                    }
                    self.columns = Some(
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
            // Leica PTS: the first data line holds only the point count
            if self.width == 0
                && self.pts_count.is_none()
                && values.len() == 1
                && values[0] >= 0.0
                && values[0].fract() == 0.0
            {
                self.pts_count = Some((line_no, values[0] as u64));
                continue;
            }
            if self.width == 0 {
                self.width = self.columns.as_ref().map_or(fields.len(), |c| c.len());
                if let Some(c) = &self.columns {
                    // x, y, z by name when the header names them (any order)
                    let find = |axis: &str| c.iter().position(|n| n.eq_ignore_ascii_case(axis));
                    if let (Some(x), Some(y), Some(z)) = (find("x"), find("y"), find("z")) {
                        self.order = [x, y, z];
                    }
                }
                if self.width < 3 {
                    return Err(perr(
                        line_no,
                        format!(
                            "{} columns found; a point needs at least x, y, z",
                            self.width
                        ),
                    ));
                }
                let order = self.order;
                self.extra_index = (0..self.width).filter(|k| !order.contains(k)).collect();
            }
            if rows.extra.len() != self.extra_index.len() {
                rows.extra = vec![Vec::new(); self.extra_index.len()];
            }
            let width = self.width;
            if values.len() != width {
                return Err(perr(
                    line_no,
                    format!(
                        "{} values found, but the file has {width} columns",
                        values.len()
                    ),
                ));
            }
            let order = self.order;
            if let Some(k) = order.into_iter().find(|&k| !values[k].is_finite()) {
                if policy == NonFinite::Drop {
                    self.dropped += 1;
                    continue;
                }
                return Err(perr(
                    line_no,
                    format!(
                        "value {} is {}; every coordinate must be a finite number (fix the line, or read with ReadOptions {{ non_finite: NonFinite::Drop, .. }} to leave such points out)",
                        k + 1,
                        values.get(k).copied().unwrap_or(f64::NAN)
                    ),
                ));
            }
            let value = |k: usize| values.get(k).copied().unwrap_or(0.0);
            rows.points.push(Point3::new(
                value(order[0]),
                value(order[1]),
                value(order[2]),
            ));
            for (col, &k) in rows.extra.iter_mut().zip(&self.extra_index) {
                col.push(value(k));
            }
            rows.lines.push(line_no);
            self.any_point = true;
        }
        Ok(())
    }

    /// Errors when the whole file gave no points (`points` read in all).
    pub(crate) fn check_not_empty(&self, points: usize) -> Result<()> {
        if points > 0 {
            return Ok(());
        }
        Err(Error::Invalid {
            path: self.path.to_path_buf(),
            message: if self.dropped > 0 {
                format!(
                    "no points left: all {} have a non-finite coordinate",
                    self.dropped
                )
            } else {
                "no points found (the file is empty or holds only a header/comments)".into()
            },
        })
    }

    /// The warnings once the whole file is read (`points` read in all).
    pub(crate) fn warnings(&self, points: usize) -> Vec<String> {
        let mut warnings = Vec::new();
        if let Some((line, declared)) = self.pts_count {
            let found = (points + self.dropped) as u64;
            if declared != found {
                warnings.push(format!(
                    "{}:{line}: the count line declares {declared} points, but the file holds {found}; all {found} were read (fix the count, or check whether the file is truncated)",
                    self.path.display()
                ));
            }
        }
        warnings
    }

    /// The table's columns: x, y, z first, then the others in file order.
    pub(crate) fn columns(&self) -> Vec<String> {
        match &self.columns {
            Some(c) => {
                let mut out: Vec<String> = self.order.iter().map(|&k| c[k].clone()).collect();
                out.extend(self.extra_index.iter().map(|&k| c[k].clone()));
                out
            }
            None => {
                let mut c: Vec<String> = ["x", "y", "z"].iter().map(|s| s.to_string()).collect();
                c.extend((4..=self.width).map(|k| format!("col{k}")));
                c
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<PointTable> {
        parse_points(Path::new("t.csv"), text)
    }

    #[test]
    fn header_names_place_x_y_z_in_any_order() {
        let t = parse("id,Z,x,y,w\n7,3,1,2,0.5\n8,6,4,5,1.5\n").unwrap();
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(4., 5., 6.)]
        );
        assert_eq!(t.columns, ["x", "y", "Z", "id", "w"]);
        assert_eq!(t.column("id"), Some(&[7.0, 8.0][..]));
        assert_eq!(t.column("w"), Some(&[0.5, 1.5][..]));
        // non-finite checks look at the named coordinates
        let e = parse("id,x,y,z\nnan,1,2,3\n1,inf,2,3\n").unwrap_err();
        assert!(e.to_string().contains("t.csv:3"), "{e}");
    }

    #[test]
    fn leica_pts_count_line_is_skipped() {
        let t = parse("2\n1 2 3 -100 200 10 20\n4 5 6 -90 10 20 30\n").unwrap();
        assert_eq!(t.points.len(), 2);
        assert_eq!(t.points[1], Point3::new(4., 5., 6.));
        assert_eq!(t.extra.len(), 4);
        assert_eq!(t.locate(0), "t.csv:2");
    }

    #[test]
    fn csv_with_header_and_extra_columns() {
        let t = parse("x,y,z,w\n1,2,3,0.5\n\n# c\n4,5,6,1.5\n").unwrap();
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(4., 5., 6.)]
        );
        assert_eq!(t.origin, Origin::Lines(vec![2, 5]));
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
    fn non_finite_coordinates_dropped_on_request_and_kept_in_extra_columns() {
        let text = "x y z w\n1 2 3 nan\n1 inf 3 0.5\n4 5 6 -inf\n";
        let t = parse_points_with(Path::new("t.xyz"), text, NonFinite::Drop).unwrap();
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(4., 5., 6.)]
        );
        assert_eq!(t.dropped_non_finite, 1);
        assert_eq!(t.locate(1), "t.xyz:4");
        let w = t.column("w").unwrap();
        assert!(w[0].is_nan() && w[1] == f64::NEG_INFINITY);
        let e = parse_points(Path::new("t.xyz"), text)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.xyz:3: value 2 is inf"), "{e}");
        let e = parse_points_with(Path::new("t.xyz"), "nan 1 1\n", NonFinite::Drop)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no points left: all 1"), "{e}");
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

    #[test]
    fn every_line_ending_gives_the_same_points() {
        let want = vec![
            Point3::new(1., 2., 3.),
            Point3::new(4., 5., 6.),
            Point3::new(7., 8., 9.),
        ];
        for eol in ["\n", "\r\n", "\r"] {
            let text = ["x y z", "1 2 3", "4 5 6", "7 8 9"].join(eol) + eol;
            let t = parse(&text).unwrap();
            assert_eq!(t.points, want, "{eol:?}");
            assert_eq!(t.columns, ["x", "y", "z"], "{eol:?}");
            assert_eq!(t.locate(2), "t.csv:4", "{eol:?}");
        }
        // mixed endings in one file, and a CR-only file without a final one
        let t = parse("1 2 3\r4 5 6\n7 8 9\r\n").unwrap();
        assert_eq!(t.points, want);
        let t = parse("1 2 3\r4 5 6\r7 8 9").unwrap();
        assert_eq!(t.points, want);
        assert_eq!(t.origin, Origin::Lines(vec![1, 2, 3]));
    }

    #[test]
    fn an_empty_field_is_an_error_or_nan_never_a_shift() {
        for (text, line, value) in [
            ("1,2,3,4\n5,,7,8\n", 2, 2),
            ("1,2,3,4\n,6,7,8\n", 2, 1),
            ("1,2,3,4\n5,6,7,\n", 2, 4),
            ("1;2;3;4\n5; ;7;8\n", 2, 2),
            ("x,y,z,w\n1, ,3,4\n", 2, 2),
        ] {
            let e = parse(text).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("t.csv:{line}: value {value} is empty")),
                "{text:?}: {e}"
            );
        }
        // a space after a comma is one separator, not an empty field
        let t = parse("1, 2, 3, 4\n5 ,6 , 7,8\n").unwrap();
        assert_eq!(t.points[1], Point3::new(5., 6., 7.));
        assert_eq!(t.extra, vec![vec![4.0, 8.0]]);
        // under the drop policy: NaN; a point with an empty coordinate is dropped,
        // an empty extra value stays NaN in its own column
        let t = parse_points_with(
            Path::new("t.csv"),
            "x,y,z,w\n1,2,3,\n4,,6,7\n8,9,10,11\n",
            NonFinite::Drop,
        )
        .unwrap();
        assert_eq!(
            t.points,
            vec![Point3::new(1., 2., 3.), Point3::new(8., 9., 10.)]
        );
        assert_eq!(t.dropped_non_finite, 1);
        let w = t.column("w").unwrap();
        assert!(w[0].is_nan() && w[1] == 11.0, "{w:?}");
        let e = parse("x,,z\n1,2,3\n").unwrap_err().to_string();
        assert!(
            e.starts_with("t.csv:1: column 2 of the header line has no name"),
            "{e}"
        );
    }

    #[test]
    fn a_pts_count_that_disagrees_is_a_warning() {
        let t = parse("2\n1 2 3\n4 5 6\n").unwrap();
        assert!(t.warnings.is_empty(), "{:?}", t.warnings);
        let t = parse("5\n1 2 3\n4 5 6\n").unwrap();
        assert_eq!(t.points.len(), 2);
        assert_eq!(
            t.warnings,
            ["t.csv:1: the count line declares 5 points, but the file holds 2; all 2 were read (fix the count, or check whether the file is truncated)"]
        );
        let t = parse("1\n1 2 3\n4 5 6\n7 8 9\n").unwrap();
        assert_eq!(t.points.len(), 3);
        assert!(t.warnings[0].contains("declares 1 points, but the file holds 3"));
    }

    #[test]
    fn wide_lines_are_linear_and_bounded() {
        // at the limit: read, each column kept
        let n = crate::table::MAX_COLUMNS;
        let row = |v: usize| vec![v.to_string(); n].join(" ");
        let t = parse(&format!("{}\n{}\n", row(1), row(2))).unwrap();
        assert_eq!(t.extra.len(), n - 3);
        assert_eq!(t.columns[n - 1], format!("col{n}"));
        // beyond it: an error on the first line, before any column is built
        let wide = "1 ".repeat(500_000);
        let start = std::time::Instant::now();
        let e = parse(&format!("{wide}\n{wide}\n")).unwrap_err().to_string();
        assert!(
            e.starts_with("t.csv:1: 500000 columns; a point file may have at most 1024"),
            "{e}"
        );
        assert!(start.elapsed().as_secs_f64() < 2.0, "{:?}", start.elapsed());
    }
}
