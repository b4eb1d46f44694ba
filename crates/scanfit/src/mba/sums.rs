//! The sums over points behind a multilevel B-spline approximation, as
//! accumulators that can be built in pieces (chunks of a file, tiles on
//! other machines) and merged: the data's frame ([`FrameSums`]: bounding
//! box and mean height), the BA step of one level ([`BaAccumulator`]: the
//! numerator and denominator of [LWS97] eq. 4, [MBA18] eqs. 3-4, per control
//! value, for the heights and, with the fitted start, the constant 1), what
//! a pass measures besides ([`PassSums`]: a row's residual statistics and
//! the fitted start's sums) and the statistics of the residuals
//! ([`ResidualSums`]).
//!
//! A distributed level loop ([`super::MbaLevels`]) runs, per level: the
//! driver sends the frame and the level lattices so far to every worker;
//! each worker creates the level's accumulator
//! ([`super::MbaLevels::accumulator`]), adds its points
//! ([`BaAccumulator::add_levels`] given [`super::MbaLevels::inputs`], which
//! evaluates the levels so far at the points) and returns it with the
//! pass's [`PassSums`]; the driver merges them, records the sums
//! ([`super::MbaLevels::record`]) and finishes the level
//! ([`super::MbaLevels::push`]). Only lattices travel, never points.
//!
//! Points are summed in blocks counted from the first point added (of at
//! least 16384 points, and at least as many as the lattice has control
//! values; constants of the lattice, never of the thread count), so adding
//! a file's points in chunks of any size, in file order, gives the same
//! lattice bit for bit as one call with all of them. Merging accumulators
//! summed separately gives the one-pass lattice up to the rounding of the
//! additions (floating-point addition is not associative).

use crate::metrics::ErrorStats;
use crate::par::BlockSum;
use crate::wire::{read_pair_sums, write_pair_sums, Reader, Writer};
use crate::{validate_points, Error, Point3, Result};

use super::lattice::{locate, uniform_cubic_basis, ControlFormula, Lattice};
use super::{Frame, Start};

/// Fewest points per block of the BA sums.
pub(super) const BA_BLOCK: usize = 16_384;

/// Tags of the byte records ([`crate::wire`]). Version 2 of the BA sums
/// carries the number of value sets (the constant's, for the fitted
/// start); version 1 bytes are refused as of another version.
const BA_TAG: &[u8; 8] = b"SFBASUM2";
const PASS_TAG: &[u8; 8] = b"SFPASSM1";
const FRAME_TAG: &[u8; 8] = b"SFFRAME1";
const RESIDUAL_TAG: &[u8; 8] = b"SFRESID1";

/// Bytes of partial sums that may exist at a time while a chunk is summed.
pub(super) const PARTIAL_BUDGET: usize = 256 << 20;

/// The BA sums of one lattice ([LWS97] eq. 4, [MBA18] eqs. 3-4): for every
/// control value the numerator `sum_c w_c^2 phi_c` and the denominator
/// `sum_c w_c^2` over the points `c` in its 4 x 4 neighbourhood (weights
/// `w_c` instead of `w_c^2` for [`ControlFormula::Hjelle`]), with the
/// candidate `phi_c = w_c z_c / sum_ab w_ab^2` of eq. 3.
/// [`finish`](Self::finish) divides them into the lattice.
///
/// For the fitted start ([`Start::Fitted`]) the sums carry a second value
/// set, the constant 1's residuals (a second numerator per control value;
/// the denominator depends on the points' positions only and is shared).
///
/// ```
/// use scanfit::mba::{BaAccumulator, ControlFormula, Lattice};
///
/// let xy: Vec<[f64; 2]> = (0..5000).map(|k| [(k % 71) as f64 / 70.0 * 4.0, (k / 71) as f64 / 70.0 * 3.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] - 2.0) * p[1]).collect();
/// let once = Lattice::approximate(4, 3, &xy, &z, ControlFormula::LeeWolbergShin)?;
/// // in chunks of 999, in order: the same lattice, bit for bit
/// let mut acc = BaAccumulator::new(4, 3, ControlFormula::LeeWolbergShin)?;
/// for (a, b) in xy.chunks(999).zip(z.chunks(999)) {
///     acc.add(a, b)?;
/// }
/// assert_eq!(acc.finish(), once);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct BaAccumulator {
    m: usize,
    n: usize,
    formula: ControlFormula,
    /// Value sets: 1 (the heights) or 2 (and the constant).
    sets: usize,
    /// The numerators of all sets, one lattice after the other, and the
    /// shared denominators.
    sums: BlockSum<(Vec<f64>, Vec<f64>)>,
}

impl BaAccumulator {
    /// Empty sums for a lattice of `m x n` cells (control net `(m + 3) x
    /// (n + 3)`); errors like [`Lattice::zeros`].
    pub fn new(m: usize, n: usize, formula: ControlFormula) -> Result<Self> {
        Self::with_sets(m, n, formula, 1)
    }

    /// Empty sums of the level loop that starts from `start`: the heights'
    /// values, and the constant's too for [`Start::Fitted`].
    pub fn for_start(m: usize, n: usize, formula: ControlFormula, start: Start) -> Result<Self> {
        Self::with_sets(m, n, formula, sets_of(start))
    }

    fn with_sets(m: usize, n: usize, formula: ControlFormula, sets: usize) -> Result<Self> {
        let len = Lattice::zeros(m, n)?.phi.len();
        Ok(Self {
            m,
            n,
            formula,
            sets,
            sums: BlockSum::new((vec![0.0; sets * len], vec![0.0; len]), BA_BLOCK.max(len)),
        })
    }

    /// The start whose value sets these sums carry.
    pub fn start(&self) -> Start {
        if self.sets == 2 {
            Start::Fitted
        } else {
            Start::Mean
        }
    }

    /// Cells `(m, n)` of the lattice.
    pub fn cells(&self) -> (usize, usize) {
        (self.m, self.n)
    }

    /// Points added so far (over all merged accumulators).
    pub fn points(&self) -> u64 {
        self.sums.items()
    }

