//! Camera options shared by the commands that draw pictures: `--view`,
//! `--up` and `--z-scale`. The camera itself (up axes, presets, the
//! automatic choices) is `scanfit_io::render`'s; this only parses.

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use scanfit::{Point3, Vector3};
use scanfit_io::render::{angles_facing, auto_exaggeration, RenderOptions, Up, ViewPreset};

use crate::args::{Parsed, ANGLES};

/// A camera direction: angles or a named view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    /// Azimuth and elevation in degrees.
    Angles(f64, f64),
    /// `front`, `top` or `iso`.
    Preset(ViewPreset),
}

/// `"AZ,EL"` in degrees, or `front`, `top`, `iso`.
pub const VIEW: Parsed<View> = Parsed(view);

fn view(s: &str, what: &str) -> std::result::Result<View, String> {
    if let Some(p) = ViewPreset::from_name(s.trim()) {
        return Ok(View::Preset(p));
    }
    if !s.contains(',') {
        return Err(format!(
            "unknown {what} '{s}'; use front, top, iso or AZ,EL in degrees (e.g. -60,35)"
        ));
    }
    let a = ANGLES.0(s, what)?;
    Ok(View::Angles(a.azimuth, a.elevation))
}

impl View {
    /// `(azimuth, elevation)` in degrees.
    pub fn angles(self) -> (f64, f64) {
        match self {
            View::Angles(a, e) => (a, e),
            View::Preset(p) => p.angles(),
        }
    }
}

/// `--up`: an axis or automatic.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpArg {
    /// The thin axis of sheet-like data (terrain, reliefs), else z.
    Auto,
    /// x is up.
    X,
    /// y is up (most mesh and scanner software).
    Y,
    /// z is up (CAD, terrain).
    Z,
}

/// `--view`, `--up` and `--z-scale`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Camera of pictures: front, top, iso, or azimuth and elevation in
    /// degrees around the up axis, e.g. "-60,35" [default: -60,35; a top
    /// view of the patch for `cloud boundary`].
    #[arg(long, value_name = "VIEW", allow_hyphen_values = true, value_parser = VIEW)]
    pub view: Option<View>,
    /// The axis that is up in pictures: x, y, z, or auto (the thin axis of
    /// sheet-like data such as terrain stored y-up; z otherwise).
    #[arg(long, value_name = "AXIS", default_value = "auto", value_parser = crate::args::choice::<UpArg>())]
    pub up: UpArg,
    /// Vertical exaggeration (along the up axis) of pictures [default:
    /// automatic, for flat data such as terrain].
    #[arg(long, value_name = "S")]
    pub z_scale: Option<f64>,
}

/// What a picture shows when no `--view` is given.
#[derive(Debug, Clone, Copy)]
pub enum DefaultView {
    /// These angles (degrees).
    Angles(f64, f64),
    /// Looking down onto a patch with this normal.
    Facing(Vector3),
}

impl ViewArgs {
    /// Render options for pictures of `points`.
    pub fn options(&self, points: &[Point3]) -> Result<RenderOptions> {
        self.options_or(points, DefaultView::Angles(-60.0, 35.0))
    }

    /// The up axis for pictures of `points`.
    pub fn up(&self, points: &[Point3]) -> Up {
        self.up_given().unwrap_or_else(|| Up::automatic(points))
    }

    /// The up axis when `--up` names one (`None` for auto).
    pub fn up_given(&self) -> Option<Up> {
        match self.up {
            UpArg::Auto => None,
            UpArg::X => Some(Up::X),
            UpArg::Y => Some(Up::Y),
            UpArg::Z => Some(Up::Z),
        }
    }

    /// Render options for pictures of `points`, with the camera `default`
    /// unless `--view` is given.
    pub fn options_or(&self, points: &[Point3], default: DefaultView) -> Result<RenderOptions> {
        let up = self.up(points);
        let (azimuth, elevation) = match (self.view, default) {
            (Some(v), _) => v.angles(),
            (None, DefaultView::Angles(a, e)) => (a, e),
            (None, DefaultView::Facing(n)) => angles_facing(&n, up),
        };
        let z_scale = match self.z_scale {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => bail!("--z-scale {s} must be a positive number"),
            None => auto_exaggeration(points, up),
        };
        Ok(RenderOptions {
            azimuth,
            elevation,
            up,
            z_scale,
            ..Default::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_are_presets_or_angles() {
        assert_eq!(view("top", "--view"), Ok(View::Preset(ViewPreset::Top)));
        assert_eq!(view("-60,35", "--view"), Ok(View::Angles(-60.0, 35.0)));
        assert!(view("side", "--view")
            .unwrap_err()
            .contains("front, top, iso"));
        assert!(view("10,91", "--view").is_err());
    }
}
