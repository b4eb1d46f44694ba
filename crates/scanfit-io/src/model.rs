//! The JSON document for multi-patch models (schema `scanfit-model/1`): every
//! patch surface, the shared edges with their curves and the patches on
//! either side, the corner vertices, and a report section that the
//! reconstruction pipeline fills.
//!
//! ```json
//! {
//!   "schema": "scanfit-model/1",
//!   "type": "patch_model",
//!   "closed": true,
//!   "vertices": [[x, y, z], ...],
//!   "edges": [
//!     {"start": 0, "end": 1, "patches": [3, 7],
//!      "curve": {"schema": "scanfit/1", "type": "bspline_curve", "degree": 3, ...}}
//!   ],
//!   "patches": [
//!     {"id": 3, "sides": [{"edge": 0, "reversed": false}, {"edge": 4, "reversed": true},
//!                         {"edge": 5, "reversed": false}, null],
//!      "surface": {"schema": "scanfit/1", "type": "bspline_surface", ...}},
//!     {"id": 9, "sides": [{"edge": 6, "reversed": false}, {"edge": 7, "reversed": false},
//!                         [{"edge": 8, "reversed": true}, {"edge": 9, "reversed": true}],
//!                         {"edge": 10, "reversed": false}],
//!      "surface": {"schema": "scanfit/1", "type": "bspline_surface", ...}}
//!   ],
//!   "provenance": {"tool": "scanfit 0.1.0", "operation": "reconstruct", ...},
//!   "report": {"patches": [...], "edges": [...], "totals": {...}}
//! }
//! ```
//!
//! * `vertices[i]` is vertex `i`; `edges[e]` is edge `e` and runs from vertex
//!   `start` to vertex `end` along its `curve` (a [`crate::json::CurveDoc`]);
//!   `patches` lists the ids of the patches that use it (one on an open
//!   border, two inside), in the order of `patches` below.
//! * `patches[f].surface` is a [`crate::json::SurfaceDoc`]; `sides` are its
//!   four parameter sides in counter-clockwise order: `S(u, v0)` for `u` up,
//!   `S(u1, v)` for `v` up, `S(u, v1)` for `u` down, `S(u0, v)` for `v` down.
//!   Each is the edge it lies on and whether it runs against the edge's
//!   direction; a list of such objects, in order along the side, when the
//!   side runs over several edges (a patch with more than four corners: the
//!   surface's side is the edges' curves joined); or `null` for a side
//!   collapsed to a vertex (a three-sided patch). See [`scanfit::topology`]
//!   for the model's rules. One-edge sides are written as the single object
//!   (as documents did before chains), so older documents read unchanged.
//! * `closed` is true when every edge has two patches (the patches bound a
//!   solid).
//! * `report` (optional) holds the pipeline's measurements: per patch
//!   ([`PatchReport`]), per edge ([`EdgeReport`]) and totals
//!   ([`ModelTotals`]); unknown fields in each are kept.
//!
//! Reading is defensive: the document is size-limited, degrees are bounded
//! by [`MAX_DEGREE`], every count is checked against its list, every index
//! against its range, and the model must pass
//! [`scanfit::topology::PatchComplex::validate_structure`]; the error names
//! the patch or edge. Numbers are written in the shortest form that reads
//! back to the same `f64`, so a write/read round trip is exact.

use std::collections::BTreeMap;
use std::path::Path;

use scanfit::topology::{Edge, EdgeUse, Face, PatchComplex, Vertex};
use scanfit::Point3;
use serde::{Deserialize, Serialize};

use crate::json::{CurveDoc, Provenance, SurfaceDoc};
use crate::{Error, Result};

/// Schema identifier of model documents.
pub const MODEL_SCHEMA: &str = "scanfit-model/1";

/// Largest degree a model document may declare (per curve and per surface
/// direction); higher degrees are refused before anything is allocated.
pub const MAX_DEGREE: usize = 25;

/// Largest model document read, in bytes (256 MiB).
pub const MAX_DOCUMENT_BYTES: u64 = 256 << 20;

/// A side of a patch in the document: the edge and its direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SideDoc {
    /// Index into `edges`.
    pub edge: usize,
    /// True when the side runs from the edge's `end` to its `start`.
    pub reversed: bool,
}

/// A patch side in the document: one edge, or a chain of edges in order
/// along the side.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum SideChain {
    /// A side on one edge (a JSON object).
    One(SideDoc),
    /// A side over several edges (a JSON list of objects).
    Chain(Vec<SideDoc>),
}

