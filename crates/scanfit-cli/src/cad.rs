//! The CAD outputs shared by the fitting commands: `--step` and `--iges`,
//! the declared length unit (`--units`) and the trimming switch
//! (`--trim` / `--no-trim`).

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::{Args, ValueEnum};
use scanfit::bspline::Surface;
use scanfit::cloud::boundary::Boundary;
use scanfit::pipeline::assess::{AssessConfig, SurfaceQuality};
use scanfit::pipeline::assess_trimmed::assess_trimmed;
use scanfit::trim::{trim_surface, trim_to_points, TrimConfig, TrimmedSurface};
use scanfit::{Point3, PointCloud};
use scanfit_io::iges::iges_file_with;
use scanfit_io::step::{step_file_with, CadItem};
use scanfit_io::units::{CadOptions, LengthUnit};

/// `--units` of every command that writes STEP or IGES.
#[derive(Args, Debug, Clone, Copy)]
pub struct UnitsArgs {
    /// Length unit the data are in, declared in the STEP and IGES files
    /// (the coordinates are written unscaled; a CAD system converts on
    /// import: data in metres with --units m arrive at their true size);
    /// pictures label their colour bars with it [default: mm in CAD files,
    /// "data units" in pictures].
    #[arg(long, value_name = "UNIT", value_parser = crate::args::choice::<UnitsArg>())]
    pub units: Option<UnitsArg>,
}

/// The command-line names of [`LengthUnit`].
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitsArg {
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches.
    In,
    /// Feet.
    Ft,
}

impl UnitsArgs {
    /// The writers' options.
    pub fn options(&self) -> CadOptions {
        CadOptions::with_units(match self.units.unwrap_or(UnitsArg::Mm) {
            UnitsArg::Mm => LengthUnit::Millimetre,
            UnitsArg::Cm => LengthUnit::Centimetre,
            UnitsArg::M => LengthUnit::Metre,
            UnitsArg::In => LengthUnit::Inch,
            UnitsArg::Ft => LengthUnit::Foot,
        })
    }
}

impl UnitsArgs {
    /// The unit's name for pictures: the one given, else "data units".
    pub fn label(&self) -> &'static str {
        match self.units {
            Some(UnitsArg::Mm) => "mm",
            Some(UnitsArg::Cm) => "cm",
            Some(UnitsArg::M) => "m",
            Some(UnitsArg::In) => "in",
            Some(UnitsArg::Ft) => "ft",
            None => "data units",
        }
    }
}

/// `--trim` / `--no-trim` of the commands that know the cloud's boundary.
#[derive(Args, Debug, Clone, Copy)]
pub struct TrimArgs {
    /// Bound the surface by the cloud's boundary loops (alpha shape: the
    /// outline and the holes) instead of its whole parameter rectangle:
    /// STEP faces bounded by trim curves, IGES entity 144, meshes and
    /// pictures of the trimmed part only. The default where the command
    /// maps the boundary into the surface (see the command's help).
    #[arg(long, conflicts_with = "no_trim")]
    pub trim: bool,
    /// Keep the untrimmed rectangle.
    #[arg(long)]
    pub no_trim: bool,
}

impl TrimArgs {
    /// Whether to trim, `default` when neither flag is given.
    pub fn wanted(&self, default: bool) -> bool {
        self.trim || (default && !self.no_trim)
    }

    /// The trimmed surface when wanted: `surface` bounded by the boundary
    /// loops of `points` (`boundary` when the pipeline computed them),
    /// mapped by their parameters `uv`.
    pub fn apply(
        &self,
        default: bool,
        surface: &Surface,
        points: &[Point3],
        uv: &[[f64; 2]],
        boundary: Option<&Boundary>,
    ) -> Result<Option<TrimmedSurface>> {
        if !self.wanted(default) {
            return Ok(None);
        }
        let cfg = TrimConfig::default();
        let t = match boundary {
            Some(b) => trim_surface(surface, uv, b, &cfg),
            None => trim_to_points(surface, points, uv, &cfg),
        };
        let t = match t {
            Ok(t) => t,
            Err(e) if !self.trim => {
                // the default: say why and keep the rectangle
                eprintln!("note: the surface is not trimmed: {e}");
                return Ok(None);
            }
            Err(e) => anyhow::bail!("trimming the surface: {e} (or give --no-trim)"),
        };
        // a boundary that is the rectangle's own, without holes, trims nothing
        Ok((t.outer.is_some() || !t.holes.is_empty()).then_some(t))
    }
}

/// The surface-to-points measures and the extent check of `quality` (the
/// pipeline's assessment with `config`) taken again over the trimmed face,
/// when there is one: the parts of the rectangle outside the trim loops are
/// in no output and do not count.
pub fn measure_trimmed(
    quality: &mut SurfaceQuality,
    trimmed: Option<&TrimmedSurface>,
    cloud: &PointCloud,
    config: &AssessConfig,
) -> Result<()> {
    if let Some(t) = trimmed {
        assess_trimmed(quality, t, cloud, config)?;
    }
    Ok(())
}

/// One line describing a trimmed face, for the command's report.
pub fn trim_line(t: &TrimmedSurface) -> String {
    let outer = match &t.outer {
        Some(o) => format!("the outline ({} boundary points)", o.points),
        None => "the parameter rectangle".to_string(),
    };
    let dev = t.curves().map(|c| c.deviation).fold(0.0, f64::max);
    let skipped = if t.skipped_holes > 0 {
        format!(
            "; {} holes of fewer than {} boundary points left untrimmed",
            t.skipped_holes,
            TrimConfig::default().min_hole_points
        )
    } else {
        String::new()
    };
    format!(
        "trimmed face: bounded by {outer} and {} holes; 3D trim curves within {dev:.3e} data units of the surface{skipped}; surface samples and extent measured on the face (eq. 17 on the whole knot grid)",
        t.holes.len()
    )
}

/// The trimmed face for `--json` reports (`{"trimmed": false}` when not
/// trimmed).
pub fn trim_json(t: Option<&TrimmedSurface>) -> serde_json::Value {
    // JSON output holds no null: an untrimmed face says so, and a face that
    // keeps its rectangle has no "outer"
    let Some(t) = t else {
        return serde_json::json!({ "trimmed": false });
    };
    let mut v = serde_json::json!({
        "trimmed": true,
        "holes": t.holes.iter().map(|h| h.points).collect::<Vec<_>>(),
        "skipped_holes": t.skipped_holes,
        "max_curve_deviation": t.curves().map(|c| c.deviation).fold(0.0, f64::max),
    });
    if let Some(o) = &t.outer {
        v["outer"] = o.points.into();
    }
    v
}

/// Prints [`trim_line`] for a trimmed face.
pub fn print_trim(t: Option<&TrimmedSurface>) -> Result<()> {
    if let Some(t) = t {
        outln!("{}", trim_line(t));
    }
    Ok(())
}

/// The STEP and IGES files requested, named after the input's file stem.
pub fn cad_files<'a>(
    step: &'a Option<PathBuf>,
    iges: &'a Option<PathBuf>,
    item: CadItem,
    input: &Path,
    options: &CadOptions,
) -> Result<Vec<(&'a Path, Vec<u8>)>> {
    let name = input
        .file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut files = Vec::new();
    if let Some(s) = step {
        files.push((
            s.as_path(),
            step_file_with(&[item], &name, options)?.into_bytes(),
        ));
    }
    if let Some(i) = iges {
        files.push((
            i.as_path(),
            iges_file_with(&[item], &name, options)?.into_bytes(),
        ));
    }
    Ok(files)
}
