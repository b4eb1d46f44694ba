//! The outputs every surface pipeline writes, one way for all of them
//! (`fit`, `mba`, ...): the surface as JSON, STEP and IGES, a mesh (OBJ, PLY
//! or glb) carrying the local fit error, a shaded picture with the points
//! and a picture coloured by the fit error.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;
use scanfit::bspline::{tessellate, Surface};
use scanfit::metrics::{nearest_points, ErrorStats};
use scanfit::pipeline::SurfaceQuality;
use scanfit::trim::TrimmedSurface;
use scanfit::Point3;
use scanfit_io::gltf::mesh_glb;
use scanfit_io::json::{Provenance, SurfaceDoc, SurfaceQualityDoc};
use scanfit_io::ply::{mesh_obj, mesh_ply, points_ply, points_xyz, PlyFormat};
use scanfit_io::render::{
    format_value, render_surface_scene_png, viridis, ColourScale, Colouring, Marker, Polyline,
    RenderOptions, DEVIATION_PERCENTILE,
};
use scanfit_io::step::CadItem;

use crate::table::{num, Table};

/// `-o`, `--step`, `--iges`, `--mesh`, `--png`, `--deviation-png` and the camera.
#[derive(Args, Debug)]
pub struct SurfaceOutputArgs {
    /// Write the surface as JSON (schema scanfit/1).
    #[arg(short, long, value_name = "SURFACE.json")]
    pub output: Option<PathBuf>,
    /// Write the surface as a STEP file (AP214; a face in an open shell).
    #[arg(long, value_name = "OUT.stp")]
    pub step: Option<PathBuf>,
    /// Write the same as an IGES 5.3 file (entity 126 or 128).
    #[arg(long, value_name = "OUT.igs")]
    pub iges: Option<PathBuf>,
    /// Write a triangle mesh of the surface (.obj, .ply or .glb; PLY and glb
    /// carry the local fit error, the deviation of each vertex's nearest
    /// input point, as a colour from 0 to its 99th percentile, PLY also as
    /// the property `deviation`).
    #[arg(long, value_name = "OUT")]
    pub mesh: Option<PathBuf>,
    /// Write a shaded, height-coloured picture with the input points.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Write a picture of the surface coloured by the local fit error (the
    /// deviation of the nearest input point), with a colour bar and the
    /// error figures.
    #[arg(long, value_name = "OUT.png")]
    pub deviation_png: Option<PathBuf>,
    /// Write the surface even when it leaves the data (samples farther
    /// outside the points' bounding box than 10 point spacings and a quarter
    /// of its diagonal).
    #[arg(long)]
    pub allow_extrapolation: bool,
    #[command(flatten)]
    pub measure: crate::measure::MeasureArgs,
    #[command(flatten)]
    pub units: crate::cad::UnitsArgs,
    #[command(flatten)]
    pub view: crate::view::ViewArgs,
}

/// The lower-case extension of `p`.
pub fn extension(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Fails unless each given path ends in one of its allowed extensions.
pub fn check_extensions(outputs: &[(&Option<PathBuf>, &str, &[&str])]) -> Result<()> {
    for (p, what, allowed) in outputs {
        if let Some(p) = p {
            if !allowed.contains(&extension(p).as_str()) {
                bail!(
                    "{what} {}: the file name must end in .{}",
                    p.display(),
                    allowed.join(" or .")
                );
            }
        }
    }
    Ok(())
}

/// The one check every command makes before any work: each given output
/// ends in one of its allowed extensions, no output is given twice, and no
/// output is one of the `inputs` (after following symlinks), so a run never
/// overwrites its own input.
pub fn check_outputs(
    inputs: &[&Path],
    outputs: &[(&Option<PathBuf>, &str, &[&str])],
) -> Result<()> {
    let given: Vec<&PathBuf> = outputs.iter().filter_map(|(p, _, _)| p.as_ref()).collect();
    scanfit_io::check_paths(inputs, &given)?;
    check_extensions(outputs)
}

/// Output files: path and content, written together at the end.
pub type Files = Vec<(PathBuf, Vec<u8>)>;

/// How the `--png` picture colours the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PngStyle {
    /// Shaded and coloured by height (fit, mba).
    #[default]
    Height,
    /// Coloured by the local fit error, with a colour bar (coons).
    Deviation,
}