impl SideChain {
    /// The document form of a side's chain (`None` for a collapsed side).
    pub fn of(chain: &[EdgeUse]) -> Option<Self> {
        let doc = |u: &EdgeUse| SideDoc {
            edge: u.edge,
            reversed: u.reversed,
        };
        match chain {
            [] => None,
            [u] => Some(SideChain::One(doc(u))),
            more => Some(SideChain::Chain(more.iter().map(doc).collect())),
        }
    }

    /// The edges of the side, in order.
    pub fn uses(&self) -> Vec<EdgeUse> {
        let use_of = |d: &SideDoc| EdgeUse {
            edge: d.edge,
            reversed: d.reversed,
        };
        match self {
            SideChain::One(d) => vec![use_of(d)],
            SideChain::Chain(v) => v.iter().map(use_of).collect(),
        }
    }
}

/// An edge in the document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EdgeDoc {
    /// Start vertex.
    pub start: usize,
    /// End vertex.
    pub end: usize,
    /// Ids of the patches that use the edge (1 or 2).
    pub patches: Vec<i64>,
    /// The shared curve, from `start` to `end`.
    pub curve: CurveDoc,
}

/// A patch in the document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatchDoc {
    /// The patch label.
    pub id: i64,
    /// The four sides (`null` = collapsed; a list = a chain of edges).
    pub sides: [Option<SideChain>; 4],
    /// The surface.
    pub surface: SurfaceDoc,
}

/// Mean, maximum and RMS of a set of distances.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Mean.
    pub mean: f64,
    /// Maximum.
    pub max: f64,
    /// Root mean square.
    pub rmse: f64,
}

/// The pipeline's measurements of one patch.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PatchReport {
    /// The patch label.
    pub id: i64,
    /// Non-degenerate sides (3 or 4).
    pub sides: usize,
    /// Points of the patch.
    pub points: usize,
    /// `|P_i - S_c(u_i, v_i)|` of the Coons patch (PDE paper eq. 15).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coons_error: Option<ErrorStats>,
    /// `|P_i - S(u_i, v_i)|` of the final surface (PDE paper eq. 15).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<ErrorStats>,
    /// Orthogonal distances of the points to the final surface.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance: Option<ErrorStats>,
    /// Further measurements.
    #[serde(flatten)]
    pub extra: BTreeMap<String, serde_json::Value>,
}

/// The pipeline's measurements of one edge.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EdgeReport {
    /// Index of the edge.
    pub edge: usize,
    /// Ids of its patches.
    pub patches: Vec<i64>,
    /// Interface points the curve was fitted to.
    #[serde(default)]
    pub points: usize,
    /// Largest gap between the two patches sampled along the edge.
    pub max_gap: f64,
    /// Largest angle between the two patches' normals along the edge, in
    /// degrees (the G1 defect); absent on a border edge.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_normal_angle_deg: Option<f64>,
    /// Further measurements.
    #[serde(flatten)]
    pub extra: BTreeMap<String, serde_json::Value>,
}

/// Totals over the model.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelTotals {
    /// Patches.
    pub patches: usize,
    /// Edges.
    pub edges: usize,
    /// Vertices.
    pub vertices: usize,
    /// Points used.
    #[serde(default)]
    pub points: usize,
    /// Largest gap over all edges.
    pub max_gap: f64,
    /// Largest G1 defect (degrees) over the inner edges.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_normal_angle_deg: Option<f64>,
    /// Error of the final surfaces over all points (PDE paper eq. 15).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<ErrorStats>,
    /// Enclosed volume of a closed model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume: Option<f64>,
    /// Further measurements.
    #[serde(flatten)]
    pub extra: BTreeMap<String, serde_json::Value>,
}

/// The report section.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelReport {
    /// Per patch, in the order of `patches`.
    #[serde(default)]
    pub patches: Vec<PatchReport>,
    /// Per edge, in the order of `edges`.
    #[serde(default)]
    pub edges: Vec<EdgeReport>,
    /// Totals.
    #[serde(default)]
    pub totals: ModelTotals,
}

/// A model document as written to and read from JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelDoc {
    /// Always [`MODEL_SCHEMA`].
    pub schema: String,
    /// Always `patch_model`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Every edge has two patches.
    pub closed: bool,
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// The shared edges.
    pub edges: Vec<EdgeDoc>,
    /// The patches.
    pub patches: Vec<PatchDoc>,
    /// Where the model came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
    /// The pipeline's measurements.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub report: Option<ModelReport>,
}

