//! Typed parsing of the option values the commands share, and the shared
//! input argument group.
//!
//! Every option value is parsed by clap through a typed parser, never
//! matched by hand in a handler:
//!
//! * [`choice`]: a `clap::ValueEnum` whose unknown values are refused with
//!   "unknown --option 'x'; use a, b or c" (the help lists the values);
//! * [`NXM`] (`"NxM"` or `"N"`), [`INDICES`] (`"I,J,K"`), [`ANGLES`]
//!   (`"AZ,EL"` in degrees), [`VECTOR3`] (`"X,Y,Z"`), [`VECTOR`] (`"dx,dy"` or
//!   `"dx,dy,dz"`) and [`VECTORS`] (`"x,y,z;x,y,z;..."`): each a
//!   [`Parsed`] value parser that names the option in its message.
//!
//! A value that can start with a minus sign (`--view -60,35`, `--axis
//! -0.3,0.1,0.9`) needs `allow_hyphen_values = true` on its argument, or
//! clap takes it for an option.
//!
//! Values refused by these parsers are bad input, not a malformed command
//! line: `main` exits with status 1 for them, as for any other bad input.

// INDICES, VECTOR3 and VECTORS serve the handlers being typed (coons,
// cloud, turntable, curve); until all use them some are unused.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::marker::PhantomData;
use std::path::PathBuf;

use anyhow::Result;
use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;
use clap::{Arg, Args, Command, ValueEnum};
use scanfit::{PointCloud, Vector3};
use scanfit_io::{read_cloud, Format, NonFinite, PointTable, ReadOptions};

/// The option's name as the user typed it (`--ctrl`), for messages.
fn option_name(arg: Option<&Arg>) -> String {
    match arg {
        Some(a) => match a.get_long() {
            Some(l) => format!("--{l}"),
            None => a.get_id().to_string(),
        },
        None => "the value".to_string(),
    }
}

fn invalid(cmd: &Command, message: String) -> clap::Error {
    clap::Error::raw(ErrorKind::ValueValidation, format!("{message}\n")).with_cmd(cmd)
}

/// A clap value parser from a function `(value, option name) -> T`.
#[derive(Clone, Copy)]
pub struct Parsed<T>(pub fn(&str, &str) -> std::result::Result<T, String>);

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Parsed<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> std::result::Result<T, clap::Error> {
        let name = option_name(arg);
        let Some(s) = value.to_str() else {
            return Err(invalid(cmd, format!("{name}: the value is not UTF-8 text")));
        };
        (self.0)(s, &name).map_err(|m| invalid(cmd, m))
    }
}

/// A clap value parser for the `ValueEnum` `T` whose error says
/// "unknown --option 'x'; use a, b or c". Matching ignores case.
pub fn choice<T: ValueEnum + Clone + Send + Sync + 'static>() -> Choice<T> {
    Choice(PhantomData)
}

/// The parser [`choice`] returns.
#[derive(Clone, Copy)]
pub struct Choice<T>(PhantomData<fn() -> T>);

impl<T: ValueEnum + Clone + Send + Sync + 'static> TypedValueParser for Choice<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> std::result::Result<T, clap::Error> {
        let s = value.to_string_lossy();
        T::from_str(&s, true).map_err(|_| {
            let names: Vec<String> = T::value_variants()
                .iter()
                .filter_map(|v| v.to_possible_value())
                .filter(|p| !p.is_hide_set())
                .map(|p| p.get_name().to_string())
                .collect();
            invalid(
                cmd,
                format!(
                    "unknown {} '{s}'; use {}",
                    option_name(arg),
                    or_list(&names)
                ),
            )
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            T::value_variants()
                .iter()
                .filter_map(|v| v.to_possible_value()),
        ))
    }
}

