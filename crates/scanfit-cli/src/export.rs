//! `scanfit export`: several curves and surfaces (scanfit JSON documents)
//! into one STEP and/or IGES file, e.g. the patches of a multi-patch result.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::bspline::{Curve, Surface};
use scanfit_io::iges::iges_file_with;
use scanfit_io::json::{read_curve, read_surface};
use scanfit_io::step::{step_file_with, CadItem};
use scanfit_io::write_all_atomic;

use crate::outputs::check_outputs;

const EXAMPLES: &str = "Examples:
  scanfit export left.json right.json top.json --step panel.stp --iges panel.igs
  scanfit export curve.json surface.json --step both.stp

Each input is a curve or surface document written by scanfit (-o SURFACE.json);
every surface becomes a face of one open shell in the STEP file (and an entity
128 in the IGES file), every curve a B-spline curve (entity 126).";

/// Arguments of `scanfit export`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct ExportArgs {
    /// Curve and surface JSON documents (schema scanfit/1).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Write one STEP file (AP214) with all of them.
    #[arg(long, value_name = "OUT.stp")]
    pub step: Option<PathBuf>,
    /// Write one IGES 5.3 file with all of them.
    #[arg(long, value_name = "OUT.igs")]
    pub iges: Option<PathBuf>,
    /// Product name in the files [default: the first input's file stem].
    #[arg(long)]
    pub name: Option<String>,
    #[command(flatten)]
    pub units: crate::cad::UnitsArgs,
}

/// A curve or a surface read from a document.
enum Item {
    Curve(Curve),
    Surface(Surface),
}

fn read_item(path: &Path) -> Result<Item> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let kind = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v.get("type").and_then(|k| k.as_str()).map(String::from));
    match kind.as_deref() {
        Some("bspline_curve") => Ok(Item::Curve(read_curve(path)?.1)),
        Some("bspline_surface") => Ok(Item::Surface(read_surface(path)?.1)),
        _ => {
            // let the surface reader say what is wrong with the document
            Ok(Item::Surface(read_surface(path)?.1))
        }
    }
}

/// Runs `scanfit export`.
pub fn run(a: ExportArgs) -> Result<()> {
    let inputs: Vec<&Path> = a.inputs.iter().map(PathBuf::as_path).collect();
    check_outputs(
        &inputs,
        &[
            (&a.step, "--step", &["stp", "step"][..]),
            (&a.iges, "--iges", &["igs", "iges"][..]),
        ],
    )?;
    if a.step.is_none() && a.iges.is_none() {
        bail!("nothing to write: give --step OUT.stp and/or --iges OUT.igs");
    }
    let items: Vec<Item> = a
        .inputs
        .iter()
        .map(|p| read_item(p))
        .collect::<Result<_>>()?;
    let cad: Vec<CadItem> = items
        .iter()
        .map(|i| match i {
            Item::Curve(c) => CadItem::Curve(c),
            Item::Surface(s) => CadItem::Surface(s),
        })
        .collect();
    let name = a.name.clone().unwrap_or_else(|| {
        a.inputs[0]
            .file_stem()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    });
    let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
    if let Some(s) = &a.step {
        files.push((
            s,
            step_file_with(&cad, &name, &a.units.options())?.into_bytes(),
        ));
    }
    if let Some(i) = &a.iges {
        files.push((
            i,
            iges_file_with(&cad, &name, &a.units.options())?.into_bytes(),
        ));
    }
    write_all_atomic(&files)?;
    let (nc, ns) = items.iter().fold((0, 0), |(c, s), i| match i {
        Item::Curve(_) => (c + 1, s),
        Item::Surface(_) => (c, s + 1),
    });
    for (p, _) in &files {
        outln!("wrote {} ({nc} curves, {ns} surfaces)", p.display());
    }
    Ok(())
}
