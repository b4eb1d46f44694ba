//! The trimming loops of a surface document (`"trim"` of a `scanfit/1`
//! surface, written when the face is bounded by the cloud's outline or has
//! holes):
//!
//! ```json
//! "trim": {
//!   "outer": {"uv": {CURVE}, "space": {CURVE}, "deviation": 1.2e-3, "points": 271},
//!   "holes": [{"uv": {CURVE}, "space": {CURVE}, "deviation": 4e-4, "points": 40}],
//!   "skipped_holes": 37
//! }
//! ```
//!
//! Each `{CURVE}` is a full curve document ([`CurveDoc`]): `uv` the closed
//! pcurve in the surface's parameter space (points `(u, v, 0)`), `space` its
//! 3D image. `outer` is left out when the face keeps the parameter
//! rectangle. Documents without `"trim"` (older ones, untrimmed faces) read
//! as the untrimmed rectangle.

use scanfit::bspline::Surface;
use scanfit::trim::{TrimCurve, TrimmedSurface};
use serde::{Deserialize, Serialize};

use crate::json::CurveDoc;

/// One trimming loop as stored: [`TrimCurve`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrimCurveDoc {
    /// The pcurve, closed, in the surface's `(u, v)` (z = 0).
    pub uv: CurveDoc,
    /// Its 3D image on the same parameter.
    pub space: CurveDoc,
    /// Largest measured distance between `space(t)` and `S(uv(t))`.
    pub deviation: f64,
    /// Number of boundary points the loop had.
    pub points: usize,
}

/// The trimming loops of a face as stored: [`TrimmedSurface`] without its
/// surface (the document's own).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrimDoc {
    /// The outline; absent when the face keeps the parameter rectangle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outer: Option<TrimCurveDoc>,
    /// One loop per hole (clockwise in `(u, v)`).
    #[serde(default)]
    pub holes: Vec<TrimCurveDoc>,
    /// Holes of the boundary left untrimmed (too few boundary points).
    #[serde(default)]
    pub skipped_holes: usize,
}

impl TrimCurveDoc {
    fn new(c: &TrimCurve) -> Self {
        Self {
            uv: CurveDoc::new(&c.uv),
            space: CurveDoc::new(&c.space),
            deviation: c.deviation,
            points: c.points,
        }
    }

    fn curve(&self, which: &str) -> Result<TrimCurve, String> {
        let build = |d: &CurveDoc, part: &str| {
            d.checked_curve()
                .map_err(|e| format!("trim {which} {part} curve: {e}"))
        };
        let uv = build(&self.uv, "uv")?;
        if !uv.is_periodic() {
            return Err(format!(
                "trim {which} uv curve is not closed (periodic); the document is damaged"
            ));
        }
        if !(self.deviation.is_finite() && self.deviation >= 0.0) {
            return Err(format!(
                "trim {which} deviation {} must be finite and >= 0",
                self.deviation
            ));
        }
        Ok(TrimCurve {
            uv,
            space: build(&self.space, "space")?,
            deviation: self.deviation,
            points: self.points,
        })
    }
}

impl TrimDoc {
    /// The loops of `t`.
    pub fn new(t: &TrimmedSurface) -> Self {
        Self {
            outer: t.outer.as_ref().map(TrimCurveDoc::new),
            holes: t.holes.iter().map(TrimCurveDoc::new).collect(),
            skipped_holes: t.skipped_holes,
        }
    }

    /// `surface` bounded by these loops (each curve validated: degree,
    /// knots, closed pcurves); the message says which loop is damaged.
    pub fn trimmed(&self, surface: &Surface) -> Result<TrimmedSurface, String> {
        let outer = self.outer.as_ref().map(|o| o.curve("outer")).transpose()?;
        let holes = self
            .holes
            .iter()
            .enumerate()
            .map(|(k, h)| h.curve(&format!("hole {k}")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(TrimmedSurface {
            surface: surface.clone(),
            outer,
            holes,
            skipped_holes: self.skipped_holes,
        })
    }
}
