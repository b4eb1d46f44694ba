//! The JSON document for curves (schema `scanfit/1`).
//!
//! ```json
//! {
//!   "schema": "scanfit/1",
//!   "type": "bspline_curve",
//!   "degree": 3,
//!   "periodic": false,
//!   "knots": [0, 0, 0, 0, 0.5, 1, 1, 1, 1],
//!   "control_points": [[x, y, z], ...],
//!   "provenance": {"tool": "scanfit 0.1.0", "operation": "curve fit (interpolation)",
//!                  "parameterization": "proposed", "input": "data.csv", "point_count": 10,
//!                  "settings": {"degree": 3, "smoothing": 0}},
//!   "params": [0, 0.12, ...],
//!   "quality": {"max_deviation": 3.5e-15, ...}
//! }
//! ```
//!
//! Surfaces (`"type": "bspline_surface"`) carry `degree_u`, `degree_v`,
//! `periodic_u`, `periodic_v`, `knots_u`, `knots_v`, `count_u`, `count_v` and
//! `control_points` row-major with `u` slow (`P_ij` at `i * count_v + j`), the
//! same `weights`, `provenance`, and a `quality` section ([`SurfaceQualityDoc`]);
//! a trimmed face also its trimming loops (`trim`, [`TrimDoc`]).
//!
//! A periodic curve lists all `n + p` control points (the last `p` repeat the
//! first `p`) and its unclamped knots. Numbers are written in the shortest form
//! that reads back to the same `f64`, so a write/read round trip is exact.

use std::collections::BTreeMap;
use std::path::Path;

use scanfit::bspline::{Curve, KnotVector, Surface};
use scanfit::quality::CurveQuality;
use scanfit::Point3;
use serde::{Deserialize, Serialize};

use crate::json_trim::TrimDoc;
use crate::{Error, Result};

/// Pretty JSON text of `value` (with a final newline), refusing any number
/// that is not finite: `serde_json` writes NaN and infinities as `null`, and
/// no scanfit document or report has a `null` of its own (absent values are
/// left out), so a `null` in the text is a non-finite number and an error
/// naming where it is. `what` names the document in the error.
///
/// ```
/// let ok = scanfit_io::json::finite_json(&serde_json::json!({"rmse": 0.5}), "report").unwrap();
/// assert_eq!(ok, "{\n  \"rmse\": 0.5\n}\n");
/// let bad = scanfit_io::json::finite_json(&[1.0, f64::NAN], "report").unwrap_err();
/// assert!(bad.to_string().contains("the value at [1] is not a finite number"), "{bad}");
/// ```
pub fn finite_json<T: Serialize + ?Sized>(value: &T, what: &str) -> Result<String> {
    finite_json_except(value, what, |_| false)
}

/// [`finite_json`] for a document whose format has `null`s of its own at
/// the paths `allowed` accepts (the model document's degenerate side of a
/// three-sided patch, `.patches[i].sides[k]`).
pub fn finite_json_except<T: Serialize + ?Sized>(
    value: &T,
    what: &str,
    allowed: fn(&str) -> bool,
) -> Result<String> {
    let invalid = |message: String| Error::Invalid {
        path: what.into(),
        message,
    };
    let text = serde_json::to_string_pretty(value).map_err(|e| invalid(e.to_string()))?;
    // read back (the text keeps the writer's key order; the value is only searched)
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| invalid(e.to_string()))?;
    if let Some(at) = first_null(&v, allowed) {
        return Err(Error::NonFinite {
            what: what.into(),
            at: if at.is_empty() {
                "the top level".into()
            } else {
                at
            },
        });
    }
    Ok(text + "\n")
}

