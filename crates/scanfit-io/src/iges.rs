//! IGES 5.3 export: rational B-spline curves (entity 126) and surfaces
//! (entity 128), with the Start, Global, Directory Entry, Parameter Data and
//! Terminate sections in fixed 80-column records and their sequence numbers.
//!
//! Entity 128 lists weights and control points with the `u` index varying
//! fastest (`W(0,0), W(1,0), ..., W(K1,0), W(0,1), ...`), the transpose of
//! scanfit's row-major net. Units are declared as millimetres unless
//! [`CadOptions::units`] says otherwise (global parameters 14 and 15; the
//! values are never scaled). A multi-patch model ([`iges_model_file`]) is
//! written as its patches and its shared edge curves.
//!
//! A trimmed surface ([`CadItem::Trimmed`]) is an entity 144 (trimmed
//! parametric surface) on its entity 128, with one entity 142 (curve on a
//! parametric surface) per trim loop; each 142 points at the loop's 2D
//! curve in the surface's parameter space (entity 126, planar, entity use
//! "parametric") and its 3D curve (entity 126), and prefers the former
//! (`PREF = 1`, `S(B(t))`). A face that keeps its rectangle has `N1 = 0`
//! (its outer boundary is the domain's). The referenced entities are
//! flagged physically dependent in their directory entries.

use scanfit::bspline::{Curve, Surface};
use scanfit::topology::PatchComplex;

use crate::step::CadItem;
use crate::units::CadOptions;
use crate::{Error, Result};
use scanfit::trim::TrimmedSurface;

/// IGES reals use the same form as STEP's (shortest round trip, a decimal point).
use crate::step::real;

fn hollerith(s: &str) -> String {
    format!("{}H{s}", s.len())
}

/// Parameters of entity 126 for `c` (clamped or not; periodic flagged);
/// `planar` flags a parameter-space curve (in the plane `z = 0`).
fn curve_params(c: &Curve, planar: bool) -> Vec<String> {
    let k = c.control_points().len() - 1;
    let m = c.degree();
    let w: Vec<f64> = c
        .weights()
        .map(|w| w.to_vec())
        .unwrap_or_else(|| vec![1.0; k + 1]);
    let polynomial = w.iter().all(|&x| x == w[0]);
    let (a, b) = c.domain();
    let mut v = vec![
        "126".into(),
        k.to_string(),
        m.to_string(),
        (planar as u8).to_string(),
        (c.is_closed() as u8).to_string(),
        (polynomial as u8).to_string(),
        (c.is_periodic() as u8).to_string(),
    ];
    v.extend(c.knots().as_slice().iter().map(|&t| real(t)));
    v.extend(w.iter().map(|&x| real(x)));
    for p in c.control_points() {
        v.extend([real(p.x), real(p.y), real(p.z)]);
    }
    v.extend([real(a), real(b), "0.0".into(), "0.0".into(), "1.0".into()]);
    v
}

/// Parameters of entity 128 for `s`.
fn surface_params(s: &Surface) -> Vec<String> {
    let (nu, nv) = s.counts();
    let (p, q) = s.degrees();
    let w: Vec<f64> = s
        .weights()
        .map(|w| w.to_vec())
        .unwrap_or_else(|| vec![1.0; nu * nv]);
    let polynomial = w.iter().all(|&x| x == w[0]);
    let (pu, pv) = s.periodic();
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut v = vec![
        "128".into(),
        (nu - 1).to_string(),
        (nv - 1).to_string(),
        p.to_string(),
        q.to_string(),
        (pu as u8).to_string(),
        (pv as u8).to_string(),
        (polynomial as u8).to_string(),
        (pu as u8).to_string(),
        (pv as u8).to_string(),
    ];
    v.extend(s.knots_u().as_slice().iter().map(|&t| real(t)));
    v.extend(s.knots_v().as_slice().iter().map(|&t| real(t)));
    // u index fastest
    for j in 0..nv {
        for i in 0..nu {
            v.push(real(w[i * nv + j]));
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let c = s.control_point(i, j);
            v.extend([real(c.x), real(c.y), real(c.z)]);
        }
    }
    v.extend([real(u0), real(u1), real(v0), real(v1)]);
    v
}

/// An 80-column record: 72 columns of text, the section letter, a 7-digit sequence number.
fn record(text: &str, section: char, seq: usize) -> String {
    format!("{text:<72}{section}{seq:>7}\n")
}

/// One entity to write: its type, parameters (the type first), label and
/// directory status (blank, subordinate, use, hierarchy).
struct Entity {
    etype: u32,
    params: Vec<String>,
    label: &'static str,
    status: &'static str,
}

/// Independent entities.
const INDEPENDENT: &str = "00000000";
/// Physically dependent on a referencing entity.
const DEPENDENT: &str = "00010000";
/// Physically dependent, used as a curve in a parameter space.
const PARAMETRIC: &str = "00010500";

/// An IGES file with `items` (curves as entity 126, surfaces as 128,
/// trimmed surfaces as 144), lengths in millimetres.
pub fn iges_file(items: &[CadItem], name: &str) -> Result<String> {
    iges_file_with(items, name, &CadOptions::default())
}