    /// Bytes of one set of sums (numerators and denominator per control value).
    pub fn bytes(&self) -> usize {
        (self.sets + 1) * (self.m + 3) * (self.n + 3) * std::mem::size_of::<f64>()
    }

    /// Adds the values `z` at lattice coordinates `xy` (in `[0, m] x [0, n]`;
    /// points outside are clamped to it). Errors when the lengths differ,
    /// a value is not finite, or the sums carry two value sets.
    pub fn add(&mut self, xy: &[[f64; 2]], z: &[f64]) -> Result<()> {
        if xy.len() != z.len() {
            return Err(Error::LengthMismatch {
                what: "values",
                expected: xy.len(),
                got: z.len(),
            });
        }
        if self.sets != 1 {
            return Err(Error::InvalidInput(
                "these BA sums carry the constant's values beside the heights (the fitted start); add the points with add_levels".into(),
            ));
        }
        let values: Vec<[f64; 1]> = z.iter().map(|&v| [v]).collect();
        self.add_sets(xy, &values)
    }

    /// [`add`](Self::add) of `K` values per point (`K` the sets).
    fn add_sets<const K: usize>(&mut self, xy: &[[f64; 2]], z: &[[f64; K]]) -> Result<()> {
        if let Some(i) = (0..z.len()).find(|&i| {
            !(z[i].iter().all(|v| v.is_finite()) && xy[i][0].is_finite() && xy[i][1].is_finite())
        }) {
            return Err(Error::BadPoint {
                index: i,
                problem: format!(
                    "has lattice coordinates ({}, {}) and value {}; all must be finite",
                    xy[i][0], xy[i][1], z[i][0]
                ),
            });
        }
        let (m, n, formula) = (self.m, self.n, self.formula);
        let len = (m + 3) * (n + 3);
        let partials = self.partials();
        self.sums.add(
            xy.len(),
            partials,
            || (vec![0.0; K * len], vec![0.0; len]),
            |(num, den), range| {
                let mut sets = num.chunks_exact_mut(len);
                let mut num: [&mut [f64]; K] = std::array::from_fn(|_| match sets.next() {
                    Some(s) => s,
                    None => unreachable!("the numerators hold K lattices"),
                });
                for (p, zc) in xy[range.clone()].iter().zip(&z[range]) {
                    add_point_values(&mut num, den, m, n, formula, *p, *zc);
                }
            },
            merge_sums,
        );
        Ok(())
    }

    /// Adds the residuals of `points` after the `levels` fitted so far
    /// (`z - z0 - sum_k f_k(x, y)`, each level evaluated at the point's
    /// unit coordinates in `frame`, subtracted in level order exactly as the
    /// in-memory level loop does), and returns their statistics (the
    /// residuals of the previous level, for its report). Point indices in
    /// the statistics count from 0 within `points`. For the mean start
    /// ([`add_levels`](Self::add_levels) for either).
    pub fn add_residuals(
        &mut self,
        frame: &Frame,
        levels: &[Lattice],
        points: &[Point3],
    ) -> Result<ResidualSums> {
        let inputs = LevelInputs {
            frame: *frame,
            heights: levels,
            constant: &[],
            start: Start::Mean,
            row: (!levels.is_empty()).then_some((levels.len(), 0.0)),
        };
        Ok(self.add_levels(&inputs, points)?.row)
    }

    /// Adds the residuals of `points` after the levels of `inputs` (from
    /// [`super::MbaLevels::inputs`]): the heights' `z - z0 - sum_k Z_k(x, y)`
    /// and, for the fitted start, the constant's `1 - sum_k C_k(x, y)`, each
    /// level evaluated at the point's unit coordinates and subtracted in
    /// level order as the in-memory level loop does. Returns what the pass
    /// measures ([`PassSums`], point indices counted from 0 within
    /// `points`). Errors when the sums' value sets are not the start's.
    pub fn add_levels(&mut self, inputs: &LevelInputs<'_>, points: &[Point3]) -> Result<PassSums> {
        if self.sets != sets_of(inputs.start) {
            return Err(Error::InvalidInput(format!(
                "these BA sums carry {} value set(s), but a level loop with the {:?} start needs {}; make them with the loop's accumulator()",
                self.sets,
                inputs.start,
                sets_of(inputs.start)
            )));
        }
        let (m, n) = (self.m as f64, self.n as f64);
        let mut xy = Vec::with_capacity(points.len());
        let mut rc = Vec::with_capacity(points.len());
        let sums = walk_levels(inputs, points, |u, v| {
            xy.push([u[0] * m, u[1] * n]);
            rc.push(v);
        })?;
        if self.sets == 1 {
            let z: Vec<[f64; 1]> = rc.iter().map(|v| [v[0]]).collect();
            self.add_sets(&xy, &z)?;
        } else {
            self.add_sets(&xy, &rc)?;
        }
        Ok(sums)
    }

    /// Adds the sums of another accumulator of the same lattice (points
    /// summed separately).
    pub fn merge(&mut self, other: Self) -> Result<()> {
        if (self.m, self.n, self.formula, self.sets)
            != (other.m, other.n, other.formula, other.sets)
        {
            return Err(Error::InvalidInput(format!(
                "cannot merge the BA sums of a {} x {} lattice into those of a {} x {} lattice (or of another control formula or start); every chunk of a level must use that level's accumulator",
                other.m, other.n, self.m, self.n
            )));
        }
        self.sums.merge(other.sums, merge_sums);
        Ok(())
    }

