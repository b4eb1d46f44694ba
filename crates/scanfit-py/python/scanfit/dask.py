"""scanfit on a Dask cluster: ``mba`` and ``fit_surface`` over points that never leave the workers.

MBA (Lee, Wolberg & Shin 1997, eqs. 3-4) and the least-squares surface (the normal
equations, NURBS Book eq. 9.63) are sums over points. Here every pass over the
points is one Dask task per chunk of points on the workers, which returns partial
sums (``scanfit.sums``); the partial sums are merged in a fixed tree (in chunk
order, so the result does not depend on which worker ran what, nor on retries), and
the client finishes them. Per MBA level the client broadcasts the level's state (the
frame and the lattices so far: the lattice size, never the point count) and gets back
one merged set of sums; no point ever travels to the client.

``points`` is either a Dask array of shape ``(N, 3)`` chunked by rows (any chunking,
empty chunks allowed; an unpersisted array is recomputed per pass, a persisted one is
read from the workers' memory), or a list of point files (LAS/LAZ/PLY/XYZ/... tiles,
paths the workers can read) that each worker reads itself, once per pass; a tile that
fails to read raises a ``ScanfitError`` naming the tile.

The keywords are those of ``scanfit.mba`` and ``scanfit.fit_surface``, with their
defaults. The fit's settings that look at all points at once run as more passes of
mergeable sums: ``params="plane"`` (covariance sums for the plane, the convex hull
in it for the minimum-area rectangle, the extents along its axes; then every
worker computes its points' parameters), ``knots="distribution"`` (the few order
statistics eq. 9.69 needs, found exactly by rounds of histograms) and ``correct``
(per round, the workers re-project their points onto the surfaces of the accepted
rounds in turn, as the single-process correction does). MBA's ``adjust`` (the
nearest points of the whole cloud per knot) remains
single-process and is a ``ScanfitError`` saying why. The surface equals the
single-process one up to the rounding of the merged additions (about 1e-15
relative, tested at 1e-12 on 10^6 points).

Example::

    >>> from distributed import Client, LocalCluster
    >>> import dask.array as da, scanfit.dask
    >>> client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
    >>> pts = da.from_array(terrain, chunks=(250_000, 3))          # or a list of tiles
    >>> r = scanfit.dask.mba(pts, levels=8)
    >>> r["surface"].to_step("terrain.stp"); r["vertical"]["rmse"]  # doctest: +SKIP
"""

import time

import numpy as np

from . import read_cloud
from ._scanfit import ScanfitError
from .sums import (
    Centring,
    FitSetup,
    FrameSums,
    MbaLevels,
    Parameterization,
    PlanePasses,
)

__all__ = ["mba", "fit_surface"]

#: partial sums merged per task of the merge tree
FAN_IN = 8


def _client(client):
    if client is not None:
        return client
    try:
        from distributed import get_client
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ScanfitError(
            "scanfit.dask needs dask.distributed: pip install 'dask[distributed]'"
        ) from e
    try:
        return get_client()
    except ValueError as e:
        raise ScanfitError(
            "scanfit.dask runs on the current dask.distributed client and there is none: "
            "start one first, e.g. distributed.Client(distributed.LocalCluster()) or "
            "distributed.Client('scheduler-address:8786'), or pass client="
        ) from e


# ---- reading a part of the points (runs on the workers) ------------------------


def _read_tile(path, uv):
    """The points (and with ``uv`` the u, v attributes) of one tile."""
    try:
        cloud = read_cloud(path)
    except Exception as e:  # the message names the file too; say it is a tile
        raise ScanfitError(f"tile {path!s} could not be read: {e}") from None
    pts = np.ascontiguousarray(cloud.positions, dtype=np.float64)
    if not uv:
        return pts, None
    a = cloud.attributes
    if "u" not in a or "v" not in a:
        raise ScanfitError(
            f"tile {path!s} has no attributes u and v (it has: {', '.join(sorted(a)) or 'none'}); "
            "params='uv' reads the parameters from each tile's u and v columns"
        )
    return pts, np.column_stack([a["u"], a["v"]])


class _Tile:
    """A tile read inside the task that sums it (its points never leave that task)."""

    def __init__(self, path, uv):
        self.path, self.uv = path, uv

    def load(self):
        return _read_tile(self.path, self.uv)


def _load(part):
    return part.load() if isinstance(part, _Tile) else part


def _block(pts, uv):
    """A block of a Dask array (and its parameters) as the accumulators take it."""
    return np.ascontiguousarray(pts, dtype=np.float64), uv


