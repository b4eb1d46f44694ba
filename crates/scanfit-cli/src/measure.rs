//! `--measure full|sample|none`: how much of a fitted surface the surface
//! commands measure, over [`scanfit::pipeline::assess::Measure`] (issue 18).

use clap::{Args, ValueEnum};
use scanfit::pipeline::assess::{AssessConfig, Assessment, Measure, DEFAULT_SAMPLE_POINTS};

use crate::args::choice;

/// The choices of `--measure`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MeasureArg {
    /// Every measure over every point.
    Full,
    /// Spacing, fold-overs and stretch on a seeded random sample above
    /// 200000 points; the rest over every point.
    Sample,
    /// The errors at the parameters and the extent check only.
    None,
}

/// The `--measure` option of the surface commands.
#[derive(Args, Debug, Clone, Copy)]
pub struct MeasureArgs {
    /// How much of the result is measured: full (every measure over every
    /// point), sample (the point spacing, fold-overs and stretch on seeded
    /// random samples when there are more than 200000 points; the errors,
    /// orthogonal distances and eq. 17 over every point) or none (the errors
    /// at the parameters and the extent check only: the fastest).
    #[arg(long, default_value = "sample", value_name = "HOW", value_parser = choice::<MeasureArg>())]
    pub measure: MeasureArg,
}

impl MeasureArgs {
    /// `base` with this choice, keeping the per-point values only when an
    /// output needs them (`per_point`).
    pub fn config(&self, base: AssessConfig, per_point: bool) -> AssessConfig {
        let mut c = base;
        c.measure = match self.measure {
            MeasureArg::Full => Measure::Full,
            MeasureArg::Sample => Measure::Sample,
            MeasureArg::None => Measure::None,
        };
        c.per_point = per_point;
        c
    }
}

/// The `measure` object of the `--json` reports: the mode and, when the
/// statistics were taken on samples, their sizes and seed.
pub fn json(a: &Assessment) -> serde_json::Value {
    let mut m = serde_json::json!({ "mode": a.measured.name(), "sampled": a.sample.is_some() });
    if let Some(s) = a.sample {
        m["spacing_sample_points"] = s.spacing_points.into();
        m["parameterization_sample_points"] = s.parameterization_points.into();
        m["seed"] = s.seed.into();
    }
    m
}

/// The line the text reports print under their error table, saying what
/// was sampled or left out (`None` when everything was measured on every
/// point).
pub fn note(a: &Assessment) -> Option<String> {
    if a.measured == Measure::None {
        return Some(
            "(--measure none: orthogonal distances, eq. 17, surface samples and the parameterization were not measured)"
                .into(),
        );
    }
    a.sample.map(|s| {
        format!(
            "(point spacing over a random sample of {} points, fold-overs and stretch over the triangles of a sample of {} points, seed {}; the rest over all {} points; --measure full for every point; samples are taken above {DEFAULT_SAMPLE_POINTS} points)",
            s.spacing_points, s.parameterization_points, s.seed, a.quality.points
        )
    })
}
