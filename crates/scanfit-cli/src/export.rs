//! `scanfit export`: several curves and surfaces (scanfit JSON documents)
//! into one STEP and/or IGES file, e.g. the patches of a multi-patch result.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use scanfit::bspline::{Curve, Surface};
use scanfit::trim::TrimmedSurface;
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
128 in the IGES file), every curve a B-spline curve (entity 126). A surface
saved trimmed (its document has a `trim` section) stays trimmed: a face bounded
by its loops in STEP, entity 144 with 142 in IGES.";

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
    /// A surface whose document carries trimming loops.
    Trimmed(Box<TrimmedSurface>),
}

/// The surface of the document at `path`, trimmed when it says so.
fn read_face(path: &Path) -> Result<Item> {
    let (doc, surface) = read_surface(path)?;
    Ok(match doc.trimmed(&surface) {
        Ok(Some(t)) => Item::Trimmed(Box::new(t)),
        Ok(None) => Item::Surface(surface),
        Err(e) => bail!("{}: {e}", path.display()),
    })
}

fn read_item(path: &Path) -> Result<Item> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let kind = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v.get("type").and_then(|k| k.as_str()).map(String::from));
    match kind.as_deref() {
        Some("bspline_curve") => Ok(Item::Curve(read_curve(path)?.1)),
        // otherwise let the surface reader say what is wrong with the document
        _ => read_face(path),
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
            Item::Trimmed(t) => CadItem::Trimmed(t),
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
    let count = |f: fn(&Item) -> bool| items.iter().filter(|i| f(i)).count();
    let nc = count(|i| matches!(i, Item::Curve(_)));
    let ns = count(|i| !matches!(i, Item::Curve(_)));
    let nt = count(|i| matches!(i, Item::Trimmed(_)));
    for (p, _) in &files {
        outln!(
            "wrote {} ({nc} curves, {ns} surfaces, {nt} of them trimmed)",
            p.display()
        );
    }
    Ok(())
}
