//! STEP export of a whole multi-patch model ([`scanfit::topology::PatchComplex`])
//! as one sewn shell: the faces share their edges and vertices.
//!
//! * one `VERTEX_POINT` per model vertex;
//! * one `EDGE_CURVE` per model edge, on its `B_SPLINE_CURVE_WITH_KNOTS`
//!   (clamped form; rational curves as the complex `RATIONAL_B_SPLINE_CURVE`),
//!   from its start to its end vertex, referenced by every face that uses it
//!   through an `ORIENTED_EDGE` whose orientation is the use's direction;
//! * per face one `EDGE_LOOP` of its non-degenerate sides in counter-clockwise
//!   parameter order in a `FACE_OUTER_BOUND`, and an `ADVANCED_FACE` on the
//!   face's `B_SPLINE_SURFACE_WITH_KNOTS`. A degenerate (collapsed) side of a
//!   three-sided face is left out of the loop: STEP has no degenerate edge
//!   without a parameter-space curve, and OpenCASCADE's reader adds the
//!   degenerated edge at the apex itself (checked by `BRepCheck_Analyzer` in
//!   the `model_readback` test);
//! * a closed model (every edge used by two faces) becomes a `CLOSED_SHELL`
//!   in a `MANIFOLD_SOLID_BREP` (`ADVANCED_BREP_SHAPE_REPRESENTATION`), with
//!   every face oriented outwards: the model's faces are consistently
//!   oriented (checked), and when their signed volume
//!   ([`PatchComplex::signed_volume`]) is negative all faces and their bounds
//!   are written with `same_sense = .F.`;
//! * an open model becomes an `OPEN_SHELL` in a `SHELL_BASED_SURFACE_MODEL`
//!   (`MANIFOLD_SURFACE_SHAPE_REPRESENTATION`).
//!
//! The model must pass [`PatchComplex::validate_with`] at
//! [`SHELL_RELATIVE_TOLERANCE`]; the file's uncertainty (the tolerance a CAD
//! system sews with) is the larger of `1e-7` and twice the largest measured
//! boundary gap, so that the shell the reader builds is closed.

use scanfit::topology::PatchComplex;

use crate::step::{begin, curve_entity, finish, list, surface_entity};
use crate::units::CadOptions;
use crate::{Error, Result};

/// Largest gap, relative to the model's size, that [`step_shell_file`]
/// accepts between a face and its edge curves.
pub const SHELL_RELATIVE_TOLERANCE: f64 = 1e-6;

/// What kind of shell [`step_shell_file`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShellKind {
    /// `CLOSED_SHELL` in a `MANIFOLD_SOLID_BREP`.
    Closed,
    /// `OPEN_SHELL` in a `SHELL_BASED_SURFACE_MODEL`.
    Open,
}

/// The written file and facts about it.
#[derive(Debug, Clone, PartialEq)]
pub struct StepShell {
    /// The STEP text.
    pub text: String,
    /// Closed (a solid) or open.
    pub kind: ShellKind,
    /// True when the faces were written with `same_sense = .F.` because their
    /// normals pointed inwards.
    pub flipped: bool,
    /// Signed volume of the model as given (0 for an open model).
    pub volume: f64,
    /// Largest measured gap between a face and its edges (model units).
    pub max_gap: f64,
}

/// A STEP file holding `model` as one sewn shell; `name` names the product.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::topology::{FaceCorners, PatchComplex};
/// use scanfit::Point3;
/// use scanfit_io::step_shell::{step_shell_file, ShellKind};
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
/// let sq = |x0: f64| Surface::new(k.clone(), k.clone(),
///     vec![p(x0, 0.0), p(x0, 1.0), p(x0 + 1.0, 0.0), p(x0 + 1.0, 1.0)]).unwrap();
/// let verts = vec![p(0.0, 0.0), p(1.0, 0.0), p(2.0, 0.0), p(0.0, 1.0), p(1.0, 1.0), p(2.0, 1.0)];
/// let model = PatchComplex::assemble(verts, vec![
///     FaceCorners { id: 1, surface: sq(0.0), corners: [0, 1, 4, 3] },
///     FaceCorners { id: 2, surface: sq(1.0), corners: [1, 2, 5, 4] },
/// ]).unwrap();
/// let step = step_shell_file(&model, "two squares").unwrap();
/// assert_eq!(step.kind, ShellKind::Open);
/// // the shared edge is written once
/// assert_eq!(step.text.matches("EDGE_CURVE(").count(), 7);
/// assert_eq!(step.text.matches("ADVANCED_FACE(").count(), 2);
/// ```
pub fn step_shell_file(model: &PatchComplex, name: &str) -> Result<StepShell> {
    step_shell_file_with(model, name, &CadOptions::default())
}

