//! The shared topology of a multi-patch model: vertices, edges that carry one
//! boundary curve each, and faces (patches) whose four parameter sides use
//! those edges.
//!
//! The PDE paper (`pde-coons-surface-reconstruction`, abstract, §4 and Figs.
//! 9-10) reconstructs a whole object as patches that join without gaps because
//! adjacent patches share their boundary curves; this module is the data
//! structure that says which curve is shared by whom, and checks that the
//! surfaces really do meet there.
//!
//! # Conventions
//!
//! * Vertex and edge ids are indices into [`PatchComplex::vertices`] and
//!   [`PatchComplex::edges`]; a face's `id` is its patch label (free).
//! * An [`Edge`]'s curve runs from vertex `start` (at the start of its domain)
//!   to vertex `end`; `start != end` (a closed loop edge is not a side).
//! * A [`Face`]'s surface has the parameter domain
//!   `[u0, u1] x [v0, v1]` (its knot domain, usually `[0, 1]^2`). Its four
//!   sides, in counter-clockwise order in the parameter plane, are
//!   `[0]` `S(u, v0)` with `u: u0 -> u1`, `[1]` `S(u1, v)` with `v: v0 -> v1`,
//!   `[2]` `S(u, v1)` with `u: u1 -> u0`, `[3]` `S(u0, v)` with `v: v1 -> v0`.
//!   Side `k` starts at corner `k`: `S(u0,v0)`, `S(u1,v0)`, `S(u1,v1)`, `S(u0,v1)`.
//! * `sides[k]` is the chain of edges that side `k`, run in the direction
//!   above, lies on, in order: usually one [`EdgeUse`] `{ edge, reversed }`
//!   (the edge's curve run forwards, `reversed == false`, from `start` to
//!   `end`, or backwards), several where a patch has more than four corners
//!   and a side runs over some of them (each edge then covers a piece of the
//!   side between the vertices where the chain's edges meet, found by closest
//!   point on the side, [`PatchComplex::chain_ranges`]). An empty chain is a
//!   degenerate side collapsed to one vertex (the three-sided patch of the
//!   PDE paper §5.2, the Coons apex of [`crate::base::CoonsPatch`] with
//!   `P(0, v)` a point, which is side `[3]` here). At most one side of a face
//!   is degenerate.
//! * Orientation: the face normal is `S_u x S_v`. Two faces that share an
//!   edge must traverse it in opposite directions, which is exactly the
//!   condition for their normals to point to the same side of the shell.
//!
//! # Checks
//!
//! [`PatchComplex::validate`] checks the combinatorics (indices in range, each
//! face's sides form a closed cycle of vertices, every edge used by one or two
//! faces and, if two, in opposite directions) and the geometry: every edge
//! curve starts and ends at its vertices, every face side coincides with its
//! edge's curve, and every degenerate side is a single point at its vertex, all
//! to a tolerance relative to the model's size ([`PatchComplex::scale`]).
//! [`PatchComplex::boundary_gaps`] reports the measured gaps per edge and
//! [`PatchComplex::normal_angles`] the angle between the two faces' normals
//! along it (the G1 defect).
//! [`PatchComplex::signed_volume`] integrates the enclosed volume of a closed
//! complex by the divergence theorem (see [`volume`]).

mod count;
mod gaps;
pub mod volume;

pub use gaps::{distance_to_curve, EdgeGap};

use crate::bspline::{BasisWorkspace, Curve, KnotVector, Surface};
use crate::{Error, Point3, Result};

/// Default tolerance of [`PatchComplex::validate`], relative to
/// [`PatchComplex::scale`]: surfaces built to share their boundary curves
/// exactly meet to rounding (about `1e-15`); this leaves room for curves that
/// went through a text file.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-7;

/// A corner point shared by the edges that end there.
#[derive(Debug, Clone, PartialEq)]
pub struct Vertex {
    /// Its position.
    pub point: Point3,
}