/// The path (`.a.b[3]`) of the first `null` in `v`, depth first.
fn first_null(v: &serde_json::Value, allowed: fn(&str) -> bool) -> Option<String> {
    use serde_json::Value;
    let found = first_null_in(v)?;
    if !allowed(&found) {
        return Some(found);
    }
    // an allowed null: look for another one elsewhere
    fn all_nulls(v: &Value, at: String, out: &mut Vec<String>) {
        match v {
            Value::Null => out.push(at),
            Value::Array(a) => a
                .iter()
                .enumerate()
                .for_each(|(k, x)| all_nulls(x, format!("{at}[{k}]"), out)),
            Value::Object(m) => m
                .iter()
                .for_each(|(k, x)| all_nulls(x, format!("{at}.{k}"), out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    all_nulls(v, String::new(), &mut out);
    out.into_iter().find(|p| !allowed(p))
}

/// The path of the first `null` in `v`, depth first.
fn first_null_in(v: &serde_json::Value) -> Option<String> {
    use serde_json::Value;
    match v {
        Value::Null => Some(String::new()),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(k, x)| first_null_in(x).map(|rest| format!("[{k}]{rest}"))),
        Value::Object(map) => map
            .iter()
            .find_map(|(key, x)| first_null_in(x).map(|rest| format!(".{key}{rest}"))),
        _ => None,
    }
}

/// Schema identifier written into every document.
pub const SCHEMA: &str = "scanfit/1";

/// Where a curve came from: the tool, the operation and its settings.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Tool and version.
    pub tool: String,
    /// What produced the curve (e.g. `curve fit (interpolation)`).
    pub operation: String,
    /// Parameterization method, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameterization: Option<String>,
    /// Input file, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input: Option<String>,
    /// Number of input points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_count: Option<usize>,
    /// Further settings (degree, control points, smoothing, ...).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub settings: BTreeMap<String, serde_json::Value>,
}

/// The quality report as stored in JSON (see [`scanfit::quality::CurveQuality`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QualityDoc {
    /// Largest deviation at the fit parameters (data units).
    pub max_deviation: f64,
    /// Index of the point with the largest deviation.
    pub max_deviation_index: usize,
    /// Mean deviation.
    pub mean_deviation: f64,
    /// RMS deviation.
    pub rms_deviation: f64,
    /// Largest orthogonal distance from a point to the curve.
    pub max_distance: f64,
    /// Largest curvature (1 / data units).
    pub max_curvature: f64,
    /// Parameter of the largest curvature.
    pub max_curvature_at: f64,
    /// Curvature sign changes (inflections).
    pub curvature_sign_changes: usize,
    /// Self-intersections (loops).
    pub self_intersections: usize,
    /// Curve length.
    pub length: f64,
    /// Data polygon length.
    pub polygon_length: f64,
    /// Ratio of the two.
    pub length_ratio: f64,
}

impl From<&CurveQuality> for QualityDoc {
    fn from(q: &CurveQuality) -> Self {
        Self {
            max_deviation: q.max_deviation,
            max_deviation_index: q.max_deviation_index,
            mean_deviation: q.mean_deviation,
            rms_deviation: q.rms_deviation,
            max_distance: q.max_distance,
            max_curvature: q.max_curvature,
            max_curvature_at: q.max_curvature_at,
            curvature_sign_changes: q.curvature_sign_changes,
            self_intersections: q.self_intersections,
            length: q.length,
            polygon_length: q.polygon_length,
            length_ratio: q.length_ratio,
        }
    }
}

/// A curve document as written to and read from JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurveDoc {
    /// Always [`SCHEMA`].
    pub schema: String,
    /// Always `bspline_curve`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Degree.
    pub degree: usize,
    /// Periodic (closed, smooth at the seam).
    pub periodic: bool,
    /// Knot vector.
    pub knots: Vec<f64>,
    /// Control points.
    pub control_points: Vec<[f64; 3]>,
    /// Weights (rational curves only; left out otherwise, `null` is read as absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<f64>>,
    /// Where the curve came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
    /// Parameter of each input point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub params: Option<Vec<f64>>,
    /// Quality report.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<QualityDoc>,
}

impl CurveDoc {
    /// A document for `curve` without provenance, parameters or quality.
    pub fn new(curve: &Curve) -> Self {
        Self {
            schema: SCHEMA.into(),
            kind: "bspline_curve".into(),
            degree: curve.degree(),
            periodic: curve.is_periodic(),
            knots: curve.knots().as_slice().to_vec(),
            control_points: curve
                .control_points()
                .iter()
                .map(|p| [p.x, p.y, p.z])
                .collect(),
            weights: curve.weights().map(|w| w.to_vec()),
            provenance: None,
            params: None,
            quality: None,
        }
    }

    /// Pretty JSON text; an error if a number is not finite ([`finite_json`]).
    pub fn to_json(&self) -> Result<String> {
        finite_json(self, "the curve document")
    }

    /// [`CurveDoc::curve`] after the degree check of [`parse_curve`] (a
    /// degree no knot vector can carry is refused before anything is built),
    /// the error as one line.
    pub fn checked_curve(&self) -> std::result::Result<Curve, String> {
        check_degree(self.degree, self.knots.len(), "degree", "knots")?;
        self.curve().map_err(|e| e.to_string())
    }

