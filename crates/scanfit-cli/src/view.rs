//! Camera options shared by the commands that draw pictures.

use anyhow::{bail, Result};
use clap::Args;
use scanfit::Point3;
use scanfit_io::render::{auto_exaggeration, RenderOptions};

use crate::args::{Angles, ANGLES};

/// `--view AZ,EL` and `--z-scale S`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Camera azimuth and elevation in degrees for pictures, e.g. "-60,35"
    /// (z is up) [default: -60,35; a top view of the patch for `cloud boundary`].
    #[arg(long, value_name = "AZ,EL", allow_hyphen_values = true, value_parser = ANGLES)]
    pub view: Option<Angles>,
    /// Vertical exaggeration of pictures [default: automatic, for flat data such as terrain].
    #[arg(long, value_name = "S")]
    pub z_scale: Option<f64>,
}

impl ViewArgs {
    /// Render options for pictures of `points`.
    pub fn options(&self, points: &[Point3]) -> Result<RenderOptions> {
        self.options_or(points, (-60.0, 35.0))
    }

    /// Render options for pictures of `points`, with camera angles
    /// `default` (azimuth, elevation in degrees) unless `--view` is given.
    pub fn options_or(&self, points: &[Point3], default: (f64, f64)) -> Result<RenderOptions> {
        let (az, el) = match self.view {
            Some(a) => (a.azimuth, a.elevation),
            None => default,
        };
        let z_scale = match self.z_scale {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => bail!("--z-scale {s} must be a positive number"),
            None => auto_exaggeration(points),
        };
        Ok(RenderOptions {
            azimuth: az,
            elevation: el,
            z_scale,
            ..Default::default()
        })
    }
}
