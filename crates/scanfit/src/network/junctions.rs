//! Corners (junctions) and edges of the patch network (issue 15, item 2).
//!
//! Along each patch's border the patch across changes at the junctions: a
//! run of loop points facing patch B, then a run facing patch C (or the free
//! boundary). Runs shorter than a minimum length are noise at a junction and
//! are absorbed by their longer neighbour. A change from one run to the next
//! is a corner candidate of that patch; the run of A facing B is matched
//! with the run of B facing A, and their end candidates are the same
//! network vertex (joined by union-find), so a corner where three or more
//! patches meet, or where an interface reaches the free boundary, becomes
//! one shared vertex. Each matched run pair is one edge shared by two
//! patches; each free run is an edge of one patch. A patch with fewer than
//! three runs has its free runs split at their sharpest points (smallest
//! turning angle, Coons paper eq. 12).

use crate::cloud::corners::{find_corners, CornerConfig};
use crate::{Error, Point3, Result};

use super::borders::Border;

/// A run of consecutive loop points facing the same patch (or none).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    /// Loop position of the first point.
    start: usize,
    /// Number of points.
    len: usize,
    /// The patch across.
    across: Option<usize>,
}

/// A vertex of the network: a corner shared by the patches around it.
#[derive(Debug, Clone, PartialEq)]
pub struct NetVertex {
    /// Position (mean of the patches' corner estimates).
    pub point: Point3,
}

/// An edge of the network between two vertices.
#[derive(Debug, Clone, PartialEq)]
pub struct NetEdge {
    /// Start vertex.
    pub start: usize,
    /// End vertex.
    pub end: usize,
    /// The patches on either side (the second is `None` on the free boundary).
    pub patches: [Option<usize>; 2],
    /// The border points of each side's patch along the edge (indices into
    /// the labelled cloud), each in that patch's loop order.
    pub points: [Vec<usize>; 2],
}

/// A patch's use of an edge; `reversed`: traversed from `end` to `start`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NetUse {
    /// Edge index.
    pub edge: usize,
    /// Whether the patch runs the edge from its end to its start.
    pub reversed: bool,
}

/// Vertices, edges and each patch's cycle of edge uses (in loop order).
#[derive(Debug, Clone, PartialEq)]
pub struct Junctions {
    /// The vertices.
    pub vertices: Vec<NetVertex>,
    /// The edges.
    pub edges: Vec<NetEdge>,
    /// Each patch's boundary as a closed cycle of edge uses.
    pub cycles: Vec<Vec<NetUse>>,
}

/// Arc length of the loop from position `a` over `len` points.
fn run_length(pts: &[Point3], a: usize, len: usize) -> f64 {
    let n = pts.len();
    (0..len.saturating_sub(1))
        .map(|k| (pts[(a + k + 1) % n] - pts[(a + k) % n]).norm())
        .sum()
}

/// Cyclic runs of equal `across`, runs shorter than `min_length` absorbed
/// by their longer neighbour.
fn runs(border: &Border, pts: &[Point3], min_length: f64) -> Vec<Run> {
    let n = border.across.len();
    let a = &border.across;
    // start at a change, so no run wraps past position 0 unless all equal
    let Some(first) = (0..n).find(|&i| a[i] != a[(i + n - 1) % n]) else {
        return vec![Run {
            start: 0,
            len: n,
            across: a.first().copied().flatten(),
        }];
    };
    let mut out: Vec<Run> = Vec::new();
    for k in 0..n {
        let i = (first + k) % n;
        match out.last_mut() {
            Some(r) if r.across == a[i] => r.len += 1,
            _ => out.push(Run {
                start: i,
                len: 1,
                across: a[i],
            }),
        }
    }
    loop {
        if out.len() <= 1 {
            break;
        }
        let lens: Vec<f64> = out
            .iter()
            .map(|r| run_length(pts, r.start, r.len + 1))
            .collect();
        let Some(k) = (0..out.len())
            .filter(|&k| lens[k] < min_length)
            .min_by(|&x, &y| lens[x].total_cmp(&lens[y]))
        else {
            break;
        };
        let m = out.len();
        let (p, q) = ((k + m - 1) % m, (k + 1) % m);
        // absorbed by the longer neighbour
        let to = if lens[p] >= lens[q] { p } else { q };
        out[k].across = out[to].across;
        // merge equal neighbours (cyclically)
        let mut merged: Vec<Run> = Vec::new();
        for r in out.iter().copied() {
            match merged.last_mut() {
                Some(l) if l.across == r.across => l.len += r.len,
                _ => merged.push(r),
            }
        }
        if merged.len() > 1 {
            if let (Some(&l), Some(f)) = (merged.last(), merged.first().copied()) {
                if l.across == f.across {
                    merged.pop();
                    merged[0] = Run {
                        start: l.start,
                        len: l.len + f.len,
                        across: f.across,
                    };
                }
            }
        }
        out = merged;
    }
    out
}