/// A boundary curve shared by the faces on either side; its curve runs from
/// vertex `start` to vertex `end`.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// Vertex at the start of the curve's domain.
    pub start: usize,
    /// Vertex at the end of the curve's domain.
    pub end: usize,
    /// The curve (any B-spline; clamped in practice).
    pub curve: Curve,
}

/// A face's use of an edge; `reversed` = traversed from `end` to `start`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeUse {
    /// Index of the edge.
    pub edge: usize,
    /// True when the face side runs from the edge's `end` to its `start`.
    pub reversed: bool,
}

/// One patch: its surface and the edge chains on its four parameter sides.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The patch label.
    pub id: i64,
    /// The surface on its knot domain (usually `[0,1]^2`).
    pub surface: Surface,
    /// The four parameter sides in counter-clockwise order:
    /// `[0]` `S(u,0)` u:0->1, `[1]` `S(1,v)` v:0->1, `[2]` `S(u,1)` u:1->0,
    /// `[3]` `S(0,v)` v:1->0, each the chain of edges it lies on, in the
    /// side's direction (one edge, or several when the patch has more than
    /// four corners). Empty = a degenerate side collapsed to a vertex
    /// (three-sided patch, PDE paper §5.2 / Coons apex).
    pub sides: [Vec<EdgeUse>; 4],
}

/// A face side that uses an edge: which face, which of its four sides, the
/// position in the side's chain, and in which direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SideRef {
    /// Index of the face.
    pub face: usize,
    /// Which side (0..4, see [`Face::sides`]).
    pub side: usize,
    /// Position of the edge in the side's chain (0 for a one-edge side).
    pub index: usize,
    /// True when the side runs from the edge's `end` to its `start`.
    pub reversed: bool,
}

/// Vertices, shared edges and faces of a multi-patch model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PatchComplex {
    /// The corners.
    pub vertices: Vec<Vertex>,
    /// The shared boundary curves.
    pub edges: Vec<Edge>,
    /// The patches.
    pub faces: Vec<Face>,
}

impl EdgeUse {
    /// The vertices `(from, to)` in the direction the face traverses the edge.
    pub fn oriented_vertices(&self, edges: &[Edge]) -> Option<(usize, usize)> {
        let e = edges.get(self.edge)?;
        Some(if self.reversed {
            (e.end, e.start)
        } else {
            (e.start, e.end)
        })
    }
}

impl Face {
    /// Corner `k` (0..4) of the parameter domain, the start of side `k`:
    /// `(u0,v0)`, `(u1,v0)`, `(u1,v1)`, `(u0,v1)`.
    pub fn corner_parameters(&self, k: usize) -> (f64, f64) {
        let ((u0, u1), (v0, v1)) = self.surface.domain();
        match k % 4 {
            0 => (u0, v0),
            1 => (u1, v0),
            2 => (u1, v1),
            _ => (u0, v1),
        }
    }

    /// Parameters `(u, v)` at fraction `s` in `[0, 1]` along side `k` in the
    /// side's direction (see [`Face::sides`]).
    pub fn side_parameters(&self, k: usize, s: f64) -> (f64, f64) {
        let (a0, a1) = self.corner_parameters(k);
        let (b0, b1) = self.corner_parameters(k + 1);
        (a0 + (b0 - a0) * s, a1 + (b1 - a1) * s)
    }

    /// Point at fraction `s` along side `k`.
    pub fn side_point(&self, k: usize, s: f64) -> Point3 {
        let (u, v) = self.side_parameters(k, s);
        self.surface.point(u, v)
    }