impl ModelDoc {
    /// A document for `model` without provenance or report.
    ///
    /// ```
    /// use scanfit::bspline::{KnotVector, Surface};
    /// use scanfit::topology::{FaceCorners, PatchComplex};
    /// use scanfit::Point3;
    /// use scanfit_io::model::{parse_model, ModelDoc};
    /// let k = KnotVector::uniform_clamped(1, 2).unwrap();
    /// let c = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
    ///          Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
    /// let s = Surface::new(k.clone(), k, vec![c[0], c[3], c[1], c[2]]).unwrap();
    /// let model = PatchComplex::assemble(c.to_vec(),
    ///     vec![FaceCorners { id: 5, surface: s, corners: [0, 1, 2, 3] }]).unwrap();
    /// let text = ModelDoc::new(&model).to_json().unwrap();
    /// let (doc, back) = parse_model(std::path::Path::new("m.json"), &text).unwrap();
    /// assert_eq!(back, model);
    /// assert_eq!(doc.edges[0].patches, vec![5]);
    /// assert!(!doc.closed);
    /// ```
    pub fn new(model: &PatchComplex) -> Self {
        let users = model.edge_faces();
        Self {
            schema: MODEL_SCHEMA.into(),
            kind: "patch_model".into(),
            closed: model.is_closed(),
            vertices: model
                .vertices
                .iter()
                .map(|v| [v.point.x, v.point.y, v.point.z])
                .collect(),
            edges: model
                .edges
                .iter()
                .enumerate()
                .map(|(ei, e)| EdgeDoc {
                    start: e.start,
                    end: e.end,
                    patches: users
                        .get(ei)
                        .map(|u| {
                            u.iter()
                                .filter_map(|s| model.faces.get(s.face).map(|f| f.id))
                                .collect()
                        })
                        .unwrap_or_default(),
                    curve: CurveDoc::new(&e.curve),
                })
                .collect(),
            patches: model
                .faces
                .iter()
                .map(|f| PatchDoc {
                    id: f.id,
                    sides: [0, 1, 2, 3].map(|k| SideChain::of(&f.sides[k])),
                    surface: SurfaceDoc::new(&f.surface),
                })
                .collect(),
            provenance: None,
            report: None,
        }
    }

    /// Pretty JSON text; an error if a number is not finite
    /// ([`finite_json`](crate::json::finite_json)).
    pub fn to_json(&self) -> crate::Result<String> {
        // a three-sided patch's degenerate side is `null` by the format
        crate::json::finite_json_except(self, "the model document", |at| {
            at.starts_with(".patches[") && at.contains("].sides[") && at.ends_with(']')
        })
    }