    /// The sums as bytes ([`crate::wire`]), exact: an accumulator read back
    /// with [`from_bytes`](Self::from_bytes) continues, merges and finishes
    /// bit for bit as this one.
    ///
    /// ```
    /// use scanfit::mba::{BaAccumulator, ControlFormula};
    /// let mut a = BaAccumulator::new(4, 2, ControlFormula::LeeWolbergShin)?;
    /// a.add(&[[0.5, 1.0], [3.2, 0.1]], &[1.0, -2.0])?;
    /// let b = BaAccumulator::from_bytes(&a.to_bytes())?;
    /// assert_eq!(b.points(), 2);
    /// assert_eq!(b.finish(), a.finish());
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(BA_TAG);
        w.usize(self.m);
        w.usize(self.n);
        w.u64(u64::from(self.formula == ControlFormula::Hjelle));
        w.usize(self.sets);
        write_pair_sums(&mut w, &self.sums);
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote; errors for bytes of
    /// another type, cut short or inconsistent.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, BA_TAG, "the BA sums of an MBA level")?;
        let (m, n) = (r.usize()?, r.usize()?);
        let formula = match r.u64()? {
            0 => ControlFormula::LeeWolbergShin,
            1 => ControlFormula::Hjelle,
            x => return Err(r.corrupt(&format!("control formula {x}"))),
        };
        let sets = r.usize()?;
        if !(1..=2).contains(&sets) {
            return Err(r.corrupt(&format!("{sets} value sets")));
        }
        let mut acc = Self::with_sets(m, n, formula, sets)?;
        let len = (m + 3) * (n + 3);
        acc.sums = read_pair_sums(&mut r, (sets * len, len), BA_BLOCK.max(len))?;
        r.end()?;
        Ok(acc)
    }

    /// The lattice: each control value the ratio of its sums (eq. 4), 0
    /// where no point reached it (the heights' lattice when the sums carry
    /// two value sets).
    pub fn finish(self) -> Lattice {
        let mut l = self.finish_sets();
        l.swap_remove(0)
    }

    /// The lattice of each value set: the heights' and, for the fitted
    /// start, the constant's.
    pub fn finish_sets(self) -> Vec<Lattice> {
        let (m, n) = (self.m, self.n);
        let (num, den) = self.sums.finish(merge_sums);
        num.chunks_exact(den.len())
            .map(|num| ratio_lattice(m, n, num, &den))
            .collect()
    }

    /// The number of partial sums alive at a time while a chunk is summed
    /// (bounded by memory, never by the thread count).
    pub(super) fn partials(&self) -> usize {
        (PARTIAL_BUDGET / self.bytes()).clamp(1, 16)
    }
}

/// The lattice of `m x n` cells from BA sums: each control value the ratio
/// of its sums (eq. 4), 0 where no point reached it.
pub(super) fn ratio_lattice(m: usize, n: usize, num: &[f64], den: &[f64]) -> Lattice {
    let phi = num
        .iter()
        .zip(den)
        .map(|(nu, de)| if *de > 0.0 { nu / de } else { 0.0 })
        .collect();
    Lattice { m, n, phi }
}

/// Value sets of the level loop that starts from `start`.
fn sets_of(start: Start) -> usize {
    match start {
        Start::Mean => 1,
        Start::Fitted => 2,
    }
}

/// What a pass over the points needs (broadcast to every chunk or worker):
/// made by [`super::MbaLevels::inputs`].
#[derive(Debug, Clone, Copy)]
pub struct LevelInputs<'a> {
    /// The map between data and lattice coordinates.
    pub frame: Frame,
    /// The heights' level lattices so far.
    pub heights: &'a [Lattice],
    /// The constant's level lattices so far (the fitted start; empty for
    /// the mean), of the sizes of `heights`.
    pub constant: &'a [Lattice],
    /// The start of the level loop.
    pub start: Start,
    /// The row this pass measures, `(j, d)`: the statistics of
    /// `|r_j - d c_j|`, `r_j` and `c_j` the heights' and the constant's
    /// residuals after the first `j` levels and `d` the fitted start of
    /// those `j` levels (0 for the mean start).
    pub row: Option<(usize, f64)>,
}

/// Walks `points` through the levels of `inputs`: for each point its unit
/// coordinates and its residuals `[r, c]` after all levels (`c` = 0 for the
/// mean start), and the pass's [`PassSums`].
fn walk_levels(
    inputs: &LevelInputs<'_>,
    points: &[Point3],
    mut each: impl FnMut([f64; 2], [f64; 2]),
) -> Result<PassSums> {
    validate_points(points)?;
    let (heights, constant) = (inputs.heights, inputs.constant);
    let fitted = inputs.start == Start::Fitted;
    let want = if fitted { heights.len() } else { 0 };
    let sizes_match = heights
        .iter()
        .zip(constant)
        .all(|(a, b)| (a.m, a.n, a.phi.len()) == (b.m, b.n, b.phi.len()));
    if constant.len() != want || !sizes_match {
        return Err(Error::InvalidInput(format!(
            "{} height lattices and {} constant lattices: the fitted start needs one constant lattice of the same size per level, the mean start none",
            heights.len(),
            constant.len()
        )));
    }
    if inputs.row.is_some_and(|(j, _)| j > heights.len()) {
        return Err(Error::InvalidInput(format!(
            "the row to measure is after {} levels, but only {} are given",
            inputs.row.map_or(0, |r| r.0),
            heights.len()
        )));
    }
    let frame = &inputs.frame;
    let mut sums = PassSums::default();
    for p in points {
        let u = frame.unit(p);
        let mut v = [p.z - frame.z0, if fitted { 1.0 } else { 0.0 }];
        for (j, z) in heights.iter().enumerate() {
            if let Some((_, d)) = inputs.row.filter(|r| r.0 == j) {
                sums.row.push((v[0] - d * v[1]).abs());
            }
            let b = z.basis(u[0] * z.m as f64, u[1] * z.n as f64);
            v[0] -= z.eval_at(&b);
            if let Some(c) = constant.get(j) {
                v[1] -= c.eval_at(&b);
            }
        }
        if let Some((_, d)) = inputs.row.filter(|r| r.0 == heights.len()) {
            sums.row.push((v[0] - d * v[1]).abs());
        }
        sums.count += 1;
        sums.quad[0] += v[0] * v[0];
        sums.quad[1] += v[0] * v[1];
        sums.quad[2] += v[1] * v[1];
        each(u, v);
    }
    Ok(sums)
}

