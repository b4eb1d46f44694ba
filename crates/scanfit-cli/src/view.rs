//! Camera options shared by the commands that draw pictures.

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::Point3;
use scanfit_io::render::{auto_exaggeration, RenderOptions};

/// `--view AZ,EL` and `--z-scale S`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Camera azimuth and elevation in degrees for pictures, e.g. "-60,35"
    /// (z is up) [default: -60,35; a top view of the patch for `cloud boundary`].
    #[arg(long, value_name = "AZ,EL", allow_negative_numbers = true)]
    pub view: Option<String>,
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
        let view = self
            .view
            .clone()
            .unwrap_or_else(|| format!("{},{}", default.0, default.1));
        let (a, e) = view
            .split_once(',')
            .context("--view needs two angles, AZ,EL")?;
        let az: f64 = a
            .trim()
            .parse()
            .with_context(|| format!("--view azimuth '{a}' is not a number"))?;
        let el: f64 = e
            .trim()
            .parse()
            .with_context(|| format!("--view elevation '{e}' is not a number"))?;
        if !az.is_finite() || !(-90.0..=90.0).contains(&el) {
            bail!("--view {view}: the elevation must lie in [-90, 90] degrees");
        }
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