/// The directory entry number (odd, 1-based) of the entity pushed next.
fn next_de(entities: &[Entity]) -> usize {
    2 * entities.len() + 1
}

/// Pushes the entities of a trimmed surface: 128, per loop 126 (2D), 126
/// (3D) and 142, then 144.
fn push_trimmed(entities: &mut Vec<Entity>, t: &TrimmedSurface) -> scanfit::Result<()> {
    let surf = next_de(entities);
    entities.push(Entity {
        etype: 128,
        params: surface_params(&t.surface.to_clamped()?),
        label: "BSPLSRF",
        status: DEPENDENT,
    });
    let mut on_surface = Vec::new();
    for c in t.curves() {
        let b = next_de(entities);
        entities.push(Entity {
            etype: 126,
            params: curve_params(&c.uv.to_clamped()?, true),
            label: "PCURVE",
            status: PARAMETRIC,
        });
        let cc = next_de(entities);
        entities.push(Entity {
            etype: 126,
            params: curve_params(&c.space.to_clamped()?, false),
            label: "BSPLCRV",
            status: DEPENDENT,
        });
        on_surface.push(next_de(entities));
        entities.push(Entity {
            etype: 142,
            params: [
                "142",
                "1",
                &surf.to_string(),
                &b.to_string(),
                &cc.to_string(),
                "1",
            ]
            .map(String::from)
            .to_vec(),
            label: "CRVONSRF",
            status: DEPENDENT,
        });
    }
    let outer = t.outer.is_some();
    let (pto, holes) = if outer {
        (on_surface[0], &on_surface[1..])
    } else {
        (0, &on_surface[..])
    };
    let mut params = vec![
        "144".to_string(),
        surf.to_string(),
        (outer as u8).to_string(),
        holes.len().to_string(),
        pto.to_string(),
    ];
    params.extend(holes.iter().map(|h| h.to_string()));
    entities.push(Entity {
        etype: 144,
        params,
        label: "TRIMSRF",
        status: INDEPENDENT,
    });
    Ok(())
}

/// An IGES file with `items`, written with `options` (the declared length
/// unit in the global section).
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::Point3;
/// use scanfit_io::iges::iges_file_with;
/// use scanfit_io::step::CadItem;
/// use scanfit_io::units::{CadOptions, LengthUnit};
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
/// let s = Surface::new(k.clone(), k, vec![p(0., 0.), p(0., 1.), p(1., 0.), p(1., 1.)]).unwrap();
/// let text = iges_file_with(&[CadItem::Surface(&s)], "square",
///     &CadOptions::with_units(LengthUnit::Metre)).unwrap();
/// assert!(text.contains(",6,1HM,"));
/// ```
pub fn iges_file_with(items: &[CadItem], name: &str, options: &CadOptions) -> Result<String> {
    if items.is_empty() {
        return Err(Error::Invalid {
            path: name.into(),
            message: "nothing to export".into(),
        });
    }
    let mut out = String::new();
    // Start section
    let start = format!(
        "scanfit {} B-spline geometry: {name}",
        env!("CARGO_PKG_VERSION")
    );
    out.push_str(&record(&start.chars().take(72).collect::<String>(), 'S', 1));
    // Global section
    let stamp = "20260101.000000";
    let max_coord = items
        .iter()
        .flat_map(|it| match it {
            CadItem::Curve(c) => c.control_points().to_vec(),
            CadItem::Surface(s) => s.control_points().to_vec(),
            CadItem::Trimmed(t) => t.surface.control_points().to_vec(),
        })
        .fold(0.0f64, |m, p| m.max(p.coords.amax()));
    let units = options.units;
    let global = [
        "1H,".to_string(),
        "1H;".into(),
        hollerith("scanfit"),
        hollerith(name),
        hollerith("scanfit"),
        hollerith(&format!("scanfit {}", env!("CARGO_PKG_VERSION"))),
        "32".into(),
        "38".into(),
        "6".into(),
        "308".into(),
        "15".into(),
        hollerith("scanfit"),
        "1.0".into(),
        units.iges_flag().to_string(),
        hollerith(units.iges_name()),
        "1".into(),
        "1.0".into(),
        hollerith(stamp),
        "1.0E-7".into(),
        real(max_coord.max(1.0)),
        hollerith("unknown"),
        hollerith("unknown"),
        "11".into(),
        "0".into(),
        hollerith(stamp),
    ];
    let glines = pack(&global, 72);
    for (k, l) in glines.iter().enumerate() {
        out.push_str(&record(l, 'G', k + 1));
    }
    // the entities, referenced ones before those that reference them;
    // periodic or unclamped geometry goes out in the clamped form of the same shape
    let mut entities = Vec::new();
    for (k, item) in items.iter().enumerate() {
        let bad = |e: scanfit::Error| Error::Invalid {
            path: name.into(),
            message: format!("item {k}: {e}"),
        };
        match item {
            CadItem::Curve(c) => entities.push(Entity {
                etype: 126,
                params: curve_params(&c.to_clamped().map_err(bad)?, false),
                label: "BSPLCRV",
                status: INDEPENDENT,
            }),
            CadItem::Surface(s) => entities.push(Entity {
                etype: 128,
                params: surface_params(&s.to_clamped().map_err(bad)?),
                label: "BSPLSRF",
                status: INDEPENDENT,
            }),
            CadItem::Trimmed(t) => push_trimmed(&mut entities, t).map_err(bad)?,
        }
    }
    // Directory entries and parameter data
    let mut d = String::new();
    let mut pdata = String::new();
    let mut pseq = 1usize;
    for (k, e) in entities.iter().enumerate() {
        let etype = e.etype;
        let de = 2 * k + 1; // sequence number of this entity's first DE line
        let lines = pack(&e.params, 64);
        let first = pseq;
        for l in &lines {
            pdata.push_str(&format!("{l:<64} {de:>7}P{pseq:>7}\n"));
            pseq += 1;
        }
        d.push_str(&record(
            &format!(
                "{etype:>8}{first:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
                0, 0, 0, 0, 0, 0, e.status
            ),
            'D',
            de,
        ));
        d.push_str(&record(
            &format!(
                "{etype:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
                0,
                0,
                lines.len(),
                0,
                "",
                "",
                e.label,
                k + 1
            ),
            'D',
            de + 1,
        ));
    }
    out.push_str(&d);
    out.push_str(&pdata);
    let term = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}",
        1,
        glines.len(),
        2 * entities.len(),
        pseq - 1
    );
    out.push_str(&record(&term, 'T', 1));
    Ok(out)
}

