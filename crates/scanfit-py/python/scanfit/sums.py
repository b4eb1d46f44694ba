"""The accumulators of a chunked or distributed fit (``scanfit.dask`` drives them).

MBA (Lee, Wolberg & Shin 1997, eqs. 3-4) and the least-squares surface (the
normal equations, NURBS Book eq. 9.63) are sums over points. Each accumulator
here is created empty, fed chunks of points (``add``), merged with another
(``merge``) and finished; pickling is an exact bytes round trip
(``to_bytes``/``from_bytes``), so workers can return them to a client. Merged in
point order, the result equals the single-process one up to the rounding of the
additions (about 1e-15 relative).

- ``Centring(lo, hi)``: the translation the in-memory pipelines compute relative
  to (the bounding box's centre where it is far from the origin).
- ``FrameSums``: the MBA frame (bounding box in x, y; mean height).
- ``MbaLevels(frame, centring, levels=6, base=None, tolerance=None, hjelle=False,
  domain=None, start="fitted")``: the level loop on the client; ``state()`` is
  broadcast per level (``MbaState``), ``accumulator()`` gives the level's empty
  ``BaSums``, ``record(pass_sums)`` takes what the pass measured (and says whether
  the tolerance is met), ``push(sums)`` finishes the level; with the fitted start
  one more pass of ``MbaState.pass_sums`` while ``needs_pass``; ``finish()`` the
  surface.
- ``BaSums``: one level's sums (the heights' and, for the fitted start, the
  constant 1's values); ``add(state, points)`` returns the pass's ``PassSums``
  (the residual statistics of a level before, the fitted start's sums).
- ``FitSetup(count, centring, ...)``: ``fit_surface``'s keywords resolved for
  ``count`` points; ``knot_search()`` (``KnotSearch``: the exact order statistics
  behind the distribution knots, NURBS Book eq. 9.69, in rounds of ``RankQuery``
  / ``RankCounts``), ``equations(search=None)`` (empty ``NormalEquations``).
- ``NormalEquations``: ``add(points, uv)``, ``merge``, ``finish() -> Surface``.
- ``PlanePasses(centring, first, count)``: the best-fit plane (``params="plane"``)
  in three passes of ``PlaneStage`` / ``PlaneSums`` (covariance with the seeded
  fold sample, hull, extents); the first pass's ``add(stage, points, offset=row)``
  needs the global row of the chunk's first point, and ``projection`` is then the
  single-process fit's choice of direction (best-fit plane, or x, y, z when the
  plane folds the points over).
- ``Parameterization``: a chunk's ``(u, v)`` (plane or given), re-projected
  onto the surfaces of the accepted correction rounds; ``errors`` at them.
- ``surface_errors(surface, points, uv) -> ResidualSums``: errors at the parameters.

Example (two "workers" by hand)::

    >>> import numpy as np, scanfit.sums as S
    >>> rng = np.random.default_rng(1)
    >>> pts = rng.random((20000, 3)); pts[:, 2] = np.sin(4 * pts[:, 0]) * pts[:, 1]
    >>> c = S.Centring(pts.min(axis=0), pts.max(axis=0))
    >>> f = S.FrameSums(); f.add(pts, c)
    >>> run = S.MbaLevels(f, c, levels=4)
    >>> while not run.done:
    ...     state, a, b = run.state(), run.accumulator(), run.accumulator()
    ...     s = a.add(state, pts[:7000]); s.merge(b.add(state, pts[7000:]))
    ...     a.merge(S.BaSums.from_bytes(b.to_bytes()))
    ...     _ = run.record(s); run.push(a)
    >>> while run.needs_pass:
    ...     _ = run.record(run.state().pass_sums(pts))
    >>> run.finish()["cells"]
    (8, 8)
"""

from ._scanfit import (
    BaSums,
    Centring,
    FitSetup,
    FrameSums,
    KnotSearch,
    MbaLevels,
    MbaState,
    NormalEquations,
    Parameterization,
    PassSums,
    PlanePasses,
    PlaneStage,
    PlaneSums,
    RankCounts,
    RankQuery,
    ResidualSums,
    surface_errors,
)

__all__ = [
    "BaSums",
    "Centring",
    "FitSetup",
    "FrameSums",
    "KnotSearch",
    "MbaLevels",
    "MbaState",
    "NormalEquations",
    "Parameterization",
    "PassSums",
    "PlanePasses",
    "PlaneStage",
    "PlaneSums",
    "RankCounts",
    "RankQuery",
    "ResidualSums",
    "surface_errors",
]

_KINDS = {
    "BaSums": BaSums,
    "Centring": Centring,
    "FrameSums": FrameSums,
    "MbaState": MbaState,
    "NormalEquations": NormalEquations,
    "Parameterization": Parameterization,
    "PassSums": PassSums,
    "PlaneStage": PlaneStage,
    "PlaneSums": PlaneSums,
    "RankCounts": RankCounts,
    "RankQuery": RankQuery,
    "ResidualSums": ResidualSums,
}


def _restore(kind, data):
    """Unpickles an accumulator: ``kind.from_bytes(data)``."""
    return _KINDS[kind].from_bytes(data)