/// The [`PassSums`] of `points` after the levels of `inputs` without
/// summing a level: the pass after the last level of the fitted start,
/// which finds that level's start ([`super::MbaLevels::needs_pass`]).
///
/// ```
/// use scanfit::mba::{sums::pass_sums, FrameSums, MbaConfig, MbaLevels, Start};
/// use scanfit::Point3;
/// let p: Vec<Point3> = (0..500).map(|k| Point3::new((k % 25) as f64, (k / 25) as f64, ((k * 7) % 11) as f64)).collect();
/// let mut f = FrameSums::default();
/// f.add(&p)?;
/// let config = MbaConfig { max_levels: 2, start: Start::Fitted, ..Default::default() };
/// let mut run = MbaLevels::new(f.finish()?, &config)?;
/// while !run.done() {
///     let mut acc = run.accumulator()?;
///     let sums = acc.add_levels(&run.inputs(), &p)?;
///     run.record(&sums)?;
///     run.push(acc)?;
/// }
/// assert!(run.needs_pass());
/// let sums = pass_sums(&run.inputs(), &p)?;
/// run.record(&sums)?;
/// assert!(!run.needs_pass());
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn pass_sums(inputs: &LevelInputs<'_>, points: &[Point3]) -> Result<PassSums> {
    walk_levels(inputs, points, |_, _| {})
}

/// What a pass over the points measures besides a level's BA sums: the
/// statistics of the row it measures ([`LevelInputs::row`]) and the sums
/// `sum r^2, sum r c, sum c^2` of the residuals after all its levels, from
/// which the fitted start of those levels is the least-squares ratio
/// `d = sum r c / sum c^2` ([`start`](Self::start)). Mergeable in point
/// order like [`ResidualSums`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PassSums {
    /// Statistics of the row measured (empty when the pass measures none).
    pub row: ResidualSums,
    /// Points of the pass.
    pub count: u64,
    /// `sum r^2, sum r c, sum c^2` after all the pass's levels.
    pub quad: [f64; 3],
}

impl PassSums {
    /// Adds the sums of the points after these.
    pub fn merge(&mut self, other: &Self) {
        self.row.merge(&other.row);
        self.count += other.count;
        for (a, b) in self.quad.iter_mut().zip(other.quad) {
            *a += b;
        }
    }

    /// The fitted start `sum r c / sum c^2` (0 when the constant's
    /// residuals vanish, as for the mean start).
    pub fn start(&self) -> f64 {
        let [_, rc, cc] = self.quad;
        if cc > 0.0 {
            rc / cc
        } else {
            0.0
        }
    }

    /// The RMSE of `r - d c` with `d` the fitted [`start`](Self::start)
    /// (of `r` for the mean start).
    pub fn start_rmse(&self) -> f64 {
        let [rr, rc, cc] = self.quad;
        let d = self.start();
        let ss = (rr - 2.0 * d * rc + d * d * cc).max(0.0);
        (ss / self.count.max(1) as f64).sqrt()
    }

    /// The sums as bytes ([`crate::wire`], exact).
    ///
    /// ```
    /// use scanfit::mba::PassSums;
    /// let mut a = PassSums::default();
    /// a.row.push(0.5);
    /// a.quad = [1.0, 0.5, 2.0];
    /// assert_eq!(PassSums::from_bytes(&a.to_bytes())?, a);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(PASS_TAG);
        write_residual_sums(&mut w, &self.row);
        w.u64(self.count);
        for x in self.quad {
            w.f64(x);
        }
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, PASS_TAG, "the sums of an MBA pass")?;
        let row = read_residual_sums(&mut r)?;
        let count = r.u64()?;
        let quad = [r.f64()?, r.f64()?, r.f64()?];
        r.end()?;
        Ok(Self { row, count, quad })
    }
}

/// Writes the fields of [`ResidualSums`].
fn write_residual_sums(w: &mut Writer, s: &ResidualSums) {
    w.u64(s.count);
    w.f64(s.sum);
    w.f64(s.sum2);
    w.f64(s.max);
    w.u64(s.max_index);
}

/// Reads what [`write_residual_sums`] wrote.
fn read_residual_sums(r: &mut Reader<'_>) -> Result<ResidualSums> {
    Ok(ResidualSums {
        count: r.u64()?,
        sum: r.f64()?,
        sum2: r.f64()?,
        max: r.f64()?,
        max_index: r.u64()?,
    })
}

/// The statistics of the absolute residuals `|z - z0 - sum_k f_k(x, y)|`
/// of `points` after `levels` (evaluated as [`BaAccumulator::add_residuals`]
/// does): the vertical errors of the approximation so far, for a measuring
/// pass after the last level. Errors for a non-finite coordinate.
///
/// ```
/// use scanfit::mba::sums::residuals;
/// use scanfit::mba::Frame;
/// use scanfit::Point3;
/// let p = [Point3::new(0.0, 0.0, 1.0), Point3::new(1.0, 1.0, 3.0)];
/// let r = residuals(&Frame::of(&p)?, &[], &p)?; // no level: |z - mean z|
/// assert_eq!((r.count, r.max), (2, 1.0));
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn residuals(frame: &Frame, levels: &[Lattice], points: &[Point3]) -> Result<ResidualSums> {
    validate_points(points)?;
    let mut stats = ResidualSums::default();
    for p in points {
        stats.push(residual(frame, levels, p, frame.unit(p)).abs());
    }
    Ok(stats)
}

/// The residual `z - z0 - sum_k f_k` of `p` (unit coordinates `u`) after
/// `levels`, subtracted level by level.
pub(crate) fn residual(frame: &Frame, levels: &[Lattice], p: &Point3, u: [f64; 2]) -> f64 {
    let mut r = p.z - frame.z0;
    for l in levels {
        r -= l.eval(u[0] * l.m as f64, u[1] * l.n as f64);
    }
    r
}