/// An IGES file for a multi-patch model: every patch surface as entity 128
/// (in face order) followed by every shared edge curve as entity 126 (in edge
/// order), each written once. IGES 5.3 has no shell topology short of the
/// B-rep entities 186/514 (which few readers accept), so the faces are not
/// sewn here; use [`crate::step_shell`] for a sewn shell.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::topology::{FaceCorners, PatchComplex};
/// use scanfit::Point3;
/// use scanfit_io::iges::iges_model_file;
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let c = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
///          Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
/// let s = Surface::new(k.clone(), k, vec![c[0], c[3], c[1], c[2]]).unwrap();
/// let model = PatchComplex::assemble(c.to_vec(),
///     vec![FaceCorners { id: 5, surface: s, corners: [0, 1, 2, 3] }]).unwrap();
/// let text = iges_model_file(&model, "square").unwrap();
/// let de: Vec<&str> = text.lines().filter(|l| &l[72..73] == "D").collect();
/// assert_eq!(de.len(), 2 * 5); // one surface and four edge curves
/// assert!(de[0].starts_with("     128") && de[2].starts_with("     126"));
/// ```
pub fn iges_model_file(model: &PatchComplex, name: &str) -> Result<String> {
    iges_model_file_with(model, name, &CadOptions::default())
}

/// [`iges_model_file`] written with `options` (the declared length unit).
pub fn iges_model_file_with(
    model: &PatchComplex,
    name: &str,
    options: &CadOptions,
) -> Result<String> {
    let mut items: Vec<CadItem> = model
        .faces
        .iter()
        .map(|f| CadItem::Surface(&f.surface))
        .collect();
    items.extend(model.edges.iter().map(|e| CadItem::Curve(&e.curve)));
    iges_file_with(&items, name, options)
}

/// Joins parameters with ',' and a final ';' into lines of at most `width`
/// columns, never splitting a parameter.
fn pack(params: &[String], width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut cur = String::new();
    for (i, p) in params.iter().enumerate() {
        let tok = format!("{p}{}", if i + 1 == params.len() { ';' } else { ',' });
        if !cur.is_empty() && cur.len() + tok.len() > width {
            lines.push(std::mem::take(&mut cur));
        }
        cur.push_str(&tok);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use scanfit::bspline::KnotVector;
    use scanfit::Point3;

    #[test]
    fn records_are_80_columns_and_sections_are_counted() {
        let kv = KnotVector::uniform_clamped(3, 5).unwrap();
        let c = Curve::new(
            kv,
            (0..5).map(|k| Point3::new(k as f64, 1.0, 2.0)).collect(),
        )
        .unwrap();
        let text = iges_file(&[CadItem::Curve(&c)], "t").unwrap();
        for l in text.lines() {
            assert_eq!(l.len(), 80, "{l}");
        }
        // terminate record: section line counts match the sections
        let count = |c: &str| text.lines().filter(|l| &l[72..73] == c).count();
        let last = text.lines().last().unwrap();
        let want = format!(
            "S{:>7}G{:>7}D{:>7}P{:>7}",
            count("S"),
            count("G"),
            count("D"),
            count("P")
        );
        assert!(last.starts_with(&want), "{last} vs {want}");
        assert_eq!(count("D"), 2);
        let p: Vec<&str> = text.lines().filter(|l| &l[72..73] == "P").collect();
        assert!(
            p[0].starts_with("126,4,3,0,0,1,0,0.0,0.0,0.0,0.0,0.5,1.0,"),
            "{}",
            p[0]
        );
    }
}
