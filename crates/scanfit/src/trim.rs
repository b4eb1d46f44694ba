//! Trimmed surfaces: a fitted B-spline surface bounded by the cloud's own
//! boundary loops instead of its whole parameter rectangle.
//!
//! The boundary loops come from the alpha shape of the points
//! ([`crate::cloud::boundary_loops`], [PDE23] §4.1): an outer loop and one
//! loop per hole, as point indices, taken in the plane the pipeline made
//! the parameters in ([`crate::pipeline::trim`] says which for each
//! pipeline). Every pipeline that fits a surface has
//! already given each point its parameters `(u, v)`, so each loop maps into
//! the surface's parameter space through the parameters of its points. There
//! it is approximated by a closed (periodic) cubic B-spline curve, the
//! *pcurve*, by the least-squares kernel of [`crate::fit`] ([NURBS97]
//! §9.4.1, periodic form) with chord-length parameters in `(u, v)`; its
//! control points are kept inside the domain, so by the convex-hull
//! property the curve is too. The curve's 3D image `S(c(t))` is not a
//! B-spline of the same form; it is approximated by a closed B-spline on the
//! same parameter `t` (the same least squares on samples of `S(c(t))`), with
//! control points added until its largest deviation from `S(c(t))` is below
//! [`TrimConfig::space_tolerance`] times the net's diagonal. CAD files carry
//! both (STEP `SURFACE_CURVE` with a `PCURVE`, IGES entity 142).
//!
//! When the outer loop runs along the domain's edges (the Coons and PDE
//! pipelines map the boundary onto the edges of the unit square; a square
//! cloud fitted over its bounding rectangle does too) the face keeps its
//! natural rectangular boundary and only the holes are trimmed
//! ([`TrimmedSurface::outer`] is `None`).
//!
//! [`TrimmedSurface::tessellate`] meshes only the trimmed part: the
//! rectangle's grid mesh with the triangles outside dropped and the
//! triangles the trim curves cross cut along them (marching triangles on the
//! inside/outside test, crossings found by bisection), so the mesh's area
//! converges to the face's area at second order in the grid step.

use std::collections::HashMap;

use crate::bspline::{Curve, KnotVector, Mesh, Surface};
use crate::cloud::boundary::Boundary;
use crate::fit::{lsq_values, LeastSquaresOptions};
use crate::param::knots::periodic_least_squares;
use crate::{Error, Point3, Result, Vector3};

/// Smallest share of the points' parameter rectangle the outer loop must
/// enclose (a disc encloses 79%, most outlines more than half).
pub const MIN_OUTER_SHARE: f64 = 0.25;

/// Parameters of [`trim_surface`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TrimConfig {
    /// Loop points per control point of a pcurve (default 4): the alpha
    /// shape's loop zig-zags at the point spacing, so a pcurve with one
    /// control point per four loop points follows the outline and smooths
    /// the zig-zag.
    pub points_per_control: usize,
    /// Holes with fewer boundary points are not trimmed (default 12: a
    /// closed cubic needs at least 7 control points and a few points per
    /// span).
    pub min_hole_points: usize,
    /// The outer loop counts as the domain's own edges when at least this
    /// share of its points (default 0.9) lies within
    /// [`TrimConfig::edge_steps`] loop steps of the domain's edges.
    pub edge_share: f64,
    /// Distance to the domain's edges, in median loop steps in `(u, v)`,
    /// below which an outer-loop point lies on an edge (default 3).
    pub edge_steps: f64,
    /// Largest deviation of a 3D trim curve from the surface image of its
    /// pcurve, relative to the control net's diagonal (default 1e-4).
    pub space_tolerance: f64,
}

impl Default for TrimConfig {
    fn default() -> Self {
        Self {
            points_per_control: 4,
            min_hole_points: 12,
            edge_share: 0.9,
            edge_steps: 3.0,
            space_tolerance: 1e-4,
        }
    }
}

/// One closed trimming curve: in the surface's parameter space and in space.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimCurve {
    /// The pcurve: a closed periodic B-spline with points `(u, v, 0)`,
    /// parameter `t` in `[0, 1]`; counter-clockwise in `(u, v)` for the
    /// outer loop, clockwise for holes.
    pub uv: Curve,
    /// Its 3D image, a closed periodic B-spline on the same parameter `t`.
    pub space: Curve,
    /// Largest measured distance between `space(t)` and `S(uv(t))`.
    pub deviation: f64,
    /// Number of boundary points the loop had.
    pub points: usize,
}

