//! STEP (ISO 10303-21, AP214 "automotive_design") export of B-spline curves
//! and surfaces.
//!
//! Periodic and other unclamped curves and surfaces are first converted to the
//! clamped form of the same shape. Every surface becomes an `ADVANCED_FACE` bounded by its four
//! boundary curves (exact: the boundary rows and columns of the control net) in
//! one `OPEN_SHELL` of a `SHELL_BASED_SURFACE_MODEL`
//! (`MANIFOLD_SURFACE_SHAPE_REPRESENTATION`), so that CAD systems that import
//! only shells show it; the surface entity itself is the bare geometry.
//! Curves go to a `GEOMETRIC_CURVE_SET` in a
//! `GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION`. Several surfaces and
//! curves share one file and one product. Rational curves and surfaces use the
//! complex-entity forms (`RATIONAL_B_SPLINE_*`). Lengths are declared in
//! millimetres unless [`CadOptions::units`] says otherwise (the data's own
//! values are kept unscaled; see [`crate::units`]).
//!
//! A trimmed surface ([`CadItem::Trimmed`]) becomes an `ADVANCED_FACE`
//! bounded by a `FACE_OUTER_BOUND` (its outer trim curve, or the four
//! boundary curves when it keeps its rectangle) and one `FACE_BOUND` per
//! hole; each trim loop is an `EDGE_LOOP` of one closed `EDGE_CURVE` whose
//! geometry is a `SURFACE_CURVE`: the 3D B-spline curve and a `PCURVE` on
//! the face's surface holding the 2D B-spline curve in the surface's
//! parameter space (a `DEFINITIONAL_REPRESENTATION` in a 2D
//! `PARAMETRIC_REPRESENTATION_CONTEXT`), as CAD systems expect of a trimmed
//! face. The file's uncertainty is then the larger of `1e-7` and twice the
//! largest deviation between a 3D trim curve and its pcurve's image.

use std::fmt::Write as _;

use scanfit::bspline::{Curve, KnotVector, Surface};
use scanfit::trim::{TrimCurve, TrimmedSurface};
use scanfit::Point3;

use crate::units::{CadOptions, LengthUnit};
use crate::{Error, Result};

/// Something to export.
#[derive(Debug, Clone, Copy)]
pub enum CadItem<'a> {
    /// A B-spline or NURBS curve.
    Curve(&'a Curve),
    /// A B-spline or NURBS surface.
    Surface(&'a Surface),
    /// A surface bounded by trim curves ([`scanfit::trim::trim_surface`]).
    Trimmed(&'a TrimmedSurface),
}

/// Entity text being written, with the next free entity id.
pub(crate) struct Writer {
    data: String,
    next: usize,
}

impl Writer {
    /// Appends `#id=entity;` and returns the id.
    pub(crate) fn add(&mut self, entity: &str) -> usize {
        let id = self.next;
        self.next += 1;
        let _ = writeln!(self.data, "#{id}={entity};");
        id
    }
    /// Appends a `CARTESIAN_POINT`.
    pub(crate) fn point(&mut self, p: &Point3) -> usize {
        self.add(&format!(
            "CARTESIAN_POINT('',({},{},{}))",
            real(p.x),
            real(p.y),
            real(p.z)
        ))
    }
}

/// A STEP (and IGES) real: always with a decimal point, shortest round-trip digits.
pub(crate) fn real(v: f64) -> String {
    let s = format!("{v:?}");
    let (mant, exp) = match s.split_once('e') {
        Some((m, e)) => (m.to_string(), Some(e.to_string())),
        None => (s, None),
    };
    let mant = if mant.contains('.') {
        mant
    } else {
        format!("{mant}.")
    };
    match exp {
        Some(e) => format!("{mant}E{e}"),
        None => mant,
    }
}

/// Distinct knots and their multiplicities.
fn knots_mults(kv: &KnotVector) -> (Vec<f64>, Vec<usize>) {
    let mut k: Vec<f64> = Vec::new();
    let mut m: Vec<usize> = Vec::new();
    for &t in kv.as_slice() {
        if k.last() == Some(&t) {
            if let Some(x) = m.last_mut() {
                *x += 1;
            }
        } else {
            k.push(t);
            m.push(1);
        }
    }
    (k, m)
}

pub(crate) fn list<T>(items: &[T], f: impl Fn(&T) -> String) -> String {
    let v: Vec<String> = items.iter().map(f).collect();
    format!("({})", v.join(","))
}

/// Writes `curve` (clamped or not) and returns its entity id.
pub(crate) fn curve_entity(w: &mut Writer, c: &Curve) -> usize {
    let ids: Vec<usize> = c.control_points().iter().map(|p| w.point(p)).collect();
    curve_on_points(w, c, &ids)
}

/// Writes a parameter-space curve (its points' `(x, y)` as 2D
/// `CARTESIAN_POINT`s) and returns its entity id.
fn curve_2d_entity(w: &mut Writer, c: &Curve) -> usize {
    let ids: Vec<usize> = c
        .control_points()
        .iter()
        .map(|p| {
            w.add(&format!(
                "CARTESIAN_POINT('',({},{}))",
                real(p.x),
                real(p.y)
            ))
        })
        .collect();
    curve_on_points(w, c, &ids)
}

/// The `B_SPLINE_CURVE_WITH_KNOTS` (or rational complex entity) of `c` on
/// the already written control points `ids`.
fn curve_on_points(w: &mut Writer, c: &Curve, ids: &[usize]) -> usize {
    let (k, m) = knots_mults(c.knots());
    let pts = list(ids, |i| format!("#{i}"));
    let closed = if c.is_closed() { ".T." } else { ".F." };
    let mults = list(&m, |x| x.to_string());
    let knots = list(&k, |x| real(*x));
    match c.weights().filter(|_| c.is_rational()) {
        None => w.add(&format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{},{pts},.UNSPECIFIED.,{closed},.F.,{mults},{knots},.UNSPECIFIED.)",
            c.degree()
        )),
        Some(wt) => w.add(&format!(
            "(BOUNDED_CURVE() B_SPLINE_CURVE({},{pts},.UNSPECIFIED.,{closed},.F.) B_SPLINE_CURVE_WITH_KNOTS({mults},{knots},.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE({}) REPRESENTATION_ITEM(''))",
            c.degree(),
            list(wt, |x| real(*x))
        )),
    }
}