/// What a pipeline adds to its pictures: its style of `--png`, lines
/// (boundary curves) and markers (corners) drawn on top, and legend lines.
#[derive(Debug, Clone, Default)]
pub struct Picture {
    /// Colouring of `--png`.
    pub style: PngStyle,
    /// Curves over the surface.
    pub lines: Vec<Polyline>,
    /// Labelled markers over the curves.
    pub markers: Vec<Marker>,
    /// Legend lines of `--png` (the deviation picture has its own).
    pub legend: Vec<String>,
    /// The points whose deviations set the colour scale (its 99th
    /// percentile and maximum), one flag per point [default: all]; e.g. the
    /// fitted points of `turntable`, whose caps are left out of the fit.
    pub scale_points: Option<Vec<bool>>,
}

/// How far the input points are from the surface, as the pictures and the
/// mesh colours show it.
pub struct Deviation<'a> {
    /// One value per input point (orthogonal or vertical distance, >= 0).
    pub per_point: &'a [f64],
    /// Its statistics, printed in the picture's legend.
    pub stats: ErrorStats,
    /// What it is, e.g. "orthogonal distance" or "vertical distance |z - f(x, y)|".
    pub name: &'a str,
}

impl SurfaceOutputArgs {
    /// Checks the output file names before any work is done.
    pub fn check(&self, input: &Path, extra: &[(&Option<PathBuf>, &str, &[&str])]) -> Result<()> {
        let mut all: Vec<(&Option<PathBuf>, &str, &[&str])> = vec![
            (&self.output, "--output", &["json"][..]),
            (&self.mesh, "--mesh", &["obj", "ply", "glb"][..]),
            (&self.deviation_png, "--deviation-png", &["png"][..]),
            (&self.png, "--png", &["png"][..]),
            (&self.step, "--step", &["stp", "step"][..]),
            (&self.iges, "--iges", &["igs", "iges"][..]),
        ];
        all.extend_from_slice(extra);
        check_outputs(&[input], &all)
    }

    /// Whether an output shows the per-point deviation (`--deviation-png`,
    /// a PLY or glb `--mesh`, `--png` in the deviation style), so the
    /// assessment must keep it.
    pub fn needs_deviation(&self, style: PngStyle) -> bool {
        self.deviation_png.is_some()
            || (self.png.is_some() && style == PngStyle::Deviation)
            || self.mesh.as_deref().is_some_and(|m| extension(m) != "obj")
    }

    /// Refuses `--measure none` when an output (`extra`: the command's own,
    /// e.g. `--points-out`) shows the orthogonal distances it leaves out.
    pub fn check_measured(&self, style: PngStyle, extra: Option<&str>) -> Result<()> {
        if self.measure.measure != crate::measure::MeasureArg::None {
            return Ok(());
        }
        let what = if self.needs_deviation(style) {
            Some("the deviation picture and the PLY/glb mesh colours")
        } else {
            extra
        };
        if let Some(what) = what {
            bail!("{what} show the orthogonal distances, which --measure none leaves out; use --measure sample (the default)");
        }
        Ok(())
    }

    /// Fails with one line that says how far the surface left the data and
    /// what to try (`fix`, the command's own options), unless
    /// `--allow-extrapolation` is given.
    pub fn guard(&self, q: &SurfaceQuality, fix: &str) -> Result<()> {
        crate::extent::check(&q.extent, self.allow_extrapolation, fix)
    }

    /// The bytes of every requested output of `surface` fitted to `points`
    /// from `input`, and the vertical exaggeration of the shaded picture.
    pub fn files(
        &self,
        surface: &Surface,
        doc: &SurfaceDoc,
        points: &[Point3],
        deviation: &Deviation,
        input: &Path,
        picture: &Picture,
    ) -> Result<(Files, f64)> {
        self.files_with(surface, None, doc, points, deviation, input, picture)
    }