/// Eqs. 3-4 of one point in factored form. With `w_kl = B_k(s) B_l(t)`,
/// `sum_kl w_kl^2 = (sum_k B_k(s)^2)(sum_l B_l(t)^2)`, and eq. 3's candidate
/// `phi_c = w z / sum w^2` times eq. 4's weight `w^2` is
/// `(z / sum w^2) fs_k ft_l` with `fs_k = B_k(s)^3`, `ft_l = B_l(t)^3`,
/// the weight itself `ds_k dt_l` with `ds_k = B_k(s)^2` (Hjelle's weight
/// `w`: `fs = B^2`, `ds = B`): one division per value instead of 16.
#[derive(Debug, Clone, Copy)]
pub(super) struct BaFactors {
    /// Factors along x of the numerator terms.
    pub(super) fs: [f64; 4],
    /// Factors along y of the numerator terms.
    pub(super) ft: [f64; 4],
    /// Factors along x of the weights.
    pub(super) ds: [f64; 4],
    /// Factors along y of the weights.
    pub(super) dt: [f64; 4],
    /// `sum_kl w_kl^2`.
    pub(super) sum2: f64,
}

impl BaFactors {
    /// The factors at local coordinates `(s, t)` of a cell.
    #[inline]
    pub(super) fn new(s: f64, t: f64, formula: ControlFormula) -> Self {
        Self::of_basis(uniform_cubic_basis(s), uniform_cubic_basis(t), formula)
    }

    /// The factors from the basis values `bs = B(s)`, `bt = B(t)`.
    #[inline]
    pub(super) fn of_basis(bs: [f64; 4], bt: [f64; 4], formula: ControlFormula) -> Self {
        let (s2, t2) = (bs.map(|b| b * b), bt.map(|b| b * b));
        let sum2 = s2.iter().sum::<f64>() * t2.iter().sum::<f64>();
        match formula {
            ControlFormula::LeeWolbergShin => Self {
                fs: std::array::from_fn(|k| s2[k] * bs[k]),
                ft: std::array::from_fn(|l| t2[l] * bt[l]),
                ds: s2,
                dt: t2,
                sum2,
            },
            ControlFormula::Hjelle => Self {
                fs: s2,
                ft: t2,
                ds: bs,
                dt: bt,
                sum2,
            },
        }
    }
}

/// Eqs. 3-4 for one point with `K` value sets at once: its candidates and
/// weights added to the sums (one numerator each, the
/// denominator shared: it depends on the point's position only).
#[inline]
pub(super) fn add_point_values<const K: usize>(
    num: &mut [&mut [f64]; K],
    den: &mut [f64],
    m: usize,
    n: usize,
    formula: ControlFormula,
    p: [f64; 2],
    zc: [f64; K],
) {
    let st = n + 3;
    let (i, s) = locate(p[0].clamp(0.0, m as f64), m);
    let (j, t) = locate(p[1].clamp(0.0, n as f64), n);
    let f = BaFactors::new(s, t, formula);
    let q = zc.map(|z| z / f.sum2);
    for k in 0..4 {
        // the 4 values of row i + k (one bounds check per row)
        let row = (i + k) * st + j..(i + k) * st + j + 4;
        for (nu, q) in num.iter_mut().zip(q) {
            let a = q * f.fs[k];
            for (nu, ft) in nu[row.clone()].iter_mut().zip(f.ft) {
                *nu += a * ft; // eqs. 3-4 numerator
            }
        }
        let d = f.ds[k];
        for (de, dt) in den[row].iter_mut().zip(f.dt) {
            *de += d * dt;
        }
    }
}

/// Adds partial BA sums to a total.
fn merge_sums(total: &mut (Vec<f64>, Vec<f64>), part: (Vec<f64>, Vec<f64>)) {
    total.0.iter_mut().zip(&part.0).for_each(|(x, y)| *x += y);
    total.1.iter_mut().zip(&part.1).for_each(|(x, y)| *x += y);
}

/// Mergeable statistics of absolute residuals (count, sum, sum of squares,
/// maximum and its index): [`ErrorStats`] of a stream. Summed in order they
/// equal [`ErrorStats::of`] on all values bit for bit.
///
/// ```
/// use scanfit::mba::ResidualSums;
/// use scanfit::metrics::ErrorStats;
/// let d = [0.5, 2.0, 1.0, 0.25];
/// let mut a = ResidualSums::default();
/// for x in d {
///     a.push(x);
/// }
/// assert_eq!(a.stats(), ErrorStats::of(&d));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ResidualSums {
    /// Values added.
    pub count: u64,
    /// Their sum.
    pub sum: f64,
    /// The sum of their squares.
    pub sum2: f64,
    /// The largest (0 when empty).
    pub max: f64,
    /// Index of the largest, counted over all values added (and merged).
    pub max_index: u64,
}

impl ResidualSums {
    /// Adds one value.
    pub fn push(&mut self, x: f64) {
        self.sum += x;
        self.sum2 += x * x;
        if x > self.max {
            self.max = x;
            self.max_index = self.count;
        }
        self.count += 1;
    }

    /// Adds the values of `other`, which come after this one's (their
    /// indices are shifted by this one's count).
    pub fn merge(&mut self, other: &Self) {
        if other.max > self.max {
            self.max = other.max;
            self.max_index = self.count + other.max_index;
        }
        self.sum += other.sum;
        self.sum2 += other.sum2;
        self.count += other.count;
    }

    /// The sums as bytes ([`crate::wire`], exact).
    ///
    /// ```
    /// use scanfit::mba::ResidualSums;
    /// let mut a = ResidualSums::default();
    /// a.push(0.25);
    /// assert_eq!(ResidualSums::from_bytes(&a.to_bytes())?, a);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(RESIDUAL_TAG);
        write_residual_sums(&mut w, self);
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, RESIDUAL_TAG, "residual statistics")?;
        let s = read_residual_sums(&mut r)?;
        r.end()?;
        Ok(s)
    }

    /// Mean, maximum and RMSE.
    pub fn stats(&self) -> ErrorStats {
        let n = self.count.max(1) as f64;
        ErrorStats {
            count: usize::try_from(self.count).unwrap_or(usize::MAX),
            mean: self.sum / n,
            max: self.max,
            max_index: usize::try_from(self.max_index).unwrap_or(usize::MAX),
            rmse: (self.sum2 / n).sqrt(),
        }
    }
}