def _parts(points, uv, params):
    """One part per chunk or tile, in a fixed order: a Delayed ``(points, uv)`` per
    chunk of a Dask array, a ``_Tile`` (read by the task that sums it) per file."""
    import dask.array as da
    from dask import delayed

    if isinstance(points, (list, tuple)):
        if not points:
            raise ScanfitError("points is an empty list of tiles; give at least one file")
        if uv is not None:
            raise ScanfitError(
                "uv= goes with a Dask array of points; tiles carry their parameters as u and v "
                "columns (params='uv')"
            )
        return [_Tile(str(p), params == "uv") for p in points]
    if not isinstance(points, da.Array):
        raise ScanfitError(
            f"points must be a Dask array of shape (N, 3) or a list of point files; got {type(points).__name__}"
        )
    if points.ndim != 2 or points.shape[1] != 3:
        raise ScanfitError(
            f"points must have shape (N, 3), one point per row; got shape {points.shape}"
        )
    if points.numblocks[1] != 1:
        points = points.rechunk({1: 3})
    blocks = points.to_delayed().ravel()
    if uv is None:
        if params == "uv":
            raise ScanfitError(
                "params='uv' with a Dask array needs the parameters as uv=, a Dask array of shape (N, 2)"
            )
        return [delayed(_block, pure=True)(b, None) for b in blocks]
    if not isinstance(uv, da.Array) or uv.ndim != 2 or uv.shape != (points.shape[0], 2):
        raise ScanfitError(
            f"uv must be a Dask array of shape ({points.shape[0]}, 2), one (u, v) per point; "
            f"got {getattr(uv, 'shape', type(uv).__name__)}"
        )
    uv = uv.rechunk((points.chunks[0], 2))
    return [delayed(_block, pure=True)(b, u) for b, u in zip(blocks, uv.to_delayed().ravel())]


# ---- the tasks (run on the workers) --------------------------------------------


def _bounds(part):
    """Bounding box, count and first point of a part (``None`` when empty)."""
    pts, _ = _load(part)
    if len(pts) == 0:
        return None
    return pts.min(axis=0), pts.max(axis=0), len(pts), pts[0].copy()


def _merge_bounds(*bs):
    """Merged in part order: the first point is the first part's."""
    bs = [b for b in bs if b is not None]
    if not bs:
        return None
    lo = np.min([b[0] for b in bs], axis=0)
    hi = np.max([b[1] for b in bs], axis=0)
    return lo, hi, sum(b[2] for b in bs), bs[0][3]


def _frame(part, centring):
    f = FrameSums()
    f.add(_load(part)[0], centring)
    return f


def _level(part, state):
    acc = state.accumulator()
    stats = acc.add(state, _load(part)[0])
    return acc, stats


def _vertical(part, state):
    return state.residuals(_load(part)[0])


def _start_pass(part, state):
    """The pass sums of a part without a level (the fitted start of the last)."""
    return state.pass_sums(_load(part)[0])


def _plane(part, stage):
    sums = stage.accumulator()
    sums.add(stage, _load(part)[0])
    return sums


def _ranks(part, param, query):
    pts, uv = _load(part)
    counts = query.counts()
    counts.add(query, param.uv(pts, uv))
    return counts


def _equations(part, param, empty):
    pts, uv = _load(part)
    eq = empty.copy()
    if len(pts):
        eq.add(pts, param.uv(pts, uv))
    return eq


def _errors(part, param):
    pts, uv = _load(part)
    return param.errors(pts, uv)


def _merge(*xs):
    """Merges accumulators (or tuples of them) in the order given; copies the
    first, never changes an input (a retried task sees its inputs unchanged)."""
    if isinstance(xs[0], tuple):
        return tuple(_merge(*col) for col in zip(*xs))
    total = xs[0].copy()
    for x in xs[1:]:
        total.merge(x)
    return total


def _shared(value):
    """``value`` (a level state, a query, empty sums) as a constant of the task
    graph: sent to the workers that need it (its size is the lattice's, never the
    point count's), and kept by the scheduler, so a worker lost mid-pass costs
    nothing (a scattered value would be lost with its last holder)."""
    from dask import delayed

    return delayed(value, pure=False, traverse=False)


def _pass(client, parts, task, *args, merge=_merge):
    """One pass: ``task(part, *args)`` per part, merged in a fixed tree, computed."""
    from dask import delayed

    fn = delayed(task, pure=True)
    items = [fn(p, *args) for p in parts]
    join = delayed(merge, pure=True)
    while len(items) > 1:
        items = [join(*items[i : i + FAN_IN]) for i in range(0, len(items), FAN_IN)]
    return client.compute(items[0]).result()