/// "a, b or c".
pub fn or_list(names: &[String]) -> String {
    match names {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// `"NxM"` (or `"N"` for `N x N`) as two whole numbers.
pub const NXM: Parsed<(usize, usize)> = Parsed(nxm);

fn nxm(s: &str, what: &str) -> std::result::Result<(usize, usize), String> {
    let parse = |x: &str| {
        x.trim()
            .parse::<usize>()
            .map_err(|_| format!("{what} '{s}' must be N or NxM with whole numbers, e.g. 20x16"))
    };
    match s.split_once(['x', 'X']) {
        Some((a, b)) => Ok((parse(a)?, parse(b)?)),
        None => {
            let n = parse(s)?;
            Ok((n, n))
        }
    }
}

/// [`NXM`] for a handler that still holds the option as text: `what`
/// names the option in the error.
pub fn pair(s: &str, what: &str) -> Result<(usize, usize)> {
    nxm(s, what).map_err(anyhow::Error::msg)
}

/// A list of indices or positions, `"I,J,K"`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Indices(pub Vec<usize>);

/// `"I,J,K,..."` as whole numbers ([`Indices`]).
pub const INDICES: Parsed<Indices> = Parsed(indices);

fn indices(s: &str, what: &str) -> std::result::Result<Indices, String> {
    comma_list(s)
        .map(Indices)
        .ok_or_else(|| format!("{what} '{s}' must be positions I,J,K,... (whole numbers)"))
}

/// A list of ids (signed whole numbers), `"0,99,-1"`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ids(pub Vec<i64>);

/// `"I,J,K,..."` as signed whole numbers ([`Ids`]).
pub const IDS: Parsed<Ids> = Parsed(ids);

fn ids(s: &str, what: &str) -> std::result::Result<Ids, String> {
    comma_list(s)
        .map(Ids)
        .ok_or_else(|| format!("{what} '{s}' must be whole numbers separated by commas, e.g. 0,99"))
}

/// `"a,b,c"` parsed item by item; `None` when any item does not parse.
fn comma_list<T: std::str::FromStr>(s: &str) -> Option<Vec<T>> {
    s.split(',').map(|x| x.trim().parse::<T>().ok()).collect()
}

/// Camera angles in degrees: azimuth (any) and elevation in [-90, 90].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angles {
    /// Azimuth in degrees.
    pub azimuth: f64,
    /// Elevation in degrees.
    pub elevation: f64,
}

/// `"AZ,EL"` in degrees ([`Angles`]); the elevation within [-90, 90].
pub const ANGLES: Parsed<Angles> = Parsed(angles);

fn angles(s: &str, what: &str) -> std::result::Result<Angles, String> {
    let (a, e) = s
        .split_once(',')
        .ok_or_else(|| format!("{what} '{s}' needs two angles, AZ,EL"))?;
    let azimuth: f64 = a
        .trim()
        .parse()
        .map_err(|_| format!("{what} azimuth '{a}' is not a number"))?;
    let elevation: f64 = e
        .trim()
        .parse()
        .map_err(|_| format!("{what} elevation '{e}' is not a number"))?;
    if !azimuth.is_finite() || !(-90.0..=90.0).contains(&elevation) {
        return Err(format!(
            "{what} {s}: the azimuth must be finite and the elevation must lie in [-90, 90] degrees"
        ));
    }
    Ok(Angles { azimuth, elevation })
}

fn numbers(s: &str) -> Option<Vec<f64>> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .ok()?;
    v.iter().all(|c| c.is_finite()).then_some(v)
}

/// `"X,Y,Z"`: three finite numbers.
pub const VECTOR3: Parsed<Vector3> = Parsed(vector3);

fn vector3(s: &str, what: &str) -> std::result::Result<Vector3, String> {
    match numbers(s).as_deref() {
        Some(&[x, y, z]) => Ok(Vector3::new(x, y, z)),
        _ => Err(format!("{what} '{s}' must be three finite numbers X,Y,Z")),
    }
}

/// `"dx,dy,dz"` or `"dx,dy"` (dz = 0): a finite vector.
pub const VECTOR: Parsed<Vector3> = Parsed(vector);