    /// [`Self::files`] of a surface that may be trimmed: with `trimmed`,
    /// the CAD files hold the trimmed face and the mesh and pictures show
    /// only the trimmed part.
    #[allow(clippy::too_many_arguments)]
    pub fn files_with(
        &self,
        surface: &Surface,
        trimmed: Option<&TrimmedSurface>,
        doc: &SurfaceDoc,
        points: &[Point3],
        deviation: &Deviation,
        input: &Path,
        picture: &Picture,
    ) -> Result<(Files, f64)> {
        let mut files: Files = Vec::new();
        if let Some(o) = &self.output {
            // the document carries the trimming loops, so `export` and
            // `report` of the saved surface keep the trimmed face
            let mut doc = doc.clone();
            doc.set_trim(trimmed);
            files.push((o.clone(), doc.to_json()?.into_bytes()));
        }
        let item = trimmed.map_or(CadItem::Surface(surface), CadItem::Trimmed);
        files.extend(
            crate::cad::cad_files(&self.step, &self.iges, item, input, &self.units.options())?
                .into_iter()
                .map(|(p, b)| (p.to_path_buf(), b)),
        );
        let wants_mesh = self.mesh.is_some() || self.png.is_some() || self.deviation_png.is_some();
        if !wants_mesh {
            return Ok((files, 1.0));
        }
        let (cu, cv) = surface.counts();
        let (nu, nv) = ((cu * 4).clamp(32, 400), (cv * 4).clamp(32, 400));
        let mesh = match trimmed {
            Some(t) => t.tessellate(nu, nv),
            None => tessellate(surface, nu, nv),
        };
        // the local fit error on the surface: each mesh vertex shows the
        // deviation of its nearest input point, on the scale of the error table
        let vertex_dev = if self.needs_deviation(picture.style) {
            let near = nearest_points(points, &mesh.vertices)?;
            Some(
                near.iter()
                    .map(|&(i, _)| deviation.per_point[i])
                    .collect::<Vec<f64>>(),
            )
        } else {
            None
        };
        let scene = Scene {
            mesh: &mesh,
            points,
            vertex_dev: vertex_dev.as_deref(),
            deviation,
            input,
            picture,
        };
        if let Some(m) = &self.mesh {
            // the mesh colours on the pictures' scale (0 to the 99th percentile)
            let top = scene.deviation_scale(self.units.label()).range.1;
            let bytes = mesh_file(m, &mesh, vertex_dev.as_deref(), top, input);
            files.push((m.clone(), bytes));
        }
        if let (Some(dp), Some(_)) = (&self.deviation_png, &vertex_dev) {
            files.push((dp.clone(), self.deviation_picture(&scene)?));
        }
        let mut exaggeration = 1.0;
        if let Some(png) = &self.png {
            let (bytes, z) = self.shaded_picture(&scene)?;
            exaggeration = z;
            files.push((png.clone(), bytes));
        }
        Ok((files, exaggeration))
    }

    /// The render options of `points`' pictures, in `--units`.
    fn render_options(&self, points: &[Point3]) -> Result<RenderOptions> {
        Ok(RenderOptions {
            units: self.units.label().into(),
            ..self.view.options(points)?
        })
    }

    /// `--deviation-png`: the surface coloured by the local fit error.
    fn deviation_picture(&self, s: &Scene) -> Result<Vec<u8>> {
        let d = s.vertex_dev.unwrap_or(&[]);
        let scale = s.deviation_scale(self.units.label());
        let opts = RenderOptions {
            legend: s.deviation_legend(&scale, self.units.label()),
            ..self.render_options(s.points)?
        };
        let colouring = Colouring::Scalar {
            values: d,
            scale: &scale,
        };
        Ok(render_surface_scene_png(
            s.mesh,
            None,
            colouring,
            &s.picture.lines,
            &s.picture.markers,
            &opts,
        )?)
    }