    /// The model this document describes, checked (see the module doc);
    /// `path` is used in messages only.
    pub fn model(&self, path: &Path) -> Result<PatchComplex> {
        let bad = |message: String| Error::Invalid {
            path: path.to_path_buf(),
            message,
        };
        if self.schema != MODEL_SCHEMA {
            return Err(bad(format!(
                "schema is '{}', expected '{MODEL_SCHEMA}'",
                self.schema
            )));
        }
        if self.kind != "patch_model" {
            return Err(bad(format!(
                "type is '{}', expected 'patch_model'",
                self.kind
            )));
        }
        let vertices: Vec<Vertex> = self
            .vertices
            .iter()
            .map(|c| Vertex {
                point: Point3::new(c[0], c[1], c[2]),
            })
            .collect();
        let pts: Vec<Point3> = vertices.iter().map(|v| v.point).collect();
        scanfit::validate_points(&pts).map_err(|e| bad(format!("vertices: {e}")))?;
        let mut edges = Vec::with_capacity(self.edges.len());
        for (ei, e) in self.edges.iter().enumerate() {
            let c = &e.curve;
            if c.kind != "bspline_curve" {
                return Err(bad(format!(
                    "edge {ei}: curve type is '{}', expected 'bspline_curve'",
                    c.kind
                )));
            }
            if c.degree > MAX_DEGREE {
                return Err(bad(format!(
                    "edge {ei}: curve degree {} is above the limit {MAX_DEGREE}",
                    c.degree
                )));
            }
            if let Some(w) = &c.weights {
                if w.len() != c.control_points.len() {
                    return Err(bad(format!(
                        "edge {ei}: {} weights for {} control points",
                        w.len(),
                        c.control_points.len()
                    )));
                }
            }
            for (what, v) in [("start", e.start), ("end", e.end)] {
                if v >= vertices.len() {
                    return Err(bad(format!(
                        "edge {ei}: {what} vertex {v} is out of range (the model has {} vertices)",
                        vertices.len()
                    )));
                }
            }
            let curve = c.curve().map_err(|err| bad(format!("edge {ei}: {err}")))?;
            edges.push(Edge {
                start: e.start,
                end: e.end,
                curve,
            });
        }
        let mut faces = Vec::with_capacity(self.patches.len());
        for (fi, p) in self.patches.iter().enumerate() {
            let s = &p.surface;
            let name = format!("patch {} (index {fi})", p.id);
            if s.kind != "bspline_surface" {
                return Err(bad(format!(
                    "{name}: surface type is '{}', expected 'bspline_surface'",
                    s.kind
                )));
            }
            if s.degree_u > MAX_DEGREE || s.degree_v > MAX_DEGREE {
                return Err(bad(format!(
                    "{name}: surface degrees {} x {} are above the limit {MAX_DEGREE}",
                    s.degree_u, s.degree_v
                )));
            }
            let count = s.count_u.checked_mul(s.count_v);
            if count != Some(s.control_points.len()) {
                return Err(bad(format!(
                    "{name}: count_u x count_v = {} x {} but {} control points are given",
                    s.count_u,
                    s.count_v,
                    s.control_points.len()
                )));
            }
            if let Some(w) = &s.weights {
                if w.len() != s.control_points.len() {
                    return Err(bad(format!(
                        "{name}: {} weights for {} control points",
                        w.len(),
                        s.control_points.len()
                    )));
                }
            }
            let surface = s.surface().map_err(|err| bad(format!("{name}: {err}")))?;
            let mut sides: [Vec<EdgeUse>; 4] = Default::default();
            for (k, (side, doc)) in sides.iter_mut().zip(&p.sides).enumerate() {
                *side = doc.as_ref().map(SideChain::uses).unwrap_or_default();
                if side.is_empty() && doc.is_some() {
                    return Err(bad(format!(
                        "{name}: side {k} is an empty list; write null for a side collapsed to a vertex"
                    )));
                }
            }
            faces.push(Face {
                id: p.id,
                surface,
                sides,
            });
        }
        let model = PatchComplex {
            vertices,
            edges,
            faces,
        };
        model
            .validate_structure()
            .map_err(|e| bad(format!("the model's topology is inconsistent: {e}")))?;
        // the redundant fields must agree with the topology
        let users = model.edge_faces();
        for (ei, e) in self.edges.iter().enumerate() {
            let want: Vec<i64> = users[ei].iter().map(|s| model.faces[s.face].id).collect();
            if e.patches != want {
                return Err(bad(format!(
                    "edge {ei} lists patches {:?}, but the patches' sides use it from {want:?}",
                    e.patches
                )));
            }
        }
        if self.closed != model.is_closed() {
            return Err(bad(format!(
                "closed is {}, but {}",
                self.closed,
                if model.is_closed() {
                    "every edge has two patches"
                } else {
                    "some edges have one patch"
                }
            )));
        }
        Ok(model)
    }
}

/// Reads a model document from `path` and builds its model.
pub fn read_model(path: &Path) -> Result<(ModelDoc, PatchComplex)> {
    let io = |error| Error::Io {
        path: path.to_path_buf(),
        error,
    };
    let size = std::fs::metadata(path).map_err(io)?.len();
    if size > MAX_DOCUMENT_BYTES {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the file has {size} bytes, more than the {MAX_DOCUMENT_BYTES} a model document may have"
            ),
        });
    }
    let text = std::fs::read_to_string(path).map_err(io)?;
    parse_model(path, &text)
}

/// Parses a model document (`path` for messages only).
pub fn parse_model(path: &Path, text: &str) -> Result<(ModelDoc, PatchComplex)> {
    if text.len() as u64 > MAX_DOCUMENT_BYTES {
        return Err(Error::Invalid {
            path: path.to_path_buf(),
            message: format!(
                "the document has {} bytes, more than the {MAX_DOCUMENT_BYTES} a model document may have",
                text.len()
            ),
        });
    }
    let doc: ModelDoc = serde_json::from_str(text).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: e.line(),
        message: format!("not a scanfit model document: {e}"),
    })?;
    let model = doc.model(path)?;
    Ok((doc, model))
}

