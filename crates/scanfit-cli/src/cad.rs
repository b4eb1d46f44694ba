//! The CAD outputs shared by the fitting commands: `--step` and `--iges`,
//! the declared length unit (`--units`) and the trimming switch
//! (`--trim` / `--no-trim`).

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::{Args, ValueEnum};
use scanfit::pipeline::assess::{AssessConfig, SurfaceQuality};
use scanfit::pipeline::trim::{run, TrimInput, TrimMode, TrimRunConfig};
use scanfit::progress::Progress;
use scanfit::trim::{TrimConfig, TrimmedSurface};
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

    /// The library's trim mode for these flags, `default` when neither is
    /// given.
    pub fn mode(&self, default: bool) -> TrimMode {
        if self.trim {
            TrimMode::Required
        } else if self.wanted(default) {
            TrimMode::Default
        } else {
            TrimMode::Off
        }
    }

    /// The trimmed face when wanted ([`scanfit::pipeline::trim::run`]), with
    /// `quality` (the pipeline's assessment, taken with `assess`) measured
    /// again on it; a default trim that cannot be made says why on stderr
    /// and keeps the rectangle.
    pub fn apply(
        &self,
        default: bool,
        input: TrimInput,
        quality: &mut SurfaceQuality,
        assess: &AssessConfig,
        progress: &dyn Progress,
    ) -> Result<Option<TrimmedSurface>> {
        let mut config = TrimRunConfig::default();
        config.mode = self.mode(default);
        config.assess = *assess;
        let r = run(input, quality, &config, progress)
            .map_err(|e| anyhow::anyhow!("trimming the surface: {e} (or give --no-trim)"))?;
        if let Some(why) = &r.kept_rectangle {
            eprintln!("note: the surface is not trimmed: {why}");
        }
        Ok(r.trimmed)
    }
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