/// Writes `s` and returns its entity id.
pub(crate) fn surface_entity(w: &mut Writer, s: &Surface) -> usize {
    let (nu, nv) = s.counts();
    let (p, q) = s.degrees();
    let ids: Vec<usize> = s.control_points().iter().map(|c| w.point(c)).collect();
    let rows: Vec<String> = (0..nu)
        .map(|i| list(&ids[i * nv..(i + 1) * nv], |k| format!("#{k}")))
        .collect();
    let net = format!("({})", rows.join(","));
    let (ku, mu) = knots_mults(s.knots_u());
    let (kv, mv) = knots_mults(s.knots_v());
    let (pu, pv) = s.periodic();
    let flag = |b: bool| if b { ".T." } else { ".F." };
    let knot_part = format!(
        "{},{},{},{},.UNSPECIFIED.",
        list(&mu, |x| x.to_string()),
        list(&mv, |x| x.to_string()),
        list(&ku, |x| real(*x)),
        list(&kv, |x| real(*x))
    );
    let rational = s.weights().filter(|w| w.iter().any(|&x| x != w[0]));
    match rational {
        None => w.add(&format!(
            "B_SPLINE_SURFACE_WITH_KNOTS('',{p},{q},{net},.UNSPECIFIED.,{},{},.F.,{knot_part})",
            flag(pu),
            flag(pv)
        )),
        Some(wt) => {
            let wrows: Vec<String> = (0..nu)
                .map(|i| list(&wt[i * nv..(i + 1) * nv], |x| real(*x)))
                .collect();
            w.add(&format!(
                "(BOUNDED_SURFACE() B_SPLINE_SURFACE({p},{q},{net},.UNSPECIFIED.,{},{},.F.) B_SPLINE_SURFACE_WITH_KNOTS({knot_part}) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(({})) REPRESENTATION_ITEM('') SURFACE())",
                flag(pu),
                flag(pv),
                wrows.join(",")
            ))
        }
    }
}