    /// The curve this document describes (validated).
    pub fn curve(&self) -> scanfit::Result<Curve> {
        let kv = KnotVector::new(self.knots.clone(), self.degree)?;
        let ctrl: Vec<Point3> = self
            .control_points
            .iter()
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect();
        match (self.periodic, &self.weights) {
            (true, w) => Curve::new_periodic(kv, ctrl, w.clone()),
            (false, Some(w)) => Curve::new_rational(kv, ctrl, w.clone()),
            (false, None) => Curve::new(kv, ctrl),
        }
    }
}

/// Reads a curve document from `path` and builds its curve.
pub fn read_curve(path: &Path) -> Result<(CurveDoc, Curve)> {
    let text = std::fs::read_to_string(path).map_err(|error| Error::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse_curve(path, &text)
}

/// Parses a curve document (`path` for messages only).
pub fn parse_curve(path: &Path, text: &str) -> Result<(CurveDoc, Curve)> {
    let doc: CurveDoc = serde_json::from_str(text).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: e.line(),
        message: format!("not a scanfit curve document: {e}"),
    })?;
    if doc.kind != "bspline_curve" {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!("type is '{}', expected 'bspline_curve'", doc.kind),
        });
    }
    check_degree(doc.degree, doc.knots.len(), "degree", "knots").map_err(|message| {
        Error::Invalid {
            path: path.to_path_buf(),
            message,
        }
    })?;
    let curve = doc.curve().map_err(|error| Error::Geometry {
        path: path.to_path_buf(),
        error,
    })?;
    Ok((doc, curve))
}

/// Error and parameterization measures of a fitted surface, as stored in JSON.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfaceQualityDoc {
    /// Number of points measured.
    pub points: usize,
    /// Mean of `|P_i - S(u_i, v_i)|` (PDE paper eq. 15).
    pub mean_error: f64,
    /// Maximum of `|P_i - S(u_i, v_i)|` (PDE paper eq. 15).
    pub max_error: f64,
    /// RMSE of `|P_i - S(u_i, v_i)|`.
    pub rmse: f64,
    /// Mean orthogonal distance (point inversion).
    pub mean_distance: f64,
    /// Maximum orthogonal distance.
    pub max_distance: f64,
    /// RMSE of the orthogonal distances.
    pub rmse_distance: f64,
    /// Points whose inversion did not converge.
    pub unconverged: usize,
    /// MBA paper eq. 17: grid points to nearest input point.
    pub grid_rmse: f64,
    /// Delaunay triangles of the parameters.
    pub triangles: usize,
    /// Triangles folded over on the surface.
    pub fold_overs: usize,
    /// Normalised L2 stretch (1 = uniform up to scale).
    pub l2_stretch: f64,
    /// Largest triangle anisotropy.
    pub max_anisotropy: f64,
    /// RMSE after each parameter-correction round (round 0 = first fit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub correction_rmse: Vec<f64>,
}

/// A surface document as written to and read from JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceDoc {
    /// Always [`SCHEMA`].
    pub schema: String,
    /// Always `bspline_surface`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Degree in `u`.
    pub degree_u: usize,
    /// Degree in `v`.
    pub degree_v: usize,
    /// Periodic in `u`.
    pub periodic_u: bool,
    /// Periodic in `v`.
    pub periodic_v: bool,
    /// Knot vector in `u`.
    pub knots_u: Vec<f64>,
    /// Knot vector in `v`.
    pub knots_v: Vec<f64>,
    /// Control points in `u`.
    pub count_u: usize,
    /// Control points in `v`.
    pub count_v: usize,
    /// Control points, row-major with `u` slow.
    pub control_points: Vec<[f64; 3]>,
    /// Weights (rational surfaces only, same order; left out otherwise,
    /// `null` is read as absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<f64>>,
    /// Where the surface came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
    /// Error and parameterization measures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<SurfaceQualityDoc>,
    /// The trimming loops of a trimmed face; absent (older documents,
    /// untrimmed faces): the whole parameter rectangle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trim: Option<TrimDoc>,
}

impl SurfaceDoc {
    /// A document for `surface` without provenance or quality.
    pub fn new(surface: &Surface) -> Self {
        let (p, q) = surface.degrees();
        let (cu, cv) = surface.counts();
        let (pu, pv) = surface.periodic();
        Self {
            schema: SCHEMA.into(),
            kind: "bspline_surface".into(),
            degree_u: p,
            degree_v: q,
            periodic_u: pu,
            periodic_v: pv,
            knots_u: surface.knots_u().as_slice().to_vec(),
            knots_v: surface.knots_v().as_slice().to_vec(),
            count_u: cu,
            count_v: cv,
            control_points: surface
                .control_points()
                .iter()
                .map(|p| [p.x, p.y, p.z])
                .collect(),
            weights: surface.weights().map(|w| w.to_vec()),
            provenance: None,
            quality: None,
            trim: None,
        }
    }

