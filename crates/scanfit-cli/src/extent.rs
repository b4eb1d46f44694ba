//! The refusal to write a surface that has left the data
//! ([`scanfit::pipeline::Extent`]), shared by every surface command.

use anyhow::{bail, Result};
use scanfit::pipeline::Extent;

use crate::table::num;

/// Fails with one line naming how far the surface left the points'
/// bounding box (absolute and in point spacings), its control net's reach,
/// and `fix`, unless `allow` (`--allow-extrapolation`) is set.
pub fn check(e: &Extent, allow: bool, fix: &str) -> Result<()> {
    if !e.leaves || allow {
        return Ok(());
    }
    bail!("{}", message(e, fix))
}

/// The refusal's line for `e` (see [`check`]).
pub fn message(e: &Extent, fix: &str) -> String {
    format!(
        "the surface leaves the data: samples reach {} ({:.0} point spacings, {:.1}% of the diagonal) outside the points' bounding box and control points {} (limit {}); {fix}, or pass --allow-extrapolation to write it anyway",
        num(e.samples_outside),
        e.samples_outside_spacings,
        100.0 * e.samples_outside / e.diagonal.max(f64::MIN_POSITIVE),
        num(e.control_outside),
        num(e.limit),
    )
}