    /// `--png`: the shaded picture with the points, and its exaggeration.
    fn shaded_picture(&self, s: &Scene) -> Result<(Vec<u8>, f64)> {
        // at most 5,000 points drawn, evenly picked; flat data (terrain) exaggerated
        let step = (s.points.len() / 5_000).max(1);
        let shown: Vec<_> = s.points.iter().step_by(step).copied().collect();
        let mut opts = self.render_options(s.points)?;
        let scale = s.deviation_scale(self.units.label());
        let colouring = match (s.picture.style, s.vertex_dev) {
            (PngStyle::Deviation, Some(d)) => {
                opts.legend = s.deviation_legend(&scale, self.units.label());
                Colouring::Scalar {
                    values: d,
                    scale: &scale,
                }
            }
            _ => {
                opts.legend = vec![format!(
                    "{}: the surface coloured by height, red dots = input points",
                    s.input.display()
                )];
                Colouring::Height
            }
        };
        opts.legend.extend(s.picture.legend.iter().cloned());
        let bytes = render_surface_scene_png(
            s.mesh,
            Some(&shown),
            colouring,
            &s.picture.lines,
            &s.picture.markers,
            &opts,
        )?;
        Ok((bytes, opts.z_scale))
    }
}

/// What the pictures of a surface show.
struct Scene<'a> {
    mesh: &'a scanfit::bspline::Mesh,
    points: &'a [Point3],
    vertex_dev: Option<&'a [f64]>,
    deviation: &'a Deviation<'a>,
    input: &'a Path,
    picture: &'a Picture,
}

impl Scene<'_> {
    /// The colour scale of the local fit error: 0 to the 99th percentile of
    /// the points' deviations, the maximum on the bar.
    fn deviation_scale(&self, units: &str) -> ColourScale {
        let name = format!("{} [{units}]", self.deviation.name);
        let all = self.deviation.per_point;
        match &self.picture.scale_points {
            Some(mask) => {
                let some: Vec<f64> = all
                    .iter()
                    .zip(mask)
                    .filter(|(_, &m)| m)
                    .map(|(&d, _)| d)
                    .collect();
                ColourScale::deviation(name, &some, DEVIATION_PERCENTILE)
            }
            None => ColourScale::deviation(name, all, DEVIATION_PERCENTILE),
        }
    }

    /// The legend of a picture coloured by the local fit error.
    fn deviation_legend(&self, scale: &ColourScale, units: &str) -> Vec<String> {
        let d = self.deviation;
        let clip = match scale.high {
            Some(c) => format!(
                "; colours from 0 to the {}th percentile {} (max {})",
                c.percentile,
                format_value(scale.range.1),
                format_value(c.extreme)
            ),
            None => String::new(),
        };
        vec![
            format!(
                "{}: colour = {} of the nearest input point [{units}]{clip}",
                self.input.display(),
                d.name
            ),
            format!(
                "input points to surface ({}): mean {}  max {}  RMSE {}  [{units}]",
                d.name,
                num(d.stats.mean),
                num(d.stats.max),
                num(d.stats.rmse)
            ),
        ]
    }
}

/// The bytes of `--mesh` by its extension: OBJ, glb or PLY (the last two
/// coloured by the local fit error `vertex_dev` on the scale `[0, dmax]`,
/// larger values at the top colour).
fn mesh_file(
    path: &Path,
    mesh: &scanfit::bspline::Mesh,
    vertex_dev: Option<&[f64]>,
    dmax: f64,
    input: &Path,
) -> Vec<u8> {
    let colours: Option<Vec<[u8; 3]>> = vertex_dev.map(|d| {
        d.iter()
            .map(|&x| {
                viridis(if dmax > 0.0 { x / dmax } else { 0.0 }).map(|c| (c * 255.0).round() as u8)
            })
            .collect()
    });
    let name = input
        .file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    match extension(path).as_str() {
        "obj" => mesh_obj(
            mesh,
            &format!("scanfit surface fitted to {}", input.display()),
        ),
        "glb" => mesh_glb(mesh, colours.as_deref(), &name),
        _ => mesh_ply(
            mesh,
            vertex_dev.map(|d| ("deviation", d)),
            colours.as_deref(),
            PlyFormat::Binary,
        ),
    }
}

/// The bytes of a point file with per-point attributes: binary PLY for
/// `.ply`, XYZ text otherwise (the callers check the extension first).
pub fn points_file(path: &Path, points: &[Point3], attributes: &[(&str, &[f64])]) -> Vec<u8> {
    if extension(path) == "ply" {
        points_ply(points, attributes, PlyFormat::Binary)
    } else {
        points_xyz(points, attributes)
    }
}