    /// Side `k` of the surface as a B-spline curve in the side's direction
    /// (the iso-curve `v = v0`, `u = u1`, `v = v1` or `u = u0`; exact, also for
    /// unclamped and rational surfaces: the control points are the rows of the
    /// net combined with the other direction's basis functions at the boundary
    /// parameter, in homogeneous coordinates). Sides 2 and 3 are reversed so
    /// that the curve runs counter-clockwise; its domain is the surface's
    /// domain in that direction.
    pub fn side_curve(&self, k: usize) -> Result<Curve> {
        let s = &self.surface;
        let ((u0, u1), (v0, v1)) = s.domain();
        let (nu, nv) = s.counts();
        let (p, q) = s.degrees();
        let (periodic_u, periodic_v) = s.periodic();
        let weights = s.weights();
        let net = s.control_points();
        // the homogeneous control points of the iso-curve at parameter `t` of
        // the direction with knots `across` (degree `deg`): for each index
        // `a` along the side, the net entries `at(a, c)` for the across index
        // `c` combined with that direction's basis functions at `t`
        let combine = |across: &KnotVector,
                       deg: usize,
                       t: f64,
                       count: usize,
                       at: &dyn Fn(usize, usize) -> usize| {
            let span = across.find_span(t);
            let mut ws = BasisWorkspace::new(deg, 0);
            let basis = ws.values(across.as_slice(), span, t).to_vec();
            (0..count)
                .map(|along| {
                    let mut h = [0.0; 4];
                    for (r, &b) in basis.iter().enumerate() {
                        let idx = at(along, span - deg + r);
                        let w = weights.map_or(1.0, |w| w[idx]) * b;
                        let c = net[idx];
                        h[0] += c.x * w;
                        h[1] += c.y * w;
                        h[2] += c.z * w;
                        h[3] += w;
                    }
                    h
                })
                .collect::<Vec<[f64; 4]>>()
        };
        // sides 0, 2 run along u (v fixed), sides 1, 3 along v (u fixed)
        let (knots, periodic, hom): (&KnotVector, bool, Vec<[f64; 4]>) = match k % 4 {
            0 | 2 => {
                let vf = if k % 4 == 0 { v0 } else { v1 };
                let hom = combine(s.knots_v(), q, vf, nu, &|i, j| i * nv + j);
                (s.knots_u(), periodic_u, hom)
            }
            _ => {
                let uf = if k % 4 == 1 { u1 } else { u0 };
                let hom = combine(s.knots_u(), p, uf, nv, &|j, i| i * nv + j);
                (s.knots_v(), periodic_v, hom)
            }
        };
        let reverse = k % 4 >= 2;
        let (a, b) = knots.domain();
        let mut t: Vec<f64> = knots.as_slice().to_vec();
        let mut hom = hom;
        if reverse {
            t = t.iter().rev().map(|&x| a + b - x).collect();
            hom.reverse();
        }
        let kv = KnotVector::new(t, knots.degree())?;
        if hom.iter().any(|h| h[3].is_nan() || h[3] <= 0.0) {
            return Err(Error::InvalidInput(format!(
                "face {}: side {k} has a non-positive combined weight; the surface's weights must be positive",
                self.id
            )));
        }
        let ctrl: Vec<Point3> = hom
            .iter()
            .map(|h| Point3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3]))
            .collect();
        let w: Option<Vec<f64>> = weights.map(|_| hom.iter().map(|h| h[3]).collect());
        if periodic {
            Curve::new_periodic(kv, ctrl, w)
        } else {
            match w {
                Some(w) => Curve::new_rational(kv, ctrl, w),
                None => Curve::new(kv, ctrl),
            }
        }
    }

    /// Number of non-degenerate sides (3 or 4 in a valid complex).
    pub fn side_count(&self) -> usize {
        self.sides.iter().filter(|s| !s.is_empty()).count()
    }

    /// Number of edge uses around the face (the edges of its loop).
    pub fn use_count(&self) -> usize {
        self.sides.iter().map(Vec::len).sum()
    }

    /// The edge uses around the face in loop order, with their side.
    pub fn uses(&self) -> impl Iterator<Item = (usize, EdgeUse)> + '_ {
        self.sides
            .iter()
            .enumerate()
            .flat_map(|(k, c)| c.iter().map(move |&u| (k, u)))
    }
}

/// A face given by its surface and the vertex ids at its four parameter
/// corners, for [`PatchComplex::assemble`].
#[derive(Debug, Clone, PartialEq)]
pub struct FaceCorners {
    /// The patch label.
    pub id: i64,
    /// The surface.
    pub surface: Surface,
    /// Vertex ids at the corners `(u0,v0)`, `(u1,v0)`, `(u1,v1)`, `(u0,v1)`;
    /// two consecutive equal ids make the side between them degenerate.
    pub corners: [usize; 4],
}