#[cfg(test)]
mod tests {
    use super::*;
    use scanfit::bspline::{KnotVector, Surface};
    use scanfit::topology::FaceCorners;

    /// Two bicubic patches sharing one edge, one of them rational.
    fn two_patches() -> PatchComplex {
        let k = KnotVector::new(vec![0., 0., 0., 0., 0.4, 1., 1., 1., 1.], 3).unwrap();
        let kv = KnotVector::uniform_clamped(2, 3).unwrap();
        let mk = |x0: f64, rational: bool| {
            let mut c = Vec::new();
            for i in 0..5 {
                for j in 0..3 {
                    let x = x0 + i as f64 / 4.0;
                    let y = j as f64 / 2.0;
                    c.push(Point3::new(x, y, (x * 3.0).sin() * 0.1 + 1.0 / 7.0));
                }
            }
            // shared column i = 4 of the first = i = 0 of the second
            let w = rational.then(|| {
                (0..15)
                    .map(|k| {
                        if k < 3 {
                            1.0
                        } else {
                            1.0 + 0.1 * (k % 4) as f64
                        }
                    })
                    .collect()
            });
            Surface::with_options(k.clone(), kv.clone(), c, w, false, false).unwrap()
        };
        let v = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(2.0, 1.0, 0.0),
        ];
        let a = mk(0.0, false);
        let b = mk(1.0, true);
        let corners = |s: &Surface| {
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, w)| s.point(u, w))
        };
        let mut v = v;
        let ca = corners(&a);
        let cb = corners(&b);
        v[0] = ca[0];
        v[1] = ca[1];
        v[4] = ca[2];
        v[3] = ca[3];
        v[2] = cb[1];
        v[5] = cb[2];
        PatchComplex::assemble(
            v,
            vec![
                FaceCorners {
                    id: 1,
                    surface: a,
                    corners: [0, 1, 4, 3],
                },
                FaceCorners {
                    id: -4,
                    surface: b,
                    corners: [1, 2, 5, 4],
                },
            ],
        )
        .unwrap()
    }

    #[test]
    fn round_trip_is_exact() {
        let m = two_patches();
        m.validate().unwrap();
        let mut doc = ModelDoc::new(&m);
        let mut extra = BTreeMap::new();
        extra.insert("pde".to_string(), serde_json::json!([5, 5]));
        doc.report = Some(ModelReport {
            patches: vec![PatchReport {
                id: 1,
                sides: 4,
                points: 100,
                error: Some(ErrorStats {
                    mean: 0.1,
                    max: 0.3,
                    rmse: 0.15,
                }),
                extra,
                ..Default::default()
            }],
            edges: vec![EdgeReport {
                edge: 1,
                patches: vec![1, -4],
                max_gap: 1e-16,
                max_normal_angle_deg: Some(2.5),
                ..Default::default()
            }],
            totals: ModelTotals {
                patches: 2,
                edges: 7,
                vertices: 6,
                max_gap: 1e-16,
                ..Default::default()
            },
        });
        let text = doc.to_json().unwrap();
        assert!(text.contains("\"pde\": ["), "{text}");
        let (back, m2) = parse_model(Path::new("m.json"), &text).unwrap();
        assert_eq!(back, doc);
        assert_eq!(m2, m);
        let shared = doc.edges.iter().filter(|e| e.patches.len() == 2).count();
        assert_eq!(shared, 1);
        assert!(!back.closed);
    }

    #[test]
    fn side_chains_are_lists_and_one_edge_sides_objects() {
        let m = two_patches();
        let doc = ModelDoc::new(&m);
        // one-edge sides are written as the single object (the old form)
        assert!(doc.patches[0]
            .sides
            .iter()
            .all(|s| matches!(s, Some(SideChain::One(_)))));
        let text = doc.to_json().unwrap();
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        // the same side as a one-edge list reads to the same model
        let side = v["patches"][0]["sides"][1].clone();
        v["patches"][0]["sides"][1] = serde_json::json!([side]);
        let (_, m2) = parse_model(Path::new("m.json"), &v.to_string()).unwrap();
        assert_eq!(m2, m);
        // a chain of several edges round-trips as a list
        let mut chained = m.clone();
        chained.faces[0].sides[1] = vec![m.faces[0].sides[1][0]; 2];
        let d = ModelDoc::new(&chained);
        assert!(matches!(&d.patches[0].sides[1], Some(SideChain::Chain(c)) if c.len() == 2));
        let back: ModelDoc = serde_json::from_str(&d.to_json().unwrap()).unwrap();
        assert_eq!(back.patches[0].sides, d.patches[0].sides);
        // which the topology check then refuses (not a cycle), naming the patch
        let e = parse_model(Path::new("m.json"), &d.to_json().unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("closed cycle"), "{e}");
        // an empty list is not a collapsed side
        v["patches"][0]["sides"][1] = serde_json::json!([]);
        let e = parse_model(Path::new("m.json"), &v.to_string())
            .unwrap_err()
            .to_string();
        assert!(e.contains("side 1 is an empty list"), "{e}");
    }

    #[test]
    fn files_are_read_and_oversized_files_refused_before_reading() {
        let dir = std::env::temp_dir().join(format!("scanfit-model-doc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let m = two_patches();
        let path = dir.join("m.json");
        std::fs::write(&path, ModelDoc::new(&m).to_json().unwrap()).unwrap();
        let (_, back) = read_model(&path).unwrap();
        assert_eq!(back, m);
        // a sparse file just over the limit: refused by its size, not read
        let big = dir.join("big.json");
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(MAX_DOCUMENT_BYTES + 1).unwrap();
        let e = read_model(&big).unwrap_err().to_string();
        assert!(e.contains("more than the 268435456"), "{e}");
        let e = read_model(&dir.join("missing.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.json"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn err(text: &str) -> String {
        parse_model(Path::new("bad.json"), text)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn hostile_documents_are_refused_with_a_reason() {
        let m = two_patches();
        let good: serde_json::Value =
            serde_json::from_str(&ModelDoc::new(&m).to_json().unwrap()).unwrap();
        let with = |f: &dyn Fn(&mut serde_json::Value)| {
            let mut v = good.clone();
            f(&mut v);
            v.to_string()
        };
        let e = err(&with(&|v| {
            v["patches"][0]["surface"]["degree_u"] = 1_000_000_000.into()
        }));
        assert!(
            e.contains("patch 1 (index 0): surface degrees 1000000000"),
            "{e}"
        );
        let e = err(&with(&|v| v["edges"][2]["curve"]["degree"] = 99.into()));
        assert!(
            e.contains("edge 2: curve degree 99 is above the limit 25"),
            "{e}"
        );
        let e = err(&with(&|v| {
            v["patches"][1]["surface"]["count_u"] = (usize::MAX / 2).into()
        }));
        assert!(e.contains("patch -4 (index 1): count_u x count_v"), "{e}");
        let e = err(&with(&|v| {
            v["patches"][1]["surface"]["weights"] = serde_json::json!([1.0])
        }));
        assert!(e.contains("1 weights for 15 control points"), "{e}");
        let e = err(&with(&|v| v["edges"][0]["end"] = 17.into()));
        assert!(e.contains("edge 0: end vertex 17 is out of range"), "{e}");
        let e = err(&with(&|v| v["patches"][0]["sides"][1]["edge"] = 70.into()));
        assert!(e.contains("side 1 uses edge 70"), "{e}");
        let e = err(&with(&|v| {
            v["edges"][1]["patches"] = serde_json::json!([1])
        }));
        assert!(e.contains("edge 1 lists patches [1]"), "{e}");
        let e = err(&with(&|v| v["closed"] = true.into()));
        assert!(e.contains("closed is true"), "{e}");
        let e = err(&with(&|v| v["vertices"][0][0] = 1e300.into()));
        assert!(e.contains("vertices:"), "{e}");
        let e = err(&with(&|v| v["schema"] = "scanfit/1".into()));
        assert!(e.contains("expected 'scanfit-model/1'"), "{e}");
        let e = err(&with(&|v| {
            v["patches"][0]["surface"]["knots_u"][5] = (-1.0).into()
        }));
        assert!(e.contains("patch 1 (index 0): invalid knot vector"), "{e}");
        let e = err("{\"schema\": \"scanfit-model/1\"");
        assert!(e.starts_with("bad.json:1:"), "{e}");
        let e = err(&with(&|v| {
            v["patches"][0]["sides"][0] = serde_json::Value::Null
        }));
        assert!(
            e.contains("closed cycle") || e.contains("used by no face"),
            "{e}"
        );
    }
}