def _centring(client, parts, domain):
    """The centring, the point count and the first point (these two when a
    pass ran) from a bounding-box pass or the given domain."""
    if domain is not None:
        x0, y0, x1, y1 = (float(v) for v in domain)
        return Centring((x0, y0, 0.0), (x1, y1, 0.0)), None, None
    b = _pass(client, parts, _bounds, merge=_merge_bounds)
    if b is None:
        raise ScanfitError("the points are empty: no chunk or tile holds a point")
    lo, hi, n, first = b
    return Centring(tuple(map(float, lo)), tuple(map(float, hi))), n, first


# ---- the fits (run on the client) ----------------------------------------------


def _mba_start(start):
    """The distributed MBA's start of level 0 (``None``: ``"fitted"``)."""
    if start is None:
        return "fitted"
    if start not in ("mean", "fitted"):
        raise ScanfitError(f"start must be 'mean' or 'fitted'; got {start!r}")
    return start


def _last_start(client, parts, run):
    """The fitted start of the last level: one more pass while ``run`` needs it.
    Returns the passes made (0 for the mean start)."""
    passes = 0
    while run.needs_pass:
        run.record(_pass(client, parts, _start_pass, _shared(run.state())))
        passes += 1
    return passes


def mba(
    points,
    levels=6,
    base=None,
    tolerance=None,
    hjelle=False,
    adjust=False,
    alpha=1.49,
    weight="moon",
    adjust_steps=5,
    start=None,
    *,
    domain=None,
    client=None,
):
    """Multilevel B-spline approximation ``z = f(x, y)`` on the current Dask client.

    The keywords are ``scanfit.mba``'s (``levels``, ``base``, ``tolerance``,
    ``hjelle``, ``start``: ``"fitted"``, the default, or ``"mean"``);
    ``adjust=True`` is refused (the projection adjustment finds the nearest points
    of the whole cloud per knot; ``alpha``, ``weight`` and ``adjust_steps`` belong
    to it).

    Parameters:
        points: a Dask array ``(N, 3)`` chunked by rows, or a list of point files.
        domain: ``(x0, y0, x1, y1)`` in data units: the rectangle the lattice
            covers (points outside are clamped to its border), instead of a first
            pass for the data's bounding box. Tiles of one survey then share it
            whatever each holds. Without it the result equals ``scanfit.mba``'s.
        client: a ``distributed.Client`` (default: the current one).

    Passes over the points: bounding box (unless ``domain``), frame, one per
    level, with the fitted start one for the last level's start, one to measure
    the final vertical residuals.

    Returns a dict: ``surface`` (a ``Surface``), ``cells``, ``levels`` (per level:
    ``level``, ``control_points``, ``vertical`` statistics of ``|z - f|`` after
    it, ``seconds``), ``vertical`` (the final statistics: ``count``, ``mean``,
    ``max``, ``max_index``, ``rmse``), ``points``, ``passes``, ``seconds`` and
    ``broadcast_bytes`` (per level, the state sent to each worker).

    Example::

        >>> r = scanfit.dask.mba(da.from_array(pts, chunks=(100_000, 3)), levels=6)
        >>> r["vertical"]["rmse"]  # doctest: +SKIP
    """
    if adjust:
        raise ScanfitError(
            "adjust=True projects the knot grid onto the whole cloud (nearest points along z) "
            "and needs all points at once; leave it out on Dask (scanfit.mba has it)"
        )
    start = _mba_start(start)
    del alpha, weight, adjust_steps  # the adjustment's settings
    t0 = time.perf_counter()
    client = _client(client)
    parts = _parts(points, None, None)
    centring, _, _ = _centring(client, parts, domain)
    frame = _pass(client, parts, _frame, centring)
    run = MbaLevels(
        frame,
        centring,
        levels=levels,
        base=base,
        tolerance=tolerance,
        hjelle=hjelle,
        domain=domain,
        start=start,
    )
    passes = (1 if domain is None else 0) + 1
    sent = []
    while not run.done:
        state = run.state()
        sent.append(len(state.to_bytes()))
        shared = _shared(state)
        acc, sums = _pass(client, parts, _level, shared)
        passes += 1
        if run.record(sums):
            break
        run.push(acc)
    passes += _last_start(client, parts, run)
    state = run.state()
    shared = _shared(state)
    vertical = _pass(client, parts, _vertical, shared)
    passes += 1
    run.record_last(vertical)
    r = run.finish()
    r["vertical"] = vertical.stats()
    r["points"] = vertical.count
    r["passes"] = passes
    r["seconds"] = time.perf_counter() - t0
    r["broadcast_bytes"] = sent
    return r