fn vector(s: &str, what: &str) -> std::result::Result<Vector3, String> {
    match numbers(s).as_deref() {
        Some(&[x, y, z]) => Ok(Vector3::new(x, y, z)),
        Some(&[x, y]) => Ok(Vector3::new(x, y, 0.0)),
        _ => Err(format!("{what}: '{s}' is not a finite vector dx,dy,dz")),
    }
}

/// `"xmin,ymin,zmin,xmax,ymax,zmax"`: an axis-aligned box (`--box`).
pub const BOX: Parsed<[f64; 6]> = Parsed(crop_box);

fn crop_box(s: &str, what: &str) -> std::result::Result<[f64; 6], String> {
    match numbers(s).as_deref() {
        Some(&[a, b, c, d, e, f]) if a <= d && b <= e && c <= f => Ok([a, b, c, d, e, f]),
        Some(&[_, _, _, _, _, _]) => Err(format!(
            "{what} '{s}': each minimum must be at most its maximum (xmin,ymin,zmin,xmax,ymax,zmax)"
        )),
        _ => Err(format!(
            "{what} '{s}' must be six finite numbers xmin,ymin,zmin,xmax,ymax,zmax"
        )),
    }
}

/// `"x,y,z,r"`: a ball (`--sphere`), the radius > 0.
pub const SPHERE: Parsed<[f64; 4]> = Parsed(sphere);

fn sphere(s: &str, what: &str) -> std::result::Result<[f64; 4], String> {
    match numbers(s).as_deref() {
        Some(&[x, y, z, r]) if r > 0.0 => Ok([x, y, z, r]),
        _ => Err(format!(
            "{what} '{s}' must be four finite numbers x,y,z,r with the radius r > 0"
        )),
    }
}

/// A list of vectors, `"x,y,z;x,y,z;..."`.
#[derive(Debug, Clone, PartialEq)]
pub struct Vectors(pub Vec<Vector3>);

/// `"dx,dy,dz;dx,dy,dz;..."` (each also `dx,dy`) ([`Vectors`]).
pub const VECTORS: Parsed<Vectors> = Parsed(vectors);

fn vectors(s: &str, what: &str) -> std::result::Result<Vectors, String> {
    s.split(';')
        .map(|x| vector(x, what))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map(Vectors)
}

/// The library's error `e` as the command line says it. An invalid setting
/// that `options` maps to a command-line option (`(setting, option)` pairs;
/// the option may go on with advice, as in `"--corners I,J,K,L with loop
/// positions ..."`) names the option first, where the library names its
/// config field: `--alpha = -1: the adjustment's alpha must be ...`, the
/// advice last (`(try --corners I,J,K,L with ...)`). An error of one patch
/// keeps its `patch N: ` prefix; every other error is the library's message.
pub fn cli_message(e: &scanfit::Error, options: &[(&str, &str)]) -> String {
    match e {
        scanfit::Error::InvalidSetting {
            setting,
            value,
            hint,
        } => match options.iter().find(|(s, _)| s == setting) {
            Some((_, o)) => {
                let (name, advice) = o.split_once(' ').unwrap_or((o, ""));
                let advice = if advice.is_empty() {
                    String::new()
                } else {
                    format!(" (try {o})")
                };
                format!("{name} = {value}: {hint}{advice}")
            }
            None => e.to_string(),
        },
        scanfit::Error::InPatch { patch, source } => {
            format!("patch {patch}: {}", cli_message(source, options))
        }
        _ => e.to_string(),
    }
}

/// The format of a point file, `--format`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// PLY (ascii or binary).
    Ply,
    /// PCD (ascii, binary or binary_compressed).
    Pcd,
    /// LAS/LAZ.
    #[value(alias = "laz")]
    Las,
    /// Text: XYZ, CSV, TXT, PTS, ASC.
    #[value(alias = "xyz", alias = "csv", alias = "txt")]
    Text,
    /// STL mesh (binary or ascii): its vertices, normals from the triangles.
    Stl,
    /// OBJ mesh: its vertices, normals from `vn` or the faces.
    Obj,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Ply => Format::Ply,
            FormatArg::Pcd => Format::Pcd,
            FormatArg::Las => Format::Las,
            FormatArg::Text => Format::Text,
            FormatArg::Stl => Format::Stl,
            FormatArg::Obj => Format::Obj,
        }
    }
}