impl PatchComplex {
    /// Builds a complex from vertex positions and faces given by their corner
    /// vertices: one edge per distinct pair of vertices joined by a face side
    /// (so two faces with a side between the same two vertices share that
    /// edge; at most one edge may join two vertices), directed from the lower
    /// to the higher vertex id, and carrying the side curve of the first face
    /// that uses it. Run [`PatchComplex::validate`] on the result to check that
    /// the other faces' sides coincide with those curves.
    ///
    /// ```
    /// use scanfit::bspline::{KnotVector, Surface};
    /// use scanfit::topology::{FaceCorners, PatchComplex};
    /// use scanfit::Point3;
    /// let k = KnotVector::uniform_clamped(1, 2).unwrap();
    /// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
    /// // two unit squares side by side, sharing the edge x = 1
    /// let sq = |x0: f64| Surface::new(k.clone(), k.clone(),
    ///     vec![p(x0, 0.0), p(x0, 1.0), p(x0 + 1.0, 0.0), p(x0 + 1.0, 1.0)]).unwrap();
    /// let verts = vec![p(0.0, 0.0), p(1.0, 0.0), p(2.0, 0.0), p(0.0, 1.0), p(1.0, 1.0), p(2.0, 1.0)];
    /// let model = PatchComplex::assemble(verts, vec![
    ///     FaceCorners { id: 1, surface: sq(0.0), corners: [0, 1, 4, 3] },
    ///     FaceCorners { id: 2, surface: sq(1.0), corners: [1, 2, 5, 4] },
    /// ]).unwrap();
    /// assert_eq!(model.edges.len(), 7);
    /// model.validate().unwrap();
    /// assert_eq!(model.border_edges().len(), 6);
    /// ```
    pub fn assemble(vertices: Vec<Point3>, faces: Vec<FaceCorners>) -> Result<Self> {
        let mut model = PatchComplex {
            vertices: vertices.into_iter().map(|point| Vertex { point }).collect(),
            edges: Vec::new(),
            faces: Vec::with_capacity(faces.len()),
        };
        let mut by_pair: std::collections::HashMap<(usize, usize), usize> =
            std::collections::HashMap::new();
        for (fi, fc) in faces.into_iter().enumerate() {
            if let Some(&bad) = fc.corners.iter().find(|&&c| c >= model.vertices.len()) {
                return Err(Error::InvalidInput(format!(
                    "face {fi} (patch {}) has corner vertex {bad}, but only {} vertices are given",
                    fc.id,
                    model.vertices.len()
                )));
            }
            let face = Face {
                id: fc.id,
                surface: fc.surface,
                sides: Default::default(),
            };
            let mut sides: [Vec<EdgeUse>; 4] = Default::default();
            for k in 0..4 {
                let (a, b) = (fc.corners[k], fc.corners[(k + 1) % 4]);
                if a == b {
                    continue;
                }
                let key = (a.min(b), a.max(b));
                let edge = match by_pair.get(&key) {
                    Some(&e) => e,
                    None => {
                        let c = face.side_curve(k)?;
                        let curve = if a < b { c } else { reversed_curve(&c)? };
                        model.edges.push(Edge {
                            start: key.0,
                            end: key.1,
                            curve,
                        });
                        by_pair.insert(key, model.edges.len() - 1);
                        model.edges.len() - 1
                    }
                };
                sides[k] = vec![EdgeUse {
                    edge,
                    reversed: a > b,
                }];
            }
            model.faces.push(Face { sides, ..face });
        }
        Ok(model)
    }
}