/// A point of a free border whose turning angle (Coons paper eq. 12) is
/// below this is a corner of the patch (135 degrees: a right angle is 90).
const SHARP_ANGLE: f64 = 0.75 * std::f64::consts::PI;

/// Splits free runs at their sharpest points: while the patch has fewer
/// than 3 runs always, and up to 4 where the free border has a corner
/// sharper than [`SHARP_ANGLE`].
fn split_free(runs: &mut Vec<Run>, pts: &[Point3], id: i64, min_length: f64) -> Result<()> {
    let n = pts.len();
    if runs.len() == 1 && runs[0].across.is_none() {
        // no neighbour at all: the corners of the loop itself
        let c = find_corners(pts, &CornerConfig::default()).map_err(|e| {
            Error::InvalidInput(format!("patch {id}: corners of its free border: {e}"))
        })?;
        *runs = (0..c.corners.len())
            .map(|k| {
                let a = c.corners[k];
                let b = c.corners[(k + 1) % c.corners.len()];
                Run {
                    start: a,
                    len: (b + n - a) % n,
                    across: None,
                }
            })
            .collect();
        return Ok(());
    }
    // arc length along the loop, to measure angles over a fixed length
    let mut arc = vec![0.0; n + 1];
    for i in 0..n {
        arc[i + 1] = arc[i] + (pts[(i + 1) % n] - pts[i]).norm();
    }
    let total = arc[n];
    // the point `d` along the loop from position `i` (either direction)
    let along = |i: usize, d: f64| -> Point3 {
        let target = (arc[i] + d).rem_euclid(total);
        let k = arc.partition_point(|&x| x <= target).clamp(1, n) - 1;
        pts[k % n]
    };
    while runs.len() < 4 {
        // the longest free run that can still be split
        let best = runs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.across.is_none() && r.len >= 5)
            .map(|(k, r)| (k, run_length(pts, r.start, r.len)))
            .filter(|&(_, l)| l >= 2.0 * min_length)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, _)) = best else {
            if runs.len() >= 3 {
                return Ok(());
            }
            let names: Vec<String> = runs
                .iter()
                .map(|r| {
                    r.across.map_or("the free boundary".to_string(), |p| {
                        format!("patch index {p}")
                    })
                })
                .collect();
            return Err(Error::InvalidInput(format!(
                "patch {id} has only {} corner(s): its border meets {} with no place where three patches (or two and the free boundary) meet; a patch needs at least three corners: split it, or the patch around it, so that its border meets at least three patches",
                runs.len(),
                names.join(" and ")
            )));
        };
        let r = runs[k];
        // the turning angle (Coons paper eq. 12) over chords of an eighth of
        // the run (at least the shortest run): the zig-zag of the alpha shape
        // averages out
        let chord = (run_length(pts, r.start, r.len) / 8.0).max(min_length);
        let angle = |x: usize| {
            let i = (r.start + x) % n;
            let (a, b) = (along(i, -chord) - pts[i], along(i, chord) - pts[i]);
            let d = a.norm() * b.norm();
            if d > 0.0 {
                (a.dot(&b) / d).clamp(-1.0, 1.0).acos()
            } else {
                std::f64::consts::PI
            }
        };
        // keep a tenth of the run (and two points) clear of its ends
        let margin = (r.len / 10).max(2);
        let Some((at, sharp)) = (margin..r.len.saturating_sub(margin))
            .map(|x| (x, angle(x)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            return Ok(());
        };
        // a third side is always needed; a fourth only at a real corner
        if runs.len() >= 3 && sharp > SHARP_ANGLE {
            return Ok(());
        }
        runs[k] = Run {
            start: r.start,
            len: at,
            across: None,
        };
        runs.insert(
            k + 1,
            Run {
                start: (r.start + at) % n,
                len: r.len - at,
                across: None,
            },
        );
    }
    Ok(())
}