/// The input point file of a command and how to read it (`INPUT`,
/// `--format`, `--drop-non-finite`).
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Input point file (.ply, .pcd, .las/.laz, .xyz/.csv/.txt/.pts/.asc),
    /// or a mesh read as its vertices (.stl, .obj, .ply with faces).
    pub input: PathBuf,
    /// Read as this format whatever the extension.
    #[arg(long, value_name = "FORMAT", value_parser = choice::<FormatArg>())]
    pub format: Option<FormatArg>,
    /// Drop points with NaN or infinite coordinates (and report how many)
    /// instead of stopping at the first one.
    #[arg(long)]
    pub drop_non_finite: bool,
}

impl InputArgs {
    /// Reads the file into a cloud that keeps every extra column as an
    /// attribute; tells on stderr how many non-finite points were dropped
    /// (unless `quiet`, e.g. when JSON is printed).
    pub fn load(&self, quiet: bool) -> Result<PointCloud> {
        Ok(self.table(quiet)?.into_cloud()?)
    }

    /// Reads the file as a table (points, columns, and where each point is
    /// in the file, for messages); tells about dropped points as
    /// [`InputArgs::load`] does.
    pub fn table(&self, quiet: bool) -> Result<PointTable> {
        let table = self.read()?;
        note_dropped(table.dropped_non_finite, quiet);
        Ok(table)
    }

    /// Reads the file with this group's options; the reader's warnings (a
    /// header count that disagrees with the data, ...) go to stderr.
    fn read(&self) -> Result<PointTable> {
        let table = read_cloud(&self.input, &self.options()).map_err(|e| {
            e.with_advice(
                "give --drop-non-finite to leave such points out",
                "give --format FORMAT",
            )
        })?;
        crate::print_warnings(&table.warnings);
        Ok(table)
    }
}

impl InputArgs {
    /// The reader's options from `--format` and `--drop-non-finite`.
    pub fn options(&self) -> ReadOptions {
        ReadOptions {
            format: self.format.map(Format::from),
            non_finite: if self.drop_non_finite {
                NonFinite::Drop
            } else {
                NonFinite::Reject
            },
        }
    }
}

/// The one place that tells how many non-finite points were dropped.
pub fn note_dropped(dropped: usize, quiet: bool) {
    if dropped > 0 && !quiet {
        crate::print_stderr(format_args!(
            "note: {dropped} points with NaN or infinite coordinates dropped"
        ));
    }
}

// ---- typed parsers of coons, turntable and cloud (helper apib) ----

impl<T> Parsed<T> {
    /// A parser from `f(value, option name)`, for a command's own typed
    /// values (`--axis`, `--orient`, `--corners`).
    pub const fn new(f: fn(&str, &str) -> std::result::Result<T, String>) -> Self {
        Self(f)
    }

    /// Parses `s` as the value of the option `what` outside clap (a part of
    /// another option's value, e.g. the `X,Y,Z` of `--orient view:X,Y,Z`).
    pub fn parse_str(&self, s: &str, what: &str) -> std::result::Result<T, String> {
        (self.0)(s, what)
    }
}

/// The name a `ValueEnum` value has on the command line (`angle`, `lsq`).
pub fn value_name<T: ValueEnum>(v: &T) -> String {
    v.to_possible_value()
        .map(|p| p.get_name().to_string())
        .unwrap_or_default()
}