/// A surface bounded by trimming curves.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimmedSurface {
    /// The underlying (untrimmed, clamped, non-periodic) surface.
    pub surface: Surface,
    /// The outer trimming curve; `None` when the face keeps the domain's
    /// rectangular boundary.
    pub outer: Option<TrimCurve>,
    /// One clockwise curve per hole.
    pub holes: Vec<TrimCurve>,
    /// Holes of the boundary left untrimmed (fewer than
    /// [`TrimConfig::min_hole_points`] boundary points).
    pub skipped_holes: usize,
}

/// Trims `surface` by the boundary loops of the points it was fitted to.
/// `uv` holds the parameters the fit gave each point (indexed like the
/// points the boundary was computed from).
///
/// Errors: a periodic surface; `uv` shorter than a loop's indices; a
/// parameter outside the domain by more than its size or not finite; an
/// outer loop too short for a closed cubic.
///
/// ```
/// use scanfit::cloud::boundary::{boundary_loops, BoundaryConfig};
/// use scanfit::fit::surface::{fit_surface, SurfaceFitConfig};
/// use scanfit::trim::{trim_surface, TrimConfig};
/// use scanfit::Point3;
/// // a 41 x 41 grid over the unit square with a round hole in the middle
/// let mut pts = Vec::new();
/// let mut uv = Vec::new();
/// for i in 0..=40 {
///     for j in 0..=40 {
///         let (x, y) = (i as f64 / 40.0, j as f64 / 40.0);
///         if (x - 0.5).hypot(y - 0.5) > 0.2 {
///             pts.push(Point3::new(x, y, 0.1 * x * y));
///             uv.push([x, y]);
///         }
///     }
/// }
/// let cfg = SurfaceFitConfig { ctrl: (8, 8), ..SurfaceFitConfig::default() };
/// let surface = fit_surface(&pts, &uv, &cfg).unwrap();
/// let boundary = boundary_loops(&pts, &BoundaryConfig::default()).unwrap();
/// let t = trim_surface(&surface, &uv, &boundary, &TrimConfig::default()).unwrap();
/// assert!(t.outer.is_none()); // the outline is the domain's rectangle
/// assert_eq!(t.holes.len(), 1);
/// assert!(!t.contains(0.5, 0.5) && t.contains(0.1, 0.1));
/// ```
pub fn trim_surface(
    surface: &Surface,
    uv: &[[f64; 2]],
    boundary: &Boundary,
    cfg: &TrimConfig,
) -> Result<TrimmedSurface> {
    if surface.periodic() != (false, false) {
        return Err(Error::InvalidInput(
            "a periodic surface cannot be trimmed by its boundary loops; use --no-trim".into(),
        ));
    }
    if cfg.points_per_control == 0 || !(cfg.edge_share > 0.0 && cfg.edge_share <= 1.0) {
        return Err(Error::InvalidInput(format!(
            "trim settings: points_per_control {} must be positive and edge_share {} in (0, 1]",
            cfg.points_per_control, cfg.edge_share
        )));
    }
    let surface = surface.to_clamped()?;
    let domain = surface.domain();
    let loop_uv = |l: &[usize]| -> Result<Vec<[f64; 2]>> {
        l.iter()
            .map(|&i| {
                let p = *uv.get(i).ok_or_else(|| {
                    Error::InvalidInput(format!(
                        "boundary point {i} has no parameters ({} given)",
                        uv.len()
                    ))
                })?;
                check_in_domain(p, domain, i)?;
                Ok(p)
            })
            .collect()
    };
    let diag = net_diagonal(&surface);
    let tol = cfg.space_tolerance * diag;
    let outer_uv = loop_uv(boundary.outer_loop())?;
    // an alpha shape that breaks the cloud into pieces (too few points,
    // points on separate lines) has an outer loop round one piece only
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in uv {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let covered = signed_area(&outer_uv).abs() / ((hi[0] - lo[0]) * (hi[1] - lo[1]));
    if covered.is_nan() || covered < MIN_OUTER_SHARE {
        return Err(Error::InvalidInput(format!(
            "the outer boundary loop encloses only {:.1}% of the points' parameter rectangle ({} loops): the alpha shape does not hold the cloud together",
            100.0 * covered,
            boundary.loops.len()
        )));
    }
    let outer = if on_domain_edges(&outer_uv, domain, cfg) {
        None
    } else {
        Some(trim_curve(&surface, outer_uv, true, cfg, tol).map_err(|e| {
            Error::InvalidInput(format!("the outer boundary loop cannot be trimmed: {e}"))
        })?)
    };
    let mut holes = Vec::new();
    let mut skipped_holes = 0;
    for (k, l) in boundary.loops.iter().enumerate() {
        if k == boundary.outer {
            continue;
        }
        if l.len() < cfg.min_hole_points {
            skipped_holes += 1;
            continue;
        }
        holes.push(trim_curve(&surface, loop_uv(l)?, false, cfg, tol)?);
    }
    Ok(TrimmedSurface {
        surface,
        outer,
        holes,
        skipped_holes,
    })
}

/// [`trim_surface`] by the boundary loops of `points` (their alpha shape,
/// [`crate::cloud::boundary::boundary_loops`] with its defaults), mapped by
/// the points' parameters `uv`.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::trim::{trim_to_points, TrimConfig};
/// use scanfit::Point3;
/// // a flat unit square and a disc of points on it
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
/// let s = Surface::new(k.clone(), k, vec![p(0., 0.), p(0., 1.), p(1., 0.), p(1., 1.)]).unwrap();
/// let mut pts = Vec::new();
/// let mut uv = Vec::new();
/// for i in 0..=50 {
///     for j in 0..=50 {
///         let (x, y) = (i as f64 / 50.0, j as f64 / 50.0);
///         if (x - 0.5).hypot(y - 0.5) <= 0.5 {
///             pts.push(p(x, y));
///             uv.push([x, y]);
///         }
///     }
/// }
/// let t = trim_to_points(&s, &pts, &uv, &TrimConfig::default()).unwrap();
/// assert!(t.outer.is_some() && t.holes.is_empty());
/// assert!(t.contains(0.5, 0.5) && !t.contains(0.03, 0.03));
/// ```
pub fn trim_to_points(
    surface: &Surface,
    points: &[Point3],
    uv: &[[f64; 2]],
    cfg: &TrimConfig,
) -> Result<TrimmedSurface> {
    if uv.len() != points.len() {
        return Err(Error::InvalidInput(format!(
            "{} parameter pairs for {} points",
            uv.len(),
            points.len()
        )));
    }
    let boundary = crate::cloud::boundary::boundary_loops(points, &Default::default())?;
    trim_surface(surface, uv, &boundary, cfg)
}

fn check_in_domain(
    p: [f64; 2],
    ((u0, u1), (v0, v1)): ((f64, f64), (f64, f64)),
    i: usize,
) -> Result<()> {
    let (du, dv) = (u1 - u0, v1 - v0);
    let ok = p[0].is_finite()
        && p[1].is_finite()
        && p[0] >= u0 - du
        && p[0] <= u1 + du
        && p[1] >= v0 - dv
        && p[1] <= v1 + dv;
    if ok {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "boundary point {i} has parameters ({}, {}) far outside the surface's domain [{u0}, {u1}] x [{v0}, {v1}]",
            p[0], p[1]
        )))
    }
}