/// The four boundary curves of a clamped surface: `v = v0` and `v = v1` along
/// `u`, `u = u0` and `u = u1` along `v` (control points of the boundary rows).
fn boundary_curves(s: &Surface) -> scanfit::Result<[Curve; 4]> {
    let (nu, nv) = s.counts();
    let w = s.weights();
    let row = |i: usize| -> scanfit::Result<Curve> {
        let c: Vec<Point3> = (0..nv).map(|j| s.control_point(i, j)).collect();
        match w {
            Some(w) => {
                Curve::new_rational(s.knots_v().clone(), c, w[i * nv..(i + 1) * nv].to_vec())
            }
            None => Curve::new(s.knots_v().clone(), c),
        }
    };
    let col = |j: usize| -> scanfit::Result<Curve> {
        let c: Vec<Point3> = (0..nu).map(|i| s.control_point(i, j)).collect();
        match w {
            Some(w) => Curve::new_rational(
                s.knots_u().clone(),
                c,
                (0..nu).map(|i| w[i * nv + j]).collect(),
            ),
            None => Curve::new(s.knots_u().clone(), c),
        }
    };
    Ok([col(0)?, row(nu - 1)?, col(nv - 1)?, row(0)?])
}

/// The product, units and representation context every scanfit STEP file starts with.
pub(crate) struct Preamble {
    /// The `GEOMETRIC_REPRESENTATION_CONTEXT` entity.
    pub ctx: usize,
    /// The `AXIS2_PLACEMENT_3D` at the origin.
    pub axis: usize,
    /// The `PRODUCT_DEFINITION_SHAPE` the representation is attached to.
    pub pds: usize,
    /// The product name, quotes escaped.
    pub esc: String,
}

/// Starts a file: application context, product, units (`units` for
/// lengths) and a representation context whose uncertainty is
/// `uncertainty` (length units).
pub(crate) fn begin(name: &str, uncertainty: f64, units: LengthUnit) -> (Writer, Preamble) {
    let mut w = Writer {
        data: String::new(),
        next: 1,
    };
    let app = w.add("APPLICATION_CONTEXT('automotive_design')");
    w.add(&format!(
        "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"
    ));
    let pc = w.add(&format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let pdc = w.add(&format!(
        "PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"
    ));
    let esc = name.replace('\'', "''");
    let prod = w.add(&format!("PRODUCT('{esc}','{esc}','',(#{pc}))"));
    let pdf = w.add(&format!("PRODUCT_DEFINITION_FORMATION('','',#{prod})"));
    let pd = w.add(&format!("PRODUCT_DEFINITION('design','',#{pdf},#{pdc})"));
    let pds = w.add(&format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    let len = units.step_entities(|e| w.add(e));
    let ang = w.add("(NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.))");
    let sol = w.add("(NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT())");
    let unc = w.add(&format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{len},'distance_accuracy_value','confusion accuracy')",
        real_step(uncertainty)
    ));
    let ctx = w.add(&format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc})) GLOBAL_UNIT_ASSIGNED_CONTEXT((#{len},#{ang},#{sol})) REPRESENTATION_CONTEXT('Context #1','3D Context with UNIT and UNCERTAINTY'))"
    ));
    let origin = w.point(&Point3::origin());
    let zdir = w.add("DIRECTION('',(0.,0.,1.))");
    let xdir = w.add("DIRECTION('',(1.,0.,0.))");
    let axis = w.add(&format!("AXIS2_PLACEMENT_3D('',#{origin},#{zdir},#{xdir})"));

    (
        w,
        Preamble {
            ctx,
            axis,
            pds,
            esc,
        },
    )
}

/// The uncertainty as a STEP real; the default 1e-7 keeps its historical
/// spelling `1.E-07` so that existing files (and the golden files) stay
/// byte-identical.
fn real_step(v: f64) -> String {
    if v == 1e-7 {
        "1.E-07".into()
    } else {
        real(v)
    }
}

/// Ends a file: links `rep` to the product and wraps the data in the header.
pub(crate) fn finish(mut w: Writer, pre: &Preamble, rep: usize, description: &str) -> String {
    let (pds, esc) = (pre.pds, &pre.esc);
    w.add(&format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));
    let mut out = String::from("ISO-10303-21;\nHEADER;\n");
    let _ = writeln!(out, "FILE_DESCRIPTION(('{description}'),'2;1');");
    let _ = writeln!(
        out,
        "FILE_NAME('{esc}','2026-01-01T00:00:00',(''),(''),'scanfit {}','scanfit','');",
        env!("CARGO_PKG_VERSION")
    );
    out.push_str("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n");
    out.push_str(&w.data);
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    out
}