    /// Records the trimming loops of `trimmed` (none: the untrimmed
    /// rectangle).
    pub fn set_trim(&mut self, trimmed: Option<&scanfit::trim::TrimmedSurface>) {
        self.trim = trimmed.map(TrimDoc::new);
    }

    /// The trimmed face of `surface` (this document's surface) when the
    /// document has trimming loops.
    ///
    /// ```
    /// use std::path::Path;
    /// let text = r#"{"schema":"scanfit/1","type":"bspline_surface","degree_u":1,"degree_v":1,
    ///   "periodic_u":false,"periodic_v":false,"knots_u":[0,0,1,1],"knots_v":[0,0,1,1],
    ///   "count_u":2,"count_v":2,"control_points":[[0,0,0],[0,1,0],[1,0,0],[1,1,1]]}"#;
    /// let (doc, surface) = scanfit_io::json::parse_surface(Path::new("s.json"), text)?;
    /// // an older document (or an untrimmed face) has no trimming loops
    /// assert!(doc.trimmed(&surface).unwrap().is_none());
    /// # Ok::<(), scanfit_io::Error>(())
    /// ```
    pub fn trimmed(
        &self,
        surface: &Surface,
    ) -> std::result::Result<Option<scanfit::trim::TrimmedSurface>, String> {
        self.trim.as_ref().map(|t| t.trimmed(surface)).transpose()
    }

    /// Pretty JSON text; an error if a number is not finite ([`finite_json`]).
    pub fn to_json(&self) -> Result<String> {
        finite_json(self, "the surface document")
    }

    /// The surface this document describes (validated).
    pub fn surface(&self) -> scanfit::Result<Surface> {
        let ku = KnotVector::new(self.knots_u.clone(), self.degree_u)?;
        let kv = KnotVector::new(self.knots_v.clone(), self.degree_v)?;
        if ku.basis_count() != self.count_u || kv.basis_count() != self.count_v {
            return Err(scanfit::Error::InvalidInput(format!(
                "count_u x count_v = {} x {} does not match the knot vectors ({} x {})",
                self.count_u,
                self.count_v,
                ku.basis_count(),
                kv.basis_count()
            )));
        }
        let ctrl = self
            .control_points
            .iter()
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect();
        Surface::with_options(
            ku,
            kv,
            ctrl,
            self.weights.clone(),
            self.periodic_u,
            self.periodic_v,
        )
    }
}

/// Reads a surface document from `path` and builds its surface.
pub fn read_surface(path: &Path) -> Result<(SurfaceDoc, Surface)> {
    let text = std::fs::read_to_string(path).map_err(|error| Error::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse_surface(path, &text)
}

/// Parses a surface document (`path` for messages only).
///
/// ```
/// use std::path::Path;
/// let text = r#"{"schema":"scanfit/1","type":"bspline_surface","degree_u":1,"degree_v":1,
///   "periodic_u":false,"periodic_v":false,"knots_u":[0,0,1,1],"knots_v":[0,0,1,1],
///   "count_u":2,"count_v":2,"control_points":[[0,0,0],[0,1,0],[1,0,0],[1,1,1]],"weights":null}"#;
/// let (doc, surface) = scanfit_io::json::parse_surface(Path::new("s.json"), text).unwrap();
/// assert_eq!(doc.count_u * doc.count_v, surface.control_points().len());
/// // a degree no knot vector can carry is an error, not an overflow
/// let bad = text.replace(r#""degree_u":1"#, r#""degree_u":18446744073709551615"#);
/// assert!(scanfit_io::json::parse_surface(Path::new("s.json"), &bad).is_err());
/// ```
pub fn parse_surface(path: &Path, text: &str) -> Result<(SurfaceDoc, Surface)> {
    let doc: SurfaceDoc = serde_json::from_str(text).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: e.line(),
        message: format!("not a scanfit surface document: {e}"),
    })?;
    if doc.kind != "bspline_surface" {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!("type is '{}', expected 'bspline_surface'", doc.kind),
        });
    }
    let invalid = |message: String| Error::Invalid {
        path: path.to_path_buf(),
        message,
    };
    check_degree(doc.degree_u, doc.knots_u.len(), "degree_u", "knots_u").map_err(invalid)?;
    check_degree(doc.degree_v, doc.knots_v.len(), "degree_v", "knots_v").map_err(invalid)?;
    let net = doc.count_u.checked_mul(doc.count_v);
    if net != Some(doc.control_points.len()) {
        return Err(invalid(format!(
            "count_u x count_v = {} x {} does not match the {} control points; give count_u * count_v points, row-major with u slow",
            doc.count_u,
            doc.count_v,
            doc.control_points.len()
        )));
    }
    let surface = doc.surface().map_err(|error| Error::Geometry {
        path: path.to_path_buf(),
        error,
    })?;
    // the trimming loops are checked here, so readers can rely on them
    doc.trimmed(&surface).map_err(invalid)?;
    Ok((doc, surface))
}