def fit_surface(
    points,
    ctrl=None,
    degree=None,
    params="plane",
    uv=None,
    knots="distribution",
    smooth=None,
    periodic_u=False,
    correct=0,
    *,
    client=None,
):
    """Least-squares B-spline surface on the current Dask client.

    The keywords are ``scanfit.fit_surface``'s, with its defaults and rules (the
    net from the point density, the smoothing scaled to the data), and give its
    surface: ``params="plane"`` (the default: the best-fit plane's parameters),
    or given parameters (``uv=`` a Dask array ``(N, 2)`` with a Dask array of
    points, or ``params="uv"`` with tiles that have ``u`` and ``v`` columns);
    ``knots="distribution"`` (the default, NURBS Book eq. 9.69) or
    ``"uniform"``; ``correct=k`` rounds of Hoschek's parameter correction.

    Passes over the points: bounding box, count and first point; with the
    plane 3 (covariance sums, convex hull, extents); then per fit (one, plus
    one per correction round): with distribution knots 2 to 3 rounds of
    counts (more above about 10^9 points), the normal equations, the errors at
    the parameters. Correction round ``r`` re-projects every point onto the
    surfaces of the ``r`` accepted rounds before, in turn (no parameter is
    stored between passes), so its passes cost ``r`` projections per point.

    Returns a dict: ``surface``, ``smoothing`` (the weight used), ``points``,
    ``errors`` (statistics of ``|p - S(u, v)|`` at the final parameters:
    ``count``, ``mean``, ``max``, ``max_index``, ``rmse``), ``rounds`` (per
    fit: ``round``, ``rmse``, ``max``; as ``scanfit.fit_surface``'s, empty
    without correction), ``passes``, ``seconds``, ``equation_bytes`` (the size
    of the sums each task returns).

    Example::

        >>> r = scanfit.dask.fit_surface(pts, ctrl=(30, 30))   # plane, distribution knots
        >>> r["errors"]["rmse"]  # doctest: +SKIP
        >>> r = scanfit.dask.fit_surface(pts, uv=uv, knots="uniform", correct=2)
    """
    t0 = time.perf_counter()
    client = _client(client)
    given = "uv" if uv is not None else params
    # the keywords checked before any pass (the count only sizes the net)
    FitSetup(1 << 20, Centring((0, 0, 0), (1, 1, 1)), ctrl, degree, given, knots, smooth,
             periodic_u, correct)
    parts = _parts(points, uv, given)
    centring, count, first = _centring(client, parts, None)
    setup = FitSetup(count, centring, ctrl, degree, given, knots, smooth, periodic_u, correct)
    passes = 1
    if setup.plane:
        plane = PlanePasses(centring, tuple(map(float, first)), count)
        while not plane.done:
            stage = _shared(plane.stage())
            plane.push(_pass(client, parts, _plane, stage))
            passes += 1
        param = plane.parameterization()
    else:
        param = Parameterization.given(centring)

    def fit(param):
        """One least-squares fit to the parameters of ``param``: the knots, the
        equations, the errors; returns (surface, fitted param, errors, passes)."""
        n = 0
        shared = _shared(param)
        search = setup.knot_search()
        while search is not None and not search.done:
            q = _shared(search.query())
            search.push(_pass(client, parts, _ranks, shared, q))
            n += 1
        empty = _shared(setup.equations(search))
        eq = _pass(client, parts, _equations, shared, empty)
        fitted = param.fitted(eq)
        errors = _pass(client, parts, _errors, _shared(fitted))
        return eq, fitted, errors, n + 2

    # Hoschek's correction as scanfit::fit::correction::correct_parameters runs it
    eq, best, errors, n = fit(param)
    passes += n
    rounds = []
    if setup.correct > 0:
        rounds.append({"round": 0, "rmse": errors.stats()["rmse"], "max": errors.stats()["max"]})
    for k in range(1, setup.correct + 1):
        cand_eq, cand, e, n = fit(best.corrected())
        passes += n
        s = e.stats()
        rounds.append({"round": k, "rmse": s["rmse"], "max": s["max"]})
        old = errors.stats()["rmse"]
        if s["rmse"] < old:
            gain = (old - s["rmse"]) / max(old, np.finfo(float).tiny)
            eq, best, errors = cand_eq, cand, e
            if gain < setup.min_improvement:
                break
        else:
            break
    return {
        "surface": eq.finish(),
        "smoothing": eq.smoothing,
        "points": eq.points,
        "errors": errors.stats(),
        "rounds": rounds,
        "passes": passes,
        "seconds": time.perf_counter() - t0,
        "equation_bytes": eq.nbytes,
    }