/// The same curve run backwards on the same domain, `C_r(t) = C(a + b - t)`.
pub fn reversed_curve(c: &Curve) -> Result<Curve> {
    let (a, b) = c.domain();
    let t: Vec<f64> = c
        .knots()
        .as_slice()
        .iter()
        .rev()
        .map(|&x| a + b - x)
        .collect();
    let kv = KnotVector::new(t, c.degree())?;
    let mut ctrl = c.control_points().to_vec();
    ctrl.reverse();
    let w = c
        .weights()
        .map(|w| w.iter().rev().copied().collect::<Vec<f64>>());
    if c.is_periodic() {
        Curve::new_periodic(kv, ctrl, w)
    } else {
        match w {
            Some(w) => Curve::new_rational(kv, ctrl, w),
            None => Curve::new(kv, ctrl),
        }
    }
}

impl PatchComplex {
    /// For every edge, the face sides that use it (in face order).
    pub fn edge_faces(&self) -> Vec<Vec<SideRef>> {
        let mut out = vec![Vec::new(); self.edges.len()];
        for (fi, f) in self.faces.iter().enumerate() {
            for (k, chain) in f.sides.iter().enumerate() {
                for (index, u) in chain.iter().enumerate() {
                    if let Some(list) = out.get_mut(u.edge) {
                        list.push(SideRef {
                            face: fi,
                            side: k,
                            index,
                            reversed: u.reversed,
                        });
                    }
                }
            }
        }
        out
    }

    /// True when the complex has faces and every edge is used by exactly two
    /// face sides (the faces bound a solid if the complex is also valid).
    pub fn is_closed(&self) -> bool {
        !self.faces.is_empty() && self.edge_faces().iter().all(|u| u.len() == 2)
    }

    /// Edges used by exactly one face: the open border of the model.
    pub fn border_edges(&self) -> Vec<usize> {
        self.edge_faces()
            .iter()
            .enumerate()
            .filter(|(_, u)| u.len() == 1)
            .map(|(e, _)| e)
            .collect()
    }

    /// The model's size: the diagonal of the bounding box of all vertices and
    /// all surface and curve control points (tolerances are relative to it).
    pub fn scale(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut add = |p: &Point3| {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        };
        self.vertices.iter().for_each(|v| add(&v.point));
        self.edges
            .iter()
            .for_each(|e| e.curve.control_points().iter().for_each(&mut add));
        self.faces
            .iter()
            .for_each(|f| f.surface.control_points().iter().for_each(&mut add));
        if lo[0] > hi[0] {
            return 0.0;
        }
        ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
    }

    /// The vertex cycle of face `fi`: for each edge use around it in order
    /// (every edge of every side's chain), the vertex it starts at. `None`
    /// for an out-of-range face or edge.
    pub fn face_vertices(&self, fi: usize) -> Option<Vec<usize>> {
        let f = self.faces.get(fi)?;
        f.uses()
            .map(|(_, u)| u.oriented_vertices(&self.edges).map(|(a, _)| a))
            .collect()
    }

    /// The vertex a degenerate side `k` of face `fi` collapses to: the end of
    /// the previous non-degenerate side. `None` when side `k` is not
    /// degenerate or the face is out of range.
    pub fn degenerate_vertex(&self, fi: usize, k: usize) -> Option<usize> {
        let f = self.faces.get(fi)?;
        if !f.sides.get(k)?.is_empty() {
            return None;
        }
        (1..4)
            .map(|d| (k + 4 - d) % 4)
            .find_map(|j| f.sides[j].last())
            .and_then(|u| u.oriented_vertices(&self.edges).map(|(_, b)| b))
    }