/// [`step_shell_file`] written with `options` (the declared length unit).
pub fn step_shell_file_with(
    model: &PatchComplex,
    name: &str,
    options: &CadOptions,
) -> Result<StepShell> {
    let bad = |m: String| Error::Invalid {
        path: name.into(),
        message: m,
    };
    model
        .validate_with(SHELL_RELATIVE_TOLERANCE)
        .map_err(|e| bad(format!("the model is not a valid sewn shell: {e}")))?;
    let max_gap = model
        .max_boundary_gap()
        .map_err(|e| bad(format!("measuring the gaps: {e}")))?;
    let closed = model.is_closed();
    let volume = if closed { model.signed_volume() } else { 0.0 };
    let flipped = closed && volume < 0.0;
    if closed && (volume.is_nan() || volume == 0.0) {
        return Err(bad(format!(
            "the closed model encloses no volume (signed volume {volume:e}); its faces must bound a solid"
        )));
    }
    let uncertainty = (2.0 * max_gap).max(1e-7);
    let (mut w, pre) = begin(name, uncertainty, options.units);
    let (ctx, axis) = (pre.ctx, pre.axis);
    let esc = pre.esc.clone();
    let vps: Vec<usize> = model
        .vertices
        .iter()
        .map(|v| {
            let pt = w.point(&v.point);
            w.add(&format!("VERTEX_POINT('',#{pt})"))
        })
        .collect();
    let mut ecs = Vec::with_capacity(model.edges.len());
    for (ei, e) in model.edges.iter().enumerate() {
        let c = e
            .curve
            .to_clamped()
            .map_err(|err| bad(format!("edge {ei}: {err}")))?;
        let cid = curve_entity(&mut w, &c);
        ecs.push(w.add(&format!(
            "EDGE_CURVE('',#{},#{},#{cid},.T.)",
            vps[e.start], vps[e.end]
        )));
    }
    let sense = if flipped { ".F." } else { ".T." };
    let mut faces = Vec::with_capacity(model.faces.len());
    for (fi, f) in model.faces.iter().enumerate() {
        let s = f
            .surface
            .to_clamped()
            .map_err(|err| bad(format!("face {fi} (patch {}): {err}", f.id)))?;
        let surf = surface_entity(&mut w, &s);
        let oes: Vec<usize> = f
            .sides
            .iter()
            .flatten()
            .map(|u| {
                let o = if u.reversed { ".F." } else { ".T." };
                w.add(&format!("ORIENTED_EDGE('',*,*,#{},{o})", ecs[u.edge]))
            })
            .collect();
        let lp = w.add(&format!(
            "EDGE_LOOP('',{})",
            list(&oes, |i| format!("#{i}"))
        ));
        let fb = w.add(&format!("FACE_OUTER_BOUND('',#{lp},{sense})"));
        faces.push(w.add(&format!("ADVANCED_FACE('',(#{fb}),#{surf},{sense})")));
    }
    let face_list = list(&faces, |i| format!("#{i}"));
    let rep = if closed {
        let shell = w.add(&format!("CLOSED_SHELL('',{face_list})"));
        let brep = w.add(&format!("MANIFOLD_SOLID_BREP('{esc}',#{shell})"));
        w.add(&format!(
            "ADVANCED_BREP_SHAPE_REPRESENTATION('{esc}',(#{brep},#{axis}),#{ctx})"
        ))
    } else {
        let shell = w.add(&format!("OPEN_SHELL('',{face_list})"));
        let model = w.add(&format!("SHELL_BASED_SURFACE_MODEL('{esc}',(#{shell}))"));
        w.add(&format!(
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('{esc}',(#{model},#{axis}),#{ctx})"
        ))
    };
    let text = finish(w, &pre, rep, "scanfit multi-patch model");
    Ok(StepShell {
        text,
        kind: if closed {
            ShellKind::Closed
        } else {
            ShellKind::Open
        },
        flipped,
        volume,
        max_gap,
    })
}