/// Most degree a document may declare: far beyond any CAD use (CAD
/// systems stop at 25 or so), small enough that no computation on the
/// degree (knot counts, basis tables of `(p + 1)^2` entries) can overflow
/// or allocate without bound.
pub const MAX_DEGREE: usize = 64;

/// A document's degree checked before any knot vector is built from it:
/// at least 1, at most [`MAX_DEGREE`], and below the number of knots (a
/// degree-p B-spline needs at least 2(p + 1) knots).
fn check_degree(
    degree: usize,
    knots: usize,
    name: &str,
    knots_name: &str,
) -> std::result::Result<(), String> {
    if degree == 0 || degree > MAX_DEGREE {
        return Err(format!(
            "{name} is {degree}; give a degree from 1 to {MAX_DEGREE}"
        ));
    }
    let need = 2 * (degree + 1);
    if knots < need {
        return Err(format!(
            "{name} {degree} needs at least {need} knots, but {knots_name} has {knots}; the document is damaged"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_exact() {
        let kv = KnotVector::new(vec![0., 0., 0., 0.1 + 0.2, 1. / 3., 1., 1., 1.], 2).unwrap();
        let ctrl = vec![
            Point3::new(0.1, -3.47e-15, 1e140),
            Point3::new(std::f64::consts::PI, 2.0, -0.0),
            Point3::new(1.0 / 7.0, 5e-324, 3.0),
            Point3::new(-64.9885, 33.602, 10.0),
            Point3::new(1., 2., 3.),
        ];
        let w = vec![1.0, 0.3, 2.0 / 3.0, 1.5, 1.0];
        let c = Curve::new_rational(kv, ctrl, w).unwrap();
        let mut doc = CurveDoc::new(&c);
        doc.params = Some(vec![0.0, 0.1 + 0.2, 1.0]);
        let text = doc.to_json().unwrap();
        let (back, c2) = parse_curve(Path::new("x.json"), &text).unwrap();
        assert_eq!(back, doc);
        assert_eq!(c2, c);
        for (a, b) in c.control_points().iter().zip(c2.control_points()) {
            assert_eq!(a.x.to_bits(), b.x.to_bits());
        }
    }

    #[test]
    fn surface_round_trip_is_exact() {
        let ku = KnotVector::new(vec![0., 0., 0., 0.3, 1., 1., 1.], 2).unwrap();
        let kv = KnotVector::uniform_clamped(1, 3).unwrap();
        let c: Vec<Point3> = (0..12)
            .map(|k| Point3::new(k as f64 / 7.0, (k * k) as f64 * 0.1, -3.47e-15 * k as f64))
            .collect();
        let s = Surface::new(ku, kv, c).unwrap();
        let doc = SurfaceDoc::new(&s);
        let dir = std::env::temp_dir().join(format!("scanfit-json-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.json");
        std::fs::write(&path, doc.to_json().unwrap()).unwrap();
        let (back, s2) = read_surface(&path).unwrap();
        assert_eq!(back, doc);
        assert_eq!(s2, s);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn malformed_documents_are_reported() {
        let e = parse_curve(Path::new("c.json"), "{\"schema\": 1}")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.json:1:"), "{e}");
        let doc = r#"{"schema":"scanfit/1","type":"bspline_curve","degree":2,"periodic":false,
            "knots":[0,0,0,1,0.5,1],"control_points":[[0,0,0],[1,1,1],[2,2,2]],"weights":null}"#;
        let e = parse_curve(Path::new("c.json"), doc)
            .unwrap_err()
            .to_string();
        assert!(e.contains("non-decreasing"), "{e}");
    }
}