fn net_diagonal(s: &Surface) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in s.control_points() {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    (hi - lo).norm()
}

/// True when the loop runs along the domain's edges (see [`TrimConfig::edge_share`]).
fn on_domain_edges(
    l: &[[f64; 2]],
    ((u0, u1), (v0, v1)): ((f64, f64), (f64, f64)),
    cfg: &TrimConfig,
) -> bool {
    let n = l.len();
    if n < 3 {
        return true;
    }
    let mut steps: Vec<f64> = (0..n)
        .map(|k| dist(l[k], l[(k + 1) % n]))
        .filter(|d| *d > 0.0)
        .collect();
    if steps.is_empty() {
        return true;
    }
    steps.sort_by(f64::total_cmp);
    let tol = cfg.edge_steps * steps[steps.len() / 2];
    let near = l
        .iter()
        .filter(|p| {
            let d = (p[0] - u0)
                .abs()
                .min((u1 - p[0]).abs())
                .min((p[1] - v0).abs())
                .min((v1 - p[1]).abs());
            d <= tol
        })
        .count();
    near as f64 >= cfg.edge_share * n as f64
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Signed area of a closed polygon (positive counter-clockwise).
fn signed_area(l: &[[f64; 2]]) -> f64 {
    let n = l.len();
    0.5 * (0..n)
        .map(|k| {
            let (a, b) = (l[k], l[(k + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// The pcurve and 3D curve of one loop; `ccw` is the wanted orientation in `(u, v)`.
fn trim_curve(
    s: &Surface,
    mut l: Vec<[f64; 2]>,
    ccw: bool,
    cfg: &TrimConfig,
    tol: f64,
) -> Result<TrimCurve> {
    // consecutive duplicates give zero chords; drop them
    l.dedup_by(|a, b| dist(*a, *b) == 0.0);
    while l.len() > 1 && dist(l[0], l[l.len() - 1]) == 0.0 {
        l.pop();
    }
    let points = l.len();
    let p = 3;
    let min = 2 * p + 1;
    if points < min + 1 {
        return Err(Error::InvalidInput(format!(
            "a loop of {points} distinct parameter points is too short for a closed cubic ({} needed)",
            min + 1
        )));
    }
    if (signed_area(&l) > 0.0) != ccw {
        l.reverse();
    }
    // closed chord-length parameters in (u, v): t_0 = 0, ..., t_n = 1 (back at the start)
    let mut t = vec![0.0];
    for k in 0..points {
        let last = t[k];
        t.push(last + dist(l[k], l[(k + 1) % points]));
    }
    let total = t[points];
    t.iter_mut().for_each(|x| *x /= total);
    let count = (points / cfg.points_per_control).clamp(min, points);
    let kv = periodic_least_squares(&t, p, count)?;
    let values: Vec<f64> = l.iter().flat_map(|q| [q[0], q[1]]).collect();
    let (x, _) = lsq_values(
        &t[..points],
        &values,
        2,
        &kv,
        &LeastSquaresOptions::default(),
        true,
    )?;
    let ((u0, u1), (v0, v1)) = s.domain();
    let mut ctrl: Vec<Point3> = x
        .chunks(2)
        .map(|c| Point3::new(c[0].clamp(u0, u1), c[1].clamp(v0, v1), 0.0))
        .collect();
    for j in 0..p {
        ctrl.push(ctrl[j]);
    }
    let uv = Curve::new_periodic(kv, ctrl, None)?;
    let (space, deviation) = space_curve(s, &uv, count, tol)?;
    Ok(TrimCurve {
        uv,
        space,
        deviation,
        points,
    })
}

/// A closed B-spline on the pcurve's parameter approximating `S(uv(t))`,
/// refined (control points doubled) until within `tol` at the midpoints
/// between the fitted samples, or until it has a control point per 4 samples
/// of a dense sampling. Returns it and its measured deviation.
fn space_curve(s: &Surface, uv: &Curve, start: usize, tol: f64) -> Result<(Curve, f64)> {
    // evaluated and solved about the first control point, so that data far
    // from the origin keep their digits (issue 14 item 6)
    let o = s.control_points()[0];
    let centred = s.translated(-o.coords);
    let image = |t: f64| {
        let q = uv.point(t);
        centred.point(q.x, q.y)
    };
    let mut count = start;
    loop {
        let m = (8 * count).max(256);
        let t: Vec<f64> = (0..=m).map(|k| k as f64 / m as f64).collect();
        let pts: Vec<Point3> = t[..m].iter().map(|&x| image(x)).collect();
        let kv: KnotVector = periodic_least_squares(&t, 3, count)?;
        let values: Vec<f64> = pts.iter().flat_map(|q| [q.x, q.y, q.z]).collect();
        let (x, _) = lsq_values(
            &t[..m],
            &values,
            3,
            &kv,
            &LeastSquaresOptions::default(),
            true,
        )?;
        let net = |shift: &Point3| -> Vec<Point3> {
            let mut ctrl: Vec<Point3> = x
                .chunks(3)
                .map(|c| Point3::new(c[0] + shift.x, c[1] + shift.y, c[2] + shift.z))
                .collect();
            for j in 0..3 {
                ctrl.push(ctrl[j]);
            }
            ctrl
        };
        // the deviation is measured about the centre too (far from the
        // origin, the rounding of the coordinates would hide the fit's error)
        let centred_curve = Curve::new_periodic(kv.clone(), net(&Point3::origin()), None)?;
        let dev = (0..m)
            .flat_map(|k| [t[k], 0.5 * (t[k] + t[k + 1])])
            .map(|x| (centred_curve.point(x) - image(x)).norm())
            .fold(0.0, f64::max);
        if dev <= tol || count * 2 > 4096 {
            return Ok((Curve::new_periodic(kv, net(&o), None)?, dev));
        }
        count *= 2;
    }
}

/// The trimmed region in `(u, v)` as closed polygons (dense samples of the
/// trim curves; the domain rectangle when there is no outer curve), tested
/// by the even-odd rule.
struct Region {
    polys: Vec<Vec<[f64; 2]>>,
    /// Per polygon, its edges sorted into bands of `v` (see [`Bands`]).
    bands: Vec<Bands>,
}

/// A polygon's edges by horizontal band: an edge is listed in every band its
/// `v` range meets, so the edges a ray along +u from `p` can cross are all in
/// the band of `p.v` (the even-odd test is unchanged, only faster).
struct Bands {
    v0: f64,
    /// Bands per unit of `v`.
    scale: f64,
    /// Edge indices per band.
    edges: Vec<Vec<u32>>,
}

impl Bands {
    fn new(poly: &[[f64; 2]]) -> Self {
        let n = poly.len();
        let (v0, v1) = poly
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                (lo.min(q[1]), hi.max(q[1]))
            });
        let count = (n / 4).clamp(1, 4096);
        let scale = if v1 > v0 {
            count as f64 / (v1 - v0)
        } else {
            0.0
        };
        let mut edges = vec![Vec::new(); count];
        let band = |v: f64| (((v - v0) * scale) as usize).min(count - 1);
        for k in 0..n {
            let (a, b) = (poly[k], poly[(k + 1) % n]);
            for e in &mut edges[band(a[1].min(b[1]))..=band(a[1].max(b[1]))] {
                e.push(k as u32);
            }
        }
        Self { v0, scale, edges }
    }

    /// The edges that may cross the line `v` (none outside the polygon's
    /// `v` range).
    fn at(&self, v: f64) -> &[u32] {
        let t = (v - self.v0) * self.scale;
        if t.is_nan() || t < 0.0 || t > self.edges.len() as f64 {
            return &[];
        }
        &self.edges[(t as usize).min(self.edges.len() - 1)]
    }
}

impl Region {
    fn new(t: &TrimmedSurface) -> Self {
        let sample = |c: &Curve| -> Vec<[f64; 2]> {
            let n = 16 * c.control_points().len();
            (0..n)
                .map(|k| {
                    let q = c.point(k as f64 / n as f64);
                    [q.x, q.y]
                })
                .collect()
        };
        let mut polys = Vec::new();
        match &t.outer {
            Some(o) => polys.push(sample(&o.uv)),
            None => {
                let ((u0, u1), (v0, v1)) = t.surface.domain();
                polys.push(vec![[u0, v0], [u1, v0], [u1, v1], [u0, v1]]);
            }
        }
        polys.extend(t.holes.iter().map(|h| sample(&h.uv)));
        let bands = polys.iter().map(|p| Bands::new(p)).collect();
        Self { polys, bands }
    }

    /// Even-odd test; points on the domain's own rectangle count as inside.
    fn contains(&self, p: [f64; 2]) -> bool {
        let mut inside = false;
        for (poly, bands) in self.polys.iter().zip(&self.bands) {
            let n = poly.len();
            for &k in bands.at(p[1]) {
                let k = k as usize;
                let (a, b) = (poly[k], poly[(k + 1) % n]);
                if (a[1] > p[1]) != (b[1] > p[1]) {
                    let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                    if p[0] < x {
                        inside = !inside;
                    }
                }
            }
        }
        inside
    }
}

impl TrimmedSurface {
    /// True when `(u, v)` lies in the trimmed face.
    pub fn contains(&self, u: f64, v: f64) -> bool {
        Region::new(self).contains(self.clamp_inside(u, v))
    }

    /// Points on the domain's closing edges are moved a hair inwards so the
    /// rectangle's own edges count as inside.
    fn clamp_inside(&self, u: f64, v: f64) -> [f64; 2] {
        let ((u0, u1), (v0, v1)) = self.surface.domain();
        let (eu, ev) = (1e-12 * (u1 - u0), 1e-12 * (v1 - v0));
        [u.clamp(u0 + eu, u1 - eu), v.clamp(v0 + ev, v1 - ev)]
    }

    /// All trim curves, the outer one first.
    pub fn curves(&self) -> impl Iterator<Item = &TrimCurve> {
        self.outer.iter().chain(&self.holes)
    }

    /// A mesh of the trimmed face on an `nu x nv` parameter grid (see the
    /// module's notes): grid triangles inside kept, outside dropped, crossed
    /// ones cut along the trim curves.
    pub fn tessellate(&self, nu: usize, nv: usize) -> Mesh {
        let full = crate::bspline::tessellate(&self.surface, nu, nv);
        let region = Region::new(self);
        let inside: Vec<bool> = full
            .uv
            .iter()
            .map(|p| region.contains(self.clamp_inside(p[0], p[1])))
            .collect();
        let mut out = Mesh {
            vertices: full.vertices.clone(),
            normals: full.normals.clone(),
            uv: full.uv.clone(),
            triangles: Vec::new(),
        };
        let mut cut: HashMap<(u32, u32), u32> = HashMap::new();
        for tri in &full.triangles {
            let ins = tri.map(|i| inside[i as usize]);
            match ins.iter().filter(|b| **b).count() {
                3 => out.triangles.push(*tri),
                0 => {}
                k => {
                    // rotate so that the odd vertex (alone in or alone out) comes first
                    let lone = (0..3).find(|&a| (ins[a]) == (k == 1)).unwrap_or(0);
                    let [a, b, c] = [tri[lone], tri[(lone + 1) % 3], tri[(lone + 2) % 3]];
                    let pab = self.crossing(&region, &mut out, &mut cut, a, b);
                    let pac = self.crossing(&region, &mut out, &mut cut, a, c);
                    if k == 1 {
                        out.triangles.push([a, pab, pac]);
                    } else {
                        out.triangles.push([pab, b, c]);
                        out.triangles.push([pab, c, pac]);
                    }
                }
            }
        }
        compact(out)
    }

    /// The vertex where the trim boundary crosses the mesh edge `a`-`b`
    /// (one end inside, one outside), by bisection on the inside test.
    fn crossing(
        &self,
        region: &Region,
        mesh: &mut Mesh,
        cut: &mut HashMap<(u32, u32), u32>,
        a: u32,
        b: u32,
    ) -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&v) = cut.get(&key) {
            return v;
        }
        let (pa, pb) = (mesh.uv[a as usize], mesh.uv[b as usize]);
        let ina = region.contains(self.clamp_inside(pa[0], pa[1]));
        let (mut lo, mut hi) = (0.0, 1.0);
        let at = |s: f64| [pa[0] + s * (pb[0] - pa[0]), pa[1] + s * (pb[1] - pa[1])];
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            let q = at(mid);
            if region.contains(self.clamp_inside(q[0], q[1])) == ina {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let q = at(0.5 * (lo + hi));
        let (p, q2) = self.surface.degrees();
        let mut d = [Vector3::zeros(); 4];
        self.surface.derivatives_into(
            q[0],
            q[1],
            &mut crate::bspline::BasisWorkspace::new(p, 1),
            &mut crate::bspline::BasisWorkspace::new(q2, 1),
            1,
            &mut d,
        );
        let n = d[2].cross(&d[1]);
        let len = n.norm();
        let id = mesh.vertices.len() as u32;
        mesh.vertices.push(Point3::from(d[0]));
        mesh.normals.push(if len > 0.0 { n / len } else { n });
        mesh.uv.push(q);
        cut.insert(key, id);
        id
    }
}

/// Drops the vertices no triangle uses, renumbering the triangles.
fn compact(m: Mesh) -> Mesh {
    let mut map = vec![u32::MAX; m.vertices.len()];
    let mut out = Mesh::default();
    for t in &m.triangles {
        for &i in t {
            if map[i as usize] == u32::MAX {
                map[i as usize] = out.vertices.len() as u32;
                out.vertices.push(m.vertices[i as usize]);
                out.normals.push(m.normals[i as usize]);
                out.uv.push(m.uv[i as usize]);
            }
        }
    }
    out.triangles = m
        .triangles
        .iter()
        .map(|t| t.map(|i| map[i as usize]))
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::boundary::{boundary_loops, BoundaryConfig};
    use crate::fit::surface::{fit_surface, SurfaceFitConfig};

    fn mesh_area(m: &Mesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// A flat grid over `[0, 2] x [0, 1]` (`z = 0`), keeping the points `keep` accepts.
    fn flat(keep: impl Fn(f64, f64) -> bool) -> (Surface, Vec<[f64; 2]>, Boundary) {
        let mut pts = Vec::new();
        let mut uv = Vec::new();
        for i in 0..=160 {
            for j in 0..=80 {
                let (x, y) = (i as f64 / 80.0, j as f64 / 80.0);
                if keep(x, y) {
                    pts.push(Point3::new(x, y, 0.0));
                    uv.push([x / 2.0, y]);
                }
            }
        }
        let cfg = SurfaceFitConfig {
            ctrl: (6, 6),
            ..SurfaceFitConfig::default()
        };
        let s = fit_surface(&pts, &uv, &cfg).unwrap();
        let b = boundary_loops(&pts, &BoundaryConfig::default()).unwrap();
        (s, uv, b)
    }

    #[test]
    fn a_round_hole_is_cut_out_with_its_area() {
        // hole of radius 0.3 at (1, 0.5): area 2 - 0.09 pi; the alpha-shape loop
        // lies on grid points just outside the circle, within one grid step
        let (s, uv, b) = flat(|x, y| (x - 1.0).hypot(y - 0.5) > 0.3);
        let t = trim_surface(&s, &uv, &b, &TrimConfig::default()).unwrap();
        assert!(t.outer.is_none());
        assert_eq!(t.holes.len(), 1);
        let h = &t.holes[0];
        // the 3D curve is within its tolerance of the surface image
        assert!(
            h.deviation <= 1e-4 * net_diagonal(&t.surface),
            "{}",
            h.deviation
        );
        // the hole's radius in space: every sample within 1.5 grid steps of 0.3
        for k in 0..100 {
            let p = h.space.point(k as f64 / 100.0);
            let r = (p.x - 1.0).hypot(p.y - 0.5);
            assert!((r - 0.3).abs() < 1.5 / 80.0, "r = {r}");
        }
        let area = mesh_area(&t.tessellate(200, 100));
        let want = 2.0 - 0.09 * std::f64::consts::PI;
        assert!((area - want).abs() < 0.01 * want, "{area} vs {want}");
        let polygon = b.areas.iter().sum::<f64>();
        assert!(
            (area - polygon).abs() < 0.005 * polygon,
            "{area} vs {polygon}"
        );
        assert!(!t.contains(0.5, 0.5) && t.contains(0.05, 0.05));
    }

    #[test]
    fn a_rounded_outline_trims_the_rectangle() {
        // an ellipse filling the domain's rectangle: the corners are cut off
        let (s, uv, b) = flat(|x, y| ((x - 1.0) / 1.0).hypot((y - 0.5) / 0.5) <= 1.0);
        let t = trim_surface(&s, &uv, &b, &TrimConfig::default()).unwrap();
        let o = t.outer.as_ref().unwrap();
        assert!(t.holes.is_empty());
        // counter-clockwise in (u, v)
        let poly: Vec<[f64; 2]> = (0..200)
            .map(|k| {
                let q = o.uv.point(k as f64 / 200.0);
                [q.x, q.y]
            })
            .collect();
        assert!(signed_area(&poly) > 0.0);
        // the loop runs through the outermost grid points inside the ellipse,
        // about half a grid step inside it: the face's area is the loop
        // polygon's (the alpha shape's own signed area), within 0.5%
        let area = mesh_area(&t.tessellate(200, 100));
        let polygon = b.areas[b.outer];
        assert!(
            (area - polygon).abs() < 0.005 * polygon,
            "{area} vs {polygon}"
        );
        let ellipse = std::f64::consts::PI * 0.5;
        assert!(
            area < ellipse && area > 0.97 * ellipse,
            "{area} vs {ellipse}"
        );
        assert!(!t.contains(0.02, 0.02));
    }

    #[test]
    fn a_periodic_surface_is_refused() {
        let kv = KnotVector::uniform_periodic(3, 6).unwrap();
        let kc = KnotVector::uniform_clamped(1, 2).unwrap();
        let mut c = Vec::new();
        for i in 0..9 {
            for j in 0..2 {
                let a = (i % 6) as f64;
                c.push(Point3::new(a.cos(), a.sin(), j as f64));
            }
        }
        let s = Surface::with_options(kv, kc, c, None, true, false).unwrap();
        let (_, uv, b) = flat(|_, _| true);
        let e = trim_surface(&s, &uv, &b, &TrimConfig::default()).unwrap_err();
        assert!(e.to_string().contains("--no-trim"), "{e}");
    }
}