    /// Checks the combinatorics only (see [`PatchComplex::validate`]).
    pub fn validate_structure(&self) -> Result<()> {
        if self.faces.is_empty() {
            return Err(Error::InvalidInput(
                "the model has no faces; give at least one patch".into(),
            ));
        }
        let nv = self.vertices.len();
        for (ei, e) in self.edges.iter().enumerate() {
            if e.start >= nv || e.end >= nv {
                return Err(Error::InvalidInput(format!(
                    "edge {ei} joins vertices {} and {}, but the model has only {nv} vertices",
                    e.start, e.end
                )));
            }
            if e.start == e.end {
                return Err(Error::InvalidInput(format!(
                    "edge {ei} starts and ends at vertex {}; a closed loop is not a patch side, split it at a second vertex",
                    e.start
                )));
            }
        }
        for (fi, f) in self.faces.iter().enumerate() {
            let uses: Vec<(usize, EdgeUse)> = f.uses().collect();
            if f.side_count() < 3 {
                return Err(Error::InvalidInput(format!(
                    "face {fi} (patch {}) has {} non-degenerate sides; a patch needs 3 or 4",
                    f.id,
                    f.side_count()
                )));
            }
            for &(k, u) in &uses {
                if u.edge >= self.edges.len() {
                    return Err(Error::InvalidInput(format!(
                        "face {fi} (patch {}) side {k} uses edge {}, but the model has only {} edges",
                        f.id,
                        u.edge,
                        self.edges.len()
                    )));
                }
            }
            for w in 0..uses.len() {
                let (k, a) = uses[w];
                let (k2, b) = uses[(w + 1) % uses.len()];
                let (_, a_end) = a.oriented_vertices(&self.edges).unwrap_or((0, 0));
                let (b_start, _) = b.oriented_vertices(&self.edges).unwrap_or((0, 0));
                if a_end != b_start {
                    return Err(Error::InvalidInput(format!(
                        "face {fi} (patch {}): edge {} on side {k} ends at vertex {a_end} but the next edge {} on side {k2} starts at vertex {b_start}; the sides' edges must form a closed cycle (check the edges' directions and `reversed` flags)",
                        f.id, a.edge, b.edge
                    )));
                }
            }
        }
        for (ei, users) in self.edge_faces().iter().enumerate() {
            match users.as_slice() {
                [] => {
                    return Err(Error::InvalidInput(format!(
                        "edge {ei} is used by no face; remove it"
                    )))
                }
                [_] => {}
                [a, b] => {
                    if a.face == b.face {
                        return Err(Error::InvalidInput(format!(
                            "edge {ei} is used twice by face {} (sides {} and {}); a patch may not be glued to itself",
                            a.face, a.side, b.side
                        )));
                    }
                    if a.reversed == b.reversed {
                        return Err(Error::InvalidInput(format!(
                            "edge {ei} is traversed in the same direction by faces {} and {}; neighbouring faces must run their shared edge in opposite directions (flip one face's parameterization)",
                            a.face, b.face
                        )));
                    }
                }
                more => {
                    let faces: Vec<String> = more.iter().map(|s| s.face.to_string()).collect();
                    return Err(Error::InvalidInput(format!(
                        "edge {ei} is used by {} face sides (faces {}); a manifold model shares an edge between at most two faces",
                        more.len(),
                        faces.join(", ")
                    )));
                }
            }
        }
        Ok(())
    }

    /// Checks the model with [`DEFAULT_RELATIVE_TOLERANCE`]; see
    /// [`PatchComplex::validate_with`].
    ///
    /// ```
    /// use scanfit::bspline::{Curve, KnotVector, Surface};
    /// use scanfit::topology::{Edge, EdgeUse, Face, PatchComplex, Vertex};
    /// use scanfit::Point3;
    /// // one bilinear square with its four border edges
    /// let c = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
    ///          Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
    /// let k = KnotVector::uniform_clamped(1, 2).unwrap();
    /// let line = |a: Point3, b: Point3| Curve::new(k.clone(), vec![a, b]).unwrap();
    /// let surface = Surface::new(k.clone(), k.clone(), vec![c[0], c[3], c[1], c[2]]).unwrap();
    /// let model = PatchComplex {
    ///     vertices: c.iter().map(|&point| Vertex { point }).collect(),
    ///     edges: (0..4).map(|i| Edge { start: i, end: (i + 1) % 4,
    ///                                  curve: line(c[i], c[(i + 1) % 4]) }).collect(),
    ///     faces: vec![Face { id: 7, surface,
    ///         sides: [0, 1, 2, 3].map(|e| vec![EdgeUse { edge: e, reversed: false }]) }],
    /// };
    /// model.validate().unwrap();
    /// assert!(!model.is_closed());
    /// assert_eq!(model.border_edges(), vec![0, 1, 2, 3]);
    /// assert!(model.max_boundary_gap().unwrap() < 1e-12);
    /// ```
    pub fn validate(&self) -> Result<()> {
        self.validate_with(DEFAULT_RELATIVE_TOLERANCE)
    }