/// A run of a patch: (patch, run index).
type RunRef = (usize, usize);

/// Union-find over corner candidates.
struct Dsu(Vec<usize>);

impl Dsu {
    fn find(&mut self, mut x: usize) -> usize {
        while self.0[x] != x {
            self.0[x] = self.0[self.0[x]];
            x = self.0[x];
        }
        x
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb)] = ra.min(rb);
        }
    }
}

/// Builds vertices, edges and cycles from the patches' borders (see the
/// module docs). `points` are the labelled cloud's positions, `ids` the
/// patch labels (for errors), `min_length` the shortest run kept.
pub fn junctions(
    points: &[Point3],
    borders: &[Border],
    ids: &[i64],
    min_length: f64,
) -> Result<Junctions> {
    // runs of every patch
    let mut all_runs: Vec<Vec<Run>> = Vec::with_capacity(borders.len());
    for (k, b) in borders.iter().enumerate() {
        let pts: Vec<Point3> = b.points.iter().map(|&i| points[i]).collect();
        let mut r = runs(b, &pts, min_length);
        if r.len() == 1 {
            if let Some(p) = r[0].across {
                return Err(Error::InvalidInput(format!(
                    "patch {} is enclosed by patch {} alone: their common border is a closed loop with no corner; split patch {} or {} so that at least three patches meet around patch {}",
                    ids[k], ids[p], ids[k], ids[p], ids[k]
                )));
            }
        }
        if r.len() < 4 {
            split_free(&mut r, &pts, ids[k], min_length)?;
        }
        all_runs.push(r);
    }
    // candidate c(k, r) = the corner before run r of patch k
    let mut base = Vec::with_capacity(all_runs.len());
    let mut cand_pos: Vec<Point3> = Vec::new();
    for (k, rs) in all_runs.iter().enumerate() {
        base.push(cand_pos.len());
        let lp = &borders[k].points;
        let n = lp.len();
        for r in rs {
            let a = points[lp[r.start]];
            let b = points[lp[(r.start + n - 1) % n]];
            cand_pos.push(Point3::from((a.coords + b.coords) * 0.5));
        }
    }
    let cand = |k: usize, r: usize| base[k] + r % all_runs[k].len();
    let run_points = |k: usize, r: &Run| -> Vec<usize> {
        let lp = &borders[k].points;
        (0..r.len).map(|j| lp[(r.start + j) % lp.len()]).collect()
    };
    let centroid = |ix: &[usize]| {
        let s = ix
            .iter()
            .fold(crate::Vector3::zeros(), |s, &i| s + points[i].coords);
        s / ix.len().max(1) as f64
    };
    // match the run of A facing B with the run of B facing A
    let mut dsu = Dsu((0..cand_pos.len()).collect());
    // (patch, run) of each edge's first side, and of its second if shared
    let mut pairs: Vec<(RunRef, Option<RunRef>)> = Vec::new();
    for a in 0..all_runs.len() {
        for (ra, run) in all_runs[a].iter().enumerate() {
            if run.across.is_none() {
                pairs.push(((a, ra), None));
            }
        }
    }
    for a in 0..all_runs.len() {
        for b in a + 1..all_runs.len() {
            let ra: Vec<usize> = (0..all_runs[a].len())
                .filter(|&r| all_runs[a][r].across == Some(b))
                .collect();
            let rb: Vec<usize> = (0..all_runs[b].len())
                .filter(|&r| all_runs[b][r].across == Some(a))
                .collect();
            if ra.len() != rb.len() {
                return Err(Error::InvalidInput(format!(
                    "patches {} and {} do not see their common border alike ({} stretch(es) from patch {}, {} from patch {}); the labels along it are ragged: clean the segmentation there, or raise the contact radius",
                    ids[a], ids[b], ra.len(), ids[a], rb.len(), ids[b]
                )));
            }
            // greedy pairing by centroid distance
            let ca: Vec<_> = ra
                .iter()
                .map(|&r| centroid(&run_points(a, &all_runs[a][r])))
                .collect();
            let cb: Vec<_> = rb
                .iter()
                .map(|&r| centroid(&run_points(b, &all_runs[b][r])))
                .collect();
            let mut cost: Vec<(f64, usize, usize)> = Vec::new();
            for (i, x) in ca.iter().enumerate() {
                for (j, y) in cb.iter().enumerate() {
                    cost.push(((x - y).norm(), i, j));
                }
            }
            cost.sort_by(|x, y| x.0.total_cmp(&y.0));
            let (mut ua, mut ub) = (vec![false; ra.len()], vec![false; rb.len()]);
            for (_, i, j) in cost {
                if ua[i] || ub[j] {
                    continue;
                }
                ua[i] = true;
                ub[j] = true;
                let (x, y) = (ra[i], rb[j]);
                let (a0, a1) = (cand(a, x), cand(a, x + 1));
                let (b0, b1) = (cand(b, y), cand(b, y + 1));
                let d = |p: usize, q: usize| (cand_pos[p] - cand_pos[q]).norm();
                if d(a0, b1) + d(a1, b0) <= d(a0, b0) + d(a1, b1) {
                    dsu.union(a0, b1);
                    dsu.union(a1, b0);
                } else {
                    dsu.union(a0, b0);
                    dsu.union(a1, b1);
                }
                pairs.push(((a, x), Some((b, y))));
            }
        }
    }
    // vertices: classes of candidates
    let mut class_of = vec![usize::MAX; cand_pos.len()];
    let mut sums: Vec<(crate::Vector3, usize)> = Vec::new();
    for c in 0..cand_pos.len() {
        let r = dsu.find(c);
        if class_of[r] == usize::MAX {
            class_of[r] = sums.len();
            sums.push((crate::Vector3::zeros(), 0));
        }
        let v = class_of[r];
        class_of[c] = v;
        sums[v].0 += cand_pos[c].coords;
        sums[v].1 += 1;
    }
    let vertices: Vec<NetVertex> = sums
        .iter()
        .map(|(s, n)| NetVertex {
            point: Point3::from(s / *n as f64),
        })
        .collect();
    // edges and uses
    let mut edges = Vec::with_capacity(pairs.len());
    let mut uses: Vec<Vec<Option<NetUse>>> = all_runs.iter().map(|r| vec![None; r.len()]).collect();
    for ((a, x), other) in pairs {
        let (s, e) = (class_of[cand(a, x)], class_of[cand(a, x + 1)]);
        if s == e {
            return Err(Error::InvalidInput(format!(
                "patch {}: a stretch of its border{} starts and ends at the same corner; the labels there are ragged or the patch is too small for its neighbours: clean the segmentation",
                ids[a],
                other.map_or(String::new(), |(b, _)| format!(" along patch {}", ids[b]))
            )));
        }
        let idx = edges.len();
        uses[a][x] = Some(NetUse {
            edge: idx,
            reversed: false,
        });
        let mut pts = [run_points(a, &all_runs[a][x]), Vec::new()];
        let mut patches = [Some(a), None];
        if let Some((b, y)) = other {
            let (bs, be) = (class_of[cand(b, y)], class_of[cand(b, y + 1)]);
            let reversed = if bs == e && be == s {
                true
            } else if bs == s && be == e {
                false
            } else {
                return Err(Error::InvalidInput(format!(
                    "patches {} and {} disagree on where their common border ends; clean the segmentation where they meet",
                    ids[a], ids[b]
                )));
            };
            uses[b][y] = Some(NetUse {
                edge: idx,
                reversed,
            });
            pts[1] = run_points(b, &all_runs[b][y]);
            patches[1] = Some(b);
        }
        edges.push(NetEdge {
            start: s,
            end: e,
            patches,
            points: pts,
        });
    }
    let cycles = uses
        .into_iter()
        .enumerate()
        .map(|(k, u)| {
            u.into_iter().collect::<Option<Vec<_>>>().ok_or_else(|| {
                Error::InvalidInput(format!(
                    "patch {}: a stretch of its border has no matching stretch on the patch across; clean the segmentation",
                    ids[k]
                ))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Junctions {
        vertices,
        edges,
        cycles,
    })
}
