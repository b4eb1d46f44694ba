//! The CAD outputs shared by the fitting commands: `--step` and `--iges`.

use std::path::{Path, PathBuf};

use anyhow::Result;
use scanfit_io::iges::iges_file;
use scanfit_io::step::{step_file, CadItem};

/// The STEP and IGES files requested, named after the input's file stem.
pub fn cad_files<'a>(
    step: &'a Option<PathBuf>,
    iges: &'a Option<PathBuf>,
    item: CadItem,
    input: &Path,
) -> Result<Vec<(&'a Path, Vec<u8>)>> {
    let name = input
        .file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut files = Vec::new();
    if let Some(s) = step {
        files.push((s.as_path(), step_file(&[item], &name)?.into_bytes()));
    }
    if let Some(i) = iges {
        files.push((i.as_path(), iges_file(&[item], &name)?.into_bytes()));
    }
    Ok(files)
}