/// Prints `wrote FILE` for each file, naming the exaggeration of `png`.
pub fn print_written(files: &Files, png: Option<&Path>, exaggeration: f64) -> Result<()> {
    for (p, _) in files {
        if png == Some(p.as_path()) && exaggeration != 1.0 {
            outln!(
                "wrote {} (vertical exaggeration {exaggeration}x)",
                p.display()
            );
        } else {
            outln!("wrote {}", p.display());
        }
    }
    Ok(())
}

/// The JSON quality record of a surface: the library's one assessment
/// ([`SurfaceQuality`]) in the schema's field names, with the RMSE after each
/// parameter-correction round (empty when there were none).
pub fn quality_doc(q: &SurfaceQuality, correction_rmse: Vec<f64>) -> SurfaceQualityDoc {
    SurfaceQualityDoc {
        points: q.points,
        mean_error: q.at_parameters.mean,
        max_error: q.at_parameters.max,
        rmse: q.at_parameters.rmse,
        mean_distance: q.orthogonal.mean,
        max_distance: q.orthogonal.max,
        rmse_distance: q.orthogonal.rmse,
        unconverged: q.unconverged,
        grid_rmse: q.grid_rmse,
        triangles: q.parameterization.triangles,
        fold_overs: q.parameterization.fold_overs,
        l2_stretch: q.parameterization.l2_stretch,
        max_anisotropy: q.parameterization.max_anisotropy,
        correction_rmse,
    }
}

/// The surface-to-points measures of [`SurfaceQuality`] for `--json`
/// reports (the surface document's schema has no place for them).
pub fn samples_json(q: &SurfaceQuality) -> serde_json::Value {
    let s = &q.samples_to_points;
    serde_json::json!({
        "samples": s.stats.count,
        "grid": [s.grid.0, s.grid.1],
        "mean": s.stats.mean,
        "max": s.stats.max,
        "rmse": s.stats.rmse,
        "point_spacing": s.spacing,
        "far_spacings": s.far_spacings,
        "far_share": s.far_share,
        "outside_box": q.extent.samples_outside,
        "outside_box_spacings": q.extent.samples_outside_spacings,
        "control_net_outside_box": q.extent.control_outside,
        "leaves_data": q.extent.leaves,
    })
}

/// The provenance every command writes into its documents: this tool and
/// version, what ran (`operation`), how the points got their parameters,
/// the input file, the point count and the settings.
pub fn provenance(
    operation: impl Into<String>,
    parameterization: Option<String>,
    input: &Path,
    point_count: usize,
    settings: BTreeMap<String, serde_json::Value>,
) -> Provenance {
    Provenance {
        tool: format!("scanfit {}", env!("CARGO_PKG_VERSION")),
        operation: operation.into(),
        parameterization,
        input: Some(input.display().to_string()),
        point_count: Some(point_count),
        settings,
    }
}

/// The rows every surface error table ends with: the orthogonal distance
/// of the points to the surface, the MBA paper's eq. 17 and the surface
/// samples' distance to the nearest point with the share beyond
/// `far_spacings` point spacings. `eq17` labels the eq. 17 row.
pub fn quality_rows(t: &mut Table, q: &SurfaceQuality, eq17: &str) {
    let data = || "data units".to_string();
    if q.orthogonal.count == 0 {
        // --measure none
        for what in [
            "orthogonal distance to the surface",
            eq17,
            "surface samples to nearest point",
        ] {
            t.row(vec![
                what.into(),
                "-".into(),
                "-".into(),
                "-".into(),
                "not measured".into(),
            ]);
        }
        return;
    }
    t.row(vec![
        "orthogonal distance to the surface".into(),
        num(q.orthogonal.mean),
        num(q.orthogonal.max),
        num(q.orthogonal.rmse),
        data(),
    ]);
    t.row(vec![
        eq17.into(),
        "-".into(),
        "-".into(),
        num(q.grid_rmse),
        data(),
    ]);
    let s = &q.samples_to_points;
    t.row(vec![
        format!(
            "surface samples to nearest point ({:.1}% beyond {} spacings)",
            100.0 * s.far_share,
            s.far_spacings
        ),
        num(s.stats.mean),
        num(s.stats.max),
        num(s.stats.rmse),
        data(),
    ]);
}