/// A STEP file with `items`; `name` names the product. Lengths in millimetres.
pub fn step_file(items: &[CadItem], name: &str) -> Result<String> {
    step_file_with(items, name, &CadOptions::default())
}

/// A STEP file with `items`, `name` naming the product, written with `options`
/// (the declared length unit).
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::Point3;
/// use scanfit_io::step::{step_file_with, CadItem};
/// use scanfit_io::units::{CadOptions, LengthUnit};
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
/// let s = Surface::new(k.clone(), k, vec![p(0., 0.), p(0., 1.), p(1., 0.), p(1., 1.)]).unwrap();
/// let text = step_file_with(&[CadItem::Surface(&s)], "square",
///     &CadOptions::with_units(LengthUnit::Inch)).unwrap();
/// assert!(text.contains("CONVERSION_BASED_UNIT('INCH'"));
/// ```
pub fn step_file_with(items: &[CadItem], name: &str, options: &CadOptions) -> Result<String> {
    let bad = |m: String| Error::Invalid {
        path: name.into(),
        message: m,
    };
    let deviation = items
        .iter()
        .filter_map(|it| match it {
            CadItem::Trimmed(t) => Some(t.curves().map(|c| c.deviation).fold(0.0, f64::max)),
            _ => None,
        })
        .fold(0.0, f64::max);
    let (mut w, pre) = begin(name, (2.0 * deviation).max(1e-7), options.units);
    let (ctx, axis) = (pre.ctx, pre.axis);
    let esc = pre.esc.clone();
    let mut faces = Vec::new();
    let mut curves = Vec::new();
    let mut ctx2d = None;
    for (k, item) in items.iter().enumerate() {
        match item {
            CadItem::Surface(s) => {
                // periodic or unclamped: the same surface in clamped form
                let clamped = s
                    .to_clamped()
                    .map_err(|e| bad(format!("surface {k}: {e}")))?;
                let surf = surface_entity(&mut w, &clamped);
                let fb = rectangle_bound(&mut w, &clamped)
                    .map_err(|e| bad(format!("surface {k}: {e}")))?;
                faces.push(w.add(&format!("ADVANCED_FACE('',(#{fb}),#{surf},.T.)")));
            }
            CadItem::Trimmed(t) => {
                let c2 = *ctx2d.get_or_insert_with(|| {
                    w.add("(GEOMETRIC_REPRESENTATION_CONTEXT(2) PARAMETRIC_REPRESENTATION_CONTEXT() REPRESENTATION_CONTEXT('2D SPACE',''))")
                });
                faces.push(
                    trimmed_face(&mut w, t, c2).map_err(|e| bad(format!("surface {k}: {e}")))?,
                );
            }
            CadItem::Curve(c) => {
                let clamped = c.to_clamped().map_err(|e| bad(format!("curve {k}: {e}")))?;
                let c = &clamped;
                curves.push(curve_entity(&mut w, c));
            }
        }
    }
    // One representation per product (readers such as OpenCASCADE transfer
    // one): the specific kinds when only faces or only curves are present,
    // a plain SHAPE_REPRESENTATION holding both otherwise.
    let model = (!faces.is_empty()).then(|| {
        let shell = w.add(&format!(
            "OPEN_SHELL('',{})",
            list(&faces, |i| format!("#{i}"))
        ));
        w.add(&format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"))
    });
    let set = (!curves.is_empty()).then(|| {
        w.add(&format!(
            "GEOMETRIC_CURVE_SET('',{})",
            list(&curves, |i| format!("#{i}"))
        ))
    });
    let rep = match (model, set) {
        (Some(m), None) => w.add(&format!(
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('{esc}',(#{m},#{axis}),#{ctx})"
        )),
        (None, Some(c)) => w.add(&format!(
            "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('{esc}',(#{c},#{axis}),#{ctx})"
        )),
        (Some(m), Some(c)) => w.add(&format!(
            "SHAPE_REPRESENTATION('{esc}',(#{m},#{c},#{axis}),#{ctx})"
        )),
        (None, None) => return Err(bad("nothing to export".into())),
    };
    Ok(finish(w, &pre, rep, "scanfit B-spline geometry"))
}

/// The `FACE_OUTER_BOUND` of a clamped surface's own rectangle: its four
/// boundary curves (exact: the boundary rows and columns of the net).
fn rectangle_bound(w: &mut Writer, s: &Surface) -> scanfit::Result<usize> {
    let b = boundary_curves(s)?;
    let ((u0, u1), (v0, v1)) = s.domain();
    let corners = [
        s.point(u0, v0),
        s.point(u1, v0),
        s.point(u1, v1),
        s.point(u0, v1),
    ];
    let vp: Vec<usize> = corners
        .iter()
        .map(|c| {
            let pt = w.point(c);
            w.add(&format!("VERTEX_POINT('',#{pt})"))
        })
        .collect();
    // edges: v = v0 (corner 0 -> 1), u = u1 (1 -> 2), v = v1 (3 -> 2), u = u0 (0 -> 3)
    let ends = [(0, 1), (1, 2), (3, 2), (0, 3)];
    let mut oes = Vec::new();
    for (e, &(a, bb)) in ends.iter().enumerate() {
        let cid = curve_entity(w, &b[e]);
        let ec = w.add(&format!("EDGE_CURVE('',#{},#{},#{cid},.T.)", vp[a], vp[bb]));
        // the loop runs 0 -> 1 -> 2 -> 3 -> 0: the last two edges backwards
        let sense = if e < 2 { ".T." } else { ".F." };
        oes.push(w.add(&format!("ORIENTED_EDGE('',*,*,#{ec},{sense})")));
    }
    let lp = w.add(&format!(
        "EDGE_LOOP('',{})",
        list(&oes, |i| format!("#{i}"))
    ));
    Ok(w.add(&format!("FACE_OUTER_BOUND('',#{lp},.T.)")))
}

/// One trim loop on the surface entity `surf`: a closed `EDGE_CURVE` on a
/// `SURFACE_CURVE` (3D curve + `PCURVE` in the 2D context `ctx2d`) in an
/// `EDGE_LOOP`; returns the loop's id.
fn trim_loop(w: &mut Writer, c: &TrimCurve, surf: usize, ctx2d: usize) -> scanfit::Result<usize> {
    let space = c.space.to_clamped()?;
    let uv = c.uv.to_clamped()?;
    let c3 = curve_entity(w, &space);
    let c2 = curve_2d_entity(w, &uv);
    let dr = w.add(&format!("DEFINITIONAL_REPRESENTATION('',(#{c2}),#{ctx2d})"));
    let pc = w.add(&format!("PCURVE('',#{surf},#{dr})"));
    let sc = w.add(&format!("SURFACE_CURVE('',#{c3},(#{pc}),.PCURVE_S1.)"));
    let start = space.point(space.domain().0);
    let pt = w.point(&start);
    let vp = w.add(&format!("VERTEX_POINT('',#{pt})"));
    let ec = w.add(&format!("EDGE_CURVE('',#{vp},#{vp},#{sc},.T.)"));
    let oe = w.add(&format!("ORIENTED_EDGE('',*,*,#{ec},.T.)"));
    Ok(w.add(&format!("EDGE_LOOP('',(#{oe}))")))
}

/// The `ADVANCED_FACE` of a trimmed surface; returns its id.
fn trimmed_face(w: &mut Writer, t: &TrimmedSurface, ctx2d: usize) -> scanfit::Result<usize> {
    let s = t.surface.to_clamped()?;
    let surf = surface_entity(w, &s);
    let mut bounds = vec![match &t.outer {
        Some(o) => {
            let lp = trim_loop(w, o, surf, ctx2d)?;
            w.add(&format!("FACE_OUTER_BOUND('',#{lp},.T.)"))
        }
        None => rectangle_bound(w, &s)?,
    }];
    for h in &t.holes {
        let lp = trim_loop(w, h, surf, ctx2d)?;
        bounds.push(w.add(&format!("FACE_BOUND('',#{lp},.T.)")));
    }
    Ok(w.add(&format!(
        "ADVANCED_FACE('',{},#{surf},.T.)",
        list(&bounds, |i| format!("#{i}"))
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_have_a_decimal_point() {
        assert_eq!(real(1.0), "1.0");
        assert_eq!(real(0.25), "0.25");
        assert_eq!(real(1e-7), "1.E-7");
        assert_eq!(real(-3.47e-15), "-3.47E-15");
        assert_eq!(real(1.5e300), "1.5E300");
    }
}