impl InputArgs {
    /// Reads the file like [`InputArgs::load`] and returns the cloud with
    /// the number of non-finite points dropped, telling nothing (for reports
    /// that show the count themselves).
    pub fn load_counted(&self) -> Result<(PointCloud, usize)> {
        let table = self.read()?;
        let dropped = table.dropped_non_finite;
        Ok((table.into_cloud()?, dropped))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers_accept_and_refuse() {
        assert_eq!(nxm("20x16", "--ctrl"), Ok((20, 16)));
        assert_eq!(nxm(" 7 ", "--ctrl"), Ok((7, 7)));
        assert!(nxm("ax2", "--base").unwrap_err().contains("--base 'ax2'"));
        assert_eq!(indices("3, 1,4", "--corners"), Ok(Indices(vec![3, 1, 4])));
        assert!(indices("3,-1", "--corners").is_err());
        assert_eq!(
            angles("-60,35", "--view"),
            Ok(Angles {
                azimuth: -60.0,
                elevation: 35.0
            })
        );
        assert!(angles("10,91", "--view").is_err());
        assert!(angles("nan,0", "--view").is_err());
        assert!(angles("10", "--view").is_err());
        assert_eq!(
            vector3("-0.5,1,2e1", "--axis"),
            Ok(Vector3::new(-0.5, 1.0, 20.0))
        );
        assert!(vector3("1,2", "--axis")
            .unwrap_err()
            .contains("three finite numbers"));
        assert!(vector3("1,inf,2", "--axis").is_err());
        assert_eq!(vector("1,-2", "--t"), Ok(Vector3::new(1.0, -2.0, 0.0)));
        assert_eq!(
            vectors("-1,0,0;0,1", "--end-tangents"),
            Ok(Vectors(vec![
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0)
            ]))
        );
        assert!(vectors("1,0,0;", "--end-tangents").is_err());
        assert_eq!(or_list(&["a".into(), "b".into(), "c".into()]), "a, b or c");
    }
}

/// `--remove-outliers` of the surface commands: statistical outlier
/// removal (the `cloud clean --outliers` defaults) before the fit.
#[derive(Args, Debug, Clone, Default)]
pub struct OutlierArgs {
    /// Remove stray points before the fit: statistical outlier removal with
    /// the defaults of `scanfit cloud clean --outliers` (mean distance to 50
    /// neighbours above mean + 1 std and above twice the median); says how
    /// many it removed.
    #[arg(long)]
    pub remove_outliers: bool,
}

impl OutlierArgs {
    /// The cloud without its outliers when asked for (a note on stderr says
    /// how many went unless `quiet`), else the cloud as it is.
    pub fn apply(&self, cloud: PointCloud, quiet: bool) -> Result<PointCloud> {
        Ok(match self.clean(&cloud, quiet)? {
            Some(r) => r.cloud,
            None => cloud,
        })
    }

    /// The table without its outliers when asked for (its rows keep their
    /// places in the file, for messages), else the table as it is.
    pub fn apply_table(&self, mut table: PointTable, quiet: bool) -> Result<PointTable> {
        if !self.remove_outliers {
            return Ok(table);
        }
        let cloud = PointCloud::new(table.points.clone())?;
        if let Some(r) = self.clean(&cloud, quiet)? {
            let mut keep = vec![false; cloud.len()];
            for i in r.kept {
                keep[i] = true;
            }
            table.retain(&keep);
        }
        Ok(table)
    }

    /// The outlier removal when asked for, its note on stderr.
    fn clean(
        &self,
        cloud: &PointCloud,
        quiet: bool,
    ) -> Result<Option<scanfit::pipeline::cloud::CloudClean>> {
        if !self.remove_outliers {
            return Ok(None);
        }
        let r = scanfit::pipeline::cloud::clean(
            cloud,
            &scanfit::pipeline::cloud::CloudCleanConfig::remove_outliers(),
            &scanfit::progress::NoProgress,
        )?;
        if !quiet {
            crate::print_stderr(format_args!(
                "note: --remove-outliers removed {} of {} points ({})",
                cloud.len() - r.cloud.len(),
                cloud.len(),
                r.steps.first().map_or("", |s| s.detail.as_str())
            ));
        }
        Ok(Some(r))
    }
}