    /// Checks indices, the side cycles and edge uses
    /// ([`PatchComplex::validate_structure`]), then the geometry to
    /// `relative_tolerance * scale()`: edge curves end at their vertices, each
    /// face side coincides with its edge's curve, each degenerate side is a
    /// point at its vertex. The error names the face, side, edge and the gap.
    pub fn validate_with(&self, relative_tolerance: f64) -> Result<()> {
        if !(relative_tolerance.is_finite() && relative_tolerance >= 0.0) {
            return Err(Error::InvalidInput(format!(
                "the relative gap tolerance must be finite and >= 0, got {relative_tolerance}"
            )));
        }
        self.validate_structure()?;
        let scale = self.scale().max(f64::MIN_POSITIVE);
        let tol = relative_tolerance * scale;
        for (ei, e) in self.edges.iter().enumerate() {
            let (a, b) = e.curve.domain();
            for (which, t, vi) in [("start", a, e.start), ("end", b, e.end)] {
                let d = (e.curve.point(t) - self.vertices[vi].point).norm();
                if d.is_nan() || d > tol {
                    return Err(Error::InvalidInput(format!(
                        "edge {ei}: its curve's {which} is {d:e} from vertex {vi} (tolerance {tol:e} = {relative_tolerance:e} x model size {scale:e}); the curve must end at its vertices"
                    )));
                }
            }
        }
        for (fi, f) in self.faces.iter().enumerate() {
            for (k, chain) in f.sides.iter().enumerate() {
                if chain.len() < 2 {
                    continue;
                }
                let c = f.side_curve(k)?;
                let (_, d) = gaps::chain_junctions(&c, chain, self, fi, k)?;
                if d.is_nan() || d > tol {
                    return Err(Error::InvalidInput(format!(
                        "face {fi} (patch {}) side {k}: a vertex where its edges meet is {d:e} from the side (tolerance {tol:e}); the surface's boundary must run through every vertex of the side's chain",
                        f.id
                    )));
                }
            }
        }
        for g in self.boundary_gaps()? {
            if let Some(side) = g.worst_side {
                if g.curve_gap.is_nan() || g.curve_gap > tol {
                    let f = &self.faces[side.face];
                    return Err(Error::InvalidInput(format!(
                        "face {} (patch {}) side {} (its edge {} of {}) is {:e} away from edge {}'s curve (tolerance {tol:e} = {relative_tolerance:e} x model size {scale:e}); the surface's boundary must coincide with the shared edge curve",
                        side.face, f.id, side.side, side.index + 1, f.sides[side.side].len(), g.curve_gap, g.edge
                    )));
                }
            }
        }
        for (fi, f) in self.faces.iter().enumerate() {
            for k in 0..4 {
                if let Some(vi) = self.degenerate_vertex(fi, k) {
                    let apex = self.vertices[vi].point;
                    let d = (0..=16)
                        .map(|i| (f.side_point(k, i as f64 / 16.0) - apex).norm())
                        .fold(0.0f64, f64::max);
                    if d.is_nan() || d > tol {
                        return Err(Error::InvalidInput(format!(
                            "face {fi} (patch {}) side {k} is marked degenerate but reaches {d:e} from its vertex {vi} (tolerance {tol:e}); collapse that side of the surface to the vertex or give it an edge",
                            f.id
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Signed volume enclosed by the faces (divergence theorem, see
    /// [`volume::signed_volume`]); positive when the normals `S_u x S_v` point
    /// outwards. Meaningful for a closed, valid complex.
    pub fn signed_volume(&self) -> f64 {
        volume::signed_volume(self.faces.iter().map(|f| &f.surface))
    }
}

#[cfg(test)]
mod tests;