/// The sums behind a [`Frame`]: bounding box in x and y and the sum of the
/// heights. Summed in order, [`finish`](Self::finish) equals
/// [`Frame::of`] on all points bit for bit ([`Frame::of`] goes through it).
///
/// ```
/// use scanfit::mba::{Frame, FrameSums};
/// use scanfit::Point3;
/// let p: Vec<Point3> = (0..100).map(|k| Point3::new(k as f64, (k % 7) as f64, 0.1 * k as f64)).collect();
/// let mut s = FrameSums::default();
/// for c in p.chunks(30) {
///     s.add(c)?;
/// }
/// assert_eq!(s.finish()?, Frame::of(&p)?);
/// # Ok::<(), scanfit::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameSums {
    lo: Option<[f64; 2]>,
    hi: [f64; 2],
    zsum: f64,
    count: u64,
}

impl FrameSums {
    /// Adds a chunk of points (errors for a non-finite coordinate).
    pub fn add(&mut self, points: &[Point3]) -> Result<()> {
        validate_points(points)?;
        for p in points {
            let lo = self.lo.get_or_insert([p.x, p.y]);
            if self.count == 0 {
                self.hi = [p.x, p.y];
            }
            *lo = [lo[0].min(p.x), lo[1].min(p.y)];
            self.hi = [self.hi[0].max(p.x), self.hi[1].max(p.y)];
            self.zsum += p.z;
            self.count += 1;
        }
        Ok(())
    }

    /// Adds the sums of points summed separately.
    pub fn merge(&mut self, other: &Self) {
        if let Some(olo) = other.lo {
            let lo = self.lo.get_or_insert(olo);
            *lo = [lo[0].min(olo[0]), lo[1].min(olo[1])];
            self.hi = if self.count == 0 {
                other.hi
            } else {
                [self.hi[0].max(other.hi[0]), self.hi[1].max(other.hi[1])]
            };
        }
        self.zsum += other.zsum;
        self.count += other.count;
    }

    /// Points added.
    pub fn points(&self) -> u64 {
        self.count
    }

