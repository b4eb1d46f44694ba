//! Camera options shared by the commands that draw pictures.

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::Point3;
use scanfit_io::render::{auto_exaggeration, RenderOptions};

/// `--view AZ,EL` and `--z-scale S`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Camera azimuth and elevation in degrees for pictures, e.g. "-60,35" (z is up).
    #[arg(
        long,
        value_name = "AZ,EL",
        default_value = "-60,35",
        allow_negative_numbers = true
    )]
    pub view: String,
    /// Vertical exaggeration of pictures [default: automatic, for flat data such as terrain].
    #[arg(long, value_name = "S")]
    pub z_scale: Option<f64>,
}

impl ViewArgs {
    /// Render options for pictures of `points`.
    pub fn options(&self, points: &[Point3]) -> Result<RenderOptions> {
        let (a, e) = self
            .view
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
            bail!(
                "--view {}: the elevation must lie in [-90, 90] degrees",
                self.view
            );
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