    /// The sums as bytes ([`crate::wire`], exact).
    ///
    /// ```
    /// use scanfit::mba::FrameSums;
    /// use scanfit::Point3;
    /// let mut s = FrameSums::default();
    /// s.add(&[Point3::new(0.0, 0.0, 1.0), Point3::new(2.0, 1.0, 3.0)])?;
    /// assert_eq!(FrameSums::from_bytes(&s.to_bytes())?, s);
    /// # Ok::<(), scanfit::Error>(())
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(FRAME_TAG);
        w.u64(self.count);
        let lo = self.lo.unwrap_or([f64::NAN; 2]);
        for x in [lo[0], lo[1], self.hi[0], self.hi[1], self.zsum] {
            w.f64(x);
        }
        w.finish()
    }

    /// Reads what [`to_bytes`](Self::to_bytes) wrote.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes, FRAME_TAG, "the frame sums of an MBA")?;
        let count = r.u64()?;
        let lo = [r.f64()?, r.f64()?];
        let hi = [r.f64()?, r.f64()?];
        let zsum = r.f64()?;
        r.end()?;
        Ok(Self {
            lo: (count > 0).then_some(lo),
            hi,
            zsum,
            count,
        })
    }

    /// The mean height of the points added (`None` without points): the
    /// frame's `z0`, for a frame over a given domain instead of the data's
    /// bounding box.
    pub fn mean_z(&self) -> Option<f64> {
        (self.count > 0).then(|| self.zsum / self.count as f64)
    }

    /// The frame; errors for fewer than 2 points or data without extent in
    /// x or y.
    pub fn finish(&self) -> Result<Frame> {
        let lo = match self.lo {
            Some(lo) if self.count >= 2 => lo,
            _ => {
                return Err(Error::TooFewPoints {
                    got: usize::try_from(self.count).unwrap_or(usize::MAX),
                    needed: 2,
                    what: "a multilevel B-spline approximation (a domain with extent in x and y)"
                        .into(),
                })
            }
        };
        let (width, height) = (self.hi[0] - lo[0], self.hi[1] - lo[1]);
        let scale = width.max(height).max(lo[0].abs().max(lo[1].abs()));
        for (extent, axis) in [(width, "x"), (height, "y")] {
            if extent <= 1e-12 * scale || extent.is_nan() {
                return Err(Error::InvalidInput(format!(
                    "all points have the same {axis} (extent {extent:e}): the data span no rectangle to approximate over; MBA needs 2.5D data z = f(x, y) spread in both x and y"
                )));
            }
        }
        Ok(Frame {
            x0: lo[0],
            y0: lo[1],
            width,
            height,
            z0: self.zsum / self.count as f64,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mba::{mba, MbaConfig, MbaLevels};
    use crate::testdata::franke;

    #[test]
    fn sums_sent_as_bytes_continue_bit_for_bit_and_damaged_bytes_are_refused() -> Result<()> {
        let p = cloud(50_000);
        let frame = Frame::of(&p)?;
        let mut once = BaAccumulator::new(16, 8, ControlFormula::LeeWolbergShin)?;
        once.add_residuals(&frame, &[], &p)?;
        // stopped mid-block (20_000 is not a multiple of the block), sent, continued
        let mut a = BaAccumulator::new(16, 8, ControlFormula::LeeWolbergShin)?;
        a.add_residuals(&frame, &[], &p[..20_000])?;
        let bytes = a.to_bytes();
        let mut b = BaAccumulator::from_bytes(&bytes)?;
        b.add_residuals(&frame, &[], &p[20_000..])?;
        assert_eq!(b.points(), 50_000);
        assert_eq!(b.finish(), once.finish());
        // every truncation and a flipped tag are errors, never a panic
        for cut in (0..bytes.len()).step_by(97) {
            assert!(BaAccumulator::from_bytes(&bytes[..cut]).is_err(), "{cut}");
        }
        let mut other = bytes.clone();
        other[0] = b'X';
        let e = BaAccumulator::from_bytes(&other).unwrap_err().to_string();
        assert!(e.contains("BA sums"), "{e}");
        // a record of another type is named as such
        let f = FrameSums::default().to_bytes();
        assert!(BaAccumulator::from_bytes(&f).is_err());
        // version 1 (the heights' sums alone, before the fitted start's
        // second set) is refused as such, not misread
        let mut old = bytes.clone();
        old[7] = b'1';
        let e = BaAccumulator::from_bytes(&old).unwrap_err().to_string();
        assert!(e.contains("version 1") && e.contains("version 2"), "{e}");
        // the fitted start's two value sets continue bit for bit too
        let run = MbaLevels::new(frame, &MbaConfig::default())?;
        let inputs = run.inputs();
        let mut once = run.accumulator()?;
        let whole = once.add_levels(&inputs, &p)?;
        let mut a = run.accumulator()?;
        let mut part = a.add_levels(&inputs, &p[..20_000])?;
        let mut b = BaAccumulator::from_bytes(&a.to_bytes())?;
        assert_eq!(b.start(), Start::Fitted);
        part.merge(&PassSums::from_bytes(
            &b.add_levels(&inputs, &p[20_000..])?.to_bytes(),
        )?);
        // the BA sums bit for bit (blocks counted from the first point); the
        // pass sums to the rounding of the chunks' partial sums
        assert_eq!((part.count, part.row), (whole.count, whole.row));
        // (at level 0 the start is ~0: compared to the heights' RMS)
        let rms = (whole.quad[0] / whole.count as f64).sqrt();
        assert!((part.start() - whole.start()).abs() <= 1e-12 * rms);
        assert!((part.quad[0] - whole.quad[0]).abs() <= 1e-14 * whole.quad[0]);
        assert_eq!(b.finish_sets(), once.finish_sets());
        // sums of one start are not added with the other's inputs
        let mut mean = BaAccumulator::new(1, 1, ControlFormula::LeeWolbergShin)?;
        assert!(mean.add_levels(&inputs, &p[..10]).is_err());
        let mut fs = FrameSums::default();
        fs.add(&p[..10])?;
        assert_eq!(
            FrameSums::from_bytes(&fs.to_bytes())?.finish()?,
            Frame::of(&p[..10])?
        );
        Ok(())
    }

    fn cloud(n: usize) -> Vec<Point3> {
        let mut rng = crate::testdata::Lcg::new(17);
        (0..n)
            .map(|_| {
                let (x, y) = (rng.next_f64(), rng.next_f64());
                Point3::new(300.0 * x + 4.0e5, 200.0 * y - 7.0e5, 40.0 * franke(x, y))
            })
            .collect()
    }

    /// The MBA of `points` run the distributed way: a frame pass, then per
    /// level the chunks' accumulators and pass sums, merged by `tree` (the
    /// pass sums in chunk order), and the fitted start's last pass.
    fn chunked_mba(
        points: &[Point3],
        config: &MbaConfig,
        chunk: usize,
        tree: fn(Vec<BaAccumulator>) -> BaAccumulator,
    ) -> crate::mba::Mba {
        let mut fs = FrameSums::default();
        for c in points.chunks(chunk) {
            fs.add(c).unwrap();
        }
        let mut run = MbaLevels::new(fs.finish().unwrap(), config).unwrap();
        let pass = |run: &MbaLevels| {
            let mut sums = PassSums::default();
            for c in points.chunks(chunk) {
                sums.merge(&pass_sums(&run.inputs(), c).unwrap());
            }
            sums
        };
        while !run.done() {
            let mut sums = PassSums::default();
            let parts: Vec<BaAccumulator> = points
                .chunks(chunk)
                .map(|c| {
                    let mut a = run.accumulator().unwrap();
                    sums.merge(&a.add_levels(&run.inputs(), c).unwrap());
                    a
                })
                .collect();
            if run.record(&sums).unwrap() {
                break;
            }
            run.push(tree(parts)).unwrap();
        }
        while run.needs_pass() {
            let sums = pass(&run);
            run.record(&sums).unwrap();
        }
        let last = pass(&run);
        let mut r = run.finish();
        // the last row: what the finished surface leaves (a measuring pass)
        if let Some(rep) = r.reports.last_mut().filter(|x| x.residual.count == 0) {
            let mut stats = ResidualSums::default();
            for p in points {
                stats.push(residual(&r.frame, &r.levels, p, r.frame.unit(p)).abs());
            }
            rep.residual = stats.stats();
        }
        assert!(last.count as usize == points.len());
        r
    }

    fn left_fold(parts: Vec<BaAccumulator>) -> BaAccumulator {
        let mut it = parts.into_iter();
        let mut a = it.next().unwrap();
        for b in it {
            a.merge(b).unwrap();
        }
        a
    }

    fn balanced(mut parts: Vec<BaAccumulator>) -> BaAccumulator {
        while parts.len() > 1 {
            let mut next = Vec::new();
            let mut it = parts.into_iter();
            while let Some(mut a) = it.next() {
                if let Some(b) = it.next() {
                    a.merge(b).unwrap();
                }
                next.push(a);
            }
            parts = next;
        }
        parts.pop().unwrap()
    }

    fn right_fold(parts: Vec<BaAccumulator>) -> BaAccumulator {
        let mut it = parts.into_iter().rev();
        let mut a = it.next().unwrap();
        for mut b in it {
            b.merge(a).unwrap();
            a = b;
        }
        a
    }

    #[test]
    fn streamed_chunks_in_order_give_the_one_call_lattice() {
        let p = cloud(40_000);
        for start in [Start::Mean, Start::Fitted] {
            let config = MbaConfig {
                max_levels: 6,
                start,
                ..Default::default()
            };
            // one accumulator fed chunk after chunk (a file read in chunks)
            let whole = chunked_mba(&p, &config, p.len(), left_fold);
            for chunk in [1, 777, 16_384, 25_000] {
                let streamed = |p: &[Point3]| {
                    let mut fs = FrameSums::default();
                    for c in p.chunks(chunk) {
                        fs.add(c).unwrap();
                    }
                    let mut run = MbaLevels::new(fs.finish().unwrap(), &config).unwrap();
                    while !run.done() {
                        let mut a = run.accumulator().unwrap();
                        let mut sums = PassSums::default();
                        for c in p.chunks(chunk) {
                            sums.merge(&a.add_levels(&run.inputs(), c).unwrap());
                        }
                        run.record(&sums).unwrap();
                        run.push(a).unwrap();
                    }
                    while run.needs_pass() {
                        let mut sums = PassSums::default();
                        for c in p.chunks(chunk) {
                            sums.merge(&pass_sums(&run.inputs(), c).unwrap());
                        }
                        run.record(&sums).unwrap();
                    }
                    run.finish()
                };
                let got = streamed(&p);
                assert_eq!(got.frame, whole.frame, "chunk {chunk}");
                if start == Start::Mean {
                    assert_eq!(got.lattice, whole.lattice, "chunk {chunk}");
                } else {
                    // the BA sums bit for bit; the start `sum r c / sum c^2`
                    // to the rounding of the chunks' partial sums
                    let scale = whole.lattice.phi.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                    let worst = got
                        .lattice
                        .phi
                        .iter()
                        .zip(&whole.lattice.phi)
                        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                    assert!(worst <= 1e-14 * scale, "chunk {chunk}: {worst:e}");
                }
            }
            // the in-memory loop sums in cell order: the same lattice up to
            // the rounding of the sums' order, and the same rows
            let once = mba(&p, &config).unwrap();
            let f = (once.frame, whole.frame);
            assert_eq!(
                (f.0.x0, f.0.y0, f.0.width, f.0.height),
                (f.1.x0, f.1.y0, f.1.width, f.1.height)
            );
            assert!((f.0.z0 - f.1.z0).abs() <= 1e-14 * f.1.z0.abs().max(1.0));
            let scale = whole.lattice.phi.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let worst = once
                .lattice
                .phi
                .iter()
                .zip(&whole.lattice.phi)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            assert!(worst <= 1e-12 * scale, "{start:?}: {worst:e} of {scale}");
            assert_eq!(once.reports.len(), whole.reports.len());
            for (a, b) in once.reports.iter().zip(&whole.reports) {
                let (a, b) = (a.residual, b.residual);
                assert_eq!((a.count, a.max_index), (b.count, b.max_index));
                assert!((a.rmse - b.rmse).abs() <= 1e-10 * b.rmse, "{a:?} {b:?}");
                assert!((a.max - b.max).abs() <= 1e-10 * b.max, "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn merged_trees_give_the_one_call_lattice_to_1e12() {
        let p = cloud(30_000);
        let five = |start| MbaConfig {
            max_levels: 5,
            start,
            ..Default::default()
        };
        // a tolerance met after 3 levels of the fitted start
        let full = mba(&p, &five(Start::Fitted)).unwrap();
        let third = full.reports[2].residual.rmse * 1.0001;
        for (start, tolerance) in [
            (Start::Mean, None),
            (Start::Fitted, None),
            (Start::Fitted, Some(third)),
        ] {
            let config = MbaConfig {
                max_levels: 5,
                start,
                tolerance,
                ..Default::default()
            };
            let once = mba(&p, &config).unwrap();
            let scale = once.lattice.phi.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(scale > 1.0);
            if tolerance.is_some() {
                assert_eq!(once.levels.len(), 3);
            }
            for chunk in [997, 5000, 16_384] {
                for tree in [left_fold, balanced, right_fold] {
                    let got = chunked_mba(&p, &config, chunk, tree);
                    let worst = got
                        .lattice
                        .phi
                        .iter()
                        .zip(&once.lattice.phi)
                        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                    assert!(
                        worst <= 1e-12 * scale,
                        "{start:?} chunk {chunk}: {worst:e} of {scale}"
                    );
                    // and the levels too
                    assert_eq!(got.levels.len(), once.levels.len());
                }
            }
        }
    }

    #[test]
    fn the_pass_protocol_is_checked() {
        let p = cloud(2000);
        let mut run = MbaLevels::new(Frame::of(&p).unwrap(), &MbaConfig::default()).unwrap();
        let mut a = run.accumulator().unwrap();
        let s0 = a.add_levels(&run.inputs(), &p).unwrap();
        run.record(&s0).unwrap();
        run.push(a).unwrap();
        // level 1 cannot be pushed before its pass is recorded
        let mut b = run.accumulator().unwrap();
        let s1 = b.add_levels(&run.inputs(), &p).unwrap();
        assert!(run.push(b.clone()).is_err());
        run.record(&s1).unwrap();
        // nor recorded twice
        assert!(run.record(&s1).is_err());
        // sums of the mean start are not a fitted level
        let mean = BaAccumulator::new(2, 2, ControlFormula::LeeWolbergShin).unwrap();
        assert!(run.push(mean).is_err());
        run.push(b).unwrap();
    }

    #[test]
    fn mismatches_are_errors() {
        let mut a = BaAccumulator::new(2, 2, ControlFormula::LeeWolbergShin).unwrap();
        let b = BaAccumulator::new(4, 2, ControlFormula::LeeWolbergShin).unwrap();
        assert!(a.merge(b).unwrap_err().to_string().contains("4 x 2"));
        assert!(a.add(&[[0.0, 0.0]], &[]).is_err());
        assert!(a.add(&[[0.0, f64::NAN]], &[1.0]).is_err());
        let mut f = FrameSums::default();
        f.add(&[Point3::new(1.0, 1.0, 1.0)]).unwrap();
        assert!(f.finish().is_err());
        // an empty chunk changes nothing
        a.add(&[], &[]).unwrap();
        assert_eq!(a.points(), 0);
    }

    #[test]
    fn residual_sums_merge_like_one_stream() {
        let d: Vec<f64> = (0..1000).map(|k| ((k * 37) % 101) as f64 / 7.0).collect();
        let (mut a, mut b) = (ResidualSums::default(), ResidualSums::default());
        d[..400].iter().for_each(|&x| a.push(x));
        d[400..].iter().for_each(|&x| b.push(x));
        a.merge(&b);
        let want = ErrorStats::of(&d);
        let got = a.stats();
        assert_eq!(
            (got.count, got.max, got.max_index),
            (want.count, want.max, want.max_index)
        );
        assert!((got.rmse - want.rmse).abs() <= 1e-14 * want.rmse);
    }
}
